//! The whole simulation as one TOML document: plant sections (`[motor]`, `[inverter]`,
//! `[current_sensor]`, `[dc_link_sensor]`, `[load]`), the speed reference
//! (`[speed_reference]`), the drive (`[controller]`, `[estimator]`, `[baselines]`), the
//! drive's model of the motor (`[model]`, by default `[motor]` scaled by `[mismatch]`),
//! injected faults (`[faults]`, see [`crate::faults`]), and run settings (`[simulation]`).
//! `[motor]` and `[model]` are `fado_core::MachineModel`, `[controller]`
//! `fado_core::control::DriveTuning` and `[estimator]` `fado_core::EstimatorTuning`, read
//! directly through their serde derives (one schema).
//!
//! A file overrides a base configuration (a scenario's) key by key: tables merge, values and
//! arrays replace. Unknown keys are errors naming the key (`inverter.dead_tme`), and so are
//! impossible values (`motor.rs: must be > 0`). The estimator's model parameters are never
//! given directly: they are the plant's times the `[mismatch]` ratios, so "matched" stays
//! matched when the motor changes.

use fado_core::control::{DeadTimeMethod, DriveConfig, DriveTuning};
use fado_core::magnetics::Saturation;
use fado_core::{EstimatorConfig, EstimatorTuning, MachineModel};
use serde::{Deserialize, Serialize};

use crate::criteria::Criteria;
use crate::dc_link::DcLinkParams;
use crate::error::{SimConfigError, check};
pub use crate::estimators::EstimatorKind;
use crate::estimators::{check_baseline_keys, default_baselines};
use crate::faults::FaultParams;
use crate::inverter::InverterParams;
use crate::load::LoadParams;
use crate::magnetics_file;
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
    /// "Near zero speed" means |true speed| below this fraction of the rated speed. Default
    /// 0.02 \[A\] (30 r/min of the paper's 1500 r/min: 2 Hz electrical, just above its 1.5 Hz
    /// mode threshold).
    pub zero_speed_band_ratio: f64,
    /// Scalar type of the drive (estimator and control). Default f64.
    pub precision: Precision,
    /// Which rotor-angle estimator the drive runs. Default fado; the baselines run with an
    /// f64 drive only.
    pub estimator: EstimatorKind,
    /// Windows `[t_off, t_on]` in s during which the k_df feedback is switched off (Fig. 9).
    pub disturbance_feedback_off: Vec<[f64; 2]>,
    /// A holding brake holds the rotor from the start until the drive reports ready (its
    /// calibrations over, gates on); the load acts on the brake until then (a hoist, a
    /// vehicle on a slope). Default false.
    pub brake: bool,
}

impl Default for SimulationSettings {
    fn default() -> Self {
        Self {
            duration: 5.0,
            decimation: 10,
            initial_angle: 0.3,
            align_error: 0.0,
            eval_start: 0.0,
            zero_speed_band_ratio: 0.02,
            precision: Precision::F64,
            estimator: EstimatorKind::FADO,
            disturbance_feedback_off: Vec::new(),
            brake: false,
        }
    }
}

