//! The algebraic saturation model: a current map i(ψ) from a magnetic energy.

use super::{InductanceMatrix, MagneticModel, newton_checked};
use crate::error::{ConfigError, check};
use crate::{Dq, Real};

/// Steps of [`Saturation::flux_damped`] at most (each converges linearly at worst, halving
/// the error of a step that overshoots).
const DAMPED_ITERATIONS: usize = 100;

/// Halvings of one damped step at most: 2⁻⁴⁰ of a Newton step is below any flux's
/// resolution.
const DAMPING_HALVINGS: usize = 40;

/// Self- and cross-saturation of Hinkkanen et al. (IEEE TIA 53(3), 2017, eq. (7)–(9)) around
/// the magnet's flux, plus the saturating rib of Lelli et al. (ICEM 2024), as in motulator's
/// `SaturationModelSyRM` / `SaturationModelPMSyRM`:
///
/// ```text
///   ψd' = ψd − ψf
///   i_d = [a_d0 + a_dd·|ψd'|^S + a_dq/(V+2)·|ψd'|^U·|ψq|^(V+2)]·ψd' + G_b·ψb − i_f
///   i_q = [a_q0 + a_qq·|ψq|^T  + a_dq/(U+2)·|ψd'|^(U+2)·|ψq|^V]·ψq  + k_q·G_b·ψq
///   ψb = ψd − ψn,  ρ = √(ψb² + k_q·ψq²),  G_b = a_b·ρ^W / (1 + a_bp·ρ^W)
/// ```
///
/// Both currents are the gradient of one magnetic energy
///
/// ```text
///   W(ψ) = a_d0·ψd'²/2 + a_dd·|ψd'|^(S+2)/(S+2) + a_q0·ψq²/2 + a_qq·|ψq|^(T+2)/(T+2)
///        + a_dq·|ψd'|^(U+2)·|ψq|^(V+2)/((U+2)(V+2)) + ∫₀^ρ a_b·r^(W+1)/(1 + a_bp·r^W) dr,
/// ```
///
/// (minus i_f·ψd), so that the model is reciprocal (∂i_d/∂ψq = ∂i_q/∂ψd) and conserves energy.
///
/// The magnet enters in one of two ways. As a flux ψf (`psi_f`), d saturates symmetrically
/// around it and ψd = ψf at i_d = 0 whatever i_q. As a magnetomotive force i_f (`i_f`, the
/// magnet's equivalent d current, with `psi_f` = 0), the magnet's flux is where the d branch
/// carries i_f: d self-saturation then makes positive i_d saturate and negative i_d relieve it
/// (the asymmetry of surface magnets), and cross-saturation lowers ψd with i_q at i_d = 0
/// (the interior-magnet machine's cross-saturation).
///
/// Special cases: a_dd = a_qq = a_dq = a_b = 0 is the linear machine with Ld = 1/a_d0,
/// Lq = 1/a_q0, λf = ψf; ψf = 0 with a_b = 0 is the synchronous reluctance machine of
/// Hinkkanen et al.; ψf = 0 with the rib is motulator's PM-SyRM model (the magnet as the rib's
/// Norton source ψn). Coefficients in SI (a_d0 in 1/H, a_dd in A/Wb^(S+1), …).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct Saturation<T> {
    /// Unsaturated inverse d inductance a_d0 in 1/H.
    pub a_d0: T,
    /// d self-saturation coefficient a_dd.
    pub a_dd: T,
    /// d self-saturation exponent S (≥ 0).
    pub s: T,
    /// Unsaturated inverse q inductance a_q0 in 1/H.
    pub a_q0: T,
    /// q self-saturation coefficient a_qq.
    pub a_qq: T,
    /// q self-saturation exponent T (≥ 0).
    pub t: T,
    /// Cross-saturation coefficient a_dq.
    pub a_dq: T,
    /// Cross-saturation exponent U on |ψd'| (≥ 0).
    pub u: T,
    /// Cross-saturation exponent V on |ψq| (≥ 0).
    pub v: T,
    /// The magnet's flux ψf in Wb around which d saturates (0 for a reluctance machine).
    pub psi_f: T,
    /// The rib's Norton flux ψn in Wb (used when `a_b` > 0).
    pub psi_n: T,
    /// Rib inverse-inductance coefficient a_b (0: no rib).
    pub a_b: T,
    /// Rib saturation coefficient a_bp (≥ 0).
    pub a_bp: T,
    /// Rib exponent W (≥ 2, or 0: the constant conductance a_b/(1 + a_bp) of a rib that does
    /// not saturate, the magnet then a linear Norton source).
    pub w: T,
    /// Rib's share of the q flux k_q (≥ 0).
    pub k_q: T,
    /// The magnet as a magnetomotive force: its equivalent d current i_f in A (0: none).
    pub i_f: T,
}

