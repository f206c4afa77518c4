//! The observer's speed where the frame coupling is large (`crate::speed_notch`,
//! `crate::active_flux`, "The frame coupling"): the notch, and a saturating model's
//! frame-rate correction.
//!
//! **The frame-rate correction.** While the current loop holds î, a frame error δ turns the
//! machine's own current and moves |λ̂r| by s·δ against the model's λa(î) (the frame
//! coupling's s), while the angle shows only (κ/λa)·δ of it. The ratio |λ̂r|/λa(î) then moves
//! at (s/λa)·dδ/dt: the frame's own motion, which the observer's notched speed carries where
//! the coupling c = s/κ is large, and which through the disturbance observer's DC loop grows
//! while the machine generates. Where the notch acts, the observer runs at
//!
//! ```text
//!   ω̂ − (G/c)·d(|λ̂r|/λa(î))/dt
//! ```
//!
//! the rate low-passed at [`FRAME_RATE_HZ`], c judged with the notch's coupling test in the
//! integrand-offset law's slot (|c| above `OFFSET_COUPLING_MAX` there, so 1/c stays below 2).
//! Dividing by the signed c gives the correction the sign of the frame motion in both
//! quadrants where the notch acts (s·ω̂ < 0; the generating ones where s follows i_q):
//! replayed with exact signals, the pmsyrm-baldor-5k6 PM-SyRM's stop at the current limit
//! while generating (i_q < 0 at ω > 0) holds 0.048 rad with it and 0.074 without (the
//! magnitude's rate with a fixed sign, g = 6 rad: 0.58 rad).
//! The correction acts below [`FRAME_RATE_SPEED_SHARE`] of the rated speed and with a share
//! of G/c that rises from 0 at [`FRAME_RATE_CURRENT_LOW`] of the rated current to 1 at
//! [`FRAME_RATE_CURRENT_FULL`]: where the current is small the ratio's rate reads noise and
//! dead time rather than the frame, and the generating test reads the speed loop's own
//! oscillation at a standstill.
//! Constant inductances have no operating point and no correction: their step is unchanged.

use super::{Candidate, SLOT_OFFSET};
use crate::active_flux::ActiveFlux;
use crate::estimator::{EstimatorParams, EstimatorState};
use crate::magnetics::FluxLookup;
use crate::mode::Mode;
use crate::{Ab, Dq, Real};

/// G of the frame-rate correction (module docs), rad. Ours \[A\]: on motulator's ferrite
/// PM-SyRM (fado-sim's `tests/data/motulator/mot-pmsyrm-4k.toml`, coupling 1.23–1.33 at the
/// rated torque) the closed loop holds `reversal` and `rated-reversal` on the sensor seeds
/// 1–4 for G from 1 to 4 and loses `reversal` on seeds 2 and 4 at 6; 2 sits in the middle
/// (`rated-reversal` 0.044–0.088 rad near zero speed, 0.10–0.14 at G = 1, 0.03–0.04 at 4).
pub const FRAME_RATE_GAIN: f64 = 2.0;

/// The speed below which the frame-rate correction acts, a share of the rated electrical
/// speed. Ours \[A\]: above it the correction's loop grows an oscillation where the load
/// turns the machine from motoring to generating (mot-pmsyrm-4k's `regen-stop` at 400–450
/// r/min, i_q through zero: the angle lost on seed 2 with the current share alone, 0.30 rad
/// on seed 3 without either; 0.13–0.20 rad on seeds 1–4 with both). The quadrants it serves lie
/// below it: `rated-reversal` applies it only below 40 rad/s (0.13 of the rated speed), the
/// ripple replays at 6 % of the rated speed.
pub const FRAME_RATE_SPEED_SHARE: f64 = 0.15;

/// The current below which the frame-rate correction vanishes, a share of the rated
/// current, and [`FRAME_RATE_CURRENT_FULL`] where it acts whole. Ours \[A\]: the frame's rate
/// moves |λ̂r| by s·δ with s growing with the current, while the ratio's noise and the dead
/// time's distortion do not shrink with it; below 0.4 of the rated current the rate
/// reads them, and the quadrant test (ω̂·s < 0) reads the speed loop's own oscillation
/// at a standstill. The pmsyrm-baldor-5k6-measured map's unloaded standstill in
/// `regen-stop` (|i| under 3.3 A, a quarter of the rated 12.45 A; c just above 0.5) drifts
/// to 0.26 rad on seed 3 with the whole correction in 5–10 ms bursts where ω̂ crosses the
/// mode threshold, 0.13–0.16 rad on seeds 1–4 with the share and the speed bound.
pub const FRAME_RATE_CURRENT_LOW: f64 = 0.4;

/// The current above which the frame-rate correction acts whole, a share of the rated
/// current ([`FRAME_RATE_CURRENT_LOW`]). `rated-reversal` on mot-pmsyrm-4k corrects 84 % of
/// its corrected samples above 0.9 of the rated current.
pub const FRAME_RATE_CURRENT_FULL: f64 = 0.8;

/// The low-pass of the frame-rate correction's rate, Hz: above the 4–5 Hz oscillation it
/// damps, below the PWM and the current loop. Ours \[A\].
pub const FRAME_RATE_HZ: f64 = 100.0;

