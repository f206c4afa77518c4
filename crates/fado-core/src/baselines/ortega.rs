//! Baseline 2: the nonlinear flux observer of J. Lee, J. Hong, K. Nam, R. Ortega, L. Praly and
//! A. Astolfi, "Sensorless control of surface-mount permanent-magnet synchronous motors based
//! on a nonlinear observer", IEEE Trans. Power Electron. 25(2), 2010 (the "Ortega–Praly"
//! gradient observer of the ODrive and VESC firmwares), followed by the type-2 trackers.
//!
//! # Algorithm
//! For a surface-mount machine (L = Ld = Lq) the stator flux x = L·i + λf·e^{jθ} obeys
//! ẋ = y = v − R·i, and η(x) = x − L·i = λf·e^{jθ} lies on the circle |η| = λf. The observer
//! integrates y and pushes η̂ radially towards that circle (their eq. (8)):
//!
//! ```text
//! dx̂/dt = v* − R̂s·i + (γ/2)·η̂·(λ̂f² − |η̂|²),   η̂ = x̂ − L̂·i,   θm = ∠η̂  →  T2S-1 / T2S-2
//! ```
//!
//! # Gain γ (the reasoning behind the defaults)
//! With exact parameters the error e = x̂ − x obeys ė = (γ/2)(η + e)(λf² − |η + e|²);
//! linearised, ė = −γ·η·Re(η*·e): only the *radial* error is corrected, at the rate
//! ω_obs = γ·λf² (ODrive's normalised `observer_gain`, whose default is 1000 rad/s). In the
//! rotor frame (ε = e·e^{−jθ}) the error obeys
//!
//! ```text
//! ε̇d = −ω_obs·εd + ω·εq,   ε̇q = −ω·εd      ⇒   s² + ω_obs·s + ω² = 0
//! ```
//!
//! so the tangential (angle) error is corrected only through rotation: critically damped at
//! ω_obs = 2|ω|, and for |ω| ≪ ω_obs the slow pole is −ω²/ω_obs.
//!
//! **Lock condition.** A rotor-frame integrand error u (R̂s error × i, dead time) moves the
//! integrated flux circle to the radius a = λf + uq/ω; a wrong λ̂f moves the target. In
//! steady rotation with η̂ = ρ·e^{j(θ + φ)} the observer gives ρ = a·cos φ and
//!
//! ```text
//! tan φ = −(ω_obs/2ω)·(1 − (a/λ̂f)²·cos²φ)        (plus −ud/ω, as for an open integrator)
//! ```
//!
//! whose small root φ ≈ −(ω_obs/2ω)·δ, δ = 1 − (a/λ̂f)², exists only while δ ≤ ω²/ω_obs²
//! (first order); beyond it only a root near ∓90° is left, which is not held: the estimate
//! slips poles periodically. The harmful
//! side is a < λ̂f: λ̂f too large, or uq opposing the EMF (R̂s too high while motoring). So a
//! fixed gain amplifies these errors by ω_obs/ω and its margin shrinks like ω²/ω_obs²: with
//! ω_obs = 251 rad/s (critical at 300 r/min) the limit under 14.2 A at 90 r/min is a +0.8 %
//! R̂s error (tested: half of it settles as predicted, three times it slips poles), and with
//! ODrive's 1000 rad/s the limit at 300 r/min is +1.9 %.
//!
//! **Default: a speed-scheduled gain** ω_obs = clamp(k·|ω̂|, ω_min, ω_max) with k = 2 (ω̂ of
//! T2S-1): critically damped at every speed, amplification 1 and margin δ ≤ ¼ (a ≥ 0.87·λ̂f:
//! a 13 % flux or EMF error). VESC schedules its γ the same way, linearly in the duty cycle above the floor
//! `foc_observer_gain_slow`. ω_min = 2·2π·1.5 Hz keeps it critical down to fado's 1.5 Hz mode
//! threshold; ω_max = 2·2π·100 Hz is critical at the rated 1500 r/min (ω_max·Ts = 0.126).
//! k = 0 gives the paper's and ODrive's fixed gain ω_obs = `observer_bandwidth`. In the
//! paper's normalisation γ = ω_obs/λ̂f² (3.2e4 Wb⁻²s⁻¹ at 300 r/min).
//!
//! # Discretisation
//! As in ODrive: predict x̂⁻ = x̂ + Ts·(v* − R̂s·i) (the forward rectangle and averaged current
//! of [`crate::flux::FluxIntegrator`]), form η̂⁻ = x̂⁻ − L̂·i\[n\] with the fresh current, then
//! correct x̂ = x̂⁻ + k·η̂⁻ with k = Ts·(γ/2)·(λ̂f² − |η̂⁻|²). The linearised radial map is
//! 1 − ω_obs·Ts, so `new` requires ω_obs·Ts < 1 (monotone convergence). For |η̂| far outside
//! the circle k would overshoot through the origin and flip the angle; k is floored at −½,
//! which only acts for |η̂|² > λ̂f²·(1 + 1/(ω_obs·Ts)) (|η̂| > 3·λ̂f at ω_max), i.e. never in
//! operation.
//!
//! # Flux-linkage adaptation (option, off by default)
//! With `flux_adaptation_ratio` κ > 0 the target radius adapts, as in VESC's
//! `ORTEGA_LAMBDA_COMP` observer (after P. Bernard and L. Praly, IFAC 2017):
//! dλ̂/dt = κ·(γ/2)·λ̂·(|η̂|² − λ̂²), clamped to [0.3, 2.5]·λ̂f (VESC's bounds; VESC uses
//! κ = 0.2). While the rotor turns the only equilibrium without a standing radial push is
//! λ̂ = a (λf, or the radius a uq error leaves), which removes the angle error of the lock
//! condition; at standstill λ̂ is unobservable.
//! Off by default because fado and the comparison assume known parameters.
//!
//! # Where it fails
//! - **Low speed.** The tangential error decays at ω²/ω_obs (with the schedule as t·e^{−|ω|t},
//!   down to ω_min); at standstill the observer is an open integrator along the angle direction and
//!   drifts with any integrand error, and it has no mechanism like fado's limiter and
//!   positive-i_d steering (Fig. 6, eq. (23)).
//! - **Offsets.** A DC integrand error ε rotates at −ω in the rotor frame and leaves an angle
//!   ripple |ε|·√(4ω² + ω_obs²)/(|ω|·ω_obs·λf) at the fundamental (√2·|ε|/(|ω|·λf) with the
//!   schedule): bounded at speed, unbounded as ω → 0.
//! - **Parameters.** uq errors and λ̂f enter the angle (lock condition above), where fado and
//!   the EMF observer only see a magnitude error; L̂ errors act under load as in fado; the
//!   model assumes Ld = Lq.

