//! `fullrange` where the top speed is locked to the sampling: a whole number of samples per
//! electrical revolution, where the inverter's error pattern aliases onto a DC integrand
//! error of that speed alone (`fado_core::integrand_offset`, "Only where an electrical
//! revolution spans many samples"). The 750 W 10-pole servo of the start-up tests
//! (`tests/data/startup-spm-750w.toml`) holds 6,000 r/min, 500 Hz against 20 kHz sampling:
//! 40 samples per revolution. The spindle's (25 per two revolutions) is `tests/spindle.rs`.

use fado_sim::scenario::{Outcome, simulate};

const SERVO: &str = include_str!("data/startup-spm-750w.toml");

fn run(seed: u64, extra: &str) -> Outcome {
    let text = format!("{SERVO}\n[current_sensor]\nseed = {seed}\n{extra}");
    simulate("fullrange", Some(&text), false, None).unwrap()
}

fn angle_error(out: &Outcome) -> f64 {
    out.checks
        .iter()
        .find(|c| c.name.starts_with("max |θ − θ̂|"))
        .unwrap_or_else(|| panic!("no angle check: {:?}", out.checks))
        .value
}

/// R̂s over the rows in [t0, t1) as the fraction of the configured 0.9 Ω (mean).
fn rs_ratio(out: &Outcome, t0: f64, t1: f64) -> f64 {
    let rows: Vec<f64> = out
        .trace
        .rows
        .iter()
        .filter(|r| r.time >= t0 && r.time < t1)
        .map(|r| r.rs_hat)
        .collect();
    rows.iter().sum::<f64>() / rows.len() as f64 / 0.9
}

#[test]
fn a_servo_held_at_a_speed_locked_to_the_sampling_keeps_its_resistance_and_its_angle() {
    // Measured: 0.106 rad on seeds 1–4, R̂s within 0.7 % at the top; with the law learning at
    // every speed R̂s falls over the 2.5 s at the top (0.86·R0 on average over 7.5–8 s, 0.77 Ω
    // at its end) and the loaded standstill after the stop loses the angle (0.70 / 0.69 rad on
    // seeds 1 / 2, 221 r/min off the zero target).
    for seed in 1..=2 {
        let out = run(seed, "");
        let rs = rs_ratio(&out, 7.5, 8.0);
        println!(
            "seed {seed}: {:.3} rad, R̂s/R0 at the top {rs:.4}",
            angle_error(&out)
        );
        assert!(out.passed, "seed {seed}: {:?}", out.checks);
        assert!((rs - 1.0).abs() < 0.02, "seed {seed}: R̂s/R0 {rs}");
    }
    let unguarded = run(
        1,
        "[estimator.offset_adaptation]\nmin_revolution_samples = 0.0\n",
    );
    let rs = rs_ratio(&unguarded, 7.5, 8.0);
    println!(
        "unguarded: {:.3} rad, R̂s/R0 {rs:.4}",
        angle_error(&unguarded)
    );
    assert!(rs < 0.95, "{rs}");
    assert!(!unguarded.passed, "{:?}", unguarded.checks);
}
