//! Loss-of-lock detection: the estimator judges its own estimate from signals it already has,
//! and says "sensorless estimate lost" instead of driving on with a wrong angle.
//!
//! The paper's estimator has no such output; this module is ours \[A\]. Two symptoms, each a
//! few compares per sample on quantities the estimator computed anyway:
//!
//! 1. **Flux-magnitude consistency** — |λ̂r| must be the magnet's λ̂f (eq. (5): λ̂r is the
//!    active flux λf + (Ld − Lq)·i_d, Boldea et al. 2008, which is λf for a surface rotor).
//!    An integrand error u (R̂s error × current, a voltage error) integrated by eq. (21)
//!    moves λ̂r by u/ω: at speed mostly radially for a q-axis current (ΔRs·i_q/ω along d),
//!    so |λ̂r| leaves λ̂f *before* the angle does — the early warning of the loaded
//!    zero-speed passage that the paper (section V) and docs/guide/first-run.md call the critical case. In
//!    limiter mode (Fig. 6) the limiter holds |λ̂r| ≤ 1.15·λ̂f, so there a persistent
//!    shrink below the circle or a persistent push against it is what remains visible.
//!    The same consistency test is the core of the flux-magnitude checks of voltage-model
//!    observers (Hinkkanen, Tuovinen, Harnefors & Luomi, "A combined position and
//!    stator-resistance observer for salient PMSM drives", IEEE TIA 48(2), 2012, use
//!    |λ̂| − λ̂f as the error signal; Ortega et al., IEEE TCST 19(3), 2011, the same circle).
//! 2. **Tracker innovation** — |wrap(θm − θ̂⁻)|, the T2S-1 input error of Fig. 1: in lock it
//!    is the tracking error of a type-2 loop (small); a slip of the direct angle (λ̂r
//!    collapsing through the origin, a π jump) makes it large at once. This is the
//!    "phase detector" lock indicator of PLL practice (Gardner, *Phaselock Techniques*, 3rd
//!    ed., ch. 8, lock detection).
//! 3. **Mode hand-over chatter** — the rate of the mode selector's hand-overs (Fig. 3). The
//!    selector's hysteresis (docs/method/estimator.md §1) exists so that noise on ω̂ cannot make it chatter: one
//!    hand-over needs ω̂ to cross the whole band (0.004 of the rated speed by default), so a
//!    run that passes through the band once hands over once or twice. An estimate caught in a
//!    limit cycle swings ω̂ across the band tens of times a second (ipmsm-gem-50k's start-up
//!    with L̂q over-estimated by 20–30 %: typically 13–18 hand-overs in 0.25 s, with
//!    |θ − θ̂| swinging ±0.5 rad before the rotor is lost; runs that keep the rotor below
//!    0.25 rad: 1–2 on five presets, up to 9 at the start-up of the two salient ones,
//!    docs/method/lock.md). The rate is a leaky count: each hand-over adds
//!    1, and the level decays with the time constant `handover_time` (forward Euler at the
//!    detector's period, pole 1 − ts/`handover_time`); at steady rate r it settles at
//!    r·`handover_time`. Hysteresis switching that keeps switching is the classic sign of a
//!    system that does not settle in either mode (Liberzon, *Switching in Systems and
//!    Control*, Birkhäuser 2003, §1.2.3 on hysteresis switching and chattering).
//!
//! The upper half of symptom 1 (|λ̂r| above the band) is set wide by default (1.5·λ̂f): on
//! the fig11 envelope a tight bound's alarms came from the |λ̂r| overshoot after a limiter →
//! k_df hand-over in runs that kept the rotor (docs/method/lock.md). The lower half depends on the
//! speed estimate: 0.7·λ̂f below the mode hand-over band (where the start-up dip that
//! precedes a 0.5 rad start-up excursion sits), 0.6·λ̂f from the band's lower edge up, where
//! runs that keep the rotor dip to 0.67–0.70·λ̂f accelerating out of the reversal at light
//! load and the losses that only this symptom catches go through 0.42–0.53·λ̂f
//! (docs/method/lock.md, 2026-11-24). Near zero speed, where a
//! surface-magnet rotor's angle is not observable from v and i (an integrand error ΔR̂s·i
//! along q̂ turns λ̂r without changing |λ̂r|), a loss shows first on the mechanical side; the
//! drive adds that symptom (a speed-loop stall in limiter mode while the loop commands a
//! torque, with its own speed band and current gate, see
//! [`crate::control::SensorlessDrive`]). The drive reports the two apart: `LOCK_LOST` for the
//! estimator's verdict, `STALLED` for the stall symptom, which cannot tell an estimate that has
//! left the rotor from a rotor that really stalls or lags under its load (docs/method/lock.md); either starts the drive's reaction
//! ([`crate::control::lock_reaction`]).
//!
//! The verdicts feed an up/down debouncing counter (the counter-based debouncing of AUTOSAR
//! DEM, "Specification of Diagnostic Event Manager", §7.7.4.1, with its separate "passed"
//! threshold for healing): +1 per suspicious sample, −1 per clean one (floored at 0);
//! [`LockStatus::Lost`] when it reaches `detection_time/ts`. The status is **live**: once
//! lost, the counter restarts from `heal_time/ts` (and saturates there), and the status
//! returns to [`LockStatus::Locked`] when a net `heal_time` of clean samples has brought it
//! to 0. A start-up transient that raised it heals, so that a later loss raises it anew; the
//! drive's *reaction* (coast, recover) latches separately
//! ([`crate::control::lock_reaction`]). The same [`Debouncer`] turns the drive's stall
//! symptom into a live status. The estimator judges every fourth sample (its slow laws'
//! round-robin), with `ts` = 4 sampling periods: the same times to a verdict and to healing.

