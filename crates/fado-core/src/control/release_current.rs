//! The d current at the brake's release: no phase current inside the inverter's dead-time
//! band.
//!
//! # Why
//! At the release a rotor at rest carries the start-up's d current along θ̂, and the phase
//! whose axis is nearly perpendicular to it carries almost none. Inside the dead-time band
//! the inverter's voltage error of that phase is set by the current at each switching edge,
//! which the PWM ripple moves by more than the band on a low-inductance machine
//! (`dead_time_compensation`, "Edge currents"): the error then depends on the duty cycles
//! themselves, no compensation predicts it to a tenth of a volt, and a falling rotor's first
//! back-EMF (λf·ω, ≈ 0.1 V after 3 ms on the multirotor preset) is lost in it. The estimator
//! does not see the fall, and the release hold triggers late. Outside the band the error is
//! V̂·sign(i) whatever the ripple, and the compensation cancels it exactly.
//!
//! # The rule
//! The current at a phase's switching edge differs from its sampled value by the ripple that
//! the other poles' edges drive before it. At rest the duty cycles are equal to within the
//! resistive drop, and the poles' edges are apart by at most a dead time each: one pole step,
//! an α-β voltage (2/3)·Vdc, acts for at most Td before each of the two edges of a carrier
//! period, so the edge current is within
//!
//! ΔI = (4/3)·Vdc·Td / L̂min
//!
//! of the sampled current (L̂min the smaller model inductance, the fastest ripple). A phase
//! current above I_b = Ic + ΔI keeps both edges of the period outside the band Ic. While the
//! release hold is armed (from ready until it hands over or its window closes), the drive
//! raises its d reference to I_b / min_x |cos(θ̂ − φx)|, so that every phase carries at least
//! I_b, at most [`CAP_RATIO`] × the rated current. A d current along θ̂ adds no torque on the
//! rotor it is aligned with, and one whose rotor falls away from it pulls it back.
//!
//! Only where ΔI exceeds Ic: a ripple inside the band leaves each edge's current where the
//! compensation's band model puts it, and a larger d current then only costs the model's
//! accuracy (constant inductances against the iron's saturation). Of the presets, the 50 kW
//! and 1.1 kW IPMSMs, the multirotor, the servo and the paper's motor have ΔI > Ic; the
//! hub, cheetah, 2.2 kW IPMSM and PM-SyRM presets do not.
//!
//! # Salient rotors
//! A d current along θ̂ lowers a salient rotor's active flux λf − (L̂q − L̂d)·i_d, the flux
//! whose direction the estimator reads as the rotor's. The cap is at most the current that
//! leaves [`ACTIVE_FLUX_FLOOR`] of λf there. Measured on the 50 kW IPMSM (λf 66 mWb,
//! L̂q − L̂d 0.83 mH, `loaded-start` without a load, seed 2, start angle −1.66 rad): the rated
//! current's cap of 120 A puts 69 A of d current on the rotor at rest, |λ̂r| falls to 7 mWb,
//! the hold triggers on the direct angle's noise and |θ − θ̂| reaches 2.75 rad; capped at
//! 40 A (|λ̂r| 33 mWb) the release passes at rest (|θ − θ̂| 0.007 rad until the rotor turns).
//!
//! Measured (`loaded-start`, seeds 1–4, `crates/fado-sim/tests/multirotor_datasheets.rs`): the
//! start-up results, docs/results/startup.md (`python3 scripts/startup-table.py`).

use crate::control::dead_time_compensation::DeadTimeCompensationConfig;
use crate::{MachineModel, Real};

/// The largest raised d current, a fraction of the rated current: 0.5, the start-up's own
/// alignment current (`StartupTuning::align_current_ratio`'s default), which the drive puts
/// on a rotor at rest anyway. Above it the model's constant inductances meet the d iron's
/// saturation (the multirotor preset under the rated current: backward travel 1.9–5.5 rad).
pub const CAP_RATIO: f64 = 0.5;