impl SimulationSettings {
    fn validate(&self) -> Result<(), SimConfigError> {
        check::in_range("duration", self.duration, 0.0, 1e5)?;
        if self.duration <= 0.0 {
            return Err(SimConfigError::new(
                "duration",
                format!("must be > 0, got {}", self.duration),
            ));
        }
        if self.decimation == 0 {
            return Err(SimConfigError::new("decimation", "must be ≥ 1"));
        }
        check::finite("initial_angle", self.initial_angle)?;
        check::finite("align_error", self.align_error)?;
        check::non_negative("eval_start", self.eval_start)?;
        check::positive("zero_speed_band_ratio", self.zero_speed_band_ratio)?;
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

/// `[inverter_model]`: what the drive's dead-time compensation is told of the inverter, as
/// identified (e.g. by `fado_core::commissioning`) rather than derived from the plant.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InverterModel {
    /// Device threshold voltage V̂_th of the compensation, V (instead of `[inverter]
    /// threshold_voltage` × `[mismatch] threshold_voltage_ratio`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub threshold_voltage: Option<f64>,
}

impl InverterModel {
    fn validate(&self) -> Result<(), SimConfigError> {
        if let Some(v) = self.threshold_voltage {
            check::non_negative("threshold_voltage", v)?;
        }
        Ok(())
    }
}

/// The drive's model of the plant as ratios to the true values (1 = matched). The robustness
/// sweep of docs/guide/first-run.md varies these.
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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimConfig {
    /// Run settings.
    pub simulation: SimulationSettings,
    /// Speed reference in r/min (mechanical).
    pub speed_reference: Profile,
    /// The PMSM (plant): parameters and ratings.
    pub motor: MotorParams,
    /// Inverter and DC link.
    pub inverter: InverterParams,
    /// Phase-current sensors.
    pub current_sensor: CurrentSensorParams,
    /// DC-link sensor.
    pub dc_link_sensor: DcLinkSensorParams,
    /// Load machine.
    pub load: LoadParams,
    /// Drive tuning (`fado_core::control::DriveTuning`).
    pub controller: DriveTuning<f64>,
    /// Estimator tuning (`fado_core::EstimatorTuning`).
    pub estimator: EstimatorTuning<f64>,
    /// Settings of the reference observers, one table per baseline of
    /// [`crate::estimators::ESTIMATORS`] (`[baselines.ortega]`, ...); their machine model is
    /// the drive's `[model]` and their shared settings (trackers, sample bounds) are
    /// `[estimator]`'s.
    pub baselines: toml::Table,
    /// The drive's model of the plant as ratios to the true values.
    pub mismatch: Mismatch,
    /// The drive's model of the motor, key by key (same keys as `[motor]`); a key not given is
    /// the plant's (R̂s: Rs + r_on) times its `[mismatch]` ratio.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<toml::Table>,
    /// The drive's data of the inverter for its dead-time compensation, key by key; a key not
    /// given is `[inverter]`'s times its `[mismatch]` ratio. `fado-sim commission` writes the
    /// identified threshold voltage here.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inverter_model: Option<InverterModel>,
    /// Injected faults (`crate::faults`). Default none.
    pub faults: FaultParams,
    /// The DC link behind the inverter (`crate::dc_link`). Default a stiff source.
    #[serde(skip_serializing_if = "is_default")]
    pub dc_link: DcLinkParams,
    /// The user's pass criteria (`crate::criteria`): all the `custom` scenario judges, and
    /// judged after their own by the others. Default none.
    #[serde(skip_serializing_if = "Criteria::is_empty")]
    pub criteria: Criteria,
    /// The keys the configuration file left out whose values were derived from the motor's
    /// ratings (`crate::derive`), with their rules; not a TOML table.
    #[serde(skip)]
    pub derived: Vec<crate::derive::Derived>,
    /// The plant's saturating magnetics, `[motor.saturation]` (the algebraic model of
    /// [`fado_core::magnetics::Saturation`]) or `[motor] flux_map` (`crate::magnetics_file`);
    /// None: the constant inductances of `[motor]`, whose `ld`, `lq` and `flux_linkage` then
    /// stay the datasheet's (the drive's default model).
    #[serde(skip)]
    pub motor_saturation: Option<Saturation<f64>>,
    /// The plant's flux map, `[motor] flux_map = "FILE.csv"` (see `motor_saturation`).
    #[serde(skip)]
    pub motor_flux_map: Option<crate::magnetics_file::FluxMapFile>,
}

impl Default for SimConfig {
    /// The paper's experiment set-up: its motor ([`MachineModel::paper`]) on docs/method/estimator.md §7–6's
    /// inverter and sensors, standing still.
    fn default() -> Self {
        Self {
            simulation: SimulationSettings::default(),
            speed_reference: Profile::default(),
            motor: MotorParams::paper(),
            inverter: InverterParams::default(),
            current_sensor: CurrentSensorParams::default(),
            dc_link_sensor: DcLinkSensorParams::default(),
            load: LoadParams::default(),
            controller: DriveTuning::default(),
            estimator: EstimatorTuning::default(),
            baselines: default_baselines(),
            mismatch: Mismatch::default(),
            model: None,
            inverter_model: None,
            faults: FaultParams::default(),
            dc_link: DcLinkParams::default(),
            criteria: Criteria::default(),
            derived: Vec::new(),
            motor_saturation: None,
            motor_flux_map: None,
        }
    }
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
            dc_link: self.dc_link.clone(),
            magnetics: magnetics_file::plant_magnetics(
                self.motor_saturation.as_ref(),
                self.motor_flux_map.as_ref(),
            ),
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
        // The machine's cross-checks, with every key involved named (before the single-key
        // refusals of the plant's and the model's validation).
        if let Some((_, key, text)) = self
            .machine_findings()
            .into_iter()
            .find(|(s, ..)| *s == fado_core::machine_checks::Severity::Error)
        {
            return Err(SimConfigError::new(key, text));
        }
        magnetics_file::check_one_model(
            self.motor_saturation.as_ref(),
            self.motor_flux_map.as_ref(),
        )?;
        if let Some(sat) = &self.motor_saturation {
            sat.validate().map_err(|e| {
                SimConfigError::new(format!("motor.saturation.{}", e.field()), e.to_string())
            })?;
        }
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
        self.criteria
            .validate()
            .map_err(|e| e.in_section("criteria"))?;
        if let Some(im) = &self.inverter_model {
            im.validate().map_err(|e| e.in_section("inverter_model"))?;
        }
        crate::motor::validate_motor(&self.motor, self.inverter.dc_voltage).map_err(|e| {
            if e.key == "dc_voltage" {
                SimConfigError::new("inverter.dc_voltage", e.message)
            } else {
                e.in_section("motor")
            }
        })?;
        let ts = self.inverter.sample_period();
        check_time_constant(&self.motor, ts, |k| format!("motor.{k}"))?;
        let model = self.model_checked()?;
        check_time_constant(&model, ts, |k| self.model_key(k))?;
        self.estimator_config()
            .validate()
            .map_err(|e| self.core_error("estimator", e))?;
        // Every key is checked whichever estimator runs: NaN in an unused key is still an
        // error in the file.
        check_baseline_keys(&self.baselines)?;
        for e in crate::estimators::ESTIMATORS {
            (e.check)(self)?;
        }
        self.drive_config()
            .validate()
            .map_err(|e| self.core_error("controller", e))?;
        Ok(())
    }

