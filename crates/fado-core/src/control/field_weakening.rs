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
//!
//! **No weakening where no steady state needs it.** At a speed ω̂ the steady-state voltage
//! of any current within I_max is at most R̂s·I_max + |ω̂|·ψ_max, ψ_max = λ̂f +
//! max(L̂d, L̂q)·I_max (the stator flux's largest magnitude there). Where that stays below
//! the usable voltage m·v_dc/√3, a reference beyond it is the current loop's own transient
//! (L·di/dt of a torque step), which a negative d current cannot relieve: it adds an
//! L̂d·di_d/dt of its own and takes the room of the q current. There the loop only winds
//! back towards zero. On the 5 kW PM-SyRM a release hold's torque step from rest saturated
//! the current loop's voltage, the loop's gain at its speed floor (0.1·ω_rated) drove
//! Δi_d to −33.5 A in four samples, and the limiter (d first) left no q current while the
//! load turned the rotor back (`fado-sim run loaded-start`, `motors/pmsyrm-5k.toml`,
//! `[current_sensor] seed = 2`); the bound is 36 % of its rated speed.

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
    /// The ellipse's voltage per volt of the bus: the inscribed circle 1/√3, or `margin`
    /// above it ([`FieldWeakening::ellipse_flux`]).
    ellipse_ratio: T,
    /// The d current's bound, A (≤ 0): the characteristic current or −I_max.
    id_min: T,
    /// The bound is the characteristic current −λ̂f/L̂d (MTPV), not the current limit −I_max:
    /// only there is the q current cut to the loop's ellipse ([`FieldWeakening::iq_limit`]).
    bound_is_mtpv: bool,
    /// Speed floor of the gain, rad/s.
    min_speed: T,
    /// R̂s·I_max (V) and ψ_max = λ̂f + max(L̂d, L̂q)·I_max (Wb): the largest steady-state
    /// voltage at ω̂ is their R̂s·I_max + |ω̂|·ψ_max (module docs).
    rs_i_max: T,
    psi_max: T,
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
            ellipse_ratio: (m / T::lit(3.0).sqrt()).step_max(T::one() / T::lit(3.0).sqrt()),
            id_min: -characteristic.step_min(i_max),
            bound_is_mtpv: characteristic <= i_max,
            min_speed: T::lit(0.1) * machine.rated_speed(),
            rs_i_max: machine.rs * i_max,
            psi_max: machine.flux_linkage + machine.ld.step_max(machine.lq) * i_max,
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
        if error < T::zero() && self.rs_i_max + omega.abs() * self.psi_max < limit {
            return; // no steady state needs weakening here: a current-loop transient
        }
        let w = omega.abs().step_max(self.min_speed);
        let next = self.delta_id + self.gain * error / w;
        self.delta_id = next.step_min(T::zero()).step_max(self.id_min);
    }

    /// The q current allowed by the voltage ellipse at the d current `id` (A) and speed
    /// `omega`, for the bus `vdc`; +∞ unless the loop sits at its MTPV bound. Where the
    /// current limit bounds the d current first (λ̂f/L̂d > I_max) the loop's bound is no MTPV
    /// point: more torque lies along the current limit (on a salient rotor through the
    /// reluctance term), the current-vector limit and the voltage ellipse at the inscribed
    /// circle ([`FieldWeakening::ellipse_flux`]) bound the q current, and the cut to the loop's
    /// own target would hold it below what the voltage allows: with that cut the 15 kW PM-SyRM
    /// of `crates/fado-sim/tests/data/unseen/pmsrm-15kw-520v.toml` on a 520 V link (λ̂f/L̂d
    /// 145 A, I_max 58.9 A) stays at 4678 of `fullrange`'s 4800 r/min top, its q current at
    /// 3.3 A where the model's optimum has 3.7 A.
    #[inline]
    pub fn iq_limit(&self, id: T, vdc: T, omega: T) -> T {
        let at_bound = self.delta_id <= self.id_min * T::lit(0.999);
        if !(self.mtpv && self.bound_is_mtpv && at_bound && self.enabled) {
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
        let w = omega.abs().step_max(self.min_speed);
        Some(self.ellipse_ratio * vdc / w)
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
    fn no_weakening_where_no_steady_state_needs_it() {
        // The 5 kW PM-SyRM's model (R̂s 0.2 Ω, λ̂f 0.134 Wb, L̂q 17 mH, I_max 40.5 A, 310 V):
        // ψ_max = 0.134 + 0.017·40.5 = 0.82 Wb, the bound ω = (0.92·310/√3 − 0.2·40.5)/ψ_max
        // = 191 rad/s. At rest a torque step's transient asks twice the voltage: nothing
        // is integrated (the loop without the bound: −17.5 A in one sample).
        let mut m = MachineModel::<f64>::paper();
        (m.rs, m.ld, m.lq, m.flux_linkage) = (0.2, 4e-3, 17e-3, 0.134);
        (m.rated_speed_rpm, m.dc_voltage) = (2550.0, 310.0);
        let vdc = m.dc_voltage;
        let i_max = 40.5;
        let mut f = FieldWeakening::new(&FieldWeakeningTuning::default(), &m, i_max, 1e-4).unwrap();
        let v = 2.0 * vdc / 3f64.sqrt();
        let psi_max = 0.134 + 0.017 * i_max;
        let bound = (0.92 * vdc / 3f64.sqrt() - 0.2 * i_max) / psi_max;
        for w in [0.0, 1.0, 0.1 * m.rated_speed(), 0.99 * bound] {
            for _ in 0..100 {
                f.update(v * v, vdc, w);
            }
            assert_eq!(f.delta_id(), 0.0, "at {w} rad/s");
        }
        // Beyond it the loop weakens as before, and below it again the loop winds back
        // (a positive margin) but never further down.
        f.update(v * v, vdc, 1.01 * bound);
        let weakened = f.delta_id();
        assert!(weakened < 0.0);
        f.update(v * v, vdc, 0.5 * bound);
        assert_eq!(f.delta_id(), weakened);
        let low = 0.5 * vdc / 3f64.sqrt();
        f.update(low * low, vdc, 0.5 * bound);
        assert!(f.delta_id() > weakened);
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
    fn a_current_limit_bound_is_no_mtpv_point() {
        let (_, m) = fw();
        // λf/Ld = 33.5 A above a 20 A limit: the loop stops at −20 A, no q cut there.
        let mut f = FieldWeakening::new(&FieldWeakeningTuning::default(), &m, 20.0, 1e-4).unwrap();
        let vdc = m.dc_voltage;
        let w = 20.0 * vdc / m.flux_linkage;
        for _ in 0..20_000 {
            f.update(4.0 * vdc * vdc, vdc, w);
        }
        assert!((f.delta_id() + 20.0).abs() < 1e-9, "{}", f.delta_id());
        assert_eq!(f.iq_limit(-20.0, vdc, w), f64::INFINITY);
        // The voltage ellipse still bounds it.
        assert!(f.ellipse_flux(vdc, w).is_some());
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
