//! # fado
//!
//! Facade over the workspace: [`core`] is the `no_std` estimator and drive (`fado-core`),
//! [`sim`] the closed-loop plant and the paper's scenarios (`fado-sim`). Integration tests
//! and benchmarks of the whole project live beside this file (`tests/`, `benches/`).

pub use fado_core as core;
pub use fado_sim as sim;