    /// The drive's model of the motor derived from the plant: `[motor]` (R̂s: Rs + r_on of
    /// the inverter) scaled by `[mismatch]`, DC link from `[inverter]`.
    pub(crate) fn derived_model(&self) -> MachineModel<f64> {
        let (mo, inv, m) = (&self.motor, &self.inverter, &self.mismatch);
        MachineModel {
            rs: (mo.rs + inv.on_resistance) * m.rs_ratio,
            ld: mo.ld * m.ld_ratio,
            lq: mo.lq * m.lq_ratio,
            flux_linkage: mo.flux_linkage * m.flux_linkage_ratio,
            inertia: mo.inertia * m.inertia_ratio,
            dc_voltage: inv.dc_voltage,
            ..*mo
        }
    }

    /// The drive's model: `[model]`'s keys over the derived one, checked; errors name
    /// `model.<key>` for a key the file gives and the plant key it derives from otherwise.
    fn model_checked(&self) -> Result<MachineModel<f64>, SimConfigError> {
        let (derived, table) = crate::model_magnetics::split(self)?;
        let Some(table) = table else {
            return Ok(derived);
        };
        let mut merged = toml::Table::try_from(derived)
            .map_err(|e| SimConfigError::new("model", e.to_string()))?;
        merge(&mut merged, table);
        let mut model = MachineModel::<f64>::deserialize(toml::Value::Table(merged))
            .map_err(|e| key_error(e).in_section("model"))?;
        model.dc_voltage = self.inverter.dc_voltage;
        model.validate().map_err(|e| self.core_error("model", e))?;
        Ok(model.with_magnetics(derived.magnetics))
    }

    /// The key a user wrote for the model's field `k`: `model.k` when `[model]` gives it,
    /// else `mismatch.k_ratio` when that ratio is not 1, else the plant's `motor.k`.
    fn model_key(&self, k: &str) -> String {
        if self.model.as_ref().is_some_and(|t| t.contains_key(k)) {
            return format!("model.{k}");
        }
        let m = &self.mismatch;
        let ratio = match k {
            "rs" => m.rs_ratio,
            "ld" => m.ld_ratio,
            "lq" => m.lq_ratio,
            _ => 1.0,
        };
        if ratio != 1.0 {
            format!("mismatch.{k}_ratio")
        } else {
            format!("motor.{k}")
        }
    }

    /// The drive's model of the motor (`[model]`, or `[motor]` × `[mismatch]`). A `[model]`
    /// table that [`validate`](Self::validate) refuses is ignored here.
    pub fn machine_model(&self) -> MachineModel<f64> {
        self.model_checked()
            .unwrap_or_else(|_| self.derived_model())
    }

