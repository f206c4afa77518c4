//! Tests of [`super`]: the calibration on standstill RL machines.

use super::*;

const TS: f64 = 1e-4;

fn config(current: f64, r: f64, l: f64) -> GainCalibrationConfig<f64> {
    GainCalibrationConfig {
        ts: TS,
        current,
        rs_hat: r,
        settle_time: 5.0 * l / r,
        hold_time: 5.0 * l / r,
        max_hold_time: 0.2,
        window_time: 0.05,
        swing_window_time: 0.0,
        min_observability: DEFAULT_MIN_OBSERVABILITY,
        max_mismatch: DEFAULT_MAX_MISMATCH,
        current_limit: 2.5 * current,
        lq_hat: 1e-3,
        max_time: f64::INFINITY,
        motion_voltage: f64::INFINITY,
    }
}

/// Runs the calibration on a standstill RL machine (R, L per phase, exact discretisation)
/// behind an inverter whose pole voltages fall short by `v_err`·sign(i_x) (dead time and
/// device drop, docs/method/estimator.md §7, without its band), sensed with gains (1 + ga, 1 + gb) on phases a
/// and b (c = −a − b), under a PI current loop in the calibration's axis frame. Returns the
/// calibration, the largest true current and the samples taken.
fn run(angle: f64, ga: f64, gb: f64, v_err: f64) -> (GainCalibration<f64>, f64, u32) {
    run_sensed(angle, ga, gb, v_err, f64::INFINITY, 0.0)
}

/// The sign of a phase current, zero at zero (the direction a pole's voltage error takes).
fn current_sign(x: f64) -> f64 {
    if x == 0.0 { 0.0 } else { x.signum() }
}

/// [`run`] with the rotor-motion test at `motion_voltage` (V) and the phase currents read in
/// steps of `lsb` (A; 0: exact).
fn run_sensed(
    angle: f64,
    ga: f64,
    gb: f64,
    v_err: f64,
    motion_voltage: f64,
    lsb: f64,
) -> (GainCalibration<f64>, f64, u32) {
    let (r, l) = (0.3, 3e-3);
    let mut cal = GainCalibration::new(GainCalibrationConfig {
        motion_voltage,
        lq_hat: l,
        ..config(8.0, r, l)
    })
    .unwrap();
    // Uniform noise of ±LSB/2 ahead of the steps (a 64-bit xorshift), which dithers them.
    let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut quantise = |x: f64| {
        if lsb > 0.0 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let u = (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            ((x + u * lsb) / lsb).round() * lsb
        } else {
            x
        }
    };
    let decay = (-r * TS / l).exp();
    let (kp, ki) = (
        l * 2.0 * core::f64::consts::PI * 250.0,
        r * 2.0 * core::f64::consts::PI * 250.0,
    );
    let (s, c) = angle.sin_cos();
    let to_axis = |x: Ab<f64>| (x.alpha * c + x.beta * s, -x.alpha * s + x.beta * c);
    let mut i: Ab<f64> = Ab::zero();
    let mut v_prev: Ab<f64> = Ab::zero();
    let mut integral = (0.0, 0.0);
    let mut peak: f64 = 0.0;
    let mut n = 0;
    cal.start(angle);
    while cal.running() && n < 100_000 {
        // Sensors.
        let abc = i.to_abc();
        let (a, b) = (quantise((1.0 + ga) * abc.a), quantise((1.0 + gb) * abc.b));
        let meas = crate::Abc::new(a, b, -a - b).to_ab();
        let cmd = cal.step(meas, v_prev);
        let v = match cmd.voltage {
            Some(v) => v,
            None => {
                let (d, q) = to_axis(meas);
                let (ed, eq) = (cmd.current_d - d, -q);
                integral = (integral.0 + ki * TS * ed, integral.1 + ki * TS * eq);
                let (vd, vq) = (kp * ed + integral.0, kp * eq + integral.1);
                Ab::new(vd * c - vq * s, vd * s + vq * c)
            }
        };
        // Inverter: every pole falls short by v_err in the direction of its current.
        let u = crate::Abc::new(
            -v_err * current_sign(abc.a),
            -v_err * current_sign(abc.b),
            -v_err * current_sign(abc.c),
        )
        .to_ab();
        let applied = v + u;
        i = i * decay + applied * ((1.0 - decay) / r);
        v_prev = v;
        peak = peak.max(i.norm());
        n += 1;
    }
    (cal, peak, n)
}

