//! # fado-py
//!
//! Python bindings of fado, built by maturin from the top-level `pyproject.toml` into the
//! native module `fado._fado`, which the pure-Python package `fado` (in `python/fado/`)
//! re-exports. Layout, after pydantic-core and rust-numpy:
//!
//! - [`machine`]: `Machine` (the motor's parameters and ratings), its presets
//!   (`machine_presets`).
//! - [`config`]: `EstimatorConfig`, the estimator's tuning as keyword arguments with the Rust
//!   defaults.
//! - [`estimator`]: `Estimator` (step by step or chunk by chunk) and `estimate` (a whole
//!   recording with the GIL released).
//! - [`outputs`]: `StepResult`, `EstimateResult` and the column buffers behind them.
//! - [`inputs`]: checks of the signal arrays; [`replay`]: the Python-free replay loop.
//! - [`simulate`]: `simulate`, `SimResult`, `scenarios`, `default_config`: the closed-loop
//!   simulator of `fado-sim` (the paper's Fig. 8–12) with the GIL released.
//! - [`record`]: the Python view of a serde record of the core (fields, attributes, `dict`).
//! - [`errors`]: `FadoError` and its subclasses.
//! - [`interrupt`]: long calls run without the GIL and stop on Ctrl-C.
//! - [`compare`]: `compare`, fado against the baseline estimators in the simulator.
//! - [`sweep`]: `sweep` and `sweep_point`, operating-envelope sweeps of the simulator.
//! - [`commission`]: `commission`, `CommissionResult`: the commissioning procedure on the
//!   simulated plant, identified against the plant's truth.

pub mod commission;
pub mod compare;
pub mod config;
pub mod datasheet;
pub mod elsewhere;
pub mod errors;
pub mod estimator;
pub mod flux_map;
pub mod inputs;
pub mod interrupt;
pub mod machine;
pub mod number;
pub mod outputs;
pub mod record;
pub mod recording_checks;
pub mod recording_model;
pub mod replay;
pub mod scalar;
pub mod simulate;
pub mod sweep;

use pyo3::prelude::*;

/// Native core of the `fado` package: the sensorless estimator of Park & Sul
/// ("Sensorless Control Method for PMSM Based on Frequency-Adaptive Disturbance Observer").
/// Import from `fado`, not from here.
#[pymodule]
pub mod _fado {
    #[pymodule_export]
    use super::commission::{CommissionResult, commission};
    #[pymodule_export]
    use super::compare::{compare, estimators};
    #[pymodule_export]
    use super::config::PyEstimatorConfig;
    #[pymodule_export]
    use super::estimator::{PyEstimator, estimate};
    #[pymodule_export]
    use super::machine::{PyMachine, machine_presets};
    #[pymodule_export]
    use super::outputs::{EstimateResult, StepResult};
    #[pymodule_export]
    use super::simulate::{SimResult, default_config, describe_scenario, scenarios, simulate};
    #[pymodule_export]
    use super::sweep::{sweep, sweep_point};

    #[pymodule_export]
    const MODE_LIMITER: i8 = super::outputs::MODE_LIMITER;
    #[pymodule_export]
    const MODE_DISTURBANCE_FEEDBACK: i8 = super::outputs::MODE_DISTURBANCE_FEEDBACK;

    use pyo3::prelude::*;

    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        super::errors::Exceptions::register(m)?;
        // Private (not in `__all__`): the Python wrappers' keyword check (`fado._keywords`).
        m.setattr(
            "_unexpected_keyword",
            wrap_pyfunction!(super::elsewhere::unexpected_keyword, m)?,
        )?;
        m.add("__version__", env!("CARGO_PKG_VERSION"))?;
        m.add("OUTPUT_NAMES", super::outputs::OUTPUT_NAMES.to_vec())?;
        m.add("TRACE_COLUMNS", super::simulate::trace_columns())?;
        m.add(
            "COMMISSION_TRACE_COLUMNS",
            super::commission::COMMISSION_TRACE_COLUMNS.to_vec(),
        )?;
        m.add("COMMISSION_PHASES", super::commission::phase_names())?;
        let parameters = pyo3::types::PyDict::new(m.py());
        for (name, meaning) in fado_sim::sweep::PARAMETERS {
            parameters.set_item(name, meaning)?;
        }
        m.add("SWEEP_PARAMETERS", parameters)?;
        // The records' attributes and signatures, named by their serde derive (`record`).
        let py = m.py();
        super::record::install(
            &py.get_type::<super::config::PyEstimatorConfig>(),
            super::config::PyEstimatorConfig::signature(py)?,
            &[],
        )?;
        super::record::install(
            &py.get_type::<super::machine::PyMachine>(),
            super::machine::PyMachine::signature(py)?,
            &[super::flux_map::FLUX_MAP],
        )?;
        Ok(())
    }
}
