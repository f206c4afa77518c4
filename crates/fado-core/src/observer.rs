//! The frequency-adaptive disturbance observer: paper eq. (7)-(10) with the gains (16), Fig. 2.
//!
//! # Model and gains
//! The initially estimated stator flux is a vector rotating at ω_f plus a slowly varying
//! disturbance, λ1 = λm·e^{jθf} + D (eq. (7)). In complex form (docs/method/estimator.md §2, with z = λ̂1,
//! d = D̂, y = λ1, e = y − z) the observer (10) with the gains (16)
//! (p1 = p4 = 2|ω|, p2 = −p3 = −ω, q1 = q4 = 0, q2 = −q3 = −ω) reads
//!
//! ```text
//! dz/dt = jω(z − d) + (2|ω| + jω)·e,    dd/dt = jω·e
//! ```
//!
//! whose characteristic polynomial is (s + |ω|)⁴ for either sign of ω, with
//! d/y = ω(ω + js)/(s + |ω|)²: unity at DC, a notch at s = jω (eq. (17)-(19)).
//!
//! # Discretisation (why this one)
//! Forward Euler leaks 1.6 % of the rotating flux through the notch at 100 Hz and goes
//! unstable for |ω|·Ts > 2; Tustin and ZOH move the notch off ω. We instead discretise the
//! *internal model* exactly — between samples z − d rotates by a = e^{jωTs} — and place the
//! observer's double complex pole at r = e^{−|ω|Ts}, the exact image of −|ω|:
//!
//! ```text
//! z⁺ = a·z + (1 − a)·d + ℓ1·e,   ℓ1 = 1 + a − 2r
//! d⁺ = d + ℓ2·e,                 ℓ2 = (1 − r)² / (1 − a)
//! ```
//!
//! so the four real poles sit at r for every ω (tested up to |ω|·Ts = 3), the map is
//! symmetric in the sign of ω, the notch is exactly at e^{jωTs}, and all gains vanish at
//! ω = 0 so the observer freezes at standstill (paper, Fig. 2 discussion). `f64` evaluates the
//! gains through the half angle, 1 − a = −2j·sin(x/2)·e^{jx/2} with x = ωTs; `f32` from short
//! polynomials in x itself (`f32_gains`: 1 − cos x, sin x, 1 − r and x·cot(x/2)/2 as x², x, |x|
//! and 1 times a polynomial), which keeps them accurate at the smallest speeds
//! (ℓ2 → jωTs as ωTs → 0).

use crate::error::{ConfigError, NonFiniteInput, check};
use crate::{Ab, Real};

/// Configuration of a [`DisturbanceObserver`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisturbanceObserverConfig<T> {
    /// Sampling period Ts in s (paper, section V: 100 µs, 10 kHz sampling). No default: the
    /// set-up's.
    pub ts: T,
}

/// The discrete observer gains for one value of ω·Ts (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscreteGains<T> {
    /// a = e^{jωTs}: rotation of the internal model over one sample.
    pub a: Ab<T>,
    /// 1 − a, computed through the half angle.
    pub one_minus_a: Ab<T>,
    /// ℓ1 = 1 + a − 2r.
    pub l1: Ab<T>,
    /// ℓ2 = (1 − r)² / (1 − a).
    pub l2: Ab<T>,
    /// r = e^{−|ω|Ts}: the (quadruple) observer pole.
    pub r: T,
}

impl<T: Real> DiscreteGains<T> {
    /// Gains for the flux speed `omega` (rad/s, signed) and sampling period `ts`.
    #[inline(always)]
    pub fn new(omega: T, ts: T) -> Self {
        let x = omega * ts;
        // `f32` in its series range: the short minimax polynomials of `f32_gains` (the test
        // folds to a constant per type; `f64` never takes this branch).
        if single_precision::<T>() && x.abs() <= T::lit(SERIES_LIMIT_F32) {
            return f32_gains(x);
        }
        let half = T::lit(0.5);
        let two = T::lit(2.0);
        let (sh, ch, one_minus_r) = half_angle_terms(x);
        let a = Ab::new(ch * ch - sh * sh, two * sh * ch);
        let one_minus_a = Ab::new(two * sh * sh, -two * sh * ch);
        let l1 = Ab::new(two * one_minus_r - one_minus_a.alpha, -one_minus_a.beta);
        // (1 − r)²/(1 − a) = (1 − r)²·(sh + j·ch)/(2·sh); exactly zero at ω = 0.
        let m = one_minus_r * one_minus_r * half;
        let l2 = if sh == T::zero() {
            Ab::zero()
        } else {
            Ab::new(m, m * ch / sh)
        };
        Self {
            a,
            one_minus_a,
            l1,
            l2,
            r: T::one() - one_minus_r,
        }
    }
}

