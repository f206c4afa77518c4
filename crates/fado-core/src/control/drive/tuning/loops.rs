//! The drive's records for its loops and its voltage path: the current and speed loops, the
//! d-current references, the modulation, the dead-time and delay compensations and the
//! inverter data they use.

use crate::Real;
use crate::control::dead_time_compensation::{self, DeadTimeMethod};
use crate::control::modulation::VoltageLimit;
use crate::control::{current_controller, delay_compensation, speed_controller};
use crate::injection;
use crate::real::cast_record;

/// Tuning of the current loop: its PI, decoupling and the current limit (`[controller.current]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct CurrentLoopTuning<T> {
    /// Current-loop bandwidth in Hz. Default 250 Hz (paper, V).
    pub bandwidth_hz: T,
    /// Current PI back-calculation gain in units of Ki/Kp. Default 1 (realisable
    /// reference) \[A\].
    pub anti_windup_ratio: T,
    /// Decoupling and back-EMF feed-forward in the current PI. Default true (docs/method/estimator.md, "The paper's motor and drive" \[A\]).
    pub decoupling: bool,
    /// Current limit I_max (|i_dq*|) as a multiple of the rated current. Default 40/21.78
    /// (docs/method/estimator.md, "The paper's motor and drive" \[A\]: 40 A on the paper's motor).
    pub limit_ratio: T,
}

cast_record!(CurrentLoopTuning { bandwidth_hz, anti_windup_ratio, limit_ratio ; decoupling });

impl<T: Real> Default for CurrentLoopTuning<T> {
    fn default() -> Self {
        Self {
            bandwidth_hz: T::lit(current_controller::DEFAULT_BANDWIDTH_HZ),
            anti_windup_ratio: T::lit(current_controller::DEFAULT_ANTI_WINDUP_RATIO),
            decoupling: current_controller::DEFAULT_DECOUPLING,
            limit_ratio: T::lit(speed_controller::DEFAULT_CURRENT_LIMIT_RATIO),
        }
    }
}

/// Tuning of the speed loop's PI (`[controller.speed]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct SpeedLoopTuning<T> {
    /// Speed-loop bandwidth in Hz. Default 5 Hz (paper, V).
    pub bandwidth_hz: T,
    /// Speed PI zero as a fraction of its bandwidth, Ki = Kp·ωsc/ratio. Default 5 (docs/method/estimator.md, "The paper's motor and drive").
    pub zero_ratio: T,
    /// Speed PI back-calculation gain in units of Ki/Kp. Default 5 (tracking at ωsc) \[A\].
    pub anti_windup_ratio: T,
    /// The drive raises `bandwidth_hz` (and T2S-2's with it) until the first-order speed dip
    /// of a step of the rated torque at the rated speed, Ω_rated/(ωs·τm) with τm =
    /// Ĵ·Ω_rated/T_rated, is at most this multiple of the rated speed
    /// ([`crate::control::speed_bandwidth`]). Default 2 \[D\]: the rotor stays within the
    /// rated speed turning the other way, where the drive has the voltage for its rated
    /// torque; no preset needs more than its 5 Hz. A large value (1e9) keeps `bandwidth_hz`.
    pub load_step_dip_ratio: T,
    /// The drive raises `bandwidth_hz` (and T2S-2's with it) until a ramp of the rated torque
    /// over `load_ramp_time` leaves a steady speed error of at most `load_ramp_error_ratio` ×
    /// the rated speed: ωs ≥ √(zero_ratio/(ε·t_r·τm)) ([`crate::control::speed_bandwidth`]).
    /// Default 1 s \[A\]: the scaled scenarios ramp 65 % of the rated torque in 0.5 s (1.3
    /// rated torques per second). A large value (1e9) keeps `bandwidth_hz`.
    pub load_ramp_time: T,
    /// The steady speed error ε (a multiple of the rated speed) that a ramp of the rated
    /// torque over `load_ramp_time` may leave. Default 0.13 \[A\]: every preset keeps its 5 Hz
    /// from ε·t_r = 0.086 s on (pmsyrm-5k, τm = 59 ms), a 32-pole torque motor (τm = 39 ms),
    /// whose loaded passage through zero speed does not take a faster loop, from 0.129 s on
    /// ([`crate::control::speed_bandwidth`]); a light rotor (τm of a few ms) gets the bandwidth
    /// of its ramp. A large value (1e9) keeps `bandwidth_hz`.
    pub load_ramp_error_ratio: T,
}

cast_record!(SpeedLoopTuning { bandwidth_hz, zero_ratio, anti_windup_ratio, load_step_dip_ratio, load_ramp_time, load_ramp_error_ratio ;  });

impl<T: Real> Default for SpeedLoopTuning<T> {
    fn default() -> Self {
        Self {
            bandwidth_hz: T::lit(speed_controller::DEFAULT_BANDWIDTH_HZ),
            zero_ratio: T::lit(speed_controller::DEFAULT_ZERO_RATIO),
            anti_windup_ratio: T::lit(speed_controller::DEFAULT_ANTI_WINDUP_RATIO),
            load_step_dip_ratio: T::lit(2.0),
            load_ramp_time: T::lit(1.0),
            load_ramp_error_ratio: T::lit(0.13),
        }
    }
}

