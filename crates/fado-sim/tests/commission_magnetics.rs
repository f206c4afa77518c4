//! The commissioning's magnetic identification (`fado_core::commissioning`, step 5) on the
//! simulated plant: the algebraic model of saturated machines recovered within stated
//! bounds over the rated current range, the rotor left nearly where it was, and
//! magnetically linear machines reported as such.

use fado_core::MachineModel;
use fado_core::commissioning::Status;
use fado_sim::commission::{CommissionOptions, CommissionOutcome, commission, identified_toml};
use fado_sim::magnetic_accuracy::MagneticAccuracy;

/// Largest rotor motion during the flux-linkage pulses, rad (electrical): measured 0.012 to
/// 0.10 rad on the presets (the 24 V outrunner, the lowest inertia per torque, the most).
const MAX_MOTION: f64 = 0.15;

fn run(text: &str) -> CommissionOutcome {
    let cfg = fado_sim::SimConfig::from_toml(text).unwrap();
    let plant = cfg.plant();
    let nameplate = MachineModel {
        dc_voltage: plant.inverter.dc_voltage,
        ..plant.motor
    };
    let o = commission(
        &plant,
        nameplate,
        CommissionOptions::default(),
        |_| {},
        None,
    )
    .unwrap();
    assert_eq!(o.status, Status::Done);
    assert!(
        o.rotor_motion_magnetics < MAX_MOTION,
        "rotor turned {} rad",
        o.rotor_motion_magnetics
    );
    o
}

fn file(path: &str) -> String {
    std::fs::read_to_string(format!("{}/{path}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// Every inductance within `bound` (relative) over the rated current range.
fn assert_within(a: &MagneticAccuracy, bound: f64) {
    for (name, s) in [
        ("incremental Ld", a.incremental_ld),
        ("incremental Lq", a.incremental_lq),
        ("secant Ld", a.secant_ld),
        ("secant Lq", a.secant_lq),
    ] {
        assert!(s.max < bound, "{name}: {:?}", s);
    }
}

/// The 2.2 kW IPMSM with q self-saturation (Lq 51 → 36 mH) and cross-saturation: the fitted
/// model within 2 % of the plant's (measured: 0.7 % at most).
#[test]
fn the_saturated_ipmsm_preset_is_identified_within_two_percent() {
    let o = run(&file("../../motors/saturated/ipmsm-2k2-qsat.toml"));
    let id = o.identification.unwrap();
    assert!(id.saturation.is_some(), "{}", id.saturation_change);
    assert_within(&o.magnetics.unwrap().accuracy, 0.02);
}

/// A made-up IPMSM with other exponents (d and q saturation of exponent 2, a cross term of
/// exponents 1, 1; Ld 5 → 2 mH, Lq 30 mH falling by half at rated current): within 2 %
/// (measured: 0.5 % at most), and its identified.toml carries the model.
#[test]
fn a_made_up_saturated_ipmsm_is_identified_within_two_percent() {
    let text = file("tests/data/ipmsm-test-saturated.toml");
    let o = run(&text);
    let id = o.identification.unwrap();
    assert!(id.saturation.is_some(), "{}", id.saturation_change);
    assert_within(&o.magnetics.unwrap().accuracy, 0.02);
    let doc = identified_toml(&text, &id).unwrap();
    let table: toml::Table = doc.parse().unwrap();
    assert!(table["model"].get("saturation").is_some());
    assert!(doc.contains("# Magnetic saturation detected"));
    // It runs as it is: the drive takes the identified model.
    let cfg = fado_sim::SimConfig::from_toml(&doc).unwrap();
    assert!(
        !fado_sim::model_magnetics::split(&cfg)
            .unwrap()
            .0
            .magnetics
            .is_linear()
    );
}

/// Magnetically linear machines, the strongly salient low-inductance PM-SyRM among them (the
/// least accurate integration: its constant-inductance residual is 1.6 % of the rated
/// current), are reported unsaturated and keep constant inductances.
#[test]
fn linear_machines_are_reported_unsaturated() {
    for name in ["paper", "pmsyrm-5k", "outrunner-cheetah-24v"] {
        let text = fado_sim::presets::find(name).unwrap().toml;
        let o = run(text);
        let id = o.identification.unwrap();
        assert!(
            id.saturation.is_none(),
            "{name}: change {}, residual {} against {}",
            id.saturation_change,
            id.saturation_residual,
            id.linear_residual
        );
        let doc = identified_toml(text, &id).unwrap();
        let table: toml::Table = doc.parse().unwrap();
        assert!(table["model"].get("saturation").is_none());
        assert!(doc.contains("# No magnetic saturation detected"), "{name}");
    }
}

/// The 5.6 kW PM-SyRM (Lq/Ld ≈ 5, λf/(Lq − Ld) ≈ 4 A against a 6.2 A test limit), as its
/// algebraic model with the rib and as its measured flux map, runs the procedure to its end:
/// the inertia test's current step at the I-f level keeps the PLL's active flux above half
/// the magnet's. λ̂f within 10 % of ψd(0, 0) (measured +3.2 % and +8.3 %: the coast's
/// d current reads the saturated active flux through constant L̂d, L̂q).
#[test]
fn the_pm_syrm_presets_are_commissioned_to_the_end() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/saturated");
    fado_sim::magnetics_file::set_config_dir(Some(std::path::Path::new(dir)));
    for name in ["pmsyrm-baldor-5k6", "pmsyrm-baldor-5k6-measured"] {
        let o = run(&file(&format!("../../motors/saturated/{name}.toml")));
        let id = o.identification.unwrap();
        let truth = o.truth.flux_linkage;
        let e = id.model.flux_linkage / truth - 1.0;
        assert!(e.abs() < 0.10, "{name}: flux linkage {e:+.3}");
    }
}

/// The measured 1.1 kW PMSM map (gym-electric-motor's, its saliency 1.2): the best fits with
/// the rib fold back on some seeds (a second flux for some currents inside the rated range,
/// the incremental inductance about zero there) and are refused for constant inductances;
/// the commissioned flux stays within 25 % of the magnet's over the rated current range
/// (measured: 14 % with constant inductances, 3 % with a fitted model that stays
/// invertible; a folding fit reaches 4–50 times the magnet's flux).
#[test]
fn the_measured_pmsm_map_is_never_given_a_folding_model() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/saturated");
    fado_sim::magnetics_file::set_config_dir(Some(std::path::Path::new(dir)));
    let o = run(&file("../../motors/saturated/pmsm-gem-1k1-measured.toml"));
    let a = o.magnetics.unwrap().accuracy;
    assert!(a.flux.max < 0.25, "flux: {:?}", a.flux);
}
