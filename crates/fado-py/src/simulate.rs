//! `fado.simulate` and `fado.SimResult`: the closed-loop simulator of `fado-sim` (the paper's
//! Fig. 8–12 as named scenarios) from Python, with the GIL released while it runs.
//!
//! The native function takes the configuration as TOML text only; `fado.simulate` (Python)
//! also accepts a path or a `dict` and turns it into TOML. The result holds what the CLI
//! `fado-sim run` writes: the metrics (`metrics.json`, parsed) and the trace columns
//! (`traces.csv`, as float64 arrays under the same names, bit for bit).

use std::io::Write;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use fado_sim::scenario::{self, RunOptions, SCENARIOS, TraceOutput};
use fado_sim::sim::{TraceColumns, TraceRow};
use fado_sim::{SimConfig, SimConfigError};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::config::PyEstimatorConfig;
use crate::errors::{config_error_message, input_error};
use crate::interrupt;
use crate::machine::PyMachine;

/// Width of the progress bar printed to stderr.
const BAR_WIDTH: usize = 30;

/// The trace column names, in `traces.csv` order.
pub fn trace_columns() -> Vec<&'static str> {
    TraceRow::COLUMNS.to_vec()
}

/// A refused configuration or scenario as the Python exception it means: an unknown scenario
/// is a bad argument (`InputError`), anything else a bad configuration key (`ConfigError`
/// with `.field` = the TOML path, e.g. `inverter.dead_time`, and `.line`, `.column` where
/// the TOML text sets it).
pub(crate) fn sim_error(py: Python<'_>, e: SimConfigError) -> PyErr {
    if e.key == "scenario" {
        input_error(py, "scenario", e.message)
    } else {
        let message = e.to_string();
        let err = config_error_message(py, &e.key, message);
        // Where the key is in the TOML text (1-based), or None for a value derived from
        // other keys.
        let (line, column) = e.location.map(|l| (l.line, l.column)).unzip();
        let value = err.value(py);
        match value
            .setattr("line", line)
            .and_then(|()| value.setattr("column", column))
        {
            Ok(()) => err,
            Err(set_failed) => set_failed,
        }
    }
}

/// Prints a one-line progress bar to stderr (no GIL needed; Python's `sys.stderr` is not
/// involved, so it shows even when Python output is captured).
struct ProgressLine<'a> {
    scenario: &'a str,
    started: Instant,
}

impl ProgressLine<'_> {
    fn draw(&self, fraction: f64) {
        let filled = ((fraction.clamp(0.0, 1.0) * BAR_WIDTH as f64).round()) as usize;
        let bar: String = "=".repeat(filled) + &" ".repeat(BAR_WIDTH - filled);
        let mut err = std::io::stderr().lock();
        // A failed write to stderr is not worth failing the simulation for.
        let _ = write!(
            err,
            "\r{} [{bar}] {:>3.0}% {:>6.1} s",
            self.scenario,
            fraction * 100.0,
            self.started.elapsed().as_secs_f64()
        );
        let _ = err.flush();
    }

    fn finish(&self) {
        let _ = writeln!(std::io::stderr().lock());
    }
}

/// Most trace rows `simulate` keeps in memory: 4 million rows × 39 float64 columns = 1.25 GB
/// (400 s at 10 kHz without decimation). Longer traces are refused before the run; raise
/// `simulation.decimation`, or use `fado-sim run`, which streams the trace to disk.
pub const MAX_TRACE_ROWS_IN_MEMORY: u64 = 4_000_000;

/// Why a run gave no result.
enum Failed {
    Config(SimConfigError),
    Json(serde_json::Error),
    Cancelled,
}

/// What `fado_sim::simulate` returns, reduced to what crosses into Python.
struct Finished {
    report_json: String,
    passed: bool,
    averaged: bool,
    config_toml: String,
    estimator: fado_core::EstimatorConfig<f64>,
    columns: Vec<Vec<f64>>,
    /// The carrier's warning (`SimConfig::carrier_findings`) and a paper experiment's note on
    /// the user's motor (`Scenario::units_note`), each issued as a `UserWarning`.
    warnings: Vec<String>,
}

