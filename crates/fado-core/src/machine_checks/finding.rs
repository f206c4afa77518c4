//! What a [check](super::check) finds: each [`Finding`], its severity, the keys it names and
//! the configuration error it becomes, and [`Findings`], the fixed-capacity list of one check.

use super::Severity;

/// The slip a torque disagreement most likely comes from (the one whose undoing brings the
/// model's torque at rated current closest to `rated_torque`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TorqueSlip {
    /// λf (or the current) given rms where the peak is meant: the model is √2 short.
    Rms,
    /// λf from a line-to-line constant: √3 too large.
    LineToLine,
    /// λf √2 too large: a torque constant per A rms (a datasheet's Kt) converted as per A
    /// peak, λf = Kt/(1.5·p) where Kt/(1.5·√2·p) is meant.
    KtRms,
    /// λf √(3/2) = 1.22 too large: a back-EMF constant in V rms line-to-line taken as the
    /// phase peak (λf = E_LL,rms/ω where E_LL,rms·√2/(√3·ω) is meant).
    LineRmsAsPhasePeak,
    /// The pole count given for the pole pairs: twice too many.
    PoleCount,
    /// Half the pole pairs (a sheet's pole-pair count read as the poles): the model is half
    /// the rating.
    PolePairsHalved,
    /// A back-EMF constant in V rms line-to-line per 1000 r/min entered as λf: p·128 × too
    /// large.
    KeVllRms,
    /// A back-EMF constant in V peak line-to-line per 1000 r/min entered as λf: p·181 × too
    /// large.
    KeVllPeak,
    /// A flux in V/Hz (2π·λf, the unit of TI's InstaSPIN "rated flux") entered as λf: 2π ×
    /// too large.
    VoltsPerHertz,
    /// None of these: check the units.
    Unknown,
}

