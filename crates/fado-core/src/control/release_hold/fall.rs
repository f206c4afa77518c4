//! The load a rotor's fall from a brake's release reveals, and the share of it the hold's
//! integral starts from where its stiffness is capped.
//!
//! # Why
//! The hold's loop is a triple pole at ω_h designed so that the rated load moves the rotor by
//! its design travel, ω_d = √(0.27·a_rated/travel). The current loop (ω_h ≤ ωc/10, ωc·Ts at
//! most 0.2) and the sampling (ω_h ≤ 0.1/Ts) cap it: a rotor whose rated load accelerates it
//! faster than its sampling can follow then runs back by 0.27·a/ω_h², (ω_d/ω_h)² times the
//! design. The Estun EMJ-04 400 W servo's bare rotor (3.1e-5 kg·m², 8 poles, rated torque to
//! rated speed in 7.7 ms) sampled at 10 kHz has ω_d = 470 rad/s and, with its current loop at
//! ωc·Ts = 0.2, ω_h = 200 rad/s (350 at the cap [`MAX_CURRENT_WC_TS`](super::MAX_CURRENT_WC_TS)): its
//! integral builds the rated load's 3.4 A over 2.5 ms while the rotor falls at 1.6·10⁵ rad/s²
//! (electrical), −637 r/min and 1.28 rad back (`loaded-start` seed 1,
//! `crates/fado-sim/tests/unseen_motor_tables.rs`).
//!
//! # The rule
//! A drive with a holding brake knows when it opens; from there the rotor, at rest, falls
//! under the load alone (the drive's q current is zero), at a = b·i_L (b = 1.5·p²·λ̂f/Ĵ):
//! after t it has travelled a·t²/2. The capped hold watches the direct angle for its trigger,
//! as on a saturating model (the tracked angle lags the fall by a sample or more: on the
//! servo it had moved 0.024 rad of a 0.058 rad fall when it triggered). At the trigger it
//! reads the load from the direct angle's travel e and the time since the release,
//! i_L = 2·e/(b·t²), and starts its integral
//! from the share 1 − (ω_h/ω_d)² of it, at most that share of the rated load: the loop takes
//! the rest, (ω_h/ω_d)² of the load, within its design travel. Where nothing caps ω_h the
//! share is zero and the hold is the designed loop. The angles lag the rotor: the read load
//! is a lower bound of the true one, never a torque the load has not shown. The lag is small
//! only once the release's d-current floor keeps every phase out of the inverter's dead-time
//! band: the servo's rotor falls by the trigger's 0.02 rad within 0.6 ms of the release,
//! before the current loop (1/ωc = 0.5 ms) raises a floor put on at the opening, and at seed
//! 2 (θ̂ at −1.66 rad, phase a across it at 0.05 A) the direct angle triggered at 0.8 ms,
//! having moved 0.022 rad of a 0.045 rad fall, and the load read 1.37 A of 3.4 A; the drive
//! puts the floor on while the brake still holds such a rotor
//! (`SensorlessDrive::arm_release_hold`), and the load then reads 2.62 A. A direct angle
//! that moves against the tracked one at the trigger is the
//! currents' transient, not a fall, and gives no preset (the saturated PM-SyRM
//! `motors/saturated/pmsyrm-baldor-5k6-measured.toml` at `loaded-start` seed 3: a preset
//! from it sent the full opposite torque and lost the rotor).
//!
//! Real drives with a holding brake energise the motor before they open it and hold with a
//! position loop sampled fast enough for their rotor (a servo's encoder loop at kHz), or
//! start from a stored or weighed load torque (a hoist's "torque memory", an elevator's
//! load-weighing pre-torque); a sensorless drive at its first start has neither, and the
//! fall itself is its measurement of the load.
//!
//! # Measured
//! `loaded-start` backward travel (rad, `python3 scripts/startup-table.py`, seeds 1–4; without
//! the rule in brackets): the Estun servo with its current loop at ωc·Ts = 0.2 0.447 / 0.458 /
//! 0.451 / 0.440 (1.28 at seed 1), its |θ − θ̂| from ready 0.051 / 0.063 / 0.074 / 0.053, at
//! the cap of 0.35 0.255 / 0.312 / 0.261 / 0.259 and 0.064 / 0.067 / 0.069 / 0.064; the made-up 750 W servo
//! (`crates/fado-sim/tests/data/startup-spm-750w.toml`) 0.22 / 0.22 / 0.23 / 0.22 (0.38 / 0.46
//! / 0.39 / 0.38); the MAD 5010 kv200 0.22 / 0.21 / 0.26 / 0.23 (0.41 / 0.39 / 0.48 / 0.41);
//! the multirotor preset 0.18 / 0.20 / 0.22 / 0.18 (0.21 / 0.20 / 0.23 / 0.22); the 36 V tool
//! motor at seeds 1 / 2 0.21 / 0.28, |θ − θ̂| from ready 0.112 / 0.128 rad (0.137 / 0.2516).
//! Every other preset, made-up and datasheet machine of the table is uncapped and unchanged.
//! With the preset but the trigger on the tracked angle the servo ran back 0.49 / 0.88 / 0.53
//! / 0.48 rad.

