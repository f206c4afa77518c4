//! Paired (interleaved) timing of fado's `f32` step against the Ortega baseline's: the ratio
//! fado's bound ("fado's f32 step ≤ 1.2× the Ortega baseline's in the same run"),
//! measured so that the machine's drift cancels.
//!
//! criterion times each estimator in its own few seconds, one after the other; on a shared
//! virtual machine the speed of the host moves by 10–20 % between those windows, and the ratio
//! of two criterion medians moves with it (docs/results/firmware-cost.md: 0.96–1.41× over
//! nine runs). Here every round times one block of steps of *each* estimator, in a random
//! order, back to back, and the statistic is the median over rounds of the per-round ratio:
//! a paired design (the two blocks of a round share the machine's state; what changes between
//! rounds cancels in the ratio), the method of paired benchmarking harnesses such as
//! `tango-bench` (D. Bazhenov, "Paired benchmarking", 2023) and of the classic A/B
//! interleaving in Kalibera & Jones, "Rigorous benchmarking in reasonable time" (ISMM 2013).
//! The 95 % confidence interval of the median ratio is distribution-free: the order
//! statistics at ranks n/2 ∓ 0.98·√n (the binomial sign-test interval, normal
//! approximation), so no assumption about the noise's shape.
//!
//! The inputs, the estimators and their warm-up are those of `benches/baselines.rs` (300 r/min
//! under load, every branch the one taken in operation); each step's output goes through
//! `black_box` as there. It is a measured report, not a test: run
//! `cargo bench --bench paired` (`-- REPEATS ROUNDS BLOCK` to change the design, default
//! 5 × 2000 × 1000: about 15 s). Each repeat prints its own ratios: between repeats the host's
//! state can change (docs/results/firmware-cost.md), and the ratio with it.

// A benchmark binary: it prints its report.
#![allow(missing_docs)]

use std::hint::black_box;
use std::time::Instant;

use fado_core::baselines::{OrtegaConfig, OrtegaEstimator};
use fado_core::{Ab, MachineModel, RotorAngleEstimator};

mod common;

use common::{fado, inputs};

/// An estimator under test, with its place in the input period.
struct Subject {
    name: &'static str,
    run: Box<dyn FnMut(usize) -> f64>,
    /// Per-round nanoseconds per step.
    ns: Vec<f64>,
}

/// Warms an estimator up as `baselines.rs` does (two seconds: trackers locked, fado in k_df
/// mode) through `step`, its call under test, and returns a closure that times `block` calls
/// and gives nanoseconds per step. Each call's output goes through `black_box` whole.
fn subject<R: 'static>(
    name: &'static str,
    mut step: impl FnMut(Ab<f32>, Ab<f32>) -> R + 'static,
    data: std::rc::Rc<Vec<(Ab<f32>, Ab<f32>)>>,
) -> Subject {
    for k in 0..20_000 {
        let (v, i) = data[k % data.len()];
        step(v, i);
    }
    let mut k = 0;
    Subject {
        name,
        run: Box::new(move |block| {
            let start = Instant::now();
            for _ in 0..block {
                let (v, i) = data[k];
                k = if k + 1 == data.len() { 0 } else { k + 1 };
                black_box(step(black_box(v), black_box(i)));
            }
            start.elapsed().as_nanos() as f64 / block as f64
        }),
        ns: Vec::new(),
    }
}

/// The trait's step of an estimator: what criterion times in `baselines.rs`.
fn trait_step<E: RotorAngleEstimator<f32> + 'static>(
    mut est: E,
) -> impl FnMut(Ab<f32>, Ab<f32>) -> fado_core::Estimate<f32> + 'static {
    move |v, i| est.step(v, i)
}

