//! The words of each [`Finding`]: what was found, every key involved and the likely slip.

use core::fmt;

use super::{
    Finding, MAX_ELECTRICAL_FREQUENCY, RESISTANCE_ERROR, Severity, TORQUE_KEYS_SALIENT, TorqueSlip,
};
use crate::ratings::{MAX_OMEGA_TS, MAX_RUNNING_OMEGA_TS};

/// `keys` as "`a`, `b` and `c`".
fn write_keys(f: &mut fmt::Formatter<'_>, keys: &[&str]) -> fmt::Result {
    for (k, key) in keys.iter().enumerate() {
        if k > 0 {
            f.write_str(if k + 1 == keys.len() { " and " } else { ", " })?;
        }
        write!(f, "`{key}`")?;
    }
    Ok(())
}

/// The text of [`Finding::Torque`]: the ratio, the torque it compares with, the likely slip.
fn write_torque(
    f: &mut fmt::Formatter<'_>,
    ratio: f64,
    severity: Severity,
    slip: TorqueSlip,
    flux_linkage: f64,
) -> fmt::Result {
    if severity == Severity::Error {
        write!(
            f,
            "`rated_torque` is {ratio:.3} × the magnet torque 1.5·p·λf·I at \
             `rated_current` (from `flux_linkage` and `pole_pairs`)"
        )?;
    } else {
        write!(
            f,
            "`rated_torque` is {ratio:.3} × the torque the model gives at \
             `rated_current` on the MTPA point (from "
        )?;
        write_keys(f, &TORQUE_KEYS_SALIENT[2..])?;
        f.write_str(")")?;
    }
    let ke = |f: &mut fmt::Formatter<'_>, unit: &str| {
        write!(
            f,
            ": `flux_linkage` a back-EMF constant in V {unit} line-to-line per 1000 r/min? \
             Give it as `ke_vll_{unit}_per_krpm` (λf in Wb peak per phase from it and \
             `pole_pairs`)"
        )
    };
    match slip {
        TorqueSlip::KeVllRms => return ke(f, "rms"),
        TorqueSlip::KeVllPeak => return ke(f, "peak"),
        TorqueSlip::VoltsPerHertz => {
            return f.write_str(
                ": `flux_linkage` in V/Hz (2π·λf, a \"rated flux\" of TI's InstaSPIN) where Wb \
                 is meant? λf = the V/Hz value / 2π",
            );
        }
        TorqueSlip::KtRms | TorqueSlip::LineRmsAsPhasePeak => {
            return write_flux_undone(f, slip, flux_linkage);
        }
        TorqueSlip::PolePairsHalved => {
            return f.write_str(
                ": `pole_pairs` half the pole pairs (a sheet's pole-pair count read as the \
                 poles)? The model's torque is half the rating",
            );
        }
        _ => {}
    }
    if (0.3e-3..3e-3).contains(&ratio) {
        return f.write_str(": `flux_linkage` in mWb where Wb is meant?");
    } else if (300.0..3000.0).contains(&ratio) {
        return f.write_str(": `flux_linkage` in Wb where mWb is meant, or `rated_current` in mA?");
    }
    match slip {
        TorqueSlip::Rms => f.write_str(
            ": rms where peak is meant (√2 = 1.41)? Give the current in A peak and λf in Wb peak",
        ),
        TorqueSlip::PoleCount => f.write_str(
            ": `pole_pairs` a pole count (the model's torque twice the rating), or `ld`/`lq` off?",
        ),
        TorqueSlip::LineToLine if severity == Severity::Warning && ratio > 0.6 => f.write_str(
            ": λf from a line-to-line constant where the phase value is meant (√3 = 1.73)? \
             Give λf in Wb peak per phase. (A saturated machine entered with its no-load \
             `ld`, `lq` lands here too: give its saturation model or flux map.)",
        ),
        TorqueSlip::LineToLine => f.write_str(
            ": λf from a line-to-line constant where the phase value is meant (√3 = 1.73)? \
             Give λf in Wb peak per phase",
        ),
        _ => f.write_str(": check the units (λf in Wb peak per phase, current in A peak)"),
    }
}

