//! Criterion benchmarks of the estimator step and of each of its blocks, in `f32` and `f64`.
//!
//! Inputs are a precomputed ideal PMSM signal (crates/fado-core/tests/common) at 293 r/min (19.53 Hz electrical,
//! so that the 4096-sample table holds exactly 8 electrical periods and wraps seamlessly),
//! 10 A on q: the estimator runs in its disturbance-feedback mode as it would in a drive.
//! The blocks are fed the signals the estimator itself produced on that table.
//!
//! Run with `cargo bench -p fado --bench estimator`; `-- estimator/f32` selects one.

#[path = "../crates/fado-core/tests/common/mod.rs"]
mod common;

use std::hint::black_box;
use std::time::Duration;

use criterion::Criterion;
use fado_core::flux::{FluxIntegrator, FluxIntegratorConfig, FluxLimiter, FluxLimiterConfig};
use fado_core::lock::{LockDetector, LockDetectorConfig};
use fado_core::observer::{DiscreteGains, DisturbanceObserver, DisturbanceObserverConfig};
use fado_core::plausibility::SampleBounds;
use fado_core::rotor_flux::rotor_angle;
use fado_core::tracker::{TrackerConfig, TypeTwoTracker};
use fado_core::{Ab, Dq, EstimatorConfig, MachineModel, Real, SensorlessEstimator, wrap_angle};

/// Samples in the signal table: a power of two, 8 electrical periods.
const TABLE: usize = 4096;
const MASK: usize = TABLE - 1;

/// One recorded sample: the inputs and what the estimator made of them.
#[derive(Clone, Copy)]
struct Sample<T> {
    v: Ab<T>,
    i: Ab<T>,
    lambda1: Ab<T>,
    lambda_r: Ab<T>,
    theta_direct: T,
    omega: T,
}

fn ab<T: Real>(x: Ab<f64>) -> Ab<T> {
    Ab::new(T::lit(x.alpha), T::lit(x.beta))
}

/// The signal table and an estimator warmed up on it (two seconds, settled, k_df mode).
fn setup<T: Real>(
    rs_adaptation: bool,
    lock_detection: bool,
) -> (Vec<Sample<T>>, SensorlessEstimator<T>) {
    let f_elec = 8.0 / (TABLE as f64 * common::TS);
    let rpm = f_elec * 60.0 / common::PP;
    let theta0 = 0.3;
    let i_dq = Dq::new(0.0, 10.0);
    let raw: Vec<_> = common::constant_speed(rpm, theta0, i_dq, TABLE, Ab::zero())
        .map(|(v, i, _)| (ab::<T>(v), ab::<T>(i)))
        .collect();
    let mut est =
        SensorlessEstimator::<T>::new(common::config_with(|c: &mut EstimatorConfig<T>| {
            c.initial_angle = T::lit(theta0);
            c.tuning.rs_adaptation.enabled = rs_adaptation;
            if !lock_detection {
                c.tuning.lock.detection_time = T::zero();
            }
        }))
        .expect("default config is valid");
    let (_, i0) = common::flux_and_current(theta0, i_dq);
    est.align(T::lit(theta0), ab(i0));
    let mut table = Vec::with_capacity(TABLE);
    for pass in 0..5 {
        for &(v, i) in &raw {
            let out = est.step(v, i);
            if pass == 4 {
                let d = out.diagnostics;
                table.push(Sample {
                    v,
                    i,
                    lambda1: d.lambda1,
                    lambda_r: d.lambda_r,
                    theta_direct: d.theta_direct,
                    omega: out.omega,
                });
            }
        }
    }
    (table, est)
}

