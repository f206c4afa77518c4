//! The calibration's sequence: start, the levels sample by sample, and the ratio at the end.

use super::measure::{ratio_of, reciprocal_of_count, resistance_of};
use super::{GainCalibration, GainCalibrationCommand, GainCalibrationStatus, Stage};
use crate::{Ab, Real};

impl<T: Real> GainCalibration<T> {
    /// Starts the sequence along the axis at `angle` (the aligned rotor's d axis): skipped
    /// at once (no current) when unobservable. Returns whether it runs.
    pub fn start(&mut self, angle: T) -> bool {
        self.hold_samples = self.hold_default;
        self.unsettled = false;
        self.start_held(angle)
    }

    /// [`start`](Self::start) along an axis whose current settles more slowly than the
    /// configuration's: each level is held at least `hold_time` (s). Beyond `max_hold_time`
    /// the levels are held that long and only k is measured: the upper level is a voltage
    /// step whose unsettled residue scales both phases alike (k keeps none of it) but biases
    /// the resistance, which is then NaN. A non-finite `hold_time` skips the calibration as
    /// too slow.
    pub fn start_with_hold(&mut self, angle: T, hold_time: T) -> bool {
        // NaN compares false: too slow.
        if !(hold_time >= T::zero() && hold_time.is_finite()) {
            self.stage = Stage::Idle;
            self.status = GainCalibrationStatus::TooSlow;
            return false;
        }
        let max_hold = self.config.max_hold_time;
        self.unsettled = hold_time > max_hold;
        let n = hold_time.step_min(max_hold) / self.config.ts;
        // Rounded in `T` (n ≥ 0): no double-precision conversion in the firmware's step.
        let n = (n + T::lit(0.5)).index_floor(u32::MAX as usize) as u32;
        self.hold_samples = self.hold_default.max(n);
        self.start_held(angle)
    }

    fn start_held(&mut self, angle: T) -> bool {
        if self.window_samples == 0 {
            self.status = GainCalibrationStatus::Off;
            return false;
        }
        if self.too_slow {
            self.stage = Stage::Idle;
            self.status = GainCalibrationStatus::TooSlow;
            return false;
        }
        // The window the swing needs along this axis (∞ where phase a or b carries nothing);
        // NaN compares false: too slow.
        let swing = if self.config.swing_window_time <= T::zero() {
            T::zero()
        } else {
            self.config.swing_window_time * self.swing_window_share(angle)
        };
        let within = swing <= self.config.max_hold_time;
        if !within {
            self.stage = Stage::Idle;
            self.status = GainCalibrationStatus::TooSlow;
            return false;
        }
        let n = swing / self.config.ts;
        // Rounded in `T` (n ≥ 0): no double-precision conversion in the firmware's step.
        let n = (n + T::lit(0.5)).index_floor(u32::MAX as usize) as u32;
        self.window_run = self.window_samples.max(n);
        // The whole sequence along this axis within `max_time`, else not run.
        if self.duration_samples() > self.max_samples {
            self.stage = Stage::Idle;
            self.status = GainCalibrationStatus::TooSlow;
            return false;
        }
        let share = Self::observability(angle);
        // NaN compares false: a non-finite angle is unobservable too.
        if !(share >= self.config.min_observability && share > T::zero()) {
            self.stage = Stage::Idle;
            self.status = GainCalibrationStatus::Unobservable;
            return false;
        }
        let (s, c) = angle.step_sin_cos_any();
        self.axis = Ab::new(c, s);
        self.sum_i = [Ab::zero(); 2];
        self.sum_v = [Ab::zero(); 2];
        self.count = [0; 2];
        self.aborted = false;
        self.moved_in_release = false;
        self.cross_ref = T::zero();
        self.cross_filtered = T::zero();
        self.cross_v_ref = T::zero();
        self.cross_v_filtered = T::zero();
        self.motion_flux = T::zero();
        self.motion_current = T::zero();
        self.motion_emf = T::zero();
        self.noise_floor = T::zero();
        self.motion_peak = T::zero();
        self.loop_motion_peak = T::zero();
        self.loop_window_peak = T::zero();
        self.v_lower = Ab::zero();
        self.v_lower_count = 0;
        self.stage = Stage::Settle;
        self.remaining = self.settle_samples;
        self.status = GainCalibrationStatus::Running;
        true
    }

    /// The command of the present stage.
    pub fn command(&self) -> GainCalibrationCommand<T> {
        let i1 = self.config.current;
        match self.stage {
            Stage::Settle => GainCalibrationCommand {
                current_d: i1,
                voltage: None,
            },
            Stage::HoldUpper | Stage::AverageUpper => GainCalibrationCommand {
                current_d: i1 + i1,
                voltage: Some(self.v_lower + self.axis * (self.config.rs_hat * i1)),
            },
            Stage::HoldLower | Stage::AverageLower => GainCalibrationCommand {
                current_d: i1,
                voltage: Some(self.v_lower),
            },
            Stage::Idle | Stage::Release => GainCalibrationCommand {
                current_d: T::zero(),
                voltage: None,
            },
        }
    }

    /// One sample while running: `i_ab` the measured current now (offsets removed, no gain
    /// correction), `v_ab` the voltage that acted over the last sampling period (the drive's
    /// realised reference). Returns what to apply at this sample. A non-finite pair is left
    /// out of the averages; every sample advances the sequence, so it always ends (after
    /// [`duration_samples`](Self::duration_samples) at most).
    pub fn step(&mut self, i_ab: Ab<T>, v_ab: Ab<T>) -> GainCalibrationCommand<T> {
        self.step_with_inverter(i_ab, v_ab, Ab::zero())
    }

