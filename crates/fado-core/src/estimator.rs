//! The sensorless estimator of Fig. 5: flux integration with disturbance feedback or limiter,
//! the frequency-adaptive disturbance observer, the rotor-flux angle and the two T2S trackers.
//!
//! ```text
//!  v*_ab ─┐     ┌────────────┐ λ1  ┌──────────┐ D̂   λ2 = λ1 − D̂   λ̂r = λ2 − L̂q·i   θm = ∠λ̂r
//!  i_ab ──┴──▶ │ ∫(v − R̂s·i │────▶│   DOB    │───▶ ──────────────▶ ────────────────▶ ──┬──▶ T2S-1 ──▶ θ̂, ω̂1 ─┐
//!              │    − fb)   │     │ (Fig. 2) │                                            └──▶ T2S-2 ──▶ ω̂ (control)
//!              └─────▲──────┘     └────▲─────┘                                                              │
//!                    │ fb = k_df·D̂ (|f̂| > 1.5 Hz, Fig. 3)  │ ω̂1 ◀──────────────────────────────────────────┘
//!                    │   or k_af·(λ̂r − Π(λ̂r)) (below, Fig. 6)
//! ```
//!
//! Order of operations at sample n (SPEC §1): integrate with the feedback from sample n−1,
//! run the observer with ω̂ of T2S-1, form λ2, λ̂r and θm, update both trackers, then choose
//! the mode from |ω̂| of T2S-2 and compute the feedback for sample n+1.
//!
//! # Parameters and state
//!
//! The estimator is two records, as quartiq's `idsp` keeps a filter's configuration apart from
//! its state (`iir::Stateful { config, state }`, stepped through `StatefulRef { &config,
//! &mut state }`, src/iir/process.rs):
//!
//! - [`EstimatorParams`]: every constant of the step — Ts, L̂q, L̂d − L̂q, λ̂f, the gains and
//!   limits, the lag filter's coefficients, the slow laws' and the lock detector's
//!   configuration, the sample bounds — precomputed and checked once from an
//!   [`EstimatorConfig`] by [`EstimatorParams::new`]. Each block keeps its constants in its
//!   own parameter record (`FluxIntegratorParams`, `TrackerParams`,
//!   `ResistanceAdaptationParams`, …), built from its own configuration: one place defines
//!   each of them.
//! - [`EstimatorState`]: what the step changes (λ1, λ̂1 and D̂, the trackers, the mode, the
//!   slow laws' state and sums, the counters and flags) and what the user changes at run
//!   time: R̂s ([`EstimatorState::set_rs_hat`], the adaptation) with what the adaptation
//!   derives from the R0 it restarts from, λ̂f (its law), the adaptation's and the k_df
//!   switches. At most 256 B in `f32` (`state_size`, docs/firmware.md).
//!
//! [`EstimatorState::step`] / [`EstimatorState::step_lean`] take the parameters by
//! reference: the firmware path, with the parameters built once (in a `static`, never copied
//! into the state; `EstimatorParams::new` is not a `const fn`, see its docs).
//! [`SensorlessEstimator`] owns one of each and steps them with the same code, bit for bit
//! (`tests/estimator_split.rs`).

use crate::error::{ConfigError, check};
use crate::flux::{
    DisturbanceFeedbackConfig, DisturbanceFeedbackParams, FluxIntegratorConfig,
    FluxIntegratorParams, FluxIntegratorState, FluxLimiter, FluxLimiterConfig,
};
use crate::integrand_offset::{IntegrandOffsetConfig, IntegrandOffsetParams, IntegrandOffsetState};
use crate::lock::{LockDetectorConfig, LockDetectorParams, LockState, LockStatus};
use crate::mode::{Mode, ModeSelectorConfig, ModeSelectorParams};
use crate::observer::{
    DisturbanceObserverConfig, DisturbanceObserverParams, ObserverGains, ObserverState,
};
use crate::plausibility::{self, SampleBounds};
use crate::real::all_finite;
use crate::rotor_flux::{rotor_angle, rotor_flux, stator_flux};
use crate::rs_adaptation::{
    AdaptationRegime, ResistanceAdaptationConfig, ResistanceAdaptationParams,
    ResistanceAdaptationState, ResistanceScale,
};
use crate::tracker::{BandwidthDefinition, TrackerConfig, TrackerParams, TrackerState};
use crate::{Ab, MachineModel, Real};

/// Observer time constants 1/(2π·f_th) the λ̂f law waits after a LO→HI hand-over.
const FLUX_SETTLE_TIME_CONSTANTS: f64 = 2.0;

/// The slow laws — the R̂s adaptation (with its λ̂f law) and the integrand-offset law — run
/// once every `SLOW_PERIOD` samples and the loss-of-lock detector once every [`LOCK_PERIOD`],
/// each in its own slot of a round-robin of `SLOW_PERIOD` slots ([`SLOT_RS`], [`SLOT_OFFSET`],
/// [`SLOT_LOCK`] and `SLOT_LOCK + LOCK_PERIOD`; the observer's gains, held over 4 samples by
/// default, are formed in the slots after the detector's, see
/// [`EstimatorTuning::observer_gain_period`]), so that one sample runs at most one of them
/// (the worst-case step is what a firmware interrupt budgets for, not the mean).
///
/// Why this is a valid discretisation: their rates are 0.5–31 s⁻¹ (γ = 1, γ_s = 20, ω_m =
/// 2π·0.5, k_m = 2π·5, k_θ = 2, k_e = 2 s⁻¹), against 10 kHz. Each law is a forward-Euler
/// step of period N·Ts with its gains for that period (every law's configuration takes its
/// period as `ts`), so its pole sits at 1 − rate·N·Ts instead of 1 − rate·Ts: for the fastest
/// default rate, k_m = 31.4 s⁻¹, at 0.975 (N = 8, Ts = 100 µs), where the relative error of
/// forward Euler against the exact e^{−rate·N·Ts} is below rate·N·Ts/2 = 1.3 % of the decay
/// per period (2.6 % at 5 kHz; `slow_laws_poles_stay_near_one` checks every default rate on
/// sampling periods from 50 to 200 µs). The inputs are sampled, not averaged, over the period
/// (the standstill law's voltage and current excepted: it integrates their means): what they
/// carry near the decimated Nyquist frequency (625 Hz) is noise that the laws' 0.5–31 s⁻¹
/// bandwidth rejects either way. N was 4 until issue 16's sixth session; 8 halves the two laws'
/// share of the mean `f32` step on a Cortex-M4F (docs/firmware.md) with fig8–fig12 and the
/// R̂s-adaptation tests unchanged within their noise.
const SLOW_PERIOD: u8 = 8;
/// The loss-of-lock detector runs once every `LOCK_PERIOD` samples (slots [`SLOT_LOCK`] and
/// `SLOT_LOCK + LOCK_PERIOD` of the round-robin): its 5 ms detection time spans ≥ 6 of its
/// periods at every sampling period up to 200 µs.
const LOCK_PERIOD: u8 = 4;
/// Slot of the R̂s adaptation (and its λ̂f law) in the round-robin of [`SLOW_PERIOD`].
const SLOT_RS: u8 = 0;
/// Slot of the integrand-offset law.
const SLOT_OFFSET: u8 = 1;
/// Slot of the loss-of-lock detector (modulo [`LOCK_PERIOD`]).
const SLOT_LOCK: u8 = 2;
/// `slow_broken` bits: the regime was interrupted (a mode change, the trackers coasting)
/// since the R̂s adaptation's / the offset law's last run, which then does not adapt.
const BROKEN_RS: u8 = 1;
const BROKEN_OFFSET: u8 = 2;

/// Default of [`EstimatorTuning::observer_gain_period`], s.
const OBSERVER_GAIN_PERIOD: f64 = 4e-4;
/// Largest [`EstimatorTuning::observer_gain_period`] accepted, s.
const MAX_OBSERVER_GAIN_PERIOD: f64 = 1.0;

