//! Short Taylor polynomials for the small arguments of the per-interval propagators
//! (|x| ≤ 0.1: ωh and μh over at most one 100 µs sample), with libm as the fallback.
//! Truncation error < 3e-17 relative inside the range: below f64 rounding. Also the two
//! frame rotations every propagator shares.

use fado_core::{Ab, Dq};
use num_complex::Complex64;

/// e^{jx}.
#[inline(always)]
pub(crate) fn cis(x: f64) -> Complex64 {
    if x.abs() <= 0.1 {
        let x2 = x * x;
        // cos to x¹⁰, sin to x¹¹: remainders x¹²/12! and x¹³/13! < 3e-21.
        // Reciprocal factorials as constants: no division in the loop.
        const C: [f64; 5] = [
            1.0 / 2.0,
            1.0 / 24.0,
            1.0 / 720.0,
            1.0 / 40_320.0,
            1.0 / 3_628_800.0,
        ];
        const S: [f64; 5] = [
            1.0 / 6.0,
            1.0 / 120.0,
            1.0 / 5040.0,
            1.0 / 362_880.0,
            1.0 / 39_916_800.0,
        ];
        let c = 1.0 - x2 * (C[0] - x2 * (C[1] - x2 * (C[2] - x2 * (C[3] - x2 * C[4]))));
        let s = x * (1.0 - x2 * (S[0] - x2 * (S[1] - x2 * (S[2] - x2 * (S[3] - x2 * S[4])))));
        Complex64::new(c, s)
    } else {
        let (s, c) = x.sin_cos();
        Complex64::new(c, s)
    }
}

/// e^{x}.
#[inline(always)]
pub(crate) fn exp(x: f64) -> f64 {
    if x.abs() <= 0.1 {
        // Horner to x¹⁰: remainder x¹¹/11! < 3e-19. Reciprocal factorials as constants.
        const K: [f64; 10] = [
            1.0 / 362_880.0,
            1.0 / 40_320.0,
            1.0 / 5040.0,
            1.0 / 720.0,
            1.0 / 120.0,
            1.0 / 24.0,
            1.0 / 6.0,
            1.0 / 2.0,
            1.0,
            1.0,
        ];
        let mut p = 1.0 / 3_628_800.0;
        for k in K {
            p = p * x + k;
        }
        p
    } else {
        x.exp()
    }
}

/// The rotor-frame vector `x` in the stationary frame, rotor at `rot` = e^{jθ}.
#[inline]
pub(crate) fn rotate(x: Dq<f64>, rot: Complex64) -> Ab<f64> {
    Ab::new(x.d * rot.re - x.q * rot.im, x.d * rot.im + x.q * rot.re)
}

/// The stationary-frame vector `x` in the rotor frame, rotor at `rot` = e^{jθ}.
#[inline]
pub(crate) fn unrotate(x: Ab<f64>, rot: Complex64) -> Dq<f64> {
    Dq::new(
        x.alpha * rot.re + x.beta * rot.im,
        -x.alpha * rot.im + x.beta * rot.re,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polynomials_match_libm_to_rounding() {
        for k in -1000..=1000 {
            let x = k as f64 * 1.3e-4;
            let c = cis(x);
            assert!(
                (c.re - x.cos()).abs() < 2e-16 && (c.im - x.sin()).abs() < 2e-16,
                "{x}"
            );
            assert!((exp(x) - x.exp()).abs() < 4e-16 * x.exp(), "{x}");
        }
        assert_eq!(cis(2.0).re, 2f64.cos());
    }
}
