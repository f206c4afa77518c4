//! `fado._fado.compare`: fado against the baseline estimators in the simulator
//! ([`fado_sim::compare`]), run with the GIL released. The Python face (`fado.compare`) wraps
//! the list of row dicts in a small result object.

use fado_sim::compare::{CompareOptions, CompareRow, compare as run_compare, parse_estimator};
use fado_sim::sim::{Trace, TraceRow};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::errors::config_error_message;

/// The estimators `compare` runs by default, in its order: the names of the simulator's
/// registry ([`fado_sim::estimators::ESTIMATORS`]).
#[pyfunction]
pub fn estimators() -> Vec<&'static str> {
    fado_sim::estimators::names()
}

/// Runs every estimator in every scenario on the same plant, seed and controllers and
/// returns one dict per (scenario, estimator), scenario-major.
///
/// Keys: scenario, estimator, passed, passed_common, zero_speed_samples,
/// max_angle_error_zero_speed, rms_angle_error_zero_speed, max_angle_error, rms_angle_error,
/// max_speed_error_rpm, tripped, lowest_speed_held_rpm (``None`` outside ``lowspeed``),
/// levels (list of dicts), checks (list of dicts), simulated_seconds, wall_seconds and, with
/// ``traces=True``, trace (dict of 1-D float64 arrays, the ``traces.csv`` columns).
/// ``config`` is TOML applied over every scenario (its ``[simulation] estimator`` is replaced).
/// Raises ``ConfigError`` naming the key for an unknown scenario, estimator or bad TOML.
#[pyfunction]
#[pyo3(
    signature = (scenarios = None, estimators = None, averaged = false, *, config = None, traces = false, threads = 2),
    text_signature = "(scenarios=None, estimators=None, averaged=False, *, config=None, traces=False, threads=2)"
)]
pub fn compare(
    py: Python<'_>,
    scenarios: Option<Vec<String>>,
    estimators: Option<Vec<String>>,
    averaged: bool,
    config: Option<String>,
    traces: bool,
    threads: usize,
) -> PyResult<Py<PyList>> {
    let mut opts = CompareOptions {
        averaged,
        config_toml: config,
        keep_traces: traces,
        threads: crate::sweep::capped_threads(py, threads)?,
        ..Default::default()
    };
    if let Some(s) = scenarios {
        opts.scenarios = s;
    }
    if let Some(e) = estimators {
        opts.estimators = e
            .iter()
            .map(|n| parse_estimator(n))
            .collect::<Result<_, _>>()
            .map_err(|e| config_error_message(py, &e.key, e.to_string()))?;
    }
    let result = py
        .detach(|| run_compare(&opts))
        .map_err(|e| config_error_message(py, &e.key, e.to_string()))?;
    let list = PyList::empty(py);
    for row in &result.rows {
        list.append(row_dict(py, row)?)?;
    }
    Ok(list.unbind())
}

fn row_dict<'py>(py: Python<'py>, r: &CompareRow) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("scenario", &r.scenario)?;
    d.set_item("estimator", &r.estimator)?;
    d.set_item("passed", r.passed)?;
    d.set_item("passed_common", r.passed_common)?;
    d.set_item("zero_speed_samples", r.zero_speed_samples)?;
    d.set_item("max_angle_error_zero_speed", r.max_angle_error_zero_speed)?;
    d.set_item("rms_angle_error_zero_speed", r.rms_angle_error_zero_speed)?;
    d.set_item("max_angle_error", r.max_angle_error)?;
    d.set_item("rms_angle_error", r.rms_angle_error)?;
    d.set_item("max_speed_error_rpm", r.max_speed_error_rpm)?;
    d.set_item("tripped", r.tripped)?;
    d.set_item("lowest_speed_held_rpm", r.lowest_speed_held_rpm)?;
    let levels = PyList::empty(py);
    for l in &r.levels {
        let ld = PyDict::new(py);
        ld.set_item("level_rpm", l.level_rpm)?;
        ld.set_item("from", l.from)?;
        ld.set_item("to", l.to)?;
        ld.set_item("samples", l.samples)?;
        ld.set_item("max_angle_error", l.max_angle_error)?;
        ld.set_item("max_speed_error_rpm", l.max_speed_error_rpm)?;
        ld.set_item("mean_speed_rpm", l.mean_speed_rpm)?;
        ld.set_item("tripped", l.tripped)?;
        ld.set_item("held", l.held())?;
        levels.append(ld)?;
    }
    d.set_item("levels", levels)?;
    let checks = PyList::empty(py);
    for c in &r.checks {
        let cd = PyDict::new(py);
        cd.set_item("name", &c.name)?;
        cd.set_item("value", c.value)?;
        cd.set_item("min", c.min)?;
        cd.set_item("max", c.max)?;
        cd.set_item("passed", c.passed)?;
        checks.append(cd)?;
    }
    d.set_item("checks", checks)?;
    d.set_item("simulated_seconds", r.simulated_seconds)?;
    d.set_item("wall_seconds", r.wall_seconds)?;
    if let Some(t) = &r.trace {
        d.set_item("trace", trace_dict(py, t)?)?;
    }
    Ok(d)
}

/// The trace as one float64 array per `traces.csv` column.
fn trace_dict<'py>(py: Python<'py>, t: &Trace) -> PyResult<Bound<'py, PyDict>> {
    let mut columns = vec![Vec::with_capacity(t.rows.len()); TraceRow::COLUMNS.len()];
    for row in &t.rows {
        for (col, v) in columns.iter_mut().zip(row.values()) {
            col.push(v);
        }
    }
    let d = PyDict::new(py);
    for (name, col) in TraceRow::COLUMNS.iter().zip(columns) {
        d.set_item(*name, PyArray1::from_vec(py, col))?;
    }
    Ok(d)
}
