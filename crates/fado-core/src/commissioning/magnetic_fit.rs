//! The magnetic model read from the standstill flux-linkage pulses (module docs, step 5): the
//! stored samples (Δψ, i) and the search over the algebraic model's shapes.
//!
//! Each sample is a flux-linkage change Δψ from zero current (where ψ = (λf, 0)) and the
//! current it carries. With λ̂f (the spin's) the samples are points (ψ, i) of the machine's
//! map, and for fixed exponents the algebraic model of [`Saturation`] is linear in its
//! coefficients (as in [`super::SaturationFit`]). Two ways for the magnet to enter are tried,
//! the two a [`Saturation`] offers:
//! - **around the flux** (`psi_f` = λ̂f): d saturates symmetrically about the magnet's flux,
//!   x = Δψd, and ψd = λf at i_d = 0 for any i_q;
//! - **as a current** (`i_f`, `psi_f` = 0): x = λ̂f + Δψd, with i_f a sixth unknown: d
//!   saturation is then asymmetric about the magnet's flux and cross-saturation lowers ψd with
//!   i_q at i_d = 0 (the interior-magnet machine's).
//!
//! Every combination of the exponents S, T ∈ {none, 1, …, 8} and of the cross term (none, or
//! U, V ∈ {0, 1, 2}) is fitted in each form (1620 least-squares problems of at most six
//! unknowns over the stored samples, once, at the end of the procedure); the model with the
//! least squared current residual among those that are monotonic (non-negative saturation
//! coefficients) is kept.
//!
//! A third form adds the **saturating rib** of Lelli, Hinkkanen & Giulii Capponi (ICEM 2024):
//! a PM-assisted SyRM's magnet acts through the iron bridges, a Norton source ψn behind the
//! bridges' saturating inverse inductance a_b·ρ^W/(1 + a_bp·ρ^W), ρ = √((ψd − ψn)² + k_q·ψq²).
//! For fixed ψn, a_bp, k_q (W = 2) the model is again linear in its coefficients (a_b a
//! seventh); the three are searched on a grid with the exponents, then refined
//! (`rib_search`). The rib is kept only when it at least halves the squared residual of the
//! best model without it (`RIB_GAIN`), so that a machine without bridges keeps the simpler
//! model. Hinkkanen et al. (IEEE TIA 53(3), 2017) choose the exponents by hand
//! for their machine; a search lets the data choose them for a machine nobody looked at.

use super::saturation_fit::solve_normal;
use crate::magnetics::{MagneticModel, Saturation};
use crate::{Dq, Real};

/// Most stored samples (Δψd, Δψq, i_d, i_q and the pulses' rotor-motion shape): 160 × 5
/// numbers (3.2 kB in f32).
pub(super) const SAMPLE_CAPACITY: usize = 160;

/// Unknowns of one fit: a_d0, a_dd, a_q0, a_qq, a_dq, i_f, a_b.
const COLS: usize = 7;

/// The rib's Norton flux ψn tried, in units of λ̂f (the magnet's flux at zero current lies
/// below it; 1.69 on the 5.6 kW PM-SyRM of Lelli et al.).
const RIB_PSI_N: [f64; 9] = [1.1, 1.2, 1.35, 1.5, 1.6, 1.7, 1.85, 2.1, 2.5];

/// The rib's saturation a_bp tried, in units of 1/λ̂f² (W = 2: a_bp·ρ² is the rib's own
/// saturation at ρ; 0.23 on that machine).
const RIB_A_BP: [f64; 4] = [0.0, 0.25, 1.0, 4.0];

/// The rib's share of the q flux k_q tried (0.1 on that machine).
const RIB_K_Q: [f64; 5] = [0.0, 0.05, 0.1, 0.2, 0.4];

/// Rounds of the alternating search over the rib's grid and the exponents (`rib_search`).
const RIB_ROUNDS: usize = 2;

/// The rib is kept when it lowers the squared current residual of the best model without it
/// by at least this factor (its 3 searched parameters and a_b would otherwise fit noise).
const RIB_GAIN: f64 = 0.5;

/// A rib's nonlinear parameters (W = 2), in the units of the grids above.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Rib {
    psi_n: f64,
    a_bp: f64,
    k_q: f64,
}

