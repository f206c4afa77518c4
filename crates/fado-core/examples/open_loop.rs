//! The f32 estimator, open loop, on a synthetic PMSM signal: standstill, run-up, a speed
//! reversal through zero and a stop, with the current sensors' offsets and noise of docs/method/estimator.md, "The paper's motor and drive".
//! Prints the angle and speed errors per phase of the run.
//!
//! ```text
//! cargo run --release -p fado-core --example open_loop
//! ```
//!
//! The machine is ideal (docs/method/estimator.md, "The paper's motor and drive" data) and the voltage is the one that exactly moves its flux
//! from sample to sample, so what is measured is the estimator: the observer, the k_df and
//! limiter feedbacks, the hand-over between them and the trackers. The closed loop with an
//! inverter and a load is the simulator's job (fado-sim).

use core::f64::consts::TAU;

use fado_core::injection::{CurrentInjection, CurrentInjectionConfig};
use fado_core::{
    Ab, Dq, EstimatorConfig, MachineModel, Mode, Rotation, SensorlessEstimator, wrap_angle,
};

const TS: f64 = 100e-6;
const RS: f64 = 0.327;
const L: f64 = 2.63e-3;
const LF: f64 = 0.088;
const POLE_PAIRS: f64 = 4.0;

/// Speed profile: (phase, duration in s, speed at its end in r/min, mechanical), linear within.
const PROFILE: [(&str, f64, f64); 7] = [
    ("standstill", 0.5, 0.0),
    ("run-up to +300", 1.0, 300.0),
    ("+300 r/min", 1.0, 300.0),
    ("reversal to -300", 2.0, -300.0),
    ("-300 r/min", 1.0, -300.0),
    ("stop", 1.0, 0.0),
    ("standstill", 0.5, 0.0),
];

/// q-axis current (A): light load, so that eq. (23) injects d-axis current.
const IQ: f64 = 2.5;

fn speed_rpm(t: f64) -> (usize, f64) {
    let (mut t0, mut w0) = (0.0, 0.0);
    for (k, &(_, d, w1)) in PROFILE.iter().enumerate() {
        if t < t0 + d || k == PROFILE.len() - 1 {
            let x = ((t - t0) / d).clamp(0.0, 1.0);
            return (k, w0 + (w1 - w0) * x);
        }
        t0 += d;
        w0 = w1;
    }
    unreachable!()
}

/// A small deterministic uniform noise source in [−1, 1].
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

#[derive(Default)]
struct Stats {
    samples: usize,
    max_angle: f64,
    sum_sq_angle: f64,
    max_speed_rpm: f64,
    limiter: usize,
}

fn main() {
    let injection =
        CurrentInjection::new(CurrentInjectionConfig::for_machine(&MachineModel::paper()))
            .expect("valid");
    let i_dq = Dq::new(injection.step(IQ), IQ);
    let machine = |theta: f64| {
        let rot = Rotation::from_angle(theta);
        (
            Dq::new(LF + L * i_dq.d, L * i_dq.q).to_ab(rot),
            i_dq.to_ab(rot),
        )
    };

    let theta0 = 0.8;
    let mut est = SensorlessEstimator::<f32>::new(EstimatorConfig {
        initial_angle: theta0 as f32,
        ..EstimatorConfig::for_machine(&MachineModel::paper())
    })
    .expect("the default configuration is valid");
    let (_, i0) = machine(theta0);
    // Start-up from a known (aligned) angle, docs/method/estimator.md, "Start-up".
    est.align(theta0 as f32, Ab::new(i0.alpha as f32, i0.beta as f32));

    // Current sensors, docs/method/estimator.md, "The paper's motor and drive": offsets 20 mA and -10 mA, 10 mA rms white noise.
    let offset = Ab::new(0.02, -0.01);
    let noise_peak = 0.01 * 3f64.sqrt();
    let mut noise = Noise(0x5eed);

    let total: f64 = PROFILE.iter().map(|p| p.1).sum();
    let n = (total / TS).round() as usize;
    let mut stats: Vec<Stats> = PROFILE.iter().map(|_| Stats::default()).collect();
    let (mut theta, mut omega_prev) = (theta0, 0.0);
    let (mut lambda_prev, mut i_prev) = machine(theta0);
    for k in 1..=n {
        let t = k as f64 * TS;
        let (phase, rpm) = speed_rpm(t);
        let omega = rpm * POLE_PAIRS * TAU / 60.0;
        theta += 0.5 * TS * (omega + omega_prev);
        omega_prev = omega;
        let (lambda, i) = machine(theta);
        let v = (lambda - lambda_prev) * (1.0 / TS) + (i + i_prev) * (0.5 * RS);
        (lambda_prev, i_prev) = (lambda, i);
        let i_meas = i + offset + Ab::new(noise.next(), noise.next()) * noise_peak;

        let out = est.step(
            Ab::new(v.alpha as f32, v.beta as f32),
            Ab::new(i_meas.alpha as f32, i_meas.beta as f32),
        );

        let s = &mut stats[phase];
        let angle_error = wrap_angle(theta - f64::from(out.theta)).abs();
        s.samples += 1;
        s.max_angle = s.max_angle.max(angle_error);
        s.sum_sq_angle += angle_error * angle_error;
        let speed_error = (f64::from(out.omega_control) - omega) * 60.0 / (TAU * POLE_PAIRS);
        s.max_speed_rpm = s.max_speed_rpm.max(speed_error.abs());
        s.limiter += usize::from(out.diagnostics.mode == Mode::Limiter);
    }

    println!(
        "fado open-loop check: f32 estimator, {total} s at 10 kHz, i_d = {:.2} A (eq. 23), i_q = {IQ} A,",
        i_dq.d
    );
    println!(
        "current sensor offsets (20, -10) mA and 10 mA rms noise; rejected samples: {}",
        est.rejected_samples()
    );
    println!();
    println!(
        "{:<18} {:>6}  {:>13} {:>13} {:>15} {:>8}",
        "phase", "time s", "angle err max", "angle err rms", "speed err max", "limiter"
    );
    println!(
        "{:<18} {:>6}  {:>13} {:>13} {:>15} {:>8}",
        "", "", "rad", "rad", "r/min", "(FLAG)"
    );
    let mut worst: f64 = 0.0;
    for (s, p) in stats.iter().zip(PROFILE) {
        worst = worst.max(s.max_angle);
        println!(
            "{:<18} {:>6.1}  {:>13.4} {:>13.4} {:>15.2} {:>7.0}%",
            p.0,
            p.1,
            s.max_angle,
            (s.sum_sq_angle / s.samples as f64).sqrt(),
            s.max_speed_rpm,
            100.0 * s.limiter as f64 / s.samples as f64
        );
    }
    println!();
    println!(
        "worst angle error {worst:.4} rad ({:.2}°); the paper's criterion near zero speed is 0.25 rad",
        worst.to_degrees()
    );
}
