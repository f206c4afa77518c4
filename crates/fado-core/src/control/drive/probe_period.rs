//! The loaded-standstill probe's period from the speed estimate's answer to the probe's own
//! d step: long enough that the reading's inertia term sees the rotor, not the estimator.
//!
//! **Why.** The probe ([`crate::control::standstill_probe`]) reads the torque balance with
//! the rotor's acceleration removed, c_J·dω̂/dt, c_J = Ĵ/(1.5·p²·λ̂f), over the second half of
//! each half-period (a quarter period after each step, an eighth after its ramp ends). On a
//! salient rotor the d step moves the active flux by (L̂q − L̂d)·Δi_d, and the estimate's angle
//! answers it with a step proportional to the angle error δ itself: measured on
//! pmsyrm-baldor-5k6 and on its constant-inductance twin at a loaded standstill, θ̂ steps by
//! about a quarter of δ for a 15 % change of |λ̂r| (docs/range.md). The speed tracker T2S-2
//! turns that step into a ω̂ pulse that decays with its envelope e^(−σ·t), σ = ζ·ωn, and the
//! inertia term carries what is left of it into the reading. Relative to the probe's signal
//! (the torque error A·λ̂a·δ/λ̂f, in units of the magnet's q current) the pulse's part scales
//! as x·e^(−σ·T_p/8) with
//!
//! x = c_J·(L̂q − L̂d)·σ²/λ̂f,
//!
//! (the step's size ∝ (L̂q − L̂d)·A·δ/λ̂a, the pulse's height ∝ σ² times it, the inertia term
//! ∝ c_J; A and δ cancel, so neither the amplitude nor the angle changes the ratio). x is 25
//! on pmsyrm-baldor-5k6 (Ĵ = 0.05 kg·m², L̂q − L̂d = 0.12 H), 28 on its measured map, at most
//! 3.1 on the other presets (ipmsm-gem-50k) and 0 on a round rotor.
//!
//! **Rule.** The period is lengthened until the pulse's part is bounded:
//! T_p ≥ (8/σ)·ln(x/[`MAX_RESIDUE`]), with the bound x·e^(−σ·T_p/8) ≤ 1.4 measured on the
//! rotor where the loop is closest to losing its sign, a drawn 140 kW IPMSM of 23.3 kg·m²
//! (`fado-sim/tests/data/drawn/ipm-5p-800v-140kw.toml`: 5 pole pairs, L̂q − L̂d = 1.87 mH,
//! λ̂f = 1.17 Wb, x = 4.83). There the pulse's part of the reading is 3.5–3.9 times the signal at
//! the default 0.1 s (x·e^(−σ·T_p/8) = 1.88): reconstructed from `traces.csv` over `fullrange`'s
//! loaded standstill, the reading is −3 × δ with ω̂ and +1.0 × δ with the rotor's true speed, θ̂
//! is turned away from the rotor and |θ − θ̂| doubles every 0.1 s (0.64 rad in `fullrange`, 0.48
//! in `regen-stop`). Swept over the period (gain scaled, g·T_p kept): 0.11 s leaves 0.107 /
//! 0.050 rad (x·e^(−σ·T_p/8) = 1.73), 0.12 s 0.029 / 0.023 (1.56), 0.13 s and longer 0.020 /
//! 0.023 (1.41). The same proportion on pmsyrm-baldor-5k6 is about 2 at x·e^(−σ·T_p/8) = 9.8
//! (the reading −1 × δ at 0.1 s): x's model orders the rotors but misses a factor of about ten
//! between the two, so the bound takes the stricter of them, the heavy rotor's. The gain keeps
//! g·T_p (the correction loop's triple pole per period). On the presets: pmsyrm-baldor-5k6
//! 0.306 s, its measured map 0.316 s; every other preset (at most x = 3.13, ipmsm-gem-50k:
//! 0.085 s) and every made-up test machine below x = 4 keeps 0.1 s, to the bit.

use crate::Real;
use crate::control::DriveTuning;
use crate::estimator::EstimatorTuning;
use crate::machine::MachineModel;
use crate::tracker::TrackerConfig;

/// The largest x·e^(−σ·T_p/8) the rule leaves (module docs): measured on a drawn 140 kW IPMSM,
/// whose loaded standstill loses the rotor at 1.73 and holds it within 0.03 rad from 1.56 on \[A\].
pub const MAX_RESIDUE: f64 = 1.4;

/// x = c_J·(L̂q − L̂d)·σ²/λ̂f (module docs) for the machine and the speed tracker's envelope
/// decay rate `sigma` (s⁻¹); 0 on a rotor without L̂q > L̂d.
pub fn response_ratio<T: Real>(machine: &MachineModel<T>, sigma: T) -> T {
    let m = machine;
    let p = T::lit(m.pole_pairs as f64);
    let c_j = m.inertia / (T::lit(1.5) * p * p * m.flux_linkage);
    let saliency = crate::real::max(m.lq - m.ld, T::zero());
    c_j * saliency * sigma * sigma / m.flux_linkage
}

