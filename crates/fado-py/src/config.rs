//! `fado.EstimatorConfig`: the estimator's tuning (`fado_core::EstimatorTuning`) with keyword
//! arguments.
//!
//! The Python class mirrors `fado_core::EstimatorTuning<f64>` field by field (the conversions
//! below are exhaustive struct literals, so a field added in the core fails to compile here
//! until it is exposed). The machine and the sampling period are not part of it: they are
//! `fado.Machine` and the `ts` argument of `fado.Estimator`/`fado.estimate`. Every default is
//! the Rust one; a refusal raises `fado.ConfigError` (a `ValueError`) naming the field.
//!
//! A tuning on its own is checked for what it alone decides (finite, signs, order of the
//! thresholds, hold ratio below 1, …): [`PyEstimatorConfig::check`] validates it around the
//! paper's motor at a sampling period so short that no rate limit binds. The limits that
//! depend on the sampling period and the motor (k_af·ts ≤ 1, bandwidths and the mode
//! threshold below the Nyquist frequency) are checked when an estimator is built with them.

use fado_core::tracker::BandwidthDefinition;
use fado_core::{EstimatorConfig, EstimatorTuning, MachineModel};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::errors::{config_error, config_error_message};
use crate::scalar::Scalar;

/// The spelling of [`BandwidthDefinition::Minus3Db`] (as in TOML: serde's snake case).
pub const MINUS_3DB: &str = "minus3_db";
/// The spelling of [`BandwidthDefinition::NaturalFrequency`] (as in TOML).
pub const NATURAL: &str = "natural_frequency";

/// Sampling period at which a tuning alone is checked: short enough (1 ns) that no limit
/// tied to the sampling rate binds for any plausible gain or bandwidth.
const CHECK_TS: f64 = 1e-9;

fn bandwidth_name(definition: BandwidthDefinition) -> &'static str {
    match definition {
        BandwidthDefinition::Minus3Db => MINUS_3DB,
        BandwidthDefinition::NaturalFrequency => NATURAL,
    }
}

fn parse_bandwidth(py: Python<'_>, name: &str) -> PyResult<BandwidthDefinition> {
    match name {
        MINUS_3DB => Ok(BandwidthDefinition::Minus3Db),
        NATURAL => Ok(BandwidthDefinition::NaturalFrequency),
        _ => Err(config_error_message(
            py,
            "bandwidth_definition",
            format!("`bandwidth_definition` must be '{MINUS_3DB}' or '{NATURAL}', got {name:?}"),
        )),
    }
}

