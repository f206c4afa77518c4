//! The registry of estimators the simulator runs, as [`crate::scenario::SCENARIOS`] is the
//! registry of scenarios: one row per estimator, and every list of estimators (the CLI's
//! `--estimators` and its help, `[simulation] estimator`, [`crate::compare`]'s default set,
//! Python's `fado.compare.ESTIMATORS`, the benchmark docs, the tests) is derived from
//! [`ESTIMATORS`].
//!
//! A row names the estimator, says where its settings live (fado's in `[estimator]`, a
//! baseline's in `[baselines.<key>]`), builds its drive from the configuration (the machine
//! model, the [`CommonTuning`] every estimator shares, and its own settings) and names its
//! criterion benchmark (`<name>_step_f32` in `benches/baselines.rs`). A baseline is one row
//! made by [`baseline`] from a type implementing [`fado_core::baselines::Baseline`]:
//!
//! ```text
//! baseline::<OrtegaEstimator<f64>>("Ortega–Praly nonlinear flux observer (Lee et al., 2010)"),
//! ```
//!
//! and one line in `benches/baselines.rs` (`bench_baseline::<OrtegaEstimator<f32>>`).

use fado_core::baselines::{
    Baseline, CommonTuning, EmfObserverEstimator, LpfIntegratorEstimator, OrtegaEstimator,
    ReducedOrderEstimator,
};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::config::{Precision, SimConfig};
use crate::controller::Controller;
use crate::error::SimConfigError;

/// One estimator of the registry.
#[derive(Clone, Copy)]
pub struct Estimator {
    /// Its name in tables, on the command line and in `[simulation] estimator` (where `_`
    /// may stand for `-`): `fado`, `fado-fixed-rs`, `ortega`, ...
    pub name: &'static str,
    /// What it is, in one line.
    pub summary: &'static str,
    /// Its settings are its own table `[baselines.<key>]` ([`Estimator::key`]); otherwise
    /// they are `[estimator]`.
    pub own_settings: bool,
    /// Its settings' defaults, as the TOML table `--dump-config` shows.
    pub defaults: fn() -> toml::Table,
    /// What it changes in the configuration it runs with, before anything is built or
    /// checked (`fado-fixed-rs`: `[estimator.rs_adaptation] enabled = false`).
    pub prepare: fn(&mut SimConfig),
    /// Builds the drive around it (f64, or f32 where it supports it); a bad setting is
    /// named by its TOML key.
    pub build: fn(&SimConfig) -> Result<Box<dyn Controller>, SimConfigError>,
    /// Builds it alone, to check its settings whichever estimator runs.
    pub check: fn(&SimConfig) -> Result<(), SimConfigError>,
}

impl core::fmt::Debug for Estimator {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name)
    }
}

impl PartialEq for Estimator {
    /// Estimators are named values: equal when their names are.
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

impl Eq for Estimator {}

/// Every estimator: fado (with its R̂s adaptation), fado as the paper has it (fixed R̂s),
/// then the baselines of [`fado_core::baselines`]. `fado-sim compare` runs them all by
/// default, in this order.
pub const ESTIMATORS: &[Estimator] = &[
    Estimator {
        name: "fado",
        summary: "the paper's estimator with fado's additions (`[estimator]`)",
        own_settings: false,
        defaults: toml::Table::new,
        prepare: keep,
        build: build_fado,
        check: no_check,
    },
    Estimator {
        name: "fado-fixed-rs",
        summary: "fado with the paper's fixed R̂s (`[estimator.rs_adaptation] enabled = false`)",
        own_settings: false,
        defaults: toml::Table::new,
        prepare: |cfg| cfg.estimator.rs_adaptation.enabled = false,
        build: build_fado,
        check: no_check,
    },
    baseline::<LpfIntegratorEstimator<f64>>(
        "low-pass integrator with gain/phase compensation (Hu and Wu, 1998)",
    ),
    baseline::<OrtegaEstimator<f64>>("Ortega–Praly nonlinear flux observer (Lee et al., 2010)"),
    baseline::<EmfObserverEstimator<f64>>("extended-EMF observer in α-β"),
    baseline::<ReducedOrderEstimator<f64>>(
        "reduced-order flux observer (Hinkkanen et al., 2018; motulator's sensorless observer)",
    ),
];

/// The registry row of a baseline: named by [`Baseline::NAME`], its settings under
/// `[baselines.<key>]`.
pub const fn baseline<B>(summary: &'static str) -> Estimator
where
    B: Baseline<f64> + 'static,
    B::Settings: Serialize + DeserializeOwned,
{
    Estimator {
        name: B::NAME,
        summary,
        own_settings: true,
        defaults: defaults_of::<B>,
        prepare: keep,
        build: build_baseline::<B>,
        check: check_baseline::<B>,
    }
}

/// The estimator named `name` (`-` or `_`, surrounding blanks ignored).
pub fn find(name: &str) -> Option<&'static Estimator> {
    let wanted = name.trim().replace('_', "-");
    ESTIMATORS.iter().find(|e| e.name == wanted)
}

/// The names of every estimator, in registry order.
pub fn names() -> Vec<&'static str> {
    ESTIMATORS.iter().map(|e| e.name).collect()
}

