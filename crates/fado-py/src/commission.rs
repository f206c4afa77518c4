//! `fado.commission` and `fado.CommissionResult`: the commissioning procedure
//! (`fado_core::commissioning`) run on the simulated plant of `fado-sim commission`, from
//! Python, with the GIL released while it runs and Ctrl-C honoured ([`crate::interrupt`]).
//!
//! The result holds what the CLI prints and writes: the identified model (a `Machine`), the
//! per-parameter comparison with the plant's truth (`metrics.json`'s `parameters`), the trace
//! (`traces.csv`'s columns as float64 arrays) and `identified.toml`.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use fado_core::commissioning::{Phase, Status};
use fado_sim::SimConfig;
use fado_sim::commission::{self as sim_commission, CommissionOptions, CommissionOutcome};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};

use crate::errors::input_error;
use crate::interrupt;
use crate::machine::PyMachine;
use crate::number::number;
use crate::simulate::{Motor, sim_error};

/// The trace columns of a `CommissionResult`, in `traces.csv` order.
pub const COMMISSION_TRACE_COLUMNS: [&str; 12] = sim_commission::TraceRow::COLUMNS;

/// The procedure's phase names, by `Phase::index` (the `phase` trace column).
pub fn phase_names() -> Vec<&'static str> {
    [
        Phase::Offset,
        Phase::Align,
        Phase::Resistance,
        Phase::InductanceD,
        Phase::InductanceQ,
        Phase::Magnetics,
        Phase::Spin,
        Phase::Coast,
        Phase::Inertia,
        Phase::Done,
        Phase::Aborted,
    ]
    .iter()
    .map(|p| p.name())
    .collect()
}

/// The plant `motor` names: a preset's whole file, or a `Machine` (or dict of its fields)
/// over the simulator's defaults; then `config_toml` key by key, the seed and the inverter
/// model.
fn plant_config(
    py: Python<'_>,
    motor: &Bound<'_, PyAny>,
    config_toml: Option<&str>,
    seed: u64,
    averaged: bool,
) -> PyResult<SimConfig> {
    let motor = if let Ok(name) = motor.cast::<PyString>() {
        let name = name.to_str()?;
        match fado_sim::presets::find(name) {
            Some(p) => Motor::Preset(p),
            None => {
                return Err(input_error(
                    py,
                    "motor",
                    format!(
                        "unknown motor preset {name:?}; one of {:?}",
                        crate::machine::preset_names()
                    ),
                ));
            }
        }
    } else {
        Motor::of_machine(&PyMachine::from_argument(
            py,
            Some(motor),
            "motor",
            "commission",
        )?)
    };
    let base = motor.base().map_err(|e| sim_error(py, e))?;
    let mut cfg = match config_toml {
        Some(text) => {
            sim_commission::refuse_unused(text, "fado.commission").map_err(|e| sim_error(py, e))?;
            SimConfig::from_toml_over(&base, text).map_err(|e| sim_error(py, e))?
        }
        None => base,
    };
    cfg.current_sensor.seed = seed;
    if averaged {
        cfg.inverter.model = fado_sim::inverter::InverterModel::Averaged;
    }
    Ok(cfg)
}

