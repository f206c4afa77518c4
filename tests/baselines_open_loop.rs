//! Open-loop sanity checks of the baseline estimators against the ideal PMSM signal generator
//! of `tests/common`: each must settle at medium speed, both directions, loaded and unloaded,
//! so that a comparison with fado never rests on a broken baseline. Further checks measure
//! the failure mechanisms the module docs predict (offset ripple, λ̂f sensitivity).

mod common;

use common::*;
use fado_core::baselines::{
    EmfObserverConfig, EmfObserverEstimator, LpfIntegratorConfig, LpfIntegratorEstimator,
    OrtegaConfig, OrtegaEstimator,
};
use fado_core::{Ab, Dq, RotorAngleEstimator, wrap_angle};

/// Runs `est` for `seconds` from an aligned start and returns the worst angle error over the
/// last `tail` seconds.
fn settled_error<E: RotorAngleEstimator<f64>>(
    est: &mut E,
    speed_rpm: f64,
    i_dq: Dq<f64>,
    seconds: f64,
    tail: f64,
    v_error: Ab<f64>,
) -> f64 {
    let theta0 = 0.4;
    let (_, i0) = flux_and_current(theta0, i_dq);
    est.align(theta0, i0);
    let n = (seconds / TS) as usize;
    let tail = (tail / TS) as usize;
    let mut worst: f64 = 0.0;
    for (k, (v, i, theta)) in constant_speed(speed_rpm, theta0, i_dq, n, v_error).enumerate() {
        let out = est.step(v, i);
        assert!(!out.diagnostics.input_fault);
        if k >= n - tail {
            worst = worst.max(wrap_angle(theta - out.theta).abs());
        }
    }
    worst
}

const LOADS: [Dq<f64>; 3] = [Dq::new(4.0, 0.0), Dq::new(0.0, 14.2), Dq::new(0.0, -14.2)];

fn medium_speed_sanity<E: RotorAngleEstimator<f64>>(est: &mut E) {
    for rpm in [300.0, -300.0] {
        for i_dq in LOADS {
            let err = settled_error(est, rpm, i_dq, 2.0, 0.5, Ab::zero());
            println!("{} {rpm} r/min {i_dq:?}: {err:.2e} rad", est.name());
            assert!(
                err < 0.05,
                "{} at {rpm} r/min, {i_dq:?}: max |θ − θ̂| = {err:.4} rad",
                est.name()
            );
        }
    }
}

#[test]
fn lpf_integrator_settles_at_plus_minus_300_rpm() {
    medium_speed_sanity(&mut LpfIntegratorEstimator::new(LpfIntegratorConfig::default()).unwrap());
}

#[test]
fn ortega_settles_at_plus_minus_300_rpm() {
    medium_speed_sanity(&mut OrtegaEstimator::new(OrtegaConfig::default()).unwrap());
}

#[test]
fn emf_observer_settles_at_plus_minus_300_rpm() {
    medium_speed_sanity(&mut EmfObserverEstimator::new(EmfObserverConfig::default()).unwrap());
}

#[test]
fn every_baseline_settles_in_f32() {
    fn run<E: RotorAngleEstimator<f32>>(est: &mut E) {
        for rpm in [300.0, -300.0] {
            let i_dq = Dq::new(0.0, 14.2);
            let theta0 = 0.4;
            let (_, i0) = flux_and_current(theta0, i_dq);
            est.align(theta0 as f32, Ab::new(i0.alpha as f32, i0.beta as f32));
            let mut worst: f64 = 0.0;
            for (k, (v, i, theta)) in
                constant_speed(rpm, theta0, i_dq, 20_000, Ab::zero()).enumerate()
            {
                let out = est.step(
                    Ab::new(v.alpha as f32, v.beta as f32),
                    Ab::new(i.alpha as f32, i.beta as f32),
                );
                if k >= 15_000 {
                    worst = worst.max(wrap_angle(theta - out.theta as f64).abs());
                }
            }
            assert!(worst < 0.01, "{} f32 at {rpm} r/min: {worst}", est.name());
        }
    }
    run(&mut LpfIntegratorEstimator::<f32>::new(LpfIntegratorConfig::default()).unwrap());
    run(&mut OrtegaEstimator::<f32>::new(OrtegaConfig::default()).unwrap());
    run(&mut EmfObserverEstimator::<f32>::new(EmfObserverConfig::default()).unwrap());
}

/// |T(jω)| of the continuous T2S-1 loop, through which a ripple of θm at the fundamental
/// reaches θ̂.
fn tracker_gain(omega: f64) -> f64 {
    tracker_gain_with_speed_feedback(omega, f64::INFINITY)
}

/// The same when θm also carries (ω̂ − ω)/p (the EMF filter's phase off its tuning): the loop
/// becomes (Kp·s + Ki)/(s² + (Kp − Ki/p)·s + Ki) (emf_observer module docs).
fn tracker_gain_with_speed_feedback(omega: f64, p: f64) -> f64 {
    let (kp, ki) = fado_core::tracker::TrackerConfig::<f64>::default().gains();
    let w2 = omega * omega;
    let damping = kp - ki / p;
    ((ki * ki + kp * kp * w2) / ((ki - w2).powi(2) + damping * damping * w2)).sqrt()
}

fn electrical_speed(rpm: f64) -> f64 {
    rpm * PP * core::f64::consts::TAU / 60.0
}

/// Asserts that `measured` is within `rel` of `predicted`.
fn assert_close(what: &str, measured: f64, predicted: f64, rel: f64) {
    println!("{what}: measured {measured:.4e}, predicted {predicted:.4e}");
    assert!(
        (measured - predicted).abs() < rel * predicted,
        "{what}: measured {measured:.4e} vs predicted {predicted:.4e}"
    );
}

