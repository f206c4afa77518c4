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
//! around ε which moves the DC loop's slowest pole to the right where c and ω have opposite
//! signs (while the machine generates where L_q,s exceeds L_dd, c then following i_q),
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
//!
//! **The chirp.** A ripple at ω0 is told apart from the speed only while its frequency stays
//! within the notch's band 2ζω0 for the band-pass's settling time 1/(ζω0): while the speed's
//! rate |ω̇| stays below 2ζ²·ω0² ([`CHIRP_RATIO`]). Beyond it the speed's own change fills
//! the band, and the band-pass part of a change Δα of the rate is 2ζ·Δα/ω0, which grows as
//! ω0 falls: in a stop at the current limit (twice the rated torque on the PM-SyRM,
//! 2,400 rad/s² electrical, beyond 2ζ²·ω0² below 115 rad/s) the rate falls by 2,000 rad/s²
//! as the speed loop leaves the current limit, and a notch without the bound removes
//! 20–47 rad/s from an observer speed of 25–30 rad/s and loses the rotor (`regen-stop` at
//! 110 r/min). So while |x3|, the rate's steady part (24 % of a ripple's rate reaches it),
//! exceeds 2ζ²·ω0², x3 follows x2 at once and the notch removes nothing; it resumes from no
//! ripple once the speed settles, and a change of the rate within the bound removes at most
//! 2ζ·2ζ²·ω0²/ω0 = 4ζ³·ω0 (11 % of ω0). The onset of a deceleration is judged only once x3
//! has followed it, within 1/(k_h·ω0): a stop from 165 rad/s at 2,400 rad/s² removes at most
//! 7 % of ω0 on its way, one at 4,000 rad/s² 18 %. The test is on x3, not on x2: x2 carries a
//! ripple A as A·ω0/(2ζ), and a gate on it would pass the large ripple of an aligned start
//! under load that the notch is for (the automotive IPMSM's loaded reversal replay then
//! loses 0.53 rad). What the notch is for is untouched: the slow mode it
//! cuts grows over seconds at a steady speed. `saturated_replay` replays the stop at the
//! current limit on five machines.

use crate::Real;

/// ζ of the notch, ours \[A\]: the slow mode's rate on the PM-SyRM and the automotive IPMSM
/// is the k_df decay from ζ = 0.2 up; 0.3 keeps a margin, and the reversal's replay within
/// 0.1 rad (`saturated_replay`, narrower notches reject a ripple that drifts with the speed
/// less well, wider ones pass more of a load transient's speed change).
pub const NOTCH_DAMPING: f64 = 0.3;

/// k_h: the ramp-keeping low-pass of the band-pass part at k_h·ω0, ours \[A\] (a quarter of
/// the notch frequency: 76 % of the ripple at ω0 removed, a ramp's lag gone within 4/ω0).
pub const RAMP_KEEP: f64 = 0.25;

/// The chirp bound 2ζ² of the notch: it removes a ripple only while the speed's rate stays
/// within 2ζ²·ω0² (module docs, "The chirp"): the notch's band 2ζω0 swept in its settling
/// time 1/(ζω0).
pub const CHIRP_RATIO: f64 = 2.0 * NOTCH_DAMPING * NOTCH_DAMPING;

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
        // The chirp: while the speed moves faster than 2ζ²·ω0² the ramp keeper follows the
        // rate at once, so that nothing is removed (module docs).
        let rate_mean = if s.rate_mean.abs() > T::lit(CHIRP_RATIO) * w0 * w0 {
            rate
        } else {
            s.rate_mean + self.ts * T::lit(RAMP_KEEP) * w0 * (rate - s.rate_mean)
        };
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

    /// A stop at the current limit from 165 rad/s (the PM-SyRM's 2,400 rad/s² at twice its
    /// rated torque, and a slower one), the rate falling to a fifth below 40 rad/s as a speed
    /// loop leaves the limit: what the notch removes stays within 4ζ³ of the notch frequency
    /// (module docs, "The chirp"; 7 % and 2 %), while without the chirp bound it exceeds the
    /// speed three times over.
    #[test]
    fn the_notch_removes_nothing_of_a_stop_faster_than_its_band() {
        let ts = 1e-4;
        let notch = SpeedNotch::new(ts, 6.0);
        let bound = 4.0 * NOTCH_DAMPING.powi(3);
        for (limit, rate) in [(2400.0, 500.0), (1000.0, 200.0)] {
            let mut s: SpeedNotchState<f64> = SpeedNotch::state_at(165.0);
            let (mut u, mut worst_share): (f64, f64) = (165.0, 0.0);
            let mut unbounded: SpeedNotchState<f64> = SpeedNotch::state_at(165.0);
            let mut worst_unbounded: f64 = 0.0;
            while u > 10.0 {
                u -= ts * if u > 40.0 { limit } else { rate };
                let w0 = s.speed.abs().max(6.0);
                let (next, ripple) = notch.step(&s, u);
                s = next;
                worst_share = worst_share.max(ripple.abs() / w0);
                // The same filter without the chirp bound (its ramp keeper always slow).
                let (mut next, _) = notch.step(&unbounded, u);
                let w0 = unbounded.speed.abs().max(6.0);
                next.rate_mean =
                    unbounded.rate_mean + ts * RAMP_KEEP * w0 * (next.rate - unbounded.rate_mean);
                let ripple = 2.0 * NOTCH_DAMPING / w0 * (next.rate - next.rate_mean);
                unbounded = next;
                worst_unbounded = worst_unbounded.max(ripple.abs() / u);
            }
            assert!(
                worst_share < bound,
                "{limit}: {worst_share} of the speed removed"
            );
            assert!(
                worst_unbounded > 0.5,
                "{limit}: {worst_unbounded} without the bound"
            );
        }
    }
}
