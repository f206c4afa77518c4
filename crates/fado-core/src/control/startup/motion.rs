//! The start-up's motion monitor: how far the rotor has turned since a reference sample, from
//! the drive's own voltages and currents, while nothing else knows the angle.
//!
//! # Why
//! The offset calibration and the angle search assume a rotor at rest. A load present from
//! t = 0 without a brake (a vehicle on a slope, a compressor against pressure) turns a rotor
//! that no current holds; a search on a turning rotor reads its back-EMF as an inductance,
//! and offsets averaged over a short-circuit current are wrong. The drive has to notice the
//! motion before the rotor has moved measurably, and without knowing the angle.
//!
//! # The measure
//! The stator flux obeys dψ/dt = v − Rs·i, and ψ = L·i + λr with λr = λf·e^(jθ) the magnet's
//! flux. From a reference sample on,
//!
//! Δλr = Σ (v − R̂s·i)·Ts − L̂·(i − i₀),
//!
//! whatever the rotor's angle, and |Δλr| = 2·λf·sin(|Δθ|/2) ≈ λf·|Δθ|: the travel is
//! |Δλr|/λ̂f electrical rad. The voltage is the realised reference that acted over the
//! period: the drive reads it under the zero vector (the watched offset calibration, a
//! deferral), whose phases are shorted, so that a turning rotor drives a current that brakes
//! it and shows here. L̂ is the mean of L̂d and L̂q (its error, the saliency, multiplies the
//! small short-circuit current). The inverter's dead time, not compensated under the zero
//! vector, adds a voltage against the current that the monitor does not count: it reads less
//! than the true travel, the more so the smaller the machine's resistance against the dead
//! time's voltage (measured in `crates/fado-sim/tests/startup_motion.rs`: 0.17 rad true for
//! 0.05 read on the 2.2 kW IPMSM, 1.75 rad on the servo motor). The reference current is uncertain (the mean of a few
//! samples): the threshold grows with what that uncertainty integrates to through R̂s
//! ([`MotionMonitor::set_reference_error`]). A rotor stands still
//! ([`MotionMonitor::quiet`]) when the reading stays small and the shorted phases carry no
//! current above [`READ_CURRENT_RATIO`] of the rated current.
//!
//! Measured on the presets at rest (`loaded-start`, the brake holding the rotor; switching-
//! resolved inverter, default sensors): at most 0.036 rad read over the offsets (same test).

use crate::control::snapshot_window::SnapshotWindow;
use crate::{Ab, Real};

/// Largest short-circuit current of a rotor that stands still, a fraction of the rated
/// current \[A\]: ten times the sensors' resolution on the presets, below the current of a
/// rotor that turns at 1 % of its rated speed with its phases shorted.
pub const READ_CURRENT_RATIO: f64 = 0.1;

/// Low-pass time constant (s) of the derivative of Δλr ([`MotionMonitor::flux_rate`]) \[A\]:
/// the gain calibration's motion filter's (ten 10 kHz samples).
pub const RATE_FILTER_TIME: f64 = 1e-3;

/// The recent window of [`MotionMonitor::recent_travel`] (s) \[A\]: a rotor that a load
/// accelerates from rest has turned a·W²/2 in it, and the reference's drift adds only
/// R̂s·δ·W/λ̂f (on the 12S multirotor of `crates/fado-sim/tests/calibration_load_classes.rs`,
/// whose shorted phases' device slope makes the drift 5.3 rad/s: 0.02 rad in 4 ms, against
/// 0.27 rad over the first 50 ms of the offsets).
pub const RECENT_WINDOW_TIME: f64 = 4e-3;

/// Snapshots of Δλr over [`RECENT_WINDOW_TIME`]: the window read spans between 7/8 and all of
/// it.
const RECENT_SLOTS: usize = 8;

