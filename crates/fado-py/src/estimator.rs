//! `fado.Estimator` (sample by sample, or a chunk of samples at a time) and `fado.estimate`
//! (a whole recording in one call).

use std::sync::atomic::AtomicBool;

use fado_core::{Ab, SensorlessEstimator};
use numpy::{PyArrayDescr, PyArrayDescrMethods, dtype};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::config::PyEstimatorConfig;
use crate::errors::{config_error, input_error};
use crate::inputs::{ColumnSlice, Signals};
use crate::interrupt;
use crate::machine::PyMachine;
use crate::number::number;
use crate::outputs::{EstimateResult, StepResult};
use crate::replay::replay_until;
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

/// A scalar argument, refused naming it unless finite.
pub fn finite(py: Python<'_>, argument: &str, value: f64) -> PyResult<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(input_error(
            py,
            argument,
            format!("must be a finite number, got {value}"),
        ))
    }
}

/// What an estimator is built from: the machine, the tuning, the sampling period and the
/// start-up angle.
struct Setup {
    machine: PyMachine,
    tuning: PyEstimatorConfig,
    ts: f64,
    initial_angle: f64,
}

impl Setup {
    fn new(
        py: Python<'_>,
        function: &str,
        machine: Option<&Bound<'_, PyAny>>,
        config: Option<&Bound<'_, PyAny>>,
        ts: f64,
        initial_angle: f64,
    ) -> PyResult<Self> {
        let machine = PyMachine::from_argument(py, machine, "machine", function)?;
        let tuning = PyEstimatorConfig::from_argument(py, config, function)?;
        let ts = finite(py, "ts", ts)?;
        // The sampling period against the machine's rated speed (a period in ms given as
        // s is refused naming `ts`), before any gain derived from it is refused instead.
        if ts > 0.0 {
            crate::machine::check_plausible(py, &machine.to_core_with_map(), Some(ts))?;
        }
        Ok(Self {
            machine,
            tuning,
            ts,
            initial_angle,
        })
    }