/// The estimator's tuning: every setting that is not the machine or the sampling period.
/// Defaults are the paper's (section V) or SPEC.md's, as each field says; none depends on the
/// motor (speeds are ratios of the rated electrical frequency). With the `serde` feature this
/// is the `[estimator]` table of `fado-sim`'s TOML and the keyword set of Python's
/// `fado.EstimatorConfig`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct EstimatorTuning<T> {
    /// Disturbance feedback gain k_df in s⁻¹ (Fig. 3), at most 1/ts. Default 0.5 (paper, V).
    pub k_df: T,
    /// Ramp time of k_df on activation in s, 0 = abrupt as in the paper. Default 0 (SPEC §1 \[A\]).
    pub k_df_ramp_time: T,
    /// Limiter gain k_af in s⁻¹ (Fig. 6), at most 1/ts (a larger step pulls λ̂r through the
    /// circle). Default 2π·100 (paper, V).
    pub k_af: T,
    /// Limiter radius as a multiple of λ̂f, at least 1. Default 1.15 (paper, V).
    pub limiter_radius_ratio: T,
    /// Speed threshold between limiter and k_df as a fraction of the rated electrical
    /// frequency; threshold + hysteresis below the Nyquist frequency 1/(2·ts). Default 0.015
    /// (paper, V: 1.5 Hz of its motor's 100 Hz).
    pub mode_threshold_ratio: T,
    /// Hysteresis half-band of the threshold as a fraction of the rated electrical frequency,
    /// at most the threshold. Default 0.002 (SPEC §1 \[A\]: 0.2 Hz of 100 Hz).
    pub mode_hysteresis_ratio: T,
    /// Bandwidth of T2S-1 (angle, observer speed) in Hz. Default 60 Hz (paper, V).
    pub t2s1_bandwidth_hz: T,
    /// Bandwidth of T2S-2 (speed for control) in Hz. Default 35 Hz (paper, V).
    pub t2s2_bandwidth_hz: T,
    /// Damping ratio of both trackers. Default 1/√2 (SPEC §3 \[A\]).
    pub tracker_damping: T,
    /// Meaning of the tracker bandwidths. Default −3 dB (SPEC §3).
    pub bandwidth_definition: BandwidthDefinition,
    /// Trackers coast (no update) while |λ̂r| is below this fraction of λ̂f. Default 0.2
    /// (SPEC §3 \[A\]).
    pub tracker_hold_ratio: T,
    /// Average the current over the interval for the resistive drop. Default true (SPEC §1 \[A\]).
    pub average_current: bool,
    /// Feed the disturbance observer with λ1 − L̂q·i instead of λ1. Default true (our
    /// improvement \[A\]; `false` is the paper's Fig. 5, where the observer sees λ1).
    ///
    /// The observer's internal model (eq. (9)) is "a constant plus a vector rotating at ω".
    /// λ1 = λem·e^{jθ} + L·i + D: the current term L·i only rotates with the rotor while the
    /// current is constant in the rotor frame. A rotor-frame current modulation at f_m (a
    /// speed-loop oscillation, a load step, the i_d* swing at the eq. (23) knee) appears in
    /// α-β at f ± f_m; near standstill-to-low speed f − f_m is close to DC, falls into the
    /// observer's DC pass-band (d/y = ω(ω + js)/(s + |ω|)², SPEC §2) and is taken for a
    /// disturbance: D̂ moves, λ2 = λ1 − D̂ loses part of L·Δi, λ̂r turns, and the loop closes
    /// through θ̂ and the current controller. Subtracting the known L̂q·i first leaves the
    /// observer exactly its model (λ̂r is a rotating vector plus the DC disturbance), so D̂ no
    /// longer responds to current transients. λ2 = λ1 − D̂ and λ̂r = λ2 − L̂q·i are unchanged
    /// in form (eq. (20), (5)); in steady state L̂q·i has no DC, so D̂ is the same. Measured
    /// (fado-sim fig8, switching-resolved, with the drive's offset calibration): the ≈ 5 Hz
    /// oscillation after the 2 N·m step disappears and the worst revolution's DC of λ2 − λs
    /// drops from 6.0 % to 2.1 % of λf, the rest being the observer's speed lag through the
    /// reversal (see `observer_lag_compensation`;
    /// crates/fado-sim/README.md).
    pub observer_on_rotor_flux: bool,
    /// Drive the observer's gains (16) and its internal model's rotation with ω̂1 + c, c the
    /// T2S-1 proportional term Kp·e through a first-order low-pass at the Fig. 3 threshold
    /// frequency, instead of ω̂1 alone. Default true (ours \[A\]; `false` is the paper's
    /// Fig. 5, and gives its results bit for bit with `observer_gain_period` = 0).
    ///
    /// The observer's model (eq. (9)) rotates the flux by ω between samples and places its
    /// notch (eq. (18)-(19)) at ω. Under a constant acceleration α the type-2 tracker's
    /// integrator ω̂1 lags the flux's frequency by Kp·α/Ki = 2ζα/ωn (7.7 ms × α with the
    /// paper's 60 Hz), while the rate of θ̂, ω̂1 + Kp·e, does not (θ̂ − θ is the constant
    /// α/Ki, see [`crate::tracker`]). With the notch off by Δω the observer passes the
    /// rotating flux into D̂ by d/y(jω) = ω̂(ω̂ − ω)/(jω + |ω̂|)², |D̂| ≈ λf·|Δω|/(2|ω|):
    /// growing as 1/|ω| towards zero speed, frozen where ω̂ crosses zero, and then a DC error
    /// of λ2 = λ1 − D̂ that the observer removes only with its time constant 1/|ω̂| after the
    /// LO→HI hand-over. The low-pass keeps Kp·e's ripple out of the observer (unfiltered, the
    /// loop θm → e → observer speed → D̂ → θm doubled fig9's angle ripple), and its time
    /// constant is the observer's own at the hand-over, so that the compensation follows a
    /// change of acceleration as fast as the observer needs it. Measured (fado-sim fig8, the
    /// ramp through zero at 90 r/min/s): the worst revolution's DC of λ2 − λs drops from
    /// 1.67 % to 0.33 % of λf with an averaged inverter without dead time or device drop and
    /// ideal sensors, and from 1.57–2.17 % to 0.29–0.72 % with the default non-idealities on
    /// sensor seeds 1–8 (0.27–0.87 % with a fixed R̂s); the loaded one-hour standstill then
    /// runs to the current limit on four of five seeds instead of one (docs/zero-speed-errors.md).
    pub observer_lag_compensation: bool,
    /// The observer's gains (16) are recomputed from its speed once every this many seconds
    /// (rounded to whole samples, at least every sample) and held in between; 0 = every
    /// sample, as in the paper. Default 0.4 ms (4 samples at the paper's 10 kHz) \[A\].
    ///
    /// The gains depend only on the speed the observer runs at, ω̂1 (+ the lag
    /// compensation), which T2S-1's 60 Hz bandwidth keeps from moving much within a
    /// millisecond; forming them (four polynomials, 19 multiplies) is a tenth of the `f32`
    /// step on a Cortex-M4F (docs/firmware.md). Held over N samples, the internal model
    /// rotates and the notch sits at the speed of the last update: under an acceleration α
    /// they lag the speed by at most α·(N − 1)·Ts, 0.3 ms × α by default, 4 % of the lag
    /// 2ζ/ωn·α = 7.7 ms × α of T2S-1's own ω̂1 that `observer_lag_compensation` corrects
    /// (through a 106 ms low-pass). The poles stay at the held speed's r = e^{−|ω|Ts}: the
    /// observer is a fixed stable filter between updates. Keep it well below T2S-1's time
    /// constant 1/(2π·`t2s1_bandwidth_hz`) (2.7 ms at 60 Hz); above 1 s it is refused as a
    /// mistake. Measured (fado-sim fig8–fig12,
    /// sensor seeds 1–8): every run passes, the means of the worst angle error move by at
    /// most 1.1e-3 rad (fig10 0.0562 → 0.0573 rad; docs/firmware.md, "Sixth session").
    pub observer_gain_period: T,
    /// Adapt R̂s online (our extension \[A\], see [`crate::rs_adaptation`]): from the d-axis
    /// voltage at standstill under the eq. (23) injection, and from the flux-magnitude error
    /// while turning. `false` keeps R̂s fixed as in the paper. Default true.
    ///
    /// Why on by default: with a fixed R̂s the loaded zero-speed passages of Fig. 11 and
    /// Fig. 12 are lost for a resistance error of a few per cent (the winding's resistance moves
    /// by 30 % between cold and hot). Measured in fado-sim (switching-resolved, default
    /// non-idealities): both pass for a plant resistance from 0.8× to 1.3× the configured one,
    /// the Fig. 11 reversal also under the rated 11.5 N·m, and with matched parameters the
    /// worst zero-speed angle error drops from 0.16 to 0.12 rad (Fig. 11) and from 0.18 to
    /// 0.09 rad (Fig. 12).
    pub rs_adaptation: bool,
    /// γ of the R̂s adaptation in s⁻¹. Default as [`ResistanceAdaptationConfig::rate`].
    pub rs_adaptation_rate: T,
    /// χ0 of the R̂s adaptation. Default as [`ResistanceAdaptationConfig::excitation_floor`].
    pub rs_adaptation_excitation_floor: T,
    /// Lower bound of the adapted R̂s as a multiple of `rs_hat`. Default as
    /// [`ResistanceAdaptationConfig::min_ratio`].
    pub rs_adaptation_min_ratio: T,
    /// Upper bound of the adapted R̂s as a multiple of `rs_hat`. Default as
    /// [`ResistanceAdaptationConfig::max_ratio`].
    pub rs_adaptation_max_ratio: T,
    /// With `rs_adaptation`: rate at which the flux-magnitude reference λ̂f is learned where R̂s
    /// is not observable, s⁻¹ (0 = the configured λ̂f throughout). Default as
    /// [`ResistanceAdaptationConfig::flux_linkage_rate`] (5 s⁻¹).
    ///
    /// Measured (fado-sim fig11, switching-resolved, default settings otherwise): with λ̂f
    /// −10 % / +10 % / −5 % and R̂s +10 % the worst near-zero-speed angle error drops from
    /// 1.02 / 1.21 / 0.98 rad (off) to 0.03 / 0.15 / 0.09 rad; with λ̂f right nothing moves
    /// (fig8, fig10 on seeds 1–8, fig12: the same results, the revolution means stay inside
    /// the law's 1 % dead zone; docs/zero-speed-errors.md).
    pub flux_linkage_adaptation_rate: T,
    /// With `rs_adaptation`: rate k_e in s⁻¹ at which a constant integrand error (a voltage
    /// offset) is learned while turning and subtracted from the integrand in both modes
    /// (ours \[A\], see [`crate::integrand_offset`]); 0 = off. Default as
    /// [`IntegrandOffsetConfig::rate`] (2 s⁻¹).
    ///
    /// Measured (fado-sim fig11, switching-resolved, 0.1 V on the α voltage): the worst
    /// near-zero-speed angle error drops from 1.21 rad (off) to 0.13 rad (docs/zero-speed-errors.md).
    pub offset_adaptation_rate: T,
    /// With `rs_adaptation`: rate k_θ in s⁻¹ at which, at standstill under the eq. (23)
    /// injection (the current along the estimated d axis, light load), λ̂r is turned towards
    /// the stator current (ours \[A\], see [`crate::rs_adaptation`]); 0 = off. Default as
    /// [`ResistanceAdaptationConfig::standstill_angle_rate`] (2 s⁻¹).
    ///
    /// Measured (fado-sim fig10, switching-resolved, sensor seeds 1–8): the worst angle error
    /// over the run drops from 0.384 rad (off) to 0.308 rad, and during the hold the error
    /// decays instead of walking; what remains is the swing at the stop, before the law acts
    /// (0.5, 1, 4 and 8 s⁻¹ and a 1 Hz filter on i_q/i_d were worse: docs/zero-speed-errors.md).
    pub standstill_angle_rate: T,
    /// In limiter mode, move λ1 and the observer's λ̂1 and D̂ together by −k_df·Ts·D̂ each
    /// sample. Default true (ours \[A\]; `false` is the paper).
    ///
    /// A shift common to λ1, λ̂1 and D̂ changes nothing the estimator uses: λ2 = λ1 − D̂, λ̂r
    /// and the observer's innovation and z − d are the same. In HI mode k_df·D̂ (acting on λ1
    /// alone) pulls that common mode back; in limiter mode nothing does (the limiter sees
    /// λ̂r only), so the tangential part of a DC integrand error that the observer absorbs
    /// whenever ω̂ ≠ 0 makes λ1 and D̂ ramp together without bound while the angle stays put.
    /// Measured (fado-sim long run, 0 r/min under 7.5 N·m, averaged plant, default sensors):
    /// 0.6 mWb/s, |λ1| ≈ |D̂| ≈ 2.1 Wb after an hour, f32 and f64 alike — in f32 the flux
    /// increments (≈ 0.5 mWb per sample at standstill) would drown in the rounding of λ1
    /// after days. The shift keeps D̂ at rate/k_df instead; θ̂ is unchanged while the
    /// estimator stays in limiter mode (at a hand-over to HI mode D̂ is smaller, so the k_df
    /// transient that follows differs).
    pub limiter_recentring: bool,
    /// A sample whose α-β current's magnitude reaches this multiple of the rated current is
    /// refused like a non-finite one (see [`crate::plausibility`]). Default
    /// [`plausibility::CURRENT_RATIO`] (4; 87.1 A for the paper's motor) \[A\].
    pub plausible_current_ratio: T,
    /// A sample whose α-β voltage's magnitude reaches this multiple of the DC-link voltage
    /// is refused. Default [`plausibility::VOLTAGE_RATIO`] (1.5; 450 V for the
    /// paper's 300 V link) \[A\].
    pub plausible_voltage_ratio: T,
    /// A current whose α-β vector moved by this × (plausible voltage)·ts/L̂q per sample or
    /// more since the last accepted one is refused; 0 disables the test. Default
    /// [`plausibility::STEP_RATIO`] (2) \[A\].
    pub plausible_current_step_ratio: T,
    /// Loss of lock (see [`crate::lock`]): |λ̂r| below this multiple of λ̂f is a symptom while
    /// |ω̂| is below the mode hand-over band (`mode_threshold_ratio` −
    /// `mode_hysteresis_ratio`, 0.013 of the rated speed; above it,
    /// `lock_flux_low_fast_ratio`). Default 0.7 \[A\] (chosen on the fig11 envelope sweep,
    /// docs/lock.md). 0.65 no longer flags the start-up of fig11 with R̂s +10 % (|λ̂r| below
    /// 0.7·λ̂f from 0.298 s at ω̂ −12 r/min, down to 0.67·λ̂f; the error passes 0.5 rad at
    /// 0.40 s), the flag
    /// with which the `recover` reaction switches the R̂s adaptation on in time for the
    /// loaded reversal; flagged only at the loss, that run coasts under its active load and
    /// runs away. The same start-up dip precedes the 0.5 rad start-up excursions of the
    /// envelope (57 of 67 flagged within 20 ms on seeds 7–14).
    pub lock_flux_low_ratio: T,
    /// Loss of lock: |λ̂r| below this multiple of λ̂f is a symptom while |ω̂| is at or above
    /// the lower edge of the mode hand-over band (`mode_threshold_ratio` −
    /// `mode_hysteresis_ratio`). Default 0.6 \[A\] (docs/lock.md, 2026-11-24): accelerating
    /// out of the reversal at light load, runs that keep the rotor dip to 0.67–0.70·λ̂f
    /// around the limiter → k_df hand-over (at 17–29 r/min on the paper's motor; 0.7 flagged
    /// them: 3 of 809 passing runs on seeds 7–14), while the losses this half of the symptom
    /// alone catches go through 0.42–0.53·λ̂f; 0.55–0.65 measured alike, 0 missed 4 losses.
    /// Equal to `lock_flux_low_ratio`, one bound at every speed (before 2026-11-24).
    pub lock_flux_low_fast_ratio: T,
    /// Loss of lock: |λ̂r| above this multiple of λ̂f is a symptom; 0 switches it off.
    /// Default 1.5 \[A\]: above the limiter circle (1.15) and the 1.20–1.22·λ̂f overshoot
    /// after a limiter → k_df hand-over in runs that keep the rotor (a bound of 1.2
    /// false-alarmed there, 1.3 still 2–3 times per 400 runs, 1.4 once per 400 after the
    /// reversal, |λ̂r| 1.41·λ̂f with a 0.26 rad error), within the 1.4–1.6·λ̂f of a fixed-R̂s
    /// drive that an active load runs away with in k_df mode (those losses the drive's stall
    /// symptom now sees too: 1.5 detects as many as 1.4, docs/lock.md). The voltage of a
    /// machine turning the other way gives 1.3–4.8·λ̂f.
    pub lock_flux_high_ratio: T,
    /// Loss of lock: a T2S-1 innovation |θm − θ̂⁻| above this (rad) is a symptom. Default
    /// 0.5 rad \[A\] (the angle error the drive must not reach, docs/lock.md).
    pub lock_innovation_limit: T,
    /// Loss of lock: net symptomatic time (s) before [`LockStatus::Lost`]; 0 disables the
    /// detector. Default 5 ms \[A\] (a quarter of the 20 ms detection target; 5–20 ms made
    /// no difference on the envelope, docs/lock.md).
    pub lock_detection_time: T,
    /// Loss of lock: net clean time (s) after which [`LockStatus::Lost`] clears (the status
    /// is live; the drive's reaction latches, [`crate::control::lock_reaction`]). Default
    /// 0.1 s \[A\]: twenty detection times, so that the intermittent symptoms of a lost
    /// estimate keep it up, and short against the seconds between a start-up transient and a
    /// later loss (docs/lock.md).
    pub lock_heal_time: T,
    /// Loss of lock: in limiter mode, a sample in which the limiter clamps is a symptom.
    /// Default false \[A\]: a rotor lost in limiter mode clamps continuously (fig11 with
    /// λ̂f +10 %) and a matched drive never clamps, but an adapted R̂s biased by a λ̂f error
    /// makes the limiter clamp through passages it survives (false alarms, docs/lock.md).
    pub lock_limiter_clamping: bool,
    /// Loss of lock: a rate of mode hand-overs (Fig. 3) of this many per
    /// `lock_handover_time` is a symptom (a leaky count, see [`crate::lock`], symptom 3);
    /// 0 switches it off. Default 5 \[A\] (docs/lock.md "Mode hand-over chatter"): a
    /// sustained 50 hand-overs a second, or a burst of five. On the reversal envelopes of the
    /// seven presets the count of runs that keep the rotor within 0.25 rad stays at 1.0–1.9
    /// on five, and reaches 3.9 on pmsyrm-5k and 4.0 on ipmsm-gem-50k; most start-up limit
    /// cycles that lose ipmsm-gem-50k's rotor reach 5–28.
    pub lock_handover_count: T,
    /// Loss of lock: the time constant of the hand-over count's decay, s. Default 0.1 s
    /// \[A\] (docs/lock.md "Mode hand-over chatter").
    pub lock_handover_time: T,
}

