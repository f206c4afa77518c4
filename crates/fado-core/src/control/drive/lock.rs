//! The drive's reaction to a lost rotor (see `lock.reaction`): the stall symptom, the
//! supervisor's action and the reason the drive coasts.

use super::{DriveOutput, SensorlessDrive};
use crate::Real;
use crate::control::lock_reaction::{LockAction, LockReaction};
use crate::control::monitor::DriveFlags;
use crate::estimator::{Estimate, RotorAngleEstimator};
use crate::lock::LockStatus;
use crate::mode::Mode;

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// The lock supervisor's action for this sample (`Rearm` is done here and reported as
    /// `Coast`); a realignment ends the sample (`Err`).
    #[inline(always)]
    pub(super) fn react_to_lock(
        &mut self,
        estimate: &Estimate<T>,
        speed_ref: T,
    ) -> Result<LockAction, DriveOutput<T>> {
        let diag = &estimate.diagnostics;
        let stalled = self.stall_symptom(estimate, speed_ref);
        let estimate_lost = diag.lock == LockStatus::Lost;
        let lost = estimate_lost || (stalled && self.config.tuning.lock.reaction_on_stall);
        let healthy = diag.lock == LockStatus::Locked && diag.mode == Mode::DisturbanceFeedback;
        let action = self.lock.step(lost, healthy);
        if lost && self.config.tuning.lock.reaction == LockReaction::Adapt {
            self.estimator.enable_rs_adaptation();
        }
        match action {
            LockAction::Realign => {
                self.align(estimate.theta);
                self.last.estimate = *estimate;
                return Err(self.last);
            }
            LockAction::Rearm => {
                self.estimator.rearm_lock_detector();
                self.stall.reset();
                if self.config.tuning.lock.recovery_rs_adaptation {
                    self.estimator.enable_rs_adaptation();
                }
            }
            // While recovering, the detector judges each sample afresh (its verdict is not
            // latched), so that "healthy" means no symptom now.
            LockAction::Coast if self.lock.recovering() && lost => {
                self.estimator.rearm_lock_detector();
                self.stall.reset();
            }
            LockAction::Restart => {
                self.blocks.speed.reset();
                self.stall_armed = false;
            }
            LockAction::Run | LockAction::Coast => {}
        }
        // The reason the drive coasts: the symptoms seen since the loss that started it.
        if !self.lock.coasting() {
            self.coast_reason = DriveFlags::NONE;
        } else if lost {
            self.coast_reason.set(DriveFlags::LOCK_LOST, estimate_lost);
            self.coast_reason.set(DriveFlags::STALLED, stalled);
        }
        Ok(match action {
            LockAction::Rearm => LockAction::Coast,
            a => a,
        })
    }

    /// The stall symptom, debounced: whether the drive counts as stalled now.
    ///
    /// In limiter mode (or in k_df mode just above its threshold,
    /// `StallTuning::kdf_speed_ratio`, off by default) the speed loop loses a
    /// reference it had caught by more than the band (the larger of a fraction of the rated
    /// speed and the speed error of the commanded torque, `stall.torque_band_ratio`)
    /// (armed once |ω* − ω̂| was within the band since the last start), although its current
    /// reference is below the limit (at the limit, a speed error is the machine's torque
    /// limit, not evidence against the estimate; within 1 % counts as at the limit) and it
    /// asks for a torque (see `StallTuning::min_current_ratio`), while ω̂ is near
    /// zero or turns against ω* (`StallTuning::max_speed_ratio`; off by default),
    /// and unless the estimated rotor answers the torque: it turns in the direction of the
    /// speed error beyond the band and accelerates in it (`StallTuning::follow_time`).
    #[inline(always)]
    fn stall_symptom(&mut self, estimate: &Estimate<T>, speed_ref: T) -> bool {
        let omega_ctrl = estimate.omega_control;
        let speed_error = speed_ref - omega_ctrl;
        let (m, i_ref) = (&self.config.machine, self.last.i_dq_ref);
        // The model's torque and its reluctance part over 1.5·p (folded into the band
        // factors at construction, so that the step does no integer-to-float or
        // double-precision arithmetic).
        let reluctance_flux = (m.ld - m.lq) * i_ref.d;
        let band = self.resolved.stall.speed.step_max(
            self.resolved.stall.torque_band * ((m.flux_linkage + reluctance_flux) * i_ref.q).abs(),
        ) + self.resolved.stall.reluctance_band * (reluctance_flux * i_ref.q).abs();
        let off_reference = speed_error.abs() > band;
        let follow_gain = self.resolved.stall.follow_gain;
        self.omega_slow += follow_gain * (omega_ctrl - self.omega_slow);
        let answers_torque = follow_gain > T::zero()
            && self.last.i_dq_ref.q.abs() >= self.resolved.stall.follow_min_current
            && omega_ctrl * speed_error > band * speed_error.abs()
            && (omega_ctrl - self.omega_slow) * speed_error
                > self.resolved.stall.follow_lead * speed_error.abs();
        self.stall_armed |= !off_reference && !self.lock.coasting();
        // ω̂ turns against the reference.
        let against = omega_ctrl * speed_ref < T::zero();
        let stall_now = self.stall_armed
            && off_reference
            && (omega_ctrl.abs() < self.resolved.stall.max_speed || against)
            && (estimate.diagnostics.mode == Mode::Limiter
                || omega_ctrl.abs() < self.resolved.stall.kdf_band)
            && (self.last.i_dq_ref.q.abs() >= self.resolved.stall.min_current
                || (against && speed_error.abs() > self.resolved.stall.gross_ratio * band))
            && self.last.i_dq_ref.norm() < self.resolved.i_max * T::lit(0.99)
            && !answers_torque;
        self.stall.step(stall_now)
    }
}
