//! A flux map on a uniform grid held by value, for the lookup a firmware's interrupt makes.

use super::{FluxTable, InductanceMatrix, MagneticModel};
use crate::{Dq, Real};

/// A flux map ψd(i_d, i_q), ψq(i_d, i_q) on a uniform `ND` × `NQ` grid, held by value (a
/// `static` in flash), interpolated bilinearly as [`super::FluxMap`] interpolates it, with
/// the lookup reduced to what a Cortex-M4F does fastest:
/// - the cell from the precomputed inverse node spacing, t = (x − x₀)·(1/Δ), its index ⌊t⌋
///   clamped to the edge cells by one compare (a NaN to the first) and the fraction t − ⌊t⌋:
///   no search, no division, no load of an axis;
/// - each cell's bilinear coefficients precomputed and interleaved — ψd's and ψq's
///   (p00, p10 − p00, p01 − p00, p11 − p10 − p01 + p00) side by side, eight adjacent words —
///   so that a lookup loads one run and multiplies and adds six times per table (the edge row
///   and column of the array repeat the last cell's, for the linear extension beyond the
///   grid);
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
    /// Cell (k, m)'s coefficients [ψd: p00, ex, ey, twist; ψq: the same] in `cells[k][m]`,
    /// Wb (see the type's docs).
    pub(super) cells: [[[T; 8]; NQ]; ND],
}

impl<T: Real, const ND: usize, const NQ: usize> UniformFluxTable<T, ND, NQ> {
    /// The table's map on its uniform grid; None if [`FluxTable::map`] refuses it or an axis
    /// is not uniform.
    pub fn new(table: &FluxTable<T, ND, NQ>) -> Option<Self> {
        let map = table.map().ok()?;
        let (d, q) = map.axis_scales();
        (d.uniform && q.uniform).then(|| Self {
            first: Dq::new(d.first, q.first),
            inv_step: Dq::new(d.inv_step, q.inv_step),
            cells: core::array::from_fn(|k| {
                core::array::from_fn(|m| {
                    // The cell that holds node (k, m) as its p00, the edge's last one beyond.
                    let (k, m) = (k.min(ND - 2), m.min(NQ - 2));
                    let c = |t: &[[T; NQ]; ND]| {
                        let (p00, p10, p01, p11) =
                            (t[k][m], t[k + 1][m], t[k][m + 1], t[k + 1][m + 1]);
                        [p00, p10 - p00, p01 - p00, p11 - p10 - p01 + p00]
                    };
                    let (a, b) = (c(&table.psi_d), c(&table.psi_q));
                    [a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]]
                })
            }),
        })
    }

    /// The cell (k, m) of `i` and the fractions along it (outside [0, 1] beyond the grid).
    #[inline(always)]
    fn cell(&self, i: Dq<T>) -> (usize, usize, T, T) {
        let last = (ND.saturating_sub(2), NQ.saturating_sub(2));
        cell_of(self.first, self.inv_step, last, i)
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
    let tx = (i.d - first.d) * inv_step.d;
    let ty = (i.q - first.q) * inv_step.q;
    let k = tx.index_floor(last.0);
    let m = ty.index_floor(last.1);
    (k, m, tx - T::from_index(k), ty - T::from_index(m))
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
                // As `new`: the cell that holds node (k, m), the edge's last one beyond.
                let a = if k < ND - 2 { k } else { ND - 2 };
                let b = if m < NQ - 2 { m } else { NQ - 2 };
                let (d00, d10, d01, d11) = (pd[a][b], pd[a + 1][b], pd[a][b + 1], pd[a + 1][b + 1]);
                let (q00, q10, q01, q11) = (pq[a][b], pq[a + 1][b], pq[a][b + 1], pq[a + 1][b + 1]);
                cells[k][m] = [
                    d00,
                    d10 - d00,
                    d01 - d00,
                    d11 - d10 - d01 + d00,
                    q00,
                    q10 - q00,
                    q01 - q00,
                    q11 - q10 - q01 + q00,
                ];
                m += 1;
            }
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