/// The share of λf the release's d current leaves in a salient rotor's active flux.
pub const ACTIVE_FLUX_FLOOR: f64 = 0.5;

/// The release's d-current floor (module docs). Stateless.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReleaseCurrent<T> {
    /// Td / L̂min · 4/3 (A per volt of the DC link).
    ripple_per_volt: T,
    /// The inverter's band Ic (A).
    band: T,
    /// [`CAP_RATIO`] × the rated current (A).
    cap: T,
}

impl<T: Real> ReleaseCurrent<T> {
    /// The rule for `machine` on an inverter of dead time `dead_time` (s) and band
    /// `current_band` (A); a non-positive inductance gives the cap at every angle.
    pub fn new(machine: &MachineModel<T>, dead_time: T, current_band: T) -> Self {
        let l_min = crate::real::min(machine.ld, machine.lq);
        let ripple_per_volt = if l_min > T::zero() {
            T::lit(4.0 / 3.0) * dead_time / l_min
        } else {
            T::lit(f64::INFINITY)
        };
        // A d current along θ̂ lowers the active flux λf − (L̂q − L̂d)·i_d of a salient
        // rotor: at most the current that keeps [`ACTIVE_FLUX_FLOOR`] of λf.
        let cap = T::lit(CAP_RATIO) * machine.rated_current;
        let excess = machine.lq - machine.ld;
        let cap = if excess > T::zero() {
            cap.step_min(T::lit(1.0 - ACTIVE_FLUX_FLOOR) * machine.flux_linkage / excess)
        } else {
            cap
        };
        Self {
            ripple_per_volt,
            band: current_band,
            cap,
        }
    }

    /// The rule for `machine` on the inverter of a dead-time compensation's `config` (its
    /// dead time and band).
    pub fn for_inverter(machine: &MachineModel<T>, config: &DeadTimeCompensationConfig<T>) -> Self {
        Self::new(machine, config.dead_time, config.current_band)
    }

    /// I_b = Ic + (4/3)·Vdc·Td/L̂min at DC-link voltage `vdc` (A).
    pub fn edge_band(&self, vdc: T) -> T {
        self.band + self.ripple_per_volt * vdc.step_max(T::zero())
    }

    /// The PWM ripple ΔI at `vdc` exceeds the band Ic (I_b > 2·Ic): where the rule acts
    /// ([`d_current`](Self::d_current) is `Some` exactly then). NaN compares false: no.
    pub fn ripple_beyond_band(&self, vdc: T) -> bool {
        self.edge_band(vdc) > self.band + self.band
    }

