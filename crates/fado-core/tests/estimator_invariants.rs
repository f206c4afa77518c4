//! Property tests of `SensorlessEstimator` in `f32` and `f64`: bounded state and outputs for
//! arbitrary bounded inputs at speeds of both signs, and rejection of non-finite (or
//! overflowing) inputs that leaves the whole state untouched.

mod common;

use core::fmt::Debug;

use common::*;
use fado_core::tracker::TrackerConfig;
use fado_core::{Ab, Dq, Estimate, EstimatorConfig, Real, SensorlessEstimator};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

const PI: f64 = core::f64::consts::PI;
/// Largest |v| of the random inputs (V): beyond the 300 V dc link.
const V_MAX: f64 = 400.0;
/// Largest |i| of the random inputs (A): beyond the 40 A current limit.
const I_MAX: f64 = 50.0;

fn ab<T: Real>(x: Ab<f64>) -> Ab<T> {
    Ab::new(T::lit(x.alpha), T::lit(x.beta))
}

/// A vector of magnitude at most `max`, any direction.
fn bounded_vector(max: f64) -> impl Strategy<Value = Ab<f64>> {
    (0.0..=max, -PI..PI).prop_map(|(m, a)| Ab::from_polar(m, a))
}

/// A signed electrical speed with |f| in [lo, hi] Hz.
fn signed_speed(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo..=hi, any::<bool>()).prop_map(|(f, neg)| if neg { -f } else { f } * core::f64::consts::TAU)
}

/// The estimator aligned at θ0 and run for `warm_up` samples of the ideal machine at `omega`.
fn warmed_up<T: Real>(omega: f64, warm_up: usize) -> SensorlessEstimator<T> {
    let theta0 = 0.4;
    let i_dq = Dq::new(2.0, 8.0);
    let (_, i0) = flux_and_current(theta0, i_dq);
    let mut config = EstimatorConfig {
        initial_angle: T::lit(theta0),
        ..default_config()
    };
    // The inputs drawn jump by up to 2·I_MAX per sample, more than any inductance allows:
    // this test is about boundedness, so only the magnitude bounds stay on (the step bound
    // is checked in fado-core's tests/plausibility.rs).
    config.tuning.plausibility.current_step_ratio = T::zero();
    let mut est = SensorlessEstimator::<T>::new(config).unwrap();
    est.align(T::lit(theta0), ab(i0));
    for s in profile(theta0, warm_up, |_| omega, |_| i_dq, Ab::zero(), Ab::zero()) {
        est.step(ab(s.v), ab(s.i));
    }
    est
}

/// Ki·Ts of a tracker with this bandwidth: the most ω̂ can move in one sample is Ki·Ts·π,
/// because the wrapped phase error never exceeds π.
fn ki_ts(bandwidth_hz: f64) -> f64 {
    let c = TrackerConfig::<f64>::new(bandwidth_hz, TS);
    c.gains().1 * c.ts
}

/// θ in [−π, π] with the type's own π (`f32`'s π is 8.7e-8 above the real one).
fn in_angle_range<T: Real>(theta: T) -> bool {
    -T::pi() <= theta && theta <= T::pi()
}

fn finite_estimate<T: Real>(out: &Estimate<T>) -> bool {
    let d = &out.diagnostics;
    out.theta.is_finite()
        && out.omega.is_finite()
        && out.omega_control.is_finite()
        && d.lambda1.is_finite()
        && d.disturbance.is_finite()
        && d.lambda2.is_finite()
        && d.lambda_r.is_finite()
        && d.theta_direct.is_finite()
}

