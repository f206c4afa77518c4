//! The drive around the estimator (the rest of Fig. 5): speed and current PI control with
//! anti-windup, the d-axis injection of eq. (23), delay and dead-time compensation (paper
//! IV-B, docs/method/estimator.md §7), hexagon limiting and SVPWM, composed into [`SensorlessDrive`].
//!
//! Every block follows the crate's pattern (`new(config) -> Result<_, ConfigError>`, `step`,
//! `reset`), is allocation-free, generic over [`Real`](crate::Real) and never panics.

pub mod calibration_turn;
pub mod current_controller;
pub mod dc_link_limit;
pub mod dead_time_compensation;
pub mod delay_compensation;
pub mod drive;
pub mod field_weakening;
pub mod gain_calibration;
pub mod gain_tracking;
pub mod initial_angle;
pub mod lock_reaction;
pub mod modulation;
pub mod monitor;
pub mod phase_band;
pub mod pi;
pub mod ratings_limit;
pub mod release_current;
pub mod release_hold;
pub mod saturated_references;
pub mod snapshot_window;
pub mod speed_controller;
pub mod standstill_probe;
pub mod start_ramp;
pub mod startup;
pub use drive::probe_period;
pub use drive::speed_bandwidth;
pub use drive::tracker_feedforward;
pub use drive::tuning;

pub use current_controller::{CurrentController, CurrentControllerConfig};
pub use dc_link_limit::{DcLinkLimit, DcLinkTuning};
pub use dead_time_compensation::{
    DeadTimeCompensation, DeadTimeCompensationConfig, DeadTimeMethod, EDGE_SOLVE_LOOP_GAIN,
};
pub use delay_compensation::{DelayCompensation, DelayCompensationConfig};
pub use drive::{DriveConfig, DriveOutput, DriveTuning, SensorlessDrive};
pub use field_weakening::{FieldWeakening, FieldWeakeningTuning};
pub use gain_calibration::{GainCalibration, GainCalibrationConfig, GainCalibrationStatus};
pub use initial_angle::{InitialAngle, InitialAngleConfig, InitialAngleStatus};
pub use lock_reaction::{LockAction, LockReaction, LockSupervisor};
pub use modulation::{Modulation, ModulatorConfig, SpaceVectorModulator, VoltageLimit, svpwm_duty};
pub use monitor::{DriveFlags, FlagCounts};
pub use pi::{Pi, PiConfig};
pub use ratings_limit::{RatingsLimit, RatingsLimitTuning};
pub use release_current::ReleaseCurrent;
pub use release_hold::{ReleaseHold, ReleaseHoldTuning};
pub use speed_controller::{SpeedController, SpeedControllerConfig, limit_current_d_priority};
pub use standstill_probe::{StandstillProbe, StandstillProbeConfig};
pub use start_ramp::{StartRamp, StartRampTuning};
pub use startup::{AngleSearch, StartupStatus, StartupTuning};
pub use tracker_feedforward::TrackerFeedforwardTuning;