#[test]
fn lpf_turns_a_dc_voltage_error_into_the_predicted_ripple() {
    // A DC integrand error ε leaves ψ_dc = ε/ωc, compensated to ε/ωc·(1 − jωc/ω): an angle
    // ripple asin(|δλ|/λf) at the fundamental, passed to θ̂ with the tracker gain |T(jω)|.
    let cfg = LpfIntegratorConfig::<f64>::default();
    let wc = core::f64::consts::TAU * cfg.cutoff_hz;
    let eps = Ab::new(0.03, -0.04); // 50 mV
    for rpm in [300.0, -300.0] {
        let w = electrical_speed(rpm);
        let mut est = LpfIntegratorEstimator::new(cfg).unwrap();
        let err = settled_error(&mut est, rpm, Dq::new(0.0, 10.0), 2.0, 0.5, eps);
        let dl = eps.norm() / wc * (1.0 + (wc / w).powi(2)).sqrt();
        let predicted = (dl / LF).asin() * tracker_gain(w);
        assert_close("lpf ripple", err, predicted, 0.1);
    }
}

#[test]
fn emf_observer_turns_a_dc_voltage_error_into_the_predicted_ripple() {
    // ε passes the rotating filter with gain p/√(p² + ω²) and is divided by ω; the ripple
    // reaches θ̂ through the tracker loop whose damping the filter's ω̂ feedback reduces.
    let cfg = EmfObserverConfig::<f64>::default();
    let p = core::f64::consts::TAU * cfg.emf_bandwidth_hz;
    let eps = Ab::new(0.3, 0.4); // 0.5 V
    for rpm in [300.0, -300.0] {
        let w = electrical_speed(rpm);
        let mut est = EmfObserverEstimator::new(cfg).unwrap();
        let err = settled_error(&mut est, rpm, Dq::new(0.0, 10.0), 1.0, 0.5, eps);
        let dl = eps.norm() * p / (p * p + w * w).sqrt() / w.abs();
        let predicted = (dl / LF).asin() * tracker_gain_with_speed_feedback(w, p);
        assert_close("emf ripple", err, predicted, 0.1);
    }
}

#[test]
fn ortega_turns_a_dc_voltage_error_into_the_predicted_ripple() {
    // Rotor-frame error dynamics ε̇d = ud + ω·εq − ω_obs·εd, ε̇q = uq − ω·εd driven by ε
    // rotating at −ω: |εq| = |ε|·√(4ω² + ω_obs²)/(|ω|·ω_obs) (module docs, linearised).
    let cfg = OrtegaConfig::<f64>::default();
    let w_obs = cfg.observer_bandwidth;
    let eps = Ab::new(0.12, -0.16); // 0.2 V
    for rpm in [300.0, -300.0] {
        let w = electrical_speed(rpm);
        let mut est = OrtegaEstimator::new(cfg).unwrap();
        let err = settled_error(&mut est, rpm, Dq::new(0.0, 10.0), 1.5, 0.5, eps);
        let eq = eps.norm() * (4.0 * w * w + w_obs * w_obs).sqrt() / (w.abs() * w_obs);
        let predicted = eq / LF * tracker_gain(w);
        assert_close("ortega ripple", err, predicted, 0.1);
    }
}

/// The steady angle error of the Ortega observer pulled to a wrong radius λ̂: e = c·η with
/// 1 + c = 1/(1 − jb) and −ω·b = (γ/2)·(λ̂² − λf²/(1 + b²)); the error is atan(b).
fn ortega_radius_error(w: f64, w_obs: f64, lambda_hat: f64) -> f64 {
    let half_gamma = 0.5 * w_obs / (lambda_hat * lambda_hat);
    let f = |b: f64| w * b + half_gamma * (lambda_hat * lambda_hat - LF * LF / (1.0 + b * b));
    // f is monotone in b for this sign of ω on the bracket; bisect.
    let (mut lo, mut hi) = (-10.0_f64, 10.0_f64);
    let rising = f(hi) > f(lo);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if (f(mid) > 0.0) == rising {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    (0.5 * (lo + hi)).atan().abs()
}

#[test]
fn ortega_flux_linkage_error_gives_the_predicted_angle_error_and_adaptation_removes_it() {
    for ratio in [0.9, 1.1] {
        for rpm in [300.0, -300.0] {
            let w = electrical_speed(rpm);
            let cfg = OrtegaConfig {
                flux_linkage_hat: ratio * LF,
                ..OrtegaConfig::default()
            };
            let mut est = OrtegaEstimator::new(cfg).unwrap();
            let err = settled_error(&mut est, rpm, Dq::new(0.0, 10.0), 1.5, 0.3, Ab::zero());
            let predicted = ortega_radius_error(w, cfg.observer_bandwidth, ratio * LF);
            assert_close("ortega λ̂f error", err, predicted, 0.05);
            // With the VESC-style adaptation (κ = 0.2) λ̂ converges to λf and the error goes.
            let mut est = OrtegaEstimator::new(OrtegaConfig {
                flux_adaptation_ratio: 0.2,
                ..cfg
            })
            .unwrap();
            let err = settled_error(&mut est, rpm, Dq::new(0.0, 10.0), 3.0, 0.3, Ab::zero());
            let lambda = est.flux_linkage_estimate();
            println!("adapted: λ̂ = {lambda:.5} Wb, error {err:.2e} rad");
            assert!((lambda / LF - 1.0).abs() < 1e-3, "λ̂ = {lambda}");
            assert!(err < 0.2 * predicted && err < 5e-3, "{err}");
        }
    }
}