impl Rib {
    /// Every rib of the grid.
    fn grid() -> impl Iterator<Item = Rib> {
        RIB_PSI_N.into_iter().flat_map(|psi_n| {
            RIB_A_BP
                .into_iter()
                .flat_map(move |a_bp| RIB_K_Q.into_iter().map(move |k_q| Rib { psi_n, a_bp, k_q }))
        })
    }

    /// ψn, a_bp, k_q in SI for the magnet's flux `flux`.
    fn si<T: Real>(&self, flux: T) -> (T, T, T) {
        (
            T::lit(self.psi_n) * flux,
            T::lit(self.a_bp) / (flux * flux),
            T::lit(self.k_q),
        )
    }

    /// The rib's regressor (d, q) at the flux linkage (x, y): G_b/a_b·(ψb, k_q·ψq).
    fn rows<T: Real>(&self, flux: T, x: T, y: T) -> (T, T) {
        let (psi_n, a_bp, k_q) = self.si(flux);
        let b = x - psi_n;
        let rho2 = b * b + k_q * y * y;
        let g = rho2 / (T::one() + a_bp * rho2);
        (g * b, k_q * g * y)
    }
}

/// Largest self-saturation exponent tried.
const MAX_SELF_EXPONENT: u8 = 8;

/// Largest cross-saturation exponent tried.
const MAX_CROSS_EXPONENT: u8 = 2;

/// The stored samples.
#[derive(Clone, Copy, Debug)]
pub(super) struct FluxSamples<T> {
    data: [[T; 5]; SAMPLE_CAPACITY],
    len: usize,
}

impl<T: Real> FluxSamples<T> {
    /// Empty.
    pub(super) fn new() -> Self {
        Self {
            data: [[T::zero(); 5]; SAMPLE_CAPACITY],
            len: 0,
        }
    }

    /// Samples stored.
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// Stores a sample with a fifth number `m` for [`FluxSamples::map_from`] (ignored when
    /// full or non-finite).
    pub(super) fn push(&mut self, dpsi: Dq<T>, i: Dq<T>, m: T) {
        if self.len < SAMPLE_CAPACITY && dpsi.is_finite() && i.is_finite() && m.is_finite() {
            self.data[self.len] = [dpsi.d, dpsi.q, i.d, i.q, m];
            self.len += 1;
        }
    }

    /// Replaces each sample from index `start` on by `f(Δψ, i, m)`.
    pub(super) fn map_from(&mut self, start: usize, f: impl Fn(Dq<T>, Dq<T>, T) -> (Dq<T>, Dq<T>)) {
        for s in self.data[start.min(self.len)..self.len].iter_mut() {
            let (p, i) = f(Dq::new(s[0], s[1]), Dq::new(s[2], s[3]), s[4]);
            *s = [p.d, p.q, i.d, i.q, s[4]];
        }
    }

    fn iter(&self) -> impl Iterator<Item = (Dq<T>, Dq<T>)> + '_ {
        self.data[..self.len]
            .iter()
            .map(|s| (Dq::new(s[0], s[1]), Dq::new(s[2], s[3])))
    }
}

/// How the magnet enters the fitted model (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Form {
    AroundFlux,
    MagnetCurrent,
}

/// One candidate: the form and the exponents (None: the term is left out).
#[derive(Clone, Copy, Debug)]
struct Shape {
    form: Form,
    s: Option<u8>,
    t: Option<u8>,
    cross: Option<(u8, u8)>,
    /// The saturating rib of Lelli et al. (with the magnet as a current).
    rib: Option<Rib>,
}

impl Shape {
    /// Whether column `j` is fitted.
    fn column(&self, j: usize) -> bool {
        match j {
            1 => self.s.is_some(),
            3 => self.t.is_some(),
            4 => self.cross.is_some(),
            5 => self.form == Form::MagnetCurrent,
            6 => self.rib.is_some(),
            _ => true,
        }
    }

