//! Plausibility of a machine's data: cross-checks of the parameters against the ratings and
//! the DC link that catch the usual slips (a unit, a pole count for pole pairs, swapped axes)
//! and name every key involved and the likely slip.
//!
//! [`check`] returns [`Finding`]s: an [`Severity::Error`] where the data cannot describe a
//! motor a drive can run (the rated torque twice what the model gives at rated current, a
//! reactance of hundreds per unit), a [`Severity::Warning`] where it is unusual but possible
//! (Ld > Lq on a magnet machine, a 2 s electrical time constant). The per-unit quantities
//! refer to the rated current I and the back-EMF at rated speed ω·λf:
//!
//! | check | quantity | warning | error |
//! |---|---|---|---|
//! | range | each field | — | beyond any motor ([`RANGES`]) |
//! | torque | T_rated / 1.5·p·λf·I (error), / MTPA torque (warning) | outside 0.6–1.3 (rms for peak: 1.41; λf line-to-line: 0.58; λf from Kt per A rms taken as peak: 0.71; inside it, a slip whose undoing brings it within 0.9–1.1) | outside 0.3–3; 0.4–0.55 of the MTPA torque with even p: a pole count |
//! | DC link range | Vdc | — | beyond any drive (checked after the machine's own fields) |
//! | back-EMF | ω·λf / (Vdc/√3) | — | above 2 |
//! | DC link | \|v_rated\| / (Vdc/√3) | below 0.2, above [`DC_LINK_SHORT`] (mains rms for the link? no-load speed? `rs`, `ld`, `lq` line-to-line?); above [`MAINS_LINK_RATIO`] on a link of a mains' rms voltage ([`MAINS_RMS`]) | below 0.1 (ratings / 10?) |
//! | reactance | L·I / λf | above 5 | above 50 (mH for H?) |
//! | resistance | R·I / (ω·λf) | above 0.5 (with the speed below which a 0.3 % voltage error costs 0.25 rad, [`low_speed_limit`]) | above 2 (mΩ for Ω? r/s for r/min?); either: line-to-line where halving it brings it within the bound |
//! | time constant | min(Ld, Lq)/R | above 2 s | — |
//! | saliency | Ld / Lq | above 1.1 (swapped?) | — |
//! | sampling | ω·Ts | above [`crate::ratings::MAX_RUNNING_OMEGA_TS`] | above π (Ts in ms for s? f_sw in kHz for Hz?) |
//! | friction | B·ω_rated,mech / T_rated | above 0.2 | above 1 (the rated point cannot be reached; N·m·s per krpm or per r/min?) |
//! | inertia | start time J·ω_rated,mech / T_rated | above 60 s (kg·cm² or g·m² for kg·m²?) | — |
//! | rating scale | L_min/R against T_rated·ω_rated and (L·I/ψ)·(ω·L/R) ([`scale`]) | long for the power (ratings / 10?), short (ratings × 10?) | — |
//! | electrical frequency | ω_rated/2π | above [`MAX_ELECTRICAL_FREQUENCY`] (r/min × 10? a pole count?) | — |
//!
//! The torque check names the likeliest slip by undoing each in turn (λf given rms, λf from
//! a line-to-line constant, a pole count for the pole pairs) and keeping the one that brings
//! the model's torque closest to the rating. On a salient rotor the reluctance torque makes
//! the ratio move less than the slip's factor (λf given rms on the 2.2 kW IPMSM: 1.29, inside
//! the wide band), so a ratio of 1.2–1.3 that the undone rms slip brings within 0.9–1.1 is
//! reported too. Below 1 it names a λf √2 too large (a torque constant per A rms converted as
//! per A peak: 0.71 on a surface-magnet rotor) and a line-to-line λf on a rotor with Lq/Ld ≈ 3
//! (0.79, undone 1.00)
//! on a model with constant inductances ([`LINE_TO_LINE_BELOW`]); a saturated machine entered
//! without its saturation (0.7–0.85) can land there too, and the warning says so.
//!
//! A winding entered line-to-line (`rs`, `ld` and `lq` each 2 × the phase's, as datasheets
//! state them between two terminals) keeps the time constant and moves the per-unit
//! reactance and resistance by 2, well inside the spread of real machines (0.03–4.4 and
//! 0.002–1.9 on the repository's machines): it is named where it shows, in the rated point's
//! voltage beyond the DC link (with the halved values, which fit it) and in a resistance
//! beyond its bound (with the halved one).
//!
//! The rating-scale check ([`scale`]) catches ratings scaled together (current, speed and
//! torque / 10 or × 10), which leave the torque, the resistance and a derived DC link
//! consistent.
//!
//! The bands are those of real machines: the repository's presets, from an 8 µH multirotor
//! outrunner to a 240 A automotive IPMSM, sit inside every warning band (a test checks it).