    /// The estimator configuration: `[estimator]` tuning, the drive's model, sampling period
    /// from the inverter.
    pub fn estimator_config(&self) -> EstimatorConfig<f64> {
        EstimatorConfig {
            ts: self.inverter.sample_period(),
            machine: self.machine_model(),
            initial_angle: self.simulation.initial_angle + self.simulation.align_error,
            tuning: self.estimator,
        }
    }

    /// The drive configuration: `[controller]` tuning, the drive's model, timing and the
    /// dead-time compensation's inverter data from `[inverter]` (× `[mismatch]`), its
    /// threshold voltage from `[inverter_model]` when that gives it. With the averaged
    /// inverter, which has no PWM ripple, `dead_time_method = "edge_current"` becomes the
    /// trapezoid it then equals (its exact inverse), so that "matched" stays matched.
    pub fn drive_config(&self) -> DriveConfig<f64> {
        let (inv, m) = (&self.inverter, &self.mismatch);
        let threshold = self
            .inverter_model
            .as_ref()
            .and_then(|im| im.threshold_voltage)
            .unwrap_or(inv.threshold_voltage * m.threshold_voltage_ratio);
        DriveConfig {
            ts: inv.sample_period(),
            machine: self.machine_model(),
            tuning: DriveTuning {
                dead_time: inv.dead_time * m.dead_time_ratio,
                switching_frequency: inv.switching_frequency,
                dead_time_threshold_voltage: threshold,
                dead_time_current_band: inv.current_band * m.current_band_ratio,
                dead_time_method: match (inv.model, self.controller.dead_time_method) {
                    (crate::inverter::InverterModel::Averaged, DeadTimeMethod::EdgeCurrent) => {
                        DeadTimeMethod::Trapezoidal
                    }
                    (_, method) => method,
                },
                ..self.controller
            },
        }
    }

    /// A fado-core refusal of the `[section]` block (`estimator`, `controller`, `model`, or a
    /// baseline's `lpf_`/`ortega_`/`emf_` keys), named by the TOML key the user writes. The
    /// machine model's fields are `model.<key>` where `[model]` gives them and otherwise the
    /// plant key they derive from; the timing and the inverter data are `[inverter]` keys.
    pub(crate) fn core_error(&self, section: &str, e: fado_core::ConfigError) -> SimConfigError {
        let field = e.field();
        let machine_key = |k: &str| -> String {
            let given = self.model.as_ref().is_some_and(|t| t.contains_key(k));
            if given {
                format!("model.{k}")
            } else {
                format!("motor.{k}")
            }
        };
        let derived = match field {
            "ts" | "switching_frequency" => Some("inverter.switching_frequency".to_owned()),
            "dc_voltage" => Some("inverter.dc_voltage".to_owned()),
            "rs" | "rs_hat" => Some(machine_key("rs")),
            "ld" | "ld_hat" => Some(machine_key("ld")),
            "lq" | "lq_hat" => Some(machine_key("lq")),
            "flux_linkage" | "flux_linkage_hat" => Some(machine_key("flux_linkage")),
            "inertia" | "inertia_hat" => Some(machine_key("inertia")),
            "pole_pairs" | "viscous_friction" | "rated_current" | "rated_speed_rpm"
            | "rated_torque" => Some(machine_key(field)),
            "dead_time" => Some("inverter.dead_time".to_owned()),
            "dead_time_threshold_voltage" => Some(
                if self
                    .inverter_model
                    .as_ref()
                    .is_some_and(|im| im.threshold_voltage.is_some())
                {
                    "inverter_model.threshold_voltage"
                } else {
                    "inverter.threshold_voltage"
                }
                .to_owned(),
            ),
            "dead_time_current_band" => Some("inverter.current_band".to_owned()),
            "initial_angle" => Some("simulation.initial_angle".to_owned()),
            _ => None,
        };
        if let Some(key) = derived {
            let note = if key.starts_with("model.") {
                String::new()
            } else {
                format!(" (the drive's value is derived from `{key}` and [mismatch])")
            };
            return SimConfigError::new(key, format!("{e}{note}"));
        }
        SimConfigError::new(format!("{section}.{field}"), e.to_string())
    }

    /// "Near zero speed" in r/min: `zero_speed_band_ratio` × the motor's rated speed.
    pub fn zero_speed_band_rpm(&self) -> f64 {
        self.simulation.zero_speed_band_ratio * self.motor.rated_speed_rpm
    }