impl<T: Real> EstimatorTuning<T> {
    /// This tuning on the paper's path: every addition of fado's to the estimator of Fig. 5
    /// that can be switched off is off — the fixed R̂s (no [`Self::rs_adaptation`], hence no
    /// λ̂f or integrand-offset law), the observer on λ1 with ω̂ of T2S-1 alone
    /// ([`Self::observer_on_rotor_flux`], [`Self::observer_lag_compensation`]), no
    /// [`Self::limiter_recentring`], an abrupt k_df ([`Self::k_df_ramp_time`] 0) and the gains
    /// (16) formed every sample ([`Self::observer_gain_period`] 0). The sample bounds, the
    /// finite test and the loss-of-lock detector stay. What the cost comparisons call "the
    /// paper's path" (docs/firmware.md; `benches/baselines.rs`).
    pub fn paper_path(self) -> Self {
        Self {
            rs_adaptation: false,
            observer_lag_compensation: false,
            observer_on_rotor_flux: false,
            limiter_recentring: false,
            k_df_ramp_time: T::zero(),
            observer_gain_period: T::zero(),
            ..self
        }
    }

    /// The same record in another precision (e.g. an f64 configuration for an f32 drive):
    /// every real rounded to `U`.
    pub fn cast<U: Real>(&self) -> EstimatorTuning<U> {
        EstimatorTuning {
            k_df: U::lit(self.k_df.to_f64()),
            k_df_ramp_time: U::lit(self.k_df_ramp_time.to_f64()),
            k_af: U::lit(self.k_af.to_f64()),
            limiter_radius_ratio: U::lit(self.limiter_radius_ratio.to_f64()),
            mode_threshold_ratio: U::lit(self.mode_threshold_ratio.to_f64()),
            mode_hysteresis_ratio: U::lit(self.mode_hysteresis_ratio.to_f64()),
            t2s1_bandwidth_hz: U::lit(self.t2s1_bandwidth_hz.to_f64()),
            t2s2_bandwidth_hz: U::lit(self.t2s2_bandwidth_hz.to_f64()),
            tracker_damping: U::lit(self.tracker_damping.to_f64()),
            bandwidth_definition: self.bandwidth_definition,
            tracker_hold_ratio: U::lit(self.tracker_hold_ratio.to_f64()),
            average_current: self.average_current,
            observer_on_rotor_flux: self.observer_on_rotor_flux,
            observer_lag_compensation: self.observer_lag_compensation,
            observer_gain_period: U::lit(self.observer_gain_period.to_f64()),
            rs_adaptation: self.rs_adaptation,
            rs_adaptation_rate: U::lit(self.rs_adaptation_rate.to_f64()),
            rs_adaptation_excitation_floor: U::lit(self.rs_adaptation_excitation_floor.to_f64()),
            rs_adaptation_min_ratio: U::lit(self.rs_adaptation_min_ratio.to_f64()),
            rs_adaptation_max_ratio: U::lit(self.rs_adaptation_max_ratio.to_f64()),
            flux_linkage_adaptation_rate: U::lit(self.flux_linkage_adaptation_rate.to_f64()),
            offset_adaptation_rate: U::lit(self.offset_adaptation_rate.to_f64()),
            standstill_angle_rate: U::lit(self.standstill_angle_rate.to_f64()),
            limiter_recentring: self.limiter_recentring,
            plausible_current_ratio: U::lit(self.plausible_current_ratio.to_f64()),
            plausible_voltage_ratio: U::lit(self.plausible_voltage_ratio.to_f64()),
            plausible_current_step_ratio: U::lit(self.plausible_current_step_ratio.to_f64()),
            lock_flux_low_ratio: U::lit(self.lock_flux_low_ratio.to_f64()),
            lock_flux_low_fast_ratio: U::lit(self.lock_flux_low_fast_ratio.to_f64()),
            lock_flux_high_ratio: U::lit(self.lock_flux_high_ratio.to_f64()),
            lock_innovation_limit: U::lit(self.lock_innovation_limit.to_f64()),
            lock_detection_time: U::lit(self.lock_detection_time.to_f64()),
            lock_heal_time: U::lit(self.lock_heal_time.to_f64()),
            lock_limiter_clamping: self.lock_limiter_clamping,
            lock_handover_count: U::lit(self.lock_handover_count.to_f64()),
            lock_handover_time: U::lit(self.lock_handover_time.to_f64()),
        }
    }
}

impl<T: Real> Default for EstimatorTuning<T> {
    fn default() -> Self {
        Self {
            k_df: T::lit(0.5),
            k_df_ramp_time: T::zero(),
            k_af: T::lit(2.0 * core::f64::consts::PI * 100.0),
            limiter_radius_ratio: T::lit(1.15),
            mode_threshold_ratio: T::lit(0.015),
            mode_hysteresis_ratio: T::lit(0.002),
            t2s1_bandwidth_hz: T::lit(60.0),
            t2s2_bandwidth_hz: T::lit(35.0),
            tracker_damping: T::lit(core::f64::consts::FRAC_1_SQRT_2),
            bandwidth_definition: BandwidthDefinition::Minus3Db,
            tracker_hold_ratio: T::lit(0.2),
            average_current: true,
            observer_on_rotor_flux: true,
            observer_lag_compensation: true,
            observer_gain_period: T::lit(OBSERVER_GAIN_PERIOD),
            rs_adaptation: true,
            rs_adaptation_rate: T::one(),
            rs_adaptation_excitation_floor: T::lit(0.2),
            rs_adaptation_min_ratio: T::lit(0.5),
            rs_adaptation_max_ratio: T::lit(2.0),
            flux_linkage_adaptation_rate: T::lit(5.0),
            offset_adaptation_rate: T::lit(2.0),
            standstill_angle_rate: T::lit(2.0),
            limiter_recentring: true,
            plausible_current_ratio: T::lit(plausibility::CURRENT_RATIO),
            plausible_voltage_ratio: T::lit(plausibility::VOLTAGE_RATIO),
            plausible_current_step_ratio: T::lit(plausibility::STEP_RATIO),
            lock_flux_low_ratio: T::lit(0.7),
            lock_flux_low_fast_ratio: T::lit(0.6),
            lock_flux_high_ratio: T::lit(1.5),
            lock_innovation_limit: T::lit(0.5),
            lock_detection_time: T::lit(5e-3),
            lock_heal_time: T::lit(0.1),
            lock_limiter_clamping: false,
            lock_handover_count: T::lit(5.0),
            lock_handover_time: T::lit(0.1),
        }
    }
}

/// Everything the estimator needs: the sampling period, the machine model (R̂s, L̂d, L̂q, λ̂f
/// and the ratings the tuning's ratios refer to), the start-up angle and the tuning. Build it
/// with [`EstimatorConfig::for_machine`]; nothing here assumes the paper's motor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorConfig<T> {
    /// Sampling period Ts in s (paper, V: 100 µs, 10 kHz).
    pub ts: T,
    /// The drive's model of the motor: R̂s of eq. (3), L̂q of eq. (5), λ̂f (limiter radius,
    /// tracker hold level, start-up flux; the angle does not depend on it, eq. (6)), L̂d (the
    /// active-flux magnitude λ̂f + (L̂d − L̂q)·i_d on salient rotors) and the rated speed that
    /// scales the mode threshold.
    pub machine: MachineModel<T>,
    /// Rotor angle assumed at reset (rad), e.g. from an alignment (SPEC §1 \[A\]).
    pub initial_angle: T,
    /// Gains, bandwidths, thresholds and switches.
    pub tuning: EstimatorTuning<T>,
}

impl<T: Real> EstimatorConfig<T> {
    /// The default tuning around `machine`, sampled at 10 kHz (paper, V), starting at angle 0.
    pub fn for_machine(machine: &MachineModel<T>) -> Self {
        Self {
            ts: T::lit(100e-6),
            machine: *machine,
            initial_angle: T::zero(),
            tuning: EstimatorTuning::default(),
        }
    }

    /// The mode threshold in Hz electrical: `mode_threshold_ratio` × the rated frequency.
    pub fn mode_threshold_hz(&self) -> T {
        self.tuning.mode_threshold_ratio * self.machine.rated_frequency_hz()
    }

    /// The mode hysteresis in Hz: `mode_hysteresis_ratio` × the rated frequency.
    pub fn mode_hysteresis_hz(&self) -> T {
        self.tuning.mode_hysteresis_ratio * self.machine.rated_frequency_hz()
    }

    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        EstimatorParams::new(*self).map(|_| ())
    }

    /// The period of the slow laws, [`SLOW_PERIOD`]·Ts.
    fn slow_ts(&self) -> T {
        self.ts * T::lit(SLOW_PERIOD as f64)
    }

    fn rs_adaptation_config(&self) -> ResistanceAdaptationConfig<T> {
        ResistanceAdaptationConfig::with_tuning(&self.machine, &self.tuning, self.slow_ts())
    }

    fn lock_detector(&self) -> LockDetectorConfig<T> {
        LockDetectorConfig {
            ts: self.ts * T::lit(LOCK_PERIOD as f64),
            flux_low_ratio: self.tuning.lock_flux_low_ratio,
            flux_low_fast_ratio: self.tuning.lock_flux_low_fast_ratio,
            // The speed below which the estimator is in limiter mode whatever its history
            // (the mode selector's exit speed).
            fast_speed: crate::real::max(
                T::two_pi() * (self.mode_threshold_hz() - self.mode_hysteresis_hz()),
                T::zero(),
            ),
            flux_high_ratio: self.tuning.lock_flux_high_ratio,
            innovation_limit: self.tuning.lock_innovation_limit,
            detection_time: self.tuning.lock_detection_time,
            heal_time: self.tuning.lock_heal_time,
            limiter_clamping: self.tuning.lock_limiter_clamping,
            handover_count: self.tuning.lock_handover_count,
            handover_time: self.tuning.lock_handover_time,
        }
    }

    /// The sample bounds of [`crate::plausibility`] from the machine's ratings and the
    /// `plausible_*` ratios.
    pub fn sample_bounds(&self) -> Result<SampleBounds<T>, ConfigError> {
        let t = &self.tuning;
        SampleBounds::from_ratios(
            t.plausible_current_ratio,
            t.plausible_voltage_ratio,
            t.plausible_current_step_ratio,
            self.machine.rated_current,
            self.machine.dc_voltage,
            self.machine.lq,
            self.ts,
        )
    }

    fn tracker(&self, bandwidth_hz: T) -> TrackerConfig<T> {
        TrackerConfig::with_tuning(&self.tuning, bandwidth_hz, self.ts)
    }
}

/// Internal signals of one sample, named as in the paper's figures.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Diagnostics<T> {
    /// λ1: the integrated stator flux (eq. (7), (21)).
    pub lambda1: Ab<T>,
    /// D̂: the estimated disturbance (eq. (10)).
    pub disturbance: Ab<T>,
    /// λ2 = λ1 − D̂ (eq. (20)).
    pub lambda2: Ab<T>,
    /// λ̂r = λ2 − L̂q·i (eq. (5)).
    pub lambda_r: Ab<T>,
    /// θm = ∠λ̂r, the directly calculated angle of eq. (6) (before the T2S).
    pub theta_direct: T,
    /// Which flux feedback is active.
    pub mode: Mode,
    /// FLAG_limit of Fig. 10: the limiter mode is active.
    pub flag_limit: bool,
    /// The limiter is pulling λ̂r back to its circle this sample.
    pub limiter_clamping: bool,
    /// The trackers coasted because |λ̂r| was too small.
    pub tracker_hold: bool,
    /// R̂s used by the integrator this sample (Ω): the configured value, or the adapted one
    /// with [`EstimatorTuning::rs_adaptation`].
    pub rs_hat: T,
    /// The flux-magnitude reference λ̂f (Wb): the configured value, or the adapted one with
    /// [`EstimatorTuning::rs_adaptation`].
    pub flux_linkage_hat: T,
    /// This sample's inputs were non-finite or implausible (see [`crate::plausibility`]) and
    /// were rejected; the state is unchanged and the other fields repeat the last good sample.
    pub input_fault: bool,
    /// Whether the estimate is trusted (see [`crate::lock`]).
    pub lock: LockStatus,
}

/// The estimator's outputs for one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate<T> {
    /// θ̂: estimated rotor angle (rad, electrical, in [−π, π]) from T2S-1.
    pub theta: T,
    /// ω̂ of T2S-1 (rad/s, electrical): the speed fed back to the observer.
    pub omega: T,
    /// ω̂ of T2S-2 (rad/s, electrical): the smoother speed for speed and current control.
    pub omega_control: T,
    /// Internal signals.
    pub diagnostics: Diagnostics<T>,
}

