//! Fast, low-inductance multirotor motors entered from their datasheets with only the required
//! keys and the ESC's PWM frequency (every other value derived from the ratings), closed loop:
//! `reversal` and `stops` pass, and a throttle step at the current limit keeps the angle.

use fado_sim::scenario::simulate;

/// T-Motor MN5006 KV300 (the 24N28P stator of the `multirotor-mn5006-22v` preset wound for
/// KV300): 0.125 Ω line to line, 20 A battery current from 6S; λf = 5.513/(14·300); rated
/// phase current 444 W/(1.5·11.5 V·0.96) = 26.8 A; rated speed where 0.739 N·m absorbs the
/// 444 W less 67 W of copper loss, 4800 r/min; L estimated as the preset's (L·I/λf = 0.3).
const MN5006_KV300: &str = "[motor]\nrs = 0.0625\nld = 14.7e-6\nlq = 14.7e-6\n\
    flux_linkage = 1.3126e-3\npole_pairs = 14\nrated_current = 26.8\nrated_speed_rpm = 4800.0\n\
    rated_torque = 0.739\n[inverter]\nswitching_frequency = 24000.0\n";

/// Turnigy Multistar 4225-610Kv: 16 poles, 0.120 Ω line to line, 25 A on 4S (14.8 V);
/// λf = 5.513/(8·610); rated phase current 370 W/(1.5·7.7 V·0.96) = 33.4 A; rated speed where
/// 0.453 N·m absorbs 370 W less 100 W of copper loss, 5700 r/min; L estimated (L·I/λf = 0.3).
const MULTISTAR_4225: &str = "[motor]\nrs = 0.060\nld = 10.1e-6\nlq = 10.1e-6\n\
    flux_linkage = 1.1297e-3\npole_pairs = 8\nrated_current = 33.4\nrated_speed_rpm = 5700.0\n\
    rated_torque = 0.453\n[inverter]\nswitching_frequency = 24000.0\n";

/// A 6215-size KV170 outrunner (14 pole pairs) with the resistance and inductances a VESC
/// measured on it (70 mΩ, Ld 15 µH, Lq 22 µH); λf = 5.513/(14·170); ratings assumed for 12S:
/// 40 A peak, 6000 r/min (80 % of the no-load speed at 44.4 V), 1.95 N·m.
const OUTRUNNER_6215: &str = "[motor]\nrs = 0.070\nld = 15e-6\nlq = 22e-6\n\
    flux_linkage = 2.3164e-3\npole_pairs = 14\nrated_current = 40.0\nrated_speed_rpm = 6000.0\n\
    rated_torque = 1.95\n[inverter]\nswitching_frequency = 30000.0\n";

fn worst_angle(scenario: &str, motor: &str) -> f64 {
    let out = simulate(scenario, Some(motor), false, None).unwrap();
    assert!(out.passed, "{scenario}: {:?}", out.checks);
    match scenario {
        "reversal" => out.metrics.max_angle_error_zero_speed,
        _ => out.metrics.max_angle_error,
    }
}

#[test]
fn multirotor_motors_from_their_datasheets_pass_the_reversal_and_the_stops() {
    // Measured (seed 1, switching-resolved): MN5006 KV300 0.025 / 0.046 rad, Multistar 4225
    // 0.013 / 0.208 rad (its trackers' lag at the current limit is below the 2 rad of the
    // feed-forward rule; 0.145 rad with the feed-forward), 6215 KV170 0.033 / 0.022 rad.
    // Bound: the scenarios' own 0.25 rad.
    for (name, motor) in [
        ("MN5006 KV300", MN5006_KV300),
        ("Multistar 4225", MULTISTAR_4225),
        ("6215 KV170", OUTRUNNER_6215),
    ] {
        for scenario in ["reversal", "stops"] {
            let e = worst_angle(scenario, motor);
            println!("{name} {scenario}: {e:.3} rad");
            assert!(e < 0.25, "{name} {scenario}: {e}");
        }
    }
}

