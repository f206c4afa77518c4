//! The drive's records for a lost lock: the stall symptom it detects itself and its reaction
//! to a loss (the estimator's or the stall's).

use super::super::STALL_TORQUE_BAND_RATIO;
use crate::Real;
use crate::control::lock_reaction::LockReaction;
use crate::real::cast_record;

/// Tuning of the reaction to a lost lock and of the recovery (`[controller.lock]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct LockReactionTuning<T> {
    /// Reaction to the estimator's [`LockStatus::Lost`](crate::LockStatus::Lost) (`DriveFlags::LOCK_LOST`) and, with
    /// `lock.reaction_on_stall`, to the stall symptom (`DriveFlags::STALLED`). Default report
    /// only \[A\] (the paper's behaviour plus the flags).
    pub reaction: LockReaction,
    /// Whether the stall symptom (`DriveFlags::STALLED`, see `stall.speed_ratio`) starts
    /// `lock.reaction` like the estimator's own verdict. Default on \[A\]: near zero speed a
    /// lost estimate shows first, and on the fig11 envelope in 39 % of the fixed-R̂s losses
    /// only, as a stall (docs/method/lock.md), and a drive that coasts, re-aligns and restarts
    /// from a real stall under its load does what a stall asks for too. Off: the stall is
    /// reported and the drive carries on.
    pub reaction_on_stall: bool,
    /// With `Recover`: time without symptoms in disturbance-feedback mode after which the
    /// coasting drive restarts, s. Default 20 ms \[A\] (the detection target: the detector
    /// has had as long to object as it gets to detect a loss).
    pub recovery_time: T,
    /// With `Recover`: coasting time after which a machine that has not turned fast enough
    /// for the estimator is re-aligned and restarted, s. Default 0.5 s \[A\].
    pub recovery_timeout: T,
    /// With `Recover`: recoveries since `reset` before the drive coasts for good. Default 3
    /// \[A\].
    pub recovery_attempts: u32,
    /// With `Recover`: switch the estimator's online R̂s adaptation on when a recovery starts
    /// (see [`crate::control::lock_reaction`]). Default on \[A\]: the paper's fixed R̂s is
    /// what loses the rotor in the loaded zero-speed passage (docs/method/lock.md), and restarting
    /// with the same R̂s meets the same passage with the same error.
    pub recovery_rs_adaptation: bool,
}

cast_record!(LockReactionTuning { recovery_time, recovery_timeout ; reaction, reaction_on_stall, recovery_attempts, recovery_rs_adaptation });

impl<T: Real> Default for LockReactionTuning<T> {
    fn default() -> Self {
        Self {
            reaction: LockReaction::ReportOnly,
            reaction_on_stall: true,
            recovery_time: T::lit(20e-3),
            recovery_timeout: T::lit(0.5),
            recovery_attempts: 3,
            recovery_rs_adaptation: true,
        }
    }
}