    /// The regressor rows (d, q) of the flux linkage change `dpsi`, λ̂f `flux`.
    fn rows<T: Real>(&self, flux: T, dpsi: Dq<T>) -> ([T; COLS], [T; COLS]) {
        let e = |n: u8| T::lit(f64::from(n));
        let x = match self.form {
            Form::AroundFlux => dpsi.d,
            Form::MagnetCurrent => flux + dpsi.d,
        };
        let y = dpsi.q;
        let z = T::zero();
        let (cross_d, cross_q) = match self.cross {
            Some((u, v)) => (
                powi_abs(x, u) * x * powi_abs(y, v + 2) / e(v + 2),
                powi_abs(x, u + 2) * powi_abs(y, v) * y / e(u + 2),
            ),
            None => (z, z),
        };
        let self_d = self.s.map_or(z, |s| powi_abs(x, s) * x);
        let self_q = self.t.map_or(z, |t| powi_abs(y, t) * y);
        let magnet = if self.form == Form::MagnetCurrent {
            -T::one()
        } else {
            z
        };
        let (rib_d, rib_q) = self.rib.map_or((z, z), |r| r.rows(flux, x, y));
        (
            [x, self_d, z, z, cross_d, magnet, rib_d],
            [z, z, y, self_q, cross_q, z, rib_q],
        )
    }

    /// The model of the coefficients `c`.
    fn model<T: Real>(&self, flux: T, c: &[T; COLS]) -> Saturation<T> {
        let e = |n: Option<u8>| T::lit(f64::from(n.unwrap_or(0)));
        let (u, v) = self.cross.unzip();
        let (psi_n, a_bp, k_q) = self
            .rib
            .map_or((T::zero(), T::zero(), T::zero()), |r| r.si(flux));
        Saturation {
            a_d0: c[0],
            a_dd: c[1],
            s: e(self.s),
            a_q0: c[2],
            a_qq: c[3],
            t: e(self.t),
            a_dq: c[4],
            u: e(u),
            v: e(v),
            psi_f: if self.form == Form::AroundFlux {
                flux
            } else {
                T::zero()
            },
            i_f: c[5],
            psi_n,
            a_b: c[6],
            a_bp,
            w: T::lit(2.0),
            k_q,
        }
    }

    /// The least-squares fit of this shape: the model and its squared current residual.
    fn fit<T: Real>(&self, samples: &FluxSamples<T>, flux: T) -> Option<(Saturation<T>, T)> {
        let mut a = [[T::zero(); COLS]; COLS];
        let mut b = [T::zero(); COLS];
        for (dpsi, i) in samples.iter() {
            let (rd, rq) = self.rows(flux, dpsi);
            for (row, y) in [(rd, i.d), (rq, i.q)] {
                for j in 0..COLS {
                    for k in 0..COLS {
                        a[j][k] += row[j] * row[k];
                    }
                    b[j] += row[j] * y;
                }
            }
        }
        // A term left out: its coefficient is pinned to zero.
        for j in (0..COLS).filter(|&j| !self.column(j)) {
            a[j][j] = T::one();
        }
        let c = solve_normal(a, b)?;
        let model = self.model(flux, &c);
        model.validate().ok()?;
        let mut residual = T::zero();
        for (dpsi, i) in samples.iter() {
            let (rd, rq) = self.rows(flux, dpsi);
            let dot = |r: [T; COLS]| r.iter().zip(&c).fold(T::zero(), |s, (x, y)| s + *x * *y);
            let (ed, eq) = (dot(rd) - i.d, dot(rq) - i.q);
            residual += ed * ed + eq * eq;
        }
        residual.is_finite().then_some((model, residual))
    }
}

/// |x|^n for the small integer exponents of the search (products: no `powf` in the
/// search's inner loop).
fn powi_abs<T: Real>(x: T, n: u8) -> T {
    let a = x.abs();
    (0..n).fold(T::one(), |p, _| p * a)
}

/// Every candidate shape, in a fixed order (module docs).
fn shapes() -> impl Iterator<Item = Shape> {
    let selfs = || core::iter::once(None).chain((1..=MAX_SELF_EXPONENT).map(Some));
    let crosses = core::iter::once(None).chain(
        (0..=MAX_CROSS_EXPONENT).flat_map(|u| (0..=MAX_CROSS_EXPONENT).map(move |v| Some((u, v)))),
    );
    [Form::AroundFlux, Form::MagnetCurrent]
        .into_iter()
        .flat_map(move |form| {
            crosses.clone().flat_map(move |cross| {
                selfs().flat_map(move |s| {
                    selfs().map(move |t| Shape {
                        form,
                        s,
                        t,
                        cross,
                        rib: None,
                    })
                })
            })
        })
}

