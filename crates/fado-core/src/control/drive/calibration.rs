//! The start-up calibrations' samples: current-sensor offsets (gates off) and the gain
//! ratio (a d current held along the aligned axis).

use super::{DriveOutput, SensorlessDrive};
use crate::control::gain_calibration::GainCalibrationStatus;
use crate::estimator::RotorAngleEstimator;
use crate::{Ab, Abc, Dq, Real, Rotation};

/// Samples of the watched offset calibration averaged as the motion monitor's reference
/// (1 ms at 10 kHz; at most half the calibration): before a load from t = 0 has turned the
/// rotor by a thousandth of a radian on the presets.
const OFFSET_REFERENCE_SAMPLES: u32 = 10;

/// The reference's uncertainty the motion monitor allows for, in standard errors of its mean
/// (from the spread of its samples): 3 \[A\], a false reading of motion on one start-up in
/// several hundred with Gaussian noise.
const REFERENCE_ERROR_SIGMAS: f64 = 3.0;

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// One sample of the offset calibration: gates off, duties ½, nothing else stepped; or,
    /// when the start-up watches it ([`AngleSearch::watches_offsets`]), the zero vector
    /// (gates on, the phases shorted: at rest no current flows) with the motion monitor
    /// started after the first [`OFFSET_REFERENCE_SAMPLES`] from their mean.
    ///
    /// [`AngleSearch::watches_offsets`]: crate::control::startup::AngleSearch::watches_offsets
    pub(super) fn calibration_step(&mut self, i_abc: Abc<T>) -> DriveOutput<T> {
        self.calibration_sum = Abc::new(
            self.calibration_sum.a + i_abc.a,
            self.calibration_sum.b + i_abc.b,
            self.calibration_sum.c + i_abc.c,
        );
        self.calibration_remaining -= 1;
        let watched = self.startup.watches_offsets();
        if watched {
            self.calibration_square_sum += i_abc.to_ab().norm_squared();
        }
        if watched && self.watch_offsets(i_abc) {
            // The rotor moves: the offsets of the samples before it did, and the start-up
            // defers (the zero vector from the next sample, through the angle phase).
            self.calibration_remaining = 0;
            self.last_i_ab = Ab::zero();
            return self.zero_vector_output();
        }
        if self.calibration_remaining == 0 {
            let k = T::one() / T::lit(self.resolved.offset_calibration_samples as f64);
            let sum = self.calibration_sum;
            self.current_offset = Abc::new(sum.a * k, sum.b * k, sum.c * k);
            self.last_i_ab = Ab::zero();
            self.start_at(self.aligned_angle);
            let mut out = self.last;
            out.gates_enabled = false;
            return out;
        }
        if watched {
            return self.zero_vector_output();
        }
        let mut out = self.last;
        out.gates_enabled = false;
        out.input_fault = false;
        out
    }

    /// The watched offset calibration's sample: the monitor's reference after the first
    /// samples (then also the offsets in use until the calibration ends), then its reading.
    /// True when the rotor has moved.
    fn watch_offsets(&mut self, i_abc: Abc<T>) -> bool {
        let taken = self.resolved.offset_calibration_samples - self.calibration_remaining;
        let first = OFFSET_REFERENCE_SAMPLES.min(self.resolved.offset_calibration_samples / 2);
        if taken == first.max(1) {
            let k = T::one() / T::lit(taken as f64);
            let sum = self.calibration_sum;
            self.current_offset = Abc::new(sum.a * k, sum.b * k, sum.c * k);
            let mean = self.current_offset.to_ab();
            // The spread of the samples, and three standard errors of their mean.
            let variance =
                (self.calibration_square_sum * k - mean.norm_squared()).step_max(T::zero());
            let error = T::lit(REFERENCE_ERROR_SIGMAS) * (variance * k).sqrt();
            self.startup.watch_offsets(mean, error);
            return false;
        }
        self.startup.offset_sample(i_abc.to_ab())
    }

    /// The phase currents less the offsets in use.
    pub(super) fn offsets_removed(&self, i_abc: Abc<T>) -> Abc<T> {
        let o = self.current_offset;
        Abc::new(i_abc.a - o.a, i_abc.b - o.b, i_abc.c - o.c)
    }

    /// The zero vector: gates on, duties ½ (the two zero states in turn), no voltage and no
    /// dead-time compensation (near zero current it would follow the sensors' noise and
    /// offset error, whose voltage the motion monitor would integrate as travel; the
    /// uncompensated dead time only adds to the shorted phases' braking).
    pub(super) fn zero_vector_output(&mut self) -> DriveOutput<T> {
        let half = T::lit(0.5);
        let mut out = self.last;
        out.duty = Abc::new(half, half, half);
        out.gates_enabled = true;
        out.input_fault = false;
        out.v_ref_ab = Ab::zero();
        out.v_dq_ref = Dq::zero();
        self.history = [Ab::zero(); 2];
        self.last = out;
        out
    }

    /// One sample of the gain calibration (offsets removed, no gain correction): the current
    /// loop holds the calibration's current in the frame of its axis ([`Self::gain_axis`]) at ω = 0, with
    /// the usual dead-time compensation and modulation; the estimator is not stepped (the
    /// drive re-aligns at the end). The calibration gets the realised voltage that acted over
    /// the last period, as the estimator would.
    pub(super) fn gain_calibration_step(&mut self, i_abc: Abc<T>, vdc: T) -> DriveOutput<T> {
        let i_ab = i_abc.to_ab();
        if !i_ab.is_finite() {
            return self.reject(i_abc);
        }
        self.i_ab_used = i_ab;
        let command = self.gain.step(i_ab, self.history[1]);
        if !self.gain.running() {
            // Done (zero current after the release): the ratio, then the aligned start.
            let k = self.gain.ratio();
            self.gain_correction = if k.is_finite() && k > T::zero() {
                T::one() / k
            } else {
                T::one()
            };
            // The same two levels are the classic DC test of Rs: the estimator's R̂s
            // adaptation starts from it if it lies within 0.5–2× of the model's R̂s (a value
            // outside says something else is wrong, and the model's R̂s is kept).
            if self.gain.status() == GainCalibrationStatus::Calibrated {
                let r = self.gain.resistance();
                let r0 = self.config.machine.rs;
                if r >= r0 * T::lit(0.5) && r <= r0 + r0 {
                    self.estimator.start_from_measured_rs(r);
                }
            }
            self.last_i_ab = self.gain_corrected(i_abc).to_ab();
            let theta0 = self.aligned_angle;
            if self.gain.status() == GainCalibrationStatus::RotorMoved {
                // A load turns the rotor: the drive starts from where its back-EMF says the
                // rotor has turned to, and the release hold catches it there before the speed
                // loop takes over (`ReleaseHold::engage`).
                let m = &self.config.machine;
                let turned = self.gain.motion_travel(m.flux_linkage, m.ld);
                let theta = crate::wrap_angle(self.gain_axis() + turned);
                let omega = self.gain.motion_speed(m.flux_linkage, m.ld);
                self.start_at(theta);
                self.blocks.hold.engage(theta, omega);
                return self.last;
            }
            self.start_at(theta0);
            return self.last;
        }
        let axis = self.gain_axis();
        let theta0 = if axis.is_finite() { axis } else { T::zero() };
        let rot = Rotation::from_angle(theta0);
        let i_dq = i_ab.to_dq(rot);
        let i_dq_ref = Dq::new(command.current_d, T::zero());
        let backup = self.blocks;
        let estimate = self.last.estimate;
        let b = &mut self.blocks;
        let (v_ab, v_dq) = match command.voltage {
            // Voltage mode: the current loop is not stepped (its state is kept for the
            // return to zero).
            Some(v) => (v, v.to_dq(rot)),
            None => {
                let Ok(v_dq) = b.current.step(i_dq_ref, i_dq, T::zero()) else {
                    return self.reject_after_estimate(backup, estimate, i_dq);
                };
                (v_dq.to_ab(rot), v_dq)
            }
        };
        let Some(applied) = b.modulate(rot, v_ab, v_dq, i_dq_ref, i_abc, vdc) else {
            return self.reject_after_estimate(backup, estimate, i_dq);
        };
        if command.voltage.is_none() {
            b.current.realised(applied.v_dq);
        }
        self.record(applied, i_dq, i_dq_ref, estimate, i_ab)
    }

    /// The gain calibration's axis: the aligned angle, or with a held rotor
    /// ([`StartupTuning::rotor_held`](crate::control::StartupTuning::rotor_held)) the
    /// nearest well-observed axis.
    pub(super) fn gain_axis(&self) -> T {
        let min = self.config.tuning.gain_calibration.min_observability;
        self.startup.gain_axis(self.aligned_angle, min)
    }

    /// The phase currents with the measured gain ratio applied to phase a; c keeps the sum of
    /// the three readings (c = −a − b stays so for two sensors). Untouched while k = 1.
    #[inline(always)]
    pub(super) fn gain_corrected(&self, i_abc: Abc<T>) -> Abc<T> {
        if self.gain_correction != T::one() {
            let a = i_abc.a * self.gain_correction;
            Abc::new(a, i_abc.b, i_abc.c + (i_abc.a - a))
        } else {
            i_abc
        }
    }
}