use super::{AngleTrackers, Baseline, BaselineConfig, GuardedStep, Integrand};
use crate::error::{ConfigError, check};
use crate::estimator::{Diagnostics, Estimate, RotorAngleEstimator};
use crate::{Ab, Real};

/// Lower and upper bound of the adapted flux linkage relative to λ̂f (VESC's bounds).
const ADAPTATION_BOUNDS: (f64, f64) = (0.3, 2.5);

/// Settings of [`OrtegaEstimator`] of its own (`[baselines.ortega]` in `fado-sim`'s TOML):
/// plain numbers whose defaults do not depend on the machine.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct OrtegaSettings<T> {
    /// Radial (flux-magnitude) correction rate ω_obs = γ·λ̂f² in rad/s: the fixed value when
    /// `observer_speed_ratio` is 0, else the upper bound ω_max of the schedule; times `ts`
    /// it must be below 1. Default 2·2π·100 ≈ 1257 rad/s \[A\]: critically damped at the
    /// rated 1500 r/min (module docs).
    pub observer_bandwidth: T,
    /// Speed ratio k of the schedule ω_obs = clamp(k·|ω̂|, ω_min, ω_max); 0 fixes
    /// ω_obs = `observer_bandwidth`. Default 2 \[A\]: critically damped at every speed
    /// (module docs).
    pub observer_speed_ratio: T,
    /// Lower bound ω_min of the schedule in rad/s, at most `observer_bandwidth`. Default
    /// 2·2π·1.5 ≈ 18.8 rad/s \[A\]: critical down to fado's 1.5 Hz mode threshold (paper, V).
    pub observer_bandwidth_min: T,
    /// Flux-linkage adaptation ratio κ (module docs); 0 disables it. Default 0 \[A\].
    pub flux_adaptation_ratio: T,
}

