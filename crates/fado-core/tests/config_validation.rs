//! Every public constructor validates every numeric field of its configuration (issue 6,
//! "bad input"): table-driven over the fields of each config type, in f32 and f64.
//!
//! For each field, starting from the default configuration:
//! - NaN, +∞ and −∞ are refused with an error naming exactly that field;
//! - −1 is refused naming the field unless the field is signed (an angle, a PI output bound);
//! - 0 is refused naming the field where the field must be positive;
//! - a huge value (1e30) is refused naming the field where the field is bounded by the
//!   sampling rate (bandwidths, gains whose discrete loop would be unstable) or by a ratio;
//! - where 0 or a huge value is allowed, the constructor either accepts it or names the field.
//!
//! Cross-field constraints (thresholds out of order, bandwidths above what the sampling rate
//! allows) are tested one by one below the table.

use fado_core::ConfigError;
use fado_core::Real;
use fado_core::baselines::{
    EmfObserverConfig, EmfObserverEstimator, LpfIntegratorConfig, LpfIntegratorEstimator,
    OrtegaConfig, OrtegaEstimator,
};
use fado_core::control::{
    CurrentController, CurrentControllerConfig, DeadTimeCompensation, DeadTimeCompensationConfig,
    DelayCompensation, DelayCompensationConfig, DriveConfig, ModulatorConfig, Pi, PiConfig,
    SensorlessDrive, SpaceVectorModulator, SpeedController, SpeedControllerConfig,
};
use fado_core::estimator::{EstimatorConfig, SensorlessEstimator};
use fado_core::flux::{
    DisturbanceFeedback, DisturbanceFeedbackConfig, FluxIntegrator, FluxIntegratorConfig,
    FluxLimiter, FluxLimiterConfig,
};
use fado_core::injection::{CurrentInjection, CurrentInjectionConfig};
use fado_core::mode::{ModeSelector, ModeSelectorConfig};
use fado_core::observer::{DisturbanceObserver, DisturbanceObserverConfig};
use fado_core::tracker::{TrackerConfig, TypeTwoTracker};

/// What a field's valid range is.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Range {
    /// Any finite value.
    Signed,
    /// ≥ 0, unbounded above.
    NonNegative,
    /// > 0, unbounded above.
    Positive,
    /// ≥ 0 and bounded above (by the sampling rate or a ratio).
    NonNegativeBounded,
    /// > 0 and bounded above (by the sampling rate or a ratio).
    PositiveBounded,
}

/// One row of the table: a field name, how to set it, and its range.
struct Field<C, T> {
    name: &'static str,
    set: fn(&mut C, T),
    range: Range,
}

macro_rules! fields {
    ($c:ty, $t:ty; $($name:ident: $range:ident),* $(,)?) => {
        [$(Field::<$c, $t> {
            name: stringify!($name),
            set: |c: &mut $c, v: $t| c.$name = v,
            range: Range::$range,
        }),*]
    };
}

/// Runs the table for one config type; appends every violation to `failures` and returns the
/// number of cases checked.
fn probe<C: Copy + core::fmt::Debug, T: Real>(
    failures: &mut Vec<String>,
    what: &str,
    base: C,
    build: impl Fn(C) -> Result<(), ConfigError>,
    fields: &[Field<C, T>],
) -> usize {
    assert_eq!(build(base), Ok(()), "{what}: the default must be valid");
    let mut cases = 0;
    for f in fields {
        let with = |v: T| {
            let mut c = base;
            (f.set)(&mut c, v);
            build(c)
        };
        let mut check = |v: T, must_refuse: bool, why: &str| {
            cases += 1;
            match with(v) {
                // Where the value itself may be valid, a cross-field constraint may name the
                // other field of the pair (a huge ts makes a bandwidth unstable).
                Err(ConfigError::OutOfRange { .. }) if !must_refuse => {}
                Err(e) if e.field() != f.name => failures.push(format!(
                    "{what}.{} = {v:?} ({why}): the error names another field: {e}",
                    f.name
                )),
                Ok(()) if must_refuse => {
                    failures.push(format!("{what}.{} = {v:?} ({why}) was accepted", f.name))
                }
                _ => {}
            }
        };
        check(T::lit(f64::NAN), true, "NaN");
        check(T::lit(f64::INFINITY), true, "+inf");
        check(T::lit(f64::NEG_INFINITY), true, "-inf");
        check(-T::one(), f.range != Range::Signed, "negative");
        let positive = matches!(f.range, Range::Positive | Range::PositiveBounded);
        check(T::zero(), positive, "zero");
        let bounded = matches!(f.range, Range::NonNegativeBounded | Range::PositiveBounded);
        check(T::lit(1e30), bounded, "beyond its bound");
        if !matches!(with(T::lit(f64::NAN)), Err(ConfigError::NotFinite { .. })) {
            failures.push(format!("{what}.{}: NaN not reported as NotFinite", f.name));
        }
    }
    cases
}

