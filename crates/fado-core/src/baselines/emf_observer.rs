//! Baseline 3: an extended-EMF observer in the stationary frame with the type-2 trackers.
//!
//! # Algorithm
//! The extended EMF of Z. Chen, M. Tomita, S. Doki and S. Okuma, "An extended electromotive
//! force model for sensorless control of interior permanent-magnet synchronous motors", IEEE
//! Trans. Ind. Electron. 50(2), 2003 (in the rotor frame: Morimoto et al. 2002, ref. \[4\] of the
//! paper) is the part of the voltage equation that carries the rotor position,
//! v = R·i + Ld·di/dt + ω(Ld − Lq)·J·i + e_ex. For the surface-mount machine of docs/method/estimator.md, "The paper's motor and drive"
//! (Ld = Lq = L) it is the back-EMF e = d(λf·e^{jθ})/dt = jω·λf·e^{jθ}, a vector rotating at ω
//! and leading the rotor flux by sgn(ω)·90°. It is observed here as the disturbance of the
//! current equation, in reduced-order form with a rotating internal model (ė = jω̂·e, ω̂ from
//! T2S-1):
//!
//! ```text
//! E[n]  = v* − R̂s·ī − L̂·(i[n] − i[n−1])/Ts      (the EMF averaged over the interval, exact)
//! ê[n]  = (1 − g)·a·ê[n−1] + g·E[n],   a = e^{jω̂Ts},   g = 1 − e^{−p·Ts}
//! λ̂r    = ê·e^{jω̂Ts/2}·(−j) / ω_d,     ω_d = 2·sin(ω̂Ts/2)/Ts        →  θm = ∠λ̂r  →  T2S
//! ```
//!
//! The filter is a first-order low-pass of bandwidth p in a frame rotating at ω̂: unity gain
//! and zero phase for a vector rotating at ω̂, so there is no lag at constant speed and no
//! integrator to drift. Dividing by the exact discrete derivative of a rotating vector,
//! (1 − e^{−jω̂Ts})/Ts = j·ω_d·e^{−jω̂Ts/2}, turns the interval-mean EMF back into the rotor
//! flux at the sample, λ̂r = λf·e^{jθ} (exact for a machine at constant speed), so that the angle
//! goes through the same eq. (6) and trackers as fado. Below the speed floor ω_f, |ω_d| is
//! replaced by ω_f with the sign of ω̂ (positive at ω̂ = 0).
//!
//! # Bandwidth p (the reasoning behind the default)
//! Off its tuning the filter has the phase ≈ (ω̂ − ω)/p, so ω̂ feeds back into θm. With T2S-1
//! (Kp, Ki) the loop becomes s² + (Kp − Ki/p)·s + Ki: stable only for p > Ki/Kp (130 rad/s
//! for 60 Hz), which `new` enforces. The default p = 2π·100 Hz keeps 80 % of the tracker's
//! damping term, costs 10 mrad of phase per 1 Hz of speed error (ω̂ lagging an acceleration),
//! and lets through only p·L̂·σ_i ≈ 17 mV of EMF noise for σ_i = 10 mA (docs/method/estimator.md, "The paper's motor and drive").
//!
//! # Where it fails
//! - **Low speed.** The EMF vanishes with ω (0.55 V per Hz for this motor): below a few Hz it
//!   is of the order of the inverter's voltage error (dead time, device drops: docs/method/estimator.md §7) and the
//!   angle error grows like |Δv|/(ω·λf). Below ω_f the estimate is scaled down, and once
//!   |λ̂r| < 0.2·λ̂f the trackers coast.
//! - **Reversal.** The flux direction is ∠ê − sgn(ω̂)·90°: if ω̂ has the wrong sign the angle is
//!   off by π, and crossing zero speed under load is a guess.
//! - **Offsets.** A DC voltage error ε passes the rotating filter with gain p/√(p² + ω²),
//!   giving an angle ripple ≈ |ε|·p/(√(p² + ω²)·|ω|·λf) in θm at the fundamental: bounded at
//!   speed, unbounded as ω → 0. It reaches θ̂ through the less damped loop above,
//!   |(Kp·s + Ki)/(s² + (Kp − Ki/p)·s + Ki)| (1.49 instead of 1.26 at 20 Hz; tested).
//! - **Parameters.** L̂ errors act through L̂·di/dt (transients) and, as in fado, under load.

use super::{AngleTrackers, Baseline, BaselineConfig, GuardedStep, Integrand};
use crate::error::{ConfigError, check};
use crate::estimator::{Diagnostics, Estimate, RotorAngleEstimator};
use crate::{Ab, Real};

