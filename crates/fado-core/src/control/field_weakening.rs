//! Field weakening and the maximum-torque-per-volt limit: operation above the speed at which
//! the back-EMF meets the inverter's voltage.
//!
//! **Why feedback.** The d current that keeps the voltage inside the limit can be computed
//! from the model (a feed-forward from λ̂f, L̂d, L̂q, R̂s and the measured bus) or found by
//! closing a loop on the voltage the current controller asks for (a voltage-margin feedback,
//! Kim & Sul, IEEE TIA 1997). fado uses the feedback: the voltage reference already contains
//! every error of the model (a λ̂f or L̂d off by 10 % moves the model's weakening speed by
//! as much, saturation moves L̂d with the current, the dead time and the devices' drops eat
//! volts the model does not see), and the loop needs no parameter but the sign of dV/di_d.
//! The model serves as the bound: the d current stops at the characteristic current
//! −λ̂f/L̂d (beyond it more −i_d lowers the torque: the maximum-torque-per-volt (MTPV)
//! boundary of a surface-magnet rotor, a conservative one of an interior-magnet rotor), and
//! there the q current is cut to what the voltage ellipse allows:
//! `|i_q| ≤ √((V/ω̂)² − (λ̂f + L̂d·i_d)²) / L̂q`.
//!
//! **Loop.** Once per sample, with the magnitude |v*| of the current controller's reference
//! and the measured bus v_dc: `Δi_d ← min(0, max(i_d,min, Δi_d + Ts·K·(m·v_dc/√3 − |v*|)))`,
//! with the usable fraction m (`voltage_margin`) of the hexagon's inscribed circle, and a
//! gain `K = 2π·f_fw / (|ω̂|·L̂d)` that gives the loop the bandwidth f_fw
//! (`bandwidth_hz`) at every speed (the voltage moves by ω̂·L̂d per ampere of i_d). Δi_d is
//! added to the d reference before the torque is solved for, so that a salient rotor's
//! reluctance torque is accounted for. Below the weakening speed the integrator sits at
//! zero and the drive is unchanged to the bit.

use crate::Real;
use crate::error::{ConfigError, check};
use crate::machine::MachineModel;
use crate::real::cast_record;

/// `[controller.field_weakening]`: the voltage-margin loop.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(
        deny_unknown_fields,
        default,
        bound(
            serialize = "T: serde::Serialize",
            deserialize = "T: Real + serde::Deserialize<'de>"
        )
    )
)]
pub struct FieldWeakeningTuning<T> {
    /// Weaken the field at the voltage limit. Default true.
    pub enabled: bool,
    /// Usable fraction of the inscribed circle Vdc/√3 the loop holds |v*| to. Default 0.92
    /// \[A\] (8 % left for the current loop's transients and the dead-time compensation).
    /// Above 1 (up to six-step's 2√3/π ≈ 1.10,
    /// [`SIX_STEP_MARGIN`](crate::control::modulation::SIX_STEP_MARGIN)) only with the
    /// drive's `voltage_limit = "overmodulation"`.
    pub voltage_margin: T,
    /// Bandwidth of the loop, Hz. Default 30 Hz \[A\] (a tenth of the 250 Hz current loop,
    /// well above the speed loop's 5 Hz).
    pub bandwidth_hz: T,
    /// Cut the q current to the voltage ellipse at the MTPV bound. Default true.
    pub mtpv: bool,
}

impl<T: Real> Default for FieldWeakeningTuning<T> {
    fn default() -> Self {
        Self {
            enabled: true,
            voltage_margin: T::lit(0.92),
            bandwidth_hz: T::lit(30.0),
            mtpv: true,
        }
    }
}

cast_record!(FieldWeakeningTuning { voltage_margin, bandwidth_hz ; enabled, mtpv });

/// The field-weakening loop's state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldWeakening<T> {
    enabled: bool,
    mtpv: bool,
    /// Ts·2π·f_fw / L̂d.
    gain: T,
    /// m/√3.
    margin: T,
    /// The d current's bound, A (≤ 0): the characteristic current or −I_max.
    id_min: T,
    /// Speed floor of the gain, rad/s.
    min_speed: T,
    flux: T,
    ld: T,
    lq: T,
    /// Δi_d, A (≤ 0).
    delta_id: T,
}

