//! The start-up's angle phase in the drive (see [`startup`](crate::control::startup)): its
//! pulses modulated as the gain calibration's voltage levels, its free-rotor alignment held by
//! the current loop, its result the angle the drive starts from.

use super::{DriveOutput, SensorlessDrive};
use crate::control::startup::{StartupCommand, StartupStatus};
use crate::estimator::RotorAngleEstimator;
use crate::{Abc, Dq, Real, Rotation};

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// One sample of the angle phase (offsets removed, no gain correction; the estimator is
    /// not stepped: the drive aligns it at the angle found).
    pub(super) fn angle_phase_step(&mut self, i_abc: Abc<T>, vdc: T) -> DriveOutput<T> {
        let i_ab = i_abc.to_ab();
        if !i_ab.is_finite() {
            return self.reject(i_abc);
        }
        self.i_ab_used = i_ab;
        let estimate = self.last.estimate;
        let command = self.startup.step(i_ab, self.history[1], vdc);
        if self.startup.status() == StartupStatus::RotorMoving {
            return self.zero_vector_output();
        }
        let (rot, v_ab, v_dq, i_dq_ref, i_dq) = match command {
            StartupCommand::Voltage(v) => {
                let rot = Rotation::from_angle(T::zero());
                (rot, v, v.to_dq(rot), Dq::zero(), i_ab.to_dq(rot))
            }
            StartupCommand::Align { angle, current_d } => {
                let rot = Rotation::from_angle(angle);
                let (v_dq, i_dq_ref, i_dq) =
                    match self.d_current_voltage(rot, current_d, i_ab, estimate) {
                        Ok(loop_out) => loop_out,
                        Err(out) => return out,
                    };
                (rot, v_dq.to_ab(rot), v_dq, i_dq_ref, i_dq)
            }
            StartupCommand::Start(theta) => {
                // The current is back at about zero: the estimator starts from it.
                self.last_i_ab = i_ab;
                self.start_at(theta);
                return self.last;
            }
            StartupCommand::Restart => {
                // The rotor stood still: the start-up again, from the offsets.
                self.gain.arm();
                self.calibrate_offsets();
                return self.zero_vector_output();
            }
            StartupCommand::Off => {
                let mut out = self.last;
                let half = T::lit(0.5);
                out.duty = Abc::new(half, half, half);
                out.gates_enabled = false;
                out.v_ref_ab = crate::Ab::zero();
                out.v_dq_ref = Dq::zero();
                self.history = [crate::Ab::zero(); 2];
                self.last = out;
                return out;
            }
        };
        let backup = self.blocks;
        let Some(applied) = self
            .blocks
            .modulate(rot, v_ab, v_dq, (i_dq_ref, i_dq), i_abc, vdc)
        else {
            return self.reject_after_estimate(backup, estimate, i_dq);
        };
        if matches!(self.startup.status(), StartupStatus::Aligning) {
            self.blocks.current.realised(applied.v_dq);
        }
        self.record(applied, i_dq, i_dq_ref, estimate, i_ab)
    }

    /// Where the start-up's angle phase stands ([`StartupStatus::Idle`] when the drive starts
    /// from the angle it is given).
    pub fn startup_status(&self) -> StartupStatus {
        self.startup.status()
    }

    /// The start-up's angle phase (the detection's verdict and margins, the polarity test's
    /// contrast, the angle found).
    pub fn angle_search(&self) -> &crate::control::startup::AngleSearch<T> {
        &self.startup
    }

    /// The drive runs and holds the rotor: its start-up (offsets, angle, gain calibration) is
    /// over with an angle, its gates are on and it has not tripped. A brake may release.
    pub fn ready(&self) -> bool {
        self.calibration_remaining == 0
            && !self.startup.active()
            && !self.gain.running()
            && self.last.gates_enabled
            && !self.tripped
    }
}
