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

use fado_core::control::tuning::{DeadTimeCompensationTuning, InverterData};
use fado_core::control::{DeadTimeMethod, DriveConfig, DriveTuning};
use fado_core::magnetics::Saturation;
use fado_core::{EstimatorConfig, EstimatorTuning, MachineModel};
use serde::{Deserialize, Serialize};

use crate::criteria::Criteria;
use crate::dc_link::DcLinkParams;
use crate::error::SimConfigError;
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

mod datasheet_keys;
mod drive_rules;
mod moved;
mod settings;
#[cfg(test)]
mod tests;
mod toml_io;

pub(crate) use moved::moved;
pub use settings::{InverterModel, Mismatch, Precision, SimulationSettings};
pub(crate) use toml_io::key_error;
use toml_io::merge;

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

    /// The plant's saturating model against `[motor]`'s `ld`, `lq` and `flux_linkage`
    /// ([`crate::magnetic_agreement`]).
    fn check_magnetic_agreement(&self) -> Result<(), SimConfigError> {
        let (sat, map) = (self.motor_saturation.as_ref(), self.motor_flux_map.as_ref());
        let Some(plant) = magnetics_file::plant_magnetics(sat, map) else {
            return Ok(());
        };
        let key = match map {
            Some(_) => magnetics_file::FLUX_MAP_KEY,
            None => "motor.saturation",
        };
        let stated = crate::magnetic_agreement::Stated {
            section: "motor",
            ld: self.motor.ld,
            lq: self.motor.lq,
            flux_linkage: self.motor.flux_linkage,
        };
        crate::magnetic_agreement::check(&plant.model(), key, stated)
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
        // An error that follows from a slip another finding names (ratings multiplied by 10
        // refused for the carrier they would need) carries that finding as its likely cause.
        let findings = self.machine_findings();
        if let Some((_, key, text)) = findings
            .iter()
            .find(|(s, ..)| *s == fado_core::machine_checks::Severity::Error)
        {
            let causes: Vec<&str> = findings
                .iter()
                .filter(|(s, ..)| *s == fado_core::machine_checks::Severity::Warning)
                .map(|(.., t)| t.as_str())
                .collect();
            let text = if causes.is_empty() {
                text.clone()
            } else {
                format!("{text}; likely cause: {}", causes.join("; "))
            };
            return Err(SimConfigError::new(key.clone(), text));
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
        self.check_magnetic_agreement()?;
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
        crate::motor::validate_motor_section(&self.motor, self.inverter.dc_voltage)?;
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
        self.check_current_loop_sampling()?;
        self.drive_config()
            .validate()
            .map_err(|e| self.core_error("controller", e))?;
        Ok(())
    }

    /// The current loop's bandwidth within what the sampling allows (2π·f_c·Ts ≤ 0.5, the
    /// core's bound): refused naming the switching frequency when the bandwidth is the
    /// default (a slow inverter, e.g. a medium-voltage one at 1 kHz), the bandwidth when the
    /// file sets it; the message gives both values that pass.
    fn check_current_loop_sampling(&self) -> Result<(), SimConfigError> {
        let (bw, ts) = (
            self.controller.current.bandwidth_hz,
            self.inverter.sample_period(),
        );
        let x = std::f64::consts::TAU * bw * ts;
        if !x.is_finite() || x <= 0.5 {
            return Ok(());
        }
        let f_min = std::f64::consts::TAU * bw / (2.0 * 0.5);
        let bw_max = 0.5 / (std::f64::consts::TAU * ts);
        let key = if bw == SimConfig::default().controller.current.bandwidth_hz {
            "inverter.switching_frequency"
        } else {
            "controller.current.bandwidth_hz"
        };
        Err(SimConfigError::new(
            key,
            format!(
                "the current loop's bandwidth `controller.current.bandwidth_hz` = {bw} Hz \
                 needs 2π·f_c·Ts ≤ 0.5, and `inverter.switching_frequency` = {} Hz samples \
                 at Ts = {ts:.3e} s (2π·f_c·Ts = {x:.3}): raise switching_frequency to at \
                 least {f_min:.0} Hz or lower bandwidth_hz to at most {bw_max:.1} Hz",
                self.inverter.switching_frequency
            ),
        ))
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
        let model = model.with_magnetics(derived.magnetics);
        self.check_model_agreement(&model)?;
        Ok(model)
    }

    /// A `[model]` map or `[model.saturation]` against the model's `ld`, `lq` and
    /// `flux_linkage` ([`crate::magnetic_agreement`]): a map without a magnet (a SyRM's,
    /// ψd(0, 0) = 0) is refused with any `flux_linkage` > 0 the model states.
    fn check_model_agreement(&self, model: &MachineModel<f64>) -> Result<(), SimConfigError> {
        let table = self.model.as_ref();
        let Some(key) = crate::model_magnetics::MODEL_MAGNETICS_KEYS
            .iter()
            .find(|k| table.is_some_and(|t| t.contains_key(**k)))
        else {
            return Ok(());
        };
        let stated = crate::magnetic_agreement::Stated {
            section: "model",
            ld: model.ld,
            lq: model.lq,
            flux_linkage: model.flux_linkage,
        };
        crate::magnetic_agreement::check(&model.magnetic_model(), &format!("model.{key}"), stated)
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
    /// inverter, which has no PWM ripple, `[controller.dead_time_compensation] method =
    /// "edge_current"` becomes the trapezoid it then equals (its exact inverse), so that
    /// "matched" stays matched.
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
                inverter: InverterData {
                    dead_time: inv.dead_time * m.dead_time_ratio,
                    switching_frequency: inv.switching_frequency,
                    threshold_voltage: threshold,
                    current_band: inv.current_band * m.current_band_ratio,
                },
                dead_time_compensation: DeadTimeCompensationTuning {
                    method: match (inv.model, self.controller.dead_time_compensation.method) {
                        (crate::inverter::InverterModel::Averaged, DeadTimeMethod::EdgeCurrent) => {
                            DeadTimeMethod::Trapezoidal
                        }
                        (_, method) => method,
                    },
                    ..self.controller.dead_time_compensation
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
        let field = moved(section, field).unwrap_or(field);
        SimConfigError::new(format!("{section}.{field}"), e.to_string())
    }

    /// "Near zero speed" in r/min: `zero_speed_band_ratio` × the motor's rated speed.
    pub fn zero_speed_band_rpm(&self) -> f64 {
        self.simulation.zero_speed_band_ratio * self.motor.rated_speed_rpm
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

    /// The plausibility findings of the motor against its ratings, the DC link and the
    /// sampling period (`fado_core::machine_checks`), each with its message naming the TOML
    /// keys involved: errors first, then the carrier's finding
    /// ([`carrier_findings`](Self::carrier_findings)).
    pub fn machine_findings(&self) -> Vec<(fado_core::machine_checks::Severity, String, String)> {
        let mut m = self.motor.with_dc_voltage(self.inverter.dc_voltage);
        // A saturating plant's torque is its magnetic model's, not its zero-current
        // inductances'.
        let (sat, map) = (self.motor_saturation.as_ref(), self.motor_flux_map.as_ref());
        if let Some(plant) = magnetics_file::plant_magnetics(sat, map) {
            m = m.with_magnetics(crate::model_magnetics::plant_model(&plant));
        }
        let mut findings: Vec<_> =
            fado_core::machine_checks::check(&m, Some(self.inverter.sample_period()))
                .iter()
                .map(|f| {
                    if let Some(d) = self.derived.iter().find(|d| d.key == plant_key(f.key())) {
                        return (
                            f.severity(),
                            DERIVED_DC_LINK_CAUSE.into(),
                            derived_beyond(d),
                        );
                    }
                    let mut text = f.to_string();
                    for k in f.keys() {
                        let full = plant_key(k);
                        text = text.replace(&format!("`{k}`"), &format!("`{full}`"));
                    }
                    (f.severity(), plant_key(f.key()), text)
                })
                .chain(self.carrier_findings())
                .collect();
        findings.extend(self.rms_map_warning());
        findings.extend(drive_rules::frame_coupling_warning(self));
        findings
    }

    /// A warning where `[motor] flux_map` looks like a map whose currents are rms
    /// ([`crate::magnetic_agreement::rms_currents`]).
    fn rms_map_warning(&self) -> Option<(fado_core::machine_checks::Severity, String, String)> {
        let map = self.motor_flux_map.as_ref()?;
        let plant = magnetics_file::plant_magnetics(None, Some(map))?;
        let stated = crate::magnetic_agreement::Stated {
            section: "motor",
            ld: self.motor.ld,
            lq: self.motor.lq,
            flux_linkage: self.motor.flux_linkage,
        };
        let key = magnetics_file::FLUX_MAP_KEY;
        crate::magnetic_agreement::rms_currents(
            &plant.model(),
            key,
            stated,
            self.motor.rated_current,
        )
        .map(|w| (fado_core::machine_checks::Severity::Warning, key.into(), w))
    }

    /// The carrier's finding (`fado_core::ratings::check_carrier`): a derived
    /// `inverter.switching_frequency` beyond the DC link's class of inverters (an error) or
    /// in the band of fast inverters (a warning), or a given one whose PWM ripple exceeds the
    /// rated current (a warning), with the TOML keys named.
    pub fn carrier_findings(
        &self,
    ) -> Option<(fado_core::machine_checks::Severity, String, String)> {
        use fado_core::machine_checks::Severity;
        let m = self.motor.with_dc_voltage(self.inverter.dc_voltage);
        let derived = self
            .derived
            .iter()
            .any(|d| d.key == "inverter.switching_frequency");
        let given = (!derived).then_some(self.inverter.switching_frequency);
        let finding = fado_core::ratings::check_carrier(&m, given)?;
        let mut text = finding.to_string();
        for k in [
            "switching_frequency",
            "dc_voltage",
            "rs",
            "ld",
            "lq",
            "rated_current",
            "rated_speed_rpm",
            "pole_pairs",
        ] {
            text = text.replace(&format!("`{k}`"), &format!("`{}`", plant_key(k)));
        }
        let severity = if finding.is_error() {
            Severity::Error
        } else {
            Severity::Warning
        };
        Some((severity, plant_key(finding.keys()[0]), text))
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

/// The key blamed when a value derived from the ratings (the DC link) is beyond any drive:
/// the rated speed, which with `flux_linkage` sets the rated point's voltage.
const DERIVED_DC_LINK_CAUSE: &str = "motor.rated_speed_rpm";

/// The finding on a derived value `d`: not the user's key, but the keys it is derived from.
fn derived_beyond(d: &crate::derive::Derived) -> String {
    format!(
        "`{}` = {:e} is not in the file: it is derived ({}), and it is beyond any drive; the \
         rated point it follows from (`motor.rated_speed_rpm`, `motor.flux_linkage`, \
         `motor.pole_pairs`, `motor.rated_current`, `motor.ld`, `motor.lq`) is off: check their \
         units (r/min, Wb peak per phase, A peak, H) or give `{}`",
        d.key, d.value, d.rule, d.key
    )
}

/// The TOML key of a machine-check field: `[inverter]`'s for the DC link and the sampling
/// period, `[motor]`'s otherwise.
fn plant_key(field: &str) -> String {
    match field {
        "dc_voltage" => "inverter.dc_voltage".to_owned(),
        "ts" | "switching_frequency" => "inverter.switching_frequency".to_owned(),
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

/// Whether `x` is its type's default (sections left out of the written TOML when untouched).
fn is_default<T: Default + PartialEq>(x: &T) -> bool {
    *x == T::default()
}
