//! The speed loop's torque demand, or the release hold's (see
//! [`release_hold`](crate::control::release_hold)).

use super::SensorlessDrive;
use crate::Real;
use crate::control::release_hold::HoldAction;
use crate::estimator::{Estimate, RotorAngleEstimator};

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

    /// (Re)arms the release hold at the present θ̂: the application calls it when its brake
    /// releases later than the start-up's end (a hoist opens its brake just before the lift).
    /// The loaded-standstill probe then arms after one period instead of its arming time
    /// ([`StandstillProbe::arm_at_release`](crate::control::StandstillProbe::arm_at_release)).
    pub fn arm_release_hold(&mut self) {
        // The loaded standstill that follows: the angle probe arms after one period.
        self.blocks.probe.arm_at_release();
        let theta = self.last.estimate.theta;
        self.blocks.hold.arm(theta);
    }

    /// Times the release hold acted since the drive was built (see
    /// [`release_hold`](crate::control::release_hold)).
    pub fn release_holds(&self) -> u32 {
        self.blocks.hold.engaged()
    }
}