/// The motion monitor (module docs). Allocation-free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionMonitor<T> {
    rs: T,
    inductance: T,
    flux_linkage: T,
    ts: T,
    quiet_current: T,
    /// What the quiet current alone reads, L̂·I_quiet/λ̂f (rad; 0 without a magnet flux): the
    /// floor of [`Self::threshold`].
    travel_floor: T,
    /// R̂s·δ·Ts/λ̂f: the travel a reference current off by its own uncertainty δ (A) reads per
    /// sample ([`set_reference_error`](Self::set_reference_error)); 0 without a magnet flux.
    drift_per_sample: T,
    /// Samples since the reference sample.
    samples: T,
    /// Σ (v − R̂s·(i − i₀))·Ts since the reference sample (V·s).
    flux: Ab<T>,
    /// The reference current i₀ (A).
    reference: Ab<T>,
    /// The largest travel read since the reference sample (rad).
    travel: T,
    /// Δλr at the last sample (V·s) and its derivative low-passed over
    /// [`RATE_FILTER_TIME`] (V).
    delta: Ab<T>,
    rate: Ab<T>,
    /// A sample's |i − i₀| exceeded the quiet current since the reference sample.
    loud: bool,
    running: bool,
    /// Δλr over the recent window.
    recent: SnapshotWindow<Ab<T>, RECENT_SLOTS>,
    /// The largest travel read over the recent window, less its drift allowance (rad).
    recent_excess: T,
}

impl<T: Real> MotionMonitor<T> {
    /// The monitor for a machine model of R̂s, mean inductance `inductance`, λ̂f and rated
    /// current, sampled at `ts`; not running.
    pub fn new(rs: T, inductance: T, flux_linkage: T, rated_current: T, ts: T) -> Self {
        let quiet_current = T::lit(READ_CURRENT_RATIO) * rated_current;
        let travel_floor = if flux_linkage > T::zero() {
            quiet_current * inductance / flux_linkage
        } else {
            T::zero()
        };
        Self {
            rs,
            inductance,
            flux_linkage,
            ts,
            quiet_current,
            travel_floor,
            drift_per_sample: T::zero(),
            samples: T::zero(),
            flux: Ab::zero(),
            reference: Ab::zero(),
            travel: T::zero(),
            delta: Ab::zero(),
            rate: Ab::zero(),
            loud: false,
            running: false,
            recent: SnapshotWindow::new(RECENT_WINDOW_TIME, ts, Ab::zero()),
            recent_excess: T::lit(-1.0),
        }
    }

    /// Starts from this sample with reference current `reference` (A).
    pub fn restart(&mut self, reference: Ab<T>) {
        self.flux = Ab::zero();
        self.samples = T::zero();
        self.reference = reference;
        self.travel = T::zero();
        self.delta = Ab::zero();
        self.rate = Ab::zero();
        self.loud = false;
        self.running = true;
        self.recent.reset();
        self.recent_excess = T::lit(-1.0);
    }

    /// The uncertainty δ (A, α-β magnitude) of the current the readings start from (the mean
    /// of the few samples the reference is taken over: the sensors' noise and resolution). A
    /// reference off by δ reads as a short-circuit current δ that flows on and integrates
    /// through R̂s to R̂s·δ·t/λ̂f (the travel a rotor creeping at R̂s·δ/λ̂f reads alike), which
    /// [`threshold`](Self::threshold) then adds. Kept over restarts (the deferral's windows
    /// read from the same offsets) until set again; a non-finite or negative δ counts as 0.
    pub fn set_reference_error(&mut self, delta: T) {
        let delta = if delta >= T::zero() && delta.is_finite() {
            delta
        } else {
            T::zero()
        };
        self.drift_per_sample = if self.flux_linkage > T::zero() {
            self.rs * delta * self.ts / self.flux_linkage
        } else {
            T::zero()
        };
    }

    /// Stops reading (the travel is kept).
    pub fn stop(&mut self) {
        self.running = false;
    }

    /// Running since the last [`restart`](Self::restart).
    pub fn running(&self) -> bool {
        self.running
    }

    /// One sample: `v_ab` the voltage that acted over the last period (V), `i_ab` the
    /// current now (A). Returns the largest travel read so far (electrical rad); a non-finite
    /// input is skipped.
    pub fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> T {
        if !self.running || !v_ab.is_finite() || !i_ab.is_finite() {
            return self.travel;
        }
        let di = i_ab - self.reference;
        self.samples += T::one();
        self.flux += (v_ab - di * self.rs) * self.ts;
        let small = di.norm() <= self.quiet_current;
        self.loud |= !small;
        if self.flux_linkage > T::zero() {
            let delta = self.flux - di * self.inductance;
            let a = self.ts / (T::lit(RATE_FILTER_TIME) + self.ts);
            self.rate += ((delta - self.delta) * (T::one() / self.ts) - self.rate) * a;
            self.delta = delta;
            let travel = delta.norm() / self.flux_linkage;
            if travel > self.travel {
                self.travel = travel;
            }
            self.step_recent(delta);
        }
        self.travel
    }

