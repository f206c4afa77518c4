//! Whether a motor's carrier is one a real inverter has: which bound sets the derived
//! switching frequency ([`carrier_need`]), the ceiling of realistic carriers above which no
//! derived value is given ([`max_switching_frequency`]), the band below it that needs a
//! special inverter, and a given carrier whose PWM ripple exceeds the rated current
//! ([`check_carrier`]).
//!
//! | case | condition | finding |
//! |---|---|---|
//! | derived carrier beyond any inverter | f_sw needed > [`MAX_SWITCHING_FREQUENCY`] (DC link ≤ 1.2 kV), > [`MAX_SWITCHING_FREQUENCY_MEDIUM_VOLTAGE`] (above) | error naming the keys of the bound that sets it and the carrier it needs |
//! | derived carrier of a special inverter | f_sw needed > [`FAST_CARRIER_RATIO`] of that ceiling (40 kHz; 4 kHz) | warning naming the same keys |
//! | given carrier with a large ripple | Vdc/(6·min(Ld, Lq)·f_sw) > [`MAX_GIVEN_RIPPLE_RATIO`] (1.2) × rated current | warning naming `switching_frequency` and the carrier the rule gives |
//!
//! # The ceiling (why 100 kHz and 40 kHz)
//! A low-voltage motor inverter's carrier is bounded by its switching losses, which grow with
//! the frequency while the conduction losses do not. On a 48 V silicon-MOSFET bridge they
//! already exceed the conduction losses at about 40 kHz; GaN bridges made for low-inductance
//! motors switch at up to 100 kHz (TI technical article SSZTAJ4, "Gallium Nitride Transistors
//! Open up New Frontiers in High-speed Motor Drives", 2016: "these motors … require switching
//! frequencies up to 100 kHz"). Servo controllers for slotless motors stay within that range
//! (maxon's EPOS4 and ESCON: 50–53.6 kHz, with motor chokes where the ripple asks for more).
//! So a derived carrier above 100 kHz is none a motor inverter has: the rule gives no value and
//! the error names what sets it (a motor choke in series raises the inductance; an inductance
//! in mH for H, or a rated current in mA, also land there). Between 40 and 100 kHz the motor
//! needs a GaN (or a fast, derated MOSFET) inverter, which the warning says. Medium-voltage
//! bridges (DC link above [`super::LOW_VOLTAGE_DC_LINK`]: 3.3–6.5 kV IGBTs and IGCTs switch at
//! 0.5–2 kHz, 3.3 kV SiC modules at up to about 10 kHz) get the ceiling 10 kHz and the
//! warning above 4 kHz, the same ratio \[A\].
//!
//! # A given carrier (why 1.2 times the rated current)
//! The derived carrier keeps the ripple within [`super::MAX_RIPPLE_CURRENT_RATIO`] = 0.6 of the
//! rated current; a user's inverter may run below that, and a warning names a given carrier
//! whose ripple is twice that bound, 1.2 times the rated current. Measured closed loop: the
//! slotless maxon EC 22 (`crates/fado-sim/tests/datasheet_carrier.rs`) passes `stops` with a
//! ripple of 1.0 times its rated current (40 kHz) and fails at 1.3 times (30 kHz, 0.28 rad);
//! the T-Motor U8 II on its ESC's 24 kHz (`crates/fado-sim/tests/multirotor_datasheets.rs`,
//! 1.17 times) passes `reversal` and `stops`.

use core::fmt;

use super::{
    MAX_OMEGA_TS, MAX_RIPPLE_CURRENT_RATIO, SWITCHING_FREQUENCY_STEP, ceil_to,
    min_switching_frequency, of_class, rated_speed_mech, ripple_current,
};
use crate::machine::MachineModel;

/// Highest carrier of a low-voltage motor inverter (DC link up to
/// [`LOW_VOLTAGE_DC_LINK`](super::LOW_VOLTAGE_DC_LINK)), Hz: 100 kHz, GaN bridges for
/// low-inductance motors (module documentation). A derived carrier above it is refused.
pub const MAX_SWITCHING_FREQUENCY: f64 = 100_000.0;

/// Highest carrier of a medium-voltage inverter (DC link above
/// [`LOW_VOLTAGE_DC_LINK`](super::LOW_VOLTAGE_DC_LINK)), Hz: 10 kHz, 3.3 kV SiC modules
/// (module documentation) \[A\].
pub const MAX_SWITCHING_FREQUENCY_MEDIUM_VOLTAGE: f64 = 10_000.0;

/// A derived carrier above this fraction of the class's ceiling gets a warning: 0.4 (40 kHz,
/// where a 48 V silicon-MOSFET bridge's switching losses exceed its conduction losses; module
/// documentation).
pub const FAST_CARRIER_RATIO: f64 = 0.4;

