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
    /// ⌊self⌋ as an index, clamped to `0..=max` (negative and NaN give 0): one conversion
    /// instruction on a single-precision FPU, where `to_f64() as usize` is software double
    /// precision. For table lookups in the per-sample path.
    fn index_floor(self, max: usize) -> usize;
    /// [`index_floor`](Self::index_floor) (the same index for every `self`) for a `max`
    /// that is a constant of the caller's code: where it is 2ⁿ − 1, `f32`'s clamp is one
    /// saturation (`USAT` on a Cortex-M4F) instead of a compare and a select.
    #[inline(always)]
    fn index_floor_const(self, max: usize) -> usize {
        self.index_floor(max)
    }
    /// The index `k` as this scalar (exact up to 2^24 for `f32`), the inverse of
    /// [`index_floor`](Self::index_floor) on the nodes of a table.
    fn from_index(k: usize) -> Self;
    /// (sin x, cos x) for |x| ≤ π/2, as the estimator's step computes them: `libm` for `f64`,
    /// [`crate::approx::sin_cos`] for `f32` (no software double precision on a single-precision
    /// FPU; error below 2e-7).
    fn step_sin_cos(self) -> (Self, Self);
    /// (sin x, cos x) for any x, as the drive's Park transforms compute it
    /// (`Rotation::from_angle`): `libm` for `f64`, [`crate::approx::sin_cos_any`] for `f32`
    /// (error below 2.5e-7 up to ±3π).
    fn step_sin_cos_any(self) -> (Self, Self);
    /// 1 − e^{−y} for y ≥ 0, as the estimator's step computes it: `libm`'s `exp_m1` for `f64`,
    /// [`crate::approx::one_minus_exp_neg`] for `f32` (error below 1.5e-7).
    fn step_one_minus_exp_neg(self) -> Self;
    /// atan2(self, x), as the estimator's step computes it: `libm` for `f64`,
    /// [`crate::approx::atan2`] for `f32` (error below 2.2e-6 rad).
    fn step_atan2(self, x: Self) -> Self;
    /// √x for x ≥ 0, as the estimator's step computes it: `libm` for `f64`,
    /// [`crate::approx::sqrt`] for `f32` (within 1 ulp).
    fn step_sqrt(self) -> Self;
    /// The larger of `self` and `y`, as the drive's step computes it: `f64`'s `max` (IEEE
    /// maxNum, a NaN operand ignored); for `f32` a compare and a select (`real::max`: `if self > y`),
    /// which gives `y` when either is NaN. On a Cortex-M4F (no VMAXNM) `f32::max` is a call of
    /// `libm`'s `fmaxf`, 10–20 cycles; the select is 2–3 (docs/results/firmware-cost.md).
    fn step_max(self, y: Self) -> Self;
    /// The smaller of `self` and `y`: as [`Real::step_max`] (`f32`: `if self < y`).
    fn step_min(self, y: Self) -> Self;
    /// How the T2S trackers keep their angles ([`crate::tracker`]): `f64` as a float in
    /// [−π, π] wrapped by [`wrap_angle`] (the paper's recursion as written), `f32` as wrapping
    /// fixed point, an `i32` with 2³² units = 2π, wrapped by integer overflow (no compare or
    /// branch per wrap on a Cortex-M4F; resolution 1.46e-9 rad, finer than an `f32` ulp of π).
    type Angle: Copy + core::fmt::Debug + PartialEq + Default;
    /// An angle in [−π, π] as a tracker angle (`f32`: saturating beyond ±π).
    fn angle_from(x: Self) -> Self::Angle;
    /// A tracker angle in rad, in [−π, π].
    fn angle_to(a: Self::Angle) -> Self;
    /// wrap(a − b) in rad.
    fn angle_diff(a: Self::Angle, b: Self::Angle) -> Self;
    /// wrap(a + d) for a step |d| ≤ π (`f32`: saturating at ±π beyond; `f64`: exact up to
    /// ±2π, see [`wrap_angle`]).
    fn angle_add(a: Self::Angle, d: Self) -> Self::Angle;
    /// Radians per tracker angle unit (`f32`: 2π/2³²; `f64`: 1, its angles are radians).
    /// The trackers fold it into their gains ([`crate::tracker`]), so that a step converts
    /// no phase error and no increment between radians and units.
    fn angle_unit() -> Self;
    /// Tracker angle units per radian, 1/[`Self::angle_unit`] (`f32`: 2³²/2π; `f64`: 1).
    fn angle_units_per_rad() -> Self;
    /// wrap(a − b) in tracker angle units ([`Self::angle_diff`] / [`Self::angle_unit`]).
    fn angle_diff_units(a: Self::Angle, b: Self::Angle) -> Self;
    /// wrap(a + d) for a step d in tracker angle units, |d| ≤ π/[`Self::angle_unit`]
    /// (`f32`: saturating beyond; `f64`: as [`Self::angle_add`]).
    fn angle_add_units(a: Self::Angle, d: Self) -> Self::Angle;
}

