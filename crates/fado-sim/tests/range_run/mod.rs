//! Helpers of the range-scenario tests on made-up and datasheet machines (`locked_speed.rs`,
//! `limited_voltage.rs`).

use fado_sim::scenario::{Outcome, simulate};

/// `scenario` on the motor file `motor` with current-sensor `seed` and the TOML `extra`.
pub fn run(scenario: &str, motor: &str, seed: u64, extra: &str) -> Outcome {
    let text = format!("{motor}\n[current_sensor]\nseed = {seed}\n{extra}");
    simulate(scenario, Some(&text), false, None).unwrap()
}

/// The run's max |θ − θ̂| check (rad).
pub fn angle_error(out: &Outcome) -> f64 {
    out.checks
        .iter()
        .find(|c| c.name.starts_with("max |θ − θ̂|"))
        .unwrap_or_else(|| panic!("no angle check: {:?}", out.checks))
        .value
}

/// The mean R̂s over the trace's rows in [t0, t1), divided by `r0`.
pub fn rs_ratio(out: &Outcome, r0: f64, t0: f64, t1: f64) -> f64 {
    let rows: Vec<f64> = out
        .trace
        .rows
        .iter()
        .filter(|r| r.time >= t0 && r.time < t1)
        .map(|r| r.rs_hat)
        .collect();
    rows.iter().sum::<f64>() / rows.len() as f64 / r0
}
