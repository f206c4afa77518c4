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
#[inline]
pub fn wrap_angle<T: Real>(x: T) -> T {
    let two_pi = T::two_pi();
    x - two_pi * (x / two_pi).round()
}
