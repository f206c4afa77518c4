//! The whole simulation as one TOML document: plant sections (`[motor]`, `[inverter]`,
//! `[current_sensor]`, `[dc_link_sensor]`, `[load]`), the speed reference
//! (`[speed_reference]`), the drive (`[controller]`, `[estimator]`), the estimator's view of
//! the plant (`[mismatch]`), injected faults (`[faults]`, see [`crate::faults`]), and run
//! settings (`[simulation]`).
//!
//! A file overrides a base configuration (a scenario's) key by key: tables merge, values and
//! arrays replace. Unknown keys are errors naming the key (`inverter.dead_tme`), and so are
//! impossible values (`motor.rs: must be > 0`). The estimator's model parameters are never
//! given directly: they are the plant's times the `[mismatch]` ratios, so "matched" stays
//! matched when the motor changes.

use fado_core::EstimatorConfig;
use fado_core::tracker::BandwidthDefinition;
use serde::{Deserialize, Serialize};

use crate::error::{SimConfigError, check};
use crate::faults::FaultParams;
use crate::inverter::InverterParams;
use crate::load::LoadParams;
use crate::motor::MotorParams;
use crate::profile::Profile;
use crate::sensors::{CurrentSensorParams, DcLinkSensorParams};
use crate::sim::PlantParams;
use crate::source::SourceLocation;

/// Run settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimulationSettings {
    /// Simulated time in s. Default 5 s.
    pub duration: f64,
    /// Keep one sample in this many in `traces.csv`. Default 10 (1 kHz).
    pub decimation: u32,
    /// True initial electrical rotor angle in rad. Default 0.3 \[A\].
    pub initial_angle: f64,
    /// Error of the start-up alignment (the drive starts at θ0 + this), rad. Default 0.
    pub align_error: f64,
    /// Metrics are evaluated from this time on, s (start-up excluded). Default 0.
    pub eval_start: f64,
    /// "Near zero speed" means |true speed| below this, r/min. Default 30 r/min (2 Hz
    /// electrical: just above the 1.5 Hz mode threshold) \[A\].
    pub zero_speed_band_rpm: f64,
    /// Windows `[t_off, t_on]` in s during which the k_df feedback is switched off (Fig. 9).
    pub disturbance_feedback_off: Vec<[f64; 2]>,
}

impl Default for SimulationSettings {
    fn default() -> Self {
        Self {
            duration: 5.0,
            decimation: 10,
            initial_angle: 0.3,
            align_error: 0.0,
            eval_start: 0.0,
            zero_speed_band_rpm: 30.0,
            disturbance_feedback_off: Vec::new(),
        }
    }
}

impl SimulationSettings {
    fn validate(&self) -> Result<(), SimConfigError> {
        check::in_range("duration", self.duration, 0.0, 1e5)?;
        if self.decimation == 0 {
            return Err(SimConfigError::new("decimation", "must be ≥ 1"));
        }
        check::finite("initial_angle", self.initial_angle)?;
        check::finite("align_error", self.align_error)?;
        check::non_negative("eval_start", self.eval_start)?;
        check::positive("zero_speed_band_rpm", self.zero_speed_band_rpm)?;
        for (k, w) in self.disturbance_feedback_off.iter().enumerate() {
            if !(w[0].is_finite() && w[1].is_finite() && w[0] <= w[1]) {
                return Err(SimConfigError::new(
                    format!("disturbance_feedback_off[{k}]"),
                    "must be [t_off, t_on] with t_off ≤ t_on",
                ));
            }
        }
        Ok(())
    }
}

/// Dead-time compensation method (mirrors `fado_core::control::DeadTimeMethod`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DeadTimeMethodSetting {
    /// V̂·sat(i*/Ic) trapezoid of the reference current (SPEC §5).
    #[default]
    Trapezoidal,
    /// V̂·sign(i) of the measured current.
    Sign,
}

/// Voltage limit (mirrors `fado_core::control::VoltageLimit`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VoltageLimitSetting {
    /// The inverter hexagon (SVPWM).
    #[default]
    Hexagon,
    /// Its inscribed circle.
    InscribedCircle,
}

/// Scalar type the drive runs in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Precision {
    /// f64 (analysis).
    #[default]
    F64,
    /// f32, as on the paper's TMS320F28335 (single-precision FPU).
    F32,
}