/// Whether `T` is `f32` (1 + 1e-12 rounds to 1): a constant per type, folded by the compiler,
/// that selects the `f32` polynomials of [`f32_gains`] or the `f64` series.
#[inline(always)]
fn single_precision<T: Real>() -> bool {
    T::one() + T::lit(1e-12) == T::one()
}

/// Largest |ω·Ts| (rad) served by the `f64` series in [`half_angle_terms`]: 398 Hz at 10 kHz,
/// far above the motor's 100 Hz; beyond it the gains come from `libm`.
const SERIES_LIMIT: f64 = 0.25;

/// Largest |ω·Ts| (rad) served by the `f32` polynomials of [`f32_gains`]: 796 Hz at 10 kHz,
/// which covers the 700 Hz of docs/results/firmware-cost.md; beyond it the gains come from
/// [`crate::approx`].
const SERIES_LIMIT_F32: f64 = 0.5;

/// Taylor coefficients of sin(h)/h in h² (1, −1/3!, 1/5!, ...).
const SIN_OVER_H: [f64; 6] = [
    1.0,
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
];
/// Taylor coefficients of cos(h) in h² (1, −1/2!, 1/4!, ...).
const COS: [f64; 7] = [
    1.0,
    -0.5,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
];
/// Taylor coefficients of (1 − e^{−y})/y in y (1, −1/2!, 1/3!, ...).
const ONE_MINUS_EXP_OVER_Y: [f64; 13] = [
    1.0,
    -0.5,
    1.0 / 6.0,
    -1.0 / 24.0,
    1.0 / 120.0,
    -1.0 / 720.0,
    1.0 / 5040.0,
    -1.0 / 40_320.0,
    1.0 / 362_880.0,
    -1.0 / 3_628_800.0,
    1.0 / 39_916_800.0,
    -1.0 / 479_001_600.0,
    1.0 / 6_227_020_800.0,
];

/// sin(x)/x ≈ S(x²) on |x| ≤ 0.5 (`f32`): minimax for the relative error (Lawson-weighted
/// least squares, coefficients rounded to `f32` one at a time and the rest refitted,
/// `scripts/fit_approx.py`), its leading coefficient held at the Taylor value 1 (exact as
/// x → 0, and an FPU immediate instead of a literal-pool load); 1.2e-7 fitted, 1.6e-7
/// evaluated in `f32`.
const F32_SIN_OVER_X: [f32; 3] = [1.0, -0.166_661_3, 0.008_264_322];
/// (1 − cos x)/x² ≈ C(x²) on |x| ≤ 0.5 (`f32`, as [`F32_SIN_OVER_X`]): 3.0e-8 fitted,
/// 6.2e-8 evaluated.
const F32_ONE_MINUS_COS_OVER_X2: [f32; 3] = [0.5, -0.041_665_997, 0.001_380_260_1];
/// (1 − e^{−y})/y ≈ E(y) on 0 ≤ y ≤ 0.5 (`f32`, as [`F32_SIN_OVER_X`]): 8.8e-8 fitted, 1.5e-7
/// evaluated.
const F32_ONE_MINUS_EXP_OVER_Y: [f32; 5] = [
    1.0,
    -0.499_994_64,
    0.166_563_66,
    -0.041_042_678,
    0.006_807_800_4,
];
/// (x/2)·cot(x/2) ≈ K(x²) on |x| ≤ 0.5 (`f32`, as [`F32_SIN_OVER_X`]): 2.1e-8 fitted, 5.2e-8
/// evaluated.
const F32_HALF_X_COT_HALF_X: [f32; 3] = [1.0, -0.083_332_43, -0.001_400_523_4];

