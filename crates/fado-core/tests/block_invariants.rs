//! Property tests of the estimator's blocks on their own: the frequency-adaptive disturbance
//! observer (eq. (9)-(10), gains (16)) and the type-2 tracker (Fig. 1), in `f32` and `f64`.

use core::f64::consts::{PI, TAU};
use core::fmt::Debug;

use fado_core::observer::{DisturbanceObserver, DisturbanceObserverConfig};
use fado_core::tracker::{TrackerConfig, TypeTwoTracker};
use fado_core::{Ab, Real, wrap_angle};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

const TS: f64 = 100e-6;

fn ab<T: Real>(x: Ab<f64>) -> Ab<T> {
    Ab::new(T::lit(x.alpha), T::lit(x.beta))
}

fn ab64<T: Real>(x: Ab<T>) -> Ab<f64> {
    Ab::new(x.alpha.to_f64(), x.beta.to_f64())
}

fn conj<T: Real>(x: Ab<T>) -> Ab<T> {
    Ab::new(x.alpha, -x.beta)
}

fn observer<T: Real>() -> DisturbanceObserver<T> {
    DisturbanceObserver::new(DisturbanceObserverConfig { ts: T::lit(TS) }).unwrap()
}

fn signed_speed(lo_hz: f64, hi_hz: f64) -> impl Strategy<Value = f64> {
    (lo_hz..=hi_hz, any::<bool>()).prop_map(|(f, neg)| if neg { -f } else { f } * TAU)
}

fn vector(max: f64) -> impl Strategy<Value = Ab<f64>> {
    (0.0..=max, -PI..PI).prop_map(|(m, a)| Ab::from_polar(m, a))
}

/// λ1 = A·e^{j(ωt + φ)} + D at a constant ω known to the observer: after 30 time constants of
/// its quadruple pole at −|ω| (transients t·e^{−|ω|t}) D̂ equals D and λ̂1 equals λ1 (the
/// observer's λ̂1 after a step is its internal model's prediction for the next sample), to the
/// precision of the type (eq. (7), (17)-(19): unity DC gain, notch at ω). Rounding errors of
/// the rotation add up over the ~1/(|ω|·Ts) samples of a time constant, hence the tolerance
/// ε/(|ω|·Ts).
fn separates<T: Real>(
    omega: f64,
    amplitude: f64,
    phase: f64,
    offset: Ab<f64>,
    epsilon: f64,
) -> Result<(), TestCaseError> {
    let mut obs = observer::<T>();
    let n = (30.0 / (omega.abs() * TS)) as usize + 10;
    let y = |k: usize| Ab::from_polar(amplitude, phase + omega * TS * k as f64) + offset;
    for k in 0..n {
        obs.step(ab(y(k)), T::lit(omega)).unwrap();
    }
    let scale = amplitude + offset.norm();
    let tol = 1e-9_f64.max(8.0 * epsilon / (omega.abs() * TS));
    let d_err = (ab64(obs.disturbance()) - offset).norm();
    let z_err = (ab64(obs.flux()) - y(n)).norm();
    prop_assert!(d_err <= tol * scale, "|D̂ − D| = {d_err:e} (scale {scale})");
    prop_assert!(z_err <= tol * scale, "|λ̂1 − λ1| = {z_err:e}");
    Ok(())
}

/// The gains (16) make the observer the mirror image of itself under ω → −ω (docs/method/estimator.md §2: same
/// poles for both signs): feeding the conjugate input at −ω gives exactly the conjugate
/// state, bit for bit, for any sequence of inputs and speeds.
fn mirror_symmetric<T: Real>(steps: &[(Ab<f64>, f64)]) -> Result<(), TestCaseError> {
    let (mut a, mut b) = (observer::<T>(), observer::<T>());
    for &(y, w) in steps {
        let y = ab::<T>(y);
        let w = T::lit(w);
        let da = a.step(y, w).unwrap();
        let db = b.step(conj(y), -w).unwrap();
        prop_assert_eq!(conj(da), db);
        prop_assert_eq!(conj(a.flux()), b.flux());
    }
    Ok(())
}