/// A machine at rest whose sensors read in 20 mA steps, dithered by ±10 mA of noise, each
/// step L̂q·LSB/1 ms = 0.9 of `motion_voltage` through the motion test's inductive term: the
/// settled loop's inductive reading sets the voltage-mode threshold's floor (0.142 V over
/// 0.067 V) and the calibration ends `Calibrated`; without the floor the voltage mode reads
/// 1.30 of `motion_voltage` and ends it `RotorMoved`. (At 0.3, 1 and 2 rad this synthetic PI
/// loop's quantised current reads 1.00–1.08 of the loop's window threshold, which the floor
/// does not cover: as the appliance motor's seeds 3 and 4 in
/// `crates/fado-sim/tests/unseen_motor_tables.rs`.)
#[test]
fn sensor_steps_at_rest_are_not_read_as_motion() {
    let lsb = 0.02;
    let motion_voltage = 3e-3 * lsb / MOTION_FILTER_TIME / 0.9;
    let angle = 0.0;
    let (cal, _, _) = run_sensed(angle, 0.005, 0.0, 1.5, motion_voltage, lsb);
    assert_eq!(
        cal.status(),
        GainCalibrationStatus::Calibrated,
        "{angle}: floor {} V, threshold {motion_voltage} V, peaks {} {} {}",
        cal.motion_noise_floor(),
        cal.motion_peak(),
        cal.loop_motion_peak(),
        cal.loop_window_peak()
    );
    assert!(
        cal.motion_noise_floor() > motion_voltage && cal.motion_peak() < 1.0,
        "{angle}: floor {} V over {motion_voltage} V, peak {}",
        cal.motion_noise_floor(),
        cal.motion_peak()
    );
}

#[test]
fn the_mismatch_is_identified_at_observable_angles() {
    for angle in [0.0, 0.3, 1.0, 2.0, -2.0, 3.0, -1.2] {
        for (ga, gb) in [(0.005, 0.0), (-0.01, 0.02), (0.0, 0.0), (0.03, -0.01)] {
            let (cal, peak, n) = run(angle, ga, gb, 1.5);
            let k_true = (1.0 + ga) / (1.0 + gb);
            assert_eq!(
                cal.status(),
                GainCalibrationStatus::Calibrated,
                "{angle} {ga} {gb}"
            );
            // Noise-free and purely resistive at DC: exact but for the settling residue.
            assert!(
                (cal.ratio() - k_true).abs() < 1e-5,
                "θ {angle}: k {} against {k_true}",
                cal.ratio()
            );
            // The resistance, as phase b's sensor sees it (the common gain is not
            // observable), with the inverter's 1.5 V error cancelled between the levels.
            // Unlike k (a ratio of two phases settling alike), R keeps the settling
            // residue: the step to the upper level decays as e^(−t/τ), τ = L/R = 10 ms,
            // so after a 5τ hold the window of 50 ms = 5τ averages e^(−5)·(1 − e^(−5))/5
            // ≈ 1.3e-3 of the step (measured 1.3e-3 at θ 0).
            let r_seen = 0.3 / (1.0 + gb);
            assert!(
                (cal.resistance() - r_seen).abs() < 1.5e-3 * r_seen,
                "θ {angle}: R {} against {r_seen}",
                cal.resistance()
            );
            assert!(peak <= cal.config().current_limit, "{peak}");
            assert!(n <= cal.duration_samples() + 1, "{n}");
        }
    }
}

