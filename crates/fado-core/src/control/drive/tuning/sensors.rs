//! The drive's records for its sensors and its protection: the start-up calibrations, the
//! stuck-sensor detection, the trip levels and monitors, the bounds of a plausible sample and
//! the loaded-standstill angle probe.

use crate::Real;
use crate::control::{gain_calibration, standstill_probe};
use crate::machine::PAPER_RATED_CURRENT;
use crate::real::cast_record;

/// `amps` on the paper's motor as a ratio of its rated current.
fn per_rated<T: Real>(amps: f64) -> T {
    T::lit(amps / PAPER_RATED_CURRENT)
}

/// Tuning of the current sensors' offset calibration at start-up (`[controller.offset_calibration]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct OffsetCalibrationTuning<T> {
    /// Current-sensor offset calibration at start-up, in s: the gates stay off (zero current)
    /// after `new`/`reset` while the phase currents are averaged, before the aligned start;
    /// 0 disables it. The averages are subtracted from every later sample. Default 0.1 s
    /// \[A\] (1000 samples at 10 kHz: 10 mA rms noise averages to 0.3 mA): standard practice in
    /// real drives (the paper is silent). At standstill an offset is a constant integrand
    /// error −R̂s·Δi of eq. (3); the limiter of Fig. 6 removes only its radial part, its
    /// tangential part walks θ̂ (fado-sim fig10).
    pub time: T,
}

cast_record!(OffsetCalibrationTuning { time ;  });

impl<T: Real> Default for OffsetCalibrationTuning<T> {
    fn default() -> Self {
        Self { time: T::lit(0.1) }
    }
}

/// Tuning of the current sensors' gain calibration at start-up (`[controller.gain_calibration]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct GainCalibrationTuning<T> {
    /// Current-sensor gain-mismatch calibration at start-up (see
    /// [`gain_calibration`](crate::control::gain_calibration)): after the offset calibration,
    /// two DC current levels along the aligned d axis measure the ratio of the phase-a and
    /// phase-b channel gains, which then corrects phase a. This is each level's averaging
    /// window in s; 0 disables the calibration. The current loop settles for
    /// 5·max(L̂d/R̂s, 1/ωc) (five time constants of the stator or of the current loop,
    /// whichever is slower), and each level holds 4 time constants of the rotor's swing
    /// (`swing_time_constant`) before it is averaged, fewer where that exceeds 0.2 s and the
    /// swing's bias bound allows (`swing_hold_time_constants`, a low-flux motor); a machine
    /// needing a hold above 0.2 s is skipped, unless a brake holds its rotor
    /// (`startup.rotor_held`): then nothing swings and the levels hold for the settling. Default 0.05 s \[A\] (500 samples at 10 kHz: 10 mA rms of noise averages to
    /// 0.45 mA, 0.02 % of the lower level's phase-b current at the observability limit on the
    /// paper's motor). A 0.5 % mismatch walks θ̂ at loaded standstill on a low-flux motor
    /// (README: the outrunner preset lost `reversal` and `stops`, 1.2 rad). Start-up added on
    /// the presets: 0.33 s (outrunner-cheetah-24v) to 0.52 s (paper).
    pub time: T,
    /// Upper current level of the gain calibration as a multiple of the rated current (the
    /// lower level is half of it; at most `current.limit_ratio`, and on a rotor with L̂q > L̂d
    /// at most half of λ̂f/(L̂q − L̂d), see [`DriveConfig::gain_calibration_config`](crate::control::DriveConfig::gain_calibration_config)). Default 1 \[A\]: the continuous rating (the larger the
    /// levels, the smaller the inverter error and the noise against the resistive drop; the
    /// lower level must keep every phase clear of the dead-time band and the current ripple).
    pub current_ratio: T,
    /// Smallest share min over the phases of |cos(θ0 − φ_x)| of the calibration current with
    /// which the gain calibration runs (a and b for the observability, c for the inverter
    /// error's cancellation); at an aligned angle closer to a phase null it is skipped (status
    /// `Unobservable`). Default 0.2 \[A\] (the error grows as 1/share; at θ0 = −0.5, share
    /// 0.023, an earlier version measured k 1.2e-2 to 5.4e-2 off on four presets; 0.2 skips
    /// 38 % of the angles).
    pub min_observability: T,
    /// Largest gain mismatch |k − 1| accepted from the calibration; a larger result is refused
    /// (status `Implausible`, k unchanged). Default 0.05 \[A\] (two sensors of ±2.5 % gain
    /// tolerance; the simulator's default mismatch is 0.5 %, docs/method/estimator.md, "The paper's motor and drive").
    pub max_mismatch: T,
    /// The online gain-mismatch tracker (see [`gain_tracking`](crate::control::gain_tracking)):
    /// where the start-up calibration did not calibrate (status `TooSlow`, `RotorMoved`,
    /// `Implausible` or `Unobservable`; not where `time` is 0 or it calibrated) on a machine
    /// whose R̂s·I_rated/λ̂f is at least 86.6/s (a 0.5 % mismatch walks θ̂ by 0.25 rad/s at a
    /// loaded standstill), the correction of phase a adapts while the rotor turns under load,
    /// from the −2ω̂ component of the d-q current and voltage. Default true \[A\].
    pub online: bool,
    /// The online tracker's adaptation time constant τ, s: it converges in about τ and adapts
    /// from |ω̂| ≥ 12/τ (electrical). Default 0.1 s \[A\] (from 120 rad/s; EPS motor of
    /// `crates/fado-sim/tests/unseen_motor_tables.rs`: 4 % of its rated speed is 17 rad/s,
    /// and its start-up calibrates the mismatch that a hold there would keep).
    pub online_time: T,
}