use crate::Real;
use crate::machine::MachineModel;
use crate::ratings;

/// How serious a finding is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Severity {
    /// Unusual but possible: reported, the run goes on.
    Warning,
    /// The data cannot describe a motor a drive can run: refused.
    Error,
}

/// The largest value of each field any motor has (≥ 10 × the largest machines a drive of this
/// kind runs): a value beyond it is a unit slip or a typo. `(field, max, unit)`.
pub const RANGES: [(&str, f64, &str); 10] = [
    ("rs", 1e3, "Ω"),
    ("ld", 10.0, "H"),
    ("lq", 10.0, "H"),
    ("flux_linkage", 100.0, "Wb"),
    ("pole_pairs", 1000.0, ""),
    ("inertia", 1e5, "kg·m²"),
    ("rated_current", 1e5, "A"),
    ("rated_speed_rpm", 5e5, "r/min"),
    ("rated_torque", 1e7, "N·m"),
    ("dc_voltage", 1e5, "V"),
];

/// Resistive drop at rated current per unit of the rated back-EMF, Rs·I/(ω·λf), above which
/// the data are refused: 2, a copper loss at the rated point twice its mechanical power
/// (efficiency below 33 %). Real machines have 0.005–0.35 (the repository's test machines: at
/// most 0.33, a 6S drone motor), motors wound for torque near standstill more (the 42-pole
/// robot-joint motor of `crates/fado-sim/tests/data/unseen/` 0.71, the GBM5208 gimbal motor
/// 1.9 at an assumed 100 r/min; warned); a resistance in mΩ for Ω, or a rated speed in r/s or rad/s
/// for r/min, gives 6–1000.
pub const RESISTANCE_ERROR: f64 = 2.0;

/// The rated point's phase voltage |v_rated| (MTPA at rated current and speed) per unit of
/// the DC link's linear range Vdc/√3 above which the ratings are reported as beyond the link:
/// 1.15, above six-step operation's fundamental (2/π)·Vdc = 1.10 × Vdc/√3, the most any
/// inverter makes. The drive still reaches rated speed by field weakening, with less than
/// rated torque there (the 15 kW PM-SyRM of `crates/fado-sim/tests/data/unseen/pmsrm-15kw-520v.toml`
/// on a 520 V link: 1.40); the usual slips are a DC link given as the mains' rms voltage (√2
/// short) and a no-load speed given as the rated speed. Multirotor motors rated near their
/// no-load speed sit at 1.04–1.10. Checked on constant inductances only: a saturating
/// machine's unsaturated inductances overstate its flux at rated current (the saturated
/// presets' 1.1–1.8).
pub const DC_LINK_SHORT: f64 = 1.15;

/// T_rated over the MTPA torque at rated current above which the ratings are reported as
/// unusual: 1.3. Real machines sit at 0.7–1.2 (the saturated ones below 1, as their
/// zero-current model overstates the torque); a current or a flux linkage given rms where the
/// peak value is meant gives √2 = 1.41.
pub const TORQUE_WARNING_HIGH: f64 = 1.3;

