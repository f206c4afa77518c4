//! The frame coupling's rule of `fado_core::control::speed_bandwidth`: the drive raises T2S-2
//! where its model's frame coupling at the rated torque exceeds
//! `DEFAULT_MAX_FRAME_COUPLING`, and leaves every preset's tuning alone.

use fado_core::control::speed_bandwidth::{DEFAULT_MAX_FRAME_COUPLING, rated_frame_coupling};
use fado_sim::scenario::scenario_config;

fn root() -> &'static str {
    concat!(env!("CARGO_MANIFEST_DIR"), "/../../")
}

/// The model's coupling at the rated torque, T2S-2 before and after the drive's rules, and the
/// configuration's warning on the coupling.
fn coupling_and_tracker(path: &str) -> (Option<f64>, f64, f64, Option<String>) {
    // The map's directory is the process's: one configuration at a time.
    static DIR: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _dir = DIR.lock().unwrap_or_else(|e| e.into_inner());
    let file = format!("{}{path}", root());
    let dir = std::path::Path::new(&file).parent().unwrap().to_path_buf();
    fado_sim::magnetics_file::set_config_dir(Some(&dir));
    let text = std::fs::read_to_string(&file).unwrap();
    let cfg = scenario_config("reversal", Some(&text), false).unwrap();
    let mut drive = cfg.drive_config();
    let mut estimator = cfg.estimator;
    let own = estimator.tracker.t2s2_bandwidth_hz;
    let c = rated_frame_coupling(&drive.machine, &drive.tuning);
    drive.apply_build_rules(&mut estimator);
    let warning = cfg
        .warnings()
        .into_iter()
        .find(|w| w.contains("frame coupling"));
    (c, own, estimator.tracker.t2s2_bandwidth_hz, warning)
}

/// The saturated presets and the motulator machines the drive holds at the paper's ratio
/// (c up to 0.97, the Baldor PM-SyRM) keep their T2S-2; the linear presets have no coupling.
#[test]
fn the_rule_fires_only_beyond_its_coupling() {
    let presets = [
        "motors/saturated/ipmsm-2k2-qsat.toml",
        "motors/saturated/pmsm-gem-1k1-measured.toml",
        "motors/saturated/pmsyrm-baldor-5k6.toml",
        "motors/saturated/pmsyrm-baldor-5k6-measured.toml",
        "crates/fado-sim/tests/data/motulator/mot-ipm-1k1.toml",
        "crates/fado-sim/tests/data/motulator/mot-spm-dsat.toml",
        "crates/fado-sim/tests/data/motulator/mot-ipm-60k.toml",
        "motors/paper.toml",
        "motors/pmsyrm-5k.toml",
    ];
    for path in presets {
        let (c, own, t2s2, warning) = coupling_and_tracker(path);
        assert_eq!(warning, None, "{path}");
        println!("{path}: c = {c:?}, T2S-2 {own} -> {t2s2} Hz");
        assert!(
            c.is_none_or(|c| c <= DEFAULT_MAX_FRAME_COUPLING),
            "{path}: {c:?}"
        );
        // mot-spm-dsat's 35.9 Hz is the light rotor's rule, whose speed loop moves with it.
        let speed_raised = t2s2 > own && c.is_some_and(|c| c < 0.1);
        assert!(t2s2 == own || speed_raised, "{path}: {t2s2}");
    }
}

/// motulator's 4 kW ferrite PM-SyRM (its weak magnet leaves ψd < 0 on the MTPA curve at rated
/// torque): its coupling at the rated torque is 1.23 on the drive's map (1.33 on motulator's
/// own model, `scripts/motulator-machines.py coupling`), and T2S-2 goes to 35 Hz × c = 43 Hz,
/// with which it holds `reversal` on every seed (`saturated_drive`, 0.09–0.15 rad; 3.05 rad
/// at 35 Hz).
#[test]
fn the_ferrite_pm_syrm_gets_a_faster_speed_tracker() {
    let (c, own, t2s2, warning) =
        coupling_and_tracker("crates/fado-sim/tests/data/motulator/mot-pmsyrm-4k.toml");
    let warning = warning.expect("a warning on the coupling");
    println!("{warning}");
    assert!(warning.starts_with("`model.flux_map`"), "{warning}");
    assert!(
        warning.contains("is 1.23") && warning.contains("43.0 Hz"),
        "{warning}"
    );
    let c = c.unwrap();
    println!("c = {c}, T2S-2 {own} -> {t2s2} Hz");
    assert!((c - 1.228).abs() < 0.005, "{c}");
    assert!(
        (t2s2 - own * c / DEFAULT_MAX_FRAME_COUPLING).abs() < 1e-9,
        "{t2s2}"
    );
}