fn ok<X>(r: Result<X, ConfigError>) -> Result<(), ConfigError> {
    r.map(|_| ())
}

fn run_all<T: Real>(failures: &mut Vec<String>) -> usize {
    let mut n = 0;
    n += probe(
        failures,
        "EstimatorConfig",
        EstimatorConfig::<T>::default(),
        |c| ok(SensorlessEstimator::new(c)),
        &fields!(EstimatorConfig<T>, T;
            ts: Positive,
            rs_hat: NonNegative,
            lq_hat: NonNegative,
            flux_linkage_hat: Positive,
            k_df: NonNegativeBounded,
            k_df_ramp_time: NonNegative,
            k_af: NonNegativeBounded,
            limiter_radius_ratio: Positive,
            mode_threshold_hz: NonNegativeBounded,
            mode_hysteresis_hz: NonNegativeBounded,
            t2s1_bandwidth_hz: PositiveBounded,
            t2s2_bandwidth_hz: PositiveBounded,
            tracker_damping: Positive,
            tracker_hold_ratio: NonNegativeBounded,
            initial_angle: Signed,
        ),
    );
    n += probe(
        failures,
        "DriveConfig",
        DriveConfig::<T>::default(),
        |c| c.validate(),
        &fields!(DriveConfig<T>, T;
            ts: Positive,
            pole_pairs: Positive,
            rs_hat: NonNegative,
            ld_hat: Positive,
            lq_hat: Positive,
            flux_linkage_hat: Positive,
            inertia_hat: Positive,
            current_bandwidth_hz: PositiveBounded,
            speed_bandwidth_hz: PositiveBounded,
            speed_zero_ratio: Positive,
            i_max: Positive,
            i_min: NonNegativeBounded,
            dead_time: NonNegativeBounded,
            switching_frequency: Positive,
            dead_time_threshold_voltage: NonNegative,
            dead_time_current_band: Positive,
            delay_compensation_factor: NonNegativeBounded,
            trip_current: Positive,
            max_modulation: PositiveBounded,
            current_anti_windup_ratio: NonNegativeBounded,
            speed_anti_windup_ratio: NonNegativeBounded,
        ),
    );
    // The drive with its estimator: the same checks reach `SensorlessDrive::new`.
    n += probe(
        failures,
        "SensorlessDrive",
        DriveConfig::<T>::default(),
        |c| {
            let est = EstimatorConfig {
                ts: c.ts,
                ..EstimatorConfig::default()
            };
            ok(SensorlessDrive::new(c, est))
        },
        &fields!(DriveConfig<T>, T;
            ts: Positive,
            i_max: Positive,
            current_bandwidth_hz: PositiveBounded,
        ),
    );
    n += probe(
        failures,
        "TrackerConfig",
        TrackerConfig::<T>::default(),
        |c| ok(TypeTwoTracker::new(c)),
        &fields!(TrackerConfig<T>, T;
            ts: Positive,
            bandwidth_hz: PositiveBounded,
            damping: Positive,
        ),
    );
    n += probe(
        failures,
        "FluxIntegratorConfig",
        FluxIntegratorConfig::<T> {
            ts: T::lit(1e-4),
            rs_hat: T::lit(0.3),
            average_current: true,
        },
        |c| ok(FluxIntegrator::new(c)),
        &fields!(FluxIntegratorConfig<T>, T; ts: Positive, rs_hat: NonNegative),
    );
    n += probe(
        failures,
        "DisturbanceFeedbackConfig",
        DisturbanceFeedbackConfig::<T> {
            ts: T::lit(1e-4),
            k_df: T::lit(0.5),
            ramp_time: T::zero(),
        },
        |c| ok(DisturbanceFeedback::new(c)),
        &fields!(DisturbanceFeedbackConfig<T>, T;
            ts: Positive, k_df: NonNegativeBounded, ramp_time: NonNegative),
    );
    n += probe(
        failures,
        "FluxLimiterConfig",
        FluxLimiterConfig::<T> {
            k_af: T::lit(628.0),
            radius: T::lit(0.1),
        },
        |c| ok(FluxLimiter::new(c)),
        &fields!(FluxLimiterConfig<T>, T; k_af: NonNegative, radius: Positive),
    );
    n += probe(
        failures,
        "ModeSelectorConfig",
        ModeSelectorConfig::<T> {
            threshold_hz: T::lit(1.5),
            hysteresis_hz: T::lit(0.2),
        },
        |c| ok(ModeSelector::new(c)),
        &fields!(ModeSelectorConfig<T>, T;
            threshold_hz: NonNegative, hysteresis_hz: NonNegativeBounded),
    );
    n += probe(
        failures,
        "DisturbanceObserverConfig",
        DisturbanceObserverConfig::<T> { ts: T::lit(1e-4) },
        |c| ok(DisturbanceObserver::new(c)),
        &fields!(DisturbanceObserverConfig<T>, T; ts: Positive),
    );
    n += probe(
        failures,
        "CurrentInjectionConfig",
        CurrentInjectionConfig::<T> { i_min: T::lit(4.0) },
        |c| ok(CurrentInjection::new(c)),
        &fields!(CurrentInjectionConfig<T>, T; i_min: NonNegative),
    );
    n += probe(
        failures,
        "PiConfig",
        PiConfig::<T> {
            ts: T::lit(1e-4),
            kp: T::lit(1.0),
            ki: T::lit(100.0),
            output_min: T::lit(-10.0),
            output_max: T::lit(10.0),
            anti_windup_ratio: T::one(),
        },
        |c| ok(Pi::new(c)),
        &fields!(PiConfig<T>, T;
            ts: Positive,
            kp: Positive,
            ki: NonNegative,
            output_min: Signed,
            output_max: Signed,
            anti_windup_ratio: NonNegativeBounded,
        ),
    );
    n += probe(
        failures,
        "CurrentControllerConfig",
        CurrentControllerConfig::<T> {
            ts: T::lit(1e-4),
            rs_hat: T::lit(0.327),
            ld_hat: T::lit(2.63e-3),
            lq_hat: T::lit(2.63e-3),
            flux_linkage_hat: T::lit(0.088),
            bandwidth_hz: T::lit(250.0),
            decoupling: true,
            anti_windup_ratio: T::one(),
            voltage_bound: T::lit(180.0),
        },
        |c| ok(CurrentController::new(c)),
        &fields!(CurrentControllerConfig<T>, T;
            ts: Positive,
            rs_hat: NonNegative,
            ld_hat: Positive,
            lq_hat: Positive,
            flux_linkage_hat: NonNegative,
            bandwidth_hz: PositiveBounded,
            anti_windup_ratio: NonNegativeBounded,
            voltage_bound: Positive,
        ),
    );
    n += probe(
        failures,
        "SpeedControllerConfig",
        SpeedControllerConfig::<T> {
            ts: T::lit(1e-4),
            pole_pairs: T::lit(4.0),
            inertia_hat: T::lit(0.012),
            flux_linkage_hat: T::lit(0.088),
            bandwidth_hz: T::lit(5.0),
            zero_ratio: T::lit(5.0),
            i_max: T::lit(40.0),
            anti_windup_ratio: T::lit(5.0),
        },
        |c| ok(SpeedController::new(c)),
        &fields!(SpeedControllerConfig<T>, T;
            ts: Positive,
            pole_pairs: Positive,
            inertia_hat: Positive,
            flux_linkage_hat: Positive,
            bandwidth_hz: PositiveBounded,
            zero_ratio: Positive,
            i_max: Positive,
            anti_windup_ratio: NonNegativeBounded,
        ),
    );
    n += probe(
        failures,
        "DelayCompensationConfig",
        DelayCompensationConfig::<T> {
            ts: T::lit(1e-4),
            factor: T::lit(1.5),
        },
        |c| ok(DelayCompensation::new(c)),
        &fields!(DelayCompensationConfig<T>, T; ts: Positive, factor: NonNegativeBounded),
    );
    n += probe(
        failures,
        "DeadTimeCompensationConfig",
        DeadTimeCompensationConfig::<T>::default(),
        |c| ok(DeadTimeCompensation::new(c)),
        &fields!(DeadTimeCompensationConfig<T>, T;
            dead_time: NonNegativeBounded,
            switching_frequency: Positive,
            threshold_voltage: NonNegative,
            current_band: Positive,
        ),
    );
    n += probe(
        failures,
        "ModulatorConfig",
        ModulatorConfig::<T>::default(),
        |c| ok(SpaceVectorModulator::new(c)),
        &fields!(ModulatorConfig<T>, T; max_modulation: PositiveBounded),
    );
    n += probe(
        failures,
        "LpfIntegratorConfig",
        LpfIntegratorConfig::<T>::default(),
        |c| ok(LpfIntegratorEstimator::new(c)),
        &fields!(LpfIntegratorConfig<T>, T;
            ts: Positive,
            rs_hat: NonNegative,
            lq_hat: NonNegative,
            flux_linkage_hat: Positive,
            cutoff_hz: NonNegativeBounded,
            compensation_floor_hz: Positive,
            t2s1_bandwidth_hz: PositiveBounded,
            t2s2_bandwidth_hz: PositiveBounded,
            tracker_damping: Positive,
            tracker_hold_ratio: NonNegativeBounded,
            initial_angle: Signed,
        ),
    );
    n += probe(
        failures,
        "OrtegaConfig",
        OrtegaConfig::<T>::default(),
        |c| ok(OrtegaEstimator::new(c)),
        &fields!(OrtegaConfig<T>, T;
            ts: Positive,
            rs_hat: NonNegative,
            lq_hat: NonNegative,
            flux_linkage_hat: Positive,
            observer_bandwidth: PositiveBounded,
            observer_speed_ratio: NonNegative,
            observer_bandwidth_min: PositiveBounded,
            flux_adaptation_ratio: NonNegative,
            t2s1_bandwidth_hz: PositiveBounded,
            t2s2_bandwidth_hz: PositiveBounded,
            tracker_damping: Positive,
            tracker_hold_ratio: NonNegativeBounded,
            initial_angle: Signed,
        ),
    );
    n += probe(
        failures,
        "EmfObserverConfig",
        EmfObserverConfig::<T>::default(),
        |c| ok(EmfObserverEstimator::new(c)),
        &fields!(EmfObserverConfig<T>, T;
            ts: Positive,
            rs_hat: NonNegative,
            lq_hat: NonNegative,
            flux_linkage_hat: Positive,
            emf_bandwidth_hz: PositiveBounded,
            speed_floor_hz: Positive,
            t2s1_bandwidth_hz: PositiveBounded,
            t2s2_bandwidth_hz: PositiveBounded,
            tracker_damping: Positive,
            tracker_hold_ratio: NonNegativeBounded,
            initial_angle: Signed,
        ),
    );
    n
}

