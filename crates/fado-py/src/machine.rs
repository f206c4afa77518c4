//! `fado.Machine`: the motor's parameters and ratings (`fado_core::MachineModel`), the model
//! every estimator is built around, and the motor presets of the repository's `motors/`
//! folder (`fado_sim::presets`).
//!
//! The conversions below are exhaustive struct literals, so a field added to the core's
//! `MachineModel` fails to compile here until it is exposed. Validation is the core's
//! (`MachineModel::validate`: signs, finiteness and unit slips); a refusal raises
//! `fado.ConfigError` (a `ValueError`) whose `.field` names the field.

use fado_core::MachineModel;
use fado_sim::presets::{PRESETS, find};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple};

use crate::errors::{config_error, config_error_message};

/// The preset names, in `motors/` order.
pub fn preset_names() -> Vec<&'static str> {
    PRESETS.iter().map(|p| p.name).collect()
}

/// The field names, in `MachineModel` order.
pub const FIELDS: &[&str] = &[
    "rs",
    "ld",
    "lq",
    "flux_linkage",
    "pole_pairs",
    "inertia",
    "viscous_friction",
    "rated_current",
    "rated_speed_rpm",
    "rated_torque",
    "dc_voltage",
];

/// The motor's parameters and ratings, as the drive models it (SI units, per phase,
/// amplitude-invariant peak values; the rated speed in r/min).
///
/// Every argument is keyword-only and required except `viscous_friction` (default 0).
/// `Machine.paper()` is the paper's motor, `Machine.preset(name)` a motor of the repository's
/// `motors/` folder (`fado.machine_presets()`). Instances are immutable; `replace(**changes)`
/// returns a modified copy. Invalid values (including unit slips such as a flux linkage in
/// mWb) raise `fado.ConfigError` (a `ValueError`) whose `.field` names the field.
#[pyclass(name = "Machine", module = "fado", frozen, eq, get_all)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyMachine {
    /// Stator resistance Rs in Ω (per phase; everything in series the drive should see).
    pub rs: f64,
    /// d-axis inductance Ld in H.
    pub ld: f64,
    /// q-axis inductance Lq in H (= ld for a surface-magnet rotor).
    pub lq: f64,
    /// Magnet flux linkage λf in Wb (peak, per phase).
    pub flux_linkage: f64,
    /// Pole pairs p.
    pub pole_pairs: u32,
    /// Shaft inertia J in kg·m² (motor and load).
    pub inertia: f64,
    /// Viscous friction B in N·m·s/rad.
    pub viscous_friction: f64,
    /// Rated current in A, peak of the phase current.
    pub rated_current: f64,
    /// Rated speed in r/min (mechanical).
    pub rated_speed_rpm: f64,
    /// Rated torque in N·m.
    pub rated_torque: f64,
    /// Nominal DC-link voltage in V.
    pub dc_voltage: f64,
}

impl PyMachine {
    /// The Python view of a core machine model (not validated).
    pub fn from_core(m: &MachineModel<f64>) -> Self {
        Self {
            rs: m.rs,
            ld: m.ld,
            lq: m.lq,
            flux_linkage: m.flux_linkage,
            pole_pairs: m.pole_pairs,
            inertia: m.inertia,
            viscous_friction: m.viscous_friction,
            rated_current: m.rated_current,
            rated_speed_rpm: m.rated_speed_rpm,
            rated_torque: m.rated_torque,
            dc_voltage: m.dc_voltage,
        }
    }

    /// The core machine model.
    pub fn to_core(&self) -> MachineModel<f64> {
        MachineModel {
            rs: self.rs,
            ld: self.ld,
            lq: self.lq,
            flux_linkage: self.flux_linkage,
            pole_pairs: self.pole_pairs,
            inertia: self.inertia,
            viscous_friction: self.viscous_friction,
            rated_current: self.rated_current,
            rated_speed_rpm: self.rated_speed_rpm,
            rated_torque: self.rated_torque,
            dc_voltage: self.dc_voltage,
        }
    }

