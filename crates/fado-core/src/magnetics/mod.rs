//! The machine's magnetics: the stator flux linkage ψ as a function of the stator current i in
//! the rotor frame (d on the magnet), and its inverse — one model for the plant, the estimator,
//! the drive and commissioning alike (the pattern of motulator's `MagneticModel`).
//!
//! Three forms implement [`MagneticModel`]:
//! - [`ConstantInductance`]: ψ = (Ld·i_d + λf, Lq·i_q), the magnetically linear machine;
//! - [`Saturation`]: the algebraic self- and cross-saturation model of Hinkkanen et al., "Sensorless
//!   self-commissioning of synchronous reluctance motors at standstill without rotor locking",
//!   IEEE TIA 53(3), 2017, <https://doi.org/10.1109/TIA.2016.2644624>, with the magnet and the
//!   saturating rib ("bridge") of Lelli, Hinkkanen & Giulii Capponi, "A saturation model based on
//!   a simplified equivalent magnetic circuit for permanent magnet machines", ICEM 2024,
//!   <https://doi.org/10.1109/ICEM60801.2024.10700403>. It is a current map i(ψ) derived from a
//!   magnetic energy, so it is reciprocal by construction;
//! - [`FluxMap`]: a measured or computed map ψd(i_d, i_q), ψq(i_d, i_q) on a rectangular grid,
//!   interpolated bilinearly, borrowed from a `&'static` table in firmware (flash) or from a
//!   [`FluxTable`] held by value. The estimator reads it through its C¹ interpolant of the same
//!   nodes ([`FluxMap::smooth_flux_and_jacobian`]), whose incremental inductances do not jump at
//!   the cell edges.
//!
//! [`Magnetics`] holds any of the three by value (`Copy`), for records that must name one type.
//!
//! # Quantities
//! - **Incremental inductance** L_inc(i) = ∂ψ/∂i, a 2×2 [`InductanceMatrix`]: what a current
//!   controller sees for a small step, and what the flux-linkage state equation
//!   dψ/dt = v − Rs·i − ω·J·ψ turns into di/dt. For an energy-consistent model it is symmetric
//!   (reciprocity: ∂ψd/∂i_q = ∂ψq/∂i_d).
//! - **Secant q inductance** L_q,s(i) = ψq/i_q: the one inductance that makes the active flux
//!   ψ − L_q,s·i lie on the d axis for any map (its q component is ψq − (ψq/i_q)·i_q = 0).
//!   [`MagneticModel::active_flux`] is its d component, ψd − L_q,s·i_d.
//! - **Torque** from the co-energy: T = 1.5·p·(ψd·i_q − ψq·i_d) ([`MagneticModel::torque`]).
//!   For a magnetically linear machine it is 1.5·p·(λf·i_q + (Ld − Lq)·i_d·i_q).
//!
//! # Inversion
//! A flux map's i(ψ) is solved in closed form: inside one cell the bilinear map is inverted by
//! a quadratic, starting in the cell of a warm start (a plant's last current) and walking to
//! the neighbouring cell the solution points into, one or two cells per inversion — Newton's
//! method on the whole map needs three evaluations or more and stalls on the kinks of its
//! Jacobian at the cell edges (it remains the fallback where a cell's quadratic has no real
//! root). A caller that inverts many times from one warm start (a plant's Runge–Kutta stages)
//! keeps the start's cell and the last cells' polynomials in an [`InverseCache`]: the same walk
//! and arithmetic, so the same result to the bit, without finding the start cell or loading a
//! cell's corners again. The algebraic model's ψ(i) (its inverse form) is solved by
//! Newton's method on the model's own Jacobian, from the magnetically linear guess or from a
//! caller's warm start: at most [`NEWTON_ITERATIONS`] steps, stopping when the step is below
//! √ε/16 of the solution's size (then the error is of the order of ε), and again from the
//! linear guess where a warm start's solve does not stop within them. A block that solves it
//! every sample keeps the tangent plane of its last solution ([`FluxWarmStart`]): one step
//! and the one that confirms it. Saturation curves are
//! monotonic and convex (i(ψ)) or concave (ψ(i)) on each side of the origin, where Newton's
//! iterates from the linear guess converge monotonically; the tests check inverse ∘ forward = 1.
//!
//! Nothing here allocates, panics or uses `unsafe`; a non-finite argument gives a non-finite
//! result, which callers reject as they reject any non-finite sample.

mod cell_inverse;
mod constant;
mod flux_map;
mod inverse_cache;
mod lookup;
mod machine;
mod saturation;
mod smooth_map;
mod uniform_map;
mod uniform_table;
mod warm_start;

