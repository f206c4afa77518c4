//! A flux map's C¹ interpolant: the estimator's view of a map.
//!
//! The bilinear interpolant of [`FluxMap`] is continuous, but its incremental inductances are
//! the cells' chord slopes: constant along their own axis inside a cell and jumping at every
//! cell edge. The estimator reads the map's slope, not only its values: its angle turns a q
//! flux error ε into ε/κ, κ = λa + L_qd·i_q − (L_qq − L_q,s)·i_d (`crate::active_flux`), and
//! the frame's ripple moves î across the map's gradient every electrical period. On a
//! saturating q axis the chord slope is below the tangent in the lower part of a cell and
//! above it in the upper part: on motulator's 6.7 kW SyRM with an 8.7 mVs magnet, tabulated on
//! a 13 × 17 grid (5.5 A nodes), the bilinear L_qq at 30 % of the rated torque is 0.028 H
//! against the machine's 0.038 H, κ falls from 0.72 to 0.51 of λa, and the estimator's slow
//! mode, which decays at 0.59 s⁻¹ on the machine's own model while it generates, stops
//! decaying (docs/method/saturation.md, "A map's interpolation").
//!
//! This interpolant is the tensor product of piecewise-cubic Hermite interpolants through the
//! same nodes: along i_q in the four rows around the cell, then along i_d through those four
//! rows' values. Each node's slope is the three-point (quadratic) slope of its neighbours on
//! any spacing, limited as in Fritsch & Carlson (SIAM J. Numer. Anal. 17(2), 1980) to three
//! times the smaller chord slope and to zero between chords of opposite sign, so that the
//! interpolant is monotonic wherever the nodes are (ψd in i_d, ψq in i_q) and keeps the
//! extremum of ψd at i_q = 0 on its node. An edge node takes its edge cell's chord slope.
//! It passes through every node, it is exact for quadratics between the limiter's bounds, its
//! Jacobian is continuous, and beyond the grid it extends its edge linearly along the
//! exceeded axis (as the bilinear map extends its edge cells). The Jacobian is the
//! interpolant's own derivative: the slopes' weights are linear in the node values once the
//! limiter's branch is chosen, so the same weights give the derivative along the other axis.
//!
//! **Cost.** A lookup interpolates four rows along i_q, each through two nodes and their
//! slopes, then once along i_d through the rows. The rows' node slopes depend on the map
//! alone: a host program finds them once per map ([`FluxMap::fill_node_slopes`],
//! [`FluxMap::with_node_slopes`]; `fado-sim` does for every map it reads) and a lookup loads
//! them, the same numbers a lookup without them finds from the nodes' neighbours (tested bit
//! for bit). The slopes along i_d are those of the rows' values at the point's i_q, found per
//! lookup. The cells are found as the bilinear lookup finds them (O(1) on a uniform axis),
//! and [`FluxMap::smooth_flux`] leaves out the Jacobian where a caller needs the flux alone
//! (the estimator's operating point).

use super::flux_map::{AxisScale, cell, pair};
use super::{FluxMap, FluxMapError, InductanceMatrix};
use crate::real::{max, min};
use crate::{Dq, Real};

/// One cell of an axis around a point: its four nodes (the neighbours repeated at an edge),
/// the widths and their inverses, and the Hermite basis at the point's fraction along it —
/// everything the interpolant needs that does not depend on the node values, computed once
/// per lookup and shared by the four rows and both flux components.
struct Cell<T> {
    /// Widths of the left neighbour's cell, this cell and the right neighbour's cell (zero
    /// where the neighbour is an edge repeat).
    h: [T; 3],
    /// Their inverses (zero for a zero width).
    inv: [T; 3],
    /// The basis (h00, h10·h, h01, h11·h) for the value and (d00, d10, d01, d11) for its
    /// derivative along the axis.
    value: [T; 4],
    slope: [T; 4],
}

impl<T: Real> Cell<T> {
    /// The cell with the nodes `x` (the neighbours repeated at an edge) on an axis of
    /// `scale`, at the fraction `t`: a uniform axis' widths have the precomputed inverse.
    fn new(x: [T; 4], t: T, scale: &AxisScale<T>) -> Self {
        let zero = T::zero();
        let h = [x[1] - x[0], x[2] - x[1], x[3] - x[2]];
        let inv = if scale.uniform {
            h.map(|w| if w > zero { scale.inv_step } else { zero })
        } else {
            h.map(|w| if w > zero { T::one() / w } else { zero })
        };
        let one = T::one();
        let (two, three, six) = (T::lit(2.0), T::lit(3.0), T::lit(6.0));
        let (t2, t3) = (t * t, t * t * t);
        let hc = h[1];
        Self {
            h,
            inv,
            value: [
                two * t3 - three * t2 + one,
                (t3 - two * t2 + t) * hc,
                three * t2 - two * t3,
                (t3 - t2) * hc,
            ],
            slope: [
                (six * t2 - six * t) * inv[1],
                three * t2 - two * t * two + one,
                (six * t - six * t2) * inv[1],
                three * t2 - two * t,
            ],
        }
    }

