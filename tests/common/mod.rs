//! An ideal PMSM signal generator for open-loop estimator checks: a few lines, not the
//! simulator. The voltage is the exact interval average that moves the flux from one sample
//! to the next, so the only errors left are the estimator's own.

#![allow(dead_code)]

use fado_core::{Ab, Dq, Rotation};

/// Motor of SPEC §6.
pub const RS: f64 = 0.327;
/// Inductance (SMPMSM, Ld = Lq).
pub const L: f64 = 2.63e-3;
/// Magnet flux linkage.
pub const LF: f64 = 0.088;
/// Pole pairs.
pub const PP: f64 = 4.0;
/// Sampling period.
pub const TS: f64 = 100e-6;

/// One sample of the ideal machine at electrical angle `theta` with rotor currents `i_dq`.
pub fn flux_and_current(theta: f64, i_dq: Dq<f64>) -> (Ab<f64>, Ab<f64>) {
    let rot = Rotation::from_angle(theta);
    let lambda = Dq::new(LF + L * i_dq.d, L * i_dq.q).to_ab(rot);
    (lambda, i_dq.to_ab(rot))
}

/// Samples (v applied over the interval ending at n, i[n], θ[n]) for a constant speed
/// `speed_rpm` (mechanical r/min at the user edge) and constant rotor currents, with an optional
/// constant voltage error added to v (an uncompensated integrand error).
pub fn constant_speed(
    speed_rpm: f64,
    theta0: f64,
    i_dq: Dq<f64>,
    samples: usize,
    v_error: Ab<f64>,
) -> impl Iterator<Item = (Ab<f64>, Ab<f64>, f64)> {
    let w = speed_rpm * PP * core::f64::consts::TAU / 60.0;
    let (mut lambda_prev, mut i_prev) = flux_and_current(theta0, i_dq);
    (1..=samples).map(move |n| {
        let theta = theta0 + w * TS * n as f64;
        let (lambda, i) = flux_and_current(theta, i_dq);
        let v = (lambda - lambda_prev) * (1.0 / TS) + (i + i_prev) * (0.5 * RS) + v_error;
        lambda_prev = lambda;
        i_prev = i;
        (v, i, theta)
    })
}
