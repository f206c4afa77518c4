//! The sensorless drive of `fado-core` (Fig. 5) as a [`Controller`] of the closed loop.

use fado_core::control::SensorlessDrive;
use fado_core::{Ab, Abc, Diagnostics, Dq, Estimate, EstimatorConfig, RotorAngleEstimator};

use crate::controller::{Actuation, ControlEvent, Controller, Measurements};

/// Estimators whose k_df feedback can be switched at run time (Fig. 9).
pub trait DisturbanceFeedbackSwitch {
    /// Enables or disables k_df.
    fn set_disturbance_feedback(&mut self, enabled: bool);
}

impl<T: fado_core::Real> DisturbanceFeedbackSwitch for fado_core::SensorlessEstimator<T> {
    fn set_disturbance_feedback(&mut self, enabled: bool) {
        self.set_disturbance_feedback_enabled(enabled);
    }
}

/// The baselines have no k_df: the Fig. 9 event does nothing to them.
macro_rules! no_disturbance_feedback {
    ($($t:ty),*) => {$(
        impl DisturbanceFeedbackSwitch for $t {
            fn set_disturbance_feedback(&mut self, _enabled: bool) {}
        }
    )*};
}
no_disturbance_feedback!(
    fado_core::LpfIntegratorEstimator<f64>,
    fado_core::OrtegaEstimator<f64>,
    fado_core::EmfObserverEstimator<f64>
);

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
                self.estimator_mut().set_disturbance_feedback(on)
            }
        }
    }

    fn name(&self) -> &str {
        self.estimator().name()
    }
}

use fado_core::control::{DeadTimeMethod, DriveConfig, VoltageLimit};

