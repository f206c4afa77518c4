//! Selection between the two flux feedbacks by speed (paper, section V: k_df above 1.5 Hz
//! electrical, the limiter k_af below), with hysteresis so that noise on ω̂ cannot chatter.

use crate::error::{ConfigError, check};
use crate::{MachineModel, Real};

/// Which feedback closes the flux integrator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mode {
    /// |f̂| below the threshold: the flux limiter of Fig. 6 (FLAG_limit high).
    #[default]
    Limiter,
    /// |f̂| above the threshold: the disturbance feedback k_df of Fig. 3.
    DisturbanceFeedback,
}

/// Default Fig. 3 threshold as a fraction of the rated electrical frequency: 0.015 (paper,
/// section V: 1.5 Hz of its motor's 100 Hz).
pub const DEFAULT_THRESHOLD_RATIO: f64 = 0.015;

/// Default hysteresis half-band as a fraction of the rated electrical frequency: 0.002
/// (docs/method/estimator.md §1 \[A\]: 0.2 Hz of 100 Hz).
pub const DEFAULT_HYSTERESIS_RATIO: f64 = 0.002;

/// Configuration of a [`ModeSelector`].
///
/// No `Default`: the threshold scales with the motor's rated speed. Build it with
/// [`for_machine`](Self::for_machine); each field's "Default" is what it gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeSelectorConfig<T> {
    /// Threshold on |ω̂|/2π in Hz, electrical. Default 0.015 of the rated electrical
    /// frequency ([`DEFAULT_THRESHOLD_RATIO`]; paper, section V: 1.5 Hz of its motor's
    /// 100 Hz).
    pub threshold_hz: T,
    /// Half-width of the hysteresis band in Hz: enter above threshold + h, leave below
    /// threshold − h. Default 0.002 of the rated electrical frequency
    /// ([`DEFAULT_HYSTERESIS_RATIO`]; docs/method/estimator.md §1 \[A\]: 0.2 Hz on the paper's
    /// motor).
    pub hysteresis_hz: T,
}

impl<T: Real> ModeSelectorConfig<T> {
    /// The selector for `machine` with the default ratios: threshold 0.015 and hysteresis
    /// 0.002 of the rated electrical frequency (1.5 Hz and 0.2 Hz on the paper's motor:
    /// paper V, docs/method/estimator.md §1 \[A\]).
    pub fn for_machine(machine: &MachineModel<T>) -> Self {
        Self::new(
            machine,
            T::lit(DEFAULT_THRESHOLD_RATIO),
            T::lit(DEFAULT_HYSTERESIS_RATIO),
        )
    }

    /// The selector for `machine` with `threshold_ratio` and `hysteresis_ratio` times
    /// [`MachineModel::rated_frequency_hz`].
    pub fn new(machine: &MachineModel<T>, threshold_ratio: T, hysteresis_ratio: T) -> Self {
        let rated_hz = machine.rated_frequency_hz();
        Self {
            threshold_hz: threshold_ratio * rated_hz,
            hysteresis_hz: hysteresis_ratio * rated_hz,
        }
    }
}

/// The selector's constants: the speeds (rad/s) at which it enters and leaves the k_df mode
/// (the immutable half of [`ModeSelector`]; its state is the [`Mode`] alone).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ModeSelectorParams<T> {
    enter: T,
    leave: T,
}

impl<T: Real> ModeSelectorParams<T> {
    /// The bounds of `config`, checked.
    pub(crate) fn new(config: ModeSelectorConfig<T>) -> Result<Self, ConfigError> {
        let th = check::non_negative("threshold_hz", config.threshold_hz)?;
        let h = check::non_negative("hysteresis_hz", config.hysteresis_hz)?;
        if h > th {
            return Err(ConfigError::OutOfRange {
                field: "hysteresis_hz",
                expected: "at most threshold_hz",
            });
        }
        Ok(Self {
            enter: T::two_pi() * (th + h),
            leave: T::two_pi() * (th - h),
        })
    }

    /// The threshold and the hysteresis half-band, Hz (from the stored bounds, to rounding).
    pub(crate) fn threshold_hz(&self) -> (T, T) {
        let two = T::lit(2.0) * T::two_pi();
        (
            (self.enter + self.leave) / two,
            (self.enter - self.leave) / two,
        )
    }

    /// The mode after `mode` for the speed estimate ω̂ (rad/s, electrical, signed).
    #[inline(always)]
    pub(crate) fn next_mode(&self, mode: Mode, omega: T) -> Mode {
        let w = omega.abs();
        match mode {
            Mode::Limiter if w > self.enter => Mode::DisturbanceFeedback,
            Mode::DisturbanceFeedback if w < self.leave => Mode::Limiter,
            m => m,
        }
    }
}

/// Hysteretic speed comparator choosing [`Mode`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeSelector<T> {
    params: ModeSelectorParams<T>,
    mode: Mode,
}

impl<T: Real> ModeSelector<T> {
    /// A new selector, starting in [`Mode::Limiter`].
    pub fn new(config: ModeSelectorConfig<T>) -> Result<Self, ConfigError> {
        Ok(Self {
            params: ModeSelectorParams::new(config)?,
            mode: Mode::Limiter,
        })
    }

    /// The threshold and the hysteresis half-band, Hz (from the stored bounds, to rounding).
    pub fn threshold_hz(&self) -> (T, T) {
        self.params.threshold_hz()
    }

    /// Back to [`Mode::Limiter`].
    pub fn reset(&mut self) {
        self.mode = Mode::Limiter;
    }

    /// One sample with the speed estimate ω̂ (rad/s, electrical, signed).
    #[inline]
    pub fn step(&mut self, omega: T) -> Mode {
        self.mode = self.params.next_mode(self.mode, omega);
        self.mode
    }

    /// The current mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::TAU;

    #[test]
    fn hysteresis() {
        // The paper's motor: 100 Hz rated, threshold 1.5 Hz, hysteresis 0.2 Hz (paper, V).
        let paper = ModeSelectorConfig::<f64>::for_machine(&MachineModel::paper());
        let mut s = ModeSelector::new(paper).unwrap();
        assert_eq!(s.step(TAU * 1.6), Mode::Limiter);
        assert_eq!(s.step(-TAU * 1.71), Mode::DisturbanceFeedback);
        assert_eq!(s.step(TAU * 1.31), Mode::DisturbanceFeedback);
        assert_eq!(s.step(TAU * 1.29), Mode::Limiter);
        // A 6-pole motor rated 1500 r/min: 75 Hz, so 1.125 Hz ± 0.15 Hz (the same ratios).
        let six_pole = MachineModel {
            pole_pairs: 3,
            ..MachineModel::paper()
        };
        let c = ModeSelectorConfig::<f64>::for_machine(&six_pole);
        assert!((c.threshold_hz - 1.125).abs() < 1e-12 && (c.hysteresis_hz - 0.15).abs() < 1e-12);
        let mut s = ModeSelector::new(c).unwrap();
        assert_eq!(s.step(TAU * 1.26), Mode::Limiter);
        assert_eq!(s.step(TAU * 1.29), Mode::DisturbanceFeedback);
        assert_eq!(s.step(-TAU * 0.99), Mode::DisturbanceFeedback);
        assert_eq!(s.step(TAU * 0.96), Mode::Limiter);
    }
}
