//! The whole sensorless drive of Fig. 5: estimator, speed and current control, d-axis
//! injection, delay and dead-time compensation, SVPWM — one `step` per 10 kHz sample.
//!
//! Order of operations at sample n (SPEC §1, §5):
//!
//! 1. Reject non-finite inputs (trip after `input_fault_trip_time` of them in a row); remove
//!    the calibrated offsets; trip (gates off, latched) when a phase current exceeds the trip
//!    level; divide phase a by the calibrated gain ratio (see
//!    [`gain_calibration`](crate::control::gain_calibration); while that calibration runs, its
//!    sample replaces steps 2–8); replace a phase-current
//!    channel that reads about zero against a clear reference by a model reconstruction
//!    ([`StuckChannelDetector`]).
//! 2. Estimator with the α-β currents sampled now and the voltage that acted over
//!    [n−1, n]: the realised reference computed at n−2 (computation delay: a duty computed at
//!    n is loaded at n+1 and acts over [n+1, n+2]), before dead-time compensation.
//! 3. Park of the measured current at θ̂\[n\] (T2S-1).
//! 4. Speed PI on ω̂ of T2S-2 → i_q*; injection (23) → i_d*; |i_dq*| ≤ I_max (d first).
//! 5. Current PI with decoupling at ω̂ of T2S-2 → v*_dq.
//! 6. Delay compensation: v*_ab = e^{j(θ̂ + 1.5·ω̂·Ts)}·v*_dq, with ω̂ of T2S-1 (the derivative
//!    of the θ̂ being extrapolated).
//! 7. Dead-time compensation v_comp (Clarke of the per-phase trapezoid) added; the sum is
//!    limited to the hexagon and modulated. The realised reference is limited − v_comp: what
//!    the inverter produces once its non-linearity has eaten v_comp.
//! 8. Anti-windup: the realised reference, back in the same advanced d-q frame, feeds the
//!    current PIs; it enters the two-deep history for the estimator.
//! 9. The status word [`DriveFlags`] of the sample is formed and counted.

use crate::control::current_controller::{CurrentController, CurrentControllerConfig};
use crate::control::dead_time_compensation::{
    DeadTimeCompensation, DeadTimeCompensationConfig, DeadTimeMethod,
};
use crate::control::delay_compensation::{DelayCompensation, DelayCompensationConfig};
use crate::control::gain_calibration::{
    GainCalibration, GainCalibrationConfig, GainCalibrationStatus,
};
use crate::control::lock_reaction::{LockAction, LockReaction, LockSupervisor};
use crate::control::modulation::{ModulatorConfig, SpaceVectorModulator, VoltageLimit};
use crate::control::monitor::{DriveFlags, FlagCounts, PersistenceMonitor, StuckChannelDetector};
use crate::control::speed_controller::{
    SpeedController, SpeedControllerConfig, limit_current_d_priority,
};
use crate::control::standstill_probe::{StandstillProbe, StandstillProbeConfig};
use crate::error::{ConfigError, check};
use crate::estimator::{
    Estimate, EstimatorConfig, EstimatorTuning, RotorAngleEstimator, SensorlessEstimator,
};
use crate::injection::{CurrentInjection, CurrentInjectionConfig};
use crate::lock::{Debouncer, LockStatus};
use crate::machine::PAPER_RATED_CURRENT;
use crate::mode::Mode;
use crate::{Ab, Abc, Dq, MachineModel, Real, Rotation};

