//! [`DriveTuning`]: the drive's gains, limits, thresholds and switches, one record per block
//! it tunes, as ratios of the machine's ratings or durations in seconds.

use crate::Real;
use crate::control::dc_link_limit::DcLinkTuning;
use crate::control::field_weakening::FieldWeakeningTuning;
use crate::control::ratings_limit::RatingsLimitTuning;
use crate::control::release_hold::ReleaseHoldTuning;
use crate::control::start_ramp::StartRampTuning;
use crate::control::startup::StartupTuning;
use crate::control::tracker_feedforward::TrackerFeedforwardTuning;

mod lock;
mod loops;
mod sensors;

pub use lock::*;
pub use loops::*;
pub use sensors::*;

/// The drive's tuning: every setting that is not the machine or the sampling period, one
/// record per block it tunes. Defaults are ratios of the machine's ratings or durations in
/// seconds, chosen so that the paper's motor ([`MachineModel::paper`](crate::MachineModel::paper),
/// 21.78 A rated) gets the paper's absolute values (written beside each ratio); the inverter
/// data ([`InverterData`]: dead time, switching frequency, threshold voltage, current band)
/// are docs/method/estimator.md §7's and no serde keys (`fado-sim` derives them from its
/// `[inverter]` and `[mismatch]`). With the `serde` feature this is the `[controller]` table
/// of `fado-sim`'s TOML, each record a table (`[controller.stall]`, …).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct DriveTuning<T> {
    /// Tuning of the current loop: its PI, decoupling and the current limit (`[controller.current]`, see [`CurrentLoopTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub current: CurrentLoopTuning<T>,
    /// Tuning of the speed loop's PI (`[controller.speed]`, see [`SpeedLoopTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub speed: SpeedLoopTuning<T>,
    /// Tuning of the d-current injection of eq. (23) (`[controller.injection]`, see [`InjectionTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub injection: InjectionTuning<T>,
    /// Tuning of the maximum-torque-per-ampere d current (`[controller.mtpa]`, see [`MtpaTuning`]).
    pub mtpa: MtpaTuning,
    /// Tuning of the modulation: the realisable voltage set and how much of it the drive uses (`[controller.modulation]`, see [`ModulationTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub modulation: ModulationTuning<T>,
    /// Tuning of the dead-time compensation (`[controller.dead_time_compensation]`, see [`DeadTimeCompensationTuning`]).
    pub dead_time_compensation: DeadTimeCompensationTuning,
    /// Tuning of the compensation of the one-sample delay of the voltage (`[controller.delay_compensation]`, see [`DelayCompensationTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub delay_compensation: DelayCompensationTuning<T>,
    /// The inverter data of the dead-time compensation (see [`InverterData`]): no serde key.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub inverter: InverterData<T>,
    /// Tuning of the drive's protection and monitors: over-current trip, current-error monitor, DC-link under-voltage warning and the trip on a broken input (`[controller.protection]`, see [`ProtectionTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub protection: ProtectionTuning<T>,
    /// Tuning of the bounds beyond which a phase current or DC-link sample is no measurement (`[controller.plausibility]`, see [`SamplePlausibilityTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub plausibility: SamplePlausibilityTuning<T>,
    /// Tuning of the current sensors' offset calibration at start-up (`[controller.offset_calibration]`, see [`OffsetCalibrationTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub offset_calibration: OffsetCalibrationTuning<T>,
    /// Tuning of the current sensors' gain calibration at start-up (`[controller.gain_calibration]`, see [`GainCalibrationTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub gain_calibration: GainCalibrationTuning<T>,
    /// Tuning of the stuck current-sensor detection (`[controller.stuck_sensor]`, see [`StuckSensorTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub stuck_sensor: StuckSensorTuning<T>,
    /// Tuning of the loaded-standstill angle probe (`[controller.standstill_probe]`, see [`StandstillProbeTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub standstill_probe: StandstillProbeTuning<T>,
    /// The DC-link limits: source current limits, over-voltage controller and trip (`[controller.dc_link]`, see [`DcLinkTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub dc_link: DcLinkTuning<T>,
    /// Field weakening and the MTPV limit at the voltage limit (`[controller.field_weakening]`,
    /// see [`FieldWeakeningTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub field_weakening: FieldWeakeningTuning<T>,
    /// The speed, torque and power limits from the ratings (`[controller.limits]`, see
    /// [`RatingsLimitTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub limits: RatingsLimitTuning<T>,
    /// The acceleration feed-forward to the estimator's speed trackers, and when the drive turns it
    /// on by itself: a rotor its trackers would lag by more than `max_lag` at the current limit
    /// (`[controller.tracker_feedforward]`, see [`crate::control::tracker_feedforward`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub tracker_feedforward: TrackerFeedforwardTuning<T>,
    /// The release hold: a position loop that holds a rotor a load turns at zero speed
    /// after the start-up (`[controller.release_hold]`, see [`ReleaseHoldTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub release_hold: ReleaseHoldTuning<T>,
    /// How the start-up finds the rotor's angle (`[controller.startup]`, see
    /// [`StartupTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub startup: StartupTuning<T>,
    /// The speed reference's bounded acceleration from the rotor's speed at the start-up's
    /// end to the user's (`[controller.start_ramp]`, see [`StartRampTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub start_ramp: StartRampTuning<T>,
    /// Tuning of the reaction to a lost lock and of the recovery (`[controller.lock]`, see [`LockReactionTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub lock: LockReactionTuning<T>,
    /// Tuning of the stall symptom of the loss-of-lock detection (the speed loop's stall) (`[controller.stall]`, see [`StallTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub stall: StallTuning<T>,
}

