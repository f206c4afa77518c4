//! Start-up calibration of the current sensors' gain mismatch: the ratio k = (1 + g_a)/(1 + g_b)
//! of the phase-a and phase-b channels' gains, measured with two DC current levels along the
//! aligned rotor's d axis (no torque), as drives calibrate the sensor offsets.
//!
//! # Why
//! Two sensors measure phases a and b; c = −(a + b). With phase a read as (1 + g)·i_a (g the
//! relative mismatch), the α-β current reads i + g·i_a·(1 + j/√3) =
//! i + (g/2)(1 + j/√3)·i + (g/2)(1 + j/√3)·conj(i): a small scale and turn of the current, and
//! a negative-sequence part (g/2)(1 + j/√3)·conj(i). Times R̂s the latter is an integrand
//! error of eq. (3), DC at standstill; under load nothing observes the angle at standstill and it walks θ̂ at
//! about R̂s·|Δi|/λ̂f: ≈ 2.5 rad/s on a 2.4 mWb motor with a 0.5 % mismatch (the
//! `outrunner-cheetah-24v` preset). A common gain of both channels is harmless (it scales the
//! current like an R̂s scale and is unobservable without a reference); only k is measured.
//!
//! # The measurement
//! At DC steady state the machine is a symmetric resistance, so each phase obeys
//! v_x = Rs·i_x + u_x, with u_x the inverter's voltage error in phase x (dead time, device
//! drops; the phase voltages are those of the α-β vector, zero sequence removed). u_x depends
//! on the sign of i_x (and, within the inverter's current band and the ripple, on its size):
//! two current levels I₁ = I₂/2 and I₂ along the **same** axis, both with every phase well
//! outside that band, have the same u_x, and the difference of the two levels is purely
//! resistive: Δv_x = Rs·Δi_x (the classic two-point DC test, as in
//! [`crate::commissioning`]). A sensor of gain (1 + g_x) reads Δi_x,meas = (1 + g_x)·Δi_x, so
//! each phase's apparent conductance is (1 + g_x)/Rs and
//!
//! k = (Δi_a,meas / Δv_a) / (Δi_b,meas / Δv_b)
//!
//! exactly, whatever Rs (and with no small-mismatch approximation). Equivalently: the true
//! current difference is parallel to Δv; the measured one is turned from it by
//! (k − 1)·(2/√3)·cos φ·cos(φ + π/3) rad (φ the axis angle), the form of the cross-product
//! estimator. The drive applies 1/k to phase a (c following from KCL), after the offsets and
//! before everything else.
//!
//! Δv is the drive's realised voltage reference (the voltage it tells the estimator acted,
//! after its dead-time compensation); Δi is the measured current; both are averaged over a
//! window per level. The lower level I₁ is set by the drive's own current loop with the
//! reference (I₁, 0) in the d-q frame of the aligned angle θ0 at ω = 0 (the inverter error is
//! unknown, so only a loop finds the voltage for a given current); its voltage, averaged over
//! the second half of the settling, is then **frozen** (V₁), and the upper level is the voltage
//! V₁ + R̂s·I₁ along the axis (≈ 2·I₁; a wrong R̂s only moves the level). A d current makes no
//! torque on a rotor at θ0 (on a salient one too, i_q = 0).
//!
//! # Rs, from the same levels
//! The two levels are also the classic two-point DC test of the resistance:
//! R = Δv·Δi′/|Δi′|² along the axis, with Δi′ the measured difference corrected by k
//! ([`resistance_of`], [`GainCalibration::resistance`]). The inverter's constant error cancels
//! as for k; what remains of the settling is e^(−hold/τ)·τ/window of the step (τ = L/R). The
//! drive hands it to the estimator's R̂s adaptation as its start value (within 0.5–2× of the
//! model's R̂s; the paper's fixed R̂s is left as configured): a winding warmer than the model
//! is then known before the rotor turns, which the scenarios with the plant's Rs 1.3× the
//! model's need now that the drive starts later.
//!
//! # The rotor's swing
//! The loop regulates the *measured* current onto the axis; the true one is off it by an angle
//! of order g, so the rotor, held only by the d current's stiffness, swings towards it. Its
//! back-EMF jω·λf is not resistive and biases Δv: in current mode (no damping) this biased k
//! by 2.8e-3 on the paper's motor and 2.8e-2 on a 50 kW IPMSM, against a 5e-3 mismatch (fado-sim,
//! a rotor of huge inertia: 4e-6). In voltage mode the back-EMF drives a current through Rs
//! that damps the swing (J·s² + c·s + K, c = 1.5·p²·λf²/Rs); each level is averaged only after
//! a hold of several of its time constants (`hold_time`, from the drive's model), or of a
//! shorter hold and a window long enough to average what is left of the swing, whose bias on
//! a phase's conductance grows as 1/(its share of the axis current): that window is sized
//! along the calibration's axis when it starts (`swing_window_time`,
//! [`GainCalibration::swing_window_share`]). A machine whose swing (or settling) needs more
//! than `max_hold_time` of hold or window is not calibrated
//! ([`GainCalibrationStatus::TooSlow`]), unless a brake holds the rotor through the start-up
//! (the drive's `startup.rotor_held`): nothing swings then, and the drive holds each level for
//! the current's settling alone (on the 50 kW IPMSM, the 5 kW PM-SyRM, the hub motor and an
//! 8-pole saturated traction IPMSM, whose free swings need 0.61–1.0 s: k within 1.9e-3 of
//! 1.005, `crates/fado-sim/tests/gain_calibration.rs`). Where it ends without a ratio, the
//! drive learns it while the rotor turns under load
//! ([`gain_tracking`](crate::control::gain_tracking)).
//!
//! # Observability and error bound
//! Phase x carries the fraction cos(φ − φ_x) of the axis current (phase axes at φ_a = 0,
//! φ_b = 2π/3, φ_c = −2π/3 in α-β). With δv_x the part of the voltage error in phase x that does
//! not cancel between the levels (inverter error that changes with the level, what is left of
//! the swing's back-EMF) and σ the averaged noise, to first order
//!
//! |δk|/k ≤ |δv_a|/|Δv_a| + |δv_b|/|Δv_b| + σ_i/|Δi_a| + σ_i/|Δi_b|,
//! |Δv_x| = Rs·(I₂ − I₁)·|cos(φ − φ_x)|,
//!
//! so the error grows as 1/|cos(φ − φ_x)| where phase a or b carries little current
//! (φ = ±π/2: phase a; φ = π/6, −5π/6: phase b). Phase c enters through the zero sequence:
//! where it carries little current (φ = −π/6, 5π/6) its inverter error changes between the
//! levels (current band, ripple) and spreads δu_c/3 onto a and b (measured with an earlier,
//! current-mode version: k off by 1.2e-2 to 5.4e-2 at φ = −0.5, share 0.023, on four presets). The calibration is **skipped** (status
//! [`GainCalibrationStatus::Unobservable`], k unchanged, no current) when the smallest share of
//! the three phases, [`GainCalibration::observability`], is below `min_observability`, and a
//! result is refused ([`GainCalibrationStatus::Implausible`]) when the measured currents say
//! the same, when a conductance comes out non-positive or non-finite, when a current exceeds
//! `current_limit` in voltage mode, or when |k − 1| exceeds `max_mismatch`. On the simulator's
//! inverter (dead time with the docs/method/estimator.md §7 linear band, device drops, ripple resolved edge by
//! edge) the measured accuracy is in `crates/fado-sim/tests/gain_calibration.rs` (within
//! 1.2e-3 of 1.005 on four presets at four angles); an inverter whose error keeps growing well
//! beyond the current band (a capacitive commutation tail, fado-sim's
//! `Commutation::Capacitor`) breaks the cancellation and biases k.
//!
//! # Rotor motion
//! The levels assume a rotor at rest: a load that arrives while the d current holds the rotor
//! turns it (on the 2.2 kW IPMSM, 7 N·m against its 6 A upper level: towards 0.5 rad, and free
//! once the current returns to zero). A turning rotor's back-EMF ω·ψa (ψa = λ̂f + (L̂d − L̂q)·i_d,
//! the active flux) lies across the axis, and across it the voltage that acted obeys
//! Δv⊥ = R̂s·Δi⊥ + L̂q·dΔi⊥/dt + ω·ψa, Δ the change since the stage's first sample. The
//! calibration evaluates R̂s·Δi⊥ + L̂q·dΔi⊥/dt − Δv⊥ every sample of every stage (the current
//! low-passed over [`MOTION_FILTER_TIME`] for its derivative, the voltage alike): in voltage
//! mode the reference is frozen and Δv⊥ is the inverter's own change, under the current loop
//! (the settling at I₁, the release to zero) it is the loop's voltage too. The inverter's part
//! comes from the drive's dead-time trapezoid at the measured current against the one at the
//! reference current (`GainCalibration::step_with_inverter`): a phase whose current a turning
//! rotor moves into the band, or from one side of it to the other, changes its voltage by up
//! to 2·V̂, which the rotor's motion does not explain (on the 2-pole spindle of
//! `crates/fado-sim/tests/calibration_load_classes.rs`, the phase carrying a fifth of the
//! level reverses, and without the term the test reads 0.69 of its threshold while the rotor
//! turns at 500 r/min). The stage's reference, the voltage that acted at its first sample,
//! leaves that modelled part out: the stage just left is settled at its reference current
//! (at zero current before the first), where the model's compensation and loss cancel,
//! while the loss at one sample's measured current inside the band is the sensors' noise
//! times the band's slope V̂/Ic (25.7 Ω on the 560 V, 8 kHz inverter of the 32-pole torque
//! motor in `crates/fado-sim/tests/data/torque-ipm-32p.toml`: 1.7 V per phase for one
//! 0.067 A step of its sensors). Taken into the reference, that one sample would offset the
//! settling's whole reading by 0.35–0.40 V across the axis, above the loop's mean threshold
//! ([`LOOP_WINDOW_FACTOR`] × `motion_voltage`, 0.33 V there): the test would read that still
//! rotor as moving at sensor seeds 1–4, and the 310 V appliance motor of
//! `crates/fado-sim/tests/data/unseen/` at seeds 3 and 4.
//! Above `motion_voltage` ([`MOTION_SPEED_RATIO`] of the rated speed's
//! back-EMF; [`LOOP_MOTION_FACTOR`] times it under the current loop, whose step through the
//! band the trapezoid gives only roughly) the calibration ends at once with
//! [`GainCalibrationStatus::RotorMoved`]: no release to zero current. The drive starts at once
//! from the aligned angle plus the turn read ([`GainCalibration::motion_travel`]) with its
//! release hold engaged
//! ([`ReleaseHold::engage`](crate::control::release_hold::ReleaseHold::engage)), which catches
//! the rotor there and hands the load it found to the speed loop. In the release to zero
//! current both levels are averaged, with the rotor at rest: a motion read there leaves their
//! ratio and resistance standing ([`GainCalibration::moved_in_release`]), and the drive arms
//! the hold there instead, to act on the fall that follows
//! ([`ReleaseHold::arm_after_release`](crate::control::release_hold::ReleaseHold::arm_after_release)). Measured on the presets and
//! the machines of that test at rest (switching-resolved, default sensors, five angles): at
//! most 0.59 of the threshold in voltage mode ([`GainCalibration::motion_peak`]) and 0.48
//! under the loop ([`GainCalibration::loop_motion_peak`]).
//!
//! Under the loop the test also averages the back-EMF over [`LOOP_WINDOW_TIME`] (4 ms) and
//! ends the calibration where that mean exceeds [`LOOP_WINDOW_FACTOR`] × `motion_voltage`
//! (1 % of the rated speed): the band's step lasts about a millisecond and averages out,
//! while a turning rotor's back-EMF keeps growing. At rest the presets and the machines of
//! `crates/fado-sim/tests/calibration_load_classes.rs` read at most 0.46 of that threshold
//! (the 1.5 kW servo motor; [`GainCalibration::loop_window_peak`]). On the 2-pole spindle
//! there, half its rated torque arriving 1 ms into the settling then ends it with the rotor
//! 0.5 rad back instead of losing it (π off), and on the servo motor a load during the release
//! to zero is read at 0.25 rad instead of 0.65 rad.
//!
//! With the loop at zero current every phase sits in the inverter's band, a resistance of
//! V̂/I_c (V̂ the dead-time and device voltage, I_c the band): a back-EMF below V̂ drives a
//! band current of a few sensor steps, and the release stage reads a turning rotor only once
//! its back-EMF nears V̂ (the 1.5 kW servo motor there: 8.8 V, 5 % of its rated speed).
//!
//! # Sequence
//! Current loop at I₁ (`settle_time`); voltage V₁: hold (`hold_time`), average
//! (`window_time`); voltage V₁ + R̂s·I₁: hold, average; current loop at zero (`settle_time`);
//! then the status is final ([`GainCalibration::running`] false). Every stage ends after a
//! fixed number of samples: the calibration always terminates, after
//! [`GainCalibration::duration_samples`]. The current reference is never above I₁ and a
//! voltage-mode current above `current_limit` ends the sequence (the drive sets it to its
//! I_max, with I₂ = 2·I₁ ≤ I_max).
//!
//! # Duration
//! What each stage waits for: under the current loop (the settling at I₁, the release) the
//! loop's response, 5·max(L̂d/R̂s, 1/ωc) from the drive; in voltage mode the current's own
//! settling through the axis's L/R (the hold is at least the settling) and the rotor's swing,
//! and the averaging window. The whole sequence along the calibration's axis
//! ([`GainCalibration::duration_samples`]) is bounded by `max_time`: a longer one is not run
//! ([`GainCalibrationStatus::TooSlow`]), so that a calibration never holds a free rotor into
//! the time its application loads it (the drive's bound and the measurements:
//! `gain_calibration_max_time` in `control/drive/config.rs`).