/// The drive's tuning: every setting that is not the machine or the sampling period. Defaults
/// are ratios of the machine's ratings or durations in seconds, chosen so that the paper's
/// motor ([`MachineModel::paper`], 21.78 A rated) gets the paper's and SPEC's absolute values
/// (written beside each ratio); the inverter data (dead time, switching frequency, threshold
/// voltage, current band) are SPEC §5's; they are not serde keys (`fado-sim` derives them from
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
    /// Speed PI zero as a fraction of its bandwidth, Ki = Kp·ωsc/ratio. Default 5 (SPEC §6).
    pub speed_zero_ratio: T,
    /// Current limit I_max (|i_dq*|) as a multiple of the rated current. Default 40/21.78
    /// (SPEC §6 \[A\]: 40 A on the paper's motor).
    pub current_limit_ratio: T,
    /// Minimum current I_min of the injection (23) as a fraction of the rated current; 0
    /// disables it. Default 4/21.78 (paper, V: 4 A).
    pub injection_current_ratio: T,
    /// Maximum-torque-per-ampere d current on salient machines (L̂d ≠ L̂q; see
    /// [`MachineModel::mtpa_id`]), added to the injection's. No effect on a surface-magnet
    /// rotor. Default true.
    pub mtpa: bool,
    /// Dead time Td in s (inverter datum). Default 2.5 µs (paper, V).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub dead_time: T,
    /// Switching frequency in Hz (inverter datum). Default 5 kHz (paper, V).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub switching_frequency: T,
    /// Device threshold voltage of the dead-time compensation in V (inverter datum). Default
    /// 1 V (SPEC §5 \[A\]).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub dead_time_threshold_voltage: T,
    /// Current band Ic of the trapezoidal compensation in A (inverter datum). Default 0.3 A
    /// (SPEC §5 \[A\]).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub dead_time_current_band: T,
    /// Compensate the dead time at all. Default true (paper IV-B).
    pub dead_time_compensation: bool,
    /// Shape of the compensation. Default [`DeadTimeMethod::EdgeCurrent`] \[A\]: the SPEC §5
    /// trapezoid evaluated at each switching edge's predicted current (PWM ripple included,
    /// L̂d, L̂q of the machine model); it keeps |λ̂r| from shrinking while a phase
    /// current sits in the band at standstill under load (docs/zero-speed-errors.md).
    pub dead_time_method: DeadTimeMethod,
    /// Angle advance of the voltage in samples. Default 1.5 (SPEC §5 \[A\], ref. \[13\]).
    pub delay_compensation_factor: T,
    /// Over-current trip level on any phase current, as a multiple of the rated current
    /// (latched until `reset`). Default 60/21.78 (1.5·I_max: 60 A on the paper's motor) \[A\].
    pub trip_current_ratio: T,
    /// Decoupling and back-EMF feed-forward in the current PI. Default true (SPEC §6 \[A\]).
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
    /// (`swing_time_constant`) before it is averaged; a machine needing a hold above 0.2 s is
    /// skipped. Default 0.05 s \[A\] (500 samples at 10 kHz: 10 mA rms of noise averages to
    /// 0.45 mA, 0.02 % of the lower level's phase-b current at the observability limit on the
    /// paper's motor). A 0.5 % mismatch walks θ̂ at loaded standstill on a low-flux motor
    /// (README: the outrunner preset lost `reversal` and `stops`, 1.2 rad). Start-up added on
    /// the presets: 0.33 s (outrunner-cheetah-24v) to 0.52 s (paper).
    pub gain_calibration_time: T,
    /// Upper current level of the gain calibration as a multiple of the rated current (the
    /// lower level is half of it; at most `current_limit_ratio`, and on a rotor with L̂q > L̂d
    /// at most half of λ̂f/(L̂q − L̂d), see [`DriveConfig::gain_calibration_config`]). Default 1 \[A\]: the continuous rating (the larger the
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
    /// tolerance; the simulator's default mismatch is 0.5 %, SPEC §6).
    pub gain_calibration_max_mismatch: T,
    /// Stuck current-sensor detection: a channel reading within ±this fraction of the rated
    /// current of zero while the reference asks for at least `stuck_sensor_reference_ratio`
    /// in its phase. Default 0.25/21.78 \[A\] (0.25 A: 10 LSB of a 12-bit ±50 A ADC, 25σ of
    /// 10 mA sensor noise, SPEC §6).
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
    /// Reaction to the estimator's [`LockStatus::Lost`] (`DriveFlags::LOCK_LOST`) and, with
    /// `lock_reaction_on_stall`, to the stall symptom (`DriveFlags::STALLED`). Default report
    /// only \[A\] (the paper's behaviour plus the flags).
    pub lock_reaction: LockReaction,
    /// Whether the stall symptom (`DriveFlags::STALLED`, see `lock_stall_speed_ratio`) starts
    /// `lock_reaction` like the estimator's own verdict. Default on \[A\]: near zero speed a
    /// lost estimate shows first, and on the fig11 envelope in 39 % of the fixed-R̂s losses
    /// only, as a stall (docs/lock.md), and a drive that coasts, re-aligns and restarts
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
    /// what loses the rotor in the loaded zero-speed passage (docs/lock.md), and restarting
    /// with the same R̂s meets the same passage with the same error.
    pub lock_recovery_rs_adaptation: bool,
    /// Stall symptom of the loss-of-lock detection (see [`crate::lock`], "speed-loop stall"):
    /// in limiter mode, a speed error |ω* − ω̂| above this multiple of the rated speed for
    /// `lock_stall_time` raises `STALLED` (and starts the lock reaction, see
    /// `lock_reaction_on_stall`; widened with the commanded torque on motors of small inertia
    /// for their torque, `lock_stall_torque_band_ratio`). Default 0.003
    /// \[A\] (4.5 r/min at 1500 r/min rated, a fifth of the default Fig. 3 threshold
    /// `mode_threshold_ratio` 0.015; chosen on the fig11 envelope with the current gate
    /// `lock_stall_min_current_ratio` and the exception `lock_stall_follow_time`,
    /// docs/lock.md: 0.005 reaches the band 20–60 ms after the error passes 0.5 rad in 10
    /// of 208 fixed-R̂s losses; the light-load losses that 0.004 saw late reach
    /// 0.0034–0.0038·rated by 15 ms after the error passes 0.5 rad; below 0.004 the rotor
    /// lagging the ramp under heavy load false-alarmed until the exception); 0 disables.
    pub lock_stall_speed_ratio: T,
    /// Net time (s) the stall condition must hold (up/down count, [`crate::lock::Debouncer`]).
    /// Default 5 ms \[A\] (the estimator's
    /// `lock_detection_time`).
    pub lock_stall_time: T,
    /// Net time (s) without the stall condition after which the stall symptom clears (it is
    /// a live status like the estimator's, see [`crate::lock::Debouncer`]; the reaction
    /// latches). Default 0.1 s \[A\] (the estimator's `lock_heal_time`).
    pub lock_stall_heal_time: T,
    /// The stall symptom counts only while |ω̂| is below this multiple of the rated speed, or
    /// while ω̂ turns against ω*; 0: at any speed. Default 0 (off) \[A\]. The first round's
    /// false alarms of the symptom (|n̂| 12–25 r/min around the limiter ↔ k_df hand-over)
    /// were swings of ω̂ at light load; the current gate `lock_stall_min_current_ratio`
    /// removes them without this restriction, which missed the losses in which ω̂ sticks
    /// at 12–20 r/min while the reference passes (docs/lock.md: 0.0075 detects 81.7 % of the
    /// fixed-R̂s losses, off 94.2 %, both at the 0.005 band).
    pub lock_stall_max_speed_ratio: T,
    /// The stall symptom counts only while the speed loop asks for a torque: |i_q*| at least
    /// this multiple of the rated current. Default 0.2 \[A\] (docs/lock.md). A lost
    /// estimate shows on the mechanical side through the torque the drive commands and the
    /// rotor does not answer; with next to no torque commanded the rotor's motion is the
    /// load's and the inertia's, and a swing of ω̂ past the band is no evidence against the
    /// angle. On the fig11 envelope every false alarm of the symptom without the speed
    /// restriction had |i_q*| of 0.05–0.15 of rated (light loads; the lag of ω̂ behind the
    /// ramp at the limiter → k_df hand-over after the reversal, one at start-up), every
    /// loss it caught that the restriction had missed 0.26 or more; 0.15 still false-alarmed
    /// at 0.151 (docs/lock.md). 0: always.
    pub lock_stall_min_current_ratio: T,
    /// The current gate of `lock_stall_min_current_ratio` does not apply while the speed error
    /// |ω* − ω̂| exceeds this multiple of the stall band *and* ω̂ turns against ω* (ω̂·ω* < 0):
    /// a gross speed error against the reference, evidence against the estimate whatever the
    /// current. The gate's 0.2 of rated current is, through the speed loop's proportional
    /// gain, a speed error of 13 bands on the paper's motor but 28 on ipmsm-gem-50k, whose
    /// inertia is small for its torque; there the start-up losses with L̂q over-estimated
    /// (ω̂ oscillating against the reference, |i_q*| 0.12–0.16 of rated) were flagged 25–100 ms
    /// late. 0: the gate always applies. Default 0 \[A\]: with 3, on the reversal envelope
    /// (docs/lock.md, "A gross speed error against the reference"), ipmsm-gem-50k detects
    /// 124/140 and 212/247 losses on seed 7 instead of 96 and 185 (119/141 and 189/224 instead
    /// of 100 and 172 on seed 8) and outrunner-cheetah-24v 268/274 instead of 251 (fixed R̂s),
    /// the paper's motor, ipmsm-2k2, servo-1ft6084 and hub-hoverboard-48v are unchanged on
    /// seed 7, but pmsyrm-5k flags 3 of 153 and 8 of 162 passing runs that stayed within
    /// 0.25 rad (0 and 1 with the gate) for the same start-up oscillation of ω̂ that does not
    /// lose its rotor: a trade to choose per motor, not a default.
    pub lock_stall_gross_error_ratio: T,
    /// The stall symptom also counts in k_df mode while |ω̂| is below this multiple of the
    /// rated speed (the limiter ↔ k_df threshold `mode_threshold_ratio` is 0.015, so the
    /// default is a band of 0.0025·rated, 3.75 r/min at 1500 r/min, above it); 0: limiter
    /// mode only. Default 0.0175 \[A\] since the sixth session (docs/lock.md, "The stall
    /// symptom on other motors"); issue 14b's 0.02 (chosen on the fig11 envelope: under heavy
    /// load the estimate is lost in k_df mode just above the threshold, where a limiter-only
    /// symptom does not look) also flagged passing runs on servo-1ft6084 (11 of 259, seed 7),
    /// outrunner-cheetah-24v and hub-hoverboard-48v in which ω̂ swings ±0.003 of rated around
    /// ω* just after the limiter → k_df hand-over at 0.0176–0.0197·rated (0.0175: 4 of 259 on
    /// servo-1ft6084, seed 7; 1 of 254 on seed 8, 12 before); off (0), one fig11 loss in
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
    /// envelope (docs/lock.md, fifth session) were the rotor *itself* lagging the ramp
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
    /// estimate off by δ = 0.25 rad, the largest angle error issue 14 still calls a clean
    /// run. A rotor that lags its reference because the estimate is off by less than that is
    /// then inside the band; one off by more, or stalled, leaves it (docs/lock.md, "A band
    /// from the clean threshold", ninth session). Measured on the seven presets' reversal
    /// envelopes, seeds 7 and 8, against the sixth session's 0.015:
    /// - outrunner-cheetah-24v with the R̂s adaptation: its false alarms go from 13 of 183
    ///   and 12 of 166 passing runs to none. They were rotors lagging the zero-speed exit of
    ///   the ramp by 0.003–0.008 of rated speed under an estimate 0.16–0.25 rad off.
    /// - pmsyrm-5k, fixed R̂s, seed 8: 1 of 162 to none.
    /// - Detections lost: the paper's motor 1 of 218 (seed 8, at 93 % of rated torque, 115 ms
    ///   late) and outrunner-cheetah-24v with fixed R̂s 3 of 292 (seed 8).
    /// - Nothing else changed on any preset.
    ///
    /// The sixth session's value, 0.015, was the largest that left the paper's motor as it
    /// was then (0.02 delayed 92 of its 205 detections on seed 7 and 0.025 missed one; the
    /// symptom has gained the reluctance band and the gross-error waiver since).
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
    /// right (docs/lock.md). Zero on a surface-magnet model (L̂d = L̂q). Default 0.05 \[A\]
    /// (docs/lock.md, "A band for the reluctance torque": on seed 7 of the seven presets
    /// 0.15 loses 10 of 96 detections on ipmsm-gem-50k and 12 of 53 on pmsyrm-5k, 0.05 none;
    /// over seeds 7, 8, 21 and 22 it takes the passing runs flagged from 100 to 10 of 1012 on
    /// pmsyrm-5k and from 213 to 158 of 564 on ipmsm-gem-50k, with no detection lost on any
    /// preset, and leaves fig11's hold-out seeds 17–20 at 856/856 detected, 0 of 418 flagged).
    pub lock_stall_reluctance_band_ratio: T,
    /// The loaded-standstill angle probe (see [`crate::control::standstill_probe`]): at a
    /// loaded standstill a slow square-wave d current, read through the speed loop's torque
    /// balance, turns θ̂ towards the rotor. Default true \[A\] (without it the one-hour loaded
    /// standstill drifts to the current limit on 4 of 5 sensor seeds, docs/long-run.md).
    pub standstill_probe: bool,
    /// Probe amplitude Δi_d as a fraction of the rated current. Default 0.1 \[A\] (2.2 A on
    /// the paper's motor: no torque at δ = 0, 0.5 % more copper loss at rated load; the
    /// reading Δi_d·tan δ is 0.2 A at δ = 0.1 rad against a speed-loop ripple the
    /// demodulation averages over a whole period).
    pub standstill_probe_current_ratio: T,
    /// Probe period T_p in s. Default 0.5 s \[A\]: each half holds 0.25 s, 8 time constants
    /// 1/(2π·f_sc) of the 5 Hz speed loop (1.6 of its PI zero's ratio/(2π·f_sc) = 0.16 s), the
    /// correlation reads the second half of each half, after 4 loop time constants. Measured
    /// on the loaded hour's configuration (docs/zero-speed-errors.md, fifth pass): a longer
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
            current_bandwidth_hz: T::lit(250.0),
            speed_bandwidth_hz: T::lit(5.0),
            speed_zero_ratio: T::lit(5.0),
            current_limit_ratio: per_rated(40.0),
            injection_current_ratio: per_rated(4.0),
            mtpa: true,
            dead_time: T::lit(2.5e-6),
            switching_frequency: T::lit(5e3),
            dead_time_threshold_voltage: T::one(),
            dead_time_current_band: T::lit(0.3),
            dead_time_compensation: true,
            dead_time_method: DeadTimeMethod::EdgeCurrent,
            delay_compensation_factor: T::lit(1.5),
            trip_current_ratio: per_rated(60.0),
            decoupling: true,
            voltage_limit: VoltageLimit::Hexagon,
            max_modulation: T::one(),
            current_anti_windup_ratio: T::one(),
            speed_anti_windup_ratio: T::lit(5.0),
            offset_calibration_time: T::lit(0.1),
            gain_calibration_time: T::lit(0.05),
            gain_calibration_current_ratio: T::one(),
            gain_calibration_min_observability: T::lit(0.2),
            gain_calibration_max_mismatch: T::lit(0.05),
            stuck_sensor_band_ratio: per_rated(0.25),
            stuck_sensor_reference_ratio: per_rated(2.0),
            stuck_sensor_time: T::lit(0.5e-3),
            current_error_ratio: per_rated(5.0),
            current_error_time: T::lit(2e-3),
            dc_link_min_ratio: T::lit(2.0 / 3.0),
            input_fault_trip_time: T::lit(10e-3),
            plausible_current_ratio: T::lit(2.0),
            dc_link_max_ratio: T::lit(crate::plausibility::VOLTAGE_RATIO),
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

/// Everything the drive around the estimator needs: the sampling period, the machine model
/// (R̂s, L̂d, L̂q, λ̂f, Ĵ, pole pairs and the ratings the tuning's ratios refer to) and the
/// tuning. Build it with [`DriveConfig::for_machine`]; the drive hands the same machine model
/// to its estimator, so the model exists once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriveConfig<T> {
    /// Sampling period Ts in s (paper, V: 100 µs, 10 kHz, twice the switching frequency).
    pub ts: T,
    /// The drive's model of the motor.
    pub machine: MachineModel<T>,
    /// Gains, limits, thresholds and switches.
    pub tuning: DriveTuning<T>,
}

impl<T: Real> DriveConfig<T> {
    /// The default tuning around `machine`, sampled at 10 kHz (paper, V).
    pub fn for_machine(machine: &MachineModel<T>) -> Self {
        Self {
            ts: T::lit(100e-6),
            machine: *machine,
            tuning: DriveTuning::default(),
        }
    }