/// A given carrier whose PWM ripple ([`ripple_current`]) exceeds this multiple of the rated
/// current gets a warning: 1.2, twice the derived carrier's bound (measured, module
/// documentation).
pub const MAX_GIVEN_RIPPLE_RATIO: f64 = 1.2;

/// The ceiling of realistic carriers for an inverter on `dc_voltage` (V), Hz:
/// [`MAX_SWITCHING_FREQUENCY`] up to [`LOW_VOLTAGE_DC_LINK`](super::LOW_VOLTAGE_DC_LINK),
/// else [`MAX_SWITCHING_FREQUENCY_MEDIUM_VOLTAGE`].
pub fn max_switching_frequency(dc_voltage: f64) -> f64 {
    of_class(
        dc_voltage,
        MAX_SWITCHING_FREQUENCY,
        MAX_SWITCHING_FREQUENCY_MEDIUM_VOLTAGE,
    )
}

/// The bound that sets a derived switching frequency.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CarrierBound {
    /// The DC link's class floor ([`min_switching_frequency`]).
    ClassFloor,
    /// ω_rated·Ts ≤ [`MAX_OMEGA_TS`].
    OmegaTs,
    /// min(Ld, Lq)/Rs ≥ 2·Ts.
    TimeConstant,
    /// The PWM ripple ≤ [`MAX_RIPPLE_CURRENT_RATIO`] of the rated current.
    Ripple,
}

impl CarrierBound {
    /// The fields that set it (`MachineModel` names; `dc_voltage` the inverter's DC link).
    pub fn keys(self) -> &'static [&'static str] {
        match self {
            CarrierBound::ClassFloor => &["dc_voltage"],
            CarrierBound::OmegaTs => &["rated_speed_rpm", "pole_pairs"],
            CarrierBound::TimeConstant => &["rs", "ld", "lq"],
            CarrierBound::Ripple => &["ld", "lq", "dc_voltage", "rated_current"],
        }
    }

    /// The bound in words, with its keys.
    pub fn rule(self) -> &'static str {
        match self {
            CarrierBound::ClassFloor => "the DC link's class floor",
            CarrierBound::OmegaTs => {
                "ω_rated·Ts ≤ 0.2 (`rated_speed_rpm`, `pole_pairs`; Ts = 1/(2·f_sw))"
            }
            CarrierBound::TimeConstant => {
                "the electrical time constant min(`ld`, `lq`)/`rs` ≥ 2·Ts (Ts = 1/(2·f_sw))"
            }
            CarrierBound::Ripple => {
                "the PWM current ripple `dc_voltage`/(6·min(`ld`, `lq`)·f_sw) ≤ 0.6·`rated_current`"
            }
        }
    }
}

/// A derived switching frequency and the bound that sets it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CarrierNeed {
    /// The carrier, Hz (a whole kHz).
    pub frequency: f64,
    /// The bound that sets it (the last one to raise it).
    pub bound: CarrierBound,
}

/// The switching frequency of machine `m` (on `m.dc_voltage`) and the bound that sets it:
/// [`super::switching_frequency_of`] is its `frequency`.
pub fn carrier_need(m: &MachineModel<f64>) -> CarrierNeed {
    let omega = rated_speed_mech(m.rated_speed_rpm) * m.pole_pairs as f64;
    let needed = omega / (2.0 * MAX_OMEGA_TS);
    let floor = min_switching_frequency(m.dc_voltage);
    let bound = if needed > floor {
        CarrierBound::OmegaTs
    } else {
        CarrierBound::ClassFloor
    };
    let mut need = CarrierNeed {
        frequency: ceil_to(needed.max(floor), SWITCHING_FREQUENCY_STEP),
        bound,
    };
    let l = m.ld.min(m.lq);
    let tau = l / m.rs;
    if tau.is_finite() && tau > 0.0 && 1.0 / tau > need.frequency {
        need = CarrierNeed {
            frequency: ceil_to(1.0 / tau, SWITCHING_FREQUENCY_STEP),
            bound: CarrierBound::TimeConstant,
        };
    }
    let ripple =
        ripple_current(m.dc_voltage, l, 1.0) / (MAX_RIPPLE_CURRENT_RATIO * m.rated_current);
    if ripple.is_finite() && ripple > need.frequency {
        need = CarrierNeed {
            frequency: ceil_to(ripple, SWITCHING_FREQUENCY_STEP),
            bound: CarrierBound::Ripple,
        };
    }
    need
}