fn bench_precision<T: Real>(c: &mut Criterion, name: &str) {
    let (table, warmed) = setup::<T>(true, true);
    let (_, warmed_fixed_rs) = setup::<T>(false, true);
    let (_, warmed_no_lock) = setup::<T>(true, false);
    let ts = T::lit(common::TS);
    let mut group = c.benchmark_group(name);

    group.bench_function("estimator", |b| {
        let mut est = warmed;
        let mut k = 0usize;
        b.iter(|| {
            let s = &table[k & MASK];
            k += 1;
            black_box(est.step(black_box(s.v), black_box(s.i)))
        })
    });

    // The paper's estimator: R̂s fixed (`rs_adaptation: false`).
    group.bench_function("estimator_fixed_rs", |b| {
        let mut est = warmed_fixed_rs;
        let mut k = 0usize;
        b.iter(|| {
            let s = &table[k & MASK];
            k += 1;
            black_box(est.step(black_box(s.v), black_box(s.i)))
        })
    });

    // The default estimator with the loss-of-lock detector off (`lock_detection_time = 0`):
    // the difference to `estimator` is the detector's cost inside the step.
    group.bench_function("estimator_no_lock_detector", |b| {
        let mut est = warmed_no_lock;
        let mut k = 0usize;
        b.iter(|| {
            let s = &table[k & MASK];
            k += 1;
            black_box(est.step(black_box(s.v), black_box(s.i)))
        })
    });

    // The detector alone (its symptoms and counter; the innovation's wrap is in `wrap_angle`).
    group.bench_function("lock_detector", |b| {
        let d = fado_core::EstimatorTuning::<T>::default();
        let lf = T::lit(0.088);
        let mut det = LockDetector::new(LockDetectorConfig {
            ts,
            flux_low_ratio: d.lock.flux_low_ratio,
            flux_low_fast_ratio: d.lock.flux_low_fast_ratio,
            fast_speed: T::lit(2.0 * core::f64::consts::PI * 1.3),
            flux_high_ratio: d.lock.flux_high_ratio,
            innovation_limit: d.lock.innovation_limit,
            detection_time: d.lock.detection_time,
            heal_time: d.lock.heal_time,
            limiter_clamping: true,
            handover_count: T::lit(5.0),
            handover_time: d.lock.handover_time,
        })
        .unwrap();
        let flux_sq = lf * lf;
        let mut k = 0usize;
        b.iter(|| {
            let s = &table[k & MASK];
            k += 1;
            let next = det.next_state(
                black_box(s.lambda_r.norm_squared()),
                black_box(flux_sq),
                black_box(s.theta_direct - s.omega * ts),
                black_box(s.omega),
                false,
                k.is_multiple_of(64),
            );
            det.commit(next);
            black_box(next)
        })
    });

    // The plausibility check of a sample (magnitudes and current step).
    group.bench_function("plausibility", |b| {
        // The paper motor's bounds: 4 × 21.78 A, 1.5 × 311 V, 2·466 V·Ts/L̂q.
        let bounds = SampleBounds::new(T::lit(87.1), T::lit(466.5), T::lit(34.0)).unwrap();
        let mut k = 0usize;
        b.iter(|| {
            let s = &table[k & MASK];
            let p = &table[k.wrapping_sub(1) & MASK];
            k += 1;
            black_box(bounds.check(black_box(s.v), black_box(s.i), black_box(p.i), T::lit(34.0)))
        })
    });

    group.bench_function("integrator", |b| {
        let mut int = FluxIntegrator::new(FluxIntegratorConfig::<T>::for_machine(
            &MachineModel::paper(),
            ts,
        ))
        .unwrap();
        let mut k = 0usize;
        b.iter(|| {
            let s = &table[k & MASK];
            k += 1;
            black_box(int.step(black_box(s.v), black_box(s.i), Ab::zero()))
        })
    });

    group.bench_function("observer", |b| {
        let mut obs = DisturbanceObserver::new(DisturbanceObserverConfig::<T> { ts }).unwrap();
        let mut k = 0usize;
        b.iter(|| {
            let s = &table[k & MASK];
            k += 1;
            black_box(obs.step(black_box(s.lambda1), black_box(s.omega)))
        })
    });

    group.bench_function("observer_gains", |b| {
        let mut k = 0usize;
        b.iter(|| {
            let s = &table[k & MASK];
            k += 1;
            black_box(DiscreteGains::new(black_box(s.omega), ts))
        })
    });

    group.bench_function("tracker", |b| {
        let mut t2s = TypeTwoTracker::new(TrackerConfig::<T>::new(
            fado_core::EstimatorTuning::<T>::default()
                .tracker
                .t2s1_bandwidth_hz,
            ts,
        ))
        .unwrap();
        let mut k = 0usize;
        b.iter(|| {
            let s = &table[k & MASK];
            k += 1;
            black_box(t2s.step(black_box(s.theta_direct)))
        })
    });

    // The limiter's working path: |λ̂r| 30 % beyond the circle, so it projects every sample.
    group.bench_function("limiter", |b| {
        let lim =
            FluxLimiter::new(FluxLimiterConfig::<T>::for_machine(&MachineModel::paper())).unwrap();
        let scale = T::lit(1.3 * 1.15);
        let mut k = 0usize;
        b.iter(|| {
            let s = &table[k & MASK];
            k += 1;
            black_box(lim.step(black_box(s.lambda_r * scale)))
        })
    });

    group.bench_function("rotor_angle", |b| {
        let mut k = 0usize;
        b.iter(|| {
            let s = &table[k & MASK];
            k += 1;
            black_box(rotor_angle(black_box(s.lambda_r)))
        })
    });

    group.bench_function("wrap_angle", |b| {
        let mut k = 0usize;
        b.iter(|| {
            let s = &table[k & MASK];
            k += 1;
            // θm + 2 lies in (−π + 2, π + 2]: wraps on about a third of the samples.
            black_box(wrap_angle(black_box(s.theta_direct + T::lit(2.0))))
        })
    });

    group.finish();
}

fn main() {
    println!(
        "size_of::<SensorlessEstimator<f32>>() = {} bytes, size_of::<SensorlessEstimator<f64>>() = {} bytes",
        size_of::<SensorlessEstimator<f32>>(),
        size_of::<SensorlessEstimator<f64>>()
    );
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(50)
        .configure_from_args();
    bench_precision::<f32>(&mut c, "f32");
    bench_precision::<f64>(&mut c, "f64");
    c.final_summary();
}
