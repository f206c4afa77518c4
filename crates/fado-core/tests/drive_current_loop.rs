//! The current loop of Fig. 5 closed around an ideal surface-mounted PMSM with the real
//! timing: a voltage computed at sample n is held in the *stationary* frame over [n+1, n+2]
//! (one sample of computation, zero-order hold) while the rotor turns. The rotor angle is
//! known here, so what is checked is the current control itself: its bandwidth, the
//! decoupling and the delay compensation (docs/method/estimator.md §7, §6).

use core::f64::consts::{PI, TAU};
use fado_core::control::{
    CurrentController, CurrentControllerConfig, DelayCompensation, DelayCompensationConfig,
};
use fado_core::{Ab, Dq, MachineModel, Rotation};

const RS: f64 = 0.327;
const L: f64 = 2.63e-3;
const LF: f64 = 0.088;
const TS: f64 = 100e-6;
const SUBSTEPS: usize = 20;

/// The paper's motor (`MachineModel::paper()`, which the controller is built for).
///
/// Ideal SMPMSM in α-β: dλ/dt = v − R·i, i = (λ − λf·e^{jθ})/L, θ' = ω (constant speed).
struct Motor {
    lambda: Ab<f64>,
    theta: f64,
    omega: f64,
}

impl Motor {
    fn at_rest_current(omega: f64) -> Self {
        Self {
            lambda: Ab::from_polar(LF, 0.0),
            theta: 0.0,
            omega,
        }
    }
    fn current(&self) -> Ab<f64> {
        (self.lambda - Ab::from_polar(LF, self.theta)) * (1.0 / L)
    }
    /// One sampling interval with the stationary-frame voltage `v` held (midpoint rule).
    fn advance(&mut self, v: Ab<f64>) {
        let h = TS / SUBSTEPS as f64;
        for _ in 0..SUBSTEPS {
            let i0 = self.current();
            let half = Motor {
                lambda: self.lambda + (v - i0 * RS) * (0.5 * h),
                theta: self.theta + 0.5 * h * self.omega,
                omega: self.omega,
            };
            self.lambda += (v - half.current() * RS) * h;
            self.theta += h * self.omega;
        }
    }
}

struct Loop {
    motor: Motor,
    cc: CurrentController<f64>,
    delay: DelayCompensation<f64>,
    /// The voltage computed at the previous sample, acting over the coming interval.
    pending: Ab<f64>,
}

impl Loop {
    fn new(omega: f64, decoupling: bool, delay_factor: f64) -> Self {
        Self {
            motor: Motor::at_rest_current(omega),
            cc: CurrentController::new(CurrentControllerConfig {
                decoupling,
                ..CurrentControllerConfig::for_machine(&MachineModel::paper(), TS)
            })
            .unwrap(),
            delay: DelayCompensation::new(DelayCompensationConfig {
                ts: TS,
                factor: delay_factor,
            })
            .unwrap(),
            pending: Ab::zero(),
        }
    }

    /// Sample n: measure, control, then let the interval [n, n+1] elapse under the voltage
    /// computed at n−1. Returns the current sampled at n in the true rotor frame.
    fn step(&mut self, reference: Dq<f64>) -> Dq<f64> {
        let (theta, omega) = (self.motor.theta, self.motor.omega);
        let i_dq = self.motor.current().to_dq(Rotation::from_angle(theta));
        let v_dq = self.cc.step(reference, i_dq, omega).unwrap();
        let (v_ab, _) = self.delay.step(v_dq, theta, omega);
        self.motor.advance(self.pending);
        self.pending = v_ab;
        i_dq
    }
}

fn wc() -> f64 {
    TAU * 250.0
}

/// Response of i_q to a step: 10-90 % rise time (crossings interpolated between samples),
/// peak |i_d| excursion, relative overshoot, and the loop after 40 ms.
struct StepResponse {
    rise: f64,
    id_peak: f64,
    overshoot: f64,
    settled: Loop,
}

