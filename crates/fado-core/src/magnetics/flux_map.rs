//! A flux map ψd(i_d, i_q), ψq(i_d, i_q) on a rectangular grid, interpolated bilinearly.

use core::fmt;

use super::cell_inverse::{self, CellGrid, CellPolynomial};
use super::{InductanceMatrix, MagneticModel};
use crate::{Dq, Real};

/// A flux map on the rectangular grid `i_d` × `i_q` (both strictly increasing), borrowed:
/// `psi_d[k·n_q + m]` and `psi_q[k·n_q + m]` are ψd and ψq at (`i_d[k]`, `i_q[m]`).
///
/// Between grid nodes the map is bilinear (continuous, its Jacobian piecewise linear);
/// beyond the grid it extends the edge cells linearly. [`FluxMap::smooth_flux_and_jacobian`]
/// is its C¹ interpolant, the estimator's view of the same nodes. Firmware keeps the four slices in
/// flash (`&'static`, e.g. a `static` [`FluxTable`]); a host program borrows them from its
/// own storage. A lookup finds the cell in O(1) on a uniform axis (found so at construction)
/// — the node index ⌊(x − x₀)/Δ⌋ with 1/Δ precomputed, clamped to the edge cells, and the
/// fraction the remainder: no load, no division — and by bisection (4 comparisons on 16
/// nodes) and a division on any other; the corners are two loads of adjacent nodes per row
/// and table, each pair behind one bounds check.
///
/// [`FluxMap::new`] refuses a map that is not monotonic in its own current (ψd strictly
/// increasing in i_d along every row, ψq in i_q along every column): such a map has no
/// inverse i(ψ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluxMap<'a, T> {
    i_d: &'a [T],
    i_q: &'a [T],
    psi_d: &'a [T],
    psi_q: &'a [T],
    /// The i_d axis' first node and (n_d − 1)/(i_d[last] − i_d[0]), its inverse node
    /// spacing if uniform; whether it is.
    axis_d: AxisScale<T>,
    /// The same for i_q.
    axis_q: AxisScale<T>,
    /// The C¹ interpolant's node slopes along i_q, ∂ψd/∂i_q then ∂ψq/∂i_q at every node
    /// (row-major, 2·n_d·n_q values; [`FluxMap::with_node_slopes`]), or empty: each lookup
    /// then finds the slopes of its stencil's nodes from their neighbours.
    q_slopes: &'a [T],
}

/// An axis' first node, its inverse mean node spacing and whether every cell has that spacing
/// (to [`UNIFORM_TOLERANCE_EPS`]): a uniform axis finds a cell with no load and no division.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct AxisScale<T> {
    pub(super) first: T,
    pub(super) inv_step: T,
    pub(super) uniform: bool,
    /// The axis has a node at zero and the other flux component is zero at every node there
    /// (the i_q axis of a map made odd in i_q: its interpolants' ψq(i_d, 0) is zero,
    /// [`FluxMap::smooth_q_flux_offset`]); kept here, in the scale's padding, so that the map
    /// every model record carries does not grow.
    pub(super) zero_values: bool,
}

impl<T: Real> AxisScale<T> {
    fn of(axis: &[T]) -> Self {
        let inv_step = inverse_step(axis);
        let tol = T::default_epsilon() * T::lit(UNIFORM_TOLERANCE_EPS);
        let uniform = axis
            .windows(2)
            .all(|w| ((w[1] - w[0]) * inv_step - T::one()).abs() <= tol);
        Self {
            first: axis.first().copied().unwrap_or(T::zero()),
            inv_step,
            uniform,
            zero_values: false,
        }
    }
}

/// Why a flux map was refused: the grid node (k along i_d, m along i_q) where it was seen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FluxMapError {
    /// An axis has fewer than two nodes.
    TooFewNodes {
        /// "i_d" or "i_q".
        axis: &'static str,
    },
    /// A table's length is not n_d·n_q.
    Ragged {
        /// "psi_d" or "psi_q".
        table: &'static str,
    },
    /// An axis is not strictly increasing (or not finite) at this node.
    Axis {
        /// "i_d" or "i_q".
        axis: &'static str,
        /// Node index along the axis.
        index: usize,
    },
    /// A flux value is not finite.
    NotFinite {
        /// "psi_d" or "psi_q".
        table: &'static str,
        /// Node along i_d.
        k: usize,
        /// Node along i_q.
        m: usize,
    },
    /// ψd does not increase with i_d (or ψq with i_q) from the previous node to this one.
    NotMonotonic {
        /// "psi_d" or "psi_q".
        table: &'static str,
        /// Node along i_d.
        k: usize,
        /// Node along i_q.
        m: usize,
    },
    /// The grid does not reach zero current: i_d's nodes do not include or bracket 0, or
    /// i_q's do not reach both signs (a half map).
    NoZeroCurrent {
        /// "i_d" or "i_q".
        axis: &'static str,
    },
}

