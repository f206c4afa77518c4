//! The magnetic model a [`MachineModel`](crate::MachineModel) carries beside its constant
//! inductances: what the estimator, the drive and the baselines evaluate where they need the
//! flux at the present current.
//!
//! [`MachineMagnetics::Linear`] (the default) is the record's own `ld`, `lq` and
//! `flux_linkage`: every block then runs its constant-inductance arithmetic unchanged, bit for
//! bit. [`MachineMagnetics::Saturation`] holds the algebraic model by value;
//! [`MachineMagnetics::Map`] borrows a flux map for the program's life — a `&'static` table in
//! flash in firmware, a leaked allocation in a simulator or a binding (loaded once per model).
//! The record stays `Copy` and allocation-free either way.

use super::{FluxMap, MagneticModel, Magnetics, Saturation};
use crate::{Dq, Real};

/// The magnetic model of a [`MachineModel`](crate::MachineModel).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum MachineMagnetics<T: 'static> {
    /// Constant inductances: the record's `ld`, `lq` and `flux_linkage`.
    #[default]
    Linear,
    /// The algebraic self- and cross-saturation model.
    Saturation(Saturation<T>),
    /// A flux map on a rectangular grid, borrowed for the program's life.
    Map(FluxMap<'static, T>),
}

impl<T: Real> MachineMagnetics<T> {
    /// True for [`MachineMagnetics::Linear`].
    #[inline]
    pub fn is_linear(&self) -> bool {
        matches!(self, MachineMagnetics::Linear)
    }

    /// The model in another precision. A saturation model is rounded; a map keeps its table
    /// when `U` is `T` and is `None` otherwise (a borrowed table cannot be converted without
    /// allocating: build the map in the drive's precision, see `FluxTable`).
    pub fn cast<U: Real>(&self) -> Option<MachineMagnetics<U>> {
        match self {
            MachineMagnetics::Linear => Some(MachineMagnetics::Linear),
            MachineMagnetics::Saturation(s) => Some(MachineMagnetics::Saturation(s.cast())),
            MachineMagnetics::Map(m) => (m as &dyn core::any::Any)
                .downcast_ref::<FluxMap<'static, U>>()
                .map(|m| MachineMagnetics::Map(*m)),
        }
    }

    /// The model as a [`Magnetics`], with `linear` standing for [`MachineMagnetics::Linear`].
    #[inline]
    pub fn resolve(&self, linear: super::ConstantInductance<T>) -> Magnetics<'static, T> {
        match *self {
            MachineMagnetics::Linear => Magnetics::Constant(linear),
            MachineMagnetics::Saturation(s) => Magnetics::Saturation(s),
            MachineMagnetics::Map(m) => Magnetics::Map(m),
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
