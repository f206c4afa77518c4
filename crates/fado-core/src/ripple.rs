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
//! algebraic model's explicit i(ψ) and one at ψ.
//!
//! **The resistive drop within the period.** The flux obeys ψ' = v − R·i(ψ), not ψ' = v − R·ī:
//! the ripple current's own drop bends the ripple. To first order in R·Γ·Ts (Γ = ∂i/∂ψ, the
//! inverse incremental inductance) the periodic solution adds to the mean minus the mean of
//! the two samples R·Ts·Γ·Γ·F, F = ∫₀¹(τ − ½)·Δψ_f(τ) dτ over the falling half, again a
//! polynomial in the duties (∫₀¹(τ − ½)·g_k dτ = A_k − d_k/3 + d_k·(1 − d_k)/4). It is a
//! first-order term, present with a constant inductance too, and it grows with Γ²: on the
//! saturated 127 W drawn IPMSM at its rated standstill (i_q = 1.796 A, Γ_qq ≈ 1170 A/Wb,
//! R·Γ·Ts ≈ 0.10) it is 0.76 mA, as large as the curvature's 0.68 mA; the switching-resolved
//! plant's mean minus sample there is 1.43 mA with an ideal inverter (fado-sim's switching
//! inverter with its mean current integrated, rotor locked, fixed duties), and 1.42 mA by brute
//! force on ψ' = v − R·i(ψ); without the drop's ripple 0.68 mA.
//!
//! **The dead time.** Each pole's pulse is delayed by half the dead time against its gate
//! pulse: an edge whose current opposes it waits Td, the other commutates at once, so the
//! rising edge of a positive current and the falling edge of a negative one wait, and both
//! centres move by Td/2 (out of the band; the drive's compensation widens the gate pulse
//! symmetrically, which does not move its centre). The whole ripple then lags the carrier by
//! Td/2 and the samples at its peak and valley read the flux Td/2 ahead of the pattern's own
//! symmetric points: on average over the two the samples lead the period's mean flux by
//! Σ_k e_k·(Td/2)·(d_k − ½)·Vdc = (Td/2)·v_αβ, and the mean current lies Γ·(Td/2)·v_αβ below
//! the samples. On the 127 W machine (Td 0.32 µs, 39 kHz) that is −2.3 mA against the plant's
//! −2.4 mA (its mean minus sample at the loaded start's hold: −0.89 mA with the dead time,
//! +1.52 mA with none); on the 69 W one (Td 2.1 µs, 6 kHz) −11.8 mA against −10 to −11.5 mA.
//! Within the current band the delays differ per phase (up to Td on both edges at zero
//! current); the lead keeps Td/2 there.
//!
//! The estimator computes none of this for a constant inductance or a flux map; for the
//! algebraic model it does every [`RIPPLE_EVERY`] samples (module `crate::estimator`).

use crate::control::modulation::svpwm_duty;
use crate::magnetics::{InductanceMatrix, MagneticModel, Saturation};
use crate::{Ab, Abc, Dq, Real, Rotation};

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

    /// The moment of α-β ripple in the frame rotated by `rot` (angle θ):
    /// Δψ_dq = R(−θ)·Δψ_αβ, so C_dq = R(−θ)·C·R(θ).
    pub fn rotated(&self, rot: Rotation<T>) -> Self {
        let (cos, sin) = (rot.cos, rot.sin);
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

/// How often (in samples) the estimator refreshes the ripple's terms: the moment on one
/// sample, the mean-current offset two samples later, each on one sample in this many.
pub const RIPPLE_EVERY: u8 = 4;

/// The PWM period's terms between the sampled and the mean current (module docs), α-β.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PwmRipple<T> {
    /// The flux ripple's second moment about the sample, Wb².
    pub moment: RippleMoment<T>,
    /// F = ∫₀¹(τ − ½)·Δψ_f(τ) dτ over the falling half, Wb: the resistive drop's share.
    pub damping: Ab<T>,
    /// The flux by which the samples lead the period's mean flux through the poles' dead-time
    /// delay, (Td/2)·v_αβ, Wb.
    pub lead: Ab<T>,
}

