//! [`EstimatorConfig`]: the sampling period, the machine model, the start-up angle and the
//! tuning, and the block configurations derived from them.

use super::{EstimatorParams, EstimatorTuning, LOCK_PERIOD, SLOW_PERIOD};
use crate::error::ConfigError;
use crate::lock::LockDetectorConfig;
use crate::plausibility::SampleBounds;
use crate::{MachineModel, Real};

/// Everything the estimator needs: the sampling period, the machine model (R̂s, L̂d, L̂q, λ̂f
/// and the ratings the tuning's ratios refer to), the start-up angle and the tuning. Build it
/// with [`EstimatorConfig::for_machine`]; nothing here assumes the paper's motor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorConfig<T: 'static> {
    /// Sampling period Ts in s (paper, V: 100 µs, 10 kHz).
    pub ts: T,
    /// The drive's model of the motor: R̂s of eq. (3), L̂q of eq. (5), λ̂f (limiter radius,
    /// tracker hold level, start-up flux; the angle does not depend on it, eq. (6)), L̂d (the
    /// active-flux magnitude λ̂f + (L̂d − L̂q)·i_d on salient rotors) and the rated speed that
    /// scales the mode threshold.
    pub machine: MachineModel<T>,
    /// Rotor angle assumed at reset (rad), e.g. from an alignment (docs/method/estimator.md §1 \[A\]).
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

    /// The mode threshold in Hz electrical: `mode.threshold_ratio` × the rated frequency.
    pub fn mode_threshold_hz(&self) -> T {
        self.tuning.mode.threshold_ratio * self.machine.rated_frequency_hz()
    }

    /// The mode hysteresis in Hz: `mode.hysteresis_ratio` × the rated frequency.
    pub fn mode_hysteresis_hz(&self) -> T {
        self.tuning.mode.hysteresis_ratio * self.machine.rated_frequency_hz()
    }

    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        EstimatorParams::new(*self).map(|_| ())
    }

    /// The period of the slow laws, [`SLOW_PERIOD`]·Ts.
    pub(super) fn slow_ts(&self) -> T {
        self.ts * T::lit(SLOW_PERIOD as f64)
    }

    pub(super) fn lock_detector(&self) -> LockDetectorConfig<T> {
        LockDetectorConfig {
            ts: self.ts * T::lit(LOCK_PERIOD as f64),
            flux_low_ratio: self.tuning.lock.flux_low_ratio,
            flux_low_fast_ratio: self.tuning.lock.flux_low_fast_ratio,
            // The speed below which the estimator is in limiter mode whatever its history
            // (the mode selector's exit speed).
            fast_speed: crate::real::max(
                T::two_pi() * (self.mode_threshold_hz() - self.mode_hysteresis_hz()),
                T::zero(),
            ),
            flux_high_ratio: self.tuning.lock.flux_high_ratio,
            innovation_limit: self.tuning.lock.innovation_limit,
            detection_time: self.tuning.lock.detection_time,
            heal_time: self.tuning.lock.heal_time,
            limiter_clamping: self.tuning.lock.limiter_clamping,
            handover_count: self.tuning.lock.handover_count,
            handover_time: self.tuning.lock.handover_time,
        }
    }

    /// The sample bounds of [`crate::plausibility`] from the machine's ratings and the
    /// `plausible_*` ratios.
    pub fn sample_bounds(&self) -> Result<SampleBounds<T>, ConfigError> {
        let t = &self.tuning;
        SampleBounds::from_ratios(
            t.plausibility.current_ratio,
            t.plausibility.voltage_ratio,
            t.plausibility.current_step_ratio,
            self.machine.rated_current,
            self.machine.dc_voltage,
            self.machine.lq.step_min(self.machine.ld),
            self.ts,
        )
    }
}
