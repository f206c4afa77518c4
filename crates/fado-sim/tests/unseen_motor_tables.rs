//! Six machines of classes no preset or other test machine has, entered from public parameter
//! tables as a user writes them (only the table's keys; `tests/data/unseen/*.toml`, each naming
//! its source): an 8-pole 400 W industrial servo on a 310 V link (Estun EMJ-04, its bare rotor
//! 3.1e-5 kg·m², 7.7 ms to rated speed at rated torque), a 6-pole rotary-compressor IPMSM (GMCC,
//! Lq/Ld 1.43), an 8-pole 12 V electric-power-steering motor (Rs·I/(ω·λf) 0.54 at rated), a
//! 4-pole 36 V power-tool inrunner at 20 000 r/min, a 20-pole 47 kW axial-flux traction motor
//! on 560 V (EMRAX 228 HV) and a 16-pole high-inductance appliance motor on 310 V (L·I/λf 2.4).
//! Switching-resolved inverter, the default sensor model, current-sensor seeds 1 and 2.
//!
//! Measured (the largest |θ − θ̂| of each run, seeds 1 / 2, rad): the compressor `reversal`
//! 0.008 / 0.009, `stops` 0.073 / 0.068, `rated-reversal` 0.009 / 0.009, `loaded-start` 0.148 /
//! 0.168, `fullrange` 0.109 / 0.106, `regen-stop` 0.052 / 0.052; EMRAX 0.012 / 0.011, 0.031 /
//! 0.030, 0.013 / 0.013, 0.121 / 0.187, 0.095 / 0.095, 0.072 / 0.066; the servo 0.004 / 0.007,
//! 0.008 / 0.007, 0.004 / 0.007, `loaded-start` 0.051 / 0.063, `fullrange` 0.144 / 0.127,
//! `regen-stop` seed 2 0.157; the tool
//! 0.017 / 0.019, 0.051 / 0.062, 0.019 / 0.020, `loaded-start` 0.112 / 0.126, 0.088 / 0.088,
//! 0.070 / 0.056; the EPS motor 0.027 / 0.020, `stops` 0.095 / 0.119, 0.021 / 0.019,
//! `loaded-start` 0.042 / 0.043, `fullrange` 0.117 / 0.126, `regen-stop` 0.024 / 0.036; the
//! appliance motor 0.016 / 0.015, 0.169 / 0.106, 0.038 / 0.018, 0.056 / 0.085, 0.136 / 0.083,
//! 0.045 / 0.066. The commissioned models (compressor, EMRAX, the servo with its bare rotor)
//! pass `reversal`.
//!
//! The light servo rotor's held regenerating stop, where the standstill probe's torque swings
//! it, has its own test below with its figures.

use fado_core::MachineModel;
use fado_core::commissioning::{AbortReason, Phase, Status};
use fado_sim::commission::{commission_on_own_nameplate, identified_toml};
use fado_sim::scenario::simulate;

mod unseen_common;
use unseen_common::{SCENARIOS, file};

/// `scenario` on machine `name` with the current sensors' noise `seed` and the `extra`
/// `[current_sensor]` keys: (passed, the largest |θ − θ̂| of the run), printed.
fn run(name: &str, scenario: &str, seed: u64, extra: &str) -> (bool, f64) {
    let text = format!("{}\n[current_sensor]\nseed = {seed}\n{extra}", file(name));
    let out = simulate(scenario, Some(&text), false, None).unwrap();
    let angle = out.metrics.max_angle_error;
    eprintln!(
        "{name} {scenario} seed {seed}: {angle:.3} rad, passed {}",
        out.passed
    );
    if !out.passed {
        eprintln!("  {:?}", out.checks);
    }
    (out.passed, angle)
}

/// Every scenario at seeds 1 and 2 but those `skip`ped; the misses listed together.
fn every_scenario(name: &str, skip: &[(&str, u64)]) {
    let mut missed = Vec::new();
    for scenario in SCENARIOS {
        for seed in [1, 2] {
            if !skip.contains(&(scenario, seed)) && !run(name, scenario, seed, "").0 {
                missed.push(format!("{scenario} seed {seed}"));
            }
        }
    }
    assert!(missed.is_empty(), "{name} missed: {missed:?}");
}

