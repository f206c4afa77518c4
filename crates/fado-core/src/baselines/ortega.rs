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
//! # Gain γ (the reasoning behind the default)
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
//! ω_obs = 2|ω|, and for |ω| ≪ ω_obs the slow pole is −ω²/ω_obs. The steady state for a
//! constant rotor-frame voltage error u is εd = uq/ω, εq = (ω_obs·uq/ω − ud)/ω: beyond what
//! the open integrator suffers (−ud/ω), a q-axis error (R̂s error × iq, dead time) and,
//! equivalently, a flux-linkage error Δλ (angle error ≈ (ω_obs/ω)·Δλ/λf) are amplified by
//! ω_obs/ω. A large ω_obs is therefore *not* better at low speed. The default
//! ω_obs = 2·(2π·20 Hz) ≈ 251 rad/s makes the observer critically damped at 20 Hz electrical
//! (300 r/min with 4 pole pairs: the medium speed of these checks and of the fig9 scenario);
//! at the 6 Hz of the ±90 r/min reversal the slow pole is then −5.6 s⁻¹ and the amplification
//! 6.7, where ODrive's 1000 rad/s would give −1.4 s⁻¹ and 26.5. In the paper's normalisation
//! γ = ω_obs/λ̂f² = 3.2e4 Wb⁻²s⁻¹ at λ̂f = 0.088 Wb.
//!
//! # Discretisation
//! As in ODrive: predict x̂⁻ = x̂ + Ts·(v* − R̂s·i) (the forward rectangle and averaged current
//! of [`crate::flux::FluxIntegrator`]), form η̂⁻ = x̂⁻ − L̂·i[n] with the fresh current, then
//! correct x̂ = x̂⁻ + k·η̂⁻ with k = Ts·(γ/2)·(λ̂f² − |η̂⁻|²). The linearised radial map is
//! 1 − ω_obs·Ts, so `new` requires ω_obs·Ts < 1 (monotone convergence). For |η̂| far outside
//! the circle k would overshoot through the origin and flip the angle; k is floored at −½,
//! which only acts for |η̂|² > λ̂f²·(1 + 1/(ω_obs·Ts)) (|η̂| > 6.4·λ̂f at the defaults), i.e.
//! never in operation.
//!
//! # Flux-linkage adaptation (option, off by default)
//! With `flux_adaptation_ratio` κ > 0 the target radius adapts, as in VESC's
//! `ORTEGA_LAMBDA_COMP` observer (after P. Bernard and L. Praly, IFAC 2017):
//! dλ̂/dt = κ·(γ/2)·λ̂·(|η̂|² − λ̂²), clamped to [0.3, 2.5]·λ̂f (VESC's bounds; VESC uses
//! κ = 0.2). While the rotor turns the only equilibrium without a standing radial push is
//! λ̂ = λf, which removes the Δλ angle error above; at standstill λ̂ is unobservable.
//! Off by default because fado and the comparison assume known parameters.
//!
//! # Where it fails
//! - **Low speed.** The tangential error decays at ≈ ω²/ω_obs; at standstill the observer is
//!   an open integrator along the angle direction and drifts with any integrand error, and it
//!   has no mechanism like fado's limiter and positive-i_d steering (Fig. 6, eq. (23)).
//! - **Offsets.** A DC integrand error ε is rejected at speed (average decay ω_obs/2 in every
//!   direction when |ω| ≫ ω_obs), leaving an angle ripple ≈ 2|ε|/(ω_obs·λf) at the
//!   fundamental, but is integrated along the angle at standstill.
//! - **Parameters.** λ̂f, R̂s (under load) and q-axis voltage errors are amplified by
//!   ω_obs/ω (above); L̂ errors act under load as in fado; the model assumes Ld = Lq.

use super::{AngleTrackers, Integrand, TrackerSettings};
use crate::error::{ConfigError, check};
use crate::estimator::{Diagnostics, Estimate, RotorAngleEstimator};
use crate::tracker::BandwidthDefinition;
use crate::{Ab, Real};

/// Lower and upper bound of the adapted flux linkage relative to λ̂f (VESC's bounds).
const ADAPTATION_BOUNDS: (f64, f64) = (0.3, 2.5);

