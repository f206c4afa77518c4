//! [`EstimatorParams::new`]: every constant of the step, checked and derived once from an
//! [`EstimatorConfig`], one block after the other.

use super::{
    EstimatorConfig, EstimatorParams, EstimatorState, FLUX_SETTLE_TIME_CONSTANTS,
    MAX_OBSERVER_GAIN_PERIOD,
};
use crate::active_flux::ActiveFlux;
use crate::error::{ConfigError, check};
use crate::flux::{
    DisturbanceFeedbackParams, FluxIntegratorParams, FluxIntegratorState, FluxLimiter,
};
use crate::integrand_offset::{IntegrandOffsetParams, IntegrandOffsetState};
use crate::lock::{LockDetectorParams, LockState, LockStatus};
use crate::magnetics::FluxWarmStart;
use crate::mode::{Mode, ModeSelectorParams};
use crate::observer::{
    DisturbanceObserverConfig, DisturbanceObserverParams, ObserverGains, ObserverState,
};
use crate::plausibility::SampleBounds;
use crate::ripple::PwmRipple;
use crate::rs_adaptation::ResistanceAdaptationParams;
use crate::speed_notch::SpeedNotch;
use crate::tracker::TrackerParams;
use crate::{Ab, Real};

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
        let (ratio, hold) = check_limits(&config, ts)?;
        let blocks = SampleBlocks::new(&config, ts)?;
        let (rs_adaptation, offset) = slow_laws(&config)?;
        check::non_negative(
            "offset_adaptation_min_revolution_samples",
            config.tuning.offset_adaptation.min_revolution_samples,
        )?;
        let lf = config.machine.flux_linkage;
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
        Ok(Self::assemble(
            &config,
            hold,
            blocks,
            rs_adaptation,
            offset,
            bounds,
            lock,
        ))
    }

    /// The parameters from the checked blocks: the constants the step reads directly.
    fn assemble(
        config: &EstimatorConfig<T>,
        hold: T,
        blocks: SampleBlocks<T>,
        rs_adaptation: ResistanceAdaptationParams<T>,
        offset: IntegrandOffsetParams<T>,
        bounds: SampleBounds<T>,
        lock: LockDetectorParams<T>,
    ) -> Self {
        let ts = config.ts;
        let lf = config.machine.flux_linkage;
        let threshold_hz = config.mode_threshold_hz();
        // The observer's lag compensation: Kp·e of T2S-1 low-passed at the threshold
        // frequency (see `EstimatorTuning::observer_lag_compensation`).
        let lag_gain = (T::two_pi() * threshold_hz * ts).step_one_minus_exp_neg();
        let hold_level = hold * lf;
        Self {
            ts,
            lq: config.machine.lq,
            saliency: config.machine.ld - config.machine.lq,
            active_flux: ActiveFlux::of(&config.machine),
            flux_linkage: lf,
            tracker_hold_ratio: hold,
            limiter_recentring_gain: if config.tuning.limiter.recentring {
                config.tuning.disturbance_feedback.k_df * ts
            } else {
                T::zero()
            },
            offset_recentring_gain: config.tuning.offset_adaptation.rate * ts,
            offset_max_speed: offset_max_speed(
                config.tuning.offset_adaptation.min_revolution_samples,
                ts,
            ),
            initial_angle: config.initial_angle,
            observer_on_rotor_flux: config.tuning.observer.on_rotor_flux,
            swing_reference_gain: ts / T::lit(crate::active_flux::SWING_REFERENCE_TIME),
            gain_hold: blocks.gain_hold,
            lag_compensation: config.tuning.observer.lag_compensation,
            lag_keep: if config.tuning.observer.lag_compensation {
                T::one() - lag_gain
            } else {
                T::zero()
            },
            // The innovation it low-passes is in tracker angle units: × rad per unit.
            lag_input: if config.tuning.observer.lag_compensation {
                lag_gain * blocks.t2s1.kp() * T::angle_unit()
            } else {
                T::zero()
            },
            rs_adaptation: config.tuning.rs_adaptation.enabled,
            speed_notch: SpeedNotch::new(ts, T::two_pi() * threshold_hz),
            frame_ripple_notch: config.tuning.observer.frame_ripple_notch,
            frame_rate_speed: config.machine.rated_speed()
                * T::lit(super::step::notch::FRAME_RATE_SPEED_SHARE),
            frame_rate_current: frame_rate_current(config.machine.rated_current),
            rs_initial: config.machine.rs,
            hold_level_sq: hold_level * hold_level,
            flux_settle_periods: (T::lit(FLUX_SETTLE_TIME_CONSTANTS)
                / (T::two_pi() * threshold_hz * config.slow_ts()))
            .ceil()
            .to_f64() as u32,
            integrator: blocks.integrator,
            observer: blocks.observer,
            disturbance_feedback: blocks.disturbance_feedback,
            limiter: blocks.limiter,
            selector: blocks.selector,
            t2s1: blocks.t2s1,
            t2s1_running: blocks.t2s1_running,
            t2s2: blocks.t2s2,
            rs_adaptation_params: rs_adaptation,
            offset,
            bounds,
            lock,
        }
    }

    /// The start-up state ([`EstimatorState::reset`]: θ̂ = `initial_angle`, zero current,
    /// R̂s and λ̂f as configured).
    pub fn initial_state(&self) -> EstimatorState<T> {
        let rs_scale = self.rs_adaptation_params.scale(self.rs_initial);
        let mut state = EstimatorState {
            integrator: FluxIntegratorState::new(self.rs_initial),
            observer: ObserverState::zero(),
            lq_secant: self.lq,
            swing_reference: self.flux_linkage,
            flux_warm: FluxWarmStart::empty(),
            t2s1: self.t2s1.state_at(T::zero(), T::zero()),
            t2s2: self.t2s2.state_at(T::zero(), T::zero()),
            kdf_gain: T::zero(),
            lag_compensation: T::zero(),
            speed_notch: SpeedNotch::state_at(T::zero()),
            frame_coupled: false,
            offset_share: T::one(),
            coupled_steady: 0,
            notch_on: false,
            frame_rate_gain: T::zero(),
            active_ratio: T::one(),
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
            release_tracking: false,
            ripple: PwmRipple::zero(),
            ripple_phase: 0,
            ripple_offset: Ab::zero(),
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

/// The blocks stepped every sample, built and checked from the configuration.
struct SampleBlocks<T: Real> {
    integrator: FluxIntegratorParams<T>,
    observer: DisturbanceObserverParams<T>,
    disturbance_feedback: DisturbanceFeedbackParams<T>,
    limiter: FluxLimiter<T>,
    selector: ModeSelectorParams<T>,
    t2s1: TrackerParams<T>,
    t2s1_running: TrackerParams<T>,
    t2s2: TrackerParams<T>,
    /// The observer's gains are held over this many samples after the one that computes
    /// them.
    gain_hold: u32,
}

impl<T: Real> SampleBlocks<T> {
    fn new(config: &EstimatorConfig<T>, ts: T) -> Result<Self, ConfigError> {
        let (integrator, _) = FluxIntegratorParams::new(config.flux_integrator_config(ts))?;
        let observer = DisturbanceObserverParams::new(DisturbanceObserverConfig { ts })?;
        let disturbance_feedback = DisturbanceFeedbackParams::new(
            config.disturbance_feedback_config(ts),
        )
        .map_err(|e| match e.field() {
            "ramp_time" => rename("k_df_ramp_time")(e),
            _ => e,
        })?;
        let limiter = FluxLimiter::new(config.limiter_config())?;
        let selector =
            ModeSelectorParams::new(config.mode_selector_config()).map_err(|e| {
                match e.field() {
                    "threshold_hz" => rename("mode_threshold_ratio")(e),
                    _ => rename("mode_hysteresis_ratio")(e),
                }
            })?;
        below_nyquist(
            "mode_hysteresis_ratio",
            config.mode_threshold_hz() + config.mode_hysteresis_hz(),
            ts,
        )?;
        check::positive("tracker_damping", config.tuning.tracker.damping)?;
        let load_pole = config.tuning.tracker.load_pole_ratio;
        let (c1, c2) = (
            config.tracker_config(config.tuning.tracker.t2s1_bandwidth_hz),
            config.tracker_config(config.tuning.tracker.t2s2_bandwidth_hz),
        );
        let t2s1 = TrackerParams::new(c1)
            .map_err(rename("t2s1_bandwidth_hz"))?
            .with_load_pole(&c1, load_pole)?;
        let t2s2 = TrackerParams::new(c2)
            .map_err(rename("t2s2_bandwidth_hz"))?
            .with_load_pole(&c2, load_pole)?;
        // T2S-1 in disturbance-feedback mode: its own bandwidth where one is set.
        let running_hz = config.tuning.tracker.t2s1_running_bandwidth_hz;
        let t2s1_running = if running_hz == T::zero() {
            t2s1
        } else {
            let c = config.tracker_config(running_hz);
            TrackerParams::new(c)
                .map_err(rename("t2s1_running_bandwidth_hz"))?
                .with_load_pole(&c, load_pole)?
        };
        Ok(Self {
            integrator,
            observer,
            disturbance_feedback,
            limiter,
            selector,
            t2s1,
            t2s1_running,
            t2s2,
            gain_hold: gain_hold(config, ts)?,
        })
    }
}

/// The limiter radius ratio and the tracker hold ratio, checked with the start-up angle, k_af
/// and the mode threshold.
fn check_limits<T: Real>(config: &EstimatorConfig<T>, ts: T) -> Result<(T, T), ConfigError> {
    let ratio = check::positive("limiter_radius_ratio", config.tuning.limiter.radius_ratio)?;
    let hold = check::non_negative("tracker_hold_ratio", config.tuning.tracker.hold_ratio)?;
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
    let k_af = check::non_negative("k_af", config.tuning.limiter.k_af)?;
    check::below("k_af", k_af * ts, T::lit(1.0 + 1e-6), "k_af·ts at most 1")?;
    below_nyquist("mode_threshold_ratio", config.mode_threshold_hz(), ts)?;
    Ok((ratio, hold))
}

/// The mode switch compares |ω̂| with the band: it must lie below the Nyquist frequency.
fn below_nyquist<T: Real>(field: &'static str, hz: T, ts: T) -> Result<T, ConfigError> {
    let hz = check::finite(field, hz)?;
    check::below(
        field,
        hz * ts,
        T::lit(0.5),
        "below the Nyquist frequency 1/(2·ts)",
    )
}

/// A block's error renamed to the estimator's `field`.
fn rename(field: &'static str) -> impl Fn(ConfigError) -> ConfigError {
    move |e: ConfigError| match e {
        ConfigError::OutOfRange { expected, .. } => ConfigError::OutOfRange { field, expected },
        ConfigError::NotFinite { .. } => ConfigError::NotFinite { field },
        ConfigError::NotPositive { .. } => ConfigError::NotPositive { field },
        ConfigError::Negative { .. } => ConfigError::Negative { field },
    }
}

/// The observer's gain hold in samples: `observer.gain_period`/Ts rounded, less one.
fn gain_hold<T: Real>(config: &EstimatorConfig<T>, ts: T) -> Result<u32, ConfigError> {
    // A hold beyond a second is refused as a mistake (the observer would be a fixed
    // filter through any speed change; see the field's docs).
    let gain_period =
        check::non_negative("observer_gain_period", config.tuning.observer.gain_period)?;
    check::below(
        "observer_gain_period",
        gain_period,
        T::lit(MAX_OBSERVER_GAIN_PERIOD * (1.0 + 1e-9)),
        "at most 1 s",
    )?;
    // Whole samples, at least one (`as` saturates: a count beyond u32 would need a
    // sampling period below 1e-12 s).
    Ok(crate::real::max((gain_period / ts).round() - T::one(), T::zero()).to_f64() as u32)
}

/// The slow laws: the R̂s adaptation (with its λ̂f law) and the integrand-offset law, their
/// errors named after the estimator's fields.
#[allow(clippy::type_complexity)]
fn slow_laws<T: Real>(
    config: &EstimatorConfig<T>,
) -> Result<(ResistanceAdaptationParams<T>, IntegrandOffsetParams<T>), ConfigError> {
    let rs_adaptation =
        ResistanceAdaptationParams::new(config.rs_adaptation_config()).map_err(|e| {
            match e.field() {
                "rs_initial" => rename("rs")(e),
                "rate" => rename("rs_adaptation_rate")(e),
                "excitation_floor" => rename("rs_adaptation_excitation_floor")(e),
                "min_ratio" => rename("rs_adaptation_min_ratio")(e),
                "max_ratio" => rename("rs_adaptation_max_ratio")(e),
                "model_flux_uncertainty" => rename("rs_adaptation_model_flux_uncertainty")(e),
                "model_flux_growth" => rename("rs_adaptation_model_flux_uncertainty_rated")(e),
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
    let offset =
        IntegrandOffsetParams::new(config.integrand_offset_config()).map_err(|e| {
            match e.field() {
                "rate" => rename("offset_adaptation_rate")(e),
                _ => rename("mode_threshold_ratio")(e),
            }
        })?;
    Ok((rs_adaptation, offset))
}

/// The speed (rad/s) below which the integrand-offset law learns: an electrical revolution of
/// at least `samples` sampling periods, 2π/(samples·Ts); unbounded for 0 samples (see
/// [`crate::integrand_offset::MIN_REVOLUTION_SAMPLES`]).
fn offset_max_speed<T: Real>(samples: T, ts: T) -> T {
    if samples > T::zero() {
        T::two_pi() / (samples * ts)
    } else {
        T::lit(f64::INFINITY)
    }
}

/// The frame-rate correction's current share (`step::notch`) for a machine of `rated`
/// current: the current where it starts, A, and the share per ampere above it.
fn frame_rate_current<T: Real>(rated: T) -> (T, T) {
    use super::step::notch::{FRAME_RATE_CURRENT_FULL, FRAME_RATE_CURRENT_LOW};
    let low = T::lit(FRAME_RATE_CURRENT_LOW) * rated;
    let span = T::lit(FRAME_RATE_CURRENT_FULL - FRAME_RATE_CURRENT_LOW) * rated;
    (low, T::one() / span)
}