#[test]
fn a_propeller_s_inertia_leaves_the_sensor_gain_calibrated() {
    // With its 15-inch propeller (3.4e-4 kg·m², 4 swing time constants 0.36 s) the motor's
    // sensor gain mismatch is still measured (1.25 time constants); skipped, it walked θ̂ at
    // 3 rad/s through the stops (0.47 rad on the MN5006 KV450).
    let motor = MN5006_KV300.replace("[inverter]", "inertia = 3.4e-4\n[inverter]");
    let e = worst_angle("stops", &motor);
    assert!(e < 0.2, "{e}");
}

#[test]
fn a_throttle_step_at_the_current_limit_keeps_the_angle() {
    // 0 → 6000 r/min as a step: the speed loop asks for the current limit; with the paper's
    // type-2 trackers the angle lagged by 2.1 rad, the drive's feed-forward keeps it.
    let preset = fado_sim::presets::find("multirotor-mn5006-22v")
        .unwrap()
        .toml;
    let text = format!(
        "{preset}\n[simulation]\nduration = 1.6\neval_start = 0.7\n\
         [speed_reference]\npoints = [[0.0, 0.0], [0.8, 0.0], [0.801, 6000.0]]\n\
         [criteria]\nmax_angle_error = 0.25\nno_trip = true\n"
    );
    let out = simulate("custom", Some(&text), false, None).unwrap();
    assert!(out.passed, "{:?}", out.checks);
    let off = format!("{text}\n[controller.tracker_feedforward]\nmax_lag = 1e300\n");
    let out = simulate("custom", Some(&off), false, None).unwrap();
    assert!(
        out.metrics.max_angle_error > 1.0,
        "{}",
        out.metrics.max_angle_error
    );
}

/// max |θ − θ̂| of a rated load step (0 → T_rated in one sample at 1.5 s) at 80 % of the rated
/// speed, reached at the current limit from standstill, on `motor` with `extra` appended.
fn load_step_error(motor: &str, rated_rpm: f64, rated_torque: f64, extra: &str) -> f64 {
    let n = 0.8 * rated_rpm;
    let text = format!(
        "{motor}\n[simulation]\nduration = 1.8\neval_start = 0.7\n\
         [speed_reference]\npoints = [[0.0, 0.0], [0.6, 0.0], [0.601, {n}]]\n\
         [load.torque]\npoints = [[1.5, 0.0], [1.5, {rated_torque}]]\n\
         [criteria]\nno_trip = true\n{extra}"
    );
    let out = simulate("custom", Some(&text), false, None).unwrap();
    assert!(out.passed, "{:?}", out.checks);
    out.metrics.max_angle_error
}

#[test]
fn a_rated_load_step_on_a_light_rotor_keeps_the_angle() {
    // The drive's acceleration feed-forward cannot announce the load: a step of the rated
    // torque decelerates the cheetah outrunner at 5.5e4 rad/s² electrical, the 6215 KV170
    // (inertia from its ratings) at 5.6e4. In the paper's 60 Hz T2S-1 that peaks near
    // κ·α/ωn² = 0.5·5.5e4/183² = 0.82 rad; the drive's running bandwidth (the tracker
    // feed-forward rule: a rated step within 0.2 rad) keeps it there. Bound: the range
    // scenarios' 0.25 rad; the paper's bandwidth is shown to lose more than twice it.
    let cheetah = fado_sim::presets::find("outrunner-cheetah-24v")
        .unwrap()
        .toml;
    let off = "[controller.tracker_feedforward]\nload_step_error = 1e9\n";
    for (name, motor, rpm, torque) in [
        ("cheetah", cheetah, 1800.0, 1.32),
        ("6215 KV170", OUTRUNNER_6215, 6000.0, 1.95),
    ] {
        let on = load_step_error(motor, rpm, torque, "");
        let paper = load_step_error(motor, rpm, torque, off);
        println!("{name}: {on:.3} rad (60 Hz T2S-1: {paper:.3} rad)");
        assert!(on < 0.25, "{name}: {on}");
        assert!(paper > 0.5, "{name}: {paper}");
    }
}