/// The slips of λf a factor too large whose text gives the value undone: a Kt per A rms taken
/// as per A peak (√2), a line-to-line rms constant taken as the phase peak (√(3/2)).
fn write_flux_undone(
    f: &mut fmt::Formatter<'_>,
    slip: TorqueSlip,
    flux_linkage: f64,
) -> fmt::Result {
    match slip {
        TorqueSlip::KtRms => {
            write!(
                f,
                ": `flux_linkage` √2 too large, from a torque constant per A rms converted as \
                 per A peak (λf = Kt/(1.5·p) where Kt/(1.5·√2·p) is meant)? flux_linkage = \
                 {:e} Wb (or give Kt as `kt_nm_per_arms`)",
                flux_linkage / core::f64::consts::SQRT_2
            )
        }
        TorqueSlip::LineRmsAsPhasePeak => {
            write!(
                f,
                ": `flux_linkage` √(3/2) = 1.22 too large, from a line-to-line rms back-EMF \
                 taken as the phase peak (λf = E_LL,rms/ω where √2·E_LL,rms/(√3·ω) is \
                 meant)? flux_linkage = {:e} Wb (or give the constant as \
                 `ke_vll_rms_per_krpm`)",
                flux_linkage * 0.816_496_580_927_726_1
            )
        }
        _ => Ok(()),
    }
}

/// The text of [`Finding::Sampling`]: the angle per sample and what it costs.
fn write_sampling(
    f: &mut fmt::Formatter<'_>,
    omega_ts: f64,
    switching_frequency: f64,
    severity: Severity,
) -> fmt::Result {
    write!(
        f,
        "the rotor turns ω_rated·Ts = {omega_ts:.3} rad per sample at rated speed \
         (`rated_speed_rpm`, `pole_pairs`, sampling period `ts`)"
    )?;
    if severity == Severity::Error {
        f.write_str(
            ", more than π: the angle cannot be sampled (a sampling period in ms \
             where s is meant, or a switching frequency in kHz where Hz is meant?)",
        )
    } else {
        write!(
            f,
            "; the drive's angle estimate degrades above {MAX_RUNNING_OMEGA_TS} and \
             commissioning needs at most {MAX_OMEGA_TS} (switching frequency ≥ \
             {switching_frequency} Hz)"
        )
    }
}

/// The text of [`Finding::RatingScale`]: the size the ratings state against the windings'
/// and the direction.
fn write_scale(f: &mut fmt::Formatter<'_>, finding: &Finding) -> fmt::Result {
    let Finding::RatingScale {
        reaction,
        x_over_r,
        tau,
        power,
        divided,
    } = *finding
    else {
        return Ok(());
    };
    let (long, short) = super::scale::tau_bounds(power);
    let (bound, kind) = if divided {
        (long, "at most")
    } else {
        (short, "at least")
    };
    write!(
        f,
        "the ratings look scaled: `rated_torque` at `rated_speed_rpm` is {power:.4} W while the \
         windings' time constant min(`ld`, `lq`)/`rs` is {:.4} ms (machines of that power have \
         {kind} about {:.4} ms), and the armature reaction L·`rated_current`/ψ {reaction:.3} \
         times ω·L/R {x_over_r:.3} is {:.3e} (machines have 0.005–60)",
        tau * 1e3,
        bound * 1e3,
        reaction * x_over_r
    )?;
    if divided {
        f.write_str(": are `rated_current`, `rated_speed_rpm` and `rated_torque` divided by 10?")
    } else {
        f.write_str(
            ": are `rated_current`, `rated_speed_rpm` and `rated_torque` multiplied by 10, or \
             `rs` 1000 × too small?",
        )
    }
}

