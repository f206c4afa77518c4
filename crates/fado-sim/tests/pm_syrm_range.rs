//! `fullrange` on the PM-assisted synchronous-reluctance rotor (docs/range.md): the loaded
//! standstill probe's period from the speed estimate's answer to its d step
//! (`fado_core::control::probe_period`) and the current loop's decoupling from the saturating
//! model's flux (`CurrentController::step_with_flux`), on the Baldor's algebraic model, its
//! measured flux map, its constant-inductance twin, and an IPMSM whose probe period stays the
//! default.

use fado_sim::scenario::{run_config, scenario_config};

fn file(path: &std::path::Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    // A flux map's relative path, made absolute for the in-memory configuration.
    let dir = path.parent().unwrap().display().to_string();
    text.replace("flux_map = \"", &format!("flux_map = \"{dir}/"))
}

fn preset(name: &str) -> String {
    file(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../motors")
            .join(name),
    )
}

fn test_machine(name: &str) -> String {
    file(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
}

/// Every criterion of `fullrange` (|θ − θ̂| < 0.25 rad from 0.7 s on, every speed target, the
/// top speed and power, no trip), and the largest angle error of the hold at zero speed
/// under 65 % of the rated torque and of its departure (8.8–10.3 s).
fn fullrange(text: &str) -> f64 {
    let cfg = scenario_config("fullrange", Some(text), false).unwrap();
    let out = run_config("fullrange", cfg, None).unwrap();
    for c in &out.checks {
        assert!(c.passed, "{c:?}");
    }
    out.trace
        .rows
        .iter()
        .filter(|r| (8.8..10.3).contains(&r.time))
        .map(|r| r.angle_error.abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_pm_syrm_keeps_its_angle_through_the_whole_range() {
    for (name, text) in [
        (
            "pmsyrm-baldor-5k6",
            preset("saturated/pmsyrm-baldor-5k6.toml"),
        ),
        (
            "pmsyrm-baldor-5k6-measured",
            preset("saturated/pmsyrm-baldor-5k6-measured.toml"),
        ),
        (
            "pmsyrm-baldor-linear",
            test_machine("pmsyrm-baldor-linear.toml"),
        ),
        ("ipmsm-2k2-qsat", preset("saturated/ipmsm-2k2-qsat.toml")),
    ] {
        let hold = fullrange(&text);
        assert!(hold < 0.2, "{name}: {hold} rad at the loaded standstill");
    }
}