impl<T: Real> Estimate<T> {
    /// True when every number in it (outputs and diagnostics) is finite.
    pub fn is_finite(&self) -> bool {
        let d = &self.diagnostics;
        self.theta.is_finite()
            && self.omega.is_finite()
            && self.omega_control.is_finite()
            && d.lambda1.is_finite()
            && d.disturbance.is_finite()
            && d.lambda2.is_finite()
            && d.lambda_r.is_finite()
            && d.theta_direct.is_finite()
            && d.rs_hat.is_finite()
            && d.flux_linkage_hat.is_finite()
    }
}

/// The outputs of [`SensorlessEstimator::step_lean`]: what a firmware control loop uses of
/// [`Estimate`], without the diagnostics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LeanEstimate<T> {
    /// θ̂: estimated rotor angle (rad, electrical, in [−π, π]) from T2S-1.
    pub theta: T,
    /// ω̂ of T2S-1 (rad/s, electrical).
    pub omega: T,
    /// ω̂ of T2S-2 (rad/s, electrical): the speed for speed and current control.
    pub omega_control: T,
    /// Which flux feedback is active (FLAG_limit of Fig. 10 is `Mode::Limiter`).
    pub mode: Mode,
    /// Whether the estimate is trusted (see [`crate::lock`]).
    pub lock: LockStatus,
    /// This sample was rejected (non-finite or implausible, see [`crate::plausibility`]); the
    /// other fields repeat the last good sample.
    pub input_fault: bool,
}

impl<T> From<Estimate<T>> for LeanEstimate<T> {
    #[inline(always)]
    fn from(e: Estimate<T>) -> Self {
        Self {
            theta: e.theta,
            omega: e.omega,
            omega_control: e.omega_control,
            mode: e.diagnostics.mode,
            lock: e.diagnostics.lock,
            input_fault: e.diagnostics.input_fault,
        }
    }
}

/// The estimator's immutable parameters: every constant its step needs, precomputed and
/// checked once from an [`EstimatorConfig`] by [`EstimatorParams::new`] (Ts, L̂q, L̂d − L̂q,
/// λ̂f, the gains and limits of every block, the slow laws' constants, the sample bounds, the
/// lock detector's thresholds). Nothing in it changes after construction, so firmware can
/// build it once and keep it where the interrupt reads it (a `static`, see the module docs
/// of the `examples/cortex-m` image and docs/firmware.md); the mutable half is
/// [`EstimatorState`].
///
/// The split follows quartiq's `idsp` (`iir::Stateful`/`StatefulRef`, src/iir/process.rs:
/// a processor is its configuration plus its state, and the firmware path steps a state with
/// a borrowed configuration). [`SensorlessEstimator`] is the owner of both, with the same
/// step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorParams<T: Real> {
    /// Sampling period Ts, s.
    ts: T,
    /// L̂q (eq. (5)), H.
    lq: T,
    /// L̂d − L̂q, H (0 on a surface-magnet rotor).
    saliency: T,
    /// The configured λ̂f, Wb.
    flux_linkage: T,
    /// `EstimatorTuning::tracker_hold_ratio`.
    tracker_hold_ratio: T,
    /// (λ̂f·`tracker_hold_ratio`)²: the trackers coast below this |λ̂r|².
    hold_level_sq: T,
    /// k_df·Ts with `EstimatorTuning::limiter_recentring`, else 0.
    limiter_recentring_gain: T,
    /// k_e·Ts (k_e = `EstimatorTuning::offset_adaptation_rate`): the k_df mode's re-centring
    /// while the R̂s adaptation runs (the state holds it, or 0, since the adaptation can be
    /// switched on at run time).
    offset_recentring_gain: T,
    /// `EstimatorConfig::initial_angle`, rad.
    initial_angle: T,
    /// The configured R̂s (`MachineModel::rs`), Ω: the start-up R̂s.
    rs_initial: T,
    /// e^{−2π·f_th·Ts} and (1 − e^{−2π·f_th·Ts})·Kp·(rad per tracker angle unit) of T2S-1 with
    /// `EstimatorTuning::observer_lag_compensation` (f_th the Fig. 3 threshold), else 0 and 0:
    /// the low-pass c ← keep·c + input·e.
    lag_keep: T,
    lag_input: T,
    /// `EstimatorTuning::observer_lag_compensation`: without it the low-pass is not stepped
    /// (its state stays 0, which keep·0 + input·e with keep = input = 0 would also give).
    lag_compensation: bool,
    /// The λ̂f law waits this many periods of the slow laws ([`SLOW_PERIOD`] samples) of the
    /// k_df mode after a hand-over (see `rs_adaptation`): two observer time constants at the
    /// Fig. 3 threshold, 2/(2π·f_th).
    flux_settle_periods: u32,
    /// `EstimatorTuning::observer_on_rotor_flux`.
    observer_on_rotor_flux: bool,
    /// The observer's gains are held over this many samples after the one that computes
    /// them: `EstimatorTuning::observer_gain_period`/Ts rounded, less one.
    gain_hold: u32,
    /// `EstimatorTuning::rs_adaptation`: whether the start-up state adapts R̂s.
    rs_adaptation: bool,
    integrator: FluxIntegratorParams<T>,
    observer: DisturbanceObserverParams<T>,
    disturbance_feedback: DisturbanceFeedbackParams<T>,
    limiter: FluxLimiter<T>,
    selector: ModeSelectorParams<T>,
    t2s1: TrackerParams<T>,
    t2s2: TrackerParams<T>,
    rs_adaptation_params: ResistanceAdaptationParams<T>,
    offset: IntegrandOffsetParams<T>,
    bounds: SampleBounds<T>,
    lock: LockDetectorParams<T>,
}

/// The estimator's mutable state: λ1, the observer's λ̂1 and D̂, both trackers, the mode and
/// the k_df gain, the feedback for the next sample, the slow laws' state (R̂s with the R0 it
/// scales with, λ̂f, ê, their sums, slot and flags), the lock detector's count, the sample
/// counters. Run-time settings live here too: R̂s (`set_rs_hat`, the adaptation), λ̂f (its
/// law), the adaptation's on switch (`enable_rs_adaptation`) and the k_df switch. Stepped
/// with [`EstimatorState::step`] / [`EstimatorState::step_lean`] and the
/// [`EstimatorParams`] it was made for; `size_of` is 256 B or less in `f32`
/// (docs/firmware.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorState<T: Real> {
    integrator: FluxIntegratorState<T>,
    observer: ObserverState<T>,
    t2s1: TrackerState<T>,
    t2s2: TrackerState<T>,
    /// The k_df gain in effect (it ramps on activation, `EstimatorTuning::k_df_ramp_time`).
    kdf_gain: T,
    /// The low-passed Kp·e of T2S-1 added to ω̂1 for the observer, rad/s.
    lag_compensation: T,
    /// The observer's gains, held between their updates
    /// (`EstimatorTuning::observer_gain_period`).
    observer_gains: ObserverGains<T>,
    /// Feedback term computed at the end of the previous sample.
    feedback: Ab<T>,
    /// The step the current may have moved by since the last accepted one (the integrator's
    /// last current; grows by one step per rejected sample).
    step_allowance: T,
    /// k_e·Ts while the R̂s adaptation runs (the k_df mode's re-centring), else 0.
    offset_recentring_gain: T,
    /// What the R̂s adaptation derives from the R0 it started from (replaced by
    /// `set_rs_hat`).
    rs_scale: ResistanceScale<T>,
    rs_adaptation: ResistanceAdaptationState<T>,
    /// ê, the learned integrand offset (with the R̂s adaptation).
    offset: IntegrandOffsetState<T>,
    /// Σ v and Σ i (the integrator's current) over the samples since the R̂s adaptation
    /// last ran: the standstill law integrates their means (see [`SLOW_PERIOD`]).
    v_sum: Ab<T>,
    i_sum: Ab<T>,
    /// The slow laws' share of the feedback, held between their runs: the learned integrand
    /// offset ê plus the R̂s adaptation's standstill pull (V, see `rs_adaptation`).
    slow_feedback: Ab<T>,
    lock: LockState<T>,
    rejected_samples: u32,
    mode: Mode,
    /// The mode at the detector's last judged sample: a hand-over since is counted there
    /// (symptom 3 of `lock`).
    lock_mode: Mode,
    /// `lock`'s status, kept where the detector's slot commits it (one byte to read per
    /// sample instead of the debouncer's state).
    lock_status: LockStatus,
    /// This sample's slot in the slow laws' round-robin (see [`SLOW_PERIOD`]).
    slot: u8,
    /// Samples left before the observer's gains are computed again (0: this sample).
    gain_countdown: u32,
    /// `BROKEN_*` bits: which slow law's regime was interrupted since it last ran.
    slow_broken: u8,
    /// The R̂s adaptation runs: `EstimatorTuning::rs_adaptation`, or switched on by
    /// [`EstimatorState::enable_rs_adaptation`].
    rs_adaptation_on: bool,
    k_df_enabled: bool,
}

