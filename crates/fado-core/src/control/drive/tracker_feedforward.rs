//! When the drive feeds the commanded acceleration to the estimator's speed trackers: on a
//! rotor whose acceleration at the current limit the paper's type-2 trackers cannot follow.
//!
//! **Why.** A type-2 tracker lags a constant electrical acceleration α by α/Ki in angle
//! ([`crate::tracker`]). At the current limit α = p·T_max/Ĵ, and in units of the ratings
//! α/Ki = ω_rated·(T_max/T_rated)/(t_m·Ki), t_m = Ĵ·ω_rated,mech/T_rated the mechanical start
//! time: the lag grows with the rated *electrical* speed. The paper's motor (4 pole pairs,
//! 1500 r/min) lags 0.21 rad behind its 60 Hz T2S-1; a 14-pole-pair multirotor motor at
//! 8000 r/min with its propeller lags 2.4 rad, and a 21-pole-pair actuator outrunner 3.0 rad:
//! a throttle step loses the rotor (measured on `motors/multirotor-mn5006-22v.toml`, 0 → 6000
//! r/min at the current limit: 2.1 rad; with the feed-forward 0.09 rad).
//!
//! **Rule.** Where the lag α/Ki at the current limit (T_max = min(`current.limit_ratio`,
//! `limits.torque_ratio`)·T_rated, Ki of T2S-1) exceeds [`TrackerFeedforwardTuning::max_lag`],
//! the drive turns on its acceleration feed-forward (`TrackerFeedforwardTuning::enabled`)
//! and gives the trackers their load integrator (`EstimatorTuning::tracker.load_pole_ratio`
//! [`LOAD_POLE_RATIO`] where the tuning leaves it at 0): without it the load the model does not
//! know would leave p·T_L/(Ĵ·Ki) of angle error. A tuning that turns them on itself is kept.
//!
//! **Threshold.** 1 rad \[A\]: on the repository's presets the rule turns the feed-forward on for
//! the two fast outrunners (lags 2.4 and 3.0 rad; `reversal` and `stops` within 0.07 rad) and
//! leaves the paper's trackers on the others (lags 0.06 to 0.68 rad). On the two strongly
//! salient presets (0.50 and 0.68 rad) the type-3 trackers lose `reversal` near zero speed
//! (measured: ipmsm-gem-50k 3.1 rad, pmsyrm-5k 0.21 rad), so a threshold below their lags would
//! cost them their zero-speed passage.

use crate::Real;
use crate::control::DriveTuning;
use crate::estimator::EstimatorTuning;
use crate::machine::MachineModel;
use crate::tracker::TrackerConfig;

/// Load-integrator pole of the trackers the rule turns on, as a ratio of ωn: 0.5 \[A\] (the
/// range scenarios' value, docs/range.md).
pub const LOAD_POLE_RATIO: f64 = 0.5;

/// `[controller.tracker_feedforward]`: the rule of the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(
        deny_unknown_fields,
        default,
        bound(
            serialize = "T: serde::Serialize",
            deserialize = "T: Real + serde::Deserialize<'de>"
        )
    )
)]
pub struct TrackerFeedforwardTuning<T> {
    /// Give the estimator's speed trackers the acceleration the commanded torque causes,
    /// p·T*/Ĵ (a mechanical-model feed-forward, see [`crate::tracker`]); use with the
    /// estimator's `tracker.load_pole_ratio` > 0, whose third integrator takes up the load.
    /// Default false (the paper's trackers) \[A\]; the drive turns it on itself on a rotor its
    /// trackers would lag by more than `max_lag` (the module docs).
    pub enabled: bool,
    /// Largest angle lag (rad) of the type-2 T2S-1 behind an acceleration at the current limit
    /// that the drive leaves without feed-forward. Default 2 rad \[A\]: the multirotor preset
    /// (2.4 rad) and the cheetah outrunner (3.0 rad) need the feed-forward; a 750 W 10-pole
    /// servo (1.5–2 rad) holds its loaded start without it and loses it with it (5 rad
    /// backward, `fado-sim/tests/loaded_start.rs`); the strongly salient presets lose their
    /// `reversal` with it. A large value (1e9) keeps the paper's trackers on every rotor.
    pub max_lag: T,
}

impl<T: Real> Default for TrackerFeedforwardTuning<T> {
    fn default() -> Self {
        Self {
            enabled: false,
            max_lag: T::lit(2.0),
        }
    }
}

