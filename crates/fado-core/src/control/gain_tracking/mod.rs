//! Online tracking of the current sensors' gain mismatch while the rotor turns: the
//! correction the start-up's [`gain_calibration`](crate::control::gain_calibration) sets, for
//! the machines on which that calibration cannot run at standstill (its status `TooSlow`,
//! `RotorMoved`, `Implausible` or `Unobservable`).
//!
//! # Why
//! With phase a read as (1 + ε)·i_a against phase b, the α-β reading is
//! i + (ε/2)(1 + j/√3)·i + N·conj(i), N = (ε/2)(1 + j/√3) (a phase-b mismatch gives the same
//! form with −ε; a common gain gives no conj(i) term). The negative-sequence part N·conj(i)
//! is, in the d-q frame of θ, N·conj(i_dq)·e^(−j2θ): at a constant current a component at
//! −2ω of the measured current. Times R̂s it is a 2ω̂ integrand error of eq. (3), which at
//! speed averages out of the flux, but at a loaded zero-speed hold is a constant that walks
//! θ̂ (the EPS motor of `crates/fado-sim/tests/unseen_motor_tables.rs` with its start-up
//! calibration skipped: 1.1 rad in `stops` with 0.5 %). Every loaded hold follows a spell at speed, where the mismatch is observable.
//!
//! # The measurement
//! The current loop regulates the *measured* current, so the machine's current carries
//! −D·e^(−j2θ) with D = N·conj(i₀) (i₀ the d-q current), and the voltage it needs carries
//! −Z·D·e^(−j2θ). The d-q voltage equation in complex form,
//! v = R̂s·i + L̄·(di/dt + jω·i) + ΔL·(d conj(i)/dt + jω·conj(i)) + jω·λ̂f,
//! L̄ = (L̂d + L̂q)/2, ΔL = (L̂d − L̂q)/2, gives for the −2ω components (V₂ of the voltage that
//! acted, I₂ of the measured current, I₂⁺ the measured current's +2ω component):
//!
//! V₂ = (R̂s − jω·L̄)·(I₂ − D) − jω·ΔL·conj(I₂⁺),
//!
//! so D = I₂ − (V₂ + jω·ΔL·conj(I₂⁺))/(R̂s − jω·L̄), whatever the current loop's bandwidth
//! (a loop that tracks leaves I₂ ≈ 0 and D in the voltage; one that does not leaves it in the
//! current). Then N = D·i₀/|i₀|² and the residual mismatch of the corrected reading is
//!
//! ε̂ = 2·Re(N·conj(1 + j/√3))/|1 + j/√3|² = 1.5·Re(N·(1 − j/√3)).
//!
//! The drive multiplies the phase-a reading by the correction c (1/k of the start-up
//! calibration); the tracker integrates c ← c·(1 − ε̂·Ts/τ) with τ the tuning's `time`.
//!
//! # Discretisation
//! Per sample: the d-q current i (measured, corrected, in the frame of θ̂ₙ) and the voltage
//! that acted over [n−1, n] in the same frame; i₀ and v₀ are their first-order low-passes,
//! and the −2ω and +2ω components are the low-passes of (i − i₀)·e^(±j2θ̂) and
//! (v − v₀)·e^(j2θ̂) (e^(j2θ̂) the square of the sample's rotation: no extra sin/cos). Every
//! low-pass has the time constant τf = [`FILTER_PERIODS`]/|ω̂| (at most τ/4): a DC left in
//! the demodulated signal is a 2ω̂ ripple that the filter reduces by 2|ω̂|·τf = 6 and the
//! integrator by a further 2|ω̂|·τ; the dead time's 6ω̂ harmonics land at 4ω̂ and 8ω̂.
//! The voltage of [n−1, n] is demodulated with θ̂ₙ rather than with its mid-interval angle:
//! a phase of ω̂·Ts on V₂ (0.1 rad at 1000 rad/s and 10 kHz), a gain of the loop, no bias.
//!
//! # Why it converges without bias
//! Everything above is linear in the residual ε: ε̂ = G·ε + b. The integrator's fixed point
//! is ε̂ = 0, so an error of the model (R̂s, L̂, a salient rotor's cross term, the rotor's
//! own 2ω speed ripple from the torque ripple of D, the demodulation phase) changes only the
//! loop gain G (it converges while Re G > 0, at the rate G/τ), and only a b independent of ε
//! biases the result: a −2ω component of the d-q voltage or current that the mismatch does
//! not cause. Offsets (ω̂ in d-q), the inverter's dead time and its compensation (6kω̂ for
//! a symmetric inverter) and a salient rotor at a constant current (DC in d-q) give none;
//! what remains of them after the filters is a ripple of zero mean. Measured on the
//! simulator (EPS motor of `crates/fado-sim/tests/unseen_motor_tables.rs`, `fullrange`, plant
//! mismatch 1.005): the correction settles at 0.99503 (1/1.005 = 0.995025) at 1000 and
//! 2000 r/min and at −1000 r/min; the module tests converge within 3e-4 of k on a synthetic
//! machine (L̂d = L̂q and L̂d ≠ L̂q, both directions) and stay within 1e-4 of 1 with matched
//! gains.
//!
//! # Limits
//! It adapts only while |ω̂|·τ ≥ [`MIN_FILTER_SPEED_FACTOR`] (τf at most τ/4: 120 rad/s
//! electrical at the default τ = 0.1 s), |i₀| ≥ `min_current` (D ∝ |i₀|: without load
//! there is nothing to see), the speed is steady (|ω̂ − ω̂₀| ≤ [`STEADY_SPEED_SHARE`]·|ω̂|:
//! an acceleration leaves the DC trackers behind), the modulator did not limit the voltage
//! and the whole reading 2|N|/|1 + j/√3| is at most `max_mismatch` (a larger one is a
//! transient: a 2000 r/min stop in 0.3 s reads 0.26 on the EPS motor), after
//! [`SETTLE_TIME_CONSTANTS`] filter time constants of these conditions in a row. The
//! correction stays within 1 ± `max_mismatch`. The convergence time is τ/G (G ≈ 1 with a
//! good model). The start-up calibration, where it ran, is kept: the drive runs the tracker
//! only where it did not. Below 12/τ it learns nothing: a loaded hold reached from 4 % of the
//! rated speed only (the `stops` scenario, 17 rad/s on the EPS motor) keeps the mismatch the
//! start-up left; on a 14-pole gimbal motor rated at 73 rad/s it never learns.
//!
//! The bound of a bias: saliency at a constant current and the symmetric dead time are
//! outside −2ω̂ (none to first order); an inverter whose phases differ, or a rotor whose
//! flux carries a −2ω̂ harmonic in d-q, bias ε̂ by that component over Z·D per unit mismatch.