/// A finding of [`check_carrier`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CarrierFinding {
    /// The derived carrier is above the class's ceiling: no inverter has it (an error).
    Unrealistic {
        /// What the rule asks for.
        need: CarrierNeed,
        /// The ceiling ([`max_switching_frequency`]), Hz.
        ceiling: f64,
    },
    /// The derived carrier is above [`FAST_CARRIER_RATIO`] of the ceiling (a warning).
    Fast {
        /// What the rule asks for.
        need: CarrierNeed,
        /// The ceiling, Hz.
        ceiling: f64,
    },
    /// A given carrier's ripple is above [`MAX_GIVEN_RIPPLE_RATIO`] of the rated current (a
    /// warning).
    Ripple {
        /// The given carrier, Hz.
        given: f64,
        /// Its peak-to-peak ripple per rated current.
        ripple_ratio: f64,
        /// The carrier the rule gives, Hz.
        derived: f64,
    },
}

impl CarrierFinding {
    /// True for [`CarrierFinding::Unrealistic`]: the run is refused.
    pub fn is_error(&self) -> bool {
        matches!(self, CarrierFinding::Unrealistic { .. })
    }

    /// Every field involved, the likeliest culprit first (`MachineModel` names;
    /// `dc_voltage` the DC link, `switching_frequency` the inverter's carrier).
    pub fn keys(&self) -> &'static [&'static str] {
        match self {
            CarrierFinding::Unrealistic { need, .. } | CarrierFinding::Fast { need, .. } => {
                need.bound.keys()
            }
            CarrierFinding::Ripple { .. } => &[
                "switching_frequency",
                "ld",
                "lq",
                "dc_voltage",
                "rated_current",
            ],
        }
    }
}

/// The carrier findings of machine `m` (on `m.dc_voltage`): with `given` None (the carrier is
/// derived) the class's ceiling and warning band against [`carrier_need`]; with a given
/// carrier its ripple against the rated current. None when nothing is unusual or the data
/// leave the carrier undefined (the machine checks name those).
pub fn check_carrier(m: &MachineModel<f64>, given: Option<f64>) -> Option<CarrierFinding> {
    let need = carrier_need(m);
    if !need.frequency.is_finite() {
        return None;
    }
    let ceiling = max_switching_frequency(m.dc_voltage);
    match given {
        None if need.frequency > ceiling => Some(CarrierFinding::Unrealistic { need, ceiling }),
        None if need.frequency > FAST_CARRIER_RATIO * ceiling => {
            Some(CarrierFinding::Fast { need, ceiling })
        }
        None => None,
        Some(f) => {
            let ripple_ratio = ripple_current(m.dc_voltage, m.ld.min(m.lq), f) / m.rated_current;
            (ripple_ratio.is_finite() && ripple_ratio > MAX_GIVEN_RIPPLE_RATIO).then_some(
                CarrierFinding::Ripple {
                    given: f,
                    ripple_ratio,
                    derived: need.frequency,
                },
            )
        }
    }
}

/// `keys` as `` `a`, `b` ``.
struct Keys(&'static [&'static str]);

impl fmt::Display for Keys {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (n, k) in self.0.iter().enumerate() {
            if n > 0 {
                f.write_str(", ")?;
            }
            write!(f, "`{k}`")?;
        }
        Ok(())
    }
}

