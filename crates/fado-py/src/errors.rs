//! The exception hierarchy seen from Python.
//!
//! ```text
//! Exception
//! └── FadoError                      every error fado raises on purpose
//!     ├── ConfigError(…, ValueError)  a configuration field is invalid (`.field` names it)
//!     ├── InputError(…, ValueError)   an input array or argument is unusable (`.argument`)
//!     └── SimulationError             reserved for the simulator bindings
//! ```
//!
//! `ConfigError` and `InputError` also derive from `ValueError`, so code that catches
//! `ValueError` keeps working. Multiple inheritance is not expressible with PyO3's
//! `create_exception!`, so the classes are made once with Python's `type(...)`.

use fado_core::ConfigError;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

/// The Python module the exception classes say they belong to (where users import them).
const PUBLIC_MODULE: &str = "fado";

/// The four exception classes, created together on first use.
pub struct Exceptions {
    /// `FadoError(Exception)`.
    pub fado_error: Py<PyType>,
    /// `ConfigError(FadoError, ValueError)`.
    pub config_error: Py<PyType>,
    /// `InputError(FadoError, ValueError)`.
    pub input_error: Py<PyType>,
    /// `SimulationError(FadoError)`.
    pub simulation_error: Py<PyType>,
}

static EXCEPTIONS: PyOnceLock<Exceptions> = PyOnceLock::new();

fn new_class<'py>(
    py: Python<'py>,
    name: &str,
    bases: Bound<'py, PyTuple>,
    doc: &str,
) -> PyResult<Py<PyType>> {
    let namespace = PyDict::new(py);
    namespace.set_item("__module__", PUBLIC_MODULE)?;
    namespace.set_item("__doc__", doc)?;
    let class = py
        .get_type::<PyType>()
        .call1((name, bases, namespace))?
        .cast_into::<PyType>()?;
    Ok(class.unbind())
}

impl Exceptions {
    /// The classes, created on first call.
    pub fn get(py: Python<'_>) -> PyResult<&Exceptions> {
        EXCEPTIONS.get_or_try_init(py, || {
            let exception = py.get_type::<PyException>();
            let value_error = py.get_type::<PyValueError>();
            let fado_error = new_class(
                py,
                "FadoError",
                PyTuple::new(py, [&exception])?,
                "Base class of every error fado raises on purpose.",
            )?;
            let base = fado_error.bind(py);
            let config_error = new_class(
                py,
                "ConfigError",
                PyTuple::new(py, [base, &value_error])?,
                "A configuration field is invalid; `.field` names it.",
            )?;
            let input_error = new_class(
                py,
                "InputError",
                PyTuple::new(py, [base, &value_error])?,
                "An input array or argument is unusable; `.argument` names it.",
            )?;
            let simulation_error = new_class(
                py,
                "SimulationError",
                PyTuple::new(py, [base])?,
                "A simulation could not be run or failed.",
            )?;
            Ok(Exceptions {
                fado_error,
                config_error,
                input_error,
                simulation_error,
            })
        })
    }

    /// Adds the classes to `module` under their names.
    pub fn register(module: &Bound<'_, PyModule>) -> PyResult<()> {
        let py = module.py();
        let e = Self::get(py)?;
        module.add("FadoError", e.fado_error.bind(py))?;
        module.add("ConfigError", e.config_error.bind(py))?;
        module.add("InputError", e.input_error.bind(py))?;
        module.add("SimulationError", e.simulation_error.bind(py))?;
        Ok(())
    }
}

/// An instance of `class(message)` with one extra attribute, as a `PyErr`.
fn raise_with(
    py: Python<'_>,
    class: &Py<PyType>,
    message: String,
    attribute: &str,
    value: &str,
) -> PyErr {
    let made = class.bind(py).call1((message,)).and_then(|err| {
        err.setattr(attribute, value)?;
        Ok(err)
    });
    match made {
        Ok(err) => PyErr::from_value(err),
        Err(e) => e,
    }
}

/// `fado.ConfigError` for a refused configuration, with `.field` set.
pub fn config_error(py: Python<'_>, error: ConfigError) -> PyErr {
    config_error_message(py, error.field(), error.to_string())
}

/// `fado.ConfigError` with a message of our own, naming `field`.
pub fn config_error_message(py: Python<'_>, field: &str, message: String) -> PyErr {
    match Exceptions::get(py) {
        Ok(e) => raise_with(py, &e.config_error, message, "field", field),
        Err(e) => e,
    }
}

/// `fado.InputError` naming the offending `argument`.
pub fn input_error(py: Python<'_>, argument: &str, message: String) -> PyErr {
    match Exceptions::get(py) {
        Ok(e) => raise_with(
            py,
            &e.input_error,
            format!("{argument}: {message}"),
            "argument",
            argument,
        ),
        Err(e) => e,
    }
}