/// Random bounded inputs after a warm-up at a signed speed: every output finite, angles in
/// [−π, π], ω̂ moving at most Ki·Ts·π per sample (hence |ω̂| ≤ |ω̂0| + n·Ki·Ts·π), and the flux
/// states within twice the envelope of a pure integrator fed the worst-case integrand
/// (exponential growth would break it within a few hundred samples).
fn bounded_for_bounded_inputs<T: Real>(
    omega: f64,
    inputs: &[(Ab<f64>, Ab<f64>)],
) -> Result<(), TestCaseError> {
    let mut est = warmed_up::<T>(omega, 3000);
    let start = est.last();
    let flux0 = start
        .diagnostics
        .lambda1
        .norm()
        .to_f64()
        .max(start.diagnostics.disturbance.norm().to_f64());
    let (k1, k2) = (ki_ts(60.0) * PI, ki_ts(35.0) * PI);
    let u_max = V_MAX + default_config::<f64>().machine.rs * I_MAX;
    let (mut w1, mut w2) = (start.omega.to_f64(), start.omega_control.to_f64());
    let slack = 1.0 + 1e-5; // f32 rounding of ω̂ itself
    for (n, &(v, i)) in inputs.iter().enumerate() {
        let out = est.step(ab(v), ab(i));
        let d = out.diagnostics;
        prop_assert!(!d.input_fault, "bounded finite input refused at {n}");
        prop_assert!(finite_estimate(&out), "non-finite output at {n}: {out:?}");
        for th in [out.theta, d.theta_direct] {
            prop_assert!(in_angle_range(th), "angle {th:?} out of [−π, π]");
        }
        let (o1, o2) = (out.omega.to_f64(), out.omega_control.to_f64());
        prop_assert!(
            (o1 - w1).abs() <= k1 * slack + 1e-9 * w1.abs(),
            "ω̂ jumped {w1} → {o1}"
        );
        prop_assert!(
            (o2 - w2).abs() <= k2 * slack + 1e-9 * w2.abs(),
            "ω̂ jumped {w2} → {o2}"
        );
        (w1, w2) = (o1, o2);
        let envelope = 2.0 * (flux0 + LF + (n + 1) as f64 * TS * u_max);
        for (name, x) in [("λ1", d.lambda1), ("D̂", d.disturbance), ("λ̂r", d.lambda_r)] {
            let m = x.norm().to_f64();
            prop_assert!(m <= envelope, "|{name}| = {m} > {envelope} at sample {n}");
        }
    }
    Ok(())
}

/// The ideal machine at a signed speed, started at speed (ω̂ = 0 at first), with bounded
/// noise, DC voltage error and current offset: the state stays near the physical flux
/// (λf + L·|i| plus the k_df-bounded DC drift (|e| + R̂s·|i_off|)/k_df), D̂ never exceeds the
/// flux it is separated from plus that drift, and once settled the angle error stays small.
fn bounded_near_the_machine<T: Real>(
    omega: f64,
    i_dq: Dq<f64>,
    v_dc: Ab<f64>,
    i_off: Ab<f64>,
    noise: &[(Ab<f64>, Ab<f64>)],
) -> Result<(), TestCaseError> {
    let theta0 = -1.0;
    let (_, i0) = flux_and_current(theta0, i_dq);
    let mut est = SensorlessEstimator::<T>::new(EstimatorConfig {
        initial_angle: T::lit(theta0),
        ..default_config()
    })
    .unwrap();
    est.align(T::lit(theta0), ab(i0 + i_off));
    let n = (1.5 / TS) as usize;
    let drift = (v_dc.norm() + RS * i_off.norm()) / 0.5;
    // The noise table is replayed with alternating sign, so it has no DC; its integral over
    // one pass is at most |dv|max·len·Ts.
    let v_noise = noise.iter().map(|n| n.0.norm()).fold(0.0, f64::max);
    let noise_flux = (v_noise + RS * 0.05) * noise.len() as f64 * TS;
    let flux_bound = 1.5 * (LF + L * i_dq.norm()) + drift + noise_flux;
    let mut worst_tail = 0.0_f64;
    for (k, s) in profile(theta0, n, |_| omega, |_| i_dq, v_dc, i_off).enumerate() {
        let (dv, di) = noise[k % noise.len()];
        let sign = if (k / noise.len()).is_multiple_of(2) {
            1.0
        } else {
            -1.0
        };
        let out = est.step(ab(s.v + dv * sign), ab(s.i + di * sign));
        let d = out.diagnostics;
        prop_assert!(!d.input_fault && finite_estimate(&out));
        prop_assert!(in_angle_range(out.theta) && in_angle_range(d.theta_direct));
        let l1 = d.lambda1.norm().to_f64();
        prop_assert!(l1 <= flux_bound, "|λ1| = {l1} > {flux_bound} at {k}");
        let dh = d.disturbance.norm().to_f64();
        let d_bound = drift + LF + L * i_dq.norm() + noise_flux;
        prop_assert!(dh <= d_bound, "|D̂| = {dh} > {d_bound} at {k}");
        if k >= n - 3000 {
            worst_tail = worst_tail.max(fado_core::wrap_angle(s.theta - out.theta.to_f64()).abs());
        }
    }
    // What is left of the angle error once settled, term by term:
    // - Lq·|i_off| shifts λ̂r (eq. (5)): an angle ripple of up to asin(Lq·|i_off|/λf);
    // - the DC part of λ1 still ramps (τ = 1/k_df), and D̂ follows a ramp of slope c with the
    //   lag c·(2|ω| − jω)/ω², i.e. √5·c/|ω| (from D̂/λ1 = ω(ω + js)/(s + |ω|)², docs/method/estimator.md §2), with
    //   c ≤ |e| + R̂s·|i_off| — large at 2 Hz, negligible at 300 Hz (taken 4·c/|ω|);
    // - noise above |ω| passes into λ2: at most its integral over one pass of the table;
    // - 0.05 rad for the settling of the coupled tracker and observer at the lowest speeds.
    let ramp = 4.0 * (v_dc.norm() + RS * i_off.norm()) / omega.abs();
    let allowed = 0.05 + (L * i_off.norm() / LF).asin() + (ramp + noise_flux) / LF;
    prop_assert!(
        worst_tail < allowed,
        "settled angle error {worst_tail} > {allowed}"
    );
    Ok(())
}

