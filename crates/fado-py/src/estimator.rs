//! `fado.Estimator` (sample by sample, or a chunk of samples at a time) and `fado.estimate`
//! (a whole recording in one call).

use fado_core::{Ab, SensorlessEstimator};
use numpy::{PyArrayDescr, PyArrayDescrMethods, dtype};
use pyo3::prelude::*;

use crate::config::PyEstimatorConfig;
use crate::errors::{config_error, input_error};
use crate::inputs::{ColumnSlice, Signals};
use crate::outputs::{EstimateResult, StepResult};
use crate::replay::replay;
use crate::scalar::{Dtype, Scalar};

impl<'a, 'py> FromPyObject<'a, 'py> for Dtype {
    type Error = PyErr;

    /// Anything `numpy.dtype()` understands that means float64 or float32.
    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let py = obj.py();
        let refuse = || {
            input_error(
                py,
                "dtype",
                format!(
                    "expected 'float64' or 'float32', got {}",
                    obj.repr()
                        .map(|r| r.to_string())
                        .unwrap_or_else(|_| "?".to_owned())
                ),
            )
        };
        let descr = PyArrayDescr::new(py, obj).map_err(|_| refuse())?;
        if descr.is_equiv_to(&dtype::<f64>(py)) {
            Ok(Dtype::Float64)
        } else if descr.is_equiv_to(&dtype::<f32>(py)) {
            Ok(Dtype::Float32)
        } else {
            Err(refuse())
        }
    }
}

/// The estimator in the arithmetic the user chose. Held once per Python object, so the
/// f32 variant's unused bytes do not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
enum Engine {
    F64(SensorlessEstimator<f64>),
    F32(SensorlessEstimator<f32>),
}

/// Runs `$body` with `$e` bound to the estimator, whatever its scalar type.
macro_rules! with_engine {
    ($engine:expr, $e:ident => $body:expr) => {
        match $engine {
            Engine::F64($e) => $body,
            Engine::F32($e) => $body,
        }
    };
}

impl Engine {
    fn new(py: Python<'_>, config: &PyEstimatorConfig, dtype: Dtype) -> PyResult<Self> {
        let engine = match dtype {
            Dtype::Float64 => Engine::F64(
                SensorlessEstimator::new(config.to_core_as(py)?)
                    .map_err(|e| config_error(py, e))?,
            ),
            Dtype::Float32 => Engine::F32(
                SensorlessEstimator::new(config.to_core_as(py)?)
                    .map_err(|e| config_error(py, e))?,
            ),
        };
        Ok(engine)
    }

    fn dtype(&self) -> Dtype {
        match self {
            Engine::F64(_) => Dtype::Float64,
            Engine::F32(_) => Dtype::Float32,
        }
    }

    fn step(&mut self, v_ab: [f64; 2], i_ab: [f64; 2]) -> StepResult {
        with_engine!(self, e => step_one(e, v_ab, i_ab))
    }

    fn align(&mut self, theta0: f64, i_ab: [f64; 2]) {
        with_engine!(self, e => align_one(e, theta0, i_ab))
    }

    /// Replays the signals with the GIL released.
    fn run(&mut self, py: Python<'_>, signals: &Signals<'_>, ts: f64) -> EstimateResult {
        let slices = signals.slices();
        with_engine!(self, e => {
            let columns = py.detach(|| run_slices(e, slices));
            EstimateResult::from_columns(py, columns, ts)
        })
    }
}

fn step_one<T: Scalar>(e: &mut SensorlessEstimator<T>, v: [f64; 2], i: [f64; 2]) -> StepResult {
    let out = e.step(
        Ab::new(T::lit(v[0]), T::lit(v[1])),
        Ab::new(T::lit(i[0]), T::lit(i[1])),
    );
    StepResult::from_estimate(&out)
}

fn align_one<T: Scalar>(e: &mut SensorlessEstimator<T>, theta0: f64, i: [f64; 2]) {
    e.align(T::lit(theta0), Ab::new(T::lit(i[0]), T::lit(i[1])));
}

