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

use super::{AngleTrackers, GuardedStep, Integrand, TrackerSettings};
use crate::error::{ConfigError, check};
use crate::estimator::{Diagnostics, Estimate, RotorAngleEstimator};
use crate::tracker::BandwidthDefinition;
use crate::{Ab, Real};

/// Configuration of [`LpfIntegratorEstimator`]; flat like [`crate::EstimatorConfig`], whose
/// shared fields have the same names and defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LpfIntegratorConfig<T> {
    /// Sampling period Ts in s. Default 100 µs (paper, V).
    pub ts: T,
    /// Stator resistance estimate R̂s in Ω. From the machine model.
    pub rs_hat: T,
    /// q-axis inductance estimate L̂q in H (eq. (5)). From the machine model.
    pub lq_hat: T,
    /// Magnet flux linkage estimate λ̂f in Wb; sets the start-up flux and the tracker hold
    /// level only. From the machine model.
    pub flux_linkage_hat: T,
    /// Cutoff fc of the low-pass integrator 1/(s + 2π·fc) in Hz; 0 gives the open integrator
    /// of eq. (3). Default 1 Hz \[A\]: one sixth of the 6 Hz electrical speed of the paper's
    /// ±90 r/min tests (compensation 9.5° there), while a DC integrand error ε leaves a bounded
    /// flux error ε/ωc (50 mV → 8 mWb, 9 % of λf).
    pub cutoff_hz: T,
    /// Speed floor f_f of the regularised compensation ωc·ω̂/(ω̂² + ω_f²) in Hz (module docs).
    /// Default 1 Hz \[A\]: equal to the cutoff, so the regularised compensation never exceeds
    /// atan(½) = 27° and at 6 Hz it differs from the exact one by 4.4 mrad.
    pub compensation_floor_hz: T,
    /// Bandwidth of T2S-1 in Hz. Default 60 Hz (paper, V), as fado.
    pub t2s1_bandwidth_hz: T,
    /// Bandwidth of T2S-2 in Hz. Default 35 Hz (paper, V), as fado.
    pub t2s2_bandwidth_hz: T,
    /// Damping ratio of both trackers. Default 1/√2 (SPEC §3 \[A\]).
    pub tracker_damping: T,
    /// Meaning of the tracker bandwidths. Default −3 dB (SPEC §3).
    pub bandwidth_definition: BandwidthDefinition,
    /// Trackers coast while |λ̂r| is below this fraction of λ̂f. Default 0.2 (SPEC §3 \[A\]).
    pub tracker_hold_ratio: T,
    /// Average the current over the interval for the resistive drop. Default true (SPEC §1
    /// \[A\]).
    pub average_current: bool,
    /// Rated (peak) phase current in A, the unit of `plausible_current_ratio`. From the
    /// machine model.
    pub rated_current: T,
    /// DC-link voltage in V, the unit of `plausible_voltage_ratio`. From the machine model.
    pub dc_voltage: T,
    /// Samples with |i| above this × `rated_current` are refused (see
    /// [`crate::plausibility`]). Default 4, as fado's
    /// ([`crate::EstimatorTuning::plausible_current_ratio`]).
    pub plausible_current_ratio: T,
    /// Samples with |v| above this × `dc_voltage` are refused. Default 1.5, as fado's.
    pub plausible_voltage_ratio: T,
    /// A current that moved by more than this × (plausible voltage)·ts/L̂q per sample is
    /// refused; 0 switches the test off. Default 2, as fado's.
    pub plausible_current_step_ratio: T,
    /// Rotor angle assumed at reset (rad). Default 0 (SPEC §1 \[A\]).
    pub initial_angle: T,
}