/// `commission` on `name`'s plant, told its own record; then `reversal` on the
/// `identified.toml` it writes, which must pass. The identified model and the plant's.
fn commissioned_reversal(name: &str) -> (MachineModel<f64>, MachineModel<f64>) {
    let text = file(name);
    let plant = fado_sim::SimConfig::from_toml(&text).unwrap().plant();
    let o = commission_on_own_nameplate(&plant).unwrap();
    assert_eq!(o.status, Status::Done, "{name}");
    let id = o.identification.unwrap();
    let identified_model = id.model;
    let identified = identified_toml(&text, &id).unwrap();
    let r = simulate("reversal", Some(&identified), false, None).unwrap();
    eprintln!(
        "{name}: identified reversal {:.3} rad near zero speed",
        r.metrics.max_angle_error_zero_speed
    );
    assert!(r.passed, "{name}: {:?}", r.checks);
    (identified_model, plant.motor)
}

#[test]
fn a_compressor_ipmsm_passes_every_scenario_and_commissions() {
    every_scenario("compressor-gmcc-ipm-310v", &[]);
    commissioned_reversal("compressor-gmcc-ipm-310v");
}

#[test]
fn a_47_kw_axial_flux_traction_motor_passes_every_scenario_and_commissions() {
    every_scenario("traction-emrax228hv-560v", &[]);
    commissioned_reversal("traction-emrax228hv-560v");
}

#[test]
fn a_400_w_servo_with_its_bare_rotor_passes_its_running_scenarios() {
    // `loaded-start` in the light rotors' test below, `regen-stop` seed 1 in the held stop's.
    let skip = [("loaded-start", 1), ("loaded-start", 2), ("regen-stop", 1)];
    every_scenario("servo-estun-emj04-400w-310v", &skip);
}

#[test]
fn a_36_v_power_tool_motor_passes_every_scenario() {
    // `loaded-start` seed 2 in the light rotors' test below.
    every_scenario("tool-makita-4p-36v", &[("loaded-start", 2)]);
}

/// The EPS and appliance motors' scenarios away from a loaded standstill.
#[test]
fn the_eps_and_appliance_motors_pass_reversals_and_the_loaded_start() {
    let mut missed = Vec::new();
    for (name, scenarios) in [
        (
            "eps-nedic-12v",
            &["reversal", "rated-reversal", "loaded-start", "regen-stop"][..],
        ),
        (
            "appliance-chmotor-16p-310v",
            &["reversal", "rated-reversal", "loaded-start"][..],
        ),
    ] {
        for scenario in scenarios {
            for seed in [1, 2] {
                if !run(name, scenario, seed, "").0 {
                    missed.push(format!("{name} {scenario} seed {seed}"));
                }
            }
        }
    }
    assert!(missed.is_empty(), "missed: {missed:?}");
}

/// The EPS and appliance motors with matched current-sensor gains (the rest of the sensor
/// model on, seed 1): `stops` and `fullrange` at 0.056 / 0.060 rad (EPS) and 0.067 /
/// 0.134 rad (appliance); a `sensor_gain_error` sweep of `stops` with the calibration
/// skipped (0, 0.001, 0.0025, 0.005): EPS 0.056, 0.151, 0.240, 1.095 rad; appliance 0.067,
/// 0.155, 0.172, 0.529.
#[test]
fn the_eps_and_appliance_motors_hold_a_loaded_standstill_with_matched_sensor_gains() {
    let mut missed = Vec::new();
    for name in ["eps-nedic-12v", "appliance-chmotor-16p-310v"] {
        for scenario in ["stops", "fullrange"] {
            if !run(name, scenario, 1, "enable_gain_error = false\n").0 {
                missed.push(format!("{name} {scenario}"));
            }
        }
    }
    assert!(missed.is_empty(), "missed: {missed:?}");
}

/// `fullrange` (zero-speed hold at 9–10 s after 1000–2000 r/min) and the appliance motor's
/// `regen-stop`: on the EPS motor the start-up calibration ends `RotorMoved` (at 0.72 s) and
/// the drive's online gain tracker (`fado_core::control::gain_tracking`) learns the mismatch
/// while the rotor turns under load, 0.117 / 0.126 rad (seeds 1, 2; 0.594 / 0.581 rad with
/// the mismatch unlearnt); the appliance motor calibrates at its start, 0.136 / 0.083 rad,
/// `regen-stop` at seed 1 0.045 rad.
#[test]
fn the_eps_and_appliance_motors_learn_their_sensor_gains_at_speed() {
    let mut missed = Vec::new();
    for (name, scenario, seed) in [
        ("eps-nedic-12v", "fullrange", 1),
        ("eps-nedic-12v", "fullrange", 2),
        ("appliance-chmotor-16p-310v", "fullrange", 1),
        ("appliance-chmotor-16p-310v", "fullrange", 2),
        ("appliance-chmotor-16p-310v", "regen-stop", 1),
    ] {
        if !run(name, scenario, seed, "").0 {
            missed.push(format!("{name} {scenario} seed {seed}"));
        }
    }
    assert!(missed.is_empty(), "missed: {missed:?}");
}

