//! Commissioning the machines of motulator's algebraic models (`tests/data/motulator/`,
//! `scripts/motulator-machines.py`) from their datasheet values: the plant's `[motor]` (its
//! unsaturated constants and ratings) is what the procedure is told, its `[motor.saturation]`
//! the truth it identifies, and the identified model (`identified_toml`, the fitted algebraic
//! model) drives `reversal`, `stops` and `rated-reversal` on the sensor seeds 1–4.
//! `bash scripts/motulator-closed-loop.sh` prints the same runs with the CLI's identified map.

use fado_core::commissioning::Status;
use fado_sim::commission::{CommissionOutcome, commission_on_own_nameplate, identified_toml};
use fado_sim::scenario::{run_config, scenario_config};

/// The machine's plant on sensor seed `seed`: its file without the drive's `[model]` (the
/// true map), as `scripts/motulator-closed-loop.sh` gives it to `fado-sim commission`.
fn plant(name: &str, seed: u32) -> String {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/motulator");
    let text = std::fs::read_to_string(format!("{dir}/{name}.toml")).unwrap();
    let plant: String = text
        .lines()
        .filter(|l| *l != "[model]" && !l.starts_with("flux_map = "))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_ne!(plant, text, "{name}: the drive's [model] removed");
    format!("{plant}\n[current_sensor]\nseed = {seed}\n")
}

fn commissioned(text: &str) -> CommissionOutcome {
    let cfg = fado_sim::SimConfig::from_toml(text).unwrap();
    commission_on_own_nameplate(&cfg.plant()).unwrap()
}

/// Commissions the machine on each seed and runs the scenarios on the identified model;
/// asserts that every run passes.
fn commissioned_passes(name: &str, scenarios: &[&str]) {
    for seed in 1..=4 {
        let text = plant(name, seed);
        let o = commissioned(&text);
        assert_eq!(o.status, Status::Done, "{name} seed {seed}");
        let doc = identified_toml(&text, &o.identification.unwrap()).unwrap();
        for &scenario in scenarios {
            let cfg = scenario_config(scenario, Some(&doc), false).unwrap();
            let out = run_config(scenario, cfg, None).unwrap();
            let m = &out.metrics;
            let angle = if scenario == "stops" {
                m.max_angle_error
            } else {
                m.max_angle_error_zero_speed
            };
            println!(
                "{name} seed {seed} {scenario}: {angle:.3} rad, {:.1} r/min",
                m.max_speed_error_rpm
            );
            assert!(
                out.passed,
                "{name} seed {seed} {scenario}: {angle} rad, {} r/min",
                m.max_speed_error_rpm
            );
        }
    }
}

/// The 60 kW IPMSM (0.01 Ω, 400 A): its identified map's flux error under load (up to
/// 1.45 % over the rated current, `fado-sim commission`) reads as a resistance error to the
/// online R̂s law, which the model's flux uncertainty under load
/// (`model_flux_uncertainty_rated`, written by commissioning from the fit's residuals)
/// holds: without it (the key set to 0) `stops` loses its margin on seeds 1–3 (0.254 /
/// 0.297 / 0.290 rad, R̂s +0.5 %), with the law off it passes (0.150 / 0.158 / 0.156 rad).
#[test]
fn the_commissioned_60_kw_ipmsm_passes_every_seed() {
    commissioned_passes("mot-ipm-60k", &["reversal", "stops", "rated-reversal"]);
}

/// The ferrite PM-SyRM (λf 0.2 Vs against L_d·I = 0.64 Vs): the reluctance rotor's cap on
/// the DC test's current (½·λf/(L_q − L_d) = 0.6 A of its 5 A limit) leaves phases b and c
/// at 0.15 A and 0.3 A, inside the inverter's current band, where the two levels'
/// inverter errors differ: measured from them, R̂s came out +50 % (1.35 Ω), the inverter
/// voltage −0.21 V. The procedure keeps the nameplate's Rs (1-σ ∞) and takes the inverter
/// voltage at the upper level; its heavy rotor's I-f ramp (10.5 s) is added to the spin's
/// phase limit, so the procedure runs to the end.
#[test]
fn the_weak_magnet_pm_syrm_is_commissioned_with_its_nameplate_resistance() {
    let o = commissioned(&plant("mot-pmsyrm-4k", 1));
    assert_eq!(o.status, Status::Done);
    let id = o.identification.unwrap();
    assert_eq!(id.model.rs, 0.9);
    assert!(id.confidence.rs.is_infinite(), "{:?}", id.confidence);
    assert!(id.confidence.current_gain_ratio.is_infinite());
    let dv = id.inverter_voltage - o.truth.inverter_voltage;
    // Measured −0.002 V.
    assert!(dv.abs() < 0.02, "inverter voltage {dv:+} V off");
}

/// The same machine's identified model (the fitted algebraic model) in `reversal` and
/// `stops`, although its λ̂f is +17.5 % (0.235 Vs, from the spin's back-EMF at the coast's
/// 2.5 A of d current) and its flux error reaches 23 % over the rated current. Measured on
/// seeds 1–4: `reversal` 0.170 / 0.121 / 0.121 / 0.034 rad, `stops` 0.061 / 0.061 / 0.037 /
/// 0.074 rad. The CLI's identified map of the same fit (`scripts/motulator-closed-loop.sh`)
/// loses `reversal` on seeds 1 and 3 (1.99, 3.14 rad) and holds `stops` (0.04–0.24 rad).
#[test]
fn the_commissioned_weak_magnet_pm_syrm_holds_reversal_and_stops() {
    commissioned_passes("mot-pmsyrm-4k", &["reversal", "stops"]);
}

/// The same machine's identified model under its rated torque near zero speed.
#[test]
#[ignore = "rated-reversal loses the angle (seed 1: 1515 r/min of speed error, the \
            angle near zero speed never reached), as with the true map \
            (saturated_drive motulator_ferrite_pm_syrm_passes_every_seed: frame coupling \
            1.23-1.33, psi_d < 0 on the MTPA curve)"]
fn the_commissioned_weak_magnet_pm_syrm_passes_rated_reversal() {
    commissioned_passes("mot-pmsyrm-4k", &["rated-reversal"]);
}