/// The gains for `f32` in |x| ≤ 0.5 (x = ω·Ts), from four short polynomials and no division:
///
/// ```text
/// a  = (1 − x²·C, x·S)            ℓ1 = (2u − x²·C, x·S)          u = 1 − r = y·E,  y = |x|
/// ℓ2 = u²·(1 + j·cot(x/2))/2 = (x²·E²/2, x·E²·K)
/// ```
///
/// (u² = x²·E², and u²·cot(x/2)/2 = x²·E²·(2K/x)/2 = x·E²·K.) Each gain is exactly 0 at
/// x = 0, so the observer still freezes at standstill. Why these errors are harmless, with
/// the criteria tested in `f32_gains_keep_the_poles_and_the_notch`:
/// - the notch sits where a = e^{jωTs}: S and C put a within 8.1e-8 of e^{jx} (arg a − x,
///   i.e. a notch displaced by |Δω|·Ts ≤ 7.9e-8 rad per sample, and ||a| − 1| ≤ 5.6e-8), the
///   size of `f32`'s own rounding of a (half an ulp of 1 is 6e-8; the half-angle Taylor
///   products gave 7.2e-8 and 1.7e-7);
/// - an error of E is a different u, and every gain is built from that same u: the poles stay a
///   quadruple at r' = 1 − u' within 1.5e-7·u of r, a pole at −|ω|·(1 ± 1.5e-7);
/// - errors of S, C, K that do not match each other split the double poles by about the square
///   root of the mismatch (a 2×2 Jordan block); so does `f32`'s rounding of each gain, by
///   √(6e-8/|x|) relative. The poles stay within 1.3e-2·(1 − r) of r (1.9e-3·(1 − r) above
///   |x| = 0.01, 16 Hz at 10 kHz), where the previous Taylor gains, accurate to rounding, put
///   them within 1.6e-2·(1 − r) (2.8e-3).
///
/// Measured against the closed forms: |a − e^{jx}| ≤ 8.1e-8, ℓ1 and ℓ2 within 2.1e-7 and
/// 4.0e-7 relative, |r − e^{−|x|}| ≤ 8.7e-8 (Taylor: 1.7e-7, 1.7e-7, 3.1e-7, 7.3e-8).
///
/// The previous Taylor polynomials in the half angle h (sin h/h and cos h to degree 6 in h,
/// (1 − e^{−y})/y to degree 7 in y, h·cot h to h⁶) were accurate to `f32` rounding and cost 20
/// coefficients and the half-angle products; these cost 14, four of them FPU immediates.
#[inline(always)]
fn f32_gains<T: Real>(x: T) -> DiscreteGains<T> {
    let lit = |c: f32| T::lit(c as f64);
    let y = x.abs();
    let t = x * x;
    let (s, c, e, k) = (
        &F32_SIN_OVER_X,
        &F32_ONE_MINUS_COS_OVER_X2,
        &F32_ONE_MINUS_EXP_OVER_Y,
        &F32_HALF_X_COT_HALF_X,
    );
    let sin = x * (lit(s[0]) + t * (lit(s[1]) + t * lit(s[2])));
    let one_minus_cos = t * (lit(c[0]) + t * (lit(c[1]) + t * lit(c[2])));
    let e = lit(e[0]) + y * (lit(e[1]) + y * (lit(e[2]) + y * (lit(e[3]) + y * lit(e[4]))));
    let k = lit(k[0]) + t * (lit(k[1]) + t * lit(k[2]));
    let one_minus_r = y * e;
    let e2 = e * e;
    DiscreteGains {
        a: Ab::new(T::one() - one_minus_cos, sin),
        one_minus_a: Ab::new(one_minus_cos, -sin),
        l1: Ab::new(one_minus_r + one_minus_r - one_minus_cos, sin),
        l2: Ab::new(t * e2 * T::lit(0.5), x * e2 * k),
        r: T::one() - one_minus_r,
    }
}

/// (sin(x/2), cos(x/2), 1 − e^{−|x|}) for x = ω·Ts, outside the `f32` range of [`f32_gains`].
///
/// The observer needs these every sample because ω̂ changes every sample. In the operating
/// range |x| ≤ 0.25 `f64` evaluates truncated Taylor series instead of `sin_cos` and `exp_m1`
/// (a third of the estimator's instructions otherwise): the first omitted term is below half
/// an ulp (|h| ≤ 1/8: h¹²/13! = 2e-22 for sin, h¹⁴/14! = 3e-24 for cos, y¹³/14! = 2e-19 for
/// 1 − e^{−y}), so the results differ from `libm`'s by float rounding only.
#[inline(always)]
fn half_angle_terms<T: Real>(x: T) -> (T, T, T) {
    let y = x.abs();
    if !single_precision::<T>() && y <= T::lit(SERIES_LIMIT) {
        let h = x * T::lit(0.5);
        let h2 = h * h;
        let h4 = h2 * h2;
        let y2 = y * y;
        let y4 = y2 * y2;
        // The sums are grouped by Estrin's scheme (see `cubic`).
        let (s, c, e) = (&SIN_OVER_H, &COS, &ONE_MINUS_EXP_OVER_Y);
        let lit = T::lit;
        let y8 = y4 * y4;
        let (sin_over_h, cos, one_minus_exp_over_y) = (
            cubic(h2, h4, s) + h4 * h4 * (lit(s[4]) + lit(s[5]) * h2),
            cubic(h2, h4, c) + h4 * h4 * ((lit(c[4]) + lit(c[5]) * h2) + h4 * lit(c[6])),
            (cubic(y, y2, e) + y4 * cubic(y, y2, &e[4..]))
                + y8 * (cubic(y, y2, &e[8..]) + y4 * lit(e[12])),
        );
        (h * sin_over_h, cos, y * one_minus_exp_over_y)
    } else {
        // Large speeds (and NaN, which propagates). a = e^{jx} is 2π-periodic in x and every
        // gain depends on (sin(x/2), cos(x/2)) only through products of two of them, which a
        // shift of x by 2π (both change sign) leaves alone: wrap x first, so that the f32
        // approximation needs only [−π/2, π/2] (see `Real::step_sin_cos`). r depends on |x|
        // itself.
        let (sh, ch) = (crate::wrap_angle(x) * T::lit(0.5)).step_sin_cos();
        (sh, ch, y.step_one_minus_exp_neg())
    }
}