cast_record!(GainCalibrationTuning { time, current_ratio, min_observability, max_mismatch, online_time ; online });

impl<T: Real> Default for GainCalibrationTuning<T> {
    fn default() -> Self {
        Self {
            time: T::lit(0.05),
            current_ratio: T::one(),
            min_observability: T::lit(gain_calibration::DEFAULT_MIN_OBSERVABILITY),
            max_mismatch: T::lit(gain_calibration::DEFAULT_MAX_MISMATCH),
            online: true,
            online_time: T::lit(0.1),
        }
    }
}

/// Tuning of the stuck current-sensor detection (`[controller.stuck_sensor]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct StuckSensorTuning<T> {
    /// Stuck current-sensor detection: a channel reading within ±this fraction of the rated
    /// current of zero while the reference asks for at least `stuck_sensor.reference_ratio`
    /// in its phase. Default 0.25/21.78 \[A\] (0.25 A: 10 LSB of a 12-bit ±50 A ADC, 25σ of
    /// 10 mA sensor noise, docs/method/estimator.md, "The paper's motor and drive").
    pub band_ratio: T,
    /// Stuck current-sensor detection: the reference's phase component, as a fraction of the
    /// rated current, from which a near-zero reading is implausible. Default 1/21.78 \[A\]
    /// (1 A on the paper's motor, a quarter of I_min: every running state has |i_dq*| ≥ I_min,
    /// so some phase always carries ≥ 0.866·I_min). A channel that sticks while its phase's
    /// reference is below it reads what a healthy channel reads at its zero crossing until
    /// the reference leaves the band: at 14 A and 20 Hz up to 0.57 ms (1.1 ms at 2 A, where
    /// the current loop acting on the stuck reading turns θ̂ by 0.069–0.076 rad; at 1 A at
    /// most 0.01 rad, crates/fado-sim/tests/faults.rs). Below twice it a reading is replaced
    /// before the flag only where the model contradicts it too
    /// ([`crate::control::monitor::StuckChannelDetector`]), so the threshold changes no
    /// sample of a healthy run.
    pub reference_ratio: T,
    /// Stuck current-sensor detection: how long (s) a channel must look stuck; 0 disables
    /// the detector. Default 0.5 ms (< 1 current-loop time constant) \[A\].
    pub time: T,
}

cast_record!(StuckSensorTuning { band_ratio, reference_ratio, time ;  });

impl<T: Real> Default for StuckSensorTuning<T> {
    fn default() -> Self {
        Self {
            band_ratio: per_rated(0.25),
            reference_ratio: per_rated(1.0),
            time: T::lit(0.5e-3),
        }
    }
}

/// Tuning of the drive's protection and monitors: over-current trip, current-error monitor, DC-link under-voltage warning and the trip on a broken input (`[controller.protection]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct ProtectionTuning<T> {
    /// Over-current trip level on any phase current, as a multiple of the rated current
    /// (latched until `reset`). Default 60/21.78 (1.5·I_max: 60 A on the paper's motor) \[A\].
    pub trip_current_ratio: T,
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
}

cast_record!(ProtectionTuning { trip_current_ratio, current_error_ratio, current_error_time, dc_link_min_ratio, input_fault_trip_time ;  });

impl<T: Real> Default for ProtectionTuning<T> {
    fn default() -> Self {
        Self {
            trip_current_ratio: per_rated(60.0),
            current_error_ratio: per_rated(5.0),
            current_error_time: T::lit(2e-3),
            dc_link_min_ratio: T::lit(2.0 / 3.0),
            input_fault_trip_time: T::lit(10e-3),
        }
    }
}

/// Tuning of the bounds beyond which a phase current or DC-link sample is no measurement (`[controller.plausibility]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct SamplePlausibilityTuning<T> {
    /// A phase current beyond ± this multiple of the trip level is no measurement of the
    /// machine (a glitch, an ADC or bus error) and is refused like a non-finite sample,
    /// instead of tripping; a real over-current passes the trip level first and trips.
    /// Default 2 \[A\] (see [`crate::plausibility`]).
    pub current_ratio: T,
    /// A DC-link reading above this multiple of the nominal DC-link voltage is refused like a
    /// non-finite sample. Default [`crate::plausibility::VOLTAGE_RATIO`] (1.5) \[A\].
    pub dc_link_ratio: T,
}

cast_record!(SamplePlausibilityTuning { current_ratio, dc_link_ratio ;  });

