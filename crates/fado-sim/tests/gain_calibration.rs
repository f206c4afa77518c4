//! The drive's start-up current-sensor gain calibration (fado_core::control::gain_calibration)
//! in closed loop with the simulator's plant, switching-resolved inverter and sensors.

use fado_core::control::GainCalibrationStatus;
use fado_sim::presets::PRESETS;
use fado_sim::profile::Profile;

/// Runs the start-up of `preset` at rest at `angle` with the sensors' `gain_error_a`; returns
/// the drive's ratio, its status, the largest |true phase current| seen, and the start-up
/// time.
fn start_up(preset: &str, angle: f64, extra: &str) -> (f64, f64, GainCalibrationStatus, f64, f64) {
    let p = fado_sim::presets::find(preset).unwrap();
    let base = fado_sim::config::SimConfig::from_toml(&format!(
        "{}\n[simulation]\ninitial_angle = {angle}\n",
        p.toml
    ))
    .unwrap();
    let mut cfg = fado_sim::config::SimConfig::from_toml_over(&base, extra).unwrap();
    cfg.speed_reference = Profile::constant(0.0);
    let k_true = (1.0 + cfg.current_sensor.gain_error_a) / (1.0 + cfg.current_sensor.gain_error_b);
    let drive = cfg.build_drive().unwrap();
    let mut sim = cfg.simulation(drive).unwrap();
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
    let d = sim.controller();
    (
        d.current_gain_ratio(),
        k_true,
        d.gain_calibration_status(),
        peak,
        t,
    )
}

#[test]
fn explore_sources() {
    let extras = [
        ("default", ""),
        (
            "ideal sensors",
            "[current_sensor]\nenable_noise = false\nenable_quantization = false\nenable_offset = false\n",
        ),
        ("no dead time", "[inverter]\ndead_time = 0.0\n"),
        (
            "no dead time, vth",
            "[inverter]\ndead_time = 0.0\nthreshold_voltage = 0.0\n",
        ),
        ("averaged", "[inverter]\nmodel = \"averaged\"\n"),
        ("huge inertia", "[motor]\ninertia = 1000.0\n"),
    ];
    for name in ["paper", "servo-1ft6084", "ipmsm-gem-50k", "pmsyrm-5k"] {
        for (what, extra) in extras {
            let (k, kt, st, _, _) = start_up(name, 0.0, extra);
            println!("{name:24} {what:20}: err {:+.2e} {st:?}", k - kt);
        }
    }
}

#[test]
fn explore() {
    for p in PRESETS {
        for angle in [0.3, 0.0, 1.0, -0.5, 2.0, -2.5, 0.52] {
            let (k, kt, st, peak, t) = start_up(p.name, angle, "");
            println!(
                "{:24} θ0 {angle:5.2}: k {k:.5} true {kt:.5} err {:+.2e} {st:?} peak {peak:.2} A t {t:.3} s",
                p.name,
                k - kt
            );
        }
    }
}
