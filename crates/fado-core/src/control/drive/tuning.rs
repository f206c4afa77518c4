//! [`DriveTuning`]: the drive's gains, limits, thresholds and switches, as ratios of the
//! machine's ratings or durations in seconds.

use super::STALL_TORQUE_BAND_RATIO;
use crate::Real;
use crate::control::dc_link_limit::DcLinkTuning;
use crate::control::dead_time_compensation::{self, DeadTimeMethod};
use crate::control::field_weakening::FieldWeakeningTuning;
use crate::control::lock_reaction::LockReaction;
use crate::control::modulation::VoltageLimit;
use crate::control::ratings_limit::RatingsLimitTuning;
use crate::control::release_hold::ReleaseHoldTuning;
use crate::control::startup::StartupTuning;
use crate::control::tracker_feedforward::TrackerFeedforwardTuning;
use crate::control::{current_controller, delay_compensation, gain_calibration, speed_controller};
use crate::injection;
use crate::machine::PAPER_RATED_CURRENT;

/// The drive's tuning: every setting that is not the machine or the sampling period. Defaults
/// are ratios of the machine's ratings or durations in seconds, chosen so that the paper's
/// motor ([`MachineModel::paper`](crate::MachineModel::paper), 21.78 A rated) gets the paper's absolute values
/// (written beside each ratio); the inverter data (dead time, switching frequency, threshold
/// voltage, current band) are docs/method/estimator.md §7's; they are not serde keys (`fado-sim` derives them from
/// its `[inverter]` and `[mismatch]`). With the `serde` feature this is the `[controller]`
/// table of `fado-sim`'s TOML.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct DriveTuning<T> {
    /// Current-loop bandwidth in Hz. Default 250 Hz (paper, V).
    pub current_bandwidth_hz: T,
    /// Speed-loop bandwidth in Hz. Default 5 Hz (paper, V).
    pub speed_bandwidth_hz: T,
    /// Speed PI zero as a fraction of its bandwidth, Ki = Kp·ωsc/ratio. Default 5 (docs/method/estimator.md, "The paper's motor and drive").
    pub speed_zero_ratio: T,
    /// Current limit I_max (|i_dq*|) as a multiple of the rated current. Default 40/21.78
    /// (docs/method/estimator.md, "The paper's motor and drive" \[A\]: 40 A on the paper's motor).
    pub current_limit_ratio: T,
    /// Minimum current I_min of the injection (23) as a fraction of the rated current; 0
    /// disables it. Default 4/21.78 (paper, V: 4 A).
    pub injection_current_ratio: T,
    /// Maximum-torque-per-ampere d current on salient machines (L̂d ≠ L̂q; see
    /// [`MachineModel::mtpa_id`](crate::MachineModel::mtpa_id)), added to the injection's. No effect on a surface-magnet
    /// rotor. Default true.
    pub mtpa: bool,
    /// Give the estimator's speed trackers the acceleration the commanded torque causes,
    /// p·T*/Ĵ (a mechanical-model feed-forward, see [`crate::tracker`]); use with the
    /// estimator's `tracker.load_pole_ratio` > 0, whose third integrator takes up the load.
    /// Default false (the paper's trackers) \[A\]; the drive turns it on itself on a rotor its
    /// trackers would lag (`tracker_feedforward`).
    pub acceleration_feedforward: bool,
    /// Dead time Td in s (inverter datum). Default 2.5 µs (paper, V).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub dead_time: T,
    /// Switching frequency in Hz (inverter datum). Default 5 kHz (paper, V).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub switching_frequency: T,
    /// Device threshold voltage of the dead-time compensation in V (inverter datum). Default
    /// 1 V (docs/method/estimator.md §7 \[A\]).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub dead_time_threshold_voltage: T,
    /// Current band Ic of the trapezoidal compensation in A (inverter datum). Default 0.3 A
    /// (docs/method/estimator.md §7 \[A\]).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub dead_time_current_band: T,
    /// Compensate the dead time at all. Default true (paper IV-B).
    pub dead_time_compensation: bool,
    /// Shape of the compensation. Default [`DeadTimeMethod::EdgeCurrent`] \[A\]: the docs/method/estimator.md §7
    /// trapezoid evaluated at each switching edge's predicted current (PWM ripple included,
    /// L̂d, L̂q of the machine model); it keeps |λ̂r| from shrinking while a phase
    /// current sits in the band at standstill under load (docs/method/additions.md).
    pub dead_time_method: DeadTimeMethod,
    /// Angle advance of the voltage in samples. Default 1.5 (docs/method/estimator.md §7 \[A\], ref. \[13\]).
    pub delay_compensation_factor: T,
    /// Over-current trip level on any phase current, as a multiple of the rated current
    /// (latched until `reset`). Default 60/21.78 (1.5·I_max: 60 A on the paper's motor) \[A\].
    pub trip_current_ratio: T,
    /// Decoupling and back-EMF feed-forward in the current PI. Default true (docs/method/estimator.md, "The paper's motor and drive" \[A\]).
    pub decoupling: bool,
    /// Realisable voltage set. Default the hexagon (SVPWM \[16\]).
    pub voltage_limit: VoltageLimit,
    /// Usable fraction of the voltage limit (0, 1]. Default 1 \[A\].
    pub max_modulation: T,
    /// Current PI back-calculation gain in units of Ki/Kp. Default 1 (realisable
    /// reference) \[A\].
    pub current_anti_windup_ratio: T,
    /// Speed PI back-calculation gain in units of Ki/Kp. Default 5 (tracking at ωsc) \[A\].
    pub speed_anti_windup_ratio: T,
    /// Current-sensor offset calibration at start-up, in s: the gates stay off (zero current)
    /// after `new`/`reset` while the phase currents are averaged, before the aligned start;
    /// 0 disables it. The averages are subtracted from every later sample. Default 0.1 s
    /// \[A\] (1000 samples at 10 kHz: 10 mA rms noise averages to 0.3 mA): standard practice in
    /// real drives (the paper is silent). At standstill an offset is a constant integrand
    /// error −R̂s·Δi of eq. (3); the limiter of Fig. 6 removes only its radial part, its
    /// tangential part walks θ̂ (fado-sim fig10).
    pub offset_calibration_time: T,
    /// Current-sensor gain-mismatch calibration at start-up (see
    /// [`gain_calibration`](crate::control::gain_calibration)): after the offset calibration,
    /// two DC current levels along the aligned d axis measure the ratio of the phase-a and
    /// phase-b channel gains, which then corrects phase a. This is each level's averaging
    /// window in s; 0 disables the calibration. The current loop settles for
    /// 5·max(L̂d/R̂s, 1/ωc) (five time constants of the stator or of the current loop,
    /// whichever is slower), and each level holds 4 time constants of the rotor's swing
    /// (`swing_time_constant`) before it is averaged, fewer where that exceeds 0.2 s and the
    /// swing's bias bound allows (`swing_hold_time_constants`, a low-flux motor); a machine
    /// needing a hold above 0.2 s is skipped. Default 0.05 s \[A\] (500 samples at 10 kHz: 10 mA rms of noise averages to
    /// 0.45 mA, 0.02 % of the lower level's phase-b current at the observability limit on the
    /// paper's motor). A 0.5 % mismatch walks θ̂ at loaded standstill on a low-flux motor
    /// (README: the outrunner preset lost `reversal` and `stops`, 1.2 rad). Start-up added on
    /// the presets: 0.33 s (outrunner-cheetah-24v) to 0.52 s (paper).
    pub gain_calibration_time: T,
    /// Upper current level of the gain calibration as a multiple of the rated current (the
    /// lower level is half of it; at most `current_limit_ratio`, and on a rotor with L̂q > L̂d
    /// at most half of λ̂f/(L̂q − L̂d), see [`DriveConfig::gain_calibration_config`](crate::control::DriveConfig::gain_calibration_config)). Default 1 \[A\]: the continuous rating (the larger the
    /// levels, the smaller the inverter error and the noise against the resistive drop; the
    /// lower level must keep every phase clear of the dead-time band and the current ripple).
    pub gain_calibration_current_ratio: T,
    /// Smallest share min over the phases of |cos(θ0 − φ_x)| of the calibration current with
    /// which the gain calibration runs (a and b for the observability, c for the inverter
    /// error's cancellation); at an aligned angle closer to a phase null it is skipped (status
    /// `Unobservable`). Default 0.2 \[A\] (the error grows as 1/share; at θ0 = −0.5, share
    /// 0.023, an earlier version measured k 1.2e-2 to 5.4e-2 off on four presets; 0.2 skips
    /// 38 % of the angles).
    pub gain_calibration_min_observability: T,
    /// Largest gain mismatch |k − 1| accepted from the calibration; a larger result is refused
    /// (status `Implausible`, k unchanged). Default 0.05 \[A\] (two sensors of ±2.5 % gain
    /// tolerance; the simulator's default mismatch is 0.5 %, docs/method/estimator.md, "The paper's motor and drive").
    pub gain_calibration_max_mismatch: T,
    /// Stuck current-sensor detection: a channel reading within ±this fraction of the rated
    /// current of zero while the reference asks for at least `stuck_sensor_reference_ratio`
    /// in its phase. Default 0.25/21.78 \[A\] (0.25 A: 10 LSB of a 12-bit ±50 A ADC, 25σ of
    /// 10 mA sensor noise, docs/method/estimator.md, "The paper's motor and drive").
    pub stuck_sensor_band_ratio: T,
    /// Stuck current-sensor detection: the reference's phase component, as a fraction of the
    /// rated current, from which a near-zero reading is implausible. Default 2/21.78 \[A\]
    /// (half of I_min: every running state has |i_dq*| ≥ I_min, so some phase always carries
    /// ≥ 0.866·I_min).
    pub stuck_sensor_reference_ratio: T,
    /// Stuck current-sensor detection: how long (s) a channel must look stuck; 0 disables
    /// the detector. Default 0.5 ms (< 1 current-loop time constant) \[A\].
    pub stuck_sensor_time: T,
    /// Current-error monitor: |i_dq* − i_dq| above this fraction of the rated current counts
    /// as an error. Default 5/21.78 \[A\] (more than the I_min injection step the loop takes at
    /// start-up).
    pub current_error_ratio: T,
    /// Current-error monitor: how long (s) the error must last before `CURRENT_ERROR` is
    /// raised; 0 disables it. Default 2 ms (≈ 3 time constants of the 250 Hz current loop)
    /// \[A\].
    pub current_error_time: T,
    /// DC-link under-voltage warning level as a fraction of the machine's nominal DC-link
    /// voltage: `DC_LINK_LOW` below it. Default 2/3 \[A\] (200 V of the paper's 300 V; the
    /// modulation always uses the measured voltage, the flag only reports it).
    pub dc_link_min_ratio: T,
    /// How long (s) rejected samples may follow each other before the drive trips; 0 never
    /// trips on bad input. Default 10 ms \[A\]: a single bad sample is ridden through with the
    /// duty held, a sensor chain that stays broken is a fault.
    pub input_fault_trip_time: T,
    /// A phase current beyond ± this multiple of the trip level is no measurement of the
    /// machine (a glitch, an ADC or bus error) and is refused like a non-finite sample,
    /// instead of tripping; a real over-current passes the trip level first and trips.
    /// Default 2 \[A\] (see [`crate::plausibility`]).
    pub plausible_current_ratio: T,
    /// A DC-link reading above this multiple of the nominal DC-link voltage is refused like a
    /// non-finite sample. Default [`crate::plausibility::VOLTAGE_RATIO`] (1.5) \[A\].
    pub dc_link_max_ratio: T,
    /// The DC-link limits: source current limits, over-voltage controller and trip
    /// (`[controller.dc_link]`, see [`DcLinkTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub dc_link: DcLinkTuning<T>,
    /// Field weakening and the MTPV limit at the voltage limit (`[controller.field_weakening]`,
    /// see [`FieldWeakeningTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub field_weakening: FieldWeakeningTuning<T>,
    /// The speed, torque and power limits from the ratings (`[controller.limits]`, see
    /// [`RatingsLimitTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub limits: RatingsLimitTuning<T>,
    /// When the drive turns on the acceleration feed-forward by itself: a rotor its trackers
    /// would lag by more than `max_lag` at the current limit (`[controller.tracker_feedforward]`,
    /// see [`crate::control::tracker_feedforward`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub tracker_feedforward: TrackerFeedforwardTuning<T>,
    /// The release hold: a position loop that holds a rotor a load turns at zero speed
    /// after the start-up (`[controller.release_hold]`, see [`ReleaseHoldTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub release_hold: ReleaseHoldTuning<T>,
    /// How the start-up finds the rotor's angle (`[controller.startup]`, see
    /// [`StartupTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub startup: StartupTuning<T>,
    /// Reaction to the estimator's [`LockStatus::Lost`](crate::LockStatus::Lost) (`DriveFlags::LOCK_LOST`) and, with
    /// `lock_reaction_on_stall`, to the stall symptom (`DriveFlags::STALLED`). Default report
    /// only \[A\] (the paper's behaviour plus the flags).
    pub lock_reaction: LockReaction,
    /// Whether the stall symptom (`DriveFlags::STALLED`, see `lock_stall_speed_ratio`) starts
    /// `lock_reaction` like the estimator's own verdict. Default on \[A\]: near zero speed a
    /// lost estimate shows first, and on the fig11 envelope in 39 % of the fixed-R̂s losses
    /// only, as a stall (docs/method/lock.md), and a drive that coasts, re-aligns and restarts
    /// from a real stall under its load does what a stall asks for too. Off: the stall is
    /// reported and the drive carries on.
    pub lock_reaction_on_stall: bool,
    /// With `Recover`: time without symptoms in disturbance-feedback mode after which the
    /// coasting drive restarts, s. Default 20 ms \[A\] (the detection target: the detector
    /// has had as long to object as it gets to detect a loss).
    pub lock_recovery_time: T,
    /// With `Recover`: coasting time after which a machine that has not turned fast enough
    /// for the estimator is re-aligned and restarted, s. Default 0.5 s \[A\].
    pub lock_recovery_timeout: T,
    /// With `Recover`: recoveries since `reset` before the drive coasts for good. Default 3
    /// \[A\].
    pub lock_recovery_attempts: u32,
    /// With `Recover`: switch the estimator's online R̂s adaptation on when a recovery starts
    /// (see [`crate::control::lock_reaction`]). Default on \[A\]: the paper's fixed R̂s is
    /// what loses the rotor in the loaded zero-speed passage (docs/method/lock.md), and restarting
    /// with the same R̂s meets the same passage with the same error.
    pub lock_recovery_rs_adaptation: bool,
    /// Stall symptom of the loss-of-lock detection (see [`crate::lock`], "speed-loop stall"):
    /// in limiter mode, a speed error |ω* − ω̂| above this multiple of the rated speed for
    /// `lock_stall_time` raises `STALLED` (and starts the lock reaction, see
    /// `lock_reaction_on_stall`; widened with the commanded torque on motors of small inertia
    /// for their torque, `lock_stall_torque_band_ratio`). Default 0.003
    /// \[A\] (4.5 r/min at 1500 r/min rated, a fifth of the default Fig. 3 threshold
    /// `mode.threshold_ratio` 0.015; chosen on the fig11 envelope with the current gate
    /// `lock_stall_min_current_ratio` and the exception `lock_stall_follow_time`,
    /// docs/method/lock.md: 0.005 reaches the band 20–60 ms after the error passes 0.5 rad in 10
    /// of 208 fixed-R̂s losses; the light-load losses that 0.004 saw late reach
    /// 0.0034–0.0038·rated by 15 ms after the error passes 0.5 rad; below 0.004 the rotor
    /// lagging the ramp under heavy load false-alarmed until the exception); 0 disables.
    pub lock_stall_speed_ratio: T,
    /// Net time (s) the stall condition must hold (up/down count, [`crate::lock::Debouncer`]).
    /// Default 5 ms \[A\] (the estimator's
    /// `lock.detection_time`).
    pub lock_stall_time: T,
    /// Net time (s) without the stall condition after which the stall symptom clears (it is
    /// a live status like the estimator's, see [`crate::lock::Debouncer`]; the reaction
    /// latches). Default 0.1 s \[A\] (the estimator's `lock.heal_time`).
    pub lock_stall_heal_time: T,
    /// The stall symptom counts only while |ω̂| is below this multiple of the rated speed, or
    /// while ω̂ turns against ω*; 0: at any speed. Default 0 (off) \[A\]. The first round's
    /// false alarms of the symptom (|n̂| 12–25 r/min around the limiter ↔ k_df hand-over)
    /// were swings of ω̂ at light load; the current gate `lock_stall_min_current_ratio`
    /// removes them without this restriction, which missed the losses in which ω̂ sticks
    /// at 12–20 r/min while the reference passes (docs/method/lock.md: 0.0075 detects 81.7 % of the
    /// fixed-R̂s losses, off 94.2 %, both at the 0.005 band).
    pub lock_stall_max_speed_ratio: T,
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
    pub lock_stall_min_current_ratio: T,
    /// The current gate of `lock_stall_min_current_ratio` does not apply while the speed error
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
    pub lock_stall_gross_error_ratio: T,
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
    pub lock_stall_kdf_speed_ratio: T,
    /// The stall symptom does not count while the estimated rotor *answers the torque*: ω̂
    /// turns in the direction the speed loop drives it (ω̂·(ω* − ω̂) > 0) faster than the
    /// stall band `lock_stall_speed_ratio`, and accelerates in that direction by at least
    /// `lock_stall_follow_accel_ratio`, the acceleration read as (ω̂ − ω̂_lp)/τ with ω̂_lp
    /// the first-order low-pass of ω̂ with this time constant τ (s; for a constant
    /// acceleration a, ω̂ − ω̂_lp → a·τ; discretised exactly, pole exp(−Ts/τ)), and |i_q*|
    /// is at least `lock_stall_follow_min_current_ratio`. 0 disables. Default 10 ms \[A\]
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
    pub lock_stall_follow_time: T,
    /// The "answers the torque" exception of `lock_stall_follow_time` holds only from this
    /// |i_q*| on, as a multiple of the rated current. Default 0.5 \[A\]. The lag it excuses
    /// is the torque deficit (1 − cos δ)·T of a tolerated angle error δ, which only a heavy
    /// torque makes larger than what the reference's acceleration needs (fig11's false
    /// alarms: |i_q*| 0.70–1.04 of rated); at light load an estimate running ahead of a
    /// rotor that does not move also follows the ramp (fig11 seeds 11–12: ω̂ 6–7 r/min,
    /// accelerating at a third of the ramp, the rotor at 1 r/min, |i_q*| 0.23–0.32 of
    /// rated), and a lag there is the loss.
    pub lock_stall_follow_min_current_ratio: T,
    /// The least acceleration of ω̂ towards ω* (multiple of the rated speed per second) that
    /// counts as answering the torque (see `lock_stall_follow_time`). Default 0.005 \[A\]
    /// (7.5 r/min/s on the paper's motor, below the 19 r/min/s the slowest of fig11's false
    /// alarms showed and above the decay of the low-pass once ω̂ stops: a stuck estimate
    /// reads below it within τ·ln(a/0.005·ω_rated/s) of stopping).
    pub lock_stall_follow_accel_ratio: T,
    /// The stall band is the larger of `lock_stall_speed_ratio` × the rated speed and this
    /// ratio ε times the speed error that commands the present torque through the speed
    /// loop's proportional gain, |T*|/(Ĵ·ω_s): T* the model's torque of the current
    /// reference (`MachineModel::torque`, reluctance torque included), Ĵ the model's inertia,
    /// ω_s = 2π·`speed_bandwidth_hz` (the speed PI's kp = Ĵ·ω_s/K_t, so right after a step of
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
    pub lock_stall_torque_band_ratio: T,
    /// The stall band widens further by this ratio ε_r times the speed error that commands the
    /// model's *reluctance* torque through the speed loop's proportional gain,
    /// ε_r·|T_r*|/(Ĵ·ω_s) with T_r* = 1.5·p·(L̂d − L̂q)·i_d*·i_q* (added to the band of
    /// `lock_stall_torque_band_ratio`). The reluctance torque rests on L̂d − L̂q, the least
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
    pub lock_stall_reluctance_band_ratio: T,
    /// The loaded-standstill angle probe (see [`crate::control::standstill_probe`]): at a
    /// loaded standstill a slow square-wave d current, read through the speed loop's torque
    /// balance, turns θ̂ towards the rotor. Default true \[A\] (without it the one-hour loaded
    /// standstill drifts to the current limit on 4 of 5 sensor seeds, docs/method/additions.md).
    pub standstill_probe: bool,
    /// Probe amplitude Δi_d as a fraction of the rated current. Default 0.1 \[A\] (2.2 A on
    /// the paper's motor: no torque at δ = 0, 0.5 % more copper loss at rated load; the
    /// reading Δi_d·tan δ is 0.2 A at δ = 0.1 rad against a speed-loop ripple the
    /// demodulation averages over a whole period).
    pub standstill_probe_current_ratio: T,
    /// Probe period T_p in s. Default 0.5 s \[A\]: each half holds 0.25 s, 8 time constants
    /// 1/(2π·f_sc) of the 5 Hz speed loop (1.6 of its PI zero's ratio/(2π·f_sc) = 0.16 s), the
    /// correlation reads the second half of each half, after 4 loop time constants. Measured
    /// on the loaded hour's configuration (docs/method/additions.md): a longer
    /// period lets the probe's own Δi_d move the angle more within a half (the inverter
    /// residual's tangential part depends on the current vector): worst |θ − θ̂| over five
    /// sensor seeds 0.51 rad at 2 s, 0.095 at 1 s, 0.065 at 0.5 s.
    pub standstill_probe_period: T,
    /// Correction gain g in s⁻¹: θ̂ turns at g·δ̂. Default 1 s⁻¹ \[A\]: g·T_p = 1/2 with
    /// the default period (a first-order loop per period with the measurement half a period
    /// late: half the deadbeat gain), a steady error c/g = 0.01–0.02 rad under the measured
    /// 0.01–0.02 rad/s creep.
    pub standstill_probe_gain: T,
    /// The probe's gate: the speed reference |ω*| at most this multiple of the rated speed.
    /// Default 0.0005 \[A\] (0.75 r/min at 1500 r/min): a standstill reference. The probe
    /// moves the rotor by ±1–1.5 r/min on the paper's motor, a speed error at a low non-zero
    /// reference: with 0.0075 (11 r/min) the `lowspeed` staircase lost its 1.9 and 0.94 r/min
    /// levels on the 0.5 r/min speed criterion (7 → 4 levels held).
    pub standstill_probe_speed_ratio: T,
    /// The probe's gate: the speed loop's torque demand |τ| at least this fraction of the
    /// rated current. Default 0.25 \[A\] (above the eq. (23) injection level 4/21.78, where the
    /// R̂s adaptation's no-load angle law takes over).
    pub standstill_probe_load_ratio: T,
}