/// One finding of [`check`](super::check).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Finding {
    /// λf = 0: a synchronous reluctance motor without magnet, outside the method.
    NoMagnet,
    /// A field beyond any motor ([`RANGES`](super::RANGES)).
    Range {
        /// The field.
        key: &'static str,
        /// Its value.
        value: f64,
        /// The largest plausible value.
        max: f64,
        /// Its unit.
        unit: &'static str,
    },
    /// The rated torque is about half what the model gives at rated current and the pole
    /// pairs are even: the pole count was given.
    PoleCount {
        /// The value given.
        pole_pairs: u32,
        /// T_rated / T_model(I_rated) on the MTPA point.
        ratio: f64,
    },
    /// The rated torque and the model's torque at rated current disagree.
    Torque {
        /// T_rated / T_model(I_rated).
        ratio: f64,
        /// Warning or error.
        severity: Severity,
        /// The likeliest slip.
        slip: TorqueSlip,
        /// λf as given, Wb (the text gives it with the slip undone).
        flux_linkage: f64,
    },
    /// The viscous friction takes a large share of the rated torque at rated speed.
    Friction {
        /// B·ω_rated,mech / T_rated.
        ratio: f64,
        /// Warning or error.
        severity: Severity,
    },
    /// The rated torque takes long to accelerate the inertia to rated speed.
    Inertia {
        /// J·ω_rated,mech / T_rated, s.
        start_time: f64,
    },
    /// The ratings look scaled together (/ 10 or × 10): see [`scale`](super::scale).
    RatingScale {
        /// L_max·I/ψ (armature reaction per unit).
        reaction: f64,
        /// ω_rated·L_min/R.
        x_over_r: f64,
        /// L_min/R, s.
        tau: f64,
        /// T_rated·ω_rated,mech, W.
        power: f64,
        /// True for ratings that look divided by 10, false for multiplied.
        divided: bool,
    },
    /// The rated electrical frequency is beyond any motor of this kind.
    ElectricalFrequency {
        /// ω_rated/2π, Hz.
        frequency: f64,
    },
    /// The back-EMF at rated speed is far above what the DC link can oppose.
    BackEmf {
        /// ω_rated·λf / (Vdc/√3).
        ratio: f64,
    },
    /// The rated point needs a small fraction of the DC link.
    DcLinkOversized {
        /// |v_rated| / (Vdc/√3).
        ratio: f64,
        /// Warning or error.
        severity: Severity,
        /// `rated_speed_rpm` × 30/π when the rated speed reads as given in rad/s: with it the
        /// rated point fits the link and the resistance its warning bound.
        speed_rpm: Option<f64>,
    },
    /// The rated point needs more voltage than the DC link makes: rated speed at rated
    /// current only by field weakening.
    DcLinkShort {
        /// |v_rated| on MTPA at rated current and speed, V (phase peak).
        needed: f64,
        /// Vdc/√3, V.
        available: f64,
        /// Vdc, V.
        dc_voltage: f64,
        /// The per-phase winding when `rs`, `ld` and `lq` look line-to-line: the halved
        /// values, with which the rated point fits the link.
        line_to_line: Option<PhaseWinding>,
    },
    /// The DC link is a mains' rms voltage ([`MAINS_RMS`](super::MAINS_RMS)) and the rated
    /// point needs most of its linear range: a link rectified from those mains is √2 × it.
    DcLinkMains {
        /// Vdc, V.
        dc_voltage: f64,
        /// |v_rated| / (Vdc/√3).
        ratio: f64,
    },
    /// An inductance is large for the rated current and flux linkage.
    Reactance {
        /// `ld` or `lq`.
        key: &'static str,
        /// L·I_rated/λf.
        per_unit: f64,
        /// Warning or error.
        severity: Severity,
    },
    /// The resistive drop at rated current is large against the back-EMF.
    Resistance {
        /// Rs·I_rated/(ω_rated·λf).
        per_unit: f64,
        /// Warning or error.
        severity: Severity,
        /// Rs/2, Ω, when the resistance halved (a line-to-line value for the phase's) is
        /// within the bound of this severity.
        line_to_line: Option<f64>,
        /// `rated_speed_rpm` × 30/π when the rated speed reads as given in rad/s (as for
        /// [`Finding::DcLinkOversized`]); the likelier slip then, named first.
        speed_rpm: Option<f64>,
    },
    /// The electrical time constant is long.
    TimeConstant {
        /// min(Ld, Lq)/Rs, s.
        tau: f64,
    },
    /// Ld > Lq on a magnet machine: swapped?
    Saliency {
        /// Ld.
        ld: f64,
        /// Lq.
        lq: f64,
    },
    /// The rotor turns far per sample at rated speed.
    Sampling {
        /// ω_rated·Ts, rad.
        omega_ts: f64,
        /// The derived switching frequency that keeps ω_rated·Ts within the bound, Hz.
        switching_frequency: f64,
        /// Warning or error.
        severity: Severity,
    },
}

/// A winding's per-phase values, Ω and H: those of a winding whose data look line-to-line
/// (between two terminals of a star connection, 2 × the phase's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseWinding {
    /// Rs, Ω.
    pub rs: f64,
    /// Ld, H.
    pub ld: f64,
    /// Lq, H.
    pub lq: f64,
}

/// The findings of one [`check`](super::check), errors first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Findings {
    items: [Option<Finding>; 12],
    len: usize,
}

impl Findings {
    pub(super) fn new() -> Self {
        Self {
            items: [None; 12],
            len: 0,
        }
    }

    pub(super) fn push(&mut self, f: Finding) {
        if self.len < self.items.len() {
            self.items[self.len] = Some(f);
            self.len += 1;
        }
    }

    /// Every finding, errors first.
    pub fn iter(&self) -> impl Iterator<Item = &Finding> {
        let errors = self.items[..self.len]
            .iter()
            .flatten()
            .filter(|f| f.severity() == Severity::Error);
        let warnings = self.items[..self.len]
            .iter()
            .flatten()
            .filter(|f| f.severity() == Severity::Warning);
        errors.chain(warnings)
    }

    /// The first error, if any.
    pub fn error(&self) -> Option<&Finding> {
        self.iter().find(|f| f.severity() == Severity::Error)
    }

    /// The warnings.
    pub fn warnings(&self) -> impl Iterator<Item = &Finding> {
        self.iter().filter(|f| f.severity() == Severity::Warning)
    }

