//! Fault monitoring of the drive: the status word of every sample ([`DriveFlags`]), per-flag
//! sample counters ([`FlagCounts`]) and the detectors behind the flags that are not simply a
//! block's report — a stuck phase-current channel ([`StuckChannelDetector`]) and a persistent
//! current-control error ([`PersistenceMonitor`]).
//!
//! The paper is silent on faults; everything here is ours \[A\], after common drive practice:
//! a bad sample is refused and the last output held, a persistent bad input trips, a
//! measurement that contradicts the controller's own reference is flagged and, where the
//! remaining sensor allows it, replaced by a reconstruction.

use core::ops::{BitOr, BitOrAssign};

use crate::{Ab, Real};

/// The drive's status word for one sample: faults and warnings as bits, so that it fits a
/// firmware status register and a trace column. Combine with `|`, test with
/// [`contains`](Self::contains).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct DriveFlags(u16);

impl DriveFlags {
    /// No flag.
    pub const NONE: Self = Self(0);
    /// This sample's inputs were non-finite (or a controller refused them): the last duty is
    /// held and the controllers are untouched.
    pub const INPUT_REJECTED: Self = Self(1 << 0);
    /// The drive has tripped (gates off, latched until `reset`): over-current, or too many
    /// consecutive rejected samples.
    pub const TRIPPED: Self = Self(1 << 1);
    /// The voltage reference had to be limited to the realisable set (hexagon).
    pub const VOLTAGE_SATURATED: Self = Self(1 << 2);
    /// The current has differed from its reference by more than `current_error_limit` for
    /// `current_error_samples` samples in a row: the current loop has lost control.
    pub const CURRENT_ERROR: Self = Self(1 << 3);
    /// A phase-current channel reads about zero while the reference asks for a clear current
    /// in that phase: judged stuck; its value is reconstructed from the other channel and the
    /// reference (see [`StuckChannelDetector`]).
    pub const SENSOR_STUCK: Self = Self(1 << 4);
    /// The measured DC-link voltage is below `dc_link_min_voltage`.
    pub const DC_LINK_LOW: Self = Self(1 << 5);
    /// FLAG_limit of the paper's Fig. 10: the estimator runs in limiter mode (not a fault).
    pub const LIMITER_MODE: Self = Self(1 << 6);
    /// The estimator reports its estimate lost ([`crate::lock`]'s flux and tracker symptoms; a
    /// live status that heals), or the drive coasts because of it: a reason for
    /// [`COASTING`](Self::COASTING).
    pub const LOCK_LOST: Self = Self(1 << 7);
    /// The drive holds zero current (speed loop off) because the rotor was lost
    /// (`lock_reaction` coast or recover; see [`crate::control::lock_reaction`]).
    pub const COASTING: Self = Self(1 << 8);
    /// This sample was refused as implausible (finite but beyond what the machine and
    /// inverter can produce, see [`crate::plausibility`]); `INPUT_REJECTED` is set too.
    pub const INPUT_IMPLAUSIBLE: Self = Self(1 << 9);
    /// The speed does not follow the torque: the speed loop asks for a torque below the
    /// current limit and ω̂ has left a reference it had caught without answering that torque
    /// (the drive's stall symptom, docs/method/lock.md; a live status that
    /// heals), or the drive coasts because of it: a reason for [`COASTING`](Self::COASTING).
    /// Either the rotor itself stalls or lags under its load, or the estimate has left the
    /// rotor near zero speed, where a back-EMF estimator cannot tell the two apart from v and
    /// i (docs/method/lock.md). Reported apart from
    /// [`LOCK_LOST`](Self::LOCK_LOST) so that a real stall is not called a lost estimate; it
    /// starts the lock reaction too unless the drive is told to report it only.
    pub const STALLED: Self = Self(1 << 10);