impl<T: Real> EstimatorParams<T> {
    /// Builds the parameters; every field of `config` is checked and a bad one is named.
    /// Not `const`: the checks and the derived gains go through [`Real`]'s trait methods
    /// (√, e^x, the tracker gains), which stable Rust cannot call in a `const fn`.
    pub fn new(config: EstimatorConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        config.machine.validate()?;
        // The sampling period against the rated speed (a period in ms given as s), before any
        // gain derived from it is refused in its stead.
        crate::machine_checks::validate(&config.machine.cast::<f64>(), Some(ts.to_f64()))?;
        let lf = config.machine.flux_linkage;
        let ratio = check::positive("limiter_radius_ratio", config.tuning.limiter_radius_ratio)?;
        let hold = check::non_negative("tracker_hold_ratio", config.tuning.tracker_hold_ratio)?;
        check::below("tracker_hold_ratio", hold, T::one(), "below 1")?;
        check::finite("initial_angle", config.initial_angle)?;
        // A radius below λ̂f would clamp the magnet flux itself, not only drift (Fig. 6).
        check::below(
            "limiter_radius_ratio",
            T::one(),
            ratio + T::lit(1e-6),
            "at least 1",
        )?;
        // One limiter step pulls the excess radius back by k_af·Ts of itself: above 1 it
        // overshoots through the circle, above 2 it is unstable.
        let k_af = check::non_negative("k_af", config.tuning.k_af)?;
        check::below("k_af", k_af * ts, T::lit(1.0 + 1e-6), "k_af·ts at most 1")?;
        // The mode switch compares |ω̂| with the band: it must lie below the Nyquist frequency.
        let nyquist = |field, hz: T| {
            let hz = check::finite(field, hz)?;
            check::below(
                field,
                hz * ts,
                T::lit(0.5),
                "below the Nyquist frequency 1/(2·ts)",
            )
        };
        nyquist("mode_threshold_ratio", config.mode_threshold_hz())?;
        let rename = |field: &'static str| {
            move |e: ConfigError| match e {
                ConfigError::OutOfRange { expected, .. } => {
                    ConfigError::OutOfRange { field, expected }
                }
                ConfigError::NotFinite { .. } => ConfigError::NotFinite { field },
                ConfigError::NotPositive { .. } => ConfigError::NotPositive { field },
                ConfigError::Negative { .. } => ConfigError::Negative { field },
            }
        };
        let (integrator, _) = FluxIntegratorParams::new(FluxIntegratorConfig::with_tuning(
            &config.machine,
            &config.tuning,
            ts,
        ))?;
        let observer = DisturbanceObserverParams::new(DisturbanceObserverConfig { ts })?;
        let disturbance_feedback = DisturbanceFeedbackParams::new(
            DisturbanceFeedbackConfig::with_tuning(&config.tuning, ts),
        )
        .map_err(|e| match e.field() {
            "ramp_time" => rename("k_df_ramp_time")(e),
            _ => e,
        })?;
        let limiter = FluxLimiter::new(FluxLimiterConfig::with_tuning(
            &config.machine,
            &config.tuning,
        ))?;
        let selector = ModeSelectorParams::new(ModeSelectorConfig::with_tuning(
            &config.machine,
            &config.tuning,
        ))
        .map_err(|e| match e.field() {
            "threshold_hz" => rename("mode_threshold_ratio")(e),
            _ => rename("mode_hysteresis_ratio")(e),
        })?;
        nyquist(
            "mode_hysteresis_ratio",
            config.mode_threshold_hz() + config.mode_hysteresis_hz(),
        )?;
        check::positive("tracker_damping", config.tuning.tracker_damping)?;
        let t2s1 = TrackerParams::new(config.tracker(config.tuning.t2s1_bandwidth_hz))
            .map_err(rename("t2s1_bandwidth_hz"))?;
        let t2s2 = TrackerParams::new(config.tracker(config.tuning.t2s2_bandwidth_hz))
            .map_err(rename("t2s2_bandwidth_hz"))?;
        // A hold beyond a second is refused as a mistake (the observer would be a fixed
        // filter through any speed change; see the field's docs).
        let gain_period =
            check::non_negative("observer_gain_period", config.tuning.observer_gain_period)?;
        check::below(
            "observer_gain_period",
            gain_period,
            T::lit(MAX_OBSERVER_GAIN_PERIOD * (1.0 + 1e-9)),
            "at most 1 s",
        )?;
        // Whole samples, at least one (`as` saturates: a count beyond u32 would need a
        // sampling period below 1e-12 s).
        let gain_hold =
            crate::real::max((gain_period / ts).round() - T::one(), T::zero()).to_f64() as u32;
        let rs_adaptation = ResistanceAdaptationParams::new(config.rs_adaptation_config())
            .map_err(|e| {
                match e.field() {
                    "rs_initial" => rename("rs")(e),
                    "rate" => rename("rs_adaptation_rate")(e),
                    "excitation_floor" => rename("rs_adaptation_excitation_floor")(e),
                    "min_ratio" => rename("rs_adaptation_min_ratio")(e),
                    "max_ratio" => rename("rs_adaptation_max_ratio")(e),
                    "flux_linkage_rate" => rename("flux_linkage_adaptation_rate")(e),
                    // Fixed rates of the block that only a sampling period can make unstable.
                    "standstill_angle_rate" => e,
                    "flux_linkage_min_speed" => rename("mode_threshold_ratio")(e),
                    "standstill_rate" | "standstill_memory_hz" | "standstill_flux_rate" => {
                        rename("ts")(e)
                    }
                    _ => e,
                }
            })?;
        let threshold_hz = config.mode_threshold_hz();
        let offset = IntegrandOffsetParams::new(IntegrandOffsetConfig::with_tuning(
            &config.machine,
            &config.tuning,
            config.slow_ts(),
        ))
        .map_err(|e| match e.field() {
            "rate" => rename("offset_adaptation_rate")(e),
            _ => rename("mode_threshold_ratio")(e),
        })?;
        // The observer's lag compensation: Kp·e of T2S-1 low-passed at the threshold
        // frequency (see `EstimatorTuning::observer_lag_compensation`).
        let lag_gain = (T::two_pi() * threshold_hz * ts).step_one_minus_exp_neg();
        let hold_level = hold * lf;
        // Both circles are compared squared: in f32 a huge λ̂f would make them ∞.
        let squared = |field, x: T| {
            if (x * x).is_finite() {
                Ok(())
            } else {
                Err(ConfigError::OutOfRange {
                    field,
                    expected: "a value whose square is finite in this precision",
                })
            }
        };
        squared("flux_linkage", lf)?;
        squared("limiter_radius_ratio", ratio * lf)?;
        let bounds = config.sample_bounds()?;
        let lock = LockDetectorParams::new(config.lock_detector())?;
        Ok(Self {
            ts,
            lq: config.machine.lq,
            saliency: config.machine.ld - config.machine.lq,
            flux_linkage: lf,
            tracker_hold_ratio: hold,
            limiter_recentring_gain: if config.tuning.limiter_recentring {
                config.tuning.k_df * ts
            } else {
                T::zero()
            },
            offset_recentring_gain: config.tuning.offset_adaptation_rate * ts,
            initial_angle: config.initial_angle,
            observer_on_rotor_flux: config.tuning.observer_on_rotor_flux,
            gain_hold,
            lag_compensation: config.tuning.observer_lag_compensation,
            lag_keep: if config.tuning.observer_lag_compensation {
                T::one() - lag_gain
            } else {
                T::zero()
            },
            // The innovation it low-passes is in tracker angle units: × rad per unit.
            lag_input: if config.tuning.observer_lag_compensation {
                lag_gain * t2s1.kp() * T::angle_unit()
            } else {
                T::zero()
            },
            rs_adaptation: config.tuning.rs_adaptation,
            rs_initial: config.machine.rs,
            hold_level_sq: hold_level * hold_level,
            flux_settle_periods: (T::lit(FLUX_SETTLE_TIME_CONSTANTS)
                / (T::two_pi() * threshold_hz * config.slow_ts()))
            .ceil()
            .to_f64() as u32,
            integrator,
            observer,
            disturbance_feedback,
            limiter,
            selector,
            t2s1,
            t2s2,
            rs_adaptation_params: rs_adaptation,
            offset,
            bounds,
            lock,
        })
    }

    /// The start-up state ([`EstimatorState::reset`]: θ̂ = `initial_angle`, zero current,
    /// R̂s and λ̂f as configured).
    pub fn initial_state(&self) -> EstimatorState<T> {
        let rs_scale = self.rs_adaptation_params.scale(self.rs_initial);
        let mut state = EstimatorState {
            integrator: FluxIntegratorState::new(self.rs_initial),
            observer: ObserverState::zero(),
            t2s1: self.t2s1.state_at(T::zero(), T::zero()),
            t2s2: self.t2s2.state_at(T::zero(), T::zero()),
            kdf_gain: T::zero(),
            lag_compensation: T::zero(),
            observer_gains: ObserverGains::standstill(),
            feedback: Ab::zero(),
            step_allowance: self.bounds.step(),
            offset_recentring_gain: if self.rs_adaptation {
                self.offset_recentring_gain
            } else {
                T::zero()
            },
            rs_scale,
            rs_adaptation: self.rs_adaptation_params.initial_state(&rs_scale),
            offset: IntegrandOffsetState::default(),
            v_sum: Ab::zero(),
            i_sum: Ab::zero(),
            slow_feedback: Ab::zero(),
            lock: LockState::default(),
            rejected_samples: 0,
            mode: Mode::Limiter,
            lock_mode: Mode::Limiter,
            lock_status: LockStatus::Locked,
            slot: 0,
            gain_countdown: 0,
            slow_broken: 0,
            rs_adaptation_on: self.rs_adaptation,
            k_df_enabled: true,
        };
        state.reset(self);
        state
    }

    /// The sampling period Ts in use, s.
    pub fn ts(&self) -> T {
        self.ts
    }

    /// The Fig. 3 mode threshold in use and its hysteresis half-band, Hz electrical
    /// ([`EstimatorConfig::mode_threshold_hz`], [`EstimatorConfig::mode_hysteresis_hz`]).
    pub fn mode_threshold_hz(&self) -> (T, T) {
        self.selector.threshold_hz()
    }
}

impl<T: Real> EstimatorState<T> {
    /// The start-up state for `params` (as [`EstimatorParams::initial_state`]).
    pub fn new(params: &EstimatorParams<T>) -> Self {
        params.initial_state()
    }

    /// Back to the start-up state at `config.initial_angle` with zero current; an adapted R̂s
    /// goes back to the value the adaptation started from.
    pub fn reset(&mut self, p: &EstimatorParams<T>) {
        if self.rs_adaptation_on {
            self.rs_adaptation = p.rs_adaptation_params.initial_state(&self.rs_scale);
            self.offset = IntegrandOffsetState::default();
            self.integrator
                .set_rs_hat_unchecked(self.rs_adaptation.rs_hat);
        }
        self.align(p, p.initial_angle, Ab::zero());
    }

    /// Start-up at a known rotor angle θ0 with the present current (SPEC §1 step 6):
    /// λ1 = λ̂a·e^{jθ0} + L̂q·i with the active flux λ̂a = λ̂f + (L̂d − L̂q)·i_d, D̂ = 0, θ̂ = θ0,
    /// ω̂ = 0, limiter mode. An adapted R̂s is kept (the winding is as warm as it was).
    pub fn align(&mut self, p: &EstimatorParams<T>, theta0: T, i_ab: Ab<T>) {
        let theta0 = if theta0.is_finite() {
            theta0
        } else {
            T::zero()
        };
        // The active flux λ̂f + (L̂d − L̂q)·i_d (λ̂f exactly for L̂d = L̂q).
        let rotor = Ab::from_polar(T::one(), theta0);
        let active = p.flux_linkage + p.saliency * rotor.dot(i_ab);
        let active = if active.is_finite() && active > T::zero() {
            active
        } else {
            p.flux_linkage
        };
        let lambda_r = Ab::from_polar(active, theta0);
        // A current so large that L̂q·i overflows is as unusable as a NaN (found by fuzzing,
        // f32: i = 3e37 A gave λ1 = ∞): start as with zero current.
        let lambda1 = lambda_r + i_ab * p.lq;
        let (lambda1, i_ab) = if lambda1.is_finite() {
            (lambda1, i_ab)
        } else {
            (lambda_r, Ab::zero())
        };
        self.integrator.reset_to(lambda1);
        // The last current is also what the first sample's current step is checked against
        // (see `crate::plausibility`): an implausible one is not kept.
        self.integrator
            .set_last_current(if p.bounds.current_ok(i_ab) {
                i_ab
            } else {
                Ab::zero()
            });
        self.observer = ObserverState::at(if p.observer_on_rotor_flux {
            Ab::from_polar(p.flux_linkage, theta0)
        } else {
            lambda1
        });
        self.kdf_gain = T::zero();
        self.mode = Mode::Limiter;
        self.t2s1 = p.t2s1.state_at(theta0, T::zero());
        self.t2s2 = p.t2s2.state_at(theta0, T::zero());
        self.lag_compensation = T::zero();
        // The observer's gains for ω̂ = 0, held as after any update (so that with the
        // default period they are formed in the slots after the lock detector's, which no
        // slow law uses: see `SLOW_PERIOD`).
        self.observer_gains = p.observer.gains(T::zero());
        self.gain_countdown = p.gain_hold;
        self.feedback = Ab::zero();
        self.rejected_samples = 0;
        self.lock = LockState::default();
        self.lock_status = self.lock.status();
        self.lock_mode = Mode::Limiter;
        self.slot = 0;
        self.slow_broken = 0;
        self.v_sum = Ab::zero();
        self.i_sum = Ab::zero();
        self.slow_feedback = self.offset.offset;
        self.step_allowance = p.bounds.step();
    }

