//! The scalar type every block is generic over: `f32` for firmware, `f64` for analysis.

use nalgebra::RealField;

/// A real scalar the estimator runs on: implemented for `f32` and `f64`.
///
/// It is nalgebra's [`RealField`] (whose transcendental functions come from `libm` in a
/// `no_std` build) plus a lossless way to write constants in generic code.
pub trait Real: RealField + Copy + Default {
    /// Converts an `f64` literal (a constant or default) into this scalar.
    fn lit(x: f64) -> Self;
    /// Converts this scalar to `f64` (for reporting and tests).
    fn to_f64(self) -> f64;
}

impl Real for f32 {
    #[inline(always)]
    fn lit(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
}

impl Real for f64 {
    #[inline(always)]
    fn lit(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
}

/// Wraps an angle into [−π, π]: `x − 2π·round(x / 2π)` (SPEC notation).
///
/// Every caller in the estimator wraps a sum of angles already in [−π, π] plus a small step,
/// so the argument lies within ±3π; there one exact subtraction (Sterbenz: |x| ≥ π = 2π/2)
/// gives the same result as the rounding formula without a call to `round`. Anything larger
/// takes the general formula; NaN stays NaN and ±∞ becomes NaN as with the formula.
#[inline]
pub fn wrap_angle<T: Real>(x: T) -> T {
    let pi = T::pi();
    let two_pi = T::two_pi();
    let three_pi = T::lit(3.0 * core::f64::consts::PI);
    if x > pi {
        if x <= three_pi {
            return x - two_pi;
        }
    } else if x < -pi {
        if x >= -three_pi {
            return x + two_pi;
        }
    } else {
        return x;
    }
    let r = x - two_pi * (x / two_pi).round();
    if r.abs() <= pi {
        return r;
    }
    // |x| beyond ~2^53·2π (f64) or ~2^24·2π (f32): the formula has lost all precision (found
    // by fuzzing: θ0 = 1e30 gave θ̂ = 1e15). The remainder is exact in IEEE arithmetic; the
    // angle is still arbitrary, but in range.
    let r = x % two_pi;
    if r > pi {
        r - two_pi
    } else if r < -pi {
        r + two_pi
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    #[test]
    fn wrap_agrees_with_the_rounding_formula() {
        let reference = |x: f64| x - 2.0 * PI * (x / (2.0 * PI)).round();
        for k in -4000..=4000 {
            let x = k as f64 * 0.00731 * PI;
            let w = wrap_angle(x);
            assert!((-PI..=PI).contains(&w), "{x} -> {w}");
            // Equal, or the two representations ±π of the same angle at a tie.
            let r = reference(x);
            assert!(w == r || (w.abs() - PI).abs() < 1e-12 && (r.abs() - PI).abs() < 1e-12);
            let wf = wrap_angle(x as f32);
            let rf = (x as f32)
                - 2.0
                    * core::f32::consts::PI
                    * ((x as f32) / (2.0 * core::f32::consts::PI)).round();
            assert!(
                (wf - rf).abs() < 1e-5 || (wf.abs() - core::f32::consts::PI).abs() < 1e-5,
                "{x}"
            );
        }
        // Huge but finite angles land in range too (fuzz regression: the formula alone gave
        // 1.1e15 for 9.1e30 and −6e234 for −5.7e250).
        for x in [
            9.112e30,
            -5.727778756618604e250,
            f64::MAX,
            -f64::MAX,
            1e17,
            3.0e15,
        ] {
            assert!((-PI..=PI).contains(&wrap_angle(x)), "{x}");
            let xf = x as f32;
            if xf.is_finite() {
                let w = wrap_angle(xf);
                assert!(
                    (-core::f32::consts::PI..=core::f32::consts::PI).contains(&w),
                    "{x}"
                );
            }
        }
        assert!(wrap_angle(f32::MAX).abs() <= core::f32::consts::PI);
        assert!(wrap_angle(f64::NAN).is_nan());
        assert!(wrap_angle(f64::INFINITY).is_nan());
        assert!(wrap_angle(f32::NEG_INFINITY).is_nan());
    }
}