mod measure;
mod motion;
mod sequence;
#[cfg(test)]
mod tests;

pub use measure::{ratio_of, resistance_of};
pub use motion::{
    LOOP_MOTION_FACTOR, LOOP_WINDOW_FACTOR, LOOP_WINDOW_TIME, MOTION_FILTER_TIME,
    MOTION_NOISE_MARGIN, MOTION_SPEED_RATIO, MOTION_TRAVEL_SHARE, motion_voltage,
};

use crate::control::snapshot_window::SnapshotWindow;
use crate::error::{ConfigError, check};
use crate::{Ab, Real};
use measure::{PHASE_B_ALPHA, PHASE_B_BETA};

/// Configuration of a [`GainCalibration`], in absolute units (its user derives it from its
/// own ratios and its machine model; defaults `DEFAULT_*`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GainCalibrationConfig<T> {
    /// Sampling period in s.
    pub ts: T,
    /// Lower current level I₁ in A, set by the current loop; the upper one is reached with
    /// the voltage step R̂s·I₁ (I₂ ≈ 2·I₁).
    pub current: T,
    /// R̂s in Ω: sizes the voltage step to the upper level.
    pub rs_hat: T,
    /// Settling of the current loop at I₁, of each voltage step and of the return to zero, s.
    pub settle_time: T,
    /// Time for the rotor's swing to die out after the voltage is frozen, s (at least
    /// `settle_time` is used).
    pub hold_time: T,
    /// Longest hold accepted, s: a machine needing a longer `hold_time` or `settle_time` is
    /// not calibrated ([`GainCalibrationStatus::TooSlow`]).
    pub max_hold_time: T,
    /// Averaging window of each level, s; 0 disables the calibration.
    pub window_time: T,
    /// The averaging window (s) the rotor's swing left after the hold needs along an axis
    /// whose phases a and b both carry the share `min_observability` (the swing's bias bound,
    /// [`DriveConfig::gain_calibration_config`](crate::control::DriveConfig::gain_calibration_config));
    /// 0 where `window_time` meets it. The bias on each phase's conductance scales as
    /// 1/share, so along the calibration's axis, shares s_a and s_b, the swing needs
    /// s_min·(1/s_a + 1/s_b)/2 of it ([`GainCalibration::swing_window_share`]): each level is
    /// averaged over the longer of that and `window_time`, and an axis that needs more than
    /// `max_hold_time` is not calibrated ([`GainCalibrationStatus::TooSlow`]; as is a
    /// non-finite one).
    pub swing_window_time: T,
    /// Smallest share min(|cos φ|, |cos(φ − 2π/3)|) of the axis current in phases a and b,
    /// and |cos(φ + 2π/3)| in phase c, with which the calibration runs, in [0, 1).
    pub min_observability: T,
    /// Largest |k − 1| accepted as a measurement of the sensors (a larger one is refused).
    pub max_mismatch: T,
    /// A measured current above this (A) in voltage mode aborts the calibration (R̂s far
    /// above the machine's resistance).
    pub current_limit: T,
    /// L̂q in H: the inductance across the axis, for the rotor-motion test.
    pub lq_hat: T,
    /// Longest whole sequence accepted, s (∞: no bound): a sequence (settle, both levels'
    /// holds and windows along the calibration's axis, release) beyond it is not run
    /// ([`GainCalibrationStatus::TooSlow`]; module docs, "Duration").
    pub max_time: T,
    /// The rotor-motion test's threshold (V): in voltage mode, a back-EMF across the axis
    /// |R̂s·Δi⊥ + L̂q·dΔi⊥/dt| (Δi⊥ the change of the current across the axis since the
    /// level's voltage was frozen, low-passed over [`MOTION_FILTER_TIME`]) above this ends
    /// the calibration at once with [`GainCalibrationStatus::RotorMoved`]. ∞ disables the
    /// test.
    pub motion_voltage: T,
}