/// With ω varying no faster than 1 rad/s per sample (10⁴ rad/s² electrical, above this
/// drive's 3.8·10³ at full torque), the time-varying observer stays bounded: its state never
/// exceeds 4 times the largest input.
fn bounded_for_slow_speed_changes<T: Real>(
    omega0: f64,
    steps: &[(Ab<f64>, f64)],
) -> Result<(), TestCaseError> {
    let mut obs = observer::<T>();
    let mut w = omega0;
    let mut y_max: f64 = 1e-3;
    for (k, &(y, dw)) in steps.iter().enumerate() {
        w = (w + dw).clamp(-TAU * 300.0, TAU * 300.0);
        y_max = y_max.max(y.norm());
        obs.step(ab(y), T::lit(w)).unwrap();
        let m = ab64(obs.disturbance()).norm().max(ab64(obs.flux()).norm());
        prop_assert!(
            m.is_finite() && m <= 4.0 * y_max,
            "state {m} at {k}, |y| ≤ {y_max}"
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
    #![proptest_config(ProptestConfig { cases: cases(64), ..ProptestConfig::default() })]

    #[test]
    fn f64_observer_converges_to_the_offset(
        omega in signed_speed(1.0, 300.0),
        amplitude in 0.01..0.5,
        phase in -PI..PI,
        offset in vector(0.2),
    ) {
        separates::<f64>(omega, amplitude, phase, offset, f64::EPSILON)?;
    }

    #[test]
    fn f32_observer_converges_to_the_offset(
        omega in signed_speed(1.0, 300.0),
        amplitude in 0.01..0.5,
        phase in -PI..PI,
        offset in vector(0.2),
    ) {
        separates::<f32>(omega, amplitude, phase, offset, f32::EPSILON as f64)?;
    }

    #[test]
    fn f64_observer_is_mirror_symmetric_in_omega(
        steps in prop::collection::vec((vector(1.0), -3000.0..3000.0), 1..400),
    ) {
        mirror_symmetric::<f64>(&steps)?;
    }

    #[test]
    fn f32_observer_is_mirror_symmetric_in_omega(
        steps in prop::collection::vec((vector(1.0), -3000.0..3000.0), 1..400),
    ) {
        mirror_symmetric::<f32>(&steps)?;
    }

    #[test]
    fn observer_freezes_at_standstill(
        start in vector(1.0),
        inputs in prop::collection::vec(vector(100.0), 1..200),
    ) {
        // All gains of (16) vanish at ω = 0 (paper, Fig. 2 discussion): nothing moves.
        let mut obs = observer::<f64>();
        obs.reset_to(start);
        let before = obs;
        for y in inputs {
            prop_assert_eq!(obs.step(y, 0.0).unwrap(), Ab::zero());
        }
        prop_assert_eq!(obs, before);
    }

    #[test]
    fn f64_observer_bounded_for_slow_speed_changes(
        omega0 in signed_speed(0.0, 300.0),
        steps in prop::collection::vec((vector(1.0), -1.0..1.0), 1..4000),
    ) {
        bounded_for_slow_speed_changes::<f64>(omega0, &steps)?;
    }

    #[test]
    fn f32_observer_bounded_for_slow_speed_changes(
        omega0 in signed_speed(0.0, 300.0),
        steps in prop::collection::vec((vector(1.0), -1.0..1.0), 1..4000),
    ) {
        bounded_for_slow_speed_changes::<f32>(omega0, &steps)?;
    }
}

fn tracker<T: Real>(bandwidth_hz: f64) -> TypeTwoTracker<T> {
    TypeTwoTracker::new(TrackerConfig::new(T::lit(bandwidth_hz), T::lit(TS))).unwrap()
}

/// Any finite measurement sequence, of any size: θ̂ and θ̂⁻ stay in [−π, π] and ω̂ moves by at
/// most Ki·Ts·π per sample (the wrapped error is at most π, plus the rounding of a huge input
/// itself: 0.06 rad for 10⁶ rad in `f32`); a non-finite measurement is refused and changes
/// nothing.
fn tracker_stays_in_range<T: Real + Debug>(
    bandwidth_hz: f64,
    inputs: &[f64],
    epsilon: f64,
) -> Result<(), TestCaseError> {
    let mut t = tracker::<T>(bandwidth_hz);
    let (_, ki) = t.gains();
    for &x in inputs {
        let max_dw = ki.to_f64() * TS * (PI + 4.0 * epsilon * (x.abs() + PI));
        let before = t;
        match t.step(T::lit(x)) {
            Ok((theta, omega)) => {
                prop_assert!(x.is_finite());
                for a in [theta, t.predicted_angle()] {
                    // The type's own π: f32's is 8.7e-8 above the real one.
                    prop_assert!(-T::pi() <= a && a <= T::pi(), "angle {a:?} for input {x}");
                }
                let dw = (omega - before.speed()).to_f64().abs();
                prop_assert!(dw <= max_dw + 1e-6 * omega.to_f64().abs(), "Δω̂ = {dw}");
            }
            Err(_) => {
                prop_assert!(!x.is_finite());
                prop_assert_eq!(t, before);
            }
        }
    }
    Ok(())
}

fn measurement() -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => -10.0..10.0,
        2 => -1e6..1e6,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(64), ..ProptestConfig::default() })]

    #[test]
    fn f64_tracker_output_stays_in_range(
        bandwidth in 1.0..500.0,
        inputs in prop::collection::vec(measurement(), 1..500),
    ) {
        tracker_stays_in_range::<f64>(bandwidth, &inputs, f64::EPSILON)?;
    }

    #[test]
    fn f32_tracker_output_stays_in_range(
        bandwidth in 1.0..500.0,
        inputs in prop::collection::vec(measurement(), 1..500),
    ) {
        tracker_stays_in_range::<f32>(bandwidth, &inputs, f32::EPSILON as f64)?;
    }

    #[test]
    fn tracker_locks_on_any_constant_speed(
        omega in signed_speed(0.0, 300.0),
        theta0 in -PI..PI,
        bandwidth in prop_oneof![Just(35.0), Just(60.0)],
    ) {
        // Type 2: zero steady-state error for a constant speed, from ω̂ = 0 and any angle
        // error (pull-in through cycle slips, then lock), at both of the paper's bandwidths.
        let mut t = tracker::<f64>(bandwidth);
        let n = (1.5 / TS) as usize;
        for k in 0..n {
            t.step(wrap_angle(theta0 + omega * TS * k as f64)).unwrap();
        }
        let th = wrap_angle(theta0 + omega * TS * (n - 1) as f64);
        prop_assert!(wrap_angle(th - t.angle()).abs() < 1e-9, "θ error {}", wrap_angle(th - t.angle()));
        prop_assert!((t.speed() - omega).abs() < 1e-6, "ω̂ = {} vs {omega}", t.speed());
    }

    #[test]
    fn tracker_lags_a_ramp_by_alpha_over_ki(
        omega0 in signed_speed(0.0, 50.0),
        alpha in -2000.0..2000.0_f64,
        theta0 in -PI..PI,
    ) {
        // Type 2: a constant acceleration α leaves the constant angle error α/Ki (Fig. 1).
        let mut t = tracker::<f64>(60.0);
        let (_, ki) = t.gains();
        t.reset_to(theta0, omega0);
        let n = (0.5 / TS) as usize;
        let mut err = 0.0_f64;
        for k in 0..n {
            let tk = TS * k as f64;
            let th = theta0 + omega0 * tk + 0.5 * alpha * tk * tk;
            let (est, _) = t.step(wrap_angle(th)).unwrap();
            err = wrap_angle(th - est);
        }
        let expected = alpha / ki;
        prop_assert!((err - expected).abs() < 0.05 * expected.abs() + 1e-9, "{err} vs α/Ki = {expected}");
    }
}
