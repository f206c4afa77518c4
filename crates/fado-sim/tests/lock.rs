//! Implausible samples and loss-of-lock detection in closed loop (issue 14), fig11
//! switching-resolved.
//!
//! * One finite but absurd phase-current sample (1e4, 1e5, 1e6 A, as `[[faults.stuck_current]]`
//!   of one sample on channel a) during the loaded zero-speed passage is refused
//!   (`INPUT_REJECTED` and `INPUT_IMPLAUSIBLE`, no trip) and the estimated angle stays within
//!   0.05 rad of the same run without it. Before issue 14, 1e6 A left θ̂ π off for the rest of
//!   the run.
//! * The detector flags the paper's fixed R̂s at +10 % error, where fig11 loses the rotor,
//!   and stays quiet on the matched run.

use fado_core::DriveFlags;
use fado_sim::scenario::run_config;
use fado_sim::scenario_config;

fn theta_hat(toml: &str) -> (Vec<f64>, Vec<u16>, bool) {
    let cfg = scenario_config("fig11", Some(toml), false).unwrap();
    let out = run_config("fig11", cfg, None).unwrap();
    (
        out.trace.column("theta_hat").unwrap(),
        out.trace.rows.iter().map(|r| r.fault_flags).collect(),
        out.metrics.tripped,
    )
}

#[test]
fn absurd_current_samples_are_refused_and_leave_the_estimate_alone() {
    // Decimation 1: the trace holds every sample, so the glitch's own sample is in it.
    let base = "[simulation]\ndecimation = 1\n";
    let (reference, _, tripped) = theta_hat(base);
    assert!(!tripped);
    for value in [1e4, 1e5, 1e6] {
        let toml = format!(
            "{base}[[faults.stuck_current]]\nchannel = \"a\"\nstart = 3.0\nduration = 1e-4\nvalue = {value:e}\n"
        );
        let (theta, flags, tripped) = theta_hat(&toml);
        assert!(!tripped, "{value}: tripped");
        let rejected = flags
            .iter()
            .filter(|f| {
                DriveFlags::from_bits(**f)
                    .contains(DriveFlags::INPUT_REJECTED | DriveFlags::INPUT_IMPLAUSIBLE)
            })
            .count();
        assert!(rejected >= 1, "{value}: not flagged");
        let worst = theta
            .iter()
            .zip(&reference)
            .map(|(a, b)| fado_core::wrap_angle(a - b).abs())
            .fold(0.0_f64, f64::max);
        println!("{value:e} A: {rejected} sample(s) refused, max |θ̂ − θ̂_ref| = {worst:.4} rad");
        assert!(worst < 0.05, "{value}: θ̂ moved by {worst} rad");
    }
}

#[test]
fn a_lost_rotor_is_flagged_and_a_matched_run_is_not() {
    let cfg = scenario_config(
        "fig11",
        Some("[estimator]\nrs_adaptation = false\n[mismatch]\nrs_ratio = 1.1\n"),
        false,
    )
    .unwrap();
    let lost = run_config("fig11", cfg, None).unwrap();
    let m = &lost.metrics;
    assert!(m.max_angle_error_run > 1.0, "{m:?}");
    let flagged = m.lock_lost_time.expect("the lost rotor was not flagged");
    let exceeded = m.angle_error_exceeded_time.unwrap();
    println!("rs ×1.1 fixed: |θ − θ̂| > 0.5 rad at {exceeded} s, LOCK_LOST at {flagged} s");
    assert!(flagged <= exceeded + 0.02);
    let matched = run_config(
        "fig11",
        scenario_config("fig11", None, false).unwrap(),
        None,
    )
    .unwrap();
    assert!(matched.passed);
    assert_eq!(matched.metrics.lock_lost_time, None);
}