    /// [`step`](Self::step) on a real inverter: `inverter` is what the inverter added to the
    /// realised reference `v_ab` over the last period as the drive models it (its dead-time
    /// compensation less the loss its model gives at the measured current; zero for an
    /// ideal inverter). The rotor-motion test reads the back-EMF from the voltage that acted,
    /// `v_ab + inverter`, in every stage (module docs, "Rotor motion"); the levels' averages
    /// take `v_ab` alone, whose inverter error cancels between them.
    pub fn step_with_inverter(
        &mut self,
        i_ab: Ab<T>,
        v_ab: Ab<T>,
        inverter: Ab<T>,
    ) -> GainCalibrationCommand<T> {
        if self.status != GainCalibrationStatus::Running {
            return GainCalibrationCommand {
                current_d: T::zero(),
                voltage: None,
            };
        }
        let finite = i_ab.is_finite() && v_ab.is_finite();
        let voltage_mode = !matches!(self.stage, Stage::Settle | Stage::Release | Stage::Idle);
        // NaN compares false: a non-finite current in voltage mode does not abort by itself.
        if voltage_mode && i_ab.norm() > self.config.current_limit {
            self.aborted = true;
            self.stage = Stage::Release;
            self.remaining = self.settle_samples;
        }
        // Rotor motion: a turning rotor's back-EMF lies across the axis (where the rotor's
        // q axis lies). With the voltage frozen it drives a current across it; with the
        // current loop holding the current, the loop's voltage across it follows the
        // back-EMF. At rest both stay where they were at the stage's first sample.
        let emf = if finite && inverter.is_finite() {
            self.motion_emf(i_ab, v_ab, inverter, voltage_mode)
        } else {
            T::zero()
        };
        let window = if finite && inverter.is_finite() && !voltage_mode {
            self.window_emf(emf)
        } else {
            T::zero()
        };
        if emf.abs() > self.motion_threshold(voltage_mode)
            || window.abs() > self.config.motion_voltage * T::lit(super::LOOP_WINDOW_FACTOR)
        {
            self.end_moving(emf);
            return GainCalibrationCommand {
                current_d: T::zero(),
                voltage: None,
            };
        }
        let level = match self.stage {
            Stage::AverageLower => Some(0),
            Stage::AverageUpper => Some(1),
            _ => None,
        };
        if let Some(level) = level
            && finite
        {
            self.sum_i[level] += i_ab;
            self.sum_v[level] += v_ab;
            self.count[level] += 1;
        }
        if self.stage == Stage::Settle && self.remaining <= self.settle_samples / 2 && finite {
            // The current loop's voltage at I₁, averaged over the second half of its settling
            // (the loop's response to the current noise averages out), becomes V₁.
            self.v_lower += v_ab;
            self.v_lower_count += 1;
        }
        if self.stage == Stage::Settle && self.remaining <= 1 {
            self.v_lower = if self.v_lower_count > 0 {
                self.v_lower * reciprocal_of_count::<T>(self.v_lower_count)
            } else {
                self.axis * (self.config.rs_hat * self.config.current)
            };
        }
        self.remaining = self.remaining.saturating_sub(1);
        while self.remaining == 0 && self.stage != Stage::Idle {
            self.advance();
        }
        self.command()
    }

    fn advance(&mut self) {
        let (next, samples) = match self.stage {
            Stage::Settle => (Stage::HoldLower, self.hold_samples),
            Stage::HoldLower => (Stage::AverageLower, self.window_run),
            Stage::AverageLower => (Stage::HoldUpper, self.hold_samples),
            Stage::HoldUpper => (Stage::AverageUpper, self.window_run),
            Stage::AverageUpper => (Stage::Release, self.settle_samples),
            Stage::Release | Stage::Idle => {
                self.stage = Stage::Idle;
                self.finish();
                return;
            }
        };
        self.stage = next;
        self.remaining = samples;
    }

    /// Ends the run [`GainCalibrationStatus::RotorMoved`] on the back-EMF `emf` (V). In the
    /// release both levels are averaged, with the rotor at rest (the test watched them):
    /// their result stands ([`GainCalibration::moved_in_release`]).
    fn end_moving(&mut self, emf: T) {
        self.motion_current = self.command().current_d;
        self.motion_emf = emf;
        self.moved_in_release = self.stage == Stage::Release && !self.aborted;
        if self.moved_in_release {
            self.finish();
            if self.status != GainCalibrationStatus::Calibrated {
                self.resistance = T::zero() / T::zero();
            }
        } else {
            self.measured = T::zero() / T::zero();
        }
        self.stage = Stage::Idle;
        self.status = GainCalibrationStatus::RotorMoved;
    }

    /// The ratio from the two levels' averages, or why not.
    fn finish(&mut self) {
        self.measured = T::zero() / T::zero();
        let min_count = (self.window_run / 2).max(1);
        if self.aborted || self.count[0] < min_count || self.count[1] < min_count {
            self.status = GainCalibrationStatus::Implausible;
            return;
        }
        let inv = [
            reciprocal_of_count::<T>(self.count[0]),
            reciprocal_of_count::<T>(self.count[1]),
        ];
        let di = self.sum_i[1] * inv[1] - self.sum_i[0] * inv[0];
        let dv = self.sum_v[1] * inv[1] - self.sum_v[0] * inv[0];
        match ratio_of(di, dv, self.config.min_observability) {
            Some(k) => {
                self.measured = k;
                if (k - T::one()).abs() <= self.config.max_mismatch {
                    self.ratio = k;
                    self.resistance = if self.unsettled {
                        T::zero() / T::zero()
                    } else {
                        resistance_of(di, dv, k)
                    };
                    self.status = GainCalibrationStatus::Calibrated;
                } else {
                    self.status = GainCalibrationStatus::Implausible;
                }
            }
            None => self.status = GainCalibrationStatus::Implausible,
        }
    }
}
