//! The measurement of the two levels: the ratio k and the resistance from their current and
//! voltage differences.

use crate::{Ab, Real};

/// The unit vector of phase b in α-β, (cos 2π/3, sin 2π/3) (amplitude-invariant Clarke: the
/// phase-b value of a vector is its projection on it).
pub(super) const PHASE_B_ALPHA: f64 = -0.5;
pub(super) const PHASE_B_BETA: f64 = 0.866_025_403_784_438_6;

/// R = Δv·Δi′/|Δi′|² (Ω): the resistance along the current difference `di` of two DC levels
/// and their voltage difference `dv` (α-β), with phase a of `di` divided by the ratio `k`
/// (phase b as measured; i_β = (i_a + 2·i_b)/√3, amplitude-invariant Clarke). NaN when the
/// difference is zero or anything is non-finite.
pub fn resistance_of<T: Real>(di: Ab<T>, dv: Ab<T>, k: T) -> T {
    let ib = di.to_abc().b;
    let ia = di.alpha / k;
    let corrected = crate::Abc::new(ia, ib, -ia - ib).to_ab();
    let den = corrected.dot(corrected);
    if den > T::zero() {
        dv.dot(corrected) / den
    } else {
        T::zero() / T::zero()
    }
}

/// 1/n for a sample count n, n built as a real by binary decomposition (adds of powers of
/// two, exact below 2^24 in f32): no integer-to-float conversion, which a Cortex-M4's f32
/// build would do through software double for `T::lit(n as f64)`.
pub(super) fn reciprocal_of_count<T: Real>(n: u32) -> T {
    let mut x = T::zero();
    let mut bit = T::one();
    let mut m = n;
    while m > 0 {
        if m & 1 == 1 {
            x += bit;
        }
        bit += bit;
        m >>= 1;
    }
    if x > T::zero() {
        T::one() / x
    } else {
        T::zero()
    }
}

/// k = (Δi_a/Δv_a)/(Δi_b/Δv_b) from the α-β differences of the measured current and the
/// voltage between two levels (module docs), or None when phase a or b carries less than
/// `min_share` of |Δi|, a conductance is not positive, or anything is non-finite.
pub fn ratio_of<T: Real>(di: Ab<T>, dv: Ab<T>, min_share: T) -> Option<T> {
    let pb = |x: Ab<T>| x.alpha * T::lit(PHASE_B_ALPHA) + x.beta * T::lit(PHASE_B_BETA);
    let (ia, ib) = (di.alpha, pb(di));
    let (va, vb) = (dv.alpha, pb(dv));
    let share = crate::real::min(ia.abs(), ib.abs());
    // Positive conductances (a current difference in the voltage's direction, per phase)
    // and enough of the current in both measured phases; NaN fails every comparison.
    let ok = share >= min_share * di.norm()
        && share > T::zero()
        && ia * va > T::zero()
        && ib * vb > T::zero();
    if !ok {
        return None;
    }
    let k = (ia * vb) / (ib * va);
    k.is_finite().then_some(k)
}
