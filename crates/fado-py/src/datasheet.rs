//! `fado.Machine.from_datasheet`: a machine's fields as its datasheet states them, converted
//! by `fado_core::datasheet` (the conversions `fado-sim`'s `[motor]` table applies too).

use fado_core::datasheet::{self, ALTERNATIVES};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::config_error_message;
use crate::number::number;

/// `fields` with each datasheet key replaced by the fado fields it gives; refused naming the
/// keys when an alternative comes with its fado field or another alternative of that field,
/// or needs `pole_pairs` without it.
pub fn convert<'py>(
    py: Python<'py>,
    fields: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let Some(fields) = fields else {
        return Ok(out);
    };
    let keys: Vec<String> = fields
        .keys()
        .iter()
        .map(|k| k.extract())
        .collect::<PyResult<_>>()?;
    if let Some((other, alt, target)) = datasheet::conflict(keys.iter().map(String::as_str)) {
        return Err(config_error_message(
            py,
            other,
            format!(
                "`{other}` and `{alt}` both give `{target}`: give one of them (`{alt}` is the \
                 datasheet's form, converted to `{target}`)"
            ),
        ));
    }
    for (k, v) in fields.iter() {
        let key: String = k.extract()?;
        if datasheet::alternative(&key).is_some() {
            continue;
        }
        if !crate::machine::is_field(&key) {
            let keys = crate::machine::field_list()
                .chain(fado_core::datasheet::ALTERNATIVES.iter().map(|a| a.key));
            let meant = fado_sim::suggest::did_you_mean(&key, keys);
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "unexpected keyword argument `{key}`{meant}: neither a Machine field ({}) nor a \
                 datasheet key ({})",
                fado_core::ratings::REQUIRED_MOTOR_KEYS.join(", ")
                    + ", inertia, viscous_friction, dc_voltage, flux_map",
                crate::machine::datasheet_keys()
            )));
        }
        out.set_item(k, v)?;
    }
    for alt in &ALTERNATIVES {
        let Some(value) = fields.get_item(alt.key)? else {
            continue;
        };
        let value = number(py, alt.key, Some(&value), 0.0)?;
        if !(value.is_finite() && value > 0.0) {
            return Err(config_error_message(
                py,
                alt.key,
                format!("`{}` must be a positive number in {}", alt.key, alt.unit),
            ));
        }
        let pole_pairs = match fields.get_item("pole_pairs")? {
            Some(p) => Some(number(py, "pole_pairs", Some(&p), 0.0)?),
            None => None,
        };
        if alt.needs_pole_pairs && pole_pairs.is_none() {
            return Err(config_error_message(
                py,
                "pole_pairs",
                format!(
                    "`pole_pairs` is needed to convert `{}` to `flux_linkage`",
                    alt.key
                ),
            ));
        }
        let converted = datasheet::convert(alt, value, pole_pairs.unwrap_or(1.0));
        for target in alt.targets {
            out.set_item(*target, converted)?;
        }
    }
    Ok(out)
}