/// Configuration of [`OrtegaEstimator`]; flat like [`crate::EstimatorConfig`], whose shared
/// fields have the same names and defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrtegaConfig<T> {
    /// Sampling period Ts in s. Default 100 µs (paper, V).
    pub ts: T,
    /// Stator resistance estimate R̂s in Ω. Default 0.327 Ω (paper, V).
    pub rs_hat: T,
    /// Inductance estimate L̂ = L̂d = L̂q in H (the observer assumes a non-salient machine).
    /// Default 2.63 mH (paper, V).
    pub lq_hat: T,
    /// Magnet flux linkage estimate λ̂f in Wb: the radius η̂ is pulled to. Unlike fado, the
    /// angle depends on it (module docs). Default 0.088 Wb (SPEC §6 [A]).
    pub flux_linkage_hat: T,
    /// Radial (flux-magnitude) correction rate ω_obs = γ·λ̂f² in rad/s; ω_obs·ts must be
    /// below 1. Default 2·2π·20 ≈ 251 rad/s [A]: critically damped at 20 Hz electrical
    /// (300 r/min), see the module docs for the trade-off.
    pub observer_bandwidth: T,
    /// Flux-linkage adaptation ratio κ (module docs); 0 disables it. Default 0 [A].
    pub flux_adaptation_ratio: T,
    /// Bandwidth of T2S-1 in Hz. Default 60 Hz (paper, V), as fado.
    pub t2s1_bandwidth_hz: T,
    /// Bandwidth of T2S-2 in Hz. Default 35 Hz (paper, V), as fado.
    pub t2s2_bandwidth_hz: T,
    /// Damping ratio of both trackers. Default 1/√2 (SPEC §3 [A]).
    pub tracker_damping: T,
    /// Meaning of the tracker bandwidths. Default −3 dB (SPEC §3).
    pub bandwidth_definition: BandwidthDefinition,
    /// Trackers coast while |η̂| is below this fraction of λ̂f. Default 0.2 (SPEC §3 [A]).
    pub tracker_hold_ratio: T,
    /// Average the current over the interval for the resistive drop. Default true (SPEC §1
    /// [A]).
    pub average_current: bool,
    /// Rotor angle assumed at reset (rad). Default 0 (SPEC §1 [A]).
    pub initial_angle: T,
}

impl<T: Real> Default for OrtegaConfig<T> {
    fn default() -> Self {
        Self {
            ts: T::lit(100e-6),
            rs_hat: T::lit(0.327),
            lq_hat: T::lit(2.63e-3),
            flux_linkage_hat: T::lit(0.088),
            observer_bandwidth: T::lit(2.0 * core::f64::consts::TAU * 20.0),
            flux_adaptation_ratio: T::zero(),
            t2s1_bandwidth_hz: T::lit(60.0),
            t2s2_bandwidth_hz: T::lit(35.0),
            tracker_damping: T::lit(core::f64::consts::FRAC_1_SQRT_2),
            bandwidth_definition: BandwidthDefinition::Minus3Db,
            tracker_hold_ratio: T::lit(0.2),
            average_current: true,
            initial_angle: T::zero(),
        }
    }
}

impl<T: Real> OrtegaConfig<T> {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        OrtegaEstimator::new(*self).map(|_| ())
    }

    /// γ of the paper's eq. (8), ω_obs/λ̂f², in Wb⁻²·s⁻¹.
    pub fn gamma(&self) -> T {
        self.observer_bandwidth / (self.flux_linkage_hat * self.flux_linkage_hat)
    }
}

/// The Ortega–Praly nonlinear flux observer with type-2 trackers (see the module docs).
///
/// ```
/// use fado_core::Ab;
/// use fado_core::baselines::{OrtegaConfig, OrtegaEstimator};
/// let mut est = OrtegaEstimator::<f32>::new(OrtegaConfig::default()).unwrap();
/// let out = est.step(Ab::new(1.2, -0.3), Ab::new(4.0, 0.1));
/// assert!(!out.diagnostics.input_fault);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrtegaEstimator<T> {
    config: OrtegaConfig<T>,
    integrand: Integrand<T>,
    trackers: AngleTrackers<T>,
    /// x̂: the estimated stator flux.
    x: Ab<T>,
    /// λ̂: the radius η̂ is pulled to (λ̂f unless adapted).
    lambda: T,
    /// Ts·γ/2.
    k_ts: T,
    last: Estimate<T>,
    rejected_samples: u32,
}

