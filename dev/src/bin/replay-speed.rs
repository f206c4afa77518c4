//! The pure-Rust reference for the speed of `fado.estimate`: the same synthetic recording as
//! `scripts/replay-speed.py` (a rotor spinning up to 20 Hz electrical under 10 A, 1 million samples
//! at 10 kHz), replayed two ways:
//!
//! - `step loop`: `SensorlessEstimator::step` per sample, outputs only folded into a checksum
//!   (the least work a replay can do);
//! - `replay`: the loop behind `fado.estimate`, filling every output column;
//! - `columns alone`: allocating and filling those columns with a constant, no estimator: the
//!   cost of writing ~100 bytes per sample into fresh memory (page faults dominate it).
//!
//! Prints the best of several runs in ns per sample, for f64 and f32:
//! `cargo run --release -p fado-dev --bin replay-speed [-- SAMPLES]`.

use std::hint::black_box;
use std::time::Instant;

use fado_core::{Ab, Estimate, EstimatorConfig, MachineModel, Real, SensorlessEstimator};
use fado_py::outputs::Columns;
use fado_py::replay::replay;

// The paper's motor (`MachineModel::paper()`), at its 10 kHz sampling.
const TS: f64 = 100e-6;
const RS: f64 = 0.327;
const LQ: f64 = 2.63e-3;
const FLUX: f64 = 0.088;
const REPEATS: usize = 5;

/// v_α, v_β, i_α, i_β of a surface-magnet rotor ramping 0 → 20 Hz in 0.3 s with i_q = 10 A,
/// voltages consistent with the estimator's integrator (see tests/python/conftest.py).
fn recording(n: usize) -> [Vec<f64>; 4] {
    let (mut va, mut vb, mut ia, mut ib) = (vec![], vec![], vec![], vec![]);
    let state = |theta: f64| {
        let (s, c) = theta.sin_cos();
        let i = (-10.0 * s, 10.0 * c);
        let flux = (FLUX * c + LQ * i.0, FLUX * s + LQ * i.1);
        (i, flux)
    };
    let mut theta = 0.3;
    let (mut i_prev, mut flux_prev) = state(theta);
    for k in 0..n {
        let omega = 2.0 * std::f64::consts::PI * 20.0 * (k as f64 * TS / 0.3).min(1.0);
        theta += omega * TS;
        let (i, flux) = state(theta);
        va.push((flux.0 - flux_prev.0) / TS + RS * 0.5 * (i.0 + i_prev.0));
        vb.push((flux.1 - flux_prev.1) / TS + RS * 0.5 * (i.1 + i_prev.1));
        ia.push(i.0);
        ib.push(i.1);
        (i_prev, flux_prev) = (i, flux);
    }
    [va, vb, ia, ib]
}

fn best_of(mut f: impl FnMut()) -> f64 {
    (0..REPEATS)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn measure<T: Real>(label: &str, signals: &[Vec<f64>; 4]) {
    let [va, vb, ia, ib] = signals
        .each_ref()
        .map(|s| s.iter().map(|&x| T::lit(x)).collect::<Vec<T>>());
    let n = va.len() as f64;
    let config = EstimatorConfig::<T>::for_machine(&MachineModel::paper());
    let step_loop = best_of(|| {
        let mut est = SensorlessEstimator::new(config).expect("the paper motor's config is valid");
        let mut sum = T::zero();
        for k in 0..va.len() {
            let out = est.step(Ab::new(va[k], vb[k]), Ab::new(ia[k], ib[k]));
            sum += out.theta + out.diagnostics.lambda1.alpha;
        }
        black_box(sum);
    });
    let columns = best_of(|| {
        let mut est = SensorlessEstimator::new(config).expect("the paper motor's config is valid");
        black_box(replay(&mut est, &va, &vb, &ia, &ib));
    });
    let fill = best_of(|| {
        let mut c = Columns::<T>::with_capacity(va.len());
        let constant = Estimate::<T>::default();
        for _ in 0..va.len() {
            c.push(black_box(&constant));
        }
        black_box(c);
    });
    println!(
        "{label}: step loop {:.1} ns/sample, replay into columns {:.1} ns/sample, columns alone \
         {:.1} ns/sample",
        step_loop / n * 1e9,
        columns / n * 1e9,
        fill / n * 1e9
    );
}

fn main() {
    let n = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let signals = recording(n);
    println!("{n} samples, best of {REPEATS}");
    measure::<f64>("f64", &signals);
    measure::<f32>("f32", &signals);
}
