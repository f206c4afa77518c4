//! # fado-sim
//!
//! Closed-loop simulator of the paper's experimental set-up (Fig. 7): an 8-pole SMPMSM
//! ([`motor`]) fed by a two-level PWM inverter ([`inverter`], switching-resolved or averaged),
//! measured by non-ideal sensors ([`sensors`]), loaded by a torque profile or a
//! speed-controlled dynamometer ([`load`]), and driven by a controller — the sensorless drive
//! of `fado-core` or any [`controller::Controller`].

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod config;
pub mod controller;
pub mod drive;
pub mod error;
mod fastmath;
pub mod inverter;
pub mod load;
pub mod motor;
pub mod profile;
pub mod scenario;
pub mod sensors;
pub mod sim;

pub use error::SimConfigError;