impl<T: Real> FieldWeakening<T> {
    /// The loop for `machine` with the current limit `i_max` (A) sampled every `ts`.
    pub fn new(
        t: &FieldWeakeningTuning<T>,
        machine: &MachineModel<T>,
        i_max: T,
        ts: T,
    ) -> Result<Self, ConfigError> {
        let m = check::positive("field_weakening.voltage_margin", t.voltage_margin)?;
        if m > T::lit(crate::control::modulation::SIX_STEP_MARGIN) {
            return Err(ConfigError::OutOfRange {
                field: "field_weakening.voltage_margin",
                expected: "at most 2√3/π ≈ 1.1027 (six-step)",
            });
        }
        let f = check::positive("field_weakening.bandwidth_hz", t.bandwidth_hz)?;
        let characteristic = machine.flux_linkage / machine.ld;
        Ok(Self {
            enabled: t.enabled,
            mtpv: t.mtpv,
            gain: ts * T::two_pi() * f / machine.ld,
            margin: m / T::lit(3.0).sqrt(),
            id_min: -characteristic.step_min(i_max),
            min_speed: T::lit(0.1) * machine.rated_speed(),
            flux: machine.flux_linkage,
            ld: machine.ld,
            lq: machine.lq,
            delta_id: T::zero(),
        })
    }

    /// Δi_d to add to the d reference now, A (≤ 0; 0 below the weakening speed).
    #[inline]
    pub fn delta_id(&self) -> T {
        self.delta_id
    }

    /// One sample of the loop with the current controller's reference `v_ref_squared` = |v*|²
    /// (V²), the measured bus `vdc` (V) and the speed `omega` (rad/s, electrical). Below the
    /// weakening speed the squares are compared, so the idle loop takes no square root.
    #[inline]
    pub fn update(&mut self, v_ref_squared: T, vdc: T, omega: T) {
        if !(self.enabled && v_ref_squared.is_finite() && vdc.is_finite() && omega.is_finite()) {
            return;
        }
        let limit = self.margin * vdc;
        if self.delta_id == T::zero() && limit >= T::zero() && v_ref_squared <= limit * limit {
            return; // below the weakening speed: nothing to integrate
        }
        let error = limit - v_ref_squared.step_sqrt();
        if error >= T::zero() && self.delta_id == T::zero() {
            return; // below the weakening speed: nothing to integrate
        }
        let w = omega.abs().step_max(self.min_speed);
        let next = self.delta_id + self.gain * error / w;
        self.delta_id = next.step_min(T::zero()).step_max(self.id_min);
    }

    /// The q current allowed by the voltage ellipse at the d current `id` (A) and speed
    /// `omega`, for the bus `vdc`; +∞ unless the loop sits at its MTPV bound.
    #[inline]
    pub fn iq_limit(&self, id: T, vdc: T, omega: T) -> T {
        let at_bound = self.delta_id <= self.id_min * T::lit(0.999);
        if !(self.mtpv && at_bound && self.enabled) {
            return T::lit(f64::INFINITY);
        }
        let w = omega.abs().step_max(self.min_speed);
        let psi = self.margin * vdc / w;
        let psi_d = self.flux + self.ld * id;
        let room = (psi * psi - psi_d * psi_d).step_max(T::zero());
        room.step_sqrt() / self.lq
    }

    /// The largest stator flux the voltage allows at the speed `omega` (rad/s, electrical) on
    /// the bus `vdc`, Wb: the hexagon's inscribed circle Vdc/√3 (or the loop's own target
    /// above it, with overmodulation) over |ω̂|; None below the weakening speed (the loop at
    /// zero), with the loop or its MTPV limit switched off. The drive cuts the q current to
    /// it ([`crate::control::drive`], the voltage ellipse): the loop moves i_d only, and
    /// where the q flux alone reaches the voltage (a synchronous-reluctance rotor,
    /// L_q·I_max > V/ω) no d current brings the voltage back.
    #[inline]
    pub fn ellipse_flux(&self, vdc: T, omega: T) -> Option<T> {
        if !(self.enabled && self.mtpv && self.delta_id < T::zero()) {
            return None;
        }
        let inscribed = T::one() / T::lit(3.0).sqrt();
        let w = omega.abs().step_max(self.min_speed);
        Some(self.margin.step_max(inscribed) * vdc / w)
    }

