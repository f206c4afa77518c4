//! The drive's start-up under a load arriving during its calibrations (the 2.2 kW IPMSM
//! benchmark of `gain_calibration.rs`: half the rated torque at 0.5 s) on motors of other
//! classes, each given only its circuit and ratings (every other value derived).

use fado_core::control::GainCalibrationStatus;
use fado_sim::config::SimConfig;
use fado_sim::profile::Profile;

/// (name, `[motor]` body, `[inverter]` body) of machines of other classes.
const MACHINES: [(&str, &str, &str); 6] = [
    (
        "400 V servo 1.5 kW",
        "rs = 1.2\nld = 6e-3\nlq = 6e-3\nflux_linkage = 0.13\npole_pairs = 4\n\
         rated_current = 6.2\nrated_speed_rpm = 3000.0\nrated_torque = 4.8\n",
        "dc_voltage = 560.0\n",
    ),
    (
        "48 V hub motor",
        "rs = 0.15\nld = 0.4e-3\nlq = 0.45e-3\nflux_linkage = 0.047\npole_pairs = 15\n\
         rated_current = 15.0\nrated_speed_rpm = 300.0\nrated_torque = 16.0\n",
        "dc_voltage = 48.0\n",
    ),
    (
        "12S multirotor",
        "rs = 0.1\nld = 50e-6\nlq = 50e-6\nflux_linkage = 0.00263\npole_pairs = 21\n\
         rated_current = 24.0\nrated_speed_rpm = 4000.0\nrated_torque = 2.0\n",
        "dc_voltage = 44.4\n",
    ),
    (
        "50 kW traction IPMSM",
        "rs = 0.01\nld = 0.2e-3\nlq = 0.5e-3\nflux_linkage = 0.08\npole_pairs = 4\n\
         rated_current = 300.0\nrated_speed_rpm = 2500.0\nrated_torque = 190.0\n",
        "dc_voltage = 400.0\n",
    ),
    (
        "10 kV-class 2 MW",
        "rs = 0.1\nld = 25e-3\nlq = 25e-3\nflux_linkage = 11.7\npole_pairs = 4\n\
         rated_current = 181.0\nrated_speed_rpm = 1500.0\nrated_torque = 12700.0\n",
        "dc_voltage = 14000.0\n",
    ),
    (
        "2-pole spindle 60k r/min",
        "rs = 0.5\nld = 1e-3\nlq = 1e-3\nflux_linkage = 0.041\npole_pairs = 1\n\
         rated_current = 5.2\nrated_speed_rpm = 60000.0\nrated_torque = 0.32\n",
        "dc_voltage = 560.0\n",
    ),
];

/// The machine `motor`/`inverter` at rest at 0.3 rad, with the TOML `extra` over it.
fn config(motor: &str, inverter: &str, extra: &str) -> SimConfig {
    SimConfig::from_toml(&format!(
        "[motor]\n{motor}[inverter]\n{inverter}[simulation]\ninitial_angle = 0.3\n{extra}"
    ))
    .unwrap()
}

/// Runs `cfg` to 2 s (0 until 0.2 s, a ramp to 20 % of rated speed at 1 s); returns the
/// time the calibrations end (s), the gain calibration's status, the largest |θ − θ̂| after
/// the drive starts (rad), the lowest speed (r/min) and the largest backward travel (rad).
fn run(mut cfg: SimConfig) -> (f64, GainCalibrationStatus, f64, f64, f64) {
    let n = 0.2 * cfg.motor.rated_speed_rpm;
    cfg.speed_reference = Profile::from_points(&[(0.0, 0.0), (0.2, 0.0), (1.0, n), (2.0, n)]);
    let mut sim = cfg.simulation(cfg.build_drive().unwrap()).unwrap();
    let (mut end, mut max_err, mut min_speed, mut back) = (f64::NAN, 0.0_f64, 0.0_f64, 0.0_f64);
    let mut status = GainCalibrationStatus::Pending;
    let (mut travel, mut last) = (0.0, f64::NAN);
    loop {
        let s = sim.step();
        let d = sim.controller();
        if last.is_finite() {
            travel += fado_core::wrap_angle(s.theta - last);
        }
        last = s.theta;
        back = back.min(travel);
        min_speed = min_speed.min(s.speed_rpm);
        if !d.is_calibrating() && !d.is_calibrating_gain() {
            if end.is_nan() {
                end = s.time;
            }
            status = d.gain_calibration_status();
            max_err = max_err.max(s.angle_error.abs());
        }
        if s.time >= 2.0 {
            break;
        }
    }
    (end, status, max_err, min_speed, -back)
}