impl<T: Real> Default for SamplePlausibilityTuning<T> {
    fn default() -> Self {
        Self {
            current_ratio: T::lit(2.0),
            dc_link_ratio: T::lit(crate::plausibility::VOLTAGE_RATIO),
        }
    }
}

/// Tuning of the loaded-standstill angle probe (`[controller.standstill_probe]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct StandstillProbeTuning<T> {
    /// The loaded-standstill angle probe (see [`crate::control::standstill_probe`]): at a
    /// loaded standstill a slow square-wave d current, read through the speed loop's torque
    /// balance, turns θ̂ towards the rotor. Default true \[A\] (without it the one-hour loaded
    /// standstill drifts to the current limit on 4 of 5 sensor seeds, docs/method/additions.md).
    pub enabled: bool,
    /// Probe amplitude Δi_d as a fraction of the rated current. Default 0.1 \[A\] (2.2 A on
    /// the paper's motor: no torque at δ = 0, 0.5 % more copper loss at rated load; the
    /// reading Δi_d·tan δ is 0.2 A at δ = 0.1 rad against a speed-loop ripple the
    /// demodulation averages over a whole period).
    pub current_ratio: T,
    /// Probe period T_p in s. Default 0.1 s \[A\]: the reading removes the rotor's
    /// acceleration from the torque balance (`StandstillProbeConfig::inertia`), so it needs
    /// no settled speed loop, only a settled current loop and speed estimate: each
    /// correlation window (a quarter period, 25 ms) spans 5.5 time constants of the 35 Hz
    /// speed tracker the speed loop reads. The correction loop's bandwidth is a fixed
    /// fraction of 1/T_p, so the period sets how fast a creep is caught: with 0.5 s the
    /// fullrange hold of the servo and hub presets ended 0.25–0.35 rad off
    /// (docs/range.md).
    pub period: T,
    /// Correction gain g in s⁻¹: θ̂ turns at g·δ̂ plus the learned creep ĉ, which grows by
    /// 0.173·g·δ̂ per period. Default 0.405/T_p = 4.05 s⁻¹ \[D\]: with the reading half a
    /// period late the loop per period has a triple pole at 4^(1/3) − 1 = 0.587
    /// (`fado_core::control::standstill_probe`, "Correction"), and a constant creep leaves no
    /// angle error.
    pub gain: T,
    /// Time (s) the loaded standstill reference holds before the probe may start; it then
    /// starts the first sample the estimator is in limiter mode. Default 0.5 s \[A\]: not in
    /// a passage through zero or a short stop (fig12's and the presets' `stops` hold zero for
    /// 0.3 s and never arm it). Counted from the reference, not from limiter mode, so that a
    /// stop at the current limit whose rotor settles into limiter mode late leaves θ̂ no
    /// unwatched half second to creep in (a 150 r/min 32-pole torque motor reached 0.45 rad
    /// that way, docs/range.md).
    pub arm_time: T,
    /// The probe's gate: the speed reference |ω*| at most this multiple of the rated speed.
    /// Default 0.0005 \[A\] (0.75 r/min at 1500 r/min): a standstill reference. The probe
    /// moves the rotor by ±1–1.5 r/min on the paper's motor, a speed error at a low non-zero
    /// reference: with 0.0075 (11 r/min) the `lowspeed` staircase lost its 1.9 and 0.94 r/min
    /// levels on the 0.5 r/min speed criterion (7 → 4 levels held).
    pub speed_ratio: T,
    /// The probe's gate: the speed loop's torque demand |τ| at least this fraction of the
    /// rated current. Default 0.25 \[A\] (above the eq. (23) injection level 4/21.78, where the
    /// R̂s adaptation's no-load angle law takes over).
    pub load_ratio: T,
    /// The largest |ω̂| the probe may swing the rotor's speed estimate to over a period, as a
    /// fraction of the rated speed: each period's amplitude is the one that would have held
    /// the last period's swing there, up to `current_ratio` and grown by at most 1.70 per
    /// period (`fado_core::control::standstill_probe::amplitude`). Default 0.0065 \[A\]: half
    /// the lower edge of the estimator's limiter band (`mode.threshold_ratio` 0.015 less
    /// `mode.hysteresis_ratio` 0.002), the standstill the probe reads in, leaving room for the
    /// swing to double with the angle error within a period (measured on a 400 W servo with
    /// a 7.7 ms rotor: the whole edge left a 65.8 r/min speed error, half of it 16.9). 0: the
    /// amplitude is `current_ratio` throughout.
    pub swing_ratio: T,
}

cast_record!(StandstillProbeTuning { current_ratio, period, gain, arm_time, speed_ratio, load_ratio, swing_ratio ; enabled });

impl<T: Real> Default for StandstillProbeTuning<T> {
    fn default() -> Self {
        Self {
            enabled: true,
            current_ratio: T::lit(0.1),
            period: T::lit(0.1),
            gain: T::lit(standstill_probe::TRIPLE_POLE_GAIN / 0.1),
            arm_time: T::lit(0.5),
            speed_ratio: T::lit(0.0005),
            load_ratio: T::lit(0.25),
            swing_ratio: T::lit(standstill_probe::amplitude::DEFAULT_SWING_RATIO),
        }
    }
}