    /// Checks every field (without an estimator); the error names the first bad one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        Resolved::new(self)
            .and_then(|r| Blocks::new(self, &r))
            .and_then(|_| GainCalibration::new(self.gain_calibration_config()?))
            .map(|_| ())
    }

    /// The start-up gain calibration's configuration in absolute units: upper level
    /// `gain_calibration_current_ratio` × the rated current (at most the current limit),
    /// settling 5·max(L̂d/R̂s, 1/ωc) per level, window `gain_calibration_time`.
    pub fn gain_calibration_config(&self) -> Result<GainCalibrationConfig<T>, ConfigError> {
        self.machine.validate()?;
        let t = &self.tuning;
        let m = &self.machine;
        let ratio = check::positive(
            "gain_calibration_current_ratio",
            t.gain_calibration_current_ratio,
        )?;
        let ratio = crate::real::min(ratio, t.current_limit_ratio);
        let omega_c =
            T::two_pi() * check::positive("current_bandwidth_hz", t.current_bandwidth_hz)?;
        let tau_stator = m.ld / m.rs;
        let tau = crate::real::max(tau_stator, T::one() / omega_c);
        let settle = T::lit(GAIN_CALIBRATION_SETTLE_TIME_CONSTANTS) * tau;
        // On a rotor with L̂q > L̂d at most half of λ̂f/(L̂q − L̂d), so that the d-axis hold keeps
        // half the magnet's stiffness (as the commissioning's DC test, see
        // `commissioning::dc_level`): at λ̂f/(L̂q − L̂d) the reluctance torque cancels it and
        // the rotor turns to the q axis.
        let dl = m.lq - m.ld;
        let i2 = ratio * m.rated_current;
        let i2 = if dl > T::zero() {
            crate::real::min(i2, T::lit(0.5) * m.flux_linkage / dl)
        } else {
            i2
        };
        let i1 = T::lit(0.5) * i2;
        let hold = T::lit(GAIN_CALIBRATION_HOLD_TIME_CONSTANTS)
            * crate::real::max(swing_time_constant(m, i1), swing_time_constant(m, i2));
        let rename = |e: ConfigError| match e {
            ConfigError::OutOfRange { field, expected } => ConfigError::OutOfRange {
                field: gain_field(field),
                expected,
            },
            ConfigError::NotFinite { field } => ConfigError::NotFinite {
                field: gain_field(field),
            },
            ConfigError::NotPositive { field } => ConfigError::NotPositive {
                field: gain_field(field),
            },
            ConfigError::Negative { field } => ConfigError::Negative {
                field: gain_field(field),
            },
        };
        let config = GainCalibrationConfig {
            ts: self.ts,
            current: i1,
            rs_hat: m.rs,
            settle_time: settle,
            hold_time: hold,
            max_hold_time: T::lit(GAIN_CALIBRATION_MAX_HOLD_TIME),
            window_time: t.gain_calibration_time,
            min_observability: t.gain_calibration_min_observability,
            max_mismatch: t.gain_calibration_max_mismatch,
            current_limit: self.i_max(),
        };
        GainCalibration::new(config).map_err(rename)?;
        Ok(config)
    }

    /// The configured current limit I_max in A.
    pub fn i_max(&self) -> T {
        self.tuning.current_limit_ratio * self.machine.rated_current
    }

    /// The configured injection level I_min of eq. (23) in A.
    pub fn i_min(&self) -> T {
        self.tuning.injection_current_ratio * self.machine.rated_current
    }

    /// The configured trip level in A.
    pub fn trip_current(&self) -> T {
        self.tuning.trip_current_ratio * self.machine.rated_current
    }
}

/// Default of [`DriveTuning::lock_stall_torque_band_ratio`]: 1 − cos(0.25 rad), the torque
/// deficit of an estimate 0.25 rad off (issue 14's largest "clean" angle error).
const STALL_TORQUE_BAND_RATIO: f64 = 0.031_087_578_289_355_3;

/// Settling of each gain-calibration level in time constants (of the stator, L̂d/R̂s, or of
/// the current loop, 1/ωc, whichever is slower): e⁻⁵ = 0.7 % of a step left \[A\].
const GAIN_CALIBRATION_SETTLE_TIME_CONSTANTS: f64 = 5.0;

/// The swing of the rotor held by the calibration's d current, after the voltage is frozen,
/// dies out in this many of its slowest time constants ([`swing_time_constant`]): e⁻⁴ = 1.8 %
/// of the swing's back-EMF left \[A\] (measured: in current mode the swing biased k by
/// 2.8e-3 on the paper's motor; a fixed rotor gives 4e-6).
const GAIN_CALIBRATION_HOLD_TIME_CONSTANTS: f64 = 4.0;

/// Longest hold of a gain-calibration level, s \[A\]: a start-up budget (with it the whole
/// calibration takes at most about 0.5 s plus the settling). A rotor whose swing needs longer
/// is not calibrated (status `TooSlow`): averaged before the swing has died out, the
/// 5 kW PM-SyRM and 50 kW IPMSM presets (held at reduced active flux) measured k off by up to
/// 1.7e-2 with a 0.15 s hold, more than the 5e-3 mismatch itself.
const GAIN_CALIBRATION_MAX_HOLD_TIME: f64 = 0.2;

/// The slowest time constant (s) of the rotor's swing about the d current `i_d` in voltage
/// mode: J·s² + c·s + K with the stiffness K = 1.5·p²·λ̂a·i_d (electrical rad → N·m about the
/// shaft; λ̂a = λ̂f + (L̂d − L̂q)·i_d the active flux) and the resistive damping
/// c = 1.5·p²·λ̂a·λ̂f/R̂s (the back-EMF's q current through R̂s, electrical lag neglected):
/// 2J/c when under-damped, 2J/(c − √(c² − 4JK)) otherwise. Friction is left out (it only
/// damps more).
pub(crate) fn swing_time_constant<T: Real>(m: &MachineModel<T>, i_d: T) -> T {
    let p2 = T::lit((m.pole_pairs as f64) * (m.pole_pairs as f64));
    let flux = crate::real::max(m.active_flux(i_d), T::lit(0.1) * m.flux_linkage);
    let c = T::lit(1.5) * p2 * flux * m.flux_linkage / m.rs;
    let k = T::lit(1.5) * p2 * flux * i_d;
    let disc = c * c - T::lit(4.0) * m.inertia * k;
    let two_j = m.inertia + m.inertia;
    if disc > T::zero() {
        two_j / (c - disc.step_sqrt())
    } else {
        two_j / c
    }
}

/// Largest `current_limit_ratio`: 5 (a drive's short-time overload is 1.5–3 × the rated
/// current; above 5 the limit is a typo, and the trip level above it would be refused in its
/// stead).
const MAX_CURRENT_LIMIT_RATIO: f64 = 5.0;

/// The drive's name of a [`GainCalibrationConfig`] field.
fn gain_field(field: &'static str) -> &'static str {
    match field {
        "window_time" => "gain_calibration_time",
        "min_observability" => "gain_calibration_min_observability",
        "max_mismatch" => "gain_calibration_max_mismatch",
        "current" => "gain_calibration_current_ratio",
        "settle_time" | "hold_time" | "max_hold_time" => "current_bandwidth_hz",
        "current_limit" => "current_limit_ratio",
        f => f,
    }
}

/// The absolute limits and sample counts of a [`DriveConfig`], resolved once from its ratios
/// and durations (nothing is recomputed per sample).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Resolved<T> {
    i_max: T,
    i_min: T,
    trip_current: T,
    current_error_limit: T,
    dc_link_min_voltage: T,
    offset_calibration_samples: u32,
    stuck_sensor_samples: u32,
    current_error_samples: u32,
    input_fault_trip_samples: u32,
    /// Stall symptom: speed error (electrical rad/s) in limiter mode, and samples in a row
    /// (0 samples or speed 0: off).
    stall_speed: T,
    stall_samples: u32,
    stall_heal_samples: u32,
    /// The stall symptom counts below this |ω̂| (electrical rad/s; ∞: always).
    stall_max_speed: T,
    /// The stall symptom also counts in k_df mode below this |ω̂| (electrical rad/s; 0: only
    /// in limiter mode).
    stall_kdf_band: T,
    /// The stall symptom counts from this |i_q*| on (A).
    stall_min_current: T,
    /// ... or beyond this multiple of the band (∞: the current gate always applies).
    stall_gross_ratio: T,
    /// Per-sample gain 1 − exp(−Ts/τ) of the ω̂ low-pass of `lock_stall_follow_time` (0: the
    /// "answers the torque" exception is off).
    stall_follow_gain: T,
    /// The exception holds from this |i_q*| on (A).
    stall_follow_min_current: T,
    /// ω̂ − ω̂_lp (electrical rad/s) beyond which ω̂ accelerates: the least acceleration
    /// times τ.
    stall_follow_lead: T,
    /// Band widening per unit of (λ̂f + (L̂d − L̂q)·i_d*)·i_q* (electrical rad/s per Wb·A): the
    /// torque ratio of `lock_stall_torque_band_ratio` times 1.5·p (torque) times p (electrical
    /// speed) over Ĵ·ω_s.
    stall_torque_band: T,
    /// The same for `lock_stall_reluctance_band_ratio`, per unit of (L̂d − L̂q)·i_d*·i_q*
    /// (Wb·A).
    stall_reluctance_band: T,
    /// Phase currents beyond ± this (A) are refused as implausible.
    plausible_current: T,
    /// DC-link readings above this (V) are refused as implausible.
    dc_link_max_voltage: T,
    /// MTPA d current on (configured and the machine is salient).
    mtpa: bool,
    /// The machine is salient: the speed loop's q current is scaled by λ̂f/λ̂a (see
    /// [`Drive::torque_current`]).
    salient: bool,
}