/// c0 + c1·t + c2·t² + c3·t³ as (c0 + c1·t) + t²·(c2 + c3·t) (Estrin's scheme): two
/// multiply-adds deep instead of Horner's three. The gains sit on the estimator's
/// sample-to-sample critical path (ω̂ → gains → D̂ → θm → ω̂), so depth is time.
#[inline(always)]
fn cubic<T: Real>(t: T, t2: T, c: &[f64]) -> T {
    (T::lit(c[0]) + T::lit(c[1]) * t) + t2 * (T::lit(c[2]) + T::lit(c[3]) * t)
}

/// Continuous-time gains of eq. (16) for a flux speed ω (rad/s, signed):
/// `[p1, p2, p3, p4, q1, q2, q3, q4]`. Used to document and test the paper's design; the
/// running observer uses [`DiscreteGains`].
pub fn continuous_gains<T: Real>(omega: T) -> [T; 8] {
    let two_abs = T::lit(2.0) * omega.abs();
    [
        two_abs,
        -omega,
        omega,
        two_abs,
        T::zero(),
        -omega,
        omega,
        T::zero(),
    ]
}

/// The observer's constant: the sampling period (the immutable half of
/// [`DisturbanceObserver`]; its gains depend on ω̂ and are formed every sample).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DisturbanceObserverParams<T> {
    ts: T,
}

/// The observer's state: λ̂1 and D̂.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ObserverState<T> {
    /// λ̂1: the observer's copy of the stator flux.
    z: Ab<T>,
    /// D̂: the estimated disturbance.
    d: Ab<T>,
}

impl<T: Real> DisturbanceObserverParams<T> {
    /// The constant of `config`, checked.
    pub(crate) fn new(config: DisturbanceObserverConfig<T>) -> Result<Self, ConfigError> {
        Ok(Self {
            ts: check::positive("ts", config.ts)?,
        })
    }

    /// (λ̂1, D̂) after one more sample from the state `s`, so that the estimator can check
    /// the whole new state before committing any of it.
    #[inline(always)]
    pub(crate) fn next_state(
        &self,
        s: &ObserverState<T>,
        lambda1: Ab<T>,
        omega: T,
    ) -> (Ab<T>, Ab<T>) {
        self.next_state_with(s, &self.gains(omega), lambda1)
    }

    /// The gains of the update for the flux speed `omega` (rad/s), as
    /// [`DisturbanceObserverParams::next_state_with`] uses them.
    #[inline(always)]
    pub(crate) fn gains(&self, omega: T) -> ObserverGains<T> {
        DiscreteGains::new(omega, self.ts).into()
    }

    /// [`Self::next_state`] with gains computed beforehand (by [`Self::gains`], possibly for
    /// an earlier sample's speed: the estimator holds them over
    /// its observer gain period).
    #[inline(always)]
    pub(crate) fn next_state_with(
        &self,
        s: &ObserverState<T>,
        g: &ObserverGains<T>,
        lambda1: Ab<T>,
    ) -> (Ab<T>, Ab<T>) {
        let e = lambda1 - s.z;
        // a·z + (1 − a)·d = d + a·(z − d): one complex product fewer.
        let z = s.d + g.a.complex_mul(s.z - s.d) + Ab::new(g.l1_alpha, g.a.beta).complex_mul(e);
        let d = s.d + g.l2.complex_mul(e);
        (z, d)
    }
}

/// The gains the update uses, a, ℓ1 and ℓ2 of [`DiscreteGains`], in five numbers: Im ℓ1 =
/// Im a exactly (ℓ1 = 1 + a − 2r with r real; both paths of [`DiscreteGains::new`] form the
/// two from the same product). The estimator keeps them in its state between updates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ObserverGains<T> {
    /// a = e^{jωTs}.
    a: Ab<T>,
    /// Re ℓ1.
    l1_alpha: T,
    /// ℓ2.
    l2: Ab<T>,
}

impl<T: Real> ObserverGains<T> {
    /// The gains at ω = 0: a = 1, ℓ1 = ℓ2 = 0 (the observer freezes).
    pub(crate) fn standstill() -> Self {
        Self {
            a: Ab::new(T::one(), T::zero()),
            l1_alpha: T::zero(),
            l2: Ab::zero(),
        }
    }
}

impl<T: Real> From<DiscreteGains<T>> for ObserverGains<T> {
    #[inline(always)]
    fn from(g: DiscreteGains<T>) -> Self {
        Self {
            a: g.a,
            l1_alpha: g.l1.alpha,
            l2: g.l2,
        }
    }
}