/// The motor a simulation runs with, before the scenario and the user's configuration.
pub(crate) enum Motor {
    /// A preset of `motors/`: its whole file (`[motor]`, `[inverter]`) over the defaults.
    Preset(&'static fado_sim::presets::Preset),
    /// A machine: `[motor]` and `[inverter] dc_voltage`, the other `[inverter]` keys its
    /// ratings give derived (`SimConfig::for_machine`), and its flux map if it has one.
    Machine(
        Box<fado_core::MachineModel<f64>>,
        Option<fado_sim::magnetics_file::FluxMapFile>,
    ),
}

impl Motor {
    /// The plant of a `fado.Machine`: its record and its flux map.
    pub(crate) fn of_machine(m: &PyMachine) -> Self {
        Motor::Machine(Box::new(m.to_core()), m.flux_map().cloned())
    }

    /// `motor` as `simulate` takes it: None, a preset name, a `fado.Machine` or a dict of its
    /// fields.
    pub(crate) fn from_argument(
        py: Python<'_>,
        motor: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Option<Self>> {
        let Some(motor) = motor.filter(|m| !m.is_none()) else {
            return Ok(None);
        };
        if let Ok(m) = motor.cast::<PyMachine>() {
            return Ok(Some(Motor::of_machine(m.get())));
        }
        if let Ok(name) = motor.extract::<String>() {
            return match fado_sim::presets::find(&name) {
                Some(p) => Ok(Some(Motor::Preset(p))),
                None => Err(input_error(
                    py,
                    "motor",
                    format!(
                        "unknown motor preset {name:?}; one of {:?}",
                        crate::machine::preset_names()
                    ),
                )),
            };
        }
        if motor.cast::<PyDict>().is_ok() {
            // A dict of `Machine` fields, as `fado.commission` and `fado.estimate` take it.
            let m = PyMachine::from_argument(py, Some(motor), "motor", "simulate")?;
            return Ok(Some(Motor::of_machine(&m)));
        }
        Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "motor must be a preset name, a fado.Machine, a dict of Machine fields or None, got {}",
            motor.get_type().name()?
        )))
    }

    /// The defaults with this motor.
    pub(crate) fn base(&self) -> Result<SimConfig, SimConfigError> {
        match self {
            Motor::Preset(p) => p.config(),
            Motor::Machine(m, flux_map) => {
                // The inverter keys the machine's ratings give, derived as for a motor file.
                let mut c = SimConfig::for_machine(m);
                c.motor_flux_map = flux_map.clone();
                // Errors name the TOML key the machine's field became (`motor.rs`).
                c.validate()?;
                Ok(c)
            }
        }
    }
}

/// The configuration of `scenario`: the defaults, `motor` over them, the scenario (scaled by
/// the motor's ratings), then the user's TOML, which wins over everything (as
/// `fado_sim::scenario::scenario_config`, with the motor as a first layer).
pub(crate) fn layered_config(
    scenario: &str,
    motor: Option<&Motor>,
    config_toml: Option<&str>,
    averaged: bool,
) -> Result<SimConfig, SimConfigError> {
    let Some(motor) = motor else {
        return scenario::scenario_config(scenario, config_toml, averaged);
    };
    let sc = scenario::find(scenario).ok_or_else(|| {
        let names: Vec<_> = SCENARIOS.iter().map(|s| s.name).collect();
        SimConfigError::new(
            "scenario",
            format!("unknown `{scenario}`; one of {names:?}"),
        )
    })?;
    let base = motor.base()?;
    let mut cfg = match config_toml {
        Some(text) => {
            let user = SimConfig::from_toml_over(&base, text)?;
            SimConfig::from_toml_over(&sc.apply(user), text)?
        }
        None => sc.apply(base),
    };
    if averaged {
        cfg.inverter.model = fado_sim::inverter::InverterModel::Averaged;
    }
    cfg.validate().map_err(|e| match config_toml {
        Some(text) => e.located_in(text),
        None => e,
    })?;
    Ok(cfg)
}