pub use constant::ConstantInductance;
pub use flux_map::{FluxMap, FluxMapError, FluxTable};
pub use inverse_cache::{InverseCache, REFINE_TOLERANCE};
pub use lookup::FluxLookup;
pub use machine::{MachineMagnetics, zero_current_constants};
pub use saturation::Saturation;
pub use uniform_map::UniformFluxMap;
pub use uniform_table::UniformFluxTable;
pub use warm_start::FluxWarmStart;

use crate::{Dq, Real};

/// The most Newton steps an inversion takes (quadratic convergence needs 3–6 from the linear
/// guess on the saturation curves of real machines; a bilinear map's cell edges may need more).
pub const NEWTON_ITERATIONS: usize = 24;

/// A 2×2 matrix acting on d-q vectors: an incremental inductance ∂ψ/∂i (H) or its inverse
/// ∂i/∂ψ (1/H). `dq` is the entry in row d, column q (∂ψd/∂i_q).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InductanceMatrix<T> {
    /// Row d, column d.
    pub dd: T,
    /// Row d, column q.
    pub dq: T,
    /// Row q, column d.
    pub qd: T,
    /// Row q, column q.
    pub qq: T,
}

impl<T: Real> InductanceMatrix<T> {
    /// The diagonal matrix diag(d, q).
    pub fn diagonal(d: T, q: T) -> Self {
        Self {
            dd: d,
            dq: T::zero(),
            qd: T::zero(),
            qq: q,
        }
    }

    /// Determinant.
    #[inline]
    pub fn det(&self) -> T {
        self.dd * self.qq - self.dq * self.qd
    }

    /// The inverse matrix (non-finite entries when the matrix is singular).
    #[inline]
    pub fn inverse(&self) -> Self {
        let k = T::one() / self.det();
        Self {
            dd: self.qq * k,
            dq: -self.dq * k,
            qd: -self.qd * k,
            qq: self.dd * k,
        }
    }

    /// The product with a d-q vector.
    #[inline]
    pub fn apply(&self, x: Dq<T>) -> Dq<T> {
        Dq::new(self.dd * x.d + self.dq * x.q, self.qd * x.d + self.qq * x.q)
    }

    /// `A·x = b` solved for x (Cramer's rule).
    #[inline]
    pub fn solve(&self, b: Dq<T>) -> Dq<T> {
        let k = T::one() / self.det();
        Dq::new(
            (self.qq * b.d - self.dq * b.q) * k,
            (self.dd * b.q - self.qd * b.d) * k,
        )
    }
}

/// A magnetic model of a synchronous machine in its rotor frame: ψ(i), i(ψ) and their
/// Jacobians. Every quantity is SI, peak, per phase (amplitude-invariant transform).
///
/// Implementors give the two maps and one Jacobian; the derived quantities (torque, secant q
/// inductance, active flux, the magnet's flux) are provided.
pub trait MagneticModel<T: Real> {
    /// Stator flux linkage ψ(i) in Wb.
    fn flux(&self, i: Dq<T>) -> Dq<T>;

    /// Stator current i(ψ) in A, the inverse of [`MagneticModel::flux`].
    fn current(&self, psi: Dq<T>) -> Dq<T>;

    /// i(ψ) starting Newton's method (where the model needs it) from `guess`, a current near
    /// the answer (a plant's last current): the same result as [`MagneticModel::current`] in
    /// fewer steps. Models with a closed-form i(ψ) ignore the guess.
    fn current_from(&self, psi: Dq<T>, guess: Dq<T>) -> Dq<T> {
        let _ = guess;
        self.current(psi)
    }

    /// ψ(i) starting Newton's method (where the model needs it) from `guess`, a flux near the
    /// answer (the model's flux at a nearby current: the last sample's, the last iterate of a
    /// solve around ψ(i)): the same result as [`MagneticModel::flux`] to the solver's tolerance
    /// in fewer steps. Models with a closed-form ψ(i) ignore the guess; a non-finite guess
    /// starts where [`MagneticModel::flux`] starts.
    fn flux_from(&self, i: Dq<T>, guess: Dq<T>) -> Dq<T> {
        let _ = guess;
        self.flux(i)
    }

    /// Incremental inductance ∂ψ/∂i at the current `i`, in H.
    fn incremental_inductance(&self, i: Dq<T>) -> InductanceMatrix<T>;

    /// ψ(i) and the incremental inductance ∂ψ/∂i at `i` together: the values of
    /// [`MagneticModel::flux`] and [`MagneticModel::incremental_inductance`], with one
    /// inversion where the model's ψ(i) is one.
    fn flux_and_inductance(&self, i: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        (self.flux(i), self.incremental_inductance(i))
    }

