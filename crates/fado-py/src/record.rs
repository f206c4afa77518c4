//! Python views of fado-core's serde records (`MachineModel`, `EstimatorTuning`).
//!
//! The Python classes hold the core record itself and learn its fields from the record's
//! `serde` derive (the same derive that makes it a TOML table in `fado-sim`): a field added to
//! the core appears in Python — keyword, attribute, `to_dict`, `repr`, pickling — with no edit
//! here. The one other place that names the fields is the type stub (`python/fado/_fado.pyi`),
//! which `mypy.stubtest` checks against the runtime.
//!
//! The record goes through JSON text: `serde_json` writes a struct's fields in declaration
//! order and Python's `json` module keeps that order in a `dict`; Python's `float` `repr` and
//! `serde_json`'s shortest round-trip formatting make the passage exact for every finite `f64`.
//! Non-finite numbers have no JSON spelling and are refused before, naming the field.

use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyString};
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::errors::config_error_message;

static JSON: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

fn json(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    Ok(JSON
        .get_or_try_init(py, || Ok::<_, PyErr>(py.import("json")?.unbind()))?
        .bind(py))
}

/// `value`'s fields as a Python `dict`, in declaration order.
pub fn to_dict<'py, T: Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyDict>> {
    let text = serde_json::to_string(value)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    Ok(json(py)?
        .call_method1("loads", (text,))?
        .cast_into::<PyDict>()?)
}

/// `value`'s field names, in declaration order.
pub fn field_names<T: Serialize>(py: Python<'_>, value: &T) -> PyResult<Vec<String>> {
    to_dict(py, value)?
        .keys()
        .iter()
        .map(|k| k.extract::<String>())
        .collect()
}

/// `value` as a plain Python number when it is a number of another type (a numpy scalar such
/// as `np.float32(0.3)` or `np.int64(4)`, registered with the `numbers` ABCs): an `int` for
/// an integral one, a `float` for a real one; any other value unchanged.
pub fn plain_number<'py>(
    py: Python<'py>,
    value: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    if value.is_instance_of::<PyFloat>()
        || value.is_instance_of::<PyInt>()
        || value.is_instance_of::<PyBool>()
        || value.is_instance_of::<PyString>()
    {
        return Ok(value.clone());
    }
    // A numpy 0-d array (`np.array(0.3)`, `x.sum(keepdims=False)` of an array) or a numpy
    // scalar not registered with the `numbers` ABCs (`np.bool_`): its Python value.
    if value
        .getattr("ndim")
        .is_ok_and(|n| n.extract::<usize>().is_ok_and(|n| n == 0))
        && value.hasattr("item")?
    {
        return plain_number(py, &value.call_method0("item")?);
    }
    let numbers = py.import("numbers")?;
    if value.is_instance(&numbers.getattr("Integral")?)? {
        return value.call_method0("__index__");
    }
    if value.is_instance(&numbers.getattr("Real")?)? {
        return Ok(PyFloat::new(py, value.extract::<f64>()?).into_any());
    }
    Ok(value.clone())
}

/// `value` as an `int` when the field's `current` value is a count (an `int`, not a `bool`)
/// and `value` a whole float (`4.0`, a pole count read from a float column); otherwise
/// unchanged, and a fractional float is refused by the field's type.
fn whole_for_count<'py>(
    py: Python<'py>,
    current: &Bound<'py, PyAny>,
    value: Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let count = current.is_instance_of::<PyInt>() && !current.is_instance_of::<PyBool>();
    if let (true, Ok(f)) = (count, value.cast::<PyFloat>()) {
        let x = f.value();
        if x.is_finite() && x.fract() == 0.0 && x.abs() < 9.0e15 {
            return Ok(PyInt::new(py, x as i64).into_any());
        }
    }
    Ok(value)
}

/// The JSON-representable Python value of field `field`, or `ConfigError` naming it (a
/// non-finite number, or anything but a bool, int, float or str).
fn plain_value<'py>(py: Python<'py>, field: &str, value: &Bound<'py, PyAny>) -> PyResult<()> {
    if let Ok(f) = value.cast::<PyFloat>() {
        let v = f.value();
        if !v.is_finite() {
            return Err(config_error_message(
                py,
                field,
                format!("`{field}` must be finite, got {v}"),
            ));
        }
        return Ok(());
    }
    if value.is_instance_of::<PyBool>()
        || value.is_instance_of::<PyInt>()
        || value.is_instance_of::<PyString>()
    {
        return Ok(());
    }
    if let Ok(shape) = value.getattr("shape") {
        // An array (`np.array([0.3])`, a column of a table): one number is meant.
        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "`{field}` must be one number, got an array of shape {}: pass one value (x.item() \
             for a one-element array)",
            shape.str()?
        )));
    }
    Err(pyo3::exceptions::PyTypeError::new_err(format!(
        "`{field}` must be a number, a bool or a str, got {}",
        value.get_type().name()?
    )))
}

