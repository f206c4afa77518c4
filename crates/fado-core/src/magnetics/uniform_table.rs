//! A flux map on a uniform grid held by value, for the lookup a firmware's interrupt makes.

use super::cell_inverse::{self, CellGrid, CellPolynomial};
use super::{FluxTable, InductanceMatrix, MagneticModel, newton};
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
    first: Dq<T>,
    /// The inverse node spacings (1/Δ_d, 1/Δ_q), 1/A.
    inv_step: Dq<T>,
    /// Cell (k, m)'s coefficients [ψd: p00, ex, ey, twist; ψq: the same] in `cells[k][m]`,
    /// Wb (see the type's docs).
    cells: [[[T; 8]; NQ]; ND],
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
        let tx = (i.d - self.first.d) * self.inv_step.d;
        let ty = (i.q - self.first.q) * self.inv_step.q;
        let k = tx.index_floor(ND.saturating_sub(2));
        let m = ty.index_floor(NQ.saturating_sub(2));
        (k, m, tx - T::from_index(k), ty - T::from_index(m))
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
        let c = self.coefficients(k, m);
        let (g, h) = (self.inv_step.d, self.inv_step.q);
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
        let c = self.coefficients(k, m);
        let value = |j: usize| c[j] + fx * c[j + 1] + fy * (c[j + 2] + fx * c[j + 3]);
        Dq::new(value(0), value(4))
    }

    /// Newton from the map's linearisation at zero current.
    fn current(&self, psi: Dq<T>) -> Dq<T> {
        let (psi0, l0) = self.flux_and_jacobian(Dq::zero());
        self.current_from(psi, l0.solve(psi - psi0))
    }

    /// In closed form cell by cell as [`super::FluxMap::current_from`]; by Newton's method
    /// where that finds no root.
    fn current_from(&self, psi: Dq<T>, guess: Dq<T>) -> Dq<T> {
        cell_inverse::invert(self, psi, guess).unwrap_or_else(|| {
            let last = self.first.d + T::from_index(ND.saturating_sub(1)) / self.inv_step.d;
            let scale = last.abs() * T::lit(1e-6);
            newton(psi, guess, scale, |i| self.flux_and_jacobian(i)).0
        })
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

impl<T: Real, const ND: usize, const NQ: usize> CellGrid<T> for UniformFluxTable<T, ND, NQ> {
    #[inline]
    fn last_cell(&self) -> (usize, usize) {
        (ND.saturating_sub(2), NQ.saturating_sub(2))
    }

    #[inline]
    fn cell_of(&self, i: Dq<T>) -> (usize, usize) {
        let (k, m, _, _) = self.cell(i);
        (k, m)
    }

    #[inline]
    fn polynomial(&self, k: usize, m: usize) -> CellPolynomial<T> {
        let c = self.coefficients(k, m);
        CellPolynomial {
            p00: Dq::new(c[0], c[4]),
            ex: Dq::new(c[1], c[5]),
            ey: Dq::new(c[2], c[6]),
            twist: Dq::new(c[3], c[7]),
        }
    }

    #[inline]
    fn current_at(&self, k: usize, m: usize, u: T, v: T) -> Dq<T> {
        Dq::new(
            self.first.d + (T::from_index(k) + u) / self.inv_step.d,
            self.first.q + (T::from_index(m) + v) / self.inv_step.q,
        )
    }
}
