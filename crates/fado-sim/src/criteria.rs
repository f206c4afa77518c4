//! `[criteria]`: the pass criteria a user writes for a run. The `custom` scenario judges only
//! these (none written: it reports and passes); every other scenario judges them after its own.
//!
//! ```toml
//! [criteria]
//! max_angle_error = 0.25        # rad, max |θ − θ̂| from `simulation.eval_start` on
//! max_speed_error_ratio = 0.02  # of the rated speed, max |n* − n| from eval_start on
//! no_trip = true                # the drive never trips
//! ```
//!
//! Every key is optional; a key not written is not judged. Angles are electrical, speeds the
//! shaft's in r/min, voltages the true DC-link voltage in V (over the whole run).

use serde::{Deserialize, Serialize};

use crate::error::{SimConfigError, check};
use crate::scenario::Check;
use crate::sim::Metrics;

/// The criteria a user writes (`[criteria]`); `None` is not judged.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Criteria {
    /// max |θ − θ̂| over the evaluation window, rad (electrical).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_angle_error: Option<f64>,
    /// max |θ − θ̂| near zero speed (|n| below `simulation.zero_speed_band_ratio` × the rated
    /// speed) over the evaluation window, rad.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_angle_error_zero_speed: Option<f64>,
    /// RMS of θ − θ̂ over the evaluation window, rad.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_rms_angle_error: Option<f64>,
    /// max |n* − n| over the evaluation window as a fraction of the rated speed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_speed_error_ratio: Option<f64>,
    /// max |n* − n| over the evaluation window, r/min.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_speed_error_rpm: Option<f64>,
    /// `true`: the drive must not trip (at any time of the run).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub no_trip: Option<bool>,
    /// Highest true DC-link voltage allowed over the run, V.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_dc_voltage: Option<f64>,
    /// Lowest true DC-link voltage allowed over the run, V.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_dc_voltage: Option<f64>,
}

impl Criteria {
    /// No criterion written.
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }

    /// Checks every bound (finite, non-negative); the error names the key.
    pub fn validate(&self) -> Result<(), SimConfigError> {
        let bounds = [
            ("max_angle_error", self.max_angle_error),
            (
                "max_angle_error_zero_speed",
                self.max_angle_error_zero_speed,
            ),
            ("max_rms_angle_error", self.max_rms_angle_error),
            ("max_speed_error_ratio", self.max_speed_error_ratio),
            ("max_speed_error_rpm", self.max_speed_error_rpm),
            ("max_dc_voltage", self.max_dc_voltage),
            ("min_dc_voltage", self.min_dc_voltage),
        ];
        for (key, value) in bounds {
            if let Some(x) = value {
                check::non_negative(key, x)?;
            }
        }
        Ok(())
    }

    /// The checks of a finished run, in the order of the keys above.
    pub fn checks(&self, rated_speed_rpm: f64, m: &Metrics) -> Vec<Check> {
        let mut out = Vec::new();
        if let Some(x) = self.max_angle_error {
            out.push(Check::at_most("max |θ − θ̂| (rad)", m.max_angle_error, x));
        }
        if let Some(x) = self.max_angle_error_zero_speed {
            out.push(Check::at_most(
                "max |θ − θ̂| near zero speed (rad)",
                m.max_angle_error_zero_speed,
                x,
            ));
        }
        if let Some(x) = self.max_rms_angle_error {
            out.push(Check::at_most("RMS θ − θ̂ (rad)", m.rms_angle_error, x));
        }
        if let Some(x) = self.max_speed_error_ratio {
            out.push(Check::at_most(
                "max speed error / rated speed",
                m.max_speed_error_rpm / rated_speed_rpm,
                x,
            ));
        }
        if let Some(x) = self.max_speed_error_rpm {
            out.push(Check::at_most(
                "max speed error (r/min)",
                m.max_speed_error_rpm,
                x,
            ));
        }
        if self.no_trip == Some(true) {
            out.push(Check::at_most("tripped", m.tripped as u8 as f64, 0.0));
        }
        if let Some(x) = self.max_dc_voltage {
            out.push(Check::at_most(
                "max DC-link voltage (V)",
                m.max_dc_voltage,
                x,
            ));
        }
        if let Some(x) = self.min_dc_voltage {
            out.push(Check::at_least(
                "min DC-link voltage (V)",
                m.min_dc_voltage,
                x,
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_written_criteria_are_judged() {
        let mut m = Metrics::default();
        m.max_angle_error = 0.2;
        m.max_speed_error_rpm = 45.0;
        m.max_dc_voltage = 400.0;
        m.min_dc_voltage = 300.0;
        assert!(Criteria::default().checks(1500.0, &m).is_empty());
        let c: Criteria =
            toml::from_str("max_angle_error = 0.25\nmax_speed_error_ratio = 0.02\nno_trip = true")
                .unwrap();
        let checks = c.checks(1500.0, &m);
        assert_eq!(checks.len(), 3);
        assert!(checks[0].passed, "{checks:?}");
        assert!(!checks[1].passed, "45 r/min is 3 % of 1500: {checks:?}");
        assert!(checks[2].passed);
        let dc: Criteria = toml::from_str("max_dc_voltage = 390\nmin_dc_voltage = 250").unwrap();
        let checks = dc.checks(1500.0, &m);
        assert!(!checks[0].passed && checks[1].passed, "{checks:?}");
        let bad: Criteria = toml::from_str("max_angle_error = -1").unwrap();
        assert_eq!(bad.validate().unwrap_err().key, "max_angle_error");
        assert!(toml::from_str::<Criteria>("max_angel_error = 1").is_err());
    }
}