    /// One sample (Fig. 5) with the parameters `p` this state was made for: as
    /// [`SensorlessEstimator::step`].
    #[inline]
    pub fn step(&mut self, p: &EstimatorParams<T>, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T> {
        self.advance(p, v_ab, i_ab)
    }

    /// [`Self::step`] without the diagnostics: as [`SensorlessEstimator::step_lean`], the
    /// firmware step.
    #[inline]
    pub fn step_lean(
        &mut self,
        p: &EstimatorParams<T>,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) -> LeanEstimate<T> {
        self.advance(p, v_ab, i_ab)
    }

    /// The step itself, for any output that is a projection of [`Estimate`]: inlined into
    /// [`Self::step`] and [`Self::step_lean`], so that the compiler drops what the output
    /// does not keep.
    #[inline(always)]
    fn advance<O: From<Estimate<T>>>(
        &mut self,
        p: &EstimatorParams<T>,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) -> O {
        // Plausibility first (a few compares; false for NaN/∞ too, see `crate::plausibility`).
        if !p.bounds.check(
            v_ab,
            i_ab,
            self.integrator.last_current(),
            self.step_allowance,
        ) {
            return self.reject(p).into();
        }
        // The whole new state is computed first and committed only if it is finite: a
        // non-finite input makes it non-finite (every input enters λ1 through Ts·v and the
        // resistive drop, or λ̂r through L̂q·i, and NaN and ±∞ propagate, 0·∞ included), finite
        // but absurd inputs can still overflow it, and a rejected sample must leave none of it
        // changed. One test at the end covers all of this (cheaper than a test per input and
        // per block, and than copying the estimator as a backup every sample).
        // L̂d − L̂q: zero on a surface-magnet rotor, where the active-flux terms vanish.
        let saliency = p.saliency;
        // 1. Integrate with the feedback of the previous sample (eq. (21) / (24)).
        let (lambda1, i_drop) = p
            .integrator
            .next_flux(&self.integrator, v_ab, i_ab, self.feedback);
        // L̂q·i of eq. (5), formed once for both of its uses (λ̂r, and the observer's input
        // on the rotor flux): what `rotor_flux` computes, bit for bit.
        let lq_i = i_ab * p.lq;
        // 2. Disturbance observer at ω̂ of T2S-1 (eq. (10), (16)), on λ1 or on λ1 − L̂q·i
        //    (see `EstimatorTuning::observer_on_rotor_flux`).
        let observer_input = if p.observer_on_rotor_flux {
            let active = lambda1 - lq_i;
            if saliency != T::zero() {
                active - self.active_flux_swing(p, i_ab, saliency)
            } else {
                active
            }
        } else {
            lambda1
        };
        //    With `observer_lag_compensation` ω̂1 plus T2S-1's low-passed Kp·e (the rate of
        //    θ̂), not the lagging ω̂1 alone.
        //    Its gains were formed for that speed at the end of a previous sample (the last
        //    one, or up to `observer_gain_period` earlier).
        let (observer_flux, disturbance) =
            p.observer
                .next_state_with(&self.observer, &self.observer_gains, observer_input);
        // 3. Rotor flux and direct angle (eq. (20), (5), (6)).
        let lambda2 = stator_flux(lambda1, disturbance);
        let lambda_r = lambda2 - lq_i;
        let tracker_hold = lambda_r.norm_squared() < p.hold_level_sq;
        let theta_direct = rotor_angle(lambda_r);
        // 4. Trackers (Fig. 1, Fig. 5).
        let (t2s1, t2s2) = if tracker_hold {
            (
                p.t2s1.coasted_state(&self.t2s1),
                p.t2s2.coasted_state(&self.t2s2),
            )
        } else {
            (
                p.t2s1.next_state(&self.t2s1, theta_direct),
                // Both trackers have the same Ts: T2S-1's Ts in angle units, loaded once.
                p.t2s2
                    .next_state_with(&self.t2s2, theta_direct, p.t2s1.ts_units()),
            )
        };
        // 5. Mode from the control speed, and the feedback for the next sample.
        let mode = p.selector.next_mode(self.mode, t2s2.omega);
        let kdf_active = mode == Mode::DisturbanceFeedback && self.k_df_enabled;
        let kdf_gain = p.disturbance_feedback.next_gain(self.kdf_gain, kdf_active);
        let (base_feedback, clamping) = match mode {
            Mode::DisturbanceFeedback => (disturbance * kdf_gain, false),
            Mode::Limiter => {
                let ratio = Self::active_ratio(p, i_ab, lambda_r, saliency, tracker_hold);
                let l = p.limiter.step_scaled(lambda_r, ratio);
                (l.feedback, l.clamping)
            }
        };
        // The learned integrand offset ê is subtracted from the integrand in both modes, with
        // the standstill pull of the R̂s adaptation (both held between the slow laws' runs).
        // Without the R̂s adaptation both are exactly zero (nothing learns them; it cannot be
        // switched off once on), so the sum needs no test of the flag.
        let feedback = base_feedback + self.slow_feedback;
        // Which values the one test needs (the others follow from them, so the test is
        // exact, not approximate): a non-finite v or i makes λ1 non-finite (Ts·v, and R̂s·i
        // with R̂s ≥ 0: ∞·R̂s = ∞, 0·∞ = NaN, ∞ − ∞ = NaN); a tracker's ω̂ = ω̂ + Ki·Ts·e is
        // finite only if its phase error e = wrap(…) is, and then θ̂ and θ̂⁻ (wrapped sums of
        // finite values) are finite too. λ̂r and the feedback can overflow on their own.
        // λ1 and D̂ need no test of their own: λ̂r = (λ1 − D̂) − L̂q·i (eq. (20), (5)) with a
        // finite L̂q·i (the bounds passed) is finite only if both are (a difference with an
        // ∞ or NaN operand is ∞ or NaN).
        let finite = all_finite([
            observer_flux.alpha,
            observer_flux.beta,
            lambda_r.alpha,
            lambda_r.beta,
            feedback.alpha,
            feedback.beta,
            t2s1.omega,
            t2s2.omega,
        ]);
        if !finite {
            return self.reject(p).into();
        }
        let rs_hat_used = self.integrator.rs_hat();
        let flux_linkage_used = self.rs_adaptation.flux_linkage_hat;
        let previous_mode = self.mode;
        // Limiter mode: re-centre the common mode (see `EstimatorTuning::limiter_recentring`).
        // With the integrand-offset law, the k_df mode re-centres too, at k_e (see
        // `crate::integrand_offset`: D̂ then decays at k_df + k_e instead of k_df, and the
        // ramp k_df·D̂ that the observer has to follow goes with it).
        // A gain switched off is 0 and its shift D̂·0 = 0 changes nothing: no test of it.
        let shift = disturbance
            * match mode {
                Mode::Limiter => p.limiter_recentring_gain,
                Mode::DisturbanceFeedback => self.offset_recentring_gain,
            };
        self.integrator.commit(lambda1 - shift, i_ab);
        self.observer
            .commit(observer_flux - shift, disturbance - shift);
        // The observer's lag compensation: Kp·e of T2S-1 through the first-order low-pass
        // (see `EstimatorTuning::observer_lag_compensation_hz`).
        if p.lag_compensation {
            self.lag_compensation =
                p.lag_keep * self.lag_compensation + p.lag_input * t2s1.innovation;
        }
        // The observer's gains for the next sample's speed, once every `gain_hold` + 1
        // samples (see `EstimatorTuning::observer_gain_period`).
        if self.gain_countdown == 0 {
            self.observer_gains = p.observer.gains(t2s1.omega + self.lag_compensation);
            self.gain_countdown = p.gain_hold;
        } else {
            self.gain_countdown -= 1;
        }
        self.t2s1.commit(t2s1);
        // T2S-2's θ̂ is never read (its ω̂ is the control speed): not stored.
        self.t2s2.commit_speed(t2s2);
        self.mode = mode;
        self.kdf_gain = kdf_gain;
        self.feedback = feedback;
        // Loss-of-lock symptoms (see `lock`), in the detector's slot: |λ̂r| against λ̂f (the
        // lower bound chosen by the control speed ω̂ of the mode selector), the T2S-1
        // innovation. Stepped here, after the finite test, so that one slot test both
        // computes and commits it (a rejected sample never reaches this point).
        // (Outside its slot the detector's state is neither copied nor written back.)
        // The innovation is T2S-1's phase error of this sample (0 when the trackers coasted).
        // The round-robin's slot, read only now: nothing before the commit needs it.
        let slot = self.slot;
        if slot % LOCK_PERIOD == SLOT_LOCK {
            // λ̂f as this sample used it (the slow laws below have not run yet).
            let flux_hat = self.rs_adaptation.flux_linkage_hat;
            let active_ratio = Self::active_ratio(p, i_ab, lambda_r, saliency, tracker_hold);
            // A hand-over since the last judged sample (the mode sampled every
            // LOCK_PERIOD samples: two hand-overs within them would need ω̂ to cross the
            // hysteresis band twice in 0.4 ms, and count as none).
            let handover = mode != self.lock_mode;
            self.lock_mode = mode;
            let lock = p.lock.next_state(
                self.lock,
                lambda_r.norm_squared(),
                flux_hat * flux_hat * active_ratio * active_ratio,
                t2s1.innovation * T::angle_unit(),
                t2s2.omega,
                clamping,
                handover,
            );
            self.lock = lock;
            self.lock_status = lock.status();
        }
        self.step_allowance = p.bounds.step();
        // SLOW_PERIOD is a power of two: the modulo is a mask.
        self.slot = (slot + 1) % SLOW_PERIOD;
        // 6. The slow laws in their slots (see [`SLOW_PERIOD`]): R̂s and ê for the next
        //    sample (see `rs_adaptation`, `integrand_offset`), after the commit so that the
        //    paper's path is untouched by them. A non-finite result is dropped (R̂s, ê stay).
        if self.rs_adaptation_on {
            // An interruption marks both laws' periods broken: with the two bits there are,
            // slow_broken | (both) is both, so the byte is written only then (and by the
            // law that runs in its slot), not in every free slot.
            if tracker_hold || previous_mode != mode {
                self.slow_broken = BROKEN_RS | BROKEN_OFFSET;
            }
            let broken = self.slow_broken;
            if slot == SLOT_RS {
                let regime = if broken & BROKEN_RS != 0 {
                    AdaptationRegime::Frozen
                } else {
                    match mode {
                        Mode::DisturbanceFeedback => AdaptationRegime::Rotating,
                        Mode::Limiter => AdaptationRegime::Standstill,
                    }
                };
                // The standstill law sees the voltage without the learned offset, and the
                // voltage and current averaged over the period.
                let per_sample = T::one() / T::lit(SLOW_PERIOD as f64);
                let v_mean = (self.v_sum + v_ab) * per_sample;
                let i_mean = (self.i_sum + i_drop) * per_sample;
                self.v_sum = Ab::zero();
                self.i_sum = Ab::zero();
                let (state, pull) = p.rs_adaptation_params.next_state(
                    &self.rs_scale,
                    &self.rs_adaptation,
                    v_mean - self.offset.offset,
                    i_drop,
                    i_mean,
                    i_ab,
                    lambda_r,
                    t2s1.omega,
                    regime,
                    self.offset.learning_samples >= p.flux_settle_periods,
                );
                // The pull acts until the law runs again (one period), with ê.
                let slow_feedback = self.offset.offset + pull;
                let feedback = base_feedback + slow_feedback;
                // R̂s and λ̂f leave the adaptation clamped by compare-and-select, which turns
                // a NaN into the bound: always finite.
                if all_finite([
                    state.charge_d,
                    state.volt_seconds_d,
                    state.i_d_prev,
                    state.offset_sensitivity.alpha,
                    state.offset_sensitivity.beta,
                    state.flux_error_angle,
                    state.flux_excitation,
                    state.flux_angle,
                    state.flux_time,
                    feedback.alpha,
                    feedback.beta,
                ]) {
                    self.rs_adaptation = state;
                    self.integrator.set_rs_hat_unchecked(state.rs_hat);
                    self.feedback = feedback;
                    self.slow_feedback = slow_feedback;
                }
                self.slow_broken = broken & !BROKEN_RS;
            } else if mode == Mode::Limiter {
                // Only the standstill law uses the means, and only after a whole period in
                // the limiter mode (else its regime is `Frozen`).
                self.v_sum += v_ab;
                self.i_sum += i_drop;
            }
            if slot == SLOT_OFFSET {
                // D̂ decays over the period by k_df·N·Ts, and by the N − 1 re-centring shifts
                // k_e·Ts·D̂ of the samples since the law last ran (see
                // `IntegrandOffset::next_state`).
                let n = T::lit(SLOW_PERIOD as f64);
                let decay = kdf_gain * (p.ts * n) + self.offset_recentring_gain * (n - T::one());
                let learning = broken & BROKEN_OFFSET == 0 && mode == Mode::DisturbanceFeedback;
                let offset = p
                    .offset
                    .next_state(&self.offset, disturbance, decay, shift, learning);
                // R̂s drops what earlier standstill tests read of the offset ê learns now.
                let change = offset.offset - self.offset.offset;
                let rs_hat = self
                    .rs_adaptation
                    .rs_after_offset_change(&self.rs_scale, change);
                let slow_feedback = self.slow_feedback + change;
                let feedback = base_feedback + slow_feedback;
                if all_finite([
                    offset.offset.alpha,
                    offset.offset.beta,
                    offset.disturbance_prev.alpha,
                    offset.disturbance_prev.beta,
                    feedback.alpha,
                    feedback.beta,
                ]) {
                    self.offset = offset;
                    self.rs_adaptation.rs_hat = rs_hat;
                    self.integrator.set_rs_hat_unchecked(rs_hat);
                    self.feedback = feedback;
                    self.slow_feedback = slow_feedback;
                }
                self.slow_broken = broken & !BROKEN_OFFSET;
            }
        }
        let estimate = Estimate {
            theta: t2s1.angle(),
            omega: t2s1.omega,
            omega_control: t2s2.omega,
            diagnostics: Diagnostics {
                lambda1,
                disturbance,
                lambda2,
                lambda_r,
                theta_direct,
                mode,
                flag_limit: mode == Mode::Limiter,
                limiter_clamping: clamping,
                tracker_hold,
                rs_hat: rs_hat_used,
                flux_linkage_hat: flux_linkage_used,
                input_fault: false,
                lock: self.lock_status,
            },
        };
        estimate.into()
    }

    /// λ̂a/λ̂f = 1 + (L̂d − L̂q)·î_d/λ̂f, the active flux the limiter circle and the lock
    /// detector's bounds refer to (1 on a surface-magnet rotor, and while the trackers hold),
    /// î_d the current along λ̂r; at least the tracker's hold ratio. Formed where it is used
    /// (the limiter mode, the detector's slot), so that a salient rotor's k_df mode skips its
    /// √ and two divisions in three samples of four.
    #[inline(always)]
    fn active_ratio(
        p: &EstimatorParams<T>,
        i_ab: Ab<T>,
        lambda_r: Ab<T>,
        saliency: T,
        tracker_hold: bool,
    ) -> T {
        if saliency != T::zero() && !tracker_hold {
            let i_d = i_ab.dot(lambda_r) / lambda_r.norm_squared().step_sqrt();
            let ratio = T::one() + saliency * i_d / p.flux_linkage;
            crate::real::max(ratio, p.tracker_hold_ratio)
        } else {
            T::one()
        }
    }

    /// (L̂d − L̂q)·î_d·e^{jθ̂}: the part of the active flux λ̂a·e^{jθ} = (λ̂f + (L̂d − L̂q)·i_d)·e^{jθ}
    /// that the drive's own i_d moves (the eq. (23) injection, MTPA, a load change under
    /// MTPA). The d axis is the observer's own rotating vector λ̂1 − D̂ of the last sample
    /// (≈ λ̂f·e^{jθ̂}, no extra state), î_d the current along it. Zero while that vector is
    /// below the tracker's hold level (no usable axis).
    #[inline]
    fn active_flux_swing(&self, p: &EstimatorParams<T>, i_ab: Ab<T>, saliency: T) -> Ab<T> {
        let axis = self.observer.flux() - self.observer.disturbance();
        let n2 = axis.norm_squared();
        if n2 > p.hold_level_sq {
            axis * (saliency * i_ab.dot(axis) / n2)
        } else {
            Ab::zero()
        }
    }

    #[cold]
    fn reject(&mut self, p: &EstimatorParams<T>) -> Estimate<T> {
        self.rejected_samples = self.rejected_samples.saturating_add(1);
        self.step_allowance += p.bounds.step();
        let mut out = self.last(p);
        out.diagnostics.input_fault = true;
        out
    }

    /// The estimate of the last good sample (or of the last `align`/`reset`), recomputed from
    /// the state: as [`SensorlessEstimator::last`].
    pub fn last(&self, p: &EstimatorParams<T>) -> Estimate<T> {
        let lambda1 = self.integrator.flux();
        let disturbance = self.observer.disturbance();
        let lambda2 = stator_flux(lambda1, disturbance);
        let lambda_r = rotor_flux(lambda2, self.integrator.last_current(), p.lq);
        let mode = self.mode;
        Estimate {
            theta: self.t2s1.angle(),
            omega: self.t2s1.speed(),
            omega_control: self.t2s2.speed(),
            diagnostics: Diagnostics {
                lambda1,
                disturbance,
                lambda2,
                lambda_r,
                theta_direct: rotor_angle(lambda_r),
                mode,
                flag_limit: mode == Mode::Limiter,
                limiter_clamping: mode == Mode::Limiter && p.limiter.step(lambda_r).clamping,
                tracker_hold: lambda_r.norm_squared() < p.hold_level_sq,
                rs_hat: self.integrator.rs_hat(),
                flux_linkage_hat: self.rs_adaptation.flux_linkage_hat,
                input_fault: false,
                lock: self.lock.status(),
            },
        }
    }

    /// Number of samples rejected since the last reset.
    pub fn rejected_samples(&self) -> u32 {
        self.rejected_samples
    }

    /// As [`SensorlessEstimator::set_disturbance_feedback_enabled`].
    pub fn set_disturbance_feedback_enabled(&mut self, enabled: bool) {
        self.k_df_enabled = enabled;
    }

    /// As [`SensorlessEstimator::set_rs_hat`].
    pub fn set_rs_hat(&mut self, p: &EstimatorParams<T>, rs_hat: T) -> Result<(), ConfigError> {
        self.integrator.set_rs_hat(rs_hat)?;
        if self.rs_adaptation_on {
            // R̂s ≥ 0 was just checked: the adaptation restarts around it.
            self.rs_scale = p.rs_adaptation_params.scale(rs_hat);
            self.rs_adaptation = p.rs_adaptation_params.initial_state(&self.rs_scale);
        }
        Ok(())
    }

    /// As [`SensorlessEstimator::enable_rs_adaptation`].
    pub fn enable_rs_adaptation(&mut self, p: &EstimatorParams<T>) {
        if self.rs_adaptation_on {
            return;
        }
        self.rs_adaptation_on = true;
        self.offset_recentring_gain = p.offset_recentring_gain;
        let rs_hat = self.integrator.rs_hat();
        self.rs_scale = p.rs_adaptation_params.scale(rs_hat);
        self.rs_adaptation = p.rs_adaptation_params.initial_state(&self.rs_scale);
        self.offset = IntegrandOffsetState::default();
        self.slow_feedback = Ab::zero();
    }

    /// As [`SensorlessEstimator::turn_angle`].
    pub fn turn_angle(&mut self, p: &EstimatorParams<T>, angle: T) {
        if !angle.is_finite() || self.mode != Mode::Limiter {
            return;
        }
        let lambda1 = self.integrator.flux();
        let lambda2 = stator_flux(lambda1, self.observer.disturbance());
        let lambda_r = rotor_flux(lambda2, self.integrator.last_current(), p.lq);
        let turned = lambda1 + lambda_r.mul_j() * angle;
        if turned.is_finite() {
            self.integrator
                .commit(turned, self.integrator.last_current());
        }
    }

    /// Clears a loss-of-lock verdict (as [`RotorAngleEstimator::rearm_lock_detector`]).
    pub fn rearm_lock_detector(&mut self) {
        self.lock = LockState::default();
        self.lock_status = self.lock.status();
        self.lock_mode = self.mode;
    }

    /// ê, the learned integrand offset (V, α-β; zero without `rs_adaptation`).
    pub fn integrand_offset(&self) -> Ab<T> {
        self.offset.offset
    }

    /// R̂s in use now (Ω).
    pub fn rs_hat(&self) -> T {
        self.integrator.rs_hat()
    }

    /// Whether the R̂s adaptation runs.
    pub fn rs_adaptation_enabled(&self) -> bool {
        self.rs_adaptation_on
    }
}

/// The sensorless estimator of Fig. 5, generic over `f32` and `f64`, allocation-free: the
/// owner of its [`EstimatorParams`] and its [`EstimatorState`] (firmware may keep the two
/// apart, the parameters in a `static`; both step identically).
///
/// ```
/// use fado_core::{Ab, EstimatorConfig, MachineModel, SensorlessEstimator};
/// let config = EstimatorConfig::for_machine(&MachineModel::paper());
/// let mut est = SensorlessEstimator::<f32>::new(config).unwrap();
/// // In the 10 kHz ISR: the voltage applied over the last interval and the sampled currents.
/// let out = est.step(Ab::new(1.2, -0.3), Ab::new(4.0, 0.1));
/// assert!(!out.diagnostics.input_fault);
/// let _angle = out.theta;
/// ```
///
/// The same with the parameters apart from the state (the firmware pattern):
///
/// ```
/// use fado_core::{Ab, EstimatorConfig, EstimatorParams, EstimatorState, MachineModel};
/// let config = EstimatorConfig::for_machine(&MachineModel::paper());
/// let params = EstimatorParams::<f32>::new(config).unwrap(); // once, e.g. into a `static`
/// let mut state = EstimatorState::new(&params);
/// let out = state.step_lean(&params, Ab::new(1.2, -0.3), Ab::new(4.0, 0.1));
/// assert!(!out.input_fault);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorlessEstimator<T: Real> {
    params: EstimatorParams<T>,
    state: EstimatorState<T>,
}