/// The best-fitting algebraic model of the samples with the magnet's flux `flux` (module
/// docs), its RMS current residual and the constant-inductance model's, in A; None when no
/// shape fits (too few samples). A model with the rib is taken only where `accept` takes it
/// (the procedure's check against the injection tests' inductances).
pub(super) fn best_fit<T: Real>(
    samples: &FluxSamples<T>,
    flux: T,
    accept: impl Fn(&Saturation<T>) -> bool,
) -> Option<(Saturation<T>, T, T)> {
    let n = T::lit((2 * samples.len()).max(1) as f64);
    let linear = Shape {
        form: Form::AroundFlux,
        s: None,
        t: None,
        cross: None,
        rib: None,
    };
    let (_, r_linear) = linear.fit(samples, flux)?;
    let (_, m, r) = best_of(shapes(), samples, flux)?;
    let (m, r) = match rib_search(samples, flux) {
        Some((m_rib, r_rib)) if r_rib < T::lit(RIB_GAIN) * r && accept(&m_rib) => (m_rib, r_rib),
        _ => (m, r),
    };
    Some((m, (r / n).sqrt(), (r_linear / n).sqrt()))
}

/// The shape of `candidates` with the least squared current residual: it, its model and
/// the residual.
fn best_of<T: Real>(
    candidates: impl Iterator<Item = Shape>,
    samples: &FluxSamples<T>,
    flux: T,
) -> Option<(Shape, Saturation<T>, T)> {
    let mut best: Option<(Shape, Saturation<T>, T)> = None;
    for shape in candidates {
        if let Some((m, r)) = shape.fit(samples, flux)
            && best.as_ref().is_none_or(|(_, _, b)| r < *b)
        {
            best = Some((shape, m, r));
        }
    }
    best
}

/// The best model with a rib: the rib's grid times the coarse exponents
/// ([`coarse_shapes`]: 180 × 100 fits), then [`RIB_ROUNDS`] rounds of every exponent with
/// the rib fixed and the rib's three parameters refined with the exponents fixed
/// ([`refine_rib`]). A search alternating from the best shape without a rib stops in a
/// local optimum (measured on the 5.6 kW PM-SyRM: incremental inductances 25 % off, where
/// the product reaches 1.4 %).
fn rib_search<T: Real>(samples: &FluxSamples<T>, flux: T) -> Option<(Saturation<T>, T)> {
    let coarse = coarse_shapes().flat_map(|shape| {
        Rib::grid().map(move |rib| Shape {
            rib: Some(rib),
            ..shape
        })
    });
    let (mut shape, mut m, mut r) = best_of(coarse, samples, flux)?;
    for _ in 0..RIB_ROUNDS {
        let rib = shape.rib;
        let exponents = shapes()
            .filter(|s| s.form == Form::MagnetCurrent)
            .map(|s| Shape { rib, ..s });
        (shape, m, r) = best_of(exponents, samples, flux)?;
        (shape, m, r) = refine_rib((shape, m, r), samples, flux);
    }
    Some((m, r))
}

/// The exponents of the rib's first search: S, T ∈ {none, 2, 4, 6, 8} and the cross term
/// none or U = V ∈ {0, 1, 2}, with the magnet as a current.
fn coarse_shapes() -> impl Iterator<Item = Shape> {
    let selfs = || core::iter::once(None).chain((2..=MAX_SELF_EXPONENT).step_by(2).map(Some));
    let crosses = core::iter::once(None).chain((0..=MAX_CROSS_EXPONENT).map(|u| Some((u, u))));
    crosses.flat_map(move |cross| {
        selfs().flat_map(move |s| {
            selfs().map(move |t| Shape {
                form: Form::MagnetCurrent,
                s,
                t,
                cross,
                rib: None,
            })
        })
    })
}