/// The record `T` read from `dict` (a whole or partial record: absent fields take
/// `T::default()`'s values, by the record's `serde(default)`), or the serde message.
fn from_dict<T: DeserializeOwned>(
    py: Python<'_>,
    dict: &Bound<'_, PyDict>,
) -> PyResult<Result<T, String>> {
    let text: String = json(py)?.call_method1("dumps", (dict,))?.extract()?;
    Ok(serde_json::from_str::<T>(&text).map_err(|e| {
        // serde_json appends the position in our JSON text, which means nothing to the user.
        let m = e.to_string();
        match m.find(" at line ") {
            Some(at) => m[..at].to_owned(),
            None => m,
        }
    }))
}

/// `base` with `changes` (field name → Python value) applied, through serde; not validated.
///
/// As Python's keyword arguments do, a key that is not a field or a value of the wrong type
/// (a str for a number, a float for a count) raises `TypeError`; a value of the right type
/// that the field cannot take (a negative count, an unknown spelling, a non-finite number)
/// raises `ConfigError` (a `ValueError`). Each names the key as the user wrote it,
/// `shown(key)`; `kind` says what a field is ("an estimator setting"). A field that is a
/// record of its own (a nested table, `lock`) takes a `dict` of some of its fields, merged
/// into the current ones; its fields are named `shown("lock.heal_time")`.
pub fn with_changes<T>(
    py: Python<'_>,
    base: &T,
    changes: &Bound<'_, PyDict>,
    kind: &str,
    shown: &dyn Fn(&str) -> String,
) -> PyResult<T>
where
    T: Serialize + DeserializeOwned,
{
    let merged = to_dict(py, base)?;
    for (key, value) in changes.iter() {
        let key: String = key.extract()?;
        let name = shown(&key);
        let Some(current) = merged.get_item(&key)? else {
            let fields = field_names(py, base)?;
            let function = if kind.contains("Machine") {
                "Machine"
            } else {
                "EstimatorConfig"
            };
            let meant =
                crate::elsewhere::hint(py, &key, function, fields.iter().map(String::as_str));
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "unexpected keyword argument `{name}`: not {kind}{meant}; one of {fields:?}"
            )));
        };
        if let Ok(table) = current.cast::<PyDict>() {
            let table = table.copy()?;
            merge_record::<T>(py, &key, &table, &value, shown)?;
            merged.set_item(&key, table)?;
            continue;
        }
        let value = whole_for_count(py, &current, plain_number(py, &value)?)?;
        plain_value(py, &name, &value)?;
        let one = PyDict::new(py);
        one.set_item(&key, &value)?;
        check_one::<T>(py, &one, &name)?;
        merged.set_item(&key, value)?;
    }
    from_dict::<T>(py, &merged)?.map_err(pyo3::exceptions::PyRuntimeError::new_err)
}

/// Merges `given` (a `dict` of some fields of the nested record `key`) into `table`, its
/// current fields, each checked on its own as [`with_changes`] checks a field.
fn merge_record<T: DeserializeOwned>(
    py: Python<'_>,
    key: &str,
    table: &Bound<'_, PyDict>,
    given: &Bound<'_, PyAny>,
    shown: &dyn Fn(&str) -> String,
) -> PyResult<()> {
    let fields = || -> PyResult<Vec<String>> {
        table.keys().iter().map(|k| k.extract::<String>()).collect()
    };
    let Ok(given) = given.cast::<PyDict>() else {
        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "`{}` must be a dict of some of its fields {:?}, got {}",
            shown(key),
            fields()?,
            given.get_type().name()?
        )));
    };
    for (sub, value) in given.iter() {
        let sub: String = sub.extract()?;
        let name = shown(&format!("{key}.{sub}"));
        if !table.contains(&sub)? {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "unexpected key `{name}`: not a field of `{}`; one of {:?}",
                shown(key),
                fields()?
            )));
        }
        let value = plain_number(py, &value)?;
        plain_value(py, &name, &value)?;
        let inner = PyDict::new(py);
        inner.set_item(&sub, &value)?;
        let one = PyDict::new(py);
        one.set_item(key, inner)?;
        check_one::<T>(py, &one, &name)?;
        table.set_item(&sub, value)?;
    }
    Ok(())
}

