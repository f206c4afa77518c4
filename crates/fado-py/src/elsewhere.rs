//! Where a keyword or key that one function refuses belongs: an argument of another function
//! (`ts` of `fado.estimate`), a field of the other record (`k_af` of `EstimatorConfig` given
//! to `Machine`), a key of a table of the simulator's configuration (`switching_frequency` of
//! `[inverter]`), or a datasheet key of `Machine.from_datasheet`. The refusals of `Machine`,
//! `EstimatorConfig`, `estimate`, `Estimator`, `simulate`, `sweep` and `commission` append it
//! after the closest name the refusing function itself takes.

use pyo3::prelude::*;

/// The keyword arguments of fado's functions that users give to another one, with the
/// functions that take each and what it is.
const ARGUMENTS: [(&str, &str); 10] = [
    (
        "ts",
        "the sampling period (s), the `ts=` argument of fado.estimate and fado.Estimator; the \
         simulated drive of fado.simulate and fado.commission samples once per PWM period, set \
         by `switching_frequency` in its config's [inverter] table \
         ({\"inverter\": {\"switching_frequency\": …}})",
    ),
    (
        "switching_frequency",
        "the PWM frequency (Hz), a key of the simulator's [inverter] table: fado.simulate's, \
         fado.sweep's and fado.commission's `config` ({\"inverter\": {\"switching_frequency\": \
         …}}); fado.estimate and fado.Estimator take the sampling period `ts=` (s) instead",
    ),
    (
        "theta0",
        "the initial electrical angle (rad), an argument of fado.estimate, fado.Estimator and \
         fado.commission",
    ),
    ("dtype", "an argument of fado.estimate and fado.Estimator"),
    (
        "machine",
        "the motor's model, an argument of fado.estimate and fado.Estimator (fado.simulate and \
         fado.commission call it `motor=`)",
    ),
    (
        "motor",
        "the plant, an argument of fado.simulate and fado.commission (fado.estimate and \
         fado.Estimator call it `machine=`)",
    ),
    ("nameplate", "an argument of fado.commission"),
    (
        "seed",
        "an argument of fado.commission (the current sensors' noise seed); in fado.simulate's \
         config it is the key `seed` of [current_sensor] ({\"current_sensor\": {\"seed\": …}})",
    ),
    (
        "averaged",
        "an argument of fado.simulate, fado.sweep and fado.commission",
    ),
    (
        "dc_voltage",
        "a Machine field (fado.Machine(dc_voltage=…)) and a key of the simulator's [inverter] \
         table ({\"inverter\": {\"dc_voltage\": …}})",
    ),
];

/// What follows the refusal of `key` by `function` (`Machine`, `EstimatorConfig`,
/// `estimate`, …), whose own names are `candidates`: where `key` belongs ("; `ts` is the
/// sampling period, …") and the nearest of `candidates`, or that nearest name alone ("; did you
/// mean `rs`?") when fado knows no other place; empty when there is neither.
pub fn hint<'a>(
    py: Python<'_>,
    key: &str,
    function: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> String {
    let meant = fado_sim::suggest::did_you_mean(key, candidates);
    match place(py, key, function) {
        Some(p) if meant.is_empty() => format!("; `{key}` is {p}"),
        Some(p) => format!("; `{key}` is {p}; as a {function} keyword{meant}"),
        None => meant,
    }
}

fn place(py: Python<'_>, key: &str, function: &str) -> Option<String> {
    if let Some((_, what)) = ARGUMENTS.iter().find(|(k, _)| *k == key) {
        return Some((*what).to_owned());
    }
    if function != "Machine" && crate::machine::is_field(key) {
        return Some(format!(
            "a Machine field: fado.Machine({key}=…), the `machine=` of fado.estimate or the \
             [motor] table of the simulator's config ({{\"motor\": {{\"{key}\": …}}}})"
        ));
    }
    if function == "Machine"
        && fado_core::datasheet::ALTERNATIVES
            .iter()
            .any(|a| a.key == key)
    {
        return Some(format!(
            "a datasheet key: Machine.from_datasheet({key}=…) converts it (or [motor] in a \
             simulator config)"
        ));
    }
    let estimator = crate::config::PyEstimatorConfig::field_names(py).ok()?;
    if function != "EstimatorConfig" && estimator.iter().any(|f| f == key) {
        return Some(format!(
            "an estimator setting: fado.EstimatorConfig({key}=…), the `config` of fado.estimate \
             or the [estimator] table of the simulator's config"
        ));
    }
    let tables = fado_sim::suggest::tables_holding(key);
    let first = tables.first()?;
    let names: Vec<String> = tables.iter().map(|t| format!("[{t}]")).collect();
    Some(format!(
        "a key of the simulator's {} table: fado.simulate's, fado.sweep's and fado.commission's \
         `config` ({{\"{first}\": {{\"{key}\": …}}}})",
        names.join(", ")
    ))
}

/// The message of the `TypeError` for the keyword `key` that `function` (with the keywords
/// `accepted`) does not take: the closest of `accepted`, then where `key` belongs
/// ([`hint`]). Called by the Python wrappers (`fado.simulate`, `fado.sweep`,
/// `fado.commission`) before they run.
#[pyfunction]
#[pyo3(name = "_unexpected_keyword")]
pub fn unexpected_keyword(
    py: Python<'_>,
    function: &str,
    key: &str,
    accepted: Vec<String>,
) -> String {
    unexpected(py, function, key, accepted.iter().map(String::as_str))
}

/// [`unexpected_keyword`] for a function written in Rust.
pub fn unexpected<'a>(
    py: Python<'_>,
    function: &str,
    key: &str,
    accepted: impl Iterator<Item = &'a str> + Clone,
) -> String {
    let list: Vec<&str> = accepted.clone().collect();
    format!(
        "{function}() got an unexpected keyword argument `{key}`{}; it takes {list:?}",
        hint(py, key, function, accepted)
    )
}

/// `TypeError` ([`unexpected`]) for the first keyword of `unknown` (the `**unknown` of a
/// function written in Rust, `function`, whose keywords are `accepted`); Ok when it is empty.
pub fn refuse_unknown(
    py: Python<'_>,
    function: &str,
    unknown: Option<&Bound<'_, pyo3::types::PyDict>>,
    accepted: &[&str],
) -> PyResult<()> {
    let Some(key) = unknown.and_then(|u| u.keys().iter().next()) else {
        return Ok(());
    };
    let key: String = key.extract()?;
    Err(pyo3::exceptions::PyTypeError::new_err(unexpected(
        py,
        function,
        &key,
        accepted.iter().copied(),
    )))
}
