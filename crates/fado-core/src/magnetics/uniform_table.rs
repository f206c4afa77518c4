//! A flux map on a uniform grid held by value, for the lookup a firmware's interrupt makes.

use super::{FluxTable, InductanceMatrix, MagneticModel};
use crate::{Dq, Real};

/// A flux map ψd(i_d, i_q), ψq(i_d, i_q) on a uniform `ND` × `NQ` grid, held by value (a
/// `static` in flash), interpolated bilinearly as [`super::FluxMap`] interpolates it, with
/// the lookup reduced to what a Cortex-M4F does fastest:
/// - the cell from the precomputed inverse node spacing, t = (x − x₀)·(1/Δ), its index ⌊t⌋
///   clamped to the nodes by one compare (by one saturation where the node count is a power
///   of two; a NaN to the first) and the fraction t − ⌊t⌋: no search, no division, no load of
///   an axis;
/// - each node's bilinear coefficients precomputed and interleaved — ψd's and ψq's
///   (p00, p10 − p00, p01 − p00, p11 − p10 − p01 + p00) side by side, eight adjacent words —
///   so that a lookup loads one run and multiplies and adds six times per table (the last
///   row and column of nodes hold the edge cell's polynomial re-expressed at their node, for
///   the linear extension beyond the grid);
/// - ψq(i_d, 0), the secant's offset, on its own line: one 1-D lookup;
/// - the array's shape in the type, so that every index is proven in bounds (no check).
///
/// Built from a [`FluxTable`] whose axes are uniform (within rounding) and whose map
/// [`super::FluxMap::new`] accepts: [`UniformFluxTable::new`] at run time,
/// [`UniformFluxTable::from_f32_table`] in a constant expression (a `static`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UniformFluxTable<T, const ND: usize, const NQ: usize> {
    /// (i_d[0], i_q[0]), A.
    pub(super) first: Dq<T>,
    /// The inverse node spacings (1/Δ_d, 1/Δ_q), 1/A.
    pub(super) inv_step: Dq<T>,
    /// Node (k, m)'s coefficients [ψd: p00, ex, ey, twist; ψq: the same] in `cells[k][m]`:
    /// cell (k, m)'s polynomial, the edge cell's at the last nodes (see the type's docs), Wb.
    pub(super) cells: [[[T; 8]; NQ]; ND],
    /// ψq(i_d, 0) from d node `k`, [value at the node, change across the cell]: the
    /// interpolant's own values on the line i_q = 0 (linear in i_d in each cell), so that the
    /// secant's offset is one 1-D lookup, not a second 2-D one.
    pub(super) q_offset: [[T; 2]; ND],
}

impl<T: Real, const ND: usize, const NQ: usize> UniformFluxTable<T, ND, NQ> {
    /// The table's map on its uniform grid; None if [`FluxTable::map`] refuses it or an axis
    /// is not uniform.
    pub fn new(table: &FluxTable<T, ND, NQ>) -> Option<Self> {
        let map = table.map().ok()?;
        let (d, q) = map.axis_scales();
        if !(d.uniform && q.uniform) {
            return None;
        }
        let first = Dq::new(d.first, q.first);
        let inv_step = Dq::new(d.inv_step, q.inv_step);
        let cells = core::array::from_fn(|k| {
            core::array::from_fn(|m| node_coefficients(&table.psi_d, &table.psi_q, k, m))
        });
        let q_offset = q_offset_line(&cells, &first, &inv_step);
        Some(Self {
            first,
            inv_step,
            cells,
            q_offset,
        })
    }

    /// The node (k, m) of `i` and the fractions from it (outside [0, 1] beyond the grid).
    #[inline(always)]
    fn cell(&self, i: Dq<T>) -> (usize, usize, T, T) {
        let (k, fx) = axis_cell(
            self.first.d,
            self.inv_step.d,
            ND.saturating_sub(1),
            i.d,
            true,
        );
        let (m, fy) = axis_cell(
            self.first.q,
            self.inv_step.q,
            NQ.saturating_sub(1),
            i.q,
            true,
        );
        (k, m, fx, fy)
    }

    /// Cell (k, m)'s coefficients (NaNs where the shape is too small for a cell).
    #[inline(always)]
    fn coefficients(&self, k: usize, m: usize) -> [T; 8] {
        match self.cells.get(k).and_then(|r| r.get(m)) {
            Some(c) => *c,
            None => [T::lit(f64::NAN); 8],
        }
    }

