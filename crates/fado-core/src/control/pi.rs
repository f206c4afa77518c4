//! A discrete PI controller with output limits and back-calculation anti-windup: the building
//! block of the current and speed loops of Fig. 5.
//!
//! Per sample, with error e and an optional feed-forward f:
//!
//! ```text
//! u = Kp·e + I + f            (unlimited output, integral of the previous sample)
//! y = clamp(u, min, max)      (output)
//! I ← I + Ts·(Ki·e + K_aw·(y − u))
//! ```
//!
//! **Anti-windup: back-calculation**, not conditional integration. Reason: the limits that
//! matter in a drive are usually applied *outside* the PI — the current PIs are limited by the
//! inverter hexagon in the α-β frame, after rotation, delay and dead-time compensation, and
//! the q-current by the |i_dq*| ≤ I_max circle after the d-axis injection of eq. (23). There
//! is no per-axis "saturated" flag for a vector limit to freeze an integrator on, but there
//! always is a realised value: [`Pi::realised`] feeds it back, exactly as the internal clamp
//! does, so one mechanism covers both.
//!
//! The tracking gain is K_aw = r·Ki/Kp with `anti_windup_ratio` r. With r = 1 the update
//! becomes I ← I + Ts·(Ki/Kp)·(y − f − I): the integral relaxes monotonically towards the
//! value that realises the limited output with zero error and can never wind beyond it
//! (the "realisable reference" of Harnefors/Nee, K_a = 1/Kp in Sul's textbook) \[A\].
//! r > 1 tracks faster (the output leaves the limit earlier, less overshoot); r = 0 disables
//! anti-windup. The discrete update is a contraction for K_aw·Ts ≤ 1, which `new` enforces.

use crate::Real;
use crate::error::{ConfigError, NonFiniteInput, check};

/// Configuration of a [`Pi`].
///
/// No `Default`: every field is the loop's (the current and speed controllers set theirs from
/// docs/method/estimator.md, "The paper's motor and drive" and the machine model).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PiConfig<T> {
    /// Sampling period Ts in s (paper, V: 100 µs, 10 kHz sampling).
    pub ts: T,
    /// Proportional gain Kp (> 0).
    pub kp: T,
    /// Integral gain Ki in s⁻¹ (≥ 0).
    pub ki: T,
    /// Lower output limit.
    pub output_min: T,
    /// Upper output limit (> `output_min`).
    pub output_max: T,
    /// Back-calculation gain as a multiple r of Ki/Kp (≥ 0, with r·Ki/Kp·Ts ≤ 1). 1 is the
    /// realisable-reference setting: the integral never winds beyond the limit \[A\].
    pub anti_windup_ratio: T,
}

/// Discrete PI controller with limits and back-calculation anti-windup (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pi<T> {
    config: PiConfig<T>,
    ki_ts: T,
    k_aw_ts: T,
    integral: T,
    /// The output returned by the last `step` (after any later `realised`).
    output: T,
}

impl<T: Real> Pi<T> {
    /// A new controller with zero integral; every field is checked and a bad one named.
    pub fn new(config: PiConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        let kp = check::positive("kp", config.kp)?;
        let ki = check::non_negative("ki", config.ki)?;
        let lo = check::finite("output_min", config.output_min)?;
        let hi = check::finite("output_max", config.output_max)?;
        if hi <= lo {
            return Err(ConfigError::OutOfRange {
                field: "output_max",
                expected: "greater than output_min",
            });
        }
        let r = check::non_negative("anti_windup_ratio", config.anti_windup_ratio)?;
        let k_aw_ts = r * ki / kp * ts;
        if k_aw_ts > T::one() {
            return Err(ConfigError::OutOfRange {
                field: "anti_windup_ratio",
                expected: "anti_windup_ratio·ki/kp·ts at most 1",
            });
        }
        let ki_ts = ki * ts;
        if !(ki_ts.is_finite() && k_aw_ts.is_finite()) {
            return Err(ConfigError::NotFinite { field: "ki" });
        }
        Ok(Self {
            config,
            ki_ts,
            k_aw_ts,
            integral: T::zero(),
            output: T::zero(),
        })
    }

