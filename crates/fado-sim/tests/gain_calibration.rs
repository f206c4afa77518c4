//! The drive's start-up current-sensor gain calibration (fado_core::control::gain_calibration)
//! in closed loop with the simulator's plant, switching-resolved inverter and sensors.

use fado_core::control::{GainCalibrationStatus, SensorlessDrive};
use fado_sim::presets::PRESETS;
use fado_sim::profile::Profile;

/// `preset` with the TOML `extra` over it, at rest at `angle`, speed reference 0.
fn config(preset: &str, angle: f64, extra: &str) -> fado_sim::config::SimConfig {
    let p = fado_sim::presets::find(preset).unwrap();
    let base = fado_sim::config::SimConfig::from_toml(&format!(
        "{}\n[simulation]\ninitial_angle = {angle}\n",
        p.toml
    ))
    .unwrap();
    let mut cfg = fado_sim::config::SimConfig::from_toml_over(&base, extra).unwrap();
    cfg.speed_reference = Profile::constant(0.0);
    cfg
}

/// Steps the drive of `cfg` until the offset and gain calibrations are over; returns the drive,
/// the largest true |i_dq| seen (A) and the time the drive starts (s).
fn run_start_up(cfg: &fado_sim::config::SimConfig) -> (SensorlessDrive<f64>, f64, f64) {
    let mut sim = cfg.simulation(cfg.build_drive().unwrap()).unwrap();
    let mut peak: f64 = 0.0;
    let mut t = 0.0;
    for _ in 0..2_000_000 {
        let s = sim.step();
        let i = s.i_dq_true;
        peak = peak.max((i.d * i.d + i.q * i.q).sqrt());
        t = s.time;
        let d = sim.controller();
        if !d.is_calibrating() && !d.is_calibrating_gain() {
            break;
        }
    }
    (*sim.controller(), peak, t)
}

/// Runs the start-up of `preset` (with the TOML `extra` over it) at rest at `angle`, speed
/// reference 0, until the offset and gain calibrations are over; returns the drive's ratio,
/// the sensors' true ratio (1 + g_a)/(1 + g_b), the calibration's status, the largest true
/// |i_dq| seen (A) and the time the drive starts (s).
fn start_up(preset: &str, angle: f64, extra: &str) -> (f64, f64, GainCalibrationStatus, f64, f64) {
    let cfg = config(preset, angle, extra);
    let k_true = (1.0 + cfg.current_sensor.gain_error_a) / (1.0 + cfg.current_sensor.gain_error_b);
    let (d, peak, t) = run_start_up(&cfg);
    // At rest the motion test reads well below its threshold (measured: at most 0.59, the
    // 2.2 kW IPMSM at θ0 = 0).
    let motion = d.gain_calibration().motion_peak();
    println!("{preset} θ0 {angle}: motion test at {motion:.3} of its threshold");
    assert!(motion < 0.8, "{preset} at {angle}: {motion}");
    (
        d.current_gain_ratio(),
        k_true,
        d.gain_calibration_status(),
        peak,
        t,
    )
}