use crate::{Ab, Dq, Real, Rotation};

/// Low-pass time constant of the demodulation as ω̂·τf (rad): a 2ω̂ ripple is reduced by
/// 2·ω̂·τf = 6.
pub const FILTER_PERIODS: f64 = 3.0;
/// Slowest speed at which the tracker adapts, as ω̂·τ (τ the adaptation time): there τf is
/// τ/4 (the loop of the low-pass and the integrator then has a damping of 1).
pub const MIN_FILTER_SPEED_FACTOR: f64 = 4.0 * FILTER_PERIODS;
/// The conditions must hold for this many filter time constants τf before the tracker adapts.
pub const SETTLE_TIME_CONSTANTS: f64 = 4.0;
/// Largest |ω̂ − ω̂₀|/|ω̂| (ω̂₀ low-passed as the filters) at which the speed counts as steady:
/// an acceleration leaves the DC trackers behind, and their lag demodulates into I₂ and V₂.
pub const STEADY_SPEED_SHARE: f64 = 0.1;

/// Configuration of a [`GainTracking`], absolute units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GainTrackingConfig<T> {
    /// Sampling period, s.
    pub ts: T,
    /// Adaptation time constant τ, s (the convergence time with a good model).
    pub time: T,
    /// R̂s, Ω.
    pub rs: T,
    /// L̂d, H.
    pub ld: T,
    /// L̂q, H.
    pub lq: T,
    /// Smallest |i₀| (A) at which it adapts.
    pub min_current: T,
    /// Largest |c − 1| it sets.
    pub max_mismatch: T,
}

/// The online gain-mismatch tracker (module docs). Allocation-free, bounded state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GainTracking<T> {
    config: GainTrackingConfig<T>,
    /// Low-passes: the d-q current and voltage (i₀, v₀), the −2ω components of current and
    /// voltage (I₂, V₂), the +2ω component of the current (I₂⁺).
    i0: Ab<T>,
    v0: Ab<T>,
    i2: Ab<T>,
    v2: Ab<T>,
    i2p: Ab<T>,
    /// ω̂ low-passed as the rest (rad/s): the steadiness test.
    omega0: T,
    /// Filter time constants the conditions held in a row (Σ Ts/τf, at most
    /// [`SETTLE_TIME_CONSTANTS`]).
    ready: T,
    /// The last residual mismatch read (0 before any).
    residual: T,
}

/// (a + jb)·(c + jd) of two α-β vectors read as complex numbers.
#[inline(always)]
fn mul<T: Real>(x: Ab<T>, y: Ab<T>) -> Ab<T> {
    x.complex_mul(y)
}

/// The conjugate.
#[inline(always)]
fn conj<T: Real>(x: Ab<T>) -> Ab<T> {
    Ab::new(x.alpha, -x.beta)
}

impl<T: Real> GainTracking<T> {
    /// A tracker; a configuration whose time, ts or limits are not positive and finite
    /// gives one that never adapts.
    pub fn new(config: GainTrackingConfig<T>) -> Self {
        Self {
            config,
            i0: Ab::zero(),
            v0: Ab::zero(),
            i2: Ab::zero(),
            v2: Ab::zero(),
            i2p: Ab::zero(),
            omega0: T::zero(),
            ready: T::zero(),
            residual: T::zero(),
        }
    }