/// Where each key of the flat `[controller]` table of earlier configuration files lives in
/// the nested one: (flat key, path below `[controller]`). `fado-sim` and Python refuse a flat
/// key naming its place from this table, and name the fields of fado-core's configuration
/// errors (which use the flat names) by it.
pub const MOVED_KEYS: &[(&str, &str)] = &[
    ("current_bandwidth_hz", "current.bandwidth_hz"),
    ("current_anti_windup_ratio", "current.anti_windup_ratio"),
    ("decoupling", "current.decoupling"),
    ("current_limit_ratio", "current.limit_ratio"),
    ("speed_bandwidth_hz", "speed.bandwidth_hz"),
    ("speed_zero_ratio", "speed.zero_ratio"),
    ("speed_anti_windup_ratio", "speed.anti_windup_ratio"),
    ("injection_current_ratio", "injection.current_ratio"),
    ("mtpa", "mtpa.enabled"),
    ("voltage_limit", "modulation.voltage_limit"),
    ("max_modulation", "modulation.max_modulation"),
    ("dead_time_compensation", "dead_time_compensation.enabled"),
    ("dead_time_method", "dead_time_compensation.method"),
    ("delay_compensation_factor", "delay_compensation.factor"),
    ("offset_calibration_time", "offset_calibration.time"),
    ("gain_calibration_time", "gain_calibration.time"),
    (
        "gain_calibration_current_ratio",
        "gain_calibration.current_ratio",
    ),
    (
        "gain_calibration_min_observability",
        "gain_calibration.min_observability",
    ),
    (
        "gain_calibration_max_mismatch",
        "gain_calibration.max_mismatch",
    ),
    (
        "gain_calibration_online_time",
        "gain_calibration.online_time",
    ),
    ("stuck_sensor_band_ratio", "stuck_sensor.band_ratio"),
    (
        "stuck_sensor_reference_ratio",
        "stuck_sensor.reference_ratio",
    ),
    ("stuck_sensor_time", "stuck_sensor.time"),
    ("trip_current_ratio", "protection.trip_current_ratio"),
    ("current_error_ratio", "protection.current_error_ratio"),
    ("current_error_time", "protection.current_error_time"),
    ("dc_link_min_ratio", "protection.dc_link_min_ratio"),
    ("input_fault_trip_time", "protection.input_fault_trip_time"),
    ("plausible_current_ratio", "plausibility.current_ratio"),
    ("dc_link_max_ratio", "plausibility.dc_link_ratio"),
    ("standstill_probe", "standstill_probe.enabled"),
    (
        "standstill_probe_current_ratio",
        "standstill_probe.current_ratio",
    ),
    ("standstill_probe_period", "standstill_probe.period"),
    ("standstill_probe_gain", "standstill_probe.gain"),
    ("standstill_probe_arm_time", "standstill_probe.arm_time"),
    (
        "standstill_probe_speed_ratio",
        "standstill_probe.speed_ratio",
    ),
    ("standstill_probe_load_ratio", "standstill_probe.load_ratio"),
    (
        "standstill_probe_swing_ratio",
        "standstill_probe.swing_ratio",
    ),
    ("lock_reaction", "lock.reaction"),
    ("lock_reaction_on_stall", "lock.reaction_on_stall"),
    ("lock_recovery_time", "lock.recovery_time"),
    ("lock_recovery_timeout", "lock.recovery_timeout"),
    ("lock_recovery_attempts", "lock.recovery_attempts"),
    ("lock_recovery_rs_adaptation", "lock.recovery_rs_adaptation"),
    ("lock_stall_speed_ratio", "stall.speed_ratio"),
    ("lock_stall_time", "stall.time"),
    ("lock_stall_heal_time", "stall.heal_time"),
    ("lock_stall_max_speed_ratio", "stall.max_speed_ratio"),
    ("lock_stall_min_current_ratio", "stall.min_current_ratio"),
    ("lock_stall_gross_error_ratio", "stall.gross_error_ratio"),
    ("lock_stall_kdf_speed_ratio", "stall.kdf_speed_ratio"),
    ("lock_stall_follow_time", "stall.follow_time"),
    (
        "lock_stall_follow_min_current_ratio",
        "stall.follow_min_current_ratio",
    ),
    ("lock_stall_follow_accel_ratio", "stall.follow_accel_ratio"),
    ("lock_stall_torque_band_ratio", "stall.torque_band_ratio"),
    (
        "lock_stall_reluctance_band_ratio",
        "stall.reluctance_band_ratio",
    ),
    ("acceleration_feedforward", "tracker_feedforward.enabled"),
];

