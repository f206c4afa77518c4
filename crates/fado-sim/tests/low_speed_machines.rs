//! The ratings-scaled low-speed scenarios on made-up machines of other classes than the
//! presets (switching-resolved, default non-idealities, current-sensor seed 1):
//!
//! - a 48 V, 7-pole-pair motor of 1.2·10⁻⁴ kg·m² (τm = 22 ms) through `reversal`: the speed
//!   loop's bandwidth of its load ramp (`fado_core::control::speed_bandwidth`, 6.7 Hz) holds
//!   the speed within 2 % of the rated speed once the load is in; with the paper's 5 Hz the
//!   ramp leaves it 1,200 r/min off and 139 r/min still at the check;
//! - a 32-pole 150 r/min interior-magnet torque motor on a 560 V link through `stops` and
//!   `reversal`: no phase current inside the dead-time band near zero speed
//!   (`fado_core::control::phase_band`) keeps the stop under 65 % of the rated torque within
//!   0.25 rad and 2 % of the rated speed; through `rated-reversal` its speed is judged from
//!   where its 5 Hz loop has settled the rated load's 0.5 s ramp (2.05 s,
//!   `fado_sim::scenario`'s load settling: the ramp leaves 25 % of its rated speed, 38 r/min,
//!   and a faster loop loses the angle), where it is within 2 % of the rated speed. Its
//!   start-up gain calibration would take 0.79 s, beyond the drive's 0.7 s budget
//!   (`gain_calibration_max_time` in `fado_core::control::drive`), and is not run: ready at
//!   0.1 s, it takes the load of `stops` (from 0.9 s) within 0.25 rad.

use fado_sim::scenario::simulate;

const FAST_48V: &str = include_str!("data/startup-fast-48v.toml");
const TORQUE_32P: &str = include_str!("data/torque-ipm-32p.toml");

fn run(motor: &str, scenario: &str, extra: &str) -> (f64, f64, bool) {
    run_seed(motor, scenario, extra, 1)
}

fn run_seed(motor: &str, scenario: &str, extra: &str, seed: u64) -> (f64, f64, bool) {
    let text = format!("{motor}\n[current_sensor]\nseed = {seed}\n{extra}");
    let out = simulate(scenario, Some(&text), false, None).unwrap();
    let m = &out.metrics;
    println!(
        "{scenario}: {:.3} rad, {:.1} r/min, passed {}",
        m.max_angle_error, m.max_speed_error_rpm, out.passed
    );
    (m.max_angle_error, m.max_speed_error_rpm, out.passed)
}

#[test]
fn a_light_rotor_holds_its_speed_through_the_load_ramp() {
    let (angle, speed, passed) = run(FAST_48V, "reversal", "");
    assert!(
        passed && angle < 0.25 && speed < 80.0,
        "{angle} rad, {speed} r/min"
    );
    // The ramp's rule off: the step's rule leaves the paper's 5 Hz.
    let (_, speed, passed) = run(
        FAST_48V,
        "reversal",
        "[controller.speed]\nload_ramp_error_ratio = 1e9\n",
    );
    assert!(
        !passed && speed > 80.0,
        "the case does not need the rule: {speed} r/min"
    );
}

#[test]
fn a_slow_torque_motor_holds_its_loaded_reversal() {
    let (angle, speed, passed) = run(TORQUE_32P, "reversal", "");
    assert!(
        passed && angle < 0.25 && speed < 3.0,
        "reversal: {angle} rad, {speed} r/min"
    );
}

/// The torque motor's start-up gain calibration would take 0.79 s on its free rotor: the
/// settling at I₁ and the release to zero 5·L̂d/R̂s = 0.1 s each, both levels held 0.2 s (its
/// swing's 4τ = 0.24 s cut to the hold budget) and averaged over the window traded for the
/// rest of the swing (0.1 s at its start axis). Beyond the drive's 0.7 s budget it is not run
/// (`TooSlow`, the ratio learned online): the drive is ready at 0.1 s, the standstill's DC test
/// has learned R̂s (0.1492 Ω) by the load, and `stops` reads 0.151–0.155 rad and
/// 1.46–1.52 r/min at seeds 1–4. Run to its end, the calibration ends `RotorMoved` in its
/// release at 0.89–0.93 s, 6 ms before `stops` applies its load (from 0.9006 s), with the
/// speed reference already at its 6 r/min, and the run loses the angle at seeds 1–3
/// (2.43/3.14/2.58 rad): the release hold engaged at its design ω_h (93 rad/s) rings at 94 Hz
/// on the direct angle's relay-like step at each sign change of i_q (δ = 0.017–0.018 rad, from
/// the inverter's dead time), and without the hold the loaded zero-speed crossing stalls on
/// R̂s 0.8 % above the plant's. With the current loop's two stages at 5/ωc (3.2 ms) it still
/// takes 0.67 s and `stops` reads 0.25/1.94/2.21/3.10 rad.
///
/// `rated-reversal`, judged from where its 5 Hz loop has settled the rated load's ramp, reads
/// 0.107–0.118 rad and 1.63–1.65 r/min at seeds 1–4.
#[test]
fn a_slow_torque_motor_holds_its_loaded_stops_and_rated_reversal() {
    let (angle, speed, passed) = run(TORQUE_32P, "stops", "");
    assert!(
        passed && angle < 0.25 && speed < 3.0,
        "stops: {angle} rad, {speed} r/min"
    );
    for seed in 1..=4 {
        let (angle, speed, passed) = run_seed(TORQUE_32P, "rated-reversal", "", seed);
        assert!(
            passed && angle < 0.25 && speed < 3.0,
            "seed {seed}: {angle} rad, {speed} r/min"
        );
    }
}