impl<T: Real> Default for OrtegaSettings<T> {
    fn default() -> Self {
        Self {
            observer_bandwidth: T::lit(2.0 * core::f64::consts::TAU * 100.0),
            observer_speed_ratio: T::lit(2.0),
            observer_bandwidth_min: T::lit(2.0 * core::f64::consts::TAU * 1.5),
            flux_adaptation_ratio: T::zero(),
        }
    }
}

/// Configuration of [`OrtegaEstimator`]: the machine model, the shared [`CommonTuning`](super::CommonTuning) and
/// [`OrtegaSettings`].
pub type OrtegaConfig<T> = BaselineConfig<T, OrtegaSettings<T>>;

impl<T: Real> Baseline<T> for OrtegaEstimator<T> {
    type Settings = OrtegaSettings<T>;
    const NAME: &'static str = "ortega";
    fn from_config(config: OrtegaConfig<T>) -> Result<Self, ConfigError> {
        Self::new(config)
    }
}

impl<T: Real> OrtegaConfig<T> {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        OrtegaEstimator::new(*self).map(|_| ())
    }

    /// γ of the paper's eq. (8), ω_obs/λ̂f², in Wb⁻²·s⁻¹, for the speed ω̂ (rad/s).
    pub fn gamma(&self, omega: T) -> T {
        self.scheduled_bandwidth(omega) / (self.machine.flux_linkage * self.machine.flux_linkage)
    }

    /// ω_obs at the speed ω̂ (rad/s): clamp(k·|ω̂|, ω_min, ω_max), or the fixed value.
    #[inline]
    pub fn scheduled_bandwidth(&self, omega: T) -> T {
        let s = &self.settings;
        if s.observer_speed_ratio > T::zero() {
            (s.observer_speed_ratio * omega.abs())
                .max(s.observer_bandwidth_min)
                .min(s.observer_bandwidth)
        } else {
            s.observer_bandwidth
        }
    }
}

/// The Ortega–Praly nonlinear flux observer with type-2 trackers (see the module docs).
///
/// ```
/// use fado_core::{Ab, MachineModel};
/// use fado_core::baselines::{OrtegaConfig, OrtegaEstimator};
/// let mut est = OrtegaEstimator::<f32>::new(OrtegaConfig::for_machine(&MachineModel::paper())).unwrap();
/// let out = est.step(Ab::new(1.2, -0.3), Ab::new(4.0, 0.1));
/// assert!(!out.diagnostics.input_fault);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrtegaEstimator<T: Real> {
    config: OrtegaConfig<T>,
    integrand: Integrand<T>,
    trackers: AngleTrackers<T>,
    /// x̂: the estimated stator flux.
    x: Ab<T>,
    /// λ̂: the radius η̂ is pulled to (λ̂f unless adapted).
    lambda: T,
    /// Ts/(2·λ̂f²): Ts·γ/2 per rad/s of ω_obs.
    ts_half_over_lf2: T,
    last: Estimate<T>,
    rejected_samples: u32,
}

