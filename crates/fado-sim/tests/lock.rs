//! Implausible samples and loss-of-lock detection in closed loop, fig11
//! switching-resolved.
//!
//! * One finite but absurd phase-current sample (1e4, 1e5, 1e6 A, as `[[faults.stuck_current]]`
//!   of one sample on channel a) during the loaded zero-speed passage is refused
//!   (`INPUT_REJECTED` and `INPUT_IMPLAUSIBLE`, no trip) and the estimated angle stays within
//!   0.05 rad of the same run without it. Without the bounds, 1e6 A leaves θ̂ π off for the rest of
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
    // The start-up gain calibration is off in these lock runs: their flag times and the
    // recovery depend on when the drive starts (with the drive started at 0 s or 0.62 s
    // instead of 0.1 s, LOCK_LOST comes 0.1 s after the 0.5 rad and `recover` runs away, as
    // in README's known limitations; at 0.1 s a start-up flag at 0.30 s triggers it early).
    let cfg = scenario_config(
        "fig11",
        Some(
            "[estimator.rs_adaptation]\nenabled = false\n[mismatch]\nrs_ratio = 1.1\n\
             [controller.gain_calibration]\ntime = 0.0\n",
        ),
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

/// The "recover" criterion: fig11 with the paper's fixed R̂s at +10 % error, reaction
/// `recover` (defaults: the recovery switches the R̂s adaptation on), ends at the reference
/// speed with the reason (`LOCK_LOST`, the estimator's flux verdict, which comes first here;
/// `COASTING`) in the flags; without switching the adaptation on, the restarted fixed-R̂s
/// drive meets the same passage and does not. The
/// `adapt` reaction (switch the adaptation on, no coasting) ends there too.
#[test]
fn recover_ends_at_the_reference_speed_with_the_reason_logged() {
    let run = |extra: &str| {
        let toml = format!(
            "[estimator.rs_adaptation]\nenabled = false\n[mismatch]\nrs_ratio = 1.1\n\
             [controller.gain_calibration]\ntime = 0.0\n{extra}"
        );
        let cfg = scenario_config("fig11", Some(&toml), false).unwrap();
        let out = run_config("fig11", cfg, None).unwrap();
        let time = out.trace.column("time").unwrap();
        let speed = out.trace.column("speed_rpm").unwrap();
        let reference = out.trace.column("speed_ref_rpm").unwrap();
        let end = time.last().copied().unwrap();
        let last: Vec<f64> = time
            .iter()
            .zip(speed.iter().zip(&reference))
            .filter(|(t, _)| **t >= end - 0.2)
            .map(|(_, (n, r))| n - r)
            .collect();
        let worst = last.iter().fold(0.0_f64, |m, e| m.max(e.abs()));
        let flags = out.trace.rows.iter().fold(DriveFlags::NONE, |acc, r| {
            acc | DriveFlags::from_bits(r.fault_flags)
        });
        (worst, flags, out.metrics)
    };
    let (worst, flags, m) = run("[controller.lock]\nreaction = \"recover\"\n");
    println!(
        "recover: LOCK_LOST at {:?} s, |n − n*| over the last 0.2 s ≤ {worst:.1} r/min",
        m.lock_lost_time
    );
    assert!(!m.tripped);
    assert!(m.lock_lost_time.is_some());
    assert!(
        flags.contains(DriveFlags::LOCK_LOST | DriveFlags::COASTING),
        "{flags:?}"
    );
    assert!(worst < 5.0, "{worst} r/min off the reference at the end");
    let (worst_fixed, _, _) =
        run("[controller.lock]\nreaction = \"recover\"\nrecovery_rs_adaptation = false\n");
    println!("recover with the fixed R̂s: ≤ {worst_fixed:.1} r/min");
    assert!(worst_fixed > 30.0, "{worst_fixed}");
    // `adapt`: no coasting, the R̂s adaptation switched on at the first verdict.
    let (worst_adapt, flags, m) = run("[controller.lock]\nreaction = \"adapt\"\n");
    println!("adapt: |n − n*| over the last 0.2 s ≤ {worst_adapt:.1} r/min");
    assert!(!m.tripped && m.lock_lost_time.is_some());
    assert!(flags.contains(DriveFlags::LOCK_LOST), "{flags:?}");
    assert!(!flags.contains(DriveFlags::COASTING), "{flags:?}");
    assert!(
        worst_adapt < 5.0,
        "{worst_adapt} r/min off the reference at the end"
    );
}

const IPMSM: &str = include_str!("../../../motors/ipmsm-2k2.toml");

/// The stall is reported as `STALLED`, not as a lost estimate: in `stops` (fig12 on the paper's
/// motor, the same ratings-scaled scenario on the 2.2 kW IPMSM) the 5 Hz speed loop does not
/// hold 4 % of rated speed against the load ramp and the rotor itself slows to a stall with
/// the estimate right (docs/method/lock.md). Before the split
/// the drive raised `LOCK_LOST` at 1.071 s in fig12. Checked: `LOCK_LOST` never up, `STALLED`
/// up, and when it rises the true speed is below half the reference and |θ − θ̂| < 0.25 rad.
#[test]
fn a_real_stall_is_reported_as_stalled_not_as_a_lost_estimate() {
    for (scenario, motor) in [("fig12", None), ("stops", Some(IPMSM))] {
        let cfg = scenario_config(scenario, motor, false).unwrap();
        let out = run_config(scenario, cfg, None).unwrap();
        assert!(out.passed, "{scenario}");
        let rows = &out.trace.rows;
        let flags = |r: &fado_sim::sim::TraceRow| DriveFlags::from_bits(r.fault_flags);
        assert!(
            rows.iter()
                .all(|r| !flags(r).contains(DriveFlags::LOCK_LOST)),
            "{scenario}: LOCK_LOST raised"
        );
        let rise = rows
            .iter()
            .find(|r| flags(r).contains(DriveFlags::STALLED))
            .unwrap_or_else(|| panic!("{scenario}: no STALLED"));
        println!(
            "{scenario}: STALLED at {:.4} s, n {:.1} of n* {:.1} r/min, |θ − θ̂| {:.3} rad",
            rise.time, rise.speed_rpm, rise.speed_ref_rpm, rise.angle_error
        );
        assert!(
            rise.speed_rpm.abs() < 0.5 * rise.speed_ref_rpm.abs(),
            "{scenario}"
        );
        assert!(rise.angle_error.abs() < 0.25, "{scenario}");
        assert_eq!(out.metrics.lock_lost_time, None, "{scenario}");
        assert!(out.metrics.stall_time.is_some(), "{scenario}");
    }
}

const OUTRUNNER: &str = include_str!("../../../motors/outrunner-cheetah-24v.toml");

/// One point of a preset's reversal envelope (`scripts/lock-sweeps-preset.sh`): the preset's
/// TOML, `extra` TOML after it, the model's relative errors of R̂s, λ̂f and L̂q, and the load
/// ramped from 0 at 1.2 s to `load` N·m at 1.7 s.
fn reversal_point(
    preset: &str,
    extra: &str,
    rs: f64,
    flux: f64,
    lq: f64,
    load: f64,
) -> fado_sim::Outcome {
    let toml = format!(
        "{preset}\n{extra}\n[mismatch]\nrs_ratio = {}\nflux_linkage_ratio = {}\nlq_ratio = {}\n\
         [load.torque]\npoints = [[1.2, 0.0], [1.7, {load}]]\n",
        1.0 + rs,
        1.0 + flux,
        1.0 + lq
    );
    let cfg = scenario_config("reversal", Some(&toml), false).unwrap();
    run_config("reversal", cfg, None).unwrap()
}

/// The stall band tolerates the lag of a rotor whose estimate is off by less than the paper's
/// clean threshold (`stall.torque_band_ratio` = 1 − cos 0.25 rad, docs/method/lock.md), and still sees a rotor that stalls. Two points of the
/// outrunner's reversal envelope (seed 7, R̂s adaptation, `scripts/lock-sweeps-preset.sh`),
/// a 21-pole-pair motor whose inertia is small for its torque:
/// * #130 (L̂q −14 %, 0.56 N·m): the rotor and the estimate lag the ramp out of zero speed by
///   up to 0.004 of rated speed with the estimate 0.21 rad off, and catch up. It passes, stays
///   below 0.25 rad and raises neither flag (with a ratio of 0.015 it raises
///   `STALLED` at 3.593 s);
/// * #218 (R̂s +4 %, L̂q +9 %, 0.44 N·m): the rotor stalls at the same passage and the angle
///   is lost 124 ms later. A flag is up 20 ms after |θ − θ̂| first exceeds 0.5 rad (and rose
///   less than 1 s before: docs/method/lock.md's detection).
#[test]
fn the_outrunner_lagging_under_a_clean_estimate_is_not_flagged_and_a_stall_is() {
    let run = |rs, flux, lq, load| reversal_point(OUTRUNNER, "", rs, flux, lq, load);
    let clean = run(-0.000_94, -0.009_12, -0.143_06, 0.558_86);
    let m = &clean.metrics;
    println!(
        "#130: max |θ − θ̂| {:.3} rad, STALLED {:?}, LOCK_LOST {:?}",
        m.max_angle_error_run, m.stall_time, m.lock_lost_time
    );
    assert!(clean.passed, "{m:?}");
    assert!(m.max_angle_error_run < 0.25, "{m:?}");
    assert_eq!((m.stall_time, m.lock_lost_time), (None, None), "{m:?}");
    let lost = run(0.040_45, 0.019_55, 0.086_33, 0.436_14);
    let m = &lost.metrics;
    // docs/method/lock.md's detection: a flag up 20 ms after the onset that rose less than 1 s
    // before it.
    let delay = m
        .lock_detection_delay
        .expect("no flag up 20 ms after the onset");
    println!(
        "#218: onset {:?} s, the flag rose {delay:+.3} s from it",
        m.loss_onset_time
    );
    assert!(m.max_angle_error_run > 1.0, "{m:?}");
    assert!(delay > -1.0, "{m:?}");
}

const GEM: &str = include_str!("../../../motors/ipmsm-gem-50k.toml");

/// The mode hand-over chatter (`lock` symptom 3, docs/method/lock.md) on
/// ipmsm-gem-50k's reversal envelope with the paper's fixed R̂s, seed 7:
/// * #125 (L̂q +25 %): the start-up ends in a limit cycle — ω̂ swinging across the mode
///   hand-over band tens of times a second, |θ − θ̂| ±0.5 rad — and the rotor is lost at
///   0.40 s. The chatter raises `LOCK_LOST` in it, before the loss; without the symptom
///   (`lock_handover_count = 0`) the flag comes late (not up 20 ms after the onset).
/// * #257 (L̂q +11 %): a start-up that hands over several times and keeps the rotor within
///   0.25 rad is not flagged.
#[test]
#[ignore = "open: with the phase band (control::phase_band, active on this rotor) #125's start-up \
            limit cycle raises LOCK_LOST at 0.29-0.42 s and again from 0.55 s, but the flag is down \
            20 ms after the onset at 0.446 s"]
fn a_start_up_limit_cycle_on_a_salient_rotor_is_flagged_by_its_mode_chatter() {
    // The eq. (23) injection at its full level (no bound on the active flux it takes,
    // `[controller.injection] max_active_flux_share`): the envelope's losses this test reads.
    let run = |rs, flux, lq, load, extra: &str| {
        let estimator = format!(
            "[controller.injection]\nmax_active_flux_share = 1e9\n\
             [estimator.rs_adaptation]\nenabled = false\n{extra}\n"
        );
        reversal_point(GEM, &estimator, rs, flux, lq, load).metrics
    };
    let lost = |extra| run(0.005_789, 0.018_911, 0.251_589, 19.965, extra);
    let m = lost("");
    println!(
        "#125: onset {:?} s, LOCK_LOST first {:?} s, detection {:?} s",
        m.loss_onset_time, m.lock_lost_time, m.lock_detection_delay
    );
    assert!(m.max_angle_error_run > 1.0, "{m:?}");
    let delay = m
        .lock_detection_delay
        .expect("no flag up 20 ms after the onset");
    assert!(delay > -1.0, "{m:?}");
    let m = lost("[estimator.lock]\nhandover_count = 0.0");
    println!(
        "#125 without the symptom: LOCK_LOST first {:?} s, detection {:?}",
        m.lock_lost_time, m.lock_detection_delay
    );
    assert_eq!(m.lock_detection_delay, None, "{m:?}");
    let m = run(0.022_722, -0.081_766, 0.105_866, 5.4847, "");
    println!(
        "#257: max |θ − θ̂| {:.3} rad, LOCK_LOST {:?}, STALLED {:?}",
        m.max_angle_error_run, m.lock_lost_time, m.stall_time
    );
    assert!(m.max_angle_error_run < 0.25, "{m:?}");
    assert_eq!((m.lock_lost_time, m.stall_time), (None, None), "{m:?}");
}