/// The drive's own settings (the model estimates come from `[mismatch]`). Defaults as in
/// `fado_core::control::DriveConfig`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControllerSettings {
    /// Scalar type of the drive (estimator and control). Default f64.
    pub precision: Precision,
    /// Current-loop bandwidth, Hz. Default 250 Hz (paper §V).
    pub current_bandwidth_hz: f64,
    /// Speed-loop bandwidth, Hz. Default 5 Hz (paper §V).
    pub speed_bandwidth_hz: f64,
    /// Speed PI zero ratio (Ki = Kp·ωsc/ratio). Default 5 (SPEC §6).
    pub speed_zero_ratio: f64,
    /// Current limit I_max, A. Default 40 A (SPEC §6).
    pub i_max: f64,
    /// I_min of the injection (23), A; 0 disables it. Default 4 A (paper §V).
    pub i_min: f64,
    /// Dead-time compensation on. Default true.
    pub dead_time_compensation: bool,
    /// Compensation method. Default trapezoidal (SPEC §5).
    pub dead_time_method: DeadTimeMethodSetting,
    /// Voltage angle advance in samples. Default 1.5 (SPEC §5).
    pub delay_compensation_factor: f64,
    /// Over-current trip, A. Default 60 A.
    pub trip_current: f64,
    /// Decoupling and back-EMF feed-forward. Default true.
    pub decoupling: bool,
    /// Realisable voltage set. Default hexagon.
    pub voltage_limit: VoltageLimitSetting,
    /// Usable fraction of the voltage limit. Default 1.
    pub max_modulation: f64,
    /// Current PI back-calculation gain (×Ki/Kp). Default 1.
    pub current_anti_windup_ratio: f64,
    /// Speed PI back-calculation gain (×Ki/Kp). Default 5.
    pub speed_anti_windup_ratio: f64,
    /// Current-sensor offset calibration at start-up, samples with the gates off (0 = none).
    /// Default 1000 (100 ms) as `fado_core::control::DriveConfig` \[A\].
    pub offset_calibration_samples: u32,
    /// Stuck current-sensor detection band, A. Default 0.25 A as `DriveConfig`.
    pub stuck_sensor_band: f64,
    /// Stuck current-sensor detection: minimum reference in the phase, A. Default 2 A.
    pub stuck_sensor_min_reference: f64,
    /// Stuck current-sensor detection: samples in a row (0 = off). Default 5.
    pub stuck_sensor_samples: u32,
    /// Current-error monitor limit |i* − i|, A. Default 5 A.
    pub current_error_limit: f64,
    /// Current-error monitor: samples in a row (0 = off). Default 20.
    pub current_error_samples: u32,
    /// DC-link under-voltage warning level, V. Default 200 V.
    pub dc_link_min_voltage: f64,
    /// Rejected samples in a row that trip the drive (0 = never). Default 100.
    pub input_fault_trip_samples: u32,
}

impl Default for ControllerSettings {
    fn default() -> Self {
        let d = fado_core::control::DriveConfig::<f64>::default();
        Self {
            precision: Precision::F64,
            current_bandwidth_hz: 250.0,
            speed_bandwidth_hz: 5.0,
            speed_zero_ratio: 5.0,
            i_max: 40.0,
            i_min: 4.0,
            dead_time_compensation: true,
            dead_time_method: DeadTimeMethodSetting::Trapezoidal,
            delay_compensation_factor: 1.5,
            trip_current: 60.0,
            decoupling: true,
            voltage_limit: VoltageLimitSetting::Hexagon,
            max_modulation: 1.0,
            current_anti_windup_ratio: 1.0,
            speed_anti_windup_ratio: 5.0,
            offset_calibration_samples: 1000,
            stuck_sensor_band: d.stuck_sensor_band,
            stuck_sensor_min_reference: d.stuck_sensor_min_reference,
            stuck_sensor_samples: d.stuck_sensor_samples,
            current_error_limit: d.current_error_limit,
            current_error_samples: d.current_error_samples,
            dc_link_min_voltage: d.dc_link_min_voltage,
            input_fault_trip_samples: d.input_fault_trip_samples,
        }
    }
}

/// Tracker bandwidth meaning (mirrors `fado_core::tracker::BandwidthDefinition`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BandwidthSetting {
    /// −3 dB frequency of the closed loop (SPEC §3).
    #[default]
    Minus3Db,
    /// Natural frequency ωn.
    NaturalFrequency,
}