impl<T: Real> ObserverState<T> {
    /// λ̂1 = D̂ = 0.
    pub(crate) fn zero() -> Self {
        Self {
            z: Ab::zero(),
            d: Ab::zero(),
        }
    }

    /// A known flux with no disturbance: λ̂1 = `lambda1`, D̂ = 0, so that the first samples
    /// see no innovation step.
    pub(crate) fn at(lambda1: Ab<T>) -> Self {
        Self {
            z: lambda1,
            d: Ab::zero(),
        }
    }

    /// Takes the state computed by [`DisturbanceObserverParams::next_state`].
    #[inline(always)]
    pub(crate) fn commit(&mut self, z: Ab<T>, d: Ab<T>) {
        self.z = z;
        self.d = d;
    }

    /// D̂.
    #[inline(always)]
    pub(crate) fn disturbance(&self) -> Ab<T> {
        self.d
    }

    /// λ̂1.
    #[inline(always)]
    pub(crate) fn flux(&self) -> Ab<T> {
        self.z
    }
}

/// Frequency-adaptive disturbance observer (paper eq. (9)-(10), gains (16), Fig. 2),
/// discretised as described in the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisturbanceObserver<T> {
    params: DisturbanceObserverParams<T>,
    state: ObserverState<T>,
}

impl<T: Real> DisturbanceObserver<T> {
    /// A new observer with zero state.
    pub fn new(config: DisturbanceObserverConfig<T>) -> Result<Self, ConfigError> {
        Ok(Self {
            params: DisturbanceObserverParams::new(config)?,
            state: ObserverState::zero(),
        })
    }

    /// Clears the state (λ̂1 = D̂ = 0).
    pub fn reset(&mut self) {
        self.state = ObserverState::zero();
    }

    /// Starts from a known flux with no disturbance: λ̂1 = `lambda1`, D̂ = 0, so that the
    /// first samples see no innovation step.
    pub fn reset_to(&mut self, lambda1: Ab<T>) {
        self.state = ObserverState::at(lambda1);
    }

    /// One sample: `lambda1` is λ1\[n\] (the integrator output), `omega` the signed flux speed
    /// estimate (rad/s) used for the adaptive gains. Returns D̂ after the update.
    ///
    /// A non-finite input is refused and leaves the state untouched.
    #[inline]
    pub fn step(&mut self, lambda1: Ab<T>, omega: T) -> Result<Ab<T>, NonFiniteInput> {
        if !(lambda1.is_finite() && omega.is_finite()) {
            return Err(NonFiniteInput);
        }
        let (z, d) = self.params.next_state(&self.state, lambda1, omega);
        self.state.commit(z, d);
        Ok(d)
    }

    /// D̂, the current disturbance estimate.
    #[inline]
    pub fn disturbance(&self) -> Ab<T> {
        self.state.d
    }

    /// λ̂1, the observer's estimate of the stator flux including the disturbance. After a
    /// `step` with λ1\[n\] it is the internal model's prediction of λ1[n+1] (the flux rotated on
    /// by one sample), which is what the next innovation is measured against.
    #[inline]
    pub fn flux(&self) -> Ab<T> {
        self.state.z
    }