/// The EPS and appliance motors held at zero speed under load after 4 % of their rated speed
/// (`stops`, below the online tracker's 12/τ = 120 rad/s), and the appliance motor's
/// overhauling stop (`regen-stop`): their start-up calibrates the current sensors' 0.5 % gain
/// mismatch. The EPS motor's swing (τ = 0.16 s) needs a 0.224 s window with the 0.2 s hold at
/// the least observable axis, 0.124 s at its 0.3 rad start (`swing_window_time`); the
/// appliance motor's 12-bit sensor steps read through L̂q/1 ms as up to 0.9 of the
/// rotor-motion threshold, which the noise floor of the settled loop lifts
/// (`fado_core::control::gain_calibration::MOTION_NOISE_MARGIN`). Measured (seeds 1 / 2,
/// rad): EPS `stops` 0.095 / 0.119, appliance `stops` 0.169 / 0.106, `regen-stop` 0.045 /
/// 0.066; uncalibrated 1.095 / 1.110, 0.529 / 0.255 and 0.219 / 0.458. The EPS motor holds
/// `stops` at seeds 3 / 4 as well (0.101 / 0.111).
#[test]
fn the_eps_and_appliance_motors_hold_a_loaded_standstill() {
    let mut missed = Vec::new();
    for (name, scenarios, seeds) in [
        ("eps-nedic-12v", &["stops"][..], &[1, 2, 3, 4][..]),
        (
            "appliance-chmotor-16p-310v",
            &["stops", "regen-stop"][..],
            &[1, 2][..],
        ),
    ] {
        for scenario in scenarios {
            for &seed in seeds {
                missed.extend(calibrated_miss(name, scenario, seed));
            }
        }
    }
    assert!(missed.is_empty(), "missed: {missed:?}");
}

/// The appliance motor at seeds 3 and 4: its start-up calibration measures the sensors' gain
/// mismatch with the rotor still. Its motion test's reference at the current loop's first
/// step to the lower level leaves out the drive's modelled inverter part, which at zero
/// current is one sample of sensor noise through the 310 V inverter's band (3.9 V over
/// 0.3 A); taken in, it reads as motion 0.6 ms into the step at these seeds and the mismatch
/// stays (`stops` 0.442 rad, `rated-reversal` 0.263 rad, `regen-stop` 0.465 rad). Measured:
/// `stops` 0.040 rad and `rated-reversal` 0.008 rad (seed 3), `regen-stop` 0.046 rad (seed 4).
#[test]
fn the_appliance_motor_calibrates_at_every_seed() {
    let mut missed = Vec::new();
    for (scenario, seed) in [("stops", 3), ("rated-reversal", 3), ("regen-stop", 4)] {
        missed.extend(calibrated_miss(
            "appliance-chmotor-16p-310v",
            scenario,
            seed,
        ));
    }
    assert!(missed.is_empty(), "missed: {missed:?}");
}

/// `scenario` on machine `name` at the current sensors' noise `seed`, printed: a miss where it
/// fails or its start-up gain calibration ends other than `Calibrated`.
fn calibrated_miss(name: &str, scenario: &str, seed: u64) -> Option<String> {
    let text = format!("{}\n[current_sensor]\nseed = {seed}\n", file(name));
    let out = simulate(scenario, Some(&text), false, None).unwrap();
    let status = out.startup.gain_calibration.clone().unwrap_or_default();
    eprintln!(
        "{name} {scenario} seed {seed}: {:.3} rad, calibration {status}",
        out.metrics.max_angle_error
    );
    (!out.passed || status != "Calibrated")
        .then(|| format!("{name} {scenario} seed {seed} ({status})"))
}