impl<T: Real> EstimatorState<T> {
    /// The observer speed of a saturating model or a salient rotor: the notch
    /// (`crate::speed_notch`) stepped every sample, its ripple removed in the k_df mode where
    /// the frame coupling is large and of the opposite sign to the speed (ω̂·s < 0), the
    /// quadrant where the DC loop's two couplings add: the radial share's copy of a DC error
    /// has the sign of s, the observer's leak the sign of ω (`crate::speed_notch`). Where
    /// L_q,s exceeds L_dd, s follows î_q and the quadrant is the generating one (ω̂·î_q < 0);
    /// where the q axis saturates below L_dd it is the motoring one. Measured on a drawn
    /// 91 kW IPMSM (`tests/data/drawn/ipm-sat-10p-800v-91kw.toml`) whose L_q,s falls to half
    /// L_dd at its current limit (c = s/κ = −0.54 at i_q = +1.84 of the rated current):
    /// gated on ω̂·î_q, its stop at the current limit loses the rotor at 0.9 rad once the
    /// frame-rate correction starts (`regen-stop`), and its through-zero reversal reaches
    /// 0.53 rad (`fullrange`). Both are judged at the operating point of the
    /// integrand-offset law's slot (the law holds on the same coupling test), once every
    /// [`SLOW_PERIOD`] samples: a saturating model's at its operating point, constant
    /// inductances' at the current `i_ab` in the frame of λ̂r
    /// (`crate::active_flux::constant_inductance_holds_offset`, s = (L̂q − L̂d)·î_q).
    #[inline(always)]
    pub(super) fn notch_speed<M: FluxLookup<T>>(
        &mut self,
        p: &EstimatorParams<T>,
        af: &ActiveFlux<T, M>,
        c: &Candidate<T>,
        i_ab: Ab<T>,
        speed: T,
    ) -> T {
        if self.slot == SLOT_OFFSET {
            let (coupled, s_sign, share) = match c.point {
                Some(point) => {
                    let (s, kappa) = af.frame_coupling(&point);
                    let coupled = af.holds_offset(&point);
                    // G/c where the notch's coupling test holds (|c| > 0.5, κ > 0) below
                    // the correction's speed, times the current's share.
                    let slow = c.t2s1.omega.abs() < p.frame_rate_speed;
                    self.frame_rate_gain = if coupled && kappa > T::zero() && slow {
                        T::lit(FRAME_RATE_GAIN) * kappa / s * Self::frame_rate_share(p, point.i_dq)
                    } else {
                        T::zero()
                    };
                    (coupled, s, af.offset_rate_share(&point))
                }
                None => {
                    let i_dq = ActiveFlux::<T>::frame_current(c.lambda_r, i_ab);
                    let lf = self.rs_adaptation.flux_linkage_hat;
                    let holds =
                        crate::active_flux::constant_inductance_holds_offset(lf, c.saliency, i_dq);
                    // s = (L̂q − L̂d)·î_q, saliency = L̂d − L̂q.
                    (holds, -c.saliency * i_dq.q, T::one())
                }
            };
            self.frame_coupled = coupled;
            self.offset_share = share;
            self.notch_on =
                p.frame_ripple_notch && self.frame_coupled && s_sign * c.t2s1.omega < T::zero();
        }
        let rate = self.frame_rate(p, c);
        let (notch, ripple) = p.speed_notch.step(&self.speed_notch, speed);
        self.speed_notch = notch;
        if self.notch_on && c.mode == Mode::DisturbanceFeedback {
            speed - ripple - self.frame_rate_gain * rate
        } else {
            speed
        }
    }

    /// The share of G/c the current leaves to the frame-rate correction: 0 below
    /// [`FRAME_RATE_CURRENT_LOW`] of the rated current, 1 above [`FRAME_RATE_CURRENT_FULL`],
    /// linear between (module docs).
    #[inline(always)]
    fn frame_rate_share(p: &EstimatorParams<T>, i_dq: Dq<T>) -> T {
        let (low, per_amp) = p.frame_rate_current;
        // A NaN share gives 0 (`real::max`).
        let share = crate::real::max((i_dq.norm() - low) * per_amp, T::zero());
        crate::real::min(share, T::one())
    }

    /// A saturating model's d(|λ̂r|/λa(î))/dt low-passed at [`FRAME_RATE_HZ`] (module docs):
    /// ω_c·(r − r̄), r̄ the ratio's first-order low-pass, stepped here; zero where the
    /// trackers coast or on the constant-inductance path (no operating point).
    #[inline(always)]
    fn frame_rate(&mut self, p: &EstimatorParams<T>, c: &Candidate<T>) -> T {
        let Some(point) = c.point else {
            return T::zero();
        };
        if c.tracker_hold || point.active <= T::zero() {
            return T::zero();
        }
        let ratio = c.lambda_r.norm() / point.active;
        let wc = T::two_pi() * T::lit(FRAME_RATE_HZ);
        let rate = wc * (ratio - self.active_ratio);
        self.active_ratio = self.active_ratio + wc * p.ts() * (ratio - self.active_ratio);
        rate
    }
}