fn run_slices<T: Scalar>(
    e: &mut SensorlessEstimator<T>,
    [va, vb, ia, ib]: [ColumnSlice<'_>; 4],
) -> crate::outputs::Columns<T> {
    let (va, vb, ia, ib) = (T::column(va), T::column(vb), T::column(ia), T::column(ib));
    replay(e, &va, &vb, &ia, &ib)
}

/// The sensorless estimator of Fig. 5 (SPEC §1), stepped one sample at a time with `step`
/// or a chunk at a time with `run`; the state carries over between calls.
///
/// `dtype='float32'` runs the single-precision estimator, as firmware would; inputs are
/// rounded to float32 and outputs widened back (exactly) to Python floats.
#[pyclass(name = "Estimator", module = "fado")]
pub struct PyEstimator {
    engine: Engine,
    config: Py<PyEstimatorConfig>,
}

#[pymethods]
impl PyEstimator {
    #[new]
    #[pyo3(signature = (config = None, *, dtype = Dtype::Float64), text_signature = "(config=None, *, dtype='float64')")]
    fn py_new(
        py: Python<'_>,
        config: Option<Bound<'_, PyEstimatorConfig>>,
        dtype: Dtype,
    ) -> PyResult<Self> {
        let config = match config {
            Some(c) => c.unbind(),
            None => Py::new(py, PyEstimatorConfig::default())?,
        };
        let engine = Engine::new(py, config.get(), dtype)?;
        Ok(Self { engine, config })
    }

    /// The configuration in use (read-only; `set_rs_hat` updates its `rs_hat`).
    #[getter]
    fn config(&self, py: Python<'_>) -> Py<PyEstimatorConfig> {
        self.config.clone_ref(py)
    }

    /// The arithmetic: 'float64' or 'float32'.
    #[getter]
    fn dtype(&self) -> &'static str {
        self.engine.dtype().name()
    }

    /// One sample: `v_alpha, v_beta` the voltage applied over the last sampling interval (V),
    /// `i_alpha, i_beta` the currents sampled now (A). A non-finite input is rejected: the
    /// state is untouched and the result repeats the last good one with `input_fault` set.
    fn step(&mut self, v_alpha: f64, v_beta: f64, i_alpha: f64, i_beta: f64) -> StepResult {
        self.engine.step([v_alpha, v_beta], [i_alpha, i_beta])
    }

    /// Steps through whole arrays (1-D, contiguous, float64 or float32, equal lengths) with the
    /// GIL released, continuing from the present state; returns every output as arrays.
    /// Other threads keep running meanwhile: they must not write to the input arrays, and
    /// using this estimator from another thread raises until the call returns.
    fn run(
        &mut self,
        py: Python<'_>,
        v_alpha: &Bound<'_, PyAny>,
        v_beta: &Bound<'_, PyAny>,
        i_alpha: &Bound<'_, PyAny>,
        i_beta: &Bound<'_, PyAny>,
    ) -> PyResult<EstimateResult> {
        let signals = Signals::new(v_alpha, v_beta, i_alpha, i_beta)?;
        let ts = self.config.get().ts;
        Ok(self.engine.run(py, &signals, ts))
    }

    /// Back to the start-up state at `config.initial_angle` with zero current.
    fn reset(&mut self) {
        with_engine!(&mut self.engine, e => e.reset())
    }

    /// Start-up at a known rotor angle `theta0` (rad, electrical) with the present current
    /// (SPEC §1 step 6): λ1 = λ̂f·e^{jθ0} + L̂q·i, D̂ = 0, θ̂ = θ0, ω̂ = 0, limiter mode.
    #[pyo3(signature = (theta0, i_alpha = 0.0, i_beta = 0.0))]
    fn align(&mut self, theta0: f64, i_alpha: f64, i_beta: f64) {
        self.engine.align(theta0, [i_alpha, i_beta]);
    }

    /// Enables or disables the k_df feedback regardless of speed (Fig. 9 switches it off).
    fn set_disturbance_feedback_enabled(&mut self, enabled: bool) {
        with_engine!(&mut self.engine, e => e.set_disturbance_feedback_enabled(enabled))
    }

    /// Replaces R̂s at run time (e.g. online resistance adaptation); raises `ConfigError` for
    /// a bad value and leaves the estimator unchanged.
    fn set_rs_hat(&mut self, py: Python<'_>, rs_hat: f64) -> PyResult<()> {
        match &mut self.engine {
            Engine::F64(e) => e.set_rs_hat(rs_hat),
            Engine::F32(e) => e.set_rs_hat(rs_hat as f32),
        }
        .map_err(|e| config_error(py, e))?;
        let mut updated = self.config.get().clone();
        updated.rs_hat = rs_hat;
        self.config = Py::new(py, updated)?;
        Ok(())
    }

    /// The last good result (the start-up state after `reset` or `align`).
    #[getter]
    fn last(&self) -> StepResult {
        with_engine!(&self.engine, e => StepResult::from_estimate(e.last()))
    }

    /// Number of samples rejected (non-finite input) since the last reset.
    #[getter]
    fn rejected_samples(&self) -> u32 {
        with_engine!(&self.engine, e => e.rejected_samples())
    }

    /// An independent copy of the estimator and its state.
    fn copy(&self, py: Python<'_>) -> Self {
        Self {
            engine: self.engine.clone(),
            config: self.config.clone_ref(py),
        }
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "Estimator({}, dtype='{}')",
            self.config.bind(py).repr()?,
            self.engine.dtype().name()
        ))
    }
}

