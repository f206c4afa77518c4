#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(test)]
extern crate std;

pub mod active_flux;
pub mod approx;
pub mod baselines;
pub mod commissioning;
pub mod control;
pub mod datasheet;
pub mod error;
pub mod estimator;
pub mod flux;
pub mod frames;
pub mod injection;
pub mod integrand_offset;
pub mod lock;
pub mod machine;
pub mod machine_checks;
pub mod magnetics;
pub mod mode;
pub mod observer;
pub mod plausibility;
pub mod ratings;
pub mod real;
pub mod ripple;
pub mod rotor_flux;
pub mod rs_adaptation;
pub mod speed_notch;
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
pub use magnetics::{MachineMagnetics, MagneticModel, Magnetics};
pub use mode::Mode;
pub use real::{Real, wrap_angle};