impl<T: Real> PwmRipple<T> {
    /// No ripple.
    pub fn zero() -> Self {
        Self {
            moment: RippleMoment::zero(),
            damping: Ab::zero(),
            lead: Ab::zero(),
        }
    }

    /// The terms for the α-β voltage `v_ab` realised by min-max SVPWM ([`svpwm_duty`]) on the
    /// dc link `vdc` over the sampling period `ts` (one carrier half), with the inverter's dead
    /// time `dead_time` (s).
    pub fn from_voltage(v_ab: Ab<T>, vdc: T, ts: T, dead_time: T) -> Self {
        let duty = svpwm_duty(v_ab, vdc);
        let (moment, first) = ripple_moments(duty, vdc, ts);
        Self {
            moment,
            damping: first,
            lead: v_ab * (dead_time * T::lit(0.5)),
        }
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
    ripple_moments(duty, vdc, ts).0
}

/// [`flux_ripple_moment`] and [`PwmRipple::damping`] from the same A_k.
#[inline(always)]
fn ripple_moments<T: Real>(duty: Abc<T>, vdc: T, ts: T) -> (RippleMoment<T>, Ab<T>) {
    let (a_a, a_b, a_c) = (moment_a(duty.a), moment_a(duty.b), moment_a(duty.c));
    // ∫₀¹(τ − ½)·g_k dτ = A_k − d_k/3 + d_k·(1 − d_k)/4.
    let first = |a: T, d: T| a - d * T::lit(1.0 / 3.0) + d * (T::one() - d) * T::lit(0.25);
    let scale = vdc * ts;
    let damping =
        Abc::new(first(a_a, duty.a), first(a_b, duty.b), first(a_c, duty.c)).to_ab() * scale;
    let g_aa = moment_g(duty.a, duty.a, a_a, a_a);
    let g_bb = moment_g(duty.b, duty.b, a_b, a_b);
    let g_cc = moment_g(duty.c, duty.c, a_c, a_c);
    let g_ab = moment_g(duty.a, duty.b, a_a, a_b);
    let g_ac = moment_g(duty.a, duty.c, a_a, a_c);
    let g_bc = moment_g(duty.b, duty.c, a_b, a_c);
    let s2 = scale * scale;
    let two = T::lit(2.0);
    let four = T::lit(4.0);
    // e_α = (2, −1, −1)/3, e_β = (0, 1, −1)/√3.
    let xx = (four * (g_aa - g_ab - g_ac) + g_bb + g_cc + two * g_bc) * T::lit(1.0 / 9.0);
    let xy = (two * (g_ab - g_ac) - g_bb + g_cc) * T::lit(1.0 / (3.0 * 1.732_050_807_568_877_2));
    let yy = (g_bb + g_cc - two * g_bc) * T::lit(1.0 / 3.0);
    let moment = RippleMoment {
        xx: xx * s2,
        xy: xy * s2,
        yy: yy * s2,
    };
    (moment, damping)
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

/// The period's mean current minus its sampled current in α-β for a sample whose rotor
/// frame is rotated by `rot`, on the algebraic model at the flux `psi` with the incremental
/// inductance `l` there (module docs): the curvature's [`mean_current_offset`] plus
/// Γ·(`rs_ts`·Γ·F − lead), Γ = `l`⁻¹, `rs_ts` = R·Ts (Ω·s).
pub fn mean_current_offset_ab<T: Real>(
    model: &Saturation<T>,
    psi: Dq<T>,
    l: &InductanceMatrix<T>,
    ripple: &PwmRipple<T>,
    rs_ts: T,
    rot: Rotation<T>,
) -> Ab<T> {
    let curvature = mean_current_offset(model, psi, &ripple.moment.rotated(rot));
    let gamma = l.inverse();
    let flux = gamma.apply(ripple.damping.to_dq(rot)) * rs_ts - ripple.lead.to_dq(rot);
    (curvature + gamma.apply(flux)).to_ab(rot)
}

#[cfg(test)]
mod tests;
