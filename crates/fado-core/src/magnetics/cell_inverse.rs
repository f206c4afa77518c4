//! The inverse i(ψ) of a bilinear flux map in closed form, cell by cell.
//!
//! Inside one cell of a grid the map is ψ = p00 + ex·u + ey·v + twist·u·v (each coefficient a
//! d-q vector, u and v the fractions along i_d and i_q). Eliminating u leaves a quadratic in v
//! (the inverse of bilinear interpolation):
//!
//! ```text
//!   h = ψ − p00,   k2·v² + k1·v + k0 = 0,
//!   k2 = twist × ey,   k1 = ex × ey + h × twist,   k0 = h × ex,   u = (h_d − ey_d·v)/(ex_d + twist_d·v)
//! ```
//!
//! (× the 2-D cross product), solved by the cancellation-free form of its roots, so that a
//! cell that is a parallelogram (twist = 0, k2 = 0) needs no special case. A map that
//! [`super::FluxMap::new`] accepts has ψd increasing in i_d along every row, so the
//! denominator ex_d + twist_d·v is positive across the cell.
//!
//! The inverse starts in the cell of a warm start (the last current), jumps once to the cell
//! of that cell's extrapolated solution, and from there walks to the neighbouring cell the
//! solution points into until the solution lies in the cell it was
//! solved in (to [`CELL_TOLERANCE_EPS`]), or beyond the grid in an edge cell (the map's linear
//! extension); the result reproduces ψ to a few ulp (tested). Each cell costs one square root
//! and three divisions; a plant's sub-step stays in its cell or
//! moves to a neighbour, so one or two cells per inversion, where Newton's method on the whole
//! map needs three evaluations or more and stalls on the kinks of the Jacobian between cells.
//! Where a cell's polynomial has no real root (the point lies where that cell's extension
//! folds over), the cell's linearisation at its centre gives the direction of the walk. A walk
//! that ends in a cell with no root or walks longer than the grid (a map with no inverse
//! there) returns None: the caller falls back to Newton's method.

use super::{InductanceMatrix, newton};
use crate::{Dq, Real};

/// Tolerance, in units of the type's ε, of a fraction outside [0, 1] that still counts as in
/// its cell: the two cells on either side of an edge solve the same point to rounding, and
/// without it the walk could alternate between them.
const CELL_TOLERANCE_EPS: f64 = 64.0;

/// [`CELL_TOLERANCE_EPS`] in the type's units.
#[inline(always)]
pub(super) fn cell_tolerance<T: Real>() -> T {
    T::default_epsilon() * T::lit(CELL_TOLERANCE_EPS)
}

/// One cell's bilinear polynomial ψ(u, v) = p00 + ex·u + ey·v + twist·u·v, u and v its
/// fractions along i_d and i_q.
#[derive(Clone, Copy, Debug)]
pub(super) struct CellPolynomial<T> {
    pub p00: Dq<T>,
    pub ex: Dq<T>,
    pub ey: Dq<T>,
    pub twist: Dq<T>,
}

/// A grid of cells the inverse walks: its shape, the cell of a current, each cell's polynomial
/// and the current at fractions of a cell.
pub(super) trait CellGrid<T: Real> {
    /// The last cell index along i_d and along i_q (nodes − 2).
    fn last_cell(&self) -> (usize, usize);
    /// The cell (k, m) holding the current `i` (clamped to the edge cells).
    fn cell_of(&self, i: Dq<T>) -> (usize, usize);
    /// Cell (k, m)'s polynomial (NaNs where there is no such cell).
    fn polynomial(&self, k: usize, m: usize) -> CellPolynomial<T>;
    /// The current at the fractions (u, v) of cell (k, m).
    fn current_at(&self, k: usize, m: usize, u: T, v: T) -> Dq<T>;
}

#[inline(always)]
fn cross<T: Real>(a: Dq<T>, b: Dq<T>) -> T {
    a.d * b.q - a.q * b.d
}

impl<T: Real> CellPolynomial<T> {
    /// From a uniform table's interleaved coefficients [ψd: p00, ex, ey, twist; ψq: the same].
    #[inline]
    pub fn from_coefficients(c: &[T; 8]) -> Self {
        Self {
            p00: Dq::new(c[0], c[4]),
            ex: Dq::new(c[1], c[5]),
            ey: Dq::new(c[2], c[6]),
            twist: Dq::new(c[3], c[7]),
        }
    }

