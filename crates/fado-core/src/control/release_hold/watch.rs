//! The hold's watch before it acts: the window it stays armed for, the fall that triggers it
//! (against a moving reference only a fall against the reference), and the start it takes
//! when triggered (its stiffness softened to the fall, a capped hold's integral from the load
//! the fall reveals, or the speed loop's integral).
//!
//! # The torque the speed loop carries
//! Until the hold triggers the speed loop's torque is used, and on a heavy rotor whose fall
//! reaches the trigger late the speed loop already carries much of the load by then. Armed at
//! a brake's release on a saturating model, a hold that takes no preset from the fall starts
//! its integral from the speed loop's (where that acts against the fall): from zero it drops
//! the carried torque in a sample, and on a saturating model the direct angle it holds moves
//! with that current step. On the drawn 137 kW IPMSM (`crates/fado-sim/tests/data/drawn/`,
//! 2,650 kg·m², `loaded-start` seed 4) the direct angle reaches the trigger 29 ms after the
//! release, the speed loop then carrying 307 A against the rated load's ≈ 280 A; started from
//! zero the hold's demand fell to 14 A in a sample, the direct angle moved 0.08 rad forward
//! with the current while the rotor fell, and the hold sent −106 A for 70 ms: 0.708 rad back
//! (max |θ − θ̂| from ready 0.147 rad). From the speed loop's integral: 0.342 / 0.050 rad,
//! seed 3 0.282 / 0.082 (0.355 / 0.068). Of the 148 `loaded-start` runs of the presets and the
//! machines of `crates/fado-sim/tests/data/` at seeds 1–4 it changes 26, all on saturating
//! models: the backward travel by −0.365 (the seed 4 above) to +0.004 rad and the max
//! |θ − θ̂| from ready by −0.098 to +0.014 rad (the seed 3 above), apart from the drawn 192 kW
//! IPMSM's seed 2, which its speed loop loses either way (5.50 / 1.70 rad, 1.67 / 1.80).

use super::{ReleaseHold, fall};
use crate::{MachineModel, Real};

/// The time (s) within which a fall after a brake's release triggers the hold on `machine`:
/// [`RELEASE_WINDOW_RATIO`](super::RELEASE_WINDOW_RATIO)·√(2·trigger/a_rated), a_rated = p·T_rated/Ĵ (non-finite where the
/// model gives no rated torque; the tuning's window then holds).
pub(super) fn release_window<T: Real>(machine: &MachineModel<T>, trigger: T) -> T {
    let p = T::lit(machine.pole_pairs as f64);
    let accel = p * machine.rated_torque / machine.inertia;
    T::lit(super::RELEASE_WINDOW_RATIO) * (T::lit(2.0) * trigger / accel).step_sqrt()
}

impl<T: Real> ReleaseHold<T> {
    /// One sample of an armed hold that does not act yet: `sense` the reference's direction
    /// (zero at rest), `watched` the angle that triggers, `theta_tracked` the
    /// estimator's tracked angle, `e` the held angle's error. True when the hold
    /// triggers and acts from this sample; false while it watches or once its window ends
    /// (then disarmed).
    pub(super) fn watch(&mut self, sense: T, watched: T, theta_tracked: T, e: T) -> bool {
        self.elapsed = self.elapsed.saturating_add(1);
        // A saturating model watches within its own window.
        let window = if self.released && self.release_on_direct {
            self.release_window_samples
        } else {
            self.arm_window
        };
        if self.elapsed > window {
            self.disarm();
            return false;
        }
        let moved = crate::wrap_angle(self.theta_hold - watched);
        // NaN compares false: a non-finite angle does not trigger.
        // On a moving reference only a fall against it triggers (the rotor's lag behind
        // the reference's angle is the speed loop's to close).
        let fall = if sense == T::zero() {
            moved.abs()
        } else {
            moved * sense
        };
        self.fall_time += self.ts;
        let triggered = fall > self.trigger;
        if !triggered {
            return false;
        }
        self.active = true;
        // A linear model's hold softened for the inverter's error (`dead_time.rs`) reads its
        // stiffness from the direct angle's travel (the tracked angle that triggers lags the
        // fall).
        let soft_fall = if self.soft.linear { e.abs() } else { fall };
        self.soften(soft_fall);
        if self.released && self.fall_gain > T::zero() {
            let tracked = crate::wrap_angle(self.theta_hold - theta_tracked);
            let (gain, lim) = (self.fall_gain, self.max_fall_load);
            self.integral = fall::fall_load(e, tracked, self.fall_time, gain, lim);
        } else if self.released && self.release_on_direct && self.carried * e > T::zero() {
            // The speed loop's torque against the fall: the hold takes it over (module docs).
            let lim = self.i_max;
            self.integral = crate::control::pi::clamp(self.carried, -lim, lim);
        }
        // A fall against a moving reference is held as a motion the start-up saw: until
        // settled, then the reference resumes from zero.
        self.engaged_by_motion = sense != T::zero();
        self.engaged = self.engaged.saturating_add(1);
        true
    }

    /// Armed at a brake's release on a saturating model, where the current loop or the
    /// sampling caps the loop (it then watches the direct angle), or on a linear model whose
    /// inverter error turns the direct angle faster than the hold
    /// ([`set_dead_time_voltage`](Self::set_dead_time_voltage)), the stiffness for the load the
    /// fall of `fall` (rad, direct angle) since the release reveals ([`fall::Softening`]).
    fn soften(&mut self, fall: T) {
        if self.released
            && (self.release_on_direct || self.fall_gain > T::zero() || self.soft.linear)
        {
            self.hold_samples = self.soft.soften(fall, self.fall_time, self.stiffness());
        }
    }
}
