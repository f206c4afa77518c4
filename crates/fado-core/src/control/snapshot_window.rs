//! A sliding window of snapshots: a value recorded every few samples into a ring of `N`
//! slots spanning a stated time, so that the change of a running quantity over the recent
//! window (a flux's travel, an integral's mean) is read from the oldest snapshot. Used by the
//! start-up's motion monitor and the gain calibration's motion test.

use crate::real::Real;

/// A ring of `N` snapshots of a `V`, one every `slot_samples` samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SnapshotWindow<V, const N: usize> {
    /// Samples between two snapshots (at least 1).
    slot_samples: u32,
    /// The snapshots, the oldest at `slot`, `taken` of them.
    slots: [V; N],
    slot: usize,
    taken: u32,
    /// Samples since the last snapshot.
    since: u32,
    /// The value the slots are cleared to.
    zero: V,
}

impl<V: Copy, const N: usize> SnapshotWindow<V, N> {
    /// An empty window of `window_time` (s) sampled at `ts`: a snapshot every
    /// `window_time/(N·ts)` samples, rounded, at least one (also for a non-finite `ts`).
    pub fn new<T: Real>(window_time: f64, ts: T, zero: V) -> Self {
        let n = T::lit(window_time / N as f64) / ts;
        // NaN compares false: one sample.
        let slot_samples = if n >= T::one() && n < T::lit(1e6) {
            n.round().to_f64() as u32
        } else {
            1
        };
        Self {
            slot_samples,
            slots: [zero; N],
            slot: 0,
            taken: 0,
            since: 0,
            zero,
        }
    }

    /// Empties the window.
    pub fn reset(&mut self) {
        self.slots = [self.zero; N];
        self.slot = 0;
        self.taken = 0;
        self.since = 0;
    }

    /// How many snapshots the window holds.
    pub fn taken(&self) -> u32 {
        self.taken
    }

    /// The oldest snapshot and the samples since it (before this sample's
    /// [`push`](Self::push)); `None` while the window is empty.
    pub fn oldest(&self) -> Option<(V, u32)> {
        if self.taken == 0 {
            return None;
        }
        let span = self.since + (self.taken - 1) * self.slot_samples;
        // `% N` (the slot is always below it) proves the index in range: no panic path in
        // the firmware's step.
        Some((self.slots[self.slot % N], span))
    }

    /// This sample's value: a snapshot of it at the first sample and every `slot_samples`,
    /// replacing the oldest once the ring is full.
    pub fn push(&mut self, value: V) {
        self.since += 1;
        if self.taken == 0 || self.since >= self.slot_samples {
            if (self.taken as usize) < N {
                let k = (self.slot + self.taken as usize) % N;
                self.slots[k] = value;
                self.taken += 1;
            } else {
                self.slots[self.slot % N] = value;
                self.slot = (self.slot + 1) % N;
            }
            self.since = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_oldest_snapshot_spans_the_window_once_full() {
        // 8 slots over 8 ms at 1 ms: a snapshot every sample.
        let mut w = SnapshotWindow::<f64, 4>::new(8e-3, 1e-3, 0.0);
        assert_eq!(w.oldest(), None);
        for k in 0..20 {
            w.push(k as f64);
        }
        // Every second sample (8 ms / 4 slots / 1 ms): slots 12, 14, 16, 18; 1 sample since 18.
        let (v, span) = w.oldest().unwrap();
        assert_eq!((v, span), (12.0, 7));
        assert_eq!(w.taken(), 4);
        w.reset();
        assert_eq!(w.oldest(), None);
        // A non-finite period gives one sample per slot.
        let mut w = SnapshotWindow::<f64, 2>::new(1e-3, f64::NAN, 0.0);
        w.push(1.0);
        w.push(2.0);
        w.push(3.0);
        assert_eq!(w.oldest(), Some((2.0, 1)));
    }
}
