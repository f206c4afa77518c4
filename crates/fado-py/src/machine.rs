//! `fado.Machine`: the motor's parameters and ratings (`fado_core::MachineModel`), the model
//! every estimator is built around, and the motor presets of the repository's `motors/`
//! folder (`fado_sim::presets`).
//!
//! The Python class holds the core record and takes its fields from the record's serde derive
//! ([`crate::record`]), plus `dc_voltage`, which the record keeps out of its TOML table (there
//! it is the simulator's `[inverter] dc_voltage`) but a machine given alone needs (derived
//! from the ratings when left out, as the simulator derives it). Validation
//! is the core's (`MachineModel::validate`: signs, finiteness and unit slips); a refusal raises
//! `fado.ConfigError` (a `ValueError`) whose `.field` names the field.

use fado_core::MachineModel;
use fado_sim::magnetics_file::FluxMapFile;
use fado_sim::presets::{PRESETS, find};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::errors::{config_error, config_error_message};
use crate::record;

/// The constructor's keywords without `flux_map`, and the map if the keyword was given.
type SplitFields<'py> = (Option<Bound<'py, PyDict>>, Option<Option<FluxMapFile>>);

/// The preset names, in `motors/` order.
pub fn preset_names() -> Vec<&'static str> {
    PRESETS.iter().map(|p| p.name).collect()
}

/// The one field of `MachineModel` outside its serde record (the inverter's in TOML).
const DC_VOLTAGE: &str = "dc_voltage";

/// The fields a `Machine` derives from its ratings when they are not given, by the rules of
/// `fado_core::ratings` (the same as `fado-sim`'s `[motor]` table and `[inverter]
/// dc_voltage`).
const DERIVED: [&str; 3] = ["inertia", "viscous_friction", DC_VOLTAGE];

/// `TypeError` naming every circuit key and rating `fields` lacks (or gives as None), as
/// `fado-sim` refuses a motor file without them; None when all are given.
fn missing_required(fields: Option<&Bound<'_, PyDict>>) -> PyResult<Option<PyErr>> {
    let mut missing = Vec::new();
    for key in fado_core::ratings::REQUIRED_MOTOR_KEYS {
        let given = match fields {
            Some(f) => f.get_item(key)?.is_some_and(|v| !v.is_none()),
            None => false,
        };
        if !given {
            missing.push(format!("'{key}'"));
        }
    }
    if missing.is_empty() {
        return Ok(None);
    }
    // A key that is no field (`Kv=100` for `flux_linkage`) is the likelier cause: named first.
    let mut unknown = Vec::new();
    if let Some(f) = fields {
        for k in f.keys() {
            let k: String = k.extract()?;
            if !is_field(&k) {
                unknown.push(k);
            }
        }
    }
    let unknown = match (unknown.first(), fields) {
        (Some(k), Some(f)) => format!(
            "`{k}` is not a Machine field{}: a datasheet's values (Kv, Kt, Ke, line-to-line R \
             and L, rms currents, kg·cm²) go to Machine.from_datasheet as {}. ",
            crate::elsewhere::hint(f.py(), k, "Machine", field_list()),
            datasheet_keys()
        ),
        _ => String::new(),
    };
    Ok(Some(pyo3::exceptions::PyTypeError::new_err(format!(
        "{unknown}Machine() missing required keyword argument{}: {}. The circuit (rs, ld, lq, \
         flux_linkage, pole_pairs) and the ratings from the datasheet (rated_current in A peak, \
         rated_speed_rpm, rated_torque) are required; inertia, viscous_friction and dc_voltage \
         are derived from them when left out (fado_core::ratings); no value is taken from \
         another motor",
        if missing.len() > 1 { "s" } else { "" },
        missing.join(", ")
    ))))
}

/// True when `key` is a `Machine` field (a keyword of its constructor).
pub(crate) fn is_field(key: &str) -> bool {
    field_list().any(|k| k == key)
}

/// Every keyword of `Machine()`: the required keys, the derived ones and `flux_map`.
pub(crate) fn field_list() -> impl Iterator<Item = &'static str> {
    fado_core::ratings::REQUIRED_MOTOR_KEYS
        .iter()
        .chain(DERIVED.iter())
        .copied()
        .chain(["flux_map"])
}

/// The datasheet keys of `Machine.from_datasheet` with their units, as text.
pub(crate) fn datasheet_keys() -> String {
    let keys: Vec<String> = fado_core::datasheet::ALTERNATIVES
        .iter()
        .map(|a| format!("`{}` ({})", a.key, a.unit))
        .collect();
    keys.join(", ")
}