/// T_rated over the MTPA torque below which a model with constant inductances is searched for
/// a line-to-line λf (a warning where undoing it brings the ratio within 0.9–1.1): 0.9.
pub const LINE_TO_LINE_BELOW: f64 = 0.9;

pub use scale::{SCALE_HIGH, SCALE_LOW};

/// Rated electrical frequency above which the rated speed or the pole pairs look wrong: 5 kHz
/// (a 2-pole 240,000 r/min turbo compressor runs at 4 kHz; a 14-pole-pair drone motor at
/// 70,000 r/min, rated speed × 10, at 16 kHz).
pub const MAX_ELECTRICAL_FREQUENCY: f64 = 5000.0;

/// Mains' rms voltages (line-to-line, and line-to-neutral where a drive is fed from one
/// phase): 100–690 V. A DC link entered as one of them, where the link rectified from those
/// mains (√2 × it: 325 V from 230 V, 565 V from 400 V) is meant, is suspected when the rated
/// point needs more than [`MAINS_LINK_RATIO`] of its linear range.
pub const MAINS_RMS: [f64; 17] = [
    100.0, 110.0, 115.0, 120.0, 127.0, 200.0, 208.0, 220.0, 230.0, 240.0, 380.0, 400.0, 415.0,
    440.0, 460.0, 480.0, 690.0,
];

/// |v_rated| / (Vdc/√3) above which a DC link of a mains' rms voltage ([`MAINS_RMS`]) is
/// reported as that rms voltage where the rectified link is meant: 0.75. The repository's
/// machines on a real link of such a value (400 V: a 50 kW traction battery, the 1.1 kW
/// measured PMSM of `motors/saturated/`) need 0.63 and 0.41; the presets and test machines
/// on a link of 310–325 V or 540–565 V entered as 230 V or 400 V need 0.54–1.30 (the paper's
/// motor 0.54, rated at a third of its link's voltage, stays unnamed; 9 of 13 above 0.75).
pub const MAINS_LINK_RATIO: f64 = 0.75;

/// True when `dc_voltage` is one of [`MAINS_RMS`] (within 0.1 %: entered as its round value).
fn is_mains_rms(dc_voltage: f64) -> bool {
    MAINS_RMS.iter().any(|v| {
        let off = dc_voltage - v;
        off <= 1e-3 * v && -off <= 1e-3 * v
    })
}

use finding::TORQUE_KEYS_SALIENT;
pub use finding::{Finding, Findings, PhaseWinding, TorqueSlip};
pub use text::{LOW_SPEED_VOLTAGE_ERROR, low_speed_limit};

/// The slip whose undoing brings T_rated over the model's MTPA torque at rated current
/// closest to 1, with that ratio; [`TorqueSlip::Unknown`] (and the given ratio) when none
/// brings it within 0.9–1.1 and at least halves its distance from 1 (in log).
fn likely_slip(m: &MachineModel<f64>) -> (TorqueSlip, f64) {
    let given = m.rated_torque / ratings::rated_current_torque(m);
    // The factor a ratio is off 1 by, either way (1.1 for 1.1 and for 1/1.1).
    let off = |r: f64| if r >= 1.0 { r } else { 1.0 / r };
    let with_flux = |k: f64| MachineModel {
        flux_linkage: m.flux_linkage * k,
        ..*m
    };
    let with_pole_pairs = |pole_pairs: u32| MachineModel { pole_pairs, ..*m };
    // λf from a back-EMF constant per 1000 r/min (line-to-line), as `datasheet` converts it.
    let per_krpm = 1.0 / (m.pole_pairs as f64 * 1000.0 * core::f64::consts::PI / 30.0);
    let (sqrt2, sqrt3) = (2f64.step_sqrt(), 3f64.step_sqrt());
    let mut best = (TorqueSlip::Unknown, given);
    for (slip, undone) in [
        (TorqueSlip::Rms, with_flux(sqrt2)),
        (TorqueSlip::LineToLine, with_flux(1.0 / sqrt3)),
        (TorqueSlip::KtRms, with_flux(1.0 / sqrt2)),
        (TorqueSlip::LineRmsAsPhasePeak, with_flux(sqrt2 / sqrt3)),
        (TorqueSlip::PoleCount, with_pole_pairs(m.pole_pairs / 2)),
        (
            TorqueSlip::PolePairsHalved,
            with_pole_pairs(m.pole_pairs.saturating_mul(2)),
        ),
        (TorqueSlip::KeVllRms, with_flux(per_krpm * sqrt2 / sqrt3)),
        (TorqueSlip::KeVllPeak, with_flux(per_krpm / sqrt3)),
        (
            TorqueSlip::VoltsPerHertz,
            with_flux(1.0 / core::f64::consts::TAU),
        ),
    ] {
        if slip == TorqueSlip::PoleCount && !m.pole_pairs.is_multiple_of(2) {
            continue;
        }
        let r = m.rated_torque / ratings::rated_current_torque(&undone);
        let closer = off(r) * off(r) < off(given) && off(r) < off(best.1);
        if r.is_finite() && off(r) < 1.1 && closer {
            best = (slip, r);
        }
    }
    best
}

