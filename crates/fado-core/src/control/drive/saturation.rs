//! The drive's hooks for a saturating magnetic model (`crate::control::saturated_references`):
//! the currents for a torque, the speed loop's torque limit and the current loop's
//! inductances. With constant inductances each returns what the closed forms give.

use core::cell::Cell;

use super::{DriveConfig, SensorlessDrive};
use crate::control::saturated_references::SaturatedReferences;
use crate::control::speed_controller::SpeedControllerConfig;
use crate::estimator::RotorAngleEstimator;
use crate::magnetics::FluxWarmStart;
use crate::{Dq, Real};

impl<T: Real> DriveConfig<T> {
    /// The saturating model's references up to the current limit; None for constant
    /// inductances.
    pub(super) fn saturated_references(&self) -> Option<SaturatedReferences<T>> {
        SaturatedReferences::new(&self.machine, self.i_max())
    }

    /// The speed PI's output limit (a torque in units of the magnet's q current): the
    /// model's torque at the current limit on the MTPA curve (on the q axis without MTPA), or
    /// [`SpeedControllerConfig::torque_limit`] for constant inductances (`saturated`: the
    /// model's references, built once per drive).
    pub(super) fn speed_torque_limit(
        &self,
        saturated: Option<&SaturatedReferences<T>>,
        mtpa: bool,
    ) -> T {
        let m = &self.machine;
        let i_max = self.tuning.current.limit_ratio * m.rated_current;
        match saturated {
            Some(s) if mtpa => s.torque_limit(i_max, m.flux_linkage),
            Some(s) => s.torque_flux(Dq::new(T::zero(), i_max)) / m.flux_linkage,
            None => SpeedControllerConfig::torque_limit(m, i_max, mtpa),
        }
    }

    /// The current loop's (L̂d, L̂q): a saturating model's incremental inductances at the
    /// rated MTPA point (from its references `saturated`), else the machine model's.
    pub(super) fn current_loop_inductances(
        &self,
        saturated: Option<&SaturatedReferences<T>>,
    ) -> (T, T) {
        match saturated {
            Some(s) => s.rated_incremental(self.machine.rated_current),
            None => (self.machine.ld, self.machine.lq),
        }
    }
}

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// `currents_for_torque` with a saturating model: i_d* = the injection + the model's MTPA
    /// (with `mtpa` on) + `probe_id`, and i_q* solves ψd·i_q* − ψq·i_d* = λ̂f·i_q,t (the
    /// co-energy torque, `crate::control::saturated_references`) by the same three Newton
    /// steps, ended early by a step below `TORQUE_SETTLED` of the rated current, the slope from the model's incremental inductance (one flux solve per step, the
    /// secant's slope to O(h)). Each evaluation's ψ(i) starts from the last one's first-order
    /// prediction, the first from the model's flux at the last sample's reference
    /// (`saturated_warm`); returns the currents, the flux of the last evaluation, the warm
    /// start there (the next sample's) and the current it was evaluated at.
    pub(super) fn saturated_currents_for_torque(
        &self,
        s: &SaturatedReferences<T>,
        iq_torque: T,
        guess: T,
        probe_id: T,
    ) -> (Dq<T>, Dq<T>, FluxWarmStart<T>, Dq<T>) {
        let m = &self.config.machine;
        let injection = &self.blocks.injection;
        let mtpa = self.config.tuning.mtpa.enabled;
        let id_of = |iq: T| {
            let id = injection.step(iq) + probe_id;
            if mtpa { id + s.mtpa_id(iq) } else { id }
        };
        let target = m.flux_linkage * iq_torque;
        let h = T::lit(1e-3) * m.rated_current;
        let last = Cell::new((
            self.saturated_flux,
            self.saturated_warm,
            self.saturated_point,
        ));
        let f = |iq: T| {
            let i = Dq::new(id_of(iq), iq);
            let (_, mut warm, _) = last.get();
            let (tau, slope, psi) = s.torque_flux_slope(i, (id_of(iq + h) - i.d) / h, &mut warm);
            last.set((psi, warm, i));
            (tau - target, slope)
        };
        let settled = T::lit(super::references::TORQUE_SETTLED) * m.rated_current;
        let limits = (m.rated_current, m.flux_linkage);
        let iq = Self::solve_torque_with(f, iq_torque, guess, limits, settled);
        let (psi, warm, at) = last.get();
        (Dq::new(id_of(iq), iq), psi, warm, at)
    }

    /// A saturating model's flux at zero current and the warm start there (the torque
    /// solve's first); zero and empty for constant inductances.
    pub(super) fn zero_current_warm_start(&self) -> (Dq<T>, FluxWarmStart<T>) {
        match &self.resolved.saturated {
            Some(s) => s.warm_start(Dq::zero()),
            None => (Dq::zero(), FluxWarmStart::empty()),
        }
    }
}
