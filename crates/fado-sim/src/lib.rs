//! # fado-sim
//!
//! Closed-loop simulator of the paper's experimental set-up (Fig. 7): an 8-pole SMPMSM
//! ([`motor`]) fed by a two-level PWM inverter ([`inverter`], switching-resolved or averaged),
//! measured by non-ideal sensors ([`sensors`]), loaded by a torque profile or a
//! speed-controlled dynamometer ([`load`]), and driven by a controller — the sensorless drive
//! of `fado-core` ([`drive`]) or any [`controller::Controller`].
//!
//! * [`scenario`]: the paper's Fig. 8–12 as named scenarios with coded pass criteria;
//!   [`simulate`] is the one-call entry point (CLI `fado-sim run`, Python bindings).
//! * [`estimators`]: the registry of estimators (fado and the `fado_core::baselines`), one
//!   row each; [`compare`]: every estimator in every scenario on the same plant, seed and
//!   controllers (CLI `fado-sim compare`).
//! * [`sweep`]: operating-envelope sweeps over model, sensor, load and profile errors, in
//!   parallel, resumable, one CSV row per point (CLI `fado-sim sweep`, Python `fado.sweep`).
//! * [`criteria`]: the pass criteria a user writes (`[criteria]`), all the `custom` scenario
//!   judges; [`dc_link`]: the DC link behind the inverter (stiff, battery or rectifier, its
//!   capacitor and brake chopper).
//! * [`config`]: the whole run as one TOML document ([`SimConfig`]), overriding a scenario key
//!   by key; unknown keys and impossible values are errors naming the key.
//! * [`output`]: outputs written whole or not at all (temporary file + rename) under a lock on
//!   the output directory; [`threads`]: worker counts capped at the machine's cores.
//! * [`sim`]: the loop ([`sim::Simulation`]), the plant aggregate ([`sim::Plant`]), metrics,
//!   the decimated trace and the [`sim::Probe`] hook for custom measurements.
//!
//! Timing contract: at sample n (carrier peak or valley) the sensors read the plant, the
//! controller computes the duty for n+1, the plant integrates [n, n+1] with the duty computed
//! at n−1. Units are SI; angles and speeds electrical unless `_mech`; r/min only in profiles,
//! metrics and traces.
//!
//! ```
//! // fig11 with a shortened run and the averaged inverter (the defaults run 5.5 s,
//! // switching-resolved, in about 0.1 s in release mode).
//! let out = fado_sim::simulate(
//!     "fig11",
//!     Some("[simulation]\nduration = 0.05\n"),
//!     true,
//!     None,
//! )
//! .unwrap();
//! assert!(!out.metrics.tripped);
//! let report = out.report(); // what metrics.json holds
//! assert_eq!(report.scenario, "fig11");
//! let _csv_rows = &out.trace.rows; // what traces.csv holds
//! ```

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod commission;
pub mod compare;
pub mod config;
pub mod controller;
pub mod criteria;
pub mod dc_link;
pub mod derive;
pub mod drive;
pub mod error;
pub mod estimators;
mod fastmath;
pub mod faults;
pub mod identified_map;
pub mod inverter;
pub mod load;
pub mod magnetic_accuracy;
pub mod magnetic_agreement;
pub mod magnetics;
pub mod magnetics_file;
pub mod model_magnetics;
pub mod motor;
pub mod nameplate_agreement;
pub mod output;
pub mod presets;
pub mod profile;
pub mod range;
pub mod reach;
pub mod saturation_verdict;
pub mod scenario;
pub mod sensors;
pub mod sim;
pub mod source;
pub mod suggest;
pub mod sweep;
pub mod threads;

pub use config::SimConfig;
pub use error::SimConfigError;
pub use scenario::{Outcome, Report, SCENARIOS, Scenario, scenario_config, simulate};