    /// ψ at the fractions (u, v) and its Jacobian ∂ψ/∂(u, v).
    #[inline]
    fn eval(&self, u: T, v: T) -> (Dq<T>, InductanceMatrix<T>) {
        let du = self.ex + self.twist * v;
        let dv = self.ey + self.twist * u;
        let psi = self.p00 + self.ex * u + dv * v;
        let jac = InductanceMatrix {
            dd: du.d,
            dq: dv.d,
            qd: du.q,
            qq: dv.q,
        };
        (psi, jac)
    }

    /// The fractions (u, v) at the root v = `num`/`den`: u from the d row, whose coefficient
    /// of u is positive in the cell, (h_d − ey_d·v)/(ex_d + twist_d·v) with both terms
    /// multiplied by `den`, so that u's division does not wait for v's.
    #[inline]
    fn root_at(&self, h: Dq<T>, num: T, den: T) -> (T, T) {
        let u = (h.d * den - self.ey.d * num) / (self.ex.d * den + self.twist.d * num);
        (u, num / den)
    }

    /// The quadratic's coefficients that do not depend on ψ: (k2, ex × ey).
    #[inline]
    pub fn constants(&self) -> (T, T) {
        (cross(self.twist, self.ey), cross(self.ex, self.ey))
    }

    /// The fractions (u, v) where the polynomial is `psi`, given the cell's
    /// [`CellPolynomial::constants`]: of the (up to) two roots the one nearer the cell; None if
    /// there is no real root.
    pub fn solve_with(&self, psi: Dq<T>, (k2, ex_ey): (T, T)) -> Option<(T, T)> {
        let h = psi - self.p00;
        let k1 = ex_ey + cross(h, self.twist);
        let k0 = cross(h, self.ex);
        let disc = k1 * k1 - T::lit(4.0) * k2 * k0;
        if !disc.is_finite() || disc < T::zero() {
            return None;
        }
        // q = −(k1 + sign(k1)·√disc)/2: the roots k0/q and q/k2 without cancellation.
        let root = disc.sqrt();
        let q = T::lit(-0.5)
            * if k1 >= T::zero() {
                k1 + root
            } else {
                k1 - root
            };
        let near = self.root_at(h, k0, q);
        let first = if near.1.is_finite() {
            near
        } else {
            self.root_at(h, q, k2)
        };
        if k2 == T::zero() || outside(first) == T::zero() {
            return first.0.is_finite().then_some(first);
        }
        let second = self.root_at(h, q, k2);
        let better = if outside(second) < outside(first) {
            second
        } else {
            first
        };
        (better.0.is_finite() && better.1.is_finite()).then_some(better)
    }

    /// (u, v) after one Newton step on this polynomial towards `psi`.
    #[inline]
    pub fn newton_step(&self, psi: Dq<T>, (u, v): (T, T)) -> (T, T) {
        let (y, jac) = self.eval(u, v);
        let step = jac.solve(psi - y);
        (u + step.d, v + step.q)
    }
}

/// How far the fractions lie outside the unit cell (0 inside).
#[inline]
fn outside<T: Real>((u, v): (T, T)) -> T {
    let o = |x: T| {
        if x < T::zero() {
            -x
        } else if x > T::one() {
            x - T::one()
        } else {
            T::zero()
        }
    };
    let s = o(u) + o(v);
    if s.is_finite() {
        s
    } else {
        T::lit(f64::INFINITY)
    }
}

/// −1, 0 or +1: the neighbouring cell along one axis the fraction `x` of cell `k` points into
/// (0 inside the cell to the tolerance, or beyond the grid in an edge cell).
#[inline]
pub(super) fn direction<T: Real>(x: T, k: usize, last: usize, tol: T) -> isize {
    if x < -tol && k > 0 {
        -1
    } else if x > T::one() + tol && k < last {
        1
    } else {
        0
    }
}

/// i(ψ) on `grid` from the cell of `guess` (module docs); None where the closed form finds no
/// root or the walk does not settle.
pub(super) fn invert<T: Real>(grid: &impl CellGrid<T>, psi: Dq<T>, guess: Dq<T>) -> Option<Dq<T>> {
    invert_from(grid, grid.cell_of(guess), |k, m| {
        let cell = grid.polynomial(k, m);
        cell.root_or_direction(psi, cell.constants())
    })
    .map(|(i, _)| i)
}

