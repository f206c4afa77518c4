//! Rejected samples: the duty held, the estimator's clock kept.

use super::{Blocks, DriveOutput, SensorlessDrive, estimate_is_finite};
use crate::estimator::{Estimate, RotorAngleEstimator};
use crate::{Abc, Dq, Real};

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// Rejected sample: hold the duty, keep the estimator's clock with the last good current.
    pub(super) fn reject(&mut self, i_abc: Abc<T>) -> DriveOutput<T> {
        let i_ab = i_abc.to_ab();
        let lim = self.resolved.plausible_current;
        let plausible = (i_abc.a.abs() < lim) & (i_abc.b.abs() < lim) & (i_abc.c.abs() < lim);
        let i_ab = if plausible && i_ab.is_finite() {
            i_ab
        } else {
            self.last_i_ab
        };
        self.i_ab_used = i_ab;
        let estimate = self.estimator.step(self.history[1], i_ab);
        let mut out = self.last;
        if estimate_is_finite(&estimate) {
            out.estimate = estimate;
        }
        self.finish_reject(out)
    }

    /// Rejected after the estimator ran (a controller refused its input): controllers restored.
    pub(super) fn reject_after_estimate(
        &mut self,
        blocks: Blocks<T>,
        estimate: Estimate<T>,
        i_dq: Dq<T>,
    ) -> DriveOutput<T> {
        self.blocks = blocks;
        let mut out = self.last;
        out.estimate = estimate;
        out.i_dq = i_dq;
        self.finish_reject(out)
    }

    pub(super) fn finish_reject(&mut self, mut out: DriveOutput<T>) -> DriveOutput<T> {
        self.rejected_samples = self.rejected_samples.saturating_add(1);
        // The held duty applies the same voltage once more.
        self.history = [self.history[0], self.history[0]];
        self.limited = [self.limited[0], self.limited[0]];
        out.input_fault = true;
        self.last = out;
        out
    }
}
