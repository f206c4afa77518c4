//! One sample of the closed loop and what observes it.

use fado_core::Dq;

use crate::controller::Actuation;

/// Everything known about one sample: true plant state and the controller's view.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Time in s.
    pub time: f64,
    /// True electrical rotor angle θ, rad.
    pub theta: f64,
    /// Angle error wrap(θ − θ̂), rad.
    pub angle_error: f64,
    /// True speed, r/min (mechanical).
    pub speed_rpm: f64,
    /// Speed reference, r/min.
    pub speed_ref_rpm: f64,
    /// Estimated speed (T2S-2, for control), r/min.
    pub speed_hat_rpm: f64,
    /// True current in the true rotor frame, A.
    pub i_dq_true: Dq<f64>,
    /// True stator flux in α-β (what λ2 estimates), Wb.
    pub flux_ab_true: fado_core::Ab<f64>,
    /// Electromagnetic torque over the previous sample, N·m.
    pub torque: f64,
    /// Load torque over the previous sample, N·m.
    pub load_torque: f64,
    /// Pole pairs (to convert the controller's electrical speeds).
    pub pole_pairs: f64,
    /// True DC-link voltage over the previous sample (what the inverter switched), V.
    pub dc_voltage: f64,
    /// Stator voltage the inverter actually applied over the previous sample [n−1, n]
    /// (time average, α-β), V.
    pub v_ab_applied: fado_core::Ab<f64>,
    /// Measured current in α-β as the controller's estimator was given it (offset-corrected,
    /// a stuck channel reconstructed) when the controller reports it, else the Clarke
    /// transform of the measured phase currents, A.
    pub i_ab_measured: fado_core::Ab<f64>,
    /// The plant's holding brake holds the rotor over this sample.
    pub brake_engaged: bool,
    /// The controller reports ready at this sample (its start-up is over and it holds the
    /// rotor).
    pub ready: bool,
    /// Where the controller's start-up angle phase stands.
    pub startup: fado_core::control::StartupStatus,
    /// The controller's gain calibration status (None: a controller without one).
    pub gain_calibration: Option<fado_core::control::GainCalibrationStatus>,
    /// The controller's output at this sample.
    pub act: Actuation,
}

/// Something that watches every sample (metrics, traces, scenario criteria).
pub trait Probe {
    /// Called once per sample.
    fn observe(&mut self, s: &Sample);
    /// Called once at the end of [`Simulation::run`](crate::sim::Simulation::run) (e.g. to form RMS values).
    fn finish(&mut self) {}
}