/// A pattern search of the rib's ψn, a_bp and k_q about `best` (steps of 10 % of each, or of
/// its grid's first step, halved when no neighbour fits better, down to 0.1 %).
fn refine_rib<T: Real>(
    mut best: (Shape, Saturation<T>, T),
    samples: &FluxSamples<T>,
    flux: T,
) -> (Shape, Saturation<T>, T) {
    let mut h = 0.1;
    while h > 1e-3 {
        let Some(rib) = best.0.rib else {
            return best;
        };
        let steps = [
            (h * rib.psi_n, 0.0, 0.0),
            (0.0, h * (rib.a_bp + RIB_A_BP[1]), 0.0),
            (0.0, 0.0, h * (rib.k_q + RIB_K_Q[1])),
        ];
        let neighbours = steps.into_iter().flat_map(|(a, b, c)| {
            [1.0, -1.0].map(|sign| Rib {
                psi_n: rib.psi_n + sign * a,
                a_bp: (rib.a_bp + sign * b).max(0.0),
                k_q: (rib.k_q + sign * c).max(0.0),
            })
        });
        let candidates = neighbours.map(|rib| Shape {
            rib: Some(rib),
            ..best.0
        });
        match best_of(candidates, samples, flux) {
            Some(next) if next.2 < best.2 => best = next,
            _ => h *= 0.5,
        }
    }
    best
}

/// Equal bands of the current magnitude, from zero to the pulses' peak current, in each of
/// which the commissioning measures the fitted model's RMS flux residual
/// ([`super::Identification::saturation_flux_residuals`]): four, so that each holds tens of
/// the stored samples.
pub const RESIDUAL_BANDS: usize = 4;

/// The RMS flux residual |ψ̂(i) − ψ| (Wb) of `model` over the stored samples in each of
/// [`RESIDUAL_BANDS`] equal bands of |i| from 0 to `i_max` (a sample beyond it counts in the
/// last), the samples' ψ being (`flux` + Δψd, Δψq); 0 in a band without samples.
pub(super) fn flux_residual_bands<T: Real>(
    samples: &FluxSamples<T>,
    model: &impl MagneticModel<T>,
    flux: T,
    i_max: T,
) -> [T; RESIDUAL_BANDS] {
    let mut sums = [(T::zero(), T::zero()); RESIDUAL_BANDS];
    let width = i_max / T::from_index(RESIDUAL_BANDS);
    for (dpsi, i) in samples.iter() {
        let psi = Dq::new(flux + dpsi.d, dpsi.q);
        let r = (model.flux(i) - psi).norm();
        let k = (i.norm() / width).index_floor(RESIDUAL_BANDS - 1);
        if let Some(b) = sums.get_mut(k) {
            *b = (b.0 + r * r, b.1 + T::one());
        }
    }
    sums.map(|(s, n)| {
        if n > T::zero() {
            (s / n).sqrt()
        } else {
            T::zero()
        }
    })
}