    /// ψ(i) from `guess` as [`MagneticModel::flux_from`], and the incremental inductance
    /// ∂ψ/∂i there: a model whose ψ(i) is an inversion gives the inverse of the Jacobian its
    /// Newton's method last evaluated, within the last (converged) step of ψ(i).
    fn flux_and_inductance_from(&self, i: Dq<T>, guess: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        let _ = guess;
        self.flux_and_inductance(i)
    }

    /// Electromagnetic torque 1.5·p·(ψd·i_q − ψq·i_d) in N·m, from the co-energy.
    fn torque(&self, pole_pairs: u32, i: Dq<T>) -> T {
        let psi = self.flux(i);
        T::lit(1.5 * pole_pairs as f64) * (psi.d * i.q - psi.q * i.d)
    }

    /// The q flux at zero q current, ψq(i_d, 0), in Wb: zero for a model odd in i_q (the
    /// constant and algebraic models, a map made symmetric); a measured map keeps a few per
    /// cent of the magnet's flux there (the test bench's angle offset and iron losses).
    fn q_flux_offset(&self, i_d: T) -> T {
        self.flux(Dq::new(i_d, T::zero())).q
    }

    /// Secant q inductance L_q,s = (ψq − ψq(i_d, 0))/i_q in H: finite
    /// through i_q = 0 whether or not the model is odd in i_q.
    fn secant_q(&self, i: Dq<T>) -> T {
        let psi = self.flux(i);
        secant_q_from(i, psi.q, self.q_flux_offset(i.d), || {
            self.incremental_inductance(i).qq
        })
    }

    /// Magnitude of the active flux ψd − L_q,s·i_d in Wb (Boldea et al., IEEE TPEL 23(5),
    /// 2008, generalised to any map with the secant q inductance): ψ − L_q,s·i is
    /// (λa, ψq(i_d, 0)), on d for a model odd in i_q, else at the angle
    /// atan(ψq(i_d, 0)/λa) from d ([`MagneticModel::q_flux_offset`]).
    fn active_flux(&self, i: Dq<T>) -> T {
        self.flux(i).d - self.secant_q(i) * i.d
    }

    /// The magnet's flux linkage ψd(0, 0) in Wb (λf of a linear model).
    fn magnet_flux(&self) -> T {
        self.flux(Dq::zero()).d
    }
}

/// The secant q inductance (ψq − ψq(i_d, 0))/i_q from the q flux `psi_q` at the current `i`
/// and the model's `offset` ψq(i_d, 0): removing the offset keeps the secant finite and
/// smooth through i_q = 0 on a map that is not odd in i_q (the plain ψq/i_q grows as
/// ψq(i_d, 0)/i_q there). Below |i_q| = 1 µA, `incremental` (∂ψq/∂i_q, the secant's limit).
#[inline]
fn secant_q_from<T: Real>(i: Dq<T>, psi_q: T, offset: T, incremental: impl Fn() -> T) -> T {
    if i.q.abs() < T::lit(1e-6) {
        incremental()
    } else {
        (psi_q - offset) / i.q
    }
}

/// Newton's method for `f(x) = target` with `f` returning the value and its Jacobian at x.
/// Stops when the step is below √ε/16 of |x| + `scale` (ε the type's epsilon), or after
/// [`NEWTON_ITERATIONS`] steps; returns the last iterate (non-finite if `target` is) and the
/// Jacobian of the one before it (within that last step of the answer).
pub(crate) fn newton<T: Real>(
    target: Dq<T>,
    x: Dq<T>,
    scale: T,
    f: impl Fn(Dq<T>) -> (Dq<T>, InductanceMatrix<T>),
) -> (Dq<T>, InductanceMatrix<T>) {
    let (x, last, _) = newton_checked(target, x, scale, f);
    (x, last)
}

/// [`newton`], and whether it stopped on its test (false: after [`NEWTON_ITERATIONS`] steps,
/// or on a step that is not finite).
pub(crate) fn newton_checked<T: Real>(
    target: Dq<T>,
    mut x: Dq<T>,
    scale: T,
    f: impl Fn(Dq<T>) -> (Dq<T>, InductanceMatrix<T>),
) -> (Dq<T>, InductanceMatrix<T>, bool) {
    // Quadratic convergence: after a step of √ε/16 the error is of the order of ε.
    let tol = T::default_epsilon().sqrt() * T::lit(1.0 / 16.0);
    let mut last = InductanceMatrix::default();
    for _ in 0..NEWTON_ITERATIONS {
        let (y, jac) = f(x);
        last = jac;
        let step = jac.solve(y - target);
        x -= step;
        if !step.is_finite() {
            break;
        }
        if step.norm() <= tol * (x.norm() + scale) {
            return (x, last, true);
        }
    }
    (x, last, false)
}