#[test]
fn an_unobservable_axis_is_skipped_without_current() {
    // Phase a null at ±π/2, phase b null at π/6 and −5π/6, phase c null at −π/6, 5π/6.
    let pi = core::f64::consts::PI;
    for angle in [
        pi / 2.0,
        -pi / 2.0,
        pi / 6.0,
        -5.0 * pi / 6.0,
        -pi / 6.0,
        5.0 * pi / 6.0,
    ] {
        let (cal, peak, n) = run(angle + 0.05, 0.005, 0.0, 1.5);
        assert_eq!(cal.status(), GainCalibrationStatus::Unobservable, "{angle}");
        assert_eq!((peak, n), (0.0, 0));
        assert_eq!(cal.ratio(), 1.0);
    }
    assert!((GainCalibration::<f64>::observability(0.0) - 0.5).abs() < 1e-12);
}

#[test]
fn a_large_mismatch_is_refused_and_the_ratio_kept() {
    let (cal, _, _) = run(0.3, 0.08, 0.0, 1.5);
    assert_eq!(cal.status(), GainCalibrationStatus::Implausible);
    assert!((cal.measured_ratio() - 1.08).abs() < 1e-4);
    assert_eq!(cal.ratio(), 1.0);
}

#[test]
fn non_finite_samples_are_left_out_and_the_sequence_ends() {
    let mut cal = GainCalibration::new(config(8.0, 0.3, 3e-3)).unwrap();
    cal.start(0.3);
    let mut n = 0;
    while cal.running() {
        let cmd = cal.step(Ab::new(f64::NAN, 0.0), Ab::new(f64::INFINITY, 0.0));
        assert!(cmd.current_d.is_finite() && cmd.current_d <= 16.0);
        n += 1;
    }
    assert_eq!(n, cal.duration_samples());
    assert_eq!(cal.status(), GainCalibrationStatus::Implausible);
    assert_eq!(cal.ratio(), 1.0);
}

#[test]
fn too_slow_a_swing_or_a_zero_window_skips() {
    let mut c = config(8.0, 0.3, 3e-3);
    c.hold_time = 0.3;
    let mut cal = GainCalibration::new(c).unwrap();
    assert!(!cal.start(0.3));
    assert_eq!(cal.status(), GainCalibrationStatus::TooSlow);
    c.window_time = 0.0;
    let cal = GainCalibration::new(c).unwrap();
    assert_eq!(cal.status(), GainCalibrationStatus::Off);
    assert!(!cal.running());
}

#[test]
fn a_sequence_beyond_its_time_budget_skips() {
    // (R, L) = (0.3 Ω, 3 mH): settle, hold and window of 50 ms each, 0.3 s in all.
    let mut c = config(8.0, 0.3, 3e-3);
    c.max_time = 0.3;
    let mut cal = GainCalibration::new(c).unwrap();
    assert_eq!(cal.duration_samples(), 3000);
    assert!(cal.start(0.3));
    // A swing's window of 0.15 s along the axis at φ = 0.3 rad (shares 0.955, 0.222) makes it
    // 0.2 s longer, and a hold of 0.1 s along the axis 0.1 s: beyond it, not run.
    c.swing_window_time = 0.15 / cal.swing_window_share(0.3);
    let mut cal = GainCalibration::new(c).unwrap();
    assert!(!cal.start(0.3));
    assert_eq!(cal.status(), GainCalibrationStatus::TooSlow);
    let unbounded = GainCalibrationConfig {
        max_time: f64::INFINITY,
        ..c
    };
    assert!(GainCalibration::new(unbounded).unwrap().start(0.3));
    c.swing_window_time = 0.0;
    let mut cal = GainCalibration::new(c).unwrap();
    assert!(!cal.start_with_hold(0.3, 0.1));
    assert_eq!(cal.status(), GainCalibrationStatus::TooSlow);
    c.max_time = f64::NAN;
    assert!(GainCalibration::new(c).is_err());
}

