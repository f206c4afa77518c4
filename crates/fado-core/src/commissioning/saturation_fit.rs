//! The algebraic saturation model fitted to measured flux-linkage and current samples, the
//! regression of Hinkkanen et al., "Sensorless self-commissioning of synchronous reluctance
//! motors at standstill without rotor locking", IEEE TIA 53(3), 2017, §III–IV.
//!
//! With the exponents S, T, U, V and the magnet's flux ψf fixed, the model of
//! [`Saturation`] (without the rib, i_f = 0) is linear in its five coefficients:
//!
//! ```text
//!   i_d = a_d0·x + a_dd·|x|^S·x + a_dq·|x|^U·x·|y|^(V+2)/(V+2)
//!   i_q = a_q0·y + a_qq·|y|^T·y + a_dq·|x|^(U+2)·|y|^V·y/(U+2)       x = ψd − ψf, y = ψq
//! ```
//!
//! so each sample (ψ, i) gives two rows of one least-squares problem in
//! θ = (a_d0, a_dd, a_q0, a_qq, a_dq), a_dq shared by both axes (the model's reciprocity).
//! The normal equations are accumulated sample by sample (5 × 5, no allocation) and solved
//! by Gaussian elimination with partial pivoting on the problem scaled to a unit diagonal
//! (the regressors span several decades: |x|^5 against x).
//!
//! Standstill injections give the samples: the flux linkage is the integral of v − R̂s·i
//! from zero current (where ψ = (ψf, 0)), at the turning points of bipolar current
//! excitations along d with i_q = 0, along q with i_d held at several levels (the q
//! excitation's torque alternates, so the rotor, unlocked, stays put).

use crate::Real;
use crate::magnetics::Saturation;

/// Number of coefficients fitted.
const N: usize = 5;

/// The regression of the module docs, accumulated.
#[derive(Clone, Copy, Debug)]
pub struct SaturationFit<T> {
    /// The exponents and ψf of the fitted model (its coefficients are ignored).
    shape: Saturation<T>,
    ata: [[T; N]; N],
    atb: [T; N],
    samples: u32,
}

/// |x|^e for an exponent e ≥ 0 (|0|^0 = 1).
pub(super) fn pow_abs<T: Real>(x: T, e: T) -> T {
    if e == T::zero() {
        T::one()
    } else {
        x.abs().powf(e)
    }
}

impl<T: Real> SaturationFit<T> {
    /// An empty fit of a model with `shape`'s exponents `s`, `t`, `u`, `v` and flux `psi_f`.
    pub fn new(shape: Saturation<T>) -> Self {
        Self {
            shape,
            ata: [[T::zero(); N]; N],
            atb: [T::zero(); N],
            samples: 0,
        }
    }

    /// Samples taken so far.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// The two regressor rows of the flux linkage `psi` (d row, q row).
    fn rows(&self, psi_d: T, psi_q: T) -> ([T; N], [T; N]) {
        let s = &self.shape;
        let two = T::lit(2.0);
        let (x, y) = (psi_d - s.psi_f, psi_q);
        let z = T::zero();
        let cross_d = pow_abs(x, s.u) * x * pow_abs(y, s.v + two) / (s.v + two);
        let cross_q = pow_abs(x, s.u + two) * pow_abs(y, s.v) * y / (s.u + two);
        (
            [x, pow_abs(x, s.s) * x, z, z, cross_d],
            [z, z, y, pow_abs(y, s.t) * y, cross_q],
        )
    }

    /// Adds a sample: flux linkage ψ (Wb) and current i (A), rotor frame. Non-finite samples
    /// are ignored (they never poison the fit).
    pub fn push(&mut self, psi_d: T, psi_q: T, i_d: T, i_q: T) {
        if !(psi_d.is_finite() && psi_q.is_finite() && i_d.is_finite() && i_q.is_finite()) {
            return;
        }
        let (rd, rq) = self.rows(psi_d, psi_q);
        for (row, b) in [(rd, i_d), (rq, i_q)] {
            for j in 0..N {
                for k in 0..N {
                    self.ata[j][k] += row[j] * row[k];
                }
                self.atb[j] += row[j] * b;
            }
        }
        self.samples += 1;
    }

    /// The fitted model (the shape's exponents and ψf with the fitted coefficients), or None
    /// when the samples do not determine them (too few, or no excitation of a term: a
    /// coefficient the data cannot see is not guessed). A coefficient fitted negative
    /// (saturation terms only) is refused as well: the model would not be monotonic.
    pub fn solve(&self) -> Option<Saturation<T>> {
        let x = solve_normal(self.ata, self.atb)?;
        let c = |j: usize| x[j];
        let fitted = Saturation {
            a_d0: c(0),
            a_dd: c(1),
            a_q0: c(2),
            a_qq: c(3),
            a_dq: c(4),
            ..self.shape
        };
        fitted.validate().ok().map(|_| fitted)
    }
}