/// Tuning of the d-current injection of eq. (23) (`[controller.injection]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct InjectionTuning<T> {
    /// Minimum current I_min of the injection (23) as a fraction of the rated current; 0
    /// disables it. Default 4/21.78 (paper, V: 4 A).
    pub current_ratio: T,
    /// On a rotor with L̂q > L̂d the positive d current of the injection shrinks the active
    /// flux λ̂f + (L̂d − L̂q)·i_d the estimator's angle rests on: I_min is bounded so that it
    /// takes at most this share of λ̂f, I_min ≤ share·λ̂f/(L̂q − L̂d). Default 0.25 \[A\]:
    /// ipmsm-gem-50k (L̂q/L̂d = 3.2, I_min 44 A takes 55 %) loses 0.15–0.35 rad in
    /// `regen-stop`'s stop through zero where the injection rises as i_q reverses (0.35 at
    /// seed 3), 0.105–0.118 rad on seeds 1–4 with 0.25 (docs/range.md);
    /// the paper's motor and the surface-magnet presets take nothing, ipmsm-2k2 3 %. A large
    /// value (1e9) keeps `current_ratio`. No bound where the injection goes along −d
    /// ([`injection::direction`](crate::injection::direction)): there it raises the active flux.
    pub max_active_flux_share: T,
}

cast_record!(InjectionTuning { current_ratio, max_active_flux_share ;  });

impl<T: Real> Default for InjectionTuning<T> {
    fn default() -> Self {
        Self {
            current_ratio: T::lit(injection::DEFAULT_CURRENT_RATIO),
            max_active_flux_share: T::lit(0.25),
        }
    }
}

/// Tuning of the maximum-torque-per-ampere d current (`[controller.mtpa]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct MtpaTuning {
    /// Maximum-torque-per-ampere d current on salient machines (L̂d ≠ L̂q; see
    /// [`MachineModel::mtpa_id`](crate::MachineModel::mtpa_id)), added to the injection's. No effect on a surface-magnet
    /// rotor. Default true.
    pub enabled: bool,
}

impl Default for MtpaTuning {
    fn default() -> Self {
        Self { enabled: true }
    }
}

/// Tuning of the modulation: the realisable voltage set and how much of it the drive uses (`[controller.modulation]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct ModulationTuning<T> {
    /// Realisable voltage set. Default the hexagon (SVPWM \[16\]).
    pub voltage_limit: VoltageLimit,
    /// Usable fraction of the voltage limit (0, 1]. Default 1 \[A\].
    pub max_modulation: T,
}

cast_record!(ModulationTuning { max_modulation ; voltage_limit });

impl<T: Real> Default for ModulationTuning<T> {
    fn default() -> Self {
        Self {
            voltage_limit: VoltageLimit::Hexagon,
            max_modulation: T::one(),
        }
    }
}

/// Tuning of the dead-time compensation (`[controller.dead_time_compensation]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct DeadTimeCompensationTuning {
    /// Compensate the dead time at all. Default true (paper IV-B).
    pub enabled: bool,
    /// Shape of the compensation. Default [`DeadTimeMethod::EdgeCurrent`] \[A\]: the docs/method/estimator.md §7
    /// trapezoid evaluated at each switching edge's predicted current (PWM ripple included,
    /// L̂d, L̂q of the machine model); it keeps |λ̂r| from shrinking while a phase
    /// current sits in the band at standstill under load (docs/method/additions.md).
    pub method: DeadTimeMethod,
}

impl Default for DeadTimeCompensationTuning {
    fn default() -> Self {
        Self {
            enabled: true,
            method: dead_time_compensation::DEFAULT_METHOD,
        }
    }
}

/// Tuning of the compensation of the one-sample delay of the voltage (`[controller.delay_compensation]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct DelayCompensationTuning<T> {
    /// Angle advance of the voltage in samples. Default 1.5 (docs/method/estimator.md §7 \[A\], ref. \[13\]).
    pub factor: T,
}

cast_record!(DelayCompensationTuning { factor ;  });

impl<T: Real> Default for DelayCompensationTuning<T> {
    fn default() -> Self {
        Self {
            factor: T::lit(delay_compensation::DEFAULT_FACTOR),
        }
    }
}

/// The inverter data of the dead-time compensation: facts of the inverter, not settings, and
/// no serde keys (`fado-sim` derives them from its `[inverter]` and `[mismatch]`). Defaults
/// docs/method/estimator.md §7's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InverterData<T> {
    /// Dead time Td in s (inverter datum). Default 2.5 µs (paper, V).
    pub dead_time: T,
    /// Switching frequency in Hz (inverter datum). Default 5 kHz (paper, V).
    pub switching_frequency: T,
    /// Device threshold voltage of the dead-time compensation in V (inverter datum). Default
    /// 1 V (docs/method/estimator.md §7 \[A\]).
    pub threshold_voltage: T,
    /// Current band Ic of the trapezoidal compensation in A (inverter datum). Default 0.3 A
    /// (docs/method/estimator.md §7 \[A\]).
    pub current_band: T,
}

cast_record!(InverterData { dead_time, switching_frequency, threshold_voltage, current_band ;  });

impl<T: Real> Default for InverterData<T> {
    fn default() -> Self {
        Self {
            dead_time: T::lit(dead_time_compensation::DEFAULT_DEAD_TIME),
            switching_frequency: T::lit(dead_time_compensation::DEFAULT_SWITCHING_FREQUENCY),
            threshold_voltage: T::lit(dead_time_compensation::DEFAULT_THRESHOLD_VOLTAGE),
            current_band: T::lit(dead_time_compensation::DEFAULT_CURRENT_BAND),
        }
    }
}
