//! The sensorless drive of `fado-core` (Fig. 5) as a [`Controller`] of the closed loop.

use fado_core::control::{GainCalibrationStatus, SensorlessDrive, StartupStatus};
use fado_core::{Ab, Abc, Diagnostics, Dq, Estimate, RotorAngleEstimator};

use crate::controller::{Actuation, ControlEvent, Controller, Measurements};

impl<E> Controller for SensorlessDrive<f64, E>
where
    E: RotorAngleEstimator<f64>,
{
    fn align(&mut self, theta0: f64) {
        SensorlessDrive::align(self, theta0);
    }

    fn ready(&self) -> bool {
        SensorlessDrive::ready(self)
    }

    fn startup_status(&self) -> StartupStatus {
        SensorlessDrive::startup_status(self)
    }

    fn gain_calibration_status(&self) -> Option<GainCalibrationStatus> {
        Some(SensorlessDrive::gain_calibration_status(self))
    }

    fn brake_released(&mut self) {
        self.arm_release_hold();
    }

    #[inline]
    fn step(&mut self, m: &Measurements) -> Actuation {
        let out = SensorlessDrive::step(self, m.i_abc, m.vdc, m.speed_ref_mech);
        Actuation {
            duty: out.duty,
            gates_enabled: out.gates_enabled,
            tripped: out.tripped,
            input_fault: out.input_fault,
            flags: out.flags,
            i_ab_used: Some(out.i_ab),
            v_ref_ab: out.v_ref_ab,
            i_dq: out.i_dq,
            i_dq_ref: out.i_dq_ref,
            estimate: out.estimate,
        }
    }

    fn handle(&mut self, event: ControlEvent) {
        match event {
            ControlEvent::DisturbanceFeedback(on) => {
                RotorAngleEstimator::set_disturbance_feedback(self.estimator_mut(), on)
            }
        }
    }

    fn name(&self) -> &str {
        self.estimator().name()
    }
}

use fado_core::control::DriveConfig;

use crate::config::SimConfig;
use crate::error::SimConfigError;

impl SimConfig {
    /// The drive around a baseline estimator (`[simulation] estimator`), f64.
    pub fn build_baseline_drive<E>(
        &self,
        estimator: E,
    ) -> Result<SensorlessDrive<f64, E>, SimConfigError>
    where
        E: RotorAngleEstimator<f64>,
    {
        let drive_cfg = self.drive_config();
        SensorlessDrive::with_estimator(drive_cfg, estimator)
            .map_err(|e| self.core_error("controller", e))
    }

    /// The sensorless drive of this configuration (aligned by the simulation at start).
    pub fn build_drive(&self) -> Result<SensorlessDrive<f64>, SimConfigError> {
        let drive_cfg = self.drive_config();
        drive_cfg
            .validate()
            .map_err(|e| self.core_error("controller", e))?;
        // Validated with the whole estimator config (the drive starts at angle 0 and is
        // aligned by the simulation).
        self.estimator_config()
            .validate()
            .map_err(|e| self.core_error("estimator", e))?;
        SensorlessDrive::new(drive_cfg, self.estimator).map_err(|e| self.core_error("estimator", e))
    }
}

/// The drive in single precision (as on the paper's DSP), wrapped to talk f64 to the plant.
pub struct DriveF32(pub SensorlessDrive<f32>);

fn f32_of(x: Abc<f64>) -> Abc<f32> {
    Abc::new(x.a as f32, x.b as f32, x.c as f32)
}

fn ab64(x: Ab<f32>) -> Ab<f64> {
    Ab::new(x.alpha as f64, x.beta as f64)
}

fn dq64(x: Dq<f32>) -> Dq<f64> {
    Dq::new(x.d as f64, x.q as f64)
}

impl Controller for DriveF32 {
    fn align(&mut self, theta0: f64) {
        self.0.align(theta0 as f32);
    }

    fn ready(&self) -> bool {
        self.0.ready()
    }

    fn startup_status(&self) -> StartupStatus {
        self.0.startup_status()
    }

    fn gain_calibration_status(&self) -> Option<GainCalibrationStatus> {
        Some(self.0.gain_calibration_status())
    }

    fn brake_released(&mut self) {
        self.0.arm_release_hold();
    }

    #[inline]
    fn step(&mut self, m: &Measurements) -> Actuation {
        let o = self
            .0
            .step(f32_of(m.i_abc), m.vdc as f32, m.speed_ref_mech as f32);
        let e = o.estimate;
        let d = e.diagnostics;
        Actuation {
            duty: Abc::new(o.duty.a as f64, o.duty.b as f64, o.duty.c as f64),
            gates_enabled: o.gates_enabled,
            tripped: o.tripped,
            input_fault: o.input_fault,
            flags: o.flags,
            i_ab_used: Some(ab64(o.i_ab)),
            v_ref_ab: ab64(o.v_ref_ab),
            i_dq: dq64(o.i_dq),
            i_dq_ref: dq64(o.i_dq_ref),
            estimate: Estimate {
                theta: e.theta as f64,
                omega: e.omega as f64,
                omega_control: e.omega_control as f64,
                diagnostics: Diagnostics {
                    lambda1: ab64(d.lambda1),
                    disturbance: ab64(d.disturbance),
                    lambda2: ab64(d.lambda2),
                    lambda_r: ab64(d.lambda_r),
                    theta_direct: d.theta_direct as f64,
                    mode: d.mode,
                    flag_limit: d.flag_limit,
                    limiter_clamping: d.limiter_clamping,
                    tracker_hold: d.tracker_hold,
                    rs_hat: d.rs_hat as f64,
                    flux_linkage_hat: d.flux_linkage_hat as f64,
                    input_fault: d.input_fault,
                    lock: d.lock,
                },
            },
        }
    }

    fn handle(&mut self, event: ControlEvent) {
        match event {
            ControlEvent::DisturbanceFeedback(on) => {
                RotorAngleEstimator::set_disturbance_feedback(self.0.estimator_mut(), on)
            }
        }
    }

    fn name(&self) -> &str {
        "fado-f32"
    }
}

impl SimConfig {
    /// The drive of this configuration in single precision: every parameter rounded to f32.
    pub fn build_drive_f32(&self) -> Result<DriveF32, SimConfigError> {
        let c = self.drive_config();
        // A flux map is rounded to f32 and interned (`crate::model_magnetics`).
        let magnetics = crate::model_magnetics::to_f32(&c.machine.magnetics).ok_or_else(|| {
            SimConfigError::new(
                "model",
                "the flux map does not stay strictly monotonic rounded to f32",
            )
        })?;
        let dc = DriveConfig::<f32> {
            ts: c.ts as f32,
            machine: c.machine.cast().with_magnetics(magnetics),
            tuning: c.tuning.cast(),
        };
        dc.validate()
            .map_err(|e| self.core_error("controller", e))?;
        SensorlessDrive::new(dc, self.estimator.cast())
            .map(DriveF32)
            .map_err(|e| self.core_error("estimator", e))
    }
}