impl fmt::Display for FluxMapError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            FluxMapError::TooFewNodes { axis } => {
                write!(f, "the grid needs at least two values of {axis}")
            }
            FluxMapError::Ragged { table } => write!(
                f,
                "{table} has not one value per (i_d, i_q) pair of the rectangular grid"
            ),
            FluxMapError::Axis { axis, index } => {
                write!(
                    f,
                    "{axis}[{index}] is not finite or not above {axis}[{index}-1]"
                )
            }
            FluxMapError::NotFinite { table, k, m } => {
                write!(f, "{table} at node ({k}, {m}) is not finite")
            }
            FluxMapError::NotMonotonic { table, k, m } => write!(
                f,
                "{table} at node ({k}, {m}) does not increase with its own current: the map \
                 has no inverse (check the sign convention: d on the magnet, ψd = λf at i = 0)"
            ),
            FluxMapError::NoZeroCurrent { axis: "i_q" } => f.write_str(
                "the i_q axis does not reach both signs: beyond its grid a map extends its edge \
                 cells linearly, which bends ψd (even in i_q) and ψq (odd in i_q) the wrong way \
                 for the other sign of the torque; complete a half map by the rotor's symmetry \
                 ψd(i_d, −i_q) = ψd(i_d, i_q), ψq(i_d, −i_q) = −ψq(i_d, i_q)",
            ),
            FluxMapError::NoZeroCurrent { axis } => write!(
                f,
                "the {axis} axis does not reach zero current (the magnet's flux ψd(0, 0) is read \
                 there): its first node must be ≤ 0 and its last ≥ 0"
            ),
        }
    }
}

impl core::error::Error for FluxMapError {}

/// `x` beyond `axis` (increasing, two nodes or more) by more than its edge cell's width.
fn beyond_axis<T: Real>(axis: &[T], x: T) -> bool {
    match (axis.first_chunk::<2>(), axis.last_chunk::<2>()) {
        (Some(&[low, next]), Some(&[before, high])) => {
            x < low - (next - low) || x > high + (high - before)
        }
        _ => false,
    }
}

/// Zero current lies on the grid: i_d's nodes bracket it (an edge node may be 0: maps of
/// interior-magnet machines often end at i_d = 0) and i_q's straddle it. Both axes are
/// checked increasing and of two nodes or more.
fn check_zero_current<T: Real>(i_d: &[T], i_q: &[T]) -> Result<(), FluxMapError> {
    let zero = T::zero();
    if !(i_d[0] <= zero && i_d[i_d.len() - 1] >= zero) {
        return Err(FluxMapError::NoZeroCurrent { axis: "i_d" });
    }
    if !(i_q[0] < zero && i_q[i_q.len() - 1] > zero) {
        return Err(FluxMapError::NoZeroCurrent { axis: "i_q" });
    }
    Ok(())
}

fn check_axis<T: Real>(axis: &'static str, x: &[T]) -> Result<(), FluxMapError> {
    if x.len() < 2 {
        return Err(FluxMapError::TooFewNodes { axis });
    }
    for (index, w) in x.windows(2).enumerate() {
        if !(w[0].is_finite() && w[1].is_finite() && w[1] > w[0]) {
            return Err(FluxMapError::Axis {
                axis,
                index: index + 1,
            });
        }
    }
    Ok(())
}

/// The inverse node spacing (n − 1)/(x[last] − x[0]) of `axis` (two nodes or more): exact
/// for a uniform axis, a first guess of the cell for any other.
fn inverse_step<T: Real>(axis: &[T]) -> T {
    let n = axis.len();
    let span =
        axis.last().copied().unwrap_or(T::zero()) - axis.first().copied().unwrap_or(T::zero());
    T::from_index(n.max(2) - 1) / span
}

