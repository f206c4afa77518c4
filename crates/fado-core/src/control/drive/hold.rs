//! The speed loop's torque demand, or the release hold's (see
//! [`release_hold`](crate::control::release_hold)).

use super::SensorlessDrive;
use crate::control::release_hold::HoldAction;
use crate::estimator::{Estimate, RotorAngleEstimator};
use crate::{Dq, Real};

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// The torque demand (A of magnet q current) of this sample: the speed PI's, or while the
    /// release hold acts, the hold's; the speed PI starts from the hold's torque when it
    /// hands over. None when the speed PI rejects its inputs.
    #[inline(always)]
    pub(super) fn speed_or_hold(&mut self, speed_ref: T, estimate: &Estimate<T>) -> Option<T> {
        let direct = estimate.diagnostics.theta_direct;
        let hold = self.blocks.hold.step(speed_ref, estimate.theta, direct);
        if let HoldAction::Handover(iq) = hold {
            self.blocks.speed.preset(iq);
        }
        // After a hold the start-up's motion test engaged, the reference resumes from zero.
        let speed_ref = self.blocks.hold.resumed(speed_ref);
        let iq = self
            .blocks
            .speed
            .step(speed_ref, estimate.omega_control)
            .ok()?;
        Some(match hold {
            HoldAction::Hold(held) => held,
            _ => iq,
        })
    }

    /// `i` with its d current at least the release's floor from the application's brake
    /// opening ([`arm_release_hold`](Self::arm_release_hold)) until the rotor moves (see
    /// [`release_current`](crate::control::release_current)): no phase current inside the
    /// dead-time band at θ̂ (`theta`) when the rotor starts to fall. Once the hold acts, its
    /// q current takes the phases out of the band and its loop is the one designed (a d
    /// current would add an alignment torque that goes at the hand-over).
    #[inline(always)]
    pub(super) fn release_current_floor(&self, i: Dq<T>, theta: T, vdc: T) -> Dq<T> {
        if !self.blocks.hold.awaiting_fall() {
            return i;
        }
        match self
            .blocks
            .phase_band
            .release_current()
            .d_current(theta, vdc)
        {
            Some(floor) => Dq::new(i.d.step_max(floor), i.q),
            None => i,
        }
    }

    /// (Re)arms the release hold at the present θ̂: the application calls it when its brake
    /// releases later than the start-up's end (a hoist opens its brake just before the lift).
    /// The loaded-standstill probe then arms after one period instead of its arming time
    /// ([`StandstillProbe::arm_at_release`](crate::control::StandstillProbe::arm_at_release)).
    pub fn arm_release_hold(&mut self) {
        // The loaded standstill that follows: the angle probe arms after one period.
        self.blocks.probe.arm_at_release();
        let theta = self.last.estimate.theta;
        self.blocks.hold.arm_at_release(theta);
    }

    /// Times the release hold acted since the drive was built (see
    /// [`release_hold`](crate::control::release_hold)).
    pub fn release_holds(&self) -> u32 {
        self.blocks.hold.engaged()
    }
}
