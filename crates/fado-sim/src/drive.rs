//! The sensorless drive of `fado-core` (Fig. 5) as a [`Controller`] of the closed loop.

use fado_core::RotorAngleEstimator;
use fado_core::control::SensorlessDrive;

use crate::controller::{Actuation, ControlEvent, Controller, Measurements};

/// Estimators whose k_df feedback can be switched at run time (Fig. 9).
pub trait DisturbanceFeedbackSwitch {
    /// Enables or disables k_df.
    fn set_disturbance_feedback(&mut self, enabled: bool);
}

impl DisturbanceFeedbackSwitch for fado_core::SensorlessEstimator<f64> {
    fn set_disturbance_feedback(&mut self, enabled: bool) {
        self.set_disturbance_feedback_enabled(enabled);
    }
}

impl<E> Controller for SensorlessDrive<f64, E>
where
    E: RotorAngleEstimator<f64> + DisturbanceFeedbackSwitch,
{
    fn align(&mut self, theta0: f64) {
        SensorlessDrive::align(self, theta0);
    }

    #[inline]
    fn step(&mut self, m: &Measurements) -> Actuation {
        let out = SensorlessDrive::step(self, m.i_abc, m.vdc, m.speed_ref_mech);
        Actuation {
            duty: out.duty,
            gates_enabled: out.gates_enabled,
            tripped: out.tripped,
            input_fault: out.input_fault,
            v_ref_ab: out.v_ref_ab,
            i_dq: out.i_dq,
            i_dq_ref: out.i_dq_ref,
            estimate: out.estimate,
        }
    }

    fn handle(&mut self, event: ControlEvent) {
        match event {
            ControlEvent::DisturbanceFeedback(on) => {
                self.estimator_mut().set_disturbance_feedback(on)
            }
        }
    }

    fn name(&self) -> &str {
        self.estimator().name()
    }
}