impl<T: Real> DriveTuning<T> {
    /// The same record in another precision (e.g. an f64 configuration for an f32 drive):
    /// every real rounded to `U`.
    pub fn cast<U: Real>(&self) -> DriveTuning<U> {
        DriveTuning {
            current_bandwidth_hz: U::lit(self.current_bandwidth_hz.to_f64()),
            speed_bandwidth_hz: U::lit(self.speed_bandwidth_hz.to_f64()),
            speed_zero_ratio: U::lit(self.speed_zero_ratio.to_f64()),
            current_limit_ratio: U::lit(self.current_limit_ratio.to_f64()),
            injection_current_ratio: U::lit(self.injection_current_ratio.to_f64()),
            mtpa: self.mtpa,
            acceleration_feedforward: self.acceleration_feedforward,
            dead_time: U::lit(self.dead_time.to_f64()),
            switching_frequency: U::lit(self.switching_frequency.to_f64()),
            dead_time_threshold_voltage: U::lit(self.dead_time_threshold_voltage.to_f64()),
            dead_time_current_band: U::lit(self.dead_time_current_band.to_f64()),
            dead_time_compensation: self.dead_time_compensation,
            dead_time_method: self.dead_time_method,
            delay_compensation_factor: U::lit(self.delay_compensation_factor.to_f64()),
            trip_current_ratio: U::lit(self.trip_current_ratio.to_f64()),
            decoupling: self.decoupling,
            voltage_limit: self.voltage_limit,
            max_modulation: U::lit(self.max_modulation.to_f64()),
            current_anti_windup_ratio: U::lit(self.current_anti_windup_ratio.to_f64()),
            speed_anti_windup_ratio: U::lit(self.speed_anti_windup_ratio.to_f64()),
            offset_calibration_time: U::lit(self.offset_calibration_time.to_f64()),
            gain_calibration_time: U::lit(self.gain_calibration_time.to_f64()),
            gain_calibration_current_ratio: U::lit(self.gain_calibration_current_ratio.to_f64()),
            gain_calibration_min_observability: U::lit(
                self.gain_calibration_min_observability.to_f64(),
            ),
            gain_calibration_max_mismatch: U::lit(self.gain_calibration_max_mismatch.to_f64()),
            stuck_sensor_band_ratio: U::lit(self.stuck_sensor_band_ratio.to_f64()),
            stuck_sensor_reference_ratio: U::lit(self.stuck_sensor_reference_ratio.to_f64()),
            stuck_sensor_time: U::lit(self.stuck_sensor_time.to_f64()),
            current_error_ratio: U::lit(self.current_error_ratio.to_f64()),
            current_error_time: U::lit(self.current_error_time.to_f64()),
            dc_link_min_ratio: U::lit(self.dc_link_min_ratio.to_f64()),
            input_fault_trip_time: U::lit(self.input_fault_trip_time.to_f64()),
            plausible_current_ratio: U::lit(self.plausible_current_ratio.to_f64()),
            dc_link_max_ratio: U::lit(self.dc_link_max_ratio.to_f64()),
            dc_link: self.dc_link.cast(),
            field_weakening: self.field_weakening.cast(),
            release_hold: self.release_hold.cast(),
            startup: self.startup.cast(),
            limits: self.limits.cast(),
            tracker_feedforward: self.tracker_feedforward.cast(),
            lock_reaction: self.lock_reaction,
            lock_reaction_on_stall: self.lock_reaction_on_stall,
            lock_recovery_time: U::lit(self.lock_recovery_time.to_f64()),
            lock_recovery_timeout: U::lit(self.lock_recovery_timeout.to_f64()),
            lock_recovery_attempts: self.lock_recovery_attempts,
            lock_recovery_rs_adaptation: self.lock_recovery_rs_adaptation,
            lock_stall_speed_ratio: U::lit(self.lock_stall_speed_ratio.to_f64()),
            lock_stall_time: U::lit(self.lock_stall_time.to_f64()),
            lock_stall_heal_time: U::lit(self.lock_stall_heal_time.to_f64()),
            lock_stall_max_speed_ratio: U::lit(self.lock_stall_max_speed_ratio.to_f64()),
            lock_stall_min_current_ratio: U::lit(self.lock_stall_min_current_ratio.to_f64()),
            lock_stall_gross_error_ratio: U::lit(self.lock_stall_gross_error_ratio.to_f64()),
            lock_stall_kdf_speed_ratio: U::lit(self.lock_stall_kdf_speed_ratio.to_f64()),
            lock_stall_follow_time: U::lit(self.lock_stall_follow_time.to_f64()),
            lock_stall_follow_min_current_ratio: U::lit(
                self.lock_stall_follow_min_current_ratio.to_f64(),
            ),
            lock_stall_follow_accel_ratio: U::lit(self.lock_stall_follow_accel_ratio.to_f64()),
            lock_stall_torque_band_ratio: U::lit(self.lock_stall_torque_band_ratio.to_f64()),
            lock_stall_reluctance_band_ratio: U::lit(
                self.lock_stall_reluctance_band_ratio.to_f64(),
            ),
            standstill_probe: self.standstill_probe,
            standstill_probe_current_ratio: U::lit(self.standstill_probe_current_ratio.to_f64()),
            standstill_probe_period: U::lit(self.standstill_probe_period.to_f64()),
            standstill_probe_gain: U::lit(self.standstill_probe_gain.to_f64()),
            standstill_probe_speed_ratio: U::lit(self.standstill_probe_speed_ratio.to_f64()),
            standstill_probe_load_ratio: U::lit(self.standstill_probe_load_ratio.to_f64()),
        }
    }
}

