//! The profiles in the paper's units (Fig. 8-12, `steady300`) and the user's own (`custom`).

use crate::config::SimConfig;
use crate::profile::Profile;

/// `custom`: the user's profiles as they are; the run lasts until 1 s after the last
/// breakpoint of the speed reference or the load (the user's `[simulation] duration`, applied
/// after this, wins).
pub(super) fn setup_custom(c: &mut SimConfig) {
    let end = [
        c.speed_reference.end_time(),
        c.load.torque.end_time(),
        c.load.speed_rpm.end_time(),
    ]
    .into_iter()
    .fold(0.0, f64::max);
    c.simulation.duration = end + CUSTOM_TAIL_SECONDS;
}

/// What `custom` runs after the last breakpoint of its profiles, s: the settling of a step.
pub const CUSTOM_TAIL_SECONDS: f64 = 1.0;

/// `fig8`: profile, load, duration, evaluation window.
pub(super) fn setup_fig8(c: &mut SimConfig) {
    let pts = Profile::from_points;
    c.speed_reference = pts(&[
        (0.0, 0.0),
        (0.5, 0.0),
        (1.5, 90.0),
        (3.0, 90.0),
        (5.0, -90.0),
    ]);
    c.load.torque = pts(&[(1.5, 0.0), (2.0, 2.0)]);
    c.simulation.duration = 6.5;
    c.simulation.eval_start = 2.5;
}

/// `fig9`: profile, load, duration, evaluation window.
pub(super) fn setup_fig9(c: &mut SimConfig) {
    let pts = Profile::from_points;
    c.speed_reference = pts(&[(0.0, 0.0), (0.3, 0.0), (1.3, -300.0)]);
    c.load.torque = pts(&[(1.3, 0.0), (1.8, -3.0)]);
    c.simulation.duration = 11.0;
    c.simulation.eval_start = 2.0;
    c.simulation.disturbance_feedback_off = vec![[3.0, 5.0]];
    // Fig. 9 shows what k_df does against an integrand error; the start-up offset
    // calibration is off so that the uncalibrated 20 / −10 mA sensor offsets
    // provide one of visible size \[A\]. (Calibrated, λ1 drifts only 1–3 mWb in
    // the 2 s: too little for the drift check, and the recovery ratio is then
    // dominated by noise.)
    c.controller.offset_calibration.time = 0.0;
    // For the same reason the learned integrand offset is off: it removes that error while
    // turning, so with k_df off λ1 would have nothing to drift from (measured: 0.2 mWb
    // instead of 21 mWb in the 2 s) \[A\].
    c.estimator.offset_adaptation.rate = 0.0;
}

/// `fig10`: profile, load, duration, evaluation window.
pub(super) fn setup_fig10(c: &mut SimConfig) {
    let pts = Profile::from_points;
    c.speed_reference = pts(&[(0.0, 0.0), (0.2, 0.0), (0.7, 60.0), (1.2, 60.0), (1.7, 0.0)]);
    c.simulation.duration = 5.5;
    c.simulation.eval_start = 0.2;
}

/// `fig11`: profile, load, duration, evaluation window.
pub(super) fn setup_fig11(c: &mut SimConfig) {
    let pts = Profile::from_points;
    c.speed_reference = pts(&[
        (0.0, 0.0),
        (0.2, 0.0),
        (1.2, -90.0),
        (2.5, -90.0),
        (4.5, 90.0),
    ]);
    c.load.torque = pts(&[(1.2, 0.0), (1.7, 7.5)]);
    c.simulation.duration = 5.5;
    c.simulation.eval_start = 2.0;
}

/// `fig12`: profile, load, duration, evaluation window.
pub(super) fn setup_fig12(c: &mut SimConfig) {
    let pts = Profile::from_points;
    let mut p = vec![(0.0, 0.0), (0.2, 0.0), (0.9, 60.0), (2.0, 60.0)];
    let mut t = 2.0;
    for _ in 0..3 {
        p.extend([
            (t + 0.5, 0.0),
            (t + 0.8, 0.0),
            (t + 1.3, 60.0),
            (t + 1.8, 60.0),
        ]);
        t += 1.8;
    }
    c.speed_reference = pts(&p);
    c.load.torque = pts(&[(0.9, 0.0), (1.4, 7.5)]);
    c.simulation.duration = t;
    c.simulation.eval_start = 1.8;
}

/// `steady300`: profile, load, duration, evaluation window.
pub(super) fn setup_steady300(c: &mut SimConfig) {
    let pts = Profile::from_points;
    c.speed_reference = pts(&[(0.0, 0.0), (0.2, 0.0), (1.2, 300.0)]);
    c.load.torque = pts(&[(1.5, 0.0), (2.0, 7.5)]);
    c.simulation.duration = 4.0;
    c.simulation.eval_start = 2.5;
}