    /// True when nothing was found.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

pub(super) const TORQUE_KEYS: &[&str] = &[
    "rated_torque",
    "rated_current",
    "flux_linkage",
    "pole_pairs",
];
pub(super) const TORQUE_KEYS_SALIENT: &[&str] = &[
    "rated_torque",
    "rated_current",
    "flux_linkage",
    "pole_pairs",
    "ld",
    "lq",
];
const TORQUE_KEYS_POLES_FIRST: &[&str] = &[
    "pole_pairs",
    "rated_torque",
    "rated_current",
    "flux_linkage",
    "ld",
    "lq",
];
const TORQUE_KEYS_FLUX_FIRST: &[&str] = &[
    "flux_linkage",
    "rated_torque",
    "rated_current",
    "pole_pairs",
    "ld",
    "lq",
];
pub(super) const EMF_KEYS: &[&str] = &[
    "flux_linkage",
    "rated_speed_rpm",
    "pole_pairs",
    "dc_voltage",
];
const DC_LINK_KEYS: &[&str] = &[
    "rated_speed_rpm",
    "rated_current",
    "rated_torque",
    "dc_voltage",
];
const DC_LINK_SHORT_KEYS: &[&str] = &[
    "dc_voltage",
    "rated_speed_rpm",
    "rated_current",
    "flux_linkage",
    "ld",
    "lq",
    "rs",
];
const RESISTANCE_KEYS: &[&str] = &["rs", "rated_current", "flux_linkage", "rated_speed_rpm"];
const RESISTANCE_KEYS_SPEED_FIRST: &[&str] =
    &["rated_speed_rpm", "rs", "rated_current", "flux_linkage"];
const TAU_KEYS: &[&str] = &["rs", "ld", "lq"];
const LD_LQ: &[&str] = &["ld", "lq"];
const SAMPLING_KEYS: &[&str] = &["ts", "rated_speed_rpm", "pole_pairs"];
const SCALE_KEYS: &[&str] = &[
    "rated_current",
    "rated_speed_rpm",
    "rated_torque",
    "ld",
    "lq",
    "rs",
];
const FREQUENCY_KEYS: &[&str] = &["rated_speed_rpm", "pole_pairs"];
const EMF_KEYS_DC_FIRST: &[&str] = &[
    "dc_voltage",
    "flux_linkage",
    "rated_speed_rpm",
    "pole_pairs",
];

impl Finding {
    /// Warning or error.
    pub fn severity(&self) -> Severity {
        match *self {
            Finding::NoMagnet
            | Finding::Range { .. }
            | Finding::PoleCount { .. }
            | Finding::BackEmf { .. } => Severity::Error,
            Finding::Torque { severity, .. }
            | Finding::DcLinkOversized { severity, .. }
            | Finding::Reactance { severity, .. }
            | Finding::Resistance { severity, .. }
            | Finding::Sampling { severity, .. }
            | Finding::Friction { severity, .. } => severity,
            Finding::TimeConstant { .. }
            | Finding::Saliency { .. }
            | Finding::RatingScale { .. }
            | Finding::Inertia { .. }
            | Finding::DcLinkShort { .. }
            | Finding::DcLinkMains { .. }
            | Finding::ElectricalFrequency { .. } => Severity::Warning,
        }
    }

