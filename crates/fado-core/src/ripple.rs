//! The PWM ripple's bias of the sampled current on a saturating machine.
//!
//! **Why.** A centre-aligned PWM drive samples the phase currents at the carrier's peak and
//! valley, where the ripple of a constant-inductance machine crosses its mean: the sample is
//! the sampling period's mean current, and the estimator's resistive drop R̂s·i is exact. On a
//! curved i(ψ) the mean of i(ψ(t)) over the period differs from i at the sample by
//! δi ≈ ½·tr(∂²i/∂ψ² · C), where C is the second moment of the flux ripple Δψ(t) about the
//! sample (the first-order term J·E\[Δψ\] alternates in sign between the falling and the rising
//! half period and cancels over a carrier period). On the 69 W drawn IPMSM
//! (motors/ipm-sat-15p-47v-69w, 6 kHz, 47 V) at i_dq = (0, 3.685) A the brute-force mean over
//! the switching sequence exceeds the sample by (0.12, 9.9) mA, R·δi_q ≈ 8.8 mV: the back-EMF
//! of about 1.7 rad/s, which the zero-speed flux integration reads as rotor motion
//! (crates/fado-sim/tests/drawn_machines.rs, `saturated_rotors_hold_the_rated_load_at_standstill`).
//!
//! **Covariance, closed form.** One sampling period Ts is one carrier half. On the falling
//! half (from the peak) pole k is high for τ = t/Ts > x_k = 1 − d_k; its share of the flux
//! deviation is Vdc·Ts·g_k(τ) with g_k(τ) = (τ − x_k)₊ − d_k·τ, and
//! Δψ_αβ(τ) = Vdc·Ts·Σ_k e_k·g_k(τ) with the Clarke vectors e_a = (2/3, 0),
//! e_b = (−1/3, 1/√3), e_c = (−1/3, −1/√3) (the common mode cancels). The moments
//! G_jk = ∫₀¹ g_j·g_k dτ are polynomials in the duties:
//! G_jk = d_j·d_k/3 − d_j·A_k − d_k·A_j + B_jk, with A_k = d_k³/3 + x_k·d_k²/2 and
//! B_jk = m³/3 + |d_j − d_k|·m²/2, m = min(d_j, d_k). The rising half is the falling one
//! reversed in time, Δψ_r(τ) = −Δψ_f(1 − τ): the same second moment. No sorting of the duties
//! and no branch; about 90 flops.
//!
//! **δi from the model.** With any square root S·Sᵀ = C (here Cholesky, two square roots),
//! the sigma points ψ ± s_k give ½·Σ_k \[i(ψ + s_k) + i(ψ − s_k) − 2·i(ψ)\] = ½·tr(H·C) exactly
//! for a quadratic i(ψ) and to fourth order in the ripple otherwise: four evaluations of the
//! algebraic model's explicit i(ψ) and one at ψ. A constant inductance has H = 0, and the
//! estimator does not compute any of this for it.

use crate::control::modulation::svpwm_duty;
use crate::magnetics::{MagneticModel, Saturation};
use crate::{Ab, Abc, Dq, Real};

/// A symmetric 2×2 second moment of the flux ripple (Wb²), in whichever frame its caller
/// names (α-β from [`flux_ripple_moment`], d-q after [`RippleMoment::rotated`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RippleMoment<T> {
    /// First axis squared (α or d).
    pub xx: T,
    /// The cross moment.
    pub xy: T,
    /// Second axis squared (β or q).
    pub yy: T,
}

impl<T: Real> RippleMoment<T> {
    /// The zero moment (no ripple).
    pub fn zero() -> Self {
        Self {
            xx: T::zero(),
            xy: T::zero(),
            yy: T::zero(),
        }
    }

    /// The moment of α-β ripple in the frame at angle θ, given as (cos θ, sin θ):
    /// Δψ_dq = R(−θ)·Δψ_αβ, so C_dq = R(−θ)·C·R(θ).
    pub fn rotated(&self, cos: T, sin: T) -> Self {
        let (c2, s2, cs) = (cos * cos, sin * sin, cos * sin);
        let two_cs_xy = T::lit(2.0) * cs * self.xy;
        Self {
            xx: c2 * self.xx + two_cs_xy + s2 * self.yy,
            xy: cs * (self.yy - self.xx) + (c2 - s2) * self.xy,
            yy: s2 * self.xx - two_cs_xy + c2 * self.yy,
        }
    }

