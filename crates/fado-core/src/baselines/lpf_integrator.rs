//! Baseline 1: the voltage-model flux estimator with a low-pass "integrator" and gain/phase
//! compensation at the estimated speed.
//!
//! # Algorithm
//! The pure integrator of eq. (3) drifts with any DC integrand error; the classic remedy
//! replaces 1/s by the low-pass filter 1/(s + ωc), whose DC gain is finite (J. Hu and B. Wu,
//! "New integration algorithms for estimating motor flux over a wide speed range", IEEE
//! Trans. Power Electron. 13(5), 1998, discuss this LPF and its gain and phase error). For a
//! flux rotating at ω the LPF output differs from the integral by the factor
//! jω/(jω + ωc), so the stator flux is recovered by multiplying with its inverse at the
//! estimated speed ω̂:
//!
//! ```text
//! ψ  = (v* − R̂s·i) / (s + ωc)
//! λ̂s = ψ · (jω̂ + ωc)/(jω̂) = ψ · (1 − j·ωc/ω̂)        (exact for a sinusoid at ω̂ = ω)
//! λ̂r = λ̂s − L̂q·i,   θm = ∠λ̂r  (eq. (5)-(6))  →  T2S-1 / T2S-2 (Fig. 1)
//! ```
//!
//! ω̂ is the T2S-1 speed of the previous sample. Since 1/ω̂ has no limit at standstill, the
//! compensation is regularised \[A\]: 1/ω̂ becomes ω̂/(ω̂² + ω_f²) with the floor
//! ω_f = 2π·`compensation_floor_hz`. It is exact to a relative ω_f²/ω̂² well above the
//! floor, tends to 1 (no compensation) at ω̂ = 0 and passes through a reversal without a
//! jump, where a clamped 1/ω̂ would rotate λ̂s by 90° when ω̂ changes sign.
//!
//! # Discretisation
//! ψ ← ψ + Ts·(v* − R̂s·i − ωc·ψ): the forward rectangle of [`crate::flux::FluxIntegrator`]
//! (with the same averaged current) with the feedback ωc·ψ in place of fado's k_df·D̂. For a
//! vector rotating at ω its steady-state ratio to the pure discrete integrator is, with
//! z = e^{jωTs} and ω_d = 2·sin(ωTs/2)/Ts,
//!
//! ```text
//! 1 + ωc·Ts/(z − 1) = 1 − j·(ωc/ω_d)·e^{−jωTs/2}  =  1 − j·ωc/ω − ωc·Ts/2 + O(Ts²)
//! ```
//!
//! which is the compensation applied (with ω̂, and ω_d regularised as above). The continuous
//! factor would leave a gain error ωc·Ts/2 (3e-4); what remains with the exact one is the
//! regularisation's phase error ≈ ωc·ω_f²/ω̂³ (1.3e-4 rad at 300 r/min).
//!
//! # Where it fails
//! - **Low speed.** Below a few ωc the compensation depends on ω̂ ever more steeply
//!   (∂∠/∂ω̂ = ωc/(ω̂² + ωc²)), and below ω_f it fades out, so λ̂s becomes the low-passed
//!   EMF, sgn(ω)·90° ahead of the flux, and the angle is lost; at standstill
//!   ψ → (v* − R̂s·i)/ωc.
//!   A speed reversal therefore passes through a region with no valid angle.
//! - **Offsets.** A DC integrand error ε (current-sensor offset × R̂s, R̂s error on a DC
//!   current, uncompensated dead time) leaves the standing flux error ε/ωc·(1 − jωc/ω̂): an
//!   angle ripple at the fundamental of about |ε|/(ωc·λf) in θm (50 mV → 0.09 rad at the
//!   default), times the tracker's |T(jω)| in θ̂ (tested).
//!   Raising ωc shrinks it but widens the low-speed region; the transient after a start or
//!   a step decays with 1/ωc (160 ms at the default).
//! - **Parameters.** Like fado, R̂s errors act at low speed and L̂q errors under load.

use super::{AngleTrackers, Baseline, BaselineConfig, GuardedStep, Integrand};
use crate::error::{ConfigError, check};
use crate::estimator::{Diagnostics, Estimate, RotorAngleEstimator};
use crate::{Ab, Real};