/// Relative mismatch between a cell's width and the uniform spacing 1/`inv_step`, in units of
/// the type's ε, up to which an axis is uniform: the rounding of a uniform axis' nodes (a few
/// ulp of the largest node over the spacing: under 10 ε on 16 f32 nodes over ±12 A), so that
/// the fraction (x − x₀)·(1/Δ) − k is the divided one to rounding, and any deliberately
/// non-uniform spacing is divided.
const UNIFORM_TOLERANCE_EPS: f64 = 64.0;

/// The cell of `x` on `axis` (clamped to the edge cells), the fraction along it (outside
/// [0, 1] beyond the grid) and the cell's inverse width. On a uniform axis t = (x − x₀)/Δ
/// with 1/Δ precomputed, the cell ⌊t⌋ clamped (a NaN to the first) and the fraction t − ⌊t⌋:
/// no load, no branch but the clamp, no division. On any other axis by bisection, with the
/// width divided.
/// Indexing by `get` (a NaN where a shape check failed), so that the firmware's lookup holds
/// no bounds-check panic.
#[inline(always)]
pub(super) fn cell<T: Real>(axis: &[T], scale: &AxisScale<T>, x: T) -> (usize, T, T) {
    let n = axis.len();
    let last = n.max(2) - 2;
    if scale.uniform {
        let t = (x - scale.first) * scale.inv_step;
        let k = t.index_floor(last);
        return (k, t - T::from_index(k), scale.inv_step);
    }
    let at = |j: usize| axis.get(j).copied().unwrap_or_else(|| T::lit(f64::NAN));
    let k = axis.partition_point(|&a| a <= x).clamp(1, last + 1) - 1;
    let inv_width = T::one() / (at(k + 1) - at(k));
    (k, (x - at(k)) * inv_width, inv_width)
}

/// The pair `t[j]`, `t[j + 1]` (NaNs where a shape check failed): one bounds check for two
/// loads.
#[inline(always)]
pub(super) fn pair<T: Real>(t: &[T], j: usize) -> (T, T) {
    match t.get(j..j.wrapping_add(2)) {
        Some(&[a, b]) => (a, b),
        _ => (T::lit(f64::NAN), T::lit(f64::NAN)),
    }
}

impl<'a, T: Real> FluxMap<'a, T> {
    /// A map from its axes and row-major tables (see the type's docs), checked.
    pub fn new(
        i_d: &'a [T],
        i_q: &'a [T],
        psi_d: &'a [T],
        psi_q: &'a [T],
    ) -> Result<Self, FluxMapError> {
        check_axis("i_d", i_d)?;
        check_axis("i_q", i_q)?;
        check_zero_current(i_d, i_q)?;
        let map = Self::from_checked_parts(i_d, i_q, psi_d, psi_q)?;
        let nq = i_q.len();
        for (table, t) in [("psi_d", psi_d), ("psi_q", psi_q)] {
            if let Some(at) = t.iter().position(|v| !v.is_finite()) {
                return Err(FluxMapError::NotFinite {
                    table,
                    k: at / nq,
                    m: at % nq,
                });
            }
        }
        // Every value is finite here, so `<=` is the negation of `>`.
        for k in 0..i_d.len() {
            for m in 0..nq {
                let at = k * nq + m;
                if k > 0 && psi_d[at] <= psi_d[at - nq] {
                    let table = "psi_d";
                    return Err(FluxMapError::NotMonotonic { table, k, m });
                }
                if m > 0 && psi_q[at] <= psi_q[at - 1] {
                    let table = "psi_q";
                    return Err(FluxMapError::NotMonotonic { table, k, m });
                }
            }
        }
        Ok(map)
    }