impl<T: Real> DriveTuning<T> {
    /// The same record in another precision (e.g. an f64 configuration for an f32 drive):
    /// every real rounded to `U`.
    pub fn cast<U: Real>(&self) -> DriveTuning<U> {
        DriveTuning {
            current: self.current.cast(),
            speed: self.speed.cast(),
            injection: self.injection.cast(),
            mtpa: self.mtpa,
            modulation: self.modulation.cast(),
            dead_time_compensation: self.dead_time_compensation,
            delay_compensation: self.delay_compensation.cast(),
            inverter: self.inverter.cast(),
            protection: self.protection.cast(),
            plausibility: self.plausibility.cast(),
            offset_calibration: self.offset_calibration.cast(),
            gain_calibration: self.gain_calibration.cast(),
            stuck_sensor: self.stuck_sensor.cast(),
            standstill_probe: self.standstill_probe.cast(),
            dc_link: self.dc_link.cast(),
            field_weakening: self.field_weakening.cast(),
            limits: self.limits.cast(),
            tracker_feedforward: self.tracker_feedforward.cast(),
            release_hold: self.release_hold.cast(),
            startup: self.startup.cast(),
            start_ramp: self.start_ramp.cast(),
            lock: self.lock.cast(),
            stall: self.stall.cast(),
        }
    }
}

impl<T: Real> Default for DriveTuning<T> {
    fn default() -> Self {
        Self {
            current: CurrentLoopTuning::default(),
            speed: SpeedLoopTuning::default(),
            injection: InjectionTuning::default(),
            mtpa: MtpaTuning::default(),
            modulation: ModulationTuning::default(),
            dead_time_compensation: DeadTimeCompensationTuning::default(),
            delay_compensation: DelayCompensationTuning::default(),
            inverter: InverterData::default(),
            protection: ProtectionTuning::default(),
            plausibility: SamplePlausibilityTuning::default(),
            offset_calibration: OffsetCalibrationTuning::default(),
            gain_calibration: GainCalibrationTuning::default(),
            stuck_sensor: StuckSensorTuning::default(),
            standstill_probe: StandstillProbeTuning::default(),
            dc_link: DcLinkTuning::default(),
            field_weakening: FieldWeakeningTuning::default(),
            limits: RatingsLimitTuning::default(),
            tracker_feedforward: TrackerFeedforwardTuning::default(),
            release_hold: ReleaseHoldTuning::default(),
            startup: StartupTuning::default(),
            start_ramp: StartRampTuning::default(),
            lock: LockReactionTuning::default(),
            stall: StallTuning::default(),
        }
    }
}