    /// The recent window's sample: the travel since the oldest snapshot less the drift the
    /// reference's error reads over the samples since it, and a new snapshot every
    /// `slot_samples`.
    fn step_recent(&mut self, delta: Ab<T>) {
        if let Some((oldest, span)) = self.recent.oldest() {
            let travel = (delta - oldest).norm() / self.flux_linkage;
            let excess = travel - self.drift_per_sample * T::lit(span as f64);
            if excess > self.recent_excess {
                self.recent_excess = excess;
            }
        }
        self.recent.push(delta);
    }

    /// The largest travel (electrical rad) read over a recent window of
    /// [`RECENT_WINDOW_TIME`] since the last restart, less the drift the reference's error
    /// reads over that window ([`set_reference_error`](Self::set_reference_error)); negative
    /// before two samples. [`threshold`](Self::threshold) lets the reference's drift grow with
    /// the time since the restart: a rotor that a load accelerates late in a long window
    /// turns far before its travel passes it (the 12S multirotor of
    /// `crates/fado-sim/tests/calibration_load_classes.rs`, half its rated torque 50 ms into
    /// the offsets: 0.34 rad), and over the recent window it reads its travel with a drift
    /// allowance of a few hundredths of a radian.
    pub fn recent_travel(&self) -> T {
        self.recent_excess
    }

    /// The rotor moved within a recent window: its travel over it, less that window's drift
    /// ([`recent_travel`](Self::recent_travel)), exceeds the threshold without drift (the
    /// tuning's `travel`, at least what the quiet current reads).
    pub fn moved_recently(&self, travel: T) -> bool {
        let base = if self.travel_floor > travel {
            self.travel_floor
        } else {
            travel
        };
        self.recent_excess > base
    }

    /// The travel (electrical rad) above which the rotor counts as moving, given the tuning's
    /// `travel`: at least what the quiet current alone reads, L̂·I_quiet/λ̂f. A current step
    /// that the monitor accepts as standing still ([`READ_CURRENT_RATIO`]) must not read as
    /// motion: on a low-inductance machine of small magnet flux (a 135 µH, 1.5 mWb multirotor
    /// motor: 0.106 rad) the sensors' noise alone reads past the default 0.05 rad.
    ///
    /// Plus the reference's drift R̂s·δ·t/λ̂f since the restart
    /// ([`set_reference_error`](Self::set_reference_error)): on a multirotor motor of 0.15 Ω
    /// and 2 mWb a reference off by 7 mA (ten samples of a 12-bit sensor) reads 0.054 rad in
    /// 0.1 s, and a rotor that a brake holds would defer its start-up for ever.
    pub fn threshold(&self, travel: T) -> T {
        // NaN compares false: the tuning's travel.
        let base = if self.travel_floor > travel {
            self.travel_floor
        } else {
            travel
        };
        base + self.drift_per_sample * self.samples
    }

    /// Δλr = Σ (v − R̂s·(i − i₀))·Ts − L̂·(i − i₀) at the last sample (V·s): the change of the
    /// rotor's flux vector since the reference sample (module docs). A drive that knows the
    /// angle θ₀ the rotor started from has it at arg(λ̂f·e^(jθ₀) + Δλr).
    pub fn flux_change(&self) -> Ab<T> {
        self.delta
    }

    /// dΔλr/dt low-passed over 1 ms (`RATE_FILTER_TIME`) (V): with the rotor's flux vector λr,
    /// its electrical speed is (λr × dλr/dt)/|λr|².
    pub fn flux_rate(&self) -> Ab<T> {
        self.rate
    }

    /// The largest travel read since the last restart (electrical rad).
    pub fn travel(&self) -> T {
        self.travel
    }

    /// Since the last restart the rotor has stood still: the travel read is at most `travel`
    /// and the current stayed small (under the zero vector a turning rotor drives one).
    pub fn quiet(&self, travel: T) -> bool {
        !self.loud && self.travel <= self.threshold(travel)
    }
}