/// Cross-checks `m` (its `dc_voltage` included) and, with `ts`, the sampling period against
/// the rated speed. Fields that are not finite and positive are left to
/// [`MachineModel::validate`]; a field beyond [`RANGES`] is the only finding then.
pub fn check(m: &MachineModel<f64>, ts: Option<f64>) -> Findings {
    let mut out = Findings::new();
    check_into(m, ts, &mut out);
    out
}

/// Where [`check_into`] puts its findings: the whole list ([`Findings`]) or only the first
/// error ([`FirstError`], which `validate` uses so that the firmware never copies the list).
trait Sink {
    fn push(&mut self, f: Finding);
    fn is_empty(&self) -> bool;
    fn has_error(&self) -> bool;
}

impl Sink for Findings {
    fn push(&mut self, f: Finding) {
        Findings::push(self, f);
    }
    fn is_empty(&self) -> bool {
        Findings::is_empty(self)
    }
    fn has_error(&self) -> bool {
        self.error().is_some()
    }
}

/// The first error of a check and whether anything was found.
#[derive(Default)]
struct FirstError {
    first: Option<Finding>,
    any: bool,
}

impl Sink for FirstError {
    fn push(&mut self, f: Finding) {
        self.any = true;
        if self.first.is_none() && f.severity() == Severity::Error {
            self.first = Some(f);
        }
    }
    fn is_empty(&self) -> bool {
        !self.any
    }
    fn has_error(&self) -> bool {
        self.first.is_some()
    }
}

/// The body of [`check`], writing into `out`: the machine's own fields and their
/// cross-checks first, then the DC link against them (a DC link a front end derives from a
/// machine whose inductance is in mH for H is beyond any drive: the inductance is the cause).
fn check_into(m: &MachineModel<f64>, ts: Option<f64>, out: &mut impl Sink) {
    let usable = check_ranges(m, out);
    if !out.is_empty() || !usable {
        return;
    }
    check_torque(m, out);
    check_reactances(m, out);
    check_resistance(m, out);
    check_mechanics(m, out);
    let tau = m.ld.min(m.lq) / m.rs;
    if tau > 2.0 {
        out.push(Finding::TimeConstant { tau });
    }
    if m.ld > 1.1 * m.lq {
        out.push(Finding::Saliency { ld: m.ld, lq: m.lq });
    }
    check_scale(m, out);
    if !out.has_error() {
        check_dc_link(m, out);
    }
    if let Some(ts) = ts.filter(|t| t.is_finite() && *t > 0.0) {
        check_sampling(m, ts, out);
    }
}

/// The flux base of the per-unit checks: the larger of λf and the torque's flux per ampere
/// T/(1.5·p·I). A PM-assisted SyRM with a weak magnet makes its torque from a stator flux many
/// times its λf.
fn flux_base(m: &MachineModel<f64>) -> f64 {
    m.flux_linkage
        .max(m.rated_torque / (1.5 * m.pole_pairs as f64 * m.rated_current))
}