/// Default `min_observability` \[A\]: the error grows as 1/share (module docs); 38 % skipped.
pub const DEFAULT_MIN_OBSERVABILITY: f64 = 0.2;
/// Default `max_mismatch` \[A\]: two sensors of ±2.5 % gain tolerance.
pub const DEFAULT_MAX_MISMATCH: f64 = 0.05;

/// Where the calibration stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GainCalibrationStatus {
    /// Disabled by the configuration (window 0): the ratio stays as it is (1 at first).
    Off,
    /// Armed: runs at the next sample the drive gives it.
    Pending,
    /// Current levels being applied and averaged.
    Running,
    /// Measured: the ratio is the new one.
    Calibrated,
    /// Skipped: the axis leaves a phase with less than `min_observability` of the current
    /// (ratio unchanged, no current applied).
    Unobservable,
    /// Skipped: the rotor's swing about the d current dies out too slowly, or the current
    /// settles too slowly (`hold_time`, `settle_time` or the swing's window along the axis,
    /// `swing_window_time`, above `max_hold_time`), or the whole sequence along the axis
    /// would exceed `max_time` (ratio unchanged, no current applied).
    TooSlow,
    /// Measured but refused: non-finite, a non-positive conductance, too few finite samples,
    /// a current above `current_limit` in voltage mode, or |k − 1| above `max_mismatch`
    /// (ratio unchanged).
    Implausible,
    /// Ended early: the rotor turned during a voltage-mode level (a load arrived while the
    /// d current held it; see `motion_voltage`), or skipped because it turned during the
    /// offset calibration ([`GainCalibration::skip_moving`]). The drive starts at once from the aligned
    /// angle, so that its speed loop takes the load (ratio unchanged).
    RotorMoved,
}

