use super::*;
use crate::Abc;

/// A d-q machine at constant speed ω under a d-q PI current loop on the *measured* current,
/// phase a read as (1 + ε) and multiplied by the tracker's correction; returns the correction
/// after `seconds` and the largest |c − 1| on the way.
fn run<T: Real>(eps: f64, ld: f64, lq: f64, omega: f64, iq: f64, seconds: f64) -> (T, T) {
    let (ts, rs, lambda) = (1e-4, 0.04, 9e-3);
    let lit = T::lit;
    let mut tracker = GainTracking::new(GainTrackingConfig {
        ts: lit(ts),
        time: lit(0.1),
        rs: lit(rs),
        ld: lit(ld),
        lq: lit(lq),
        min_current: lit(1.0),
        max_mismatch: lit(0.05),
    });
    let mut c = T::one();
    let mut peak = T::zero();
    let (wc, sub) = (2000.0, 10);
    let (mut id, mut iq_t, mut theta) = (0.0f64, 0.0f64, 0.3f64);
    let (mut int_d, mut int_q) = (lit(0.0), lit(0.0));
    let mut v_last = Dq::new(lit(0.0), lit(0.0));
    let steps = (seconds / ts) as usize;
    for _ in 0..steps {
        // Measurement in α-β of the true angle (θ̂ = θ).
        let i_ab = Dq::new(id, iq_t).to_ab(Rotation::from_angle(theta));
        let abc = i_ab.to_abc();
        let a = lit(abc.a * (1.0 + eps)) * c;
        let b = lit(abc.b);
        let meas = Abc::new(a, b, -a - b).to_ab();
        let rot = Rotation::from_angle(lit(theta));
        let i = meas.to_dq(rot);
        c = tracker.step(i, v_last, rot, lit(omega), false, c);
        peak = peak.step_max((c - T::one()).abs());
        // PI on the measured current with the cross-coupling fed forward.
        let (ed, eq) = (lit(0.0) - i.d, lit(iq) - i.q);
        int_d += ed * lit(rs * wc * ts);
        int_q += eq * lit(rs * wc * ts);
        let vd = ed * lit(ld * wc) + int_d - lit(omega * lq) * i.q;
        let vq = eq * lit(lq * wc) + int_q + lit(omega) * (lit(ld) * i.d + lit(lambda));
        let v = Dq::new(vd, vq);
        let (vd, vq) = (v.d.to_f64(), v.q.to_f64());
        let h = ts / sub as f64;
        for _ in 0..sub {
            let did = (vd - rs * id + omega * lq * iq_t) / ld;
            let diq = (vq - rs * iq_t - omega * (ld * id + lambda)) / lq;
            id += did * h;
            iq_t += diq * h;
        }
        theta += omega * ts;
        v_last = v;
    }
    (c, peak)
}

#[test]
fn the_correction_converges_on_a_mismatched_machine() {
    for (ld, lq) in [(1.2e-4, 1.2e-4), (1.0e-4, 1.5e-4)] {
        for omega in [-150.0, 150.0, 800.0] {
            let (c, _) = run::<f64>(0.005, ld, lq, omega, 30.0, 1.5);
            let k = 1.0 / c;
            assert!((k - 1.005).abs() < 3e-4, "ω {omega} L {ld}/{lq}: k {k}");
        }
    }
    let (c, _) = run::<f64>(-0.01, 1.2e-4, 1.2e-4, 300.0, -20.0, 1.5);
    assert!((1.0 / c - 0.99).abs() < 3e-4, "k {}", 1.0 / c);
}

#[test]
fn the_f32_path_converges_too() {
    let (c, _) = run::<f32>(0.005, 1.2e-4, 1.2e-4, 300.0, 30.0, 1.5);
    assert!((1.0 / c - 1.005).abs() < 5e-4, "k {}", 1.0 / c);
}

#[test]
fn matched_gains_do_not_drift() {
    for omega in [150.0, 800.0] {
        let (c, peak) = run::<f64>(0.0, 1.0e-4, 1.5e-4, omega, 30.0, 1.5);
        assert!(
            (c - 1.0).abs() < 1e-4 && peak < 3e-4,
            "ω {omega}: c {c}, peak {peak}"
        );
    }
}

#[test]
fn it_stays_put_without_load_or_speed() {
    // No current: nothing to see.
    let (c, _) = run::<f64>(0.005, 1.2e-4, 1.2e-4, 300.0, 0.0, 0.5);
    assert_eq!(c, 1.0);
    // Below the slowest speed (12/τ = 120 rad/s).
    let (c, _) = run::<f64>(0.005, 1.2e-4, 1.2e-4, 100.0, 30.0, 0.5);
    assert_eq!(c, 1.0);
}

#[test]
fn the_state_is_bounded_and_non_finite_inputs_are_ignored() {
    let config = GainTrackingConfig {
        ts: 1e-4,
        time: 0.05,
        rs: 0.04,
        ld: 1e-4,
        lq: 1e-4,
        min_current: 1.0,
        max_mismatch: 0.05,
    };
    let mut t = GainTracking::new(config);
    let rot = Rotation::from_angle(0.2);
    let mut c = 1.0;
    // A constant −2ω component of the current that reads as a 4 % mismatch whatever the
    // correction (open loop): the correction stops at 1 − max_mismatch.
    let eps = 0.04;
    let i0 = Ab::new(5.0, 20.0);
    let n = Ab::new(eps / 2.0, eps / 2.0 / 3f64.sqrt());
    let x = n.complex_mul(Ab::new(i0.alpha, -i0.beta));
    for k in 0..20000 {
        let th = 0.3 + 500.0 * 1e-4 * k as f64;
        let r = Rotation::from_angle(th);
        let e = Rotation::from_angle(-2.0 * th).unit();
        let i = i0 + x.complex_mul(e);
        c = t.step(
            Dq::new(i.alpha, i.beta),
            Dq::new(0.0, 4.0),
            r,
            500.0,
            false,
            c,
        );
        assert!(c.is_finite() && (c - 1.0).abs() <= 0.05 + 1e-12);
    }
    assert!((t.residual() - eps).abs() < 2e-3, "reads {}", t.residual());
    assert!((c - 0.95).abs() < 1e-12, "it stops at the bound: c {c}");
    let before = t;
    for bad in [f64::NAN, f64::INFINITY] {
        assert_eq!(
            t.step(Dq::new(bad, 1.0), Dq::zero(), rot, 500.0, false, c),
            c
        );
        assert_eq!(
            t.step(Dq::new(1.0, 1.0), Dq::new(0.0, bad), rot, 500.0, false, c),
            c
        );
        assert_eq!(t.step(Dq::new(1.0, 1.0), Dq::zero(), rot, bad, false, c), c);
    }
    assert_eq!(t, before);
    // A configuration that cannot adapt never does.
    let mut dead = GainTracking::new(GainTrackingConfig {
        time: 0.0,
        ..config
    });
    assert_eq!(
        dead.step(Dq::new(1.0, 30.0), Dq::zero(), rot, 500.0, false, 1.0),
        1.0
    );
}