impl<T: Real> SensorlessEstimator<T> {
    /// Builds the estimator; every field of `config` is checked and a bad one is named.
    pub fn new(config: EstimatorConfig<T>) -> Result<Self, ConfigError> {
        let params = EstimatorParams::new(config)?;
        Ok(Self {
            params,
            state: params.initial_state(),
        })
    }

    /// The estimator's parameters (immutable after `new`).
    pub fn params(&self) -> &EstimatorParams<T> {
        &self.params
    }

    /// The estimator's state.
    pub fn state(&self) -> &EstimatorState<T> {
        &self.state
    }

    /// Back to the start-up state at `config.initial_angle` with zero current; an adapted R̂s
    /// goes back to the value the adaptation started from (the configured one, or the last
    /// [`Self::set_rs_hat`]).
    pub fn reset(&mut self) {
        self.state.reset(&self.params);
    }

    /// Start-up at a known rotor angle θ0 with the present current (SPEC §1 step 6):
    /// λ1 = λ̂a·e^{jθ0} + L̂q·i with the active flux λ̂a = λ̂f + (L̂d − L̂q)·i_d, D̂ = 0, θ̂ = θ0, ω̂ = 0, limiter mode. An adapted R̂s is kept
    /// (the winding is as warm as it was).
    pub fn align(&mut self, theta0: T, i_ab: Ab<T>) {
        self.state.align(&self.params, theta0, i_ab);
    }

    /// One 10 kHz sample (Fig. 5).
    ///
    /// `v_ab` is the voltage reference that was applied over the last sampling interval (with
    /// a one-sample computational delay, the one computed two samples ago, before dead-time
    /// compensation); `i_ab` the currents sampled now. A non-finite or implausible input (see
    /// [`crate::plausibility`]) is rejected: the state is untouched and [`Self::last`] is
    /// returned with `input_fault` set.
    #[inline]
    pub fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T> {
        self.state.advance(&self.params, v_ab, i_ab)
    }