use crate::Real;
use crate::error::{ConfigError, check};

/// Whether the estimate is trusted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum LockStatus {
    /// No symptom pending.
    #[default]
    Locked = 0,
    /// Symptoms seen, not yet for long enough to call the rotor lost.
    Suspect = 1,
    /// The estimate is judged lost (until a net `lock.heal_time` of clean samples, or a
    /// reset, e.g. by `align`).
    Lost = 2,
}

impl LockStatus {
    /// 0 locked, 1 suspect, 2 lost (the trace column `lock`).
    pub fn code(self) -> u8 {
        self as u8
    }
}

/// Up/down debouncing counter with a healing threshold (see the module docs): raised after a
/// net `limit` symptomatic samples, cleared after a net `heal` clean ones. `limit` 0 never
/// raises.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Debouncer {
    limit: u32,
    heal: u32,
    count: u32,
    up: bool,
}

impl Debouncer {
    /// Raised after `limit` net symptomatic samples, cleared after `heal` (at least 1) net
    /// clean ones.
    pub const fn new(limit: u32, heal: u32) -> Self {
        Self {
            limit,
            heal: if heal == 0 { 1 } else { heal },
            count: 0,
            up: false,
        }
    }

    /// The state after one sample (`symptom`: this sample is suspicious); `self` unchanged.
    #[inline]
    #[must_use]
    pub fn next(self, symptom: bool) -> Self {
        if self.limit == 0 {
            return self;
        }
        let count = if symptom {
            self.count.saturating_add(1)
        } else {
            self.count.saturating_sub(1)
        };
        if self.up {
            let count = count.min(self.heal);
            Self {
                count,
                up: count > 0,
                ..self
            }
        } else if count >= self.limit {
            Self {
                count: self.heal,
                up: true,
                ..self
            }
        } else {
            Self { count, ..self }
        }
    }

    /// One sample, committed; returns whether the status is raised.
    #[inline]
    pub fn step(&mut self, symptom: bool) -> bool {
        *self = self.next(symptom);
        self.up
    }

    /// Raised (the condition has held for a net `limit` samples and not yet healed).
    pub fn is_up(&self) -> bool {
        self.up
    }

    /// [`LockStatus::Lost`] while raised, [`LockStatus::Suspect`] while counting up.
    pub fn status(&self) -> LockStatus {
        if self.up {
            LockStatus::Lost
        } else if self.count > 0 {
            LockStatus::Suspect
        } else {
            LockStatus::Locked
        }
    }

    /// Back to cleared, count 0.
    pub fn reset(&mut self) {
        self.count = 0;
        self.up = false;
    }

    /// The counter's mutable part (its limits are constants).
    #[inline(always)]
    pub(crate) fn counter_state(&self) -> DebouncerState {
        DebouncerState {
            count: self.count,
            up: self.up,
        }
    }