/// Runs the estimator over a whole recording in Rust with the GIL released and returns every
/// output and diagnostic as numpy arrays (an `EstimateResult`).
///
/// `v_alpha, v_beta`: voltage applied over each sampling interval (V); `i_alpha, i_beta`:
/// currents sampled (A); 1-D contiguous float64 or float32 arrays of equal length.
/// `ts` overrides `config.ts`; `theta0` aligns the estimator at that angle with the first
/// current sample before the first step (otherwise it starts at `config.initial_angle`);
/// `dtype='float32'` runs the single-precision estimator. Bad arrays raise `InputError`,
/// bad settings `ConfigError` (both are `ValueError`s). The inputs are read in place, not
/// copied: other threads must not write to them during the call.
#[pyfunction]
#[pyo3(
    signature = (v_alpha, v_beta, i_alpha, i_beta, *, ts = None, config = None, theta0 = None, dtype = Dtype::Float64),
    text_signature = "(v_alpha, v_beta, i_alpha, i_beta, *, ts=None, config=None, theta0=None, dtype='float64')"
)]
#[allow(clippy::too_many_arguments)]
pub fn estimate(
    py: Python<'_>,
    v_alpha: &Bound<'_, PyAny>,
    v_beta: &Bound<'_, PyAny>,
    i_alpha: &Bound<'_, PyAny>,
    i_beta: &Bound<'_, PyAny>,
    ts: Option<f64>,
    config: Option<Bound<'_, PyEstimatorConfig>>,
    theta0: Option<f64>,
    dtype: Dtype,
) -> PyResult<EstimateResult> {
    let signals = Signals::new(v_alpha, v_beta, i_alpha, i_beta)?;
    let mut config = match config {
        Some(c) => c.get().clone(),
        None => PyEstimatorConfig::default(),
    };
    if let Some(ts) = ts {
        config.ts = ts;
    }
    let mut engine = Engine::new(py, &config, dtype)?;
    if let Some(theta0) = theta0 {
        let [_, _, ia, ib] = signals.slices();
        let first = |c: ColumnSlice<'_>| match c {
            ColumnSlice::F64(x) => x.first().copied().unwrap_or(0.0),
            ColumnSlice::F32(x) => x.first().map_or(0.0, |&v| f64::from(v)),
        };
        engine.align(theta0, [first(ia), first(ib)]);
    }
    Ok(engine.run(py, &signals, config.ts))
}