/// Which rotor-angle estimator the drive runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EstimatorKind {
    /// The paper's estimator (`fado_core::SensorlessEstimator`).
    #[default]
    Fado,
    /// Baseline: compensated low-pass integrator (`fado_core::LpfIntegratorEstimator`).
    LpfIntegrator,
    /// Baseline: Ortega–Praly nonlinear flux observer (`fado_core::OrtegaEstimator`).
    Ortega,
    /// Baseline: extended-EMF observer (`fado_core::EmfObserverEstimator`).
    EmfObserver,
}

/// The estimator's own settings (the model estimates come from `[mismatch]`). Defaults as in
/// `fado_core::EstimatorConfig` (paper §V, SPEC §1–3) and, for the baselines, in
/// `fado_core::baselines`. The trackers' settings apply to every kind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EstimatorSettings {
    /// Which estimator. Default fado. The baselines run with an f64 drive only.
    pub kind: EstimatorKind,
    /// k_df, s⁻¹ (Fig. 3). Default 0.5.
    pub k_df: f64,
    /// k_df ramp-in time, s (0 = abrupt). Default 0.
    pub k_df_ramp_time: f64,
    /// k_af, s⁻¹ (Fig. 6). Default 2π·100.
    pub k_af: f64,
    /// Limiter radius / λ̂f. Default 1.15.
    pub limiter_radius_ratio: f64,
    /// Mode threshold, Hz electrical. Default 1.5.
    pub mode_threshold_hz: f64,
    /// Mode hysteresis half-band, Hz. Default 0.2.
    pub mode_hysteresis_hz: f64,
    /// T2S-1 bandwidth, Hz. Default 60.
    pub t2s1_bandwidth_hz: f64,
    /// T2S-2 bandwidth, Hz. Default 35.
    pub t2s2_bandwidth_hz: f64,
    /// Tracker damping. Default 1/√2.
    pub tracker_damping: f64,
    /// Bandwidth definition. Default −3 dB.
    pub bandwidth_definition: BandwidthSetting,
    /// Tracker hold below this |λ̂r|/λ̂f. Default 0.2.
    pub tracker_hold_ratio: f64,
    /// Interval-average current in the resistive drop. Default true.
    pub average_current: bool,
    /// Disturbance observer on λ1 − L̂q·i (true, our improvement) or on λ1 (false, the
    /// paper's Fig. 5). Default as `EstimatorConfig::observer_on_rotor_flux`.
    pub observer_on_rotor_flux: bool,
    /// Online R̂s adaptation (our extension; false = the paper). Default as
    /// `EstimatorConfig::rs_adaptation`.
    pub rs_adaptation: bool,
    /// R̂s adaptation rate γ, s⁻¹. Default as `EstimatorConfig::rs_adaptation_rate`.
    pub rs_adaptation_rate: f64,
    /// R̂s adaptation excitation floor χ0. Default as `EstimatorConfig`.
    pub rs_adaptation_excitation_floor: f64,
    /// Lower bound of the adapted R̂s / configured R̂s. Default as `EstimatorConfig`.
    pub rs_adaptation_min_ratio: f64,
    /// Upper bound of the adapted R̂s / configured R̂s. Default as `EstimatorConfig`.
    pub rs_adaptation_max_ratio: f64,
    /// λ̂f learning rate where R̂s is unobservable, s⁻¹ (0 = fixed λ̂f). Default as
    /// `EstimatorConfig::flux_linkage_adaptation_rate`.
    pub flux_linkage_adaptation_rate: f64,
    /// In limiter mode, re-centre the common mode of λ1 and D̂ (true, ours) or not (false,
    /// the paper). Default as `EstimatorConfig::limiter_recentring`.
    pub limiter_recentring: bool,
    /// LPF baseline: cut-off of 1/(s + ωc), Hz. Default as `LpfIntegratorConfig`.
    pub lpf_cutoff_hz: f64,
    /// LPF baseline: speed below which its gain/phase compensation is frozen, Hz.
    pub lpf_compensation_floor_hz: f64,
    /// Ortega baseline: observer gain, s⁻¹ (when not scheduled on speed).
    pub ortega_observer_bandwidth: f64,
    /// Ortega baseline: gain scheduled as this × |ω̂| (0 = fixed gain).
    pub ortega_observer_speed_ratio: f64,
    /// Ortega baseline: lower bound of the scheduled gain, s⁻¹.
    pub ortega_observer_bandwidth_min: f64,
    /// Ortega baseline: λ̂f adaptation gain ratio (0 = off).
    pub ortega_flux_adaptation_ratio: f64,
    /// EMF baseline: observer bandwidth, Hz.
    pub emf_bandwidth_hz: f64,
    /// EMF baseline: speed below which the angle is held, Hz.
    pub emf_speed_floor_hz: f64,
}