/// Settings of [`EmfObserverEstimator`] of its own (`[baselines.emf_observer]` in `fado-sim`'s TOML):
/// plain numbers whose defaults do not depend on the machine.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct EmfObserverSettings<T> {
    /// Bandwidth p/2π of the rotating EMF filter in Hz; 2π·p must exceed Ki/Kp of T2S-1.
    /// Default 100 Hz \[A\] (module docs).
    pub emf_bandwidth_hz: T,
    /// Speed floor f_f in Hz below which the EMF is divided by 2π·f_f instead of ω̂.
    /// Default 2 Hz \[A\]: there the EMF (1.1 V) is already of the order of the dead-time voltage
    /// error of docs/method/estimator.md §7.
    pub speed_floor_hz: T,
}

impl<T: Real> Default for EmfObserverSettings<T> {
    fn default() -> Self {
        Self {
            emf_bandwidth_hz: T::lit(100.0),
            speed_floor_hz: T::lit(2.0),
        }
    }
}

/// Configuration of [`EmfObserverEstimator`]: the machine model, the shared [`CommonTuning`](super::CommonTuning) and
/// [`EmfObserverSettings`].
pub type EmfObserverConfig<T> = BaselineConfig<T, EmfObserverSettings<T>>;

impl<T: Real> Baseline<T> for EmfObserverEstimator<T> {
    type Settings = EmfObserverSettings<T>;
    const NAME: &'static str = "emf-observer";
    fn from_config(config: EmfObserverConfig<T>) -> Result<Self, ConfigError> {
        Self::new(config)
    }
}

impl<T: Real> EmfObserverConfig<T> {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        EmfObserverEstimator::new(*self).map(|_| ())
    }
}

/// The stationary-frame EMF observer with type-2 trackers (see the module docs).
///
/// ```
/// use fado_core::{Ab, MachineModel};
/// use fado_core::baselines::{EmfObserverConfig, EmfObserverEstimator};
/// let mut est = EmfObserverEstimator::<f32>::new(EmfObserverConfig::for_machine(&MachineModel::paper())).unwrap();
/// let out = est.step(Ab::new(1.2, -0.3), Ab::new(4.0, 0.1));
/// assert!(!out.diagnostics.input_fault);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmfObserverEstimator<T: Real> {
    config: EmfObserverConfig<T>,
    integrand: Integrand<T>,
    trackers: AngleTrackers<T>,
    /// ê: the filtered interval-mean EMF.
    emf: Ab<T>,
    /// g = 1 − e^{−p·Ts}.
    gain: T,
    /// ω_f in rad/s.
    floor: T,
    last: Estimate<T>,
    rejected_samples: u32,
}