fn q_step(omega: f64, decoupling: bool, delay_factor: f64, amplitude: f64) -> StepResponse {
    let mut lp = Loop::new(omega, decoupling, delay_factor);
    for _ in 0..2000 {
        lp.step(Dq::zero()); // settle the start-up transient of the back-EMF
    }
    let crossing = |prev: f64, now: f64, n: usize, level: f64| {
        (n as f64 - 1.0 + (level - prev) / (now - prev)) * TS
    };
    let (mut t10, mut t90, mut id_peak, mut iq_peak) = (None, None, 0.0_f64, 0.0_f64);
    let id0 = lp.step(Dq::zero()).d;
    let mut prev = 0.0;
    for n in 0..400 {
        let i = lp.step(Dq::new(0.0, amplitude));
        if t10.is_none() && i.q >= 0.1 * amplitude {
            t10 = Some(crossing(prev, i.q, n, 0.1 * amplitude));
        }
        if t90.is_none() && i.q >= 0.9 * amplitude {
            t90 = Some(crossing(prev, i.q, n, 0.9 * amplitude));
        }
        id_peak = id_peak.max((i.d - id0).abs());
        iq_peak = iq_peak.max(i.q);
        prev = i.q;
    }
    StepResponse {
        rise: t90.unwrap() - t10.unwrap(),
        id_peak,
        overshoot: iq_peak / amplitude - 1.0,
        settled: lp,
    }
}

#[test]
fn step_response_has_the_designed_first_order_rise_time() {
    // Design ωc/(s + ωc): 10-90 % in ln 9/ωc = 1.40 ms. The 1.5-sample delay τ inside the loop
    // speeds the dominant pole up to ≈ ωc/(1 − ωc·τ) (first-order Padé of e^{−sτ}), so the
    // rise time is ln 9·(1 − ωc·τ)/ωc = 1.07 ms; the crossover stays at ωc (next test).
    let r = q_step(0.0, true, 1.5, 10.0);
    let tau = 1.5 * TS;
    let predicted = 9f64.ln() * (1.0 - wc() * tau) / wc();
    assert!(
        (r.rise - predicted).abs() < 0.1 * predicted,
        "rise {} vs {predicted}",
        r.rise
    );
    assert!(r.overshoot < 0.05, "overshoot {}", r.overshoot);
    assert!(r.id_peak < 1e-9, "no coupling at standstill: {}", r.id_peak);
    let i = r.settled.motor.current().to_dq(Rotation::from_angle(0.0));
    assert!((i.q - 10.0).abs() < 1e-4 && i.d.abs() < 1e-9);
}

/// Complex closed-loop gain of the q loop at `f_hz`, from a sinusoidal reference in steady
/// state (correlation over whole periods).
fn closed_loop_gain(f_hz: f64) -> (f64, f64) {
    let mut lp = Loop::new(0.0, true, 1.5);
    let w = TAU * f_hz;
    let samples_per_period = 1.0 / (f_hz * TS);
    let settle = 400;
    let periods = 10.0;
    let n_meas = (periods * samples_per_period).round() as usize;
    let (mut re, mut im, mut norm) = (0.0, 0.0, 0.0);
    for n in 0..settle + n_meas {
        let t = n as f64 * TS;
        let i = lp.step(Dq::new(0.0, (w * t).sin())).q;
        if n >= settle {
            re += i * (w * t).sin();
            im += i * (w * t).cos();
            norm += (w * t).sin().powi(2);
        }
    }
    (re / norm, im / norm) // T = re + j·im relative to the sine reference
}

#[test]
fn loop_crosses_over_at_the_design_bandwidth_with_one_and_a_half_samples_of_delay() {
    // Open loop from the measured closed loop: L = T/(1 − T). Design: L = ωc/s·e^{−1.5·s·Ts}.
    let (re, im) = closed_loop_gain(250.0);
    let t = num_complex(re, im);
    let l = t.div(num_complex(1.0 - re, -im));
    let l_mag = l.norm();
    let l_phase = l.arg();
    assert!((l_mag - 1.0).abs() < 0.05, "|L(j·2π·250)| = {l_mag}");
    let design_phase = -PI / 2.0 - 1.5 * wc() * TS;
    assert!(
        (l_phase - design_phase).abs() < 0.05,
        "∠L = {l_phase} vs {design_phase}"
    );
    // The resulting closed loop: −3 dB where |ωc·e^{−sτ}/(s + ωc·e^{−sτ})| = 1/√2.
    let gain = |f: f64| {
        let (re, im) = closed_loop_gain(f);
        (re * re + im * im).sqrt()
    };
    assert!(gain(250.0) > 0.75 && gain(250.0) < 0.87);
    assert!(gain(300.0) > 1.0 / 2f64.sqrt() && gain(400.0) < 1.0 / 2f64.sqrt());
}