impl<T: Real> Resolved<T> {
    fn new(c: &DriveConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", c.ts)?;
        c.machine.validate()?;
        let t = &c.tuning;
        let rated = c.machine.rated_current;
        // A duration as a whole number of samples (at most about 5 days at 10 kHz).
        let samples = |field: &'static str, time: T| -> Result<u32, ConfigError> {
            let n = check::non_negative(field, time)? / ts;
            check::below(field, n, T::lit(4e9), "below 4e9 sampling periods")?;
            Ok(n.round().to_f64() as u32)
        };
        // A stall-band ratio ε per unit of torque over 1.5·p (Wb·A): ε·1.5·p (torque) times
        // p (electrical speed) over Ĵ·ω_s, the speed error whose proportional action commands
        // that torque.
        let torque_band = |field: &'static str, ratio: T| -> Result<T, ConfigError> {
            Ok(check::non_negative(field, ratio)?
                * T::lit(1.5 * (c.machine.pole_pairs as f64) * (c.machine.pole_pairs as f64))
                / (c.machine.inertia * T::lit(core::f64::consts::TAU) * t.speed_bandwidth_hz))
        };
        Ok(Self {
            i_max: check::below(
                "current_limit_ratio",
                check::positive("current_limit_ratio", t.current_limit_ratio)?,
                T::lit(MAX_CURRENT_LIMIT_RATIO),
                "at most 5 × the rated current (drives' short-time overload is 1.5–3×)",
            )? * rated,
            i_min: check::non_negative("injection_current_ratio", t.injection_current_ratio)?
                * rated,
            trip_current: check::positive("trip_current_ratio", t.trip_current_ratio)? * rated,
            current_error_limit: check::positive("current_error_ratio", t.current_error_ratio)?
                * rated,
            dc_link_min_voltage: check::below(
                "dc_link_min_ratio",
                check::non_negative("dc_link_min_ratio", t.dc_link_min_ratio)?,
                T::one(),
                "below 1 (a fraction of the nominal DC link: at or above it the warning never clears)",
            )? * c.machine.dc_voltage,
            offset_calibration_samples: samples(
                "offset_calibration_time",
                t.offset_calibration_time,
            )?,
            stuck_sensor_samples: samples("stuck_sensor_time", t.stuck_sensor_time)?,
            current_error_samples: samples("current_error_time", t.current_error_time)?,
            input_fault_trip_samples: samples("input_fault_trip_time", t.input_fault_trip_time)?,
            stall_speed: check::non_negative("lock_stall_speed_ratio", t.lock_stall_speed_ratio)?
                * c.machine.rated_speed(),
            stall_samples: if t.lock_stall_speed_ratio > T::zero() {
                samples("lock_stall_time", t.lock_stall_time)?.max(1)
            } else {
                0
            },
            stall_heal_samples: samples("lock_stall_heal_time", t.lock_stall_heal_time)?,
            stall_max_speed: match check::non_negative(
                "lock_stall_max_speed_ratio",
                t.lock_stall_max_speed_ratio,
            )? {
                r if r == T::zero() => T::lit(f64::INFINITY),
                r => r * c.machine.rated_speed(),
            },
            stall_kdf_band: check::non_negative(
                "lock_stall_kdf_speed_ratio",
                t.lock_stall_kdf_speed_ratio,
            )? * c.machine.rated_speed(),
            stall_min_current: check::non_negative(
                "lock_stall_min_current_ratio",
                t.lock_stall_min_current_ratio,
            )? * rated,
            stall_gross_ratio: match check::non_negative(
                "lock_stall_gross_error_ratio",
                t.lock_stall_gross_error_ratio,
            )? {
                k if k == T::zero() => T::lit(f64::INFINITY),
                k => k,
            },
            stall_follow_gain: match check::non_negative(
                "lock_stall_follow_time",
                t.lock_stall_follow_time,
            )? {
                tau if tau == T::zero() => T::zero(),
                tau => T::one() - (-c.ts / tau).exp(),
            },
            stall_follow_min_current: check::non_negative(
                "lock_stall_follow_min_current_ratio",
                t.lock_stall_follow_min_current_ratio,
            )? * rated,
            stall_follow_lead: check::non_negative(
                "lock_stall_follow_accel_ratio",
                t.lock_stall_follow_accel_ratio,
            )? * c.machine.rated_speed()
                * check::non_negative("lock_stall_follow_time", t.lock_stall_follow_time)?,
            stall_torque_band: torque_band(
                "lock_stall_torque_band_ratio",
                t.lock_stall_torque_band_ratio,
            )?,
            stall_reluctance_band: torque_band(
                "lock_stall_reluctance_band_ratio",
                t.lock_stall_reluctance_band_ratio,
            )?,
            plausible_current: t.plausible_current_ratio * t.trip_current_ratio * rated,
            dc_link_max_voltage: t.dc_link_max_ratio * c.machine.dc_voltage,
            mtpa: t.mtpa && c.machine.is_salient(),
            salient: c.machine.is_salient(),
        })
    }
}

/// The drive's outputs for one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriveOutput<T> {
    /// Duty cycles of the upper switches in [0, 1], to be loaded at the next sample.
    pub duty: Abc<T>,
    /// False after a trip: the gates must be switched off.
    pub gates_enabled: bool,
    /// The realised α-β voltage reference before dead-time compensation (V): what the
    /// estimator will be told acted over [n+1, n+2].
    pub v_ref_ab: Ab<T>,
    /// The measured current in the estimated rotor frame (A).
    pub i_dq: Dq<T>,
    /// The current reference (A).
    pub i_dq_ref: Dq<T>,
    /// The estimator's output for this sample.
    pub estimate: Estimate<T>,
    /// The drive has tripped (latched until `reset`).
    pub tripped: bool,
    /// This sample's inputs were non-finite: the last duty is held and the controllers are
    /// untouched.
    pub input_fault: bool,
    /// The realised voltage reference in the delay-compensated d-q frame (V).
    pub v_dq_ref: Dq<T>,
    /// The voltage reference (with dead-time compensation) had to be limited.
    pub voltage_saturated: bool,
    /// The status word of this sample: faults and warnings (see [`DriveFlags`]).
    pub flags: DriveFlags,
    /// The α-β current the estimator was given this sample (A): the measurement with the
    /// calibrated offsets removed, phase a divided by the calibrated gain ratio, and a stuck
    /// channel reconstructed (the last good current
    /// after a non-finite one; the raw measurement while calibrating or tripped).
    pub i_ab: Ab<T>,
}

impl<T: Real> DriveOutput<T> {
    /// True when every number in the output is finite (the drive guarantees it; tests check).
    pub fn is_finite(&self) -> bool {
        self.duty.is_finite()
            && self.v_ref_ab.is_finite()
            && self.i_dq.is_finite()
            && self.i_dq_ref.is_finite()
            && self.v_dq_ref.is_finite()
            && self.i_ab.is_finite()
            && self.estimate.is_finite()
    }

    fn idle(estimate: Estimate<T>) -> Self {
        let half = T::lit(0.5);
        Self {
            duty: Abc::new(half, half, half),
            gates_enabled: true,
            v_ref_ab: Ab::zero(),
            i_dq: Dq::zero(),
            i_dq_ref: Dq::zero(),
            estimate,
            tripped: false,
            input_fault: false,
            v_dq_ref: Dq::zero(),
            voltage_saturated: false,
            flags: DriveFlags::NONE,
            i_ab: Ab::zero(),
        }
    }
}

impl<T: Real> Default for DriveOutput<T> {
    /// Duties ½ (zero voltage), gates enabled, everything else zero.
    fn default() -> Self {
        Self::idle(Estimate::default())
    }
}

/// The control blocks built from a [`DriveConfig`].
#[derive(Clone, Copy, Debug, PartialEq)]
struct Blocks<T> {
    speed: SpeedController<T>,
    injection: CurrentInjection<T>,
    current: CurrentController<T>,
    delay: DelayCompensation<T>,
    dead_time: DeadTimeCompensation<T>,
    probe: StandstillProbe<T>,
    modulator: SpaceVectorModulator<T>,
}

/// What the modulator applies at a sample: the duties, and the voltage that acts (α-β and in
/// the frame of the rotation used), which is the reference itself unless the hexagon limited
/// it.
#[derive(Clone, Copy)]
struct Applied<T> {
    duty: Abc<T>,
    v_ab: Ab<T>,
    v_dq: Dq<T>,
    saturated: bool,
}

impl<T: Real> Blocks<T> {
    /// Dead-time compensation, hexagon limit and SVPWM of the reference `v_ab` (`v_dq` in the
    /// frame of `rot`), and the voltage that then acts, back-calculated without the
    /// compensation where the modulator limited it (zero without a DC link). None when
    /// anything is non-finite.
    #[inline(always)]
    fn modulate(
        &mut self,
        rot: Rotation<T>,
        v_ab: Ab<T>,
        v_dq: Dq<T>,
        i_dq_ref: Dq<T>,
        i_abc: Abc<T>,
        vdc: T,
    ) -> Option<Applied<T>> {
        let v_comp = self.dead_time.step(rot, i_dq_ref, i_abc, v_ab, vdc);
        let m = self.modulator.step(v_ab + v_comp, vdc);
        let (v_ab, v_dq) = if !m.saturated {
            (v_ab, v_dq) // exactly what was asked for: nothing to back-calculate
        } else if vdc > T::zero() {
            let v = m.v_ab - v_comp;
            (v, v.to_dq(rot))
        } else {
            (Ab::zero(), Dq::zero())
        };
        (v_ab.is_finite() && v_dq.is_finite() && m.duty.is_finite()).then_some(Applied {
            duty: m.duty,
            v_ab,
            v_dq,
            saturated: m.saturated,
        })
    }