    /// A lower-triangular square root L (L·Lᵀ = C) as its two columns; zero columns where
    /// C is zero or not positive semi-definite by rounding.
    fn cholesky_columns(&self) -> (Dq<T>, Dq<T>) {
        let z = T::zero();
        let l11 = self.xx.step_max(z).step_sqrt();
        let l21 = if l11 > z { self.xy / l11 } else { z };
        let l22 = (self.yy - l21 * l21).step_max(z).step_sqrt();
        (Dq::new(l11, l21), Dq::new(z, l22))
    }
}

/// ∫₀¹ τ·(τ − x_k)₊ dτ for the pole with duty `d` (x_k = 1 − d).
#[inline(always)]
fn moment_a<T: Real>(d: T) -> T {
    let x = T::one() - d;
    d * d * (d * T::lit(1.0 / 3.0) + x * T::lit(0.5))
}

/// G_jk = ∫₀¹ g_j·g_k dτ (module docs), given A_j and A_k.
#[inline(always)]
fn moment_g<T: Real>(dj: T, dk: T, aj: T, ak: T) -> T {
    let m = dj.step_min(dk);
    let b = m * m * (m * T::lit(1.0 / 3.0) + (dj - dk).abs() * T::lit(0.5));
    dj * dk * T::lit(1.0 / 3.0) - dj * ak - dk * aj + b
}

/// The second moment about the sample of the α-β flux ripple over one sampling period of
/// centre-aligned PWM sampled at the carrier's peak and valley (module docs): `duty` the
/// three phases' duties in \[0, 1\], `vdc` the dc link (V), `ts` the sampling period, one
/// carrier half (s).
pub fn flux_ripple_moment<T: Real>(duty: Abc<T>, vdc: T, ts: T) -> RippleMoment<T> {
    let (a_a, a_b, a_c) = (moment_a(duty.a), moment_a(duty.b), moment_a(duty.c));
    let g_aa = moment_g(duty.a, duty.a, a_a, a_a);
    let g_bb = moment_g(duty.b, duty.b, a_b, a_b);
    let g_cc = moment_g(duty.c, duty.c, a_c, a_c);
    let g_ab = moment_g(duty.a, duty.b, a_a, a_b);
    let g_ac = moment_g(duty.a, duty.c, a_a, a_c);
    let g_bc = moment_g(duty.b, duty.c, a_b, a_c);
    let scale = vdc * ts;
    let s2 = scale * scale;
    let two = T::lit(2.0);
    let four = T::lit(4.0);
    // e_α = (2, −1, −1)/3, e_β = (0, 1, −1)/√3.
    let xx = (four * (g_aa - g_ab - g_ac) + g_bb + g_cc + two * g_bc) * T::lit(1.0 / 9.0);
    let xy = (two * (g_ab - g_ac) - g_bb + g_cc) * T::lit(1.0 / (3.0 * 1.732_050_807_568_877_2));
    let yy = (g_bb + g_cc - two * g_bc) * T::lit(1.0 / 3.0);
    RippleMoment {
        xx: xx * s2,
        xy: xy * s2,
        yy: yy * s2,
    }
}

/// [`flux_ripple_moment`] for the α-β voltage `v_ab` realised by min-max SVPWM
/// ([`svpwm_duty`], the drive's modulator) on the dc link `vdc`.
pub fn svpwm_ripple_moment<T: Real>(v_ab: Ab<T>, vdc: T, ts: T) -> RippleMoment<T> {
    flux_ripple_moment(svpwm_duty(v_ab, vdc), vdc, ts)
}

/// The period's mean current minus the current at the sample, δi = E\[i(ψ + Δψ)\] − i(ψ), for
/// the algebraic model at the flux `psi` with the d-q ripple moment `moment` (sigma points,
/// module docs): four evaluations of i(ψ) and one at `psi`.
pub fn mean_current_offset<T: Real>(
    model: &Saturation<T>,
    psi: Dq<T>,
    moment: &RippleMoment<T>,
) -> Dq<T> {
    let (s1, s2) = moment.cholesky_columns();
    let i0 = model.current(psi);
    let sum = model.current(psi + s1)
        + model.current(psi - s1)
        + model.current(psi + s2)
        + model.current(psi - s2);
    (sum - i0 * T::lit(4.0)) * T::lit(0.5)
}

/// The α-β offset of [`mean_current_offset`] for a sample whose rotor frame is at
/// (cos θ, sin θ): the α-β moment rotated into d-q, δi_dq, and δi rotated back.
pub fn mean_current_offset_ab<T: Real>(
    model: &Saturation<T>,
    psi: Dq<T>,
    moment_ab: &RippleMoment<T>,
    cos: T,
    sin: T,
) -> Ab<T> {
    let di = mean_current_offset(model, psi, &moment_ab.rotated(cos, sin));
    Ab::new(cos * di.d - sin * di.q, sin * di.d + cos * di.q)
}

#[cfg(test)]
mod tests;