/// The empty record (every coefficient 0, exponents 0, the rib's exponent 2): a partial TOML
/// table merges over it; [`Saturation::validate`] refuses it naming `a_d0`.
impl<T: Real> Default for Saturation<T> {
    fn default() -> Self {
        let z = T::zero();
        Self {
            a_d0: z,
            a_dd: z,
            s: z,
            a_q0: z,
            a_qq: z,
            t: z,
            a_dq: z,
            u: z,
            v: z,
            psi_f: z,
            psi_n: z,
            a_b: z,
            a_bp: z,
            w: T::lit(2.0),
            k_q: z,
            i_f: z,
        }
    }
}

/// The largest exponent [`pow_abs`] takes by multiplication.
const POW_BY_MULTIPLICATION: f64 = 8.0;

/// |x|^e with |0|^0 = 1: repeated multiplication for the small integer exponents published
/// fits use (exact, and several times faster than libm's powf), powf otherwise. The
/// exponent is matched by counting in the scalar itself (a compare per factor), not by an
/// integer conversion: the per-solve setup of a conversion per exponent cost more than the
/// multiplications on the algebraic model's Newton solves.
#[inline(always)]
fn pow_abs<T: Real>(x: T, e: T) -> T {
    if e == T::zero() {
        return T::one();
    }
    // By multiplication: the generic `powi` of a no_std build is libm's `pow`.
    let a = x.abs();
    let (mut p, mut k) = (a, T::one());
    while k < e && k < T::lit(POW_BY_MULTIPLICATION) {
        p *= a;
        k += T::one();
    }
    if k == e { p } else { a.powf(e) }
}

impl<T: Real> Saturation<T> {
    /// The magnetically linear machine (Ld, Lq, λf) in this form.
    pub fn linear(ld: T, lq: T, flux_linkage: T) -> Self {
        Self {
            a_d0: T::one() / ld,
            a_q0: T::one() / lq,
            psi_f: flux_linkage,
            ..Self::default()
        }
    }

    /// Checks every coefficient; the error names the first bad one. The unsaturated inverse
    /// inductances must be positive and every other coefficient and exponent non-negative, so
    /// that i(ψ) is monotonic (the energy convex); the rib's exponent must be at least 2 (its
    /// Jacobian is then finite at ρ = 0) or 0 (a constant rib conductance, as motulator's
    /// `SaturationModelPMSyRM` takes it: scripts/motulator-machines.py's SPMSM).
    pub fn validate(&self) -> Result<(), ConfigError> {
        check::positive("a_d0", self.a_d0)?;
        check::non_negative("a_dd", self.a_dd)?;
        check::non_negative("s", self.s)?;
        check::positive("a_q0", self.a_q0)?;
        check::non_negative("a_qq", self.a_qq)?;
        check::non_negative("t", self.t)?;
        check::non_negative("a_dq", self.a_dq)?;
        check::non_negative("u", self.u)?;
        check::non_negative("v", self.v)?;
        check::finite("psi_f", self.psi_f)?;
        check::finite("psi_n", self.psi_n)?;
        check::non_negative("a_b", self.a_b)?;
        check::non_negative("a_bp", self.a_bp)?;
        let w = check::finite("w", self.w)?;
        if w < T::lit(2.0) && w != T::zero() {
            return Err(ConfigError::OutOfRange {
                field: "w",
                expected: "0 or at least 2",
            });
        }
        check::non_negative("k_q", self.k_q)?;
        check::finite("i_f", self.i_f)?;
        Ok(())
    }

