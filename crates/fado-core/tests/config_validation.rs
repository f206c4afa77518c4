//! Every public constructor validates every numeric field of its configuration (
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
//!
//! Nested fields (`machine.rs`, `tuning.k_df`) are named by their last component, as the
//! errors name them.

mod common;

use fado_core::Real;
use fado_core::baselines::{
    EmfObserverConfig, EmfObserverEstimator, LpfIntegratorConfig, LpfIntegratorEstimator,
    OrtegaConfig, OrtegaEstimator,
};
use fado_core::control::drive::DriveTuning;
use fado_core::control::{
    CurrentController, CurrentControllerConfig, DeadTimeCompensation, DeadTimeCompensationConfig,
    DelayCompensation, DelayCompensationConfig, DriveConfig, ModulatorConfig, Pi, PiConfig,
    SensorlessDrive, SpaceVectorModulator, SpeedController, SpeedControllerConfig,
};
use fado_core::estimator::{EstimatorConfig, EstimatorTuning, SensorlessEstimator};
use fado_core::flux::{
    DisturbanceFeedback, DisturbanceFeedbackConfig, FluxIntegrator, FluxIntegratorConfig,
    FluxLimiter, FluxLimiterConfig,
};
use fado_core::injection::{CurrentInjection, CurrentInjectionConfig};
use fado_core::mode::{ModeSelector, ModeSelectorConfig};
use fado_core::observer::{DisturbanceObserver, DisturbanceObserverConfig};
use fado_core::tracker::{TrackerConfig, TypeTwoTracker};
use fado_core::{ConfigError, MachineModel};

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