/// Reads the partial record `one` (one field) so that a serde refusal names that field,
/// `name`: a wrong type as `TypeError`, a value the field cannot take as `ConfigError`.
fn check_one<T: DeserializeOwned>(
    py: Python<'_>,
    one: &Bound<'_, PyDict>,
    name: &str,
) -> PyResult<()> {
    if let Err(message) = from_dict::<T>(py, one)? {
        let wrong_type =
            message.starts_with("invalid type: ") || message.contains(": invalid type: ");
        let message = match message.strip_prefix("invalid type: floating point `") {
            Some(rest)
                if message.ends_with("expected u32") || message.ends_with("expected u64") =>
            {
                let value = rest.split('`').next().unwrap_or(rest);
                format!("`{name}` is a count: it must be a whole number, got {value}")
            }
            _ => format!("`{name}`: {message}"),
        };
        return Err(if wrong_type {
            pyo3::exceptions::PyTypeError::new_err(message)
        } else {
            config_error_message(py, name, message)
        });
    }
    Ok(())
}

/// The Python half of [`install`]: run once per class at module initialisation.
const INSTALL: &std::ffi::CStr = cr#"
import inspect

def install(cls, params, extra):
    """Attributes, constructor signature and `replace` of a record class whose fields are
    known at run time only: `params` lists (name, default), default `inspect.Parameter.empty`
    for a required keyword; `extra` lists optional keywords that are not fields (their
    attributes are the class's own)."""
    P = inspect.Parameter
    for name, _ in params:
        def get(self, _name=name):
            return self.to_dict()[_name]
        setattr(cls, name, property(get, doc=f"The field `{name}` (read-only)."))
    params_all = list(params) + [(name, None) for name in extra]
    cls.__signature__ = inspect.Signature(
        [P(name, P.KEYWORD_ONLY, default=default) for name, default in params_all]
    )
    changed = cls._replace

    def replace(self, /, **changes):
        return changed(self, changes)

    replace.__signature__ = inspect.Signature(
        [P("self", P.POSITIONAL_ONLY)] + [P(name, P.KEYWORD_ONLY, default=None) for name, _ in params_all]
    )
    replace.__doc__ = changed.__doc__
    replace.__name__ = "replace"
    replace.__qualname__ = cls.__name__ + ".replace"
    replace.__module__ = cls.__module__
    cls.replace = replace

    def __repr__(self):
        fields = ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items())
        return f"{cls.__name__}({fields})"

    def __getnewargs_ex__(self):
        """Pickling: rebuilt through the keyword constructor."""
        return ((), self.to_dict())

    cls.__repr__ = __repr__
    cls.__getnewargs_ex__ = __getnewargs_ex__
    cls.fields = tuple(name for name, _ in params)
"#;

/// Gives the record class `class` what its fields decide and a `#[pyclass]` cannot declare
/// when they are known only at run time: a read-only attribute per field (`config.k_df`), the
/// keyword-only signature of the constructor (`inspect.signature(class)`, `help`), a
/// `replace(**changes)` with that signature calling the class's `_replace(changes)`, the
/// `fields` tuple, `__repr__` and pickling (through the keyword constructor and `to_dict`).
/// `params` lists the fields in order with their defaults, `None` for a required keyword.
/// `extra` names optional keywords (default None) that are not fields.
pub fn install(
    class: &Bound<'_, pyo3::types::PyType>,
    params: Vec<(String, Option<Bound<'_, PyAny>>)>,
    extra: &[&str],
) -> PyResult<()> {
    let py = class.py();
    let module = PyModule::from_code(py, INSTALL, c"fado/_record.py", c"fado._record")?;
    let empty = py
        .import("inspect")?
        .getattr("Parameter")?
        .getattr("empty")?;
    let params = params
        .into_iter()
        .map(|(name, default)| (name, default.unwrap_or_else(|| empty.clone())))
        .collect::<Vec<_>>();
    module
        .getattr("install")?
        .call1((class, params, extra.to_vec()))?;
    Ok(())
}