    /// Integral and remembered output back to zero.
    pub fn reset(&mut self) {
        self.integral = T::zero();
        self.output = T::zero();
    }

    /// Presets the integral (bumpless start), clamped to the output limits; a non-finite value
    /// is ignored.
    pub fn reset_to(&mut self, integral: T) {
        if integral.is_finite() {
            self.integral = clamp(integral, self.config.output_min, self.config.output_max);
        }
    }

    /// One sample with error `error` and feed-forward `feedforward`. Returns the limited
    /// output. A non-finite input, or one so large that the output overflows, is rejected
    /// with the state untouched.
    #[inline]
    pub fn step(&mut self, error: T, feedforward: T) -> Result<T, NonFiniteInput> {
        let u = self.config.kp * error + self.integral + feedforward;
        if !(u.is_finite() && error.is_finite()) {
            return Err(NonFiniteInput);
        }
        let y = clamp(u, self.config.output_min, self.config.output_max);
        let integral = self.integral + self.ki_ts * error + self.k_aw_ts * (y - u);
        if !integral.is_finite() {
            return Err(NonFiniteInput);
        }
        self.integral = integral;
        self.output = y;
        Ok(y)
    }

    /// Anti-windup for a limit applied *after* this PI: `realised` is what became of the
    /// output the last `step` returned. Back-calculates I ← I + K_aw·Ts·(realised − output)
    /// — the same correction the internal clamp applies, so calling it once per sample after
    /// `step` is equivalent to the PI having had that limit itself. Ignored if not finite.
    #[inline]
    pub fn realised(&mut self, realised: T) {
        if realised.is_finite() {
            let integral = self.integral + self.k_aw_ts * (realised - self.output);
            if integral.is_finite() {
                self.integral = integral;
                self.output = realised;
            }
        }
    }

    /// The integral state I.
    pub fn integral(&self) -> T {
        self.integral
    }

    /// The output of the last `step` (or the value passed to `realised` after it).
    pub fn output(&self) -> T {
        self.output
    }

    /// The configuration in use.
    pub fn config(&self) -> &PiConfig<T> {
        &self.config
    }
}

