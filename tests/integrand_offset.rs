//! The integrand-offset estimate (`fado_core::integrand_offset`) against the ideal PMSM
//! generator: a constant stationary-frame voltage error is learned while turning and no longer
//! walks the angle through a loaded zero-speed passage.

#[path = "../crates/fado-core/tests/common/mod.rs"]
mod common;

use common::*;
use fado_core::{Ab, Dq, SensorlessEstimator, wrap_angle};

/// 7.5 N·m on the paper's motor: T = 1.5·p·λf·i_q.
const IQ_LOAD: f64 = 7.5 / (1.5 * PP * LF);

/// Max |θ − θ̂| while |f| < 2 Hz in Fig. 11's reversal (−90 r/min from 0.5 s, −90 → +90
/// r/min from 2.5 s to 4.5 s, 7.5 N·m) with `v_error` added to the voltage, and ê at the end.
fn reversal(v_error: Ab<f64>, offset_rate: f64) -> (f64, Ab<f64>) {
    let w = rpm_to_electrical(90.0);
    let speed = move |t: f64| {
        if t < 0.5 {
            -w * t / 0.5
        } else if t < 2.5 {
            -w
        } else {
            (-w + w * (t - 2.5)).min(w)
        }
    };
    let theta0 = 0.4;
    let mut est = SensorlessEstimator::new(config_with(|c| {
        c.initial_angle = theta0;
        c.tuning.offset_adaptation.rate = offset_rate;
    }))
    .unwrap();
    let i_dq = Dq::new(0.0, IQ_LOAD);
    let (_, i0) = flux_and_current(theta0, i_dq);
    est.align(theta0, i0);
    let zero = core::f64::consts::TAU * 2.0;
    let mut worst: f64 = 0.0;
    let samples = profile(
        theta0,
        (5.0 / TS) as usize,
        speed,
        |_| i_dq,
        v_error,
        Ab::zero(),
    );
    for (k, s) in samples.enumerate() {
        let out = est.step(s.v, s.i);
        // The reversal's passage (the start-up walks before anything could be learned).
        if s.omega.abs() < zero && (k + 1) as f64 * TS > 2.5 {
            worst = worst.max(wrap_angle(s.theta - out.theta).abs());
        }
    }
    (worst, est.integrand_offset())
}

#[test]
fn a_voltage_offset_is_learned_and_does_not_walk_the_angle() {
    let (clean, _) = reversal(Ab::zero(), 2.0);
    for e in [Ab::new(0.1, 0.0), Ab::new(0.0, 0.1), Ab::new(-0.07, 0.07)] {
        let (with, learned) = reversal(e, 2.0);
        let (without, _) = reversal(e, 0.0);
        eprintln!(
            "{e:?}: ê {learned:?}, near zero {with:.3} rad (off {without:.3}, clean {clean:.3})"
        );
        assert!((learned - e).norm() < 0.01 * 1.0, "ê {learned:?} for {e:?}");
        assert!(with < clean + 0.05, "{with:.3} vs {clean:.3}");
        assert!(without > with + 0.2, "off: {without:.3}");
    }
}

#[test]
fn simulated_reversal_with_a_voltage_offset_passes() {
    // fig11 (switching-resolved, default non-idealities) with 0.1 V on the α (and on
    // the β) voltage the drive believes it applies. Without the learned offset the angle
    // walks away in the limiter mode (measured 1.21 rad on α).
    use fado::sim::scenario::simulate;
    let near_zero = |config: &str| {
        let out = simulate("fig11", Some(config), false, None).expect("valid scenario");
        out.report().max_angle_error_zero_speed
    };
    for offset in ["[0.1, 0.0]", "[0.0, 0.1]"] {
        let with = near_zero(&format!("[faults]\nvoltage_offset = {offset}\n"));
        let without = near_zero(&format!(
            "[faults]\nvoltage_offset = {offset}\n[estimator.offset_adaptation]\nrate = 0.0\n"
        ));
        eprintln!("fig11, offset {offset} V: {with:.3} rad (without the law {without:.3})");
        assert!(with < 0.25, "{offset}: {with:.3} rad");
        if offset == "[0.1, 0.0]" {
            assert!(without > 0.5, "{offset}: without the law {without:.3} rad");
        }
    }
}