impl<T: Real> OrtegaEstimator<T> {
    /// Builds the estimator; every field of `config` is checked and a bad one is named.
    pub fn new(config: OrtegaConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.common.ts)?;
        check::non_negative("lq", config.machine.lq)?;
        let integrand = integrand_of!(config.machine, config.common, ts)?;
        let lf = check::positive("flux_linkage", config.machine.flux_linkage)?;
        let w_obs = check::positive("observer_bandwidth", config.settings.observer_bandwidth)?;
        check::below(
            "observer_bandwidth",
            w_obs * ts,
            T::one(),
            "observer_bandwidth·ts below 1",
        )?;
        check::non_negative("observer_speed_ratio", config.settings.observer_speed_ratio)?;
        let w_min = check::positive(
            "observer_bandwidth_min",
            config.settings.observer_bandwidth_min,
        )?;
        check::below(
            "observer_bandwidth_min",
            w_min,
            w_obs * (T::one() + T::default_epsilon()),
            "at most observer_bandwidth",
        )?;
        check::non_negative(
            "flux_adaptation_ratio",
            config.settings.flux_adaptation_ratio,
        )?;
        check::finite("initial_angle", config.common.initial_angle)?;
        let trackers = config.common.trackers(lf)?;
        let mut est = Self {
            config,
            integrand,
            trackers,
            x: Ab::zero(),
            lambda: lf,
            ts_half_over_lf2: ts / (T::lit(2.0) * lf * lf),
            last: Estimate::default(),
            rejected_samples: 0,
        };
        est.reset();
        Ok(est)
    }

    /// Back to the start-up state at `config.common.initial_angle` with zero current.
    pub fn reset(&mut self) {
        self.align(self.config.common.initial_angle, Ab::zero());
    }

    /// Start-up at a known rotor angle θ0 with the present current: x̂ = λ̂f·e^{jθ0} + L̂·i,
    /// λ̂ = λ̂f, θ̂ = θ0, ω̂ = 0.
    pub fn align(&mut self, theta0: T, i_ab: Ab<T>) {
        let theta0 = if theta0.is_finite() {
            theta0
        } else {
            T::zero()
        };
        let i_ab = super::usable_align_current(
            i_ab,
            self.config.machine.lq,
            self.config.machine.flux_linkage,
        );
        self.lambda = self.config.machine.flux_linkage;
        let eta = Ab::from_polar(self.lambda, theta0);
        self.x = eta + i_ab * self.config.machine.lq;
        self.integrand.reset();
        self.integrand.note_current(i_ab);
        self.trackers.reset_to(theta0);
        self.rejected_samples = 0;
        self.last = Estimate {
            theta: self.trackers.angle(),
            diagnostics: Diagnostics {
                lambda1: self.x,
                lambda2: self.x,
                lambda_r: eta,
                theta_direct: self.trackers.angle(),
                rs_hat: self.config.machine.rs,
                flux_linkage_hat: self.config.machine.flux_linkage,
                ..Diagnostics::default()
            },
            ..Estimate::default()
        };
    }

    /// One sample: `v_ab` applied over the last interval, `i_ab` sampled now. A non-finite
    /// input is rejected: the state is untouched and the previous estimate is returned with
    /// `input_fault` set.
    #[inline]
    pub fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T> {
        self.guarded_step(v_ab, i_ab)
    }

    /// λ̂: the radius η̂ is pulled to (λ̂f, or its adapted value).
    pub fn flux_linkage_estimate(&self) -> T {
        self.lambda
    }

    /// The last good estimate.
    pub fn last(&self) -> &Estimate<T> {
        &self.last
    }

    /// Number of samples rejected since the last reset.
    pub fn rejected_samples(&self) -> u32 {
        self.rejected_samples
    }

    /// The configuration in use.
    pub fn config(&self) -> &OrtegaConfig<T> {
        &self.config
    }
}

