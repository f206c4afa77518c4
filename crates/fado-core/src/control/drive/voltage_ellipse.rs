//! The voltage ellipse in field weakening: the q current cut to what the voltage allows at
//! the d current the field-weakening loop sets.
//!
//! At speed ω the stator voltage is about ω·|ψ(i)| (R̂s·I is a few per cent of it at the
//! weakening speeds), so a current reference whose model flux |ψ| exceeds the largest flux
//! the voltage allows, ψ_max = (Vdc/√3)/|ω̂|
//! ([`FieldWeakening::ellipse_flux`](crate::control::field_weakening::FieldWeakening::ellipse_flux)),
//! cannot be tracked: the current controller saturates and the current runs where the
//! back-EMF takes it. The field-weakening loop moves only i_d, which lowers ψ_d; ψ_q = L_q·i_q
//! is the q current's alone. On a rotor whose q flux at the current limit exceeds ψ_max (a
//! PM-assisted synchronous-reluctance rotor: pmsyrm-baldor-5k6 has L_q·I_max = 3.4 Wb against
//! ψ_max = 0.41 Wb at 3,600 r/min) a torque step (a stop at the current limit from the top
//! speed) asks for a q flux no d current compensates, and the drive loses its currents. So
//! while the loop weakens the field the q current is cut to the ellipse
//! |ψ(i_d, i_q)| ≤ ψ_max of the model — the saturating model where there is one, whose
//! secant L_q falls with the current, else λ̂f + L̂d·i_d and L̂q·i_q. The bound is the
//! inscribed circle, above the loop's own target (`voltage_margin`, 0.92 of it): in steady
//! field weakening the loop holds the voltage below the bound and the cut acts only on the
//! transients that would leave it. Below the weakening speed nothing changes.
//!
//! The cut solves ψ_q(i_d, i_q)² = ψ_max² − ψ_d(i_d, i_q)² by the fixed point
//! i_q ← i_q·√(ψ_max² − ψ_d²)/|ψ_q| (the secant inductance held over a step), which
//! [`ELLIPSE_STEPS`] steps bring within 2 % of the root, from above, on the saturated presets
//! (the secant varies slowly): one flux evaluation per step, none while the reference is
//! inside the ellipse but the one that says so.

use super::SensorlessDrive;
use crate::estimator::RotorAngleEstimator;
use crate::{Dq, Real};

/// Fixed-point steps of the q current's cut (module docs), ours.
const ELLIPSE_STEPS: usize = 3;

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// The current reference `i` with its q current cut to the voltage ellipse at the speed
    /// `omega` on the bus `vdc` while the field-weakening loop weakens (module docs).
    #[inline]
    pub(super) fn voltage_ellipse(&self, i: Dq<T>, vdc: T, omega: T) -> Dq<T> {
        let Some(psi_max) = self.blocks.field_weakening.ellipse_flux(vdc, omega) else {
            return i;
        };
        let m = &self.config.machine;
        let mut warm = self.saturated_warm;
        let mut flux = |i: Dq<T>| match &self.resolved.saturated {
            Some(s) => {
                let psi = s.flux_from(i, warm.prediction(i));
                warm = warm.moved(i, psi);
                psi
            }
            None => Dq::new(m.flux_linkage + m.ld * i.d, m.lq * i.q),
        };
        let limit_sq = psi_max * psi_max;
        let mut iq = i.q;
        for _ in 0..ELLIPSE_STEPS {
            let psi = flux(Dq::new(i.d, iq));
            // Inside the ellipse, or a non-finite flux (NaN compares false): no cut.
            let outside = psi.d * psi.d + psi.q * psi.q > limit_sq;
            if !outside || psi.q == T::zero() {
                break;
            }
            let room = (limit_sq - psi.d * psi.d).step_max(T::zero());
            iq = iq * room.step_sqrt() / psi.q.abs();
        }
        if iq.is_finite() { Dq::new(i.d, iq) } else { i }
    }
}
