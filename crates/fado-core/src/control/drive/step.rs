//! One sample of the drive, in the order of the module docs.

use super::references::TORQUE_SETTLED;
use super::{Applied, DriveOutput, SensorlessDrive, estimate_is_finite};
use crate::control::lock_reaction::LockAction;
use crate::control::monitor::DriveFlags;
use crate::control::speed_controller::limit_current_d_priority;
use crate::estimator::{Estimate, RotorAngleEstimator};
use crate::lock::LockStatus;
use crate::mode::Mode;
use crate::{Ab, Abc, Dq, Real, Rotation};

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// One 10 kHz sample: phase currents `i_abc` sampled now (A), dc-link voltage `vdc` (V),
    /// speed reference `speed_ref_mech` (mechanical rad/s). The duty returned is to be loaded
    /// at the next sample.
    ///
    /// A non-finite input rejects the sample: the last duty is held (so the history repeats
    /// the held voltage), the controllers are untouched, and the estimator still integrates
    /// the interval with the last good current so that it keeps time. A phase current above
    /// `trip_current` trips the drive: gates off, duties ½, latched until [`reset`](Self::reset);
    /// while tripped nothing is stepped.
    ///
    /// Every output carries the status word [`DriveOutput::flags`]; the drive also counts the
    /// samples each flag was raised ([`flag_counts`](Self::flag_counts)). A stuck
    /// phase-current channel (see [`StuckChannelDetector`](crate::control::monitor::StuckChannelDetector)) is replaced by its reconstruction
    /// while it lasts; rejected samples for `protection.input_fault_trip_time` in a row trip the drive.
    pub fn step(&mut self, i_abc: Abc<T>, vdc: T, speed_ref_mech: T) -> DriveOutput<T> {
        let mut out = self.step_control(i_abc, vdc, speed_ref_mech);
        if out.input_fault && !out.tripped {
            self.consecutive_rejects = self.consecutive_rejects.saturating_add(1);
            let limit = self.resolved.input_fault_trip_samples;
            if limit > 0 && self.consecutive_rejects >= limit {
                self.tripped = true;
                self.trip_output();
                out = self.last;
                out.input_fault = true;
            }
        } else {
            self.consecutive_rejects = 0;
        }
        let mut flags = DriveFlags::NONE;
        flags.set(DriveFlags::INPUT_REJECTED, out.input_fault);
        flags.set(DriveFlags::TRIPPED, out.tripped);
        let running = out.gates_enabled && !out.tripped;
        flags.set(
            DriveFlags::VOLTAGE_SATURATED,
            running && out.voltage_saturated,
        );
        flags.set(DriveFlags::CURRENT_ERROR, running && self.current_error_now);
        flags.set(DriveFlags::SENSOR_STUCK, running && self.sensor_stuck_now);
        flags.set(
            DriveFlags::DC_LINK_LOW,
            vdc.is_finite() && vdc < self.resolved.dc_link_min_voltage,
        );
        flags.set(
            DriveFlags::LIMITER_MODE,
            out.estimate.diagnostics.flag_limit,
        );
        // The reason stays up while the drive coasts, also after the detector was re-armed.
        let coasting = self.lock.coasting();
        flags.set(
            DriveFlags::LOCK_LOST,
            out.estimate.diagnostics.lock == LockStatus::Lost
                || (coasting && self.coast_reason.contains(DriveFlags::LOCK_LOST)),
        );
        flags.set(
            DriveFlags::STALLED,
            self.stall.is_up() || (coasting && self.coast_reason.contains(DriveFlags::STALLED)),
        );
        flags.set(DriveFlags::COASTING, running && self.lock.coasting());
        flags.set(DriveFlags::INPUT_IMPLAUSIBLE, self.implausible_now);
        out.flags = flags;
        out.i_ab = self.i_ab_used;
        self.last.flags = flags;
        self.last.i_ab = self.i_ab_used;
        self.flag_counts.record(flags);
        out
    }

    /// The sample without its status word: each phase returns early (`Err`) with the
    /// sample's output when it ends the sample (a rejected or held sample, a calibration
    /// sample, a trip, a realignment).
    pub(super) fn step_control(
        &mut self,
        i_abc: Abc<T>,
        vdc: T,
        speed_ref_mech: T,
    ) -> DriveOutput<T> {
        match self.control(i_abc, vdc, speed_ref_mech) {
            Ok(out) | Err(out) => out,
        }
    }

    /// Steps 1–8 of the module docs.
    #[inline(always)]
    fn control(
        &mut self,
        i_abc: Abc<T>,
        vdc: T,
        speed_ref_mech: T,
    ) -> Result<DriveOutput<T>, DriveOutput<T>> {
        // 1. Inputs: plausibility, offsets, trip, gain calibration and correction, stuck
        //    channel.
        self.screen_inputs(i_abc, vdc, speed_ref_mech)?;
        let i_abc = self.conditioned_currents(i_abc, vdc)?;
        let i_ab = i_abc.to_ab();
        if !i_ab.is_finite() {
            return Err(self.reject(i_abc));
        }
        // 2. Estimator: voltage of [n−1, n] = realised reference computed at n−2.
        let estimate = self.estimate(i_ab, vdc)?;
        // 3. Measured current in the estimated rotor frame.
        let rot_theta = Rotation::from_angle(estimate.theta);
        let i_dq = self.measured_dq(i_ab, rot_theta, estimate.omega);
        let omega_ctrl = estimate.omega_control;
        let tracking_error = (self.last.i_dq_ref - i_dq).norm();
        self.current_error_now = self
            .current_error
            .step(tracking_error > self.resolved.current_error_limit);
        // Reaction to a lost rotor (see `lock.reaction`).
        let speed_ref = speed_ref_mech * T::lit(self.config.machine.pole_pairs as f64);
        let speed_ref = self.blocks.limits.speed(speed_ref);
        let speed_ref = self.blocks.start_ramp.step(speed_ref);
        let action = self.react_to_lock(&estimate, speed_ref)?;
        // 4. Speed loop, injection (23) and current-vector limit (zero current when coasting).
        let backup = self.blocks;
        let Some(i_dq_ref) = self.current_reference(&estimate, speed_ref, action, vdc) else {
            return Err(self.reject_after_estimate(backup, estimate, i_dq));
        };
        // 5.–8. Current loop, delay and dead-time compensation, modulation, anti-windup.
        // 5. Current loop (unlimited); a saturating model's decoupling from its flux at the
        //    reference (the torque solve's last evaluation, no extra solve).
        let flux = self
            .resolved
            .saturated
            .as_ref()
            .map(|_| self.saturated_flux);
        let b = &mut self.blocks;
        let v_dq = match flux {
            Some(psi) => b.current.step_with_flux(i_dq_ref, i_dq, omega_ctrl, psi),
            None => b.current.step(i_dq_ref, i_dq, omega_ctrl),
        };
        let Ok(v_dq) = v_dq else {
            return Err(self.reject_after_estimate(backup, estimate, i_dq));
        };
        b.field_weakening
            .update(v_dq.d * v_dq.d + v_dq.q * v_dq.q, vdc, omega_ctrl);
        // 6. Delay compensation with the advanced angle.
        //    (reusing the Park rotation: one sin/cos per sample instead of two).
        let (v_ab, rot) = b
            .delay
            .step_rotated(v_dq, rot_theta, estimate.theta, estimate.omega);
        // 7. Dead-time compensation, hexagon limit, SVPWM.
        let Some(applied) = b.modulate(rot, v_ab, v_dq, (i_dq_ref, i_dq), i_abc, vdc) else {
            return Err(self.reject_after_estimate(backup, estimate, i_dq));
        };
        // 8. Anti-windup with the realised voltage in the same frame; speed loop too.
        b.current.realised(applied.v_dq);
        let realised_torque = if let Some(s) = &self.resolved.saturated {
            // A saturating model's co-energy torque (`saturated_references`), its flux the
            // next sample's warm start.
            let reach = T::lit(TORQUE_SETTLED) * self.config.machine.rated_current;
            let at = self.saturated_point;
            let (tau, psi) = s.torque_flux_near(i_dq_ref, at, reach, &mut self.saturated_warm);
            self.saturated_flux = psi;
            tau / self.config.machine.flux_linkage
        } else if self.resolved.salient {
            let m = &self.config.machine;
            m.active_flux(i_dq_ref.d) * i_dq_ref.q / m.flux_linkage
        } else {
            i_dq_ref.q
        };
        b.speed.realised(realised_torque);
        Ok(self.record(applied, i_dq, i_dq_ref, estimate, i_ab))
    }

    /// Plausibility of the inputs: while tripped the sample is held, and an implausible one
    /// is rejected.
    #[inline(always)]
    fn screen_inputs(
        &mut self,
        i_abc: Abc<T>,
        vdc: T,
        speed_ref_mech: T,
    ) -> Result<(), DriveOutput<T>> {
        // What this sample reports as its current until the estimator is given another.
        let raw = i_abc.to_ab();
        // Plausible: finite and within what the machine and inverter can produce (false
        // for NaN/∞, so it subsumes the finite test; see `crate::plausibility`).
        let lim = self.resolved.plausible_current;
        let current_ok = (i_abc.a.abs() < lim) & (i_abc.b.abs() < lim) & (i_abc.c.abs() < lim);
        self.i_ab_used = if current_ok && raw.is_finite() {
            raw
        } else {
            self.last_i_ab
        };
        let finite = current_ok
            && vdc.abs() < self.resolved.dc_link_max_voltage
            && speed_ref_mech.is_finite();
        self.implausible_now =
            !finite && i_abc.is_finite() && vdc.is_finite() && speed_ref_mech.is_finite();
        if self.tripped {
            let mut out = self.last;
            out.input_fault = !finite;
            return Err(out);
        }
        if !finite {
            return Err(self.reject(i_abc));
        }
        Ok(())
    }

    /// The phase currents the control uses: the offset calibration's sample, the offsets
    /// removed, the trip, the gain calibration's sample, the gain correction and the
    /// stuck-channel reconstruction.
    #[inline(always)]
    fn conditioned_currents(&mut self, i_abc: Abc<T>, vdc: T) -> Result<Abc<T>, DriveOutput<T>> {
        let trip = self.resolved.trip_current;
        if self.calibration_remaining > 0
            && i_abc.a.abs() <= trip
            && i_abc.b.abs() <= trip
            && i_abc.c.abs() <= trip
        {
            return Err(self.calibration_step(i_abc));
        }
        let i_abc = self.offsets_removed(i_abc);
        let over_voltage = self.blocks.dc_link.over_voltage(vdc);
        if i_abc.a.abs() > trip || i_abc.b.abs() > trip || i_abc.c.abs() > trip || over_voltage {
            self.tripped = true;
            self.trip_output();
            self.last.input_fault = false;
            return Err(self.last);
        }
        if self.startup.active() {
            return Err(self.angle_phase_step(i_abc, vdc));
        }
        if self.gain.pending() {
            // A free rotor at an unobservable angle first turns to a well-observed axis.
            if let Some(out) = self.calibration_turn_step(i_abc, vdc) {
                return Err(out);
            }
            self.start_gain_calibration();
        }
        if self.gain.running() {
            return Err(self.gain_calibration_step(i_abc, vdc));
        }
        let i_abc = self.gain_corrected(i_abc);
        Ok(self.unstuck(i_abc))
    }

    /// Stuck-channel check against the reference the loop was tracking, advanced by the
    /// rotation over one sample; an implausible channel is replaced by its reconstruction
    /// from the model prediction.
    #[inline(always)]
    fn unstuck(&mut self, i_abc: Abc<T>) -> Abc<T> {
        // (Both are only needed when a reading is near zero or a channel is stuck.)
        let (i_ref_ab, i_model) = if self.stuck_sensor.quiet(i_abc.a, i_abc.b) {
            (Ab::zero(), Ab::zero())
        } else {
            let prev = self.last.estimate;
            let rot_ref = Rotation::from_angle(prev.theta + prev.omega * self.config.ts);
            let i_model = self.predicted_current().unwrap_or_else(|| i_abc.to_ab());
            let uncertainty = self.stuck_model_uncertainty();
            self.stuck_sensor.set_model_uncertainty(uncertainty);
            (self.last.i_dq_ref.to_ab(rot_ref), i_model)
        };
        let (ia, ib, stuck) = self.stuck_sensor.step(i_abc.a, i_abc.b, i_ref_ab, i_model);
        self.sensor_stuck_now = stuck;
        if ia != i_abc.a || ib != i_abc.b {
            Abc::new(ia, ib, -ia - ib)
        } else {
            i_abc
        }
    }

    /// Step 2: the estimator's sample with the voltage of [n−1, n], the realised reference
    /// computed at n−2; a non-finite or refused estimate holds the sample.
    #[inline(always)]
    fn estimate(&mut self, i_ab: Ab<T>, vdc: T) -> Result<Estimate<T>, DriveOutput<T>> {
        self.i_ab_used = i_ab;
        if self.config.tuning.tracker_feedforward.enabled {
            let m = &self.config.machine;
            let p = T::lit(m.pole_pairs as f64);
            // Less the load the release hold found (zero unless it acted): the trackers'
            // load acceleration starts from it (see `tracker_feedforward`).
            let held = T::lit(1.5) * p * m.flux_linkage * self.blocks.hold.load();
            let torque = self.feedforward_torque(p) - held;
            self.estimator.set_acceleration(p * torque / m.inertia);
        }
        if self.limited[1] {
            self.estimator.voltage_limited();
        }
        // From a brake's opening until the release hold hands over, T2S-1 tracks the fall
        // (see `tracker_feedforward`, "T2S-1 at a brake's release").
        self.estimator
            .set_release_tracking(self.blocks.hold.tracking_fall());
        let dead_time = self.config.tuning.inverter.dead_time;
        self.estimator
            .set_pwm_ripple(self.history[1], vdc, dead_time);
        let estimate = self.estimator.step(self.history[1], i_ab);
        if !estimate_is_finite(&estimate) {
            // An estimator that went non-finite cannot steer the drive: hold like a bad input
            // (it has had its sample).
            let out = self.last;
            return Err(self.finish_reject(out));
        }
        if estimate.diagnostics.input_fault {
            // The estimator refused the sample (its current step is implausible for L̂q and
            // the DC link, see `crate::plausibility`): hold like a bad input of the drive.
            self.implausible_now = true;
            let mut out = self.last;
            out.estimate = estimate;
            return Err(self.finish_reject(out));
        }
        self.last_i_ab = i_ab;
        Ok(estimate)
    }

    /// The torque fed forward to the trackers (N·m): the model's torque of the last
    /// reference, 1.5·p·λ̂a·i_q*; in field weakening (the loop's Δi_d < 0, hence in
    /// disturbance-feedback mode) the torque of the last sample's estimated stator flux and
    /// current, 1.5·p·(λ̂2 × i), which holds for any rotor and does not depend on θ̂. The
    /// reference's torque misses what an angle error δ adds: in the estimated frame the d
    /// current gives the rotor −1.5·p·λ̂f·i_d·sin δ more, an acceleration that grows with δ
    /// and, deep in field weakening on a light rotor, outruns the trackers (docs/range.md,
    /// "Current-limited transients").
    #[inline(always)]
    fn feedforward_torque(&self, p: T) -> T {
        let last = &self.last;
        let d = &last.estimate.diagnostics;
        if self.blocks.field_weakening.delta_id() < T::zero() && d.mode == Mode::DisturbanceFeedback
        {
            let (l, i) = (d.lambda2, last.i_ab);
            let torque = T::lit(1.5) * p * (l.alpha * i.beta - l.beta * i.alpha);
            if torque.is_finite() {
                return torque;
            }
        }
        let i = last.i_dq_ref;
        match &self.resolved.saturated {
            Some(s) => T::lit(1.5) * p * s.torque_flux_warm(i, &mut { self.saturated_warm }).0,
            None => T::lit(1.5) * p * self.config.machine.active_flux(i.d) * i.q,
        }
    }

    /// Step 4: the current reference, the speed PI's torque demand, the injection (23), MTPA and
    /// the standstill probe, limited to I_max (d first); zero while coasting. None when the
    /// speed PI refuses its input.
    #[inline(always)]
    fn current_reference(
        &mut self,
        estimate: &Estimate<T>,
        speed_ref: T,
        action: LockAction,
        vdc: T,
    ) -> Option<Dq<T>> {
        // The speed PI's output is a torque demand in units of the magnet's q current i_q,t
        // (its gain assumes Kt = 1.5·p·λ̂f). On a salient rotor the torque per q ampere is
        // 1.5·p·λ̂a with the active flux λ̂a = λ̂f + (L̂d − L̂q)·i_d (Boldea et al. 2008), which
        // the eq. (23) injection and MTPA move by 0.45–2.9 λ̂f on the salient presets: the
        // currents are solved for that torque (see `currents_for_torque`).
        let guess = self.last.i_dq_ref.q;
        let i_dq_ref = if action == LockAction::Coast {
            Dq::zero()
        } else {
            let iq_torque = self.speed_or_hold(speed_ref, estimate)?;
            // The ratings' torque and power limits (see `ratings_limit`), the DC link's power
            // limits and over-voltage controller (see `dc_link_limit`).
            let iq_torque = self.blocks.limits.torque(iq_torque, estimate.omega_control);
            let (iq_torque, brake_id) = self.blocks.dc_link.limit(
                iq_torque,
                vdc,
                estimate.omega_control,
                self.last.i_dq_ref.norm(),
            );
            // The loaded-standstill probe (see `standstill_probe`): Δi_d on the d reference,
            // and the corrections of the estimate (from the next sample).
            let probe_id = self.standstill_probe_current(speed_ref, iq_torque, estimate, action);
            // Field weakening and loss braking add to the d reference (see
            // `field_weakening`, `dc_link_limit`); zero below the voltage limit.
            let fw_id = self.blocks.field_weakening.delta_id();
            let id_added = if brake_id != T::zero() || fw_id != T::zero() {
                probe_id + brake_id.step_min(fw_id)
            } else {
                probe_id
            };
            let i = self.currents_for_torque(iq_torque, guess, id_added);
            let i = self.release_current_floor(i, estimate.theta, vdc);
            let limiter = estimate.diagnostics.mode == crate::mode::Mode::Limiter;
            let i = self
                .blocks
                .phase_band
                .shift(i, estimate.theta, vdc, limiter);
            let i = limit_current_d_priority(i, self.resolved.i_max);
            let i = self.voltage_ellipse(i, vdc, estimate.omega_control);
            let iq_max = self
                .blocks
                .field_weakening
                .iq_limit(i.d, vdc, estimate.omega_control);
            if i.q.abs() > iq_max {
                Dq::new(i.d, iq_max * i.q.signum())
            } else {
                i
            }
        };
        self.standstill_corrections(action);
        Some(i_dq_ref)
    }

    /// The sample's output with the modulated voltage `applied`, which also enters the
    /// voltage history (the estimator's input one and two samples on).
    #[inline(always)]
    pub(super) fn record(
        &mut self,
        applied: Applied<T>,
        i_dq: Dq<T>,
        i_dq_ref: Dq<T>,
        estimate: Estimate<T>,
        i_ab: Ab<T>,
    ) -> DriveOutput<T> {
        self.history = [applied.v_ab, self.history[0]];
        self.limited = [applied.saturated, self.limited[0]];
        self.last = DriveOutput {
            duty: applied.duty,
            gates_enabled: true,
            v_ref_ab: applied.v_ab,
            i_dq,
            i_dq_ref,
            estimate,
            tripped: false,
            input_fault: false,
            v_dq_ref: applied.v_dq,
            voltage_saturated: applied.saturated,
            flags: DriveFlags::NONE, // set by `step`
            i_ab,
        };
        self.last
    }
}