/// Settings of [`LpfIntegratorEstimator`] of its own (`[baselines.lpf_integrator]` in `fado-sim`'s TOML):
/// plain numbers whose defaults do not depend on the machine.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct LpfIntegratorSettings<T> {
    /// Cutoff fc of the low-pass integrator 1/(s + 2π·fc) in Hz; 0 gives the open integrator
    /// of eq. (3). Default 1 Hz \[A\]: one sixth of the 6 Hz electrical speed of the paper's
    /// ±90 r/min tests (compensation 9.5° there), while a DC integrand error ε leaves a bounded
    /// flux error ε/ωc (50 mV → 8 mWb, 9 % of λf).
    pub cutoff_hz: T,
    /// Speed floor f_f of the regularised compensation ωc·ω̂/(ω̂² + ω_f²) in Hz (module docs).
    /// Default 1 Hz \[A\]: equal to the cutoff, so the regularised compensation never exceeds
    /// atan(½) = 27° and at 6 Hz it differs from the exact one by 4.4 mrad.
    pub compensation_floor_hz: T,
}

impl<T: Real> Default for LpfIntegratorSettings<T> {
    fn default() -> Self {
        Self {
            cutoff_hz: T::lit(1.0),
            compensation_floor_hz: T::lit(1.0),
        }
    }
}

/// Configuration of [`LpfIntegratorEstimator`]: the machine model, the shared [`CommonTuning`](super::CommonTuning) and
/// [`LpfIntegratorSettings`].
pub type LpfIntegratorConfig<T> = BaselineConfig<T, LpfIntegratorSettings<T>>;

impl<T: Real> Baseline<T> for LpfIntegratorEstimator<T> {
    type Settings = LpfIntegratorSettings<T>;
    const NAME: &'static str = "lpf-integrator";
    fn from_config(config: LpfIntegratorConfig<T>) -> Result<Self, ConfigError> {
        Self::new(config)
    }
}

impl<T: Real> LpfIntegratorConfig<T> {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        LpfIntegratorEstimator::new(*self).map(|_| ())
    }
}

/// The compensated low-pass flux estimator (see the module docs), generic over `f32`/`f64`.
///
/// ```
/// use fado_core::{Ab, MachineModel};
/// use fado_core::baselines::{LpfIntegratorConfig, LpfIntegratorEstimator};
/// let mut est = LpfIntegratorEstimator::<f32>::new(LpfIntegratorConfig::for_machine(&MachineModel::paper())).unwrap();
/// let out = est.step(Ab::new(1.2, -0.3), Ab::new(4.0, 0.1));
/// assert!(!out.diagnostics.input_fault);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LpfIntegratorEstimator<T: Real> {
    config: LpfIntegratorConfig<T>,
    integrand: Integrand<T>,
    trackers: AngleTrackers<T>,
    /// ψ: the low-pass filtered integrand.
    psi: Ab<T>,
    /// ωc in rad/s.
    wc: T,
    /// ω_f² in (rad/s)².
    floor_sq: T,
    last: Estimate<T>,
    rejected_samples: u32,
}

impl<T: Real> LpfIntegratorEstimator<T> {
    /// Builds the estimator; every field of `config` is checked and a bad one is named.
    pub fn new(config: LpfIntegratorConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.common.ts)?;
        check::non_negative("lq", config.machine.lq)?;
        let integrand = integrand_of!(config.machine, config.common, ts)?;
        let lf = check::positive("flux_linkage", config.machine.flux_linkage)?;
        let fc = check::non_negative("cutoff_hz", config.settings.cutoff_hz)?;
        let wc = T::two_pi() * fc;
        check::below("cutoff_hz", wc * ts, T::one(), "2π·cutoff_hz·ts below 1")?;
        let floor = T::two_pi()
            * check::positive(
                "compensation_floor_hz",
                config.settings.compensation_floor_hz,
            )?;
        check::finite("initial_angle", config.common.initial_angle)?;
        let trackers = config.common.trackers(lf)?;
        let mut est = Self {
            config,
            integrand,
            trackers,
            psi: Ab::zero(),
            wc,
            floor_sq: floor * floor,
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

    /// Start-up at a known rotor angle θ0 with the present current: ψ = λ̂f·e^{jθ0} + L̂q·i
    /// (the compensation is 1 at ω̂ = 0, so λ̂s = ψ), θ̂ = θ0, ω̂ = 0.
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
        let lambda_r = Ab::from_polar(self.config.machine.flux_linkage, theta0);
        self.psi = lambda_r + i_ab * self.config.machine.lq;
        self.integrand.reset();
        self.integrand.note_current(i_ab);
        self.trackers.reset_to(theta0);
        self.rejected_samples = 0;
        self.last = Estimate {
            theta: self.trackers.angle(),
            diagnostics: Diagnostics {
                lambda1: self.psi,
                lambda2: self.psi,
                lambda_r,
                theta_direct: self.trackers.angle(),
                rs_hat: self.config.machine.rs,
                flux_linkage_hat: self.config.machine.flux_linkage,
                ..Diagnostics::default()
            },
            ..Estimate::default()
        };
    }