/// Each inductance per unit of the rated current and the flux base ([`flux_base`]), L·I/ψ.
fn check_reactances(m: &MachineModel<f64>, out: &mut impl Sink) {
    let flux_base = flux_base(m);
    for (key, l) in [("ld", m.ld), ("lq", m.lq)] {
        let x = l * m.rated_current / flux_base;
        let severity = if x > 50.0 {
            Some(Severity::Error)
        } else if x > 5.0 {
            Some(Severity::Warning)
        } else {
            None
        };
        if let Some(severity) = severity {
            out.push(Finding::Reactance {
                key,
                per_unit: x,
                severity,
            });
        }
    }
}

/// The resistive drop at rated current per unit of the rated back-EMF, Rs·I/(ω·ψ) with ψ the
/// [`flux_base`]: above [`RESISTANCE_ERROR`] the copper loss at the rated point is twice its
/// mechanical power.
fn check_resistance(m: &MachineModel<f64>, out: &mut impl Sink) {
    let r = m.rs * m.rated_current / (m.rated_speed() * flux_base(m));
    let severity = if r > RESISTANCE_ERROR {
        Some(Severity::Error)
    } else if r > 0.5 {
        Some(Severity::Warning)
    } else {
        None
    };
    if let Some(severity) = severity {
        // The bound of this severity, which a line-to-line value halved comes within.
        let bound = match severity {
            Severity::Error => RESISTANCE_ERROR,
            Severity::Warning => 0.5,
        };
        let speed_rpm = speed_in_rad_per_s(m);
        out.push(Finding::Resistance {
            per_unit: r,
            severity,
            line_to_line: (0.5 * r <= bound && speed_rpm.is_none()).then_some(0.5 * m.rs),
            speed_rpm,
        });
    }
}

/// `rated_speed_rpm` × 30/π when the rated speed reads as given in rad/s where r/min is
/// meant: the rated point then needs under 35 % of the DC link's linear range and, with the
/// speed undone, 30 % to [`DC_LINK_SHORT`] of it (where the repository's machines sit) and at
/// least twice what it needs as given (a line-to-line `rs` moves it by its resistive drop
/// only), with a resistive drop within its warning bound 0.5. None without a DC link.
fn speed_in_rad_per_s(m: &MachineModel<f64>) -> Option<f64> {
    if !(m.dc_voltage.is_finite() && m.dc_voltage > 0.0) {
        return None;
    }
    let v_max = m.dc_voltage / 1.732_050_807_568_877_2;
    let rpm = m.rated_speed_rpm * 30.0 / core::f64::consts::PI;
    let undone = MachineModel {
        rated_speed_rpm: rpm,
        ..*m
    };
    let given = ratings::rated_point_voltage(m) / v_max;
    let fits = ratings::rated_point_voltage(&undone) / v_max;
    let r = m.rs * m.rated_current / (undone.rated_speed() * flux_base(m));
    let plausible = (0.3..=DC_LINK_SHORT).contains(&fits) && fits >= 2.0 * given;
    (given < 0.35 && plausible && r <= 0.5).then_some(rpm)
}

/// The per-phase winding of `m` if `rs`, `ld` and `lq` are line-to-line values: the halved
/// values, when with them the rated point needs at most the link's linear range `v_max`.
fn line_to_line_winding(m: &MachineModel<f64>, v_max: f64) -> Option<PhaseWinding> {
    let phase = PhaseWinding {
        rs: 0.5 * m.rs,
        ld: 0.5 * m.ld,
        lq: 0.5 * m.lq,
    };
    let halved = MachineModel {
        rs: phase.rs,
        ld: phase.ld,
        lq: phase.lq,
        ..*m
    };
    (ratings::rated_point_voltage(&halved) <= v_max).then_some(phase)
}