/// Runs the commissioning procedure (`fado_core::commissioning`, docs/commissioning.md) on
/// the simulated plant and returns a `CommissionResult`: what `fado-sim commission` prints
/// and writes. The GIL is released while it runs; Ctrl-C stops it (`KeyboardInterrupt`).
///
/// `motor` is the plant: a preset name of `machine_presets()` (its whole `motors/` file), a
/// `Machine` or a dict of `Machine` fields (with the simulator's default inverter at its
/// `dc_voltage`). `nameplate` (a `Machine`, preset name or dict) is what the procedure is
/// told: its ratings set the test levels, its parameters only size the tests; default the
/// plant's own record. `config_toml` overrides the plant key by key (`[inverter]`,
/// `[current_sensor]`, …, as in `simulate`); `seed` is the current sensors' noise seed;
/// `averaged` selects the averaged inverter model; `theta0` is the rotor's initial electrical
/// angle in rad; the trace keeps every `decimation`-th sample; `progress` prints a progress
/// bar to stderr.
///
/// A bad key or value raises `ConfigError` (`.field` the TOML path or the `Machine` field),
/// a bad argument `InputError` (both `ValueError`s). A nameplate `rs` twice or half the
/// resistance the standstill test measures raises a `UserWarning` naming it
/// (`fado_sim::nameplate_agreement`: a line-to-line value?).
#[pyfunction]
#[pyo3(
    signature = (motor, *, nameplate = None, config_toml = None, seed = 1, averaged = false, theta0 = None, decimation = 10, progress = false),
    text_signature = "(motor, *, nameplate=None, config_toml=None, seed=1, averaged=False, theta0=1.0, decimation=10, progress=False)"
)]
#[allow(clippy::too_many_arguments)]
pub fn commission(
    py: Python<'_>,
    motor: Bound<'_, PyAny>,
    nameplate: Option<Bound<'_, PyAny>>,
    config_toml: Option<&str>,
    seed: u64,
    averaged: bool,
    theta0: Option<Bound<'_, PyAny>>,
    decimation: i64,
    progress: bool,
) -> PyResult<CommissionResult> {
    let theta0 = number(py, "theta0", theta0.as_ref(), 1.0)?;
    if !theta0.is_finite() {
        return Err(input_error(
            py,
            "theta0",
            format!("must be a finite angle in rad, got {theta0}"),
        ));
    }
    let decimation = usize::try_from(decimation)
        .ok()
        .filter(|&d| d >= 1)
        .ok_or_else(|| {
            input_error(
                py,
                "decimation",
                format!("must be a whole number of at least 1, got {decimation}"),
            )
        })?;
    let cfg = plant_config(py, &motor, config_toml, seed, averaged)?;
    let plant = cfg.plant();
    let told = nameplate.filter(|n| !n.is_none());
    let section = if told.is_some() { "nameplate" } else { "motor" };
    let nameplate = match told {
        Some(n) => PyMachine::from_argument(py, Some(&n), "nameplate", "commission")?.to_core(),
        None => plant.motor,
    };
    // The procedure runs on the plant's DC link, whatever the nameplate says.
    let nameplate = nameplate.with_dc_voltage(plant.inverter.dc_voltage);
    let config_text = cfg.to_toml();
    let started = std::time::Instant::now();
    let outcome = interrupt::run(py, |cancel| {
        let mut draw = |f: f64, phase: Phase| draw_progress(f, phase, started);
        let cb: Option<&mut dyn FnMut(f64, Phase)> = if progress { Some(&mut draw) } else { None };
        let r = sim_commission::commission(
            &plant,
            nameplate,
            CommissionOptions {
                theta0,
                decimation,
                cancel: Some(Arc::<AtomicBool>::clone(cancel)),
                ..Default::default()
            },
            |_| {},
            cb,
        );
        if progress {
            eprintln!();
        }
        r
    })?;
    let outcome: CommissionOutcome = outcome.map_err(|e| sim_error(py, e))?;
    if outcome.cancelled {
        // Only when a signal handler raised, which `interrupt::run` already returned.
        return Err(pyo3::exceptions::PyKeyboardInterrupt::new_err(
            "commissioning interrupted",
        ));
    }
    warn_nameplate(py, section, &nameplate, &outcome)?;
    CommissionResult::new(py, outcome, config_text)
}

/// A `UserWarning` where the measured resistance contradicts the nameplate's `rs`
/// (`fado_sim::nameplate_agreement`), naming it in `section` (`nameplate` or `motor`).
fn warn_nameplate(
    py: Python<'_>,
    section: &str,
    nameplate: &fado_core::MachineModel<f64>,
    outcome: &CommissionOutcome,
) -> PyResult<()> {
    let key = format!("{section}.rs");
    let Some(id) = &outcome.identification else {
        return Ok(());
    };
    match fado_sim::nameplate_agreement::resistance(&key, nameplate.rs, id.model.rs) {
        Some(w) => PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &std::ffi::CString::new(w).unwrap_or_default(),
            1,
        ),
        None => Ok(()),
    }
}

/// Draws the progress bar of a commissioning run on stderr: `phase`, the fraction `f` done and
/// the time since `started`.
fn draw_progress(f: f64, phase: Phase, started: std::time::Instant) {
    use std::io::Write;
    let filled = (f.clamp(0.0, 1.0) * 30.0).round() as usize;
    let mut err = std::io::stderr().lock();
    let _ = write!(
        err,
        "\rcommission {:<13} [{}{}] {:>3.0}% {:>6.1} s",
        phase.name(),
        "=".repeat(filled),
        " ".repeat(30 - filled),
        f * 100.0,
        started.elapsed().as_secs_f64()
    );
    let _ = err.flush();
}