    /// Back to no weakening.
    pub fn reset(&mut self) {
        self.delta_id = T::zero();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fw() -> (FieldWeakening<f64>, MachineModel<f64>) {
        let m = MachineModel::<f64>::paper();
        (
            FieldWeakening::new(&FieldWeakeningTuning::default(), &m, 40.0, 1e-4).unwrap(),
            m,
        )
    }

    #[test]
    fn idle_below_the_voltage_limit() {
        let (mut f, m) = fw();
        for _ in 0..1000 {
            f.update(100.0 * 100.0, m.dc_voltage, 300.0);
        }
        assert_eq!(f.delta_id(), 0.0);
        assert_eq!(f.iq_limit(0.0, m.dc_voltage, 300.0), f64::INFINITY);
    }

    #[test]
    fn loop_finds_the_d_current_of_the_voltage_limit() {
        // A surface-magnet motor at 1.5× its corner: |v| = ω·|λf + L·(id + Δ)| (no load, R
        // neglected) must come to m·Vdc/√3.
        let (mut f, m) = fw();
        let vdc = m.dc_voltage;
        let target = 0.92 * vdc / 3f64.sqrt();
        let w = 1.5 * target / m.flux_linkage;
        let mut v = 0.0;
        for _ in 0..5000 {
            v = w * (m.flux_linkage + m.ld * f.delta_id()).abs();
            f.update(v * v, vdc, w);
        }
        assert!((v - target).abs() < 1e-3 * target, "{v} vs {target}");
        let expected = (target / w - m.flux_linkage) / m.ld;
        assert!((f.delta_id() - expected).abs() < 1e-2, "{}", f.delta_id());
        // 30 Hz: within 2 % of the final value after 4 time constants of 5.3 ms.
        let (mut g, _) = fw();
        for _ in 0..212 {
            let v = w * (m.flux_linkage + m.ld * g.delta_id()).abs();
            g.update(v * v, vdc, w);
        }
        assert!(
            (g.delta_id() - expected).abs() < 0.03 * expected.abs(),
            "{}",
            g.delta_id()
        );
    }

    #[test]
    fn mtpv_bound_and_voltage_ellipse() {
        let (mut f, m) = fw();
        let vdc = m.dc_voltage;
        let w = 20.0 * vdc / m.flux_linkage; // far beyond what the voltage allows
        for _ in 0..20_000 {
            f.update(4.0 * vdc * vdc, vdc, w);
        }
        // Stops at the characteristic current λf/Ld = 33.5 A (below the 40 A limit).
        let ich = m.flux_linkage / m.ld;
        assert!((f.delta_id() + ich).abs() < 1e-9, "{}", f.delta_id());
        // There the q current is what the ellipse allows: (V/ω)/Lq at id = −λf/Ld.
        let iq = f.iq_limit(-ich, vdc, w);
        let psi = 0.92 * vdc / 3f64.sqrt() / w;
        assert!((iq - psi / m.lq).abs() < 1e-9, "{iq}");
        f.reset();
        assert_eq!(f.delta_id(), 0.0);
    }

    #[test]
    fn ellipse_flux_is_the_inscribed_circle_over_the_speed_while_weakening() {
        let (mut f, m) = fw();
        let (vdc, w) = (m.dc_voltage, 1000.0);
        assert_eq!(f.ellipse_flux(vdc, w), None);
        f.update(4.0 * vdc * vdc, vdc, w);
        let psi = f.ellipse_flux(vdc, w).unwrap();
        assert!((psi - vdc / 3f64.sqrt() / w).abs() < 1e-12, "{psi}");
        // The loop's own target above the inscribed circle (overmodulation) is the bound.
        let t = FieldWeakeningTuning {
            voltage_margin: 1.08,
            ..FieldWeakeningTuning::default()
        };
        let mut g = FieldWeakening::new(&t, &m, 40.0, 1e-4).unwrap();
        g.update(4.0 * vdc * vdc, vdc, w);
        let psi = g.ellipse_flux(vdc, w).unwrap();
        assert!((psi - 1.08 * vdc / 3f64.sqrt() / w).abs() < 1e-12, "{psi}");
        let off = FieldWeakeningTuning {
            mtpv: false,
            ..FieldWeakeningTuning::default()
        };
        let mut h = FieldWeakening::new(&off, &m, 40.0, 1e-4).unwrap();
        h.update(4.0 * vdc * vdc, vdc, w);
        assert_eq!(h.ellipse_flux(vdc, w), None);
    }
}