/// True when `m`'s circuit and ratings are finite and positive: the DC link can be derived
/// from them (otherwise the validation names the bad field).
fn derivable(m: &MachineModel<f64>) -> bool {
    [
        m.rs,
        m.ld,
        m.lq,
        m.flux_linkage,
        m.rated_current,
        m.rated_speed_rpm,
        m.rated_torque,
    ]
    .iter()
    .all(|x| x.is_finite() && *x > 0.0)
        && m.pole_pairs > 0
}

/// The error of a finding on a DC link derived from the ratings (not the user's value): the
/// rated point it follows from is named instead.
fn derived_dc_link_error(py: Python<'_>, dc: f64) -> PyErr {
    config_error_message(
        py,
        "rated_speed_rpm",
        format!(
            "`dc_voltage` was not given: derived from the rated point ({}), it is {dc:e} V, \
             beyond any drive; the rated point (`rated_speed_rpm`, `flux_linkage`, \
             `pole_pairs`, `rated_current`, `ld`, `lq`) is off: check their units (r/min, Wb \
             peak per phase, A peak, H) or give `dc_voltage`",
            fado_core::ratings::rule("inverter.dc_voltage").unwrap_or("")
        ),
    )
}

/// `m` with `flux_map` (if any) as its magnetic model.
fn with_map(m: &MachineModel<f64>, flux_map: Option<&FluxMapFile>) -> MachineModel<f64> {
    match flux_map.and_then(crate::flux_map::machine_magnetics::<f64>) {
        Some(magnetics) => m.with_magnetics(magnetics),
        None => *m,
    }
}

/// Raises a `UserWarning` per plausibility warning of `m` (`fado_core::machine_checks`),
/// with `ts` the sampling period when known; the first error as `ConfigError` naming its key.
pub fn check_plausible(py: Python<'_>, m: &MachineModel<f64>, ts: Option<f64>) -> PyResult<()> {
    let findings = fado_core::machine_checks::check(m, ts);
    if let Some(e) = findings.error() {
        return Err(config_error_message(py, e.key(), e.to_string()));
    }
    for w in findings.warnings() {
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &std::ffi::CString::new(w.to_string()).unwrap_or_default(),
            2,
        )?;
    }
    Ok(())
}

/// The field names, in `MachineModel` order (`dc_voltage` last).
pub fn field_names(py: Python<'_>) -> PyResult<Vec<String>> {
    let mut names = record::field_names(py, &MachineModel::<f64>::default())?;
    names.push(DC_VOLTAGE.to_owned());
    Ok(names)
}

/// The motor's parameters and ratings, as the drive models it (SI units, per phase,
/// amplitude-invariant peak values; the rated speed in r/min).
///
/// Every argument is keyword-only and required except `inertia`, `viscous_friction` and
/// `dc_voltage`, which default to the values the ratings give (`fado_core::ratings`: the
/// rated torque reaches the rated speed in 0.15 s; friction 1 % of the rated torque at rated
/// speed; the rated point's phase voltage at 80 % of Vdc/√3), as in a `fado-sim` motor file.
/// Numbers may be numpy scalars or 0-d arrays; a count (`pole_pairs`) may be a whole float.
/// Its fields (`Machine.fields`) are documented in the type stub and in the Rust documentation
/// of `MachineModel`. `Machine.paper()` is the paper's motor, `Machine.preset(name)` a motor of the repository's
/// `motors/` folder (`fado.machine_presets()`). Instances are immutable; `replace(**changes)`
/// returns a modified copy. Invalid values (including unit slips such as a flux linkage in
/// mWb) raise `fado.ConfigError` (a `ValueError`) whose `.field` names the field.
/// `flux_map=` gives the plant a saturating flux map (a CSV path or `(i_d, i_q, psi_d, psi_q)`
/// arrays, [`crate::flux_map`]) that `simulate` and `commission` run with; it is not a field.
#[pyclass(name = "Machine", module = "fado", frozen, eq)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyMachine {
    model: MachineModel<f64>,
    /// The plant's flux map (`flux_map=`, [`crate::flux_map`]); None: no map.
    flux_map: Option<FluxMapFile>,
}

impl PyMachine {
    /// The Python view of a core machine model (not validated).
    pub fn from_core(m: &MachineModel<f64>) -> Self {
        Self {
            model: *m,
            flux_map: None,
        }
    }

    /// The flux map given with the machine, if any.
    pub fn flux_map(&self) -> Option<&FluxMapFile> {
        self.flux_map.as_ref()
    }