#[test]
fn the_mismatch_is_measured_on_every_calibrated_preset_and_skipped_where_it_should_be() {
    // Default non-idealities (0.5 % on phase a, offsets, noise, ADC, dead time, ripple),
    // switching-resolved, rotor at rest at θ0. Measured (this code): |k − k_true| ≤ 1.2e-3
    // on the calibrated presets at these angles (ipmsm-2k2 the worst, 1.12e-3), i.e. at least 77 % of
    // the 5e-3 mismatch removed.
    let mut calibrated = 0;
    for p in PRESETS {
        for angle in [0.3, 0.0, 1.0, 2.0] {
            let (k, k_true, status, peak, t) = start_up(p.name, angle, "");
            println!(
                "{:24} θ0 {angle:4.1}: k {k:.5} (true {k_true:.5}, error {:+.1e}) {status:?}, \
                 peak {peak:.1} A, start-up {t:.3} s",
                p.name,
                k - k_true
            );
            let machine = p.machine().unwrap();
            let limit = fado_core::control::DriveTuning::<f64>::default()
                .current
                .limit_ratio
                * machine.rated_current;
            assert!(
                peak <= limit,
                "{}: {peak} A above the limit {limit} A",
                p.name
            );
            match status {
                GainCalibrationStatus::Calibrated => {
                    calibrated += 1;
                    assert!((k - k_true).abs() < 1.5e-3, "{} at {angle}: k {k}", p.name);
                }
                // The hub motor's weakly damped swing and the salient rotors' reduced
                // stiffness need more than the budget at these axes: skipped, k untouched.
                GainCalibrationStatus::TooSlow => {
                    assert_eq!(k, 1.0);
                    assert!(peak < 1e-6 * limit);
                }
                s => panic!("{} at {angle}: {s:?}", p.name),
            }
        }
    }
    // The outrunner (whose failure motivated the calibration), the multirotor outrunner (its
    // swing held for its bias bound, 1.25 time constants), the paper's motor, the servo and
    // the 2.2 kW IPMSM are calibrated at every angle. The hub motor is not: at θ0 = 0, where
    // phases a and b carry 1 and 0.5 of the current, its swing needs a 0.18 s window (0.34 s
    // at 0.3 rad, 0.60 s at the least observable axis) and the whole sequence 0.78 s, beyond
    // the free rotor's 0.7 s budget (`control::drive` config, `gain_calibration_max_time`).
    assert_eq!(calibrated, 20);
}

#[test]
fn an_axis_without_current_in_a_phase_is_reported_unobservable() {
    // θ0 = π/2: phase a carries no current; −π/6: phase c (inverter error would not cancel).
    // The paper's motor is too heavy for the free rotor's turn to a well-observed axis
    // (`fado_core::control::calibration_turn`, 0.43 s against 0.2 s): skipped, no current.
    // The outrunner turns in 0.11 s and is calibrated there (tests/start_angle.rs).
    for angle in [std::f64::consts::FRAC_PI_2, -std::f64::consts::FRAC_PI_6] {
        let (k, _, status, peak, _) = start_up("paper", angle, "");
        assert_eq!(status, GainCalibrationStatus::Unobservable, "{angle}");
        assert_eq!(k, 1.0);
        assert!(peak < 1e-9);
        let (k, k_true, status, _, _) = start_up("outrunner-cheetah-24v", angle, "");
        assert_eq!(status, GainCalibrationStatus::Calibrated, "{angle}");
        assert!((k - k_true).abs() < 1.5e-3, "{angle}: k {k}");
    }
}

#[test]
fn the_calibration_can_be_switched_off() {
    let (k, _, status, peak, t) = start_up(
        "outrunner-cheetah-24v",
        0.3,
        "[controller.gain_calibration]\ntime = 0.0\n",
    );
    assert_eq!((k, status), (1.0, GainCalibrationStatus::Off));
    assert!(peak < 1e-9 && t < 0.101, "{peak} {t}");
}

#[test]
fn a_wrong_resistance_estimate_changes_neither_k_nor_the_current_bound() {
    // The voltage step to the upper level is sized with R̂s: with R̂s 0.77× the motor's, the
    // upper level is 0.77× its nominal step, and k = ratio of conductances does not depend on
    // Rs. Measured: k within 3e-5 of 1.005. With R̂s 1.25× the motor's, four of the swing's
    // time constants 2J·R̂s/(1.5·p²·λ̂f²) exceed the hold budget; its bias bound allows 3.75,
    // 0.198 s. Measured: k within 1.5e-4 of 1.005.
    let (k, k_true, status, peak, _) =
        start_up("paper", 0.3, "[mismatch]\nrs_ratio = 0.7692307692307693\n");
    assert_eq!(status, GainCalibrationStatus::Calibrated);
    assert!((k - k_true).abs() < 5e-4, "{k}");
    assert!(peak < 40.0, "{peak}");
    let (k, k_true, status, _, _) = start_up("paper", 0.3, "[mismatch]\nrs_ratio = 1.25\n");
    assert_eq!(status, GainCalibrationStatus::Calibrated);
    assert!((k - k_true).abs() < 5e-4, "{k}");
}