/// The benchmark's criteria (`gain_calibration.rs`): |θ − θ̂| from the start < 0.25 rad, at
/// most 0.5 rad electrical backward, the speed never below −4 % of rated (−60 r/min of the
/// IPMSM's 1500). Measured (this code; load of half the rated torque 20 ms and 100 ms before
/// the calibrations end without load):
///
/// | machine | no load | 20 ms before | 100 ms before |
/// |---|---|---|---|
/// | 400 V servo | 0.161 rad | Calibrated (not seen), 1.22 rad, 7.0 rad back | RotorMoved, 0.167 rad, 0.081 rad back |
/// | 48 V hub | 0.124 rad | RotorMoved, 0.104 rad, 0.094 rad back | RotorMoved, 0.102 rad, 0.092 rad back |
/// | 12S multirotor | 0.009 rad | RotorMoved, 0.203 rad, 0.41 rad back | RotorMoved, 0.202 rad, 0.41 rad back |
/// | 50 kW traction | TooSlow, 0.075 rad | RotorMoved (offsets), 0.087 rad, 0.42 rad back, lowest −4.2 % | — |
/// | 10 kV-class | TooSlow, 0.055 rad | RotorMoved (offsets), 0.068 rad, 0.18 rad back, lowest −2.9 % | — |
/// | 2-pole spindle | 0.041 rad | Implausible, 3.14 rad, 60 rad back | Implausible, 3.14 rad, 57 rad back |
///
/// Where the gain calibration's motion test sees the load (a voltage-mode level), the release
/// hold catches the rotor (`ReleaseHold::engage`) and the four cases pass. Where the load
/// arrives during the offset calibration (the traction and 10 kV machines, whose gain
/// calibration is skipped as too slow), the phases are shorted through the low-side switches
/// and the motion monitor sees the rotor turn: the drive starts at once from where it has
/// turned to (the 10 kV machine passes; the traction machine's speed dips to −4.2 % of its
/// rated speed against the −4 % bound). Not met: a load that arrives during the calibration's
/// last stage (the current loop at zero current, which the motion test does not watch: the
/// servo at 20 ms); the spindle, whose motion the test does not see before the calibration
/// is refused. Ignored until they are met; run with `--ignored`.
#[test]
#[ignore = "the start-up loses these machines under a load arriving during its calibrations"]
fn a_load_arriving_during_the_calibrations_on_machines_of_other_classes() {
    let mut failed = Vec::new();
    for (name, motor, inverter) in MACHINES {
        let (end, status0, err0, _, _) = run(config(motor, inverter, ""));
        let machine = config(motor, inverter, "").motor;
        let (torque, rated) = (0.5 * machine.rated_torque, machine.rated_speed_rpm);
        for before in [0.02, 0.1] {
            let at = end - before;
            if at < 0.05 {
                continue;
            }
            let extra = format!(
                "[load.torque]\npoints = [[0.0, 0.0], [{:.6}, 0.0], [{at:.6}, {torque}]]\n",
                at - 1e-4
            );
            let (_, status, err, min_speed, back) = run(config(motor, inverter, &extra));
            let line = format!(
                "{name:26} no load: end {end:.3} s {status0:?} {err0:.3} rad | load at {at:.3} s: \
                 {status:?} max |θ − θ̂| {err:.3} rad, lowest {:.1} % of rated, back {back:.3} rad",
                100.0 * min_speed / rated
            );
            println!("{line}");
            if !(err < 0.25 && back < 0.5 && min_speed > -0.04 * rated) {
                failed.push(line);
            }
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

/// The cases of the table above that the gain calibration's motion test sees (a voltage-mode
/// level): RotorMoved, and the release hold catches the rotor within the benchmark's
/// criteria (measured: the servo 100 ms before the end, the hub motor and the 12S multirotor
/// 20 and 100 ms before; 0.08–0.41 rad back, |θ − θ̂| 0.10–0.21 rad); and the one the
/// offset calibration's motion monitor sees (the 10 kV-class machine 20 ms before: 0.18 rad
/// back, |θ − θ̂| 0.068 rad).
#[test]
fn a_load_the_motion_test_sees_is_caught_on_machines_of_other_classes() {
    for (index, befores) in [
        (0, &[0.1][..]),
        (1, &[0.02, 0.1][..]),
        (2, &[0.02, 0.1][..]),
        (4, &[0.02][..]),
    ] {
        let (name, motor, inverter) = MACHINES[index];
        let (end, ..) = run(config(motor, inverter, ""));
        let machine = config(motor, inverter, "").motor;
        let (torque, rated) = (0.5 * machine.rated_torque, machine.rated_speed_rpm);
        for &before in befores {
            let at = end - before;
            let extra = format!(
                "[load.torque]\npoints = [[0.0, 0.0], [{:.6}, 0.0], [{at:.6}, {torque}]]\n",
                at - 1e-4
            );
            let (_, status, err, min_speed, back) = run(config(motor, inverter, &extra));
            assert_eq!(status, GainCalibrationStatus::RotorMoved, "{name} {before}");
            assert!(err < 0.25, "{name} {before}: {err}");
            assert!(back < 0.5, "{name} {before}: {back}");
            assert!(min_speed > -0.04 * rated, "{name} {before}: {min_speed}");
        }
    }
}

/// The servo motor's unloaded start into the speed ramp, already at 6.4 % of its rated speed
/// when the calibrations end: the drive's start ramp (`fado_core::control::start_ramp`) keeps
/// |θ − θ̂| within the benchmark's 0.25 rad (measured 0.16 rad; stepped to: 0.26 rad).
#[test]
fn a_start_into_a_moving_reference_is_ramped() {
    let (name, motor, inverter) = MACHINES[0];
    let (_, status, err, min_speed, back) = run(config(motor, inverter, ""));
    assert_eq!(status, GainCalibrationStatus::Calibrated, "{name}");
    assert!(
        err < 0.25 && back < 0.5 && min_speed > -0.04 * 3000.0,
        "{name}: {err} {back}"
    );
}