/// Declares the Python class from one list of fields, so that the constructor, `replace`,
/// `to_dict`, `__repr__` and pickling can never disagree about which fields exist.
macro_rules! config_class {
    ($($(#[doc = $doc:literal])* $field:ident: $ty:ty,)*) => {
        /// Tuning of the sensorless estimator (paper, Fig. 5; SPEC §1–§3): everything but the
        /// machine and the sampling period.
        ///
        /// Every argument is keyword-only and optional: an omitted one takes the Rust default
        /// (`EstimatorConfig()` shows them all; speeds are ratios of the
        /// machine's rated electrical frequency). Instances are immutable; `replace(**changes)`
        /// returns a modified copy. Invalid values raise `fado.ConfigError` (a `ValueError`)
        /// whose `.field` names the field.
        #[pyclass(name = "EstimatorConfig", module = "fado", frozen, eq, get_all)]
        #[derive(Clone, Debug, PartialEq)]
        pub struct PyEstimatorConfig {
            $($(#[doc = $doc])* pub $field: $ty,)*
        }

        impl PyEstimatorConfig {
            /// The field names, in declaration order.
            pub const FIELDS: &'static [&'static str] = &[$(stringify!($field)),*];

            #[allow(clippy::too_many_arguments)] // one keyword per field
            fn with_changes(&self, py: Python<'_>, $($field: Option<$ty>),*) -> PyResult<Self> {
                let changed = Self {
                    $($field: $field.unwrap_or_else(|| self.$field.clone()),)*
                };
                // Validated, and with the bandwidth definition in its canonical spelling.
                changed.check(py)?;
                Ok(changed)
            }

            fn items<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                let dict = PyDict::new(py);
                $(dict.set_item(stringify!($field), self.$field.clone())?;)*
                Ok(dict)
            }
        }

        #[pymethods]
        impl PyEstimatorConfig {
            #[allow(clippy::too_many_arguments)] // one keyword per field
            #[new]
            #[pyo3(signature = (*, $($field = None),*))]
            fn py_new(py: Python<'_>, $($field: Option<$ty>),*) -> PyResult<Self> {
                Self::default().with_changes(py, $($field),*)
            }

            #[allow(clippy::too_many_arguments)] // one keyword per field
            /// A copy with the given fields changed (validated like the constructor).
            #[pyo3(signature = (*, $($field = None),*))]
            fn replace(&self, py: Python<'_>, $($field: Option<$ty>),*) -> PyResult<Self> {
                self.with_changes(py, $($field),*)
            }

            /// The fields as a plain `dict` (`EstimatorConfig(**config.to_dict())` round-trips).
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                self.items(py)
            }

            fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
                let items = self.items(py)?;
                let mut parts = Vec::with_capacity(Self::FIELDS.len());
                for (key, value) in items.iter() {
                    parts.push(format!("{}={}", key.str()?, value.repr()?));
                }
                Ok(format!("EstimatorConfig({})", parts.join(", ")))
            }

            /// Pickling: rebuilt through the keyword constructor.
            fn __getnewargs_ex__<'py>(
                &self,
                py: Python<'py>,
            ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
                Ok((PyTuple::empty(py), self.items(py)?))
            }

            /// The names of the fields, in order.
            #[classattr]
            fn fields(py: Python<'_>) -> PyResult<Bound<'_, PyTuple>> {
                PyTuple::new(py, Self::FIELDS)
            }
        }
    };
}

config_class! {
    /// Disturbance feedback gain k_df in 1/s (Fig. 3), at most 1/ts.
    k_df: f64,
    /// Ramp time of k_df on activation in s (0 = abrupt, as in the paper).
    k_df_ramp_time: f64,
    /// Limiter gain k_af in 1/s (Fig. 6), at most 1/ts.
    k_af: f64,
    /// Limiter radius as a multiple of λ̂f (at least 1).
    limiter_radius_ratio: f64,
    /// Speed threshold between limiter and k_df feedback as a fraction of the machine's rated
    /// electrical frequency (0.015: the paper's 1.5 Hz of its 100 Hz).
    mode_threshold_ratio: f64,
    /// Hysteresis half-band of the threshold as a fraction of the rated electrical frequency.
    mode_hysteresis_ratio: f64,
    /// Bandwidth of T2S-1 (angle and observer speed) in Hz.
    t2s1_bandwidth_hz: f64,
    /// Bandwidth of T2S-2 (speed for control) in Hz.
    t2s2_bandwidth_hz: f64,
    /// Damping ratio of both trackers.
    tracker_damping: f64,
    /// Meaning of the tracker bandwidths: 'minus3_db' or 'natural_frequency' (as in TOML).
    bandwidth_definition: String,
    /// Trackers coast while |λ̂r| is below this fraction of λ̂f.
    tracker_hold_ratio: f64,
    /// Average the current over the interval for the resistive drop.
    average_current: bool,
    /// Feed the disturbance observer with λ1 − L̂q·i instead of the paper's λ1 (our
    /// improvement, default true; false is the paper's Fig. 5).
    observer_on_rotor_flux: bool,
    /// Adapt R̂s online (our extension; false = the paper's fixed R̂s).
    rs_adaptation: bool,
    /// Rate γ of the R̂s adaptation while turning, in 1/s.
    rs_adaptation_rate: f64,
    /// Excitation floor χ0 of the R̂s adaptation.
    rs_adaptation_excitation_floor: f64,
    /// Lower bound of the adapted R̂s as a multiple of the machine's `rs`.
    rs_adaptation_min_ratio: f64,
    /// Upper bound of the adapted R̂s as a multiple of the machine's `rs`.
    rs_adaptation_max_ratio: f64,
    /// With `rs_adaptation`: rate of the λ̂f learning where R̂s is unobservable, in 1/s
    /// (0 = fixed λ̂f).
    flux_linkage_adaptation_rate: f64,
    /// With `rs_adaptation`: rate of the integrand-offset (voltage-offset) estimate while
    /// turning, in 1/s (0 = off).
    offset_adaptation_rate: f64,
    /// In limiter mode, re-centre the common mode of λ1 and D̂ (our improvement, default
    /// true; false is the paper).
    limiter_recentring: bool,
    /// Samples with an α-β current component beyond ± this × the rated current are refused like non-finite ones.
    plausible_current_ratio: f64,
    /// Samples with an α-β voltage component beyond ± this × the DC-link voltage are refused.
    plausible_voltage_ratio: f64,
    /// A current moving more than this × (plausible voltage)·ts/L̂q per sample is refused (0 = off).
    plausible_current_step_ratio: f64,
    /// Loss of lock: |λ̂r|/λ̂f below this is a symptom.
    lock_flux_low_ratio: f64,
    /// Loss of lock: |λ̂r|/λ̂f above this is a symptom.
    lock_flux_high_ratio: f64,
    /// Loss of lock: a T2S-1 innovation above this (rad) is a symptom.
    lock_innovation_limit: f64,
    /// Loss of lock: net symptomatic time (s) before `lock` = 2 (0 = detector off).
    lock_detection_time: f64,
    /// Loss of lock: limiter clamping in limiter mode is a symptom.
    lock_limiter_clamping: bool,
}

