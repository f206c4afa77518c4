//! `f32`-only approximations of the transcendental functions in the estimator's step.
//!
//! On a Cortex-M4F (single-precision FPU) `libm`'s `sinf`/`cosf` reduce their argument and
//! evaluate their kernels in `f64`, which that FPU does in software (`__aeabi_dmul`, ...), and
//! `atan2f` is a chain of calls; both cost hundreds of cycles per sample (docs/results/firmware-cost.md).
//! These versions use only `f32` add, multiply, one division and compare, so host and firmware
//! builds still compute bit-identical results (IEEE arithmetic, no fused multiply-add in Rust).
//! `f64` keeps `libm` (see [`crate::Real`]).
//!
//! Maximum errors (absolute, against `f64` `libm` on the whole argument range, tested below):
//! - [`sin_cos`]: 2e-7 on [−π/2, π/2] (measured 1.6e-7) (Taylor polynomials of degree 9 and 10 on [0, π/4],
//!   truncation below 2e-9; the rest is `f32` rounding, about one ulp of 1);
//! - [`one_minus_exp_neg`]: 1.5e-7 on [0, ∞) (reduction y = k·ln 2 + r, |r| ≤ ln 2 / 2,
//!   Taylor degree 7, truncation below 6e-9);
//! - [`sqrt`]: within 1 ulp of the correctly rounded square root for normal positive
//!   arguments (tested; `libm`'s `sqrtf` is correctly rounded but a 60-cycle call on a
//!   Cortex-M4, whose `vsqrt` stable Rust cannot reach without `unsafe` assembly);
//! - [`atan2`]: 2.2e-6 rad everywhere (measured 1.9e-6) (odd near-minimax polynomial of
//!   degree 11 for atan on [0, 1] with fit error 1.7e-6 rad, plus octant reflection). Its one
//!   use in the step is the direct rotor angle θm of eq. (6), the input of the T2S trackers:
//!   a deterministic error of 2e-6 rad is below a thousandth of the estimator's angle error
//!   in every `f32` scenario (rms |θ − θ̂| 1.2e-3 to 1.9e-2 rad in fig8–fig12), and the
//!   trackers filter it further; the degree-15 version (3.5e-7) cost 8 cycles more per step
//!   on a Cortex-M4F (docs/results/firmware-cost.md).

use core::f32::consts::{FRAC_PI_2, PI};

/// π/2 in two parts (Cody–Waite): `PIO2_HI` is the `f32` nearest π/2, and `PIO2_HI − x` is
/// exact for x in [π/4, π/2] (Sterbenz); `PIO2_LO` = π/2 − `PIO2_HI` adds the rest.
const PIO2_HI: f32 = FRAC_PI_2;
const PIO2_LO: f32 = -4.371_139e-8;

/// sin u and cos u for u in [0, π/4] (Taylor, see the module docs).
#[inline(always)]
fn sin_cos_kernel(u: f32) -> (f32, f32) {
    let u2 = u * u;
    let s = u
        * (1.0
            + u2 * (-1.0 / 6.0
                + u2 * (1.0 / 120.0 + u2 * (-1.0 / 5040.0 + u2 * (1.0 / 362_880.0)))));
    let c = 1.0
        + u2 * (-0.5
            + u2 * (1.0 / 24.0
                + u2 * (-1.0 / 720.0 + u2 * (1.0 / 40_320.0 + u2 * (-1.0 / 3_628_800.0)))));
    (s, c)
}

/// (sin x, cos x) for x in [−π/2, π/2]; NaN propagates. Callers reduce larger arguments
/// (the observer wraps ω·Ts into [−π, π] and halves it).
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    let ax = x.abs();
    let (s, c) = if ax <= 0.25 * PI {
        sin_cos_kernel(ax)
    } else {
        // sin x = cos(π/2 − x), cos x = sin(π/2 − x).
        let (s, c) = sin_cos_kernel((PIO2_HI - ax) + PIO2_LO);
        (c, s)
    };
    (if x < 0.0 { -s } else { s }, c)
}

/// π in two parts (Cody–Waite): `PI_HI − x` is exact for x in [π/2, π] (Sterbenz) and
/// `PI_LO` = π − `PI_HI` adds the rest.
const PI_HI: f32 = PI;
const PI_LO: f32 = 2.0 * PIO2_LO;