#[test]
fn the_start_up_dc_test_hands_its_resistance_to_the_adaptation_and_not_to_the_fixed_path() {
    // The two calibration levels are the classic two-point DC test: with the motor's Rs 1.3×
    // the model's, the adaptive estimator starts from the measured Rs; the paper's fixed R̂s
    // stays as configured. Two motors (the paper's and the outrunner presets), both calibrated
    // at 0.3 rad.
    for preset in ["paper", "outrunner-cheetah-24v"] {
        for adaptation in [true, false] {
            let extra = format!(
                "[mismatch]\nrs_ratio = 0.7692307692307693\n[estimator.rs_adaptation]\nenabled = {adaptation}\n"
            );
            let cfg = config(preset, 0.3, &extra);
            let rs_motor = cfg.motor.rs;
            let rs_model = rs_motor * 0.7692307692307693;
            let (d, _, _) = run_start_up(&cfg);
            assert_eq!(
                d.gain_calibration_status(),
                GainCalibrationStatus::Calibrated,
                "{preset}"
            );
            let r = d.estimator().rs_hat();
            if adaptation {
                // Measured: −0.013 % (paper), −0.040 % (outrunner); the DC test also holds the
                // devices' on-resistance and phase b's sensor gain (the estimator's scale).
                assert!(
                    (r / rs_motor - 1.0).abs() < 0.02,
                    "{preset}: R̂s {r} against {rs_motor}"
                );
            } else {
                assert_eq!(r, rs_model, "{preset}");
            }
        }
    }
}

/// Runs `cfg` (2 s, speed reference 0 until 0.2 s, then a ramp to 300 r/min at 1 s) and
/// returns the gain calibration's status, the largest |θ − θ̂| after the drive starts (rad),
/// the lowest speed (r/min) and the rotor's largest backward travel (electrical rad).
fn run_loaded(cfg: &mut fado_sim::config::SimConfig) -> (GainCalibrationStatus, f64, f64, f64) {
    cfg.speed_reference =
        Profile::from_points(&[(0.0, 0.0), (0.2, 0.0), (1.0, 300.0), (2.0, 300.0)]);
    let mut sim = cfg.simulation(cfg.build_drive().unwrap()).unwrap();
    let (mut max_err, mut min_speed, mut back) = (0.0_f64, 0.0_f64, 0.0_f64);
    let mut status = GainCalibrationStatus::Pending;
    let (mut travel, mut last) = (0.0, f64::NAN);
    loop {
        let s = sim.step();
        let d = sim.controller();
        let started = !d.is_calibrating() && !d.is_calibrating_gain();
        if last.is_finite() {
            travel += fado_core::wrap_angle(s.theta - last);
        }
        last = s.theta;
        back = back.min(travel);
        min_speed = min_speed.min(s.speed_rpm);
        if started {
            status = d.gain_calibration_status();
            max_err = max_err.max(s.angle_error.abs());
        }
        if s.time >= 2.0 {
            break;
        }
    }
    (status, max_err, min_speed, -back)
}

#[test]
fn a_load_arriving_during_the_calibration_ends_it_and_the_drive_takes_the_load() {
    // The 2.2 kW IPMSM whose 7 N·m (half its rated torque) arrives at 0.5 s, while the
    // calibration holds its upper d level (it would end at 0.51 s and then hold zero current
    // for 50 ms, the rotor free). The motion test ends it within milliseconds, the release
    // hold catches the rotor at the aligned angle and hands the load to the speed loop, whose
    // reference then resumes from zero (`ReleaseHold::engage`). Measured: RotorMoved, max
    // |θ − θ̂| 0.112 rad, lowest speed −17.7 r/min, 0.094 rad backward (the speed loop alone
    // from the aligned angle: 0.159 rad, −38 r/min, 0.43 rad; without the test: θ̂ lost,
    // 3.13 rad, −383 r/min).
    let mut cfg = config(
        "ipmsm-2k2",
        0.3,
        "[load.torque]\npoints = [[0.0, 0.0], [0.4999, 0.0], [0.5, 7.0]]\n",
    );
    let (status, err, min_speed, back) = run_loaded(&mut cfg);
    println!(
        "{status:?} max |θ − θ̂| {err:.3} rad, lowest {min_speed:.1} r/min, back {back:.3} rad"
    );
    assert_eq!(status, GainCalibrationStatus::RotorMoved);
    assert!(err < 0.25, "{err}");
    assert!(min_speed > -60.0, "{min_speed}");
    assert!(back < 0.5, "{back}");
    // Without a load the same start-up calibrates (the test does not fire at rest; measured
    // max |θ − θ̂| 0.165 rad, in the first tenths of a second of the ramp).
    let mut cfg = config("ipmsm-2k2", 0.3, "");
    let (status, err, _, _) = run_loaded(&mut cfg);
    assert_eq!(status, GainCalibrationStatus::Calibrated);
    assert!(err < 0.25, "{err}");
}