    /// Every flag with its name, in bit order (for tables and trace decoding).
    pub const ALL: [(Self, &'static str); 11] = [
        (Self::INPUT_REJECTED, "input_rejected"),
        (Self::TRIPPED, "tripped"),
        (Self::VOLTAGE_SATURATED, "voltage_saturated"),
        (Self::CURRENT_ERROR, "current_error"),
        (Self::SENSOR_STUCK, "sensor_stuck"),
        (Self::DC_LINK_LOW, "dc_link_low"),
        (Self::LIMITER_MODE, "limiter_mode"),
        (Self::LOCK_LOST, "lock_lost"),
        (Self::COASTING, "coasting"),
        (Self::INPUT_IMPLAUSIBLE, "input_implausible"),
        (Self::STALLED, "stalled"),
    ];

    /// The flags that are faults (everything but saturation and limiter mode, which occur in
    /// normal operation).
    pub const FAULTS: Self = Self(
        Self::INPUT_REJECTED.0
            | Self::TRIPPED.0
            | Self::CURRENT_ERROR.0
            | Self::SENSOR_STUCK.0
            | Self::DC_LINK_LOW.0
            | Self::LOCK_LOST.0
            | Self::COASTING.0
            | Self::INPUT_IMPLAUSIBLE.0
            | Self::STALLED.0,
    );

    /// The raw bits.
    pub const fn bits(self) -> u16 {
        self.0
    }

    /// Flags from raw bits (unknown bits are kept).
    pub const fn from_bits(bits: u16) -> Self {
        Self(bits)
    }

    /// True when every bit of `other` is set.
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// True when any bit of `other` is set.
    pub const fn intersects(self, other: Self) -> bool {
        self.0 & other.0 != 0
    }

    /// True when no bit is set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Sets or clears the bits of `flag`.
    pub fn set(&mut self, flag: Self, on: bool) {
        if on {
            self.0 |= flag.0;
        } else {
            self.0 &= !flag.0;
        }
    }
}

impl BitOr for DriveFlags {
    type Output = Self;
    fn bitor(self, o: Self) -> Self {
        Self(self.0 | o.0)
    }
}

impl BitOrAssign for DriveFlags {
    fn bitor_assign(&mut self, o: Self) {
        self.0 |= o.0;
    }
}

/// How many samples each flag has been raised since the last reset (saturating).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FlagCounts {
    counts: [u32; 16],
}

impl FlagCounts {
    /// Counts every bit set in `flags` once.
    pub fn record(&mut self, flags: DriveFlags) {
        let mut bits = flags.bits();
        while bits != 0 {
            let k = bits.trailing_zeros() as usize;
            self.counts[k] = self.counts[k].saturating_add(1);
            bits &= bits - 1;
        }
    }

    /// Samples with `flag` raised (for a multi-bit `flag`, its lowest bit).
    pub fn count(&self, flag: DriveFlags) -> u32 {
        match flag.bits() {
            0 => 0,
            b => self.counts[b.trailing_zeros() as usize],
        }
    }

    /// All counts back to zero.
    pub fn reset(&mut self) {
        self.counts = [0; 16];
    }
}

/// A condition that must hold for a number of samples in a row before it is reported (and
/// is cleared at once when it stops holding).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PersistenceMonitor {
    samples: u32,
    run: u32,
}

impl PersistenceMonitor {
    /// Reports after `samples` samples in a row; 0 never reports.
    pub const fn new(samples: u32) -> Self {
        Self { samples, run: 0 }
    }

    /// One sample of the condition; returns whether it is reported.
    pub fn step(&mut self, condition: bool) -> bool {
        self.run = if condition {
            self.run.saturating_add(1)
        } else {
            0
        };
        self.samples > 0 && self.run >= self.samples
    }

    /// Forget the run.
    pub fn reset(&mut self) {
        self.run = 0;
    }

    /// The condition held at the last sample (and the monitor is enabled).
    pub fn is_running(&self) -> bool {
        self.samples > 0 && self.run > 0
    }
}

/// Unit vectors of the phase axes a and b in α-β (amplitude-invariant Clarke: the phase-x
/// value of a vector i is Re(i·conj(u_x)), and adding Δ·u_x changes it by exactly Δ).
fn phase_axis<T: Real>(k: usize) -> Ab<T> {
    match k {
        0 => Ab::new(T::one(), T::zero()),
        _ => Ab::new(T::lit(-0.5), T::lit(0.866_025_403_784_438_6)),
    }
}

fn phase_value<T: Real>(i: Ab<T>, k: usize) -> T {
    let u = phase_axis::<T>(k);
    i.alpha * u.alpha + i.beta * u.beta
}

/// The reference level, in multiples of a [`StuckChannelDetector`]'s `min_reference`, from
/// which a near-zero reading is replaced at once, without the model's contradiction: 2 (2 A
/// on the paper's motor with the default 1 A threshold, half of I_min: a reading inside the
/// band under it is a current error of at least 1.75 A).
pub const IMMEDIATE_REFERENCE: f64 = 2.0;