/// The text of [`Finding::Reactance`]: the per-unit value and the likely unit slip.
fn write_reactance(f: &mut fmt::Formatter<'_>, key: &str, per_unit: f64) -> fmt::Result {
    write!(
        f,
        "`{key}` is {per_unit:.3e} per unit (L·`rated_current` over the larger of \
         `flux_linkage` and `rated_torque`/(1.5·p·`rated_current`); machines have 0.05–5)"
    )?;
    if per_unit > 50.0 && per_unit * 1e-3 < 5.0 {
        write!(f, ": mH where H is meant? ({key} × 1e-3)")
    } else {
        f.write_str(": check its unit (H)")
    }
}

/// The voltage error near zero speed, per unit of Rs·I, that [`low_speed_limit`] assumes
/// \[A\]: 0.3 %, the negative-sequence share (g/2)·(2/√3) of a 0.5 % gain mismatch of one
/// current sensor, and an R̂s error of that size.
pub const LOW_SPEED_VOLTAGE_ERROR: f64 = 0.003;

/// The speed, per unit of the rated speed, below which a voltage error of
/// [`LOW_SPEED_VOLTAGE_ERROR`] × Rs·I turns the estimated angle by 0.25 rad (the paper's
/// low-speed criterion) on a machine whose rated resistive drop is `per_unit` × its rated
/// back-EMF: the angle error of a voltage error e at speed ω is e/(ω·λf), so
/// ω/ω_rated = per_unit·ε/0.25. The paper's motor 0.15 %; the 42-pole robot-joint motor of
/// `crates/fado-sim/tests/data/unseen/` (0.705) 0.85 %, whose uncalibrated sensors put its
/// `reversal` at 0.33 rad within 2 % of the rated speed; the GBM5208 gimbal motor there
/// (1.876) 2.3 %, beyond the scenarios' 2 % band: its `reversal` misses by 0.31–1.58 rad with
/// its start-up calibration skipped (its swing, 2J/c = 0.56 s, outlasts the budget) and
/// passes (0.014–0.092 rad) with the gains calibrated.
pub fn low_speed_limit(per_unit: f64) -> f64 {
    per_unit * LOW_SPEED_VOLTAGE_ERROR / 0.25
}

/// The text of [`Finding::Resistance`]: the per-unit drop and the likely slip.
fn write_resistance(f: &mut fmt::Formatter<'_>, finding: &Finding) -> fmt::Result {
    let Finding::Resistance {
        per_unit,
        line_to_line,
        speed_rpm,
        ..
    } = *finding
    else {
        return Ok(());
    };
    write!(
        f,
        "`rs` drops {per_unit:.3} × the rated back-EMF at `rated_current` (Rs·I/(ω·λf) from \
         `flux_linkage` and `rated_speed_rpm`; machines have 0.005–0.3)"
    )?;
    if let Some(rpm) = speed_rpm {
        write!(f, "; {}", SpeedInRadPerS(rpm))?;
    }
    if let Some(rs) = line_to_line {
        write!(
            f,
            "; is `rs` the resistance between two terminals (line-to-line, 2 × the phase's)? \
             rs = {rs:e} Ω per phase (or give it as `rs_line_to_line`)"
        )?;
    }
    if per_unit > RESISTANCE_ERROR && per_unit * 1e-3 < 0.5 {
        f.write_str(
            ": mΩ where Ω is meant, or `rated_speed_rpm` in r/s or rad/s where r/min is meant?",
        )
    } else if per_unit <= RESISTANCE_ERROR {
        f.write_str(
            ": usual only on motors wound for torque near standstill (gimbals, robot joints: \
             0.5–2); otherwise check its unit (Ω per phase) and the ratings \
             (`rated_speed_rpm` in rad/s where r/min is meant makes it 9.55 × too large)",
        )?;
        write!(
            f,
            ". Near zero speed the angle rests on R̂s·i: a voltage error of {:.1} % of Rs·I \
             (R̂s that far off, or an uncalibrated 0.5 % gain mismatch of the current sensors) \
             turns θ̂ by 0.25 rad (the low-speed criterion) below {:.1} % of the rated speed; \
             the drive's start-up calibration of the sensors' gains needs the rotor's swing \
             about its d current to settle within the calibration's budget",
            100.0 * LOW_SPEED_VOLTAGE_ERROR,
            100.0 * low_speed_limit(per_unit),
        )
    } else {
        f.write_str(": check its unit (Ω per phase) and the ratings")
    }
}