    /// A map from parts whose shapes alone are checked (two nodes or more per axis, one value
    /// per node): no lookup can index out of bounds, and a map built from the parts of one
    /// that [`FluxMap::new`] accepted behaves identically. For a host program that keeps the
    /// checked parts in its own storage and borrows them per use (O(n_d + n_q): the axes'
    /// spacing, instead of [`FluxMap::new`]'s O(n_d·n_q)); unchecked values give wrong
    /// inverses, never a panic.
    pub fn from_checked_parts(
        i_d: &'a [T],
        i_q: &'a [T],
        psi_d: &'a [T],
        psi_q: &'a [T],
    ) -> Result<Self, FluxMapError> {
        if i_d.len() < 2 {
            return Err(FluxMapError::TooFewNodes { axis: "i_d" });
        }
        if i_q.len() < 2 {
            return Err(FluxMapError::TooFewNodes { axis: "i_q" });
        }
        for (table, t) in [("psi_d", psi_d), ("psi_q", psi_q)] {
            if t.len() != i_d.len() * i_q.len() {
                return Err(FluxMapError::Ragged { table });
            }
        }
        // The column at i_q = 0, if the axis has that node: all zero (O(n_d)).
        let m0 = i_q.partition_point(|&x| x < T::zero());
        let nq = i_q.len();
        let q_offset_zero = i_q.get(m0).is_some_and(|&x| x == T::zero())
            && (0..i_d.len()).all(|k| psi_q.get(k * nq + m0) == Some(&T::zero()));
        Ok(Self {
            i_d,
            i_q,
            psi_d,
            psi_q,
            axis_d: AxisScale::of(i_d),
            axis_q: AxisScale {
                zero_values: q_offset_zero,
                ..AxisScale::of(i_q)
            },
            q_slopes: &[],
        })
    }

    /// The axes' first node, inverse mean spacing and uniformity (d, q).
    pub(super) const fn axis_scales(&self) -> (AxisScale<T>, AxisScale<T>)
    where
        T: Copy,
    {
        (self.axis_d, self.axis_q)
    }

    /// Whether `i` lies beyond the grid by more than its edge cell along either axis: where the
    /// map's linear extension of its edge cells stands in for data it does not have.
    pub fn beyond_grid(&self, i: Dq<T>) -> bool
    where
        T: Real,
    {
        beyond_axis(self.i_d, i.d) || beyond_axis(self.i_q, i.q)
    }

    /// The i_d axis in A.
    pub fn i_d(&self) -> &'a [T] {
        self.i_d
    }

    /// The i_q axis in A.
    pub fn i_q(&self) -> &'a [T] {
        self.i_q
    }

    /// ψd at the grid nodes in Wb, row-major (`[k·n_q + m]`).
    pub fn psi_d(&self) -> &'a [T] {
        self.psi_d
    }

    /// ψq at the grid nodes in Wb, row-major.
    pub fn psi_q(&self) -> &'a [T] {
        self.psi_q
    }

    /// The node slopes the map carries ([`FluxMap::with_node_slopes`]; empty if none).
    pub fn node_slopes(&self) -> &'a [T] {
        self.q_slopes
    }

    /// Whether ψq is zero at every node of an i_q = 0 column (a map made odd in i_q).
    pub(super) fn q_offset_zero(&self) -> bool {
        self.axis_q.zero_values
    }

    /// This map with `slopes` as its node slopes (checked by the caller,
    /// `FluxMap::with_node_slopes`).
    pub(super) fn carrying_slopes(self, slopes: &'a [T]) -> Self {
        Self {
            q_slopes: slopes,
            ..self
        }
    }

    /// Whether `other` has the same nodes (axes and tables), whatever node slopes either
    /// carries.
    pub fn same_nodes(&self, other: &FluxMap<'_, T>) -> bool {
        self.i_d == other.i_d
            && self.i_q == other.i_q
            && self.psi_d == other.psi_d
            && self.psi_q == other.psi_q
    }

    /// The cell of `i` (fractions fx, fy along it, inverse widths gx, gy) and the four
    /// corners of ψd and ψq, as (p00, p10, p01, p11) with 1 one node up in i_d, 01 in i_q.
    #[inline(always)]
    fn corners(&self, i: Dq<T>) -> (T, T, T, T, Corners<T>, Corners<T>) {
        let (k, fx, gx) = cell(self.i_d, &self.axis_d, i.d);
        let (m, fy, gy) = cell(self.i_q, &self.axis_q, i.q);
        let nq = self.i_q.len();
        let at = k * nq + m;
        let corner = |t: &[T]| {
            let (p00, p01) = pair(t, at);
            let (p10, p11) = pair(t, at + nq);
            (p00, p10, p01, p11)
        };
        (fx, fy, gx, gy, corner(self.psi_d), corner(self.psi_q))
    }

    /// ψ(i) and the incremental inductance ∂ψ/∂i of the bilinear interpolant at `i`.
    #[inline]
    pub fn flux_and_jacobian(&self, i: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        let (fx, fy, gx, gy, cd, cq) = self.corners(i);
        let bilinear = |(p00, p10, p01, p11): Corners<T>| {
            let (ex, ey) = (p10 - p00, p01 - p00);
            let twist = p11 - p10 - p01 + p00;
            (
                bilinear_value((p00, p10, p01, p11), fx, fy),
                (ex + fy * twist) * gx,
                (ey + fx * twist) * gy,
            )
        };
        let (d, dd, dq) = bilinear(cd);
        let (q, qd, qq) = bilinear(cq);
        (Dq::new(d, q), InductanceMatrix { dd, dq, qd, qq })
    }
}

