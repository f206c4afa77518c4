//! What the closed loop needs from a controller: one call per sample with the measurements,
//! returning the duty for the next update and what the controller believes (for the traces).
//! The sensorless drive of `fado-core` implements it ([`crate::drive`]); so can sensored
//! reference controllers in tests.

use fado_core::control::{GainCalibrationStatus, StartupStatus};
use fado_core::{Ab, Abc, Dq, DriveFlags, Estimate};

/// Everything a controller may read at sample n.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measurements {
    /// Time of the sample in s.
    pub time: f64,
    /// Measured phase currents (through the sensor model), A.
    pub i_abc: Abc<f64>,
    /// Measured DC-link voltage, V.
    pub vdc: f64,
    /// Speed reference, mechanical rad/s.
    pub speed_ref_mech: f64,
    /// Encoder angle, mechanical rad (5000 ppr): for sensored reference controllers and
    /// evaluation only — a sensorless controller must not read it.
    pub encoder_angle_mech: f64,
}

/// A controller's answer at sample n.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Actuation {
    /// Duties in [0, 1], loaded at n+1, acting over [n+1, n+2].
    pub duty: Abc<f64>,
    /// Gates enabled (false after a trip: the diodes conduct).
    pub gates_enabled: bool,
    /// The controller tripped.
    pub tripped: bool,
    /// The controller rejected this sample's inputs.
    pub input_fault: bool,
    /// The drive's status word (faults and warnings); empty for controllers without one.
    pub flags: DriveFlags,
    /// The α-β current the controller's estimator was given (offset-corrected, a stuck
    /// channel reconstructed), A; None for controllers that do not report it.
    pub i_ab_used: Option<Ab<f64>>,
    /// Realised voltage reference (α-β), V.
    pub v_ref_ab: Ab<f64>,
    /// Measured current in the controller's (estimated) rotor frame, A.
    pub i_dq: Dq<f64>,
    /// Current reference, A.
    pub i_dq_ref: Dq<f64>,
    /// The rotor-angle estimate (a sensored controller reports its encoder angle here).
    pub estimate: Estimate<f64>,
}

/// Scenario events a controller may act on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControlEvent {
    /// Switch the k_df disturbance feedback on or off (the experiment of Fig. 9).
    DisturbanceFeedback(bool),
}

/// A closed-loop controller run by [`crate::sim::Simulation`].
pub trait Controller {
    /// Start-up at a known rotor angle θ0 (electrical rad), e.g. after an alignment.
    fn align(&mut self, theta0: f64);
    /// One sample.
    fn step(&mut self, m: &Measurements) -> Actuation;
    /// A scenario event; controllers without the feature ignore it.
    fn handle(&mut self, _event: ControlEvent) {}
    /// Short name for tables.
    fn name(&self) -> &str;
    /// The controller holds the rotor and runs: its start-up (calibrations) is over, its
    /// gates are on and it has not tripped. A plant brake (`simulation.brake`) releases at the
    /// first sample this is true. Default: always (controllers without a start-up).
    fn ready(&self) -> bool {
        true
    }
    /// Where the controller's start-up angle phase stands (see
    /// [`fado_core::control::startup`]). Default: [`StartupStatus::Idle`] (controllers that
    /// start from the angle they are given).
    fn startup_status(&self) -> StartupStatus {
        StartupStatus::Idle
    }
    /// Where the controller's gain calibration stands (see
    /// [`fado_core::control::GainCalibrationStatus`]). Default: None (controllers without one).
    fn gain_calibration_status(&self) -> Option<GainCalibrationStatus> {
        None
    }
    /// The plant's brake has released (a drive re-arms its release hold). Default: nothing.
    fn brake_released(&mut self) {}
}

/// A boxed controller (an estimator chosen at run time from
/// [`crate::estimators::ESTIMATORS`]) is a controller.
impl<C: Controller + ?Sized> Controller for Box<C> {
    fn align(&mut self, theta0: f64) {
        (**self).align(theta0);
    }
    #[inline]
    fn step(&mut self, m: &Measurements) -> Actuation {
        (**self).step(m)
    }
    fn handle(&mut self, event: ControlEvent) {
        (**self).handle(event);
    }
    fn name(&self) -> &str {
        (**self).name()
    }
    fn ready(&self) -> bool {
        (**self).ready()
    }
    fn startup_status(&self) -> StartupStatus {
        (**self).startup_status()
    }
    fn gain_calibration_status(&self) -> Option<GainCalibrationStatus> {
        (**self).gain_calibration_status()
    }
    fn brake_released(&mut self) {
        (**self).brake_released();
    }
}
