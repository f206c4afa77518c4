//! A real-number argument: a Python `int` or `float`, or a numpy real scalar (anything with
//! `__float__` but a `bool`). Python's `float(True)` is 1.0, so a plain `f64` argument takes
//! `ts=True` as a one-second sampling period; a flag where a quantity is meant is a slip, and
//! it is refused naming the argument (`InputError`).

use pyo3::prelude::*;
use pyo3::types::PyBool;

use crate::errors::input_error;

/// The real number `value` of the argument `argument`, or `default` when it is not given;
/// `InputError` naming the argument for a `bool` (`numpy.bool_` included) or anything that
/// is not a real number.
pub fn number(
    py: Python<'_>,
    argument: &str,
    value: Option<&Bound<'_, PyAny>>,
    default: f64,
) -> PyResult<f64> {
    let Some(value) = value else {
        return Ok(default);
    };
    let type_name = value
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_default();
    if value.is_instance_of::<PyBool>() || type_name == "bool" || type_name == "bool_" {
        return Err(input_error(
            py,
            argument,
            format!(
                "must be a number, got the bool {}: a flag is not a quantity",
                value.repr().map(|r| r.to_string()).unwrap_or_default()
            ),
        ));
    }
    value.extract::<f64>().map_err(|_| {
        input_error(
            py,
            argument,
            format!("must be a number (int, float or numpy real scalar), got {type_name}"),
        )
    })
}