/// The rad/s-for-r/min slip of the rated speed, with the speed it meant.
struct SpeedInRadPerS(f64);

impl fmt::Display for SpeedInRadPerS {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "`rated_speed_rpm` in rad/s where r/min is meant? rated_speed_rpm = {:.0} (× 30/π) \
             fits the DC link and the winding",
            self.0
        )
    }
}

/// The text of [`Finding::DcLinkOversized`], [`Finding::DcLinkShort`] and
/// [`Finding::DcLinkMains`].
fn write_dc_link(f: &mut fmt::Formatter<'_>, finding: &Finding) -> fmt::Result {
    match *finding {
        Finding::DcLinkOversized {
            ratio, speed_rpm, ..
        } => {
            write!(
                f,
                "the rated point (`rated_speed_rpm`, `rated_current`, `rated_torque`) needs \
                 only {:.1} % of the phase voltage the DC link `dc_voltage` makes (Vdc/√3): ",
                100.0 * ratio
            )?;
            match speed_rpm {
                Some(rpm) => write!(
                    f,
                    "{}; or are the ratings divided by 10?",
                    SpeedInRadPerS(rpm)
                ),
                None => f.write_str("are the ratings divided by 10, or the DC link the wrong one?"),
            }
        }
        Finding::DcLinkShort {
            needed,
            available,
            dc_voltage,
            line_to_line,
        } => {
            write!(
                f,
                "the rated point (`rated_speed_rpm` at `rated_current` on MTPA, from \
                 `flux_linkage`, `ld`, `lq`, `rs`) needs {needed:.1} V phase peak, {:.2} × the \
                 {available:.1} V the DC link `dc_voltage` makes (Vdc/√3): the drive reaches \
                 rated speed only by field weakening, with less than rated torque there; is \
                 `dc_voltage` the mains' rms voltage where the DC link (√2 × it, {:.0} V) is \
                 meant, or `rated_speed_rpm` the no-load speed?",
                needed / available,
                dc_voltage * core::f64::consts::SQRT_2
            )?;
            if let Some(w) = line_to_line {
                write!(
                    f,
                    " Or are `rs`, `ld` and `lq` line-to-line values (between two terminals, \
                     2 × the phase's)? Per phase rs = {:e} Ω, ld = {:e} H, lq = {:e} H fit the \
                     link (or give `rs_line_to_line` and `l_line_to_line`)",
                    w.rs, w.ld, w.lq
                )?;
            }
            Ok(())
        }
        Finding::DcLinkMains { dc_voltage, ratio } => write!(
            f,
            "`dc_voltage` = {dc_voltage} V is a mains' rms voltage, and the rated point \
             (`rated_speed_rpm` at `rated_current`, from `flux_linkage`, `ld`, `lq`, `rs`) \
             needs {:.0} % of the phase voltage it makes (Vdc/√3): if the drive is fed from \
             {dc_voltage} V AC mains, its DC link is √2 × it: dc_voltage = {:.0}?",
            100.0 * ratio,
            dc_voltage * core::f64::consts::SQRT_2
        ),
        _ => Ok(()),
    }
}

/// The text of [`Finding::Friction`] and [`Finding::Inertia`].
fn write_mechanics(f: &mut fmt::Formatter<'_>, finding: &Finding) -> fmt::Result {
    match *finding {
        Finding::Friction { ratio, .. } => write!(
            f,
            "`viscous_friction` takes {ratio:.3} × `rated_torque` at `rated_speed_rpm` \
             (B·ω_rated,mech; machines 0.005–0.05){}",
            if ratio > 1.0 {
                ": the rated point cannot be reached. B is in N·m·s/rad (N·m per rad/s): a value in \
                 N·m per 1000 r/min is 105 × it"
            } else {
                ": check its unit (N·m·s/rad)"
            }
        ),
        Finding::Inertia { start_time } => write!(
            f,
            "`inertia` takes {start_time:.1} s to reach `rated_speed_rpm` at \
             `rated_torque` (J·ω_rated,mech/T_rated; drives 0.01–30 s): kg·cm² or g·m² \
             where kg·m² is meant (÷ 10⁴, ÷ 10³)?"
        ),
        _ => Ok(()),
    }
}

