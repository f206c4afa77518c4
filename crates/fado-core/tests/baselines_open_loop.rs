//! Open-loop sanity checks of the baseline estimators against the ideal PMSM signal generator
//! of `tests/common`: each must settle at medium speed, both directions, loaded and unloaded,
//! so that a comparison with fado never rests on a broken baseline. Further checks measure
//! the failure mechanisms the module docs predict (offset ripple, λ̂f sensitivity).

mod common;

use common::*;
use fado_core::baselines::{
    EmfObserverConfig, EmfObserverEstimator, LpfIntegratorConfig, LpfIntegratorEstimator,
    OrtegaConfig, OrtegaEstimator, OrtegaSettings,
};
use fado_core::{Ab, Dq, MachineModel, RotorAngleEstimator, wrap_angle};

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
    medium_speed_sanity(
        &mut LpfIntegratorEstimator::new(LpfIntegratorConfig::for_machine(&MachineModel::paper()))
            .unwrap(),
    );
}

#[test]
fn ortega_settles_at_plus_minus_300_rpm() {
    medium_speed_sanity(
        &mut OrtegaEstimator::new(OrtegaConfig::for_machine(&MachineModel::paper())).unwrap(),
    );
}

#[test]
fn emf_observer_settles_at_plus_minus_300_rpm() {
    medium_speed_sanity(
        &mut EmfObserverEstimator::new(EmfObserverConfig::for_machine(&MachineModel::paper()))
            .unwrap(),
    );
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
    run(
        &mut LpfIntegratorEstimator::<f32>::new(LpfIntegratorConfig::for_machine(
            &MachineModel::paper(),
        ))
        .unwrap(),
    );
    run(
        &mut OrtegaEstimator::<f32>::new(OrtegaConfig::for_machine(&MachineModel::paper()))
            .unwrap(),
    );
    run(
        &mut EmfObserverEstimator::<f32>::new(EmfObserverConfig::for_machine(
            &MachineModel::paper(),
        ))
        .unwrap(),
    );
}

/// |T(jω)| of the continuous T2S-1 loop, through which a ripple of θm at the fundamental
/// reaches θ̂.
fn tracker_gain(omega: f64) -> f64 {
    tracker_gain_with_speed_feedback(omega, f64::INFINITY)
}

/// The same when θm also carries (ω̂ − ω)/p (the EMF filter's phase off its tuning): the loop
/// becomes (Kp·s + Ki)/(s² + (Kp − Ki/p)·s + Ki) (emf_observer module docs).
fn tracker_gain_with_speed_feedback(omega: f64, p: f64) -> f64 {
    let (kp, ki) = fado_core::tracker::TrackerConfig::<f64>::new(60.0, TS).gains();
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
    let cfg = LpfIntegratorConfig::<f64>::for_machine(&MachineModel::paper());
    let wc = core::f64::consts::TAU * cfg.settings.cutoff_hz;
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
    let cfg = EmfObserverConfig::<f64>::for_machine(&MachineModel::paper());
    let p = core::f64::consts::TAU * cfg.settings.emf_bandwidth_hz;
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
    let cfg = OrtegaConfig::<f64>::for_machine(&MachineModel::paper());
    let eps = Ab::new(0.12, -0.16); // 0.2 V
    for rpm in [300.0, -300.0] {
        let w = electrical_speed(rpm);
        let w_obs = cfg.scheduled_bandwidth(w);
        let mut est = OrtegaEstimator::new(cfg).unwrap();
        let err = settled_error(&mut est, rpm, Dq::new(0.0, 10.0), 1.5, 0.5, eps);
        let eq = eps.norm() * (4.0 * w * w + w_obs * w_obs).sqrt() / (w.abs() * w_obs);
        let predicted = eq / LF * tracker_gain(w);
        assert_close("ortega ripple", err, predicted, 0.1);
    }
}

