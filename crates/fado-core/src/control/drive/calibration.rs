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

/// Zero of the type of `_x`.
fn zero_of<T: Real>(_x: T) -> T {
    T::zero()
}

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
            // The rotor moves: the offsets of the samples before it did. A rotor of unknown
            // angle: the start-up defers (the zero vector from the next sample, through the
            // angle phase); one whose start angle the drive was given: it starts at once.
            self.calibration_remaining = 0;
            self.last_i_ab = Ab::zero();
            if !self.config.tuning.startup.find_angle {
                return self.start_turning(i_abc);
            }
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
            // The reference's error δ integrates through R̂s and, with the devices' drop the
            // monitor counts, through its slope V_th/I_band within the band (3.3 Ω against
            // 5.6 mΩ on the 50 kW IPMSM preset, whose 0.27 A resolution read 0.25 rad in
            // 70 ms at rest): the monitor's allowance scales δ by (R̂s + V_th/I_band)/R̂s.
            let rs = self.config.machine.rs;
            let c = self.blocks.dead_time.config();
            let slope = if c.enabled && c.current_band > zero_of(rs) {
                c.threshold_voltage / c.current_band
            } else {
                zero_of(rs)
            };
            let scale = if rs > zero_of(rs) && !self.config.tuning.startup.find_angle {
                (rs + slope) / rs
            } else {
                T::one()
            };
            self.startup.watch_offsets(mean, error * scale);
            return false;
        }
        // The zero vector's voltage: the devices' drop, −V_th·sat(i/I_band) in each phase
        // (no leg switches; the dead-time compensation's model of a held leg).
        if self.config.tuning.startup.find_angle {
            return self.startup.offset_sample(i_abc.to_ab(), Ab::zero());
        }
        let i_ab = self.offsets_removed(i_abc).to_ab();
        let zero = T::zero();
        let drop = self.blocks.dead_time.lost(
            Abc::new(zero, zero, zero),
            Rotation::from_angle(zero),
            Dq::new(i_ab.alpha, i_ab.beta),
            Abc::new(zero, zero, zero),
        );
        self.startup.offset_sample(i_abc.to_ab(), -drop.to_ab())
    }

    /// The watched offset calibration saw a rotor turn that started at the aligned angle θ₀:
    /// the offsets of the reference samples stay, the gain calibration is skipped
    /// ([`GainCalibrationStatus::RotorMoved`]) and the drive starts at once from where the
    /// rotor has turned to, arg(λ̂f·e^(jθ₀) + Δλr) with the monitor's flux change Δλr, its
    /// release hold engaged there at the speed (λr × dλr/dt)/|λr|² (as after the gain
    /// calibration's `RotorMoved`).
    fn start_turning(&mut self, i_abc: Abc<T>) -> DriveOutput<T> {
        let theta0 = if self.aligned_angle.is_finite() {
            self.aligned_angle
        } else {
            T::zero()
        };
        let (s, c) = theta0.step_sin_cos_any();
        let monitor = self.startup.motion();
        let lambda = Ab::new(c, s) * self.config.machine.flux_linkage + monitor.flux_change();
        let theta = lambda.beta.step_atan2(lambda.alpha);
        let omega = lambda.cross(monitor.flux_rate()) / lambda.norm_squared();
        self.gain.skip_moving();
        self.last_i_ab = self.offsets_removed(i_abc).to_ab();
        self.start_at(theta);
        self.blocks.hold.engage(theta, omega);
        self.last
    }

    /// The phase currents less the offsets in use.
    pub(super) fn offsets_removed(&self, i_abc: Abc<T>) -> Abc<T> {
        let o = self.current_offset;
        Abc::new(i_abc.a - o.a, i_abc.b - o.b, i_abc.c - o.c)
    }

    /// The zero vector: gates on, every low-side switch on (duties 0), no voltage. The legs
    /// do not switch, so there is no dead time: the phases are shorted through the devices
    /// alone, and the voltage the motion monitor takes as zero is zero but for their drop.
    /// With duties ½ (the two zero states in turn) each edge's dead time would set a voltage
    /// of V_dc·t_d·f_sw against the current, larger than a slowly turning rotor's back-EMF on
    /// a machine of small resistance: on a 50 kW, 400 V traction IPMSM (10 mΩ) no current
    /// flowed at 160 r/min, the rotor fell freely and the monitor read 0.02 rad of a 0.69 rad
    /// turn (`crates/fado-sim/tests/calibration_load_classes.rs`). The start-up that finds
    /// the angle (`find_angle`) keeps duties ½ and its monitor's zero voltage: its deferral's
    /// restart is measured with them (`crates/fado-sim/tests/startup_motion.rs`; with duties 0
    /// the 2.2 kW IPMSM's restarted start fails that test's bound, 0.64).
    pub(super) fn zero_vector_output(&mut self) -> DriveOutput<T> {
        let d = if self.config.tuning.startup.find_angle {
            T::lit(0.5)
        } else {
            T::zero()
        };
        let mut out = self.last;
        out.duty = Abc::new(d, d, d);
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
        let (rot, inverter) = self.calibration_inverter_voltage(i_abc, vdc);
        let command = self
            .gain
            .step_with_inverter(i_ab, self.history[1], inverter);
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
            if self.gain.status() == GainCalibrationStatus::Calibrated
                || self.gain.moved_in_release()
            {
                let r = self.gain.resistance();
                let r0 = self.config.machine.rs;
                if r >= r0 * T::lit(0.5) && r <= r0 + r0 {
                    self.estimator.start_from_measured_rs(r);
                }
            }
            self.last_i_ab = self.gain_corrected(i_abc).to_ab();
            self.calibration_compensation = [Ab::zero(); 2];
            let theta0 = self.aligned_angle;
            if self.gain.status() == GainCalibrationStatus::RotorMoved {
                return self.start_moved();
            }
            self.start_at(theta0);
            return self.last;
        }
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
        let Some(applied) = b.modulate(rot, v_ab, v_dq, (i_dq_ref, i_dq), i_abc, vdc) else {
            return self.reject_after_estimate(backup, estimate, i_dq);
        };
        if command.voltage.is_none() {
            b.current.realised(applied.v_dq);
        }
        // The trapezoid at the reference current, for the motion test two samples on, when
        // this voltage has acted.
        let reference = b.dead_time.trapezoid(i_dq_ref.to_ab(rot).to_abc(), vdc);
        self.calibration_compensation = [reference.to_ab(), self.calibration_compensation[0]];
        self.record(applied, i_dq, i_dq_ref, estimate, i_ab)
    }

    /// The start after the gain calibration's `RotorMoved`: a load turns the rotor, and the
    /// drive starts from where its back-EMF says the rotor has turned to, the release hold
    /// catching it there before the speed loop takes over (`ReleaseHold::engage`). Read in
    /// the release, the motion is where a load starts to act (or the band's noise): the hold
    /// is armed there and acts on the fall that follows (`ReleaseHold::arm_after_release`).
    fn start_moved(&mut self) -> DriveOutput<T> {
        let m = &self.config.machine;
        let saliency = m.ld - m.lq;
        let turned = self.gain.motion_travel(m.flux_linkage, saliency);
        let theta = crate::wrap_angle(self.gain_axis() + turned);
        let omega = self.gain.motion_speed(m.flux_linkage, saliency);
        self.start_at(theta);
        if self.gain.moved_in_release() {
            self.blocks.hold.arm_after_release(theta);
        } else {
            self.blocks.hold.engage(theta, omega);
        }
        self.last
    }

    /// The gain calibration's frame (its axis) and what the inverter added to the voltage that
    /// acted over the last period, as the dead-time trapezoid gives it: its value at the
    /// reference current the voltage was computed for, less its value at the measured current
    /// `i_abc` (offsets removed). Within the band a phase is a resistance of V̂/I_c (tens to
    /// hundreds of ohms): with the current loop at zero, a turning rotor's back-EMF appears
    /// across the idle devices and drives only a band current, which this term reads.
    fn calibration_inverter_voltage(&self, i_abc: Abc<T>, vdc: T) -> (Rotation<T>, Ab<T>) {
        let axis = self.gain_axis();
        let rot = Rotation::from_angle(if axis.is_finite() { axis } else { T::zero() });
        let loss = self.blocks.dead_time.trapezoid(i_abc, vdc).to_ab();
        (rot, self.calibration_compensation[1] - loss)
    }

    /// Starts the gain calibration along [`gain_axis`](Self::gain_axis); along the rotor's q
    /// axis each level is held for the settling of L̂q (5·L̂q/R̂s: the upper level is a
    /// voltage step, which settles with the axis's own time constant), at most the hold
    /// budget, beyond which only k is measured
    /// ([`GainCalibration::start_with_hold`](crate::control::GainCalibration::start_with_hold)).
    pub(super) fn start_gain_calibration(&mut self) {
        let min = self.config.tuning.gain_calibration.min_observability;
        let (axis, on_q) = self.startup.gain_axis_on_q(self.aligned_angle, min);
        if on_q {
            let hold = self
                .config
                .gain_calibration_settle_time(self.config.machine.lq);
            self.gain.start_with_hold(axis, hold);
        } else {
            self.gain.start(axis);
        }
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