    fn new(c: &DriveConfig<T>, r: &Resolved<T>) -> Result<Self, ConfigError> {
        let ts = c.ts;
        let t = &c.tuning;
        let m = &c.machine;
        let (i_max, i_min) = (r.i_max, r.i_min);
        if i_min > i_max {
            return Err(ConfigError::OutOfRange {
                field: "injection_current_ratio",
                expected: "at most current_limit_ratio",
            });
        }
        if r.trip_current <= i_max {
            return Err(ConfigError::OutOfRange {
                field: "trip_current_ratio",
                expected: "above current_limit_ratio",
            });
        }
        let band = check::non_negative("stuck_sensor_band_ratio", t.stuck_sensor_band_ratio)?;
        let min_ref = check::positive(
            "stuck_sensor_reference_ratio",
            t.stuck_sensor_reference_ratio,
        )?;
        if min_ref <= band {
            return Err(ConfigError::OutOfRange {
                field: "stuck_sensor_reference_ratio",
                expected: "above stuck_sensor_band_ratio",
            });
        }
        check::below(
            "plausible_current_ratio",
            T::one(),
            check::finite("plausible_current_ratio", c.tuning.plausible_current_ratio)?,
            "above 1",
        )?;
        check::positive("dc_link_max_ratio", c.tuning.dc_link_max_ratio)?;
        LockSupervisor::new(
            c.tuning.lock_reaction,
            c.ts,
            c.tuning.lock_recovery_time,
            c.tuning.lock_recovery_timeout,
            0,
        )?;
        let rename = |map: &'static [(&'static str, &'static str)]| {
            move |e: ConfigError| {
                let field = map
                    .iter()
                    .find(|(from, _)| *from == e.field())
                    .map_or(e.field(), |(_, to)| *to);
                match e {
                    ConfigError::NotFinite { .. } => ConfigError::NotFinite { field },
                    ConfigError::NotPositive { .. } => ConfigError::NotPositive { field },
                    ConfigError::Negative { .. } => ConfigError::Negative { field },
                    ConfigError::OutOfRange { expected, .. } => {
                        ConfigError::OutOfRange { field, expected }
                    }
                }
            }
        };
        // The speed PI's output is a torque in units of the magnet's q current (see
        // `currents_for_torque`): with MTPA on a salient rotor its limit is the torque of the
        // MTPA point on the current circle |i| = I_max (`SpeedControllerConfig::with_tuning`).
        let speed = SpeedController::new(SpeedControllerConfig::with_tuning(m, t, ts)).map_err(
            rename(&[
                ("bandwidth_hz", "speed_bandwidth_hz"),
                ("zero_ratio", "speed_zero_ratio"),
                ("anti_windup_ratio", "speed_anti_windup_ratio"),
            ]),
        )?;
        let injection = CurrentInjection::new(CurrentInjectionConfig::with_tuning(m, t))?;
        let current = CurrentController::new(CurrentControllerConfig::with_tuning(m, t, ts))
            .map_err(rename(&[
                ("bandwidth_hz", "current_bandwidth_hz"),
                ("anti_windup_ratio", "current_anti_windup_ratio"),
            ]))?;
        let delay = DelayCompensation::new(DelayCompensationConfig::with_tuning(t, ts))
            .map_err(rename(&[("factor", "delay_compensation_factor")]))?;
        let dead_time = DeadTimeCompensation::new(DeadTimeCompensationConfig::with_tuning(m, t))
            .map_err(rename(&[
                ("threshold_voltage", "dead_time_threshold_voltage"),
                ("current_band", "dead_time_current_band"),
            ]))?;
        let modulator = SpaceVectorModulator::new(ModulatorConfig {
            limit: t.voltage_limit,
            max_modulation: t.max_modulation,
        })?;
        let rated = m.rated_current;
        let probe = StandstillProbe::new(StandstillProbeConfig {
            ts,
            amplitude: if t.standstill_probe {
                check::non_negative(
                    "standstill_probe_current_ratio",
                    t.standstill_probe_current_ratio,
                )? * rated
            } else {
                T::zero()
            },
            period: t.standstill_probe_period,
            gain: t.standstill_probe_gain,
            max_speed: check::non_negative(
                "standstill_probe_speed_ratio",
                t.standstill_probe_speed_ratio,
            )? * m.rated_speed(),
            min_load: check::non_negative(
                "standstill_probe_load_ratio",
                t.standstill_probe_load_ratio,
            )? * rated,
        })?;
        Ok(Self {
            speed,
            injection,
            current,
            delay,
            dead_time,
            modulator,
            probe,
        })
    }

    fn reset(&mut self) {
        self.speed.reset();
        self.injection.reset();
        self.current.reset();
        self.delay.reset();
        self.dead_time.reset();
        self.modulator.reset();
        self.probe.reset();
    }
}

/// The sensorless drive of Fig. 5 around any [`RotorAngleEstimator`] (by default the
/// paper's [`SensorlessEstimator`]). Allocation-free, never panics; see the module docs for
/// the order of operations and the timing contract.
///
/// ```
/// use fado_core::control::{DriveConfig, SensorlessDrive};
/// use fado_core::{Abc, EstimatorTuning, MachineModel};
/// let config = DriveConfig::for_machine(&MachineModel::paper());
/// let mut drive = SensorlessDrive::<f32>::new(config, EstimatorTuning::default()).unwrap();
/// drive.align(0.0);
/// // Power-up: the first samples run with the gates off and measure the sensor offsets.
/// while drive.is_calibrating() {
///     assert!(!drive.step(Abc::new(0.02, -0.01, -0.01), 300.0, 0.0).gates_enabled);
/// }
/// assert!((drive.current_offset().a - 0.02).abs() < 1e-6);
/// // In the 10 kHz ISR: phase currents sampled now, dc-link voltage, speed reference.
/// let out = drive.step(Abc::new(0.1, -0.05, -0.05), 300.0, 10.0);
/// assert!(out.gates_enabled && (0.0..=1.0).contains(&out.duty.a));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorlessDrive<T, E = SensorlessEstimator<T>> {
    config: DriveConfig<T>,
    /// The config's limits and sample counts in absolute units.
    resolved: Resolved<T>,
    estimator: E,
    blocks: Blocks<T>,
    /// Realised references (before dead-time compensation) computed at n−1 and n−2.
    history: [Ab<T>; 2],
    /// The last finite α-β current, fed to the estimator while inputs are rejected.
    last_i_ab: Ab<T>,
    last: DriveOutput<T>,
    tripped: bool,
    rejected_samples: u32,
    /// Samples of the offset calibration still to take (gates off while > 0).
    calibration_remaining: u32,
    /// Sum of the raw phase currents during the calibration.
    calibration_sum: Abc<T>,
    /// Phase-current offsets subtracted from every sample (A).
    current_offset: Abc<T>,
    /// The angle of the last `align`, re-applied when the calibration ends.
    aligned_angle: T,
    /// The start-up gain-mismatch calibration (after the offsets) and its result.
    gain: GainCalibration<T>,
    /// 1/k: the factor on the phase-a reading (1 until a ratio is measured).
    gain_correction: T,
    /// Stuck phase-current channel detection and reconstruction.
    stuck_sensor: StuckChannelDetector<T>,
    /// Persistent current-control error.
    current_error: PersistenceMonitor,
    /// The latest verdicts of the two monitors (kept over rejected samples).
    sensor_stuck_now: bool,
    current_error_now: bool,
    /// Rejected samples in a row (trips at `input_fault_trip_samples`).
    consecutive_rejects: u32,
    /// Samples each flag was raised since the last reset.
    flag_counts: FlagCounts,
    /// The α-β current of this sample as reported in [`DriveOutput::i_ab`].
    i_ab_used: Ab<T>,
    /// Reaction to a lost rotor.
    lock: LockSupervisor,
    /// The stall symptom (see `DriveTuning::lock_stall_speed_ratio`) as a live status (heals
    /// like the estimator's; cleared by `align`, `reset`, a recovery's re-arming).
    stall: Debouncer,
    stall_armed: bool,
    /// Why the drive coasts (`LOCK_LOST`, `STALLED` or both): the symptoms up when the
    /// reaction started, kept while it coasts.
    coast_reason: DriveFlags,
    /// ω̂ low-passed with `DriveTuning::lock_stall_follow_time` (electrical rad/s).
    omega_slow: T,
    /// This sample was refused as implausible.
    implausible_now: bool,
}