    /// Every field involved, the likeliest culprit first (`MachineModel` field names; `ts` is
    /// the sampling period, `dc_voltage` the inverter's DC link).
    pub fn keys(&self) -> &'static [&'static str] {
        match *self {
            Finding::NoMagnet => &["flux_linkage"],
            Finding::Range { key, .. } => match key {
                "rs" => &["rs"],
                "ld" => &["ld"],
                "lq" => &["lq"],
                "flux_linkage" => &["flux_linkage"],
                "pole_pairs" => &["pole_pairs"],
                "inertia" => &["inertia"],
                "rated_current" => &["rated_current"],
                "rated_speed_rpm" => &["rated_speed_rpm"],
                "rated_torque" => &["rated_torque"],
                _ => &["dc_voltage"],
            },
            Finding::PoleCount { .. } => &["pole_pairs", "rated_torque", "flux_linkage"],
            Finding::Torque {
                slip: TorqueSlip::PolePairsHalved,
                ..
            } => TORQUE_KEYS_POLES_FIRST,
            Finding::Torque {
                severity: Severity::Warning,
                slip: TorqueSlip::LineToLine,
                ..
            }
            | Finding::Torque {
                slip:
                    TorqueSlip::KeVllRms
                    | TorqueSlip::KeVllPeak
                    | TorqueSlip::VoltsPerHertz
                    | TorqueSlip::KtRms
                    | TorqueSlip::LineRmsAsPhasePeak,
                ..
            } => TORQUE_KEYS_FLUX_FIRST,
            Finding::Torque {
                severity: Severity::Error,
                ..
            } => TORQUE_KEYS,
            Finding::Torque { .. } => TORQUE_KEYS_SALIENT,
            Finding::BackEmf { ratio } if ratio > 300.0 => EMF_KEYS_DC_FIRST,
            Finding::BackEmf { .. } => EMF_KEYS,
            Finding::DcLinkOversized { .. } => DC_LINK_KEYS,
            Finding::DcLinkShort { .. } | Finding::DcLinkMains { .. } => DC_LINK_SHORT_KEYS,
            Finding::Reactance { key, .. } => {
                if key == "ld" {
                    &["ld", "rated_current", "flux_linkage"]
                } else {
                    &["lq", "rated_current", "flux_linkage"]
                }
            }
            Finding::Resistance {
                speed_rpm: Some(_), ..
            } => RESISTANCE_KEYS_SPEED_FIRST,
            Finding::Resistance { .. } => RESISTANCE_KEYS,
            Finding::TimeConstant { .. } => TAU_KEYS,
            Finding::Saliency { .. } => LD_LQ,
            Finding::Sampling { .. } => SAMPLING_KEYS,
            Finding::RatingScale { .. } => SCALE_KEYS,
            Finding::Friction { .. } => &["viscous_friction", "rated_torque", "rated_speed_rpm"],
            Finding::Inertia { .. } => &["inertia", "rated_torque", "rated_speed_rpm"],
            Finding::ElectricalFrequency { .. } => FREQUENCY_KEYS,
        }
    }

    /// The likeliest culprit (the first of [`keys`](Self::keys)).
    pub fn key(&self) -> &'static str {
        self.keys()[0]
    }

    /// The finding as a fado-core [`crate::ConfigError`] naming [`key`](Self::key) (its
    /// numbers are in the `Display` text, which front ends show instead).
    pub fn config_error(&self) -> crate::ConfigError {
        let expected = match self {
            Finding::NoMagnet => "a magnet flux λf > 0 (a synchronous reluctance motor has none)",
            Finding::Range { .. } => "within the range of real motors (check the unit)",
            Finding::PoleCount { .. } => {
                "pole pairs (the rated torque is half what this many give: a pole count?)"
            }
            Finding::Torque { .. } => {
                "rated_torque within 0.3–3 × the model's torque at rated_current (check units: λf in Wb peak, current in A peak)"
            }
            Finding::BackEmf { .. } => {
                "back-EMF at rated speed (ω·λf) at most 2 × Vdc/√3 (check units and the DC link)"
            }
            Finding::DcLinkOversized { .. } => {
                "ratings that use at least 10 % of the DC link (ratings divided by 10?)"
            }
            Finding::Reactance { .. } => {
                "an inductance below 50 per unit of λf/rated_current (mH given as H?)"
            }
            Finding::Resistance { .. } => {
                "a resistive drop at rated current below 2 × the rated back-EMF (mΩ given as Ω, or the rated speed in r/s?)"
            }
            Finding::TimeConstant { .. }
            | Finding::Saliency { .. }
            | Finding::RatingScale { .. }
            | Finding::Inertia { .. }
            | Finding::DcLinkShort { .. }
            | Finding::DcLinkMains { .. }
            | Finding::ElectricalFrequency { .. } => "plausible values",
            Finding::Friction { .. } => {
                "a friction torque at rated speed below the rated torque (N·m·s/rad)"
            }
            Finding::Sampling { .. } => {
                "a sampling period in s at which the rotor turns less than π per sample at rated speed (ms given as s?)"
            }
        };
        crate::ConfigError::OutOfRange {
            field: self.key(),
            expected,
        }
    }
}