/// The shortest period (s) at which the estimate's answer to the probe's d step leaves at most
/// [`MAX_RESIDUE`] in the reading: (8/σ)·ln(x/[`MAX_RESIDUE`]), 0 where x is below it or not
/// finite (no bound).
pub fn required_period<T: Real>(machine: &MachineModel<T>, sigma: T) -> T {
    let x = response_ratio(machine, sigma) / T::lit(MAX_RESIDUE);
    if x.is_finite() && sigma > T::zero() && x > T::one() {
        T::lit(8.0) * x.ln() / sigma
    } else {
        T::zero()
    }
}

/// Applies the rule (module docs) to the drive's tuning, in place: lengthens the probe's
/// period to [`required_period`] for T2S-2's envelope decay rate ζ·ωn where it is shorter,
/// and scales the gain by the same ratio (g·T_p kept). Below it the tuning is unchanged.
pub fn apply<T: Real>(
    machine: &MachineModel<T>,
    drive: &mut DriveTuning<T>,
    estimator: &EstimatorTuning<T>,
    ts: T,
) {
    let t = &estimator.tracker;
    let tracker = TrackerConfig {
        ts,
        bandwidth_hz: t.t2s2_bandwidth_hz,
        damping: t.damping,
        definition: t.bandwidth_definition,
    };
    // Kp = 2·ζ·ωn of the type-2 loop: σ = Kp/2.
    let sigma = tracker.gains().0 * T::lit(0.5);
    let required = required_period(machine, sigma);
    let probe = &mut drive.standstill_probe;
    let own = probe.period;
    if required > own && own > T::zero() {
        probe.gain = probe.gain * own / required;
        probe.period = required;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::MachineModel;

    fn machine(ld: f64, lq: f64, flux: f64, inertia: f64, p: u32) -> MachineModel<f64> {
        let mut m = MachineModel::paper();
        m.ld = ld;
        m.lq = lq;
        m.flux_linkage = flux;
        m.inertia = inertia;
        m.pole_pairs = p;
        m
    }

    /// The rule's figures on five rotors (module docs): the Baldor PM-SyRM gets 0.306 s, the
    /// drawn 140 kW IPMSM 0.131 s; a round rotor, the 2.2 kW IPMSM and the 50 kW IPMSM keep the
    /// default 0.1 s; the bound then leaves exactly MAX_RESIDUE, and the gain keeps g·T_p.
    #[test]
    fn the_period_bound_singles_out_a_heavy_strongly_salient_rotor() {
        let sigma = 2.0 * core::f64::consts::PI * 35.0 / (2.0 + 5f64.sqrt()).sqrt()
            * core::f64::consts::FRAC_1_SQRT_2;
        let baldor = machine(0.0298, 0.1497, 0.4767, 0.05, 2);
        let x = response_ratio(&baldor, sigma);
        assert!((x - 25.1).abs() < 0.1, "{x}");
        let t = required_period(&baldor, sigma);
        assert!((t - 0.306).abs() < 0.002, "{t}");
        assert!((x * (-sigma * t / 8.0).exp() - MAX_RESIDUE).abs() < 1e-9);
        let gem = machine(0.37e-3, 1.2e-3, 0.066, 0.03883, 3);
        let ipm = machine(0.036, 0.051, 0.545, 0.015, 3);
        let round = machine(2.63e-3, 2.63e-3, 0.088, 0.012, 4);
        for m in [gem, ipm, round] {
            assert!(response_ratio(&m, sigma) < 3.2);
            assert!(required_period(&m, sigma) < 0.09);
        }
        let heavy = machine(1.31879e-3, 3.18787e-3, 1.17081, 23.2755, 5);
        let x_heavy = response_ratio(&heavy, sigma);
        assert!((x_heavy - 4.83).abs() < 0.01, "{x_heavy}");
        let t_heavy = required_period(&heavy, sigma);
        assert!((t_heavy - 0.131).abs() < 0.002, "{t_heavy}");
        // Applied to a tuning: period and gain in proportion; the paper's motor unchanged.
        let est = EstimatorTuning::<f64>::default();
        let mut d = DriveTuning::<f64>::default();
        let g_tp = d.standstill_probe.gain * d.standstill_probe.period;
        apply(&baldor, &mut d, &est, 1e-4);
        let sp = &d.standstill_probe;
        assert!((sp.period - t).abs() < 1e-9 && (sp.gain * sp.period - g_tp).abs() < 1e-12);
        let mut d0 = DriveTuning::<f64>::default();
        apply(&round, &mut d0, &est, 1e-4);
        assert_eq!(d0, DriveTuning::<f64>::default());
    }
}