impl fmt::Display for CarrierFinding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            CarrierFinding::Unrealistic { need, ceiling } => write!(
                f,
                "no realistic switching frequency for this motor: {} asks for {:.0} kHz, above \
                 the {:.0} kHz of the fastest inverters of this DC link's class (GaN bridges for \
                 low-inductance motors); check {} (units: H, V, A peak), add a motor choke \
                 in series (more inductance), or give `switching_frequency` for the inverter \
                 you have",
                need.bound.rule(),
                need.frequency / 1e3,
                ceiling / 1e3,
                Keys(need.bound.keys()),
            ),
            CarrierFinding::Fast { need, ceiling } => write!(
                f,
                "the derived switching frequency {:.0} kHz ({}) is above the {:.0} kHz of \
                 silicon inverters of this DC link's class: it needs a fast (GaN) inverter \
                 (the class's ceiling {:.0} kHz); check {}, or give `switching_frequency` \
                 for the inverter you have",
                need.frequency / 1e3,
                need.bound.rule(),
                FAST_CARRIER_RATIO * ceiling / 1e3,
                ceiling / 1e3,
                Keys(need.bound.keys()),
            ),
            CarrierFinding::Ripple {
                given,
                ripple_ratio,
                derived,
            } => write!(
                f,
                "`switching_frequency` = {:.0} Hz gives a PWM current ripple \
                 `dc_voltage`/(6·min(`ld`, `lq`)·f_sw) of {:.2} times `rated_current` (beyond \
                 about 1.2 a slotless motor's sensorless estimate loses its angle at standstill): the rule \
                 gives {:.0} Hz (ripple ≤ 0.6·`rated_current`); a motor choke in series \
                 lowers the ripple",
                given, ripple_ratio, derived,
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The slotless maxon EC 22 40 W on 24 V (27.3 µH, 3.68 A).
    fn maxon() -> MachineModel<f64> {
        MachineModel {
            rs: 0.3205,
            ld: 27.3e-6,
            lq: 27.3e-6,
            flux_linkage: 3.75e-3,
            pole_pairs: 1,
            rated_current: 3.68,
            rated_speed_rpm: 31_800.0,
            rated_torque: 20.7e-3,
            dc_voltage: 24.0,
            ..MachineModel::<f64>::paper()
        }
    }

    #[test]
    fn the_need_is_the_derived_carrier_with_its_bound() {
        let paper = MachineModel::<f64>::paper();
        let need = carrier_need(&paper);
        assert_eq!(need.frequency, super::super::switching_frequency_of(&paper));
        assert_eq!(need.bound, CarrierBound::ClassFloor);
        let need = carrier_need(&maxon());
        assert_eq!(need.frequency, 67_000.0);
        assert_eq!(need.bound, CarrierBound::Ripple);
        // A 14-pole-pair outrunner at 7000 r/min with a large inductance: ω·Ts sets it.
        let fast = MachineModel {
            pole_pairs: 14,
            rated_speed_rpm: 7000.0,
            ld: 1e-3,
            lq: 1e-3,
            rs: 0.1,
            rated_current: 20.0,
            dc_voltage: 22.2,
            ..MachineModel::<f64>::paper()
        };
        assert_eq!(carrier_need(&fast).bound, CarrierBound::OmegaTs);
        // A short time constant (2 µH / 1 Ω): min(Ld, Lq)/Rs.
        let short = MachineModel {
            ld: 2e-5,
            lq: 2e-5,
            rs: 1.0,
            rated_current: 1e3,
            ..MachineModel::<f64>::paper()
        };
        let need = carrier_need(&short);
        assert_eq!(need.bound, CarrierBound::TimeConstant);
        assert_eq!(need.frequency, 50_000.0);
    }

    #[test]
    fn one_finding_per_row() {
        // Row 1: beyond the ceiling (the maxon with a tenth of its inductance: 664 kHz),
        // an error naming the ripple's keys and the carrier it needs.
        let thin = MachineModel {
            ld: 2.73e-6,
            lq: 2.73e-6,
            ..maxon()
        };
        let finding = check_carrier(&thin, None).unwrap();
        assert!(finding.is_error());
        assert_eq!(finding.keys(), &["ld", "lq", "dc_voltage", "rated_current"]);
        let text = std::format!("{finding}");
        assert!(
            text.contains("664 kHz") && text.contains("100 kHz"),
            "{text}"
        );
        // Row 2: the maxon's 67 kHz needs a fast inverter: a warning.
        let finding = check_carrier(&maxon(), None).unwrap();
        assert!(!finding.is_error());
        assert!(matches!(finding, CarrierFinding::Fast { .. }));
        // A medium-voltage motor needing 5 kHz: the warning of its class (above 4 kHz).
        let mv = MachineModel {
            dc_voltage: 5000.0,
            ld: 2.5e-3,
            lq: 2.5e-3,
            rated_current: 100.0,
            ..MachineModel::<f64>::paper()
        };
        let need = carrier_need(&mv).frequency;
        assert!(need > 4000.0 && need <= 10_000.0, "{need}");
        assert!(matches!(
            check_carrier(&mv, None),
            Some(CarrierFinding::Fast { .. })
        ));
        // The paper's motor at its derived 5 kHz: nothing.
        assert_eq!(check_carrier(&MachineModel::<f64>::paper(), None), None);
        // Row 3: a given 12 kHz carrier on the maxon (ripple 3.3 × rated): a warning naming
        // the carrier; at 30 kHz (1.33 ×) one too, at 40 kHz (1.0 ×) none.
        let finding = check_carrier(&maxon(), Some(12_000.0)).unwrap();
        assert_eq!(finding.keys()[0], "switching_frequency");
        let text = std::format!("{finding}");
        assert!(text.contains("3.3") && text.contains("67000 Hz"), "{text}");
        assert!(check_carrier(&maxon(), Some(30_000.0)).is_some());
        assert_eq!(check_carrier(&maxon(), Some(40_000.0)), None);
        // A given carrier is never refused for the class's ceiling (the user's inverter).
        assert!(!check_carrier(&thin, Some(20_000.0)).unwrap().is_error());
    }
}