impl Default for EstimatorSettings {
    fn default() -> Self {
        let d = EstimatorConfig::<f64>::default();
        let lpf = fado_core::baselines::LpfIntegratorConfig::<f64>::default();
        let ortega = fado_core::baselines::OrtegaConfig::<f64>::default();
        let emf = fado_core::baselines::EmfObserverConfig::<f64>::default();
        Self {
            k_df: d.k_df,
            k_df_ramp_time: d.k_df_ramp_time,
            k_af: d.k_af,
            limiter_radius_ratio: d.limiter_radius_ratio,
            mode_threshold_hz: d.mode_threshold_hz,
            mode_hysteresis_hz: d.mode_hysteresis_hz,
            t2s1_bandwidth_hz: d.t2s1_bandwidth_hz,
            t2s2_bandwidth_hz: d.t2s2_bandwidth_hz,
            tracker_damping: d.tracker_damping,
            bandwidth_definition: match d.bandwidth_definition {
                BandwidthDefinition::Minus3Db => BandwidthSetting::Minus3Db,
                BandwidthDefinition::NaturalFrequency => BandwidthSetting::NaturalFrequency,
            },
            tracker_hold_ratio: d.tracker_hold_ratio,
            average_current: d.average_current,
            observer_on_rotor_flux: d.observer_on_rotor_flux,
            rs_adaptation: d.rs_adaptation,
            rs_adaptation_rate: d.rs_adaptation_rate,
            rs_adaptation_excitation_floor: d.rs_adaptation_excitation_floor,
            rs_adaptation_min_ratio: d.rs_adaptation_min_ratio,
            rs_adaptation_max_ratio: d.rs_adaptation_max_ratio,
            flux_linkage_adaptation_rate: d.flux_linkage_adaptation_rate,
            limiter_recentring: d.limiter_recentring,
            kind: EstimatorKind::Fado,
            lpf_cutoff_hz: lpf.cutoff_hz,
            lpf_compensation_floor_hz: lpf.compensation_floor_hz,
            ortega_observer_bandwidth: ortega.observer_bandwidth,
            ortega_observer_speed_ratio: ortega.observer_speed_ratio,
            ortega_observer_bandwidth_min: ortega.observer_bandwidth_min,
            ortega_flux_adaptation_ratio: ortega.flux_adaptation_ratio,
            emf_bandwidth_hz: emf.emf_bandwidth_hz,
            emf_speed_floor_hz: emf.speed_floor_hz,
        }
    }
}

/// The drive's model of the plant as ratios to the true values (1 = matched). The robustness
/// sweep of SPEC §7 varies these.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Mismatch {
    /// R̂s / (Rs + r_on). Default 1.
    pub rs_ratio: f64,
    /// L̂d / Ld. Default 1.
    pub ld_ratio: f64,
    /// L̂q / Lq. Default 1.
    pub lq_ratio: f64,
    /// λ̂f / λf. Default 1.
    pub flux_linkage_ratio: f64,
    /// Ĵ / J. Default 1.
    pub inertia_ratio: f64,
    /// T̂d / Td of the dead-time compensation. Default 1.
    pub dead_time_ratio: f64,
    /// V̂_th / V_th of the dead-time compensation. Default 1.
    pub threshold_voltage_ratio: f64,
    /// Îc / Ic of the dead-time compensation. Default 1.
    pub current_band_ratio: f64,
}

impl Default for Mismatch {
    fn default() -> Self {
        Self {
            rs_ratio: 1.0,
            ld_ratio: 1.0,
            lq_ratio: 1.0,
            flux_linkage_ratio: 1.0,
            inertia_ratio: 1.0,
            dead_time_ratio: 1.0,
            threshold_voltage_ratio: 1.0,
            current_band_ratio: 1.0,
        }
    }
}

impl Mismatch {
    fn validate(&self) -> Result<(), SimConfigError> {
        for (k, v) in [
            ("rs_ratio", self.rs_ratio),
            ("ld_ratio", self.ld_ratio),
            ("lq_ratio", self.lq_ratio),
            ("flux_linkage_ratio", self.flux_linkage_ratio),
            ("inertia_ratio", self.inertia_ratio),
            ("current_band_ratio", self.current_band_ratio),
        ] {
            check::positive(k, v)?;
        }
        check::non_negative("dead_time_ratio", self.dead_time_ratio)?;
        check::non_negative("threshold_voltage_ratio", self.threshold_voltage_ratio)?;
        Ok(())
    }
}

