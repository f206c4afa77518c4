//! Closed loop on the machines of motulator's algebraic models that
//! `scripts/motulator-machines.py` writes (`tests/data/motulator/*.toml`: the plant motulator
//! 0.18's `SaturationModelPMSyRM` under `[motor.saturation]`, the drive's model the exact
//! inverse of motulator's i(ψ) as a 13 × 17 flux map), switching-resolved with the default
//! non-idealities: `reversal`, `stops` and `rated-reversal` for the current-sensor seeds 1–4
//! on a 1.1 kW IPMSM of saliency 3.2, a 4 kW ferrite PM-SyRM whose secant L_q falls 57 % at
//! rated i_q, an SPMSM whose d axis alone saturates and a 60 kW IPMSM. The SyRM without a
//! magnet is refused, with its λf = 0 and with a λf > 0 that its map contradicts.
//! `bash scripts/motulator-closed-loop.sh` prints the same runs and the commissioned model's as
//! a table.

use fado_sim::scenario::{run_config, scenario_config};

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/motulator");

fn machine(name: &str) -> String {
    fado_sim::magnetics_file::set_config_dir(Some(std::path::Path::new(DIR)));
    std::fs::read_to_string(format!("{DIR}/{name}.toml")).unwrap()
}

/// `reversal`, `stops` and `rated-reversal` pass for the sensor seeds 1–4 on the machine.
fn passes_every_seed(name: &str) {
    let base = machine(name);
    for seed in 1..=4 {
        let text = format!("{base}\n[current_sensor]\nseed = {seed}\n");
        for scenario in ["reversal", "stops", "rated-reversal"] {
            let cfg = scenario_config(scenario, Some(&text), false).unwrap();
            assert!(
                !cfg.machine_model().magnetics.is_linear(),
                "{name}: the drive's model is the map"
            );
            let out = run_config(scenario, cfg, None).unwrap();
            let m = &out.metrics;
            let angle = if scenario == "stops" {
                m.max_angle_error
            } else {
                m.max_angle_error_zero_speed
            };
            let speed = m.max_speed_error_rpm;
            println!("{name} seed {seed} {scenario}: {angle:.4} rad, {speed:.2} r/min");
            assert!(
                out.passed,
                "{name} seed {seed} {scenario}: {angle} rad, {speed} r/min"
            );
        }
    }
}

#[test]
fn the_small_high_saliency_ipmsm_passes_every_seed() {
    passes_every_seed("mot-ipm-1k1");
}

/// Open loop, the same machine's exact signals hold the angle within 0.18 rad at every load
/// (`saturated_replay motulator`) and motulator's own plant's within 0.024 rad
/// (scripts/motulator-machines.py replay); closed loop the drive loses it while the machine
/// generates near zero speed. Its magnet is weak (λf 0.2 Vs against L_d·I = 0.64 Vs): ψd
/// crosses zero on the MTPA curve near 4 A of i_d (ψd = −0.14 Vs at rated torque) and the
/// secant L_q falls 57 % at rated i_q.
#[test]
#[ignore = "reversal fails on seeds 2 and 3 (max |θ − θ̂| near zero speed 3.05 and 1.77 rad; \
            seeds 1 and 4 0.086 and 0.124 rad): at 65 % load, generating at −4 % of rated \
            speed, the angle and speed errors oscillate at about 6 Hz and grow (±0.2 rad at \
            2.7 s, lost at 3.08 s); rated-reversal trips on all four seeds (lost at 1.9 s at \
            −6 % under the rated load, generating); stops passes (0.041 rad)"]
fn the_ferrite_pm_syrm_passes_every_seed() {
    passes_every_seed("mot-pmsyrm-4k");
}

#[test]
fn the_spmsm_saturated_on_d_passes_every_seed() {
    passes_every_seed("mot-spm-dsat");
}

#[test]
fn the_60_kw_ipmsm_passes_every_seed() {
    passes_every_seed("mot-ipm-60k");
}

/// The SyRM without a magnet: its `flux_linkage = 0` is refused naming the method's limit,
/// and a λf > 0 written to get past it is refused naming the map that contradicts it, in
/// `[motor]` (against `[motor.saturation]`) and in `[model]` (against `[model] flux_map`).
#[test]
fn the_syrm_without_a_magnet_is_refused_naming_why() {
    let base = machine("mot-syrm-2k2");
    let e = scenario_config("reversal", Some(&base), false).unwrap_err();
    assert_eq!(e.key, "motor.flux_linkage", "{e}");
    assert!(e.to_string().contains("synchronous reluctance"), "{e}");
    let weak = base.replace("flux_linkage = 0\n", "flux_linkage = 0.02\n");
    assert_ne!(weak, base);
    let e = scenario_config("reversal", Some(&weak), false).unwrap_err();
    assert_eq!(e.key, "motor.saturation", "{e}");
    // The plant a linear machine of λf 0.02 Wb, the drive's model the SyRM's map: the map's
    // ψd(0, 0) = 0 contradicts the model's λf (run as it was, the drive loses the rotor:
    // 8573 r/min of speed error in `reversal`).
    let start = weak.find("[motor.saturation]").unwrap();
    let end = weak.find("\n[model]").unwrap();
    let model_only = format!("{}{}", &weak[..start], &weak[end..]);
    let e = scenario_config("reversal", Some(&model_only), false).unwrap_err();
    assert_eq!(e.key, "model.flux_map", "{e}");
    assert!(e.to_string().contains("ψd = 0.000000 Wb"), "{e}");
}
