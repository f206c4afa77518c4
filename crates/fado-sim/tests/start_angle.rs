//! The start angle: a drive given the rotor's angle passes `reversal` and `stops` wherever the
//! rotor stands at the start, also where the d axis leaves a phase without current and the
//! current-sensor gain calibration turns the free rotor to a well-observed axis first
//! (`fado_core::control::calibration_turn`).

use fado_core::control::GainCalibrationStatus;
use fado_sim::profile::Profile;
use fado_sim::scenario::simulate;

/// The `outrunner-cheetah-24v` preset started at `angle` (electrical rad), sensor seed 1.
fn cheetah_at(angle: f64) -> String {
    let preset = fado_sim::presets::find("outrunner-cheetah-24v")
        .unwrap()
        .toml;
    format!("{preset}\n[simulation]\ninitial_angle = {angle}\n[current_sensor]\nseed = 1\n")
}

#[test]
fn the_outrunner_passes_the_reversal_and_the_stops_from_every_start_angle() {
    // Eight start angles, three of them within 0.2 rad of a phase's zero (0.4–0.6 near π/6
    // for phase b, 1.5 near π/2 for phase a, 2.5 near 5π/6 for phase c), where the
    // calibration is unobservable along the d axis. Left uncalibrated there, the 0.5 % gain
    // mismatch stalled the loaded zero crossing: reversal 1.205 rad at 0.4–0.6, stops
    // 1.16 rad at 0.4–0.6, 1.205 at 1.5 and 0.953 at 2.5. Measured with the turn (seed 1,
    // switching-resolved): reversal 0.002–0.010 rad, stops 0.018–0.068 rad.
    // Bound: the scenarios' own 0.25 rad.
    for angle in [0.0, 0.4, 0.5, 0.6, 1.0, 1.5, 2.0, 2.5] {
        for scenario in ["reversal", "stops"] {
            let out = simulate(scenario, Some(&cheetah_at(angle)), false, None).unwrap();
            let e = out.metrics.max_angle_error;
            println!("θ0 {angle}: {scenario} {e:.3} rad");
            assert!(out.passed, "θ0 {angle} {scenario}: {:?}", out.checks);
            assert!(e < 0.25, "θ0 {angle} {scenario}: {e}");
        }
    }
}

#[test]
fn a_free_rotor_at_an_unobservable_angle_is_calibrated_after_its_turn() {
    // At a phase's zero the rotor turns to the nearest k·π/3 and the mismatch is measured
    // there as anywhere else (within 1.5e-3 of 1.005, gain_calibration.rs's bound), the rotor
    // at rest and at the turned axis when the drive starts.
    for angle in [0.5, std::f64::consts::FRAC_PI_2, 2.6] {
        let base = fado_sim::config::SimConfig::from_toml(&cheetah_at(angle)).unwrap();
        let mut cfg = base.clone();
        cfg.speed_reference = Profile::constant(0.0);
        let k_true =
            (1.0 + cfg.current_sensor.gain_error_a) / (1.0 + cfg.current_sensor.gain_error_b);
        let mut sim = cfg.simulation(cfg.build_drive().unwrap()).unwrap();
        let mut theta = f64::NAN;
        for _ in 0..200_000 {
            let s = sim.step();
            theta = s.theta;
            let d = sim.controller();
            if !d.is_calibrating() && !d.is_calibrating_gain() {
                break;
            }
        }
        let d = sim.controller();
        let k = d.current_gain_ratio();
        let axis = fado_core::control::calibration_turn::well_observed_axis(angle);
        let off = fado_core::wrap_angle(theta - axis);
        println!(
            "θ0 {angle}: k {k:.5} (true {k_true:.5}) {:?}, rotor {off:+.4} rad from {axis:.3}",
            d.gain_calibration_status()
        );
        assert_eq!(
            d.gain_calibration_status(),
            GainCalibrationStatus::Calibrated
        );
        assert!((k - k_true).abs() < 1.5e-3, "θ0 {angle}: k {k}");
        assert!(
            off.abs() < 0.02,
            "θ0 {angle}: rotor {off} rad off the turned axis"
        );
    }
}
