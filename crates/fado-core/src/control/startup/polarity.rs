//! The polarity test along a known axis: pulse pairs alternately along +axis and −axis; the
//! direction whose current rises faster meets the smaller incremental inductance, the one
//! whose current adds to the magnet's flux and saturates the d-axis iron further.

use super::POLARITY_PAIRS;
use crate::control::initial_angle::{DEFAULT_MIN_POLARITY, pair_samples, return_voltage};
use crate::{Ab, Real};

/// The polarity test (module docs). Allocation-free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolarityTest<T> {
    axis: T,
    voltage: T,
    n: u32,
    inductance: T,
    ts: T,
    sample: u32,
    start: T,
    peak: T,
    /// Sums of the peaks along +axis and −axis.
    sums: (T, T),
    contrast: T,
    result: Option<Option<T>>,
}

impl<T: Real> PolarityTest<T> {
    /// The test along `axis` (electrical rad) with pulses of `voltage` for `n` samples each;
    /// `inductance` and `ts` set the return of the current to zero.
    pub fn new(axis: T, voltage: T, n: u32, inductance: T, ts: T) -> Self {
        Self {
            axis,
            voltage,
            n: n.max(1),
            inductance,
            ts,
            sample: 0,
            start: T::zero(),
            peak: T::zero(),
            sums: (T::zero(), T::zero()),
            contrast: T::zero(),
            result: None,
        }
    }

    /// The axis tested.
    pub fn axis(&self) -> T {
        self.axis
    }

    /// (+axis − −axis)/mean of the peaks.
    pub fn contrast(&self) -> T {
        self.contrast
    }

    /// None while running; then Some(the magnet's angle) or Some(None) when the two
    /// directions do not differ by [`DEFAULT_MIN_POLARITY`] of their mean.
    pub fn result(&self) -> Option<Option<T>> {
        self.result
    }

    /// Samples of the whole test.
    pub fn duration_samples(&self) -> u32 {
        pair_samples(self.n).get() * 2 * POLARITY_PAIRS
    }

    /// One sample: `i_ab` the current measured now. Returns the α-β voltage to apply.
    pub fn step(&mut self, i_ab: Ab<T>) -> Ab<T> {
        if self.result.is_some() {
            return Ab::zero();
        }
        let n = self.n;
        let period = pair_samples(n);
        let pair = self.sample / period;
        let phase = self.sample % period;
        let (s, c) = self.axis.step_sin_cos_any();
        let u = if pair.is_multiple_of(2) {
            Ab::new(c, s)
        } else {
            Ab::new(-c, -s)
        };
        let along = u.dot(i_ab);
        if phase == 0 {
            // The peak of the pair before, read up to its last sample.
            self.close(pair);
            self.start = along;
            self.peak = T::zero();
        }
        let rise = along - self.start;
        if rise > self.peak || !rise.is_finite() {
            self.peak = rise;
        }
        self.sample += 1;
        if pair >= 2 * POLARITY_PAIRS {
            self.evaluate();
            return Ab::zero();
        }
        if phase < n {
            u * self.voltage
        } else if phase < 2 * n {
            u * (-self.voltage)
        } else {
            return_voltage(i_ab, self.inductance, self.ts)
        }
    }

    /// Adds the finished pair before `pair` to its direction's sum.
    fn close(&mut self, pair: u32) {
        if pair == 0 {
            return;
        }
        if (pair - 1).is_multiple_of(2) {
            self.sums.0 += self.peak;
        } else {
            self.sums.1 += self.peak;
        }
    }

    fn evaluate(&mut self) {
        let (plus, minus) = self.sums;
        let mean = T::lit(0.5) * (plus + minus);
        if !(mean > T::zero() && plus.is_finite() && minus.is_finite()) {
            self.result = Some(None);
            return;
        }
        self.contrast = (plus - minus) / mean;
        let min = T::lit(DEFAULT_MIN_POLARITY);
        self.result = Some(if self.contrast >= min {
            Some(self.axis)
        } else if self.contrast <= -min {
            Some(self.axis + T::pi())
        } else {
            None
        });
    }
}