/// What the drive applies at a sample of the calibration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GainCalibrationCommand<T> {
    /// The d-axis current (A) in the frame of the calibration's angle: the current loop's
    /// reference, or (with `voltage`) the level the dead-time compensation is set for.
    pub current_d: T,
    /// Voltage mode: this α-β voltage reference (V), before dead-time compensation, instead
    /// of the current loop's.
    pub voltage: Option<Ab<T>>,
}

/// The sequence's states.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    Idle,
    /// Current loop at I₁ (its voltage averaged over the second half into V₁).
    Settle,
    /// Voltage V₁ (lower level): swing decay, then averaging.
    HoldLower,
    AverageLower,
    /// Voltage V₁ + R̂s·I₁ along the axis (upper level): swing decay, then averaging.
    HoldUpper,
    AverageUpper,
    /// Current loop at 0.
    Release,
}

/// The two-level gain-mismatch calibration (module docs). Allocation-free; `step` once per
/// sample while [`running`](Self::running).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GainCalibration<T> {
    config: GainCalibrationConfig<T>,
    settle_samples: u32,
    hold_samples: u32,
    /// The hold `new` derives from the configuration ([`start_with_hold`](Self::start_with_hold)
    /// lengthens it for one calibration).
    hold_default: u32,
    /// The hold of this calibration is shorter than its axis's settling
    /// ([`start_with_hold`](Self::start_with_hold)): k only, no resistance.
    unsettled: bool,
    /// `max_time` in samples (`u32::MAX` without a bound).
    max_samples: u32,
    /// Settling or hold beyond `max_hold_time`: skipped.
    too_slow: bool,
    window_samples: u32,
    /// The window of the present (or last) start: `window_samples`, or the longer one the
    /// swing needs along its axis.
    window_run: u32,
    stage: Stage,
    /// Samples left in the current stage.
    remaining: u32,
    /// Unit vector of the axis.
    axis: Ab<T>,
    /// The frozen lower-level voltage V₁ (its sum while the current loop settles).
    v_lower: Ab<T>,
    v_lower_count: u32,
    /// Per level (0 lower, 1 upper): sums of the measured current and of the voltage, and
    /// finite samples.
    sum_i: [Ab<T>; 2],
    sum_v: [Ab<T>; 2],
    count: [u32; 2],
    /// Voltage mode ended by an over-current.
    aborted: bool,
    /// The measured current across the axis as the level's voltage was frozen (A), the
    /// motion test's reference, and Δi⊥ low-passed (A).
    cross_ref: T,
    cross_filtered: T,
    /// The voltage that acted across the axis at the stage's first sample (V), and its
    /// change since then low-passed as Δi⊥ is (V).
    cross_v_ref: T,
    cross_v_filtered: T,
    /// Σ of the back-EMF across the axis times Ts over the level's samples where it exceeded
    /// [`MOTION_TRAVEL_SHARE`] of `motion_voltage` (V·s): the turn of a moving rotor times its
    /// d-axis flux ([`GainCalibration::motion_flux`]).
    motion_flux: T,
    /// The d current of the level in which the rotor moved (A; zero before) and the
    /// back-EMF across the axis that ended it (V).
    motion_current: T,
    motion_emf: T,
    /// The motion test fired in the release to zero current, after both levels were
    /// averaged with the rotor at rest ([`GainCalibration::moved_in_release`]).
    moved_in_release: bool,
    /// The voltage-mode motion threshold's floor from the sensors' noise (V,
    /// [`GainCalibration::motion_noise_floor`]).
    noise_floor: T,
    /// The largest |back-EMF across the axis| read since the start, over its threshold.
    motion_peak: T,
    /// The same, of the stages under the current loop.
    loop_motion_peak: T,
    /// Under the current loop: Σ back-EMF·Ts since the stage's first sample (V·s), its
    /// snapshots over [`LOOP_WINDOW_TIME`](motion::LOOP_WINDOW_TIME); the largest mean back-EMF over the window read
    /// since the start, over its threshold ([`LOOP_WINDOW_FACTOR`] × `motion_voltage`).
    window_flux: T,
    window: SnapshotWindow<T, { motion::WINDOW_SLOTS }>,
    loop_window_peak: T,
    status: GainCalibrationStatus,
    ratio: T,
    /// The last measured ratio, also when refused (NaN before any).
    measured: T,
    /// The resistance of the last accepted measurement (NaN before any), Ω.
    resistance: T,
}