    /// A node's slope as weights on (its left neighbour, itself, its right neighbour), from
    /// the values `p` and the cells `left`, `right` of this cell's widths (a zero width where
    /// the node is an edge node).
    fn slope_weights(&self, p: [T; 3], left: usize, right: usize) -> [T; 3] {
        let zero = T::zero();
        let (hl, hr) = (self.h[left], self.h[right]);
        let (il, ir) = (self.inv[left], self.inv[right]);
        // An edge node (a zero width) takes its one cell's chord.
        if hl <= zero {
            return [zero, -ir, ir];
        }
        if hr <= zero {
            return [-il, il, zero];
        }
        let (dl, dr) = ((p[1] - p[0]) * il, (p[2] - p[1]) * ir);
        if dl * dr <= zero {
            return [zero; 3];
        }
        let span = T::one() / (hl + hr);
        let (sl, sr) = (hr * span, hl * span);
        let three = T::lit(3.0);
        let slope = sl * dl + sr * dr;
        if slope.abs() > three * min(dl.abs(), dr.abs()) {
            return if dl.abs() < dr.abs() {
                [-three * il, three * il, zero]
            } else {
                [zero, -three * ir, three * ir]
            };
        }
        // sl·(p1 − p0)/hl + sr·(p2 − p1)/hr.
        [-sl * il, sl * il - sr * ir, sr * ir]
    }

    /// The slopes at this cell's two nodes of the values `p` at the four nodes.
    #[inline]
    fn node_slopes(&self, p: [T; 4]) -> [T; 2] {
        let s1 = self.slope_weights([p[0], p[1], p[2]], 0, 1);
        let s2 = self.slope_weights([p[1], p[2], p[3]], 1, 2);
        [dot3(s1, [p[0], p[1], p[2]]), dot3(s2, [p[1], p[2], p[3]])]
    }

    /// The cubic Hermite interpolant on this cell through the values `p` at its two nodes
    /// with the slopes `s` there: (value, derivative along the axis).
    #[inline(always)]
    fn hermite(&self, p: [T; 2], s: [T; 2]) -> (T, T) {
        let (v, d) = (&self.value, &self.slope);
        (
            v[0] * p[0] + v[1] * s[0] + v[2] * p[1] + v[3] * s[1],
            d[0] * p[0] + d[1] * s[0] + d[2] * p[1] + d[3] * s[1],
        )
    }
}

/// The cell of `x` on `axis` (two nodes or more; found as the bilinear lookup finds it, in
/// O(1) on a uniform axis), the fraction along it clamped to [0, 1], the four node indices
/// around it (repeated at an edge) and their positions.
#[inline(always)]
fn stencil<T: Real>(axis: &[T], scale: &AxisScale<T>, x: T) -> ([usize; 4], [T; 4], T) {
    let n = axis.len();
    let (k, t, _) = cell(axis, scale, x);
    let t = max(min(t, T::one()), T::zero());
    let kx = [k.saturating_sub(1), k, k + 1, (k + 2).min(n - 1)];
    (kx, kx.map(|j| axis.get(j).copied().unwrap_or(T::zero())), t)
}

/// Whether `x` lies on `axis`'s grid (first node ≤ x ≤ last node; false for a NaN).
fn on_axis<T: Real>(axis: &[T], x: T) -> bool {
    match (axis.first(), axis.last()) {
        (Some(&a), Some(&b)) => a <= x && x <= b,
        _ => false,
    }
}

/// The lookup's stencils: the i_d and i_q cells around a point, their node indices, and the
/// clamped point (the point itself inside the grid).
struct Stencil<T> {
    kd: [usize; 4],
    kq: [usize; 4],
    cd: Cell<T>,
    cq: Cell<T>,
    clamped: Dq<T>,
    /// The point lies on the grid (the clamped point is the point).
    inside: bool,
}