    /// The d current (A) that puts every phase at least [`edge_band`](Self::edge_band) away
    /// from zero at the electrical angle `theta`, at most the cap (the cap for a non-finite
    /// angle). None where the ripple ΔI stays within the band Ic: there the compensation's
    /// band model holds at every edge and no floor is needed.
    pub fn d_current(&self, theta: T, vdc: T) -> Option<T> {
        if !self.ripple_beyond_band(vdc) {
            return None;
        }
        let need = self.edge_band(vdc);
        let (s, c) = theta.step_sin_cos_any();
        let k3 = T::lit(0.866_025_403_784_438_6);
        let h = T::lit(0.5);
        // cos(θ − φ) for φ = 0, 2π/3, −2π/3.
        let m = c
            .abs()
            .step_min((-h * c + k3 * s).abs())
            .step_min((-h * c - k3 * s).abs());
        // NaN compares false: the cap.
        Some(if need < self.cap * m {
            need / m
        } else {
            self.cap
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn multirotor() -> MachineModel<f64> {
        MachineModel {
            rs: 0.03,
            ld: 8e-6,
            lq: 8e-6,
            flux_linkage: 8.75e-4,
            pole_pairs: 14,
            rated_current: 34.0,
            ..MachineModel::paper()
        }
    }

    #[test]
    fn every_phase_leaves_the_band_within_the_cap() {
        // The multirotor preset's inverter: Td 0.625 µs, Ic 0.47 A, 22.2 V: ΔI = 2.31 A.
        let r = ReleaseCurrent::new(&multirotor(), 0.625e-6, 0.47);
        let ib = r.edge_band(22.2);
        assert!((ib - (0.47 + 4.0 / 3.0 * 22.2 * 0.625e-6 / 8e-6)).abs() < 1e-12);
        for k in 0..3600 {
            let th = -std::f64::consts::PI + k as f64 * std::f64::consts::TAU / 3600.0;
            let id = r.d_current(th, 22.2).unwrap();
            assert!(id > 0.0 && id <= 17.0 + 1e-9, "{th}: {id}");
            let third = 2.094_395_102_393_195;
            let phases = [th.cos(), (th - third).cos(), (th + third).cos()];
            let least = phases
                .iter()
                .fold(f64::INFINITY, |a, p| a.min((id * p).abs()));
            // At the cap only where the phase nearest zero is within asin(I_b/cap) of it.
            if id < 17.0 - 1e-9 {
                assert!((least - ib).abs() < 1e-9, "{th}: {least}");
            } else {
                assert!(least <= ib + 1e-9, "{th}: {least}");
            }
        }
        // Seed 2's start angle (−1.66 rad): phase a at cos = 0.089 needs the cap (17 A).
        assert_eq!(r.d_current(-1.66, 22.2), Some(17.0));
        assert_eq!(r.d_current(f64::NAN, 22.2), Some(17.0));
        // The paper's motor at 311 V (2.5 µs, 0.3 A, 2.63 mH): ΔI = 0.39 A above the band,
        // I_b = 0.69 A, which 4 A of d current clears wherever the nearest phase is 10° from
        // zero. A 2.2 kW IPMSM's ripple (0.05 A at 8 mH) stays inside its 0.3 A band: no floor.
        let p = ReleaseCurrent::<f64>::new(&MachineModel::paper(), 2.5e-6, 0.3);
        assert!((p.edge_band(311.0) - 0.694).abs() < 1e-3);
        // At θ = 0 phases b and c carry half the d current: 2·I_b.
        assert!((p.d_current(0.0, 311.0).unwrap() - 2.0 * p.edge_band(311.0)).abs() < 1e-12);
        let slow = MachineModel {
            ld: 8e-3,
            lq: 8e-3,
            ..MachineModel::paper()
        };
        let q = ReleaseCurrent::<f64>::new(&slow, 2.5e-6, 0.3);
        assert_eq!(q.d_current(1.57, 311.0), None);
    }

    #[test]
    fn a_salient_rotor_keeps_half_its_active_flux() {
        // The 50 kW IPMSM preset (λf 66 mWb, L̂d 0.37 mH, L̂q 1.2 mH, 240 A, 520 V, Td 2.5 µs,
        // Ic 0.3 A): at −1.66 rad phase a needs I_b/0.089 = 56 A; the rated current's cap
        // 120 A would leave λf − 0.83 mH · 120 A < 0; the cap is 39.8 A.
        let m = MachineModel {
            rs: 0.018,
            ld: 0.37e-3,
            lq: 1.2e-3,
            flux_linkage: 0.066,
            pole_pairs: 3,
            rated_current: 240.0,
            ..MachineModel::paper()
        };
        let r = ReleaseCurrent::<f64>::new(&m, 2.5e-6, 0.3);
        let cap = 0.5 * 0.066 / 0.83e-3;
        let id = r.d_current(-1.66, 520.0).unwrap();
        assert!((id - cap).abs() < 1e-9, "{id} A against {cap} A");
        assert!(0.066 - 0.83e-3 * id >= 0.5 * 0.066 - 1e-12);
    }
}