impl<T: Real> OrtegaEstimator<T> {
    /// Builds the estimator; every field of `config` is checked and a bad one is named.
    pub fn new(config: OrtegaConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        let integrand = Integrand::new(config.rs_hat, config.average_current)?;
        check::non_negative("lq_hat", config.lq_hat)?;
        let lf = check::positive("flux_linkage_hat", config.flux_linkage_hat)?;
        let w_obs = check::positive("observer_bandwidth", config.observer_bandwidth)?;
        check::below(
            "observer_bandwidth",
            w_obs * ts,
            T::one(),
            "observer_bandwidth·ts below 1",
        )?;
        check::non_negative("flux_adaptation_ratio", config.flux_adaptation_ratio)?;
        check::finite("initial_angle", config.initial_angle)?;
        let trackers = AngleTrackers::new(TrackerSettings {
            ts,
            t2s1_bandwidth_hz: config.t2s1_bandwidth_hz,
            t2s2_bandwidth_hz: config.t2s2_bandwidth_hz,
            damping: config.tracker_damping,
            definition: config.bandwidth_definition,
            hold_ratio: config.tracker_hold_ratio,
            flux_linkage_hat: lf,
        })?;
        let mut est = Self {
            config,
            integrand,
            trackers,
            x: Ab::zero(),
            lambda: lf,
            k_ts: ts * config.gamma() * T::lit(0.5),
            last: Estimate::default(),
            rejected_samples: 0,
        };
        est.reset();
        Ok(est)
    }

    /// Back to the start-up state at `config.initial_angle` with zero current.
    pub fn reset(&mut self) {
        self.align(self.config.initial_angle, Ab::zero());
    }

