//! A made-up fast multirotor motor (tests/data/made-up-multirotor-14s-80kv.toml: 28 poles,
//! 80 KV on 14S, 110 µH, R·I_rated/λf = 1070 rad/s), entered with only the required keys and
//! its PWM frequency, closed loop at every sensor seed: `reversal`, `stops` and `loaded-start`
//! pass by their own criteria.

use fado_sim::scenario::simulate;

const MOTOR: &str = include_str!("data/made-up-multirotor-14s-80kv.toml");

#[test]
fn a_made_up_14s_80kv_multirotor_passes_the_reversal_the_stops_and_a_loaded_start() {
    // Measured (seeds 1–4, largest |θ − θ̂| of each run): reversal 0.020–0.024 rad, stops
    // 0.134–0.150 rad, loaded-start 0.143–0.172 rad.
    for scenario in ["reversal", "stops", "loaded-start"] {
        for seed in 1..=4 {
            let text = format!("{MOTOR}\n[current_sensor]\nseed = {seed}\n");
            let out = simulate(scenario, Some(&text), false, None).unwrap();
            println!(
                "{scenario} seed {seed}: {} (max |θ − θ̂| {:.3} rad)",
                if out.passed { "pass" } else { "FAIL" },
                out.metrics.max_angle_error
            );
            assert!(out.passed, "{scenario} seed {seed}: {:?}", out.checks);
        }
    }
}