/// Any of the three magnetic models, by value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Magnetics<'a, T> {
    /// Constant inductances.
    Constant(ConstantInductance<T>),
    /// The algebraic saturation model.
    Saturation(Saturation<T>),
    /// A flux map on a rectangular grid.
    Map(FluxMap<'a, T>),
    /// A flux map on a uniform grid, its cells' coefficients precomputed.
    Uniform(UniformFluxMap<'a, T>),
}

impl<T: Real> Magnetics<'_, T> {
    /// True for constant inductances (a plant keeps its closed-form path for them).
    pub fn is_linear(&self) -> bool {
        matches!(self, Magnetics::Constant(_))
    }

    /// [`MagneticModel::current_from`], a map's with the warm start's cell kept in `cache`
    /// ([`InverseCache`], one per model): the same result.
    #[inline]
    pub fn current_from_cached(
        &self,
        psi: Dq<T>,
        guess: Dq<T>,
        cache: &mut InverseCache<T>,
    ) -> Dq<T> {
        match self {
            Magnetics::Map(m) => cache.current_from(m, psi, guess),
            Magnetics::Uniform(m) => cache.current_from(m, psi, guess),
            _ => self.current_from(psi, guess),
        }
    }

    /// [`Magnetics::current_from_cached`] at a flux a hair from the cache's last solution: a
    /// map's by Newton's steps in that solution's cell (one, or two where the first misses)
    /// where that is the root to [`REFINE_TOLERANCE`] of the cell (`InverseCache::refine`),
    /// else as `current_from_cached`.
    #[inline]
    pub fn current_near_cached(
        &self,
        psi: Dq<T>,
        guess: Dq<T>,
        cache: &mut InverseCache<T>,
    ) -> Dq<T> {
        self.current_near_cached_to(psi, guess, cache, T::lit(REFINE_TOLERANCE))
    }

    /// [`Magnetics::current_near_cached`] with the Newton steps taken where their error is below
    /// `tolerance` of the cell instead of [`REFINE_TOLERANCE`]: for a current whose error a
    /// caller scales down (a Runge–Kutta stage's enters the step's flux through R·h/3).
    #[inline]
    pub fn current_near_cached_to(
        &self,
        psi: Dq<T>,
        guess: Dq<T>,
        cache: &mut InverseCache<T>,
        tolerance: T,
    ) -> Dq<T> {
        let near = match self {
            Magnetics::Map(m) => cache.refine(m, psi, tolerance),
            Magnetics::Uniform(m) => cache.refine(m, psi, tolerance),
            _ => None,
        };
        near.unwrap_or_else(|| self.current_from_cached(psi, guess, cache))
    }
}

macro_rules! dispatch {
    ($self:ident, $m:ident => $e:expr) => {
        match $self {
            Magnetics::Constant($m) => $e,
            Magnetics::Saturation($m) => $e,
            Magnetics::Map($m) => $e,
            Magnetics::Uniform($m) => $e,
        }
    };
}

impl<T: Real> MagneticModel<T> for Magnetics<'_, T> {
    fn flux(&self, i: Dq<T>) -> Dq<T> {
        dispatch!(self, m => m.flux(i))
    }
    fn current(&self, psi: Dq<T>) -> Dq<T> {
        dispatch!(self, m => m.current(psi))
    }
    fn current_from(&self, psi: Dq<T>, guess: Dq<T>) -> Dq<T> {
        dispatch!(self, m => m.current_from(psi, guess))
    }
    fn flux_from(&self, i: Dq<T>, guess: Dq<T>) -> Dq<T> {
        dispatch!(self, m => m.flux_from(i, guess))
    }
    fn incremental_inductance(&self, i: Dq<T>) -> InductanceMatrix<T> {
        dispatch!(self, m => m.incremental_inductance(i))
    }
    fn q_flux_offset(&self, i_d: T) -> T {
        dispatch!(self, m => m.q_flux_offset(i_d))
    }
    fn flux_and_inductance(&self, i: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        dispatch!(self, m => m.flux_and_inductance(i))
    }
    fn flux_and_inductance_from(&self, i: Dq<T>, guess: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        dispatch!(self, m => m.flux_and_inductance_from(i, guess))
    }
}

#[cfg(test)]
pub(crate) mod tests;