impl<T: Real> EmfObserverEstimator<T> {
    /// Builds the estimator; every field of `config` is checked and a bad one is named.
    pub fn new(config: EmfObserverConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.common.ts)?;
        check::non_negative("lq", config.machine.lq)?;
        let integrand = integrand_of!(config.machine, config.common, ts)?;
        let lf = check::positive("flux_linkage", config.machine.flux_linkage)?;
        let p =
            T::two_pi() * check::positive("emf_bandwidth_hz", config.settings.emf_bandwidth_hz)?;
        check::below(
            "emf_bandwidth_hz",
            p * ts,
            T::one(),
            "2π·emf_bandwidth_hz·ts below 1",
        )?;
        let floor =
            T::two_pi() * check::positive("speed_floor_hz", config.settings.speed_floor_hz)?;
        check::finite("initial_angle", config.common.initial_angle)?;
        let trackers = config.common.trackers(lf)?;
        let (kp, ki) = trackers.t2s1_gains();
        if p * kp <= ki {
            return Err(ConfigError::OutOfRange {
                field: "emf_bandwidth_hz",
                expected: "2π·emf_bandwidth_hz above Ki/Kp of T2S-1 (module docs)",
            });
        }
        let mut est = Self {
            config,
            integrand,
            trackers,
            emf: Ab::zero(),
            gain: -(-p * ts).exp_m1(),
            floor,
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

    /// Start-up at a known rotor angle θ0 with the present current: θ̂ = θ0, ω̂ = 0, ê = 0
    /// (at standstill there is no EMF), `i_ab` remembered for the first L̂·di/dt.
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
        self.emf = Ab::zero();
        self.integrand.reset_to(i_ab);
        self.trackers.reset_to(theta0);
        self.rejected_samples = 0;
        let lambda_r = Ab::from_polar(self.config.machine.flux_linkage, theta0);
        let lambda_s = lambda_r + i_ab * self.config.machine.lq;
        self.last = Estimate {
            theta: self.trackers.angle(),
            diagnostics: Diagnostics {
                lambda1: lambda_s,
                lambda2: lambda_s,
                lambda_r,
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

    /// ê: the filtered EMF (V), the interval mean ending at the last sample.
    pub fn emf(&self) -> Ab<T> {
        self.emf
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
    pub fn config(&self) -> &EmfObserverConfig<T> {
        &self.config
    }
}

impl<T: Real> GuardedStep<T> for EmfObserverEstimator<T> {
    #[inline]
    fn step_unchecked(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Option<Estimate<T>> {
        let ts = self.config.common.ts;
        let lq = self.config.machine.lq;
        let di = i_ab - self.integrand.previous_current().unwrap_or(i_ab);
        let emf_measured = self.integrand.next(v_ab, i_ab) - di * (lq / ts);
        // Half a sample of rotation at ω̂; a = half².
        let (sin_half, cos_half) = (self.trackers.speed() * ts * T::lit(0.5)).sin_cos();
        let half = Ab::new(cos_half, sin_half);
        let a = half.complex_mul(half);
        let g = self.gain;
        let emf = self.emf.complex_mul(a) * (T::one() - g) + emf_measured * g;
        let omega_d = T::lit(2.0) * sin_half / ts;
        let divisor = if omega_d.abs() >= self.floor {
            omega_d
        } else if omega_d < T::zero() {
            -self.floor
        } else {
            self.floor
        };
        // λ̂r = ê·e^{jω̂Ts/2}·(−j)/ω_d.
        let lambda_r = -emf.complex_mul(half).mul_j() * (T::one() / divisor);
        if !(emf.is_finite() && lambda_r.is_finite()) {
            return None;
        }
        let mut trackers = self.trackers;
        let t = trackers.step(lambda_r)?;
        self.trackers = trackers;
        self.integrand.accept(i_ab);
        self.emf = emf;
        let lambda_s = lambda_r + i_ab * lq;
        Some(Estimate {
            theta: t.theta,
            omega: t.omega,
            omega_control: t.omega_control,
            diagnostics: Diagnostics {
                lambda1: lambda_s,
                lambda2: lambda_s,
                lambda_r,
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

rotor_angle_estimator!(EmfObserverEstimator);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MachineModel;
    use crate::baselines::CommonTuning;

    #[test]
    fn config_errors_name_the_machine_field() {
        type C = EmfObserverConfig<f64>;
        let cases: [(C, &str); 3] = [
            (
                C::for_machine(&MachineModel {
                    rs: -0.1,
                    ..MachineModel::paper()
                }),
                "rs",
            ),
            (
                C::for_machine(&MachineModel {
                    lq: f64::INFINITY,
                    ..MachineModel::paper()
                }),
                "lq",
            ),
            (
                C::for_machine(&MachineModel {
                    flux_linkage: -0.088,
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
    fn config_errors_name_the_sampling_and_filter_field() {
        type C = EmfObserverConfig<f64>;
        let cases: [(C, &str); 3] = [
            (
                C {
                    common: CommonTuning {
                        ts: f64::NAN,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "ts",
            ),
            (
                C {
                    common: CommonTuning {
                        t2s1_bandwidth_hz: -60.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "t2s1_bandwidth_hz",
            ),
            (
                C {
                    common: CommonTuning {
                        t2s2_bandwidth_hz: 0.0,
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
        type C = EmfObserverConfig<f64>;
        let cases: [(C, &str); 2] = [
            (
                C {
                    common: CommonTuning {
                        tracker_damping: -1.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "tracker_damping",
            ),
            (
                C {
                    common: CommonTuning {
                        initial_angle: f64::NEG_INFINITY,
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
        type C = EmfObserverConfig<f64>;
        let cases: [(C, &str); 4] = [
            (
                C {
                    settings: EmfObserverSettings {
                        emf_bandwidth_hz: 0.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "emf_bandwidth_hz",
            ),
            (
                C {
                    settings: EmfObserverSettings {
                        emf_bandwidth_hz: 2_000.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "emf_bandwidth_hz",
            ),
            // 2π·10 Hz = 63 rad/s < Ki/Kp = 130 rad/s of the 60 Hz T2S-1.
            (
                C {
                    settings: EmfObserverSettings {
                        emf_bandwidth_hz: 10.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "emf_bandwidth_hz",
            ),
            (
                C {
                    settings: EmfObserverSettings {
                        speed_floor_hz: 0.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "speed_floor_hz",
            ),
        ];
        for (config, field) in cases {
            assert_eq!(config.validate().unwrap_err().field(), field);
        }
        assert!(C::for_machine(&MachineModel::paper()).validate().is_ok());
        // Just above the speed-feedback bound is accepted.
        assert!(
            C {
                settings: EmfObserverSettings {
                    emf_bandwidth_hz: 21.0,
                    ..Default::default()
                },
                ..C::for_machine(&MachineModel::paper())
            }
            .validate()
            .is_ok()
        );
    }

    #[test]
    fn no_emf_at_standstill_makes_the_trackers_coast() {
        let mut est = EmfObserverEstimator::new(EmfObserverConfig::<f64>::for_machine(
            &MachineModel::paper(),
        ))
        .unwrap();
        est.align(0.5, Ab::new(4.0, 0.0));
        for _ in 0..1_000 {
            // A standing current: v = R·i, no EMF.
            let out = est.step(Ab::new(0.327 * 4.0, 0.0), Ab::new(4.0, 0.0));
            assert!(out.diagnostics.tracker_hold);
            assert!((out.theta - 0.5).abs() < 1e-12);
        }
        assert!(est.emf().norm() < 1e-9);
    }
}
