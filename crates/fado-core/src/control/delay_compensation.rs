//! Compensation of the digital delay (paper IV-B, after ref. \[13\]; SPEC §5):
//! v*_ab\[n\] = e^{j(θ̂\[n\] + k·ω̂·Ts)}·v*_dq\[n\], k = 1.5 by default.
//!
//! The reference computed at sample n is loaded at n+1 and held until n+2 (one sample of
//! computation), so on average it acts 1.5 samples after the angle θ̂\[n\] it was computed
//! with. Rotating it by the angle the rotor turns meanwhile makes the d-q voltage the current
//! controller asked for arrive in the d-q frame it meant; without it the voltage lags by
//! 1.5·ω·Ts (0.094 rad at 1500 r/min), which couples the axes and, in the estimator, rotates
//! the integrand.

use crate::error::{ConfigError, check};
use crate::{Ab, Dq, Real, Rotation, wrap_angle};

/// Configuration of a [`DelayCompensation`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DelayCompensationConfig<T> {
    /// Sampling period Ts in s. Default 100 µs (paper, V).
    pub ts: T,
    /// Advance in samples k: 1 of computation + ½ of PWM hold. Default 1.5 (SPEC §5 \[A\]);
    /// 0 switches the compensation off.
    pub factor: T,
}

impl<T: Real> Default for DelayCompensationConfig<T> {
    fn default() -> Self {
        Self {
            ts: T::lit(100e-6),
            factor: T::lit(1.5),
        }
    }
}

/// The angle advance of SPEC §5 (module docs). Stateless.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DelayCompensation<T> {
    config: DelayCompensationConfig<T>,
    advance_per_omega: T,
}

impl<T: Real> DelayCompensation<T> {
    /// A new compensation; `factor` must be in [0, 10].
    pub fn new(config: DelayCompensationConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        let k = check::non_negative("factor", config.factor)?;
        if k > T::lit(10.0) {
            return Err(ConfigError::OutOfRange {
                field: "factor",
                expected: "at most 10 samples",
            });
        }
        Ok(Self {
            config,
            advance_per_omega: k * ts,
        })
    }

    /// No state.
    pub fn reset(&mut self) {}

    /// θ̂ + k·ω̂·Ts, wrapped to [−π, π]: the angle the reference computed now will act at.
    #[inline]
    pub fn angle(&self, theta: T, omega: T) -> T {
        wrap_angle(theta + self.advance_per_omega * omega)
    }

    /// v*_ab = e^{j(θ̂ + k·ω̂·Ts)}·v*_dq, returned with the rotation used (to take the realised
    /// voltage back into d-q for the anti-windup).
    #[inline]
    pub fn step(&self, v_dq: Dq<T>, theta: T, omega: T) -> (Ab<T>, Rotation<T>) {
        let rot = Rotation::from_angle(self.angle(theta, omega));
        (v_dq.to_ab(rot), rot)
    }

    /// The configuration in use.
    pub fn config(&self) -> &DelayCompensationConfig<T> {
        &self.config
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advances_by_one_and_a_half_samples() {
        let dc = DelayCompensation::new(DelayCompensationConfig::<f64>::default()).unwrap();
        let w = 2.0 * core::f64::consts::PI * 100.0;
        let (v, rot) = dc.step(Dq::new(0.0, 10.0), 0.3, w);
        let expected = 0.3 + 1.5 * w * 100e-6;
        assert!((v.norm() - 10.0).abs() < 1e-12);
        assert!((v.angle() - (expected + core::f64::consts::FRAC_PI_2)).abs() < 1e-12);
        assert!((rot.sin - expected.sin()).abs() < 1e-15);
        // Wraps through ±π.
        assert!((dc.angle(3.1, 1000.0) - (3.1 + 0.15 - 2.0 * core::f64::consts::PI)).abs() < 1e-12);
        let off = DelayCompensation::new(DelayCompensationConfig {
            ts: 100e-6,
            factor: 0.0,
        })
        .unwrap();
        assert_eq!(off.angle(0.3, w), 0.3);
        assert_eq!(
            DelayCompensation::new(DelayCompensationConfig {
                ts: 100e-6,
                factor: -1.0
            })
            .unwrap_err()
            .field(),
            "factor"
        );
    }
}