    /// The core configuration; a machine's flux map becomes its model's magnetics.
    fn core<T: Scalar + 'static>(&self, py: Python<'_>) -> PyResult<fado_core::EstimatorConfig<T>> {
        let mut c = self.tuning.estimator_config(
            py,
            self.ts,
            &self.machine.to_core(),
            self.initial_angle,
        )?;
        if let Some(m) = self.machine.flux_map() {
            c.machine.magnetics = crate::flux_map::machine_magnetics(m).ok_or_else(|| {
                crate::errors::config_error_message(
                    py,
                    crate::flux_map::FLUX_MAP,
                    "`flux_map`: the map does not stay strictly monotonic rounded to float32"
                        .to_owned(),
                )
            })?;
            c.validate().map_err(|e| config_error(py, e))?;
        }
        Ok(c)
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
    fn new(py: Python<'_>, setup: &Setup, dtype: Dtype) -> PyResult<Self> {
        let engine = match dtype {
            Dtype::Float64 => Engine::F64(
                SensorlessEstimator::new(setup.core(py)?)
                    .map_err(|e| crate::config::core_error(py, e))?,
            ),
            Dtype::Float32 => Engine::F32(
                SensorlessEstimator::new(setup.core(py)?)
                    .map_err(|e| crate::config::core_error(py, e))?,
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

    /// Replays the signals with the GIL released; Ctrl-C stops it ([`interrupt::run`]).
    fn run(&mut self, py: Python<'_>, signals: &Signals<'_>, ts: f64) -> PyResult<EstimateResult> {
        let slices = signals.slices();
        with_engine!(self, e => {
            let columns = interrupt::run(py, |cancel| run_slices(e, slices, cancel.as_ref()))?;
            // None only when cancelled, and then `interrupt::run` raised.
            let columns = columns.ok_or_else(|| {
                pyo3::exceptions::PyKeyboardInterrupt::new_err("estimate interrupted")
            })?;
            Ok(EstimateResult::from_columns(py, columns, ts))
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
    cancel: &AtomicBool,
) -> Option<crate::outputs::Columns<T>> {
    let (va, vb, ia, ib) = (T::column(va), T::column(vb), T::column(ia), T::column(ib));
    replay_until(e, &va, &vb, &ia, &ib, Some(cancel))
}

/// The sensorless estimator of Fig. 5 (docs/method/estimator.md §1) around a machine model, stepped one sample
/// at a time with `step` or a chunk at a time with `run`; the state carries over between
/// calls.
///
/// `machine` (required) is the drive's model of the motor: a `fado.Machine`, a preset name
/// (`fado.machine_presets()`; `'paper'` is the paper's motor) or a dict of `Machine` fields.
/// `config` is the tuning: an `EstimatorConfig`, a dict as `fado.simulate` takes it, or None
/// (the defaults). `ts` is the sampling period in s, `theta0` the rotor angle (rad,
/// electrical) assumed at start-up and after `reset`. `dtype='float32'` runs the
/// single-precision estimator, as firmware would; inputs are rounded to float32 and outputs
/// widened back (exactly) to Python floats.
#[pyclass(name = "Estimator", module = "fado")]
pub struct PyEstimator {
    engine: Engine,
    config: Py<PyEstimatorConfig>,
    machine: Py<PyMachine>,
    ts: f64,
    theta0: f64,
}

#[pymethods]
impl PyEstimator {
    #[new]
    #[pyo3(
        signature = (machine = None, config = None, *, ts = None, theta0 = None, dtype = Dtype::Float64, **unknown),
        text_signature = "(machine, config=None, *, ts=0.0001, theta0=0.0, dtype='float64')"
    )]
    fn py_new(
        py: Python<'_>,
        machine: Option<Bound<'_, PyAny>>,
        config: Option<Bound<'_, PyAny>>,
        ts: Option<Bound<'_, PyAny>>,
        theta0: Option<Bound<'_, PyAny>>,
        dtype: Dtype,
        unknown: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let accepted = ["machine", "config", "ts", "theta0", "dtype"];
        crate::elsewhere::refuse_unknown(py, "Estimator", unknown, &accepted)?;
        let ts = number(py, "ts", ts.as_ref(), DEFAULT_TS)?;
        let theta0 = finite(py, "theta0", number(py, "theta0", theta0.as_ref(), 0.0)?)?;
        let setup = Setup::new(
            py,
            "Estimator",
            machine.as_ref(),
            config.as_ref(),
            ts,
            theta0,
        )?;
        let engine = Engine::new(py, &setup, dtype)?;
        Ok(Self {
            engine,
            config: Py::new(py, setup.tuning)?,
            machine: Py::new(py, setup.machine)?,
            ts,
            theta0,
        })
    }

    /// The tuning in use (read-only).
    #[getter]
    fn config(&self, py: Python<'_>) -> Py<PyEstimatorConfig> {
        self.config.clone_ref(py)
    }

    /// The machine model in use (read-only; `set_rs_hat` updates its `rs`).
    #[getter]
    fn machine(&self, py: Python<'_>) -> Py<PyMachine> {
        self.machine.clone_ref(py)
    }

    /// Sampling period Ts in s.
    #[getter]
    fn ts(&self) -> f64 {
        self.ts
    }

    /// Rotor angle assumed at start-up and after `reset`, rad (electrical).
    #[getter]
    fn theta0(&self) -> f64 {
        self.theta0
    }

    /// The arithmetic: 'float64' or 'float32'.
    #[getter]
    fn dtype(&self) -> &'static str {
        self.engine.dtype().name()
    }

    /// One sample: `v_alpha, v_beta` the voltage applied over the last sampling interval (V),
    /// `i_alpha, i_beta` the currents sampled now (A). A non-finite sample is rejected as a
    /// measurement fault: the state is untouched and the result repeats the last good one
    /// with `input_fault` set.
    fn step(&mut self, v_alpha: f64, v_beta: f64, i_alpha: f64, i_beta: f64) -> StepResult {
        self.engine.step([v_alpha, v_beta], [i_alpha, i_beta])
    }

    /// Steps through whole arrays (1-D, contiguous, float64 or float32, equal lengths) with the
    /// GIL released, continuing from the present state; returns every output as arrays.
    /// Other threads keep running meanwhile: they must not write to the input arrays, and
    /// using this estimator from another thread raises until the call returns. Ctrl-C stops
    /// it within a few milliseconds (`KeyboardInterrupt`), the state then part-way through.
    fn run(
        &mut self,
        py: Python<'_>,
        v_alpha: &Bound<'_, PyAny>,
        v_beta: &Bound<'_, PyAny>,
        i_alpha: &Bound<'_, PyAny>,
        i_beta: &Bound<'_, PyAny>,
    ) -> PyResult<EstimateResult> {
        let signals = Signals::new(v_alpha, v_beta, i_alpha, i_beta)?;
        self.engine.run(py, &signals, self.ts)
    }

    /// Back to the start-up state at `theta0` with zero current.
    fn reset(&mut self) {
        with_engine!(&mut self.engine, e => e.reset())
    }

    /// Start-up at a known rotor angle `theta0` (rad, electrical) with the present current
    /// (docs/method/estimator.md, "Start-up"): λ1 = λ̂f·e^{jθ0} + L̂q·i, D̂ = 0, θ̂ = θ0, ω̂ = 0, limiter mode.
    /// Non-finite arguments raise `InputError` naming them.
    #[pyo3(
        signature = (theta0, i_alpha = None, i_beta = None),
        text_signature = "(self, theta0, i_alpha=0.0, i_beta=0.0)"
    )]
    fn align(
        &mut self,
        py: Python<'_>,
        theta0: Bound<'_, PyAny>,
        i_alpha: Option<Bound<'_, PyAny>>,
        i_beta: Option<Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let theta0 = finite(py, "theta0", number(py, "theta0", Some(&theta0), 0.0)?)?;
        let i = [
            finite(py, "i_alpha", number(py, "i_alpha", i_alpha.as_ref(), 0.0)?)?,
            finite(py, "i_beta", number(py, "i_beta", i_beta.as_ref(), 0.0)?)?,
        ];
        self.engine.align(theta0, i);
        Ok(())
    }

    /// Enables or disables the k_df feedback regardless of speed (Fig. 9 switches it off).
    fn set_disturbance_feedback_enabled(&mut self, enabled: bool) {
        with_engine!(&mut self.engine, e => e.set_disturbance_feedback_enabled(enabled))
    }

    /// Replaces R̂s at run time (e.g. online resistance adaptation); raises `ConfigError` for
    /// a bad value and leaves the estimator unchanged.
    fn set_rs_hat(&mut self, py: Python<'_>, rs_hat: Bound<'_, PyAny>) -> PyResult<()> {
        let rs_hat = number(py, "rs_hat", Some(&rs_hat), 0.0)?;
        match &mut self.engine {
            Engine::F64(e) => e.set_rs_hat(rs_hat),
            Engine::F32(e) => e.set_rs_hat(rs_hat as f32),
        }
        .map_err(|e| config_error(py, e))?;
        self.machine = Py::new(py, self.machine.get().with_rs(rs_hat))?;
        Ok(())
    }

    /// The last good result (the start-up state after `reset` or `align`).
    #[getter]
    fn last(&self) -> StepResult {
        with_engine!(&self.engine, e => StepResult::from_estimate(&e.last()))
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
            machine: self.machine.clone_ref(py),
            ts: self.ts,
            theta0: self.theta0,
        }
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "Estimator({}, {}, ts={:?}, theta0={:?}, dtype='{}')",
            self.machine.bind(py).repr()?,
            self.config.bind(py).repr()?,
            self.ts,
            self.theta0,
            self.engine.dtype().name()
        ))
    }
}

