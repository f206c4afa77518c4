//! Open-loop estimator check against an ideal PMSM signal generator (issue: fado-core).

mod common;

use common::*;
use fado_core::{Ab, Dq, EstimatorConfig, Mode, SensorlessEstimator, wrap_angle};

/// Runs the estimator for `seconds` and returns the worst angle error over the last second.
fn settled_error(speed_rpm: f64, i_dq: Dq<f64>, seconds: f64, v_error: Ab<f64>) -> (f64, Mode) {
    let theta0 = 0.4;
    let mut est = SensorlessEstimator::<f64>::new(EstimatorConfig {
        initial_angle: theta0,
        ..default_config()
    })
    .unwrap();
    let (_, i0) = flux_and_current(theta0, i_dq);
    est.align(theta0, i0);
    let n = (seconds / TS) as usize;
    let tail = (1.0 / TS) as usize;
    let mut worst: f64 = 0.0;
    let mut mode = Mode::Limiter;
    for (k, (v, i, theta)) in constant_speed(speed_rpm, theta0, i_dq, n, v_error).enumerate() {
        let out = est.step(v, i);
        if k >= n - tail {
            worst = worst.max(wrap_angle(theta - out.theta).abs());
            mode = out.diagnostics.mode;
        }
    }
    (worst, mode)
}

#[test]
fn settles_below_0_02_rad_at_plus_minus_300_and_30_rpm() {
    for rpm in [300.0, -300.0, 30.0, -30.0] {
        for i_dq in [Dq::new(4.0, 0.0), Dq::new(0.0, 14.2), Dq::new(0.0, -14.2)] {
            let (err, mode) = settled_error(rpm, i_dq, 4.0, Ab::zero());
            assert!(
                err < 0.02,
                "{rpm} r/min, {i_dq:?}: max |θ − θ̂| = {err:.4} rad"
            );
            assert_eq!(mode, Mode::DisturbanceFeedback, "{rpm} r/min");
        }
    }
}

#[test]
fn dc_integrand_error_is_absorbed_by_the_disturbance_observer() {
    // 50 mV of uncompensated voltage: a pure integrator drifts 0.05 V·s per s, far beyond λf in a
    // few seconds; with D̂ subtracted and k_df bounding λ1 the angle stays accurate.
    for rpm in [300.0, -300.0] {
        let (err, _) = settled_error(rpm, Dq::new(0.0, 10.0), 8.0, Ab::new(0.05, -0.03));
        assert!(err < 0.02, "{rpm} r/min: {err}");
    }
}

#[test]
fn machine_constants_are_the_paper_preset() {
    // The signal generator's motor and the estimator's model of it (`default_config`) must be
    // the same motor, or every check here would test a parameter mismatch.
    let m = default_config::<f64>().machine;
    assert_eq!((m.rs, m.ld, m.lq, m.flux_linkage), (RS, L, L, LF));
    assert_eq!(f64::from(m.pole_pairs), PP);
    assert_eq!(default_config::<f64>().ts, TS);
}