impl<T: Real> SensorlessDrive<T, SensorlessEstimator<T>> {
    /// The drive with the paper's estimator, built with the drive's own sampling period and
    /// machine model and the given estimator tuning (start-up angle 0; see
    /// [`align`](Self::align)).
    pub fn new(config: DriveConfig<T>, estimator: EstimatorTuning<T>) -> Result<Self, ConfigError> {
        let estimator = EstimatorConfig {
            ts: check::positive("ts", config.ts)?,
            machine: config.machine,
            initial_angle: T::zero(),
            tuning: estimator,
        };
        Self::with_estimator(config, SensorlessEstimator::new(estimator)?)
    }
}

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// The drive around an estimator built by the caller (which must run at `config.ts`).
    /// The estimator is reset.
    pub fn with_estimator(config: DriveConfig<T>, estimator: E) -> Result<Self, ConfigError> {
        let resolved = Resolved::new(&config)?;
        let blocks = Blocks::new(&config, &resolved)?;
        let mut drive = Self {
            config,
            resolved,
            estimator,
            blocks,
            history: [Ab::zero(); 2],
            last_i_ab: Ab::zero(),
            last: DriveOutput::idle(Estimate::default()),
            tripped: false,
            rejected_samples: 0,
            calibration_remaining: 0,
            calibration_sum: Abc::new(T::zero(), T::zero(), T::zero()),
            current_offset: Abc::new(T::zero(), T::zero(), T::zero()),
            aligned_angle: T::zero(),
            gain: GainCalibration::new(config.gain_calibration_config()?)?,
            gain_correction: T::one(),
            stuck_sensor: StuckChannelDetector::new(
                config.tuning.stuck_sensor_band_ratio * config.machine.rated_current,
                config.tuning.stuck_sensor_reference_ratio * config.machine.rated_current,
                resolved.stuck_sensor_samples,
            ),
            current_error: PersistenceMonitor::new(resolved.current_error_samples),
            stall: Debouncer::new(resolved.stall_samples, resolved.stall_heal_samples),
            stall_armed: false,
            coast_reason: DriveFlags::NONE,
            omega_slow: T::zero(),
            sensor_stuck_now: false,
            current_error_now: false,
            consecutive_rejects: 0,
            flag_counts: FlagCounts::default(),
            i_ab_used: Ab::zero(),
            lock: LockSupervisor::new(
                config.tuning.lock_reaction,
                config.ts,
                config.tuning.lock_recovery_time,
                config.tuning.lock_recovery_timeout,
                config.tuning.lock_recovery_attempts,
            )?,
            implausible_now: false,
        };
        drive.reset();
        Ok(drive)
    }

    /// Everything back to the start-up state: controllers, history, estimator, the trip, and
    /// the current-offset calibration (restarted if configured; the old offsets are kept
    /// until the new ones are measured).
    pub fn reset(&mut self) {
        self.estimator.reset();
        self.clear_control(T::zero());
        self.last_i_ab = Ab::zero();
        self.tripped = false;
        self.rejected_samples = 0;
        self.consecutive_rejects = 0;
        self.flag_counts.reset();
        self.lock.reset();
        self.gain.arm();
        self.calibrate_offsets();
    }

    /// (Re)arms the current-sensor gain calibration (see
    /// [`gain_calibration`](crate::control::gain_calibration)): it runs at the next sample
    /// after any offset calibration, along the d axis of the last [`align`](Self::align)'s
    /// angle (the rotor must be there and at rest), then the drive re-aligns there and starts.
    /// The ratio in use is kept until a new one is measured. Nothing happens when it is
    /// disabled (`gain_calibration_time` 0).
    pub fn calibrate_gain(&mut self) {
        self.gain.arm();
    }

    /// True while the gain calibration is armed or running (the gates are on, the speed
    /// reference is ignored).
    pub fn is_calibrating_gain(&self) -> bool {
        self.gain.running()
    }

    /// The current-sensor gain ratio k = (1 + g_a)/(1 + g_b) in use: the phase-a reading is
    /// divided by it. 1 until the calibration has measured one.
    pub fn current_gain_ratio(&self) -> T {
        self.gain.ratio()
    }

    /// Where the gain calibration stands (skipped as unobservable or refused as implausible
    /// leaves [`current_gain_ratio`](Self::current_gain_ratio) unchanged).
    pub fn gain_calibration_status(&self) -> GainCalibrationStatus {
        self.gain.status()
    }

    /// The gain calibration block (its last measured ratio, accepted or not, and its
    /// configuration).
    pub fn gain_calibration(&self) -> &GainCalibration<T> {
        &self.gain
    }

    /// (Re)starts the current-sensor offset calibration: for the next
    /// `offset_calibration_time` the samples run with the gates off (the machine must be at
    /// rest, so that the true current is zero) and average the raw phase currents; then the
    /// drive re-aligns at the angle of the last [`align`](Self::align) and starts.
    pub fn calibrate_offsets(&mut self) {
        self.calibration_remaining = self.resolved.offset_calibration_samples;
        self.calibration_sum = Abc::new(T::zero(), T::zero(), T::zero());
        if self.calibration_remaining > 0 {
            self.last.gates_enabled = false;
        }
    }

    /// True while the offset calibration runs (gates off).
    pub fn is_calibrating(&self) -> bool {
        self.calibration_remaining > 0
    }

    /// The phase-current offsets subtracted from every sample (A).
    pub fn current_offset(&self) -> Abc<T> {
        self.current_offset
    }

    /// Start-up at a known (e.g. aligned) rotor angle θ0 (SPEC §1 step 6): the estimator
    /// starts from it with the last measured current; controllers and voltage history are
    /// cleared (the next duty is the first). A trip stays latched.
    pub fn align(&mut self, theta0: T) {
        if self.gain.running() {
            // A gain calibration under way restarts along the new axis.
            self.gain.arm();
        }
        self.realign(theta0);
    }

    /// [`align`](Self::align) without touching the gain calibration (its own end re-aligns).
    fn realign(&mut self, theta0: T) {
        self.aligned_angle = theta0;
        self.estimator.align(theta0, self.last_i_ab);
        let theta0 = if theta0.is_finite() {
            crate::wrap_angle(theta0)
        } else {
            T::zero()
        };
        self.clear_control(theta0);
        self.lock.restart();
        if self.tripped {
            self.trip_output();
        } else if self.calibration_remaining > 0 {
            self.last.gates_enabled = false;
        }
    }

    /// One sample of the offset calibration: gates off, duties ½, nothing else stepped.
    fn calibration_step(&mut self, i_abc: Abc<T>) -> DriveOutput<T> {
        self.calibration_sum = Abc::new(
            self.calibration_sum.a + i_abc.a,
            self.calibration_sum.b + i_abc.b,
            self.calibration_sum.c + i_abc.c,
        );
        self.calibration_remaining -= 1;
        if self.calibration_remaining == 0 {
            let k = T::one() / T::lit(self.resolved.offset_calibration_samples as f64);
            let sum = self.calibration_sum;
            self.current_offset = Abc::new(sum.a * k, sum.b * k, sum.c * k);
            self.last_i_ab = Ab::zero();
            let theta0 = self.aligned_angle;
            self.realign(theta0);
            let mut out = self.last;
            out.gates_enabled = false;
            return out;
        }
        let mut out = self.last;
        out.gates_enabled = false;
        out.input_fault = false;
        out
    }

    /// One sample of the gain calibration (offsets removed, no gain correction): the current
    /// loop holds the calibration's d current in the frame of the aligned angle at ω = 0, with
    /// the usual dead-time compensation and modulation; the estimator is not stepped (the
    /// drive re-aligns at the end). The calibration gets the realised voltage that acted over
    /// the last period, as the estimator would.
    fn gain_calibration_step(&mut self, i_abc: Abc<T>, vdc: T) -> DriveOutput<T> {
        let i_ab = i_abc.to_ab();
        if !i_ab.is_finite() {
            return self.reject(i_abc);
        }
        self.i_ab_used = i_ab;
        let command = self.gain.step(i_ab, self.history[1]);
        if !self.gain.running() {
            // Done (zero current after the release): the ratio, then the aligned start.
            let k = self.gain.ratio();
            self.gain_correction = if k.is_finite() && k > T::zero() {
                T::one() / k
            } else {
                T::one()
            };
            // The same two levels are the classic DC test of Rs: the estimator's R̂s
            // adaptation starts from it if it lies within 0.5–2× of the model's R̂s (a value
            // outside says something else is wrong, and the model's R̂s is kept).
            if self.gain.status() == GainCalibrationStatus::Calibrated {
                let r = self.gain.resistance();
                let r0 = self.config.machine.rs;
                if r >= r0 * T::lit(0.5) && r <= r0 + r0 {
                    self.estimator.start_from_measured_rs(r);
                }
            }
            self.last_i_ab = self.gain_corrected(i_abc).to_ab();
            let theta0 = self.aligned_angle;
            self.realign(theta0);
            return self.last;
        }
        let theta0 = if self.aligned_angle.is_finite() {
            self.aligned_angle
        } else {
            T::zero()
        };
        let rot = Rotation::from_angle(theta0);
        let i_dq = i_ab.to_dq(rot);
        let i_dq_ref = Dq::new(command.current_d, T::zero());
        let backup = self.blocks;
        let estimate = self.last.estimate;
        let b = &mut self.blocks;
        let (v_ab, v_dq) = match command.voltage {
            // Voltage mode: the current loop is not stepped (its state is kept for the
            // return to zero).
            Some(v) => (v, v.to_dq(rot)),
            None => {
                let Ok(v_dq) = b.current.step(i_dq_ref, i_dq, T::zero()) else {
                    return self.reject_after_estimate(backup, estimate, i_dq);
                };
                (v_dq.to_ab(rot), v_dq)
            }
        };
        let Some(applied) = b.modulate(rot, v_ab, v_dq, i_dq_ref, i_abc, vdc) else {
            return self.reject_after_estimate(backup, estimate, i_dq);
        };
        if command.voltage.is_none() {
            b.current.realised(applied.v_dq);
        }
        self.record(applied, i_dq, i_dq_ref, estimate, i_ab)
    }

    /// The phase currents with the measured gain ratio applied to phase a; c keeps the sum of
    /// the three readings (c = −a − b stays so for two sensors). Untouched while k = 1.
    #[inline(always)]
    fn gain_corrected(&self, i_abc: Abc<T>) -> Abc<T> {
        if self.gain_correction != T::one() {
            let a = i_abc.a * self.gain_correction;
            Abc::new(a, i_abc.b, i_abc.c + (i_abc.a - a))
        } else {
            i_abc
        }
    }

    fn clear_control(&mut self, theta: T) {
        self.blocks.reset();
        self.stuck_sensor.reset();
        self.current_error.reset();
        self.stall.reset();
        self.stall_armed = false;
        self.omega_slow = T::zero();
        self.sensor_stuck_now = false;
        self.current_error_now = false;
        self.history = [Ab::zero(); 2];
        self.last = DriveOutput::idle(Estimate {
            theta,
            ..Estimate::default()
        });
    }

    fn trip_output(&mut self) {
        let half = T::lit(0.5);
        self.last.duty = Abc::new(half, half, half);
        self.last.gates_enabled = false;
        self.last.tripped = true;
        self.last.v_ref_ab = Ab::zero();
        self.last.v_dq_ref = Dq::zero();
        self.history = [Ab::zero(); 2];
    }

    /// One 10 kHz sample: phase currents `i_abc` sampled now (A), dc-link voltage `vdc` (V),
    /// speed reference `speed_ref_mech` (mechanical rad/s). The duty returned is to be loaded
    /// at the next sample.
    ///
    /// A non-finite input rejects the sample: the last duty is held (so the history repeats
    /// the held voltage), the controllers are untouched, and the estimator still integrates
    /// the interval with the last good current so that it keeps time. A phase current above
    /// `trip_current` trips the drive: gates off, duties ½, latched until [`reset`](Self::reset);
    /// while tripped nothing is stepped.
    ///
    /// Every output carries the status word [`DriveOutput::flags`]; the drive also counts the
    /// samples each flag was raised ([`flag_counts`](Self::flag_counts)). A stuck
    /// phase-current channel (see [`StuckChannelDetector`]) is replaced by its reconstruction
    /// while it lasts; rejected samples for `input_fault_trip_time` in a row trip the drive.
    pub fn step(&mut self, i_abc: Abc<T>, vdc: T, speed_ref_mech: T) -> DriveOutput<T> {
        let mut out = self.step_control(i_abc, vdc, speed_ref_mech);
        if out.input_fault && !out.tripped {
            self.consecutive_rejects = self.consecutive_rejects.saturating_add(1);
            let limit = self.resolved.input_fault_trip_samples;
            if limit > 0 && self.consecutive_rejects >= limit {
                self.tripped = true;
                self.trip_output();
                out = self.last;
                out.input_fault = true;
            }
        } else {
            self.consecutive_rejects = 0;
        }
        let mut flags = DriveFlags::NONE;
        flags.set(DriveFlags::INPUT_REJECTED, out.input_fault);
        flags.set(DriveFlags::TRIPPED, out.tripped);
        let running = out.gates_enabled && !out.tripped;
        flags.set(
            DriveFlags::VOLTAGE_SATURATED,
            running && out.voltage_saturated,
        );
        flags.set(DriveFlags::CURRENT_ERROR, running && self.current_error_now);
        flags.set(DriveFlags::SENSOR_STUCK, running && self.sensor_stuck_now);
        flags.set(
            DriveFlags::DC_LINK_LOW,
            vdc.is_finite() && vdc < self.resolved.dc_link_min_voltage,
        );
        flags.set(
            DriveFlags::LIMITER_MODE,
            out.estimate.diagnostics.flag_limit,
        );
        // The reason stays up while the drive coasts, also after the detector was re-armed.
        let coasting = self.lock.coasting();
        flags.set(
            DriveFlags::LOCK_LOST,
            out.estimate.diagnostics.lock == LockStatus::Lost
                || (coasting && self.coast_reason.contains(DriveFlags::LOCK_LOST)),
        );
        flags.set(
            DriveFlags::STALLED,
            self.stall.is_up() || (coasting && self.coast_reason.contains(DriveFlags::STALLED)),
        );
        flags.set(DriveFlags::COASTING, running && self.lock.coasting());
        flags.set(DriveFlags::INPUT_IMPLAUSIBLE, self.implausible_now);
        out.flags = flags;
        out.i_ab = self.i_ab_used;
        self.last.flags = flags;
        self.last.i_ab = self.i_ab_used;
        self.flag_counts.record(flags);
        out
    }

    fn step_control(&mut self, i_abc: Abc<T>, vdc: T, speed_ref_mech: T) -> DriveOutput<T> {
        // What this sample reports as its current until the estimator is given another.
        let raw = i_abc.to_ab();
        // Plausible: finite and within what the machine and inverter can produce (false
        // for NaN/∞, so it subsumes the finite test; see `crate::plausibility`).
        let lim = self.resolved.plausible_current;
        let current_ok = (i_abc.a.abs() < lim) & (i_abc.b.abs() < lim) & (i_abc.c.abs() < lim);
        self.i_ab_used = if current_ok && raw.is_finite() {
            raw
        } else {
            self.last_i_ab
        };
        let finite = current_ok
            && vdc.abs() < self.resolved.dc_link_max_voltage
            && speed_ref_mech.is_finite();
        self.implausible_now =
            !finite && i_abc.is_finite() && vdc.is_finite() && speed_ref_mech.is_finite();
        if self.tripped {
            let mut out = self.last;
            out.input_fault = !finite;
            return out;
        }
        if !finite {
            return self.reject(i_abc);
        }
        let trip = self.resolved.trip_current;
        if self.calibration_remaining > 0
            && i_abc.a.abs() <= trip
            && i_abc.b.abs() <= trip
            && i_abc.c.abs() <= trip
        {
            return self.calibration_step(i_abc);
        }
        let o = self.current_offset;
        let i_abc = Abc::new(i_abc.a - o.a, i_abc.b - o.b, i_abc.c - o.c);
        if i_abc.a.abs() > trip || i_abc.b.abs() > trip || i_abc.c.abs() > trip {
            self.tripped = true;
            self.trip_output();
            self.last.input_fault = false;
            return self.last;
        }
        if self.gain.pending() {
            let theta0 = self.aligned_angle;
            self.gain.start(theta0);
        }
        if self.gain.running() {
            return self.gain_calibration_step(i_abc, vdc);
        }
        let i_abc = self.gain_corrected(i_abc);
        // Stuck-channel check against the reference the loop was tracking, advanced by the
        // rotation over one sample; an implausible channel is replaced by its reconstruction
        // from the model prediction.
        // (Both are only needed when a reading is near zero or a channel is stuck.)
        let (i_ref_ab, i_model) = if self.stuck_sensor.quiet(i_abc.a, i_abc.b) {
            (Ab::zero(), Ab::zero())
        } else {
            let prev = self.last.estimate;
            let rot_ref = Rotation::from_angle(prev.theta + prev.omega * self.config.ts);
            let i_model = self.predicted_current().unwrap_or_else(|| i_abc.to_ab());
            (self.last.i_dq_ref.to_ab(rot_ref), i_model)
        };
        let (ia, ib, stuck) = self.stuck_sensor.step(i_abc.a, i_abc.b, i_ref_ab, i_model);
        self.sensor_stuck_now = stuck;
        let i_abc = if ia != i_abc.a || ib != i_abc.b {
            Abc::new(ia, ib, -ia - ib)
        } else {
            i_abc
        };
        let i_ab = i_abc.to_ab();
        if !i_ab.is_finite() {
            return self.reject(i_abc);
        }

        // 2. Estimator: voltage of [n−1, n] = realised reference computed at n−2.
        self.i_ab_used = i_ab;
        let estimate = self.estimator.step(self.history[1], i_ab);
        if !estimate_is_finite(&estimate) {
            // An estimator that went non-finite cannot steer the drive: hold like a bad input
            // (it has had its sample).
            let out = self.last;
            return self.finish_reject(out);
        }
        if estimate.diagnostics.input_fault {
            // The estimator refused the sample (its current step is implausible for L̂q and
            // the DC link, see `crate::plausibility`): hold like a bad input of the drive.
            self.implausible_now = true;
            let mut out = self.last;
            out.estimate = estimate;
            return self.finish_reject(out);
        }
        self.last_i_ab = i_ab;
        // 3. Measured current in the estimated rotor frame.
        let rot_theta = Rotation::from_angle(estimate.theta);
        let i_dq = i_ab.to_dq(rot_theta);
        let omega_ctrl = estimate.omega_control;
        let tracking_error = (self.last.i_dq_ref - i_dq).norm();
        self.current_error_now = self
            .current_error
            .step(tracking_error > self.resolved.current_error_limit);

        // Reaction to a lost rotor (see `lock_reaction`).
        let diag = &estimate.diagnostics;
        // The stall symptom: in limiter mode (or in k_df mode just above its threshold,
        // `DriveTuning::lock_stall_kdf_speed_ratio`, off by default) the speed loop loses a
        // reference it had caught by more than the band (the larger of a fraction of the rated
        // speed and the speed error of the commanded torque, `lock_stall_torque_band_ratio`)
        // (armed once |ω* − ω̂| was within the band since the last start), although its
        // current reference is below the limit (at the limit, a speed error is the machine's
        // torque limit, not evidence against the estimate; within 1 % counts as at the
        // limit) and it asks for a torque (see `DriveTuning::lock_stall_min_current_ratio`),
        // while ω̂ is near zero or turns against ω* (`DriveTuning::lock_stall_max_speed_ratio`;
        // off by default), and unless the estimated rotor answers the torque: it turns in the
        // direction of the speed error beyond the band and accelerates in it
        // (`DriveTuning::lock_stall_follow_time`).
        let speed_ref = speed_ref_mech * T::lit(self.config.machine.pole_pairs as f64);
        let speed_error = speed_ref - omega_ctrl;
        let (m, i_ref) = (&self.config.machine, self.last.i_dq_ref);
        // The model's torque and its reluctance part over 1.5·p (folded into the band
        // factors at construction, so that the step does no integer-to-float or
        // double-precision arithmetic).
        let reluctance_flux = (m.ld - m.lq) * i_ref.d;
        let band = self.resolved.stall_speed.step_max(
            self.resolved.stall_torque_band * ((m.flux_linkage + reluctance_flux) * i_ref.q).abs(),
        ) + self.resolved.stall_reluctance_band * (reluctance_flux * i_ref.q).abs();
        let off_reference = speed_error.abs() > band;
        let follow_gain = self.resolved.stall_follow_gain;
        self.omega_slow += follow_gain * (omega_ctrl - self.omega_slow);
        let answers_torque = follow_gain > T::zero()
            && self.last.i_dq_ref.q.abs() >= self.resolved.stall_follow_min_current
            && omega_ctrl * speed_error > band * speed_error.abs()
            && (omega_ctrl - self.omega_slow) * speed_error
                > self.resolved.stall_follow_lead * speed_error.abs();
        self.stall_armed |= !off_reference && !self.lock.coasting();
        // ω̂ turns against the reference.
        let against = omega_ctrl * speed_ref < T::zero();
        let stall_now = self.stall_armed
            && off_reference
            && (omega_ctrl.abs() < self.resolved.stall_max_speed || against)
            && (diag.mode == Mode::Limiter || omega_ctrl.abs() < self.resolved.stall_kdf_band)
            && (self.last.i_dq_ref.q.abs() >= self.resolved.stall_min_current
                || (against && speed_error.abs() > self.resolved.stall_gross_ratio * band))
            && self.last.i_dq_ref.norm() < self.resolved.i_max * T::lit(0.99)
            && !answers_torque;
        let stalled = self.stall.step(stall_now);
        let estimate_lost = diag.lock == LockStatus::Lost;
        let lost = estimate_lost || (stalled && self.config.tuning.lock_reaction_on_stall);
        let healthy = diag.lock == LockStatus::Locked && diag.mode == Mode::DisturbanceFeedback;
        let action = self.lock.step(lost, healthy);
        if lost && self.config.tuning.lock_reaction == LockReaction::Adapt {
            self.estimator.enable_rs_adaptation();
        }
        match action {
            LockAction::Realign => {
                self.align(estimate.theta);
                self.last.estimate = estimate;
                return self.last;
            }
            LockAction::Rearm => {
                self.estimator.rearm_lock_detector();
                self.stall.reset();
                if self.config.tuning.lock_recovery_rs_adaptation {
                    self.estimator.enable_rs_adaptation();
                }
            }
            // While recovering, the detector judges each sample afresh (its verdict is not
            // latched), so that "healthy" means no symptom now.
            LockAction::Coast if self.lock.recovering() && lost => {
                self.estimator.rearm_lock_detector();
                self.stall.reset();
            }
            LockAction::Restart => {
                self.blocks.speed.reset();
                self.stall_armed = false;
            }
            LockAction::Run | LockAction::Coast => {}
        }
        // The reason the drive coasts: the symptoms seen since the loss that started it.
        if !self.lock.coasting() {
            self.coast_reason = DriveFlags::NONE;
        } else if lost {
            self.coast_reason.set(DriveFlags::LOCK_LOST, estimate_lost);
            self.coast_reason.set(DriveFlags::STALLED, stalled);
        }
        let action = match action {
            LockAction::Rearm => LockAction::Coast,
            a => a,
        };
        // 4. Speed loop, injection (23) and current-vector limit (zero current when coasting).
        // The speed PI's output is a torque demand in units of the magnet's q current i_q,t
        // (its gain assumes Kt = 1.5·p·λ̂f). On a salient rotor the torque per q ampere is
        // 1.5·p·λ̂a with the active flux λ̂a = λ̂f + (L̂d − L̂q)·i_d (Boldea et al. 2008), which
        // the eq. (23) injection and MTPA move by 0.45–2.9 λ̂f on the salient presets: the
        // currents are solved for that torque (see `currents_for_torque`).
        let backup = self.blocks;
        let guess = self.last.i_dq_ref.q;
        let i_dq_ref = if action == LockAction::Coast {
            Dq::zero()
        } else {
            let Ok(iq_torque) = self.blocks.speed.step(speed_ref, omega_ctrl) else {
                return self.reject_after_estimate(backup, estimate, i_dq);
            };
            // The loaded-standstill probe (see `standstill_probe`): Δi_d on the d reference,
            // and the turn of θ̂ its reading implies (from the next sample).
            let probe = &mut self.blocks.probe;
            let gate = probe.gate(
                speed_ref,
                iq_torque,
                diag.mode == Mode::Limiter,
                action == LockAction::Run,
            );
            let m = &self.config.machine;
            let last = self.last.i_dq_ref;
            let probe_id = probe.step(
                gate,
                iq_torque,
                (last.d, last.q),
                m.flux_linkage,
                m.ld - m.lq,
            );
            let i = self.currents_for_torque(iq_torque, guess, probe_id);
            limit_current_d_priority(i, self.resolved.i_max)
        };
        if action == LockAction::Coast {
            self.blocks.probe.reset();
        }
        let turn = self.blocks.probe.rate();
        if turn != T::zero() {
            self.estimator.turn_angle(turn * self.config.ts);
        }
        let b = &mut self.blocks;
        // 5. Current loop (unlimited).
        let Ok(v_dq) = b.current.step(i_dq_ref, i_dq, omega_ctrl) else {
            return self.reject_after_estimate(backup, estimate, i_dq);
        };
        // 6. Delay compensation with the advanced angle.
        //    (reusing the Park rotation: one sin/cos per sample instead of two).
        let (v_ab, rot) = b
            .delay
            .step_rotated(v_dq, rot_theta, estimate.theta, estimate.omega);
        // 7. Dead-time compensation, hexagon limit, SVPWM.
        let Some(applied) = b.modulate(rot, v_ab, v_dq, i_dq_ref, i_abc, vdc) else {
            return self.reject_after_estimate(backup, estimate, i_dq);
        };
        // 8. Anti-windup with the realised voltage in the same frame; speed loop too.
        b.current.realised(applied.v_dq);
        let realised_torque = if self.resolved.salient {
            let m = &self.config.machine;
            m.active_flux(i_dq_ref.d) * i_dq_ref.q / m.flux_linkage
        } else {
            i_dq_ref.q
        };
        b.speed.realised(realised_torque);
        self.record(applied, i_dq, i_dq_ref, estimate, i_ab)
    }

    /// The sample's output with the modulated voltage `applied`, which also enters the
    /// voltage history (the estimator's input one and two samples on).
    #[inline(always)]
    fn record(
        &mut self,
        applied: Applied<T>,
        i_dq: Dq<T>,
        i_dq_ref: Dq<T>,
        estimate: Estimate<T>,
        i_ab: Ab<T>,
    ) -> DriveOutput<T> {
        self.history = [applied.v_ab, self.history[0]];
        self.last = DriveOutput {
            duty: applied.duty,
            gates_enabled: true,
            v_ref_ab: applied.v_ab,
            i_dq,
            i_dq_ref,
            estimate,
            tripped: false,
            input_fault: false,
            v_dq_ref: applied.v_dq,
            voltage_saturated: applied.saturated,
            flags: DriveFlags::NONE, // set by `step`
            i_ab,
        };
        self.last
    }

    /// (i_d*, i_q*) for a torque demand `iq_torque` in units of the magnet's q current
    /// (torque / (1.5·p·λ̂f)): i_d* = the eq. (23) injection + MTPA of i_q* + the
    /// standstill probe's `probe_id`, and i_q* solves
    /// (λ̂f + (L̂d − L̂q)·i_d*(i_q*))·i_q* = λ̂f·i_q,t by three Newton steps from `guess` (the
    /// last sample's i_q*; a secant over 0.1 % of the rated current for the slope). On a
    /// surface-magnet rotor i_q* = i_q,t, as in the paper. Taking i_d* from the last
    /// sample's i_q* instead (no solve) closes an algebraic loop through the injection that
    /// oscillates sample by sample under load (measured on ipmsm-gem-50k `stops`).
    fn currents_for_torque(&self, iq_torque: T, guess: T, probe_id: T) -> Dq<T> {
        let m = &self.config.machine;
        let injection = &self.blocks.injection;
        let mtpa = self.resolved.mtpa;
        let id_of = |iq: T| {
            let id = injection.step(iq) + probe_id;
            if mtpa { id + m.mtpa_id(iq) } else { id }
        };
        if !self.resolved.salient {
            return Dq::new(id_of(iq_torque), iq_torque);
        }
        let target = m.flux_linkage * iq_torque;
        let f = |iq: T| m.active_flux(id_of(iq)) * iq - target;
        let h = T::lit(1e-3) * m.rated_current;
        let mut iq = if guess.is_finite() && guess * iq_torque > T::zero() {
            guess
        } else {
            iq_torque
        };
        for _ in 0..3 {
            let f0 = f(iq);
            let slope = (f(iq + h) - f0) / h;
            // A flat or non-finite slope (NaN compares false): keep the last iterate.
            if slope > T::lit(1e-3) * m.flux_linkage {
                iq -= f0 / slope;
            } else {
                break;
            }
        }
        if !iq.is_finite() {
            iq = iq_torque;
        }
        Dq::new(id_of(iq), iq)
    }

    /// The current at this sample predicted from the last one used (measured or
    /// reconstructed) by the machine model over [n−1, n]: L̂q·di/dt = v − R̂s·i − jω̂·λ̂r with
    /// the voltage that acted (the realised reference computed at n−2) and the estimator's
    /// last rotor flux and speed. Exact in form for the SPMSM (L̂d = L̂q); forward Euler is
    /// enough at R̂s·Ts/L̂q ≈ 0.012. None when the prediction is no plausible current
    /// (non-finite, or beyond the trip level after absurd inputs): the readings are used.
    fn predicted_current(&self) -> Option<Ab<T>> {
        let c = &self.config;
        let e = &self.last.estimate;
        let emf = e.diagnostics.lambda_r.mul_j() * e.omega;
        // The estimator's R̂s when it reports one (it may adapt it), else the configured one.
        let rs_hat = if e.diagnostics.rs_hat > T::zero() {
            e.diagnostics.rs_hat
        } else {
            c.machine.rs
        };
        let i = self.last_i_ab;
        let predicted = i + (self.history[1] - i * rs_hat - emf) * (c.ts / c.machine.lq);
        let n = predicted.norm();
        (n.is_finite() && n <= self.resolved.trip_current).then_some(predicted)
    }

    /// Rejected sample: hold the duty, keep the estimator's clock with the last good current.
    fn reject(&mut self, i_abc: Abc<T>) -> DriveOutput<T> {
        let i_ab = i_abc.to_ab();
        let lim = self.resolved.plausible_current;
        let plausible = (i_abc.a.abs() < lim) & (i_abc.b.abs() < lim) & (i_abc.c.abs() < lim);
        let i_ab = if plausible && i_ab.is_finite() {
            i_ab
        } else {
            self.last_i_ab
        };
        self.i_ab_used = i_ab;
        let estimate = self.estimator.step(self.history[1], i_ab);
        let mut out = self.last;
        if estimate_is_finite(&estimate) {
            out.estimate = estimate;
        }
        self.finish_reject(out)
    }

    /// Rejected after the estimator ran (a controller refused its input): controllers restored.
    fn reject_after_estimate(
        &mut self,
        blocks: Blocks<T>,
        estimate: Estimate<T>,
        i_dq: Dq<T>,
    ) -> DriveOutput<T> {
        self.blocks = blocks;
        let mut out = self.last;
        out.estimate = estimate;
        out.i_dq = i_dq;
        self.finish_reject(out)
    }

    fn finish_reject(&mut self, mut out: DriveOutput<T>) -> DriveOutput<T> {
        self.rejected_samples = self.rejected_samples.saturating_add(1);
        // The held duty applies the same voltage once more.
        self.history = [self.history[0], self.history[0]];
        out.input_fault = true;
        self.last = out;
        out
    }

    /// The estimator.
    pub fn estimator(&self) -> &E {
        &self.estimator
    }

    /// The estimator, mutable (e.g. to switch k_df off as in Fig. 9).
    pub fn estimator_mut(&mut self) -> &mut E {
        &mut self.estimator
    }

    /// The configuration in use.
    pub fn config(&self) -> &DriveConfig<T> {
        &self.config
    }

    /// The last output.
    pub fn last(&self) -> &DriveOutput<T> {
        &self.last
    }

    /// True after an over-current trip, until `reset`.
    pub fn is_tripped(&self) -> bool {
        self.tripped
    }

    /// Samples rejected since the last reset.
    pub fn rejected_samples(&self) -> u32 {
        self.rejected_samples
    }

    /// Recoveries from a lost rotor started since the last reset (`lock_reaction` recover).
    pub fn lock_recoveries(&self) -> u32 {
        self.lock.attempts()
    }

    /// Samples each [`DriveFlags`] bit was raised since the last reset.
    pub fn flag_counts(&self) -> &FlagCounts {
        &self.flag_counts
    }

    /// The current PIs' integral states (V, d and q): bounded in any healthy run.
    pub fn current_integral(&self) -> Dq<T> {
        self.blocks.current.integral()
    }

    /// The speed PI's integral state (A of i_q*).
    pub fn speed_integral(&self) -> T {
        self.blocks.speed.integral()
    }

    /// The realised references computed at n−1 and n−2 (the latter is what the estimator
    /// gets at the next sample).
    pub fn voltage_history(&self) -> [Ab<T>; 2] {
        self.history
    }
}

fn estimate_is_finite<T: Real>(e: &Estimate<T>) -> bool {
    e.theta.is_finite() && e.omega.is_finite() && e.omega_control.is_finite()
}

#[cfg(test)]
mod tests {
    /// The stall band's default torque ratio is what its documentation derives it from: the
    /// torque deficit 1 − cos δ of an estimate δ = 0.25 rad off.
    #[test]
    fn stall_torque_band_default_is_the_deficit_of_the_clean_threshold() {
        let deficit = 1.0 - nalgebra::ComplexField::cos(0.25_f64);
        assert!((super::STALL_TORQUE_BAND_RATIO - deficit).abs() < 1e-16);
    }
}