/// Four corner values of a cell: (p00, p10, p01, p11).
type Corners<T> = (T, T, T, T);

/// The bilinear interpolant p00 + fx·(p10 − p00) + fy·((p01 − p00) + fx·twist): the one
/// expression [`FluxMap::flux`] and [`FluxMap::flux_and_jacobian`] share, so that both give
/// the same ψ bit for bit.
#[inline(always)]
fn bilinear_value<T: Real>((p00, p10, p01, p11): Corners<T>, fx: T, fy: T) -> T {
    let (ex, ey) = (p10 - p00, p01 - p00);
    let twist = p11 - p10 - p01 + p00;
    p00 + fx * ex + fy * (ey + fx * twist)
}

impl<T: Real> MagneticModel<T> for FluxMap<'_, T> {
    /// The bilinear values alone (no Jacobian).
    #[inline]
    fn flux(&self, i: Dq<T>) -> Dq<T> {
        let (fx, fy, _, _, cd, cq) = self.corners(i);
        Dq::new(bilinear_value(cd, fx, fy), bilinear_value(cq, fx, fy))
    }

    /// From the map's linearisation at zero current.
    fn current(&self, psi: Dq<T>) -> Dq<T> {
        let at_zero = self.flux_and_jacobian(Dq::zero());
        cell_inverse::current_from_zero(psi, at_zero, |p, g| self.current_from(p, g))
    }

    /// In closed form, cell by cell from the cell of `guess` (each cell's bilinear map inverts
    /// as a quadratic; see the module docs' Inversion); by Newton's method from `guess` where
    /// that finds no root.
    fn current_from(&self, psi: Dq<T>, guess: Dq<T>) -> Dq<T> {
        let scale = self.i_d.last().map_or(T::one(), |x| x.abs()) * T::lit(1e-6);
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

impl<T: Real> CellGrid<T> for FluxMap<'_, T> {
    #[inline]
    fn last_cell(&self) -> (usize, usize) {
        (self.i_d.len().max(2) - 2, self.i_q.len().max(2) - 2)
    }

    #[inline]
    fn cell_of(&self, i: Dq<T>) -> (usize, usize) {
        let (k, _, _) = cell(self.i_d, &self.axis_d, i.d);
        let (m, _, _) = cell(self.i_q, &self.axis_q, i.q);
        (k, m)
    }

    #[inline]
    fn polynomial(&self, k: usize, m: usize) -> CellPolynomial<T> {
        let nq = self.i_q.len();
        let at = k * nq + m;
        let corner = |t: &[T]| {
            let (p00, p01) = pair(t, at);
            let (p10, p11) = pair(t, at + nq);
            (p00, p10 - p00, p01 - p00, p11 - p10 - p01 + p00)
        };
        let (d, q) = (corner(self.psi_d), corner(self.psi_q));
        CellPolynomial {
            p00: Dq::new(d.0, q.0),
            ex: Dq::new(d.1, q.1),
            ey: Dq::new(d.2, q.2),
            twist: Dq::new(d.3, q.3),
        }
    }

    #[inline]
    fn current_at(&self, k: usize, m: usize, u: T, v: T) -> Dq<T> {
        let along = |axis: &[T], j: usize, f: T| {
            let (a, b) = pair(axis, j);
            a + f * (b - a)
        };
        Dq::new(along(self.i_d, k, u), along(self.i_q, m, v))
    }
}

/// A flux map held by value: `ND` × `NQ` nodes in const-generic arrays (a `static` in
/// firmware, in flash). [`FluxTable::map`] borrows it as a [`FluxMap`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluxTable<T, const ND: usize, const NQ: usize> {
    /// The i_d axis in A, strictly increasing.
    pub i_d: [T; ND],
    /// The i_q axis in A, strictly increasing.
    pub i_q: [T; NQ],
    /// ψd in Wb: `psi_d[k][m]` at (`i_d[k]`, `i_q[m]`).
    pub psi_d: [[T; NQ]; ND],
    /// ψq in Wb, as `psi_d`.
    pub psi_q: [[T; NQ]; ND],
}