/// Stuck-channel detector for the usual two-sensor set-up (phases a and b measured, c
/// reconstructed as −a − b, docs/method/estimator.md, "The paper's motor and drive").
///
/// Two sensors give no redundancy (a three-sensor sum check is impossible), but the drive knows
/// what current it is asking for. A channel is judged stuck when, for `samples` samples in a
/// row, it reads within ±`band` of zero while the reference's component in that phase is at
/// least `min_reference`: the current loop removes static errors and moving currents cross
/// zero within a fraction of a sample (at 20 Hz and 14 A, 0.5 A of band lasts 30 µs), so in
/// normal operation this does not persist. The channel is released as soon as it reads
/// outside the band again.
///
/// A channel is replaced by a reconstruction from its first implausible sample on (the flag
/// waits for the persistence, the substitution does not, so that the current loop acts on a
/// stuck reading for as few samples as possible). Under a reference of at least
/// [`IMMEDIATE_REFERENCE`] × `min_reference` in its phase a near-zero reading is implausible
/// at once; under a reference between `min_reference` and that, only where the model's
/// one-sample prediction of the phase also lies `band` or more from the reading. After a
/// reference step a healthy reading lags the reference by the loop's delay and can sit inside
/// the band for a sample while the reference asks for more; the prediction, driven by the
/// voltage that acted, follows it to within 0.22 band (fig8–fig12, and `reversal` and `stops`
/// on motors/ipmsm-2k2, servo-1ft6084 and hub-hoverboard-48v), while a channel stuck under
/// such a reference reads 5.9–9.5 band from it (steady300, phase a stuck at 2.5 s and
/// 2.525 s, crates/fado-sim/tests/faults.rs). So `min_reference` sets when a fault is
/// flagged and replaced, and changes no sample of a healthy run that raises no flag. On a
/// fast machine the prediction itself misses a healthy reading by the back-EMF's turn over
/// the sample, which the test allows ([`set_model_uncertainty`](Self::set_model_uncertainty)).
///
/// The reconstruction is the caller's model prediction of the current vector (the drive
/// propagates the machine model one sample from the last trusted current), corrected along
/// the other (good) phase's axis so that it matches that phase's reading exactly; with both
/// channels implausible, the prediction itself. The current loop and the estimator then run
/// on one sensor and the model, which rides through a short fault. In normal operation a
/// substitution of a sample or two (a transient with a large current error at a zero
/// crossing) changes the current by the model's one-sample error only.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StuckChannelDetector<T> {
    band: T,
    min_reference: T,
    /// The model's one-sample uncertainty (A, ≥ 0) the prediction may lie from a healthy
    /// reading near zero beyond `band` ([`set_model_uncertainty`](Self::set_model_uncertainty)).
    allowance: T,
    monitors: [PersistenceMonitor; 2],
    stuck: [bool; 2],
}

impl<T: Real> StuckChannelDetector<T> {
    /// A detector with the given band (A), minimum reference (A) and persistence (samples;
    /// 0 disables it). The caller validates the values.
    pub fn new(band: T, min_reference: T, samples: u32) -> Self {
        Self {
            band,
            min_reference,
            allowance: T::zero(),
            monitors: [PersistenceMonitor::new(samples); 2],
            stuck: [false; 2],
        }
    }

    /// Allows `uncertainty` (A, ≥ 0; a bad value counts as 0) more than `band` between a
    /// near-zero reading and the model's one-sample prediction in the contradiction test,
    /// and as much more reference for a replacement at once ([`IMMEDIATE_REFERENCE`]):
    /// what the prediction cannot know over the sample (the drive gives the back-EMF's turn
    /// over the sample through the inductance, which the prediction holds at its start).
    /// Measured on motors/multirotor-mn5006-22v (8 µH, 14 pole pairs, ω̂·Ts up to 0.29 rad):
    /// `regen-stop` at seed 2 0.237 rad when healthy zero-crossing samples are read as
    /// contradicted and replaced by the prediction, 0.105 rad with this allowance (0.095
    /// with the detector off); on the paper's motor the allowance is below 0.01 A at 300 r/min.
    pub fn set_model_uncertainty(&mut self, uncertainty: T) {
        self.allowance = if uncertainty.is_finite() && uncertainty > T::zero() {
            uncertainty
        } else {
            T::zero()
        };
    }

    /// Which of channels a and b are judged stuck now.
    pub fn stuck(&self) -> [bool; 2] {
        self.stuck
    }

