//! A loaded rotor near zero speed: no phase current left inside the inverter's dead-time band.
//!
//! # Why
//! Under a load at low speed the current vector turns slowly in the stator frame, and once per
//! sixth of an electrical revolution one phase current passes through zero. While it is within
//! the edge band I_b = Ic + ΔI of [`release_current`](crate::control::release_current) (the
//! band Ic plus the PWM ripple ΔI = (4/3)·Vdc·Td/L̂min that the other poles' edges drive before
//! its own), that phase's voltage error is set by the current at each switching edge, which
//! the ripple moves across zero: it depends on the duty cycles, the rotor's position through
//! the inductance the ripple sees, and no compensation predicts it. The error is up to the
//! whole dead-time voltage Td·fs·Vdc along that phase's axis. Near zero speed the estimator
//! integrates it as flux: its part across λ̂r turns λ̂r as a back-EMF would, so the rotor can
//! run at the speed whose back-EMF it cancels without the estimate seeing it. On a motor whose
//! back-EMF at low speed is small against that voltage the rotor then runs away: a 32-pole
//! 150 r/min torque motor on a 560 V link (Td·fs·Vdc = 6.7 V against λf·ω = 0.33 V per
//! r/min), stopped under 65 % of its rated torque with phase c at −0.4 A (I_b = 0.67 A), saw
//! an integrand error grow to 1.3 V while the rotor rolled back to −5 r/min with ω̂ at zero,
//! and lost 0.29 rad (`stops`, every seed). Outside the band the error is V̂·sign(i) whatever
//! the ripple, and the compensation cancels it.
//!
//! # The rule
//! In limiter mode (the estimator's near-zero-speed regime) the drive shifts its d reference
//! so that the phase nearest zero carries at least I_b, on the side it came from: with θ̂ the
//! estimated angle and φx the phase's axis, the phase current of the reference is
//! i_x = i_d·cos(θ̂ − φx) − i_q·sin(θ̂ − φx), and Δi_d = (s_x·I_b − i_x)/cos(θ̂ − φx) with s_x the
//! sign i_x last had outside the band (a hysteresis of 2·I_b: the phase crosses the band in
//! one step when the unshifted reference reaches the other side, and never dwells in it). A d
//! current changes the torque only through the reluctance term (L̂d − L̂q)·Δi_d·i_q, which the
//! speed loop takes up. The shift is at most [`CAP_RATIO`] × the rated current, and only
//! where the phase's axis is within 60° of d (|cos(θ̂ − φx)| ≥ ½; else the current vector is
//! near d, the no-load regime of the eq. (23) injection, which this rule does not serve).
//! Only where ΔI exceeds Ic, as the release's floor: a ripple inside the band leaves each
//! edge's current where the compensation's band model puts it.
//!
//! # Where
//! Only on a machine whose dead-time voltage Td·fs·Vdc is at least [`MIN_VOLTAGE_RATIO`] of
//! its rated back-EMF λ̂f·ω_rated: the speed whose back-EMF the band's error can cancel is then
//! beyond the ±6 % of the rated speed of the low-speed scenarios. The torque motor above has
//! 0.21 (6.7 V against 32.7 V), the 50 kW IPMSM preset 0.21 (13 V against 62 V); the paper's
//! motor 0.07, every other preset and made-up test machine 0.01–0.06, and their drives are
//! unchanged to the bit.

use crate::control::dead_time_compensation::DeadTimeCompensationConfig;
use crate::control::release_current::ReleaseCurrent;
use crate::{Dq, MachineModel, Real};

/// The largest d shift, a fraction of the rated current: 0.1 \[A\], several times the edge
/// band on the machines where the rule acts (I_b = 0.67 A, 6 A on the torque motor above).
pub const CAP_RATIO: f64 = 0.1;

/// The smallest ratio Td·fs·Vdc/(λ̂f·ω_rated) at which the rule acts: 0.1 \[A\] (module docs,
/// "Where": between the paper's motor, 0.07, and the machines that need it, 0.21).
pub const MIN_VOLTAGE_RATIO: f64 = 0.1;

/// The phase-band shift's state (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseBand<T> {
    rule: ReleaseCurrent<T>,
    /// The machine's dead-time voltage is at least [`MIN_VOLTAGE_RATIO`] of its rated
    /// back-EMF (module docs, "Where").
    enabled: bool,
    /// [`CAP_RATIO`] × the rated current (A).
    cap: T,
    /// The sign each phase's reference current last had outside the band (0: none yet).
    side: [T; 3],
}

impl<T: Real> PhaseBand<T> {
    /// The rule for `machine` on the inverter of the dead-time compensation `config` (dead
    /// time, switching frequency, band) at the machine's DC-link voltage.
    pub fn new(machine: &MachineModel<T>, config: &DeadTimeCompensationConfig<T>) -> Self {
        let dead_time_voltage = config.dead_time * config.switching_frequency * machine.dc_voltage;
        let rated_emf = machine.flux_linkage * machine.rated_speed();
        // NaN compares false: off.
        let enabled = dead_time_voltage >= T::lit(MIN_VOLTAGE_RATIO) * rated_emf;
        Self {
            rule: ReleaseCurrent::for_inverter(machine, config),
            enabled,
            cap: T::lit(CAP_RATIO) * machine.rated_current,
            side: [T::zero(); 3],
        }
    }