impl<T: Real> LpfIntegratorConfig<T> {
    /// The default tuning around `machine` (its R̂s, L̂q and λ̂f), sampled at 10 kHz.
    pub fn for_machine(machine: &crate::MachineModel<T>) -> Self {
        Self {
            ts: T::lit(100e-6),
            rs_hat: machine.rs,
            lq_hat: machine.lq,
            flux_linkage_hat: machine.flux_linkage,
            cutoff_hz: T::lit(1.0),
            compensation_floor_hz: T::lit(1.0),
            t2s1_bandwidth_hz: T::lit(60.0),
            t2s2_bandwidth_hz: T::lit(35.0),
            tracker_damping: T::lit(core::f64::consts::FRAC_1_SQRT_2),
            bandwidth_definition: BandwidthDefinition::Minus3Db,
            tracker_hold_ratio: T::lit(0.2),
            average_current: true,
            rated_current: machine.rated_current,
            dc_voltage: machine.dc_voltage,
            plausible_current_ratio: T::lit(crate::plausibility::CURRENT_RATIO),
            plausible_voltage_ratio: T::lit(crate::plausibility::VOLTAGE_RATIO),
            plausible_current_step_ratio: T::lit(crate::plausibility::STEP_RATIO),
            initial_angle: T::zero(),
        }
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
        let ts = check::positive("ts", config.ts)?;
        check::non_negative("lq_hat", config.lq_hat)?;
        let integrand = integrand_of!(config, ts)?;
        let lf = check::positive("flux_linkage_hat", config.flux_linkage_hat)?;
        let fc = check::non_negative("cutoff_hz", config.cutoff_hz)?;
        let wc = T::two_pi() * fc;
        check::below("cutoff_hz", wc * ts, T::one(), "2π·cutoff_hz·ts below 1")?;
        let floor =
            T::two_pi() * check::positive("compensation_floor_hz", config.compensation_floor_hz)?;
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
            psi: Ab::zero(),
            wc,
            floor_sq: floor * floor,
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

    /// Start-up at a known rotor angle θ0 with the present current: ψ = λ̂f·e^{jθ0} + L̂q·i
    /// (the compensation is 1 at ω̂ = 0, so λ̂s = ψ), θ̂ = θ0, ω̂ = 0.
    pub fn align(&mut self, theta0: T, i_ab: Ab<T>) {
        let theta0 = if theta0.is_finite() {
            theta0
        } else {
            T::zero()
        };
        let i_ab =
            super::usable_align_current(i_ab, self.config.lq_hat, self.config.flux_linkage_hat);
        let lambda_r = Ab::from_polar(self.config.flux_linkage_hat, theta0);
        self.psi = lambda_r + i_ab * self.config.lq_hat;
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
                rs_hat: self.config.rs_hat,
                flux_linkage_hat: self.config.flux_linkage_hat,
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
        let ts = self.config.ts;
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
        let psi = self.psi + (u - self.psi * self.wc) * self.config.ts;
        let lambda_s = psi.complex_mul(self.compensation(self.trackers.speed()));
        let lambda_r = lambda_s - i_ab * self.config.lq_hat;
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
                rs_hat: self.config.rs_hat,
                flux_linkage_hat: self.config.flux_linkage_hat,
                ..Diagnostics::default()
            },
        })
    }

    fn record(&mut self) -> (&mut Estimate<T>, &mut u32) {
        (&mut self.last, &mut self.rejected_samples)
    }
    fn integrand(&mut self) -> &mut Integrand<T> {
        &mut self.integrand
    }
}

impl<T: Real> RotorAngleEstimator<T> for LpfIntegratorEstimator<T> {
    #[inline]
    fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T> {
        LpfIntegratorEstimator::step(self, v_ab, i_ab)
    }
    fn align(&mut self, theta0: T, i_ab: Ab<T>) {
        LpfIntegratorEstimator::align(self, theta0, i_ab)
    }
    fn reset(&mut self) {
        LpfIntegratorEstimator::reset(self)
    }
    fn name(&self) -> &'static str {
        "lpf-integrator"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MachineModel;

    #[test]
    fn config_errors_name_the_field() {
        type C = LpfIntegratorConfig<f64>;
        let cases: [(C, &str); 13] = [
            (
                C {
                    ts: 0.0,
                    ..C::for_machine(&MachineModel::paper())
                },
                "ts",
            ),
            (
                C {
                    rs_hat: -1.0,
                    ..C::for_machine(&MachineModel::paper())
                },
                "rs_hat",
            ),
            (
                C {
                    lq_hat: f64::NAN,
                    ..C::for_machine(&MachineModel::paper())
                },
                "lq_hat",
            ),
            (
                C {
                    flux_linkage_hat: 0.0,
                    ..C::for_machine(&MachineModel::paper())
                },
                "flux_linkage_hat",
            ),
            (
                C {
                    cutoff_hz: -1.0,
                    ..C::for_machine(&MachineModel::paper())
                },
                "cutoff_hz",
            ),
            (
                C {
                    cutoff_hz: 2_000.0,
                    ..C::for_machine(&MachineModel::paper())
                },
                "cutoff_hz",
            ),
            (
                C {
                    compensation_floor_hz: 0.0,
                    ..C::for_machine(&MachineModel::paper())
                },
                "compensation_floor_hz",
            ),
            (
                C {
                    t2s1_bandwidth_hz: 5_000.0,
                    ..C::for_machine(&MachineModel::paper())
                },
                "t2s1_bandwidth_hz",
            ),
            (
                C {
                    t2s2_bandwidth_hz: f64::NAN,
                    ..C::for_machine(&MachineModel::paper())
                },
                "t2s2_bandwidth_hz",
            ),
            (
                C {
                    tracker_damping: 0.0,
                    ..C::for_machine(&MachineModel::paper())
                },
                "tracker_damping",
            ),
            (
                C {
                    tracker_hold_ratio: 1.0,
                    ..C::for_machine(&MachineModel::paper())
                },
                "tracker_hold_ratio",
            ),
            (
                C {
                    tracker_hold_ratio: -0.1,
                    ..C::for_machine(&MachineModel::paper())
                },
                "tracker_hold_ratio",
            ),
            (
                C {
                    initial_angle: f64::INFINITY,
                    ..C::for_machine(&MachineModel::paper())
                },
                "initial_angle",
            ),
        ];
        for (config, field) in cases {
            assert_eq!(config.validate().unwrap_err().field(), field);
        }
        assert!(C::for_machine(&MachineModel::paper()).validate().is_ok());
        // ωc = 0 is the open integrator of eq. (3).
        assert!(
            C {
                cutoff_hz: 0.0,
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
            cutoff_hz: 3.0,
            compensation_floor_hz: 1e-9,
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
            flux_linkage_hat: 1e-3,
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
