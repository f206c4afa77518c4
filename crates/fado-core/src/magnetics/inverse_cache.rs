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
use super::cell_inverse::{CellGrid, CellPolynomial, invert_from};
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
        if guess != self.guess {
            self.start = grid.cell_of(guess);
            self.guess = guess;
        }
        let (slots, next) = (&mut self.slots, &mut self.next);
        invert_from(grid, self.start, |k, m| {
            let at = match slots
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
            };
            match &slots[at] {
                // The polynomial solved where it lies in the cache (no copy).
                Some((_, _, cell, constants)) => cell.root_or_direction(psi, *constants),
                None => (None, (T::lit(f64::NAN), T::lit(f64::NAN))),
            }
        })
    }
}
