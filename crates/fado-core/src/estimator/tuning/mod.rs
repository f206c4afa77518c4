//! [`EstimatorTuning`]: the estimator's gains, bandwidths, thresholds and switches, grouped
//! by the block they tune.

use crate::Real;

mod records;

pub use records::*;

/// The estimator's tuning: every setting that is not the machine or the sampling period, one
/// record per block it tunes. Defaults are the paper's (section V) or the method pages', as
/// each field says; none depends on the motor (speeds are ratios of the rated electrical
/// frequency). With the `serde` feature this is the `[estimator]` table of `fado-sim`'s TOML
/// (each record a table, `[estimator.lock]`, …) and the keyword set of Python's
/// `fado.EstimatorConfig` (each record a dict).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct EstimatorTuning<T> {
    /// Tuning of the flux integrator (eq. (3)) (`[estimator.integrator]`, see [`IntegratorTuning`]).
    pub integrator: IntegratorTuning,
    /// Tuning of the disturbance feedback k_df (Fig. 3) (`[estimator.disturbance_feedback]`, see [`DisturbanceFeedbackTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub disturbance_feedback: DisturbanceFeedbackTuning<T>,
    /// Tuning of the flux limiter (Fig. 6) (`[estimator.limiter]`, see [`LimiterTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub limiter: LimiterTuning<T>,
    /// Tuning of the selection between limiter and k_df (Fig. 3) (`[estimator.mode]`, see [`ModeTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub mode: ModeTuning<T>,
    /// Tuning of the speed trackers T2S-1 and T2S-2 (`[estimator.tracker]`, see [`TrackerTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub tracker: TrackerTuning<T>,
    /// Tuning of the disturbance observer (Fig. 5) (`[estimator.observer]`, see [`ObserverTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub observer: ObserverTuning<T>,
    /// Tuning of the online R̂s law (`[estimator.rs_adaptation]`, see [`RsAdaptationTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub rs_adaptation: RsAdaptationTuning<T>,
    /// Tuning of the λ̂f law (`[estimator.flux_linkage_adaptation]`, see [`FluxLinkageAdaptationTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub flux_linkage_adaptation: FluxLinkageAdaptationTuning<T>,
    /// Tuning of the integrand-offset law (`[estimator.offset_adaptation]`, see [`OffsetAdaptationTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub offset_adaptation: OffsetAdaptationTuning<T>,
    /// Tuning of the sample bounds (`[estimator.plausibility]`, see [`PlausibilityTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub plausibility: PlausibilityTuning<T>,
    /// Tuning of the loss-of-lock detector (`[estimator.lock]`, see [`LockTuning`]).
    #[cfg_attr(
        feature = "serde",
        serde(bound(deserialize = "T: Real + serde::Deserialize<'de>"))
    )]
    pub lock: LockTuning<T>,
}

