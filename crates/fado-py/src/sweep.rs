//! `fado._fado.sweep` and `fado._fado.sweep_point`: operating-envelope sweeps of `fado-sim`
//! ([`fado_sim::sweep`]) from Python. `sweep` runs every point in Rust on a rayon pool with
//! the GIL released; `sweep_point` runs one point, for `fado.sweep(..., executor=...)` to
//! spread the points over processes or machines. Both return the same row dicts.

use std::io::Write;
use std::sync::Arc;

use fado_sim::sweep::{self as engine, PointResult, SweepError, SweepOptions, SweepSpec, Value};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString};

use crate::errors::input_error;
use crate::interrupt;
use crate::simulate::sim_error;

fn sweep_error(py: Python<'_>, e: SweepError) -> PyErr {
    match e {
        SweepError::Config(e) => sim_error(py, e),
        SweepError::Io(e) => {
            let errno = e.source.raw_os_error();
            let message = e.to_string();
            match errno {
                Some(n) => PyOSError::new_err((n, message, e.path.display().to_string())),
                None => PyOSError::new_err(message),
            }
        }
        SweepError::Mismatch(m) => PyValueError::new_err(m),
        SweepError::Threads(m) => pyo3::exceptions::PyRuntimeError::new_err(m),
        SweepError::Cancelled => {
            pyo3::exceptions::PyKeyboardInterrupt::new_err("sweep interrupted")
        }
    }
}

/// A Python bool, int, float or str as a TOML value.
fn to_value(py: Python<'_>, name: &str, v: &Bound<'_, PyAny>) -> PyResult<Value> {
    if v.is_instance_of::<PyBool>() {
        Ok(Value::Boolean(v.extract()?))
    } else if v.is_instance_of::<PyInt>() {
        Ok(Value::Integer(v.extract()?))
    } else if v.is_instance_of::<PyFloat>() {
        Ok(Value::Float(v.extract()?))
    } else if v.is_instance_of::<PyString>() {
        Ok(Value::String(v.extract()?))
    } else if let Ok(x) = v.extract::<f64>() {
        // numpy scalars and other numbers
        Ok(Value::Float(x))
    } else {
        Err(input_error(
            py,
            name,
            format!(
                "sweep values must be bool, int, float or str, got {}",
                v.get_type().name()?
            ),
        ))
    }
}

fn to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Boolean(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        Value::Float(x) => x.into_pyobject(py)?.into_any(),
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        other => other.to_string().into_pyobject(py)?.into_any(),
    })
}

fn spec_of(
    py: Python<'_>,
    scenario: &str,
    axes: Vec<String>,
    points: &[Vec<Bound<'_, PyAny>>],
    config: Option<String>,
    averaged: bool,
) -> PyResult<SweepSpec> {
    let mut values = Vec::with_capacity(points.len());
    for p in points {
        if p.len() != axes.len() {
            return Err(input_error(
                py,
                "points",
                format!("a point has {} values for {} axes", p.len(), axes.len()),
            ));
        }
        let row = axes
            .iter()
            .zip(p)
            .map(|(n, v)| to_value(py, n, v))
            .collect::<PyResult<Vec<_>>>()?;
        values.push(row);
    }
    Ok(SweepSpec {
        scenario: scenario.to_owned(),
        config_toml: config,
        averaged,
        axes,
        points: values,
        design: "points".to_owned(),
    })
}

/// `requested` worker threads capped at the machine's cores ([`fado_sim::threads`]), with a
/// `RuntimeWarning` when more were asked for.
pub(crate) fn capped_threads(py: Python<'_>, requested: usize) -> PyResult<usize> {
    let (threads, warning) = fado_sim::threads::capped(requested);
    if let Some(w) = warning {
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyRuntimeWarning>(),
            &std::ffi::CString::new(w).unwrap_or_default(),
            1,
        )?;
    }
    Ok(threads)
}