/// The complete, serialisable simulation configuration.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimConfig {
    /// Run settings.
    pub simulation: SimulationSettings,
    /// Speed reference in r/min (mechanical).
    pub speed_reference: Profile,
    /// The PMSM.
    pub motor: MotorParams,
    /// Inverter and DC link.
    pub inverter: InverterParams,
    /// Phase-current sensors.
    pub current_sensor: CurrentSensorParams,
    /// DC-link sensor.
    pub dc_link_sensor: DcLinkSensorParams,
    /// Load machine.
    pub load: LoadParams,
    /// Drive settings.
    pub controller: ControllerSettings,
    /// Estimator settings.
    pub estimator: EstimatorSettings,
    /// The drive's model of the plant.
    pub mismatch: Mismatch,
    /// Injected faults (`crate::faults`). Default none.
    pub faults: FaultParams,
}

impl Default for Profile {
    fn default() -> Self {
        Profile::constant(0.0)
    }
}

impl SimConfig {
    /// The plant records.
    pub fn plant(&self) -> PlantParams {
        PlantParams {
            motor: self.motor,
            inverter: self.inverter.clone(),
            current_sensor: self.current_sensor.clone(),
            dc_link_sensor: self.dc_link_sensor.clone(),
            load: self.load.clone(),
            faults: self.faults.clone(),
        }
    }

    /// Checks every section, and the estimator and drive configurations derived from it; the
    /// error names the key (`section.field`).
    pub fn validate(&self) -> Result<(), SimConfigError> {
        self.simulation
            .validate()
            .map_err(|e| e.in_section("simulation"))?;
        self.speed_reference
            .validate()
            .map_err(|e| e.in_section("speed_reference"))?;
        self.plant().validate()?;
        let rows = self.simulation.duration
            / self.inverter.sample_period()
            / self.simulation.decimation as f64;
        if rows > 2e7 {
            return Err(SimConfigError::new(
                "simulation.decimation",
                format!("the trace would hold {rows:.3e} rows (limit 2e7): raise it"),
            ));
        }
        self.mismatch
            .validate()
            .map_err(|e| e.in_section("mismatch"))?;
        self.estimator_config()
            .validate()
            .map_err(|e| core_error("estimator", e))?;
        // Every key is checked whichever estimator runs: NaN in an unused key is still an
        // error in the file.
        self.lpf_estimator()?;
        self.ortega_estimator()?;
        self.emf_estimator()?;
        self.drive_config()
            .validate()
            .map_err(|e| core_error("controller", e))?;
        Ok(())
    }

    /// The estimator configuration: settings of `[estimator]`, model from the plant and
    /// `[mismatch]`, sampling period from the inverter.
    pub fn estimator_config(&self) -> EstimatorConfig<f64> {
        let e = &self.estimator;
        let m = &self.mismatch;
        EstimatorConfig {
            ts: self.inverter.sample_period(),
            rs_hat: (self.motor.rs + self.inverter.on_resistance) * m.rs_ratio,
            lq_hat: self.motor.lq * m.lq_ratio,
            flux_linkage_hat: self.motor.flux_linkage * m.flux_linkage_ratio,
            k_df: e.k_df,
            k_df_ramp_time: e.k_df_ramp_time,
            k_af: e.k_af,
            limiter_radius_ratio: e.limiter_radius_ratio,
            mode_threshold_hz: e.mode_threshold_hz,
            mode_hysteresis_hz: e.mode_hysteresis_hz,
            t2s1_bandwidth_hz: e.t2s1_bandwidth_hz,
            t2s2_bandwidth_hz: e.t2s2_bandwidth_hz,
            tracker_damping: e.tracker_damping,
            bandwidth_definition: match e.bandwidth_definition {
                BandwidthSetting::Minus3Db => BandwidthDefinition::Minus3Db,
                BandwidthSetting::NaturalFrequency => BandwidthDefinition::NaturalFrequency,
            },
            tracker_hold_ratio: e.tracker_hold_ratio,
            average_current: e.average_current,
            observer_on_rotor_flux: e.observer_on_rotor_flux,
            rs_adaptation: e.rs_adaptation,
            rs_adaptation_rate: e.rs_adaptation_rate,
            rs_adaptation_excitation_floor: e.rs_adaptation_excitation_floor,
            rs_adaptation_min_ratio: e.rs_adaptation_min_ratio,
            rs_adaptation_max_ratio: e.rs_adaptation_max_ratio,
            flux_linkage_adaptation_rate: e.flux_linkage_adaptation_rate,
            limiter_recentring: e.limiter_recentring,
            initial_angle: self.simulation.initial_angle + self.simulation.align_error,
        }
    }