    /// This configuration as a TOML document.
    pub fn to_toml(&self) -> String {
        let (sat, map) = (self.motor_saturation.as_ref(), self.motor_flux_map.as_ref());
        if sat.is_none() && map.is_none() {
            // Straight from the record: its field order (a TOML table would sort the keys).
            return toml::to_string(self)
                .expect("every field of SimConfig is representable in TOML");
        }
        let mut table = toml::Table::try_from(self).expect("SimConfig is a TOML table");
        magnetics_file::insert_magnetics(&mut table, sat, map);
        toml::to_string(&table).expect("every field of SimConfig is representable in TOML")
    }

    /// Parses a partial TOML document on top of `base`, an explicit configuration (a
    /// scenario's with the user's motor, a sweep point's): tables merge, values and arrays
    /// replace, so `[motor]\nrs = 0.5` changes one key of `base`'s motor. The result is
    /// validated. Errors name the key.
    pub fn from_toml_over(base: &SimConfig, text: &str) -> Result<SimConfig, SimConfigError> {
        Self::parse_over(base, text, false)
    }

    /// Parses a user's configuration file on top of `base`: as
    /// [`from_toml_over`](Self::from_toml_over), except that a `[motor]` table describes the
    /// whole motor — every circuit key and rating required, the others derived from the
    /// ratings with the `[inverter]` keys they give (`crate::derive`), none taken from
    /// `base`'s motor.
    pub fn from_user_toml(base: &SimConfig, text: &str) -> Result<SimConfig, SimConfigError> {
        Self::parse_over(base, text, true)
    }

    fn parse_over(
        base: &SimConfig,
        text: &str,
        whole_motor: bool,
    ) -> Result<SimConfig, SimConfigError> {
        let mut user: toml::Table = text.parse().map_err(|e| located(text, e))?;
        let (saturation, flux_map) =
            magnetics_file::take_magnetics(&mut user).map_err(|e| e.located_in(text))?;
        // Check the user's document on its own first, so that errors (unknown keys, wrong
        // types) name the key the user wrote and point at it.
        if saturation.is_some() || flux_map.is_some() {
            SimConfig::deserialize(toml::Value::Table(user.clone()))
                .map_err(|e| key_error(e).located_in(text))?;
        } else {
            toml::from_str::<SimConfig>(text).map_err(|e| located(text, e))?;
        }
        let derived = if whole_motor {
            crate::derive::complete_motor(&mut user, text)?
        } else {
            Vec::new()
        };
        let given = user.clone();
        let mut merged = toml::Table::try_from(base)
            .map_err(|e| SimConfigError::new("<base>", e.to_string()))?;
        merge(&mut merged, user);
        let mut cfg = SimConfig::deserialize(toml::Value::Table(merged))
            .map_err(|e| key_error(e).located_in(text))?;
        // What `base` derived stays derived unless the document gives it now.
        cfg.derived = base
            .derived
            .iter()
            .filter(|d| {
                let (section, key) = d.key.split_once('.').unwrap_or(("", ""));
                !given
                    .get(section)
                    .and_then(|t| t.as_table())
                    .is_some_and(|t| t.contains_key(key))
            })
            .filter(|d| !derived.iter().any(|n| n.key == d.key))
            .cloned()
            .collect();
        cfg.derived.extend(derived);
        // `[motor]` has no DC link of its own (it is the inverter's).
        cfg.motor.dc_voltage = cfg.inverter.dc_voltage;
        // A document giving one magnetic model replaces the base's (either).
        if saturation.is_some() || flux_map.is_some() {
            (cfg.motor_saturation, cfg.motor_flux_map) = (saturation, flux_map);
        } else {
            cfg.motor_saturation = base.motor_saturation;
            cfg.motor_flux_map = base.motor_flux_map.clone();
        }
        cfg.validate().map_err(|e| e.located_in(text))?;
        Ok(cfg)
    }

    /// Parses a user's TOML document over the defaults (see
    /// [`from_user_toml`](Self::from_user_toml)).
    pub fn from_toml(text: &str) -> Result<SimConfig, SimConfigError> {
        Self::from_user_toml(&SimConfig::default(), text)
    }