    /// The release's d-current floor of the same inverter (the edge band's rule).
    pub fn release_current(&self) -> &ReleaseCurrent<T> {
        &self.rule
    }

    /// Forgets the phases' sides.
    pub fn reset(&mut self) {
        self.side = [T::zero(); 3];
    }

    /// `i` with its d current shifted so that no phase current lies inside the edge band at
    /// the estimated angle `theta` (module docs) while `active`; `i` itself (and the sides
    /// forgotten) otherwise or where the ripple stays within the band.
    pub fn shift(&mut self, i: Dq<T>, theta: T, vdc: T, active: bool) -> Dq<T> {
        if !self.enabled {
            return i;
        }
        if !active || !self.rule.ripple_beyond_band(vdc) {
            self.reset();
            return i;
        }
        let need = self.rule.edge_band(vdc);
        let (s, c) = theta.step_sin_cos_any();
        let k3 = T::lit(0.866_025_403_784_438_6);
        let h = T::lit(0.5);
        // cos and sin of θ − φ for φ = 0, 2π/3, −2π/3.
        let cos = [c, -h * c + k3 * s, -h * c - k3 * s];
        let sin = [s, -h * s - k3 * c, -h * s + k3 * c];
        let mut shift = T::zero();
        let mut nearest = T::lit(f64::INFINITY);
        for x in 0..3 {
            let ix = i.d * cos[x] - i.q * sin[x];
            if ix.abs() > need {
                self.side[x] = if ix > T::zero() { T::one() } else { -T::one() };
            } else if ix.abs() < nearest && cos[x].abs() >= h {
                nearest = ix.abs();
                if self.side[x] == T::zero() {
                    self.side[x] = if ix < T::zero() { -T::one() } else { T::one() };
                }
                shift = (self.side[x] * need - ix) / cos[x];
            }
        }
        let shift = shift.step_max(-self.cap).step_min(self.cap);
        Dq::new(i.d + shift, i.q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The made-up 32-pole torque motor of the module docs on its 560 V, 8 kHz inverter
    /// (Td 1.5 µs, Ic 0.3 A).
    fn torque_motor() -> (MachineModel<f64>, DeadTimeCompensationConfig<f64>) {
        let m = MachineModel {
            rs: 0.15,
            ld: 3e-3,
            lq: 6e-3,
            flux_linkage: 0.13,
            pole_pairs: 16,
            rated_current: 60.0,
            rated_torque: 200.0,
            rated_speed_rpm: 150.0,
            inertia: 0.5,
            dc_voltage: 560.0,
            ..MachineModel::paper()
        };
        let c = DeadTimeCompensationConfig {
            dead_time: 1.5e-6,
            switching_frequency: 8000.0,
            current_band: 0.3,
            ..DeadTimeCompensationConfig::for_machine(&m)
        };
        (m, c)
    }

    fn phases(i: Dq<f64>, theta: f64) -> [f64; 3] {
        let third = core::f64::consts::TAU / 3.0;
        [0.0, third, -third].map(|phi| i.d * (theta - phi).cos() - i.q * (theta - phi).sin())
    }

    /// Turning the loaded current vector through a whole revolution in small steps: in
    /// limiter mode no phase current of the shifted reference is ever inside the edge band
    /// (I_b = 0.673 A), each crossing happens in one step, and q is untouched; outside limiter
    /// mode, and on the paper's motor (Td·fs·Vdc/(λ̂f·ω_rated) = 0.07), nothing changes.
    #[test]
    fn no_phase_current_dwells_in_the_band() {
        let (m, c) = torque_motor();
        let mut band = PhaseBand::new(&m, &c);
        let need = band.rule.edge_band(560.0);
        assert!((need - (0.3 + 4.0 / 3.0 * 560.0 * 1.5e-6 / 3e-3)).abs() < 1e-12);
        let i = Dq::new(-16.0, 31.0);
        let mut shifts = 0;
        for k in 0..=36_000 {
            let theta = -core::f64::consts::PI + k as f64 * core::f64::consts::TAU / 36_000.0;
            let out = band.shift(i, theta, 560.0, true);
            assert_eq!(out.q, i.q);
            assert!((out.d - i.d).abs() <= 6.0 + 1e-9, "{theta}: {}", out.d);
            if out.d != i.d {
                shifts += 1;
            }
            for p in phases(out, theta) {
                assert!(p.abs() >= need - 1e-9, "{theta}: {p}");
            }
            assert_eq!(band.shift(i, theta, 560.0, false), i);
        }
        // Six band crossings per revolution, each held over ±I_b of the phase's travel.
        assert!(shifts > 0 && shifts < 36_000 / 10, "{shifts}");
        let paper = MachineModel::<f64>::paper();
        let mut off = PhaseBand::new(&paper, &DeadTimeCompensationConfig::for_machine(&paper));
        for theta in [0.0, 0.5, 1.0, core::f64::consts::FRAC_PI_2] {
            let i = Dq::new(0.0, 0.1);
            assert_eq!(off.shift(i, theta, 311.0, true), i);
        }
    }
}
