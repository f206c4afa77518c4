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
    /// The flux integrator sampled every `ts`, with the tuning's `integrator.average_current`.
    pub(super) fn flux_integrator_config(&self, ts: T) -> FluxIntegratorConfig<T> {
        FluxIntegratorConfig {
            average_current: self.tuning.integrator.average_current,
            ..FluxIntegratorConfig::for_machine(&self.machine, ts)
        }
    }

    /// The k_df feedback sampled every `ts`, with the tuning's `k_df` and `disturbance_feedback.ramp_time`.
    pub(super) fn disturbance_feedback_config(&self, ts: T) -> DisturbanceFeedbackConfig<T> {
        DisturbanceFeedbackConfig {
            ts,
            k_df: self.tuning.disturbance_feedback.k_df,
            ramp_time: self.tuning.disturbance_feedback.ramp_time,
        }
    }

    /// The Fig. 6 limiter with the tuning's `k_af` and `limiter.radius_ratio`.
    pub(super) fn limiter_config(&self) -> FluxLimiterConfig<T> {
        FluxLimiterConfig::new(
            &self.machine,
            self.tuning.limiter.k_af,
            self.tuning.limiter.radius_ratio,
        )
    }

    /// The Fig. 3 selector with the tuning's `mode.threshold_ratio` and
    /// `mode.hysteresis_ratio`.
    pub(super) fn mode_selector_config(&self) -> ModeSelectorConfig<T> {
        ModeSelectorConfig::new(
            &self.machine,
            self.tuning.mode.threshold_ratio,
            self.tuning.mode.hysteresis_ratio,
        )
    }

    /// The integrand-offset law at the slow laws' period, with the tuning's
    /// `offset_adaptation.rate` and `mode.threshold_ratio`.
    pub(super) fn integrand_offset_config(&self) -> IntegrandOffsetConfig<T> {
        IntegrandOffsetConfig::new(
            &self.machine,
            self.tuning.offset_adaptation.rate,
            self.tuning.mode.threshold_ratio,
            self.slow_ts(),
        )
    }

    /// The R̂s and λ̂f laws at the slow laws' period, with the tuning's `rs_adaptation_*`,
    /// `flux_linkage_adaptation.rate`, `rs_adaptation.standstill_angle_rate`,
    /// `rs_adaptation.model_flux_uncertainty`, `rs_adaptation.model_flux_uncertainty_rated`
    /// (over the rated current squared: the block's growth per A²) and `mode.threshold_ratio`.
    pub(super) fn rs_adaptation_config(&self) -> ResistanceAdaptationConfig<T> {
        let t = &self.tuning;
        ResistanceAdaptationConfig {
            rate: t.rs_adaptation.rate,
            excitation_floor: t.rs_adaptation.excitation_floor,
            min_ratio: t.rs_adaptation.min_ratio,
            max_ratio: t.rs_adaptation.max_ratio,
            flux_linkage_rate: t.flux_linkage_adaptation.rate,
            standstill_angle_rate: t.rs_adaptation.standstill_angle_rate,
            model_flux_uncertainty: t.rs_adaptation.model_flux_uncertainty,
            model_flux_growth: t.rs_adaptation.model_flux_uncertainty_rated
                / (self.machine.rated_current * self.machine.rated_current),
            ..ResistanceAdaptationConfig::new(&self.machine, t.mode.threshold_ratio, self.slow_ts())
        }
    }

    /// A tracker (T2S-1 or T2S-2) of `bandwidth_hz` sampled every `ts`, with the tuning's
    /// `tracker.damping` and `bandwidth_definition`.
    pub fn tracker_config(&self, bandwidth_hz: T) -> TrackerConfig<T> {
        TrackerConfig {
            ts: self.ts,
            bandwidth_hz,
            damping: self.tuning.tracker.damping,
            definition: self.tuning.tracker.bandwidth_definition,
        }
    }
}