/// The last component of a field path: `tuning.k_df` → `k_df`.
/// The name errors give the field at `path`: its last segment, or for a field of the
/// estimator's or the drive's nested tuning its flat name (`tuning.lock.heal_time` →
/// `lock_heal_time`, `tuning.inverter.current_band` → `dead_time_current_band`).
fn leaf(path: &'static str) -> &'static str {
    const INVERTER: &[(&str, &str)] = &[
        ("dead_time_threshold_voltage", "inverter.threshold_voltage"),
        ("dead_time_current_band", "inverter.current_band"),
    ];
    let compact = path.replace(' ', "");
    let flat = fado_core::estimator::tuning::MOVED_KEYS
        .iter()
        .chain(fado_core::control::tuning::MOVED_KEYS)
        .chain(INVERTER)
        .find(|(_, new)| compact == *new || compact.ends_with(&format!("tuning.{new}")))
        .map(|(old, _)| *old);
    flat.unwrap_or_else(|| path.rsplit('.').next().unwrap_or(path).trim())
}

macro_rules! fields {
    ($c:ty, $t:ty; $($($path:ident).+: $range:ident),* $(,)?) => {
        [$(Field::<$c, $t> {
            name: leaf(stringify!($($path).+)),
            set: |c: &mut $c, v: $t| c.$($path).+ = v,
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

/// The 2.2 kW IPMSM of the "any motor" issue (p 3, Rs 3.6 Ω, Ld 36 mH, Lq 51 mH, λf 0.545 Wb,
/// 6 A peak, 1500 r/min, 540 V); rated torque 14.9 N·m = magnet plus reluctance torque at the
/// MTPA point of 6 A (`drive_salient.rs` checks it).
fn ipmsm<T: Real>() -> MachineModel<T> {
    MachineModel {
        viscous_friction: 1e-3,
        ..common::ipmsm_model()
    }
    .cast()
}

fn run_all<T: Real>(failures: &mut Vec<String>, machine: MachineModel<T>) -> usize {
    let mut n = 0;
    n += probe(
        failures,
        "MachineModel",
        machine,
        |c| c.validate(),
        &fields!(MachineModel<T>, T;
            rs: Positive,
            ld: Positive,
            lq: Positive,
            // Huge λf, rated current or speed break the unit-slip checks, which name
            // `rated_torque` or `flux_linkage`.
            flux_linkage: Positive,
            inertia: Positive,
            viscous_friction: NonNegative,
            rated_current: Positive,
            rated_speed_rpm: Positive,
            rated_torque: PositiveBounded,
            dc_voltage: Positive,
        ),
    );
    n += probe(
        failures,
        "EstimatorConfig",
        EstimatorConfig::<T>::for_machine(&machine),
        |c| ok(SensorlessEstimator::new(c)),
        &fields!(EstimatorConfig<T>, T;
            ts: Positive,
            machine.rs: Positive,
            machine.ld: Positive,
            machine.lq: Positive,
            machine.flux_linkage: Positive,
            machine.inertia: Positive,
            machine.rated_current: Positive,
            machine.rated_speed_rpm: Positive,
            machine.rated_torque: PositiveBounded,
            machine.dc_voltage: Positive,
            tuning.disturbance_feedback.k_df: NonNegativeBounded,
            tuning.disturbance_feedback.ramp_time: NonNegative,
            tuning.limiter.k_af: NonNegativeBounded,
            tuning.limiter.radius_ratio: Positive,
            tuning.mode.threshold_ratio: NonNegativeBounded,
            tuning.mode.hysteresis_ratio: NonNegativeBounded,
            tuning.tracker.t2s1_bandwidth_hz: PositiveBounded,
            tuning.tracker.t2s2_bandwidth_hz: PositiveBounded,
            tuning.tracker.t2s1_running_bandwidth_hz: NonNegativeBounded,
            tuning.tracker.damping: Positive,
            tuning.tracker.hold_ratio: NonNegativeBounded,
            tuning.observer.gain_period: NonNegativeBounded,
            initial_angle: Signed,
        ),
    );
    n += probe(
        failures,
        "DriveConfig",
        DriveConfig::<T>::for_machine(&machine),
        |c| c.validate(),
        &fields!(DriveConfig<T>, T;
            ts: Positive,
            machine.rs: Positive,
            machine.ld: Positive,
            machine.lq: Positive,
            machine.flux_linkage: Positive,
            machine.inertia: Positive,
            machine.viscous_friction: NonNegative,
            machine.rated_current: Positive,
            machine.rated_speed_rpm: Positive,
            machine.rated_torque: PositiveBounded,
            machine.dc_voltage: Positive,
            tuning.current.bandwidth_hz: PositiveBounded,
            tuning.speed.bandwidth_hz: PositiveBounded,
            tuning.speed.zero_ratio: Positive,
            // A huge limit makes the trip level (a ratio of its own) fall below it.
            tuning.current.limit_ratio: Positive,
            tuning.injection.current_ratio: NonNegativeBounded,
            tuning.inverter.dead_time: NonNegativeBounded,
            tuning.inverter.switching_frequency: Positive,
            tuning.inverter.threshold_voltage: NonNegative,
            tuning.inverter.current_band: Positive,
            tuning.delay_compensation.factor: NonNegativeBounded,
            tuning.protection.trip_current_ratio: Positive,
            tuning.modulation.max_modulation: PositiveBounded,
            tuning.current.anti_windup_ratio: NonNegativeBounded,
            tuning.speed.anti_windup_ratio: NonNegativeBounded,
            tuning.offset_calibration.time: NonNegativeBounded,
            tuning.gain_calibration.time: NonNegativeBounded,
            // A huge level is capped at current.limit_ratio, a huge mismatch bound accepted.
            tuning.gain_calibration.current_ratio: Positive,
            tuning.gain_calibration.min_observability: NonNegativeBounded,
            tuning.gain_calibration.max_mismatch: Positive,
            // A huge band is refused naming `stuck_sensor.reference_ratio`, which must exceed it.
            tuning.stuck_sensor.band_ratio: NonNegative,
            tuning.stuck_sensor.reference_ratio: Positive,
            tuning.stuck_sensor.time: NonNegativeBounded,
            tuning.protection.current_error_ratio: Positive,
            tuning.protection.current_error_time: NonNegativeBounded,
            tuning.protection.dc_link_min_ratio: NonNegative,
            tuning.protection.input_fault_trip_time: NonNegativeBounded,
        ),
    );
    // The drive with its estimator: the same checks reach `SensorlessDrive::new`, and so do
    // the estimator's through the tuning.
    n += probe(
        failures,
        "SensorlessDrive",
        DriveConfig::<T>::for_machine(&machine),
        |c| ok(SensorlessDrive::new(c, EstimatorTuning::default())),
        &fields!(DriveConfig<T>, T;
            ts: Positive,
            machine.rs: Positive,
            machine.flux_linkage: Positive,
            tuning.current.limit_ratio: Positive,
            tuning.current.bandwidth_hz: PositiveBounded,
        ),
    );
    n += probe(
        failures,
        "SensorlessDrive(EstimatorTuning)",
        EstimatorTuning::<T>::default(),
        |t| ok(SensorlessDrive::new(DriveConfig::for_machine(&machine), t)),
        &fields!(EstimatorTuning<T>, T;
            disturbance_feedback.k_df: NonNegativeBounded,
            mode.threshold_ratio: NonNegativeBounded,
            tracker.t2s1_bandwidth_hz: PositiveBounded,
        ),
    );
    n += probe(
        failures,
        "TrackerConfig",
        TrackerConfig::<T>::new(T::lit(60.0), T::lit(1e-4)),
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
        FluxIntegratorConfig::<T>::for_machine(&machine, T::lit(1e-4)),
        |c| ok(FluxIntegrator::new(c)),
        &fields!(FluxIntegratorConfig<T>, T; ts: Positive, rs_hat: NonNegative),
    );
    n += probe(
        failures,
        "DisturbanceFeedbackConfig",
        DisturbanceFeedbackConfig::<T>::with_ts(T::lit(1e-4)),
        |c| ok(DisturbanceFeedback::new(c)),
        &fields!(DisturbanceFeedbackConfig<T>, T;
            ts: Positive, k_df: NonNegativeBounded, ramp_time: NonNegative),
    );
    n += probe(
        failures,
        "FluxLimiterConfig",
        FluxLimiterConfig::<T>::for_machine(&machine),
        |c| ok(FluxLimiter::new(c)),
        &fields!(FluxLimiterConfig<T>, T; k_af: NonNegative, radius: Positive),
    );
    n += probe(
        failures,
        "ModeSelectorConfig",
        ModeSelectorConfig::<T>::for_machine(&machine),
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
        CurrentInjectionConfig::<T>::for_machine(&machine),
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
        CurrentControllerConfig::<T>::for_machine(&machine, T::lit(1e-4)),
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
        SpeedControllerConfig::<T>::for_machine(&machine, T::lit(1e-4)),
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
        DelayCompensationConfig::<T>::with_ts(T::lit(1e-4)),
        |c| ok(DelayCompensation::new(c)),
        &fields!(DelayCompensationConfig<T>, T; ts: Positive, factor: NonNegativeBounded),
    );
    n += probe(
        failures,
        "DeadTimeCompensationConfig",
        DeadTimeCompensationConfig::<T>::for_machine(&machine),
        |c| ok(DeadTimeCompensation::new(c)),
        &fields!(DeadTimeCompensationConfig<T>, T;
            dead_time: NonNegativeBounded,
            switching_frequency: Positive,
            threshold_voltage: NonNegative,
            current_band: Positive,
            dc_voltage: NonNegative,
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
        LpfIntegratorConfig::<T>::for_machine(&machine),
        |c| ok(LpfIntegratorEstimator::new(c)),
        &fields!(LpfIntegratorConfig<T>, T;
            common.ts: Positive,
            machine.rs: NonNegative,
            machine.lq: NonNegative,
            machine.flux_linkage: Positive,
            settings.cutoff_hz: NonNegativeBounded,
            settings.compensation_floor_hz: Positive,
            common.t2s1_bandwidth_hz: PositiveBounded,
            common.t2s2_bandwidth_hz: PositiveBounded,
            common.tracker_damping: Positive,
            common.tracker_hold_ratio: NonNegativeBounded,
            common.initial_angle: Signed,
        ),
    );
    n += probe(
        failures,
        "OrtegaConfig",
        OrtegaConfig::<T>::for_machine(&machine),
        |c| ok(OrtegaEstimator::new(c)),
        &fields!(OrtegaConfig<T>, T;
            common.ts: Positive,
            machine.rs: NonNegative,
            machine.lq: NonNegative,
            machine.flux_linkage: Positive,
            settings.observer_bandwidth: PositiveBounded,
            settings.observer_speed_ratio: NonNegative,
            settings.observer_bandwidth_min: PositiveBounded,
            settings.flux_adaptation_ratio: NonNegative,
            common.t2s1_bandwidth_hz: PositiveBounded,
            common.t2s2_bandwidth_hz: PositiveBounded,
            common.tracker_damping: Positive,
            common.tracker_hold_ratio: NonNegativeBounded,
            common.initial_angle: Signed,
        ),
    );
    n += probe(
        failures,
        "EmfObserverConfig",
        EmfObserverConfig::<T>::for_machine(&machine),
        |c| ok(EmfObserverEstimator::new(c)),
        &fields!(EmfObserverConfig<T>, T;
            common.ts: Positive,
            machine.rs: NonNegative,
            machine.lq: NonNegative,
            machine.flux_linkage: Positive,
            settings.emf_bandwidth_hz: PositiveBounded,
            settings.speed_floor_hz: Positive,
            common.t2s1_bandwidth_hz: PositiveBounded,
            common.t2s2_bandwidth_hz: PositiveBounded,
            common.tracker_damping: Positive,
            common.tracker_hold_ratio: NonNegativeBounded,
            common.initial_angle: Signed,
        ),
    );
    n
}

fn check_all<T: Real>(machine: MachineModel<T>, which: &str) {
    let mut failures = Vec::new();
    let n = run_all::<T>(&mut failures, machine);
    assert!(
        failures.is_empty(),
        "{which}: {} of {n} cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(n > 500, "{which}: only {n} cases ran");
}

#[test]
fn every_field_of_every_config_is_validated_f64() {
    check_all::<f64>(MachineModel::paper(), "paper motor");
    check_all::<f64>(ipmsm(), "2.2 kW IPMSM");
}

#[test]
fn every_field_of_every_config_is_validated_f32() {
    check_all::<f32>(MachineModel::paper(), "paper motor");
    check_all::<f32>(ipmsm(), "2.2 kW IPMSM");
}

#[test]
fn zero_pole_pairs_are_refused_everywhere() {
    let mut m = MachineModel::<f64>::paper();
    m.pole_pairs = 0;
    assert_eq!(refused_field(m.validate()), "pole_pairs");
    let e = EstimatorConfig::for_machine(&m);
    assert_eq!(refused_field(SensorlessEstimator::new(e)), "pole_pairs");
    let d = DriveConfig::for_machine(&m);
    assert_eq!(refused_field(d.validate()), "pole_pairs");
    assert_eq!(
        refused_field(SensorlessDrive::new(d, EstimatorTuning::default())),
        "pole_pairs"
    );
}

/// The field a config is refused for, or "" when it is accepted.
fn refused_field<X>(r: Result<X, ConfigError>) -> &'static str {
    r.map_or_else(|e| e.field(), |_| "")
}

/// The field the default estimator config is refused for after `f`, or "".
fn est(f: impl FnOnce(&mut EstimatorConfig<f64>)) -> &'static str {
    let mut c = EstimatorConfig::for_machine(&MachineModel::paper());
    f(&mut c);
    refused_field(SensorlessEstimator::new(c))
}

/// The field the default drive config is refused for after `f`, or "".
fn drive(f: impl FnOnce(&mut DriveConfig<f64>)) -> &'static str {
    let mut c = DriveConfig::for_machine(&MachineModel::paper());
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
                ..TrackerConfig::new(60.0, ts)
            })
            .is_err()
        })
        .expect("some bandwidth below 20 kHz must be unstable at 10 kHz");
    let (kp, ki) = TrackerConfig {
        bandwidth_hz: limit,
        ..TrackerConfig::<f64>::new(60.0, ts)
    }
    .gains();
    assert!(
        kp * ts >= 2.0 || 2.0 * kp * ts + ki * ts * ts >= 4.0,
        "refused at {limit} Hz although Jury's conditions hold"
    );
    assert_eq!(
        est(|c| c.tuning.tracker.t2s1_bandwidth_hz = limit),
        "t2s1_bandwidth_hz"
    );
    assert_eq!(
        est(|c| c.tuning.tracker.t2s2_bandwidth_hz = limit),
        "t2s2_bandwidth_hz"
    );
    assert_eq!(
        est(|c| c.tuning.tracker.t2s1_bandwidth_hz = limit - 1.0),
        ""
    );
    // Limiter and disturbance feedback: one step must not remove more than the excess.
    assert_eq!(est(|c| c.tuning.limiter.k_af = 1.0 / ts), "");
    assert_eq!(est(|c| c.tuning.limiter.k_af = 1.01 / ts), "k_af");
    assert_eq!(est(|c| c.tuning.disturbance_feedback.k_df = 1.0 / ts), "");
    assert_eq!(
        est(|c| c.tuning.disturbance_feedback.k_df = 1.01 / ts),
        "k_df"
    );
    // The observer's gains are held at most 1 s, whatever ts (a u32 count of samples).
    assert_eq!(est(|c| c.tuning.observer.gain_period = 1.0), "");
    assert_eq!(
        est(|c| c.tuning.observer.gain_period = 1.01),
        "observer_gain_period"
    );
    assert_eq!(
        est(|c| {
            c.tuning.observer.gain_period = 1.0;
            c.ts = 1e-9;
        }),
        ""
    );
    // The mode band must lie below Nyquist (5 kHz; the paper motor's rated frequency is
    // 100 Hz, so the ratios are the old thresholds in Hz / 100).
    assert_eq!(
        est(|c| c.tuning.mode.threshold_ratio = 50.0),
        "mode_threshold_ratio"
    );
    assert_eq!(est(|c| c.tuning.mode.threshold_ratio = 49.9), "");
    assert_eq!(
        est(|c| {
            c.tuning.mode.threshold_ratio = 49.0;
            c.tuning.mode.hysteresis_ratio = 2.0;
        }),
        "mode_hysteresis_ratio"
    );
    // The same ratio is a lower frequency on a slower motor: 50 × 75 Hz (the 2.2 kW IPMSM,
    // 3 pole pairs at 1500 r/min) is below Nyquist.
    let mut slow = EstimatorConfig::for_machine(&ipmsm::<f64>());
    slow.tuning.mode.threshold_ratio = 50.0;
    assert!((slow.mode_threshold_hz() - 3750.0).abs() < 1e-9);
    assert_eq!(refused_field(SensorlessEstimator::new(slow)), "");
    // Drive: current PI (2π·f·Ts ≤ 0.5) and speed PI (2π·f·Ts < 0.1).
    let f_cc = 0.5 / (2.0 * std::f64::consts::PI * ts);
    assert_eq!(drive(|c| c.tuning.current.bandwidth_hz = 790.0), "");
    assert!(f_cc < 800.0);
    assert_eq!(
        drive(|c| c.tuning.current.bandwidth_hz = 800.0),
        "current_bandwidth_hz"
    );
    assert_eq!(
        drive(|c| c.tuning.speed.bandwidth_hz = 160.0),
        "speed_bandwidth_hz"
    );
    assert_eq!(drive(|c| c.tuning.speed.bandwidth_hz = 150.0), "");
    // Baselines.
    let mut lpf = LpfIntegratorConfig::<f64>::for_machine(&MachineModel::paper());
    lpf.settings.cutoff_hz = 1600.0;
    assert_eq!(refused_field(LpfIntegratorEstimator::new(lpf)), "cutoff_hz");
    let mut emf = EmfObserverConfig::<f64>::for_machine(&MachineModel::paper());
    emf.settings.emf_bandwidth_hz = 1600.0;
    assert_eq!(
        refused_field(EmfObserverEstimator::new(emf)),
        "emf_bandwidth_hz"
    );
    let mut ortega = OrtegaConfig::<f64>::for_machine(&MachineModel::paper());
    ortega.settings.observer_bandwidth = 1.0e4;
    assert_eq!(
        refused_field(OrtegaEstimator::new(ortega)),
        "observer_bandwidth"
    );
}

#[test]
fn thresholds_out_of_order_are_refused() {
    // Hysteresis at most the threshold (1.5 Hz = 0.015 of the paper motor's 100 Hz).
    assert_eq!(
        est(|c| c.tuning.mode.hysteresis_ratio = 0.016),
        "mode_hysteresis_ratio"
    );
    assert_eq!(est(|c| c.tuning.mode.hysteresis_ratio = 0.015), "");
    assert_eq!(
        est(|c| c.tuning.tracker.hold_ratio = 1.0),
        "tracker_hold_ratio"
    );
    assert_eq!(
        est(|c| c.tuning.limiter.radius_ratio = 0.9),
        "limiter_radius_ratio"
    );
    assert_eq!(est(|c| c.tuning.limiter.radius_ratio = 1.0), "");
    // Injection at most the current limit, the trip level above it (as ratios of the same
    // rated current: 41 A, 40 A against the 40 A limit of the paper's motor).
    let limit = DriveConfig::<f64>::for_machine(&MachineModel::paper())
        .tuning
        .current
        .limit_ratio;
    assert_eq!(
        drive(|c| c.tuning.injection.current_ratio = limit * 41.0 / 40.0),
        "injection_current_ratio"
    );
    assert_eq!(drive(|c| c.tuning.injection.current_ratio = limit), "");
    assert_eq!(
        drive(|c| c.tuning.protection.trip_current_ratio = limit),
        "trip_current_ratio"
    );
    assert_eq!(
        drive(|c| c.tuning.stuck_sensor.reference_ratio = c.tuning.stuck_sensor.band_ratio),
        "stuck_sensor_reference_ratio"
    );
    // Durations: at most 4e9 sampling periods (a u32 count).
    assert_eq!(
        drive(|c| c.tuning.protection.current_error_time = 4.1e5),
        "current_error_time"
    );
    assert_eq!(
        drive(|c| c.tuning.protection.current_error_time = 3.9e5),
        ""
    );
    assert_eq!(
        drive(|c| c.tuning.modulation.max_modulation = 1.01),
        "max_modulation"
    );
    assert_eq!(drive(|c| c.tuning.inverter.dead_time = 1e-4), "dead_time");
    let pi = PiConfig::<f64> {
        ts: 1e-4,
        kp: 1.0,
        ki: 100.0,
        output_min: 10.0,
        output_max: 10.0,
        anti_windup_ratio: 1.0,
    };
    assert_eq!(refused_field(Pi::new(pi)), "output_max");
    // The drive builds its estimator with its own ts and machine (they cannot disagree); a
    // NaN ts is named as not finite.
    let c = DriveConfig::<f64> {
        ts: 50e-6,
        ..DriveConfig::for_machine(&ipmsm())
    };
    let d = SensorlessDrive::new(c, EstimatorTuning::default()).unwrap();
    assert_eq!(d.estimator().ts(), 50e-6);
    assert_eq!(d.estimator().rs_hat(), ipmsm().rs);
    assert_eq!(
        d.estimator().last().diagnostics.flux_linkage_hat,
        ipmsm().flux_linkage
    );
    let nan_ts = DriveConfig::<f64> {
        ts: f64::NAN,
        ..DriveConfig::for_machine(&MachineModel::paper())
    };
    assert_eq!(
        SensorlessDrive::new(nan_ts, EstimatorTuning::default()).err(),
        Some(ConfigError::NotFinite { field: "ts" })
    );
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    /// Random motors that pass the unit-slip checks: surface-magnet and salient (Lq/Ld 0.8–2),
    /// 1–8 pole pairs, rated torque 0.4–2.5 × the magnet torque, DC link 0.6–3 × the
    /// line-to-line back-EMF amplitude at rated speed.
    fn valid_machine() -> impl Strategy<Value = MachineModel<f64>> {
        // Per unit of the rated point (current I, back-EMF ω·λf), inside the bands of
        // `fado_core::machine_checks` that real machines occupy: reactance L·I/λf 0.02–3
        // (× saliency ≤ 2), resistance R·I/(ω·λf) 0.001–0.5, magnet torque 0.65–2.5 of
        // 1.5·p·λf·I (below 0.6 with an even p reads as a pole count), DC link 0.6–3 × the
        // rated back-EMF's line value.
        (
            (0.001..0.5f64, 0.02..3.0f64, 0.8..2.0f64, 0.001..1.0f64),
            (1u32..=8, 1e-4..1.0f64, 0.0..0.01f64, 0.5..200.0f64),
            (100.0..6000.0f64, 0.65..2.5f64, 0.6..3.0f64),
        )
            .prop_map(
                |((r_pu, x_pu, saliency, lf), (p, j, b, i_rated), (rpm, torque, dc))| {
                    let w = rpm * std::f64::consts::PI / 30.0 * p as f64;
                    let ld = x_pu * lf / i_rated;
                    MachineModel {
                        rs: r_pu * w * lf / i_rated,
                        ld,
                        lq: ld * saliency,
                        flux_linkage: lf,
                        pole_pairs: p,
                        inertia: j,
                        viscous_friction: b,
                        rated_current: i_rated,
                        rated_speed_rpm: rpm,
                        rated_torque: torque * 1.5 * p as f64 * lf * i_rated,
                        dc_voltage: dc * 3f64.sqrt() * w * lf,
                        magnetics: Default::default(),
                    }
                },
            )
            // The corners of the box beyond any motor's field ranges (say 5 kΩ for a 0.5 A,
            // 1 V·s, 40,000 r/min machine) are not motors.
            .prop_filter("inside the machine checks' field ranges", |m| {
                fado_core::machine_checks::check(m, None).error().is_none()
            })
    }

    /// Random configurations inside the documented ranges.
    fn valid_estimator() -> impl Strategy<Value = EstimatorConfig<f64>> {
        (
            (20e-6..500e-6f64, valid_machine()),
            (0.0..10.0f64, 0.0..0.1f64, 0.0..1.0f64, 1.0..3.0f64),
            (0.0..0.2f64, 0.0..1.0f64, 1.0..100.0f64, 1.0..100.0f64),
            (0.3..2.0f64, 0.0..0.9f64, -10.0..10.0f64),
        )
            .prop_map(
                |((ts, machine), (kdf, ramp, kaf_ts, ratio), (th, hy, b1, b2), (z, hold, a0))| {
                    EstimatorConfig {
                        ts,
                        machine,
                        initial_angle: a0,
                        tuning: {
                            let mut tuned = EstimatorTuning::default();
                            tuned.disturbance_feedback.k_df = kdf;
                            tuned.disturbance_feedback.ramp_time = ramp;
                            tuned.limiter.k_af = kaf_ts / ts;
                            tuned.limiter.radius_ratio = ratio;
                            tuned.mode.threshold_ratio = th;
                            tuned.mode.hysteresis_ratio = hy * th;
                            tuned.tracker.t2s1_bandwidth_hz = b1;
                            tuned.tracker.t2s2_bandwidth_hz = b2;
                            tuned.tracker.damping = z;
                            tuned.tracker.hold_ratio = hold;
                            tuned
                        },
                    }
                },
            )
    }

    /// Random drive configurations inside the documented ranges, bandwidths up to 90 % of
    /// their sampling-rate limits.
    fn valid_drive() -> impl Strategy<Value = DriveConfig<f64>> {
        (
            (50e-6..200e-6f64, valid_machine()),
            (0.01..0.9f64, 0.01..0.9f64, 1.0..20.0f64),
            (
                0.1..5.0f64,
                0.0..1.0f64,
                1.01..3.0f64,
                0.0..0.45f64,
                0.0..10.0f64,
            ),
            (0.1..1.0f64, 0.0..1.0f64, 0.0..50.0f64),
            (
                (0.0..1.0f64, 0.0..0.05f64, 1e-3..0.5f64, 0.0..0.01f64),
                (0.01..2.0f64, 0.0..0.1f64, 0.0..1.0f64, 0.0..1.0f64),
            ),
        )
            .prop_map(
                |(
                    (ts, machine),
                    (cbw, sbw, zr),
                    (limit, imin, trip, td, delay),
                    (m, caw, saw),
                    ((cal, band, reference, stuck), (err, err_time, dc_min, fault)),
                )| {
                    let two_pi_ts = 2.0 * std::f64::consts::PI * ts;
                    // Back-calculation gains below their limit ratio·Ki/Kp·Ts ≤ 1 (PI docs):
                    // Ki/Kp = R̂s/L̂ for the current PI, ωsc/zero_ratio for the speed PI.
                    let (rs, ld, lq) = (machine.rs, machine.ld, machine.lq);
                    let caw = caw * ld.min(lq) / (rs * ts).max(1e-12);
                    let saw = saw / 50.0 * zr / (sbw * 0.1);
                    DriveConfig {
                        ts,
                        machine,
                        tuning: {
                            let mut t = DriveTuning::default();
                            t.current.bandwidth_hz = cbw * 0.5 / two_pi_ts;
                            t.speed.bandwidth_hz = sbw * 0.1 / two_pi_ts;
                            t.speed.zero_ratio = zr;
                            t.current.limit_ratio = limit;
                            t.injection.current_ratio = imin * limit;
                            t.protection.trip_current_ratio = trip * limit;
                            t.inverter.dead_time = td * ts;
                            t.inverter.switching_frequency = 0.5 / ts;
                            t.delay_compensation.factor = delay;
                            t.modulation.max_modulation = m;
                            t.current.anti_windup_ratio = caw;
                            t.speed.anti_windup_ratio = saw;
                            t.offset_calibration.time = cal;
                            t.stuck_sensor.band_ratio = band;
                            t.stuck_sensor.reference_ratio = band + reference;
                            t.stuck_sensor.time = stuck;
                            t.protection.current_error_ratio = err;
                            t.protection.current_error_time = err_time;
                            t.protection.dc_link_min_ratio = dc_min;
                            t.protection.input_fault_trip_time = fault;
                            t
                        },
                    }
                },
            )
    }

    proptest! {
        #[test]
        fn valid_machines_validate(m in valid_machine()) {
            prop_assert_eq!(m.validate().err(), None);
        }

        #[test]
        fn valid_drive_configs_construct(c in valid_drive()) {
            prop_assert_eq!(SensorlessDrive::new(c, EstimatorTuning::default()).err(), None);
        }

        #[test]
        fn valid_estimator_configs_construct(c in valid_estimator()) {
            prop_assert_eq!(SensorlessEstimator::new(c).err(), None);
        }

        #[test]
        fn one_nan_field_is_refused_naming_it(c in valid_estimator(), which in 0usize..20) {
            let fields = fields!(EstimatorConfig<f64>, f64;
                ts: Positive, machine.rs: Positive, machine.ld: Positive, machine.lq: Positive,
                machine.flux_linkage: Positive, machine.inertia: Positive,
                machine.rated_current: Positive, machine.rated_speed_rpm: Positive,
                machine.rated_torque: Positive, machine.dc_voltage: Positive,
                tuning.disturbance_feedback.k_df: NonNegative, tuning.disturbance_feedback.ramp_time: NonNegative,
                tuning.limiter.k_af: NonNegative, tuning.limiter.radius_ratio: Positive,
                tuning.mode.threshold_ratio: NonNegative, tuning.mode.hysteresis_ratio: NonNegative,
                tuning.tracker.t2s1_bandwidth_hz: Positive, tuning.tracker.t2s2_bandwidth_hz: Positive,
                tuning.tracker.damping: Positive, tuning.tracker.hold_ratio: NonNegative,
            );
            let f = &fields[which];
            let mut bad = c;
            (f.set)(&mut bad, f64::NAN);
            prop_assert_eq!(
                SensorlessEstimator::new(bad).err(),
                Some(ConfigError::NotFinite { field: f.name })
            );
        }

        #[test]
        fn one_nan_drive_field_is_refused_naming_it(c in valid_drive(), which in 0usize..12) {
            let fields = fields!(DriveConfig<f64>, f64;
                ts: Positive, machine.rs: Positive, machine.lq: Positive,
                machine.rated_current: Positive, machine.dc_voltage: Positive,
                tuning.current.limit_ratio: Positive, tuning.injection.current_ratio: NonNegative,
                tuning.protection.trip_current_ratio: Positive, tuning.offset_calibration.time: NonNegative,
                tuning.stuck_sensor.band_ratio: NonNegative, tuning.protection.current_error_time: NonNegative,
                tuning.protection.dc_link_min_ratio: NonNegative,
            );
            let f = &fields[which];
            let mut bad = c;
            (f.set)(&mut bad, f64::NAN);
            prop_assert_eq!(
                SensorlessDrive::new(bad, EstimatorTuning::default()).err(),
                Some(ConfigError::NotFinite { field: f.name })
            );
        }
    }
}

/// A PM-assisted SyRM with a weak magnet makes most of its torque from the saliency: the
/// 6.7 kW SyRM of motulator's examples with a 8.7 mVs magnet (zero-current L_d 15.7 mH,
/// L_q 57.5 mH, 20.1 N·m at 21.9 A peak) is 35 × its magnet torque and about its MTPA torque,
/// and its L_q·I is 4 × the torque's flux per ampere (145 × its λf): it passes. The same
/// machine without its saliency is still refused on the torque.
#[test]
fn a_weak_magnet_pm_syrm_passes_the_torque_check_on_its_mtpa_torque() {
    let syrm = MachineModel {
        rs: 0.54,
        ld: 15.75e-3,
        lq: 57.47e-3,
        flux_linkage: 8.652e-3,
        pole_pairs: 2,
        inertia: 0.015,
        viscous_friction: 1e-3,
        rated_current: 21.92,
        rated_speed_rpm: 3174.0,
        rated_torque: 20.1,
        dc_voltage: 540.0,
        magnetics: Default::default(),
    };
    let findings = fado_core::machine_checks::check(&syrm, None);
    assert!(findings.error().is_none(), "{findings:?}");
    let round = MachineModel {
        lq: syrm.ld,
        ..syrm
    };
    let findings = fado_core::machine_checks::check(&round, None);
    let error = findings.error().expect("refused");
    assert_eq!(error.key(), "rated_torque", "{findings:?}");
}
