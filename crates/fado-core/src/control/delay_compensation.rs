//! Compensation of the digital delay (paper IV-B, after ref. \[13\]; docs/method/estimator.md §7):
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

/// Default advance in samples: 1 of computation + ½ of PWM hold (docs/method/estimator.md §7
/// \[A\], ref. \[13\]).
pub const DEFAULT_FACTOR: f64 = 1.5;

/// Configuration of a [`DelayCompensation`].
///
/// No `Default`: Ts is the set-up's. Build it with [`with_ts`](Self::with_ts).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DelayCompensationConfig<T> {
    /// Sampling period Ts in s (paper, V: 100 µs). No default: the set-up's.
    pub ts: T,
    /// Advance in samples k: 1 of computation + ½ of PWM hold. Default [`DEFAULT_FACTOR`] (1.5,
    /// docs/method/estimator.md §7 \[A\]);
    /// 0 switches the compensation off.
    pub factor: T,
}

impl<T: Real> DelayCompensationConfig<T> {
    /// The compensation sampled every `ts` with the default advance of 1.5 samples
    /// ([`DEFAULT_FACTOR`]).
    pub fn with_ts(ts: T) -> Self {
        Self {
            ts,
            factor: T::lit(DEFAULT_FACTOR),
        }
    }
}

/// The angle advance of docs/method/estimator.md §7 (module docs). Stateless.
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

    /// As [`step`](Self::step), reusing the rotation by θ̂ that the caller already has (the
    /// Park transform of the currents): e^{j(θ̂ + δ)} = e^{jθ̂}·e^{jδ} with δ = factor·ω̂·Ts.
    /// For |δ| ≤ 0.25 rad (|f̂| ≤ 265 Hz electrical at the defaults, 2.6× rated) e^{jδ} comes
    /// from its Taylor series to δ⁷ (error < 0.25⁸/8! ≈ 4e-10 in f64, below f32 resolution),
    /// which saves one sin/cos per sample; beyond, it falls back to `step`. `rot_theta` must be
    /// `Rotation::from_angle(theta)`.
    #[inline]
    pub fn step_rotated(
        &self,
        v_dq: Dq<T>,
        rot_theta: Rotation<T>,
        theta: T,
        omega: T,
    ) -> (Ab<T>, Rotation<T>) {
        let d = self.advance_per_omega * omega;
        if d.abs() > T::lit(0.25) {
            return self.step(v_dq, theta, omega);
        }
        let d2 = d * d;
        let c = T::lit(1.0 / 720.0);
        let cos_d = T::one() - d2 * (T::lit(0.5) - d2 * (T::lit(1.0 / 24.0) - d2 * c));
        let sin_d = d
            * (T::one()
                - d2 * (T::lit(1.0 / 6.0)
                    - d2 * (T::lit(1.0 / 120.0) - d2 * T::lit(1.0 / 5040.0))));
        let rot = Rotation {
            cos: rot_theta.cos * cos_d - rot_theta.sin * sin_d,
            sin: rot_theta.sin * cos_d + rot_theta.cos * sin_d,
        };
        (v_dq.to_ab(rot), rot)
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
    fn reused_rotation_matches_the_direct_one() {
        let dc = DelayCompensation::new(DelayCompensationConfig::<f64>::with_ts(100e-6)).unwrap();
        let v = Dq::new(3.0, -7.0);
        // Polynomial branch up to |δ| = 0.25 (ω = 0.25 / 150 µs) and the fallback beyond.
        for &w in &[
            0.0, 50.0, -700.0, 1666.0, -1666.6, 1667.0, 5000.0, -20_000.0,
        ] {
            for &theta in &[-3.0, -1.0, 0.0, 0.7, 3.1] {
                let (a, ra) = dc.step(v, theta, w);
                let (b, rb) = dc.step_rotated(v, Rotation::from_angle(theta), theta, w);
                assert!((a - b).norm() < 1e-8, "w {w} θ {theta}: {a:?} vs {b:?}");
                assert!((ra.cos - rb.cos).abs() < 1e-9 && (ra.sin - rb.sin).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn advances_by_one_and_a_half_samples() {
        let dc = DelayCompensation::new(DelayCompensationConfig::<f64>::with_ts(100e-6)).unwrap();
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
