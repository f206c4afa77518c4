//! The loaded standstill: the angle probe's d current and its corrections of the estimate
//! (see [`standstill_probe`](crate::control::standstill_probe)).

use super::SensorlessDrive;
use crate::control::lock_reaction::LockAction;
use crate::estimator::{Estimate, RotorAngleEstimator};
use crate::mode::Mode;
use crate::{Dq, Real};

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// The probe's Δi_d for this sample's d reference (A) from the torque demand `iq_torque`
    /// (A of magnet q current) at the limited speed reference `speed_ref`.
    #[inline(always)]
    pub(super) fn standstill_probe_current(
        &mut self,
        speed_ref: T,
        iq_torque: T,
        estimate: &Estimate<T>,
        action: LockAction,
    ) -> T {
        let probe = &mut self.blocks.probe;
        probe.leave_release(speed_ref);
        let gate = probe.gate(speed_ref, iq_torque, action == LockAction::Run);
        let m = &self.config.machine;
        let last = self.last.i_dq_ref;
        probe.step(
            gate,
            estimate.diagnostics.mode == Mode::Limiter,
            iq_torque,
            estimate.omega_control,
            (last.d, last.q),
            m.flux_linkage,
            m.ld - m.lq,
        )
    }

    /// The corrections of the estimate at a loaded standstill, after the sample's reference:
    /// the probe's turn of θ̂, and |λ̂r| held on the model's active flux at the last reference
    /// (the radial part of the integrand error, which the limiter's disc lets grow to its
    /// radius, would otherwise leave λ1 off-centre when the rotor leaves).
    #[inline(always)]
    pub(super) fn standstill_corrections(&mut self, action: LockAction) {
        if action == LockAction::Coast {
            self.blocks.probe.reset();
        }
        let turn = self.blocks.probe.rate();
        if turn != T::zero() {
            self.estimator.turn_angle(turn * self.config.ts);
        }
        if self.blocks.probe.active() {
            let flux = self.model_active_flux(self.last.i_dq_ref);
            self.estimator.hold_flux_magnitude(flux);
        }
    }

    /// |λa| of the drive's model at the current `i` of the estimated frame (Wb): the
    /// saturating model's torque flux, else λ̂f + (L̂d − L̂q)·i_d.
    fn model_active_flux(&self, i: Dq<T>) -> T {
        let m = &self.config.machine;
        match &self.resolved.saturated {
            Some(s) if i.q.abs() > T::zero() => s.torque_flux(i) / i.q,
            _ => m.active_flux(i.d),
        }
    }
}
