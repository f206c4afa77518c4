//! The magnetic model as a block's per-sample code evaluates it: by reference, with the
//! machine's constant inductances standing for a linear model.
//!
//! [`MachineMagnetics`] is the record's form (one type for any model, chosen at run time: each
//! evaluation matches on the model and loads the borrowed model's record). A firmware whose
//! map is known when it is built names its table's type instead (`&'static
//! UniformFluxTable<f32, 16, 16>`): the block's code is then compiled for that table, with
//! no match, the grid's shape a constant and no index checked
//! (`EstimatorState::step_lean_in`).

use super::{
    ConstantInductance, FluxWarmStart, InductanceMatrix, MachineMagnetics, MagneticModel,
    UniformFluxTable,
};
use crate::{Dq, Real};

/// A magnetic model evaluated by reference (module docs): what the estimator's saturating
/// step (`crate::active_flux::ActiveFlux`) asks of its model.
pub trait FluxLookup<T: Real>: Copy {
    /// Whether the model is the machine's constant inductances.
    fn is_linear(&self) -> bool;

    /// Whether this is `machine`'s model (a typed table stands for the record's
    /// [`MachineMagnetics::Uniform`] borrowing that same table).
    fn is_model_of(&self, machine: &MachineMagnetics<T>) -> bool;

    /// ψ(i), `linear` standing for constant inductances.
    fn flux_at(&self, linear: ConstantInductance<T>, i: Dq<T>) -> Dq<T>;

    /// ψ(i) and the warm start of the next solve ([`MachineMagnetics::flux_warm`]).
    fn flux_warm(
        &self,
        linear: ConstantInductance<T>,
        i: Dq<T>,
        fallback: Dq<T>,
        warm: &FluxWarmStart<T>,
    ) -> (Dq<T>, FluxWarmStart<T>);

    /// ψq(i_d, 0) ([`MagneticModel::q_flux_offset`]).
    fn q_flux_offset(&self, linear: ConstantInductance<T>, i_d: T) -> T;

    /// The incremental inductance ∂ψ/∂i at `i`.
    fn inductance_at(&self, linear: ConstantInductance<T>, i: Dq<T>) -> InductanceMatrix<T>;

    /// Whether `i` lies beyond a map's data ([`MachineMagnetics::beyond_data`]).
    fn beyond_data(&self, i: Dq<T>) -> bool;

    /// A map read through its C¹ interpolant (`flux_at`): its bilinear ψ(i), the other
    /// interpolant of the same nodes (their difference measures what the nodes leave open
    /// between them); None for any other model.
    fn bilinear_flux(&self, i: Dq<T>) -> Option<Dq<T>>;
}

impl<T: Real> FluxLookup<T> for MachineMagnetics<T> {
    #[inline]
    fn is_linear(&self) -> bool {
        MachineMagnetics::is_linear(self)
    }

    /// The same variant borrowing the same model (by address, not by value).
    #[inline]
    fn is_model_of(&self, machine: &MachineMagnetics<T>) -> bool {
        use core::ptr::eq;
        match (self, machine) {
            (MachineMagnetics::Linear, MachineMagnetics::Linear) => true,
            (MachineMagnetics::Saturation(a), MachineMagnetics::Saturation(b)) => eq(*a, *b),
            (MachineMagnetics::Map(a), MachineMagnetics::Map(b)) => eq(*a, *b),
            (MachineMagnetics::Uniform(a), MachineMagnetics::Uniform(b)) => eq(*a, *b),
            _ => false,
        }
    }

    /// A [`MachineMagnetics::Map`]'s C¹ interpolant (`FluxMap::smooth_flux`), any other
    /// model's own ψ(i).
    #[inline]
    fn flux_at(&self, linear: ConstantInductance<T>, i: Dq<T>) -> Dq<T> {
        match *self {
            MachineMagnetics::Map(m) => m.smooth_flux(i),
            _ => self.resolve(linear).flux(i),
        }
    }

    #[inline(always)]
    fn flux_warm(
        &self,
        linear: ConstantInductance<T>,
        i: Dq<T>,
        fallback: Dq<T>,
        warm: &FluxWarmStart<T>,
    ) -> (Dq<T>, FluxWarmStart<T>) {
        match *self {
            MachineMagnetics::Map(m) => (m.smooth_flux(i), *warm),
            _ => MachineMagnetics::flux_warm(self, linear, i, fallback, warm),
        }
    }

    #[inline(always)]
    fn q_flux_offset(&self, linear: ConstantInductance<T>, i_d: T) -> T {
        match *self {
            MachineMagnetics::Map(m) => m.smooth_q_flux_offset(i_d),
            _ => MachineMagnetics::q_flux_offset(self, linear, i_d),
        }
    }

    #[inline]
    fn inductance_at(&self, linear: ConstantInductance<T>, i: Dq<T>) -> InductanceMatrix<T> {
        match *self {
            MachineMagnetics::Map(m) => m.smooth_flux_and_jacobian(i).1,
            _ => self.resolve(linear).incremental_inductance(i),
        }
    }

    #[inline]
    fn beyond_data(&self, i: Dq<T>) -> bool {
        MachineMagnetics::beyond_data(self, i)
    }

    #[inline]
    fn bilinear_flux(&self, i: Dq<T>) -> Option<Dq<T>> {
        match *self {
            MachineMagnetics::Map(m) => Some(m.flux(i)),
            _ => None,
        }
    }
}

/// A uniform-grid table in flash, named by its type: the lookup's shape and its cells'
/// address are constants of the code that evaluates it.
impl<T: Real, const ND: usize, const NQ: usize> FluxLookup<T> for &UniformFluxTable<T, ND, NQ> {
    #[inline(always)]
    fn is_linear(&self) -> bool {
        false
    }

    /// True where `machine` borrows this table's cells ([`UniformFluxTable::map`]).
    #[inline]
    fn is_model_of(&self, machine: &MachineMagnetics<T>) -> bool {
        match machine {
            MachineMagnetics::Uniform(map) => map.borrows(self),
            _ => false,
        }
    }

    #[inline(always)]
    fn flux_at(&self, _linear: ConstantInductance<T>, i: Dq<T>) -> Dq<T> {
        MagneticModel::flux(*self, i)
    }

    #[inline(always)]
    fn flux_warm(
        &self,
        _linear: ConstantInductance<T>,
        i: Dq<T>,
        _fallback: Dq<T>,
        warm: &FluxWarmStart<T>,
    ) -> (Dq<T>, FluxWarmStart<T>) {
        (MagneticModel::flux(*self, i), *warm)
    }

    #[inline(always)]
    fn q_flux_offset(&self, _linear: ConstantInductance<T>, i_d: T) -> T {
        MagneticModel::q_flux_offset(*self, i_d)
    }

    #[inline]
    fn inductance_at(&self, _linear: ConstantInductance<T>, i: Dq<T>) -> InductanceMatrix<T> {
        self.flux_and_jacobian(i).1
    }

    #[inline]
    fn beyond_data(&self, i: Dq<T>) -> bool {
        self.map().beyond_grid(i)
    }

    /// None: a typed table is read bilinearly.
    #[inline(always)]
    fn bilinear_flux(&self, _i: Dq<T>) -> Option<Dq<T>> {
        None
    }
}