use crate::config::{DeadTimeMethodSetting, SimConfig, VoltageLimitSetting, core_error};
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
            offset_calibration_samples: c.offset_calibration_samples,
            stuck_sensor_band: c.stuck_sensor_band,
            stuck_sensor_min_reference: c.stuck_sensor_min_reference,
            stuck_sensor_samples: c.stuck_sensor_samples,
            current_error_limit: c.current_error_limit,
            current_error_samples: c.current_error_samples,
            dc_link_min_voltage: c.dc_link_min_voltage,
            input_fault_trip_samples: c.input_fault_trip_samples,
        }
    }

    /// The drive around a baseline estimator (`[estimator] kind`), f64.
    pub fn build_baseline_drive<E>(
        &self,
        estimator: E,
    ) -> Result<SensorlessDrive<f64, E>, SimConfigError>
    where
        E: RotorAngleEstimator<f64>,
    {
        let drive_cfg = self.drive_config();
        SensorlessDrive::with_estimator(drive_cfg, estimator)
            .map_err(|e| core_error("controller", e))
    }

    /// The compensated-LPF baseline of this configuration.
    pub fn lpf_estimator(&self) -> Result<fado_core::LpfIntegratorEstimator<f64>, SimConfigError> {
        let e = self.estimator_config();
        let s = &self.estimator;
        fado_core::LpfIntegratorEstimator::new(fado_core::baselines::LpfIntegratorConfig {
            ts: e.ts,
            rs_hat: e.rs_hat,
            lq_hat: e.lq_hat,
            flux_linkage_hat: e.flux_linkage_hat,
            cutoff_hz: s.lpf_cutoff_hz,
            compensation_floor_hz: s.lpf_compensation_floor_hz,
            t2s1_bandwidth_hz: e.t2s1_bandwidth_hz,
            t2s2_bandwidth_hz: e.t2s2_bandwidth_hz,
            tracker_damping: e.tracker_damping,
            bandwidth_definition: e.bandwidth_definition,
            tracker_hold_ratio: e.tracker_hold_ratio,
            average_current: e.average_current,
            initial_angle: e.initial_angle,
        })
        .map_err(|e| core_error("estimator", e))
    }

    /// The Ortega–Praly baseline of this configuration.
    pub fn ortega_estimator(&self) -> Result<fado_core::OrtegaEstimator<f64>, SimConfigError> {
        let e = self.estimator_config();
        let s = &self.estimator;
        fado_core::OrtegaEstimator::new(fado_core::baselines::OrtegaConfig {
            ts: e.ts,
            rs_hat: e.rs_hat,
            lq_hat: e.lq_hat,
            flux_linkage_hat: e.flux_linkage_hat,
            observer_bandwidth: s.ortega_observer_bandwidth,
            observer_speed_ratio: s.ortega_observer_speed_ratio,
            observer_bandwidth_min: s.ortega_observer_bandwidth_min,
            flux_adaptation_ratio: s.ortega_flux_adaptation_ratio,
            t2s1_bandwidth_hz: e.t2s1_bandwidth_hz,
            t2s2_bandwidth_hz: e.t2s2_bandwidth_hz,
            tracker_damping: e.tracker_damping,
            bandwidth_definition: e.bandwidth_definition,
            tracker_hold_ratio: e.tracker_hold_ratio,
            average_current: e.average_current,
            initial_angle: e.initial_angle,
        })
        .map_err(|e| core_error("estimator", e))
    }

    /// The extended-EMF baseline of this configuration.
    pub fn emf_estimator(&self) -> Result<fado_core::EmfObserverEstimator<f64>, SimConfigError> {
        let e = self.estimator_config();
        let s = &self.estimator;
        fado_core::EmfObserverEstimator::new(fado_core::baselines::EmfObserverConfig {
            ts: e.ts,
            rs_hat: e.rs_hat,
            lq_hat: e.lq_hat,
            flux_linkage_hat: e.flux_linkage_hat,
            emf_bandwidth_hz: s.emf_bandwidth_hz,
            speed_floor_hz: s.emf_speed_floor_hz,
            t2s1_bandwidth_hz: e.t2s1_bandwidth_hz,
            t2s2_bandwidth_hz: e.t2s2_bandwidth_hz,
            tracker_damping: e.tracker_damping,
            bandwidth_definition: e.bandwidth_definition,
            tracker_hold_ratio: e.tracker_hold_ratio,
            average_current: e.average_current,
            initial_angle: e.initial_angle,
        })
        .map_err(|e| core_error("estimator", e))
    }

    /// The sensorless drive of this configuration (aligned by the simulation at start).
    pub fn build_drive(&self) -> Result<SensorlessDrive<f64>, SimConfigError> {
        let drive_cfg = self.drive_config();
        drive_cfg
            .validate()
            .map_err(|e| core_error("controller", e))?;
        SensorlessDrive::new(drive_cfg, self.estimator_config())
            .map_err(|e| core_error("estimator", e))
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
                },
            },
        }
    }

    fn handle(&mut self, event: ControlEvent) {
        match event {
            ControlEvent::DisturbanceFeedback(on) => {
                self.0.estimator_mut().set_disturbance_feedback(on)
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
        let f = |x: f64| x as f32;
        let dc = DriveConfig::<f32> {
            ts: f(c.ts),
            pole_pairs: f(c.pole_pairs),
            rs_hat: f(c.rs_hat),
            ld_hat: f(c.ld_hat),
            lq_hat: f(c.lq_hat),
            flux_linkage_hat: f(c.flux_linkage_hat),
            inertia_hat: f(c.inertia_hat),
            current_bandwidth_hz: f(c.current_bandwidth_hz),
            speed_bandwidth_hz: f(c.speed_bandwidth_hz),
            speed_zero_ratio: f(c.speed_zero_ratio),
            i_max: f(c.i_max),
            i_min: f(c.i_min),
            dead_time: f(c.dead_time),
            switching_frequency: f(c.switching_frequency),
            dead_time_threshold_voltage: f(c.dead_time_threshold_voltage),
            dead_time_current_band: f(c.dead_time_current_band),
            dead_time_compensation: c.dead_time_compensation,
            dead_time_method: c.dead_time_method,
            delay_compensation_factor: f(c.delay_compensation_factor),
            trip_current: f(c.trip_current),
            decoupling: c.decoupling,
            voltage_limit: c.voltage_limit,
            max_modulation: f(c.max_modulation),
            current_anti_windup_ratio: f(c.current_anti_windup_ratio),
            speed_anti_windup_ratio: f(c.speed_anti_windup_ratio),
            offset_calibration_samples: c.offset_calibration_samples,
            stuck_sensor_band: f(c.stuck_sensor_band),
            stuck_sensor_min_reference: f(c.stuck_sensor_min_reference),
            stuck_sensor_samples: c.stuck_sensor_samples,
            current_error_limit: f(c.current_error_limit),
            current_error_samples: c.current_error_samples,
            dc_link_min_voltage: f(c.dc_link_min_voltage),
            input_fault_trip_samples: c.input_fault_trip_samples,
        };
        let e = self.estimator_config();
        let ec = EstimatorConfig::<f32> {
            ts: f(e.ts),
            rs_hat: f(e.rs_hat),
            lq_hat: f(e.lq_hat),
            flux_linkage_hat: f(e.flux_linkage_hat),
            k_df: f(e.k_df),
            k_df_ramp_time: f(e.k_df_ramp_time),
            k_af: f(e.k_af),
            limiter_radius_ratio: f(e.limiter_radius_ratio),
            mode_threshold_hz: f(e.mode_threshold_hz),
            mode_hysteresis_hz: f(e.mode_hysteresis_hz),
            t2s1_bandwidth_hz: f(e.t2s1_bandwidth_hz),
            t2s2_bandwidth_hz: f(e.t2s2_bandwidth_hz),
            tracker_damping: f(e.tracker_damping),
            bandwidth_definition: e.bandwidth_definition,
            tracker_hold_ratio: f(e.tracker_hold_ratio),
            average_current: e.average_current,
            initial_angle: f(e.initial_angle),
            observer_on_rotor_flux: e.observer_on_rotor_flux,
            rs_adaptation: e.rs_adaptation,
            rs_adaptation_rate: f(e.rs_adaptation_rate),
            rs_adaptation_excitation_floor: f(e.rs_adaptation_excitation_floor),
            rs_adaptation_min_ratio: f(e.rs_adaptation_min_ratio),
            rs_adaptation_max_ratio: f(e.rs_adaptation_max_ratio),
            flux_linkage_adaptation_rate: f(e.flux_linkage_adaptation_rate),
            limiter_recentring: e.limiter_recentring,
        };
        dc.validate().map_err(|e| core_error("controller", e))?;
        SensorlessDrive::new(dc, ec)
            .map(DriveF32)
            .map_err(|e| core_error("estimator", e))
    }
}