#[test]
fn a_longer_hold_lengthens_one_calibration_and_beyond_the_budget_measures_k_only() {
    // (R, L) = (0.3 Ω, 3 mH): each level held 5·L/R = 50 ms. Along an axis of twice the
    // inductance the caller asks 100 ms: two holds longer by 50 ms each; 0.3 s (beyond the
    // 0.2 s budget) holds 0.2 s; a plain start afterwards holds 50 ms again.
    let mut cal = GainCalibration::new(config(8.0, 0.3, 3e-3)).unwrap();
    let base = cal.duration_samples();
    assert!(cal.start_with_hold(0.0, 0.1));
    assert_eq!(cal.duration_samples(), base + 1000);
    assert!(cal.start_with_hold(0.0, 0.3));
    assert_eq!(cal.duration_samples(), base + 3000);
    assert!(!cal.start_with_hold(0.0, f64::NAN));
    assert_eq!(cal.status(), GainCalibrationStatus::TooSlow);
    assert!(cal.start(0.0));
    assert_eq!(cal.duration_samples(), base);
    // A shorter hold than the configured one keeps the configured one.
    assert!(cal.start_with_hold(0.0, 0.01));
    assert_eq!(cal.duration_samples(), base);
}

#[test]
fn f32_identifies_the_mismatch_too() {
    let mut cal = GainCalibration::<f32>::new(GainCalibrationConfig {
        ts: 1e-4,
        current: 8.0,
        rs_hat: 0.3,
        settle_time: 0.05,
        hold_time: 0.05,
        max_hold_time: 0.2,
        window_time: 0.05,
        swing_window_time: 0.0,
        min_observability: 0.2,
        max_mismatch: 0.05,
        current_limit: 20.0,
        lq_hat: 1e-3,
        max_time: f32::INFINITY,
        motion_voltage: f32::INFINITY,
    })
    .unwrap();
    // A resistive machine with no dynamics behind an ideal current loop: the current is
    // the last voltage over R, phase a read 0.5 % high.
    let (sin, cos) = (1.0f32).sin_cos();
    let mut v = Ab::zero();
    cal.start(1.0);
    while cal.running() {
        let i = (v * (1.0 / 0.3)).to_abc();
        let a = 1.005 * i.a;
        let meas = crate::Abc::new(a, i.b, -a - i.b).to_ab();
        let cmd = cal.step(meas, v);
        v = cmd
            .voltage
            .unwrap_or(Ab::new(cos, sin) * (0.3 * cmd.current_d));
    }
    assert_eq!(cal.status(), GainCalibrationStatus::Calibrated);
    assert!((cal.ratio() - 1.005).abs() < 2e-5, "{}", cal.ratio());
}

/// Feeds the calibration a resistive machine (the current is the last voltage over R)
/// whose rotor, from `turn_at` s, turns at `omega` (electrical rad/s): its back-EMF
/// ω·λf across the axis drives a current towards −ω·λf/R there through L = 3 mH
/// (λf 0.1 Wb). Returns the calibration.
fn turning_rotor(omega: f64, turn_at: f64) -> GainCalibration<f64> {
    rotor_with_emf(|t| if t >= turn_at { omega * 0.1 } else { 0.0 })
}