/// (sin x, cos x) for any finite x: wrapped into [−π, π] ([`crate::wrap_angle`]: one
/// compare for |x| ≤ π, one subtraction up to ±3π), then reflected into [−π/2, π/2]
/// (sin x = sin(±π − x), cos x = −cos(±π − x)) for [`sin_cos`]. Error below 2.5e-7 for
/// |x| ≤ 3π (tested; the reflection adds the rounding of ±π − x). NaN and ±∞ give NaN.
/// The Park transforms of the drive use it (`Rotation::from_angle` for `f32`), so that no
/// software double precision is left on the `f32` drive's path either.
#[inline]
pub fn sin_cos_any(x: f32) -> (f32, f32) {
    let x = crate::wrap_angle(x);
    if x > FRAC_PI_2 {
        let (s, c) = sin_cos((PI_HI - x) + PI_LO);
        (s, -c)
    } else if x < -FRAC_PI_2 {
        let (s, c) = sin_cos((-PI_HI - x) - PI_LO);
        (s, -c)
    } else {
        sin_cos(x)
    }
}

/// 1 − e^{−y} for y ≥ 0 (and for y ≥ 0.25 at full relative accuracy; below, use a series
/// in y as the observer does, which keeps the relative accuracy as y → 0). NaN propagates,
/// +∞ gives 1.
#[inline]
pub fn one_minus_exp_neg(y: f32) -> f32 {
    // Beyond 17.4, e^{−y} is below half an ulp of 1.
    if y > 17.5 {
        return 1.0;
    }
    const LN2_HI: f32 = 0.693_145_75;
    const LN2_LO: f32 = 1.428_606_8e-6;
    let k = (y * core::f32::consts::LOG2_E + 0.5) as i32; // round, y ≥ 0 (NaN gives 0)
    let kf = k as f32;
    let r = (y - kf * LN2_HI) - kf * LN2_LO; // |r| ≤ ln2/2
    let e = 1.0
        - r * (1.0
            - r * (0.5
                - r * (1.0 / 6.0
                    - r * (1.0 / 24.0
                        - r * (1.0 / 120.0 - r * (1.0 / 720.0 - r * (1.0 / 5040.0)))))));
    // 2^−k with 0 ≤ k ≤ 26: a normal number.
    let scale = f32::from_bits(((127 - k) as u32) << 23);
    1.0 - e * scale
}

/// √x for x ≥ 0: reciprocal square root from the exponent-halving bit trick (relative error
/// below 3.5e-3, Lomont's constant 0x5f375a86), two Newton steps for 1/√x (error squares each
/// step: about 2e-5, then 1e-9, below f32 rounding), then s = x·y and one Newton step on √x
/// itself (s + (x − s²)·y/2), which corrects the last bit. √0 = 0; NaN, −x and +∞ give a
/// non-finite or NaN result (the estimator rejects it).
#[inline]
pub fn sqrt(x: f32) -> f32 {
    let half_x = 0.5 * x;
    let mut y = f32::from_bits(0x5f37_5a86_u32.wrapping_sub(x.to_bits() >> 1));
    y *= 1.5 - half_x * y * y;
    y *= 1.5 - half_x * y * y;
    let s = x * y;
    s + (x - s * s) * (0.5 * y)
}

/// Coefficients of atan(t) ≈ t·P(t²) on [0, 1], degree 11: near-minimax for the absolute
/// error (Lawson-weighted least squares, coefficients rounded to `f32` one at a time and the
/// rest refitted, `scripts/fit_approx.py`); fit error 1.7e-6 rad. Degree 15 (8 coefficients,
/// 3.7e-8) cost 8 cycles more per step on a Cortex-M4F for an accuracy nothing downstream
/// uses; degree 9 (5 coefficients) would be 1.1e-5 rad.
const ATAN: [f32; 6] = [
    0.999_977_23,
    -0.332_623,
    0.193_541_21,
    -0.116_428_2,
    0.052_648_935,
    -0.011_719_678_5,
];