    /// True when neither reading is near zero and no channel is judged stuck: then `step` needs
    /// neither the reference nor the model (the caller may pass zeros and skip computing them).
    #[inline]
    pub fn quiet(&self, i_a: T, i_b: T) -> bool {
        i_a.abs() >= self.band && i_b.abs() >= self.band && !self.stuck[0] && !self.stuck[1]
    }

    /// One sample: the (offset-corrected) readings of phases a and b, the current reference
    /// and the model's prediction of the current, both in α-β. Returns the phase currents a
    /// and b to use (readings, or reconstructions of the implausible channels) and whether
    /// any channel is judged stuck (implausible for `samples` samples in a row).
    pub fn step(&mut self, i_a: T, i_b: T, i_ref_ab: Ab<T>, i_model_ab: Ab<T>) -> (T, T, bool) {
        let reading = [i_a, i_b];
        let mut suspect = [false; 2];
        let contradiction = self.band + self.allowance;
        let immediate = T::lit(IMMEDIATE_REFERENCE) * self.min_reference + self.allowance;
        for k in 0..2 {
            let near_zero = reading[k].abs() < self.band;
            if self.stuck[k] {
                if !near_zero {
                    self.stuck[k] = false;
                    self.monitors[k].reset();
                }
            } else {
                let asked = phase_value(i_ref_ab, k).abs();
                self.stuck[k] = self.monitors[k].step(near_zero && asked >= self.min_reference);
                // Replaced before the flag only where the reading cannot be a healthy one
                // (see the type's docs): a reference of twice the threshold, or the model's
                // one-sample prediction a band away from the reading.
                let contradicted = asked >= self.min_reference
                    && (reading[k] - phase_value(i_model_ab, k)).abs() >= contradiction;
                suspect[k] = near_zero
                    && (asked >= immediate || contradicted)
                    && self.monitors[k].is_running();
            }
            suspect[k] |= self.stuck[k];
        }
        let i = match suspect {
            [false, false] => return (i_a, i_b, false),
            [true, true] => i_model_ab,
            [true, false] => i_model_ab + phase_axis::<T>(1) * (i_b - phase_value(i_model_ab, 1)),
            [false, true] => i_model_ab + phase_axis::<T>(0) * (i_a - phase_value(i_model_ab, 0)),
        };
        let (a, b) = (phase_value(i, 0), phase_value(i, 1));
        (
            if suspect[0] { a } else { i_a },
            if suspect[1] { b } else { i_b },
            self.stuck[0] || self.stuck[1],
        )
    }