impl<T: Real> Default for DriveTuning<T> {
    fn default() -> Self {
        let per_rated = |amps: f64| T::lit(amps / PAPER_RATED_CURRENT);
        Self {
            current_bandwidth_hz: T::lit(current_controller::DEFAULT_BANDWIDTH_HZ),
            speed_bandwidth_hz: T::lit(speed_controller::DEFAULT_BANDWIDTH_HZ),
            speed_zero_ratio: T::lit(speed_controller::DEFAULT_ZERO_RATIO),
            current_limit_ratio: T::lit(speed_controller::DEFAULT_CURRENT_LIMIT_RATIO),
            injection_current_ratio: T::lit(injection::DEFAULT_CURRENT_RATIO),
            mtpa: true,
            acceleration_feedforward: false,
            dead_time: T::lit(dead_time_compensation::DEFAULT_DEAD_TIME),
            switching_frequency: T::lit(dead_time_compensation::DEFAULT_SWITCHING_FREQUENCY),
            dead_time_threshold_voltage: T::lit(dead_time_compensation::DEFAULT_THRESHOLD_VOLTAGE),
            dead_time_current_band: T::lit(dead_time_compensation::DEFAULT_CURRENT_BAND),
            dead_time_compensation: true,
            dead_time_method: dead_time_compensation::DEFAULT_METHOD,
            delay_compensation_factor: T::lit(delay_compensation::DEFAULT_FACTOR),
            trip_current_ratio: per_rated(60.0),
            decoupling: current_controller::DEFAULT_DECOUPLING,
            voltage_limit: VoltageLimit::Hexagon,
            max_modulation: T::one(),
            current_anti_windup_ratio: T::lit(current_controller::DEFAULT_ANTI_WINDUP_RATIO),
            speed_anti_windup_ratio: T::lit(speed_controller::DEFAULT_ANTI_WINDUP_RATIO),
            offset_calibration_time: T::lit(0.1),
            gain_calibration_time: T::lit(0.05),
            gain_calibration_current_ratio: T::one(),
            gain_calibration_min_observability: T::lit(gain_calibration::DEFAULT_MIN_OBSERVABILITY),
            gain_calibration_max_mismatch: T::lit(gain_calibration::DEFAULT_MAX_MISMATCH),
            stuck_sensor_band_ratio: per_rated(0.25),
            stuck_sensor_reference_ratio: per_rated(2.0),
            stuck_sensor_time: T::lit(0.5e-3),
            current_error_ratio: per_rated(5.0),
            current_error_time: T::lit(2e-3),
            dc_link_min_ratio: T::lit(2.0 / 3.0),
            input_fault_trip_time: T::lit(10e-3),
            plausible_current_ratio: T::lit(2.0),
            dc_link_max_ratio: T::lit(crate::plausibility::VOLTAGE_RATIO),
            dc_link: DcLinkTuning::default(),
            field_weakening: FieldWeakeningTuning::default(),
            release_hold: ReleaseHoldTuning::default(),
            startup: StartupTuning::default(),
            limits: RatingsLimitTuning::default(),
            tracker_feedforward: TrackerFeedforwardTuning::default(),
            lock_reaction: LockReaction::ReportOnly,
            lock_reaction_on_stall: true,
            lock_recovery_time: T::lit(20e-3),
            lock_recovery_timeout: T::lit(0.5),
            lock_recovery_attempts: 3,
            lock_recovery_rs_adaptation: true,
            lock_stall_speed_ratio: T::lit(0.003),
            lock_stall_time: T::lit(5e-3),
            lock_stall_heal_time: T::lit(0.1),
            lock_stall_max_speed_ratio: T::lit(0.0),
            lock_stall_min_current_ratio: T::lit(0.2),
            lock_stall_gross_error_ratio: T::lit(0.0),
            lock_stall_kdf_speed_ratio: T::lit(0.0175),
            lock_stall_follow_time: T::lit(10e-3),
            lock_stall_follow_min_current_ratio: T::lit(0.5),
            lock_stall_follow_accel_ratio: T::lit(0.005),
            lock_stall_torque_band_ratio: T::lit(STALL_TORQUE_BAND_RATIO),
            lock_stall_reluctance_band_ratio: T::lit(0.05),
            standstill_probe: true,
            standstill_probe_current_ratio: T::lit(0.1),
            standstill_probe_period: T::lit(0.5),
            standstill_probe_gain: T::one(),
            standstill_probe_speed_ratio: T::lit(0.0005),
            standstill_probe_load_ratio: T::lit(0.25),
        }
    }
}