/// [`turning_rotor`]'s machine with the back-EMF `emf(t)` (V) across the axis.
fn rotor_with_emf(emf: impl Fn(f64) -> f64) -> GainCalibration<f64> {
    let r = 0.3;
    let mut c = config(8.0, r, 3e-3);
    // 1 % of 300 rad/s electrical on a 0.1 Wb magnet.
    c.motion_voltage = 0.01 * 300.0 * 0.1;
    c.lq_hat = 3e-3;
    let mut cal = GainCalibration::new(c).unwrap();
    let axis = Ab::new(1.0, 0.0);
    let mut v: Ab<f64> = Ab::zero();
    // The back-EMF's current across the axis, through L/R = 10 ms (exact step).
    let (mut i_emf, decay) = (0.0, (-TS / 0.01f64).exp());
    let mut n = 0u32;
    cal.start(0.0);
    while cal.running() {
        let emf = emf(n as f64 * TS);
        i_emf = decay * i_emf + (1.0 - decay) * (-emf / r);
        // A small steady offset across the axis (the sensors' mismatch) at rest.
        let i = v * (1.0 / r) + axis.mul_j() * (0.02 + i_emf);
        let cmd = cal.step(i, v);
        v = cmd.voltage.unwrap_or(axis * (r * cmd.current_d));
        n += 1;
    }
    cal
}

fn with_turning_rotor(omega: f64, turn_at: f64) -> GainCalibrationStatus {
    turning_rotor(omega, turn_at).status()
}

#[test]
fn a_turning_rotor_s_speed_and_turn_are_read_from_its_back_emf() {
    // 6 rad/s electrical from mid-hold: the speed that ended the calibration and the turn
    // since the rotor started (ψd = λf = 0.1 Wb here, no d-axis inductance term).
    let cal = turning_rotor(6.0, 0.075);
    assert_eq!(cal.status(), GainCalibrationStatus::RotorMoved);
    let speed = cal.motion_speed(0.1, 0.0);
    let turn = cal.motion_travel(0.1, 0.0);
    assert!(speed > 3.0 && speed <= 6.5, "{speed}");
    // Noticed within a few milliseconds: the turn is a few of them at 6 rad/s.
    assert!(turn > 0.0 && turn < 6.0 * 0.005, "{turn}");
    assert!(cal.motion_peak() >= 1.0);
    // At rest nothing is read.
    let rest = turning_rotor(0.0, 0.0);
    assert_eq!(rest.motion_travel(0.1, 0.0), 0.0);
    assert_eq!(rest.motion_speed(0.1, 0.0), 0.0);
    assert!(rest.motion_peak() < 0.5, "{}", rest.motion_peak());
}

#[test]
fn a_rotor_turning_during_a_level_ends_the_calibration() {
    // At rest: calibrated; turning at 2 % of the rated speed from mid-sequence: ended.
    assert_eq!(
        with_turning_rotor(0.0, 0.0),
        GainCalibrationStatus::Calibrated
    );
    // Half-way through the lower level's hold (settling 0.05 s, hold 0.05 s).
    let mid = 0.075;
    assert_eq!(
        with_turning_rotor(6.0, mid),
        GainCalibrationStatus::RotorMoved
    );
    // Below the threshold (0.5 % of the rated speed): not noticed.
    assert_eq!(
        with_turning_rotor(1.5, mid),
        GainCalibrationStatus::Calibrated
    );
}

#[test]
fn a_rotor_turning_under_the_loop_is_read_by_the_window_mean() {
    // The machine of `turning_rotor`, its rotor accelerating at 5·10³ rad/s² (electrical)
    // from 10 ms into the settling at I₁: the loop's 4 ms mean passes its threshold (2 × 3 V)
    // while the 1 ms reading is still below its own (6 × 3 V), and the turn is read; at rest
    // neither reads it.
    let run = |accel: f64| rotor_with_emf(|t| accel * (t - 0.01).max(0.0) * 0.1);
    let cal = run(5e3);
    assert_eq!(cal.status(), GainCalibrationStatus::RotorMoved);
    assert!(cal.loop_motion_peak() < 1.0, "{}", cal.loop_motion_peak());
    assert!(cal.loop_window_peak() >= 1.0, "{}", cal.loop_window_peak());
    assert!(cal.motion_travel(0.1, 0.0) > 0.0);
    let rest = run(0.0);
    assert_eq!(rest.status(), GainCalibrationStatus::Calibrated);
    assert!(rest.loop_window_peak() < 0.5, "{}", rest.loop_window_peak());
}