impl<T: Real, const ND: usize, const NQ: usize> FluxTable<T, ND, NQ> {
    /// The table borrowed as a checked [`FluxMap`].
    pub fn map(&self) -> Result<FluxMap<'_, T>, FluxMapError> {
        FluxMap::new(
            &self.i_d,
            &self.i_q,
            self.psi_d.as_flattened(),
            self.psi_q.as_flattened(),
        )
    }

    /// Tabulates any magnetic model on the grid `i_d` × `i_q` (e.g. an algebraic model
    /// turned into the table firmware keeps in flash).
    pub fn from_model(model: &impl MagneticModel<T>, i_d: [T; ND], i_q: [T; NQ]) -> Self {
        let mut psi_d = [[T::zero(); NQ]; ND];
        let mut psi_q = [[T::zero(); NQ]; ND];
        for (k, &id) in i_d.iter().enumerate() {
            for (m, &iq) in i_q.iter().enumerate() {
                let psi = model.flux(Dq::new(id, iq));
                psi_d[k][m] = psi.d;
                psi_q[k][m] = psi.q;
            }
        }
        Self {
            i_d,
            i_q,
            psi_d,
            psi_q,
        }
    }
}

impl<const ND: usize, const NQ: usize> FluxTable<f32, ND, NQ> {
    /// The table borrowed as a [`FluxMap`] in a constant expression, for a map in flash
    /// beside its table (`static MAP: FluxMap<'static, f32> = TABLE.const_map();`): the checks
    /// of [`FluxMap::new`] run by the compiler, so that a table it refuses does not build (the
    /// panic names the check), and the map it gives is [`FluxTable::map`]'s.
    pub const fn const_map(&self) -> FluxMap<'_, f32> {
        assert!(
            ND >= 2 && NQ >= 2,
            "a flux map needs two nodes or more per axis"
        );
        let axis_d = const_axis(&self.i_d);
        let axis_q = const_axis(&self.i_q);
        let mut k = 0;
        while k < ND {
            let mut m = 0;
            while m < NQ {
                let (d, q) = (self.psi_d[k][m], self.psi_q[k][m]);
                assert!(d.is_finite() && q.is_finite(), "a flux value is not finite");
                assert!(
                    k == 0 || d > self.psi_d[k - 1][m],
                    "psi_d does not increase with i_d"
                );
                assert!(
                    m == 0 || q > self.psi_q[k][m - 1],
                    "psi_q does not increase with i_q"
                );
                m += 1;
            }
            k += 1;
        }
        // The column at i_q = 0, if the axis has that node: all zero ([`FluxMap::new`]'s).
        let mut m0 = 0;
        while m0 < NQ && self.i_q[m0] < 0.0 {
            m0 += 1;
        }
        let mut q_offset_zero = m0 < NQ && self.i_q[m0] == 0.0;
        let mut k = 0;
        while q_offset_zero && k < ND {
            q_offset_zero = self.psi_q[k][m0] == 0.0;
            k += 1;
        }
        FluxMap {
            i_d: &self.i_d,
            i_q: &self.i_q,
            psi_d: self.psi_d.as_flattened(),
            psi_q: self.psi_q.as_flattened(),
            axis_d,
            axis_q: AxisScale {
                zero_values: q_offset_zero,
                ..axis_q
            },
            q_slopes: &[],
        }
    }
}

/// [`AxisScale::of`] in a constant expression (`f32`), the axis checked as [`check_axis`]
/// checks it (a panic instead of an error).
const fn const_axis<const N: usize>(axis: &[f32; N]) -> AxisScale<f32> {
    let mut k = 1;
    while k < N {
        let ok = axis[k - 1].is_finite() && axis[k].is_finite() && axis[k] > axis[k - 1];
        assert!(ok, "an axis is not finite and strictly increasing");
        k += 1;
    }
    let inv_step = (N - 1) as f32 / (axis[N - 1] - axis[0]);
    let tol = f32::EPSILON * UNIFORM_TOLERANCE_EPS as f32;
    let mut uniform = true;
    let mut k = 1;
    while k < N {
        let mismatch = (axis[k] - axis[k - 1]) * inv_step - 1.0;
        uniform &= mismatch <= tol && -mismatch <= tol;
        k += 1;
    }
    AxisScale {
        first: axis[0],
        inv_step,
        uniform,
        zero_values: false,
    }
}