/// The start-up of the machine file `toml` at `angle` with its rotor on a brake that the
/// drive is told of (`startup.rotor_held`), speed reference 0: the drive's ratio, the
/// sensors' true ratio, the status and the time the drive starts (s).
fn braked_start_up(toml: &str, angle: f64) -> (f64, f64, GainCalibrationStatus, f64) {
    start_up_of(&format!(
        "{toml}\n[controller.startup]\nrotor_held = true\n\
         [simulation]\ninitial_angle = {angle}\nbrake = true\nbrake_release_at = 10.0\n"
    ))
}

/// [`braked_start_up`] of the whole configuration `toml`.
fn start_up_of(toml: &str) -> (f64, f64, GainCalibrationStatus, f64) {
    let mut cfg = fado_sim::config::SimConfig::from_toml(toml).unwrap();
    cfg.speed_reference = Profile::constant(0.0);
    let k_true = (1.0 + cfg.current_sensor.gain_error_a) / (1.0 + cfg.current_sensor.gain_error_b);
    let (d, _, t) = run_start_up(&cfg);
    (
        d.current_gain_ratio(),
        k_true,
        d.gain_calibration_status(),
        t,
    )
}

#[test]
fn a_braked_rotor_too_heavy_for_the_swing_hold_is_calibrated_on_the_settling_alone() {
    // Free, these rotors' swing about the d current needs more than the 0.2 s hold budget
    // (4 time constants: traction IPMSM 0.61 s, 50 kW IPMSM 0.67 s, PM-SyRM 1.0 s, hub motor
    // 0.89 s) and the calibration is skipped (`TooSlow`). On a brake the drive knows of
    // nothing swings. Measured (this code, default sensors with 0.5 % on phase a,
    // switching-resolved): |k − k_true| ≤ 1.9e-3 (the saturated traction IPMSM at 0.3 rad),
    // ≤ 1.6e-3 on the three presets; at least 62 % of the mismatch removed.
    for (name, toml) in [
        (
            "traction-ipm-saturated",
            include_str!("data/traction-ipm-saturated.toml"),
        ),
        (
            "ipmsm-gem-50k",
            fado_sim::presets::find("ipmsm-gem-50k").unwrap().toml,
        ),
        (
            "pmsyrm-5k",
            fado_sim::presets::find("pmsyrm-5k").unwrap().toml,
        ),
        (
            "hub-hoverboard-48v",
            fado_sim::presets::find("hub-hoverboard-48v").unwrap().toml,
        ),
    ] {
        for angle in [0.3, 0.0, 1.0, 2.0] {
            let (k, k_true, status, t) = braked_start_up(toml, angle);
            println!(
                "{name:24} θ0 {angle:4.1}: k {k:.5} (true {k_true:.5}, error {:+.1e}) {status:?}, \
                 start-up {t:.3} s",
                k - k_true
            );
            assert_eq!(
                status,
                GainCalibrationStatus::Calibrated,
                "{name} at {angle}"
            );
            assert!((k - k_true).abs() < 2.5e-3, "{name} at {angle}: k {k}");
        }
        // Free, the same rotor is still skipped: nothing holds it through the levels.
        let (k, _, status, _) =
            start_up_of(&format!("{toml}\n[simulation]\ninitial_angle = 0.3\n"));
        assert_eq!(status, GainCalibrationStatus::TooSlow, "{name}");
        assert_eq!(k, 1.0);
    }
}