impl fmt::Display for Finding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Finding::NoMagnet => f.write_str(
                "`flux_linkage` must be positive: λf = 0 is a synchronous reluctance motor \
                 without magnet, outside this method. The estimator takes the rotor's angle \
                 from the rotor flux λs − Lq·i, of magnitude λf + (Ld − Lq)·id, and its \
                 limiter holds that magnitude at λ̂f at standstill: without a magnet it \
                 vanishes at zero d current, and the angle with it. A PM-assisted SyRM is \
                 entered with its magnet's λf (motors/pmsyrm-5k.toml: 0.134 Wb)",
            ),
            Finding::Range {
                key,
                value,
                max,
                unit,
            } => write!(
                f,
                "`{key}` = {value:e} {unit} is beyond any motor (at most {max:e} {unit}): check its unit"
            ),
            Finding::PoleCount { pole_pairs, ratio } => write!(
                f,
                "`pole_pairs` = {pole_pairs} looks like a pole count: {}? With it the model \
                 gives {:.2} × `rated_torque` at `rated_current` (on the MTPA point, with \
                 `flux_linkage`)",
                pole_pairs / 2,
                1.0 / ratio
            ),
            Finding::Torque {
                ratio,
                severity,
                slip,
                flux_linkage,
            } => write_torque(f, ratio, severity, slip, flux_linkage),
            Finding::RatingScale { .. } => write_scale(f, self),
            Finding::ElectricalFrequency { frequency } => write!(
                f,
                "the rated electrical frequency p·`rated_speed_rpm`/60 with `pole_pairs` is \
                 {frequency:.0} Hz, above the {MAX_ELECTRICAL_FREQUENCY} Hz of the fastest \
                 motors: is `rated_speed_rpm` × 10, or `pole_pairs` a pole count?"
            ),
            Finding::BackEmf { ratio } => {
                write!(
                    f,
                    "the back-EMF at rated speed ω·λf (`flux_linkage`, `rated_speed_rpm`, \
                     `pole_pairs`) is {ratio:.2} × the phase voltage the DC link `dc_voltage` \
                     can make (Vdc/√3)"
                )?;
                if ratio > 300.0 {
                    f.write_str(": `dc_voltage` in kV where V is meant?")
                } else {
                    f.write_str(": check their units (λf in Wb peak per phase) and the DC link")
                }
            }
            Finding::Friction { .. } | Finding::Inertia { .. } => write_mechanics(f, self),
            Finding::DcLinkOversized { .. }
            | Finding::DcLinkShort { .. }
            | Finding::DcLinkMains { .. } => write_dc_link(f, self),
            Finding::Reactance { key, per_unit, .. } => write_reactance(f, key, per_unit),
            Finding::Resistance { .. } => write_resistance(f, self),
            Finding::TimeConstant { tau } => write!(
                f,
                "the electrical time constant min(`ld`, `lq`)/`rs` is {tau:.3} s, unusually long \
                 (motors have 0.1–100 ms): check the units of rs (Ω) and ld, lq (H)"
            ),
            Finding::Saliency { ld, lq } => write!(
                f,
                "`ld` = {ld:e} H is {:.2} × `lq` = {lq:e} H: a magnet rotor has Ld ≤ Lq (the \
                 magnet is in the d-axis path); are ld and lq swapped?",
                ld / lq
            ),
            Finding::Sampling {
                omega_ts,
                switching_frequency,
                severity,
            } => write_sampling(f, omega_ts, switching_frequency, severity),
        }
    }
}
