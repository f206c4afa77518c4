//! Online R̂s adaptation in closed loop (fado-sim, switching-resolved, default non-idealities):
//! the loaded zero-speed passages of Fig. 11 and Fig. 12 survive a plant resistance from 0.8×
//! to 1.3× the configured value, starting from the configured value; the reversal holds under
//! the rated 11.5 N·m; and switching the adaptation on never makes a passing scenario fail.

use fado::sim::scenario::{Outcome, SCENARIOS, simulate};

fn run(name: &str, config: &str) -> Outcome {
    let out = simulate(name, Some(config), false, None).expect("valid scenario");
    let r = out.report();
    eprintln!(
        "{name} [{}]: max |θ−θ̂| {:.3} rad, near zero {:.3} rad, speed error {:.1} r/min, \
         passed {}",
        config.replace('\n', " "),
        r.max_angle_error,
        r.max_angle_error_zero_speed,
        r.max_speed_error_rpm,
        r.passed
    );
    out
}

/// `[mismatch] rs_ratio` is R̂s/Rs: a plant resistance k × the configured one is 1/k.
///
/// The start-up gain calibration is off here: these runs depend on when the drive starts
/// relative to the profile's ramp at 0.2 s (measured with the calibration off: fig11 / fig12
/// with Rs 1.3× pass for a start at 0 or 0.1 s, 0.128 / 0.166 and 0.106 / 0.119 rad, and lose
/// the rotor for a start at 0.3 or 0.5 s, 1.08 / 3.14 and 0.97 / 3.14 rad); the calibration
/// starts the paper's motor at 0.62 s (README, known limitations).
fn plant_resistance(k: f64, adaptation: bool) -> String {
    format!(
        "[mismatch]\nrs_ratio = {}\n[estimator.rs_adaptation]\nenabled = {adaptation}\n\
         [controller.gain_calibration]\ntime = 0.0\n",
        1.0 / k
    )
}

#[test]
fn reversal_and_stops_survive_plant_resistance_from_0_8_to_1_3_times() {
    for name in ["fig11", "fig12"] {
        for k in [0.8, 1.3] {
            let out = run(name, &plant_resistance(k, true));
            assert!(out.passed, "{name}, Rs = {k}×: {:?}", out.checks);
            // R̂s ends within 5 % of the plant's (it also absorbs the dead-time residual).
            let rs_plant = out.config.motor.rs + out.config.inverter.on_resistance;
            let rs_end = out.trace.rows.last().unwrap().rs_hat;
            assert!(
                (rs_end / rs_plant - 1.0).abs() < 0.05,
                "{name}, Rs = {k}×: R̂s/Rs = {}",
                rs_end / rs_plant
            );
        }
    }
}

#[test]
fn without_adaptation_a_5_percent_resistance_error_loses_the_reversal() {
    // The problem the adaptation solves (and evidence that the test above can fail).
    let out = run("fig11", &plant_resistance(1.05, false));
    assert!(!out.passed);
    assert!(out.metrics.max_angle_error_zero_speed > 0.5);
}

#[test]
fn reversal_holds_under_rated_torque() {
    let rated = "[load.torque]\npoints = [[1.2, 0.0], [1.7, 11.5]]\n";
    let out = run("fig11", rated);
    assert!(out.passed, "{:?}", out.checks);
}

#[test]
fn adaptation_never_makes_a_passing_scenario_fail() {
    // fig10 is decided by the sensor-noise seed around its 0.35 rad threshold (0.12–0.68 rad
    // over seeds, either setting): it is judged over eight seeds below.
    for s in SCENARIOS.iter().filter(|s| s.name != "fig10") {
        let off = run(s.name, "[estimator.rs_adaptation]\nenabled = false\n");
        let on = run(s.name, "[estimator.rs_adaptation]\nenabled = true\n");
        if off.passed {
            assert!(on.passed, "{}: {:?}", s.name, on.checks);
        }
    }
}

#[test]
fn fig10_over_eight_noise_seeds_both_paths_stay_within_0_25_rad() {
    // fig10 < 0.25 rad on sensor seeds 1–8. Measured (observer lag
    // compensation): fixed R̂s 8/8, worst 0.0613 rad; adapted 8/8, worst 0.0619 rad (0.0568 /
    // 0.0570 with the edge-current dead-time compensation). Without
    // the compensation the adapted path is the better one (worst 0.43 against 0.68 rad when
    // the stop transient decides it); with it both sit at the sensor-noise floor, so the adapted
    // path may not be worse than the fixed one by more than that noise (0.01 rad).
    let mut passed = [0, 0];
    let mut worst = [0.0f64, 0.0];
    for seed in 1..=8 {
        for (k, on) in [false, true].into_iter().enumerate() {
            let cfg = format!(
                "[current_sensor]\nseed = {seed}\n[estimator.rs_adaptation]\nenabled = {on}\n"
            );
            let out = run("fig10", &cfg);
            passed[k] += usize::from(out.passed);
            worst[k] = worst[k].max(out.metrics.max_angle_error);
        }
    }
    eprintln!("fig10 over 8 seeds: fixed R̂s {passed:?} passed, worst {worst:?} rad");
    assert_eq!(
        passed,
        [8, 8],
        "worst: fixed {}, adapted {}",
        worst[0],
        worst[1]
    );
    assert!(worst[0] < 0.25 && worst[1] < 0.25, "worst {worst:?}");
    assert!(
        worst[1] <= worst[0] + 0.01,
        "worst: fixed {}, adapted {}",
        worst[0],
        worst[1]
    );
}

#[test]
fn flux_linkage_error_needs_the_flux_linkage_law() {
    // A 10 % λ̂f error biases the turning R̂s law by Δλf·ω/i_q (7 % at −90 r/min, 7.5 N·m),
    // which loses the reversal that a fixed, right R̂s survives; learning λ̂f unloaded
    // (`flux_linkage_adaptation.rate`, on by default) restores it, with λ̂f too low or too
    // high, and together with an R̂s error.
    for case in [
        "flux_linkage_ratio = 0.9",
        "flux_linkage_ratio = 1.1",
        "flux_linkage_ratio = 0.95\nrs_ratio = 1.1",
    ] {
        let mismatch = format!("[mismatch]\n{case}\n");
        let biased = run(
            "fig11",
            &format!("{mismatch}[estimator.flux_linkage_adaptation]\nrate = 0.0\n"),
        );
        let learned = run("fig11", &mismatch);
        assert!(!biased.passed && learned.passed, "{case}");
    }
    let lf = "[mismatch]\nflux_linkage_ratio = 0.9\n";
    let fixed = run(
        "fig11",
        &format!("{lf}[estimator.rs_adaptation]\nenabled = false\n"),
    );
    assert!(fixed.passed);
}
