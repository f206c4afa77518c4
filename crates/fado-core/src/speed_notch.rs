//! The observer's speed without the electrical-frequency ripple of a DC flux error: a notch
//! at the estimated electrical frequency on ω̂1 + the lag compensation, used on a saturating
//! model where the frame coupling is large (docs/method/saturation.md, "The slow mode").
//!
//! **Why.** A DC error ε of λ2 (a constant vector in the stator frame) is seen from the rotor
//! as a vector turning at −ω: it turns λ̂r, hence θ̂, by δ(t) = Im(ε·e^{−jθ})/κ, a ripple at
//! the electrical frequency |ω|. T2S-1 (60 Hz) passes its rate dδ/dt into ω̂1 at any speed
//! where |ω| is below its bandwidth, and the observer rotates its model at that speed: with
//! the notch of eq. (17)–(19) off by Δω it leaks λ·Δω/(2jω) of the rotating flux into D̂
//! (the observer's lag compensation), a leak that turns with the same e^{jθ} as
//! the ripple and so has a DC part proportional to ε. With the frame coupling c of
//! `crate::active_flux` (the observer's radial input e_d + c·e_q) that leak closes a loop
//! around ε which moves the DC loop's slowest pole to the right while the machine generates,
//! past zero where c approaches 1. Running the observer at the true speed removes the loop:
//! every slow-mode rate is then the k_df decay (−0.5 s⁻¹) on the PM-SyRM and the automotive
//! IPMSM at every load (`saturated_replay`). The notch removes from the observer's speed
//! exactly the component at the electrical frequency, the signature of a DC error, and
//! keeps the rest.
//!
//! **The filter.** A state-variable band-pass at ω0 = max(|ω̄|, ω_min) (ω̄ its own low-passed
//! output), damping [`NOTCH_DAMPING`]:
//!
//! ```text
//!   x1' = x2,   x2' = ω0²·(u − x1) − 2ζω0·x2,   x3' = k_h·ω0·(x2 − x3)
//!   y = u − (2ζ/ω0)·(x2 − x3)
//! ```
//!
//! (2ζ/ω0)·x2 is the band-pass part of u: y without x3 is the notch
//! (s² + ω0²)/(s² + 2ζω0·s + ω0²), whose response to a ramp of slope α lags by 2ζα/ω0, at
//! the floor enough to turn the observer's notch off the flux through a reversal (0.2–1 rad
//! in the replays of `saturated_replay`). x3, x2 low-passed at
//! k_h·ω0 ([`RAMP_KEEP`]), is the band-pass part's steady value on a ramp (x2 → α): removing
//! only x2 − x3 keeps a ramp unchanged. At ω0 the high-pass x2 − x3 = s/(s + k_h·ω0)·x2 is
//! (1 + j·k_h)/(1 + k_h²) of x2, so that k_h/√(1 + k_h²) = 24 % of the ripple stays: enough,
//! since the loop it closes needs its gain lowered, not cut (the rates of `saturated_replay`
//! are the k_df decay with it). Integrated by semi-implicit Euler at the sample rate
//! (ω0·Ts ≤ 0.1 over the rated range at 10 kHz).

use crate::Real;

/// ζ of the notch, ours \[A\]: the slow mode's rate on the PM-SyRM and the automotive IPMSM
/// is the k_df decay from ζ = 0.2 up; 0.3 keeps a margin, and the reversal's replay within
/// 0.1 rad (`saturated_replay`, narrower notches reject a ripple that drifts with the speed
/// less well, wider ones pass more of a load transient's speed change).
pub const NOTCH_DAMPING: f64 = 0.3;

/// k_h: the ramp-keeping low-pass of the band-pass part at k_h·ω0, ours \[A\] (a quarter of
/// the notch frequency: 76 % of the ripple at ω0 removed, a ramp's lag gone within 4/ω0).
pub const RAMP_KEEP: f64 = 0.25;

/// The notch's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedNotch<T> {
    /// Ts, s.
    ts: T,
    /// The lowest notch frequency ω_min, rad/s (the estimator's mode threshold).
    floor: T,
}

/// The notch's state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpeedNotchState<T> {
    /// The input low-passed (x1, the notch frequency's source), rad/s.
    speed: T,
    /// Its rate (x2), rad/s².
    rate: T,
    /// The rate low-passed at k_h·ω0 (x3), rad/s².
    rate_mean: T,
}

impl<T: Real> SpeedNotch<T> {
    /// A notch stepped every `ts` whose frequency stays at or above `floor` (rad/s).
    pub fn new(ts: T, floor: T) -> Self {
        Self { ts, floor }
    }

    /// The state that passes a constant `speed` unchanged.
    pub fn state_at(speed: T) -> SpeedNotchState<T> {
        SpeedNotchState {
            speed,
            rate: T::zero(),
            rate_mean: T::zero(),
        }
    }

    /// One sample of the input speed `u`: the next state, and the ripple to remove from `u`
    /// ((2ζ/ω0)·(x2 − x3)).
    #[inline(always)]
    pub fn step(&self, s: &SpeedNotchState<T>, u: T) -> (SpeedNotchState<T>, T) {
        let w0 = crate::real::max(s.speed.abs(), self.floor);
        let two_zeta = T::lit(2.0 * NOTCH_DAMPING);
        let rate = s.rate + self.ts * (w0 * w0 * (u - s.speed) - two_zeta * w0 * s.rate);
        let speed = s.speed + self.ts * rate;
        let rate_mean = s.rate_mean + self.ts * T::lit(RAMP_KEEP) * w0 * (rate - s.rate_mean);
        let ripple = two_zeta / w0 * (rate - rate_mean);
        (
            SpeedNotchState {
                speed,
                rate,
                rate_mean,
            },
            ripple,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ramp passes unchanged once the filter has settled; of a sinusoid at the notch
    /// frequency (the speed riding on it) k_h/√(1 + k_h²) = 24 % stays (module docs).
    #[test]
    fn the_notch_keeps_a_ramp_and_removes_the_ripple_at_the_electrical_frequency() {
        let ts = 1e-4;
        let notch = SpeedNotch::new(ts, 6.0);
        // A ramp from 20 rad/s at 20 rad/s²: the residual after 2 s.
        let mut s = SpeedNotch::state_at(20.0);
        let mut worst_late: f64 = 0.0;
        for k in 1..=30_000 {
            let t = k as f64 * ts;
            let (next, ripple) = notch.step(&s, 20.0 + 20.0 * t);
            s = next;
            if t > 2.0 {
                worst_late = worst_late.max(ripple.abs());
            }
        }
        assert!(worst_late < 0.01, "ramp residual {worst_late} rad/s");
        // 30 rad/s with a 1 rad/s ripple at 30 rad/s: the ripple removed.
        let mut s = SpeedNotch::state_at(30.0);
        let mut worst: f64 = 0.0;
        for k in 1..=60_000 {
            let t = k as f64 * ts;
            let u = 30.0 + (30.0 * t).sin();
            let (next, ripple) = notch.step(&s, u);
            s = next;
            if t > 4.0 {
                worst = worst.max((u - ripple - 30.0).abs());
            }
        }
        let expected = RAMP_KEEP / (1.0 + RAMP_KEEP * RAMP_KEEP).sqrt();
        assert!((worst - expected).abs() < 0.02, "ripple left {worst} rad/s");
    }
}