    /// The defaults with `machine` as the motor and its `dc_voltage` as the DC link; the
    /// other `[inverter]` keys its ratings give are derived (`crate::derive`) and recorded.
    pub fn for_machine(machine: &MachineModel<f64>) -> SimConfig {
        let mut c = SimConfig {
            motor: *machine,
            ..SimConfig::default()
        };
        let mut given = toml::Table::new();
        given.insert("dc_voltage".into(), toml::Value::Float(machine.dc_voltage));
        c.inverter.dc_voltage = machine.dc_voltage;
        for (key, value) in crate::derive::inverter_values(machine, &given) {
            match key {
                "switching_frequency" => c.inverter.switching_frequency = value,
                "dead_time" => c.inverter.dead_time = value,
                "threshold_voltage" => c.inverter.threshold_voltage = value,
                "current_band" => c.inverter.current_band = value,
                _ => continue,
            }
            let full = format!("inverter.{key}");
            c.derived.push(crate::derive::Derived {
                rule: fado_core::ratings::rule(&full).unwrap_or(""),
                key: full,
                value,
            });
        }
        c
    }

    /// This configuration as TOML with each derived key's rule beside it (`--dump-config`).
    pub fn to_toml_annotated(&self) -> String {
        crate::derive::annotate(&self.to_toml(), &self.derived)
    }

    /// The plausibility findings of the motor against its ratings, the DC link and the
    /// sampling period (`fado_core::machine_checks`), each with its message naming the TOML
    /// keys involved: errors first.
    pub fn machine_findings(&self) -> Vec<(fado_core::machine_checks::Severity, String, String)> {
        let m = MachineModel {
            dc_voltage: self.inverter.dc_voltage,
            ..self.motor
        };
        fado_core::machine_checks::check(&m, Some(self.inverter.sample_period()))
            .iter()
            .map(|f| {
                let mut text = f.to_string();
                for k in f.keys() {
                    let full = plant_key(k);
                    text = text.replace(&format!("`{k}`"), &format!("`{full}`"));
                }
                (f.severity(), plant_key(f.key()), text)
            })
            .collect()
    }

    /// The plausibility warnings of [`machine_findings`](Self::machine_findings), as
    /// `key: message` lines.
    pub fn warnings(&self) -> Vec<String> {
        self.machine_findings()
            .into_iter()
            .filter(|(s, ..)| *s == fado_core::machine_checks::Severity::Warning)
            .map(|(_, _, text)| text)
            .collect()
    }
}

/// The TOML key of a machine-check field: `[inverter]`'s for the DC link and the sampling
/// period, `[motor]`'s otherwise.
fn plant_key(field: &str) -> String {
    match field {
        "dc_voltage" => "inverter.dc_voltage".to_owned(),
        "ts" => "inverter.switching_frequency".to_owned(),
        k => format!("motor.{k}"),
    }
}