/// Rotor currents of the paper's operating range: i_d from 0 to the injection level I_min =
/// 4 A (eq. (23)), |i_q| up to the rated 21.8 A (docs/method/estimator.md, "The paper's motor and drive").
fn rated_current() -> impl Strategy<Value = Dq<f64>> {
    (0.0..=4.0, -21.8..=21.8).prop_map(|(d, q)| Dq::new(d, q))
}

/// The estimator's state with the rejected-sample counter blanked out. `Debug` prints every
/// field, floats in their shortest round-trip form, so equal strings mean equal states
/// (bit-for-bit, −0.0 included) — a stricter comparison than `PartialEq`.
fn state<T: Real + Debug>(est: &SensorlessEstimator<T>) -> String {
    let counter = format!("rejected_samples: {}", est.rejected_samples());
    format!("{est:?}").replace(&counter, "rejected_samples: _")
}

/// One sample: if it is refused, the whole state must be exactly as before (apart from the
/// counter, which must count it) and the output must be the last good estimate with
/// `input_fault` set; if it is taken, every output must be finite.
fn step_and_check<T: Real + Debug>(
    est: &mut SensorlessEstimator<T>,
    v: Ab<T>,
    i: Ab<T>,
) -> Result<bool, TestCaseError> {
    let before = *est;
    let out = est.step(v, i);
    if out.diagnostics.input_fault {
        prop_assert_eq!(est.rejected_samples(), before.rejected_samples() + 1);
        prop_assert_eq!(state(est), state(&before));
        let mut expected = before.last();
        expected.diagnostics.input_fault = true;
        prop_assert_eq!(format!("{out:?}"), format!("{expected:?}"));
    } else {
        prop_assert!(finite_estimate(&out), "accepted sample gave {out:?}");
        prop_assert!(in_angle_range(out.theta) && in_angle_range(out.diagnostics.theta_direct));
        prop_assert_eq!(est.rejected_samples(), before.rejected_samples());
        // `last` recomputes the diagnostics from the state; the outputs are the sample's.
        let last = est.last();
        prop_assert_eq!(
            (
                last.theta,
                last.omega,
                last.omega_control,
                last.diagnostics.mode
            ),
            (
                out.theta,
                out.omega,
                out.omega_control,
                out.diagnostics.mode
            )
        );
    }
    Ok(out.diagnostics.input_fault)
}

/// A non-finite value of one of three kinds.
fn non_finite() -> impl Strategy<Value = f64> {
    prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)]
}

/// A poisoning event: at sample `at`, replace the components selected by the bits of `mask`
/// (vα, vβ, iα, iβ; at least one) by `value`.
fn poison() -> impl Strategy<Value = (usize, u8, f64)> {
    (0usize..600, 1u8..16, non_finite())
}