    /// The same model in another precision.
    pub fn cast<U: Real>(&self) -> Saturation<U> {
        let c = |x: T| U::lit(x.to_f64());
        Saturation {
            a_d0: c(self.a_d0),
            a_dd: c(self.a_dd),
            s: c(self.s),
            a_q0: c(self.a_q0),
            a_qq: c(self.a_qq),
            t: c(self.t),
            a_dq: c(self.a_dq),
            u: c(self.u),
            v: c(self.v),
            psi_f: c(self.psi_f),
            psi_n: c(self.psi_n),
            a_b: c(self.a_b),
            a_bp: c(self.a_bp),
            w: c(self.w),
            k_q: c(self.k_q),
            i_f: c(self.i_f),
        }
    }

    /// The current i(ψ) and its Jacobian ∂i/∂ψ (the incremental inverse inductance, symmetric).
    pub fn current_and_jacobian(&self, psi: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        self.evaluate::<true>(psi)
    }

    /// i(ψ) and, with `JACOBIAN`, ∂i/∂ψ (else a zero matrix): one body, so that the current
    /// alone (a plant's four evaluations per sub-step) skips the Jacobian's arithmetic and the
    /// rib's second power while giving the same current bit for bit.
    #[inline(always)]
    fn evaluate<const JACOBIAN: bool>(&self, psi: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        let x = psi.d - self.psi_f;
        let y = psi.q;
        let (two, one) = (T::lit(2.0), T::one());
        let xs = pow_abs(x, self.s);
        let yt = pow_abs(y, self.t);
        let xu = pow_abs(x, self.u);
        let yv = pow_abs(y, self.v);
        let (x2, y2) = (x * x, y * y);
        let cu = self.a_dq / (self.u + two);
        // One division where U = V (the published fits), the same value.
        let cv = if self.v == self.u {
            cu
        } else {
            self.a_dq / (self.v + two)
        };
        // G_d·x and G_q·y; |x|^(U+2) = |x|^U·x², |y|^(V+2) = |y|^V·y².
        let g_d = self.a_d0 + self.a_dd * xs + cv * xu * yv * y2;
        let g_q = self.a_q0 + self.a_qq * yt + cu * xu * x2 * yv;
        let mut i = Dq::new(g_d * x - self.i_f, g_q * y);
        let mut jac = InductanceMatrix::default();
        if JACOBIAN {
            let cross = self.a_dq * xu * x * yv * y;
            jac = InductanceMatrix {
                dd: self.a_d0
                    + self.a_dd * (self.s + one) * xs
                    + cv * (self.u + one) * xu * yv * y2,
                dq: cross,
                qd: cross,
                qq: self.a_q0
                    + self.a_qq * (self.t + one) * yt
                    + cu * (self.v + one) * xu * x2 * yv,
            };
        }
        if self.a_b > T::zero() {
            let b = psi.d - self.psi_n;
            let kq = self.k_q;
            let rho2 = b * b + kq * y2;
            let rho = rho2.sqrt();
            let rw = pow_abs(rho, self.w);
            let den = one + self.a_bp * rw;
            let g_b = self.a_b * rw / den;
            i.d += g_b * b;
            i.q += kq * g_b * y;
            if JACOBIAN {
                // (dG_b/dρ)/ρ = a_b·W·ρ^(W−2)/den², finite at ρ = 0 for W ≥ 2, zero for a
                // constant G_b (W = 0).
                let h = if self.w == T::zero() {
                    T::zero()
                } else {
                    self.a_b * self.w * pow_abs(rho, self.w - two) / (den * den)
                };
                let c = h * kq * b * y;
                jac.dd += g_b + h * b * b;
                jac.dq += c;
                jac.qd += c;
                jac.qq += kq * g_b + h * kq * kq * y2;
            }
        }
        (i, jac)
    }

    /// ψ(i) by Newton's method on i(ψ) from a caller's `start` (with ∂i/∂ψ at the last
    /// iterate but one), and [`Saturation::flux_solved`]
    /// where that solve does not converge: on a stiff model (a high power of ψ) Newton's
    /// steps from far on the steep side shrink the error by a fixed fraction each and may
    /// not reach the tolerance within [`super::NEWTON_ITERATIONS`].
    #[inline]
    fn flux_newton_from(&self, i: Dq<T>, start: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        let f = |psi| self.current_and_jacobian(psi);
        let (psi, jac, converged) = newton_checked(i, start, self.newton_scale(), f);
        if converged {
            (psi, jac)
        } else {
            self.flux_solved(i)
        }
    }