    /// The map against the machine's zero-current constants ([`crate::flux_map::check_agreement`]).
    fn check_flux_map(&self, py: Python<'_>) -> PyResult<()> {
        match &self.flux_map {
            Some(map) => crate::flux_map::check_agreement(py, &self.model, map),
            None => Ok(()),
        }
    }

    /// `fields` without `flux_map`, and the map it gave (`Some(None)`: given as None).
    fn split_flux_map<'py>(
        py: Python<'py>,
        fields: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<SplitFields<'py>> {
        let Some(fields) = fields else {
            return Ok((None, None));
        };
        let rest = fields.copy()?;
        let Some(obj) = rest.get_item(crate::flux_map::FLUX_MAP)? else {
            return Ok((Some(rest), None));
        };
        rest.del_item(crate::flux_map::FLUX_MAP)?;
        Ok((Some(rest), Some(crate::flux_map::from_argument(py, &obj)?)))
    }

    /// The core machine model.
    pub fn to_core(&self) -> MachineModel<f64> {
        self.model
    }

    /// The core record with the plant's flux map as its magnetic model (what the plausibility
    /// checks weigh: a saturated machine's torque is its map's).
    pub fn to_core_with_map(&self) -> MachineModel<f64> {
        with_map(&self.model, self.flux_map.as_ref())
    }

    /// The same machine with R̂s replaced (not validated).
    pub fn with_rs(&self, rs: f64) -> Self {
        Self {
            model: MachineModel { rs, ..self.model },
            flux_map: self.flux_map.clone(),
        }
    }

    /// A checked machine: `fado.ConfigError` naming the first bad field otherwise.
    pub fn checked(py: Python<'_>, m: MachineModel<f64>) -> PyResult<Self> {
        m.validate().map_err(|e| config_error(py, e))?;
        Ok(Self::from_core(&m))
    }

    /// `fields` with [`DERIVED`] fields that are absent or `None` set from the ratings given
    /// (`fado_core::ratings`); left out when the ratings are missing (the constructor then
    /// names the missing rating).
    fn with_derived<'py>(
        py: Python<'py>,
        fields: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let out = match fields {
            Some(f) => f.copy()?,
            None => PyDict::new(py),
        };
        let rating = |k: &str| -> Option<f64> {
            let v = out.get_item(k).ok()??;
            let x: f64 = crate::record::plain_number(py, &v).ok()?.extract().ok()?;
            (x.is_finite() && x > 0.0).then_some(x)
        };
        let ratings = rating("rated_torque").zip(rating("rated_speed_rpm"));
        for key in DERIVED {
            if out.get_item(key)?.is_some_and(|v| v.is_none()) {
                out.del_item(key)?;
            }
            if out.contains(key)? || key == DC_VOLTAGE {
                // The DC link needs the whole circuit: derived in `changed`.
                continue;
            }
            if let Some((torque, speed)) = ratings {
                let value = match key {
                    "inertia" => fado_core::ratings::inertia(torque, speed),
                    _ => fado_core::ratings::viscous_friction(torque, speed),
                };
                out.set_item(key, value)?;
            }
        }
        Ok(out)
    }

    /// `base` with `changes` applied, validated. When `constructing`, a field the core refuses
    /// that the caller did not give is a missing required keyword: `TypeError` naming it.
    fn changed(
        py: Python<'_>,
        base: &MachineModel<f64>,
        changes: Option<&Bound<'_, PyDict>>,
        constructing: bool,
        flux_map: Option<&FluxMapFile>,
    ) -> PyResult<Self> {
        let mut model = *base;
        if let Some(changes) = changes {
            let record_changes = changes.copy()?;
            let dc_given = changes.get_item(DC_VOLTAGE)?;
            if dc_given.is_some() {
                record_changes.del_item(DC_VOLTAGE)?;
            }
            let dc_voltage = model.dc_voltage;
            model = record::with_changes(py, &model, &record_changes, "a Machine field", &|k| {
                k.to_owned()
            })?;
            // Outside the serde record: the round trip left it at the empty record's value.
            model.dc_voltage = dc_voltage;
            if let Some(v) = dc_given {
                let v = crate::record::plain_number(py, &v)?;
                model.dc_voltage = v.extract().map_err(|_| {
                    pyo3::exceptions::PyTypeError::new_err(format!(
                        "`{DC_VOLTAGE}` must be a number (V), got {}",
                        v.get_type()
                            .name()
                            .map(|n| n.to_string())
                            .unwrap_or_default()
                    ))
                })?;
            }
        }
        let dc_derived =
            constructing && !changes.is_some_and(|c| c.contains(DC_VOLTAGE).unwrap_or(false));
        if dc_derived && derivable(&model) {
            model.dc_voltage = fado_core::ratings::dc_voltage(&model);
        }
        // The cross-checks first: their errors name every field involved.
        if let Some(e) = fado_core::machine_checks::check(&with_map(&model, flux_map), None).error()
        {
            if dc_derived && e.key() == DC_VOLTAGE {
                return Err(derived_dc_link_error(py, model.dc_voltage));
            }
            return Err(config_error_message(py, e.key(), e.to_string()));
        }
        if let Err(e) = model.validate() {
            let given = match changes {
                Some(c) => c.contains(e.field())?,
                None => false,
            };
            if constructing && !given && DERIVED.contains(&e.field()) {
                // A derived field refused: the rating it is derived from is the cause
                // (`rated_speed_rpm = -1500` leaves no inertia to derive).
                let probe = MachineModel {
                    inertia: 1.0,
                    viscous_friction: 0.0,
                    dc_voltage: 1.0,
                    ..model
                };
                if let Err(cause) = probe.validate()
                    && !DERIVED.contains(&cause.field())
                {
                    return Err(config_error(py, cause));
                }
            }
            if constructing && !given {
                return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                    "Machine() missing required keyword argument: '{}'",
                    e.field()
                )));
            }
            return Err(config_error(py, e));
        }
        check_plausible(py, &with_map(&model, flux_map), None)?;
        Ok(Self::from_core(&model))
    }

    /// The preset called `name`; `ValueError` (`ConfigError` on `machine`) listing the names
    /// otherwise.
    pub fn from_preset(py: Python<'_>, name: &str, argument: &str) -> PyResult<Self> {
        let Some(preset) = find(name) else {
            return Err(config_error_message(
                py,
                argument,
                format!(
                    "`{argument}`: unknown motor preset {name:?}; one of {:?}",
                    preset_names()
                ),
            ));
        };
        let m = preset.machine().map_err(|e| {
            pyo3::exceptions::PyRuntimeError::new_err(format!("preset {name}: {e}"))
        })?;
        Self::checked(py, m)
    }

    /// `machine` as the estimator's functions take it: a `Machine`, a preset name or a `dict`
    /// of `Machine` fields. `argument` names it in errors.
    pub fn from_argument(
        py: Python<'_>,
        machine: Option<&Bound<'_, PyAny>>,
        argument: &str,
        function: &str,
    ) -> PyResult<Self> {
        let Some(machine) = machine.filter(|m| !m.is_none()) else {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "{function}() missing the required argument `{argument}`: the motor's model, a \
                 fado.Machine, a preset name (one of {:?}; 'paper' is the paper's motor) or a \
                 dict of Machine fields",
                preset_names()
            )));
        };
        if let Ok(m) = machine.cast::<PyMachine>() {
            return Ok(m.get().clone());
        }
        if let Ok(name) = machine.cast::<PyString>() {
            return Self::from_preset(py, name.to_str()?, argument);
        }
        if let Ok(dict) = machine.cast::<PyDict>() {
            for key in dict.keys() {
                let key: String = key.extract()?;
                if !field_names(py)?.contains(&key) && key != crate::flux_map::FLUX_MAP {
                    return Err(config_error_message(
                        py,
                        &key,
                        format!(
                            "`{key}` is not a Machine field{}; one of {:?}",
                            crate::elsewhere::hint(py, &key, "Machine", field_list()),
                            field_names(py)?
                        ),
                    ));
                }
            }
            let made = py
                .get_type::<PyMachine>()
                .call((), Some(dict))?
                .cast_into::<PyMachine>()?;
            return Ok(made.get().clone());
        }
        Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "`{argument}` must be a fado.Machine, a preset name or a dict of Machine fields, got {}",
            machine.get_type().name()?
        )))
    }

    fn items<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = record::to_dict(py, &self.model)?;
        dict.set_item(DC_VOLTAGE, self.model.dc_voltage)?;
        if let Some(m) = &self.flux_map {
            dict.set_item(
                crate::flux_map::FLUX_MAP,
                crate::flux_map::to_python(py, m)?,
            )?;
        }
        Ok(dict)
    }

    /// The constructor's keywords for [`record::install`]: the fields derived from the
    /// ratings (`DERIVED`) default to `None` (derived); a field is optional, with the empty
    /// record's value as its default, when the paper's motor with that value is still valid;
    /// every other field is required.
    pub fn signature(py: Python<'_>) -> PyResult<Vec<(String, Option<Bound<'_, PyAny>>)>> {
        let empty = Self::from_core(&MachineModel::default()).items(py)?;
        let mut params = Vec::new();
        for name in field_names(py)? {
            if DERIVED.contains(&name.as_str()) {
                params.push((name, Some(py.None().into_bound(py))));
                continue;
            }
            let value = empty.get_item(&name)?.ok_or_else(|| {
                pyo3::exceptions::PyRuntimeError::new_err(format!("no field {name}"))
            })?;
            let alone = PyDict::new(py);
            alone.set_item(&name, &value)?;
            let optional =
                Self::changed(py, &MachineModel::paper(), Some(&alone), false, None).is_ok();
            params.push((name, optional.then_some(value)));
        }
        Ok(params)
    }
}

