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

use fado_core::control::{DeadTimeMethod, DriveConfig, VoltageLimit};

use crate::config::{DeadTimeMethodSetting, SimConfig, VoltageLimitSetting};
use crate::error::SimConfigError;

impl SimConfig {
    /// The drive configuration: `[controller]` settings, model estimates from the plant and
    /// `[mismatch]`, timing from the inverter.
    pub fn drive_config(&self) -> DriveConfig<f64> {
        let c = &self.controller;
        let m = &self.mismatch;
        let (mo, inv) = (&self.motor, &self.inverter);
        DriveConfig {
            ts: inv.sample_period(),
            pole_pairs: mo.pole_pairs as f64,
            rs_hat: (mo.rs + inv.on_resistance) * m.rs_ratio,
            ld_hat: mo.ld * m.ld_ratio,
            lq_hat: mo.lq * m.lq_ratio,
            flux_linkage_hat: mo.flux_linkage * m.flux_linkage_ratio,
            inertia_hat: mo.inertia * m.inertia_ratio,
            current_bandwidth_hz: c.current_bandwidth_hz,
            speed_bandwidth_hz: c.speed_bandwidth_hz,
            speed_zero_ratio: c.speed_zero_ratio,
            i_max: c.i_max,
            i_min: c.i_min,
            dead_time: inv.dead_time * m.dead_time_ratio,
            switching_frequency: inv.switching_frequency,
            dead_time_threshold_voltage: inv.threshold_voltage * m.threshold_voltage_ratio,
            dead_time_current_band: inv.current_band * m.current_band_ratio,
            dead_time_compensation: c.dead_time_compensation,
            dead_time_method: match c.dead_time_method {
                DeadTimeMethodSetting::Trapezoidal => DeadTimeMethod::Trapezoidal,
                DeadTimeMethodSetting::Sign => DeadTimeMethod::Sign,
            },
            delay_compensation_factor: c.delay_compensation_factor,
            trip_current: c.trip_current,
            decoupling: c.decoupling,
            voltage_limit: match c.voltage_limit {
                VoltageLimitSetting::Hexagon => VoltageLimit::Hexagon,
                VoltageLimitSetting::InscribedCircle => VoltageLimit::InscribedCircle,
            },
            max_modulation: c.max_modulation,
            current_anti_windup_ratio: c.current_anti_windup_ratio,
            speed_anti_windup_ratio: c.speed_anti_windup_ratio,
        }
    }

    /// The sensorless drive of this configuration (aligned by the simulation at start).
    pub fn build_drive(&self) -> Result<SensorlessDrive<f64>, SimConfigError> {
        let drive_cfg = self.drive_config();
        drive_cfg
            .validate()
            .map_err(|e| SimConfigError::from(e).in_section("controller"))?;
        SensorlessDrive::new(drive_cfg, self.estimator_config())
            .map_err(|e| SimConfigError::from(e).in_section("estimator"))
    }
}