    /// This configuration as a TOML document.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("every field of SimConfig is representable in TOML")
    }

    /// Parses a complete or partial TOML document on top of `base`: tables merge, values and
    /// arrays replace. The result is validated. Errors name the key.
    pub fn from_toml_over(base: &SimConfig, text: &str) -> Result<SimConfig, SimConfigError> {
        let user: toml::Table = text.parse().map_err(|e| located(text, e))?;
        // Check the user's document on its own first, so that errors (unknown keys, wrong
        // types) name the key the user wrote and point at it.
        toml::from_str::<SimConfig>(text).map_err(|e| located(text, e))?;
        let mut merged = toml::Table::try_from(base)
            .map_err(|e| SimConfigError::new("<base>", e.to_string()))?;
        merge(&mut merged, user);
        let cfg = SimConfig::deserialize(toml::Value::Table(merged))
            .map_err(|e| key_error(e).located_in(text))?;
        cfg.validate().map_err(|e| e.located_in(text))?;
        Ok(cfg)
    }

    /// Parses a TOML document over the defaults.
    pub fn from_toml(text: &str) -> Result<SimConfig, SimConfigError> {
        Self::from_toml_over(&SimConfig::default(), text)
    }
}

/// A fado-core refusal of the `[section]` block (`estimator` or `controller`, including the
/// baselines' `lpf_`/`ortega_`/`emf_` keys), named by the TOML key the user writes. The
/// model estimates (R̂s, L̂q, λ̂f, …) and the timing are not keys of their own: they are plant
/// keys times the `[mismatch]` ratios, so a refusal of one names the plant key.
pub(crate) fn core_error(section: &str, e: fado_core::ConfigError) -> SimConfigError {
    let derived = match e.field() {
        "ts" | "switching_frequency" => Some("inverter.switching_frequency"),
        "rs_hat" => Some("motor.rs"),
        "ld_hat" => Some("motor.ld"),
        "lq_hat" => Some("motor.lq"),
        "flux_linkage_hat" => Some("motor.flux_linkage"),
        "inertia_hat" => Some("motor.inertia"),
        "pole_pairs" => Some("motor.pole_pairs"),
        "dead_time" => Some("inverter.dead_time"),
        "dead_time_threshold_voltage" => Some("inverter.threshold_voltage"),
        "dead_time_current_band" => Some("inverter.current_band"),
        "initial_angle" => Some("simulation.initial_angle"),
        _ => None,
    };
    if let Some(key) = derived {
        return SimConfigError::new(
            key,
            format!("{e} (the drive's value is derived from `{key}` and [mismatch])"),
        );
    }
    let own = match e.field() {
        "cutoff_hz" => "lpf_cutoff_hz",
        "compensation_floor_hz" => "lpf_compensation_floor_hz",
        "observer_bandwidth" => "ortega_observer_bandwidth",
        "observer_speed_ratio" => "ortega_observer_speed_ratio",
        "observer_bandwidth_min" => "ortega_observer_bandwidth_min",
        "flux_adaptation_ratio" => "ortega_flux_adaptation_ratio",
        "speed_floor_hz" => "emf_speed_floor_hz",
        other => other,
    };
    SimConfigError::new(format!("{section}.{own}"), e.to_string())
}

fn merge(base: &mut toml::Table, over: toml::Table) {
    for (k, v) in over {
        match (base.get_mut(&k), v) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge(b, o),
            (_, v) => {
                base.insert(k, v);
            }
        }
    }
}

/// An error of parsing or deserialising the user's `text`: named by the key at its span (or
/// as `key_error` does), located at the span.
fn located(text: &str, e: toml::de::Error) -> SimConfigError {
    let start = e.span().map(|s| s.start);
    let key = start.and_then(|at| crate::source::key_at(text, at));
    let mut err = match key {
        Some(key) => SimConfigError::new(key, e.message().trim_end().to_owned()),
        None => {
            let mut k = key_error(e.clone());
            k.message = e.message().trim_end().to_owned();
            k
        }
    };
    err.location = start.map(|at| SourceLocation::at(text, at));
    err
}

