//! `fado.Machine(..., flux_map=...)`: a flux map given as a CSV path or as arrays
//! (`fado_sim::magnetics_file`), and back to Python.
//!
//! Arrays come in one of two forms: four 1-D arrays of equal length, one entry per grid node
//! in any order (the CSV's columns), or the axes `i_d` (n_d) and `i_q` (n_q) with `psi_d` and
//! `psi_q` of shape (n_d, n_q). Every refusal of the CSV reader applies; a ConfigError on
//! `flux_map` names the node (its index in the arrays) or the file and line.

use fado_core::MachineModel;
use fado_core::magnetics::MachineMagnetics;
use fado_sim::magnetic_agreement::{Stated, check, rms_currents};
use fado_sim::magnetics::FluxMapData;
use fado_sim::magnetics_file::{FluxMapFile, flux_map_from_rows};
use fado_sim::model_magnetics;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::errors::config_error_message;

/// The keyword, as errors name it.
pub const FLUX_MAP: &str = "flux_map";

fn refuse(py: Python<'_>, message: String) -> PyErr {
    config_error_message(py, FLUX_MAP, format!("`{FLUX_MAP}`: {message}"))
}

/// One argument as float64: its shape and its values in C order.
fn array(py: Python<'_>, obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(Vec<usize>, Vec<f64>)> {
    let np = py.import("numpy")?;
    let a = np
        .call_method1("asarray", (obj, "float64"))
        .map_err(|e| refuse(py, format!("`{name}` is not an array of numbers ({e})")))?;
    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
    let values: Vec<f64> = a.call_method0("ravel")?.call_method0("tolist")?.extract()?;
    Ok((shape, values))
}

/// The map from `flux_map=(i_d, i_q, psi_d, psi_q)`.
fn from_arrays(py: Python<'_>, parts: &Bound<'_, PyAny>) -> PyResult<FluxMapData> {
    let names = ["i_d", "i_q", "psi_d", "psi_q"];
    let items: Vec<Bound<'_, PyAny>> = parts.try_iter()?.collect::<PyResult<_>>()?;
    if items.len() != 4 {
        return Err(refuse(
            py,
            format!(
                "arrays must be four, (i_d, i_q, psi_d, psi_q), got {}",
                items.len()
            ),
        ));
    }
    let mut a = Vec::new();
    for (obj, name) in items.iter().zip(names) {
        a.push(array(py, obj, name)?);
    }
    let (nd, nq) = (a[0].1.len(), a[1].1.len());
    let grid = a[2].0 == [nd, nq] && a[3].0 == [nd, nq] && a[0].0.len() == 1;
    if grid {
        return FluxMapData::new(
            a[0].1.clone(),
            a[1].1.clone(),
            a[2].1.clone(),
            a[3].1.clone(),
        )
        .map_err(|e| refuse(py, format!("{e} (node (k, m) = (i_d[k], i_q[m]))")));
    }
    if a.iter().any(|(s, v)| s.len() != 1 || v.len() != nd) {
        let shapes: Vec<_> = a.iter().map(|(s, _)| format!("{s:?}")).collect();
        return Err(refuse(
            py,
            format!(
                "expected four 1-D arrays of the same length (one entry per node) or the axes \
                 i_d (n_d), i_q (n_q) with psi_d, psi_q of shape (n_d, n_q); got shapes {}",
                shapes.join(", ")
            ),
        ));
    }
    // Rows numbered from 1 as lines: `line − 1` is the node's index in the arrays; line 0
    // (the "header") is the whole grid.
    let rows: Vec<([f64; 4], usize)> = (0..nd)
        .map(|k| ([a[0].1[k], a[1].1[k], a[2].1[k], a[3].1[k]], k + 1))
        .collect();
    flux_map_from_rows(&rows, "arrays", 0).map_err(|e| {
        match e.location.as_ref().map_or(0, |l| l.line) {
            0 => refuse(py, format!("the arrays' grid: {}", e.message)),
            line => refuse(
                py,
                format!("node {} of the arrays: {}", line - 1, e.message),
            ),
        }
    })
}

/// `flux_map` as `Machine` takes it: None, a path (str or `os.PathLike`) or arrays.
pub fn from_argument(py: Python<'_>, obj: &Bound<'_, PyAny>) -> PyResult<Option<FluxMapFile>> {
    if obj.is_none() {
        return Ok(None);
    }
    let fspath = py.import("os")?.getattr("fspath")?;
    if let Ok(path) = fspath.call1((obj,)).and_then(|p| p.extract::<String>()) {
        return FluxMapFile::read(&path)
            .map(Some)
            .map_err(|e| refuse(py, e.to_string()));
    }
    from_arrays(py, obj).map(|d| Some(FluxMapFile::in_memory(d)))
}

/// Refuses a map whose zero-current values disagree with the machine's `ld`, `lq` and
/// `flux_linkage` (`fado_sim::magnetic_agreement`: other units, other axes, another machine);
/// warns where its currents look rms (`fado_sim::magnetic_agreement::rms_currents`).
pub fn check_agreement(py: Python<'_>, model: &MachineModel<f64>, m: &FluxMapFile) -> PyResult<()> {
    let stated = Stated {
        section: "",
        ld: model.ld,
        lq: model.lq,
        flux_linkage: model.flux_linkage,
    };
    check(&m.data.map(), FLUX_MAP, stated).map_err(|e| refuse(py, e.message))?;
    // Currents given rms: a UserWarning naming the slip (the map can still describe a motor).
    if let Some(w) = rms_currents(&m.data.map(), FLUX_MAP, stated, model.rated_current) {
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &std::ffi::CString::new(w).unwrap_or_default(),
            2,
        )?;
    }
    Ok(())
}

/// The map back to Python: its path (as given, resolved), or the four node arrays
/// (i_d-major) of a map given as arrays.
pub fn to_python<'py>(py: Python<'py>, m: &FluxMapFile) -> PyResult<Bound<'py, PyAny>> {
    if let Some(p) = &m.path {
        return Ok(p.display().to_string().into_pyobject(py)?.into_any());
    }
    let map = m.data.map();
    let mut cols: [Vec<f64>; 4] = Default::default();
    let nq = map.i_q().len();
    for (k, &id) in map.i_d().iter().enumerate() {
        for (m, &iq) in map.i_q().iter().enumerate() {
            let at = k * nq + m;
            for (c, v) in cols
                .iter_mut()
                .zip([id, iq, map.psi_d()[at], map.psi_q()[at]])
            {
                c.push(v);
            }
        }
    }
    let np = py.import("numpy")?;
    let arrays = cols
        .into_iter()
        .map(|c| np.call_method1("asarray", (c,)))
        .collect::<PyResult<Vec<_>>>()?;
    Ok(PyTuple::new(py, arrays)?.into_any())
}

/// The map as the estimator's model holds it in `T` (f64, or rounded to f32), interned for
/// the program's life (`fado_sim::model_magnetics`); None when rounding to f32 breaks its
/// monotonicity.
pub fn machine_magnetics<T: 'static + Copy>(m: &FluxMapFile) -> Option<MachineMagnetics<T>> {
    use core::any::Any;
    let f64_map = MachineMagnetics::Map(model_magnetics::interned_map(&m.data));
    if let Some(x) = (&f64_map as &dyn Any).downcast_ref::<MachineMagnetics<T>>() {
        return Some(*x);
    }
    let f32_map = model_magnetics::to_f32(&f64_map)?;
    (&f32_map as &dyn Any)
        .downcast_ref::<MachineMagnetics<T>>()
        .copied()
}
