//! The hold's watch before it acts: the window it stays armed for, the fall that triggers it
//! (against a moving reference only a fall against the reference), and the start it takes
//! when triggered (its stiffness softened to the fall, a capped hold's integral from the load
//! the fall reveals).

use super::{ReleaseHold, fall};
use crate::Real;

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
        // A linear salient model's hold reads its stiffness from the direct angle's travel
        // (the tracked angle that triggers lags the fall).
        let soft_fall = if self.soft.linear { e.abs() } else { fall };
        self.soften(soft_fall);
        if self.released && self.fall_gain > T::zero() {
            let tracked = crate::wrap_angle(self.theta_hold - theta_tracked);
            let (gain, lim) = (self.fall_gain, self.max_fall_load);
            self.integral = fall::fall_load(e, tracked, self.fall_time, gain, lim);
        }
        // A fall against a moving reference is held as a motion the start-up saw: until
        // settled, then the reference resumes from zero.
        self.engaged_by_motion = sense != T::zero();
        self.engaged = self.engaged.saturating_add(1);
        true
    }
}