    /// This counter's limits with the mutable part `s`.
    #[inline(always)]
    pub(crate) fn with_state(self, s: DebouncerState) -> Self {
        Self {
            count: s.count,
            up: s.up,
            ..self
        }
    }
}

/// The mutable part of a [`Debouncer`]: the count and whether it is raised (its limits are
/// in the detector's parameters).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct DebouncerState {
    count: u32,
    up: bool,
}

impl DebouncerState {
    /// The status this state means (as [`Debouncer::status`]).
    #[inline(always)]
    pub(crate) fn status(&self) -> LockStatus {
        Debouncer::new(0, 1).with_state(*self).status()
    }
}

/// Samples in `time` s at period `ts`, saturating (longer than 2^32 samples, 5 days at 10 kHz,
/// is "never"); errors name `field`.
pub(crate) fn samples<T: Real>(field: &'static str, time: T, ts: T) -> Result<u32, ConfigError> {
    let time = check::non_negative(field, time)?;
    Ok((time / ts).round().to_f64().min(u32::MAX as f64) as u32)
}

/// A hand-over count below this is 0 (symptom 3; see [`LockDetectorParams::next_state`]).
const HANDOVER_FLOOR: f64 = 1e-6;

/// Configuration of a [`LockDetector`]: plain numbers, which the estimator derives from its
/// loss-of-lock tuning.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LockDetectorConfig<T> {
    /// Period at which the detector judges a sample, s: the sampling period, or N·Ts when
    /// the estimator runs it once every N samples (each verdict then stands for N·Ts of
    /// symptomatic or clean time).
    pub ts: T,
    /// |λ̂r| below this multiple of λ̂f is suspicious while |ω̂| is below `fast_speed`.
    pub flux_low_ratio: T,
    /// |λ̂r| below this multiple of λ̂f is suspicious while |ω̂| is at or above `fast_speed`.
    pub flux_low_fast_ratio: T,
    /// Speed (rad/s, electrical) from which `flux_low_fast_ratio` applies instead of
    /// `flux_low_ratio`; the estimator passes the lower edge of its mode hand-over band.
    pub fast_speed: T,
    /// |λ̂r| above this multiple of λ̂f is suspicious; 0 switches this half of the test off.
    pub flux_high_ratio: T,
    /// |θm − θ̂⁻| above this (rad) is suspicious.
    pub innovation_limit: T,
    /// Net suspicious time (s) after which the rotor is lost; 0 disables the detector.
    pub detection_time: T,
    /// Net clean time (s) after which a lost status clears.
    pub heal_time: T,
    /// In limiter mode, a sample in which the limiter clamps (|λ̂r| beyond its circle) is
    /// suspicious.
    pub limiter_clamping: bool,
    /// A hand-over rate (the leaky count of symptom 3) at or above this many hand-overs is
    /// suspicious; 0 switches the symptom off.
    pub handover_count: T,
    /// Time constant of the hand-over count's decay, s (longer than `ts`).
    pub handover_time: T,
}

/// The detector's constants, precomputed once from a [`LockDetectorConfig`] (the immutable
/// half of [`LockDetector`]; its state is the debouncer's count and flag).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LockDetectorParams<T> {
    low_sq: T,
    low_fast_sq: T,
    fast_speed: T,
    high_sq: T,
    innovation_limit: T,
    /// The debouncer's limits, with its state cleared.
    counter: Debouncer,
    clamping: bool,
    /// 1 − ts/`handover_time`: the hand-over count's decay per judged sample.
    handover_keep: T,
    /// The hand-over count that is suspicious (+∞ when off).
    handover_limit: T,
}

/// The detector's state: the debouncer and the hand-over count (symptom 3). The estimator
/// keeps it in its state; [`LockDetector`] around its constants.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LockState<T> {
    counter: DebouncerState,
    handovers: T,
}

impl<T: Real> LockState<T> {
    /// The status this state means.
    #[inline(always)]
    pub fn status(&self) -> LockStatus {
        self.counter.status()
    }

    /// The hand-over count (symptom 3): hand-overs, decaying with `handover_time`.
    pub fn handovers(&self) -> T {
        self.handovers
    }
}