use crate::Real;

/// The held angle's error, a share of the design travel, beyond which a softened hold's
/// damping stiffens again ([`Softening`], "The fall that reads low"): 0.5 \[A\]. Its K_d
/// takes the share k·|e|_max/(0.5·travel) of the capped loop's, at most all of it. Measured
/// (`loaded-start` rated load, backward travel / max |θ − θ̂| from ready, rad): from 0.75·travel
/// the drawn 127 W IPMSM's seed 2 runs 0.500 rad back, from 0.5·travel 0.498; the traction
/// IPMSM's seed 2 0.462 / 0.202 and 0.473 / 0.152. A linear salient model's softened hold
/// (`release_hold/dead_time.rs`) keeps the fall's damping: stiffened, its D path turns the
/// direct angle's jumps at the phase currents' zero crossings back into the ringing, and the
/// 50 kW IPMSM under a tenth of its rated torque loses seeds 3 and 4 (|θ − θ̂| from ready
/// 2.82 / 2.75 rad; 0.073 / 0.078 with the fall's damping).
const STIFFEN_ONSET_RATIO: f64 = 0.5;

/// The share of a load the hold armed at a brake's release takes from the fall's start
/// rather than through its loop: 1 − (ω_h/ω_d)² for the loop's capped stiffness `omega` and
/// its design's `design`, in [0, 1] (0 where nothing caps it or the inputs are not finite).
pub(super) fn fall_share<T: Real>(omega: T, design: T) -> T {
    let ratio = omega / design;
    let share = T::one() - ratio * ratio;
    // NaN compares false: no share.
    if share > T::zero() && share <= T::one() {
        share
    } else {
        T::zero()
    }
}

/// The integral's start (A of magnet q current) at the trigger: the direct angle's travel
/// `e` (θ_hold − θ) in the time `t` since the release as a constant acceleration, 2·e/t²,
/// times `gain` (the share over b), within ±`lim`. Zero where the tracked angle's travel
/// `tracked` (θ_hold − θ̂) runs the other way, or the inputs give no finite load.
pub(super) fn fall_load<T: Real>(e: T, tracked: T, t: T, gain: T, lim: T) -> T {
    let load = T::lit(2.0) * e * gain / (t * t);
    // NaN compares false: no preset.
    if e * tracked >= T::zero() && load.is_finite() {
        crate::control::pi::clamp(load, -lim, lim)
    } else {
        T::zero()
    }
}