/// The DC link: its range, the back-EMF at rated speed against it and the rated point's
/// voltage against it (only for a plausible machine: a reactance in mH for H makes the rated
/// point's voltage meaningless).
fn check_dc_link(m: &MachineModel<f64>, out: &mut impl Sink) {
    let (_, max, unit) = RANGES[RANGES.len() - 1];
    if m.dc_voltage > max {
        out.push(Finding::Range {
            key: "dc_voltage",
            value: m.dc_voltage,
            max,
            unit,
        });
        return;
    }
    if !(m.dc_voltage.is_finite() && m.dc_voltage > 0.0) {
        return;
    }
    let v_max = m.dc_voltage / 1.732_050_807_568_877_2;
    let emf_ratio = m.rated_speed() * m.flux_linkage / v_max;
    if emf_ratio > 2.0 {
        out.push(Finding::BackEmf { ratio: emf_ratio });
        return;
    }
    let needed = ratings::rated_point_voltage(m);
    let v = needed / v_max;
    let linear = m.magnetics.is_linear();
    if v > DC_LINK_SHORT && linear {
        out.push(Finding::DcLinkShort {
            needed,
            available: v_max,
            dc_voltage: m.dc_voltage,
            line_to_line: line_to_line_winding(m, v_max),
        });
    } else if v > MAINS_LINK_RATIO && linear && is_mains_rms(m.dc_voltage) {
        out.push(Finding::DcLinkMains {
            dc_voltage: m.dc_voltage,
            ratio: v,
        });
    } else if v < 0.2 {
        out.push(Finding::DcLinkOversized {
            ratio: v,
            severity: if v < 0.1 {
                Severity::Error
            } else {
                Severity::Warning
            },
            speed_rpm: speed_in_rad_per_s(m),
        });
    }
}

/// Pushes a [`Finding::Range`] for each machine field beyond [`RANGES`] (the DC link's is
/// checked with the DC link, after the machine); true when every field is finite and positive
/// (the cross-checks need it).
fn check_ranges(m: &MachineModel<f64>, out: &mut impl Sink) -> bool {
    if m.flux_linkage == 0.0 {
        out.push(Finding::NoMagnet);
    }
    let values = [
        m.rs,
        m.ld,
        m.lq,
        m.flux_linkage,
        m.pole_pairs as f64,
        m.inertia,
        m.rated_current,
        m.rated_speed_rpm,
        m.rated_torque,
    ];
    let mut usable = true;
    for ((key, max, unit), value) in RANGES.iter().zip(values) {
        // A value that is not finite is named by the validation ("must be finite").
        if value.is_finite() && value > *max {
            out.push(Finding::Range {
                key,
                value,
                max: *max,
                unit,
            });
        }
        usable &= value.is_finite() && value > 0.0;
    }
    usable
}