/// The light rotors under the rated gravity-like load at the brake's release: the servo's
/// bare rotor (rated torque to rated speed in 7.7 ms) and the tool motor, whose release holds
/// are capped by the 10 kHz sampling below their design stiffness (servo ω_h 350 of 470
/// rad/s): they trigger on the direct angle and start their integral from the load the fall
/// reveals (`fado_core::control::release_hold`, "The load the fall reveals"). The servo's
/// rotor falls by the trigger's 0.02 rad within 0.49 ms of the release, 1.72 time constants
/// of its current loop (557 Hz, 1/ωc = 0.29 ms), by which the release's d-current floor
/// raised at the opening is in time; a rotor whose fall is faster than 1.5/ωc gets the floor
/// while the brake still holds it (`fado_core::control::SensorlessDrive::arm_release_hold`). Measured (backward travel, |θ − θ̂| from ready, rad): the servo at
/// seeds 1 / 2 / 3 / 4 0.255 / 0.312 / 0.261 / 0.259 and 0.064 / 0.067 / 0.069 / 0.064 with
/// its current loop at the hold's cap ωc·Ts = 0.35 (557 Hz; the floor raised at the opening
/// is then in time); with the loop at ωc·Ts = 0.2 (318 Hz) and the floor at the brake
/// 0.447 / 0.458 / 0.451 / 0.440 and 0.051 / 0.063 / 0.074 / 0.053 (seed 2
/// 0.863 with the floor raised at the opening: the phase across θ̂ inside the dead-time band,
/// the direct angle 0.022 rad behind a 0.045 rad fall at the trigger, the load read 1.37 A of
/// 3.4 A; 1.28 back at seed 1 without the fall's preset; the criterion's 0.5); the tool motor
/// at seed 2 0.264 and 0.126 (0.2516 without; 0.25 allowed).
#[test]
fn the_light_rotors_lift_their_load_from_the_brake() {
    let mut missed = Vec::new();
    for (name, seed) in [
        ("servo-estun-emj04-400w-310v", 1),
        ("servo-estun-emj04-400w-310v", 2),
        ("servo-estun-emj04-400w-310v", 3),
        ("servo-estun-emj04-400w-310v", 4),
        ("tool-makita-4p-36v", 2),
    ] {
        if !run(name, "loaded-start", seed, "").0 {
            missed.push(format!("{name} loaded-start seed {seed}"));
        }
    }
    assert!(missed.is_empty(), "missed: {missed:?}");
}

/// The speed error of `regen-stop`'s held stop under the overhauling load (7–8 s, r/min) on
/// machine `name` at `seed` with the `extra` keys, and whether the run passed.
fn held_stop_speed_error(name: &str, seed: u64, extra: &str) -> (f64, bool) {
    let text = format!("{}\n[current_sensor]\nseed = {seed}\n{extra}", file(name));
    let out = simulate("regen-stop", Some(&text), false, None).unwrap();
    let check = out
        .checks
        .iter()
        .find(|c| c.name.starts_with("speed error at 0 r/min, 7.0"))
        .unwrap();
    eprintln!(
        "{name} regen-stop seed {seed} {extra:?}: held stop {:.1} r/min",
        check.value
    );
    (check.value, out.passed)
}

/// The servo's bare rotor at `regen-stop`, held at zero under the overhauling rated load: the
/// loaded-standstill probe's d-current square wave is a torque through the angle error δ,
/// b·A·sin δ (b = 1.5·p²·λ̂f/Ĵ = 4.8·10⁴ rad/s² per A), which this rotor (rated torque to
/// rated speed in 7.7 ms) follows against its 11 Hz speed loop. At the configured amplitude
/// (±0.34 A) and δ ≈ 0.1 rad it swings between −38 and +81 r/min; the amplitude that follows
/// the rotor's answer (`fado_core::control::standstill_probe::amplitude`) holds the swing.
/// Measured, speed error over 7–8 s at seeds 1 / 2 / 3 / 4: 16.9 / 16.9 / 3.1 / 11.1 r/min
/// (60 allowed); with the amplitude fixed (`swing_ratio = 0`) 76.5 / 42.3 / 14.0 / 25.1.
#[test]
fn the_servo_rotor_holds_its_regenerating_stop() {
    let name = "servo-estun-emj04-400w-310v";
    for seed in 1..=4 {
        let (error, passed) = held_stop_speed_error(name, seed, "");
        assert!(passed && error < 30.0, "seed {seed}: {error:.1} r/min");
    }
    let fixed = "[controller.standstill_probe]\nswing_ratio = 0\n";
    let (error, passed) = held_stop_speed_error(name, 1, fixed);
    assert!(
        !passed && error > 60.0,
        "the case needs the rule: {error:.1} r/min"
    );
}