/// atan2(y, x) in [−π, π], with atan2(±0, +0) = ±0, atan2(±0, −0) = ±π as in IEEE; NaN
/// propagates. Infinite arguments are outside the tested range (one infinite argument gives
/// the axis' angle, two give NaN; the estimator never passes them: it rejects a non-finite
/// state before using the angle).
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    // Above the diagonal atan(ay/ax) = π/2 − atan(ax/ay): the quotient negated and π/2 added,
    // chosen with the operands (one select, no second test of `swap`); bit for bit the
    // same as π/2 − atan(ax/ay).
    let swap = ay > ax;
    let (num, den, offset) = if swap {
        (-ax, ay, FRAC_PI_2)
    } else {
        (ay, ax, 0.0)
    };
    let t = if den == 0.0 { 0.0 } else { num / den };
    let t2 = t * t;
    let p = ATAN;
    let poly = p[0] + t2 * (p[1] + t2 * (p[2] + t2 * (p[3] + t2 * (p[4] + t2 * p[5]))));
    let mut a = offset + t * poly;
    if x.is_sign_negative() {
        a = PI - a;
    }
    if y.is_sign_negative() { -a } else { a }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI as PI64;

    #[test]
    fn sin_cos_any_error_below_2_5e_7_to_three_pi() {
        let mut worst = 0.0_f64;
        for k in -300_000..=300_000 {
            let x = k as f32 * (3.0 * core::f32::consts::PI / 300_000.0);
            let (s, c) = sin_cos_any(x);
            let (s64, c64) = (x as f64).sin_cos();
            worst = worst
                .max((s as f64 - s64).abs())
                .max((c as f64 - c64).abs());
        }
        assert!(worst < 2.5e-7, "{worst}");
        for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let (s, c) = sin_cos_any(x);
            assert!(s.is_nan() && c.is_nan(), "{x}");
        }
        // Far arguments take wrap_angle's general path and stay accurate to its reduction.
        let (s, c) = sin_cos_any(1000.0);
        assert!(
            (s as f64 - 1000.0_f64.sin()).abs() < 1e-4
                && (c as f64 - 1000.0_f64.cos()).abs() < 1e-4
        );
    }

    #[test]
    fn sin_cos_error_below_2e_7_on_half_turn() {
        let mut worst = 0.0_f64;
        let n = 200_000;
        for k in -n..=n {
            let x = (k as f64 / n as f64 * PI64 / 2.0) as f32;
            let (s, c) = sin_cos(x);
            let (s64, c64) = (x as f64).sin_cos();
            worst = worst
                .max((s as f64 - s64).abs())
                .max((c as f64 - c64).abs());
        }
        assert!(worst < 2e-7, "{worst}");
        assert!(sin_cos(f32::NAN).0.is_nan() && sin_cos(f32::NAN).1.is_nan());
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
    }

    #[test]
    fn one_minus_exp_neg_error_below_1_5e_7() {
        let mut worst = 0.0_f64;
        for k in 0..=400_000 {
            let y = k as f32 * 5e-5; // 0 … 20
            let got = one_minus_exp_neg(y) as f64;
            let want = -(-(y as f64)).exp_m1();
            worst = worst.max((got - want).abs());
        }
        assert!(worst < 1.5e-7, "{worst}");
        assert_eq!(one_minus_exp_neg(f32::INFINITY), 1.0);
        assert_eq!(one_minus_exp_neg(1e30), 1.0);
        assert!(one_minus_exp_neg(f32::NAN).is_nan());
    }

    #[test]
    fn sqrt_within_one_ulp() {
        let mut x = 1e-30_f32;
        while x < 1e30 {
            for k in 0..64 {
                let v = x * (1.0 + k as f32 / 64.0);
                let want = (v as f64).sqrt();
                let got = sqrt(v) as f64;
                let ulp = f32::EPSILON as f64 * want;
                assert!((got - want).abs() <= ulp, "{v}: {got} vs {want}");
            }
            x *= 1.37;
        }
        assert_eq!(sqrt(0.0), 0.0);
        assert_eq!(sqrt(4.0), 2.0);
        assert!(sqrt(f32::NAN).is_nan());
        assert!(!sqrt(f32::INFINITY).is_finite());
    }

    #[test]
    fn atan2_error_below_2_2e_6_all_round() {
        let mut worst = 0.0_f64;
        for k in 0..100_000 {
            let phi = k as f64 / 100_000.0 * 2.0 * PI64 - PI64;
            for r in [1e-30_f64, 1e-3, 1.0, 7.5e3, 1e30] {
                let (x, y) = ((r * phi.cos()) as f32, (r * phi.sin()) as f32);
                let want = (y as f64).atan2(x as f64);
                let got = atan2(y, x) as f64;
                // ±π are the same angle.
                let e = (got - want).abs();
                let e = e.min((e - 2.0 * PI64).abs());
                worst = worst.max(e);
            }
        }
        assert!(worst < 2.2e-6, "{worst}");
        assert_eq!(atan2(0.0, 0.0), 0.0);
        assert_eq!(atan2(-0.0, 0.0), -0.0);
        assert_eq!(atan2(0.0, -0.0), PI);
        assert_eq!(atan2(-0.0, -1.0), -PI);
        assert_eq!(atan2(1.0, 0.0), FRAC_PI_2);
        assert_eq!(atan2(-1e-30, 0.0), -FRAC_PI_2);
        assert_eq!(atan2(0.0, 7.5e3), 0.0);
        assert_eq!(atan2(0.0, -1e30), PI);
        // Extreme ratios: the quotient underflows to 0 or the swap keeps it in [0, 1].
        assert_eq!(atan2(1e-30, 1e30), 0.0);
        assert_eq!(atan2(-1e30, -1e-30), -FRAC_PI_2);
        assert_eq!(atan2(1e30, -1e-30), FRAC_PI_2);
        assert!(atan2(f32::NAN, 1.0).is_nan() && atan2(1.0, f32::NAN).is_nan());
    }
}