fn run(
    scenario: &str,
    motor: Option<&Motor>,
    config_toml: Option<&str>,
    averaged: bool,
    progress: bool,
    cancel: &AtomicBool,
) -> Result<Finished, Failed> {
    let cfg = layered_config(scenario, motor, config_toml, averaged).map_err(Failed::Config)?;
    let mut warnings: Vec<String> = cfg
        .carrier_findings()
        .filter(|(s, ..)| *s == fado_core::machine_checks::Severity::Warning)
        .map(|(.., text)| text)
        .into_iter()
        .collect();
    // A paper experiment in its motor's units on a motor of other ratings says so.
    warnings.extend(scenario::find(scenario).and_then(|s| s.units_note(&cfg)));
    // A speed reference or a load beyond the model's limits.
    warnings.extend(fado_sim::reach::findings(&cfg).into_iter().map(|(_, w)| w));
    let rows = scenario::trace_rows(&cfg);
    if rows > MAX_TRACE_ROWS_IN_MEMORY {
        let e = SimConfigError::new(
            "simulation.decimation",
            format!(
                "the trace would hold {rows} rows, more than the {MAX_TRACE_ROWS_IN_MEMORY} \
                 `simulate` keeps in memory: raise it (or shorten simulation.duration, or run \
                 `fado-sim run`, which streams the trace to disk)"
            ),
        );
        return Err(Failed::Config(match config_toml {
            Some(text) => e.located_in(text),
            None => e,
        }));
    }
    let line = ProgressLine {
        scenario,
        started: Instant::now(),
    };
    let mut draw = |f: f64| line.draw(f);
    let callback: Option<&mut dyn FnMut(f64)> = if progress { Some(&mut draw) } else { None };
    // The rows go straight into the columns numpy will own: no second copy of the trace.
    let mut columns = TraceColumns::with_capacity(rows as usize);
    let outcome = scenario::run_config_with(
        scenario,
        cfg,
        RunOptions {
            progress: callback,
            trace: TraceOutput::Sink(&mut columns),
            cancel: Some(cancel),
        },
    )
    .map_err(Failed::Config)?;
    if progress {
        line.finish();
    }
    if outcome.stats.cancelled {
        return Err(Failed::Cancelled);
    }
    let report = outcome.report();
    Ok(Finished {
        report_json: serde_json::to_string(&report).map_err(Failed::Json)?,
        passed: outcome.passed,
        averaged: outcome.config.inverter.model == fado_sim::inverter::InverterModel::Averaged,
        config_toml: outcome.config.to_toml(),
        estimator: outcome.config.estimator_config(),
        columns: columns.columns,
        warnings,
    })
}

/// Runs one of the paper's experiments (`scenarios()`) on the simulated drive and returns a
/// `SimResult`. `config_toml` overrides the scenario's configuration key by key (the format
/// of `default_config`); `averaged` selects the averaged inverter model (fast) instead of the
/// switching-resolved one; `progress` prints a progress bar to stderr. The GIL is released
/// while the simulation runs.
///
/// `motor` (a preset name of `machine_presets()` or a `Machine`) replaces the paper's motor
/// before the scenario and `config_toml` are applied: a preset's whole file (`[motor]` and
/// its `[inverter]`), a `Machine` as `[motor]` and `[inverter] dc_voltage`.
///
/// Bad keys or values raise `ConfigError` (`.field` is the TOML path), an unknown scenario
/// or motor `InputError` (both are `ValueError`s). Prefer `fado.simulate`, which also takes a
/// path or a `dict`.
#[pyfunction]
#[pyo3(
    signature = (scenario = "fig11", config_toml = None, averaged = false, *, progress = false, motor = None),
    text_signature = "(scenario='fig11', config_toml=None, averaged=False, *, progress=False, motor=None)"
)]
pub fn simulate(
    py: Python<'_>,
    scenario: &str,
    config_toml: Option<&str>,
    averaged: bool,
    progress: bool,
    motor: Option<Bound<'_, PyAny>>,
) -> PyResult<SimResult> {
    let motor = Motor::from_argument(py, motor.as_ref())?;
    let finished = interrupt::run(py, |cancel| {
        run(
            scenario,
            motor.as_ref(),
            config_toml,
            averaged,
            progress,
            cancel.as_ref(),
        )
    })?;
    match finished {
        Ok(f) => {
            for w in &f.warnings {
                PyErr::warn(
                    py,
                    &py.get_type::<pyo3::exceptions::PyUserWarning>(),
                    &std::ffi::CString::new(w.as_str()).unwrap_or_default(),
                    1,
                )?;
            }
            SimResult::new(py, scenario, f)
        }
        Err(Failed::Config(e)) => Err(sim_error(py, e)),
        Err(Failed::Json(e)) => Err(pyo3::exceptions::PyRuntimeError::new_err(format!(
            "metrics to JSON: {e}"
        ))),
        // Only when a signal handler raised, which `interrupt::run` already returned.
        Err(Failed::Cancelled) => Err(pyo3::exceptions::PyKeyboardInterrupt::new_err(
            "simulation interrupted",
        )),
    }
}