/// The servo commissions with its bare rotor (seed 1; rated torque reaches rated speed in
/// 7.7 ms): Ĵ within the 10 % and λ̂f within the 2 % the presets are held to, and its
/// identified model passes `reversal`. At 10 % of the current limit (the steps' usual floor)
/// the inertia test's step lasted 46 ms, inside its 30 ms settling and 40 ms windows
/// (`Implausible { Inertia }`); its steps are sized to last 0.25 s on the nameplate inertia
/// (0.03 A, eight current resolutions at least) and hold the coast's d current, which keeps
/// the PLL out of the inverter's dead-time band, with the PLL's lag under the acceleration
/// added back to Ĵ; that d current is 0.26 of the limit (0.5 elsewhere), so that the rotor's
/// inertia is three times what the PLL's lag takes from it. Measured, seeds 1 / 2 / 3:
/// Ĵ −1.21 / −1.10 / −1.15 %, λ̂f −1.40 / −1.41 / −1.39 %, B̂ +14 / +15 / +14 %.
#[test]
fn a_400_w_servo_with_its_bare_rotor_commissions() {
    let name = "servo-estun-emj04-400w-310v";
    let (m, truth) = commissioned_reversal(name);
    let j = m.inertia / truth.inertia - 1.0;
    let flux = m.flux_linkage / truth.flux_linkage - 1.0;
    eprintln!("{name}: J {:+.2} %, λf {:+.2} %", 100.0 * j, 100.0 * flux);
    assert!(j.abs() < 0.10, "{name}: J {j:+.4}");
    assert!(flux.abs() < 0.02, "{name}: λf {flux:+.4}");
}

/// The servo's bare rotor read through a current sensor of ten times the default noise
/// (0.46 % of the rated current rms): the smallest torque step, eight resolutions, takes the
/// rotor up by 840 r/min in 72 ms, and the procedure aborts naming it (`RotorTooLight`, the
/// steps' 110 ms needed); at five times the noise it commissions (Ĵ −0.09 %, λ̂f −1.26 %).
#[test]
fn a_400_w_servo_behind_a_coarse_current_sensor_aborts_naming_its_light_rotor() {
    let name = "servo-estun-emj04-400w-310v";
    let text = format!(
        "{}\n[current_sensor]\nnoise_rms_ratio = 0.0046\n",
        file(name)
    );
    let plant = fado_sim::SimConfig::from_toml(&text).unwrap().plant();
    let o = commission_on_own_nameplate(&plant).unwrap();
    let Status::Aborted(reason) = o.status else {
        panic!("{name}: {:?}", o.status);
    };
    let message = reason.to_string();
    eprintln!("{name}: {message}");
    assert!(
        matches!(reason, AbortReason::RotorTooLight { .. }),
        "{name}: {reason:?}"
    );
    assert!(message.contains("too light"), "{message}");
}

/// The servo's plant with a 1.5e-5 kg·m² rotor (half its own): its friction (4.0e-5 N·m·s)
/// slows the coast from its 600 r/min to 129 r/min (below a quarter) within 229 ms, before the
/// 270 ms of the back-EMF window end, and the procedure aborts naming it (`RotorTooLight` in
/// the coast: 471 r/min lost).
#[test]
fn a_servo_rotor_too_light_against_its_friction_aborts_naming_its_coast() {
    let name = "servo-estun-emj04-400w-310v";
    let text = file(name).replace("inertia = 3.1e-5", "inertia = 1.5e-5");
    let plant = fado_sim::SimConfig::from_toml(&text).unwrap().plant();
    assert_eq!(plant.motor.inertia, 1.5e-5);
    let o = commission_on_own_nameplate(&plant).unwrap();
    let Status::Aborted(reason) = o.status else {
        panic!("{name}: {:?}", o.status);
    };
    eprintln!("{name} at 1.5e-5 kg·m²: {reason}");
    assert!(
        matches!(
            reason,
            AbortReason::RotorTooLight {
                phase: Phase::Coast,
                ..
            }
        ),
        "{name}: {reason:?}"
    );
}