    /// Start-up at a known rotor angle θ0 with the present current: x̂ = λ̂f·e^{jθ0} + L̂·i,
    /// λ̂ = λ̂f, θ̂ = θ0, ω̂ = 0.
    pub fn align(&mut self, theta0: T, i_ab: Ab<T>) {
        let theta0 = if theta0.is_finite() {
            theta0
        } else {
            T::zero()
        };
        let i_ab = if i_ab.is_finite() { i_ab } else { Ab::zero() };
        self.lambda = self.config.flux_linkage_hat;
        let eta = Ab::from_polar(self.lambda, theta0);
        self.x = eta + i_ab * self.config.lq_hat;
        self.integrand.reset();
        self.trackers.reset_to(theta0);
        self.rejected_samples = 0;
        self.last = Estimate {
            theta: self.trackers.angle(),
            diagnostics: Diagnostics {
                lambda1: self.x,
                lambda2: self.x,
                lambda_r: eta,
                theta_direct: self.trackers.angle(),
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
        if !(v_ab.is_finite() && i_ab.is_finite()) {
            return self.reject();
        }
        let backup = *self;
        match self.step_unchecked(v_ab, i_ab) {
            Some(out) => {
                self.last = out;
                out
            }
            None => {
                // Finite but absurd inputs overflowed a state: roll back, never poison.
                *self = backup;
                self.reject()
            }
        }
    }

    fn reject(&mut self) -> Estimate<T> {
        self.rejected_samples = self.rejected_samples.saturating_add(1);
        let mut out = self.last;
        out.diagnostics.input_fault = true;
        out
    }

    #[inline]
    fn step_unchecked(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Option<Estimate<T>> {
        let li = i_ab * self.config.lq_hat;
        // Predict with the voltage model, then correct radially with the fresh current.
        let x_pred = self.x + self.integrand.step(v_ab, i_ab) * self.config.ts;
        let eta_pred = x_pred - li;
        let radius_error = self.lambda * self.lambda - eta_pred.norm_squared();
        let k = (self.k_ts * radius_error).max(T::lit(-0.5));
        let x = x_pred + eta_pred * k;
        let eta = x - li;
        let kappa = self.config.flux_adaptation_ratio;
        let lambda = if kappa > T::zero() {
            let lf = self.config.flux_linkage_hat;
            let (lo, hi) = ADAPTATION_BOUNDS;
            (self.lambda - kappa * self.k_ts * self.lambda * radius_error)
                .max(T::lit(lo) * lf)
                .min(T::lit(hi) * lf)
        } else {
            self.lambda
        };
        if !(x.is_finite() && eta.is_finite() && lambda.is_finite()) {
            return None;
        }
        let t = self.trackers.step(eta)?;
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
                ..Diagnostics::default()
            },
        })
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

impl<T: Real> RotorAngleEstimator<T> for OrtegaEstimator<T> {
    #[inline]
    fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T> {
        OrtegaEstimator::step(self, v_ab, i_ab)
    }
    fn align(&mut self, theta0: T, i_ab: Ab<T>) {
        OrtegaEstimator::align(self, theta0, i_ab)
    }
    fn reset(&mut self) {
        OrtegaEstimator::reset(self)
    }
    fn name(&self) -> &'static str {
        "ortega"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn config_errors_name_the_field() {
        type C = OrtegaConfig<f64>;
        let cases: [(C, &str); 12] = [
            (
                C {
                    ts: -1e-4,
                    ..C::default()
                },
                "ts",
            ),
            (
                C {
                    rs_hat: f64::NAN,
                    ..C::default()
                },
                "rs_hat",
            ),
            (
                C {
                    lq_hat: -1e-3,
                    ..C::default()
                },
                "lq_hat",
            ),
            (
                C {
                    flux_linkage_hat: 0.0,
                    ..C::default()
                },
                "flux_linkage_hat",
            ),
            (
                C {
                    observer_bandwidth: 0.0,
                    ..C::default()
                },
                "observer_bandwidth",
            ),
            (
                C {
                    observer_bandwidth: 10_000.0,
                    ..C::default()
                },
                "observer_bandwidth",
            ),
            (
                C {
                    flux_adaptation_ratio: -0.2,
                    ..C::default()
                },
                "flux_adaptation_ratio",
            ),
            (
                C {
                    t2s1_bandwidth_hz: 0.0,
                    ..C::default()
                },
                "t2s1_bandwidth_hz",
            ),
            (
                C {
                    t2s2_bandwidth_hz: 1e9,
                    ..C::default()
                },
                "t2s2_bandwidth_hz",
            ),
            (
                C {
                    tracker_damping: f64::NAN,
                    ..C::default()
                },
                "tracker_damping",
            ),
            (
                C {
                    tracker_hold_ratio: 2.0,
                    ..C::default()
                },
                "tracker_hold_ratio",
            ),
            (
                C {
                    initial_angle: f64::NAN,
                    ..C::default()
                },
                "initial_angle",
            ),
        ];
        for (config, field) in cases {
            assert_eq!(config.validate().unwrap_err().field(), field);
        }
        assert!(C::default().validate().is_ok());
    }

    #[test]
    fn default_gain_is_critically_damped_at_300_rpm() {
        // s² + ω_obs·s + ω² has a double root at ω = 2π·20 Hz (4 pole pairs, 300 r/min).
        let c = OrtegaConfig::<f64>::default();
        let w = core::f64::consts::TAU * 300.0 / 60.0 * 4.0;
        assert!((c.observer_bandwidth * c.observer_bandwidth - 4.0 * w * w).abs() < 1e-6);
        assert!((c.gamma() * 0.088 * 0.088 - c.observer_bandwidth).abs() < 1e-9);
    }

    #[test]
    fn radial_error_decays_at_the_observer_bandwidth_without_turning_the_angle() {
        // At standstill with no current the map is r⁺ = r + Ts·(γ/2)·r·(λ² − r²), linearised
        // 1 − ω_obs·Ts at r = λ; the direction of η̂ must not move.
        let c = OrtegaConfig::<f64>::default();
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
        let predicted = (1.0 - c.observer_bandwidth * c.ts).powi(n);
        assert!(
            (measured / predicted - 1.0).abs() < 1e-3,
            "{measured} {predicted}"
        );
    }

    #[test]
    fn a_far_out_flux_is_pulled_in_monotonically_without_flipping() {
        let mut est = OrtegaEstimator::new(OrtegaConfig::<f64>::default()).unwrap();
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
        let c = OrtegaConfig::<f64>::default();
        let (ts, lf) = (c.ts, c.flux_linkage_hat);
        for w in [
            2.0 * core::f64::consts::PI * 3.0,
            -2.0 * core::f64::consts::PI * 3.0,
        ] {
            let slow =
                (-c.observer_bandwidth + (c.observer_bandwidth.powi(2) - 4.0 * w * w).sqrt()) / 2.0;
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
