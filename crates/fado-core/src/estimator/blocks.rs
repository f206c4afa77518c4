//! The configurations of the estimator's blocks, built from its [`EstimatorConfig`]: the
//! machine model and the sampling period, with the numbers of its tuning record. The blocks
//! know nothing of the tuning; this is the one place where its fields meet them.

use super::EstimatorConfig;
use crate::Real;
use crate::flux::{DisturbanceFeedbackConfig, FluxIntegratorConfig, FluxLimiterConfig};
use crate::integrand_offset::IntegrandOffsetConfig;
use crate::mode::ModeSelectorConfig;
use crate::rs_adaptation::ResistanceAdaptationConfig;
use crate::tracker::TrackerConfig;

impl<T: Real> EstimatorConfig<T> {
    /// The flux integrator sampled every `ts`, with the tuning's `average_current`.
    pub(super) fn flux_integrator_config(&self, ts: T) -> FluxIntegratorConfig<T> {
        FluxIntegratorConfig {
            average_current: self.tuning.average_current,
            ..FluxIntegratorConfig::for_machine(&self.machine, ts)
        }
    }

    /// The k_df feedback sampled every `ts`, with the tuning's `k_df` and `k_df_ramp_time`.
    pub(super) fn disturbance_feedback_config(&self, ts: T) -> DisturbanceFeedbackConfig<T> {
        DisturbanceFeedbackConfig {
            ts,
            k_df: self.tuning.k_df,
            ramp_time: self.tuning.k_df_ramp_time,
        }
    }

    /// The Fig. 6 limiter with the tuning's `k_af` and `limiter_radius_ratio`.
    pub(super) fn limiter_config(&self) -> FluxLimiterConfig<T> {
        FluxLimiterConfig::new(
            &self.machine,
            self.tuning.k_af,
            self.tuning.limiter_radius_ratio,
        )
    }

    /// The Fig. 3 selector with the tuning's `mode_threshold_ratio` and
    /// `mode_hysteresis_ratio`.
    pub(super) fn mode_selector_config(&self) -> ModeSelectorConfig<T> {
        ModeSelectorConfig::new(
            &self.machine,
            self.tuning.mode_threshold_ratio,
            self.tuning.mode_hysteresis_ratio,
        )
    }

    /// The integrand-offset law at the slow laws' period, with the tuning's
    /// `offset_adaptation_rate` and `mode_threshold_ratio`.
    pub(super) fn integrand_offset_config(&self) -> IntegrandOffsetConfig<T> {
        IntegrandOffsetConfig::new(
            &self.machine,
            self.tuning.offset_adaptation_rate,
            self.tuning.mode_threshold_ratio,
            self.slow_ts(),
        )
    }

    /// The R̂s and λ̂f laws at the slow laws' period, with the tuning's `rs_adaptation_*`,
    /// `flux_linkage_adaptation_rate`, `standstill_angle_rate` and `mode_threshold_ratio`.
    pub(super) fn rs_adaptation_config(&self) -> ResistanceAdaptationConfig<T> {
        let t = &self.tuning;
        ResistanceAdaptationConfig {
            rate: t.rs_adaptation_rate,
            excitation_floor: t.rs_adaptation_excitation_floor,
            min_ratio: t.rs_adaptation_min_ratio,
            max_ratio: t.rs_adaptation_max_ratio,
            flux_linkage_rate: t.flux_linkage_adaptation_rate,
            standstill_angle_rate: t.standstill_angle_rate,
            ..ResistanceAdaptationConfig::new(&self.machine, t.mode_threshold_ratio, self.slow_ts())
        }
    }

    /// A tracker (T2S-1 or T2S-2) of `bandwidth_hz` sampled every `ts`, with the tuning's
    /// `tracker_damping` and `bandwidth_definition`.
    pub fn tracker_config(&self, bandwidth_hz: T) -> TrackerConfig<T> {
        TrackerConfig {
            ts: self.ts,
            bandwidth_hz,
            damping: self.tuning.tracker_damping,
            definition: self.tuning.bandwidth_definition,
        }
    }
}
