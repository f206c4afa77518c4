//! The magnetic model a [`MachineModel`](crate::MachineModel) carries beside its constant
//! inductances: what the estimator, the drive and the baselines evaluate where they need the
//! flux at the present current.
//!
//! [`MachineMagnetics::Linear`] (the default) is the record's own `ld`, `lq` and
//! `flux_linkage`: every block then runs its constant-inductance arithmetic unchanged, bit for
//! bit. [`MachineMagnetics::Saturation`] and [`MachineMagnetics::Map`] borrow their model for
//! the program's life — a `static` in firmware (a map's table in flash), a leaked allocation in
//! a simulator or a binding (made once per model). The record stays `Copy`, allocation-free and
//! two words larger than the constant-inductance one (a configuration copied by value stays
//! small enough for a freestanding image, which has no `memcpy`).

use super::{FluxMap, MagneticModel, Magnetics, Saturation, UniformFluxMap};
use crate::{Dq, Real};

/// The magnetic model of a [`MachineModel`](crate::MachineModel).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum MachineMagnetics<T: 'static> {
    /// Constant inductances: the record's `ld`, `lq` and `flux_linkage`.
    #[default]
    Linear,
    /// The algebraic self- and cross-saturation model, borrowed for the program's life.
    Saturation(&'static Saturation<T>),
    /// A flux map on a rectangular grid, borrowed for the program's life.
    Map(&'static FluxMap<'static, T>),
    /// A flux map on a uniform grid ([`super::UniformFluxTable`]'s lookup: no search, each
    /// cell's coefficients precomputed), borrowed for the program's life.
    Uniform(&'static UniformFluxMap<'static, T>),
}

impl<T: Real> MachineMagnetics<T> {
    /// True for [`MachineMagnetics::Linear`].
    #[inline]
    pub fn is_linear(&self) -> bool {
        matches!(self, MachineMagnetics::Linear)
    }

    /// Whether the model at `i` is a map's extension beyond its data: `i` beyond the grid
    /// by more than the edge cell (`FluxMap::beyond_grid`); never for a model defined
    /// everywhere (constant inductances, the algebraic model).
    #[inline]
    pub fn beyond_data(&self, i: Dq<T>) -> bool {
        match self {
            MachineMagnetics::Linear | MachineMagnetics::Saturation(_) => false,
            MachineMagnetics::Map(map) => map.beyond_grid(i),
            MachineMagnetics::Uniform(map) => map.beyond_grid(i),
        }
    }

    /// The model in another precision: itself when `U` is `T`, `None` for a borrowed model
    /// otherwise (it cannot be converted without allocating: build it in the drive's
    /// precision, e.g. `Saturation::cast` into a `static`, a map with `FluxTable`).
    pub fn cast<U: Real>(&self) -> Option<MachineMagnetics<U>> {
        match *self {
            MachineMagnetics::Linear => Some(MachineMagnetics::Linear),
            MachineMagnetics::Saturation(s) => {
                let s: &'static dyn core::any::Any = s;
                s.downcast_ref::<Saturation<U>>()
                    .map(MachineMagnetics::Saturation)
            }
            MachineMagnetics::Map(m) => {
                let m: &'static dyn core::any::Any = m;
                m.downcast_ref::<FluxMap<'static, U>>()
                    .map(MachineMagnetics::Map)
            }
            MachineMagnetics::Uniform(m) => {
                let m: &'static dyn core::any::Any = m;
                m.downcast_ref::<UniformFluxMap<'static, U>>()
                    .map(MachineMagnetics::Uniform)
            }
        }
    }

    /// The model as a [`Magnetics`], with `linear` standing for [`MachineMagnetics::Linear`].
    #[inline]
    pub fn resolve(&self, linear: super::ConstantInductance<T>) -> Magnetics<'static, T> {
        match *self {
            MachineMagnetics::Linear => Magnetics::Constant(linear),
            MachineMagnetics::Saturation(s) => Magnetics::Saturation(*s),
            MachineMagnetics::Map(m) => Magnetics::Map(*m),
            MachineMagnetics::Uniform(m) => Magnetics::Uniform(*m),
        }
    }
}

/// The zero-current values a saturating model implies for a record's constant fields:
/// (incremental L_d, incremental L_q, ψd) at i = 0 — what a datasheet or a no-load test
/// gives, and the constants a block falls back to where it needs one number.
pub fn zero_current_constants<T: Real>(model: &impl MagneticModel<T>) -> (T, T, T) {
    let l = model.incremental_inductance(Dq::zero());
    (l.dd, l.qq, model.magnet_flux())
}