/// Tuning of the stall symptom of the loss-of-lock detection (the speed loop's stall) (`[controller.stall]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct StallTuning<T> {
    /// Stall symptom of the loss-of-lock detection (see [`crate::lock`], "speed-loop stall"):
    /// in limiter mode, a speed error |ω* − ω̂| above this multiple of the rated speed for
    /// `stall.time` raises `STALLED` (and starts the lock reaction, see
    /// `lock.reaction_on_stall`; widened with the commanded torque on motors of small inertia
    /// for their torque, `stall.torque_band_ratio`). Default 0.003
    /// \[A\] (4.5 r/min at 1500 r/min rated, a fifth of the default Fig. 3 threshold
    /// `mode.threshold_ratio` 0.015; chosen on the fig11 envelope with the current gate
    /// `stall.min_current_ratio` and the exception `stall.follow_time`,
    /// docs/method/lock.md: 0.005 reaches the band 20–60 ms after the error passes 0.5 rad in 10
    /// of 208 fixed-R̂s losses; the light-load losses that 0.004 saw late reach
    /// 0.0034–0.0038·rated by 15 ms after the error passes 0.5 rad; below 0.004 the rotor
    /// lagging the ramp under heavy load false-alarmed until the exception); 0 disables.
    pub speed_ratio: T,
    /// Net time (s) the stall condition must hold (up/down count, [`crate::lock::Debouncer`]).
    /// Default 5 ms \[A\] (the estimator's
    /// `lock.detection_time`).
    pub time: T,
    /// Net time (s) without the stall condition after which the stall symptom clears (it is
    /// a live status like the estimator's, see [`crate::lock::Debouncer`]; the reaction
    /// latches). Default 0.1 s \[A\] (the estimator's `lock.heal_time`).
    pub heal_time: T,
    /// The stall symptom counts only while |ω̂| is below this multiple of the rated speed, or
    /// while ω̂ turns against ω*; 0: at any speed. Default 0 (off) \[A\]. The first round's
    /// false alarms of the symptom (|n̂| 12–25 r/min around the limiter ↔ k_df hand-over)
    /// were swings of ω̂ at light load; the current gate `stall.min_current_ratio`
    /// removes them without this restriction, which missed the losses in which ω̂ sticks
    /// at 12–20 r/min while the reference passes (docs/method/lock.md: 0.0075 detects 81.7 % of the
    /// fixed-R̂s losses, off 94.2 %, both at the 0.005 band).
    pub max_speed_ratio: T,
    /// The stall symptom counts only while the speed loop asks for a torque: |i_q*| at least
    /// this multiple of the rated current. Default 0.2 \[A\] (docs/method/lock.md). A lost
    /// estimate shows on the mechanical side through the torque the drive commands and the
    /// rotor does not answer; with next to no torque commanded the rotor's motion is the
    /// load's and the inertia's, and a swing of ω̂ past the band is no evidence against the
    /// angle. On the fig11 envelope every false alarm of the symptom without the speed
    /// restriction had |i_q*| of 0.05–0.15 of rated (light loads; the lag of ω̂ behind the
    /// ramp at the limiter → k_df hand-over after the reversal, one at start-up), every
    /// loss it caught that the restriction had missed 0.26 or more; 0.15 still false-alarmed
    /// at 0.151 (docs/method/lock.md). 0: always.
    pub min_current_ratio: T,
    /// The current gate of `stall.min_current_ratio` does not apply while the speed error
    /// |ω* − ω̂| exceeds this multiple of the stall band *and* ω̂ turns against ω* (ω̂·ω* < 0):
    /// a gross speed error against the reference, evidence against the estimate whatever the
    /// current. The gate's 0.2 of rated current is, through the speed loop's proportional
    /// gain, a speed error of 13 bands on the paper's motor but 28 on ipmsm-gem-50k, whose
    /// inertia is small for its torque; there the start-up losses with L̂q over-estimated
    /// (ω̂ oscillating against the reference, |i_q*| 0.12–0.16 of rated) were flagged 25–100 ms
    /// late. 0: the gate always applies. Default 0 \[A\]: with 3, on the reversal envelope
    /// (docs/method/lock.md), ipmsm-gem-50k detects
    /// 124/140 and 212/247 losses on seed 7 instead of 96 and 185 (119/141 and 189/224 instead
    /// of 100 and 172 on seed 8) and outrunner-cheetah-24v 268/274 instead of 251 (fixed R̂s),
    /// the paper's motor, ipmsm-2k2, servo-1ft6084 and hub-hoverboard-48v are unchanged on
    /// seed 7, but pmsyrm-5k flags 3 of 153 and 8 of 162 passing runs that stayed within
    /// 0.25 rad (0 and 1 with the gate) for the same start-up oscillation of ω̂ that does not
    /// lose its rotor: a trade to choose per motor, not a default.
    pub gross_error_ratio: T,
    /// The stall symptom also counts in k_df mode while |ω̂| is below this multiple of the
    /// rated speed (the limiter ↔ k_df threshold `mode.threshold_ratio` is 0.015, so the
    /// default is a band of 0.0025·rated, 3.75 r/min at 1500 r/min, above it); 0: limiter
    /// mode only. Default 0.0175 \[A\] (docs/method/lock.md). A band of 0.02 (chosen on the fig11
    /// envelope: under heavy
    /// load the estimate is lost in k_df mode just above the threshold, where a limiter-only
    /// symptom does not look) also flagged passing runs on servo-1ft6084 (11 of 259, seed 7),
    /// outrunner-cheetah-24v and hub-hoverboard-48v in which ω̂ swings ±0.003 of rated around
    /// ω* just after the limiter → k_df hand-over at 0.0176–0.0197·rated (0.0175: 4 of 259 on
    /// servo-1ft6084, seed 7; 1 of 254 on seed 8, against 12 with 0.02); off (0), one fig11 loss in
    /// 2173 (seeds 7–16) and 1–2 of 220–229 hub-hoverboard-48v losses went late, which
    /// 0.0175 keeps.
    pub kdf_speed_ratio: T,
    /// The stall symptom does not count while the estimated rotor *answers the torque*: ω̂
    /// turns in the direction the speed loop drives it (ω̂·(ω* − ω̂) > 0) faster than the
    /// stall band `stall.speed_ratio`, and accelerates in that direction by at least
    /// `stall.follow_accel_ratio`, the acceleration read as (ω̂ − ω̂_lp)/τ with ω̂_lp
    /// the first-order low-pass of ω̂ with this time constant τ (s; for a constant
    /// acceleration a, ω̂ − ω̂_lp → a·τ; discretised exactly, pole exp(−Ts/τ)), and |i_q*|
    /// is at least `stall.follow_min_current_ratio`. 0 disables. Default 10 ms \[A\]
    /// (half the 20 ms detection deadline). The stall symptom's false alarms on the fig11
    /// envelope (docs/method/lock.md) were the rotor *itself* lagging the ramp
    /// after the reversal under 7.7–11.5 N·m: the 0.18–0.25 rad angle error δ costs
    /// 1 − cos δ ≈ 2–3 % of the torque, more than J·dω*/dt needs at those loads, so the
    /// speed loop falls 6 r/min behind while rotor and estimate accelerate together (ω̂
    /// 9–30 r/min in the direction of the speed error, accelerating towards ω* at 19–76
    /// r/min/s). A lost estimate does not answer the torque: at the stall flag of the 343
    /// losses only the stall symptom caught on seeds 7–10, ω̂ sat within 6 r/min of zero,
    /// turned against the speed error, or fell away from ω*. The check is the sign side
    /// of the mechanical equation J·dω/dt = T_e − T_L (the torque the drive commands must
    /// show in the estimated speed); the load is unknown, hence only its direction.
    pub follow_time: T,
    /// The "answers the torque" exception of `stall.follow_time` holds only from this
    /// |i_q*| on, as a multiple of the rated current. Default 0.5 \[A\]. The lag it excuses
    /// is the torque deficit (1 − cos δ)·T of a tolerated angle error δ, which only a heavy
    /// torque makes larger than what the reference's acceleration needs (fig11's false
    /// alarms: |i_q*| 0.70–1.04 of rated); at light load an estimate running ahead of a
    /// rotor that does not move also follows the ramp (fig11 seeds 11–12: ω̂ 6–7 r/min,
    /// accelerating at a third of the ramp, the rotor at 1 r/min, |i_q*| 0.23–0.32 of
    /// rated), and a lag there is the loss.
    pub follow_min_current_ratio: T,
    /// The least acceleration of ω̂ towards ω* (multiple of the rated speed per second) that
    /// counts as answering the torque (see `stall.follow_time`). Default 0.005 \[A\]
    /// (7.5 r/min/s on the paper's motor, below the 19 r/min/s the slowest of fig11's false
    /// alarms showed and above the decay of the low-pass once ω̂ stops: a stuck estimate
    /// reads below it within τ·ln(a/0.005·ω_rated/s) of stopping).
    pub follow_accel_ratio: T,
    /// The stall band is the larger of `stall.speed_ratio` × the rated speed and this
    /// ratio ε times the speed error that commands the present torque through the speed
    /// loop's proportional gain, |T*|/(Ĵ·ω_s): T* the model's torque of the current
    /// reference (`MachineModel::torque`, reluctance torque included), Ĵ the model's inertia,
    /// ω_s = 2π·`speed.bandwidth_hz` (the speed PI's kp = Ĵ·ω_s/K_t, so right after a step of
    /// the speed error e the band is max(band, ε·e) plus the integral's share). How far a rotor
    /// that really lags its reference under a torque error δT falls behind is δT/(Ĵ·ω_s) on
    /// the same scale: a band in rated speed cannot follow it from motor to motor, since
    /// T_rated/(Ĵ·ω_s·ω_rated) is 0.19 on the paper's motor and the 2.2 kW IPMSM, 0.04–0.07 on
    /// the hub motor and the servo, 0.42–0.54 on the outrunner, ipmsm-gem-50k and pmsyrm-5k
    /// (their J is small for their torque). 0: the fixed band alone.
    ///
    /// Default 1 − cos(0.25 rad) = 0.0311 \[A\]: the torque deficit δT/T* = 1 − cos δ of an
    /// estimate off by δ = 0.25 rad, the largest angle error the paper's criterion still calls a
    /// clean run. A rotor that lags its reference because the estimate is off by less than that is
    /// then inside the band; one off by more, or stalled, leaves it (docs/method/lock.md). Measured on the seven presets' reversal
    /// envelopes, seeds 7 and 8, against a ratio of 0.015:
    /// - outrunner-cheetah-24v with the R̂s adaptation: its false alarms go from 13 of 183
    ///   and 12 of 166 passing runs to none. They were rotors lagging the zero-speed exit of
    ///   the ramp by 0.003–0.008 of rated speed under an estimate 0.16–0.25 rad off.
    /// - pmsyrm-5k, fixed R̂s, seed 8: 1 of 162 to none.
    /// - Detections lost: the paper's motor 1 of 218 (seed 8, at 93 % of rated torque, 115 ms
    ///   late) and outrunner-cheetah-24v with fixed R̂s 3 of 292 (seed 8).
    /// - Nothing else changed on any preset.
    ///
    /// Without the reluctance band and the gross-error waiver, 0.015 is the largest ratio that
    /// leaves the paper's motor's detections on time (0.02 delays 92 of its 205 detections on
    /// seed 7 and 0.025 misses one).
    pub torque_band_ratio: T,
    /// The stall band widens further by this ratio ε_r times the speed error that commands the
    /// model's *reluctance* torque through the speed loop's proportional gain,
    /// ε_r·|T_r*|/(Ĵ·ω_s) with T_r* = 1.5·p·(L̂d − L̂q)·i_d*·i_q* (added to the band of
    /// `stall.torque_band_ratio`). The reluctance torque rests on L̂d − L̂q, the least
    /// certain of the model's parameters (saturation moves L̂q by tens of per cent, and the
    /// difference of two inductances carries the error of both; the envelope draws L̂q ±30 %),
    /// so on a salient rotor the torque error δT, and the lag δT/(Ĵ·ω_s) of a rotor that
    /// really follows its reference late, is mostly this part: on pmsyrm-5k (L̂q/L̂d 4.25)
    /// and ipmsm-gem-50k (3.24) the stall symptom's false alarms were rotors lagging or
    /// overshooting the reversal ramp by 0.003–0.005 of the rated speed with the estimate
    /// right (docs/method/lock.md). Zero on a surface-magnet model (L̂d = L̂q). Default 0.05 \[A\]
    /// (docs/method/lock.md: on seed 7 of the seven presets
    /// 0.15 loses 10 of 96 detections on ipmsm-gem-50k and 12 of 53 on pmsyrm-5k, 0.05 none;
    /// over seeds 7, 8, 21 and 22 it takes the passing runs flagged from 100 to 10 of 1012 on
    /// pmsyrm-5k and from 213 to 158 of 564 on ipmsm-gem-50k, with no detection lost on any
    /// preset, and leaves fig11's hold-out seeds 17–20 at 856/856 detected, 0 of 418 flagged).
    pub reluctance_band_ratio: T,
}

cast_record!(StallTuning { speed_ratio, time, heal_time, max_speed_ratio, min_current_ratio, gross_error_ratio, kdf_speed_ratio, follow_time, follow_min_current_ratio, follow_accel_ratio, torque_band_ratio, reluctance_band_ratio ;  });

impl<T: Real> Default for StallTuning<T> {
    fn default() -> Self {
        Self {
            speed_ratio: T::lit(0.003),
            time: T::lit(5e-3),
            heal_time: T::lit(0.1),
            max_speed_ratio: T::lit(0.0),
            min_current_ratio: T::lit(0.2),
            gross_error_ratio: T::lit(0.0),
            kdf_speed_ratio: T::lit(0.0175),
            follow_time: T::lit(10e-3),
            follow_min_current_ratio: T::lit(0.5),
            follow_accel_ratio: T::lit(0.005),
            torque_band_ratio: T::lit(STALL_TORQUE_BAND_RATIO),
            reluctance_band_ratio: T::lit(0.05),
        }
    }
}
