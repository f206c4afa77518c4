//! What a scenario run produced and its `metrics.json` document.

use serde::Serialize;

use crate::config::{EstimatorKind, Precision, SimConfig};
use crate::inverter::InverterModel;
use crate::sim::{Metrics, RunStats, StartupOutcome, Trace};

use super::{Check, ScenarioProbe};

/// Everything a scenario run produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The scenario's own accumulations (revolution DC, D̂ series, hold statistics).
    pub probe: ScenarioProbe,
    /// Scenario name.
    pub scenario: String,
    /// The configuration run.
    pub config: SimConfig,
    /// All criteria passed.
    pub passed: bool,
    /// The criteria.
    pub checks: Vec<Check>,
    /// Angle and speed metrics.
    pub metrics: Metrics,
    /// The drive's start-up: how it ended, when it was ready, the rotor's motion before.
    pub startup: StartupOutcome,
    /// Timing.
    pub stats: RunStats,
    /// Decimated trace.
    pub trace: Trace,
}

/// The `metrics.json` document.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Scenario name.
    pub scenario: String,
    /// Inverter model run.
    pub inverter_model: InverterModel,
    /// Scalar type of the drive.
    pub precision: Precision,
    /// Which rotor-angle estimator ran.
    pub estimator: EstimatorKind,
    /// All criteria passed.
    pub passed: bool,
    /// max |θ − θ̂| over the evaluation window, rad.
    pub max_angle_error: f64,
    /// RMS angle error, rad.
    pub rms_angle_error: f64,
    /// max |θ − θ̂| near zero speed, rad.
    pub max_angle_error_zero_speed: f64,
    /// RMS angle error near zero speed, rad.
    pub rms_angle_error_zero_speed: f64,
    /// Zero-speed band, r/min.
    pub zero_speed_band_rpm: f64,
    /// max speed error, r/min.
    pub max_speed_error_rpm: f64,
    /// Tripped.
    pub tripped: bool,
    /// Highest true DC-link voltage over the run, V.
    pub max_dc_voltage: f64,
    /// Lowest true DC-link voltage over the run, V.
    pub min_dc_voltage: f64,
    /// Simulated seconds.
    pub simulated_seconds: f64,
    /// Wall seconds.
    pub wall_seconds: f64,
    /// The drive's start-up from t = 0, whatever the evaluation window: its status (`ready`,
    /// `deferred`, `aborted`, `no_angle_information`, `implausible_angle`, `not_ready`), the
    /// time of ready, the rotor's motion before it, the start-up's restarts, the gain
    /// calibration's status and the angle phase ([`StartupOutcome`]).
    pub startup: StartupOutcome,
    /// The criteria.
    pub checks: Vec<Check>,
}

impl Outcome {
    /// The `metrics.json` document of this run.
    pub fn report(&self) -> Report {
        let m = &self.metrics;
        Report {
            scenario: self.scenario.clone(),
            inverter_model: self.config.inverter.model,
            precision: self.config.simulation.precision,
            estimator: self.config.simulation.estimator,
            passed: self.passed,
            max_angle_error: m.max_angle_error,
            rms_angle_error: m.rms_angle_error,
            max_angle_error_zero_speed: m.max_angle_error_zero_speed,
            rms_angle_error_zero_speed: m.rms_angle_error_zero_speed,
            zero_speed_band_rpm: m.zero_speed_band_rpm,
            max_speed_error_rpm: m.max_speed_error_rpm,
            tripped: m.tripped,
            max_dc_voltage: m.max_dc_voltage,
            min_dc_voltage: m.min_dc_voltage,
            simulated_seconds: self.stats.simulated_seconds,
            wall_seconds: self.stats.wall_seconds,
            startup: self.startup.clone(),
            checks: self.checks.clone(),
        }
    }
}