    /// The last residual mismatch ε̂ read (0 before any adapting sample).
    pub fn residual(&self) -> T {
        self.residual
    }

    /// One sample: the measured d-q current `i` (corrected with `correction`, in the frame
    /// `rot` of θ̂), the voltage `v` that acted over the last period in the same frame,
    /// ω̂ (electrical rad/s) and whether the modulator limited that voltage. Returns the new
    /// correction; a non-finite input changes nothing.
    pub fn step(
        &mut self,
        i: Dq<T>,
        v: Dq<T>,
        rot: Rotation<T>,
        omega: T,
        limited: bool,
        correction: T,
    ) -> T {
        let c = self.config;
        let finite = i.is_finite() && v.is_finite() && omega.is_finite() && correction.is_finite();
        if !finite || !rot.cos.is_finite() || !rot.sin.is_finite() {
            return correction;
        }
        let w = omega.abs();
        // τf = FILTER_PERIODS/|ω̂|, at most τ/4: a = Ts/τf.
        let a_min = c.ts * T::lit(MIN_FILTER_SPEED_FACTOR / FILTER_PERIODS) / c.time;
        let a = (c.ts * w / T::lit(FILTER_PERIODS)).step_max(a_min);
        let a = a.step_min(T::lit(0.5));
        // False for a time or period that is zero, negative or NaN.
        let usable = a > T::zero() && c.time > T::zero();
        if !usable {
            return correction;
        }
        let i = Ab::new(i.d, i.q);
        let v = Ab::new(v.d, v.q);
        self.i0 = self.i0 + (i - self.i0) * a;
        self.v0 = self.v0 + (v - self.v0) * a;
        // e^(j2θ̂) from the rotation.
        let e2 = Ab::new(
            rot.cos * rot.cos - rot.sin * rot.sin,
            (rot.cos + rot.cos) * rot.sin,
        );
        let di = i - self.i0;
        self.i2 = self.i2 + (mul(di, e2) - self.i2) * a;
        self.i2p = self.i2p + (mul(di, conj(e2)) - self.i2p) * a;
        self.v2 = self.v2 + (mul(v - self.v0, e2) - self.v2) * a;
        self.omega0 = self.omega0 + (omega - self.omega0) * a;
        // A sensor mismatch reads at most `max_mismatch` (in either component of N): a larger
        // reading is a transient the filters have not settled on (a fast speed change, a
        // load step), and restarts the wait.
        let (residual, size) = self.residual_mismatch(omega);
        let steady = (omega - self.omega0).abs() <= T::lit(STEADY_SPEED_SHARE) * w;
        let on = w * c.time >= T::lit(MIN_FILTER_SPEED_FACTOR)
            && self.i0.norm_squared() >= c.min_current * c.min_current
            && !limited
            && steady
            && size <= c.max_mismatch;
        let settle = T::lit(SETTLE_TIME_CONSTANTS);
        self.ready = if on {
            (self.ready + a).step_min(settle)
        } else {
            T::zero()
        };
        let settled = self.ready >= settle;
        if !settled {
            return correction;
        }
        self.residual = residual;
        let step = residual * c.ts / c.time;
        let next = correction * (T::one() - step);
        let lo = T::one() - c.max_mismatch;
        let hi = T::one() + c.max_mismatch;
        next.step_max(lo).step_min(hi)
    }

    /// ε̂ from the filters' state at speed ω̂ (module docs), and the size 2|N|/|1 + j/√3| of
    /// the whole reading (NaN for a non-finite one).
    fn residual_mismatch(&self, omega: T) -> (T, T) {
        let c = self.config;
        let half = T::lit(0.5);
        let l_mean = (c.ld + c.lq) * half;
        let l_diff = (c.ld - c.lq) * half;
        // Z = R̂s − jω̂·L̄; 1/Z = conj(Z)/|Z|².
        let z = Ab::new(c.rs, -omega * l_mean);
        let cross = Ab::new(T::zero(), omega * l_diff);
        let v = self.v2 + mul(cross, conj(self.i2p));
        let d = self.i2 - mul(v, conj(z)) * (T::one() / z.norm_squared());
        let n = mul(d, self.i0) * (T::one() / self.i0.norm_squared());
        // 1.5·Re(N·(1 − j/√3)); |1 + j/√3| = 2/√3.
        let r = T::lit(1.5) * (n.alpha + n.beta * T::lit(1.0 / 1.732_050_807_568_877_2));
        let size = n.norm() * T::lit(1.732_050_807_568_877_2);
        if r.is_finite() && size.is_finite() {
            (r, size)
        } else {
            (T::zero(), T::zero() / T::zero())
        }
    }

    /// Clears the filters (a new start).
    pub fn reset(&mut self) {
        *self = Self::new(self.config);
    }
}

#[cfg(test)]
mod tests;
