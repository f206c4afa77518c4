//! Runs `SensorlessEstimator::step` a given number of times over a precomputed rotating signal:
//! the workload `scripts/callgrind.sh` counts instructions of (two runs, differenced, so that
//! set-up and warm-up cancel).
//!
//! ```text
//! cargo run --release -p fado-dev --bin estimator-step-workload -- f32 100000
//! FIXED_RS=1 cargo run ...   # the paper's fixed R̂s (rs_adaptation = false)
//! PAPER_PATH=1 cargo run ...  # fado on the paper's path (every fado addition that can be off)
//! LEAN=1 cargo run ...        # `step_lean`, the firmware's call (no diagnostics record)
//! ESTIMATOR=ortega cargo run ...  # the Ortega baseline, for the host ratio against it
//! ESTIMATOR=paper-kernel cargo run ...  # the paper's method alone (f32 only; docs/results/firmware-cost.md)
//! ```

use std::hint::black_box;

use fado_core::baselines::{OrtegaConfig, OrtegaEstimator};
use fado_core::{
    Ab, Estimate, EstimatorConfig, LeanEstimate, MachineModel, Real, RotorAngleEstimator,
    SensorlessEstimator,
};

/// Samples in the signal table: a power of two holding exactly 8 electrical periods.
const TABLE: usize = 4096;
/// Sampling period (s).
const TS: f64 = 100e-6;

/// An ideal surface-mounted PMSM (docs/method/estimator.md, "The paper's motor and drive") at 19.5 Hz electrical with 10 A on q: the voltage is
/// the exact interval average that moves the flux from one sample to the next.
fn signal<T: Real>() -> Vec<(Ab<T>, Ab<T>)> {
    let (rs, l, lf, iq) = (0.327, 2.63e-3, 0.088, 10.0);
    let w = core::f64::consts::TAU * 8.0 / (TABLE as f64 * TS);
    let at = |n: usize| {
        let th = w * TS * n as f64;
        let (s, c) = th.sin_cos();
        // λ = e^{jθ}(λf + j·L·iq), i = e^{jθ}(j·iq)
        let lambda = (lf * c - l * iq * s, lf * s + l * iq * c);
        let i = (-iq * s, iq * c);
        (lambda, i)
    };
    (1..=TABLE)
        .map(|n| {
            let ((l0a, l0b), (i0a, i0b)) = at(n - 1);
            let ((l1a, l1b), (i1a, i1b)) = at(n);
            let va = (l1a - l0a) / TS + 0.5 * rs * (i1a + i0a);
            let vb = (l1b - l0b) / TS + 0.5 * rs * (i1b + i0b);
            (
                Ab::new(T::lit(va), T::lit(vb)),
                Ab::new(T::lit(i1a), T::lit(i1b)),
            )
        })
        .collect()
}

/// One estimator step behind a call, as a firmware ISR makes it; not inlined, so that callgrind
/// can count exactly the instructions inside (`--toggle-collect=*isr_step*`).
#[inline(never)]
fn isr_step<T: Real, E: RotorAngleEstimator<T>>(est: &mut E, v: Ab<T>, i: Ab<T>) -> Estimate<T> {
    est.step(v, i)
}

/// fado's firmware call, `step_lean` (no diagnostics record), behind the same kind of call.
#[inline(never)]
fn isr_step_lean<T: Real>(est: &mut SensorlessEstimator<T>, v: Ab<T>, i: Ab<T>) -> LeanEstimate<T> {
    est.step_lean(v, i)
}

// The Cortex-M image's hand-lean paper's estimator (`examples/cortex-m`), the same source.
#[path = "../../../examples/cortex-m/src/paper_kernel.rs"]
#[allow(dead_code)]
mod paper_kernel;

/// `paper_kernel_step` behind the same kind of call as [`isr_step`] (it is `inline(never)`
/// itself; this wrapper only gives callgrind the same `*isr_step*` name to collect under).
#[inline(never)]
fn isr_step_kernel(k: &mut paper_kernel::PaperKernel, v: Ab<f32>, i: Ab<f32>) -> f32 {
    paper_kernel::paper_kernel_step(k, v, i)
}

/// The paper's method alone, `f32`, on the paper's motor (as the Cortex-M image runs it).
fn run_kernel(steps: usize) -> f64 {
    let config = EstimatorConfig::for_machine(&MachineModel::paper());
    let mut k = paper_kernel::PaperKernel::new(&config);
    let table = signal::<f32>();
    k.prime(table[TABLE - 1].1);
    run_steps(&table, steps, |v, i| isr_step_kernel(&mut k, v, i))
}

/// fado's estimator (default, `FIXED_RS`, `PAPER_PATH`; `LEAN` for `step_lean`) or the Ortega
/// baseline.
fn run<T: Real>(steps: usize, ortega: bool) -> f64 {
    let machine = MachineModel::paper();
    let table = signal::<T>();
    if ortega {
        let mut est =
            OrtegaEstimator::<T>::new(OrtegaConfig::for_machine(&machine)).expect("valid");
        return run_steps(&table, steps, |v, i| isr_step(&mut est, v, i).theta);
    }
    let mut config = EstimatorConfig::for_machine(&machine);
    config.tuning.rs_adaptation.enabled = std::env::var("FIXED_RS").is_err();
    if std::env::var("PAPER_PATH").is_ok() {
        config.tuning = config.tuning.paper_path();
    }
    let mut est = SensorlessEstimator::<T>::new(config).expect("valid");
    if std::env::var("LEAN").is_ok() {
        return run_steps(&table, steps, |v, i| isr_step_lean(&mut est, v, i).theta);
    }
    run_steps(&table, steps, |v, i| isr_step(&mut est, v, i).theta)
}

/// One second of warm-up over `table` (so that the counted steps run in the settled k_df
/// mode), then `steps` calls of `step`; returns the sum of the angles (a checksum that keeps
/// the work alive).
fn run_steps<T: Real>(
    table: &[(Ab<T>, Ab<T>)],
    steps: usize,
    mut step: impl FnMut(Ab<T>, Ab<T>) -> T,
) -> f64 {
    for &(v, i) in table.iter().cycle().take(10_000) {
        step(v, i);
    }
    let mut acc = T::zero();
    for k in 0..steps {
        let (v, i) = table[k & (TABLE - 1)];
        acc += black_box(step(black_box(v), black_box(i)));
    }
    acc.to_f64()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let precision = args.next().unwrap_or_else(|| "f32".into());
    let steps: usize = args
        .next()
        .map(|s| s.parse().expect("N must be an integer"))
        .unwrap_or(100_000);
    let estimator = std::env::var("ESTIMATOR").unwrap_or_default();
    let ortega = estimator == "ortega";
    let acc = match precision.as_str() {
        "f32" if estimator == "paper-kernel" => run_kernel(steps),
        "f32" => run::<f32>(steps, ortega),
        "f64" => run::<f64>(steps, ortega),
        other => {
            eprintln!("usage: estimator-step-workload <f32|f64> <N>  (got {other:?})");
            std::process::exit(2);
        }
    };
    println!("{precision}: {steps} steps, checksum {acc:.6}");
}
