//! A uniform-grid flux table borrowed with its shape at run time: the form a machine record
//! holds (one type for any grid size), with the table's lookup.

use super::cell_inverse::{self, CellGrid, CellPolynomial};
use super::uniform_table::{
    UniformFluxTable, axis_cell, bilinear_value, bilinear_with_jacobian, cell_of,
};
use super::{InductanceMatrix, MagneticModel};
use crate::{Dq, Real};

/// A [`UniformFluxTable`] borrowed ([`UniformFluxTable::map`]): the same lookup, its cells a
/// slice and its shape numbers, so that [`super::MachineMagnetics::Uniform`] and
/// [`super::Magnetics::Uniform`] name one type for any grid. In firmware a `static` beside its
/// table (`static MAP: UniformFluxMap<'static, f32> = TABLE.map();`), in flash. The lookup is
/// the table's with one bounds check of the cell index (a NaN result where the check fails,
/// which a map built by [`UniformFluxTable::map`] never does).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UniformFluxMap<'a, T> {
    /// (i_d[0], i_q[0]), A.
    first: Dq<T>,
    /// The inverse node spacings (1/Δ_d, 1/Δ_q), 1/A.
    inv_step: Dq<T>,
    /// The table's cells, row-major (`cells[k·n_q + m]`).
    cells: &'a [[T; 8]],
    /// ψq(i_d, 0) along each d cell (the table's `q_offset`).
    q_offset: &'a [[T; 2]],
    /// Nodes along i_q (the row length of `cells`).
    nq: usize,
    /// The last cell index along i_d and along i_q (nodes − 2).
    last: (usize, usize),
    /// The last node index along i_d and along i_q (nodes − 1): a lookup's clamp (the
    /// table's last nodes hold the edge cells' polynomials).
    last_node: (usize, usize),
}

impl<T: Copy, const ND: usize, const NQ: usize> UniformFluxTable<T, ND, NQ> {
    /// The table borrowed as a [`UniformFluxMap`] (a constant expression: a `static` beside
    /// the table's).
    pub const fn map(&self) -> UniformFluxMap<'_, T> {
        UniformFluxMap {
            first: self.first,
            inv_step: self.inv_step,
            cells: self.cells.as_flattened(),
            q_offset: &self.q_offset,
            nq: NQ,
            last: (ND.saturating_sub(2), NQ.saturating_sub(2)),
            last_node: (ND.saturating_sub(1), NQ.saturating_sub(1)),
        }
    }
}

impl<T: Real> UniformFluxMap<'_, T> {
    /// Cell (k, m)'s coefficients (NaNs outside the table).
    #[inline(always)]
    fn coefficients(&self, k: usize, m: usize) -> [T; 8] {
        match self.cells.get(k * self.nq + m) {
            Some(c) => *c,
            None => [T::lit(f64::NAN); 8],
        }
    }

    /// Whether this borrows `table`'s cells (is `table.map()`).
    #[inline]
    pub fn borrows<const ND: usize, const NQ: usize>(
        &self,
        table: &UniformFluxTable<T, ND, NQ>,
    ) -> bool {
        core::ptr::eq(self.cells, table.cells.as_flattened())
    }

    /// Whether `i` lies beyond the grid by more than its edge cell along either axis (as
    /// [`super::FluxMap::beyond_grid`]).
    pub fn beyond_grid(&self, i: Dq<T>) -> bool {
        let td = (i.d - self.first.d) * self.inv_step.d;
        let tq = (i.q - self.first.q) * self.inv_step.q;
        let end = |last: usize| T::from_index(last) + T::lit(2.0);
        let minus_one = -T::one();
        td < minus_one || tq < minus_one || td > end(self.last.0) || tq > end(self.last.1)
    }

    /// ψ(i) and the incremental inductance ∂ψ/∂i of the bilinear interpolant at `i`.
    #[inline]
    pub fn flux_and_jacobian(&self, i: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        let (k, m, fx, fy) = cell_of(self.first, self.inv_step, self.last_node, i);
        bilinear_with_jacobian(&self.coefficients(k, m), fx, fy, self.inv_step)
    }
}

impl<T: Real> MagneticModel<T> for UniformFluxMap<'_, T> {
    /// The bilinear values alone (no Jacobian), inlined into the caller (the lookup a
    /// firmware's step makes twice per sample).
    #[inline(always)]
    fn flux(&self, i: Dq<T>) -> Dq<T> {
        let (k, m, fx, fy) = cell_of(self.first, self.inv_step, self.last_node, i);
        bilinear_value(&self.coefficients(k, m), fx, fy)
    }

    /// ψq(i_d, 0) from the table's line i_q = 0: one 1-D lookup inlined into the caller.
    #[inline(always)]
    fn q_flux_offset(&self, i_d: T) -> T {
        let (k, fx) = axis_cell(self.first.d, self.inv_step.d, self.last_node.0, i_d, false);
        match self.q_offset.get(k) {
            Some(c) => c[0] + fx * c[1],
            None => T::lit(f64::NAN),
        }
    }

    /// From the map's linearisation at zero current.
    fn current(&self, psi: Dq<T>) -> Dq<T> {
        let at_zero = self.flux_and_jacobian(Dq::zero());
        cell_inverse::current_from_zero(psi, at_zero, |p, g| self.current_from(p, g))
    }

    /// In closed form cell by cell as [`super::FluxMap::current_from`]; by Newton's method
    /// where that finds no root.
    fn current_from(&self, psi: Dq<T>, guess: Dq<T>) -> Dq<T> {
        let last = self.first.d + T::from_index(self.last.0 + 1) / self.inv_step.d;
        let scale = last.abs() * T::lit(1e-6);
        cell_inverse::current_from(self, psi, guess, scale, |i| self.flux_and_jacobian(i))
    }

    #[inline]
    fn incremental_inductance(&self, i: Dq<T>) -> InductanceMatrix<T> {
        self.flux_and_jacobian(i).1
    }

    #[inline]
    fn flux_and_inductance(&self, i: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        self.flux_and_jacobian(i)
    }
}

impl<T: Real> CellGrid<T> for UniformFluxMap<'_, T> {
    #[inline]
    fn last_cell(&self) -> (usize, usize) {
        self.last
    }

    #[inline]
    fn cell_of(&self, i: Dq<T>) -> (usize, usize) {
        let (k, m, _, _) = cell_of(self.first, self.inv_step, self.last, i);
        (k, m)
    }

    #[inline]
    fn polynomial(&self, k: usize, m: usize) -> CellPolynomial<T> {
        CellPolynomial::from_coefficients(&self.coefficients(k, m))
    }

    #[inline]
    fn current_at(&self, k: usize, m: usize, u: T, v: T) -> Dq<T> {
        cell_inverse::uniform_current_at(self.first, self.inv_step, k, m, u, v)
    }
}