/// A serde error from a `toml::Value` carries "in `path`"; unknown fields name the field.
fn key_error(e: toml::de::Error) -> SimConfigError {
    let msg = e.to_string();
    let path = msg
        .split("in `")
        .nth(1)
        .and_then(|s| s.split('`').next())
        .unwrap_or("")
        .to_owned();
    let field = msg
        .split("unknown field `")
        .nth(1)
        .and_then(|s| s.split('`').next());
    let key = match (field, path.is_empty()) {
        (Some(f), true) => f.to_owned(),
        (Some(f), false) => format!("{path}.{f}"),
        (None, _) => path,
    };
    let first_line = msg.lines().next().unwrap_or("").to_owned();
    SimConfigError::new(
        if key.is_empty() { "<file>".into() } else { key },
        first_line,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inverter::InverterModel;

    #[test]
    fn defaults_round_trip_through_toml() {
        let cfg = SimConfig::default();
        let text = cfg.to_toml();
        let back = SimConfig::from_toml(&text).unwrap();
        assert_eq!(back, cfg);
    }

    #[test]
    fn partial_file_overrides_only_its_keys() {
        let mut base = SimConfig::default();
        base.load.torque = Profile::constant(7.5);
        base.simulation.duration = 3.0;
        let cfg = SimConfig::from_toml_over(
            &base,
            "[inverter]\nmodel = \"averaged\"\n[mismatch]\nrs_ratio = 1.02\n",
        )
        .unwrap();
        assert_eq!(cfg.inverter.model, InverterModel::Averaged);
        assert_eq!(cfg.inverter.dead_time, 2.5e-6);
        assert_eq!(cfg.load.torque, Profile::constant(7.5));
        assert_eq!(cfg.simulation.duration, 3.0);
        assert!((cfg.estimator_config().rs_hat - 0.327 * 1.02).abs() < 1e-15);
    }

    #[test]
    fn unknown_keys_are_errors_naming_the_key() {
        let e = SimConfig::from_toml("[inverter]\ndead_tme = 1e-6\n").unwrap_err();
        assert_eq!(e.key, "inverter.dead_tme", "{e}");
        let e = SimConfig::from_toml("[motorr]\nrs = 1.0\n").unwrap_err();
        assert_eq!(e.key, "motorr", "{e}");
        let e = SimConfig::from_toml("[load.torque]\npoints = [[0.0, 1.0]]\nx = 1\n").unwrap_err();
        assert_eq!(e.key, "load.torque.x", "{e}");
    }

    #[test]
    fn wrong_types_and_impossible_values_name_the_key() {
        let e = SimConfig::from_toml("[inverter]\nmodel = \"fast\"\n").unwrap_err();
        assert_eq!(e.key, "inverter.model", "{e}");
        let e = SimConfig::from_toml("[motor]\nrs = \"big\"\n").unwrap_err();
        assert_eq!(e.key, "motor.rs", "{e}");
        let e = SimConfig::from_toml("[motor]\nrs = -0.3\n").unwrap_err();
        assert_eq!(e.key, "motor.rs", "{e}");
        let e = SimConfig::from_toml("[estimator]\nt2s1_bandwidth_hz = -60.0\n").unwrap_err();
        assert_eq!(e.key, "estimator.t2s1_bandwidth_hz", "{e}");
        let e = SimConfig::from_toml("[simulation]\ndecimation = 0\n").unwrap_err();
        assert_eq!(e.key, "simulation.decimation", "{e}");
        let e = SimConfig::from_toml("[simulation]\nduration = 50000.0\n").unwrap_err();
        assert_eq!(e.key, "simulation.decimation", "{e}");
        let e = SimConfig::from_toml("[speed_reference]\npoints = [[1.0, 0.0], [0.0, 1.0]]\n")
            .unwrap_err();
        assert_eq!(e.key, "speed_reference.points[1]", "{e}");
        let e = SimConfig::from_toml(
            "[[faults.stuck_current]]\nchannel = \"a\"\nstart = 1.0\nduration = -0.01\n",
        )
        .unwrap_err();
        assert_eq!(e.key, "faults.stuck_current[0].duration", "{e}");
        let e = SimConfig::from_toml("[[faults.non_finite]]\ntime = 1.0\nsignal = \"dc\"\n")
            .unwrap_err();
        // A serde type error: located at the bad value (line 3) rather than named by key.
        assert_eq!(e.location.as_ref().map(|l| l.line), Some(3), "{e}");
        assert!(e.message.contains("`dc`"), "{e}");
        let ok = SimConfig::from_toml(
            "[[faults.non_finite]]\ntime = 1.0\nsignal = \"dc_link\"\n\
             [faults.dc_link_scale]\npoints = [[1.0, 1.0], [1.1, 0.5]]\n",
        )
        .unwrap();
        assert_eq!(ok.faults.non_finite[0].samples, 1);
        assert_eq!(ok, SimConfig::from_toml(&ok.to_toml()).unwrap());
    }
}

#[cfg(test)]
mod located_errors {
    use super::*;

    /// (key, line, column, message) of the error `text` gives.
    fn err(text: &str) -> (String, usize, usize, String) {
        let e = SimConfig::from_toml(text).unwrap_err();
        let loc = e
            .location
            .clone()
            .unwrap_or_else(|| panic!("not located: {e}"));
        (e.key.clone(), loc.line, loc.column, e.to_string())
    }

    #[test]
    fn semantic_errors_name_key_line_and_column() {
        let text = "[simulation]\nduration = 1.0\n\n[motor]\nlq = 2e-3\nrs   = -1\n";
        let (key, line, col, msg) = err(text);
        assert_eq!((key.as_str(), line, col), ("motor.rs", 6, 8));
        assert_eq!(msg, "line 6, column 8: `motor.rs`: must be > 0, got -1");
        let e = SimConfig::from_toml(text)
            .unwrap_err()
            .in_file("config.toml");
        assert_eq!(
            e.to_string(),
            "config.toml:6:8: `motor.rs`: must be > 0, got -1"
        );
        // Estimator and drive checks of fado-core, renamed to their TOML keys.
        let (key, line, col, _) = err("[estimator]\nk_df = 0.5\nt2s1_bandwidth_hz = -60.0\n");
        assert_eq!(
            (key.as_str(), line, col),
            ("estimator.t2s1_bandwidth_hz", 3, 21)
        );
        let (key, line, _, _) = err("[estimator]\nmode_hysteresis_hz = 3.0\n");
        assert_eq!((key.as_str(), line), ("estimator.mode_hysteresis_hz", 2));
        // Array elements and dotted keys.
        let (key, line, col, _) =
            err("[simulation]\ndisturbance_feedback_off = [[0.0, 1.0], [2.0, 1.0]]\n");
        assert_eq!(
            (key.as_str(), line, col),
            ("simulation.disturbance_feedback_off[1]", 2, 41)
        );
        let (key, line, col, _) = err("motor.rs = nan\n");
        assert_eq!((key.as_str(), line, col), ("motor.rs", 1, 12));
    }

    #[test]
    fn type_errors_and_unknown_keys_name_key_line_and_column() {
        let (key, line, col, msg) = err("[motor]\nrs = \"big\"\n");
        assert_eq!((key.as_str(), line, col), ("motor.rs", 2, 6));
        assert!(msg.starts_with("line 2, column 6: `motor.rs`: "), "{msg}");
        let (key, line, col, _) = err("[inverter]\n\ndead_tme = 1e-6\n");
        assert_eq!((key.as_str(), line, col), ("inverter.dead_tme", 3, 1));
        let (key, line, _, msg) = err("[inverter]\nmodel = \"fast\"\n");
        assert_eq!((key.as_str(), line), ("inverter.model", 2));
        assert!(msg.contains("fast"), "{msg}");
        let (key, line, col, _) = err("[motorr]\nrs = 1.0\n");
        assert_eq!((key.as_str(), line, col), ("motorr", 1, 2));
        let (key, line, _, _) = err("[simulation]\ndecimation = 2.5\n");
        assert_eq!((key.as_str(), line), ("simulation.decimation", 2));
    }

    #[test]
    fn syntax_errors_are_located() {
        let (key, line, col, msg) = err("[motor]\nrs = 0.3\nlq = = 2\n");
        assert_eq!((key.as_str(), line), ("<file>", 3));
        assert!(col >= 5, "{msg}");
    }

    #[test]
    fn derived_values_are_named_but_not_located() {
        // rs_hat is motor.rs·mismatch.rs_ratio: nothing in the file to point at.
        let e = SimConfig::from_toml("[estimator]\nk_af = 1e6\n").unwrap_err();
        assert_eq!(e.key, "estimator.k_af");
        assert_eq!(e.location.map(|l| l.line), Some(2));
        let e = SimConfigError::new("estimator.rs_hat", "x").located_in("[motor]\nrs = 1\n");
        assert_eq!(e.location, None);
        assert_eq!(e.to_string(), "`estimator.rs_hat`: x");
    }
}
