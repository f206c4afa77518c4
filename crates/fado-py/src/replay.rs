//! Replaying a recorded (or simulated) set of signals through the estimator: the loop behind
//! `fado.estimate` and `Estimator.run`. Plain Rust, no Python: it runs with the GIL released
//! and is what `dev/src/bin/replay-speed.rs` times.

use std::sync::atomic::{AtomicBool, Ordering};

use fado_core::{Ab, Real, SensorlessEstimator};
use fado_sim::sim::CANCEL_CHECK_SAMPLES;

use crate::outputs::Columns;

/// Steps `estimator` once per sample of v_α, v_β, i_α, i_β (equal lengths; a longer slice's
/// tail is ignored) and returns every output, column by column.
pub fn replay<T: Real>(
    estimator: &mut SensorlessEstimator<T>,
    v_alpha: &[T],
    v_beta: &[T],
    i_alpha: &[T],
    i_beta: &[T],
) -> Columns<T> {
    replay_until(estimator, v_alpha, v_beta, i_alpha, i_beta, None)
        .expect("a replay without a cancel flag is never cancelled")
}

/// [`replay`] that stops (None) once `cancel` is set, looking at it every
/// [`CANCEL_CHECK_SAMPLES`] samples; the estimator has then consumed part of the signals.
pub fn replay_until<T: Real>(
    estimator: &mut SensorlessEstimator<T>,
    v_alpha: &[T],
    v_beta: &[T],
    i_alpha: &[T],
    i_beta: &[T],
    cancel: Option<&AtomicBool>,
) -> Option<Columns<T>> {
    let n = v_alpha
        .len()
        .min(v_beta.len())
        .min(i_alpha.len())
        .min(i_beta.len());
    let mut columns = Columns::with_capacity(n);
    let chunk = CANCEL_CHECK_SAMPLES as usize;
    for start in (0..n).step_by(chunk) {
        if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return None;
        }
        let end = (start + chunk).min(n);
        let samples = v_alpha[start..end]
            .iter()
            .zip(&v_beta[start..end])
            .zip(i_alpha[start..end].iter().zip(&i_beta[start..end]));
        for ((&va, &vb), (&ia, &ib)) in samples {
            let out = estimator.step(Ab::new(va, vb), Ab::new(ia, ib));
            columns.push(&out);
        }
    }
    Some(columns)
}
