//! `fado.EstimatorConfig`: the estimator's tuning (`fado_core::EstimatorTuning`) with keyword
//! arguments.
//!
//! The Python class holds the core record and takes its fields from the record's serde derive
//! ([`crate::record`]): nothing here lists them. The machine and the sampling period are not
//! part of it: they are `fado.Machine` and the `ts` argument of
//! `fado.Estimator`/`fado.estimate`. Every default is the Rust one; a refusal raises
//! `fado.ConfigError` (a `ValueError`) naming the field.
//!
//! A tuning on its own is checked for what it alone decides (finite, signs, order of the
//! thresholds, hold ratio below 1, …): [`PyEstimatorConfig::check`] validates it around the
//! paper's motor at a sampling period so short that no rate limit binds. The limits that
//! depend on the sampling period and the motor (k_af·ts ≤ 1, bandwidths and the mode
//! threshold below the Nyquist frequency) are checked when an estimator is built with them.

use fado_core::estimator::tuning::MOVED_KEYS;
use fado_core::{EstimatorConfig, EstimatorTuning, MachineModel};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{config_error, config_error_message};
use crate::record;
use crate::scalar::Scalar;

/// Sampling period at which a tuning alone is checked: short enough (1 ns) that no limit
/// tied to the sampling rate binds for any plausible gain or bandwidth.
const CHECK_TS: f64 = 1e-9;

/// Tuning of the sensorless estimator (paper, Fig. 5; docs/method/estimator.md §1–§3): everything but the machine
/// and the sampling period (`fado_core::EstimatorTuning`).
///
/// Every argument is keyword-only and optional: an omitted one takes the Rust default
/// (`EstimatorConfig()` shows them all; speeds are ratios of the machine's rated electrical
/// frequency; `EstimatorConfig.fields` names them; each is documented in the type stub and in
/// the Rust documentation of `EstimatorTuning`). Instances are immutable;
/// `replace(**changes)` returns a modified copy. Invalid values raise `fado.ConfigError` (a
/// `ValueError`) whose `.field` names the field.
#[pyclass(name = "EstimatorConfig", module = "fado", frozen, eq)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyEstimatorConfig {
    tuning: EstimatorTuning<f64>,
}

impl Default for PyEstimatorConfig {
    fn default() -> Self {
        Self::from_core(&EstimatorTuning::default())
    }
}

impl PyEstimatorConfig {
    /// The Python view of a core tuning (not validated).
    pub fn from_core(tuning: &EstimatorTuning<f64>) -> Self {
        Self { tuning: *tuning }
    }

    /// The core tuning in scalar type `T` (not validated: see [`Self::check`] and
    /// [`Self::estimator_config`]).
    pub fn to_core_as<T: Scalar>(&self) -> EstimatorTuning<T> {
        self.tuning.cast()
    }

    /// The field names, in declaration order (from the serde derive of `EstimatorTuning`).
    pub fn field_names(py: Python<'_>) -> PyResult<Vec<String>> {
        record::field_names(py, &EstimatorTuning::<f64>::default())
    }

    fn items<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        record::to_dict(py, &self.tuning)
    }

    /// The constructor's keywords for [`record::install`]: every field, default `None` (the
    /// Rust default).
    pub fn signature(py: Python<'_>) -> PyResult<Vec<(String, Option<Bound<'_, PyAny>>)>> {
        Ok(Self::field_names(py)?
            .into_iter()
            .map(|f| (f, Some(py.None().into_bound(py))))
            .collect())
    }

    /// A copy with `changes` applied, validated; errors name `shown(field)`.
    fn with_changes(
        &self,
        py: Python<'_>,
        changes: Option<&Bound<'_, PyDict>>,
        shown: &dyn Fn(&str) -> String,
    ) -> PyResult<Self> {
        if let Some(c) = changes {
            refuse_moved(c, shown)?;
        }
        let changed = match changes {
            Some(c) => Self {
                tuning: record::with_changes(py, &self.tuning, c, "an estimator setting", shown)?,
            },
            None => self.clone(),
        };
        changed.check(py)?;
        Ok(changed)
    }
}

