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
//! Order of operations at sample n (docs/method/estimator.md §1): integrate with the feedback from sample n−1,
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
//!   switches. At most 368 B in `f32` (`state_size`, docs/results/firmware-cost.md).
//!
//! [`EstimatorState::step`] / [`EstimatorState::step_lean`] take the parameters by
//! reference: the firmware path, with the parameters built once (in a `static`, never copied
//! into the state; `EstimatorParams::new` is not a `const fn`, see its docs).
//! [`SensorlessEstimator`] owns one of each and steps them with the same code, bit for bit
//! (`tests/estimator_split.rs`).

mod blocks;
mod config;
mod output;
mod owner;
mod params;
mod state;
mod step;
pub mod tuning;

#[cfg(test)]
mod tests;

pub use config::EstimatorConfig;
pub use output::{Diagnostics, Estimate, LeanEstimate};
pub use owner::{RotorAngleEstimator, SensorlessEstimator};
pub use tuning::{
    DisturbanceFeedbackTuning, EstimatorTuning, FluxLinkageAdaptationTuning, IntegratorTuning,
    LimiterTuning, LockTuning, ModeTuning, ObserverTuning, OffsetAdaptationTuning,
    PlausibilityTuning, RsAdaptationTuning, TrackerTuning,
};

use crate::active_flux::ActiveFlux;
use crate::flux::{
    DisturbanceFeedbackParams, FluxIntegratorParams, FluxIntegratorState, FluxLimiter,
};
use crate::integrand_offset::{IntegrandOffsetParams, IntegrandOffsetState};
use crate::lock::{LockDetectorParams, LockState, LockStatus};
use crate::magnetics::FluxWarmStart;
use crate::mode::{Mode, ModeSelectorParams};
use crate::observer::{DisturbanceObserverParams, ObserverGains, ObserverState};
use crate::plausibility::SampleBounds;
use crate::ripple::PwmRipple;
use crate::rs_adaptation::{
    ResistanceAdaptationParams, ResistanceAdaptationState, ResistanceScale,
};
use crate::speed_notch::{SpeedNotch, SpeedNotchState};
use crate::tracker::{TrackerParams, TrackerState};
use crate::{Ab, Real};

/// Observer time constants 1/(2π·f_th) the λ̂f law waits after a LO→HI hand-over.
const FLUX_SETTLE_TIME_CONSTANTS: f64 = 2.0;

/// A frame-coupled operating point is steady while the active flux λ̂a(î) stays within this
/// share of its low-pass (`crate::active_flux::SWING_REFERENCE_TIME`): a load's arrival moves
/// λ̂a by more, and leaves a frame error that the coupling reads as flux magnitude. Ours \[A\]
/// (docs/method/saturation.md, "The offset law's gate").
const STEADY_ACTIVE_SHARE: f64 = 0.05;

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
/// bandwidth rejects either way. N = 8 rather than 4 halves the two laws'
/// share of the mean `f32` step on a Cortex-M4F (docs/results/firmware-cost.md) with fig8–fig12 and the
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
/// `slow_broken` bit: a sample since the R̂s adaptation's last run had a voltage the drive's
/// modulator limited; the turning law does not adapt (the standstill laws do).
const BROKEN_LIMITED: u8 = 4;

/// Default of [`EstimatorTuning::observer_gain_period`], s.
const OBSERVER_GAIN_PERIOD: f64 = 4e-4;
/// Largest [`EstimatorTuning::observer_gain_period`] accepted, s.
const MAX_OBSERVER_GAIN_PERIOD: f64 = 1.0;