#[pymethods]
impl PyMachine {
    #[new]
    #[pyo3(signature = (**fields))]
    fn py_new(py: Python<'_>, fields: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let (fields, flux_map) = Self::split_flux_map(py, fields)?;
        if let Some(e) = missing_required(fields.as_ref())? {
            return Err(e);
        }
        let fields = Self::with_derived(py, fields.as_ref())?;
        let flux_map = flux_map.flatten();
        let base = MachineModel::default();
        let mut m = Self::changed(py, &base, Some(&fields), true, flux_map.as_ref())?;
        m.flux_map = flux_map;
        m.check_flux_map(py)?;
        Ok(m)
    }

    /// A machine from its datasheet's values: any `Machine` field, or instead of `rs`, `ld`,
    /// `lq`, `flux_linkage`, `rated_current` and `inertia` the datasheet's `rs_line_to_line`,
    /// `l_line_to_line`, `ke_vll_rms_per_krpm`, `ke_vll_peak_per_krpm`, `kt_nm_per_arms`,
    /// `kv_rpm_per_volt`, `rated_current_arms` and `inertia_kg_cm2` (converted as `fado-sim`'s `[motor]` table converts them; see
    /// docs/configuration.md). A field given both ways is refused naming both.
    #[staticmethod]
    #[pyo3(signature = (**fields))]
    fn from_datasheet(py: Python<'_>, fields: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let converted = crate::datasheet::convert(py, fields)?;
        Self::py_new(py, Some(&converted))
    }

