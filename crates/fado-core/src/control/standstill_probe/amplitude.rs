//! The probe's amplitude from the rotor's answer: each period's d-current step A is the
//! largest, up to the configured one, whose swing of the speed estimate stays within half the
//! edge of the estimator's limiter band.
//!
//! **Why.** Held at zero speed, the probe's d-current step is a torque error through the angle
//! error δ, A·sin δ in units of the magnet's q current (module docs of
//! [`crate::control::standstill_probe`], "Torque balance"): the signal the probe reads is a
//! torque that turns the rotor. A heavy rotor does not follow it; a light one does, and a
//! swing of the speed estimate across the edge of the estimator's limiter band (Fig. 3's
//! threshold less its hysteresis, 1.3 % of the rated speed) switches the estimator out of the
//! limiter mode the probe reads in and back: each switch moves θ̂, a new angle error that the
//! next period's torque swings the rotor by again. The swing grows with A at a given δ, so the
//! amplitude is the lever: with S_k the largest |ω̂| over period k and S_b the bound,
//!
//! A_(k+1) = min(A_max, A_k·S_b/S_k, A_k/p0),
//!
//! the amplitude that would have held the swing at the bound (the swing is proportional to A
//! at a given δ), grown by at most 1/p0 = 1.70 per period, p0 = 0.587 the correction loop's
//! triple pole per period ([`super::TRIPLE_POLE`]): as fast as the loop takes δ down, so that
//! a growing amplitude does not outrun the shrinking angle error it swings the rotor by. The
//! first period uses A_max: the reading at the probe's start, when δ is largest, needs its
//! full signal (started at a twentieth of A_max, the 22-pole-pair gimbal's angle error grew
//! from 0.13 to 0.25 rad over its first readings and its `regen-stop` failed).
//!
//! **Bound.** S_b is half the band's edge (`[controller.standstill_probe] swing_ratio` 0.0065
//! of the rated speed \[A\]): within one period the estimate's angle error can double (the
//! servo below: δ 0.066 → 0.117 rad within 25 ms as its rotor reverses), and so the swing
//! with it; half the edge keeps that doubled swing inside the band. Measured on the servo's
//! `regen-stop` seed 1: with S_b the whole edge the estimate reaches 69 r/min (39 r/min edge)
//! in the period the angle error doubles, a speed error of 65.8 r/min over 7–8 s (60 allowed).
//!
//! Measured (`fado-sim run regen-stop`, the unseen 400 W servo of
//! `crates/fado-sim/tests/data/unseen/`, rated torque to rated speed in 7.7 ms): at
//! δ ≈ 0.1 rad the configured 0.34 A (0.1 of the rated current) swings the rotor between −38
//! and +81 r/min and the estimator leaves limiter mode in each swing; with the rule the speed
//! error over 7–8 s is 16.9 / 16.9 / 3.1 / 11.1 r/min at seeds 1–4 (76.5 / 42.3 / 14.0 /
//! 25.1 with the amplitude fixed), the 22-pole-pair gimbal's (`tests/data/gimbal-22pp.toml`)
//! 4.5 / 3.9 r/min at seeds 1–2 (8.3 / 7.1; 12 allowed), their largest |θ − θ̂| unchanged
//! (it comes before the probe starts). Heavier rotors, whose speed does not answer the probe
//! beyond the bound, keep the configured amplitude.

use crate::Real;

/// Default bound S_b as a fraction of the rated speed: half the lower edge of the estimator's
/// limiter band, (0.015 − 0.002)/2 = 0.0065 (module docs, "Bound") \[A\].
pub const DEFAULT_SWING_RATIO: f64 =
    0.5 * (crate::mode::DEFAULT_THRESHOLD_RATIO - crate::mode::DEFAULT_HYSTERESIS_RATIO);

/// The amplitude (A) for the next period from the running `amplitude` A_k, the largest |ω̂|
/// `swing` S_k over the last period and the `bound` S_b (rad/s): min(A_max, A_k·S_b/S_k,
/// A_k/p0) with A_max = `largest` (module docs). `bound` 0, or S_k not finite: A_max.
pub fn next_amplitude<T: Real>(largest: T, amplitude: T, bound: T, swing: T) -> T {
    if bound <= T::zero() || !swing.is_finite() {
        return largest;
    }
    let grown = amplitude * T::lit(1.0 / super::TRIPLE_POLE);
    let held = if amplitude * bound < largest * swing {
        amplitude * bound / swing
    } else {
        largest
    };
    held.step_min(grown)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rule: a swing twice the bound halves the amplitude, a swing within it grows the
    /// amplitude in proportion but by at most 1/p0 = 1.70 per period, up to the largest; no
    /// bound or no finite swing gives the largest.
    #[test]
    fn the_amplitude_holds_the_speed_swing_to_the_band_edge() {
        let (largest, bound) = (0.34, 16.3);
        assert_eq!(
            next_amplitude(largest, largest, bound, 2.0 * bound),
            0.5 * largest
        );
        let a: f64 = next_amplitude(largest, 0.1, bound, 3.0 * bound);
        assert!((a - 0.1 / 3.0).abs() < 1e-15, "{a}");
        // Within the bound: grows, by at most 1/p0 per period, up to the largest.
        let a: f64 = next_amplitude(largest, 0.1, bound, 0.8 * bound);
        assert!((a - 0.125).abs() < 1e-15, "{a}");
        let a: f64 = next_amplitude(largest, 0.1, bound, 0.1 * bound);
        assert!((a - 0.1 / crate::control::standstill_probe::TRIPLE_POLE).abs() < 1e-15);
        assert_eq!(next_amplitude(largest, 0.3, bound, 0.1 * bound), largest);
        assert_eq!(next_amplitude(largest, largest, bound, 0.0), largest);
        assert_eq!(next_amplitude(largest, 0.1, 0.0, 3.0 * bound), largest);
        assert_eq!(next_amplitude(largest, 0.1, bound, f64::NAN), largest);
        assert_eq!(next_amplitude(largest, 0.1, bound, f64::INFINITY), largest);
    }
}