/// [`find`], or an error under `key` naming every estimator.
pub fn parse(key: &str, name: &str) -> Result<&'static Estimator, SimConfigError> {
    find(name)
        .ok_or_else(|| SimConfigError::new(key, format!("unknown `{name}`; one of {:?}", names())))
}

impl Estimator {
    /// Its value in TOML (`[simulation] estimator`) and the key of its settings table
    /// (`[baselines.<key>]`): the name with `_` for `-`.
    pub fn key(&self) -> String {
        self.name.replace('-', "_")
    }

    /// Its criterion benchmark of one `f32` step (`benches/baselines.rs`, named after
    /// `RotorAngleEstimator::name`), which `fado-sim compare --criterion` reads back.
    pub fn bench(&self) -> String {
        format!("{}_step_f32", self.name)
    }
}

fn no_check(_: &SimConfig) -> Result<(), SimConfigError> {
    Ok(())
}

fn build_fado(cfg: &SimConfig) -> Result<Box<dyn Controller>, SimConfigError> {
    Ok(match cfg.simulation.precision {
        Precision::F64 => Box::new(cfg.build_drive()?),
        Precision::F32 => Box::new(cfg.build_drive_f32()?),
    })
}

fn keep(_: &mut SimConfig) {}

fn defaults_of<B>() -> toml::Table
where
    B: Baseline<f64>,
    B::Settings: Serialize,
{
    toml::Table::try_from(B::Settings::default())
        .expect("a baseline's settings are representable in TOML")
}

/// The [`CommonTuning`] of a configuration: `[estimator]`'s trackers, current averaging and
/// sample bounds, the inverter's sampling period, the start-up angle.
pub fn common_tuning(cfg: &SimConfig) -> CommonTuning<f64> {
    let e = cfg.estimator_config();
    let t = &e.tuning;
    CommonTuning {
        ts: e.ts,
        t2s1_bandwidth_hz: t.tracker.t2s1_bandwidth_hz,
        t2s2_bandwidth_hz: t.tracker.t2s2_bandwidth_hz,
        tracker_damping: t.tracker.damping,
        bandwidth_definition: t.tracker.bandwidth_definition,
        tracker_hold_ratio: t.tracker.hold_ratio,
        average_current: t.integrator.average_current,
        plausible_current_ratio: t.plausibility.current_ratio,
        plausible_voltage_ratio: t.plausibility.voltage_ratio,
        plausible_current_step_ratio: t.plausibility.current_step_ratio,
        initial_angle: e.initial_angle,
    }
}

/// The baseline `B` of a configuration: the drive's machine model, [`common_tuning`] and its
/// settings `[baselines.<key>]` (over their defaults).
fn estimator_of<B>(cfg: &SimConfig) -> Result<B, SimConfigError>
where
    B: Baseline<f64>,
    B::Settings: Serialize + DeserializeOwned,
{
    let key = B::NAME.replace('-', "_");
    let section = format!("baselines.{key}");
    let mut table = defaults_of::<B>();
    if let Some(given) = cfg.baselines.get(&key) {
        let Some(given) = given.as_table() else {
            return Err(SimConfigError::new(section, "must be a table"));
        };
        table.extend(given.clone());
    }
    let settings: B::Settings = toml::Value::Table(table)
        .try_into()
        .map_err(|e| crate::config::key_error(e).in_section(&section))?;
    B::build(&cfg.machine_model(), &common_tuning(cfg), &settings).map_err(|e| {
        let field = e.field();
        let own = toml::Table::try_from(settings).is_ok_and(|t| t.contains_key(field));
        if own {
            SimConfigError::new(format!("{section}.{field}"), e.to_string())
        } else {
            cfg.core_error("estimator", e)
        }
    })
}

fn check_baseline<B>(cfg: &SimConfig) -> Result<(), SimConfigError>
where
    B: Baseline<f64>,
    B::Settings: Serialize + DeserializeOwned,
{
    estimator_of::<B>(cfg).map(|_| ())
}

fn build_baseline<B>(cfg: &SimConfig) -> Result<Box<dyn Controller>, SimConfigError>
where
    B: Baseline<f64> + 'static,
    B::Settings: Serialize + DeserializeOwned,
{
    if cfg.simulation.precision != Precision::F64 {
        return Err(SimConfigError::new(
            "simulation.estimator",
            "the baselines run with an f64 drive only (simulation.precision = \"f64\")",
        ));
    }
    let estimator = estimator_of::<B>(cfg)?;
    Ok(Box::new(cfg.build_baseline_drive(estimator)?))
}