impl<'a, T: Real> FluxMap<'a, T> {
    /// This map carrying its C¹ interpolant's node slopes along i_q (`slopes`, filled by
    /// [`FluxMap::fill_node_slopes`]): a lookup then loads its stencil's slopes instead of
    /// finding them from their neighbours, the same interpolant with a third of its
    /// arithmetic. For a host program that keeps a map for many lookups. Refused with
    /// [`FluxMapError::Ragged`] unless `slopes` are this map's own (2·n_d·n_q values, each
    /// the slope a lookup would find).
    pub fn with_node_slopes(self, slopes: &'a [T]) -> Result<Self, FluxMapError> {
        let n = self.psi_d().len();
        let own = slopes.len() == 2 * n
            && (0..2 * n).all(|at| slopes[at] == self.q_node_slope(at / n, at % n));
        if !own {
            return Err(FluxMapError::Ragged {
                table: "node slopes",
            });
        }
        Ok(self.carrying_slopes(slopes))
    }

    /// Writes the C¹ interpolant's node slopes along i_q into `out` (2·n_d·n_q values:
    /// ∂ψd/∂i_q then ∂ψq/∂i_q, row-major); false, `out` untouched, if its length differs.
    pub fn fill_node_slopes(&self, out: &mut [T]) -> bool {
        let n = self.psi_d().len();
        if out.len() != 2 * n {
            return false;
        }
        for (at, slot) in out.iter_mut().enumerate() {
            *slot = self.q_node_slope(at / n, at % n);
        }
        true
    }

    /// The slope along i_q at node `at` (row-major) of ψd (`table` 0) or ψq (1): what a
    /// lookup's stencil finds there.
    fn q_node_slope(&self, table: usize, at: usize) -> T {
        let (axis, nq) = (self.i_q(), self.i_q().len());
        let values = if table == 0 {
            self.psi_d()
        } else {
            self.psi_q()
        };
        let (k, m) = (at / nq, at % nq);
        let node = |t: &[T], j: usize| t.get(j).copied().unwrap_or(T::zero());
        // The stencil of the cell starting at this node (the last node: the cell ending there).
        let (first, col) = if m + 1 < nq { (m, 0) } else { (m - 1, 1) };
        let kq = [
            first.saturating_sub(1),
            first,
            first + 1,
            (first + 2).min(nq - 1),
        ];
        let (_, scale) = self.axis_scales();
        let cell = Cell::new(kq.map(|j| node(axis, j)), T::zero(), &scale);
        let slopes = cell.node_slopes(kq.map(|j| node(values, k * nq + j)));
        slopes[col]
    }

    #[inline(always)]
    fn stencil(&self, i: Dq<T>) -> Stencil<T> {
        let (i_d, i_q) = (self.i_d(), self.i_q());
        let (scale_d, scale_q) = self.axis_scales();
        let (kd, xd, u) = stencil(i_d, &scale_d, i.d);
        let (kq, xq, v) = stencil(i_q, &scale_q, i.q);
        // Inside the grid the clamped point is i itself; beyond it the edge extends linearly.
        let clamped = Dq::new(xd[1] + u * (xd[2] - xd[1]), xq[1] + v * (xq[2] - xq[1]));
        Stencil {
            kd,
            kq,
            cd: Cell::new(xd, u, &scale_d),
            cq: Cell::new(xq, v, &scale_q),
            clamped,
            inside: on_axis(i_d, i.d) && on_axis(i_q, i.q),
        }
    }

    /// One table's surface at the stencil's point: (value, ∂/∂i_d, ∂/∂i_q), the derivatives
    /// zero unless `JACOBIAN`. `table` 0 is ψd, 1 ψq.
    #[inline(always)]
    fn surface<const JACOBIAN: bool>(&self, s: &Stencil<T>, table: usize) -> (T, T, T) {
        let values = if table == 0 {
            self.psi_d()
        } else {
            self.psi_q()
        };
        let nq = self.i_q().len();
        let n = values.len();
        let node = |t: &[T], j: usize| t.get(j).copied().unwrap_or(T::zero());
        // Along i_q in the four rows, then along i_d through their values and slopes.
        let mut rows = [T::zero(); 4];
        let mut rows_q = [T::zero(); 4];
        for (r, &k) in s.kd.iter().enumerate() {
            // The stencil's inner nodes along i_q are adjacent (kq[2] = kq[1] + 1): each
            // pair behind one bounds check.
            let at = k * nq + s.kq[1];
            let (p0, p1) = pair(values, at);
            let slopes = if self.node_slopes().is_empty() {
                s.cq.node_slopes(s.kq.map(|m| node(values, k * nq + m)))
            } else {
                let (s0, s1) = pair(self.node_slopes(), table * n + at);
                [s0, s1]
            };
            let (value, along_q) = s.cq.hermite([p0, p1], slopes);
            rows[r] = value;
            rows_q[r] = along_q;
        }
        let (cd, r) = (&s.cd, rows);
        let w1 = cd.slope_weights([r[0], r[1], r[2]], 0, 1);
        let w2 = cd.slope_weights([r[1], r[2], r[3]], 1, 2);
        let slopes = [dot3(w1, [r[0], r[1], r[2]]), dot3(w2, [r[1], r[2], r[3]])];
        let (value, along_d) = cd.hermite([r[1], r[2]], slopes);
        if !JACOBIAN {
            return (value, T::zero(), T::zero());
        }
        // The i_d slopes' weights are linear in the rows once the limiter's branch is
        // chosen: the same weights on the rows' i_q derivatives.
        let q = rows_q;
        let slopes_q = [dot3(w1, [q[0], q[1], q[2]]), dot3(w2, [q[1], q[2], q[3]])];
        let (along_q, _) = cd.hermite([q[1], q[2]], slopes_q);
        (value, along_d, along_q)
    }

