//! The free rotor's turn onto a well-observed axis before the gain calibration
//! ([`calibration_turn`](crate::control::calibration_turn)), in the drive: the current loop
//! holds the calibration's lower level along the turning axis.

use super::{DriveOutput, SensorlessDrive};
use crate::control::calibration_turn::CalibrationTurn;
use crate::estimator::{Estimate, RotorAngleEstimator};
use crate::{Ab, Abc, Dq, Real, Rotation};

/// The current loop's voltage, its reference and the measured current, all d-q (V, A, A).
type CurrentLoopSample<T> = (Dq<T>, Dq<T>, Dq<T>);

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// While the gain calibration is armed: the turn's sample, or `None` when no turn is under
    /// way (none needed or possible, or this one just ended: the rotor is then at the turned
    /// axis, which becomes the aligned angle the calibration runs along and the drive starts
    /// from).
    pub(super) fn calibration_turn_step(
        &mut self,
        i_abc: Abc<T>,
        vdc: T,
    ) -> Option<DriveOutput<T>> {
        if self.turn.is_none() {
            self.turn = self.plan_turn();
        }
        let turn = self.turn.as_mut()?;
        let Some(angle) = turn.step() else {
            self.aligned_angle = crate::wrap_angle(turn.target());
            self.turn = None;
            return None;
        };
        let current = turn.current();
        Some(self.turn_sample(angle, current, i_abc, vdc))
    }

    /// The turn a free rotor at the aligned angle needs for a calibration that would then run.
    fn plan_turn(&self) -> Option<CalibrationTurn<T>> {
        if self.config.tuning.startup.rotor_held {
            return None;
        }
        let c = self.gain.config();
        let turn = CalibrationTurn::plan(
            &self.config.machine,
            self.aligned_angle,
            c.current,
            c.min_observability,
            self.config.ts,
        )?;
        // Only where the calibration runs there (not off, not too slow for its hold).
        let mut probe = self.gain;
        probe.start(turn.target()).then_some(turn)
    }

    /// One sample of the current loop holding `current_d` along `angle` at ω = 0 (offsets
    /// removed, no gain correction; the estimator is not stepped).
    fn turn_sample(&mut self, angle: T, current_d: T, i_abc: Abc<T>, vdc: T) -> DriveOutput<T> {
        let i_ab = i_abc.to_ab();
        if !i_ab.is_finite() {
            return self.reject(i_abc);
        }
        self.i_ab_used = i_ab;
        let estimate = self.last.estimate;
        let rot = Rotation::from_angle(angle);
        let backup = self.blocks;
        let (v_dq, i_dq_ref, i_dq) = match self.d_current_voltage(rot, current_d, i_ab, estimate) {
            Ok(loop_out) => loop_out,
            Err(out) => return out,
        };
        let v_ab = v_dq.to_ab(rot);
        let Some(applied) = self
            .blocks
            .modulate(rot, v_ab, v_dq, (i_dq_ref, i_dq), i_abc, vdc)
        else {
            return self.reject_after_estimate(backup, estimate, i_dq);
        };
        self.blocks.current.realised(applied.v_dq);
        self.record(applied, i_dq, i_dq_ref, estimate, i_ab)
    }

    /// The current loop's voltage (v_dq, i_dq_ref, i_dq) holding `current_d` along the frame
    /// `rot` at ω = 0, or the rejected sample's output (the blocks restored).
    pub(super) fn d_current_voltage(
        &mut self,
        rot: Rotation<T>,
        current_d: T,
        i_ab: Ab<T>,
        estimate: Estimate<T>,
    ) -> Result<CurrentLoopSample<T>, DriveOutput<T>> {
        let i_dq = i_ab.to_dq(rot);
        let i_dq_ref = Dq::new(current_d, T::zero());
        let backup = self.blocks;
        match self.blocks.current.step(i_dq_ref, i_dq, T::zero()) {
            Ok(v_dq) => Ok((v_dq, i_dq_ref, i_dq)),
            Err(_) => Err(self.reject_after_estimate(backup, estimate, i_dq)),
        }
    }
}