/// A solution's cell and its fractions there: (k, m, u, v).
pub(super) type Solved<T> = (usize, usize, T, T);

impl<T: Real> CellPolynomial<T> {
    /// The root (u, v) at `psi` as [`CellPolynomial::solve_with`], and the fractions the walk
    /// follows: the root, or where there is none (the point lies where this cell's extension
    /// folds) this cell's linearisation at its centre, which still points towards the
    /// solution's cell.
    #[inline]
    pub fn root_or_direction(&self, psi: Dq<T>, constants: (T, T)) -> (Option<(T, T)>, (T, T)) {
        let root = self.solve_with(psi, constants);
        let half = T::lit(0.5);
        (
            root,
            root.unwrap_or_else(|| self.newton_step(psi, (half, half))),
        )
    }
}

/// [`invert`] from the cell `start` (the warm start's), with cell (k, m)'s
/// [`CellPolynomial::root_or_direction`] at the ψ sought from `solve_at` (a cache's,
/// [`super::InverseCache`]).
#[inline]
pub(super) fn invert_from<T: Real>(
    grid: &impl CellGrid<T>,
    start: (usize, usize),
    mut solve_at: impl FnMut(usize, usize) -> (Option<(T, T)>, (T, T)),
) -> Option<(Dq<T>, Solved<T>)> {
    let (last_k, last_m) = grid.last_cell();
    let (mut k, mut m) = start;
    let tol = cell_tolerance::<T>();
    for walk in 0..last_k + last_m + 2 {
        let (root, (u, v)) = solve_at(k, m);
        let (dk, dm) = (direction(u, k, last_k, tol), direction(v, m, last_m, tol));
        if dk == 0 && dm == 0 {
            let (u, v) = root?;
            let i = grid.current_at(k, m, u, v);
            return i.is_finite().then_some((i, (k, m, u, v)));
        }
        if walk == 0 && u.is_finite() && v.is_finite() {
            // From the warm start's cell, straight to the cell of this cell's extrapolated
            // solution (a Newton step's worth): a far warm start costs two or three cells.
            let jump = grid.cell_of(grid.current_at(k, m, u, v));
            if jump != (k, m) {
                (k, m) = jump;
                continue;
            }
        }
        k = k.wrapping_add_signed(dk);
        m = m.wrapping_add_signed(dm);
    }
    None
}

/// The current at the fractions (u, v) of cell (k, m) of a uniform grid from `first` with
/// inverse spacings `inv_step`.
#[inline]
pub(super) fn uniform_current_at<T: Real>(
    first: Dq<T>,
    inv_step: Dq<T>,
    k: usize,
    m: usize,
    u: T,
    v: T,
) -> Dq<T> {
    Dq::new(
        first.d + (T::from_index(k) + u) / inv_step.d,
        first.q + (T::from_index(m) + v) / inv_step.q,
    )
}

/// i(ψ) on `grid` by [`invert`] from the cell of `guess`, by Newton's method on
/// `flux_and_jacobian` from `guess` (steps relative to `scale`) where that finds no root: a
/// bilinear map's [`super::MagneticModel::current_from`].
#[inline]
pub(super) fn current_from<T: Real>(
    grid: &impl CellGrid<T>,
    psi: Dq<T>,
    guess: Dq<T>,
    scale: T,
    flux_and_jacobian: impl Fn(Dq<T>) -> (Dq<T>, InductanceMatrix<T>),
) -> Dq<T> {
    invert(grid, psi, guess).unwrap_or_else(|| newton(psi, guess, scale, flux_and_jacobian).0)
}

/// i(ψ) on `grid` from the map's linearisation at zero current (`at_zero`, its ψ and ∂ψ/∂i
/// there) as the guess: a bilinear map's [`super::MagneticModel::current`].
#[inline]
pub(super) fn current_from_zero<T: Real>(
    psi: Dq<T>,
    at_zero: (Dq<T>, InductanceMatrix<T>),
    current_from: impl Fn(Dq<T>, Dq<T>) -> Dq<T>,
) -> Dq<T> {
    let (psi0, l0) = at_zero;
    current_from(psi, l0.solve(psi - psi0))
}
