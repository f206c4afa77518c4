//! Replaying a recorded (or simulated) set of signals through the estimator: the loop behind
//! `fado.estimate` and `Estimator.run`. Plain Rust, no Python: it runs with the GIL released
//! and is what `examples/replay_speed.rs` times.

use fado_core::{Ab, Real, SensorlessEstimator};

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
    let n = v_alpha
        .len()
        .min(v_beta.len())
        .min(i_alpha.len())
        .min(i_beta.len());
    let mut columns = Columns::with_capacity(n);
    let samples = v_alpha
        .iter()
        .zip(v_beta)
        .zip(i_alpha.iter().zip(i_beta))
        .take(n);
    for ((&va, &vb), (&ia, &ib)) in samples {
        let out = estimator.step(Ab::new(va, vb), Ab::new(ia, ib));
        columns.push(&out);
    }
    columns
}