    /// [`Self::step`] for firmware: the same sample, the same new state, but only the
    /// outputs a control loop uses ([`LeanEstimate`]: θ̂, ω̂, ω̂ for control, the mode, the
    /// lock status and the input-fault flag). The diagnostics of [`Estimate`] (λ1, D̂, λ2,
    /// λ̂r, θm, R̂s, λ̂f, flags) are not formed: on a Cortex-M4F that saves about 65 of the
    /// step's cycles (docs/firmware.md). [`Self::last`] still gives them for the last sample
    /// (recomputed from the state).
    #[inline]
    pub fn step_lean(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> LeanEstimate<T> {
        self.state.advance(&self.params, v_ab, i_ab)
    }

    /// The estimate of the last good sample (or of the last `align`/`reset`), recomputed from
    /// the state: the estimator keeps no copy of its output (64 bytes written every sample in
    /// `f32`; a caller that needs the output keeps what `step` returned).
    ///
    /// θ̂, ω̂, ω̂ for control, the mode and FLAG_limit are those of that sample exactly. The
    /// diagnostics are recomputed: λ1 and D̂ as stored (after the limiter re-centring, see
    /// [`EstimatorTuning::limiter_recentring`]), λ2 = λ1 − D̂, λ̂r = λ2 − L̂q·i with that
    /// sample's current, θm = ∠λ̂r, the limiter and hold flags from this λ̂r, R̂s and λ̂f as
    /// they will be used next.
    pub fn last(&self) -> Estimate<T> {
        self.state.last(&self.params)
    }

    /// Number of samples rejected since the last reset.
    pub fn rejected_samples(&self) -> u32 {
        self.state.rejected_samples()
    }

    /// Enables or disables the k_df feedback at run time regardless of speed (the experiment
    /// of Fig. 9 switches it off on purpose). Enabled after `new`.
    pub fn set_disturbance_feedback_enabled(&mut self, enabled: bool) {
        self.state.set_disturbance_feedback_enabled(enabled);
    }

    /// Replaces R̂s at run time, as if it had been configured (an external estimate, or a
    /// value saved from the last run): the integrator uses it from the next sample, and with
    /// [`EstimatorTuning::rs_adaptation`] the adaptation restarts from it, scaled and bounded
    /// around it (a learned λ̂f goes back to the configured one too). Refuses bad values and
    /// then changes nothing.
    pub fn set_rs_hat(&mut self, rs_hat: T) -> Result<(), ConfigError> {
        self.state.set_rs_hat(&self.params, rs_hat)
    }

    /// Switches the R̂s adaptation ([`EstimatorTuning::rs_adaptation`], with its integrand-
    /// offset law) on at run time, starting from the R̂s in use now; nothing changes if it is
    /// on already. The drive's `recover` reaction does this after the paper's fixed R̂s lost
    /// the rotor (see [`crate::control::lock_reaction`]). It stays on through
    /// [`Self::reset`] and [`Self::align`]; a rebuilt estimator starts as configured.
    pub fn enable_rs_adaptation(&mut self) {
        self.state.enable_rs_adaptation(&self.params);
    }

    /// Turns θ̂ by `angle` (rad, positive: θ̂ increases) in limiter mode: an external angle
    /// correction such as the drive's loaded-standstill probe
    /// ([`crate::control::standstill_probe`]), called once per sample with rate·Ts. λ1 moves by
    /// j·λ̂r·angle, tangentially to the last λ̂r = λ1 − D̂ − L̂q·i, as the tangential integrand
    /// feedback of the R̂s adaptation's no-load standstill angle law (`rs_adaptation`) moves
    /// it; θ̂ follows through the trackers. Off the step's path (no cost in the step); does
    /// nothing outside limiter mode or for a non-finite angle or result.
    pub fn turn_angle(&mut self, angle: T) {
        self.state.turn_angle(&self.params, angle);
    }

    /// ê, the learned integrand offset (V, α-β; zero without `rs_adaptation`).
    pub fn integrand_offset(&self) -> Ab<T> {
        self.state.integrand_offset()
    }

    /// R̂s in use now (Ω).
    pub fn rs_hat(&self) -> T {
        self.state.rs_hat()
    }

    /// The sampling period Ts in use, s. (The estimator keeps what its step needs of its
    /// [`EstimatorConfig`], not the record: the caller keeps that.)
    pub fn ts(&self) -> T {
        self.params.ts
    }

    /// Whether the R̂s adaptation runs ([`EstimatorTuning::rs_adaptation`], or switched on
    /// by [`Self::enable_rs_adaptation`]).
    pub fn rs_adaptation_enabled(&self) -> bool {
        self.state.rs_adaptation_enabled()
    }

    /// The Fig. 3 mode threshold in use and its hysteresis half-band, Hz electrical
    /// ([`EstimatorConfig::mode_threshold_hz`], [`EstimatorConfig::mode_hysteresis_hz`]).
    pub fn mode_threshold_hz(&self) -> (T, T) {
        self.params.mode_threshold_hz()
    }
}

/// What a drive needs from a rotor-angle estimator. Implemented by [`SensorlessEstimator`]
/// and by the reference observers fado is compared against, so that one drive and one set of
/// scenarios can run any of them.
pub trait RotorAngleEstimator<T: Real> {
    /// One sample: `v_ab` applied over the last interval, `i_ab` sampled now. Fields of
    /// [`Diagnostics`] an estimator does not have are left at their defaults.
    fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T>;
    /// Start-up at a known rotor angle with the present current.
    fn align(&mut self, theta0: T, i_ab: Ab<T>);
    /// Back to the configured start-up state.
    fn reset(&mut self);
    /// A short name for tables and plots.
    fn name(&self) -> &'static str;
    /// Clears a loss-of-lock verdict ([`Diagnostics::lock`]) without touching the
    /// estimate, so that the detector judges afresh (the drive's recovery, see
    /// [`crate::control::lock_reaction`]). Default: nothing to clear.
    fn rearm_lock_detector(&mut self) {}
    /// Switches an online R̂s adaptation on, if the estimator has one (the drive's recovery
    /// after a loss with a fixed R̂s, see [`crate::control::lock_reaction`]). Default:
    /// nothing to switch.
    fn enable_rs_adaptation(&mut self) {}
    /// The stator resistance measured at start-up (Ω; the drive's two-point DC test, see
    /// [`crate::control::gain_calibration`]): an estimator that adapts R̂s online starts its
    /// adaptation from it. Default: nothing (a fixed R̂s stays as configured, so the paper's
    /// path is unchanged).
    fn start_from_measured_rs(&mut self, _rs: T) {}
    /// Turns θ̂ by `angle` (rad) now, if the estimator can (the drive's loaded-standstill
    /// probe, see [`crate::control::standstill_probe`]). Default: nothing.
    fn turn_angle(&mut self, _angle: T) {}
}

impl<T: Real> RotorAngleEstimator<T> for SensorlessEstimator<T> {
    #[inline]
    fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T> {
        SensorlessEstimator::step(self, v_ab, i_ab)
    }
    fn align(&mut self, theta0: T, i_ab: Ab<T>) {
        SensorlessEstimator::align(self, theta0, i_ab)
    }
    fn reset(&mut self) {
        SensorlessEstimator::reset(self)
    }
    fn name(&self) -> &'static str {
        "fado"
    }
    fn rearm_lock_detector(&mut self) {
        self.state.rearm_lock_detector();
    }
    fn enable_rs_adaptation(&mut self) {
        SensorlessEstimator::enable_rs_adaptation(self)
    }
    fn turn_angle(&mut self, angle: T) {
        SensorlessEstimator::turn_angle(self, angle);
    }
    /// With [`EstimatorTuning::rs_adaptation`]: [`SensorlessEstimator::set_rs_hat`] (a bad
    /// value changes nothing); with the paper's fixed R̂s: nothing.
    fn start_from_measured_rs(&mut self, rs: T) {
        if self.state.rs_adaptation_on {
            let _ = self.set_rs_hat(rs);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sample `n` (Ts = 100 µs) of the paper's surface PMSM turning at 20 Hz electrical:
    /// i = j·4 A·e^{jθ}, v = Rs·i + d/dt of the flux (paper V's Rs, Ls, λf), in f64.
    fn paper_sample(n: u32) -> (Ab<f64>, Ab<f64>) {
        let (w, ts) = (2.0 * core::f64::consts::PI * 20.0, 1e-4);
        let th = w * ts * n as f64;
        let (c, s) = (th.cos(), th.sin());
        let i = Ab::new(-4.0 * s, 4.0 * c);
        let v = Ab::new(
            0.327 * i.alpha - w * 0.088 * s - w * 2.63e-3 * 4.0 * c,
            0.327 * i.beta + w * 0.088 * c - w * 2.63e-3 * 4.0 * s,
        );
        (v, i)
    }

    /// `step_lean` is `step` without the diagnostics: the same state after every sample and
    /// the same θ̂, ω̂, mode, lock and fault flag, accepted and rejected samples alike, with
    /// and without the R̂s adaptation, in both precisions.
    fn lean_matches_full<T: Real>(rs_adaptation: bool) {
        let model = MachineModel::<T>::paper();
        let mut config = EstimatorConfig::for_machine(&model);
        config.tuning.rs_adaptation = rs_adaptation;
        let mut full = SensorlessEstimator::new(config).unwrap();
        let mut lean = full;
        for n in 0..6000 {
            let (v, i) = paper_sample(n);
            let (v, i) = match n {
                1000 => (Ab::new(f64::NAN, 0.0), i),
                2000 => (v, Ab::new(1e6, 0.0)),
                _ => (v, i),
            };
            let v = Ab::new(T::lit(v.alpha), T::lit(v.beta));
            let i = Ab::new(T::lit(i.alpha), T::lit(i.beta));
            let a = full.step(v, i);
            let b = lean.step_lean(v, i);
            assert_eq!(LeanEstimate::from(a), b, "sample {n}");
            assert_eq!(full, lean, "sample {n}");
            assert_eq!(b.input_fault, n == 1000 || n == 2000);
        }
        assert_eq!(full.rejected_samples(), 2);
    }

    #[test]
    fn step_lean_is_step_without_diagnostics() {
        lean_matches_full::<f32>(true);
        lean_matches_full::<f32>(false);
        lean_matches_full::<f64>(true);
        lean_matches_full::<f64>(false);
    }

    /// The firmware state budget (docs/firmware.md, issue 16: ≤ 256 B in `f32`): the mutable
    /// state alone, the parameters apart (they can live in flash or a `static` the step
    /// borrows). Prints both precisions' sizes.
    #[test]
    fn state_size() {
        use core::mem::size_of;
        let (s32, s64) = (
            size_of::<EstimatorState<f32>>(),
            size_of::<EstimatorState<f64>>(),
        );
        let (p32, p64) = (
            size_of::<EstimatorParams<f32>>(),
            size_of::<EstimatorParams<f64>>(),
        );
        let (o32, o64) = (
            size_of::<SensorlessEstimator<f32>>(),
            size_of::<SensorlessEstimator<f64>>(),
        );
        std::println!(
            "EstimatorState<f32>: {s32} B, <f64>: {s64} B; EstimatorParams<f32>: {p32} B, \
             <f64>: {p64} B; SensorlessEstimator<f32>: {o32} B, <f64>: {o64} B"
        );
        // Before the split (issue 16's fourth pass) the one record was 484 B in `f32`, its
        // constants and its state mixed. The state now holds what changes (and R0's 20 B of
        // scaled constants, since `set_rs_hat` replaces R0 at run time).
        assert!(s32 <= 256, "{s32}");
        assert_eq!(o32, s32 + p32);
    }

    /// The reason the slow laws may run every [`SLOW_PERIOD`] samples (see its docs): at
    /// every default rate, for sampling periods from 50 to 200 µs, the forward-Euler pole
    /// 1 − rate·N·Ts stays near 1 (rate·N·Ts ≤ 0.051) and within 2.6 % of the decay per
    /// period of the exact e^{−rate·N·Ts} (≤ 0.026 and 1.3 % at the paper's 10 kHz); the
    /// detector's 5 ms still spans ≥ 6 of its periods ([`LOCK_PERIOD`]).
    /// (`slow_laws_run_in_their_slots` and the R̂s-adaptation and offset-law tests check the
    /// behaviour.)
    #[test]
    fn slow_laws_poles_stay_near_one() {
        // The default rates are motor-independent (s⁻¹, see each field): one motor serves.
        {
            let model = MachineModel::<f64>::paper();
            for ts in [50e-6, 100e-6, 200e-6] {
                let mut config = EstimatorConfig::for_machine(&model);
                config.ts = ts;
                let rs = config.rs_adaptation_config();
                let period = config.slow_ts();
                assert_eq!(rs.ts, period);
                assert_eq!(config.lock_detector().ts, ts * f64::from(LOCK_PERIOD));
                let t = &config.tuning;
                let rates = [
                    t.rs_adaptation_rate,
                    rs.standstill_rate,
                    core::f64::consts::TAU * rs.standstill_memory_hz,
                    rs.standstill_flux_rate,
                    t.standstill_angle_rate,
                    t.offset_adaptation_rate,
                    // The λ̂f law at the rate its test uses (off by default).
                    5.0,
                ];
                for rate in rates {
                    let x = rate * period;
                    assert!(x <= 0.051, "rate {rate} s⁻¹ at ts {ts}: {x}");
                    let exact = 1.0 - (-x).exp();
                    assert!((x - exact).abs() <= 0.026 * exact, "rate {rate}, ts {ts}");
                }
                let lock_period = ts * f64::from(LOCK_PERIOD);
                assert!(t.lock_detection_time / lock_period >= 6.0, "ts {ts}");
                // The estimator is built with these periods.
                let est = SensorlessEstimator::new(config).unwrap();
                assert_eq!(est.params.rs_adaptation_params.config().ts, period);
                assert_eq!(est.params.offset.config().ts, period);
            }
        }
    }

    /// One slow law per sample: R̂s, ê and the lock detector each change only in their own
    /// slot, and the slot advances on accepted samples only.
    #[test]
    fn slow_laws_run_in_their_slots() {
        let model = MachineModel::<f64>::paper();
        let mut est = SensorlessEstimator::new(EstimatorConfig::for_machine(&model)).unwrap();
        let (w, ts) = (2.0 * core::f64::consts::PI * 20.0, 1e-4);
        let mut rs_changes = [0usize; SLOW_PERIOD as usize];
        for n in 0..20_000 {
            let th = w * ts * n as f64;
            let (c, s) = (th.cos(), th.sin());
            // The plant's resistance 10 % above R̂s, so that the turning law has work.
            let i = Ab::new(-8.0 * s, 8.0 * c);
            let v = Ab::new(
                1.1 * 0.327 * i.alpha - w * 0.088 * s - w * 2.63e-3 * 8.0 * c,
                1.1 * 0.327 * i.beta + w * 0.088 * c - w * 2.63e-3 * 8.0 * s,
            );
            let slot = est.state.slot;
            let (rs_before, offset_before) = (est.rs_hat(), est.integrand_offset());
            est.step(v, i);
            assert_eq!(est.state.slot, (slot + 1) % SLOW_PERIOD);
            if est.rs_hat() != rs_before {
                rs_changes[slot as usize] += 1;
            }
            if slot != SLOT_OFFSET {
                assert_eq!(est.integrand_offset(), offset_before, "sample {n}");
            }
        }
        // R̂s moves in its own slot, and in the offset law's (by −⟨Δê, ∂R̂s/∂ê⟩) only.
        assert!(rs_changes[SLOT_RS as usize] > 1000, "{rs_changes:?}");
        let slow = [SLOT_RS as usize, SLOT_OFFSET as usize];
        for free in (0..SLOW_PERIOD as usize).filter(|k| !slow.contains(k)) {
            assert_eq!(rs_changes[free], 0, "{rs_changes:?}");
        }
        // A rejected sample does not advance the slot.
        let slot = est.state.slot;
        est.step(Ab::new(f64::NAN, 0.0), Ab::zero());
        assert_eq!(est.state.slot, slot);
    }

    /// `observer_gain_period` (see its docs): the gains the observer uses are those of the
    /// speed (ω̂1 + the lag compensation) at the end of the sample that last updated them,
    /// updated once every N = period/Ts accepted samples (N = 4 by default at 10 kHz, in the
    /// slots after the lock detector's), every sample with period 0; a rejected sample
    /// does not advance the count; `align` forms them for ω̂ = 0.
    #[test]
    fn observer_gains_are_held_over_their_period() {
        fn check<T: Real>(period: f64, samples_per_update: u32) {
            let mut config = EstimatorConfig::<T>::for_machine(&MachineModel::paper());
            config.tuning.observer_gain_period = T::lit(period);
            let mut est = SensorlessEstimator::new(config).unwrap();
            let p = est.params;
            assert_eq!(p.gain_hold, samples_per_update - 1);
            assert_eq!(est.state.observer_gains, p.observer.gains(T::zero()));
            let mut updates = 0;
            for n in 0..4000 {
                let (v, i) = paper_sample(n);
                let v = if n == 1001 { Ab::new(f64::NAN, 0.0) } else { v };
                let v = Ab::new(T::lit(v.alpha), T::lit(v.beta));
                let i = Ab::new(T::lit(i.alpha), T::lit(i.beta));
                let before = est.state;
                est.step(v, i);
                let after = est.state;
                if n == 1001 {
                    assert_eq!(after.observer_gains, before.observer_gains);
                    assert_eq!(after.gain_countdown, before.gain_countdown);
                    assert_eq!(after.rejected_samples, before.rejected_samples + 1);
                    continue;
                }
                let speed = after.t2s1.speed() + after.lag_compensation;
                if before.gain_countdown == 0 {
                    updates += 1;
                    assert_eq!(after.observer_gains, p.observer.gains(speed), "sample {n}");
                    assert_eq!(after.gain_countdown, p.gain_hold);
                    if samples_per_update == u32::from(LOCK_PERIOD) {
                        // The slots after the lock detector's, free of the slow laws.
                        assert_eq!(before.slot % LOCK_PERIOD, SLOT_LOCK + 1);
                        assert!(before.slot != SLOT_RS && before.slot != SLOT_OFFSET);
                    }
                } else {
                    assert_eq!(after.observer_gains, before.observer_gains, "sample {n}");
                    assert_eq!(after.gain_countdown, before.gain_countdown - 1);
                }
            }
            assert_eq!(updates, 3999 / samples_per_update);
            est.state.align(&p, T::one(), Ab::zero());
            assert_eq!(est.state.observer_gains, p.observer.gains(T::zero()));
            assert_eq!(est.state.gain_countdown, p.gain_hold);
        }
        for (period, n) in [(0.0, 1), (1e-4, 1), (1.4e-4, 1), (4e-4, 4), (8e-4, 8)] {
            check::<f32>(period, n);
            check::<f64>(period, n);
        }
        assert_eq!(
            EstimatorTuning::<f64>::default().observer_gain_period,
            OBSERVER_GAIN_PERIOD
        );
    }
}