    /// A copy with the given fields changed (validated like the constructor).
    fn _replace(&self, py: Python<'_>, changes: &Bound<'_, PyDict>) -> PyResult<Self> {
        let (changes, flux_map) = Self::split_flux_map(py, Some(changes))?;
        let flux_map = flux_map.unwrap_or_else(|| self.flux_map.clone());
        let mut m = Self::changed(py, &self.model, changes.as_ref(), false, flux_map.as_ref())?;
        m.flux_map = flux_map;
        m.check_flux_map(py)?;
        Ok(m)
    }

    /// The plant's flux map: None, the CSV file's path, or (i_d, i_q, psi_d, psi_q) node
    /// arrays for a map given as arrays. `simulate` and `commission` run their plant with it.
    #[getter(flux_map)]
    fn py_flux_map<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.flux_map
            .as_ref()
            .map(|m| crate::flux_map::to_python(py, m))
            .transpose()
    }

    /// The paper's motor (section V: 8-pole SMPMSM, 11.5 N·m, 1500 r/min, Rs 0.327 Ω,
    /// Ld = Lq = 2.63 mH, 311 V DC link; λf 0.088 Wb and J 0.012 kg·m² from docs/method/estimator.md, "The paper's motor and drive").
    #[staticmethod]
    fn paper() -> Self {
        Self::from_core(&MachineModel::paper())
    }

    /// The motor preset `name` of the repository's `motors/` folder (`fado.machine_presets()`),
    /// with the DC link of its inverter. `ConfigError` (a `ValueError`) listing the names for
    /// an unknown one.
    #[staticmethod]
    fn preset(py: Python<'_>, name: &str) -> PyResult<Self> {
        Self::from_preset(py, name, "name")
    }

    /// The fields as a plain `dict` (`Machine(**machine.to_dict())` round-trips).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.items(py)
    }

    /// True when Ld and Lq differ by more than 2 % (an interior-magnet rotor).
    #[getter]
    fn salient(&self) -> bool {
        self.model.is_salient()
    }
}

/// The names of the motor presets (`Machine.preset(name)`, `simulate(motor=name)`), one per
/// file of the repository's `motors/` folder.
#[pyfunction]
pub fn machine_presets() -> Vec<&'static str> {
    preset_names()
}