    /// ψ(i) and the incremental inductance ∂ψ/∂i of the bilinear interpolant at `i`.
    #[inline]
    pub fn flux_and_jacobian(&self, i: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        let (k, m, fx, fy) = self.cell(i);
        bilinear_with_jacobian(&self.coefficients(k, m), fx, fy, self.inv_step)
    }

    /// ψq(i_d, 0) of the interpolant: one 1-D lookup (`q_offset`).
    #[inline(always)]
    fn q_offset_at(&self, i_d: T) -> T {
        let (k, fx) = axis_cell(
            self.first.d,
            self.inv_step.d,
            ND.saturating_sub(1),
            i_d,
            true,
        );
        match self.q_offset.get(k) {
            Some(c) => c[0] + fx * c[1],
            None => T::lit(f64::NAN),
        }
    }
}

/// The cell along one uniform axis from `first` with inverse spacing `inv_step` of `x`,
/// clamped to the cells up to `last` (a NaN to the first), and the fraction along it;
/// `constant`: `last` is a constant of the caller's code ([`Real::index_floor_const`]).
#[inline(always)]
pub(super) fn axis_cell<T: Real>(
    first: T,
    inv_step: T,
    last: usize,
    x: T,
    constant: bool,
) -> (usize, T) {
    let t = (x - first) * inv_step;
    let k = if constant {
        t.index_floor_const(last)
    } else {
        t.index_floor(last)
    };
    (k, t - T::from_index(k))
}

/// Node (k, m)'s coefficients from the tables `pd`, `pq` (see [`UniformFluxTable`]): cell
/// (a, b) = (min(k, ND − 2), min(m, NQ − 2))'s bilinear polynomial at node (k, m), i.e.
/// p00 = ψ(k, m), ex = ψ(a+1, m) − ψ(a, m), ey = ψ(k, b+1) − ψ(k, b) and the cell's twist
/// (the usual four inside, the edge cell's shifted by a node at the last row and column).
fn node_coefficients<T: Real, const ND: usize, const NQ: usize>(
    pd: &[[T; NQ]; ND],
    pq: &[[T; NQ]; ND],
    k: usize,
    m: usize,
) -> [T; 8] {
    let (a, b) = (k.min(ND - 2), m.min(NQ - 2));
    let c = |t: &[[T; NQ]; ND]| {
        [
            t[k][m],
            t[a + 1][m] - t[a][m],
            t[k][b + 1] - t[k][b],
            t[a + 1][b + 1] - t[a + 1][b] - t[a][b + 1] + t[a][b],
        ]
    };
    let (d, q) = (c(pd), c(pq));
    [d[0], d[1], d[2], d[3], q[0], q[1], q[2], q[3]]
}

/// The table's line i_q = 0 (`q_offset`) from its nodes' coefficients: the q node of
/// i_q = 0 and the fraction from it, as a lookup at (i_d, 0) finds them.
fn q_offset_line<T: Real, const ND: usize, const NQ: usize>(
    cells: &[[[T; 8]; NQ]; ND],
    first: &Dq<T>,
    inv_step: &Dq<T>,
) -> [[T; 2]; ND] {
    let (m0, fy0) = axis_cell(first.q, inv_step.q, NQ.saturating_sub(1), T::zero(), false);
    core::array::from_fn(|k| {
        let c = &cells[k][m0];
        [c[4] + fy0 * c[6], c[5] + fy0 * c[7]]
    })
}

/// The cell (k, m) of `i` on a uniform grid from `first` with inverse spacings `inv_step`,
/// clamped to the cells up to `last` (a NaN to the first), and the fractions along it: no
/// search, no division.
#[inline(always)]
pub(super) fn cell_of<T: Real>(
    first: Dq<T>,
    inv_step: Dq<T>,
    last: (usize, usize),
    i: Dq<T>,
) -> (usize, usize, T, T) {
    let (k, fx) = axis_cell(first.d, inv_step.d, last.0, i.d, false);
    let (m, fy) = axis_cell(first.q, inv_step.q, last.1, i.q, false);
    (k, m, fx, fy)
}

/// ψ from a cell's interleaved coefficients at the fractions (fx, fy).
#[inline(always)]
pub(super) fn bilinear_value<T: Real>(c: &[T; 8], fx: T, fy: T) -> Dq<T> {
    let value = |j: usize| c[j] + fx * c[j + 1] + fy * (c[j + 2] + fx * c[j + 3]);
    Dq::new(value(0), value(4))
}