    /// The sampling period.
    pub fn ts(&self) -> T {
        self.params.ts
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;
    use nalgebra::{Matrix2, Matrix4};

    /// Real 4×4 error-dynamics matrix of the discrete observer, state (zα, zβ, dα, dβ).
    fn error_matrix(omega: f64, ts: f64) -> Matrix4<f64> {
        let g = DiscreteGains::new(omega, ts);
        let c = |v: Ab<f64>| Matrix2::new(v.alpha, -v.beta, v.beta, v.alpha);
        let a_l1 = c(g.a - g.l1);
        let oma = c(g.one_minus_a);
        let l2 = c(g.l2);
        let mut m = Matrix4::zeros();
        m.fixed_view_mut::<2, 2>(0, 0).copy_from(&a_l1);
        m.fixed_view_mut::<2, 2>(0, 2).copy_from(&oma);
        m.fixed_view_mut::<2, 2>(2, 0).copy_from(&(-l2));
        m.fixed_view_mut::<2, 2>(2, 2)
            .copy_from(&Matrix2::identity());
        m
    }

    /// Above the series limit the f32 gains come from `crate::approx` (no f64 inside): they
    /// agree with the f64 (`libm`) gains within f32 rounding for both signs, up to the Nyquist
    /// speed |ω·Ts| = 3 and beyond it (there x is wrapped first; ℓ2 ∝ 1/sin(x/2) is
    /// ill-conditioned near x = 2π, so the test stops at 5.5).
    #[test]
    fn f32_gains_beyond_the_series_match_f64() {
        let ts = 1e-4;
        let mut worst = 0.0_f64;
        for k in 0..=5300 {
            let x = 0.2 + k as f64 * 1e-3; // 0.2 … 5.5 rad per sample
            for omega in [x / ts, -x / ts] {
                let g64 = DiscreteGains::new(omega, ts);
                let g32 = DiscreteGains::new(omega as f32, ts as f32);
                let d = |a: Ab<f32>, b: Ab<f64>| {
                    (a.alpha as f64 - b.alpha)
                        .abs()
                        .max((a.beta as f64 - b.beta).abs())
                };
                let scale = 1.0 + g64.l2.alpha.abs().max(g64.l2.beta.abs());
                worst = worst
                    .max(d(g32.a, g64.a))
                    .max(d(g32.one_minus_a, g64.one_minus_a))
                    .max(d(g32.l1, g64.l1))
                    .max(d(g32.l2, g64.l2) / scale)
                    .max((g32.r as f64 - g64.r).abs());
            }
        }
        assert!(worst < 2e-6, "{worst}");
    }

    #[test]
    fn discrete_poles_are_image_of_minus_abs_omega_both_signs() {
        let ts = 100e-6;
        for k in 0..=60 {
            let f = -300.0 + 10.0 * k as f64;
            let w = 2.0 * PI * f;
            let r = (-w.abs() * ts).exp();
            let m = error_matrix(w, ts);
            // All four eigenvalues at r (two 2×2 Jordan blocks): (M − rI)² = 0.
            let n = m - Matrix4::identity() * r;
            let n2 = n * n;
            assert!(
                n2.abs().max() < 1e-12,
                "f = {f} Hz: |(M-rI)^2| = {}",
                n2.abs().max()
            );
            // And the map for −ω is the mirror (complex conjugate) of the one for +ω.
            let mm = error_matrix(-w, ts);
            let flip = Matrix4::from_diagonal(&nalgebra::Vector4::new(1.0, -1.0, 1.0, -1.0));
            assert!((flip * m * flip - mm).abs().max() < 1e-15);
        }
        // Far beyond the 300 Hz the issue asks for: ωTs = 3.
        let n = error_matrix(3.0 / ts, ts) - Matrix4::identity() * (-3.0f64).exp();
        assert!((n * n).abs().max() < 1e-12);
    }

    #[test]
    fn continuous_gains_place_poles_at_minus_abs_omega() {
        for w in [-2.0 * PI * 300.0, -5.0, 0.3, 2.0 * PI * 50.0] {
            let [p1, p2, p3, p4, q1, q2, q3, q4] = continuous_gains(w);
            // A_m − L_m C_m of eq. (9)-(10).
            let a = Matrix4::new(
                -p1,
                -w - p2,
                0.0,
                w, //
                w - p3,
                -p4,
                -w,
                0.0, //
                -q1,
                -q2,
                0.0,
                0.0, //
                -q3,
                -q4,
                0.0,
                0.0,
            );
            let n = a + Matrix4::identity() * w.abs();
            let scale = w.abs().powi(2);
            assert!((n * n).abs().max() < 1e-9 * scale, "ω = {w}");
        }
    }

    #[test]
    fn separates_rotating_flux_from_dc_offset() {
        let ts = 100e-6;
        for f in [-50.0, -6.0, 1.0, 20.0, 300.0] {
            let w = 2.0 * PI * f;
            let offset = Ab::new(0.013, -0.021);
            let mut obs = DisturbanceObserver::new(DisturbanceObserverConfig { ts }).unwrap();
            let mut d = Ab::zero();
            let settle = (25.0 / (w.abs() * ts)) as usize + 10;
            for n in 0..settle {
                let y = Ab::from_polar(0.088, w * ts * n as f64) + offset;
                d = obs.step(y, w).unwrap();
            }
            assert!((d - offset).norm() < 1e-4 * 0.088, "f = {f}: D̂ = {d:?}");
        }
    }

    #[test]
    fn notch_is_exactly_at_omega() {
        // Steady-state response of D̂ to a pure rotating input at the model frequency is zero.
        let ts = 100e-6;
        let w = 2.0 * PI * 100.0;
        let g = DiscreteGains::new(w, ts);
        // Closed loop: state x = (z, d); input y = a^n; steady state x = X·a^n.
        // z: a·Z = a·Z + (1−a)·D + ℓ1(1 − Z)  and  d: a·D = D + ℓ2(1 − Z).
        // Solve the 2×2 complex system numerically through nalgebra.
        use nalgebra::Complex;
        let cx = |v: Ab<f64>| Complex::new(v.alpha, v.beta);
        let (a, l1, l2, oma) = (cx(g.a), cx(g.l1), cx(g.l2), cx(g.one_minus_a));
        let m = nalgebra::Matrix2::new(l1, -oma, l2, a - Complex::new(1.0, 0.0));
        let rhs = nalgebra::Vector2::new(l1, l2);
        let x = m.lu().solve(&rhs).unwrap();
        assert!(
            x[1].norm_sqr().sqrt() < 1e-12,
            "notch leak {}",
            x[1].norm_sqr().sqrt()
        );
        // Negative sequence passes with unity-order gain (the continuous |d/y| = 1).
        let a_neg = a.conj();
        let m = nalgebra::Matrix2::new(a_neg - a + l1, -oma, l2, a_neg - Complex::new(1.0, 0.0));
        let x = m.lu().solve(&rhs).unwrap();
        assert!(
            (x[1].norm_sqr().sqrt() - 1.0).abs() < 0.01,
            "negative sequence gain {}",
            x[1].norm_sqr().sqrt()
        );
    }

    #[test]
    fn freezes_at_zero_speed() {
        let mut obs = DisturbanceObserver::new(DisturbanceObserverConfig { ts: 1e-4 }).unwrap();
        obs.reset_to(Ab::new(0.1, 0.0));
        for _ in 0..1000 {
            obs.step(Ab::new(0.5, 0.5), 0.0).unwrap();
        }
        assert_eq!(obs.disturbance(), Ab::zero());
        assert_eq!(obs.flux(), Ab::new(0.1, 0.0));
    }

    #[test]
    fn series_gains_match_libm_to_rounding() {
        // Against the closed forms evaluated with libm, across the series range and its edge.
        for k in -250..=250 {
            let x = k as f64 * 1e-3 + 1e-7;
            let g = DiscreteGains::<f64>::new(x, 1.0);
            let (s, c) = x.sin_cos();
            let omr = -(-x.abs()).exp_m1();
            assert!(
                (g.a.alpha - c).abs() < 4e-16 && (g.a.beta - s).abs() < 4e-16,
                "{x}"
            );
            let m = 0.5 * omr * omr;
            assert!((g.l2.alpha - m).abs() <= 3.0 * f64::EPSILON * m, "{x}");
            assert!((g.r - (-x.abs()).exp()).abs() <= 2.3e-16, "{x}");
            let gf = DiscreteGains::<f32>::new(x as f32, 1.0);
            assert!((gf.a.alpha as f64 - c).abs() < 2e-7 && (gf.a.beta as f64 - s).abs() < 2e-7);
            assert!((gf.l2.alpha as f64 - m).abs() <= 5e-7 * m, "{x}");
            assert!((gf.r as f64 - (-x.abs()).exp()).abs() <= 1.2e-7, "{x}");
            assert!(
                (gf.l2.beta as f64 - g.l2.beta).abs() <= 1e-6 * g.l2.beta.abs(),
                "{x}"
            );
        }
        // f32 keeps its series to |x| = 0.5 (`SERIES_LIMIT_F32`), with the same accuracy.
        for k in -550..=550 {
            let x = k as f64 * 1e-3 + 1e-7;
            let (s, c) = x.sin_cos();
            let omr = -(-x.abs()).exp_m1();
            let m = 0.5 * omr * omr;
            let g = DiscreteGains::<f64>::new(x, 1.0);
            let gf = DiscreteGains::<f32>::new(x as f32, 1.0);
            assert!((gf.a.alpha as f64 - c).abs() < 2e-7 && (gf.a.beta as f64 - s).abs() < 2e-7);
            assert!((gf.l2.alpha as f64 - m).abs() <= 5e-7 * m, "{x}");
            assert!((gf.r as f64 - (-x.abs()).exp()).abs() <= 1.2e-7, "{x}");
            assert!(
                (gf.l2.beta as f64 - g.l2.beta).abs() <= 1e-6 * g.l2.beta.abs(),
                "{x}"
            );
        }
        // Beyond the series range the libm path gives the same pole.
        let g = DiscreteGains::<f64>::new(0.6, 1.0);
        assert!((g.r - (-0.6f64).exp()).abs() <= 2.3e-16);
    }

    /// The criteria of `f32_gains` (see its docs), from the `f32` gains evaluated exactly in
    /// `f64` over |x| ≤ 0.5 down to x = 1e-6: each gain against its closed form, the notch
    /// (the internal model a against e^{jx}) and the four poles of the error dynamics against
    /// r = e^{−|x|}. The error dynamics of (e_z, e_d) are [[a − ℓ1, 1 − a], [−ℓ2, 1]]; with
    /// λ = r + μ their characteristic polynomial is μ² − δB·μ + (δC − r·δB) with
    /// δB = 2u − p − ℓ1 and δC = u(2 − u) − p − ℓ1 + ℓ2·p (p = 1 − a, u = 1 − r): both vanish
    /// for exact gains (a quadruple pole at r), and in this form they are computed without
    /// cancellation down to the smallest speeds. The pole bounds are those `f32` rounding
    /// alone gives (the previous Taylor gains, accurate to rounding, measured 1.6e-2 over the
    /// whole range, the worst at small |x|, and 2.8e-3 above |x| = 0.01: a double pole splits
    /// by the square root of a rounding error relative to |x|).
    #[test]
    fn f32_gains_keep_the_poles_and_the_notch() {
        use nalgebra::{Complex, ComplexField};
        let (mut notch, mut modulus) = (0.0_f64, 0.0_f64);
        let (mut pole, mut pole_above) = (0.0_f64, 0.0_f64);
        let (mut ea, mut el1, mut el2, mut er) = (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
        let mut xs: std::vec::Vec<f64> = (1..=5000).map(|k| k as f64 * 1e-4).collect();
        for d in [1e-6, 1e-5, 1e-4, 1e-3] {
            xs.extend((0..300).map(|k| d * (1.0 + k as f64 * 0.03)));
        }
        for x0 in xs {
            for x in [x0, -x0] {
                let g = DiscreteGains::<f32>::new(x as f32, 1.0);
                let x = (x as f32) as f64;
                let cx = |v: Ab<f32>| Complex::new(v.alpha as f64, v.beta as f64);
                let (a, l1, l2) = (cx(g.a), cx(g.l1), cx(g.l2));
                // Closed forms in f64.
                let u = -(-x.abs()).exp_m1();
                let a_exact = Complex::new(x.cos(), x.sin());
                let l1_exact = Complex::new(1.0 + x.cos() - 2.0 * (1.0 - u), x.sin());
                let h = 0.5 * x;
                let l2_exact = Complex::new(1.0, h.cos() / h.sin()) * (0.5 * u * u);
                ea = ea.max((a - a_exact).modulus());
                el1 = el1.max((l1 - l1_exact).modulus() / l1_exact.modulus());
                el2 = el2.max((l2 - l2_exact).modulus() / l2_exact.modulus());
                er = er.max((g.r as f64 - (1.0 - u)).abs());
                notch = notch.max((a.argument() - x).abs());
                modulus = modulus.max((a.modulus() - 1.0).abs());
                let p = Complex::new(1.0 - g.a.alpha as f64, -(g.a.beta as f64));
                let db = Complex::new(2.0 * u, 0.0) - p - l1;
                let dc = Complex::new(u * (2.0 - u), 0.0) - p - l1 + l2 * p;
                let root = (db * db - (dc - db * (1.0 - u)) * 4.0).sqrt();
                for mu in [(db + root) * 0.5, (db - root) * 0.5] {
                    pole = pole.max(mu.modulus() / u);
                    if x.abs() >= 0.01 {
                        pole_above = pole_above.max(mu.modulus() / u);
                    }
                }
            }
        }
        std::eprintln!(
            "a {ea:.2e}, l1 {el1:.2e}, l2 {el2:.2e}, r {er:.2e}; notch {notch:.2e} rad, \
             |a| - 1 {modulus:.2e}, poles {pole:.2e} / {pole_above:.2e} (|x| >= 0.01)"
        );
        assert!(ea <= 1e-7, "|a - e^jx| = {ea}");
        assert!(
            el1 <= 3e-7 && el2 <= 5e-7,
            "relative errors l1 {el1}, l2 {el2}"
        );
        assert!(er <= 1e-7, "|r - e^-|x|| = {er}");
        assert!(notch <= 1e-7, "notch displaced by {notch} rad per sample");
        assert!(modulus <= 1e-7, "|a| - 1 = {modulus}");
        assert!(pole <= 2e-2, "poles {pole}·(1 - r) from r");
        assert!(
            pole_above <= 3e-3,
            "poles {pole_above}·(1 - r) from r above |x| = 0.01"
        );
    }

    #[test]
    fn small_speed_gains_are_accurate_in_f32() {
        let w = 1e-3_f32;
        let g = DiscreteGains::<f32>::new(w, 1e-4);
        // ℓ2 → jωTs.
        assert!((g.l2.beta / (w * 1e-4) - 1.0).abs() < 1e-3);
    }

    #[test]
    fn rejects_non_finite_and_keeps_state() {
        let mut obs = DisturbanceObserver::new(DisturbanceObserverConfig { ts: 1e-4 }).unwrap();
        obs.step(Ab::new(0.1, 0.2), 100.0).unwrap();
        let before = obs;
        assert!(obs.step(Ab::new(f64::NAN, 0.0), 100.0).is_err());
        assert!(obs.step(Ab::new(0.0, 0.0), f64::INFINITY).is_err());
        assert_eq!(obs, before);
        assert!(DisturbanceObserver::new(DisturbanceObserverConfig { ts: -1.0 }).is_err());
    }
}