#[pymethods]
impl PyEstimatorConfig {
    #[new]
    #[pyo3(signature = (**changes))]
    fn py_new(py: Python<'_>, changes: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        Self::default().with_changes(py, changes, &str::to_owned)
    }

    /// A copy with the given fields changed (validated like the constructor).
    fn _replace(&self, py: Python<'_>, changes: &Bound<'_, PyDict>) -> PyResult<Self> {
        self.with_changes(py, Some(changes), &str::to_owned)
    }

    /// The fields as a plain `dict` (`EstimatorConfig(**config.to_dict())` round-trips).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.items(py)
    }

    /// A copy on the paper's path (`fado_core::EstimatorTuning::paper_path`): fixed R̂s, the
    /// observer on λ1 at T2S-1's ω̂, no limiter re-centring, an abrupt k_df and the gains (16)
    /// every sample; the sample bounds and the lock detector stay.
    fn paper_path(&self) -> Self {
        Self::from_core(&self.tuning.paper_path())
    }
}

impl PyEstimatorConfig {
    /// Checks what the tuning alone decides: validated around the paper's motor at a 1 ns
    /// sampling period, where no rate limit binds (those are checked with the real `ts` and
    /// machine by [`Self::estimator_config`]).
    pub fn check(&self, py: Python<'_>) -> PyResult<()> {
        self.estimator_config::<f64>(py, CHECK_TS, &MachineModel::paper(), 0.0)
            .map(|_| ())
    }

    /// The complete core configuration in scalar type `T` around `machine`, sampled every
    /// `ts`, starting at `initial_angle`; validated for that type (a value that is fine in
    /// f64 can still underflow or overflow in f32).
    pub fn estimator_config<T: Scalar>(
        &self,
        py: Python<'_>,
        ts: f64,
        machine: &MachineModel<f64>,
        initial_angle: f64,
    ) -> PyResult<EstimatorConfig<T>> {
        let config = EstimatorConfig {
            ts: T::lit(ts),
            machine: machine.cast(),
            initial_angle: T::lit(initial_angle),
            tuning: self.to_core_as(),
        };
        config.validate().map_err(|e| core_error(py, e))?;
        Ok(config)
    }
}

/// The section of a simulator configuration that is the estimator's tuning.
const SECTION: &str = "estimator";

impl PyEstimatorConfig {
    /// `config` as given to `fado.estimate`/`fado.Estimator`: `None` (the defaults), an
    /// `EstimatorConfig`, or a `dict` as `fado.simulate` takes it: flat tuning keys
    /// (`{"k_df": 1.0}`), the `[estimator]` table (`{"estimator": {"k_df": 1.0}}`) or dotted
    /// keys (`{"estimator.disturbance_feedback.k_df": 1.0}`). Any other key raises `ConfigError` naming it; a
    /// table of the simulator's configuration (`motor`, `simulation`, …) names the functions
    /// that take it (`function` is the caller's name, `estimate`).
    pub fn from_argument(
        py: Python<'_>,
        config: Option<&Bound<'_, PyAny>>,
        function: &str,
    ) -> PyResult<Self> {
        let Some(config) = config.filter(|c| !c.is_none()) else {
            return Ok(Self::default());
        };
        if let Ok(c) = config.cast::<PyEstimatorConfig>() {
            return Ok(c.get().clone());
        }
        let Ok(dict) = config.cast::<PyDict>() else {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "config must be a fado.EstimatorConfig, a dict or None, got {}",
                config.get_type().name()?
            )));
        };
        let fields = Self::field_names(py)?;
        let given = Given::new(py, &fields);
        let put = |path: &str, shown: &str, value| given.put(path, shown, value);
        for (key, value) in dict.iter() {
            let key: String = key.extract()?;
            if key == SECTION {
                let Ok(table) = value.cast::<PyDict>() else {
                    return Err(config_error_message(
                        py,
                        SECTION,
                        format!("`{SECTION}` must be a table (dict) of estimator settings"),
                    ));
                };
                for (k, v) in table.iter() {
                    let k: String = k.extract()?;
                    put(&k, &format!("{SECTION}.{k}"), v)?;
                }
            } else if let Some(k) = key.strip_prefix("estimator.") {
                put(k, &key, value)?;
            } else if fields
                .iter()
                .any(|f| Some(f.as_str()) == key.split('.').next())
                || moved(&key).is_some()
            {
                put(&key, &key, value)?;
            } else if value.cast::<PyDict>().is_ok() || key.contains('.') {
                // Another table of a simulator configuration: not this function's.
                let section = key.split('.').next().unwrap_or(&key);
                return Err(config_error_message(
                    py,
                    &key,
                    not_used(function, &key, section),
                ));
            } else {
                put(&key, &key, value)?;
            }
        }
        let (kwargs, shown_as) = (&given.kwargs, &given.shown_as);
        let shown = |field: &str| -> String {
            shown_as
                .get_item(field)
                .ok()
                .flatten()
                .and_then(|s| s.extract::<String>().ok())
                .unwrap_or_else(|| field.to_owned())
        };
        let made = Self::default().with_changes(py, Some(kwargs), &shown);
        made.map_err(|e| renamed(py, e, shown_as))
    }
}