/// The median and its distribution-free 95 % interval (order statistics at n/2 ∓ 0.98·√n).
fn median_ci(values: &[f64]) -> (f64, f64, f64) {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let half = 0.98 * (n as f64).sqrt();
    let lo = ((n as f64 / 2.0 - half).floor().max(0.0)) as usize;
    let hi = ((n as f64 / 2.0 + half).ceil() as usize).min(n - 1);
    let median = if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    };
    (median, v[lo], v[hi])
}

fn main() {
    // `cargo bench` passes `--bench`; numbers after it are REPEATS, ROUNDS and BLOCK.
    let numbers: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let repeats = numbers.first().copied().unwrap_or(5).max(1);
    let rounds = numbers.get(1).copied().unwrap_or(2000).max(1);
    let block = numbers.get(2).copied().unwrap_or(1000).max(1);
    let data = std::rc::Rc::new(inputs());
    let machine = MachineModel::paper();
    let mut subjects = vec![
        subject(
            "ortega",
            trait_step(
                OrtegaEstimator::<f32>::new(OrtegaConfig::for_machine(&machine))
                    .expect("the paper's motor is a valid config"),
            ),
            data.clone(),
        ),
        subject("fado", trait_step(fado(|_| {})), data.clone()),
        subject(
            "fado-fixed-rs",
            trait_step(fado(|c| c.tuning.rs_adaptation.enabled = false)),
            data.clone(),
        ),
        subject(
            "fado-paper-path",
            trait_step(fado(|c| c.tuning = c.tuning.paper_path())),
            data.clone(),
        ),
        // fado's firmware call, without the diagnostics (`LeanEstimate`).
        subject(
            "fado step_lean",
            {
                let mut est = fado(|_| {});
                move |v, i| est.step_lean(v, i)
            },
            data.clone(),
        ),
    ];
    // xorshift64*: a random order of the subjects in each round, reproducible.
    let mut seed: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = move || {
        seed ^= seed >> 12;
        seed ^= seed << 25;
        seed ^= seed >> 27;
        seed.wrapping_mul(0x2545_F491_4F6C_DD1D)
    };
    // One untimed round per subject, so that the first timed one finds warm caches.
    for s in &mut subjects {
        (s.run)(block);
    }
    println!(
        "paired timing of the f32 step: {repeats} repeats of {rounds} rounds; a round times {block} \
         steps of each estimator, in a random order"
    );
    println!(
        "cells: median over the rounds of (ns per step ÷ Ortega's in the same round), its 95 % \
         confidence interval; Ortega's median ns per step"
    );
    print!("{:<8} {:>11}", "repeat", "ortega ns");
    for s in &subjects[1..] {
        print!(" {:>24}", s.name);
    }
    println!();
    let mut ranges = vec![(f64::INFINITY, f64::NEG_INFINITY); subjects.len()];
    let mut order: Vec<usize> = (0..subjects.len()).collect();
    for repeat in 1..=repeats {
        for s in &mut subjects {
            s.ns.clear();
        }
        for _ in 0..rounds {
            for i in (1..order.len()).rev() {
                order.swap(i, (next() % (i as u64 + 1)) as usize);
            }
            for &j in &order {
                let ns = (subjects[j].run)(block);
                subjects[j].ns.push(ns);
            }
        }
        let (base_ns, _, _) = median_ci(&subjects[0].ns);
        print!("{repeat:<8} {base_ns:>11.2}");
        for (j, s) in subjects.iter().enumerate().skip(1) {
            let ratios: Vec<f64> =
                s.ns.iter()
                    .zip(&subjects[0].ns)
                    .map(|(a, b)| a / b)
                    .collect();
            let (r, lo, hi) = median_ci(&ratios);
            ranges[j] = (ranges[j].0.min(r), ranges[j].1.max(r));
            print!(" {:>24}", format!("{r:.3} ({lo:.3}–{hi:.3})"));
        }
        println!();
    }
    print!("{:<8} {:>11}", "range", "");
    for range in &ranges[1..] {
        print!(" {:>24}", format!("{:.3}–{:.3}", range.0, range.1));
    }
    println!();
}
