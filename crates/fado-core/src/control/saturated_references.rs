//! The drive's references from a saturating magnetic model: MTPA, the current for a torque,
//! the torque limit and the current loop's inductances.
//!
//! **Torque.** From the co-energy, T = 1.5·p·(ψd·i_q − ψq·i_d) = 1.5·p·λa·i_q with the
//! active flux λa = ψd − L_q,s·i_d (`crate::active_flux`): the drive's "torque in units of the
//! magnet's q current", i_q,t = T/(1.5·p·λ̂f), is met by solving τ(i) = ψd·i_q − ψq·i_d =
//! λ̂f·i_q,t along the MTPA curve, as for constant inductances with λa = λf + (Ld − Lq)·i_d.
//!
//! **MTPA.** The torque per ampere is largest where ∇τ is parallel to i, i.e.
//! g = (∂τ/∂i_d)·i_q − (∂τ/∂i_q)·i_d = 0 with ∂τ/∂i_d = L_dd·i_q − ψq − L_qd·i_d and
//! ∂τ/∂i_q = ψd + L_dq·i_q − L_qq·i_d (L_xy the incremental inductances). For each i_q of a
//! table of [`MTPA_NODES`] points over [0, I_max] the d current is found once, at
//! construction, by bisection of g on [−2·I_max, 0] (g < 0 at i_d = 0 on a rotor with
//! L_qq > L_dd, and > 0 far negative); between the nodes it is interpolated linearly, and it
//! is even in i_q. 17 nodes put the interpolation error below 0.1 % of the rated torque on the
//! saturated presets (the test checks the torque per ampere against a search on the circle).
//!
//! **Current loop.** The PI's Kp = L·ωc places the bandwidth at ωc for the inductance L the
//! current meets, the incremental one. Saturation lowers it with the load, so the loop is
//! designed at the rated MTPA point, where L_inc is smallest and the loop gain Kp/L largest:
//! the configured bandwidth is then the highest the loop reaches anywhere in the rated range,
//! and at light load the loop is slower than designed, never faster (a faster one would eat
//! the delay's phase margin, `CurrentControllerConfig::bandwidth_hz`).

use crate::magnetics::{FluxWarmStart, MagneticModel, Magnetics};
use crate::{Dq, MachineModel, Real};

/// Nodes of the MTPA table over [0, I_max].
pub const MTPA_NODES: usize = 17;

/// Bisection steps of the MTPA condition (2⁻⁴⁰ of 2·I_max).
const MTPA_BISECTIONS: usize = 40;

/// A saturating model's references (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SaturatedReferences<T: 'static> {
    model: Magnetics<'static, T>,
    /// I_max/(MTPA_NODES − 1), A.
    step: T,
    /// MTPA i_d at i_q = k·step, A.
    mtpa: [T; MTPA_NODES],
}

/// τ = ψd·i_q − ψq·i_d (the torque over 1.5·p), Wb·A.
#[inline]
fn torque_flux<T: Real>(model: &impl MagneticModel<T>, i: Dq<T>) -> T {
    let psi = model.flux(i);
    psi.d * i.q - psi.q * i.d
}

/// The MTPA condition g (module docs) at `i`, the model's flux solved from `guess` (a nearby
/// current's), and that flux.
fn mtpa_condition<T: Real>(model: &impl MagneticModel<T>, i: Dq<T>, guess: Dq<T>) -> (T, Dq<T>) {
    let (psi, l) = model.flux_and_inductance_from(i, guess);
    let d_tau_d = l.dd * i.q - psi.q - l.qd * i.d;
    let d_tau_q = psi.d + l.dq * i.q - l.qq * i.d;
    (d_tau_d * i.q - d_tau_q * i.d, psi)
}

