//! The whole sensorless drive of Fig. 5: estimator, speed and current control, d-axis
//! injection, delay and dead-time compensation, SVPWM — one `step` per 10 kHz sample.
//!
//! Order of operations at sample n (docs/method/estimator.md §1, §5):
//!
//! 1. Reject non-finite inputs (trip after `protection.input_fault_trip_time` of them in a row); remove
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

mod angle_phase;
mod blocks;
mod calibration;
mod config;
mod gain_online;
mod hold;
mod lifecycle;
mod lock;
mod output;
pub mod probe_period;
mod references;
mod reject;
mod resolved;
mod saturation;
pub mod speed_bandwidth;
mod standstill;
mod step;
pub mod tracker_feedforward;
pub mod tuning;
mod turn;
mod voltage_ellipse;

pub use config::DriveConfig;
pub(crate) use config::swing_time_constant;
pub use output::DriveOutput;
pub use tuning::DriveTuning;

use crate::control::calibration_turn::CalibrationTurn;
use crate::control::current_controller::CurrentController;
use crate::control::dc_link_limit::DcLinkLimit;
use crate::control::dead_time_compensation::DeadTimeCompensation;
use crate::control::delay_compensation::DelayCompensation;
use crate::control::field_weakening::FieldWeakening;
use crate::control::gain_calibration::GainCalibration;
use crate::control::gain_tracking::GainTracking;
use crate::control::lock_reaction::LockSupervisor;
use crate::control::modulation::SpaceVectorModulator;
use crate::control::monitor::{DriveFlags, FlagCounts, PersistenceMonitor, StuckChannelDetector};
use crate::control::phase_band::PhaseBand;
use crate::control::ratings_limit::RatingsLimit;
#[cfg(doc)]
use crate::control::release_current::ReleaseCurrent;
use crate::control::release_hold::ReleaseHold;
use crate::control::saturated_references::SaturatedReferences;
use crate::control::speed_controller::SpeedController;
use crate::control::standstill_probe::StandstillProbe;
use crate::control::start_ramp::StartRamp;
use crate::control::startup::AngleSearch;
use crate::estimator::{Estimate, SensorlessEstimator};
use crate::injection::CurrentInjection;
use crate::lock::Debouncer;
use crate::magnetics::FluxWarmStart;
use crate::{Ab, Abc, Dq, Real};

/// Default of [`StallTuning::torque_band_ratio`](crate::control::tuning::StallTuning::torque_band_ratio): 1 − cos(0.25 rad), the torque
/// deficit of an estimate 0.25 rad off (the largest angle error of a clean run).
const STALL_TORQUE_BAND_RATIO: f64 = 0.031_087_578_289_355_3;

/// The absolute limits and sample counts of a [`DriveConfig`], resolved once from its ratios
/// and durations (nothing is recomputed per sample).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Resolved<T: 'static> {
    i_max: T,
    i_min: T,
    trip_current: T,
    current_error_limit: T,
    dc_link_min_voltage: T,
    offset_calibration_samples: u32,
    stuck_sensor_samples: u32,
    current_error_samples: u32,
    input_fault_trip_samples: u32,
    /// The stall symptom's thresholds.
    stall: StallResolved<T>,
    /// Phase currents beyond ± this (A) are refused as implausible.
    plausible_current: T,
    /// Ts²/(2·L̂q) (s/H): the stuck-channel detector's model allowance per (rad/s)²·Wb
    /// (`SensorlessDrive::stuck_model_uncertainty`).
    stuck_turn_gain: T,
    /// DC-link readings above this (V) are refused as implausible.
    dc_link_max_voltage: T,
    /// MTPA d current on (configured and the machine is salient).
    mtpa: bool,
    /// The machine is salient: the speed loop's q current is scaled by λ̂f/λ̂a (see
    /// [`Drive::torque_current`]).
    salient: bool,
    /// A saturating model's MTPA table and torque (`crate::control::saturated_references`);
    /// None for constant inductances.
    saturated: Option<SaturatedReferences<T>>,
    /// The release's d-current floor is on while a brake holds the rotor, before it opens
    /// (`hold::floor_at_brake`).
    floor_at_brake: bool,
}