/// The names of the scenarios `simulate` runs (the paper's Fig. 8–12, and the ones scaled by
/// the motor's ratings).
#[pyfunction]
pub fn scenarios() -> Vec<&'static str> {
    SCENARIOS.iter().map(|s| s.name).collect()
}

/// What a scenario does, as a dict with `name`, `title` (the paper's figure), `profile` and
/// `criterion` (the pass criterion checked in code, docs/guide/first-run.md).
#[pyfunction]
pub fn describe_scenario<'py>(py: Python<'py>, scenario: &str) -> PyResult<Bound<'py, PyDict>> {
    let Some(s) = scenario::find(scenario) else {
        return Err(input_error(
            py,
            "scenario",
            format!("unknown `{scenario}`; one of {:?}", scenarios()),
        ));
    };
    let dict = PyDict::new(py);
    dict.set_item("name", s.name)?;
    dict.set_item("title", s.title)?;
    dict.set_item("profile", s.profile)?;
    dict.set_item("criterion", s.criterion)?;
    Ok(dict)
}

/// The configuration a scenario runs with, as the TOML document of `fado-sim run SCENARIO
/// --dump-config [--averaged]`: edit it and pass it (or a part of it) to `simulate`.
/// With `motor` (as in `simulate`), the configuration for that motor.
#[pyfunction]
#[pyo3(
    signature = (scenario = "fig11", averaged = false, *, motor = None),
    text_signature = "(scenario='fig11', averaged=False, *, motor=None)"
)]
pub fn default_config(
    py: Python<'_>,
    scenario: &str,
    averaged: bool,
    motor: Option<Bound<'_, PyAny>>,
) -> PyResult<String> {
    let motor = Motor::from_argument(py, motor.as_ref())?;
    layered_config(scenario, motor.as_ref(), None, averaged)
        .map(|c| c.to_toml())
        .map_err(|e| sim_error(py, e))
}

/// A finished simulation: the metrics and checks of `metrics.json` and the trace columns of
/// `traces.csv` (float64 arrays, flags as 0.0/1.0), plus the configuration it ran with.
#[pyclass(name = "SimResult", module = "fado", frozen)]
pub struct SimResult {
    /// Scenario name.
    #[pyo3(get)]
    scenario: String,
    /// All pass criteria met.
    #[pyo3(get)]
    passed: bool,
    /// The averaged inverter model ran (otherwise the switching-resolved one).
    #[pyo3(get)]
    averaged: bool,
    /// The effective configuration as TOML (feed it back to `simulate` to rerun).
    #[pyo3(get)]
    config_toml: String,
    /// The tuning of the estimator inside the drive (for replaying the trace with
    /// `fado.Estimator(result.machine, result.estimator_config, ts=result.ts)`).
    #[pyo3(get)]
    estimator_config: Py<PyEstimatorConfig>,
    /// The drive's model of the motor (`[model]`, or `[motor]` × `[mismatch]`).
    #[pyo3(get)]
    machine: Py<PyMachine>,
    /// The drive's sampling period in s.
    #[pyo3(get)]
    ts: f64,
    /// The rotor angle the drive's estimator starts from, rad (the plant's initial angle plus
    /// the alignment error).
    #[pyo3(get)]
    theta0: f64,
    metrics: Py<PyDict>,
    traces: Py<PyDict>,
    rows: usize,
}

