//! The values the drive's build-time rules set in its tuning, shown by `--dump-config` as
//! derived keys beside the rule: what the drive runs with, not only what the file says.

use super::SimConfig;
use crate::derive::Derived;

/// The rule of `fado_core::control::tracker_feedforward` in words, beside the keys it sets.
const FEEDFORWARD_RULE: &str = "on where the type-2 T2S-1 would lag the acceleration at the \
    current limit by more than `[controller.tracker_feedforward] max_lag`, or where the \
    mechanical time constant Ĵ·Ω_rated/T_rated exceeds `heavy_rotor_time` \
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
    enabled or armed at the start-up's end (`at_start`) and that is above the tuning's, at most ωc·Ts = 0.35 \
    (fado_core::control::release_hold)";

/// The speed loop's bandwidth on a light rotor, and T2S-2's with it.
const SPEED_RULE: &str = "raised until a step of the rated torque at the rated speed dips \
    the speed by at most `[controller.speed] load_step_dip_ratio` × the rated speed and a ramp \
    of the rated torque over `load_ramp_time` leaves at most `load_ramp_error_ratio` × the \
    rated speed, T2S-2 in the tuning's ratio (fado_core::control::speed_bandwidth)";

/// T2S-2's bandwidth on a saturating model of strong frame coupling.
const COUPLING_RULE: &str = "the tuning's T2S-2 × c/c_max where the model's frame coupling c = \
    |s|/κ at the rated torque's MTPA point (at most the current limit) exceeds c_max = \
    DEFAULT_MAX_FRAME_COUPLING = 1, at most Kp·Ts = 0.25 (fado_core::control::speed_bandwidth)";

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
    // T2S-2 moves with the speed loop (the light rotor's rule) or alone (the frame coupling's).
    let tracker_rule = if tuning.speed.bandwidth_hz != c.controller.speed.bandwidth_hz {
        SPEED_RULE
    } else {
        COUPLING_RULE
    };
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
            tracker_rule,
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

/// A warning where the drive's magnetic model couples the frame beyond what the tuning's
/// speed tracker holds (`fado_core::control::speed_bandwidth::rated_frame_coupling` above
/// `DEFAULT_MAX_FRAME_COUPLING`), naming the model's magnetic key: the drive raises T2S-2,
/// which holds such a rotor through zero speed at part load, not generating under the rated
/// torque.
pub(crate) fn frame_coupling_warning(
    cfg: &SimConfig,
) -> Option<(fado_core::machine_checks::Severity, String, String)> {
    use fado_core::control::speed_bandwidth::{DEFAULT_MAX_FRAME_COUPLING, rated_frame_coupling};
    let drive = cfg.drive_config();
    let c = rated_frame_coupling(&drive.machine, &drive.tuning)?;
    if !(c > DEFAULT_MAX_FRAME_COUPLING && c.is_finite()) {
        return None;
    }
    let model = cfg.model.as_ref();
    let key = match crate::model_magnetics::MODEL_MAGNETICS_KEYS
        .iter()
        .find(|k| model.is_some_and(|t| t.contains_key(**k)))
    {
        Some(k) => format!("model.{k}"),
        None if cfg.motor_flux_map.is_some() => crate::magnetics_file::FLUX_MAP_KEY.to_owned(),
        None => "motor.saturation".to_owned(),
    };
    let (mut built, mut estimator) = (drive, cfg.estimator);
    built.apply_build_rules(&mut estimator);
    let text = format!(
        "`{key}`: the frame coupling |s|/κ at the rated torque's MTPA point (`motor.rated_torque`) \
         is {c:.2}, above the {DEFAULT_MAX_FRAME_COUPLING} the speed tracker holds at its \
         tuning's ratio to the speed loop: the drive runs T2S-2 at {:.1} Hz instead of {:.1} Hz \
         (fado_core::control::speed_bandwidth); generating under the rated torque near zero \
         speed may lose the angle (a 4 kW ferrite PM-SyRM of coupling 1.23, ψd < 0 on its MTPA \
         curve, loses it in `rated-reversal`)",
        estimator.tracker.t2s2_bandwidth_hz, cfg.estimator.tracker.t2s2_bandwidth_hz
    );
    Some((fado_core::machine_checks::Severity::Warning, key, text))
}