impl<T: Real> TrackerFeedforwardTuning<T> {
    /// The same tuning in another scalar type.
    pub fn cast<U: Real>(&self) -> TrackerFeedforwardTuning<U> {
        TrackerFeedforwardTuning {
            enabled: self.enabled,
            max_lag: U::lit(self.max_lag.to_f64()),
        }
    }
}

/// The angle (rad) by which the type-2 T2S-1 of `estimator`, sampled every `ts`, lags the
/// electrical acceleration p·T_max/Ĵ of `machine` at the drive's current limit (module docs).
pub fn current_limit_lag<T: Real>(
    machine: &MachineModel<T>,
    drive: &DriveTuning<T>,
    estimator: &EstimatorTuning<T>,
    ts: T,
) -> T {
    let tracker = TrackerConfig {
        damping: estimator.tracker.damping,
        definition: estimator.tracker.bandwidth_definition,
        ..TrackerConfig::new(estimator.tracker.t2s1_bandwidth_hz, ts)
    };
    let (_, ki) = tracker.gains();
    let ratio = crate::real::min(drive.current.limit_ratio, drive.limits.torque_ratio);
    let p = T::lit(machine.pole_pairs as f64);
    p * ratio * machine.rated_torque / (machine.inertia * ki)
}

/// Applies the rule of the module docs to the drive's and the estimator's tuning, in place.
pub fn apply<T: Real>(
    machine: &MachineModel<T>,
    drive: &mut DriveTuning<T>,
    estimator: &mut EstimatorTuning<T>,
    ts: T,
) {
    // NaN compares false: no feed-forward.
    if current_limit_lag(machine, drive, estimator, ts) > drive.tracker_feedforward.max_lag {
        drive.tracker_feedforward.enabled = true;
        if estimator.tracker.load_pole_ratio == T::zero() {
            estimator.tracker.load_pole_ratio = T::lit(LOAD_POLE_RATIO);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn resolve(
        m: &MachineModel<f64>,
        mut d: DriveTuning<f64>,
        mut e: EstimatorTuning<f64>,
        ts: f64,
    ) -> (DriveTuning<f64>, EstimatorTuning<f64>) {
        apply(m, &mut d, &mut e, ts);
        (d, e)
    }

    #[test]
    fn the_lag_grows_with_the_rated_electrical_speed_and_turns_the_feedforward_on() {
        let d = DriveTuning::<f64>::default();
        let e = EstimatorTuning::<f64>::default();
        // The paper's motor (with its dynamometer, 0.012 kg·m²): 4·(40/21.78)·11.5/0.012 =
        // 7.0e3 rad/s² against Ki = (2π·60/2.058)² = 3.36e4 s⁻²: 0.21 rad, type-2 kept.
        let m = MachineModel::<f64>::paper();
        let lag = current_limit_lag(&m, &d, &e, 100e-6);
        assert!((lag - 0.21).abs() < 0.01, "{lag}");
        let (d2, e2) = resolve(&m, d, e, 100e-6);
        assert!(!d2.tracker_feedforward.enabled && e2.tracker.load_pole_ratio == 0.0);
        assert_eq!((d2, e2), (d, e));
        // A 14-pole-pair multirotor motor with its propeller: 2.4 rad, feed-forward on.
        let fast = MachineModel {
            pole_pairs: 14,
            flux_linkage: 8.75e-4,
            rated_current: 34.0,
            rated_torque: 0.625,
            rated_speed_rpm: 8000.0,
            inertia: 2.0e-4,
            ..m
        };
        let lag = current_limit_lag(&fast, &d, &e, 25e-6);
        assert!((lag - 2.4).abs() < 0.05, "{lag}");
        let (d2, e2) = resolve(&fast, d, e, 25e-6);
        assert!(d2.tracker_feedforward.enabled);
        assert_eq!(e2.tracker.load_pole_ratio, LOAD_POLE_RATIO);
        // A tuning's own load pole is kept; an infinite threshold keeps the paper's trackers.
        let mut own = e;
        own.tracker.load_pole_ratio = 0.3;
        assert_eq!(resolve(&fast, d, own, 25e-6).1.tracker.load_pole_ratio, 0.3);
        let mut off = d;
        off.tracker_feedforward.max_lag = 1e9;
        assert!(!resolve(&fast, off, e, 25e-6).0.tracker_feedforward.enabled);
    }
}