/// The hold's stiffness for the load the fall reveals, armed at a brake's release on a
/// saturating machine model or where the current loop or the sampling caps the loop (both
/// watch the direct angle, from which the fall is read). The rotor, at rest at the release, falls by e in t: an
/// acceleration a = 2·e/t². A loop of ω_h·√(a/a_rated) moves it by the design travel under
/// that load (0.27·a/ω², module docs of the hold), at most the capped ω_h and at least
/// 1/[`RELEASE_WINDOW_RATIO`](super::RELEASE_WINDOW_RATIO) of the design's (the slowest fall
/// the release's window takes); it settles in 10 of its own time constants.
///
/// # Why
/// The loop holds the direct angle, which on a saturating model moves with the current as
/// well as with the rotor (`crate::active_flux`, "The frame coupling"). At the rated load's
/// stiffness a light load's hold swings the q current through zero, and from there the
/// direct angle's motion with the current feeds the loop: on the saturated traction IPMSM
/// (`crates/fado-sim/tests/data/traction-ipm-saturated.toml`) at a quarter of its rated
/// torque the hold caught the fall at +128 A, the rotor rebounded at 15 r/min, the q
/// current ran to the −337 A limit within 4 ms while θ̂ moved 0.11 rad with the rotor still,
/// and the loop cycled between the limits (`loaded-start` seed 1: 0.72 rad back, |θ − θ̂|
/// 1.0 rad from ready; seeds 3 and 4 lost). The gains scale as k², k and k³ (k the
/// stiffness's share), so a quarter load's hold has a quarter of the rated one's
/// proportional gain.
///
/// A capped loop on a linear model meets the same cycle through the inverter instead: the
/// light rotor's hold at the rated stiffness swings its q current through zero, and at every
/// phase current's zero crossing the dead-time compensation's residual moves θ̂. On the
/// multirotor preset (`motors/multirotor-mn5006-22v.toml`, 8 µH, 40 kHz sampling) under a
/// quarter of its rated torque the hold cycled between its ±62 A limits at ≈ 25 Hz and
/// |θ − θ̂| from ready reached 0.44–0.95 rad at seeds 1–4; softened to the fall, 0.065–0.121.
/// On the capped machines of crates/fado-sim/tests (the multirotor preset, the Estun 400 W
/// servo, the made-up 750 W servo, the MAD 5010 kv200, the 36 V tool motor) at the rated
/// load, a quarter of it and none, seeds 1–4, 57 of the 60 starts pass softened and 50 at the
/// rated stiffness; the one it costs is the tool motor's unloaded seed 2, whose stiff hold
/// kept θ̂ from drifting at rest after the release (0.046 rad; softened 0.637).
/// Measured (`loaded-start`, a constant load from t = 0, backward travel / max |θ − θ̂| from
/// ready, rad) in crates/fado-sim/tests/light_load_start.rs.
///
/// # The fall that reads low
/// The direct angle can lag the falling rotor: where the start angle leaves a phase's
/// current inside the inverter's dead-time band it moves by about half the rotor's fall, and
/// the fall reads half the load. On the saturated traction IPMSM
/// (`crates/fado-sim/tests/data/traction-ipm-saturated.toml`, `loaded-start` seed 2) it had
/// moved 0.027 rad of the rotor's 0.062 rad 3.45 ms after the release, the hold triggered at
/// 1.85 times the rated load's time to the trigger and took the stiffness k ≈ 0.66 of the
/// capped loop's; on the drawn 127 W IPMSM (`crates/fado-sim/tests/data/drawn/`, seed 2)
/// 0.014 of 0.030 rad at 0.54 ms. A loop softened to the read load lets the true one move the
/// rotor past its design travel, and a held angle's error beyond [`STIFFEN_ONSET_RATIO`] of
/// that travel shows the load is heavier than read. The loop's damping K_d then stiffens with
/// the largest error so far, k·|e|_max/onset, up to the capped loop's; K_p and K_i stay at
/// the fall's stiffness. The damping acts on the speed alone: it brakes the fall and fades as
/// the rotor stops. Stiffening all three gains by √(|e|_max/travel) instead stops the traction
/// IPMSM's rotor 0.41 rad back, but its integral, wound up at the limit, keeps the 337 A
/// limit 6 ms past the stop, the rotor swings forward at 98 r/min and θ̂, which drifts from
/// the rotor at ≈ 0.03 rad/ms while that current flows, is lost. Measured (rated load,
/// backward travel / max |θ − θ̂| from ready, rad; the fall's stiffness alone in brackets): the
/// traction IPMSM seed 2 0.473 / 0.152 (0.540 / 0.196), the 127 W IPMSM seed 2 0.498 / 0.123
/// (0.584 / 0.126). Of the 148 `loaded-start` runs of the presets (`motors/`,
/// `motors/saturated/`) and the made-up and drawn machines of `crates/fado-sim/tests/data/`
/// at seeds 1–4 it changes 43, all on saturating models: the backward travel by −0.085 to
/// +0.003 rad (the drawn 6.8 kW IPMSM's seed 2 0.445 → 0.377), the max |θ − θ̂| from ready by
/// −0.044 to +0.027 rad (the drawn 192 kW IPMSM's seed 4 0.122 → 0.149); every run that
/// passed without it passes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Softening<T> {
    /// The rated load's electrical acceleration p·T_rated/Ĵ (rad/s²).
    a_rated: T,
    /// ω_h before the caps, for the design travel (rad/s).
    design: T,
    /// 10/ω_h in samples at the full stiffness.
    samples: u32,
    /// The stiffness's share of ω_h (1: the design's).
    k: T,
    /// The held angle's error beyond which a softened loop's damping stiffens again (rad):
    /// [`STIFFEN_ONSET_RATIO`] × the design travel.
    onset: T,
    /// The largest |error| of the held angle since the trigger (rad).
    peak: T,
    /// Armed at a brake's release on a linear model whose inverter error outruns it, the hold
    /// softens too
    /// ([`ReleaseHold::set_dead_time_voltage`](super::ReleaseHold::set_dead_time_voltage)).
    pub(super) linear: bool,
    /// A salient rotor's [`linear`](Self::linear) hold keeps the fall's damping at any error
    /// ([`STIFFEN_ONSET_RATIO`]).
    pub(super) keep_damping: bool,
    /// ω_h is the current loop's cap ωc/10 (`dead_time.rs`, "At the current loop's cap").
    pub(super) at_current_cap: bool,
}