/// `x` clamped to [lo, hi] (lo ≤ hi assumed); NaN-free inputs only.
#[inline]
pub(crate) fn clamp<T: Real>(x: T, lo: T, hi: T) -> T {
    if x < lo {
        lo
    } else if x > hi {
        hi
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pi(kp: f64, ki: f64, lim: f64, r: f64) -> Pi<f64> {
        Pi::new(PiConfig {
            ts: 1e-3,
            kp,
            ki,
            output_min: -lim,
            output_max: lim,
            anti_windup_ratio: r,
        })
        .unwrap()
    }

    #[test]
    fn linear_region_is_textbook_pi() {
        let mut c = pi(2.0, 10.0, 100.0, 1.0);
        // u = Kp·e + I; I += Ki·Ts·e
        assert_eq!(c.step(1.0, 0.5).unwrap(), 2.5);
        assert!((c.integral() - 0.01).abs() < 1e-15);
        assert!((c.step(1.0, 0.0).unwrap() - 2.01).abs() < 1e-15);
    }

    #[test]
    fn realisable_reference_never_winds_beyond_limit() {
        // r = 1: I relaxes monotonically to (limit − feed-forward) however long the error lasts.
        let mut c = pi(1.0, 50.0, 1.0, 1.0);
        let mut prev = c.integral();
        for _ in 0..5000 {
            assert_eq!(c.step(10.0, 0.0).unwrap(), 1.0);
            assert!(c.integral() >= prev && c.integral() <= 1.0 + 1e-12);
            prev = c.integral();
        }
        assert!((c.integral() - 1.0).abs() < 1e-9);
        // Without anti-windup the same run winds up to Ki·∫e = 2500.
        let mut naive = pi(1.0, 50.0, 1.0, 0.0);
        for _ in 0..5000 {
            naive.step(10.0, 0.0).unwrap();
        }
        assert!((naive.integral() - 2500.0).abs() < 1e-6);
    }

    /// An integrating plant y' = u (a rigid rotor) with an actuator limit of 1 and a step of
    /// 2, which keeps the PI saturated for about two seconds. Returns the overshoot relative to
    /// the step.
    fn step_overshoot(r: f64, step: f64) -> f64 {
        let ts = 1e-3;
        let mut c = Pi::new(PiConfig {
            ts,
            kp: 10.0,
            ki: 20.0, // zero at 2 rad/s, crossover ≈ 10 rad/s
            output_min: -1.0,
            output_max: 1.0,
            anti_windup_ratio: r,
        })
        .unwrap();
        let (mut y, mut peak) = (0.0_f64, 0.0_f64);
        for _ in 0..20_000 {
            y += ts * c.step(step - y, 0.0).unwrap();
            peak = peak.max(y);
        }
        assert!((y - step).abs() < 1e-6 * step, "settles, y = {y}");
        peak / step - 1.0
    }

    #[test]
    fn anti_windup_limits_overshoot_after_saturation() {
        // The linear loop (a step too small to saturate) overshoots by ≈ 12 % because of the
        // PI zero; that is the yardstick.
        let linear = step_overshoot(1.0, 0.01);
        assert!(linear > 0.05 && linear < 0.2, "{linear}");
        let realisable = step_overshoot(1.0, 2.0);
        let faster = step_overshoot(5.0, 2.0);
        let without = step_overshoot(0.0, 2.0);
        assert!(realisable < linear, "with anti-windup {realisable}");
        assert!(faster <= realisable);
        assert!(without > 4.0 * linear, "without {without}");
    }

    #[test]
    fn external_limit_back_calculates_like_internal_one() {
        let mut internal = pi(1.0, 20.0, 0.3, 1.0);
        let mut external = pi(1.0, 20.0, 100.0, 1.0);
        for k in 0..200 {
            let e = if k < 100 { 1.0 } else { -0.2 };
            let a = internal.step(e, 0.0).unwrap();
            let b = external.step(e, 0.0).unwrap();
            external.realised(clamp(b, -0.3, 0.3));
            assert!((a - clamp(b, -0.3, 0.3)).abs() < 1e-12);
            assert!((internal.integral() - external.integral()).abs() < 1e-12);
        }
    }

    #[test]
    fn rejects_bad_inputs_and_configs() {
        let mut c = pi(1.0, 1.0, 1.0, 1.0);
        c.step(0.5, 0.0).unwrap();
        let before = c;
        assert_eq!(c.step(f64::NAN, 0.0), Err(NonFiniteInput));
        assert_eq!(c.step(1.0, f64::INFINITY), Err(NonFiniteInput));
        assert_eq!(c.step(f64::MAX, f64::MAX), Err(NonFiniteInput));
        c.realised(f64::NAN);
        assert_eq!(c, before);
        let bad = |f: fn(&mut PiConfig<f64>)| {
            let mut cfg = PiConfig {
                ts: 100e-6,
                kp: 1.0,
                ki: 0.0,
                output_min: -1.0,
                output_max: 1.0,
                anti_windup_ratio: 1.0,
            };
            f(&mut cfg);
            Pi::new(cfg).unwrap_err().field()
        };
        assert_eq!(bad(|c| c.ts = 0.0), "ts");
        assert_eq!(bad(|c| c.kp = 0.0), "kp");
        assert_eq!(bad(|c| c.ki = -1.0), "ki");
        assert_eq!(bad(|c| c.output_min = f64::NAN), "output_min");
        assert_eq!(bad(|c| c.output_max = -2.0), "output_max");
        assert_eq!(bad(|c| c.anti_windup_ratio = -1.0), "anti_windup_ratio");
        assert_eq!(
            bad(|c| {
                c.ki = 1e5;
                c.anti_windup_ratio = 1.0
            }),
            "anti_windup_ratio"
        );
    }
}
