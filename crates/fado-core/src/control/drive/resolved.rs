//! The drive's limits and sample counts in absolute units, resolved once from the tuning's
//! ratios and durations.

use super::{DriveConfig, Resolved, StallResolved};
use crate::Real;
use crate::error::{ConfigError, check};

/// Largest `current.limit_ratio`: 5 (a drive's short-time overload is 1.5–3 × the rated
/// current; above 5 the limit is a typo, and the trip level above it would be refused in its
/// stead).
const MAX_CURRENT_LIMIT_RATIO: f64 = 5.0;

impl<T: Real> Resolved<T> {
    pub(super) fn new(c: &DriveConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", c.ts)?;
        c.machine.validate()?;
        let t = &c.tuning;
        check::positive("tracker_feedforward.max_lag", t.tracker_feedforward.max_lag)?;
        check::positive(
            "tracker_feedforward.load_step_error",
            t.tracker_feedforward.load_step_error,
        )?;
        check::positive(
            "tracker_feedforward.heavy_rotor_time",
            t.tracker_feedforward.heavy_rotor_time,
        )?;
        let rated = c.machine.rated_current;
        // A duration as a whole number of samples (at most about 5 days at 10 kHz).
        let samples = &|field: &'static str, time: T| check::samples(field, time, ts);
        Ok(Self {
            floor_at_brake: super::hold::floor_at_brake(c),
            i_max: check::below(
                "current_limit_ratio",
                check::positive("current_limit_ratio", t.current.limit_ratio)?,
                T::lit(MAX_CURRENT_LIMIT_RATIO),
                "at most 5 × the rated current (drives' short-time overload is 1.5–3×)",
            )? * rated,
            i_min: {
                check::non_negative("injection_current_ratio", t.injection.current_ratio)?;
                check::non_negative(
                    "injection.max_active_flux_share",
                    t.injection.max_active_flux_share,
                )?;
                check::positive("speed.load_step_dip_ratio", t.speed.load_step_dip_ratio)?;
                check::positive("speed.load_ramp_time", t.speed.load_ramp_time)?;
                check::positive("speed.load_ramp_error_ratio", t.speed.load_ramp_error_ratio)?;
                c.i_min()
            },
            trip_current: check::positive("trip_current_ratio", t.protection.trip_current_ratio)?
                * rated,
            current_error_limit: check::positive(
                "current_error_ratio",
                t.protection.current_error_ratio,
            )? * rated,
            dc_link_min_voltage: check::below(
                "dc_link_min_ratio",
                check::non_negative("dc_link_min_ratio", t.protection.dc_link_min_ratio)?,
                T::one(),
                "below 1 (a fraction of the nominal DC link: at or above it the warning never clears)",
            )? * c.machine.dc_voltage,
            offset_calibration_samples: samples(
                "offset_calibration_time",
                t.offset_calibration.time,
            )?,
            stuck_sensor_samples: samples("stuck_sensor_time", t.stuck_sensor.time)?,
            current_error_samples: samples("current_error_time", t.protection.current_error_time)?,
            input_fault_trip_samples: samples(
                "input_fault_trip_time",
                t.protection.input_fault_trip_time,
            )?,
            stall: StallResolved::new(c, samples)?,
            plausible_current: t.plausibility.current_ratio
                * t.protection.trip_current_ratio
                * rated,
            dc_link_max_voltage: t.plausibility.dc_link_ratio * c.machine.dc_voltage,
            stuck_turn_gain: c.ts * T::lit(0.5) * (c.ts / c.machine.lq),
            mtpa: t.mtpa.enabled && c.machine.is_salient(),
            salient: c.machine.is_salient(),
            saturated: c.saturated_references(),
        })
    }
}

impl<T: Real> StallResolved<T> {
    /// The stall symptom's thresholds; `samples` turns a duration field into samples.
    fn new(
        c: &DriveConfig<T>,
        samples: &dyn Fn(&'static str, T) -> Result<u32, ConfigError>,
    ) -> Result<Self, ConfigError> {
        let t = &c.tuning;
        let rated = c.machine.rated_current;
        // A stall-band ratio ε per unit of torque over 1.5·p (Wb·A): ε·1.5·p (torque) times
        // p (electrical speed) over Ĵ·ω_s, the speed error whose proportional action commands
        // that torque.
        let torque_band = |field: &'static str, ratio: T| -> Result<T, ConfigError> {
            Ok(check::non_negative(field, ratio)?
                * T::lit(1.5 * (c.machine.pole_pairs as f64) * (c.machine.pole_pairs as f64))
                / (c.machine.inertia * T::lit(core::f64::consts::TAU) * t.speed.bandwidth_hz))
        };
        Ok(Self {
            speed: check::non_negative("lock_stall_speed_ratio", t.stall.speed_ratio)?
                * c.machine.rated_speed(),
            samples: if t.stall.speed_ratio > T::zero() {
                samples("lock_stall_time", t.stall.time)?.max(1)
            } else {
                0
            },
            heal_samples: samples("lock_stall_heal_time", t.stall.heal_time)?,
            max_speed: match check::non_negative(
                "lock_stall_max_speed_ratio",
                t.stall.max_speed_ratio,
            )? {
                r if r == T::zero() => T::lit(f64::INFINITY),
                r => r * c.machine.rated_speed(),
            },
            kdf_band: check::non_negative("lock_stall_kdf_speed_ratio", t.stall.kdf_speed_ratio)?
                * c.machine.rated_speed(),
            min_current: check::non_negative(
                "lock_stall_min_current_ratio",
                t.stall.min_current_ratio,
            )? * rated,
            gross_ratio: match check::non_negative(
                "lock_stall_gross_error_ratio",
                t.stall.gross_error_ratio,
            )? {
                k if k == T::zero() => T::lit(f64::INFINITY),
                k => k,
            },
            follow_gain: match check::non_negative("lock_stall_follow_time", t.stall.follow_time)? {
                tau if tau == T::zero() => T::zero(),
                tau => T::one() - (-c.ts / tau).exp(),
            },
            follow_min_current: check::non_negative(
                "lock_stall_follow_min_current_ratio",
                t.stall.follow_min_current_ratio,
            )? * rated,
            follow_lead: check::non_negative(
                "lock_stall_follow_accel_ratio",
                t.stall.follow_accel_ratio,
            )? * c.machine.rated_speed()
                * check::non_negative("lock_stall_follow_time", t.stall.follow_time)?,
            torque_band: torque_band("lock_stall_torque_band_ratio", t.stall.torque_band_ratio)?,
            reluctance_band: torque_band(
                "lock_stall_reluctance_band_ratio",
                t.stall.reluctance_band_ratio,
            )?,
        })
    }
}