    /// ψ(i) and ∂ψ/∂i of the map's C¹ interpolant (module docs): the same nodes as
    /// [`FluxMap::flux_and_jacobian`]'s bilinear one, a smooth surface between them.
    pub fn smooth_flux_and_jacobian(&self, i: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        let s = self.stencil(i);
        let (d, dd, dq) = self.surface::<true>(&s, 0);
        let (q, qd, qq) = self.surface::<true>(&s, 1);
        let l = InductanceMatrix { dd, dq, qd, qq };
        if s.inside {
            return (Dq::new(d, q), l);
        }
        (Dq::new(d, q) + l.apply(i - s.clamped), l)
    }

    /// ψ(i) of the map's C¹ interpolant alone: [`FluxMap::smooth_flux_and_jacobian`]'s flux,
    /// bit for bit, without the Jacobian inside the grid (beyond it the extension needs it).
    /// Out of line, as the full lookup is: a step that matches on the model (the firmware's
    /// record) keeps its other models' code as small as without it.
    #[inline(never)]
    pub fn smooth_flux(&self, i: Dq<T>) -> Dq<T> {
        let s = self.stencil(i);
        if !s.inside {
            return self.smooth_flux_and_jacobian(i).0;
        }
        let (d, _, _) = self.surface::<false>(&s, 0);
        let (q, _, _) = self.surface::<false>(&s, 1);
        Dq::new(d, q)
    }
}

impl<T: Real> FluxMap<'_, T> {
    /// ψq(i_d, 0) of the map's C¹ interpolant: where the i_q axis has a node at zero the
    /// interpolant passes through it, so only the interpolation along i_d of that node column
    /// remains (one Hermite cell instead of five), and where that column is zero at every node
    /// (a map made odd in i_q, found once when the map is built) nothing; elsewhere the full
    /// surface. Out of line,
    /// as [`FluxMap::smooth_flux`] is: inlined, its Hermite cell takes the registers of a step
    /// that matches on the model (the firmware's record), whose other models' code then spills
    /// (docs/results/firmware-cost.md).
    #[inline(never)]
    pub fn smooth_q_flux_offset(&self, i_d: T) -> T {
        if self.q_offset_zero() {
            // A zero node column: the Hermite cell through zeros with zero slopes (NaN for a
            // NaN i_d, as the cell's extension gives it).
            return i_d * T::zero();
        }
        let i_q = self.i_q();
        // The axis ascends: the first node not below zero, if it is zero.
        let m0 = i_q.partition_point(|&x| x < T::zero());
        if i_q.get(m0).is_none_or(|&x| x != T::zero()) {
            return self.smooth_flux(Dq::new(i_d, T::zero())).q;
        }
        let (scale, _) = self.axis_scales();
        let (kd, xd, u) = stencil(self.i_d(), &scale, i_d);
        let node = |table: &[T], j: usize| table.get(j).copied().unwrap_or(T::zero());
        let nq = i_q.len();
        let column = kd.map(|k| node(self.psi_q(), k * nq + m0));
        let cell = Cell::new(xd, u, &scale);
        let (value, slope) = cell.hermite([column[1], column[2]], cell.node_slopes(column));
        // Beyond the grid the edge extends linearly along i_d.
        let beyond = i_d - (xd[1] + u * (xd[2] - xd[1]));
        value + slope * beyond
    }
}

fn dot3<T: Real>(w: [T; 3], p: [T; 3]) -> T {
    w[0] * p[0] + w[1] * p[1] + w[2] * p[2]
}

#[cfg(test)]
mod tests;
