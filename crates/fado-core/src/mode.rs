//! Selection between the two flux feedbacks by speed (paper, section V: k_df above 1.5 Hz
//! electrical, the limiter k_af below), with hysteresis so that noise on ω̂ cannot chatter.

use crate::Real;
use crate::error::{ConfigError, check};

/// Which feedback closes the flux integrator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mode {
    /// |f̂| below the threshold: the flux limiter of Fig. 6 (FLAG_limit high).
    #[default]
    Limiter,
    /// |f̂| above the threshold: the disturbance feedback k_df of Fig. 3.
    DisturbanceFeedback,
}

/// Configuration of a [`ModeSelector`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeSelectorConfig<T> {
    /// Threshold on |ω̂|/2π in Hz, electrical. Default 1.5 Hz (paper, section V).
    pub threshold_hz: T,
    /// Half-width of the hysteresis band in Hz: enter above threshold + h, leave below
    /// threshold − h. Default 0.2 Hz (SPEC §1 \[A\]).
    pub hysteresis_hz: T,
}

impl<T: Real> Default for ModeSelectorConfig<T> {
    fn default() -> Self {
        Self {
            threshold_hz: T::lit(1.5),
            hysteresis_hz: T::lit(0.2),
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
        let mut s = ModeSelector::new(ModeSelectorConfig::<f64>::default()).unwrap();
        assert_eq!(s.step(TAU * 1.6), Mode::Limiter);
        assert_eq!(s.step(-TAU * 1.71), Mode::DisturbanceFeedback);
        assert_eq!(s.step(TAU * 1.31), Mode::DisturbanceFeedback);
        assert_eq!(s.step(TAU * 1.29), Mode::Limiter);
    }
}
