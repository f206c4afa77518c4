//! A caller's last solution of an iterative ψ(i), the start of its next one.
//!
//! The algebraic model's ψ(i) is a Newton solve of its i(ψ) (`super::Saturation`). A block
//! that solves it sample after sample near one operating point (the estimator at its
//! estimated current, the drive at its reference) keeps the last solution (i₀, ψ₀) and the
//! incremental inductance L₀ = ∂ψ/∂i there, and starts the next solve at the first-order
//! prediction ψ₀ + L₀·(i − i₀). Its error is of the order of the curvature times |i − i₀|²,
//! so that a sample's current change leaves one Newton step to take and one to confirm it —
//! where a start from the estimated flux (off by the estimator's own error) or from the
//! magnetically linear guess (off by the saturation) takes four to eight. The answer is the
//! same root to the solver's tolerance whatever the start (tested).
//!
//! Models whose ψ(i) is not an iteration (constant inductances, flux maps) evaluate it
//! directly and leave the warm start empty: no prediction and no Jacobian on their path.

use super::{
    ConstantInductance, InductanceMatrix, MachineMagnetics, MagneticModel, Magnetics, Saturation,
};
use crate::{Dq, Real};

/// The tangent plane of ψ(i) at the last solution, ψ ≈ c + L·i (module docs); empty until
/// the first solve. Five numbers: the intercept c = ψ₀ − L₀·i₀ and L₀'s three entries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluxWarmStart<T> {
    /// ψ₀ − L₀·i₀, Wb.
    c: Dq<T>,
    /// L₀ = ∂ψ/∂i at the solution, H: (L_dd, L_dq = L_qd, L_qq), symmetric for an
    /// energy-consistent model. L_dd > 0 for a solution (an incremental inductance), 0 while
    /// empty.
    l: (T, T, T),
}

impl<T: Real> Default for FluxWarmStart<T> {
    fn default() -> Self {
        Self::empty()
    }
}

impl<T: Real> FluxWarmStart<T> {
    /// No solution yet: the next solve starts from its caller's guess.
    pub fn empty() -> Self {
        Self {
            c: Dq::zero(),
            l: (T::zero(), T::zero(), T::zero()),
        }
    }

    /// The solution ψ at the current `i` with the incremental inductance `l` there.
    pub fn at(i: Dq<T>, psi: Dq<T>, l: &InductanceMatrix<T>) -> Self {
        Self::plane(i, psi, (l.dd, l.dq, l.qq))
    }

    /// The same inductance at another solution (ψ at `i`): the warm start of a solve that
    /// did not evaluate the inductance, within that step of the last one that did.
    pub fn moved(&self, i: Dq<T>, psi: Dq<T>) -> Self {
        Self::plane(i, psi, self.l)
    }

    fn plane(i: Dq<T>, psi: Dq<T>, l: (T, T, T)) -> Self {
        let (dd, dq, qq) = l;
        let c = Dq::new(psi.d - dd * i.d - dq * i.q, psi.q - dq * i.d - qq * i.q);
        Self { c, l }
    }

    /// The incremental inductance L₀ of the last solution (zero while empty).
    pub fn inductance(&self) -> InductanceMatrix<T> {
        let (dd, dq, qq) = self.l;
        InductanceMatrix { dd, dq, qd: dq, qq }
    }

    /// Whether it holds a solution.
    pub fn is_set(&self) -> bool {
        self.l.0 > T::zero()
    }

    /// The prediction of ψ(`i`): c + L₀·i = ψ₀ + L₀·(i − i₀), not finite while empty (a
    /// model's [`MagneticModel::flux_from`] then starts from its own guess).
    #[inline]
    pub fn prediction(&self, i: Dq<T>) -> Dq<T> {
        let (dd, dq, qq) = self.l;
        if !self.is_set() {
            let nan = T::lit(f64::NAN);
            return Dq::new(nan, nan);
        }
        Dq::new(
            self.c.d + dd * i.d + dq * i.q,
            self.c.q + dq * i.d + qq * i.q,
        )
    }

    /// The start of a solve at `i`: the [prediction](FluxWarmStart::prediction), or
    /// `fallback` while empty (or where the prediction is not finite).
    #[inline]
    pub fn guess(&self, i: Dq<T>, fallback: Dq<T>) -> Dq<T> {
        let g = self.prediction(i);
        if g.is_finite() { g } else { fallback }
    }
}

impl<T: Real> Magnetics<'_, T> {
    /// ψ(`i`) and the warm start for the next solve: an iterative model's ψ(i) solved from
    /// `warm`'s prediction (from `fallback`, a flux near the answer, while `warm` is empty),
    /// the returned warm start holding this solution; any other model's ψ(i) evaluated
    /// directly, `warm` returned as it is (module docs).
    #[inline]
    pub fn flux_warm(
        &self,
        i: Dq<T>,
        fallback: Dq<T>,
        warm: &FluxWarmStart<T>,
    ) -> (Dq<T>, FluxWarmStart<T>) {
        match self {
            Magnetics::Saturation(s) => s.flux_warm(i, fallback, warm),
            _ => (self.flux(i), *warm),
        }
    }
}

impl<T: Real> MachineMagnetics<T> {
    /// [`Magnetics::flux_warm`] of the borrowed model, `linear` standing for
    /// [`MachineMagnetics::Linear`]: evaluated by reference, so that a map's lookup is inlined
    /// into its caller (no copy of the map's record into a [`Magnetics`], no call of its
    /// dispatch, no call frame: what a firmware's step pays is the lookup's own instructions).
    #[inline(always)]
    pub fn flux_warm(
        &self,
        linear: ConstantInductance<T>,
        i: Dq<T>,
        fallback: Dq<T>,
        warm: &FluxWarmStart<T>,
    ) -> (Dq<T>, FluxWarmStart<T>) {
        match *self {
            MachineMagnetics::Linear => (linear.flux(i), *warm),
            MachineMagnetics::Saturation(s) => s.flux_warm(i, fallback, warm),
            MachineMagnetics::Map(m) => (m.flux(i), *warm),
            MachineMagnetics::Uniform(m) => (m.flux(i), *warm),
        }
    }
}

impl<T: Real> MachineMagnetics<T> {
    /// [`MagneticModel::q_flux_offset`] of the borrowed model by reference, as
    /// [`MachineMagnetics::flux_warm`] evaluates ψ (a map's lookup inlined into the caller).
    #[inline(always)]
    pub fn q_flux_offset(&self, linear: ConstantInductance<T>, i_d: T) -> T {
        match *self {
            MachineMagnetics::Linear => linear.q_flux_offset(i_d),
            MachineMagnetics::Saturation(s) => s.q_flux_offset(i_d),
            MachineMagnetics::Map(m) => m.q_flux_offset(i_d),
            MachineMagnetics::Uniform(m) => m.q_flux_offset(i_d),
        }
    }
}

impl<T: Real> Saturation<T> {
    /// ψ(i) solved from `warm`'s prediction (`fallback` while empty), and the warm start at
    /// that solution.
    #[inline]
    fn flux_warm(
        &self,
        i: Dq<T>,
        fallback: Dq<T>,
        warm: &FluxWarmStart<T>,
    ) -> (Dq<T>, FluxWarmStart<T>) {
        let (psi, l) = self.flux_and_inductance_from(i, warm.guess(i, fallback));
        (psi, FluxWarmStart::at(i, psi, &l))
    }
}

#[cfg(test)]
mod tests;