/// ψ and ∂ψ/∂i from a cell's interleaved coefficients at the fractions (fx, fy), the grid's
/// inverse spacings `inv_step`.
#[inline(always)]
pub(super) fn bilinear_with_jacobian<T: Real>(
    c: &[T; 8],
    fx: T,
    fy: T,
    inv_step: Dq<T>,
) -> (Dq<T>, InductanceMatrix<T>) {
    let (g, h) = (inv_step.d, inv_step.q);
    let axis = |j: usize| {
        let (p00, ex, ey, twist) = (c[j], c[j + 1], c[j + 2], c[j + 3]);
        (
            p00 + fx * ex + fy * (ey + fx * twist),
            (ex + fy * twist) * g,
            (ey + fx * twist) * h,
        )
    };
    let (d, dd, dq) = axis(0);
    let (q, qd, qq) = axis(4);
    (Dq::new(d, q), InductanceMatrix { dd, dq, qd, qq })
}

impl<const ND: usize, const NQ: usize> UniformFluxTable<f32, ND, NQ> {
    /// [`UniformFluxTable::new`] in a constant expression (`static MAP: UniformFluxTable<f32,
    /// 16, 16> = UniformFluxTable::from_f32_table(&TABLE);`): the checks run by the compiler,
    /// so that a table with a non-uniform axis or one [`FluxTable::const_map`] refuses does
    /// not build.
    pub const fn from_f32_table(table: &FluxTable<f32, ND, NQ>) -> Self {
        let (d, q) = table.const_map().axis_scales();
        assert!(
            d.uniform && q.uniform,
            "an axis of the table is not uniform"
        );
        assert!(
            ND >= 2 && NQ >= 2,
            "a flux map needs two nodes or more per axis"
        );
        let mut cells = [[[0.0; 8]; NQ]; ND];
        let (pd, pq) = (&table.psi_d, &table.psi_q);
        let mut k = 0;
        while k < ND {
            let mut m = 0;
            while m < NQ {
                // As `node_coefficients` (`new`), operation for operation.
                let a = if k < ND - 2 { k } else { ND - 2 };
                let b = if m < NQ - 2 { m } else { NQ - 2 };
                cells[k][m] = [
                    pd[k][m],
                    pd[a + 1][m] - pd[a][m],
                    pd[k][b + 1] - pd[k][b],
                    pd[a + 1][b + 1] - pd[a + 1][b] - pd[a][b + 1] + pd[a][b],
                    pq[k][m],
                    pq[a + 1][m] - pq[a][m],
                    pq[k][b + 1] - pq[k][b],
                    pq[a + 1][b + 1] - pq[a + 1][b] - pq[a][b + 1] + pq[a][b],
                ];
                m += 1;
            }
            k += 1;
        }
        // As `q_offset_line`: the q node of i_q = 0, the fraction from it, and ψq(i_d, 0)
        // from each d node.
        let ty0 = (0.0 - q.first) * q.inv_step;
        let m0 = if ty0 > 0.0 { ty0 as usize } else { 0 };
        let m0 = if m0 < NQ - 1 { m0 } else { NQ - 1 };
        let fy0 = ty0 - m0 as f32;
        let mut q_offset = [[0.0; 2]; ND];
        let mut k = 0;
        while k < ND {
            let c = &cells[k][m0];
            q_offset[k] = [c[4] + fy0 * c[6], c[5] + fy0 * c[7]];
            k += 1;
        }
        Self {
            first: Dq {
                d: d.first,
                q: q.first,
            },
            inv_step: Dq {
                d: d.inv_step,
                q: q.inv_step,
            },
            cells,
            q_offset,
        }
    }
}

impl<T: Real, const ND: usize, const NQ: usize> MagneticModel<T> for UniformFluxTable<T, ND, NQ> {
    /// The bilinear values alone (no Jacobian).
    #[inline]
    fn flux(&self, i: Dq<T>) -> Dq<T> {
        let (k, m, fx, fy) = self.cell(i);
        bilinear_value(&self.coefficients(k, m), fx, fy)
    }

    /// ψq(i_d, 0) from the table's line i_q = 0 (one 1-D lookup, the interpolant's value).
    #[inline]
    fn q_flux_offset(&self, i_d: T) -> T {
        self.q_offset_at(i_d)
    }

    /// As [`super::UniformFluxMap`]'s (the table borrowed, [`UniformFluxTable::map`]).
    fn current(&self, psi: Dq<T>) -> Dq<T> {
        self.map().current(psi)
    }

    /// As [`super::UniformFluxMap`]'s: in closed form cell by cell.
    fn current_from(&self, psi: Dq<T>, guess: Dq<T>) -> Dq<T> {
        self.map().current_from(psi, guess)
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
