//! `fado.EstimatorConfig`: the flat estimator configuration with keyword arguments.
//!
//! The Python class mirrors `fado_core::EstimatorConfig<f64>` field by field (the conversions
//! below are exhaustive struct literals, so a field added in the core fails to compile here
//! until it is exposed). Every default is the Rust one; validation is the Rust one, and a
//! refusal raises `fado.ConfigError` (a `ValueError`) naming the field.

use fado_core::EstimatorConfig;
use fado_core::tracker::BandwidthDefinition;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::errors::{config_error, config_error_message};
use crate::scalar::Scalar;

/// The spelling of [`BandwidthDefinition::Minus3Db`] in Python.
pub const MINUS_3DB: &str = "-3dB";
/// The spelling of [`BandwidthDefinition::NaturalFrequency`] in Python.
pub const NATURAL: &str = "natural";

fn bandwidth_name(definition: BandwidthDefinition) -> &'static str {
    match definition {
        BandwidthDefinition::Minus3Db => MINUS_3DB,
        BandwidthDefinition::NaturalFrequency => NATURAL,
    }
}

fn parse_bandwidth(py: Python<'_>, name: &str) -> PyResult<BandwidthDefinition> {
    if name.eq_ignore_ascii_case(MINUS_3DB) {
        Ok(BandwidthDefinition::Minus3Db)
    } else if name.eq_ignore_ascii_case(NATURAL) {
        Ok(BandwidthDefinition::NaturalFrequency)
    } else {
        Err(config_error_message(
            py,
            "bandwidth_definition",
            format!("`bandwidth_definition` must be '{MINUS_3DB}' or '{NATURAL}', got {name:?}"),
        ))
    }
}