/// The estimator's immutable parameters: every constant its step needs, precomputed and
/// checked once from an [`EstimatorConfig`] by [`EstimatorParams::new`] (Ts, L̂q, L̂d − L̂q,
/// λ̂f, the gains and limits of every block, the slow laws' constants, the sample bounds, the
/// lock detector's thresholds). Nothing in it changes after construction, so firmware can
/// build it once and keep it where the interrupt reads it (a `static`, see the module docs
/// of the `examples/cortex-m` image and docs/results/firmware-cost.md); the mutable half is
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
    /// A saturating model's active flux (`crate::active_flux`): λ̂r with the secant L̂q at
    /// the estimated current, the limiter's and the lock detector's bounds from λ̂a(î).
    /// [`ActiveFlux::saturating`] is None for constant inductances (`lq` and `saliency`
    /// then hold).
    active_flux: ActiveFlux<T>,
    /// The configured λ̂f, Wb.
    flux_linkage: T,
    /// `EstimatorTuning::tracker_hold_ratio`.
    tracker_hold_ratio: T,
    /// (λ̂f·`tracker.hold_ratio`)²: the trackers coast below this |λ̂r|².
    hold_level_sq: T,
    /// k_df·Ts with `LimiterTuning::recentring`, else 0.
    limiter_recentring_gain: T,
    /// k_e·Ts (k_e = `EstimatorTuning::offset_adaptation_rate`): the k_df mode's re-centring
    /// while the R̂s adaptation runs (the state holds it, or 0, since the adaptation can be
    /// switched on at run time).
    offset_recentring_gain: T,
    /// The integrand-offset law learns while |ω̂| is at most this (rad/s): an electrical
    /// revolution of `offset_adaptation.min_revolution_samples` samples (the law holds ê
    /// above it, see [`crate::integrand_offset::MIN_REVOLUTION_SAMPLES`]).
    offset_max_speed: T,
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
    /// Ts/τ of a saturating model's observer reference (`crate::active_flux`).
    swing_reference_gain: T,
    /// The observer's gains are held over this many samples after the one that computes
    /// them: `EstimatorTuning::observer_gain_period`/Ts rounded, less one.
    gain_hold: u32,
    /// `EstimatorTuning::rs_adaptation`: whether the start-up state adapts R̂s.
    rs_adaptation: bool,
    /// A saturating model's notch on the observer's speed at the electrical frequency
    /// (`crate::speed_notch`), its floor the Fig. 3 threshold.
    speed_notch: SpeedNotch<T>,
    /// `EstimatorTuning::observer.frame_ripple_notch`.
    frame_ripple_notch: bool,
    /// The frame-rate correction's speed bound, rad/s electrical (`step::notch`).
    frame_rate_speed: T,
    /// The frame-rate correction's current share (`step::notch`): the current where it
    /// starts, A, and the share per ampere above it.
    frame_rate_current: (T, T),
    integrator: FluxIntegratorParams<T>,
    observer: DisturbanceObserverParams<T>,
    disturbance_feedback: DisturbanceFeedbackParams<T>,
    limiter: FluxLimiter<T>,
    selector: ModeSelectorParams<T>,
    t2s1: TrackerParams<T>,
    /// T2S-1 in disturbance-feedback mode (`tracker.t2s1_running_bandwidth_hz`; a copy of
    /// `t2s1` where none is set).
    t2s1_running: TrackerParams<T>,
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
/// [`EstimatorParams`] it was made for; `size_of` is 368 B or less in `f32`
/// (docs/results/firmware-cost.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorState<T: Real> {
    integrator: FluxIntegratorState<T>,
    observer: ObserverState<T>,
    /// The q inductance of eq. (5) the last sample used: L̂q, or a saturating model's
    /// secant at the estimated current (`crate::active_flux`).
    lq_secant: T,
    /// A saturating model's reference magnitude of the observer's rotating vector: the active
    /// flux λ̂a(î) low-passed (`crate::active_flux`, "The observer's reference").
    swing_reference: T,
    /// A saturating model's last ψ(î), the start of the next sample's solves
    /// (`crate::magnetics::FluxWarmStart`; empty for a model that needs none).
    flux_warm: FluxWarmStart<T>,
    t2s1: TrackerState<T>,
    t2s2: TrackerState<T>,
    /// The k_df gain in effect (it ramps on activation, `EstimatorTuning::k_df_ramp_time`).
    kdf_gain: T,
    /// The low-passed Kp·e of T2S-1 added to ω̂1 for the observer, rad/s.
    lag_compensation: T,
    /// A saturating model's notch on the observer's speed (`crate::speed_notch`).
    speed_notch: SpeedNotchState<T>,
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
    /// A saturating model's frame coupling exceeds `active_flux::OFFSET_COUPLING_MAX` at the
    /// operating point of the integrand-offset law's last slot: the law holds, and the
    /// observer runs at the notched speed.
    frame_coupled: bool,
    /// The share of its rate at which the integrand-offset law learns, judged in the same
    /// slot (`crate::active_flux::ActiveFlux::offset_rate_share`; 1 for constant
    /// inductances).
    offset_share: T,
    /// Consecutive slots of the integrand-offset law with `frame_coupled` at a steady
    /// operating point in the k_df mode (the active flux within [`STEADY_ACTIVE_SHARE`] of
    /// its low-pass `swing_reference`, the law's regime unbroken): from
    /// `flux_settle_periods` on the turning R̂s law runs at the coupled point
    /// (`crate::rs_adaptation`, "The frame coupling").
    coupled_steady: u16,
    /// The observer runs at the notched speed (`crate::speed_notch`): `frame_coupled` where
    /// the frame coupling's s and ω̂ have opposite signs (on a rotor with L_q,s above L_dd,
    /// while the machine generates), judged in the same slot.
    notch_on: bool,
    /// G/c of the frame-rate correction (`step::notch`), judged in the same slot: zero
    /// where the notch's coupling test fails and on the constant-inductance path.
    frame_rate_gain: T,
    /// |λ̂r|/λa(î) low-passed, the frame-rate correction's rate source (`step::notch`).
    active_ratio: T,
    /// The R̂s adaptation runs: `EstimatorTuning::rs_adaptation`, or switched on by
    /// [`EstimatorState::enable_rs_adaptation`].
    rs_adaptation_on: bool,
    k_df_enabled: bool,
    /// T2S-1 runs at its running gains in limiter mode too (the drive's brake release, see
    /// [`EstimatorState::set_release_tracking`]).
    release_tracking: bool,
    /// The PWM ripple's terms over the sampling interval (`crate::ripple`), from
    /// [`EstimatorState::set_pwm_ripple`]: zero unless the model is the algebraic saturating
    /// one.
    ripple: PwmRipple<T>,
    /// Which sample of [`RIPPLE_EVERY`](crate::ripple::RIPPLE_EVERY) this is: the ripple's
    /// terms are refreshed on phase 0, the offset on phase 2.
    ripple_phase: u8,
    /// The interval's mean current minus its sampled current (`crate::ripple`), judged at the
    /// last committed sample and added to the next sample's resistive drop.
    ripple_offset: Ab<T>,
}