/// The fields of a config dict (a nested record as a dict of its fields) and the key as the
/// user wrote each (`field` or `field.sub` → `estimator.field.sub`, …).
struct Given<'py, 'a> {
    kwargs: Bound<'py, PyDict>,
    shown_as: Bound<'py, PyDict>,
    fields: &'a [String],
}

impl<'py, 'a> Given<'py, 'a> {
    fn new(py: Python<'py>, fields: &'a [String]) -> Self {
        Self {
            kwargs: PyDict::new(py),
            shown_as: PyDict::new(py),
            fields,
        }
    }

    /// Puts `value` at `path` (`field`, or `field.sub` of a nested record; a `dict` for
    /// `field` gives several of its fields), written by the user as `shown`. A key that is
    /// no field, that moved, or that is given twice raises `ConfigError` naming `shown`.
    fn put(&self, path: &str, shown: &str, value: Bound<'py, PyAny>) -> PyResult<()> {
        let py = self.kwargs.py();
        let (field, sub) = match path.split_once('.') {
            Some((f, s)) => (f, Some(s)),
            None => (path, None),
        };
        let moved_error = || moved(path).map(|new| moved_message(shown, path, new));
        if !self.fields.iter().any(|f| f == field) {
            let message = moved_error().unwrap_or_else(|| {
                format!(
                    "`{shown}` is not an estimator setting{}; one of {:?}",
                    crate::elsewhere::hint(
                        py,
                        field,
                        "EstimatorConfig",
                        self.fields.iter().map(String::as_str)
                    ),
                    self.fields
                )
            });
            return Err(config_error_message(py, shown, message));
        }
        let twice = || config_error_message(py, shown, format!("`{shown}` given twice"));
        let (kwargs, shown_as) = (&self.kwargs, &self.shown_as);
        match (sub, value.cast::<PyDict>()) {
            (None, Ok(table)) => {
                for (k, v) in table.iter() {
                    let k: String = k.extract()?;
                    put_sub(kwargs, shown_as, field, &k, &format!("{shown}.{k}"), v)
                        .map_err(|_| twice())?;
                }
            }
            (Some(k), _) => {
                put_sub(kwargs, shown_as, field, k, shown, value).map_err(|_| twice())?
            }
            (None, Err(_)) => {
                if let Some(message) = moved_error() {
                    return Err(config_error_message(py, shown, message));
                }
                if kwargs.contains(field)? {
                    return Err(twice());
                }
                shown_as.set_item(field, shown)?;
                kwargs.set_item(field, value)?;
            }
        }
        Ok(())
    }
}

/// Puts `value` as field `sub` of the nested record `field` of `kwargs`, shown as `shown`;
/// an error when it is there already.
fn put_sub<'py>(
    kwargs: &Bound<'py, PyDict>,
    shown_as: &Bound<'py, PyDict>,
    field: &str,
    sub: &str,
    shown: &str,
    value: Bound<'py, PyAny>,
) -> PyResult<()> {
    let py = kwargs.py();
    let table = match kwargs.get_item(field)? {
        Some(t) => t.cast_into::<PyDict>()?,
        None => {
            let t = PyDict::new(py);
            kwargs.set_item(field, &t)?;
            t
        }
    };
    if table.contains(sub)? {
        return Err(pyo3::exceptions::PyKeyError::new_err(shown.to_owned()));
    }
    shown_as.set_item(format!("{field}.{sub}"), shown)?;
    table.set_item(sub, value)
}