    /// A checked machine: `fado.ConfigError` naming the first bad field otherwise.
    pub fn checked(py: Python<'_>, m: MachineModel<f64>) -> PyResult<Self> {
        m.validate().map_err(|e| config_error(py, e))?;
        Ok(Self::from_core(&m))
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
                if !FIELDS.contains(&key.as_str()) {
                    return Err(config_error_message(
                        py,
                        &key,
                        format!("`{key}` is not a Machine field; one of {FIELDS:?}"),
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
        let dict = PyDict::new(py);
        dict.set_item("rs", self.rs)?;
        dict.set_item("ld", self.ld)?;
        dict.set_item("lq", self.lq)?;
        dict.set_item("flux_linkage", self.flux_linkage)?;
        dict.set_item("pole_pairs", self.pole_pairs)?;
        dict.set_item("inertia", self.inertia)?;
        dict.set_item("viscous_friction", self.viscous_friction)?;
        dict.set_item("rated_current", self.rated_current)?;
        dict.set_item("rated_speed_rpm", self.rated_speed_rpm)?;
        dict.set_item("rated_torque", self.rated_torque)?;
        dict.set_item("dc_voltage", self.dc_voltage)?;
        Ok(dict)
    }
}

/// Pole pairs as given (any Python int), refused naming the field unless a positive `u32`.
fn pole_pairs(py: Python<'_>, p: i64) -> PyResult<u32> {
    u32::try_from(p).ok().filter(|&p| p > 0).ok_or_else(|| {
        config_error_message(
            py,
            "pole_pairs",
            format!("`pole_pairs` must be a whole number of at least 1, got {p}"),
        )
    })
}

#[pymethods]
impl PyMachine {
    #[allow(clippy::too_many_arguments)] // one keyword per field
    #[new]
    #[pyo3(signature = (*, rs, ld, lq, flux_linkage, pole_pairs, inertia, rated_current, rated_speed_rpm, rated_torque, dc_voltage, viscous_friction = 0.0))]
    fn py_new(
        py: Python<'_>,
        rs: f64,
        ld: f64,
        lq: f64,
        flux_linkage: f64,
        pole_pairs: i64,
        inertia: f64,
        rated_current: f64,
        rated_speed_rpm: f64,
        rated_torque: f64,
        dc_voltage: f64,
        viscous_friction: f64,
    ) -> PyResult<Self> {
        Self::checked(
            py,
            MachineModel {
                rs,
                ld,
                lq,
                flux_linkage,
                pole_pairs: self::pole_pairs(py, pole_pairs)?,
                inertia,
                viscous_friction,
                rated_current,
                rated_speed_rpm,
                rated_torque,
                dc_voltage,
            },
        )
    }

    #[allow(clippy::too_many_arguments)] // one keyword per field
    /// A copy with the given fields changed (validated like the constructor).
    #[pyo3(signature = (*, rs = None, ld = None, lq = None, flux_linkage = None, pole_pairs = None, inertia = None, rated_current = None, rated_speed_rpm = None, rated_torque = None, dc_voltage = None, viscous_friction = None))]
    fn replace(
        &self,
        py: Python<'_>,
        rs: Option<f64>,
        ld: Option<f64>,
        lq: Option<f64>,
        flux_linkage: Option<f64>,
        pole_pairs: Option<i64>,
        inertia: Option<f64>,
        rated_current: Option<f64>,
        rated_speed_rpm: Option<f64>,
        rated_torque: Option<f64>,
        dc_voltage: Option<f64>,
        viscous_friction: Option<f64>,
    ) -> PyResult<Self> {
        let pole_pairs = match pole_pairs {
            Some(p) => self::pole_pairs(py, p)?,
            None => self.pole_pairs,
        };
        Self::checked(
            py,
            MachineModel {
                rs: rs.unwrap_or(self.rs),
                ld: ld.unwrap_or(self.ld),
                lq: lq.unwrap_or(self.lq),
                flux_linkage: flux_linkage.unwrap_or(self.flux_linkage),
                pole_pairs,
                inertia: inertia.unwrap_or(self.inertia),
                viscous_friction: viscous_friction.unwrap_or(self.viscous_friction),
                rated_current: rated_current.unwrap_or(self.rated_current),
                rated_speed_rpm: rated_speed_rpm.unwrap_or(self.rated_speed_rpm),
                rated_torque: rated_torque.unwrap_or(self.rated_torque),
                dc_voltage: dc_voltage.unwrap_or(self.dc_voltage),
            },
        )
    }

    /// The paper's motor (section V: 8-pole SMPMSM, 11.5 N·m, 1500 r/min, Rs 0.327 Ω,
    /// Ld = Lq = 2.63 mH, 311 V DC link; λf 0.088 Wb and J 0.012 kg·m² from SPEC §6).
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
        self.to_core().is_salient()
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let mut parts = Vec::with_capacity(FIELDS.len());
        for (key, value) in self.items(py)?.iter() {
            parts.push(format!("{}={}", key.str()?, value.repr()?));
        }
        Ok(format!("Machine({})", parts.join(", ")))
    }

    /// Pickling: rebuilt through the keyword constructor.
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        Ok((PyTuple::empty(py), self.items(py)?))
    }

    /// The names of the fields, in order.
    #[classattr]
    fn fields(py: Python<'_>) -> PyResult<Bound<'_, PyTuple>> {
        PyTuple::new(py, FIELDS)
    }
}

/// The names of the motor presets (`Machine.preset(name)`, `simulate(motor=name)`), one per
/// file of the repository's `motors/` folder.
#[pyfunction]
pub fn machine_presets() -> Vec<&'static str> {
    preset_names()
}