/// The normal equations `a·x = b` solved on the problem scaled to a unit diagonal (the
/// regressors span several decades: |x|^5 against x); None when a diagonal entry is not
/// positive (a regressor the data never excites) or the matrix is singular.
pub(super) fn solve_normal<T: Real, const M: usize>(
    mut a: [[T; M]; M],
    mut b: [T; M],
) -> Option<[T; M]> {
    let mut scale = [T::zero(); M];
    for j in 0..M {
        if !a[j][j].is_finite() || a[j][j] <= T::zero() {
            return None;
        }
        scale[j] = T::one() / a[j][j].sqrt();
    }
    for j in 0..M {
        for k in 0..M {
            a[j][k] *= scale[j] * scale[k];
        }
        b[j] *= scale[j];
    }
    let x = solve_in_place(&mut a, &mut b)?;
    Some(core::array::from_fn(|j| x[j] * scale[j]))
}

/// Gaussian elimination with partial pivoting; None for a (numerically) singular matrix.
pub(super) fn solve_in_place<T: Real, const M: usize>(
    a: &mut [[T; M]; M],
    b: &mut [T; M],
) -> Option<[T; M]> {
    let tiny = T::lit(1e-12);
    for col in 0..M {
        let mut pivot = col;
        for r in col + 1..M {
            if a[r][col].abs() > a[pivot][col].abs() {
                pivot = r;
            }
        }
        let p = a[pivot][col].abs();
        if !p.is_finite() || p <= tiny {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for r in col + 1..M {
            let f = a[r][col] / a[col][col];
            let (upper, lower) = a.split_at_mut(r);
            for (x, v) in lower[0][col..].iter_mut().zip(&upper[col][col..]) {
                *x -= f * *v;
            }
            let v = b[col];
            b[r] -= f * v;
        }
    }
    let mut x = [T::zero(); M];
    for col in (0..M).rev() {
        let mut acc = b[col];
        for k in col + 1..M {
            acc -= a[col][k] * x[k];
        }
        x[col] = acc / a[col][col];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Dq;
    use crate::magnetics::MagneticModel;

    /// motulator's 6.7 kW SyRM fit (Hinkkanen et al. 2017's machine) with a magnet's flux.
    fn truth() -> Saturation<f64> {
        Saturation {
            psi_f: 0.1,
            ..crate::magnetics::tests::syrm()
        }
    }

    /// The turning points of the standstill excitations: d alone, and q at several d levels.
    fn excite(model: &impl MagneticModel<f64>, fit: &mut SaturationFit<f64>, noise: f64) {
        let mut k = 0u32;
        for &id in &[-12.0, -6.0, 0.0, 6.0, 12.0, 18.0] {
            for &iq in &[-30.0, -20.0, -10.0, 0.0, 10.0, 20.0, 30.0] {
                let psi = model.flux(Dq::new(id, iq));
                // A deterministic ±noise on the flux (the integration's error).
                k += 1;
                let e = noise * if k.is_multiple_of(2) { 1.0 } else { -1.0 };
                fit.push(psi.d * (1.0 + e), psi.q * (1.0 - e), id, iq);
            }
        }
    }

    #[test]
    fn exact_samples_give_the_coefficients_back() {
        let truth = truth();
        let mut fit = SaturationFit::new(Saturation {
            a_d0: 1.0,
            a_q0: 1.0,
            ..truth
        });
        excite(&truth, &mut fit, 0.0);
        let got = fit.solve().unwrap();
        for (name, a, b) in [
            ("a_d0", got.a_d0, truth.a_d0),
            ("a_dd", got.a_dd, truth.a_dd),
            ("a_q0", got.a_q0, truth.a_q0),
            ("a_qq", got.a_qq, truth.a_qq),
            ("a_dq", got.a_dq, truth.a_dq),
        ] {
            assert!((a / b - 1.0).abs() < 1e-7, "{name}: {a} against {b}");
        }
    }

    #[test]
    fn a_noisy_flux_gives_a_close_model_and_bad_data_none() {
        let truth = truth();
        let mut fit = SaturationFit::new(truth);
        excite(&truth, &mut fit, 0.005);
        let got = fit.solve().unwrap();
        // The fitted model's flux at rated-like currents within 2 % of the truth's.
        for &(id, iq) in &[(0.0, 25.0), (10.0, 20.0), (-8.0, 5.0)] {
            let (a, b) = (got.flux(Dq::new(id, iq)), truth.flux(Dq::new(id, iq)));
            assert!(
                (a - b).norm() < 0.02 * b.norm(),
                "({id}, {iq}): {a:?} against {b:?}"
            );
        }
        // Only d excited: the q coefficients are not determined.
        let mut d_only = SaturationFit::new(truth);
        for id in [-10.0, -5.0, 5.0, 10.0] {
            let psi = truth.flux(Dq::new(id, 0.0));
            d_only.push(psi.d, psi.q, id, 0.0);
        }
        d_only.push(f64::NAN, 0.0, 1.0, 0.0);
        assert_eq!(d_only.samples(), 4);
        assert!(d_only.solve().is_none());
    }
}