/// `max_time` (s) in sampling periods `ts`: `u32::MAX` for +∞ (no bound); NaN and −∞ refused.
fn bound_samples<T: Real>(time: T, ts: T) -> Result<u32, ConfigError> {
    if time > T::zero() && !time.is_finite() {
        Ok(u32::MAX)
    } else {
        check::samples("max_time", time, ts)
    }
}

impl<T: Real> GainCalibration<T> {
    /// A new calibration (armed unless disabled); every field is checked and a bad one named.
    pub fn new(config: GainCalibrationConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        check::positive("current", config.current)?;
        check::positive("rs_hat", config.rs_hat)?;
        let samples = |field: &'static str, time: T| check::samples(field, time, ts);
        let max_hold = check::non_negative("max_hold_time", config.max_hold_time)?;
        let max_hold_samples = samples("max_hold_time", max_hold)?;
        // Settling and hold from the model: beyond the budget (or NaN) skipped, not refused.
        let too_slow = !(config.settle_time <= max_hold && config.hold_time <= max_hold);
        let within = |time: T| -> Result<u32, ConfigError> {
            if time >= T::zero() && time <= max_hold {
                samples("hold_time", time)
            } else {
                Ok(max_hold_samples)
            }
        };
        let settle_samples = within(config.settle_time)?;
        let hold_samples = within(config.hold_time)?.max(settle_samples);
        let window_samples = samples("window_time", config.window_time)?;
        let max_samples = bound_samples(config.max_time, ts)?;
        check::below(
            "min_observability",
            check::non_negative("min_observability", config.min_observability)?,
            T::one(),
            "in [0, 1)",
        )?;
        check::positive("max_mismatch", config.max_mismatch)?;
        check::positive("current_limit", config.current_limit)?;
        if config.current > config.current_limit {
            return Err(ConfigError::OutOfRange {
                field: "current",
                expected: "at most current_limit",
            });
        }
        let status = if window_samples == 0 {
            GainCalibrationStatus::Off
        } else {
            GainCalibrationStatus::Pending
        };
        Ok(Self {
            config,
            settle_samples,
            max_samples,
            hold_samples,
            hold_default: hold_samples,
            unsettled: false,
            too_slow,
            window_samples,
            window_run: window_samples,
            stage: Stage::Idle,
            remaining: 0,
            axis: Ab::new(T::one(), T::zero()),
            v_lower: Ab::zero(),
            v_lower_count: 0,
            sum_i: [Ab::zero(); 2],
            sum_v: [Ab::zero(); 2],
            count: [0; 2],
            aborted: false,
            cross_ref: T::zero(),
            cross_filtered: T::zero(),
            cross_v_ref: T::zero(),
            cross_v_filtered: T::zero(),
            motion_flux: T::zero(),
            motion_current: T::zero(),
            motion_emf: T::zero(),
            moved_in_release: false,
            noise_floor: T::zero(),
            motion_peak: T::zero(),
            loop_motion_peak: T::zero(),
            window_flux: T::zero(),
            window: SnapshotWindow::new(motion::LOOP_WINDOW_TIME, ts, T::zero()),
            loop_window_peak: T::zero(),
            status,
            ratio: T::one(),
            measured: T::zero() / T::zero(),
            resistance: T::zero() / T::zero(),
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> &GainCalibrationConfig<T> {
        &self.config
    }

    /// The whole sequence's duration in samples when it runs: settle at I₁, hold and window
    /// at each level (the window of the last start, the configured one before any), release.
    pub fn duration_samples(&self) -> u32 {
        self.settle_samples
            .saturating_mul(2)
            .saturating_add(self.hold_samples.saturating_mul(2))
            .saturating_add(self.window_run.saturating_mul(2))
    }

    /// Arms the calibration (unless disabled): it starts at the next [`step`](Self::step).
    /// The ratio measured before is kept until a new one is.
    pub fn arm(&mut self) {
        self.stage = Stage::Idle;
        if self.window_samples > 0 {
            self.status = GainCalibrationStatus::Pending;
        }
    }

    /// Skipped because the rotor turned before it could run (the drive's offset calibration
    /// saw a load turn it): [`GainCalibrationStatus::RotorMoved`], no current, the ratio kept.
    pub fn skip_moving(&mut self) {
        self.stage = Stage::Idle;
        self.motion_flux = T::zero();
        self.motion_current = T::zero();
        self.motion_emf = T::zero();
        self.status = GainCalibrationStatus::RotorMoved;
    }

    /// Armed and waiting for its first sample.
    pub fn pending(&self) -> bool {
        self.status == GainCalibrationStatus::Pending
    }

    /// Armed or applying current.
    pub fn running(&self) -> bool {
        matches!(
            self.status,
            GainCalibrationStatus::Pending | GainCalibrationStatus::Running
        )
    }

    /// The status.
    pub fn status(&self) -> GainCalibrationStatus {
        self.status
    }

    /// The ratio k = (1 + g_a)/(1 + g_b) in use: the last accepted measurement, 1 before any.
    /// The drive divides the phase-a reading by it.
    pub fn ratio(&self) -> T {
        self.ratio
    }

    /// The last measured ratio, accepted or not (NaN before any measurement).
    pub fn measured_ratio(&self) -> T {
        self.measured
    }

    /// The stator resistance the last accepted measurement gives, Ω (NaN before any): the
    /// two-point DC test R = Δv·Δi′/|Δi′|² along the axis, Δi′ the current difference with
    /// phase a corrected by the measured k ([`resistance_of`]). The inverter's constant
    /// error cancels between the levels as it does for k; what grows with the current (the
    /// devices' on-resistance) is in it, as it is in the voltage the estimator integrates.
    /// The drive starts its R̂s adaptation from it (TI's InstaSPIN re-measures Rs at every
    /// start the same way, "Rs recalibration", SPRUHJ1, §"Rs Online and Rs Recalibration").
    pub fn resistance(&self) -> T {
        self.resistance
    }

    /// Whether the run ended [`GainCalibrationStatus::RotorMoved`] in its release to zero
    /// current, after both levels were averaged with the rotor at rest: their ratio and
    /// resistance stand ([`ratio`](Self::ratio), [`resistance`](Self::resistance); NaN
    /// where the levels gave none), and the turn the release read
    /// ([`motion_travel`](Self::motion_travel)) is where a load starts to act, not one it
    /// has finished (module docs, "Rotor motion").
    pub fn moved_in_release(&self) -> bool {
        self.moved_in_release
    }

    /// The share of `swing_window_time` the rotor's swing needs along the axis at `angle`
    /// (electrical rad): s_min·(1/s_a + 1/s_b)/2 with s_a = |cos φ|, s_b = |cos(φ − 2π/3)| the
    /// shares of phases a and b and s_min = `min_observability` (1 where both are s_min,
    /// 0.3 at φ = 0; ∞ where a share is zero).
    pub fn swing_window_share(&self, angle: T) -> T {
        let (s, c) = angle.step_sin_cos_any();
        let b = c * T::lit(PHASE_B_ALPHA) + s * T::lit(PHASE_B_BETA);
        let half = T::lit(0.5) * self.config.min_observability;
        half * (T::one() / c.abs() + T::one() / b.abs())
    }

    /// The smallest share of the axis current in any phase, min over x of |cos(φ − φ_x)|,
    /// for an axis at `angle` (electrical rad): phases a and b for the observability, c for
    /// the inverter error's cancellation (module docs).
    pub fn observability(angle: T) -> T {
        let (s, c) = angle.step_sin_cos_any();
        let b = c * T::lit(PHASE_B_ALPHA) + s * T::lit(PHASE_B_BETA);
        let phase_c = -c - b;
        crate::real::min(crate::real::min(c.abs(), b.abs()), phase_c.abs())
    }
}
