//! A flux map's inverse i(ψ) with its last cells kept: what a plant's integrator calls many
//! times per sample from one warm start.
//!
//! A plant's Runge–Kutta sub-step inverts the map four times from the same warm start (the
//! last sub-step's current), and its current stays in one cell, or moves between two or three
//! neighbours, for many sub-steps. The cache keeps the warm start's cell and the last
//! [`SLOTS`] cells' polynomials with the quadratic's coefficients that do not depend on ψ, so
//! that an inversion in those cells is the quadratic alone: no search for the start cell, no
//! corner loads. The walk through the cells is the map's own
//! ([`super::MagneticModel::current_from`]) with the same arithmetic, so the result is the
//! same to the bit (tested).

use super::MagneticModel;
use super::cell_inverse::{CellGrid, CellPolynomial, cell_tolerance, direction, invert_from};
use crate::{Dq, Real};

/// Cells kept: the warm start's and its neighbours that a ripple current crosses into.
pub const SLOTS: usize = 4;

/// One kept cell: (k, m), its polynomial and the polynomial's constants (k2, ex × ey).
type Slot<T> = (usize, usize, CellPolynomial<T>, (T, T));

/// The cells an inverse of one flux map last visited, for
/// [`super::Magnetics::current_from_cached`] on a [`super::FluxMap`] or a
/// [`super::UniformFluxMap`]. One cache belongs to one map: [`InverseCache::new`] for another.
#[derive(Clone, Copy, Debug)]
pub struct InverseCache<T> {
    /// The warm start whose cell `start` is (a NaN before the first call: never equal).
    guess: Dq<T>,
    /// The cell of `guess`.
    start: (usize, usize),
    /// The last cells visited, replaced in turn from `next`.
    slots: [Option<Slot<T>>; SLOTS],
    next: usize,
    /// The last solution's slot and fractions (`InverseCache::refine` starts there).
    last: Option<(usize, T, T)>,
}

impl<T: Real> Default for InverseCache<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Real> InverseCache<T> {
    /// An empty cache.
    pub fn new() -> Self {
        Self {
            guess: Dq::new(T::lit(f64::NAN), T::lit(f64::NAN)),
            start: (0, 0),
            slots: [None; SLOTS],
            next: 0,
            last: None,
        }
    }

    /// The map's [`MagneticModel::current_from`] with its cells from the cache: the same
    /// result.
    #[inline]
    pub(super) fn current_from<G: CellGrid<T> + MagneticModel<T>>(
        &mut self,
        map: &G,
        psi: Dq<T>,
        guess: Dq<T>,
    ) -> Dq<T> {
        match self.invert(map, psi, guess) {
            Some(i) => i,
            // No root on the walk: the map's own inverse, with its Newton fallback.
            None => map.current_from(psi, guess),
        }
    }

    /// i(ψ) on `grid` by the map's walk from the cell of `guess`, its cells from the cache;
    /// None where the walk finds no root (the caller's Newton fallback).
    #[inline]
    pub(super) fn invert(
        &mut self,
        grid: &impl CellGrid<T>,
        psi: Dq<T>,
        guess: Dq<T>,
    ) -> Option<Dq<T>> {
        if let Some(found) = self.near_last_cell(grid, psi) {
            return Some(found);
        }
        if guess != self.guess {
            self.start = grid.cell_of(guess);
            self.guess = guess;
        }
        if let Some(found) = self.in_start_cell(grid, psi) {
            return Some(found);
        }
        let (slots, next) = (&mut self.slots, &mut self.next);
        let solved = invert_from(grid, self.start, |k, m| {
            let at = slot_of(slots, next, grid, k, m);
            match &slots[at] {
                // The polynomial solved where it lies in the cache (no copy).
                Some((_, _, cell, constants)) => cell.root_or_direction(psi, *constants),
                None => (None, (T::lit(f64::NAN), T::lit(f64::NAN))),
            }
        });
        // The solution's cell was the walk's last, so it is in a slot.
        self.last = solved.and_then(|(_, (k, m, u, v))| {
            let at = self
                .slots
                .iter()
                .position(|s| matches!(s, Some((a, b, _, _)) if (*a, *b) == (k, m)))?;
            Some((at, u, v))
        });
        solved.map(|(i, _)| i)
    }

    /// The last solution's cell, or the neighbour its root points into, where the root lies
    /// inside that cell by more than [`INSIDE_MARGIN`] of it: no other cell then holds the
    /// root within the walk's tolerance, so the walk from any warm start ends in this cell,
    /// with this arithmetic (the same result, bit for bit). A plant's next inversion lies in
    /// the last one's cell or its neighbour: one or two roots, no search for the warm start's
    /// cell. None elsewhere (near an edge, beyond the grid, two cells away: the walk).
    #[inline(always)]
    fn near_last_cell(&mut self, grid: &impl CellGrid<T>, psi: Dq<T>) -> Option<Dq<T>> {
        let (mut at, _, _) = self.last?;
        let (last_k, last_m) = grid.last_cell();
        let tol = cell_tolerance::<T>();
        let (lo, hi) = (T::lit(INSIDE_MARGIN), T::lit(1.0 - INSIDE_MARGIN));
        for neighbour in [false, true] {
            // The slot where it lies (no copy of its polynomial).
            let (k, m, cell, constants) = self.slots.get(at)?.as_ref()?;
            let (k, m) = (*k, *m);
            let (u, v) = cell.solve_with(psi, *constants)?;
            if u > lo && u < hi && v > lo && v < hi {
                let i = grid.current_at(k, m, u, v);
                if !i.is_finite() {
                    return None;
                }
                self.last = Some((at, u, v));
                return Some(i);
            }
            let (dk, dm) = (direction(u, k, last_k, tol), direction(v, m, last_m, tol));
            if neighbour || (dk == 0 && dm == 0) {
                return None;
            }
            let (k, m) = (k.wrapping_add_signed(dk), m.wrapping_add_signed(dm));
            at = slot_of(&mut self.slots, &mut self.next, grid, k, m);
        }
        None
    }