    /// Newton from the linear guess, and where that does not converge the damped solve
    /// [`Saturation::flux_damped`]. A strong cross term overshoots from the linear guess:
    /// on a 30 mH / 12 mH IPMSM whose q saturation is all cross term (a_dq 4000, U 0, V 1;
    /// `ipm-cross20` of scripts/saturated-replay.py), the plain iteration from
    /// i = (−0.84, 11.97) A ends at a flux whose current is (21.8, −24.4) A.
    fn flux_solved(&self, i: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        let f = |psi| self.current_and_jacobian(psi);
        let (psi, jac, converged) = newton_checked(i, self.linear_flux(i), self.newton_scale(), f);
        if converged {
            (psi, jac)
        } else {
            self.flux_damped(i)
        }
    }

    /// Newton with step halving from the linear guess: a step that does not lower the
    /// current's error |i(ψ) − i| is halved until it does (at most [`DAMPING_HALVINGS`]
    /// times). i(ψ) is the gradient of the magnetic energy W (type docs), convex for a
    /// monotonic model, so the damped iteration converges from any start; it stops on
    /// Newton's step test or after [`DAMPED_ITERATIONS`] steps.
    fn flux_damped(&self, i: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        let tol = T::default_epsilon().sqrt() * T::lit(1.0 / 16.0);
        let mut psi = self.linear_flux(i);
        let (mut y, mut jac) = self.current_and_jacobian(psi);
        for _ in 0..DAMPED_ITERATIONS {
            let error = (y - i).norm();
            let full = jac.solve(y - i);
            if !full.is_finite() {
                break;
            }
            let mut t = T::one();
            for _ in 0..DAMPING_HALVINGS {
                let (yt, _) = self.current_and_jacobian(psi - Dq::new(full.d * t, full.q * t));
                if (yt - i).norm() < error {
                    break;
                }
                t *= T::lit(0.5);
            }
            let step = Dq::new(full.d * t, full.q * t);
            psi -= step;
            (y, jac) = self.current_and_jacobian(psi);
            if step.norm() <= tol * (psi.norm() + self.newton_scale()) {
                break;
            }
        }
        (psi, jac)
    }

    /// The flux added to |ψ| in Newton's stopping test (the magnet's and the rib's, so that
    /// the test stays relative near ψ = 0), Wb.
    #[inline]
    pub(super) fn newton_scale(&self) -> T {
        self.psi_f.abs() + self.psi_n.abs() + (self.i_f / self.a_d0).abs() + T::lit(1e-6)
    }

    /// The magnetically linear guess ψ(i) ≈ (ψf + (i_d + i_f)/a_d0, i_q/a_q0).
    pub(super) fn linear_flux(&self, i: Dq<T>) -> Dq<T> {
        Dq::new(self.psi_f + (i.d + self.i_f) / self.a_d0, i.q / self.a_q0)
    }
}

impl<T: Real> MagneticModel<T> for Saturation<T> {
    /// Newton from the magnetically linear guess.
    fn flux(&self, i: Dq<T>) -> Dq<T> {
        self.flux_solved(i).0
    }

    /// Newton from `guess` (from the linear guess if `guess` is not finite, or where the solve
    /// from `guess` does not converge).
    #[inline]
    fn flux_from(&self, i: Dq<T>, guess: Dq<T>) -> Dq<T> {
        self.flux_and_inductance_from(i, guess).0
    }

    #[inline]
    fn flux_and_inductance_from(&self, i: Dq<T>, guess: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        let start = if guess.is_finite() {
            guess
        } else {
            self.linear_flux(i)
        };
        let (psi, jac) = self.flux_newton_from(i, start);
        (psi, jac.inverse())
    }

    fn current(&self, psi: Dq<T>) -> Dq<T> {
        self.evaluate::<false>(psi).0
    }

    /// Zero: i_q is odd in ψq and i_d even, so ψq(i_d, 0) = 0.
    #[inline]
    fn q_flux_offset(&self, _i_d: T) -> T {
        T::zero()
    }

    fn incremental_inductance(&self, i: Dq<T>) -> InductanceMatrix<T> {
        self.current_and_jacobian(self.flux(i)).1.inverse()
    }

    fn flux_and_inductance(&self, i: Dq<T>) -> (Dq<T>, InductanceMatrix<T>) {
        let psi = self.flux(i);
        (psi, self.current_and_jacobian(psi).1.inverse())
    }
}