/// Where each key of the flat `[estimator]` table of earlier configuration files lives in
/// the nested one: (flat key, path below `[estimator]`). `fado-sim` and Python refuse a flat
/// key naming its place from this table, and name the fields of fado-core's configuration
/// errors (which use the flat names) by it.
pub const MOVED_KEYS: &[(&str, &str)] = &[
    ("average_current", "integrator.average_current"),
    ("k_df", "disturbance_feedback.k_df"),
    ("k_df_ramp_time", "disturbance_feedback.ramp_time"),
    ("k_af", "limiter.k_af"),
    ("limiter_radius_ratio", "limiter.radius_ratio"),
    ("limiter_recentring", "limiter.recentring"),
    ("mode_threshold_ratio", "mode.threshold_ratio"),
    ("mode_hysteresis_ratio", "mode.hysteresis_ratio"),
    ("t2s1_bandwidth_hz", "tracker.t2s1_bandwidth_hz"),
    ("t2s2_bandwidth_hz", "tracker.t2s2_bandwidth_hz"),
    ("tracker_damping", "tracker.damping"),
    ("bandwidth_definition", "tracker.bandwidth_definition"),
    ("tracker_hold_ratio", "tracker.hold_ratio"),
    ("tracker_load_pole_ratio", "tracker.load_pole_ratio"),
    (
        "t2s1_running_bandwidth_hz",
        "tracker.t2s1_running_bandwidth_hz",
    ),
    ("observer_on_rotor_flux", "observer.on_rotor_flux"),
    ("observer_lag_compensation", "observer.lag_compensation"),
    ("observer_gain_period", "observer.gain_period"),
    ("rs_adaptation", "rs_adaptation.enabled"),
    ("rs_adaptation_rate", "rs_adaptation.rate"),
    (
        "rs_adaptation_excitation_floor",
        "rs_adaptation.excitation_floor",
    ),
    ("rs_adaptation_min_ratio", "rs_adaptation.min_ratio"),
    ("rs_adaptation_max_ratio", "rs_adaptation.max_ratio"),
    (
        "standstill_angle_rate",
        "rs_adaptation.standstill_angle_rate",
    ),
    (
        "rs_adaptation_model_flux_uncertainty",
        "rs_adaptation.model_flux_uncertainty",
    ),
    (
        "rs_adaptation_model_flux_uncertainty_rated",
        "rs_adaptation.model_flux_uncertainty_rated",
    ),
    (
        "flux_linkage_adaptation_rate",
        "flux_linkage_adaptation.rate",
    ),
    ("offset_adaptation_rate", "offset_adaptation.rate"),
    (
        "offset_adaptation_min_revolution_samples",
        "offset_adaptation.min_revolution_samples",
    ),
    ("plausible_current_ratio", "plausibility.current_ratio"),
    ("plausible_voltage_ratio", "plausibility.voltage_ratio"),
    (
        "plausible_current_step_ratio",
        "plausibility.current_step_ratio",
    ),
    ("lock_flux_low_ratio", "lock.flux_low_ratio"),
    ("lock_flux_low_fast_ratio", "lock.flux_low_fast_ratio"),
    ("lock_flux_high_ratio", "lock.flux_high_ratio"),
    ("lock_innovation_limit", "lock.innovation_limit"),
    ("lock_detection_time", "lock.detection_time"),
    ("lock_heal_time", "lock.heal_time"),
    ("lock_limiter_clamping", "lock.limiter_clamping"),
    ("lock_handover_count", "lock.handover_count"),
    ("lock_handover_time", "lock.handover_time"),
];

impl<T: Real> EstimatorTuning<T> {
    /// This tuning on the paper's path: every addition of fado's to the estimator of Fig. 5
    /// that can be switched off is off — the fixed R̂s (no [`RsAdaptationTuning::enabled`],
    /// hence no λ̂f or integrand-offset law), the observer on λ1 with ω̂ of T2S-1 alone
    /// ([`ObserverTuning::on_rotor_flux`], [`ObserverTuning::lag_compensation`], no
    /// [`ObserverTuning::frame_ripple_notch`]), no
    /// [`LimiterTuning::recentring`], an abrupt k_df ([`DisturbanceFeedbackTuning::ramp_time`]
    /// 0) and the gains (16) formed every sample ([`ObserverTuning::gain_period`] 0). The sample
    /// bounds, the finite test and the loss-of-lock detector stay. What the cost comparisons
    /// call "the paper's path" (docs/results/firmware-cost.md; `benches/baselines.rs`).
    pub fn paper_path(self) -> Self {
        let mut t = self;
        t.rs_adaptation.enabled = false;
        t.observer.lag_compensation = false;
        t.observer.on_rotor_flux = false;
        t.observer.frame_ripple_notch = false;
        t.limiter.recentring = false;
        t.disturbance_feedback.ramp_time = T::zero();
        t.observer.gain_period = T::zero();
        t
    }

    /// The same record in another precision (e.g. an f64 configuration for an f32 drive):
    /// every real rounded to `U`.
    pub fn cast<U: Real>(&self) -> EstimatorTuning<U> {
        EstimatorTuning {
            integrator: self.integrator,
            disturbance_feedback: self.disturbance_feedback.cast(),
            limiter: self.limiter.cast(),
            mode: self.mode.cast(),
            tracker: self.tracker.cast(),
            observer: self.observer.cast(),
            rs_adaptation: self.rs_adaptation.cast(),
            flux_linkage_adaptation: self.flux_linkage_adaptation.cast(),
            offset_adaptation: self.offset_adaptation.cast(),
            plausibility: self.plausibility.cast(),
            lock: self.lock.cast(),
        }
    }
}

impl<T: Real> Default for EstimatorTuning<T> {
    fn default() -> Self {
        Self {
            integrator: IntegratorTuning::default(),
            disturbance_feedback: DisturbanceFeedbackTuning::default(),
            limiter: LimiterTuning::default(),
            mode: ModeTuning::default(),
            tracker: TrackerTuning::default(),
            observer: ObserverTuning::default(),
            rs_adaptation: RsAdaptationTuning::default(),
            flux_linkage_adaptation: FluxLinkageAdaptationTuning::default(),
            offset_adaptation: OffsetAdaptationTuning::default(),
            plausibility: PlausibilityTuning::default(),
            lock: LockTuning::default(),
        }
    }
}