impl<T: Real> GuardedStep<T> for OrtegaEstimator<T> {
    #[inline]
    fn step_unchecked(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Option<Estimate<T>> {
        let li = i_ab * self.config.machine.lq;
        // Predict with the voltage model, then correct radially with the fresh current.
        let x_pred = self.x + self.integrand.next(v_ab, i_ab) * self.config.common.ts;
        let eta_pred = x_pred - li;
        let radius_error = self.lambda * self.lambda - eta_pred.norm_squared();
        let k_ts = self.ts_half_over_lf2 * self.config.scheduled_bandwidth(self.trackers.speed());
        let k = (k_ts * radius_error).max(T::lit(-0.5));
        let x = x_pred + eta_pred * k;
        let eta = x - li;
        let kappa = self.config.settings.flux_adaptation_ratio;
        let lambda = if kappa > T::zero() {
            let lf = self.config.machine.flux_linkage;
            let (lo, hi) = ADAPTATION_BOUNDS;
            (self.lambda - kappa * k_ts * self.lambda * radius_error)
                .max(T::lit(lo) * lf)
                .min(T::lit(hi) * lf)
        } else {
            self.lambda
        };
        if !(x.is_finite() && eta.is_finite() && lambda.is_finite()) {
            return None;
        }
        let mut trackers = self.trackers;
        let t = trackers.step(eta)?;
        self.trackers = trackers;
        self.integrand.accept(i_ab);
        self.x = x;
        self.lambda = lambda;
        Some(Estimate {
            theta: t.theta,
            omega: t.omega,
            omega_control: t.omega_control,
            diagnostics: Diagnostics {
                lambda1: x,
                lambda2: x,
                lambda_r: eta,
                theta_direct: t.theta_direct,
                tracker_hold: t.hold,
                rs_hat: self.config.machine.rs,
                flux_linkage_hat: self.config.machine.flux_linkage,
                ..Diagnostics::default()
            },
        })
    }

    guarded_state!();
}

rotor_angle_estimator!(OrtegaEstimator);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MachineModel;
    use crate::baselines::CommonTuning;

    #[test]
    fn config_errors_name_the_machine_field() {
        type C = OrtegaConfig<f64>;
        let cases: [(C, &str); 5] = [
            (
                C::for_machine(&MachineModel {
                    rated_current: f64::NAN,
                    ..MachineModel::paper()
                }),
                "rated_current",
            ),
            (
                C::for_machine(&MachineModel {
                    dc_voltage: 0.0,
                    ..MachineModel::paper()
                }),
                "dc_voltage",
            ),
            (
                C::for_machine(&MachineModel {
                    rs: f64::NAN,
                    ..MachineModel::paper()
                }),
                "rs",
            ),
            (
                C::for_machine(&MachineModel {
                    lq: -1e-3,
                    ..MachineModel::paper()
                }),
                "lq",
            ),
            (
                C::for_machine(&MachineModel {
                    flux_linkage: 0.0,
                    ..MachineModel::paper()
                }),
                "flux_linkage",
            ),
        ];
        for (config, field) in cases {
            assert_eq!(config.validate().unwrap_err().field(), field);
        }
    }