impl Default for PyEstimatorConfig {
    fn default() -> Self {
        Self::from_core(&EstimatorTuning::default())
    }
}

impl PyEstimatorConfig {
    /// The Python view of a core tuning.
    pub fn from_core(c: &EstimatorTuning<f64>) -> Self {
        Self {
            k_df: c.k_df,
            k_df_ramp_time: c.k_df_ramp_time,
            k_af: c.k_af,
            limiter_radius_ratio: c.limiter_radius_ratio,
            mode_threshold_ratio: c.mode_threshold_ratio,
            mode_hysteresis_ratio: c.mode_hysteresis_ratio,
            t2s1_bandwidth_hz: c.t2s1_bandwidth_hz,
            t2s2_bandwidth_hz: c.t2s2_bandwidth_hz,
            tracker_damping: c.tracker_damping,
            bandwidth_definition: bandwidth_name(c.bandwidth_definition).to_owned(),
            tracker_hold_ratio: c.tracker_hold_ratio,
            average_current: c.average_current,
            observer_on_rotor_flux: c.observer_on_rotor_flux,
            rs_adaptation: c.rs_adaptation,
            rs_adaptation_rate: c.rs_adaptation_rate,
            rs_adaptation_excitation_floor: c.rs_adaptation_excitation_floor,
            rs_adaptation_min_ratio: c.rs_adaptation_min_ratio,
            rs_adaptation_max_ratio: c.rs_adaptation_max_ratio,
            flux_linkage_adaptation_rate: c.flux_linkage_adaptation_rate,
            offset_adaptation_rate: c.offset_adaptation_rate,
            limiter_recentring: c.limiter_recentring,
            plausible_current_ratio: c.plausible_current_ratio,
            plausible_voltage_ratio: c.plausible_voltage_ratio,
            plausible_current_step_ratio: c.plausible_current_step_ratio,
            lock_flux_low_ratio: c.lock_flux_low_ratio,
            lock_flux_high_ratio: c.lock_flux_high_ratio,
            lock_innovation_limit: c.lock_innovation_limit,
            lock_detection_time: c.lock_detection_time,
            lock_limiter_clamping: c.lock_limiter_clamping,
        }
    }