impl<T: Real> LockDetectorParams<T> {
    /// Checks and precomputes (squared ratios, the sample counts); errors name the tuning
    /// field the estimator derives the bad value from (`lock_*`).
    pub(crate) fn new(c: LockDetectorConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", c.ts)?;
        let low = check::non_negative("lock_flux_low_ratio", c.flux_low_ratio)?;
        let high = check::non_negative("lock_flux_high_ratio", c.flux_high_ratio)?;
        check::below("lock_flux_low_ratio", low, T::one(), "below 1")?;
        let low_fast = check::non_negative("lock_flux_low_fast_ratio", c.flux_low_fast_ratio)?;
        check::below("lock_flux_low_fast_ratio", low_fast, T::one(), "below 1")?;
        let fast_speed = check::non_negative("mode_threshold_ratio", c.fast_speed)?;
        // 0 = off: an infinite bound that no |λ̂r| exceeds (the compare stays, no branch).
        let high_sq = if high == T::zero() {
            T::lit(f64::INFINITY)
        } else {
            check::below(
                "lock_flux_high_ratio",
                T::one(),
                high,
                "above 1, or 0 (off)",
            )?;
            high * high
        };
        let innovation = check::positive("lock_innovation_limit", c.innovation_limit)?;
        let limit = samples("lock_detection_time", c.detection_time, ts)?;
        let heal = samples("lock_heal_time", c.heal_time, ts)?;
        let handover_count = check::non_negative("lock_handover_count", c.handover_count)?;
        let handover_time = check::positive("lock_handover_time", c.handover_time)?;
        // Forward Euler needs ts < τ for a pole in (0, 1); any useful τ is hundreds of ts.
        check::below(
            "lock_handover_time",
            ts,
            handover_time,
            "longer than the detector's period (the estimator's is 4 sampling periods)",
        )?;
        Ok(Self {
            low_sq: low * low,
            low_fast_sq: low_fast * low_fast,
            fast_speed,
            high_sq,
            innovation_limit: innovation,
            counter: Debouncer::new(limit, heal),
            clamping: c.limiter_clamping,
            handover_keep: T::one() - ts / handover_time,
            handover_limit: if handover_count == T::zero() {
                T::lit(f64::INFINITY)
            } else {
                handover_count
            },
        })
    }

    /// The state after one sample `s`: `lambda_r_sq` = |λ̂r|², `flux_sq` = λ̂f²,
    /// `innovation` = wrap(θm − θ̂⁻) (0 when the trackers coasted), `omega` = ω̂ (rad/s,
    /// electrical; it picks the lower flux bound), `clamping` = the limiter clamped this
    /// sample, `handover` = the mode changed since the last judged sample. Five
    /// multiplications, seven compares.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn next_state(
        &self,
        s: LockState<T>,
        lambda_r_sq: T,
        flux_sq: T,
        innovation: T,
        omega: T,
        clamping: bool,
        handover: bool,
    ) -> LockState<T> {
        let low_sq = if omega.abs() < self.fast_speed {
            self.low_sq
        } else {
            self.low_fast_sq
        };
        // Below 1e-6 hand-overs the count is 0: the decay alone would take it into the
        // subnormal range and hold it at the smallest subnormal for ever (0.996 times it
        // rounds back to it), and a multiplication by a subnormal is a microcode assist on
        // x86 (it cost 5 % of the whole step there, docs/method/lock.md).
        let decayed = s.handovers * self.handover_keep;
        let decayed = if decayed < T::lit(HANDOVER_FLOOR) {
            T::zero()
        } else {
            decayed
        };
        let handovers = if handover {
            decayed + T::one()
        } else {
            decayed
        };
        let suspicious = (lambda_r_sq < low_sq * flux_sq)
            | (lambda_r_sq > self.high_sq * flux_sq)
            | (innovation.abs() > self.innovation_limit)
            | (clamping & self.clamping)
            | (handovers >= self.handover_limit);
        LockState {
            counter: self
                .counter
                .with_state(s.counter)
                .next(suspicious)
                .counter_state(),
            handovers,
        }
    }
}

/// The loss-of-lock state machine (see the module docs): its constants and its state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LockDetector<T> {
    params: LockDetectorParams<T>,
    state: LockState<T>,
}

impl<T: Real> LockDetector<T> {
    /// Checks and precomputes (squared ratios, the sample counts); errors name the tuning
    /// field the estimator derives the bad value from (`lock_*`).
    pub fn new(c: LockDetectorConfig<T>) -> Result<Self, ConfigError> {
        Ok(Self {
            params: LockDetectorParams::new(c)?,
            state: LockState::default(),
        })
    }