impl<T: Real> Softening<T> {
    /// For the rated load's acceleration `a_rated` (electrical rad/s²), the design's ω_h
    /// `design`, the loop's ω_h·Ts `omega_ts`, the design travel `travel` (rad) and whether
    /// ω_h is the current loop's cap (`at_current_cap`).
    pub(super) fn new(a_rated: T, design: T, omega_ts: T, travel: T, at_current_cap: bool) -> Self {
        Self {
            a_rated,
            design,
            samples: (T::lit(super::SETTLE_TIMES) / omega_ts).round().to_f64() as u32,
            k: T::one(),
            linear: false,
            keep_damping: false,
            at_current_cap,
            onset: T::lit(STIFFEN_ONSET_RATIO) * travel,
            peak: T::zero(),
        }
    }

    /// Records the held angle's error `e` (rad) of a sample: its largest magnitude since the
    /// trigger stiffens a softened loop's damping ([`gains`](Self::gains)).
    pub(super) fn track(&mut self, e: T) {
        let a = e.abs();
        // NaN compares false: kept.
        if a > self.peak {
            self.peak = a;
        }
    }

    /// Back to the full stiffness; its settling time in samples.
    pub(super) fn reset(&mut self) -> u32 {
        self.k = T::one();
        self.peak = T::zero();
        self.samples
    }

    /// The stiffness for a fall of `fall` (rad) in `t` (s) from rest, the loop's ω_h
    /// `omega_h` (rad/s); the settling time in samples.
    pub(super) fn soften(&mut self, fall: T, t: T, omega_h: T) -> u32 {
        let accel = T::lit(2.0) * fall / (t * t);
        let k = self.design * (accel / self.a_rated).step_sqrt() / omega_h;
        let floor = T::one() / T::lit(super::RELEASE_WINDOW_RATIO);
        // NaN compares false: the full stiffness.
        if !(k.is_finite() && k < T::one()) {
            return self.samples;
        }
        self.k = if k > floor { k } else { floor };
        // k ∈ [floor, 1]: a finite count; one conversion instruction in the per-sample path.
        let n = (T::from_index(self.samples as usize) / self.k).round();
        n.index_floor(u32::MAX as usize) as u32
    }

    /// The loop's gains K_p, K_d and K_i·Ts at the stiffness (K_d stiffened by the largest
    /// error so far, [`track`](Self::track)).
    pub(super) fn gains(&self, kp: T, kd: T, ki_ts: T) -> (T, T, T) {
        let k = self.k;
        (kp * k * k, kd * self.damping(), ki_ts * k * k * k)
    }

    /// The damping's share of the capped loop's at the largest error so far: k, and once that
    /// error passes the onset k times its ratio to the onset, at most 1.
    fn damping(&self) -> T {
        let k = self.k;
        let r = self.peak / self.onset;
        // NaN compares false: the fall's. A linear salient model's hold keeps it: its D path
        // is what turns the direct angle's jumps at the currents' zero crossings into the
        // ringing its softening is there to avoid.
        if self.keep_damping || !(k < T::one() && r > T::one()) {
            return k;
        }
        (k * r).step_min(T::one())
    }
}
