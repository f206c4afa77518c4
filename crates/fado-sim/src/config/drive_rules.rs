//! The values the drive's build-time rules set in its tuning, shown by `--dump-config` as
//! derived keys beside the rule: what the drive runs with, not only what the file says.

use super::SimConfig;
use crate::derive::Derived;

/// The rule of `fado_core::control::tracker_feedforward` in words, beside the keys it sets.
const FEEDFORWARD_RULE: &str = "on where the type-2 T2S-1 would lag the acceleration at the \
    current limit by more than `[controller.tracker_feedforward] max_lag` \
    (fado_core::control::tracker_feedforward)";

/// The same rule's load integrator of the trackers, where the tuning leaves it at 0.
const LOAD_POLE_RULE: &str = "0.5 with the acceleration feed-forward the drive turns on \
    itself (fado_core::control::tracker_feedforward)";

/// The same rule's running bandwidth of T2S-1 on a light rotor.
const BANDWIDTH_RULE: &str = "T2S-1's bandwidth in k_df mode at which a step of the rated \
    torque peaks at `[controller.tracker_feedforward] load_step_error` \
    (fado_core::control::tracker_feedforward)";

/// The release hold's rule for the current loop's bandwidth.
const HOLD_CURRENT_RULE: &str = "10·ω_h of the release hold's design travel where the hold is \
    enabled or armed at the start-up's end (`at_start`) and that is above the tuning's, at most ωc·Ts = 0.2 \
    (fado_core::control::release_hold)";

/// The speed loop's bandwidth on a light rotor, and T2S-2's with it.
const SPEED_RULE: &str = "raised until a step of the rated torque at the rated speed dips \
    the speed by at most `[controller.speed] load_step_dip_ratio` × the rated speed and a ramp \
    of the rated torque over `load_ramp_time` leaves at most `load_ramp_error_ratio` × the \
    rated speed, T2S-2 in the tuning's ratio (fado_core::control::speed_bandwidth)";

/// The injection's bound on a salient rotor.
const INJECTION_RULE: &str = "the injection's I_min bounded to `[controller.injection] \
    max_active_flux_share` × λ̂f/(L̂q − L̂d), the d current that shrinks the active flux by \
    that share (DriveConfig::i_min)";

/// `cfg` with the values the drive's build-time rule sets in its tuning (the acceleration
/// feed-forward, the trackers' load pole and T2S-1's running bandwidth of
/// `fado_core::control::tracker_feedforward`, the current loop's bandwidth of
/// `fado_core::control::release_hold`, the speed loop's and T2S-2's of
/// `fado_core::control::speed_bandwidth`, the injection's bound of `DriveConfig::i_min`), each
/// recorded as derived: what the drive runs
/// with, as `--dump-config` shows it.
pub(crate) fn with_drive_rules(cfg: &SimConfig) -> SimConfig {
    let mut c = cfg.clone();
    let drive = c.drive_config();
    let (mut built, mut estimator) = (drive, c.estimator);
    built.apply_build_rules(&mut estimator);
    let tuning = built.tuning;
    let mut derived = std::mem::take(&mut c.derived);
    if tuning.tracker_feedforward.enabled != c.controller.tracker_feedforward.enabled {
        record(
            &mut derived,
            "controller.tracker_feedforward.enabled",
            1.0,
            FEEDFORWARD_RULE,
        );
        c.controller.tracker_feedforward.enabled = true;
    }
    let injection = injection_ratio(&c, &drive);
    let t = &mut c.estimator.tracker;
    for (key, value, field, rule) in [
        (
            "estimator.tracker.load_pole_ratio",
            estimator.tracker.load_pole_ratio,
            &mut t.load_pole_ratio,
            LOAD_POLE_RULE,
        ),
        (
            "estimator.tracker.t2s1_running_bandwidth_hz",
            estimator.tracker.t2s1_running_bandwidth_hz,
            &mut t.t2s1_running_bandwidth_hz,
            BANDWIDTH_RULE,
        ),
        (
            "controller.current.bandwidth_hz",
            tuning.current.bandwidth_hz,
            &mut c.controller.current.bandwidth_hz,
            HOLD_CURRENT_RULE,
        ),
        (
            "estimator.tracker.t2s2_bandwidth_hz",
            estimator.tracker.t2s2_bandwidth_hz,
            &mut t.t2s2_bandwidth_hz,
            SPEED_RULE,
        ),
        (
            "controller.speed.bandwidth_hz",
            tuning.speed.bandwidth_hz,
            &mut c.controller.speed.bandwidth_hz,
            SPEED_RULE,
        ),
        (
            "controller.injection.current_ratio",
            injection,
            &mut c.controller.injection.current_ratio,
            INJECTION_RULE,
        ),
    ] {
        if value != *field {
            record(&mut derived, key, value, rule);
            *field = value;
        }
    }
    c.derived = derived;
    c
}

/// Records `key` as derived with `value` by `rule`, replacing an earlier record of it.
fn record(derived: &mut Vec<Derived>, key: &str, value: f64, rule: &'static str) {
    derived.retain(|d| d.key != key);
    derived.push(Derived {
        key: key.to_owned(),
        value,
        rule,
    });
}

/// `[controller.injection] current_ratio` as the drive runs it: the configured ratio, or the
/// bound of `DriveConfig::i_min` on a salient rotor over the rated current where that is lower.
fn injection_ratio(c: &SimConfig, drive: &fado_core::control::DriveConfig<f64>) -> f64 {
    let (ratio, rated) = (
        c.controller.injection.current_ratio,
        drive.machine.rated_current,
    );
    if drive.i_min() < ratio * rated {
        drive.i_min() / rated
    } else {
        ratio
    }
}
