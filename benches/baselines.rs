//! Cost of one 10 kHz sample of each estimator in `f32` (the firmware type): fado's
//! `SensorlessEstimator::step` next to the baselines. Inputs cycle through one electrical
//! period of an ideal machine at 300 r/min under load, so every branch taken is the one taken
//! in operation (no tracker hold, k_df mode for fado after the warm-up).
//!
//! Run: `cargo bench --bench baselines` (medians are criterion's point estimates).

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use fado_core::baselines::{
    Baseline, CommonTuning, EmfObserverEstimator, LpfIntegratorEstimator, OrtegaEstimator,
    ReducedOrderEstimator,
};
use fado_core::{Ab, MachineModel, RotorAngleEstimator};

mod common;

use common::{fado, inputs};

/// A baseline with its default settings around the paper's machine, as `fado-sim compare`
/// runs it.
fn bench_baseline<B: Baseline<f32>>(c: &mut Criterion, data: &[(Ab<f32>, Ab<f32>)]) {
    let est = B::build(
        &MachineModel::paper(),
        &CommonTuning::default(),
        &B::Settings::default(),
    )
    .unwrap();
    bench_one(c, est, data);
}

fn bench_one<E: RotorAngleEstimator<f32>>(c: &mut Criterion, est: E, data: &[(Ab<f32>, Ab<f32>)]) {
    let name = format!("{}_step_f32", est.name());
    bench_named(c, &name, est, data);
}

/// `name` is what `fado-sim compare --criterion` looks for: `<estimator>_step_f32`.
fn bench_named<E: RotorAngleEstimator<f32>>(
    c: &mut Criterion,
    name: &str,
    mut est: E,
    data: &[(Ab<f32>, Ab<f32>)],
) {
    // Warm up over two seconds so trackers are locked and fado is in k_df mode.
    for k in 0..20_000 {
        let (v, i) = data[k % data.len()];
        est.step(v, i);
    }
    let mut k = 0;
    c.bench_function(name, |b| {
        b.iter(|| {
            let (v, i) = data[k];
            k = if k + 1 == data.len() { 0 } else { k + 1 };
            black_box(est.step(black_box(v), black_box(i)))
        })
    });
}

fn estimators(c: &mut Criterion) {
    let data = inputs();
    bench_one(c, fado(|_| {}), &data);
    // fado as the paper has it: R̂s fixed (compare's `fado-fixed-rs`).
    bench_named(
        c,
        "fado-fixed-rs_step_f32",
        fado(|c| c.tuning.rs_adaptation.enabled = false),
        &data,
    );
    // fado on the paper's path (`EstimatorTuning::paper_path`, the Cortex-M image's scenarios
    // 4-5, docs/results/firmware-cost.md): the paper's method inside fado's step, against the baselines.
    bench_named(
        c,
        "fado-paper-path_step_f32",
        fado(|c| c.tuning = c.tuning.paper_path()),
        &data,
    );
    // One line per baseline of fado-sim's registry (`fado_sim::estimators::ESTIMATORS`).
    bench_baseline::<LpfIntegratorEstimator<f32>>(c, &data);
    bench_baseline::<OrtegaEstimator<f32>>(c, &data);
    bench_baseline::<EmfObserverEstimator<f32>>(c, &data);
    bench_baseline::<ReducedOrderEstimator<f32>>(c, &data);
}

criterion_group!(benches, estimators);
criterion_main!(benches);
