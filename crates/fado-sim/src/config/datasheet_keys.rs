//! The `[motor]` keys a datasheet states (`fado_core::datasheet`): converted to fado's keys
//! when the file is read, before anything else sees it, and recorded with their conversion so
//! that `--dump-config` prints the fado value beside the rule that gave it.

use fado_core::datasheet::{self, ALTERNATIVES};

use crate::derive::Derived;
use crate::error::SimConfigError;

fn number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(n) => Some(*n as f64),
        _ => None,
    }
}

/// Replaces each datasheet key of the user's `[motor]` by the fado keys it gives; returns them
/// with their rule. Refused, naming the keys: an alternative with its fado key or with another
/// alternative of the same key, a value that is not a number, a conversion that needs
/// `pole_pairs` without it.
pub(super) fn convert(user: &mut toml::Table) -> Result<Vec<Derived>, SimConfigError> {
    let Some(toml::Value::Table(motor)) = user.get_mut("motor") else {
        return Ok(Vec::new());
    };
    let keys: Vec<&str> = motor.keys().map(String::as_str).collect();
    if let Some((other, alt, target)) = datasheet::conflict(keys.iter().copied()) {
        return Err(SimConfigError::new(
            format!("motor.{other}"),
            format!(
                "`motor.{other}` and `motor.{alt}` both give `motor.{target}`: give one of \
                 them (`{alt}` is the datasheet's form, converted to `{target}`)"
            ),
        ));
    }
    let mut out = Vec::new();
    for alt in &ALTERNATIVES {
        let Some(value) = motor.get(alt.key) else {
            continue;
        };
        let key = format!("motor.{}", alt.key);
        let value = number(value)
            .filter(|x| x.is_finite() && *x > 0.0)
            .ok_or_else(|| {
                SimConfigError::new(&key, format!("must be a positive number in {}", alt.unit))
            })?;
        let pole_pairs = motor.get("pole_pairs").and_then(number);
        if alt.needs_pole_pairs && pole_pairs.is_none() {
            return Err(SimConfigError::new(
                "motor.pole_pairs",
                format!("`motor.pole_pairs` is needed to convert `{key}` to `motor.flux_linkage`"),
            ));
        }
        let converted = datasheet::convert(alt, value, pole_pairs.unwrap_or(1.0));
        motor.remove(alt.key);
        for target in alt.targets {
            motor.insert((*target).to_owned(), toml::Value::Float(converted));
            out.push(Derived {
                key: format!("motor.{target}"),
                value: converted,
                rule: alt.rule,
            });
        }
    }
    Ok(out)
}