/// Torque against the model's at rated current: the errors against the magnet torque
/// 1.5·p·λf·I, which no rotor with Ld ≤ Lq falls short of and which a drive's model with a
/// mismatched L̂d or L̂q keeps; the warning against the MTPA torque. A rated torque above 3 ×
/// the magnet torque is an error only where the MTPA torque (with the reluctance torque) falls
/// short of it too: a PM-assisted SyRM with a weak magnet (ferrite, or the 6.7 kW SyRM of
/// motulator's examples with a 9 mVs magnet, 35 × its magnet torque) makes most of its torque
/// from the saliency.
fn check_torque(m: &MachineModel<f64>, out: &mut impl Sink) {
    let magnet = m.rated_torque / (m.torque_constant() * m.rated_current);
    let ratio = m.rated_torque / ratings::rated_current_torque(m);
    // Twice the pole pairs doubles the model's torque at every current, the reluctance
    // torque's too: the ratio against the MTPA torque is then 0.5 on any rotor. A model whose
    // Lq alone is too large (a drive's deliberately mismatched L̂q) moves only the MTPA
    // torque: the magnet torque must fall short too (by at least 20 %).
    if m.pole_pairs.is_multiple_of(2) && (0.4..0.55).contains(&ratio) && magnet <= 0.8 {
        out.push(Finding::PoleCount {
            pole_pairs: m.pole_pairs,
            ratio,
        });
    } else if magnet < 0.3 || (magnet > 3.0 && ratio > 3.0) {
        out.push(Finding::Torque {
            ratio: magnet,
            severity: Severity::Error,
            slip: likely_slip(m).0,
            flux_linkage: m.flux_linkage,
        });
    } else if !(0.6..=TORQUE_WARNING_HIGH).contains(&ratio) {
        out.push(Finding::Torque {
            ratio,
            severity: Severity::Warning,
            slip: likely_slip(m).0,
            flux_linkage: m.flux_linkage,
        });
    } else if ratio > 1.2 || (ratio < LINE_TO_LINE_BELOW && m.magnetics.is_linear()) {
        // Inside the wide band, but undoing the rms or line-to-line slip brings it to 0.9–1.1.
        let slip = likely_slip(m).0;
        if (ratio > 1.2 && slip == TorqueSlip::Rms)
            || (ratio < 1.0
                && matches!(
                    slip,
                    TorqueSlip::LineToLine | TorqueSlip::KtRms | TorqueSlip::LineRmsAsPhasePeak
                ))
        {
            out.push(Finding::Torque {
                ratio,
                severity: Severity::Warning,
                slip,
                flux_linkage: m.flux_linkage,
            });
        }
    }
}

/// The friction torque and the start time at rated speed against the rated torque.
fn check_mechanics(m: &MachineModel<f64>, out: &mut impl Sink) {
    let w = m.rated_speed_mech();
    let friction = m.viscous_friction * w / m.rated_torque;
    if friction > 1.0 {
        out.push(Finding::Friction {
            ratio: friction,
            severity: Severity::Error,
        });
    } else if friction > 0.2 {
        out.push(Finding::Friction {
            ratio: friction,
            severity: Severity::Warning,
        });
    }
    let start_time = m.inertia * w / m.rated_torque;
    if start_time > 60.0 {
        out.push(Finding::Inertia { start_time });
    }
}

/// The ratings scaled together ([`scale`]) and the rated electrical frequency
/// ([`MAX_ELECTRICAL_FREQUENCY`]).
fn check_scale(m: &MachineModel<f64>, out: &mut impl Sink) {
    scale::check(m, out);
    let frequency = m.rated_speed() / core::f64::consts::TAU;
    if frequency > MAX_ELECTRICAL_FREQUENCY {
        out.push(Finding::ElectricalFrequency { frequency });
    }
}

/// The angle the rotor turns per sample period `ts` at rated speed.
fn check_sampling(m: &MachineModel<f64>, ts: f64, out: &mut impl Sink) {
    let x = m.rated_speed() * ts;
    let severity = if x > core::f64::consts::PI {
        Some(Severity::Error)
    } else if x > ratings::MAX_RUNNING_OMEGA_TS * (1.0 + 1e-9) {
        Some(Severity::Warning)
    } else {
        None
    };
    if let Some(severity) = severity {
        out.push(Finding::Sampling {
            omega_ts: x,
            switching_frequency: ratings::switching_frequency(
                m.pole_pairs,
                m.rated_speed_rpm,
                m.dc_voltage,
            ),
            severity,
        });
    }
}

/// The first error of [`check`] as a [`crate::ConfigError`] (for `validate` methods).
pub fn validate(m: &MachineModel<f64>, ts: Option<f64>) -> Result<(), crate::ConfigError> {
    let mut first = FirstError::default();
    check_into(m, ts, &mut first);
    match first.first {
        Some(e) => Err(e.config_error()),
        None => Ok(()),
    }
}

/// [`validate`] for a model in any precision.
pub(crate) fn validate_real<T: Real>(m: &MachineModel<T>) -> Result<(), crate::ConfigError> {
    validate(&m.cast::<f64>(), None)
}

mod finding;
pub mod scale;
mod text;

#[cfg(test)]
mod slip_tests;
#[cfg(test)]
mod tests;