/// The steady angle error φ of the Ortega observer (module docs, lock condition): the root
/// nearest 0 of tan φ + (ω_obs/2ω)·(1 − (a/λ̂)²·cos²φ) = 0, where a = λf + uq/ω is the radius of
/// the integrated flux circle and λ̂ the radius the observer pulls to.
fn ortega_steady_angle(w: f64, w_obs: f64, a: f64, lambda_hat: f64) -> f64 {
    let r = w_obs / (2.0 * w);
    let k = (a / lambda_hat).powi(2);
    let g = |phi: f64| phi.tan() + r * (1.0 - k * phi.cos().powi(2));
    let half = core::f64::consts::FRAC_PI_2 - 1e-6;
    let steps = 200_000;
    let mut best = f64::NAN;
    for j in 0..steps {
        let (p0, p1) = (
            -half + 2.0 * half * j as f64 / steps as f64,
            -half + 2.0 * half * (j + 1) as f64 / steps as f64,
        );
        if g(p0).signum() != g(p1).signum() {
            let (mut lo, mut hi) = (p0, p1);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if g(mid).signum() == g(lo).signum() {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let root = 0.5 * (lo + hi);
            if best.is_nan() || root.abs() < best.abs() {
                best = root;
            }
        }
    }
    best.abs()
}

#[test]
fn ortega_flux_linkage_error_gives_the_predicted_angle_error_and_adaptation_removes_it() {
    for ratio in [0.9, 1.1] {
        for rpm in [300.0, -300.0] {
            let w = electrical_speed(rpm);
            let cfg = OrtegaConfig::for_machine(&MachineModel {
                flux_linkage: ratio * LF,
                ..MachineModel::paper()
            });
            let mut est = OrtegaEstimator::new(cfg).unwrap();
            let err = settled_error(&mut est, rpm, Dq::new(0.0, 10.0), 1.5, 0.3, Ab::zero());
            let predicted = ortega_steady_angle(w, cfg.scheduled_bandwidth(w), LF, ratio * LF);
            assert_close("ortega λ̂f error", err, predicted, 0.05);
            // With the VESC-style adaptation (κ = 0.2) λ̂ converges to λf and the error goes.
            let mut est = OrtegaEstimator::new(OrtegaConfig {
                settings: OrtegaSettings {
                    flux_adaptation_ratio: 0.2,
                    ..cfg.settings
                },
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

#[test]
fn ortega_fixed_gain_loses_lock_where_predicted_and_the_schedule_keeps_it() {
    // An R̂s error x under motoring load iq is the q-axis integrand error uq = −x·Rs·iq: the
    // integrated circle shrinks to a = λf + uq/ω. With a fixed ω_obs the small-error root
    // exists while δ = 1 − (a/λf)² ≤ ω²/ω_obs² (first order): at 90 r/min and 251 rad/s that
    // is x ≈ 0.8 %. Half of it settles where predicted; three times it leaves no equilibrium
    // and the estimate slips poles periodically; the default schedule (ω_obs = 2|ω|) keeps lock
    // at three times it, with the predicted error.
    let fixed = OrtegaConfig::<f64> {
        settings: OrtegaSettings {
            observer_speed_ratio: 0.0,
            observer_bandwidth: 2.0 * core::f64::consts::TAU * 20.0,
            ..OrtegaConfig::for_machine(&MachineModel::paper()).settings
        },
        ..OrtegaConfig::for_machine(&MachineModel::paper())
    };
    for (rpm, iq) in [(90.0, 14.2), (-90.0, -14.2)] {
        let w = electrical_speed(rpm);
        let uq_per_x = -RS * iq;
        let delta_for = |x: f64| 1.0 - ((LF + x * uq_per_x / w) / LF).powi(2);
        // Bisect the first-order limit δ(x) = ω²/ω_obs².
        let limit = (w / fixed.settings.observer_bandwidth).powi(2);
        let (mut lo, mut hi) = (0.0, 0.1);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if delta_for(mid) < limit {
                lo = mid
            } else {
                hi = mid
            }
        }
        let x_limit = lo;
        assert!((x_limit - 0.008).abs() < 0.001, "{x_limit}");
        let i_dq = Dq::new(0.0, iq);
        let run = |cfg: OrtegaConfig<f64>, x: f64, seconds: f64| {
            let mut est = OrtegaEstimator::new(OrtegaConfig {
                machine: MachineModel {
                    rs: RS * (1.0 + x),
                    ..cfg.machine
                },
                ..cfg
            })
            .unwrap();
            settled_error(&mut est, rpm, i_dq, seconds, 0.5, Ab::zero())
        };
        let a = |x: f64| LF + x * uq_per_x / w;
        // Half the limit: the predicted equilibrium.
        let x = 0.5 * x_limit;
        let predicted = ortega_steady_angle(w, fixed.settings.observer_bandwidth, a(x), LF);
        assert_close(
            "ortega fixed gain, ½ limit",
            run(fixed, x, 4.0),
            predicted,
            0.05,
        );
        // Three times the limit: a pole slip (the error passes through ±π) within 6 s.
        let mut est = OrtegaEstimator::new(OrtegaConfig {
            machine: MachineModel {
                rs: RS * (1.0 + 3.0 * x_limit),
                ..fixed.machine
            },
            ..fixed
        })
        .unwrap();
        let err = settled_error(&mut est, rpm, i_dq, 6.0, 5.8, Ab::zero());
        println!("ortega fixed gain, 3 × limit: max {err:.3} rad");
        assert!(err > 2.5, "{err}");
        // The schedule at three times the limit holds, where predicted.
        let sched = OrtegaConfig::<f64>::for_machine(&MachineModel::paper());
        let x = 3.0 * x_limit;
        let predicted = ortega_steady_angle(w, sched.scheduled_bandwidth(w), a(x), LF);
        assert_close(
            "ortega schedule, 3 × limit",
            run(sched, x, 2.0),
            predicted,
            0.05,
        );
    }
}