impl Real for f32 {
    type Angle = i32;
    #[inline(always)]
    fn angle_from(x: Self) -> i32 {
        // Towards zero, saturating (Rust's `as`, one `vcvt`); NaN gives 0.
        (x * (FIXED_ANGLE_UNITS_PER_RAD as f32)) as i32
    }
    #[inline(always)]
    fn angle_to(a: i32) -> Self {
        a as f32 * (FIXED_ANGLE_RAD_PER_UNIT as f32)
    }
    #[inline(always)]
    fn angle_diff(a: i32, b: i32) -> Self {
        Self::angle_to(a.wrapping_sub(b))
    }
    #[inline(always)]
    fn angle_add(a: i32, d: Self) -> i32 {
        a.wrapping_add(Self::angle_from(d))
    }
    #[inline(always)]
    fn angle_unit() -> Self {
        FIXED_ANGLE_RAD_PER_UNIT as f32
    }
    #[inline(always)]
    fn angle_units_per_rad() -> Self {
        FIXED_ANGLE_UNITS_PER_RAD as f32
    }
    #[inline(always)]
    fn angle_diff_units(a: i32, b: i32) -> Self {
        a.wrapping_sub(b) as f32
    }
    #[inline(always)]
    fn angle_add_units(a: i32, d: Self) -> i32 {
        // Towards zero, saturating (one `vcvt`); NaN gives 0.
        a.wrapping_add(d as i32)
    }
    #[inline(always)]
    fn lit(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn index_floor(self, max: usize) -> usize {
        // Towards zero, saturating, NaN to 0: ⌊x⌋ for x ≥ 0, 0 below.
        (self as usize).min(max)
    }
    #[inline(always)]
    fn index_floor_const(self, max: usize) -> usize {
        if (max as u32).wrapping_add(1).is_power_of_two() && max < i32::MAX as usize {
            // Towards zero, saturating, NaN to 0 as `index_floor`; clamped to [0, 2ⁿ − 1],
            // the pattern of one unsigned saturation.
            (self as i32).max(0).min(max as i32) as usize
        } else {
            self.index_floor(max)
        }
    }
    #[inline(always)]
    fn from_index(k: usize) -> Self {
        k as f32
    }
    #[inline(always)]
    fn step_sin_cos(self) -> (Self, Self) {
        crate::approx::sin_cos(self)
    }
    #[inline(always)]
    fn step_sin_cos_any(self) -> (Self, Self) {
        crate::approx::sin_cos_any(self)
    }
    #[inline(always)]
    fn step_one_minus_exp_neg(self) -> Self {
        crate::approx::one_minus_exp_neg(self)
    }
    #[inline(always)]
    fn step_atan2(self, x: Self) -> Self {
        crate::approx::atan2(self, x)
    }
    #[inline(always)]
    fn step_sqrt(self) -> Self {
        crate::approx::sqrt(self)
    }
    #[inline(always)]
    fn step_max(self, y: Self) -> Self {
        max(self, y)
    }
    #[inline(always)]
    fn step_min(self, y: Self) -> Self {
        min(self, y)
    }
}

impl Real for f64 {
    type Angle = f64;
    #[inline(always)]
    fn angle_from(x: Self) -> f64 {
        x
    }
    #[inline(always)]
    fn angle_to(a: f64) -> Self {
        a
    }
    #[inline(always)]
    fn angle_diff(a: f64, b: f64) -> Self {
        wrap_angle(a - b)
    }
    #[inline(always)]
    fn angle_add(a: f64, d: Self) -> f64 {
        wrap_angle(a + d)
    }
    #[inline(always)]
    fn angle_unit() -> Self {
        1.0
    }
    #[inline(always)]
    fn angle_units_per_rad() -> Self {
        1.0
    }
    #[inline(always)]
    fn angle_diff_units(a: f64, b: f64) -> Self {
        Self::angle_diff(a, b)
    }
    #[inline(always)]
    fn angle_add_units(a: f64, d: Self) -> f64 {
        Self::angle_add(a, d)
    }
    #[inline(always)]
    fn lit(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn index_floor(self, max: usize) -> usize {
        // Towards zero, saturating, NaN to 0: ⌊x⌋ for x ≥ 0, 0 below.
        (self as usize).min(max)
    }
    #[inline(always)]
    fn from_index(k: usize) -> Self {
        k as f64
    }
    #[inline(always)]
    fn step_sin_cos(self) -> (Self, Self) {
        nalgebra::ComplexField::sin_cos(self)
    }
    #[inline(always)]
    fn step_sin_cos_any(self) -> (Self, Self) {
        nalgebra::ComplexField::sin_cos(self)
    }
    #[inline(always)]
    fn step_one_minus_exp_neg(self) -> Self {
        -nalgebra::ComplexField::exp_m1(-self)
    }
    #[inline(always)]
    fn step_atan2(self, x: Self) -> Self {
        RealField::atan2(self, x)
    }
    #[inline(always)]
    fn step_sqrt(self) -> Self {
        nalgebra::ComplexField::sqrt(self)
    }
    #[inline(always)]
    fn step_max(self, y: Self) -> Self {
        RealField::max(self, y)
    }
    #[inline(always)]
    fn step_min(self, y: Self) -> Self {
        RealField::min(self, y)
    }
}

/// Fixed-point tracker angle units per radian (`f32`'s [`Real::Angle`]): 2³²/2π.
const FIXED_ANGLE_UNITS_PER_RAD: f64 = 4_294_967_296.0 / core::f64::consts::TAU;
/// Radians per fixed-point tracker angle unit: 2π/2³² = 1.46e-9 rad.
const FIXED_ANGLE_RAD_PER_UNIT: f64 = core::f64::consts::TAU / 4_294_967_296.0;

/// min(x, y) for a `y` that is never NaN: a compare and a select (the FPU has no minimum
/// instruction on a Cortex-M4; `libm`'s `fminf` is a call). Same result as `fmin` except for
/// the sign of a zero result; a NaN `x` gives `y`, as `fmin` does.
#[inline(always)]
pub(crate) fn min<T: Real>(x: T, y: T) -> T {
    if x < y { x } else { y }
}

/// max(x, y) for a `y` that is never NaN, as [`min`]: a NaN `x` gives `y`.
#[inline(always)]
pub(crate) fn max<T: Real>(x: T, y: T) -> T {
    if x > y { x } else { y }
}

/// True when every value is finite, in one test: the sum s of the values is finite exactly
/// when all of them are (an ∞ or NaN makes it ∞ or NaN), and s − s is +0 for a finite s and
/// NaN otherwise. One FPU add per value after the first and one compare, instead of a
/// compare and a branch per value (or a multiply and an add, for x·0 summed); s − s needs no
/// zero constant loaded, as s·0 did.
///
/// The one difference from testing each value: a sum of finite values can overflow, which
/// needs values of about 1e38 (`f32`) — the estimator's state is in Wb, A, V, Ω and rad/s,
/// some 35 orders of magnitude below. A state that large is refused like a non-finite one,
/// which still never lets a non-finite value into the state.
#[inline(always)]
pub(crate) fn all_finite<T: Real, const N: usize>(values: [T; N]) -> bool {
    let Some((&first, rest)) = values.split_first() else {
        return true;
    };
    let mut sum = first;
    for &v in rest {
        sum += v;
    }
    // s − s on purpose: +0 for a finite s, NaN for ±∞ and NaN (see above).
    #[allow(clippy::eq_op)]
    let zero_if_finite = sum - sum;
    zero_if_finite == T::zero()
}

/// Wraps an angle into [−π, π]: `x − 2π·round(x / 2π)` (the method pages' notation).
///
/// Every caller in the estimator wraps a sum of angles already in [−π, π] plus a small step,
/// so the argument lies within ±3π; there one exact subtraction (Sterbenz: |x| ≥ π = 2π/2)
/// gives the same result as the rounding formula without a call to `round`. Anything larger
/// takes the general formula; NaN stays NaN and ±∞ becomes NaN as with the formula.
#[inline(always)]
pub fn wrap_angle<T: Real>(x: T) -> T {
    let pi = T::pi();
    let two_pi = T::two_pi();
    let three_pi = T::lit(3.0 * core::f64::consts::PI);
    // The common case first, with one compare (false for NaN).
    if x.abs() <= pi {
        return x;
    }
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
    wrap_far(x)
}

/// [`wrap_angle`] beyond ±3π (and NaN, ±∞): out of line, never taken in normal operation.
#[cold]
#[inline(never)]
fn wrap_far<T: Real>(x: T) -> T {
    let pi = T::pi();
    let two_pi = T::two_pi();
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

/// `impl cast` for a tuning record: every real field rounded to `U`, the others copied.
macro_rules! cast_record {
    ($name:ident { $($real:ident),* ; $($copy:ident),* }) => {
        impl<T: $crate::Real> $name<T> {
            /// The same record in another precision: every real rounded to `U`.
            pub fn cast<U: $crate::Real>(&self) -> $name<U> {
                $name {
                    $($real: U::lit(self.$real.to_f64()),)*
                    $($copy: self.$copy,)*
                }
            }
        }
    };
}

pub(crate) use cast_record;

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    #[test]
    fn all_finite_is_the_per_value_test() {
        let values = [0.0_f32, -0.0, 1e-45, -3.5, 1e30, -1e30, f32::MIN_POSITIVE];
        assert!(all_finite(values));
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            for k in 0..values.len() {
                let mut v = values;
                v[k] = bad;
                assert!(!all_finite(v), "{bad} at {k}");
            }
        }
        // +∞ and −∞ together sum to NaN, still refused.
        assert!(!all_finite([f32::INFINITY, f32::NEG_INFINITY, 1.0]));
        assert!(!all_finite([f64::NAN, 0.0]));
        assert!(all_finite([1e300_f64, -1e300]));
        // The documented difference: an overflowing sum of finite values is refused.
        assert!(!all_finite([f32::MAX, f32::MAX]));
    }

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