/// The stall symptom's thresholds in absolute units (see
/// `StallTuning::speed_ratio`).
#[derive(Clone, Copy, Debug, PartialEq)]
struct StallResolved<T> {
    /// Speed error (electrical rad/s) in limiter mode, and samples in a row
    /// (0 samples or speed 0: off).
    speed: T,
    samples: u32,
    heal_samples: u32,
    /// The stall symptom counts below this |ω̂| (electrical rad/s; ∞: always).
    max_speed: T,
    /// The stall symptom also counts in k_df mode below this |ω̂| (electrical rad/s; 0: only
    /// in limiter mode).
    kdf_band: T,
    /// The stall symptom counts from this |i_q*| on (A).
    min_current: T,
    /// ... or beyond this multiple of the band (∞: the current gate always applies).
    gross_ratio: T,
    /// Per-sample gain 1 − exp(−Ts/τ) of the ω̂ low-pass of `stall.follow_time` (0: the
    /// "answers the torque" exception is off).
    follow_gain: T,
    /// The exception holds from this |i_q*| on (A).
    follow_min_current: T,
    /// ω̂ − ω̂_lp (electrical rad/s) beyond which ω̂ accelerates: the least acceleration
    /// times τ.
    follow_lead: T,
    /// Band widening per unit of (λ̂f + (L̂d − L̂q)·i_d*)·i_q* (electrical rad/s per Wb·A): the
    /// torque ratio of `stall.torque_band_ratio` times 1.5·p (torque) times p (electrical
    /// speed) over Ĵ·ω_s.
    torque_band: T,
    /// The same for `stall.reluctance_band_ratio`, per unit of (L̂d − L̂q)·i_d*·i_q*
    /// (Wb·A).
    reluctance_band: T,
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
    dc_link: DcLinkLimit<T>,
    field_weakening: FieldWeakening<T>,
    /// The release hold after the start-up.
    hold: ReleaseHold<T>,
    /// The d-current floor while the hold is armed (its [`ReleaseCurrent`]) and no phase
    /// current inside
    /// the dead-time band near zero speed (see [`phase_band`](crate::control::phase_band)).
    phase_band: PhaseBand<T>,
    limits: RatingsLimit<T>,
    /// The speed reference's ramp from the start-up's end.
    start_ramp: StartRamp<T>,
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

/// The sensorless drive of Fig. 5 around any [`RotorAngleEstimator`](crate::estimator::RotorAngleEstimator) (by default the
/// paper's [`SensorlessEstimator`]). Allocation-free, never panics; see the module docs for
/// the order of operations and the timing contract.
///
/// ```
/// use fado_core::control::{DriveConfig, SensorlessDrive};
/// use fado_core::{Abc, EstimatorTuning, MachineModel};
/// let config = DriveConfig::for_machine(&MachineModel::paper());
/// let mut drive = SensorlessDrive::<f32>::new(config, EstimatorTuning::default()).unwrap();
/// drive.align(0.0);
/// // Power-up: the first samples short the phases through the low-side switches (duties 0;
/// // at rest no current flows) and measure the sensor offsets.
/// while drive.is_calibrating() {
///     let out = drive.step(Abc::new(0.02, -0.01, -0.01), 300.0, 0.0);
///     assert!(!out.gates_enabled || out.duty.a == 0.0);
/// }
/// assert!((drive.current_offset().a - 0.02).abs() < 1e-6);
/// // In the 10 kHz ISR: phase currents sampled now, dc-link voltage, speed reference.
/// let out = drive.step(Abc::new(0.1, -0.05, -0.05), 300.0, 10.0);
/// assert!(out.gates_enabled && (0.0..=1.0).contains(&out.duty.a));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorlessDrive<T: 'static, E = SensorlessEstimator<T>> {
    config: DriveConfig<T>,
    /// The config's limits and sample counts in absolute units.
    resolved: Resolved<T>,
    estimator: E,
    blocks: Blocks<T>,
    /// Realised references (before dead-time compensation) computed at n−1 and n−2.
    history: [Ab<T>; 2],
    /// The dead-time trapezoid (α-β, V) at the reference currents of the gain calibration's
    /// voltages computed at n−1 and n−2 (its rotor-motion test's inverter voltage; zero
    /// outside it).
    calibration_compensation: [Ab<T>; 2],
    /// Whether the modulator limited each of `history`'s voltages (the estimator's R̂s
    /// adaptation skips a period with a limited one, `RotorAngleEstimator::voltage_limited`).
    limited: [bool; 2],
    /// The last finite α-β current, fed to the estimator while inputs are rejected.
    last_i_ab: Ab<T>,
    last: DriveOutput<T>,
    tripped: bool,
    rejected_samples: u32,
    /// Samples of the offset calibration still to take (the zero vector while > 0).
    calibration_remaining: u32,
    /// Sum of the raw phase currents during the calibration.
    calibration_sum: Abc<T>,
    /// Sum of |i_ab|² of the raw currents during a watched offset calibration (A²).
    calibration_square_sum: T,
    /// Phase-current offsets subtracted from every sample (A).
    current_offset: Abc<T>,
    /// The angle of the last `align` (or of the calibration's turn), re-applied when the
    /// calibration ends.
    aligned_angle: T,
    /// The start-up gain-mismatch calibration (after the offsets) and its result.
    gain: GainCalibration<T>,
    /// The free rotor's turn onto a well-observed axis before that calibration, while under way.
    turn: Option<CalibrationTurn<T>>,
    /// The start-up's angle phase (after the offsets, before the gain calibration).
    startup: AngleSearch<T>,
    /// 1/k: the factor on the phase-a reading (1 until a ratio is measured).
    gain_correction: T,
    /// The online tracker of that factor, where the start-up calibration did not set it.
    gain_tracking: GainTracking<T>,
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
    /// The stall symptom (see `StallTuning::speed_ratio`) as a live status (heals
    /// like the estimator's; cleared by `align`, `reset`, a recovery's re-arming).
    stall: Debouncer,
    stall_armed: bool,
    /// A brake holds the rotor from the start-up's end until the application opens it
    /// ([`arm_release_hold`](Self::arm_release_hold)) on a rotor whose floor is on there
    /// (`Resolved::floor_at_brake`).
    brake_holds: bool,
    /// Why the drive coasts (`LOCK_LOST`, `STALLED` or both): the symptoms up when the
    /// reaction started, kept while it coasts.
    coast_reason: DriveFlags,
    /// ω̂ low-passed with `StallTuning::follow_time` (electrical rad/s).
    omega_slow: T,
    /// This sample was refused as implausible.
    implausible_now: bool,
    /// A saturating model's flux ψ at the last current reference (Wb); unused for constant
    /// inductances.
    saturated_flux: Dq<T>,
    /// The tangent plane of ψ(i) there: where the next sample's torque solve starts its
    /// flux (`saturated_references`, `crate::magnetics::FluxWarmStart`).
    saturated_warm: FluxWarmStart<T>,
    /// The current that tangent plane was evaluated at, A (the realised torque reads the
    /// plane alone within a settled step of it).
    saturated_point: Dq<T>,
}

fn estimate_is_finite<T: Real>(e: &Estimate<T>) -> bool {
    e.theta.is_finite() && e.omega.is_finite() && e.omega_control.is_finite()
}

#[cfg(test)]
mod tests;