/// The electrical time constant min(Ld, Lq)/Rs must span at least two sampling periods: a
/// faster machine cannot be current-controlled at this rate (and the controllers' derived
/// limits would otherwise refuse a key the user never wrote). The error names the field that
/// is off: an inductance below 0.1 µH, else the resistance.
fn check_time_constant(
    m: &MachineModel<f64>,
    ts: f64,
    key: impl Fn(&str) -> String,
) -> Result<(), SimConfigError> {
    let l = m.ld.min(m.lq);
    let tau = l / m.rs;
    if tau >= 2.0 * ts {
        return Ok(());
    }
    let field = if l < 1e-7 {
        if m.ld <= m.lq { "ld" } else { "lq" }
    } else {
        "rs"
    };
    Err(SimConfigError::new(
        key(field),
        format!(
            "the electrical time constant min(Ld, Lq)/Rs = {tau:.3e} s must be at least two \
             sampling periods ({:.3e} s): check the units of rs, ld and lq",
            2.0 * ts
        ),
    ))
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
pub(crate) fn key_error(e: toml::de::Error) -> SimConfigError {
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
        assert!((cfg.estimator_config().machine.rs - 0.327 * 1.02).abs() < 1e-15);
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
        let (key, line, _, _) = err("[estimator]\nmode_hysteresis_ratio = 0.03\n");
        assert_eq!((key.as_str(), line), ("estimator.mode_hysteresis_ratio", 2));
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

    /// The paper's motor as a whole `[motor]` table whose first key is `first` (which
    /// replaces the paper's value of that key).
    pub(crate) fn paper_motor_with(first: &str) -> String {
        let key = first.split('=').next().unwrap_or("").trim();
        let m = MachineModel::<f64>::paper();
        let mut text = format!("[motor]\n{first}\n");
        for (k, v) in [
            ("rs", m.rs),
            ("ld", m.ld),
            ("lq", m.lq),
            ("flux_linkage", m.flux_linkage),
            ("pole_pairs", m.pole_pairs as f64),
            ("inertia", m.inertia),
            ("viscous_friction", m.viscous_friction),
            ("rated_current", m.rated_current),
            ("rated_speed_rpm", m.rated_speed_rpm),
            ("rated_torque", m.rated_torque),
        ] {
            if k != key {
                if k == "pole_pairs" {
                    text.push_str(&format!("{k} = {}\n", v as u32));
                } else {
                    text.push_str(&format!("{k} = {v:?}\n"));
                }
            }
        }
        text.push_str("[inverter]\ndc_voltage = 311.0\nswitching_frequency = 5000.0\n");
        text
    }

    #[test]
    fn derived_limits_name_the_users_own_key() {
        // Each of these keys is refused naming itself, not `controller.current_anti_windup_ratio`.
        let (key, line, col, _) = err(&paper_motor_with("rs = 1e300"));
        assert_eq!((key.as_str(), line, col), ("motor.rs", 2, 6));
        let (key, line, _, _) = err(&paper_motor_with("ld = 1e-300"));
        assert_eq!((key.as_str(), line), ("motor.ld", 2));
        let (key, line, _, _) = err("[mismatch]\nrs_ratio = 1e300\n");
        assert_eq!((key.as_str(), line), ("mismatch.rs_ratio", 2));
        let (key, line, _, msg) = err("[simulation]\nduration = 0.0\n");
        assert_eq!((key.as_str(), line), ("simulation.duration", 2), "{msg}");
    }

    /// `[inverter_model] threshold_voltage` (what `fado-sim commission` writes) replaces the
    /// compensation's V̂th derived from `[inverter]` × `[mismatch]`; a bad one is refused by
    /// its own key.
    #[test]
    fn the_inverter_model_sets_the_compensation_threshold() {
        let cfg = SimConfig::from_toml(
            "[inverter]\nthreshold_voltage = 1.0\n[mismatch]\nthreshold_voltage_ratio = 2.0\n",
        )
        .unwrap();
        assert_eq!(cfg.drive_config().tuning.dead_time_threshold_voltage, 2.0);
        let cfg = SimConfig::from_toml(
            "[mismatch]\nthreshold_voltage_ratio = 2.0\n[inverter_model]\nthreshold_voltage = 0.93\n",
        )
        .unwrap();
        assert_eq!(cfg.drive_config().tuning.dead_time_threshold_voltage, 0.93);
        assert_eq!(cfg.inverter.threshold_voltage, 1.0);
        let (key, line, col, _) = err("[inverter_model]\nthreshold_voltage = -0.1\n");
        assert_eq!(
            (key.as_str(), line, col),
            ("inverter_model.threshold_voltage", 2, 21)
        );
        let (key, line, _, _) = err("[inverter_model]\nthreshold_voltage = nan\n");
        assert_eq!(
            (key.as_str(), line),
            ("inverter_model.threshold_voltage", 2)
        );
        let (key, ..) = err("[inverter_model]\ndead_time = 1e-6\n");
        assert_eq!(key, "inverter_model.dead_time");
    }

    /// A baseline's settings are its table `[baselines.<name>]`; errors name the key there,
    /// and a setting in the old flat place is refused with its new one.
    #[test]
    fn baseline_settings_live_in_their_own_tables() {
        let cfg = SimConfig::from_toml(
            "[simulation]\nestimator = \"ortega\"\n[baselines.ortega]\nobserver_speed_ratio = 0.0\n",
        )
        .unwrap();
        assert_eq!(cfg.simulation.estimator.name(), "ortega");
        assert_eq!(
            cfg.baselines["ortega"]["observer_speed_ratio"].as_float(),
            Some(0.0)
        );
        // The other settings of the table keep their defaults (tables merge).
        assert!(cfg.baselines["ortega"].get("observer_bandwidth").is_some());
        assert_eq!(SimConfig::from_toml(&cfg.to_toml()).unwrap(), cfg);
        let (key, line, col, _) = err("[baselines.ortega]\nobserver_bandwidth = -1.0\n");
        assert_eq!(
            (key.as_str(), line, col),
            ("baselines.ortega.observer_bandwidth", 2, 22)
        );
        let (key, line, _, _) = err("[baselines.lpf_integrator]\ncutoff = 1.0\n");
        assert_eq!((key.as_str(), line), ("baselines.lpf_integrator.cutoff", 2));
        let (key, line, _, msg) = err("[baselines]\nlpf_cutoff_hz = 3.0\n");
        assert_eq!((key.as_str(), line), ("baselines.lpf_cutoff_hz", 2));
        assert!(
            msg.contains("`cutoff_hz` in `[baselines.lpf_integrator]`"),
            "{msg}"
        );
        let (key, _, _, msg) = err("[baselines.kalman]\ngain = 1.0\n");
        assert_eq!(key, "baselines.kalman");
        assert!(msg.contains("ortega"), "{msg}");
        let (key, line, _, msg) = err("[simulation]\nestimator = \"kalman\"\n");
        assert_eq!((key.as_str(), line), ("simulation.estimator", 2));
        assert!(msg.contains("lpf_integrator"), "{msg}");
        // A machine-model field a baseline refuses is named by the user's own key.
        let e = SimConfig::from_toml("[motor]\nflux_linkage = 0.0\n").unwrap_err();
        assert!(e.key.starts_with("motor."), "{e}");
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

#[cfg(test)]
mod dead_time_method {
    use super::*;
    use crate::inverter::InverterModel as Plant;
    use fado_core::control::DeadTimeMethod::{EdgeCurrent, Sign, Trapezoidal};

    #[test]
    fn edge_current_is_the_trapezoid_on_the_ripple_free_averaged_plant() {
        let method = |model: Plant, asked| {
            let mut c = SimConfig::default();
            c.inverter.model = model;
            c.controller.dead_time_method = asked;
            c.drive_config().tuning.dead_time_method
        };
        assert_eq!(
            SimConfig::default().drive_config().tuning.dead_time_method,
            EdgeCurrent
        );
        assert_eq!(method(Plant::SwitchingResolved, EdgeCurrent), EdgeCurrent);
        assert_eq!(method(Plant::Averaged, EdgeCurrent), Trapezoidal);
        assert_eq!(method(Plant::Averaged, Sign), Sign);
        assert_eq!(method(Plant::SwitchingResolved, Trapezoidal), Trapezoidal);
    }

    #[test]
    fn motor_saturation_is_read_checked_and_written_back() {
        // A whole [motor] (9 lines) with its saturation.
        const M: &str = "[motor]\nrs = 0.327\nld = 2.63e-3\nlq = 2.63e-3\nflux_linkage = 0.088\npole_pairs = 4\nrated_current = 21.78\nrated_speed_rpm = 1500.0\nrated_torque = 11.5\n";
        let text =
            "[motor.saturation]\na_d0 = 380.2\na_q0 = 380.2\npsi_f = 0.088\na_qq = 1e5\nt = 2\n";
        let cfg = SimConfig::from_toml(&format!("{M}{text}")).unwrap();
        let sat = cfg.motor_saturation.unwrap();
        assert_eq!((sat.a_qq, sat.t, sat.psi_f), (1e5, 2.0, 0.088));
        assert!(cfg.plant().magnetics.is_some());
        // --dump-config round trip keeps it.
        let back = SimConfig::from_toml(&cfg.to_toml()).unwrap();
        assert_eq!(back.motor_saturation, cfg.motor_saturation);
        // Without the table the plant keeps its constant inductances.
        assert!(SimConfig::default().plant().magnetics.is_none());
        // Errors name the key and point at it.
        let e = SimConfig::from_toml(&format!(
            "{M}[motor.saturation]\na_d0 = 380.2\na_q0 = -1.0\n"
        ))
        .unwrap_err();
        assert_eq!(e.key, "motor.saturation.a_q0", "{e}");
        assert_eq!(e.location.as_ref().map(|l| l.line), Some(12), "{e}");
        let e = SimConfig::from_toml(&format!(
            "{M}[motor.saturation]\na_d0 = 380.2\na_qqq = 1.0\n"
        ))
        .unwrap_err();
        assert!(e.key.starts_with("motor.saturation"), "{e}");
        assert!(e.to_string().contains("a_qqq"), "{e}");
        let e = SimConfig::from_toml(
            "[motor]\nrs = -1.0\n[motor.saturation]\na_d0 = 1.0\na_q0 = 1.0\n",
        )
        .unwrap_err();
        assert_eq!(e.key, "motor.rs", "{e}");
    }
}

/// Whether `x` is its type's default (sections left out of the written TOML when untouched).
fn is_default<T: Default + PartialEq>(x: &T) -> bool {
    *x == T::default()
}
