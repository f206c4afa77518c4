//! Constant inductances: the magnetically linear machine.

use super::{InductanceMatrix, MagneticModel};
use crate::{Dq, Real};

/// ψ = (Ld·i_d + λf, Lq·i_q): the model of [`crate::MachineModel::flux_dq`], whose
/// arithmetic it repeats operation for operation (bit-identical results).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstantInductance<T> {
    /// d-axis inductance Ld in H.
    pub ld: T,
    /// q-axis inductance Lq in H.
    pub lq: T,
    /// Magnet flux linkage λf in Wb.
    pub flux_linkage: T,
}

impl<T: Real> MagneticModel<T> for ConstantInductance<T> {
    #[inline]
    fn flux(&self, i: Dq<T>) -> Dq<T> {
        Dq::new(self.ld * i.d + self.flux_linkage, self.lq * i.q)
    }

    #[inline]
    fn current(&self, psi: Dq<T>) -> Dq<T> {
        Dq::new((psi.d - self.flux_linkage) / self.ld, psi.q / self.lq)
    }

    #[inline]
    fn incremental_inductance(&self, _i: Dq<T>) -> InductanceMatrix<T> {
        InductanceMatrix::diagonal(self.ld, self.lq)
    }

    #[inline]
    fn q_flux_offset(&self, _i_d: T) -> T {
        T::zero()
    }

    #[inline]
    fn secant_q(&self, _i: Dq<T>) -> T {
        self.lq
    }

    #[inline]
    fn magnet_flux(&self) -> T {
        self.flux_linkage
    }
}