impl SimResult {
    fn new(py: Python<'_>, scenario: &str, f: Finished) -> PyResult<Self> {
        let metrics = py
            .import("json")?
            .call_method1("loads", (f.report_json,))?
            .cast_into::<PyDict>()?;
        let traces = PyDict::new(py);
        let rows = f.columns.first().map_or(0, Vec::len);
        for (name, column) in TraceRow::COLUMNS.iter().zip(f.columns) {
            traces.set_item(*name, PyArray1::from_vec(py, column))?;
        }
        Ok(Self {
            scenario: scenario.to_owned(),
            passed: f.passed,
            averaged: f.averaged,
            config_toml: f.config_toml,
            estimator_config: Py::new(py, PyEstimatorConfig::from_core(&f.estimator.tuning))?,
            machine: Py::new(py, PyMachine::from_core(&f.estimator.machine))?,
            ts: f.estimator.ts,
            theta0: f.estimator.initial_angle,
            metrics: metrics.unbind(),
            traces: traces.unbind(),
            rows,
        })
    }
}

#[pymethods]
impl SimResult {
    /// The content of `metrics.json`: scenario, inverter_model, precision, estimator, passed,
    /// max/RMS angle error overall and near zero speed (rad), zero_speed_band_rpm,
    /// max_speed_error_rpm, tripped, simulated_seconds, wall_seconds, startup (the drive's
    /// start-up: status, ready_time, motion_before_ready, deferrals, gain_calibration,
    /// angle_phase; docs/method/startup.md), checks. A fresh copy.
    #[getter]
    fn metrics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("copy")?
            .call_method1("deepcopy", (self.metrics.bind(py),))
    }

    /// The pass criteria: a list of dicts with `name`, `value`, `min`, `max`, `passed`.
    #[getter]
    fn checks<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        Ok(self
            .metrics(py)?
            .get_item("checks")?
            .cast_into::<PyList>()?)
    }

    /// The trace columns by their `traces.csv` names (`TRACE_COLUMNS`), as float64 arrays.
    /// The dict is a fresh copy; the arrays are shared.
    #[getter]
    fn traces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.traces.bind(py).copy()
    }

    /// Trace time in s (the `time` column).
    #[getter]
    fn time<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.__getitem__(py, "time")
    }

    /// A `pandas.DataFrame` of the trace indexed by time in s (needs the `pandas` extra).
    fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pandas = py.import("pandas")?;
        let columns = self.traces(py)?;
        let time = columns
            .get_item("time")?
            .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err("time"))?;
        columns.del_item("time")?;
        let index = pandas.call_method1("Index", (time,))?;
        index.setattr("name", "time")?;
        let kwargs = PyDict::new(py);
        kwargs.set_item("index", index)?;
        pandas.call_method("DataFrame", (columns,), Some(&kwargs))
    }

    /// One trace column by name.
    fn __getitem__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        self.traces
            .bind(py)
            .get_item(name)?
            .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err(name.to_owned()))
    }

    /// Number of trace rows.
    fn __len__(&self) -> usize {
        self.rows
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let m = self.metrics.bind(py);
        let get = |k: &str| -> PyResult<String> {
            Ok(match m.get_item(k)? {
                Some(v) => v.repr()?.to_string(),
                None => "?".to_owned(),
            })
        };
        let near_zero: f64 = match m.get_item("max_angle_error_zero_speed")? {
            Some(v) => v.extract()?,
            None => f64::NAN,
        };
        Ok(format!(
            "SimResult(scenario='{}', passed={}, inverter={}, max_angle_error_zero_speed={:.4}, \
             tripped={}, simulated_seconds={}, rows={})",
            self.scenario,
            if self.passed { "True" } else { "False" },
            get("inverter_model")?,
            near_zero,
            get("tripped")?,
            get("simulated_seconds")?,
            self.rows
        ))
    }
}
