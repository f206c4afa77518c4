//! The online R̂s law on saturated machines, closed loop, switching-resolved with the default
//! non-idealities: started from a resistance 0.7× and 1.4× the plant's (`[mismatch] rs_ratio`,
//! the start-up gain calibration off so that the law alone has to find it), R̂s ends within 2 %
//! of the plant's through `rated-reversal` (rated load at the reversal, sensor seed 1) on the
//! saturated IPMSM preset (its algebraic model, `ipmsm-2k2-qsat`) and on the measured 1.1 kW
//! PMSM flux map (`pmsm-gem-1k1-measured`), with the plant's own magnetic model as the
//! drive's. Measured (`cargo test --release -p fado-sim --test saturated_rs_convergence --
//! --nocapture` prints them): 0.35 % at most on both machines, R̂s within 3 % of the plant's
//! a quarter of the way through the run.
//!
//! The d-saturated SPM test machine (`tests/data/spm-dq-sat-saturated.toml`, the magnet as a
//! d-axis MMF) passes its zero-speed passage under rated load only with R̂s within about
//! 0.5 % (its rated R·I/λf is 94 rad/s: 1 % of R̂s error turns θ̂ at ≈ 0.9 rad/s there); its
//! standstill test at start-up leaves R̂s 3.5–7.8 % off, and the turning law at γ keeps
//! 1.5–1.7 % at the passage and loses the rotor (0.36–0.92 rad); at three times γ it is within
//! 0.4 % and passes, but that rate loses a five-times cross-saturated IPMSM's `rated-reversal`
//! from the correct start (saturated_drive.rs), so the law keeps γ and the test is ignored.
//!
//! The PM-SyRM's measured map (`pmsyrm-baldor-5k6-measured`) does not converge, and its test
//! is ignored: at no load a resistance error moves |λ̂r| by < 0.2 % of the active flux per 1 %
//! of R (χ < χ0, frozen), its standstill test never reaches its charge (R0/λ̂f is 1.0 there,
//! so the test needs ∫i_d ≥ 0.2 A·s, and the start-up's 0.12 s at the 0.9 A injection gives
//! 0.09), and under load the frame coupling σ/κ is 0.96–0.99, where the turning law freezes
//! (docs/method/saturation.md, "The offset law's gate"): with the machine's own map it would
//! learn R̂s there (0.7 / 1.4 × → 0.994 / 0.993, seeds 1–4 passing, with that freeze lifted),
//! but with its commissioned model it then reads the model's flux error as resistance (R̂s
//! 0.87–0.95 × the truth, `stops` lost on seeds 1 and 2). Started 0.7 or 1.4 times off, the
//! drive loses the rotor at the loaded zero-speed passage (0.88–3.14 rad).

use fado_sim::scenario::{run_config, scenario_config};

fn preset(path: &str) -> String {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/");
    std::fs::read_to_string(format!("{root}{path}")).unwrap()
}

/// R̂s/Rs at the end of `rated-reversal` started from `ratio` × the plant's Rs (current-sensor
/// seed `seed`), and whether the scenario passed.
fn final_ratio(base: &str, ratio: f64, seed: u64) -> (f64, bool) {
    let text = format!(
        "{base}\n[mismatch]\nrs_ratio = {ratio}\n[controller.gain_calibration]\ntime = 0.0\n\
         [current_sensor]\nseed = {seed}\n"
    );
    let cfg = scenario_config("rated-reversal", Some(&text), false).unwrap();
    let rs = cfg.motor.rs + cfg.inverter.on_resistance;
    let out = run_config("rated-reversal", cfg, None).unwrap();
    let rows = &out.trace.rows;
    // The estimator's first R̂s is the configured one: the law starts from the wrong value.
    let first = rows.iter().find(|r| r.rs_hat > 0.0).unwrap().rs_hat;
    assert!(
        (first / rs - ratio).abs() < 0.01 * ratio,
        "started from {}",
        first / rs
    );
    (rows.last().unwrap().rs_hat / rs, out.passed)
}

fn converges(base: &str, name: &str, seeds: &[u64]) {
    for &seed in seeds {
        for ratio in [0.7, 1.4] {
            let (end, passed) = final_ratio(base, ratio, seed);
            println!(
                "{name}, seed {seed}: R̂s from {ratio} × Rs ends at {end:.4} × Rs, passed {passed}"
            );
            assert!(
                (end - 1.0).abs() < 0.02,
                "{name}, seed {seed}, from {ratio}: {end}"
            );
            assert!(passed, "{name}, seed {seed}, from {ratio}");
        }
    }
}

/// Flux maps named relative to the presets' directory.
fn in_saturated_presets() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/saturated");
    fado_sim::magnetics_file::set_config_dir(Some(std::path::Path::new(dir)));
}

#[test]
fn rs_converges_on_the_saturated_ipmsm_algebraic_model() {
    converges(
        &preset("saturated/ipmsm-2k2-qsat.toml"),
        "ipmsm-2k2-qsat",
        &[1],
    );
}

#[test]
fn rs_converges_on_the_measured_pmsm_flux_map() {
    in_saturated_presets();
    converges(
        &preset("saturated/pmsm-gem-1k1-measured.toml"),
        "pmsm-gem-1k1-measured",
        &[1],
    );
}

#[test]
#[ignore = "at γ R̂s keeps 1.5–1.7 % at the loaded passage and the rotor is lost (module docs)"]
fn rs_converges_on_the_d_saturated_spm() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/spm-dq-sat-saturated.toml"
    );
    converges(
        &std::fs::read_to_string(file).unwrap(),
        "spm-dq-sat-saturated",
        &[1, 2],
    );
}

#[test]
#[ignore = "the turning law is frozen under load by the frame coupling (module docs)"]
fn rs_converges_on_the_measured_pm_syrm_flux_map() {
    in_saturated_presets();
    converges(
        &preset("saturated/pmsyrm-baldor-5k6-measured.toml"),
        "pmsyrm-baldor-5k6-measured",
        &[1, 2],
    );
}