    /// Back to [`LockStatus::Locked`], no hand-overs counted.
    pub fn reset(&mut self) {
        self.state = LockState::default();
    }

    /// The state after one sample, without changing `self`: `lambda_r_sq` = |λ̂r|²,
    /// `flux_sq` = λ̂f², `innovation` = wrap(θm − θ̂⁻) (0 when the trackers coasted),
    /// `omega` = ω̂ (rad/s, electrical), `clamping` = the limiter clamped this sample,
    /// `handover` = the mode changed since the last judged sample. Five multiplications,
    /// seven compares.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn next_state(
        &self,
        lambda_r_sq: T,
        flux_sq: T,
        innovation: T,
        omega: T,
        clamping: bool,
        handover: bool,
    ) -> LockState<T> {
        self.params.next_state(
            self.state,
            lambda_r_sq,
            flux_sq,
            innovation,
            omega,
            clamping,
            handover,
        )
    }

    /// Takes a state computed by [`Self::next_state`].
    #[inline]
    pub fn commit(&mut self, state: LockState<T>) {
        self.state = state;
    }

    /// The committed state, as [`Self::next_state`] returns it (for a sample the detector
    /// does not judge).
    #[inline]
    pub fn state(&self) -> LockState<T> {
        self.state
    }

    /// The status after the last committed sample.
    pub fn status(&self) -> LockStatus {
        self.state().status()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn detector_config(time: f64) -> LockDetectorConfig<f64> {
        LockDetectorConfig {
            ts: 1e-4,
            flux_low_ratio: 0.5,
            flux_low_fast_ratio: 0.5,
            fast_speed: 10.0,
            flux_high_ratio: 1.3,
            innovation_limit: 0.5,
            detection_time: time,
            heal_time: 2e-3,
            limiter_clamping: true,
            handover_count: 0.0,
            handover_time: 0.1,
        }
    }

    fn detector(time: f64) -> LockDetector<f64> {
        LockDetector::new(detector_config(time)).unwrap()
    }

    fn step(d: &mut LockDetector<f64>, ratio: f64, innovation: f64) -> LockStatus {
        step_at(d, ratio, innovation, 0.0)
    }

    fn step_at(d: &mut LockDetector<f64>, ratio: f64, innovation: f64, omega: f64) -> LockStatus {
        let s = d.next_state(ratio * ratio, 1.0, innovation, omega, false, false);
        d.commit(s);
        d.status()
    }

    #[test]
    fn debounces_then_heals() {
        let mut d = detector(10e-3); // 100 samples to raise, 20 to heal
        // Alternating symptoms never accumulate.
        for k in 0..10_000 {
            let r = if k % 2 == 0 { 1.4 } else { 1.0 };
            assert_ne!(step(&mut d, r, 0.0), LockStatus::Lost);
        }
        assert_eq!(step(&mut d, 1.0, 0.0), LockStatus::Locked);
        for k in 1..100 {
            assert_eq!(step(&mut d, 0.3, 0.0), LockStatus::Suspect, "{k}");
        }
        assert_eq!(step(&mut d, 1.0, 1.0), LockStatus::Lost); // innovation counts too
        // However long the symptom lasted, a net 20 clean samples clear the status (the
        // counter saturates at the healing threshold)…
        for _ in 0..1000 {
            assert_eq!(step(&mut d, 0.3, 0.0), LockStatus::Lost);
        }
        for k in 1..20 {
            assert_eq!(step(&mut d, 1.0, 0.0), LockStatus::Lost, "{k}");
        }
        assert_eq!(step(&mut d, 1.0, 0.0), LockStatus::Locked);
        // …and a later loss raises it anew after the full detection time.
        for k in 1..100 {
            assert_eq!(step(&mut d, 0.3, 0.0), LockStatus::Suspect, "{k}");
        }
        assert_eq!(step(&mut d, 0.3, 0.0), LockStatus::Lost);
        // Intermittent symptoms while lost keep it up (net count).
        for k in 0..1000 {
            let r = if k % 2 == 0 { 0.3 } else { 1.0 };
            assert_eq!(step(&mut d, r, 0.0), LockStatus::Lost);
        }
        d.reset();
        assert_eq!(d.status(), LockStatus::Locked);
        // Each symptom alone, and NaN is never "locked" evidence against a symptom.
        let mut d = detector(1e-4);
        assert_eq!(step(&mut d, 1.31, 0.0), LockStatus::Lost);
        let mut d = detector(1e-4);
        assert_eq!(step(&mut d, 0.49, 0.0), LockStatus::Lost);
        let mut d = detector(1e-4);
        assert_eq!(step(&mut d, 1.0, -0.51), LockStatus::Lost);
        let mut d = detector(0.0);
        assert_eq!(step(&mut d, 0.0, 3.0), LockStatus::Locked); // disabled
        // The high half of the flux test off (0): only the low half and the innovation.
        let mut d = LockDetector::new(LockDetectorConfig {
            flux_high_ratio: 0.0,
            ..detector_config(1e-4)
        })
        .unwrap();
        assert_eq!(step(&mut d, 100.0, 0.0), LockStatus::Locked);
        assert_eq!(step(&mut d, 0.49, 0.0), LockStatus::Lost);
    }

    #[test]
    fn the_lower_flux_bound_depends_on_the_speed() {
        // 0.7 below |ω̂| = 10 rad/s, 0.6 from there on (either sign of ω̂).
        let c = LockDetectorConfig {
            flux_low_ratio: 0.7,
            flux_low_fast_ratio: 0.6,
            ..detector_config(1e-4)
        };
        let slow = [0.0, 9.99, -9.99];
        let fast = [10.0, -10.0, 1e4];
        let cases = [
            (slow, 0.65, LockStatus::Lost),
            (slow, 0.71, LockStatus::Locked),
            (fast, 0.65, LockStatus::Locked),
            (fast, 0.59, LockStatus::Lost),
        ];
        for (speeds, flux, status) in cases {
            for omega in speeds {
                let mut d = LockDetector::new(c).unwrap();
                assert_eq!(step_at(&mut d, flux, 0.0, omega), status, "{omega} {flux}");
            }
        }
        // A NaN speed takes the fast bound (the estimator refuses such a sample anyway).
        let mut d = LockDetector::new(c).unwrap();
        assert_eq!(step_at(&mut d, 0.59, 0.0, f64::NAN), LockStatus::Lost);
    }

    #[test]
    fn debouncer_heal_zero_clears_at_the_first_clean_sample() {
        let mut b = Debouncer::new(3, 0);
        assert!(!b.step(true) && !b.step(true) && b.step(true));
        assert!(b.step(true));
        assert!(!b.step(false));
        assert!(!Debouncer::new(0, 5).step(true));
    }

    #[test]
    fn errors_name_the_estimator_field() {
        let c = LockDetectorConfig {
            ts: 1e-4,
            flux_low_ratio: 0.5,
            flux_low_fast_ratio: 0.5,
            fast_speed: 10.0,
            flux_high_ratio: 1.3,
            innovation_limit: 0.5,
            detection_time: 0.01,
            heal_time: 0.1,
            limiter_clamping: true,
            handover_count: 4.0,
            handover_time: 0.1,
        };
        let e = |c| LockDetector::<f64>::new(c).unwrap_err().field();
        assert_eq!(
            e(LockDetectorConfig {
                flux_low_ratio: 1.0,
                ..c
            }),
            "lock_flux_low_ratio"
        );
        assert_eq!(
            e(LockDetectorConfig {
                flux_low_fast_ratio: -0.1,
                ..c
            }),
            "lock_flux_low_fast_ratio"
        );
        assert_eq!(
            e(LockDetectorConfig {
                flux_high_ratio: 0.9,
                ..c
            }),
            "lock_flux_high_ratio"
        );
        assert_eq!(
            e(LockDetectorConfig {
                innovation_limit: f64::NAN,
                ..c
            }),
            "lock_innovation_limit"
        );
        assert_eq!(
            e(LockDetectorConfig {
                detection_time: -1.0,
                ..c
            }),
            "lock_detection_time"
        );
        assert_eq!(
            e(LockDetectorConfig {
                heal_time: f64::NAN,
                ..c
            }),
            "lock_heal_time"
        );
        assert_eq!(
            e(LockDetectorConfig {
                handover_count: -1.0,
                ..c
            }),
            "lock_handover_count"
        );
        assert_eq!(
            e(LockDetectorConfig {
                handover_time: 1e-4,
                ..c
            }),
            "lock_handover_time"
        );
    }

    /// The detector judging every 0.4 ms (the estimator's period at 10 kHz) with the hand-over
    /// count at its defaults (5 per 0.1 s); the flux and innovation symptoms never fire on the
    /// inputs of the test below.
    fn chatter_config<T: Real>() -> LockDetectorConfig<T> {
        LockDetectorConfig {
            ts: T::lit(4e-4),
            flux_low_ratio: T::lit(0.5),
            flux_low_fast_ratio: T::lit(0.5),
            fast_speed: T::lit(10.0),
            flux_high_ratio: T::lit(1.3),
            innovation_limit: T::lit(0.5),
            detection_time: T::lit(2e-3),
            heal_time: T::lit(0.1),
            limiter_clamping: false,
            handover_count: T::lit(5.0),
            handover_time: T::lit(0.1),
        }
    }

    /// Symptom 3: the leaky hand-over count. At a steady rate r it settles at r·τ (so the
    /// limit N is a rate N/τ), a burst of k hand-overs counts k, and it decays with τ.
    #[test]
    fn handover_chatter_is_a_rate_with_its_time_constant() {
        let ts = 4e-4;
        let c = chatter_config::<f64>();
        let run = |period: usize, samples: usize| {
            let mut d = LockDetector::new(c).unwrap();
            let mut lost_at = None;
            for k in 0..samples {
                let s = d.next_state(1.0, 1.0, 0.0, 0.0, false, k % period == period - 1);
                d.commit(s);
                if lost_at.is_none() && d.status() == LockStatus::Lost {
                    lost_at = Some(k);
                }
            }
            (d.state().handovers(), lost_at)
        };
        // 40 hand-overs a second (one every 62 judged samples): r·τ ≈ 4, between 3.5 and 4.5
        // over a period, < 5.
        let (level, lost) = run(62, 5000);
        assert!((3.0..4.6).contains(&level), "{level}");
        assert_eq!(lost, None);
        // 62.5 a second (every 40 judged samples): r·τ ≈ 6.25, 5.75–6.75 over a period, raised
        // once the count stays above 5 (after about nine hand-overs) and the detection time.
        let (level, lost) = run(40, 5000);
        assert!((5.5..7.0).contains(&level), "{level}");
        let lost = lost.unwrap() as f64 * ts;
        assert!((0.05..0.3).contains(&lost), "{lost}");
        // Off (count 0): never.
        let mut d = LockDetector::new(LockDetectorConfig {
            handover_count: 0.0,
            ..c
        })
        .unwrap();
        for _ in 0..5000 {
            let s = d.next_state(1.0, 1.0, 0.0, 0.0, false, true);
            d.commit(s);
        }
        assert_eq!(d.status(), LockStatus::Locked);
        // The decay: one hand-over is 1, τ later e^{-1} within the Euler error.
        let mut d = LockDetector::new(c).unwrap();
        let s = d.next_state(1.0, 1.0, 0.0, 0.0, false, true);
        d.commit(s);
        assert_eq!(d.state().handovers(), 1.0);
        for _ in 0..250 {
            let s = d.next_state(1.0, 1.0, 0.0, 0.0, false, false);
            d.commit(s);
        }
        let h = d.state().handovers();
        assert!((h - (-1.0f64).exp()).abs() < 2e-3, "{h}");
        // Quiet for long, it is exactly 0, not a subnormal that the decay would hold (in
        // f32 too: 0.996 times the smallest subnormal rounds back to it).
        for _ in 0..20_000 {
            let s = d.next_state(1.0, 1.0, 0.0, 0.0, false, false);
            d.commit(s);
        }
        assert_eq!(d.state().handovers(), 0.0);
        let mut d = LockDetector::new(chatter_config::<f32>()).unwrap();
        let s = d.next_state(1.0, 1.0, 0.0, 0.0, false, true);
        d.commit(s);
        for _ in 0..40_000 {
            let s = d.next_state(1.0, 1.0, 0.0, 0.0, false, false);
            d.commit(s);
            assert!(d.state().handovers().is_normal() || d.state().handovers() == 0.0);
        }
        assert_eq!(d.state().handovers(), 0.0);
    }
}