/// The default sampling period in s: 10 kHz, as the paper's drive (section V).
pub const DEFAULT_TS: f64 = 1e-4;

/// Runs the estimator over a whole recording in Rust with the GIL released and returns every
/// output and diagnostic as numpy arrays (an `EstimateResult`).
///
/// `v_alpha, v_beta`: voltage applied over each sampling interval (V); `i_alpha, i_beta`:
/// currents sampled (A); 1-D contiguous float64 or float32 arrays of equal length.
/// `machine` (required): the drive's model of the motor, a `fado.Machine`, a preset name
/// (`fado.machine_presets()`) or a dict of `Machine` fields. `ts`: sampling period in s.
/// `config`: the tuning (an `EstimatorConfig`, a dict as `fado.simulate` takes it, or None).
/// `theta0` aligns the estimator at that angle with the first current sample before the first
/// step (otherwise it starts at angle 0 with zero current). `dtype='float32'` runs the
/// single-precision estimator. Bad arrays or arguments raise `InputError`, bad settings
/// `ConfigError` (both are `ValueError`s). The inputs are read in place, not copied: other
/// threads must not write to them during the call. Ctrl-C stops it within a
/// few milliseconds (`KeyboardInterrupt`).
#[pyfunction]
#[pyo3(
    signature = (v_alpha, v_beta, i_alpha, i_beta, *, machine = None, ts = None, config = None, theta0 = None, dtype = Dtype::Float64, **unknown),
    text_signature = "(v_alpha, v_beta, i_alpha, i_beta, *, machine, ts=0.0001, config=None, theta0=None, dtype='float64')"
)]
#[allow(clippy::too_many_arguments)]
pub fn estimate(
    py: Python<'_>,
    v_alpha: &Bound<'_, PyAny>,
    v_beta: &Bound<'_, PyAny>,
    i_alpha: &Bound<'_, PyAny>,
    i_beta: &Bound<'_, PyAny>,
    machine: Option<Bound<'_, PyAny>>,
    ts: Option<Bound<'_, PyAny>>,
    config: Option<Bound<'_, PyAny>>,
    theta0: Option<Bound<'_, PyAny>>,
    dtype: Dtype,
    unknown: Option<&Bound<'_, PyDict>>,
) -> PyResult<EstimateResult> {
    let accepted = [
        "v_alpha", "v_beta", "i_alpha", "i_beta", "machine", "ts", "config",
    ];
    let accepted = [&accepted[..], &["theta0", "dtype"]].concat();
    crate::elsewhere::refuse_unknown(py, "estimate", unknown, &accepted)?;
    let ts = number(py, "ts", ts.as_ref(), DEFAULT_TS)?;
    let theta0 = match theta0 {
        Some(t) => Some(finite(py, "theta0", number(py, "theta0", Some(&t), 0.0)?)?),
        None => None,
    };
    let setup = Setup::new(py, "estimate", machine.as_ref(), config.as_ref(), ts, 0.0)?;
    let signals = Signals::new(v_alpha, v_beta, i_alpha, i_beta)?;
    let mut engine = Engine::new(py, &setup, dtype)?;
    let core = setup.core::<f64>(py)?;
    if let Ok(bounds) = core.sample_bounds() {
        crate::recording_checks::warn_all(
            py,
            signals.slices(),
            &bounds,
            &core.machine,
            setup.ts,
            theta0,
        )?;
    }
    if let Some(theta0) = theta0 {
        let [_, _, ia, ib] = signals.slices();
        let first = |c: ColumnSlice<'_>| match c {
            ColumnSlice::F64(x) => x.first().copied().unwrap_or(0.0),
            ColumnSlice::F32(x) => x.first().map_or(0.0, |&v| f64::from(v)),
        };
        engine.align(theta0, [first(ia), first(ib)]);
    }
    engine.run(py, &signals, setup.ts)
}
