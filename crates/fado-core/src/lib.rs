//! # fado-core
//!
//! Sensorless control of permanent-magnet synchronous motors with the stator-flux estimator and
//! frequency-adaptive disturbance observer of Y. Park and S.-K. Sul, "Sensorless Control Method
//! for PMSM Based on Frequency-Adaptive Disturbance Observer" (the paper). Equation and figure
//! numbers in the docs are the paper's; "SPEC" is the project's reconstruction of what the
//! paper leaves out.
//!
//! Every block is an allocation-free state machine generic over `f32` (firmware) and `f64`
//! (analysis): `new(config) -> Result<Self, ConfigError>`, `step(..)`, `reset()`. The crate is
//! `#![no_std]`, uses no `alloc` and no `unsafe`, and never panics on bad numbers: a non-finite
//! input is rejected for that sample and reported, leaving the state untouched.
//!
//! Units are SI; angles and speeds are electrical unless a name says `_mech`.

#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(test)]
extern crate std;

pub mod approx;
pub mod baselines;
pub mod commissioning;
pub mod control;
pub mod error;
pub mod estimator;
pub mod flux;
pub mod frames;
pub mod injection;
pub mod integrand_offset;
pub mod lock;
pub mod machine;
pub mod machine_checks;
pub mod mode;
pub mod observer;
pub mod plausibility;
pub mod ratings;
pub mod real;
pub mod rotor_flux;
pub mod rs_adaptation;
pub mod tracker;

pub use baselines::{EmfObserverEstimator, LpfIntegratorEstimator, OrtegaEstimator};
pub use control::{DriveConfig, DriveFlags, DriveOutput, DriveTuning, SensorlessDrive};
pub use error::{ConfigError, NonFiniteInput};
pub use estimator::{
    Diagnostics, Estimate, EstimatorConfig, EstimatorParams, EstimatorState, EstimatorTuning,
    LeanEstimate, RotorAngleEstimator, SensorlessEstimator,
};
pub use frames::{Ab, Abc, Dq, Rotation};
pub use lock::LockStatus;
pub use machine::MachineModel;
pub use mode::Mode;
pub use real::{Real, wrap_angle};