#[test]
fn decoupling_and_delay_compensation_keep_the_axes_apart_at_speed() {
    // 1500 r/min (rated) with 4 pole pairs: ω = 2π·100 rad/s, 1.5·ω·Ts = 0.094 rad.
    let w = TAU * 100.0;
    let amplitude = 20.0;
    let standstill = q_step(0.0, true, 1.5, amplitude);
    let full = q_step(w, true, 1.5, amplitude);
    let no_delay_comp = q_step(w, true, 0.0, amplitude);
    let no_decoupling = q_step(w, false, 1.5, amplitude);
    // The q response is the standstill one.
    assert!(
        (full.rise - standstill.rise).abs() < 0.05 * standstill.rise,
        "{} vs {}",
        full.rise,
        standstill.rise
    );
    // In steady state the feed-forward is exact only in the right frame: with the delay
    // compensated the integrators hold just the resistive drop (R̂s·i_q on q, nothing on d);
    // without it they must hold the 1.5·ω·Ts rotation of the ≈ 70 V vector.
    let i_full = full.settled.cc.integral();
    assert!(i_full.d.abs() < 0.1, "d integral {}", i_full.d);
    assert!(
        (i_full.q - RS * amplitude).abs() < 0.1,
        "q integral {}",
        i_full.q
    );
    let i_off = no_delay_comp.settled.cc.integral();
    let v_ss = Dq::new(-w * L * amplitude, RS * amplitude + w * LF);
    let rotation_error = v_ss.norm() * 1.5 * w * TS;
    assert!(
        (i_off.d.abs() - rotation_error).abs() < 0.15 * rotation_error,
        "d integral without delay compensation {} vs {rotation_error}",
        i_off.d
    );
    // Transient cross-coupling into d: the measured-current decoupling lags the fast i_q by
    // the loop delay, ≈ ω·L̂q·(di_q/dt)·1.5·Ts/Kp ≈ 1 A at the step's steepest; removing
    // either compensation makes it worse.
    assert!(
        full.id_peak < 0.06 * amplitude,
        "i_d excursion {}",
        full.id_peak
    );
    assert!(no_delay_comp.id_peak > 1.5 * full.id_peak);
    assert!(no_decoupling.id_peak > 4.0 * full.id_peak);
}

#[test]
fn anti_windup_against_a_voltage_circle_recovers_without_overshoot_blow_up() {
    // Ask for 30 A with only 5 V available (a stalled inverter): the loop saturates for a
    // long time; once the limit is lifted the current must not overshoot badly.
    let run = |ratio: f64| {
        let mut cc = CurrentController::new(CurrentControllerConfig {
            anti_windup_ratio: ratio,
            ..CurrentControllerConfig::<f64>::for_machine(&MachineModel::paper(), TS)
        })
        .unwrap();
        let mut motor = Motor::at_rest_current(0.0);
        let mut pending = Ab::zero();
        let mut peak = 0.0_f64;
        for n in 0..3000 {
            let v_max = if n < 1000 { 5.0 } else { 300.0 / 3f64.sqrt() };
            let i_dq = motor.current().to_dq(Rotation::from_angle(0.0));
            let v = cc
                .step_limited(Dq::new(0.0, 30.0), i_dq, 0.0, v_max)
                .unwrap();
            motor.advance(pending);
            pending = v.to_ab(Rotation::from_angle(0.0));
            if n >= 1000 {
                peak = peak.max(i_dq.q);
            }
        }
        peak / 30.0 - 1.0
    };
    let with = run(1.0);
    let without = run(0.0);
    assert!(with < 0.05, "overshoot with anti-windup {with}");
    assert!(without > 0.5, "overshoot without {without}");
}

/// Minimal complex arithmetic for the loop-gain extraction.
#[derive(Clone, Copy)]
struct C(f64, f64);
fn num_complex(re: f64, im: f64) -> C {
    C(re, im)
}
impl C {
    fn div(self, o: C) -> C {
        let d = o.0 * o.0 + o.1 * o.1;
        C(
            (self.0 * o.0 + self.1 * o.1) / d,
            (self.1 * o.0 - self.0 * o.1) / d,
        )
    }
    fn norm(self) -> f64 {
        (self.0 * self.0 + self.1 * self.1).sqrt()
    }
    fn arg(self) -> f64 {
        self.1.atan2(self.0)
    }
}