/// Which rotor-angle estimator the drive runs: a row of [`ESTIMATORS`],
/// written in TOML by its key (`"fado"`, `"ortega"`, `"lpf_integrator"`; `-` is accepted
/// for `_`).
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct EstimatorKind(&'static Estimator);

impl EstimatorKind {
    /// fado, the default.
    pub const FADO: Self = Self(&ESTIMATORS[0]);

    /// The estimator of the registry row.
    pub const fn of(estimator: &'static Estimator) -> Self {
        Self(estimator)
    }

    /// Its registry row.
    pub const fn estimator(self) -> &'static Estimator {
        self.0
    }

    /// Its name (`lpf-integrator`).
    pub const fn name(self) -> &'static str {
        self.0.name
    }
}

impl Default for EstimatorKind {
    fn default() -> Self {
        Self::FADO
    }
}

impl std::fmt::Debug for EstimatorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0.name)
    }
}

impl Serialize for EstimatorKind {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.0.key())
    }
}

impl<'de> Deserialize<'de> for EstimatorKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        find(&name).map(Self).ok_or_else(|| {
            let keys: Vec<_> = ESTIMATORS.iter().map(|e| e.key()).collect();
            serde::de::Error::custom(format!("unknown estimator `{name}`; one of {keys:?}"))
        })
    }
}

/// `[baselines]` keys that name a setting of one baseline directly, and the table and key
/// each lives under now.
const MOVED_BASELINE_KEYS: [(&str, &str, &str); 8] = [
    ("lpf_cutoff_hz", "lpf_integrator", "cutoff_hz"),
    (
        "lpf_compensation_floor_hz",
        "lpf_integrator",
        "compensation_floor_hz",
    ),
    ("ortega_observer_bandwidth", "ortega", "observer_bandwidth"),
    (
        "ortega_observer_speed_ratio",
        "ortega",
        "observer_speed_ratio",
    ),
    (
        "ortega_observer_bandwidth_min",
        "ortega",
        "observer_bandwidth_min",
    ),
    (
        "ortega_flux_adaptation_ratio",
        "ortega",
        "flux_adaptation_ratio",
    ),
    ("emf_bandwidth_hz", "emf_observer", "emf_bandwidth_hz"),
    ("emf_speed_floor_hz", "emf_observer", "speed_floor_hz"),
];

/// The settings of the baselines, one table per baseline of the registry
/// (`[baselines.ortega]`, `[baselines.lpf_integrator]`, ...), each with its defaults.
pub(crate) fn default_baselines() -> toml::Table {
    ESTIMATORS
        .iter()
        .filter(|e| e.own_settings)
        .map(|e| (e.key(), toml::Value::Table((e.defaults)())))
        .collect()
}

/// Every key of `[baselines]` names a baseline of the registry; a setting written there
/// directly is refused with the table it belongs in.
pub(crate) fn check_baseline_keys(baselines: &toml::Table) -> Result<(), SimConfigError> {
    for key in baselines.keys() {
        if let Some((_, table, field)) = MOVED_BASELINE_KEYS.iter().find(|m| m.0 == key) {
            return Err(SimConfigError::new(
                format!("baselines.{key}"),
                format!("a setting of `[baselines.{table}]`: write it as `{field}` there"),
            ));
        }
        let known = ESTIMATORS.iter().any(|e| e.own_settings && e.key() == *key);
        if !known {
            let keys: Vec<_> = ESTIMATORS
                .iter()
                .filter(|e| e.own_settings)
                .map(|e| e.key())
                .collect();
            return Err(SimConfigError::new(
                format!("baselines.{key}"),
                format!("unknown baseline; one of {keys:?}"),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_parse_back_and_benches_follow_the_names() {
        for (k, e) in ESTIMATORS.iter().enumerate() {
            assert!(
                ESTIMATORS[..k].iter().all(|o| o.name != e.name),
                "{}",
                e.name
            );
            assert_eq!(find(e.name), Some(e));
            assert_eq!(find(&e.key()), Some(e));
            assert_eq!(e.own_settings, !(e.defaults)().is_empty(), "{}", e.name);
        }
        assert_eq!(parse("estimators", "kalman").unwrap_err().key, "estimators");
    }

    /// Every row builds a drive on the default configuration, whose name is the row's (the
    /// baselines' `RotorAngleEstimator::name`; fado's drive is named `fado`).
    #[test]
    fn every_row_builds_a_drive_named_as_the_row() {
        let cfg = SimConfig::default();
        for e in ESTIMATORS {
            (e.check)(&cfg).unwrap();
            let drive = (e.build)(&cfg).unwrap();
            let expected = if e.name.starts_with("fado") {
                "fado"
            } else {
                e.name
            };
            assert_eq!(drive.name(), expected);
        }
    }
}