/// The detection statistic: the largest relative change of the incremental inductances
/// L_dd, L_qq (and the largest cross term |L_dq| relative to √(L_dd·L_qq)) of `model` at
/// currents of magnitude ½ and 1 × `current` (twelve directions each) against its values at
/// zero current.
pub(super) fn inductance_change<T: Real>(model: &impl MagneticModel<T>, current: T) -> T {
    let l0 = model.incremental_inductance(Dq::zero());
    let norm = (l0.dd * l0.qq).abs().sqrt();
    let mut worst = T::zero();
    for k in 0..24usize {
        let angle = T::lit(core::f64::consts::TAU / 12.0) * T::from_index(k % 12);
        let mag = if k < 12 { T::lit(0.5) } else { T::one() } * current;
        let l = model.incremental_inductance(Dq::new(mag * angle.cos(), mag * angle.sin()));
        let change = (l.dd / l0.dd - T::one())
            .abs()
            .max((l.qq / l0.qq - T::one()).abs())
            .max(l.dq.abs() / norm);
        worst = if change.is_finite() {
            worst.max(change)
        } else {
            T::lit(f64::INFINITY)
        };
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::magnetics::tests::syrm;

    /// The samples a pulse test gives: flux-linkage changes from zero current along twelve
    /// directions up to `i_max`, with the current they carry.
    fn samples(model: &Saturation<f64>, i_max: f64) -> FluxSamples<f64> {
        let mut s = FluxSamples::new();
        let psi0 = model.flux(Dq::zero());
        for k in 0..12 {
            let a = core::f64::consts::TAU * k as f64 / 12.0;
            for n in 1..=10 {
                let i = Dq::new(a.cos(), a.sin()) * (i_max * n as f64 / 10.0);
                s.push(model.flux(i) - psi0, i, 0.0);
            }
        }
        s
    }

    /// The search finds the exponents and coefficients of two models of different form: the
    /// 6.7 kW SyRM of Hinkkanen et al. with a magnet's flux around which d saturates, and an
    /// IPMSM whose magnet is a current (cross-saturation lowering ψd at i_d = 0).
    #[test]
    fn the_search_recovers_models_of_both_forms() {
        let around = Saturation {
            psi_f: 0.1,
            ..syrm()
        };
        let current = Saturation {
            a_d0: 80.0,
            a_dd: 1000.0,
            s: 2.0,
            a_q0: 33.0,
            a_qq: 1500.0,
            t: 2.0,
            a_dq: 60.0,
            u: 1.0,
            v: 1.0,
            i_f: 24.0,
            ..Saturation::default()
        };
        for (truth, i_max) in [(around, 20.0), (current, 10.0)] {
            let flux = truth.flux(Dq::zero()).d;
            let (m, rms, rms_linear) = best_fit(&samples(&truth, i_max), flux, |_| true).unwrap();
            assert!(
                rms < 1e-6 * i_max && rms_linear > 1e-2 * i_max,
                "{rms} {rms_linear}"
            );
            for i in [Dq::new(0.5, 0.8), Dq::new(-0.7, 0.6), Dq::new(0.1, -0.9)] {
                let i = i * i_max;
                let (a, b) = (m.flux(i), truth.flux(i));
                assert!((a - b).norm() < 1e-6 * b.norm(), "{m:?}");
            }
            assert!(inductance_change(&m, i_max) > 0.3);
        }
    }

    /// The 5.6 kW PM-SyRM of Lelli et al. (the magnet as the rib's Norton source), sampled
    /// along the pulses' six directions (0°, 60°, …, 300°) up to its rated 12.45 A: the
    /// search with the rib finds a model whose incremental inductances are within 2 % of the
    /// truth's over the rated current range (a 9 × 9 grid of |i| ≤ 12.45 A; measured 0.26 %);
    /// the best model without it is off by more than 10 % (measured 59 %).
    #[test]
    fn the_rib_search_recovers_the_pm_syrm() {
        let truth = crate::magnetics::tests::pmsyrm();
        let i_max = 12.45;
        let psi0 = truth.flux(Dq::zero());
        let mut s = FluxSamples::new();
        for k in 0..6 {
            let a = core::f64::consts::TAU * k as f64 / 6.0;
            for n in 1..=20 {
                let i = Dq::new(a.cos(), a.sin()) * (i_max * n as f64 / 20.0);
                s.push(truth.flux(i) - psi0, i, 0.0);
            }
        }
        let worst = |m: &Saturation<f64>| {
            let mut w = 0.0f64;
            for j in -4..=4 {
                for k in -4..=4 {
                    let i = Dq::new(j as f64, k as f64) * (i_max / 4.0);
                    if i.norm() <= i_max {
                        let (a, b) = (m.incremental_inductance(i), truth.incremental_inductance(i));
                        w = w
                            .max((a.dd / b.dd - 1.0).abs())
                            .max((a.qq / b.qq - 1.0).abs());
                    }
                }
            }
            w
        };
        let (m, _, _) = best_fit(&s, psi0.d, |_| true).unwrap();
        let (_, m0, _) = best_of(shapes(), &s, psi0.d).unwrap();
        assert!(m.a_b > 0.0 && worst(&m) < 0.02 && worst(&m0) > 0.1);
    }

    /// Constant inductances: no change; too few samples: no model.
    #[test]
    fn a_linear_model_does_not_change_and_no_samples_give_none() {
        let linear = Saturation::linear(4e-3, 17e-3, 0.134);
        assert!(inductance_change(&linear, 22.0) < 1e-9);
        assert!(best_fit(&FluxSamples::<f64>::new(), 0.134, |_| true).is_none());
    }
}