/// Declares the Python class from one list of fields, so that the constructor, `replace`,
/// `to_dict`, `__repr__` and pickling can never disagree about which fields exist.
macro_rules! config_class {
    ($($(#[doc = $doc:literal])* $field:ident: $ty:ty,)*) => {
        /// Configuration of the sensorless estimator (paper, Fig. 5; SPEC §1–§3).
        ///
        /// Every argument is keyword-only and optional: an omitted one takes the Rust default
        /// (`EstimatorConfig()` shows them all). Instances are immutable; `replace(**changes)`
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
                Ok(Self::from_core(&changed.to_core(py)?))
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
    /// Sampling period Ts in s (paper, V: 10 kHz).
    ts: f64,
    /// Stator resistance estimate R̂s in Ω.
    rs_hat: f64,
    /// q-axis inductance estimate L̂q in H.
    lq_hat: f64,
    /// Magnet flux linkage estimate λ̂f in Wb (limiter radius, hold level, start-up flux).
    flux_linkage_hat: f64,
    /// Disturbance feedback gain k_df in 1/s (Fig. 3).
    k_df: f64,
    /// Ramp time of k_df on activation in s (0 = abrupt, as in the paper).
    k_df_ramp_time: f64,
    /// Limiter gain k_af in 1/s (Fig. 6).
    k_af: f64,
    /// Limiter radius as a multiple of λ̂f.
    limiter_radius_ratio: f64,
    /// Speed threshold between limiter and k_df feedback in Hz electrical.
    mode_threshold_hz: f64,
    /// Hysteresis half-band of the threshold in Hz.
    mode_hysteresis_hz: f64,
    /// Bandwidth of T2S-1 (angle and observer speed) in Hz.
    t2s1_bandwidth_hz: f64,
    /// Bandwidth of T2S-2 (speed for control) in Hz.
    t2s2_bandwidth_hz: f64,
    /// Damping ratio of both trackers.
    tracker_damping: f64,
    /// Meaning of the tracker bandwidths: '-3dB' or 'natural'.
    bandwidth_definition: String,
    /// Trackers coast while |λ̂r| is below this fraction of λ̂f.
    tracker_hold_ratio: f64,
    /// Average the current over the interval for the resistive drop.
    average_current: bool,
    /// Feed the disturbance observer with λ1 − L̂q·i instead of the paper's λ1 (our
    /// improvement, default true; false is the paper's Fig. 5).
    observer_on_rotor_flux: bool,
    /// In limiter mode, re-centre the common mode of λ1 and D̂ (our improvement, default
    /// true; false is the paper).
    limiter_recentring: bool,
    /// Rotor angle assumed at reset in rad (electrical).
    initial_angle: f64,
    /// Adapt R̂s online (our extension; false = the paper's fixed R̂s).
    rs_adaptation: bool,
    /// Rate γ of the R̂s adaptation while turning, in 1/s.
    rs_adaptation_rate: f64,
    /// Excitation floor χ0 of the R̂s adaptation.
    rs_adaptation_excitation_floor: f64,
    /// Lower bound of the adapted R̂s as a multiple of `rs_hat`.
    rs_adaptation_min_ratio: f64,
    /// Upper bound of the adapted R̂s as a multiple of `rs_hat`.
    rs_adaptation_max_ratio: f64,
    /// With `rs_adaptation`: rate of the λ̂f learning where R̂s is unobservable, in 1/s
    /// (0 = fixed λ̂f).
    flux_linkage_adaptation_rate: f64,
}

impl Default for PyEstimatorConfig {
    fn default() -> Self {
        Self::from_core(&EstimatorConfig::default())
    }
}

impl PyEstimatorConfig {
    /// The Python view of a core configuration.
    pub fn from_core(c: &EstimatorConfig<f64>) -> Self {
        Self {
            ts: c.ts,
            rs_hat: c.rs_hat,
            lq_hat: c.lq_hat,
            flux_linkage_hat: c.flux_linkage_hat,
            k_df: c.k_df,
            k_df_ramp_time: c.k_df_ramp_time,
            k_af: c.k_af,
            limiter_radius_ratio: c.limiter_radius_ratio,
            mode_threshold_hz: c.mode_threshold_hz,
            mode_hysteresis_hz: c.mode_hysteresis_hz,
            t2s1_bandwidth_hz: c.t2s1_bandwidth_hz,
            t2s2_bandwidth_hz: c.t2s2_bandwidth_hz,
            tracker_damping: c.tracker_damping,
            bandwidth_definition: bandwidth_name(c.bandwidth_definition).to_owned(),
            tracker_hold_ratio: c.tracker_hold_ratio,
            average_current: c.average_current,
            observer_on_rotor_flux: c.observer_on_rotor_flux,
            limiter_recentring: c.limiter_recentring,
            initial_angle: c.initial_angle,
            rs_adaptation: c.rs_adaptation,
            rs_adaptation_rate: c.rs_adaptation_rate,
            rs_adaptation_excitation_floor: c.rs_adaptation_excitation_floor,
            rs_adaptation_min_ratio: c.rs_adaptation_min_ratio,
            rs_adaptation_max_ratio: c.rs_adaptation_max_ratio,
            flux_linkage_adaptation_rate: c.flux_linkage_adaptation_rate,
        }
    }

    /// The core configuration in scalar type `T`, validated for that type (a value that is
    /// fine in f64 can still underflow or overflow in f32).
    pub fn to_core_as<T: Scalar>(&self, py: Python<'_>) -> PyResult<EstimatorConfig<T>> {
        let config = EstimatorConfig {
            ts: T::lit(self.ts),
            rs_hat: T::lit(self.rs_hat),
            lq_hat: T::lit(self.lq_hat),
            flux_linkage_hat: T::lit(self.flux_linkage_hat),
            k_df: T::lit(self.k_df),
            k_df_ramp_time: T::lit(self.k_df_ramp_time),
            k_af: T::lit(self.k_af),
            limiter_radius_ratio: T::lit(self.limiter_radius_ratio),
            mode_threshold_hz: T::lit(self.mode_threshold_hz),
            mode_hysteresis_hz: T::lit(self.mode_hysteresis_hz),
            t2s1_bandwidth_hz: T::lit(self.t2s1_bandwidth_hz),
            t2s2_bandwidth_hz: T::lit(self.t2s2_bandwidth_hz),
            tracker_damping: T::lit(self.tracker_damping),
            bandwidth_definition: parse_bandwidth(py, &self.bandwidth_definition)?,
            tracker_hold_ratio: T::lit(self.tracker_hold_ratio),
            average_current: self.average_current,
            observer_on_rotor_flux: self.observer_on_rotor_flux,
            limiter_recentring: self.limiter_recentring,
            initial_angle: T::lit(self.initial_angle),
            rs_adaptation: self.rs_adaptation,
            rs_adaptation_rate: T::lit(self.rs_adaptation_rate),
            rs_adaptation_excitation_floor: T::lit(self.rs_adaptation_excitation_floor),
            rs_adaptation_min_ratio: T::lit(self.rs_adaptation_min_ratio),
            rs_adaptation_max_ratio: T::lit(self.rs_adaptation_max_ratio),
            flux_linkage_adaptation_rate: T::lit(self.flux_linkage_adaptation_rate),
        };
        config.validate().map_err(|e| config_error(py, e))?;
        Ok(config)
    }

    /// The validated f64 core configuration.
    pub fn to_core(&self, py: Python<'_>) -> PyResult<EstimatorConfig<f64>> {
        self.to_core_as::<f64>(py)
    }
}