    /// The walk's first cell alone, where the start cell is kept and holds the root (the walk
    /// then ends there, with this arithmetic): no slot search, no walk.
    #[inline(always)]
    fn in_start_cell(&mut self, grid: &impl CellGrid<T>, psi: Dq<T>) -> Option<Dq<T>> {
        let (k, m) = self.start;
        let at = self.last.map_or(0, |(at, _, _)| at);
        let (a, b, cell, constants) = self.slots.get(at)?.as_ref()?;
        if (*a, *b) != (k, m) {
            return None;
        }
        let (u, v) = cell.solve_with(psi, *constants)?;
        let (last_k, last_m) = grid.last_cell();
        let tol = cell_tolerance::<T>();
        if direction(u, k, last_k, tol) != 0 || direction(v, m, last_m, tol) != 0 {
            return None;
        }
        let i = grid.current_at(k, m, u, v);
        if !i.is_finite() {
            return None;
        }
        self.last = Some((at, u, v));
        Some(i)
    }

    /// i(ψ) by one Newton step on the polynomial of the last solution's cell from that
    /// solution, where `psi` lies so near it that the step's own error (the cell's twist times
    /// the product of the step's fractions: exact for a bilinear cell) is below `tolerance`
    /// of the cell ([`REFINE_TOLERANCE`] for a state's current), and the step stays in the
    /// cell; where the first step stays in the cell but misses the tolerance, a second step
    /// from it (whose error is the first's squared, relatively: a flux farther from the last
    /// solution, a Runge–Kutta stage's); None elsewhere (the caller inverts). For a flux a
    /// hair from the last inversion's (a Runge–Kutta step's end beside its last stage): one
    /// division instead of a square root, two divisions and the walk. A step taken is the last solution from then on (the
    /// next step starts there; its cell is the same, so an inversion's result is not
    /// changed by it).
    #[inline]
    pub(super) fn refine(
        &mut self,
        grid: &impl CellGrid<T>,
        psi: Dq<T>,
        tolerance: T,
    ) -> Option<Dq<T>> {
        let (at, u, v) = self.last?;
        let (k, m, cell, _) = self.slots.get(at)?.as_ref()?;
        let (k, m) = (*k, *m);
        let twist = cell.twist.d.abs() + cell.twist.q.abs();
        let bound = tolerance * (cell.ex.d.abs() + cell.ey.q.abs());
        // A step's error: the twist times the product of its fractions (exact, bilinear).
        let step = |(u, v): (T, T)| {
            let (u2, v2) = cell.newton_step(psi, (u, v));
            (u2, v2, ((u2 - u) * (v2 - v)).abs() * twist)
        };
        let (last_k, last_m) = grid.last_cell();
        let tol = cell_tolerance::<T>();
        let inside =
            |u: T, v: T| direction(u, k, last_k, tol) == 0 && direction(v, m, last_m, tol) == 0;
        let (mut u2, mut v2, mut error) = step((u, v));
        if error > bound && inside(u2, v2) {
            // A second step from the first (a flux farther from the last solution).
            (u2, v2, error) = step((u2, v2));
        }
        if !(inside(u2, v2) && error <= bound) {
            return None;
        }
        let i = grid.current_at(k, m, u2, v2);
        if !i.is_finite() {
            return None;
        }
        self.last = Some((at, u2, v2));
        Some(i)
    }
}

/// The slot of cell (k, m), its polynomial computed into the next slot in turn if no slot
/// holds it.
#[inline]
fn slot_of<T: Real>(
    slots: &mut [Option<Slot<T>>; SLOTS],
    next: &mut usize,
    grid: &impl CellGrid<T>,
    k: usize,
    m: usize,
) -> usize {
    match slots
        .iter()
        .position(|s| matches!(s, Some((a, b, _, _)) if (*a, *b) == (k, m)))
    {
        Some(at) => at,
        None => {
            let cell = grid.polynomial(k, m);
            let at = *next;
            slots[at] = Some((k, m, cell, cell.constants()));
            *next = (at + 1) % SLOTS;
            at
        }
    }
}

/// How far inside its cell, as a fraction of the cell, a root must lie for the inverse to
/// take the last solution's cell or its neighbour without the walk: far above the walk's
/// tolerance ([`cell_tolerance`], 64 ε), so that no other cell holds that root.
const INSIDE_MARGIN: f64 = 1e-6;

/// The largest error of [`super::Magnetics::current_near_cached`]'s Newton step as a fraction
/// of its cell (10⁻⁹ A on a 1 A cell), ours: orders of magnitude below a plant integrator's
/// own error (10⁻⁵ A, `fado-sim`'s magnetics tests), at a step a Runge–Kutta step's end moves
/// from its last stage (10⁻⁵ of a cell: 10⁻¹¹ of it).
pub const REFINE_TOLERANCE: f64 = 1e-9;