/// Finite samples of the machine at `omega` with non-finite components injected: every
/// poisoned sample is refused with the state untouched, every clean one is taken.
fn rejects_non_finite<T: Real + Debug>(
    omega: f64,
    events: &[(usize, u8, f64)],
) -> Result<(), TestCaseError> {
    let mut est = warmed_up::<T>(omega, 2000);
    let i_dq = Dq::new(2.0, 8.0);
    for (k, s) in profile(0.1, 600, |_| omega, |_| i_dq, Ab::zero(), Ab::zero()).enumerate() {
        let mut c = [s.v.alpha, s.v.beta, s.i.alpha, s.i.beta];
        let mut poisoned = false;
        for &(_, mask, value) in events.iter().filter(|e| e.0 == k) {
            for (bit, x) in c.iter_mut().enumerate() {
                if mask & (1 << bit) != 0 {
                    *x = value;
                    poisoned = true;
                }
            }
        }
        let v = Ab::new(T::lit(c[0]), T::lit(c[1]));
        let i = Ab::new(T::lit(c[2]), T::lit(c[3]));
        let refused = step_and_check(&mut est, v, i)?;
        prop_assert_eq!(
            refused,
            poisoned,
            "sample {}: refused {} poisoned {}",
            k,
            refused,
            poisoned
        );
    }
    Ok(())
}

/// Cases per property: `default`, or `PROPTEST_CASES` for a deeper local run.
fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(48), ..ProptestConfig::default() })]

    #[test]
    fn f32_state_bounded_for_bounded_inputs(
        omega in signed_speed(0.5, 300.0),
        inputs in prop::collection::vec((bounded_vector(V_MAX), bounded_vector(I_MAX)), 1..1500),
    ) {
        bounded_for_bounded_inputs::<f32>(omega, &inputs)?;
    }

    #[test]
    fn f64_state_bounded_for_bounded_inputs(
        omega in signed_speed(0.5, 300.0),
        inputs in prop::collection::vec((bounded_vector(V_MAX), bounded_vector(I_MAX)), 1..1500),
    ) {
        bounded_for_bounded_inputs::<f64>(omega, &inputs)?;
    }

    #[test]
    fn f32_state_bounded_near_the_machine(
        omega in signed_speed(2.0, 300.0),
        i_dq in rated_current(),
        v_dc in bounded_vector(0.1),
        i_off in bounded_vector(0.1),
        noise in prop::collection::vec((bounded_vector(0.5), bounded_vector(0.05)), 1..400),
    ) {
        bounded_near_the_machine::<f32>(omega, i_dq, v_dc, i_off, &noise)?;
    }

    #[test]
    fn f64_state_bounded_near_the_machine(
        omega in signed_speed(2.0, 300.0),
        i_dq in rated_current(),
        v_dc in bounded_vector(0.1),
        i_off in bounded_vector(0.1),
        noise in prop::collection::vec((bounded_vector(0.5), bounded_vector(0.05)), 1..400),
    ) {
        bounded_near_the_machine::<f64>(omega, i_dq, v_dc, i_off, &noise)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(96), ..ProptestConfig::default() })]

    #[test]
    fn f32_non_finite_inputs_leave_the_state_unchanged(
        omega in signed_speed(0.0, 300.0),
        events in prop::collection::vec(poison(), 1..40),
    ) {
        rejects_non_finite::<f32>(omega, &events)?;
    }

    #[test]
    fn f64_non_finite_inputs_leave_the_state_unchanged(
        omega in signed_speed(0.0, 300.0),
        events in prop::collection::vec(poison(), 1..40),
    ) {
        rejects_non_finite::<f64>(omega, &events)?;
    }

    /// Any bit pattern at all (NaN, ±∞, subnormals, ±MAX): the estimator never takes a
    /// non-finite state; whatever it refuses leaves the state exactly as it was.
    #[test]
    fn f32_any_input_is_either_taken_finite_or_refused_cleanly(
        inputs in prop::collection::vec(prop::array::uniform4(any::<f32>()), 1..300),
    ) {
        let mut est = warmed_up::<f32>(60.0, 500);
        for c in inputs {
            step_and_check(&mut est, Ab::new(c[0], c[1]), Ab::new(c[2], c[3]))?;
        }
    }

    #[test]
    fn f64_any_input_is_either_taken_finite_or_refused_cleanly(
        inputs in prop::collection::vec(prop::array::uniform4(any::<f64>()), 1..300),
    ) {
        let mut est = warmed_up::<f64>(-60.0, 500);
        for c in inputs {
            step_and_check(&mut est, Ab::new(c[0], c[1]), Ab::new(c[2], c[3]))?;
        }
    }
}