    /// The compensation factor 1 − j·(ωc/ω_d)·e^{−jω̂Ts/2} as a complex number (the exact
    /// discrete form of (jω̂ + ωc)/(jω̂), module docs), with 1/ω_d regularised to
    /// ω_d/(ω_d² + ω_f²).
    #[inline]
    pub fn compensation(&self, omega: T) -> Ab<T> {
        let ts = self.config.common.ts;
        let (sin_half, cos_half) = (omega * ts * T::lit(0.5)).sin_cos();
        let omega_d = T::lit(2.0) * sin_half / ts;
        let k = self.wc * omega_d / (omega_d * omega_d + self.floor_sq);
        Ab::new(T::one() - k * sin_half, -k * cos_half)
    }

    /// One sample: `v_ab` applied over the last interval, `i_ab` sampled now. A non-finite
    /// input is rejected: the state is untouched and the previous estimate is returned with
    /// `input_fault` set.
    #[inline]
    pub fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T> {
        self.guarded_step(v_ab, i_ab)
    }

    /// ψ, the low-pass filtered integrand (before compensation).
    pub fn filtered_flux(&self) -> Ab<T> {
        self.psi
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
    pub fn config(&self) -> &LpfIntegratorConfig<T> {
        &self.config
    }
}

impl<T: Real> GuardedStep<T> for LpfIntegratorEstimator<T> {
    #[inline]
    fn step_unchecked(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Option<Estimate<T>> {
        let u = self.integrand.next(v_ab, i_ab);
        let psi = self.psi + (u - self.psi * self.wc) * self.config.common.ts;
        let lambda_s = psi.complex_mul(self.compensation(self.trackers.speed()));
        let lambda_r = lambda_s - i_ab * self.config.machine.lq;
        if !(psi.is_finite() && lambda_r.is_finite()) {
            return None;
        }
        let mut trackers = self.trackers;
        let t = trackers.step(lambda_r)?;
        self.trackers = trackers;
        self.integrand.accept(i_ab);
        self.psi = psi;
        Some(Estimate {
            theta: t.theta,
            omega: t.omega,
            omega_control: t.omega_control,
            diagnostics: Diagnostics {
                lambda1: self.psi,
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

rotor_angle_estimator!(LpfIntegratorEstimator);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MachineModel;
    use crate::baselines::CommonTuning;

    #[test]
    fn config_errors_name_the_machine_field() {
        type C = LpfIntegratorConfig<f64>;
        let cases: [(C, &str); 3] = [
            (
                C::for_machine(&MachineModel {
                    rs: -1.0,
                    ..MachineModel::paper()
                }),
                "rs",
            ),
            (
                C::for_machine(&MachineModel {
                    lq: f64::NAN,
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
    fn config_errors_name_the_sampling_and_filter_field() {
        type C = LpfIntegratorConfig<f64>;
        let cases: [(C, &str); 3] = [
            (
                C {
                    common: CommonTuning {
                        ts: 0.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "ts",
            ),
            (
                C {
                    common: CommonTuning {
                        t2s1_bandwidth_hz: 5_000.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "t2s1_bandwidth_hz",
            ),
            (
                C {
                    common: CommonTuning {
                        t2s2_bandwidth_hz: f64::NAN,
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
        type C = LpfIntegratorConfig<f64>;
        let cases: [(C, &str); 4] = [
            (
                C {
                    common: CommonTuning {
                        tracker_damping: 0.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "tracker_damping",
            ),
            (
                C {
                    common: CommonTuning {
                        tracker_hold_ratio: 1.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "tracker_hold_ratio",
            ),
            (
                C {
                    common: CommonTuning {
                        tracker_hold_ratio: -0.1,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "tracker_hold_ratio",
            ),
            (
                C {
                    common: CommonTuning {
                        initial_angle: f64::INFINITY,
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
        type C = LpfIntegratorConfig<f64>;
        let cases: [(C, &str); 3] = [
            (
                C {
                    settings: LpfIntegratorSettings {
                        cutoff_hz: -1.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "cutoff_hz",
            ),
            (
                C {
                    settings: LpfIntegratorSettings {
                        cutoff_hz: 2_000.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "cutoff_hz",
            ),
            (
                C {
                    settings: LpfIntegratorSettings {
                        compensation_floor_hz: 0.0,
                        ..Default::default()
                    },
                    ..C::for_machine(&MachineModel::paper())
                },
                "compensation_floor_hz",
            ),
        ];
        for (config, field) in cases {
            assert_eq!(config.validate().unwrap_err().field(), field);
        }
        assert!(C::for_machine(&MachineModel::paper()).validate().is_ok());
        // ωc = 0 is the open integrator of eq. (3).
        assert!(
            C {
                settings: LpfIntegratorSettings {
                    cutoff_hz: 0.0,
                    ..Default::default()
                },
                ..C::for_machine(&MachineModel::paper())
            }
            .validate()
            .is_ok()
        );
    }

    /// z for a rotation by x, as (re, im).
    fn div(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
        let n = b.0 * b.0 + b.1 * b.1;
        ((a.0 * b.0 + a.1 * b.1) / n, (a.1 * b.0 - a.0 * b.1) / n)
    }

    #[test]
    fn compensation_is_the_exact_inverse_of_the_discrete_low_pass() {
        // LPF ψ/u = Ts/(1 − (1 − ωcTs)z⁻¹), integrator λ/u = Ts/(1 − z⁻¹): the compensation
        // must equal their ratio (1 − (1 − ωcTs)z⁻¹)/(1 − z⁻¹) at z = e^{jωTs} (floor → 0).
        let est = LpfIntegratorEstimator::new(LpfIntegratorConfig {
            settings: LpfIntegratorSettings {
                cutoff_hz: 3.0,
                compensation_floor_hz: 1e-9,
            },
            ..LpfIntegratorConfig::for_machine(&MachineModel::paper())
        })
        .unwrap();
        let (ts, wc): (f64, f64) = (1e-4, core::f64::consts::TAU * 3.0);
        for w in [-2_000.0, -300.0, -20.0, 5.0, 125.0, 3_000.0] {
            let (s, c) = (-w * ts).sin_cos(); // z⁻¹
            let ratio = div(
                (1.0 - (1.0 - wc * ts) * c, -(1.0 - wc * ts) * s),
                (1.0 - c, -s),
            );
            let got = est.compensation(w);
            assert!(
                (got.alpha - ratio.0).abs() < 1e-9 && (got.beta - ratio.1).abs() < 1e-9,
                "{w}: {got:?} vs {ratio:?}"
            );
        }
    }

    #[test]
    fn regularised_compensation_is_one_at_standstill_and_symmetric() {
        let est = LpfIntegratorEstimator::new(LpfIntegratorConfig::<f64>::for_machine(
            &MachineModel::paper(),
        ))
        .unwrap();
        assert_eq!(est.compensation(0.0), Ab::new(1.0, 0.0));
        for w in [0.5, 6.0, 40.0, 400.0] {
            let (p, n) = (est.compensation(w), est.compensation(-w));
            assert!((p.alpha - n.alpha).abs() < 1e-15 && (p.beta + n.beta).abs() < 1e-15);
            // Never more than atan(ωc/2ω_f) = atan(½) with the default floor = cutoff.
            assert!(p.beta.abs() / p.alpha <= 0.5 + 1e-9);
        }
    }

    #[test]
    fn dc_integrand_settles_at_eps_over_wc() {
        // The bounded drift that replaces the open integrator's ramp: ψ → ε/ωc.
        let mut est = LpfIntegratorEstimator::new(LpfIntegratorConfig::<f64> {
            machine: MachineModel {
                flux_linkage: 1e-3,
                ..LpfIntegratorConfig::for_machine(&MachineModel::paper()).machine
            },
            ..LpfIntegratorConfig::for_machine(&MachineModel::paper())
        })
        .unwrap();
        est.align(0.0, Ab::zero());
        let eps = Ab::new(0.05, -0.02);
        for _ in 0..20_000 {
            est.step(eps, Ab::zero());
        }
        let wc = core::f64::consts::TAU;
        let psi = est.filtered_flux();
        assert!(
            (psi - eps * (1.0 / wc)).norm() < 1e-3 * eps.norm() / wc,
            "{psi:?}"
        );
    }
}