    /// The core tuning in scalar type `T` (not validated: see [`Self::check`] and
    /// [`Self::estimator_config`]).
    pub fn to_core_as<T: Scalar>(&self, py: Python<'_>) -> PyResult<EstimatorTuning<T>> {
        Ok(EstimatorTuning {
            k_df: T::lit(self.k_df),
            k_df_ramp_time: T::lit(self.k_df_ramp_time),
            k_af: T::lit(self.k_af),
            limiter_radius_ratio: T::lit(self.limiter_radius_ratio),
            mode_threshold_ratio: T::lit(self.mode_threshold_ratio),
            mode_hysteresis_ratio: T::lit(self.mode_hysteresis_ratio),
            t2s1_bandwidth_hz: T::lit(self.t2s1_bandwidth_hz),
            t2s2_bandwidth_hz: T::lit(self.t2s2_bandwidth_hz),
            tracker_damping: T::lit(self.tracker_damping),
            bandwidth_definition: parse_bandwidth(py, &self.bandwidth_definition)?,
            tracker_hold_ratio: T::lit(self.tracker_hold_ratio),
            average_current: self.average_current,
            observer_on_rotor_flux: self.observer_on_rotor_flux,
            rs_adaptation: self.rs_adaptation,
            rs_adaptation_rate: T::lit(self.rs_adaptation_rate),
            rs_adaptation_excitation_floor: T::lit(self.rs_adaptation_excitation_floor),
            rs_adaptation_min_ratio: T::lit(self.rs_adaptation_min_ratio),
            rs_adaptation_max_ratio: T::lit(self.rs_adaptation_max_ratio),
            flux_linkage_adaptation_rate: T::lit(self.flux_linkage_adaptation_rate),
            offset_adaptation_rate: T::lit(self.offset_adaptation_rate),
            limiter_recentring: self.limiter_recentring,
            plausible_current_ratio: T::lit(self.plausible_current_ratio),
            plausible_voltage_ratio: T::lit(self.plausible_voltage_ratio),
            plausible_current_step_ratio: T::lit(self.plausible_current_step_ratio),
            lock_flux_low_ratio: T::lit(self.lock_flux_low_ratio),
            lock_flux_high_ratio: T::lit(self.lock_flux_high_ratio),
            lock_innovation_limit: T::lit(self.lock_innovation_limit),
            lock_detection_time: T::lit(self.lock_detection_time),
            lock_limiter_clamping: self.lock_limiter_clamping,
        })
    }

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
            tuning: self.to_core_as(py)?,
        };
        config.validate().map_err(|e| config_error(py, e))?;
        Ok(config)
    }
}

/// The section of a simulator configuration that is the estimator's tuning.
const SECTION: &str = "estimator";

impl PyEstimatorConfig {
    /// `config` as given to `fado.estimate`/`fado.Estimator`: `None` (the defaults), an
    /// `EstimatorConfig`, or a `dict` as `fado.simulate` takes it: flat tuning keys
    /// (`{"k_df": 1.0}`), the `[estimator]` table (`{"estimator": {"k_df": 1.0}}`) or dotted
    /// keys (`{"estimator.k_df": 1.0}`). The other tables of a simulator configuration
    /// (`simulation`, `controller`, …) do not concern the estimator and are skipped; any other
    /// key raises `ConfigError` naming it.
    pub fn from_argument(py: Python<'_>, config: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
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
        let kwargs = PyDict::new(py);
        // The key as the user wrote it, for each field given.
        let shown_as = PyDict::new(py);
        let put = |key: &str, shown: &str, value: Bound<'_, PyAny>| -> PyResult<()> {
            if !Self::FIELDS.contains(&key) {
                return Err(config_error_message(
                    py,
                    shown,
                    format!(
                        "`{shown}` is not an estimator setting; one of {:?}",
                        Self::FIELDS
                    ),
                ));
            }
            if kwargs.contains(key)? {
                return Err(config_error_message(
                    py,
                    shown,
                    format!("`{shown}` given twice"),
                ));
            }
            shown_as.set_item(key, shown)?;
            kwargs.set_item(key, value)
        };
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
            } else if value.cast::<PyDict>().is_ok() || key.contains('.') {
                // Another table of a simulator configuration: not the estimator's.
                continue;
            } else {
                put(&key, &key, value)?;
            }
        }
        let made = py
            .get_type::<PyEstimatorConfig>()
            .call((), Some(&kwargs))
            .map_err(|e| renamed(py, e, &shown_as))?
            .cast_into::<PyEstimatorConfig>()?;
        Ok(made.get().clone())
    }
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