/// The MTPA d current at q current `i_q` ≥ 0 by bisection on [−2·`i_max`, 0]; 0 where g ≥ 0
/// at i_d = 0 (no reluctance torque to gain). Each point's flux starts from the last one's.
fn mtpa_id<T: Real>(model: &impl MagneticModel<T>, i_q: T, i_max: T) -> T {
    let start = Dq::new(T::zero(), i_q);
    let (g0, mut psi) = mtpa_condition(model, start, model.flux(start));
    if g0.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Less) {
        return T::zero();
    }
    let (mut lo, mut hi) = (-(i_max + i_max), T::zero());
    for _ in 0..MTPA_BISECTIONS {
        let mid = T::lit(0.5) * (lo + hi);
        let g;
        (g, psi) = mtpa_condition(model, Dq::new(mid, i_q), psi);
        if g < T::zero() {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    T::lit(0.5) * (lo + hi)
}

impl<T: Real> SaturatedReferences<T> {
    /// The references of `machine`'s saturating model up to the current limit `i_max` (A);
    /// None for constant inductances (the drive keeps its closed forms) or a non-finite table.
    pub fn new(machine: &MachineModel<T>, i_max: T) -> Option<Self> {
        let model = machine.magnetic_model();
        if model.is_linear() {
            return None;
        }
        let step = i_max / T::lit((MTPA_NODES - 1) as f64);
        let mtpa = core::array::from_fn(|k| mtpa_id(&model, step * T::lit(k as f64), i_max));
        let ok = step.is_finite() && step > T::zero() && mtpa.iter().all(|x| x.is_finite());
        ok.then_some(Self { model, step, mtpa })
    }

    /// The MTPA d current for the q current `i_q` (A): the table interpolated, even in i_q,
    /// held at its last node beyond I_max.
    #[inline]
    pub fn mtpa_id(&self, i_q: T) -> T {
        let x = i_q.abs() / self.step;
        let last = MTPA_NODES - 1;
        let k = x.index_floor(last - 1);
        let f = crate::real::min(x - T::from_index(k), T::one());
        if !f.is_finite() {
            return T::zero();
        }
        self.mtpa[k] + f * (self.mtpa[k + 1] - self.mtpa[k])
    }

    /// τ = ψd·i_q − ψq·i_d = λa·i_q at `i` (the torque over 1.5·p), Wb·A.
    #[inline]
    pub fn torque_flux(&self, i: Dq<T>) -> T {
        torque_flux(&self.model, i)
    }

    /// τ at `i` as [`SaturatedReferences::torque_flux`] and ψ(i), solved from `warm`'s
    /// prediction (the tangent plane at a nearby current, `crate::magnetics::FluxWarmStart`),
    /// `warm` moved to that ψ: the drive's solves chain their flux from one evaluation to the
    /// next and from sample to sample, so that each costs one or two Newton steps instead of
    /// a solve from the linear guess.
    #[inline]
    pub fn torque_flux_warm(&self, i: Dq<T>, warm: &mut FluxWarmStart<T>) -> (T, Dq<T>) {
        let psi = self.model.flux_from(i, warm.prediction(i));
        *warm = warm.moved(i, psi);
        (psi.d * i.q - psi.q * i.d, psi)
    }

    /// [`SaturatedReferences::torque_flux_warm`] where ψ(i) is a solve (the algebraic model),
    /// `i` within `reach` of the current `at` whose tangent plane `warm` is: ψ from the plane
    /// alone, off the root by the curvature times |i − at|² (10⁻¹² of the flux for a reach of
    /// 10⁻⁶ of the rated current, below the drive's other roundings), where the solve would
    /// take an evaluation of i(ψ) and its Jacobian to confirm the same prediction. The drive's
    /// realised torque at the reference, a settled Newton step from the torque solve's last
    /// evaluation. A map (a direct lookup) and a farther `i` take `torque_flux_warm`.
    #[inline]
    pub fn torque_flux_near(
        &self,
        i: Dq<T>,
        at: Dq<T>,
        reach: T,
        warm: &mut FluxWarmStart<T>,
    ) -> (T, Dq<T>) {
        let solved = matches!(self.model, Magnetics::Saturation(_));
        if solved && warm.is_set() && (i - at).norm() <= reach {
            let psi = warm.prediction(i);
            *warm = warm.moved(i, psi);
            return (psi.d * i.q - psi.q * i.d, psi);
        }
        self.torque_flux_warm(i, warm)
    }

    /// τ at `i` with its derivative along a path of slope di_d/di_q = `did_diq`, ψ(i) solved
    /// from `warm` as in [`SaturatedReferences::torque_flux_warm`] (`warm` set to the
    /// tangent plane there), and that ψ:
    /// dτ/di_q = (L·(did_diq, 1))d·i_q + ψd − (L·(did_diq, 1))q·i_d − ψq·did_diq with L the
    /// incremental inductance.
    #[inline]
    pub fn torque_flux_slope(
        &self,
        i: Dq<T>,
        did_diq: T,
        warm: &mut FluxWarmStart<T>,
    ) -> (T, T, Dq<T>) {
        let (psi, l) = self.model.flux_and_inductance_from(i, warm.prediction(i));
        *warm = FluxWarmStart::at(i, psi, &l);
        let dpsi = l.apply(Dq::new(did_diq, T::one()));
        let slope = dpsi.d * i.q + psi.d - dpsi.q * i.d - psi.q * did_diq;
        (psi.d * i.q - psi.q * i.d, slope, psi)
    }

    /// The model's flux at the current `i` and the warm start there (its tangent plane).
    pub fn warm_start(&self, i: Dq<T>) -> (Dq<T>, FluxWarmStart<T>) {
        let (psi, l) = self.model.flux_and_inductance(i);
        (psi, FluxWarmStart::at(i, psi, &l))
    }

    /// The model's flux ψ(i) in Wb.
    pub fn flux(&self, i: Dq<T>) -> Dq<T> {
        self.model.flux(i)
    }

    /// The model's flux ψ(i) in Wb, solved from `guess` (the flux at a nearby current).
    #[inline]
    pub fn flux_from(&self, i: Dq<T>, guess: Dq<T>) -> Dq<T> {
        self.model.flux_from(i, guess)
    }

    /// The MTPA point on the circle |i| = `current` (A), i_q ≥ 0 (|(mtpa_id(i_q), i_q)|
    /// grows with i_q: bisection).
    pub fn mtpa_on_circle(&self, current: T) -> Dq<T> {
        let (mut lo, mut hi) = (T::zero(), current);
        for _ in 0..MTPA_BISECTIONS {
            let mid = T::lit(0.5) * (lo + hi);
            let id = self.mtpa_id(mid);
            if id * id + mid * mid > current * current {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        Dq::new(self.mtpa_id(lo), lo)
    }

    /// The largest torque on the circle |i| = `i_max` along the MTPA curve, in units of the
    /// magnet's q current (over 1.5·p·`flux_linkage`): the speed loop's output limit.
    pub fn torque_limit(&self, i_max: T, flux_linkage: T) -> T {
        self.torque_flux(self.mtpa_on_circle(i_max)) / flux_linkage
    }

    /// The incremental (L_dd, L_qq) at the rated MTPA point (rated current on the MTPA curve):
    /// the current loop's inductances (module docs).
    pub fn rated_incremental(&self, rated_current: T) -> (T, T) {
        let l = self
            .model
            .incremental_inductance(self.mtpa_on_circle(rated_current));
        (l.dd, l.qq)
    }
}

#[cfg(test)]
mod tests;