/// Where the flat key `key` of earlier configurations lives now (`fado_core`'s table), as a
/// path below the estimator's tuning (`lock.heal_time`).
fn moved(key: &str) -> Option<&'static str> {
    MOVED_KEYS
        .iter()
        .find(|(old, _)| *old == key)
        .map(|(_, new)| *new)
}

/// The message for the flat key `key` (shown as `shown`) that lives at `path` now.
fn moved_message(shown: &str, key: &str, path: &str) -> String {
    let (table, field) = path.split_once('.').unwrap_or((path, ""));
    let prefix = shown.strip_suffix(key).unwrap_or("");
    format!(
        "`{shown}` belongs in `{prefix}{table}`: write it as `{prefix}{table}={{\"{field}\": …}}` (or `{prefix}{path}`)"
    )
}

/// Refuses a flat keyword of earlier configurations (`k_df=`) with its new place; a nested
/// record given as a dict (`rs_adaptation={...}`) is no flat key.
fn refuse_moved(changes: &Bound<'_, PyDict>, shown: &dyn Fn(&str) -> String) -> PyResult<()> {
    for (key, value) in changes.iter() {
        let key: String = key.extract()?;
        if value.cast::<PyDict>().is_ok() {
            continue;
        }
        if let Some(path) = moved(&key) {
            let name = shown(&key);
            return Err(pyo3::exceptions::PyTypeError::new_err(moved_message(
                &name, &key, path,
            )));
        }
    }
    Ok(())
}

/// A refusal of fado-core, whose errors name the flat keys, named by the nested path
/// (`lock.heal_time`).
pub(crate) fn core_error(py: Python<'_>, e: fado_core::ConfigError) -> PyErr {
    let field = e.field();
    match moved(field) {
        Some(path) => config_error_message(
            py,
            path,
            e.to_string()
                .replacen(&format!("`{field}`"), &format!("`{path}`"), 1),
        ),
        None => config_error(py, e),
    }
}

/// Why `key` (of the simulator's table `section`) is refused by `function` (`estimate`,
/// `Estimator`), which takes only the estimator's settings, and which functions take it.
fn not_used(function: &str, key: &str, section: &str) -> String {
    let takers = match section {
        "motor" | "model" => {
            "the machine is this function's `machine=` argument (a fado.Machine, a preset name or \
             a dict of Machine fields); a `motor` table is the plant of fado.simulate, \
             fado.sweep and fado.commission"
        }
        "simulation" | "speed_reference" | "inverter" | "current_sensor" | "dc_link_sensor"
        | "load" | "controller" | "baselines" | "mismatch" | "inverter_model" | "faults" => {
            "it is a table of the simulator's configuration, which fado.simulate, fado.sweep and \
             fado.commission take"
        }
        _ => "it is no table fado knows",
    };
    format!(
        "`{key}` is not used by fado.{function}, whose config takes the estimator's settings \
         only (flat, an `estimator` table or `estimator.` keys): {takers}"
    )
}

/// A `ConfigError` on a field the user gave as `estimator.<field>` (nested or dotted), named
/// that way; any other error unchanged.
fn renamed(py: Python<'_>, err: PyErr, shown_as: &Bound<'_, PyDict>) -> PyErr {
    let value = err.value(py);
    let field = match value.getattr("field").and_then(|f| f.extract::<String>()) {
        Ok(f) => f,
        Err(_) => return err,
    };
    let shown = match shown_as.get_item(&field) {
        Ok(Some(s)) => s.extract::<String>().unwrap_or_else(|_| field.clone()),
        _ => return err,
    };
    if shown == field {
        return err;
    }
    let message = value
        .str()
        .map(|m| {
            m.to_string()
                .replacen(&format!("`{field}`"), &format!("`{shown}`"), 1)
        })
        .unwrap_or_default();
    config_error_message(py, &shown, message)
}