/// One row: point, the axes, status, passed, tripped, the metrics, failed_checks.
fn row_dict<'py>(
    py: Python<'py>,
    axes: &[String],
    r: &PointResult,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("point", r.index)?;
    for (name, v) in axes.iter().zip(&r.values) {
        d.set_item(name, to_py(py, v)?)?;
    }
    d.set_item("status", r.status.to_string())?;
    d.set_item("passed", r.passed)?;
    d.set_item("tripped", r.tripped)?;
    d.set_item("max_angle_error", r.max_angle_error)?;
    d.set_item("rms_angle_error", r.rms_angle_error)?;
    d.set_item("max_angle_error_zero_speed", r.max_angle_error_zero_speed)?;
    d.set_item("rms_angle_error_zero_speed", r.rms_angle_error_zero_speed)?;
    d.set_item("max_speed_error_rpm", r.max_speed_error_rpm)?;
    d.set_item("wall_seconds", r.wall_seconds)?;
    d.set_item("failed_checks", &r.failed_checks)?;
    Ok(d)
}

/// Runs `scenario` once per point (a list of value lists, one value per name in `axes`) on
/// `threads` threads (0: all cores) with the GIL released, and returns one dict per point in
/// point order. Parameters are TOML keys (``section.key``) or the derived ``rs_error``,
/// ``lq_error``, ``ld_error``, ``flux_linkage_error``, ``dead_time_comp_error``,
/// ``sensor_offset``, ``sensor_gain_error``, ``load_torque``, ``reversal_ramp``. With
/// ``out``, writes ``sweep.csv``/``sweep.json``/``summary.*`` there and resumes a sweep
/// interrupted in it (``fresh=True``: start over). A point that fails or diverges is a row
/// with that ``status``, never an exception. ``threads`` above the machine's cores is capped
/// with a ``RuntimeWarning``. Ctrl-C stops the sweep within milliseconds
/// (``KeyboardInterrupt``); the points finished are in ``out``'s ``sweep.csv`` and the same
/// call resumes from them.
#[pyfunction]
#[pyo3(
    signature = (scenario, axes, points, *, config = None, averaged = false, threads = 0, out = None, fresh = false, progress = false),
    text_signature = "(scenario, axes, points, *, config=None, averaged=False, threads=0, out=None, fresh=False, progress=False)"
)]
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    py: Python<'_>,
    scenario: &str,
    axes: Vec<String>,
    points: Vec<Vec<Bound<'_, PyAny>>>,
    config: Option<String>,
    averaged: bool,
    threads: usize,
    out: Option<std::path::PathBuf>,
    fresh: bool,
    progress: bool,
) -> PyResult<Py<PyList>> {
    let spec = spec_of(py, scenario, axes, &points, config, averaged)?;
    let threads = capped_threads(py, threads)?;
    let total = spec.points.len();
    let outcome = interrupt::run(py, |cancel| {
        let opts = SweepOptions {
            threads,
            out,
            fresh,
            cancel: Some(Arc::clone(cancel)),
        };
        engine::run(&spec, &opts, &|_, finished| {
            if progress {
                let _ = write!(std::io::stderr().lock(), "\rsweep {finished}/{total}");
            }
        })
    })?
    .map_err(|e| sweep_error(py, e))?;
    if progress {
        let _ = writeln!(std::io::stderr().lock());
    }
    let list = PyList::empty(py);
    for r in &outcome.rows {
        list.append(row_dict(py, &spec.axes, r)?)?;
    }
    Ok(list.unbind())
}

/// Runs one point of a sweep (what `sweep` does for each point) and returns its row dict,
/// with ``point`` = ``index``. The GIL is released while it runs; Ctrl-C stops it.
#[pyfunction]
#[pyo3(
    signature = (scenario, axes, values, *, config = None, averaged = false, index = 0),
    text_signature = "(scenario, axes, values, *, config=None, averaged=False, index=0)"
)]
pub fn sweep_point(
    py: Python<'_>,
    scenario: &str,
    axes: Vec<String>,
    values: Vec<Bound<'_, PyAny>>,
    config: Option<String>,
    averaged: bool,
    index: usize,
) -> PyResult<Py<PyDict>> {
    let spec = spec_of(py, scenario, axes, &[values], config, averaged)?;
    let base = spec.base_config().map_err(|e| sim_error(py, e))?;
    let r = interrupt::run(py, |cancel| {
        engine::run_point_until(
            &spec.scenario,
            &base,
            &spec.axes,
            &spec.points[0],
            index,
            Some(cancel.as_ref()),
        )
    })?
    // None only when cancelled, and then `interrupt::run` raised.
    .ok_or_else(|| pyo3::exceptions::PyKeyboardInterrupt::new_err("sweep point interrupted"))?;
    Ok(row_dict(py, &spec.axes, &r)?.unbind())
}