    /// Forget everything.
    pub fn reset(&mut self) {
        self.monitors.iter_mut().for_each(PersistenceMonitor::reset);
        self.stuck = [false; 2];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_combine_count_and_name_every_bit() {
        let f = DriveFlags::SENSOR_STUCK | DriveFlags::VOLTAGE_SATURATED;
        assert!(f.contains(DriveFlags::SENSOR_STUCK) && !f.contains(DriveFlags::TRIPPED));
        assert!(f.intersects(DriveFlags::FAULTS));
        assert!(!DriveFlags::VOLTAGE_SATURATED.intersects(DriveFlags::FAULTS));
        let mut c = FlagCounts::default();
        c.record(f);
        c.record(DriveFlags::SENSOR_STUCK);
        assert_eq!(c.count(DriveFlags::SENSOR_STUCK), 2);
        assert_eq!(c.count(DriveFlags::VOLTAGE_SATURATED), 1);
        assert_eq!(c.count(DriveFlags::TRIPPED), 0);
        let mut all = DriveFlags::NONE;
        for (k, (flag, _)) in DriveFlags::ALL.iter().enumerate() {
            assert_eq!(flag.bits(), 1 << k, "bit order");
            all |= *flag;
        }
        assert_eq!(all.bits().count_ones() as usize, DriveFlags::ALL.len());
    }

    #[test]
    fn persistence_needs_an_unbroken_run() {
        let mut m = PersistenceMonitor::new(3);
        assert!(!m.step(true) && !m.step(true) && !m.step(false));
        assert!(!m.step(true) && !m.step(true) && m.step(true) && m.step(true));
        assert!(!m.step(false));
        let mut never = PersistenceMonitor::new(0);
        assert!((0..100).all(|_| !never.step(true)));
    }

    #[test]
    fn stuck_channel_is_detected_reconstructed_and_released() {
        let mut d = StuckChannelDetector::<f64>::new(0.25, 2.0, 5);
        // A reference of 10 A along α: phase a should carry 10 A, phase b −5 A.
        let i_ref = Ab::new(10.0, 0.0);
        // The model predicts 9.9 A along α.
        let i_model = Ab::new(9.9, 0.0);
        // Healthy readings close to the reference: never stuck, never replaced.
        for _ in 0..50 {
            assert_eq!(d.step(9.8, -4.9, i_ref, i_model), (9.8, -4.9, false));
        }
        // Channel a reads 0 while b still reads the true −4.9 A (true current 9.8 A along α):
        // replaced from the first sample, flagged at the fifth.
        for n in 1..=5 {
            let (a, b, stuck) = d.step(0.0, -4.9, i_ref, i_model);
            assert_eq!(stuck, n == 5, "sample {n}");
            // The prediction corrected along b to match b's reading:
            // i = (9.9, 0) + (−4.9 + 4.95)·(−0.5, √3/2): phase a = 9.9 − 0.025.
            assert!((a - 9.875).abs() < 1e-12 && b == -4.9, "{a} {b}");
        }
        // Released as soon as the channel reads a current again.
        assert_eq!(d.step(9.7, -4.9, i_ref, i_model), (9.7, -4.9, false));
        // A phase legitimately at zero (reference perpendicular to its axis) is not stuck
        // and not replaced.
        let perpendicular = Ab::new(0.0, 10.0);
        for _ in 0..50 {
            assert_eq!(
                d.step(0.01, 8.66, perpendicular, i_model),
                (0.01, 8.66, false)
            );
        }
        // Under a reference between the threshold and twice it (3 A in phase a), a near-zero
        // reading the model agrees with (a healthy current lagging a reference step) is
        // used as read until the persistence flags it; one the model puts 2.9 A away is
        // replaced at once.
        let mut d = StuckChannelDetector::<f64>::new(0.25, 2.0, 5);
        let small = Ab::new(3.0, 0.0);
        let agreeing = Ab::new(0.1, 0.0);
        for n in 1..=4 {
            assert_eq!(
                d.step(0.05, -0.05, small, agreeing),
                (0.05, -0.05, false),
                "{n}"
            );
        }
        let (a, _, stuck) = d.step(0.05, -0.05, small, agreeing);
        assert!(stuck && (a - 0.1).abs() < 1e-12, "{a}");
        let mut d = StuckChannelDetector::<f64>::new(0.25, 2.0, 5);
        let (a, b, stuck) = d.step(0.0, -1.45, small, Ab::new(2.9, 0.0));
        assert!(!stuck && (a - 2.9).abs() < 1e-12 && b == -1.45, "{a} {b}");
        // The model's one-sample uncertainty widens the contradiction: 1.0 A allowed, the
        // prediction 0.9 A from the reading (a fast machine's zero crossing) is no
        // contradiction; 2.9 A still is; a bad allowance counts as none.
        let mut d = StuckChannelDetector::<f64>::new(0.25, 2.0, 5);
        d.set_model_uncertainty(1.0);
        assert_eq!(
            d.step(0.0, -1.45, small, Ab::new(0.9, 0.0)),
            (0.0, -1.45, false)
        );
        let (a, _, _) = d.step(0.0, -1.45, small, Ab::new(2.9, 0.0));
        assert!((a - 2.9).abs() < 1e-12, "{a}");
        // It raises the immediate level too: 4.5 A in phase a, the model agreeing with the
        // reading, is replaced at once without the allowance and kept with 1 A of it.
        let large = Ab::new(4.5, 0.0);
        let (a, _, _) = d.step(0.05, -0.05, large, agreeing);
        assert_eq!(a, 0.05);
        let mut d = StuckChannelDetector::<f64>::new(0.25, 2.0, 5);
        let (a, _, _) = d.step(0.05, -0.05, large, agreeing);
        assert!((a - 0.1).abs() < 1e-12, "{a}");
        let mut d = StuckChannelDetector::<f64>::new(0.25, 2.0, 5);
        d.set_model_uncertainty(f64::NAN);
        let (a, _, _) = d.step(0.0, -1.45, small, Ab::new(0.9, 0.0));
        // Replaced: the prediction corrected along b, 0.9 + (−1.45 + 0.45)·(−0.5).
        assert!((a - 1.4).abs() < 1e-12, "{a}");
        // Disabled: never replaced either.
        let mut off = StuckChannelDetector::<f64>::new(0.25, 2.0, 0);
        assert!((0..50).all(|_| off.step(0.0, 0.0, i_ref, i_model) == (0.0, 0.0, false)));
    }
}
