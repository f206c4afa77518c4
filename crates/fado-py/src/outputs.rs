//! What the estimator reports, sample by sample (`StepResult`) and as arrays over a whole
//! recording (`EstimateResult`), from one list of output fields.
//!
//! Floats are in the estimator's arithmetic (float64 or float32 arrays; Python floats for a
//! single step), `mode` is an `int8` code ([`MODE_LIMITER`], [`MODE_DISTURBANCE_FEEDBACK`]),
//! `lock` an `int8` code (0 locked, 1 suspect, 2 lost: `fado_core::LockStatus`), the flags
//! are `bool`.

use fado_core::{Estimate, LockStatus, Mode, Real};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::scalar::Scalar;

/// `mode` code of [`Mode::Limiter`] (FLAG_limit high, Fig. 6).
pub const MODE_LIMITER: i8 = 0;
/// `mode` code of [`Mode::DisturbanceFeedback`] (k_df active, Fig. 3).
pub const MODE_DISTURBANCE_FEEDBACK: i8 = 1;

/// The `mode` code of a [`Mode`].
pub fn mode_code(mode: Mode) -> i8 {
    match mode {
        Mode::Limiter => MODE_LIMITER,
        Mode::DisturbanceFeedback => MODE_DISTURBANCE_FEEDBACK,
    }
}

/// An `int8` status code of the outputs.
pub trait Code {
    /// The code.
    fn code(self) -> i8;
}

impl Code for Mode {
    fn code(self) -> i8 {
        mode_code(self)
    }
}

impl Code for LockStatus {
    fn code(self) -> i8 {
        LockStatus::code(self) as i8
    }
}