/// A finished commissioning run on the simulated plant.
#[pyclass(name = "CommissionResult", module = "fado", frozen)]
pub struct CommissionResult {
    /// The procedure finished and identified the motor.
    #[pyo3(get)]
    passed: bool,
    /// How it ended: `"done"`, or the typed abort reason, e.g.
    /// `"Aborted(RotationDetected { phase: Resistance })"`.
    #[pyo3(get)]
    status: String,
    /// The identified model (`None` after an abort): parameters measured, ratings copied
    /// from the nameplate.
    #[pyo3(get)]
    machine: Option<Py<PyMachine>>,
    /// Per-phase inverter voltage error V̂ = Td·f_sw·Vdc + V_th in V (`None` after an abort).
    #[pyo3(get)]
    inverter_voltage: Option<f64>,
    /// Device threshold voltage V_th in V (`None` after an abort).
    #[pyo3(get)]
    threshold_voltage: Option<f64>,
    /// Saliency L̂q/L̂d (`None` after an abort).
    #[pyo3(get)]
    saliency: Option<f64>,
    /// Simulated duration of the run in s.
    #[pyo3(get)]
    simulated_seconds: f64,
    /// Wall-clock duration in s.
    #[pyo3(get)]
    wall_seconds: f64,
    /// Largest true current magnitude during the run, A.
    #[pyo3(get)]
    max_current: f64,
    /// Largest commanded current reference magnitude, A.
    #[pyo3(get)]
    max_current_reference: f64,
    /// The procedure's current limit, A.
    #[pyo3(get)]
    current_limit: f64,
    /// Largest rotor motion during the inductance tests, rad (electrical).
    #[pyo3(get)]
    rotor_motion_inductance: f64,
    /// Largest rotor motion during the flux-linkage pulses of the magnetic identification
    /// from the rotor's angle at their start, rad (electrical): the plant's truth. The
    /// `rotor_moved` verdict compares the procedure's own estimate of the turn over one pair
    /// of pulses with `PULSE_MOTION_LIMIT` (metrics.json's `magnetics.pulse_motion`).
    #[pyo3(get)]
    rotor_motion_magnetics: f64,
    /// Whether the magnetic identification found saturation (then `identified_toml` carries
    /// `[model.saturation]`), or `None` when nothing was identified.
    #[pyo3(get)]
    saturation_detected: Option<bool>,
    /// The standstill flux-linkage pulses' verdict on the machine's saturation, as
    /// `fado-sim commission` names it in metrics.json: `detected`, `not_detected`,
    /// `inconclusive` (a fit of large change that does not explain the flux), `rotor_moved`
    /// (the procedure's estimate of the rotor's turn over one pair of pulses beyond
    /// `PULSE_MOTION_LIMIT`) or `not_measured`;
    /// `None` when the pulses did not run to their end. It stands when the procedure aborts
    /// later (then `saturation_detected` is `None`).
    #[pyo3(get)]
    saturation_verdict: Option<String>,
    /// The plant's configuration as TOML.
    #[pyo3(get)]
    config_toml: String,
    /// `identified.toml` as `fado-sim commission` writes it (the plant's configuration with
    /// its `[model]` replaced by the identified one; runs as is with `simulate`), or `None`.
    #[pyo3(get)]
    identified_toml: Option<String>,
    truth: Py<PyDict>,
    parameters: Py<PyList>,
    traces: Py<PyDict>,
    rows: usize,
}

