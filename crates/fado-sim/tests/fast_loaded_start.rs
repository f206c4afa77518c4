//! `loaded-start` on fast, light, many-pole motors: the brake opens under the rated torque and
//! the drive must catch the rotor within the scenario's bounds (backward travel ≤ 0.5 rad,
//! |θ − θ̂| < 0.25 rad from ready on), seeds 1–4.

use fado_sim::scenario::simulate;

fn with_seed(motor: &str, seed: u64) -> String {
    format!("{motor}\n[current_sensor]\nseed = {seed}\n")
}

/// (backward travel, max |θ − θ̂| from ready) of `loaded-start` on `motor` with `seed`,
/// asserting the scenario's verdict.
fn loaded_start(name: &str, motor: &str, seed: u64) -> (f64, f64) {
    let out = simulate("loaded-start", Some(&with_seed(motor, seed)), false, None).unwrap();
    let value = |prefix: &str| {
        out.checks
            .iter()
            .find(|c| c.name.starts_with(prefix))
            .unwrap()
            .value
    };
    let (back, err) = (value("backward travel"), value("max |θ − θ̂| from ready"));
    println!("{name} seed {seed}: backward {back:.3} rad, |θ − θ̂| {err:.3} rad");
    assert!(out.passed, "{name} seed {seed}: {:?}", out.checks);
    (back, err)
}

#[test]
fn the_outrunner_presets_hold_their_rated_load_at_the_release() {
    // The rated load accelerates the multirotor's rotor at 4.4e4 rad/s² (electrical), the
    // cheetah's at 5.5e4: the release hold needs a 387/436 Hz current loop
    // (`release_hold::current_bandwidth_for_hold`), and the trackers' feed-forward leaves out
    // the torque the hold commands (its load after the hand-over), so that their speed stays on
    // the held rotor; T2S-1 tracks the fall at its running bandwidth. Measured: multirotor
    // seeds 1, 3, 4 backward 0.21–0.44 rad, |θ − θ̂| 0.09–0.11 rad; cheetah seeds 1–4
    // 0.24–0.32 / 0.09–0.12 rad.
    for (name, seeds) in [
        ("multirotor-mn5006-22v", &[1u64, 3, 4][..]),
        ("outrunner-cheetah-24v", &[1, 2, 3, 4][..]),
    ] {
        let motor = fado_sim::presets::find(name).unwrap().toml;
        for &seed in seeds {
            loaded_start(name, motor, seed);
        }
    }
}

/// Seed 2 starts the rotor at −1.66 rad, where the start-up's d current leaves phase a's
/// current inside the inverter's dead-time band, whose edge currents the PWM ripple (ΔI 2.3 A
/// against a 0.47 A band) moves: the compensation's error hides the first milliseconds of the
/// fall from the estimator. The release's d-current floor (`fado_core::control::release_current`,
/// capped at half the rated current: phase a at 0.4 A) catches the fall; the estimate stands
/// 0.1 rad off after it, and on this light rotor the standstill probe's d current at that error
/// would swing the rotor 0.72 rad back under the speed loop before the lift: the release hold
/// holds it through the standstill instead (`fado_core::control::release_hold`, "Through the
/// loaded standstill"). Measured: backward travel 0.31 rad, |θ − θ̂| from ready 0.17 rad.
#[test]
fn the_multirotor_preset_seed_2_holds_its_rated_load_at_the_release() {
    let motor = fado_sim::presets::find("multirotor-mn5006-22v")
        .unwrap()
        .toml;
    loaded_start("multirotor", motor, 2);
}

/// The made-up 45 µH, 48 V motor of `tests/data` (7 pole pairs, 2.31 N·m on 1.2e-4 kg·m²):
/// its rated load accelerates the bare rotor at 1.35e5 rad/s² (electrical) the moment the
/// brake opens. T2S-1 tracks the fall at its running bandwidth (219 Hz, placed against that
/// step: `fado_core::control::tracker_feedforward`, "T2S-1 at a brake's release"): measured
/// max |θ − θ̂| from ready 0.066–0.083 rad and backward travel 0.23–0.28 rad over seeds 1–4.
/// At the standstill's 60 Hz (`track_fall = false`) the tracked angle lags the hold's catch:
/// 0.285 rad at seed 2, which fails the 0.25 rad bound (0.22–0.24 rad at seeds 1, 3, 4).
#[test]
fn the_fast_48v_motor_tracks_its_fall_at_the_release() {
    let path = format!(
        "{}/tests/data/startup-fast-48v.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let motor = std::fs::read_to_string(path).unwrap();
    for seed in 1..=4 {
        let (back, err) = loaded_start("startup-fast-48v", &motor, seed);
        assert!(err < 0.12 && back < 0.35, "seed {seed}: {back} {err}");
    }
    let narrow = format!("{motor}\n[controller.release_hold]\ntrack_fall = false\n");
    let out = simulate("loaded-start", Some(&with_seed(&narrow, 2)), false, None).unwrap();
    let st = out.probe.start.as_ref().unwrap();
    println!(
        "track_fall = false, seed 2: |θ − θ̂| {:.3} rad",
        st.max_angle_error
    );
    assert!(st.max_angle_error > 0.25, "{}", st.max_angle_error);
}