#[test]
fn every_field_of_every_config_is_validated_f64() {
    let mut failures = Vec::new();
    let n = run_all::<f64>(&mut failures);
    assert!(
        failures.is_empty(),
        "{} of {n} cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(n > 300, "only {n} cases ran");
}

#[test]
fn every_field_of_every_config_is_validated_f32() {
    let mut failures = Vec::new();
    let n = run_all::<f32>(&mut failures);
    assert!(
        failures.is_empty(),
        "{} of {n} cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(n > 300, "only {n} cases ran");
}

/// The field a config is refused for, or "" when it is accepted.
fn refused_field<X>(r: Result<X, ConfigError>) -> &'static str {
    r.map_or_else(|e| e.field(), |_| "")
}

/// The field the default estimator config is refused for after `f`, or "".
fn est(f: impl FnOnce(&mut EstimatorConfig<f64>)) -> &'static str {
    let mut c = EstimatorConfig::default();
    f(&mut c);
    refused_field(SensorlessEstimator::new(c))
}

/// The field the default drive config is refused for after `f`, or "".
fn drive(f: impl FnOnce(&mut DriveConfig<f64>)) -> &'static str {
    let mut c = DriveConfig::default();
    f(&mut c);
    refused_field(c.validate())
}

#[test]
fn bandwidths_above_what_the_sampling_rate_allows_are_refused() {
    let ts = 100e-6; // 10 kHz
    // T2S: the first bandwidth refused must violate Jury's conditions (tracker docs), the one
    // below it must not be refused.
    let limit = (1..20_000)
        .map(|f| f as f64)
        .find(|&f| {
            TypeTwoTracker::new(TrackerConfig {
                bandwidth_hz: f,
                ..TrackerConfig::default()
            })
            .is_err()
        })
        .expect("some bandwidth below 20 kHz must be unstable at 10 kHz");
    let (kp, ki) = TrackerConfig {
        bandwidth_hz: limit,
        ..TrackerConfig::<f64>::default()
    }
    .gains();
    assert!(
        kp * ts >= 2.0 || 2.0 * kp * ts + ki * ts * ts >= 4.0,
        "refused at {limit} Hz although Jury's conditions hold"
    );
    assert_eq!(est(|c| c.t2s1_bandwidth_hz = limit), "t2s1_bandwidth_hz");
    assert_eq!(est(|c| c.t2s2_bandwidth_hz = limit), "t2s2_bandwidth_hz");
    assert_eq!(est(|c| c.t2s1_bandwidth_hz = limit - 1.0), "");
    // Limiter and disturbance feedback: one step must not remove more than the excess.
    assert_eq!(est(|c| c.k_af = 1.0 / ts), "");
    assert_eq!(est(|c| c.k_af = 1.01 / ts), "k_af");
    assert_eq!(est(|c| c.k_df = 1.0 / ts), "");
    assert_eq!(est(|c| c.k_df = 1.01 / ts), "k_df");
    // The mode band must lie below Nyquist (5 kHz).
    assert_eq!(est(|c| c.mode_threshold_hz = 5000.0), "mode_threshold_hz");
    assert_eq!(
        est(|c| {
            c.mode_threshold_hz = 4900.0;
            c.mode_hysteresis_hz = 200.0;
        }),
        "mode_hysteresis_hz"
    );
    // Drive: current PI (2π·f·Ts ≤ 0.5) and speed PI (2π·f·Ts < 0.1).
    let f_cc = 0.5 / (2.0 * std::f64::consts::PI * ts);
    assert_eq!(drive(|c| c.current_bandwidth_hz = 790.0), "");
    assert!(f_cc < 800.0);
    assert_eq!(
        drive(|c| c.current_bandwidth_hz = 800.0),
        "current_bandwidth_hz"
    );
    assert_eq!(
        drive(|c| c.speed_bandwidth_hz = 160.0),
        "speed_bandwidth_hz"
    );
    assert_eq!(drive(|c| c.speed_bandwidth_hz = 150.0), "");
    // Baselines.
    let lpf = LpfIntegratorConfig::<f64> {
        cutoff_hz: 1600.0,
        ..Default::default()
    };
    assert_eq!(refused_field(LpfIntegratorEstimator::new(lpf)), "cutoff_hz");
    let emf = EmfObserverConfig::<f64> {
        emf_bandwidth_hz: 1600.0,
        ..Default::default()
    };
    assert_eq!(
        refused_field(EmfObserverEstimator::new(emf)),
        "emf_bandwidth_hz"
    );
    let ortega = OrtegaConfig::<f64> {
        observer_bandwidth: 1.0e4,
        ..Default::default()
    };
    assert_eq!(
        refused_field(OrtegaEstimator::new(ortega)),
        "observer_bandwidth"
    );
}