impl CommissionResult {
    fn new(py: Python<'_>, o: CommissionOutcome, config_text: String) -> PyResult<Self> {
        let truth = PyDict::new(py);
        let t = o.truth;
        for (k, v) in [
            ("rs", t.rs),
            ("ld", t.ld),
            ("lq", t.lq),
            ("flux_linkage", t.flux_linkage),
            ("inertia", t.inertia),
            ("viscous_friction", t.viscous_friction),
            ("inverter_voltage", t.inverter_voltage),
            ("threshold_voltage", t.threshold_voltage),
            ("current_gain_ratio", t.current_gain_ratio),
        ] {
            truth.set_item(k, v)?;
        }
        let parameters = PyList::empty(py);
        if let Some(id) = &o.identification {
            for r in sim_commission::compare(id, &o.truth) {
                let d = PyDict::new(py);
                d.set_item("parameter", r.parameter)?;
                d.set_item("identified", r.identified)?;
                d.set_item("truth", r.truth)?;
                d.set_item("error", r.error)?;
                d.set_item("confidence", r.confidence)?;
                parameters.append(d)?;
            }
        }
        let n = o.trace.len();
        let mut cols: Vec<Vec<f64>> = (0..COMMISSION_TRACE_COLUMNS.len())
            .map(|_| Vec::with_capacity(n))
            .collect();
        for r in &o.trace {
            for (c, v) in cols.iter_mut().zip(r.values()) {
                c.push(v);
            }
        }
        let traces = PyDict::new(py);
        for (name, c) in COMMISSION_TRACE_COLUMNS.iter().zip(cols) {
            traces.set_item(*name, PyArray1::from_vec(py, c))?;
        }
        let identified_toml = match &o.identification {
            Some(id) => Some(
                sim_commission::identified_toml(&config_text, id).map_err(|e| sim_error(py, e))?,
            ),
            None => None,
        };
        let id = o.identification.as_ref();
        Ok(Self {
            passed: id.is_some(),
            status: match o.status {
                Status::Done => "done".to_owned(),
                Status::Running => "running (stopped at the simulator's time limit)".to_owned(),
                s => format!("{s:?}"),
            },
            machine: id
                .map(|id| Py::new(py, PyMachine::from_core(&id.model)))
                .transpose()?,
            inverter_voltage: id.map(|id| id.inverter_voltage),
            threshold_voltage: id.map(|id| id.threshold_voltage),
            saliency: id.map(|id| id.saliency),
            simulated_seconds: o.simulated_seconds,
            wall_seconds: o.wall_seconds,
            max_current: o.max_current,
            max_current_reference: o.max_current_reference,
            current_limit: o.current_limit,
            rotor_motion_inductance: o.rotor_motion_inductance,
            rotor_motion_magnetics: o.rotor_motion_magnetics,
            saturation_detected: id.map(|id| id.saturation.is_some()),
            saturation_verdict: o.magnetics.as_ref().map(|m| m.verdict.to_owned()),
            config_toml: config_text,
            identified_toml,
            truth: truth.unbind(),
            parameters: parameters.unbind(),
            traces: traces.unbind(),
            rows: n,
        })
    }

    fn column<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for row in self.parameters.bind(py).iter() {
            let row = row.cast_into::<PyDict>()?;
            if let (Some(p), Some(v)) = (row.get_item("parameter")?, row.get_item(key)?) {
                out.set_item(p, v)?;
            }
        }
        Ok(out)
    }
}

#[pymethods]
impl CommissionResult {
    /// The plant's true values (`rs` is Rs plus the switches' on-resistance: what the drive's
    /// model should hold), by parameter name. A fresh dict.
    #[getter]
    fn truth<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.truth.bind(py).copy()
    }

    /// One dict per parameter (`parameter`, `identified`, `truth`, `error`, `confidence`),
    /// as `metrics.json`'s `parameters`; empty after an abort. A fresh copy.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("copy")?
            .call_method1("deepcopy", (self.parameters.bind(py),))
    }

    /// identified/truth − 1 by parameter (absolute differences for `viscous_friction` in
    /// N·m·s/rad and the inverter voltages in V); empty after an abort.
    #[getter]
    fn errors<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.column(py, "error")
    }

    /// The procedure's own 1-σ statistical uncertainty by parameter (relative; absolute for
    /// `viscous_friction` and the inverter voltages); empty after an abort.
    #[getter]
    fn confidence<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.column(py, "confidence")
    }

    /// The trace columns (`COMMISSION_TRACE_COLUMNS`) as float64 arrays: time (s), phase
    /// (index into `COMMISSION_PHASES`), measured currents i_alpha/i_beta (A), commanded
    /// voltages v_alpha/v_beta and applied ones v_applied_alpha/v_applied_beta (V), true and
    /// estimated speed (r/min), true and estimated electrical angle (rad). A fresh dict; the
    /// arrays are shared.
    #[getter]
    fn traces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.traces.bind(py).copy()
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

    fn __repr__(&self) -> String {
        format!(
            "CommissionResult(passed={}, status={:?}, simulated_seconds={:.3}, rows={})",
            if self.passed { "True" } else { "False" },
            self.status,
            self.simulated_seconds,
            self.rows
        )
    }
}