macro_rules! outputs {
    (
        floats { $($(#[doc = $fdoc:literal])* $float:ident => $($fpath:ident).+,)* }
        codes { $($(#[doc = $mdoc:literal])* $mode:ident => $($mpath:ident).+,)* }
        flags { $($(#[doc = $bdoc:literal])* $flag:ident => $($bpath:ident).+,)* }
    ) => {
        /// The output field names, in order: floats, then the codes (`mode`, `lock`), then
        /// the flags.
        pub const OUTPUT_NAMES: &[&str] =
            &[$(stringify!($float),)* $(stringify!($mode),)* $(stringify!($flag),)*];

        /// One sample of the estimator's outputs and diagnostics (Fig. 5).
        #[pyclass(name = "StepResult", module = "fado", frozen, eq, get_all)]
        #[derive(Clone, Debug, PartialEq)]
        pub struct StepResult {
            $($(#[doc = $fdoc])* pub $float: f64,)*
            $($(#[doc = $mdoc])* pub $mode: i8,)*
            $($(#[doc = $bdoc])* pub $flag: bool,)*
        }

        impl StepResult {
            /// Flattens an estimate, widening its floats to f64 (exact for f32).
            pub fn from_estimate<T: Real>(e: &Estimate<T>) -> Self {
                Self {
                    $($float: e.$($fpath).+.to_f64(),)*
                    $($mode: Code::code(e.$($mpath).+),)*
                    $($flag: e.$($bpath).+,)*
                }
            }

            fn items<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                let dict = PyDict::new(py);
                $(dict.set_item(stringify!($float), self.$float)?;)*
                $(dict.set_item(stringify!($mode), self.$mode)?;)*
                $(dict.set_item(stringify!($flag), self.$flag)?;)*
                Ok(dict)
            }
        }

        /// The outputs of a recording, column by column, filled without the GIL.
        #[derive(Clone, Debug, Default, PartialEq)]
        pub struct Columns<T> {
            $($(#[doc = $fdoc])* pub $float: Vec<T>,)*
            $($(#[doc = $mdoc])* pub $mode: Vec<i8>,)*
            $($(#[doc = $bdoc])* pub $flag: Vec<bool>,)*
        }

        impl<T: Real> Columns<T> {
            /// Empty columns with room for `n` samples.
            pub fn with_capacity(n: usize) -> Self {
                Self {
                    $($float: Vec::with_capacity(n),)*
                    $($mode: Vec::with_capacity(n),)*
                    $($flag: Vec::with_capacity(n),)*
                }
            }

            /// Appends one sample.
            #[inline]
            pub fn push(&mut self, e: &Estimate<T>) {
                $(self.$float.push(e.$($fpath).+);)*
                $(self.$mode.push(Code::code(e.$($mpath).+));)*
                $(self.$flag.push(e.$($bpath).+);)*
            }

            /// Number of samples.
            pub fn len(&self) -> usize {
                self.theta.len()
            }

            /// True when no sample was pushed.
            pub fn is_empty(&self) -> bool {
                self.theta.is_empty()
            }
        }

        /// The estimator's outputs over a recording as numpy arrays, one per field of
        /// `StepResult` (floats in the estimator's dtype, `mode` and `lock` as int8, flags as
        /// bool).
        #[pyclass(name = "EstimateResult", module = "fado", frozen, get_all)]
        pub struct EstimateResult {
            $($(#[doc = $fdoc])* pub $float: Py<PyAny>,)*
            $($(#[doc = $mdoc])* pub $mode: Py<PyAny>,)*
            $($(#[doc = $bdoc])* pub $flag: Py<PyAny>,)*
            /// Sampling period Ts in s of the recording.
            pub ts: f64,
            /// The estimator's arithmetic: 'float64' or 'float32'.
            pub dtype: Py<PyString>,
        }

        impl EstimateResult {
            /// Hands the columns to numpy without copying them.
            pub fn from_columns<T: Scalar>(py: Python<'_>, c: Columns<T>, ts: f64) -> Self {
                Self {
                    $($float: PyArray1::from_vec(py, c.$float).into_any().unbind(),)*
                    $($mode: PyArray1::from_vec(py, c.$mode).into_any().unbind(),)*
                    $($flag: PyArray1::from_vec(py, c.$flag).into_any().unbind(),)*
                    ts,
                    dtype: PyString::new(py, T::DTYPE.name()).unbind(),
                }
            }

            fn items<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                let dict = PyDict::new(py);
                $(dict.set_item(stringify!($float), self.$float.bind(py))?;)*
                $(dict.set_item(stringify!($mode), self.$mode.bind(py))?;)*
                $(dict.set_item(stringify!($flag), self.$flag.bind(py))?;)*
                Ok(dict)
            }

            fn samples(&self, py: Python<'_>) -> PyResult<usize> {
                self.theta.bind(py).len()
            }
        }
    };
}

outputs! {
    floats {
        /// θ̂: estimated rotor angle in rad (electrical, in [−π, π]) from T2S-1.
        theta => theta,
        /// ω̂ of T2S-1 in rad/s (electrical): the speed fed back to the observer.
        omega => omega,
        /// ω̂ of T2S-2 in rad/s (electrical): the smoother speed for control.
        omega_control => omega_control,
        /// θm = ∠λ̂r, the directly calculated angle of eq. (6) before the T2S.
        theta_direct => diagnostics.theta_direct,
        /// λ1 α: the integrated stator flux (eq. (7), (21)) in Wb.
        lambda1_alpha => diagnostics.lambda1.alpha,
        /// λ1 β in Wb.
        lambda1_beta => diagnostics.lambda1.beta,
        /// D̂ α: the estimated disturbance (eq. (10)) in Wb.
        disturbance_alpha => diagnostics.disturbance.alpha,
        /// D̂ β in Wb.
        disturbance_beta => diagnostics.disturbance.beta,
        /// λ2 α = λ1 − D̂ (eq. (20)) in Wb.
        lambda2_alpha => diagnostics.lambda2.alpha,
        /// λ2 β in Wb.
        lambda2_beta => diagnostics.lambda2.beta,
        /// λ̂r α = λ2 − L̂q·i (eq. (5)) in Wb.
        lambda_r_alpha => diagnostics.lambda_r.alpha,
        /// λ̂r β in Wb.
        lambda_r_beta => diagnostics.lambda_r.beta,
        /// R̂s the integrator used in Ω (moves with `rs_adaptation`).
        rs_hat => diagnostics.rs_hat,
        /// The flux-magnitude reference λ̂f in Wb (moves with `rs_adaptation`).
        flux_linkage_hat => diagnostics.flux_linkage_hat,
    }
    codes {
        /// Active flux feedback: 0 = limiter (Fig. 6), 1 = disturbance feedback k_df (Fig. 3).
        mode => diagnostics.mode,
        /// Loss-of-lock status (`fado_core::lock`): 0 locked, 1 suspect, 2 lost (a live
        /// status: clears after `lock.heal_time` without symptoms, or at `align`/`reset`).
        lock => diagnostics.lock,
    }
    flags {
        /// FLAG_limit of Fig. 10: the limiter mode is active.
        flag_limit => diagnostics.flag_limit,
        /// The limiter pulled λ̂r back to its circle this sample.
        limiter_clamping => diagnostics.limiter_clamping,
        /// The trackers coasted because |λ̂r| was too small.
        tracker_hold => diagnostics.tracker_hold,
        /// The sample's inputs were non-finite or implausible (beyond `plausible_current`,
        /// `plausible_voltage` or the current-step bound) and were rejected (state unchanged,
        /// the other fields repeat the last good sample).
        input_fault => diagnostics.input_fault,
    }
}

#[pymethods]
impl StepResult {
    /// The fields as a plain `dict`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.items(py)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let mut parts = Vec::with_capacity(OUTPUT_NAMES.len());
        for (key, value) in self.items(py)?.iter() {
            parts.push(format!("{}={}", key.str()?, value.repr()?));
        }
        Ok(format!("StepResult({})", parts.join(", ")))
    }
}

#[pymethods]
impl EstimateResult {
    /// The output arrays as a plain `dict` of name → array (the arrays are shared, not copied).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.items(py)
    }

    /// The output names, in order.
    fn keys(&self) -> Vec<&'static str> {
        OUTPUT_NAMES.to_vec()
    }

    /// Sample times n·Ts in s, as float64.
    #[getter]
    fn time<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.samples(py)?;
        let ts = self.ts;
        Ok(PyArray1::from_iter(py, (0..n).map(|k| k as f64 * ts)))
    }

    /// A `pandas.DataFrame` with one column per output, indexed by time in s (needs the
    /// `pandas` extra).
    fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pandas = py.import("pandas")?;
        let index = pandas.call_method1("Index", (self.time(py)?,))?;
        index.setattr("name", "time_s")?;
        let kwargs = PyDict::new(py);
        kwargs.set_item("index", index)?;
        pandas.call_method("DataFrame", (self.items(py)?,), Some(&kwargs))
    }

    fn __getitem__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        self.items(py)?
            .get_item(name)?
            .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err(name.to_owned()))
    }

    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.samples(py)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "EstimateResult(samples={}, ts={}, dtype='{}')",
            self.samples(py)?,
            self.ts,
            self.dtype.bind(py)
        ))
    }
}