#[test]
fn thresholds_out_of_order_are_refused() {
    assert_eq!(est(|c| c.mode_hysteresis_hz = 1.6), "mode_hysteresis_hz");
    assert_eq!(est(|c| c.mode_hysteresis_hz = 1.5), "");
    assert_eq!(est(|c| c.tracker_hold_ratio = 1.0), "tracker_hold_ratio");
    assert_eq!(
        est(|c| c.limiter_radius_ratio = 0.9),
        "limiter_radius_ratio"
    );
    assert_eq!(est(|c| c.limiter_radius_ratio = 1.0), "");
    assert_eq!(drive(|c| c.i_min = 41.0), "i_min");
    assert_eq!(drive(|c| c.i_min = 40.0), "");
    assert_eq!(drive(|c| c.trip_current = 40.0), "trip_current");
    assert_eq!(drive(|c| c.max_modulation = 1.01), "max_modulation");
    assert_eq!(drive(|c| c.dead_time = 1e-4), "dead_time");
    let pi = PiConfig::<f64> {
        ts: 1e-4,
        kp: 1.0,
        ki: 100.0,
        output_min: 10.0,
        output_max: 10.0,
        anti_windup_ratio: 1.0,
    };
    assert_eq!(refused_field(Pi::new(pi)), "output_max");
    // The drive and its estimator must share ts; a NaN ts is named as not finite.
    let est_cfg = EstimatorConfig::<f64> {
        ts: 50e-6,
        ..Default::default()
    };
    assert_eq!(
        refused_field(SensorlessDrive::new(DriveConfig::default(), est_cfg)),
        "ts"
    );
    let nan_ts = DriveConfig::<f64> {
        ts: f64::NAN,
        ..Default::default()
    };
    let nan_est = EstimatorConfig::<f64> {
        ts: f64::NAN,
        ..Default::default()
    };
    assert_eq!(
        SensorlessDrive::new(nan_ts, nan_est).err(),
        Some(ConfigError::NotFinite { field: "ts" })
    );
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    /// Random configurations inside the documented ranges.
    fn valid_estimator() -> impl Strategy<Value = EstimatorConfig<f64>> {
        (
            (20e-6..500e-6f64, 0.0..5.0f64, 0.0..0.05f64, 0.001..1.0f64),
            (0.0..10.0f64, 0.0..0.1f64, 0.0..1.0f64, 1.0..3.0f64),
            (0.0..20.0f64, 0.0..1.0f64, 1.0..100.0f64, 1.0..100.0f64),
            (0.3..2.0f64, 0.0..0.9f64, -10.0..10.0f64),
        )
            .prop_map(
                |(
                    (ts, rs, lq, lf),
                    (kdf, ramp, kaf_ts, ratio),
                    (th, hy, b1, b2),
                    (z, hold, a0),
                )| {
                    EstimatorConfig {
                        ts,
                        rs_hat: rs,
                        lq_hat: lq,
                        flux_linkage_hat: lf,
                        k_df: kdf,
                        k_df_ramp_time: ramp,
                        k_af: kaf_ts / ts,
                        limiter_radius_ratio: ratio,
                        mode_threshold_hz: th,
                        mode_hysteresis_hz: hy * th,
                        t2s1_bandwidth_hz: b1,
                        t2s2_bandwidth_hz: b2,
                        tracker_damping: z,
                        tracker_hold_ratio: hold,
                        initial_angle: a0,
                        ..EstimatorConfig::default()
                    }
                },
            )
    }

    /// Random drive configurations inside the documented ranges, bandwidths up to 90 % of
    /// their sampling-rate limits.
    fn valid_drive() -> impl Strategy<Value = DriveConfig<f64>> {
        (
            (
                50e-6..200e-6f64,
                1.0..8.0f64,
                0.0..2.0f64,
                1e-4..0.05f64,
                1e-4..0.05f64,
            ),
            (
                0.01..1.0f64,
                1e-4..1.0f64,
                0.01..0.9f64,
                0.01..0.9f64,
                1.0..20.0f64,
            ),
            (
                1.0..200.0f64,
                0.0..1.0f64,
                1.01..3.0f64,
                0.0..0.45f64,
                0.0..10.0f64,
            ),
            (0.1..1.0f64, 0.0..1.0f64, 0.0..50.0f64),
        )
            .prop_map(
                |(
                    (ts, p, rs, ld, lq),
                    (lf, j, cbw, sbw, zr),
                    (imax, imin, trip, td, delay),
                    (m, caw, saw),
                )| {
                    let two_pi_ts = 2.0 * std::f64::consts::PI * ts;
                    // Back-calculation gains below their limit ratio·Ki/Kp·Ts ≤ 1 (PI docs):
                    // Ki/Kp = R̂s/L̂ for the current PI, ωsc/zero_ratio for the speed PI.
                    let caw = caw * ld.min(lq) / (rs * ts).max(1e-12);
                    let saw = saw / 50.0 * zr / (sbw * 0.1);
                    DriveConfig {
                        ts,
                        pole_pairs: p.round(),
                        rs_hat: rs,
                        ld_hat: ld,
                        lq_hat: lq,
                        flux_linkage_hat: lf,
                        inertia_hat: j,
                        current_bandwidth_hz: cbw * 0.5 / two_pi_ts,
                        speed_bandwidth_hz: sbw * 0.1 / two_pi_ts,
                        speed_zero_ratio: zr,
                        i_max: imax,
                        i_min: imin * imax,
                        trip_current: trip * imax,
                        dead_time: td * ts,
                        switching_frequency: 0.5 / ts,
                        delay_compensation_factor: delay,
                        max_modulation: m,
                        current_anti_windup_ratio: caw,
                        speed_anti_windup_ratio: saw,
                        ..DriveConfig::default()
                    }
                },
            )
    }

    proptest! {
        #[test]
        fn valid_drive_configs_construct(c in valid_drive()) {
            let est = EstimatorConfig { ts: c.ts, ..EstimatorConfig::default() };
            prop_assert_eq!(SensorlessDrive::new(c, est).err(), None);
        }

        #[test]
        fn valid_estimator_configs_construct(c in valid_estimator()) {
            prop_assert_eq!(SensorlessEstimator::new(c).err(), None);
        }

        #[test]
        fn one_nan_field_is_refused_naming_it(c in valid_estimator(), which in 0usize..15) {
            let fields = fields!(EstimatorConfig<f64>, f64;
                ts: Positive, rs_hat: NonNegative, lq_hat: NonNegative,
                flux_linkage_hat: Positive, k_df: NonNegative, k_df_ramp_time: NonNegative,
                k_af: NonNegative, limiter_radius_ratio: Positive,
                mode_threshold_hz: NonNegative, mode_hysteresis_hz: NonNegative,
                t2s1_bandwidth_hz: Positive, t2s2_bandwidth_hz: Positive,
                tracker_damping: Positive, tracker_hold_ratio: NonNegative, initial_angle: Signed,
            );
            let f = &fields[which];
            let mut bad = c;
            (f.set)(&mut bad, f64::NAN);
            prop_assert_eq!(
                SensorlessEstimator::new(bad).err(),
                Some(ConfigError::NotFinite { field: f.name })
            );
        }
    }
}