    #[test]
    fn config_errors_name_the_plausibility_field() {
        type C = OrtegaConfig<f64>;
        let cases: [(C, &str); 3] = [
            (
                C {
                    common: CommonTuning {
                        plausible_current_ratio: -4.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "plausible_current_ratio",
            ),
            (
                C {
                    common: CommonTuning {
                        plausible_voltage_ratio: f64::INFINITY,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "plausible_voltage_ratio",
            ),
            (
                C {
                    common: CommonTuning {
                        plausible_current_step_ratio: f64::NAN,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "plausible_current_step_ratio",
            ),
        ];
        for (config, field) in cases {
            assert_eq!(config.validate().unwrap_err().field(), field);
        }
    }

    #[test]
    fn config_errors_name_the_sampling_and_filter_field() {
        type C = OrtegaConfig<f64>;
        let cases: [(C, &str); 3] = [
            (
                C {
                    common: CommonTuning {
                        ts: -1e-4,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "ts",
            ),
            (
                C {
                    common: CommonTuning {
                        t2s1_bandwidth_hz: 0.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "t2s1_bandwidth_hz",
            ),
            (
                C {
                    common: CommonTuning {
                        t2s2_bandwidth_hz: 1e9,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "t2s2_bandwidth_hz",
            ),
        ];
        for (config, field) in cases {
            assert_eq!(config.validate().unwrap_err().field(), field);
        }
    }

    #[test]
    fn config_errors_name_the_tracker_field() {
        type C = OrtegaConfig<f64>;
        let cases: [(C, &str); 3] = [
            (
                C {
                    common: CommonTuning {
                        tracker_damping: f64::NAN,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "tracker_damping",
            ),
            (
                C {
                    common: CommonTuning {
                        tracker_hold_ratio: 2.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "tracker_hold_ratio",
            ),
            (
                C {
                    common: CommonTuning {
                        initial_angle: f64::NAN,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "initial_angle",
            ),
        ];
        for (config, field) in cases {
            assert_eq!(config.validate().unwrap_err().field(), field);
        }
    }

    #[test]
    fn config_errors_name_the_settings_field() {
        type C = OrtegaConfig<f64>;
        let cases: [(C, &str); 6] = [
            (
                C {
                    settings: OrtegaSettings {
                        observer_bandwidth: 0.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "observer_bandwidth",
            ),
            (
                C {
                    settings: OrtegaSettings {
                        observer_bandwidth: 10_000.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "observer_bandwidth",
            ),
            (
                C {
                    settings: OrtegaSettings {
                        observer_speed_ratio: -1.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "observer_speed_ratio",
            ),
            (
                C {
                    settings: OrtegaSettings {
                        observer_bandwidth_min: 0.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "observer_bandwidth_min",
            ),
            (
                C {
                    settings: OrtegaSettings {
                        observer_bandwidth_min: 2_000.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "observer_bandwidth_min",
            ),
            (
                C {
                    settings: OrtegaSettings {
                        flux_adaptation_ratio: -0.2,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "flux_adaptation_ratio",
            ),
        ];
        for (config, field) in cases {
            assert_eq!(config.validate().unwrap_err().field(), field);
        }
        assert!(C::for_machine(&MachineModel::paper()).validate().is_ok());
    }

    #[test]
    fn default_schedule_is_critically_damped_between_its_bounds() {
        // s² + ω_obs·s + ω² has a double root when ω_obs = 2|ω|.
        let c = OrtegaConfig::<f64>::for_machine(&MachineModel::paper());
        let tau = core::f64::consts::TAU;
        for f in [-100.0, -20.0, -1.6, 1.6, 6.0, 20.0, 100.0] {
            let w = tau * f;
            let w_obs = c.scheduled_bandwidth(w);
            assert!((w_obs * w_obs - 4.0 * w * w).abs() < 1e-9 * w * w, "{f} Hz");
            assert!((c.gamma(w) * 0.088 * 0.088 - w_obs).abs() < 1e-9);
        }
        assert_eq!(
            c.scheduled_bandwidth(0.0),
            c.settings.observer_bandwidth_min
        );
        assert_eq!(
            c.scheduled_bandwidth(-tau * 500.0),
            c.settings.observer_bandwidth
        );
        let fixed = OrtegaConfig {
            settings: OrtegaSettings {
                observer_speed_ratio: 0.0,
                ..c.settings
            },
            ..c
        };
        assert_eq!(
            fixed.scheduled_bandwidth(tau * 3.0),
            c.settings.observer_bandwidth
        );
    }

    #[test]
    fn radial_error_decays_at_the_observer_bandwidth_without_turning_the_angle() {
        // At standstill with no current the map is r⁺ = r + Ts·(γ/2)·r·(λ² − r²), linearised
        // 1 − ω_obs·Ts at r = λ; the direction of η̂ must not move. ω̂ = 0: the fixed gain, or
        // the schedule's floor.
        for speed_ratio in [0.0, 2.0] {
            let c = OrtegaConfig::<f64> {
                settings: OrtegaSettings {
                    observer_speed_ratio: speed_ratio,
                    ..OrtegaConfig::for_machine(&MachineModel::paper()).settings
                },
                ..OrtegaConfig::for_machine(&MachineModel::paper())
            };
            let mut est = OrtegaEstimator::new(c).unwrap();
            est.align(0.7, Ab::zero());
            est.x = Ab::from_polar(0.088 * 1.0001, 0.7);
            let n = 60;
            let mut eta = Ab::zero();
            for _ in 0..n {
                eta = est.step(Ab::zero(), Ab::zero()).diagnostics.lambda_r;
                assert!((eta.angle() - 0.7).abs() < 1e-12);
            }
            let measured = (eta.norm() - 0.088) / (0.088 * 1e-4);
            let predicted = (1.0 - c.scheduled_bandwidth(0.0) * c.common.ts).powi(n);
            assert!(
                (measured / predicted - 1.0).abs() < 1e-3,
                "{measured} {predicted}"
            );
        }
    }

    #[test]
    fn a_far_out_flux_is_pulled_in_monotonically_without_flipping() {
        // The fixed ω_max gain, where the floor k ≥ −½ acts for |η̂| > 3·λ̂f.
        let mut est = OrtegaEstimator::new(OrtegaConfig::<f64> {
            settings: OrtegaSettings {
                observer_speed_ratio: 0.0,
                ..OrtegaConfig::for_machine(&MachineModel::paper()).settings
            },
            ..OrtegaConfig::for_machine(&MachineModel::paper())
        })
        .unwrap();
        est.align(-2.0, Ab::zero());
        est.x = Ab::from_polar(0.088 * 50.0, -2.0);
        let mut r = est.x.norm();
        for _ in 0..5_000 {
            let eta = est.step(Ab::zero(), Ab::zero()).diagnostics.lambda_r;
            assert!((eta.angle() + 2.0).abs() < 1e-9);
            assert!(eta.norm() <= r && eta.norm() >= 0.088 * (1.0 - 1e-12));
            r = eta.norm();
        }
        assert!((r / 0.088 - 1.0).abs() < 1e-9, "{r}");
    }

    #[test]
    fn tangential_error_decays_at_the_slow_pole_at_low_speed() {
        // Rotor-frame error dynamics s² + ω_obs·s + ω² (module docs): at 3 Hz electrical the
        // slow pole is ≈ −ω²/ω_obs = −1.4 s⁻¹. Start with the flux estimate 2 mrad off (small:
        // the second-order term of |η̂|² is amplified by ω_obs/ω like a λ̂f error). The forward
        // step's radial rate −ln(1 − ω_obs·Ts)/Ts is 1.3 % above ω_obs, hence the tolerance.
        // The fixed gain of the analysis, critical at 300 r/min.
        let c = OrtegaConfig::<f64> {
            settings: OrtegaSettings {
                observer_speed_ratio: 0.0,
                observer_bandwidth: 2.0 * core::f64::consts::TAU * 20.0,
                ..OrtegaConfig::for_machine(&MachineModel::paper()).settings
            },
            ..OrtegaConfig::for_machine(&MachineModel::paper())
        };
        let (ts, lf) = (c.common.ts, c.machine.flux_linkage);
        for w in [
            2.0 * core::f64::consts::PI * 3.0,
            -2.0 * core::f64::consts::PI * 3.0,
        ] {
            let slow = (-c.settings.observer_bandwidth
                + (c.settings.observer_bandwidth.powi(2) - 4.0 * w * w).sqrt())
                / 2.0;
            let mut est = OrtegaEstimator::new(c).unwrap();
            est.align(0.002, Ab::zero());
            let err_at = |t_end: f64, est: &mut OrtegaEstimator<f64>, n0: usize| {
                let n1 = (t_end / ts) as usize;
                let mut err = 0.0;
                for n in n0..n1 {
                    // No current; v = d(λf·e^{jθ})/dt over the interval, exactly.
                    let th = |k: usize| w * ts * k as f64;
                    let v =
                        (Ab::from_polar(lf, th(n + 1)) - Ab::from_polar(lf, th(n))) * (1.0 / ts);
                    let out = est.step(v, Ab::zero());
                    err = crate::wrap_angle(out.diagnostics.theta_direct - th(n + 1));
                }
                (err, n1)
            };
            let (e1, n1) = err_at(0.5, &mut est, 0);
            let (e2, _) = err_at(1.5, &mut est, n1);
            let measured = (e2 / e1).ln();
            assert!(
                (measured / slow - 1.0).abs() < 0.03,
                "ω = {w}: decay {measured} vs {slow}"
            );
        }
    }
}
