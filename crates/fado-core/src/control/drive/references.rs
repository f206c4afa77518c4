//! Model computations of the sample: the currents for a torque demand, the current
//! predicted from the last sample.

use super::SensorlessDrive;
use crate::estimator::RotorAngleEstimator;
use crate::{Ab, Dq, Real};

/// Halvings of the torque solve's bracket where its path is not monotone (2⁻²⁴ of the bracket,
/// below 10⁻⁶ of the rated current; the next sample's Newton steps refine it), ours.
const TORQUE_BISECTIONS: usize = 24;

/// Doublings of the torque solve's bracket before it gives up (2⁴ × the rated current beyond
/// the demand), ours.
const TORQUE_BRACKET_DOUBLINGS: usize = 4;

/// A Newton step of the saturating model's torque solve below this fraction of the rated
/// current ends it (ours): the step is the iterate's error to first order, and what remains
/// after it is that step times the slope's relative error (the secant over 10⁻³ of the rated
/// current of the injection and MTPA path: ≈ 10⁻³), below 10⁻⁹ of the rated current. From
/// the last sample's i_q* most samples end after one or two of the three steps, each a flux
/// solve on the model (1.8 on average on `pmsm-gem-1k1-measured` `stops`); the solve stays
/// within 10⁻⁷ of the rated current of the cold solve (`saturated_torque_solve_is_the_cold_solve`).
pub(super) const TORQUE_SETTLED: f64 = 1e-6;

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// (i_d*, i_q*) for a torque demand `iq_torque` in units of the magnet's q current
    /// (torque / (1.5·p·λ̂f)): i_d* = the eq. (23) injection + MTPA of i_q* + the
    /// standstill probe's `probe_id`, and i_q* solves
    /// (λ̂f + (L̂d − L̂q)·i_d*(i_q*))·i_q* = λ̂f·i_q,t by three Newton steps from `guess` (the
    /// last sample's i_q*; a secant over 0.1 % of the rated current for the slope), by
    /// bisection where the slope is flat or falling (L̂d > L̂q: [`Self::solve_torque`]). On a
    /// surface-magnet rotor i_q* = i_q,t, as in the paper. Taking i_d* from the last
    /// sample's i_q* instead (no solve) closes an algebraic loop through the injection that
    /// oscillates sample by sample under load (measured on ipmsm-gem-50k `stops`).
    pub(super) fn currents_for_torque(&mut self, iq_torque: T, guess: T, probe_id: T) -> Dq<T> {
        if let Some(s) = &self.resolved.saturated {
            let (i, psi, warm, at) =
                self.saturated_currents_for_torque(s, iq_torque, guess, probe_id);
            (
                self.saturated_flux,
                self.saturated_warm,
                self.saturated_point,
            ) = (psi, warm, at);
            return i;
        }
        let m = &self.config.machine;
        let injection = &self.blocks.injection;
        let mtpa = self.resolved.mtpa;
        let id_of = |iq: T| {
            let id = injection.step(iq) + probe_id;
            if mtpa { id + m.mtpa_id(iq) } else { id }
        };
        if !self.resolved.salient {
            return Dq::new(id_of(iq_torque), iq_torque);
        }
        let target = m.flux_linkage * iq_torque;
        let f = |iq: T| m.active_flux(id_of(iq)) * iq - target;
        let iq = Self::solve_torque(f, iq_torque, guess, m.rated_current, m.flux_linkage);
        Dq::new(id_of(iq), iq)
    }

    /// The q current where `f` (the torque flux less its target) vanishes: three Newton steps
    /// from `guess` (when it has the sign of `iq_torque`, else from `iq_torque`) with a secant
    /// slope over 0.1 % of `rated_current`; a flat, falling or non-finite slope ends Newton's
    /// steps and the root is bracketed instead ([`Self::bisect_torque`]), a non-finite result
    /// gives `iq_torque`.
    pub(super) fn solve_torque(
        f: impl Fn(T) -> T,
        iq_torque: T,
        guess: T,
        rated_current: T,
        flux_linkage: T,
    ) -> T {
        let h = T::lit(1e-3) * rated_current;
        let secant = |iq: T| {
            let f0 = f(iq);
            (f0, (f(iq + h) - f0) / h)
        };
        let limits = (rated_current, flux_linkage);
        Self::solve_torque_with(secant, iq_torque, guess, limits, T::zero())
    }

    /// [`Self::solve_torque`] with `f` returning the value and its slope at i_q, and
    /// `limits` = (rated current, λ̂f); a Newton step of at most `settled` (A) ends the steps
    /// (zero: only a step of exactly zero, after which the next steps of a pure `f` would
    /// repeat it).
    pub(super) fn solve_torque_with(
        f: impl Fn(T) -> (T, T),
        iq_torque: T,
        guess: T,
        (rated_current, flux_linkage): (T, T),
        settled: T,
    ) -> T {
        let mut iq = if guess.is_finite() && guess * iq_torque > T::zero() {
            guess
        } else {
            iq_torque
        };
        for _ in 0..3 {
            let (f0, slope) = f(iq);
            // A flat, falling or non-finite slope (NaN compares false): Newton's step would
            // stay on a local extremum of the torque or run away from the root; the bracket
            // unless the iterate is a root already.
            if slope > T::lit(1e-3) * flux_linkage {
                let step = f0 / slope;
                iq -= step;
                if step.abs() <= settled {
                    break;
                }
            } else {
                if f0 != T::zero()
                    && let Some(root) = Self::bisect_torque(|x| f(x).0, iq_torque, rated_current)
                {
                    iq = root;
                }
                break;
            }
        }
        if !iq.is_finite() {
            iq = iq_torque;
        }
        iq
    }

    /// A root of `f` by bisection, for a torque path that is not monotone: where the eq. (23)
    /// injection i_d = √(I_min² − i_q²) falls to zero at |i_q| → I_min it turns the torque
    /// down on a rotor whose d current adds torque (L_d > L_q, or a measured map with
    /// ψq(i_d, 0) < 0), a local maximum of the torque below I_min that Newton's steps from
    /// the last i_q* stop on. The bracket runs from −`rated_current` to |`iq_torque`| +
    /// `rated_current` (each end doubled up to [`TORQUE_BRACKET_DOUBLINGS`] times until the
    /// torque there is on either side of the demand, in the demand's direction), so that every
    /// torque up to the path's limit is reached; [`TORQUE_BISECTIONS`] halvings of it leave
    /// 2⁻²⁴ of its width, and the next sample's Newton steps start from there. None where no
    /// bracket is found (a non-finite `f`).
    fn bisect_torque(f: impl Fn(T) -> T, iq_torque: T, rated_current: T) -> Option<T> {
        let s = if iq_torque < T::zero() {
            -T::one()
        } else {
            T::one()
        };
        // g rises with x = s·i_q on the path's monotone branches.
        let g = |x: T| s * f(s * x);
        let (mut lo, mut hi) = (-rated_current, iq_torque.abs() + rated_current);
        let mut doublings = 0;
        while !(g(hi) > T::zero() && g(lo) < T::zero()) {
            doublings += 1;
            if doublings > TORQUE_BRACKET_DOUBLINGS || !(lo.is_finite() && hi.is_finite()) {
                return None;
            }
            (lo, hi) = (lo + lo, hi + hi);
        }
        for _ in 0..TORQUE_BISECTIONS {
            let mid = T::lit(0.5) * (lo + hi);
            if g(mid) > T::zero() {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        Some(s * T::lit(0.5) * (lo + hi))
    }

    /// The current at this sample predicted from the last one used (measured or
    /// reconstructed) by the machine model over [n−1, n]: L̂q·di/dt = v − R̂s·i − jω̂·λ̂r with
    /// the voltage that acted (the realised reference computed at n−2) and the estimator's
    /// last rotor flux and speed. Exact in form for the SPMSM (L̂d = L̂q); forward Euler is
    /// enough at R̂s·Ts/L̂q ≈ 0.012. None when the prediction is no plausible current
    /// (non-finite, or beyond the trip level after absurd inputs): the readings are used.
    pub(super) fn predicted_current(&self) -> Option<Ab<T>> {
        let c = &self.config;
        let e = &self.last.estimate;
        let emf = e.diagnostics.lambda_r.mul_j() * e.omega;
        // The estimator's R̂s when it reports one (it may adapt it), else the configured one.
        let rs_hat = if e.diagnostics.rs_hat > T::zero() {
            e.diagnostics.rs_hat
        } else {
            c.machine.rs
        };
        let i = self.last_i_ab;
        let predicted = i + (self.history[1] - i * rs_hat - emf) * (c.ts / c.machine.lq);
        let n = predicted.norm();
        (n.is_finite() && n <= self.resolved.trip_current).then_some(predicted)
    }

    /// What [`predicted_current`](Self::predicted_current) cannot know over one sample, in
    /// A: the back-EMF's turn over the sample, which the prediction holds at its start (half
    /// of ω̂·Ts on average, |ω̂|·|λ̂r|·|ω̂|·Ts/2 of voltage) through L̂q over Ts. The
    /// stuck-channel detector allows it between a near-zero reading and the prediction
    /// (`StuckChannelDetector::set_model_uncertainty`).
    pub(super) fn stuck_model_uncertainty(&self) -> T {
        let e = &self.last.estimate;
        let w = e.omega.abs();
        w * e.diagnostics.lambda_r.norm() * w * self.resolved.stuck_turn_gain
    }
}
