//! Baseline 4: the reduced-order flux observer of M. Hinkkanen, S. E. Saarakkala, H. A. A.
//! Awan, E. Mölsä and T. Tuovinen, "Observers for sensorless synchronous motor drives:
//! framework for design and analysis", IEEE Trans. Ind. Appl. 54(6), 2018
//! (doi:10.1109/TIA.2018.2858753), the sensorless observer of Aalto's motulator. Unlike the
//! other baselines it estimates the angle and the speed itself, in estimated rotor
//! coordinates, and it models saliency (L̂d ≠ L̂q).
//!
//! # Algorithm
//! In rotor coordinates the machine is dψ/dt = u − R·i − jω·ψ with ψ = L̂d·id + λ̂f + j·L̂q·iq.
//! The observer runs in the coordinates of its own angle θ̂ (x' = x·e^{−jθ̂}) and corrects
//! its flux with the flux error e = ψ̂(i') − ψ̂ read from the measured current:
//!
//! ```text
//! dψ̂/dt = u' − R̂s·i' − jωc·ψ̂ + k1·e + k2·e*        e = L̂d·i'd + λ̂f + j·L̂q·i'q − ψ̂
//! ε     = −Im{e/ψ̂a},      ψ̂a = λ̂f + (L̂d − L̂q)·i'*   (auxiliary flux)
//! ωc    = ω̂ + kθ·ε,       dθ̂/dt = ωc,      dω̂/dt = kω·ε
//! ```
//!
//! For a small angle error θ̃ = θ − θ̂ the flux error is e ≈ −j·ψ̂a·θ̃, so ε ≈ θ̃: the angle and
//! speed loop is a type-2 tracker of θ̃.
//!
//! # Gain design (the paper's)
//! The gains k1 = σ, k2 = σ·ψ̂a/ψ̂a* decouple the flux error from the angle: linearised at a
//! steady operating point the error dynamics have the characteristic polynomial
//!
//! ```text
//! D(s) = (s² + 2σ·s + ω²)·(s² + kθ·s + kω)
//! ```
//!
//! (the flux error ψ̃·e^{−j∠ψ̂a} = a + jb obeys ȧ = ωb − 2σa, ḃ = −ωa). With kθ = 2αo and
//! kω = αo² the angle and speed poles are a double pole at −αo at every speed; the
//! attenuation is scheduled on the speed, σ = σ0 + ζ∞·|ω̂| with σ0 = R̂s·(1/L̂d + 1/L̂q)/4, so
//! that at standstill the flux poles are 0 and −2σ0 (no unstable double pole at the origin,
//! a stable start) and at speed their damping tends to ζ∞ (tested: every pole at 0, ±2, ±20
//! and ±100 Hz on a surface and a salient machine, and convergence from a wrong start angle).
//! The defaults are motulator's: ζ∞ = 0.2 and αo = 2π·40 rad/s.
//!
//! # Discretisation
//! As motulator, the flux error, ε and the gains of sample n are formed from the current
//! i\[n−1\] at the start of the interval in the coordinates of θ̂\[n−1\], and θ̂ and ω̂ step
//! by forward Euler. The flux steps in the stator frame and is then rotated into the new
//! coordinates, λ̂s⁺ = λ̂s + Ts·(v* − R̂s·i + e^{jθ̂}·(k1·e + k2·e*)), ψ̂⁺ = e^{−jθ̂⁺}·λ̂s⁺, with
//! the integrand of the other baselines (the interval's averaged current): the rotation
//! −jωc·ψ̂ is then exact. Euler in the rotating frame, as motulator has it, leaves a standing
//! flux error of ω²·Ts·ψ/(2σ) per sample's worth of rotation, which reads as an angle error
//! (3.4 mrad on the paper's motor at 20 Hz, measured; test
//! `converges_from_a_wrong_initial_angle` bounds it at 1 mrad). Linearised, one sample is
//! I + Ts·A to first order in Ts (tested), and `new` requires αo·Ts ≤ ½. The control speed is
//! T2S-2 fed with θ̂, as for every estimator of the comparison.
//!
//! # Where it fails
//! - **Standstill.** One flux pole is at s = 0 there: the flux error along that direction,
//!   and with it the angle, is not corrected (the voltage model carries no information at
//!   zero speed); under load a wrong R̂s turns the angle at low speed.
//! - **Parameters.** λ̂f, L̂d and L̂q enter the flux error directly, so their errors bias the
//!   angle at every speed (the paper adapts λ̂f in an extension; not here).

use super::{Baseline, BaselineConfig, GuardedStep, Integrand, renamed};
use crate::error::{ConfigError, check};
use crate::estimator::{Diagnostics, Estimate, RotorAngleEstimator};
use crate::frames::Rotation;
use crate::tracker::{TrackerConfig, TypeTwoTracker};
use crate::{Ab, Real, wrap_angle};

/// Settings of [`ReducedOrderEstimator`] of its own (`[baselines.reduced_order]` in
/// `fado-sim`'s TOML): plain numbers whose defaults do not depend on the machine.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct ReducedOrderSettings<T> {
    /// αo in rad/s: the double pole of the angle and speed estimation (kθ = 2αo, kω = αo²);
    /// times the sampling period at most ½. Default 2π·40 rad/s (motulator's observer of the
    /// paper's design).
    pub speed_pole: T,
    /// ζ∞: the damping the flux poles tend to at high speed, σ = σ0 + ζ∞·|ω̂|. Default 0.2
    /// (motulator).
    pub high_speed_damping: T,
}

impl<T: Real> Default for ReducedOrderSettings<T> {
    fn default() -> Self {
        Self {
            speed_pole: T::lit(core::f64::consts::TAU * 40.0),
            high_speed_damping: T::lit(0.2),
        }
    }
}

/// Configuration of [`ReducedOrderEstimator`]: the machine model (R̂s, L̂d, L̂q, λ̂f, rated
/// current and DC link), the shared [`CommonTuning`](super::CommonTuning) and
/// [`ReducedOrderSettings`].
pub type ReducedOrderConfig<T> = BaselineConfig<T, ReducedOrderSettings<T>>;

impl<T: Real> ReducedOrderConfig<T> {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        ReducedOrderEstimator::new(*self).map(|_| ())
    }

    /// σ0 = R̂s·(1/L̂d + 1/L̂q)/4 in s⁻¹: the flux poles at standstill are 0 and −2σ0.
    pub fn sigma0(&self) -> T {
        let m = &self.machine;
        T::lit(0.25) * m.rs * (T::one() / m.ld + T::one() / m.lq)
    }

    /// The attenuation σ = σ0 + ζ∞·|ω̂| at the speed estimate ω̂ (rad/s).
    #[inline]
    pub fn sigma(&self, omega: T) -> T {
        self.sigma0() + self.settings.high_speed_damping * omega.abs()
    }
}

impl<T: Real> Baseline<T> for ReducedOrderEstimator<T> {
    type Settings = ReducedOrderSettings<T>;
    const NAME: &'static str = "reduced-order";
    fn from_config(config: ReducedOrderConfig<T>) -> Result<Self, ConfigError> {
        Self::new(config)
    }
}

/// The reduced-order observer of Hinkkanen et al. (see the module docs), generic over
/// `f32`/`f64`.
///
/// ```
/// use fado_core::{Ab, MachineModel};
/// use fado_core::baselines::{ReducedOrderConfig, ReducedOrderEstimator};
/// let config = ReducedOrderConfig::for_machine(&MachineModel::<f32>::paper());
/// let mut est = ReducedOrderEstimator::new(config).unwrap();
/// let out = est.step(Ab::new(1.2, -0.3), Ab::new(4.0, 0.1));
/// assert!(!out.diagnostics.input_fault);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReducedOrderEstimator<T: Real> {
    config: ReducedOrderConfig<T>,
    integrand: Integrand<T>,
    /// T2S-2 fed with θ̂: the control speed.
    t2s2: TypeTwoTracker<T>,
    /// ψ̂: the stator flux in the coordinates of θ̂ (alpha: d, beta: q).
    psi: Ab<T>,
    /// θ̂ (rad, wrapped) and its rotation.
    theta: T,
    rot: Rotation<T>,
    /// ω̂ (rad/s).
    omega: T,
    /// σ0, kθ = 2αo, kω = αo².
    sigma0: T,
    k_theta: T,
    k_omega: T,
    last: Estimate<T>,
    rejected_samples: u32,
}

/// The observer's state after one sample.
struct Next<T> {
    psi: Ab<T>,
    theta: T,
    rot: Rotation<T>,
    omega: T,
}

impl<T: Real> ReducedOrderEstimator<T> {
    /// Builds the estimator; every field of `config` is checked and a bad one is named.
    pub fn new(config: ReducedOrderConfig<T>) -> Result<Self, ConfigError> {
        let (m, c, s) = (&config.machine, &config.common, &config.settings);
        let ts = check::positive("ts", c.ts)?;
        check::positive("ld", m.ld)?;
        check::positive("lq", m.lq)?;
        let integrand = integrand_of!(config.machine, config.common, ts)?;
        check::positive("flux_linkage", m.flux_linkage)?;
        let alpha = check::positive("speed_pole", s.speed_pole)?;
        check::below(
            "speed_pole",
            alpha * ts,
            T::lit(0.5000001),
            "speed_pole·ts at most ½",
        )?;
        check::non_negative("high_speed_damping", s.high_speed_damping)?;
        check::finite("initial_angle", c.initial_angle)?;
        let sigma0 = config.sigma0();
        check::finite("rs", sigma0)?;
        check::positive("tracker_damping", c.tracker_damping)?;
        let t2s2 = TypeTwoTracker::new(TrackerConfig {
            ts,
            bandwidth_hz: c.t2s2_bandwidth_hz,
            damping: c.tracker_damping,
            definition: c.bandwidth_definition,
        })
        .map_err(renamed("t2s2_bandwidth_hz"))?;
        let mut est = Self {
            config,
            integrand,
            t2s2,
            psi: Ab::zero(),
            theta: T::zero(),
            rot: Rotation::from_angle(T::zero()),
            omega: T::zero(),
            sigma0,
            k_theta: T::lit(2.0) * alpha,
            k_omega: alpha * alpha,
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

    /// Start-up at a known rotor angle θ0 with the present current: ψ̂ = ψ̂(i'), θ̂ = θ0,
    /// ω̂ = 0.
    pub fn align(&mut self, theta0: T, i_ab: Ab<T>) {
        let m = self.config.machine;
        let theta0 = if theta0.is_finite() {
            wrap_angle(theta0)
        } else {
            T::zero()
        };
        let i_ab = super::usable_align_current(i_ab, m.ld.max(m.lq), m.flux_linkage);
        self.theta = theta0;
        self.rot = Rotation::from_angle(theta0);
        self.omega = T::zero();
        self.psi = self.flux_of(rotor(i_ab, self.rot));
        self.integrand.reset();
        self.integrand.note_current(i_ab);
        self.t2s2.reset_to(theta0, T::zero());
        self.rejected_samples = 0;
        let lambda_s = stator(self.psi, self.rot);
        self.last = Estimate {
            theta: theta0,
            diagnostics: Diagnostics {
                lambda1: lambda_s,
                lambda2: lambda_s,
                lambda_r: Ab::from_polar(m.flux_linkage, theta0),
                theta_direct: theta0,
                rs_hat: m.rs,
                flux_linkage_hat: m.flux_linkage,
                ..Diagnostics::default()
            },
            ..Estimate::default()
        };
    }

    /// One sample: `v_ab` applied over the last interval, `i_ab` sampled now. A non-finite or
    /// implausible input is rejected: the state is untouched and the previous estimate is
    /// returned with `input_fault` set.
    #[inline]
    pub fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T> {
        self.guarded_step(v_ab, i_ab)
    }

    /// θ̂ (rad), ω̂ (rad/s) and ψ̂ in the coordinates of θ̂ (alpha: d, beta: q).
    pub fn state(&self) -> (T, T, Ab<T>) {
        (self.theta, self.omega, self.psi)
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
    pub fn config(&self) -> &ReducedOrderConfig<T> {
        &self.config
    }

    /// ψ̂(i) = L̂d·id + λ̂f + j·L̂q·iq of a rotor-frame current.
    #[inline]
    fn flux_of(&self, i: Ab<T>) -> Ab<T> {
        let m = &self.config.machine;
        Ab::new(m.ld * i.alpha + m.flux_linkage, m.lq * i.beta)
    }

    /// One Euler step of the observer over the interval that ends at this sample (the state
    /// is not changed).
    #[inline]
    fn advance(&self, v_ab: Ab<T>, i_ab: Ab<T>) -> Next<T> {
        let m = &self.config.machine;
        let ts = self.config.common.ts;
        // The flux error at the start of the interval, in the coordinates of θ̂[n−1].
        let i_start = self.integrand.previous_current().unwrap_or(i_ab);
        let i = rotor(i_start, self.rot);
        let e = self.flux_of(i) - self.psi;
        let dl = m.ld - m.lq;
        let psi_a = Ab::new(m.flux_linkage + dl * i.alpha, -dl * i.beta);
        let psi_a_sq = psi_a.norm_squared();
        // ε = −Im{e/ψ̂a} = −Im{e·ψ̂a*}/|ψ̂a|²; none while ψ̂a vanishes (as motulator).
        let eps = if psi_a_sq > T::zero() {
            -(psi_a.alpha * e.beta - psi_a.beta * e.alpha) / psi_a_sq
        } else {
            T::zero()
        };
        let omega_c = self.omega + self.k_theta * eps;
        // σ·e + σ·(ψ̂a/ψ̂a*)·e*, with ψ̂a/ψ̂a* = ψ̂a²/|ψ̂a|².
        let sigma = self.sigma0 + self.config.settings.high_speed_damping * self.omega.abs();
        let k2 = if psi_a_sq > T::zero() {
            psi_a.complex_mul(psi_a) * (sigma / psi_a_sq)
        } else {
            Ab::new(sigma, T::zero())
        };
        let correction = e * sigma + k2.complex_mul(Ab::new(e.alpha, -e.beta));
        // The voltage model and the correction move the flux in the stator frame; the new
        // coordinates are those of the new angle (the rotation −jωc·ψ̂ taken exactly).
        let du = self.integrand.next(v_ab, i_ab) + stator(correction, self.rot);
        let lambda_s = stator(self.psi, self.rot) + du * ts;
        let theta = wrap_angle(self.theta + omega_c * ts);
        let rot = Rotation::from_angle(theta);
        Next {
            psi: rotor(lambda_s, rot),
            theta,
            rot,
            omega: self.omega + self.k_omega * eps * ts,
        }
    }
}

/// x·e^{−jθ} of a stator-frame vector (alpha: d, beta: q).
#[inline]
fn rotor<T: Real>(x: Ab<T>, rot: Rotation<T>) -> Ab<T> {
    let dq = x.to_dq(rot);
    Ab::new(dq.d, dq.q)
}

/// x·e^{jθ} of a rotor-frame vector (alpha: d, beta: q).
#[inline]
fn stator<T: Real>(x: Ab<T>, rot: Rotation<T>) -> Ab<T> {
    x.complex_mul(rot.unit())
}

impl<T: Real> GuardedStep<T> for ReducedOrderEstimator<T> {
    #[inline]
    fn step_unchecked(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Option<Estimate<T>> {
        let next = self.advance(v_ab, i_ab);
        if !(next.psi.is_finite() && next.theta.is_finite() && next.omega.is_finite()) {
            return None;
        }
        let mut t2s2 = self.t2s2;
        let (_, omega_control) = t2s2.step(next.theta).ok()?;
        let rot = next.rot;
        let m = &self.config.machine;
        let i = rotor(i_ab, rot);
        let lambda_r_dq = next.psi - Ab::new(m.ld * i.alpha, m.lq * i.beta);
        let lambda_s = stator(next.psi, rot);
        self.t2s2 = t2s2;
        self.integrand.accept(i_ab);
        self.psi = next.psi;
        self.theta = next.theta;
        self.rot = rot;
        self.omega = next.omega;
        Some(Estimate {
            theta: next.theta,
            omega: next.omega,
            omega_control,
            diagnostics: Diagnostics {
                lambda1: lambda_s,
                lambda2: lambda_s,
                lambda_r: stator(lambda_r_dq, rot),
                theta_direct: next.theta,
                rs_hat: m.rs,
                flux_linkage_hat: m.flux_linkage,
                ..Diagnostics::default()
            },
        })
    }

    guarded_state!();
}

rotor_angle_estimator!(ReducedOrderEstimator);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MachineModel;
    use crate::baselines::CommonTuning;

    /// The paper's surface motor and motulator's 2.2 kW IPMSM (L̂q/L̂d 1.42).
    fn machines() -> [MachineModel<f64>; 2] {
        let ipmsm = MachineModel {
            rs: 3.6,
            ld: 0.036,
            lq: 0.051,
            flux_linkage: 0.545,
            pole_pairs: 3,
            rated_current: 5.0 * core::f64::consts::SQRT_2,
            rated_speed_rpm: 1500.0,
            rated_torque: 14.0,
            dc_voltage: 540.0,
            ..MachineModel::paper()
        };
        [MachineModel::paper(), ipmsm]
    }

    /// The samples of an ideal machine turning at ω (rad/s) with the rotor-frame current
    /// `i_dq` (A, alpha: d, beta: q): (v over [n−1, n], i[n]) at sample n, with the voltage
    /// the interval's average so that the averaged-current integrand is exact.
    fn machine_sample(
        m: &MachineModel<f64>,
        w: f64,
        i_dq: Ab<f64>,
        theta0: f64,
        n: u32,
    ) -> (Ab<f64>, Ab<f64>) {
        let ts = 1e-4;
        let th = |k: f64| theta0 + w * ts * k;
        let at = |k: f64| Rotation::from_angle(th(k));
        let psi = Ab::new(m.ld * i_dq.alpha + m.flux_linkage, m.lq * i_dq.beta);
        let (n0, n1) = (f64::from(n) - 1.0, f64::from(n));
        let (i0, i1) = (stator(i_dq, at(n0)), stator(i_dq, at(n1)));
        let dlambda = stator(psi, at(n1)) - stator(psi, at(n0));
        (dlambda * (1.0 / ts) + (i0 + i1) * (0.5 * m.rs), i1)
    }

    fn config(m: &MachineModel<f64>) -> ReducedOrderConfig<f64> {
        ReducedOrderConfig::for_machine(m)
    }

    #[test]
    fn config_errors_name_the_field() {
        let m = MachineModel::paper();
        let c = config(&m);
        let cases: [(ReducedOrderConfig<f64>, &str); 7] = [
            (config(&MachineModel { ld: 0.0, ..m }), "ld"),
            (config(&MachineModel { lq: f64::NAN, ..m }), "lq"),
            (
                config(&MachineModel {
                    flux_linkage: -0.1,
                    ..m
                }),
                "flux_linkage",
            ),
            (config(&MachineModel { rs: -1.0, ..m }), "rs"),
            (
                ReducedOrderConfig {
                    settings: ReducedOrderSettings {
                        speed_pole: 6000.0,
                        ..c.settings
                    },
                    ..c
                },
                "speed_pole",
            ),
            (
                ReducedOrderConfig {
                    settings: ReducedOrderSettings {
                        high_speed_damping: -0.1,
                        ..c.settings
                    },
                    ..c
                },
                "high_speed_damping",
            ),
            (
                ReducedOrderConfig {
                    common: CommonTuning {
                        t2s2_bandwidth_hz: 0.0,
                        ..c.common
                    },
                    ..c
                },
                "t2s2_bandwidth_hz",
            ),
        ];
        for (config, field) in cases {
            assert_eq!(config.validate().unwrap_err().field(), field);
        }
        assert_eq!(c.validate(), Ok(()));
    }

    /// The state (ψ̂d, ψ̂q, θ̂ − θ, ω̂ − ω) as a vector.
    fn state_vec(est: &ReducedOrderEstimator<f64>, theta: f64, w: f64) -> [f64; 4] {
        let (th, om, psi) = est.state();
        [psi.alpha, psi.beta, wrap_angle(th - theta), om - w]
    }

    fn set_state(est: &mut ReducedOrderEstimator<f64>, x: [f64; 4], theta: f64, w: f64) {
        est.psi = Ab::new(x[0], x[1]);
        est.theta = wrap_angle(theta + x[2]);
        est.rot = Rotation::from_angle(est.theta);
        est.omega = w + x[3];
    }

    /// The Jacobian of one step of the error dynamics at its steady state, by central
    /// differences.
    fn jacobian(m: &MachineModel<f64>, w: f64, i_dq: Ab<f64>) -> [[f64; 4]; 4] {
        let mut est = ReducedOrderEstimator::new(config(m)).unwrap();
        let ts = 1e-4;
        est.align(0.0, machine_sample(m, w, i_dq, 0.0, 0).1);
        est.omega = w;
        // Settle at the operating point (the error dynamics' own fixed point).
        let n0 = 40_000;
        for n in 1..=n0 {
            let (v, i) = machine_sample(m, w, i_dq, 0.0, n);
            est.step(v, i);
        }
        let theta = |n: u32| w * ts * f64::from(n);
        let x0 = state_vec(&est, theta(n0), w);
        let (v, i) = machine_sample(m, w, i_dq, 0.0, n0 + 1);
        let mut jac = [[0.0; 4]; 4];
        let scale = [1e-6, 1e-6, 1e-6, 1e-3];
        for k in 0..4 {
            let mut next = [[0.0; 4]; 2];
            for (s, sign) in [1.0, -1.0].into_iter().enumerate() {
                let mut e = est;
                let mut x = x0;
                x[k] += sign * scale[k];
                set_state(&mut e, x, theta(n0), w);
                e.step(v, i);
                next[s] = state_vec(&e, theta(n0 + 1), w);
            }
            for r in 0..4 {
                jac[r][k] = (next[0][r] - next[1][r]) / (2.0 * scale[k]);
            }
        }
        jac
    }

    type C = (f64, f64);
    fn cmul(a: C, b: C) -> C {
        (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
    }
    fn cdiv(a: C, b: C) -> C {
        let d = b.0 * b.0 + b.1 * b.1;
        ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
    }

    /// The coefficients of Π(s − p), highest power first.
    fn poly(roots: &[C]) -> [C; 5] {
        let mut c: [C; 5] = [(1.0, 0.0), (0.0, 0.0), (0.0, 0.0), (0.0, 0.0), (0.0, 0.0)];
        for (n, r) in roots.iter().enumerate() {
            for k in (1..=n + 1).rev() {
                let t = cmul(c[k - 1], *r);
                c[k] = (c[k].0 - t.0, c[k].1 - t.1);
            }
        }
        c
    }

    /// The eigenvalues of a 4×4 matrix: the characteristic polynomial (Faddeev–LeVerrier),
    /// then its roots (Durand–Kerner).
    fn eigenvalues(a: [[f64; 4]; 4]) -> [C; 4] {
        let mul = |x: &[[f64; 4]; 4], y: &[[f64; 4]; 4]| {
            let mut z = [[0.0; 4]; 4];
            for r in 0..4 {
                for c in 0..4 {
                    z[r][c] = (0..4).map(|k| x[r][k] * y[k][c]).sum();
                }
            }
            z
        };
        let mut coef = [1.0, 0.0, 0.0, 0.0, 0.0];
        let mut mk = [[0.0; 4]; 4];
        for k in 1..=4 {
            let mut next = mul(&a, &mk);
            for (r, row) in next.iter_mut().enumerate() {
                row[r] += coef[k - 1];
            }
            mk = next;
            let am = mul(&a, &mk);
            coef[k] = -(0..4).map(|r| am[r][r]).sum::<f64>() / k as f64;
        }
        let p = |z: C| {
            let mut acc = (1.0, 0.0);
            for c in &coef[1..] {
                acc = cmul(acc, z);
                acc.0 += c;
            }
            acc
        };
        let mut roots: [C; 4] = [(0.4, 0.9), (0.9, -0.3), (-0.5, 0.2), (0.1, -0.8)];
        for _ in 0..500 {
            for k in 0..4 {
                let mut d = (1.0, 0.0);
                for j in 0..4 {
                    if j != k {
                        d = cmul(d, (roots[k].0 - roots[j].0, roots[k].1 - roots[j].1));
                    }
                }
                let step = cdiv(p(roots[k]), d);
                roots[k] = (roots[k].0 - step.0, roots[k].1 - step.1);
            }
        }
        roots
    }

    /// The poles of the error dynamics are the design's at every speed, on a surface and a
    /// salient machine, loaded: the roots of s² + 2σ·s + ω² (flux) and the double pole −αo
    /// (angle and speed), through the step's discretisation, against the discrete step's
    /// eigenvalues λ; all inside the unit circle but the standstill flux pole at s = 0.
    #[test]
    fn error_dynamics_poles_are_the_design_at_every_speed() {
        let ts = 1e-4;
        for m in machines() {
            let c = config(&m);
            let alpha = c.settings.speed_pole;
            for f in [0.0, 2.0, -2.0, 20.0, -20.0, 100.0] {
                let w = core::f64::consts::TAU * f;
                let i_dq = Ab::new(-0.1 * m.rated_current, 0.5 * m.rated_current);
                let lambdas = eigenvalues(jacobian(&m, w, i_dq));
                let sigma = c.sigma(w);
                let disc = sigma * sigma - w * w;
                let flux: [C; 2] = if disc >= 0.0 {
                    [(-sigma + disc.sqrt(), 0.0), (-sigma - disc.sqrt(), 0.0)]
                } else {
                    [(-sigma, (-disc).sqrt()), (-sigma, -(-disc).sqrt())]
                };
                // The step's own mappings: the flux rotates exactly (λ = e^{p·Ts}), the angle
                // and speed step by Euler (λ = 1 + p·Ts); compared as (λ − 1)/Ts.
                let exact = |p: C| {
                    let r = (p.0 * ts).exp();
                    ((r * (p.1 * ts).cos() - 1.0) / ts, r * (p.1 * ts).sin() / ts)
                };
                let expected = [exact(flux[0]), exact(flux[1]), (-alpha, 0.0), (-alpha, 0.0)];
                let poles: std::vec::Vec<C> = lambdas
                    .iter()
                    .map(|l| ((l.0 - 1.0) / ts, l.1 / ts))
                    .collect();
                // The double pole −αo splits under O(Ts) perturbations by their square
                // root: compare the polynomials Π(s − p), coefficient by coefficient.
                let (want, got) = (poly(&expected), poly(&poles));
                let scale = alpha.max(sigma).max(w.abs());
                for k in 1..5 {
                    let tol = 0.01 * (want[k].0.abs() + scale.powi(k as i32) * 0.01);
                    assert!(
                        (got[k].0 - want[k].0).abs() < tol && got[k].1.abs() < tol,
                        "{f} Hz, ld {}: s^{} coefficient {:?} vs {:?} (poles {poles:?})",
                        m.ld,
                        4 - k,
                        got[k],
                        want[k]
                    );
                }
                for l in lambdas {
                    assert!(
                        l.0.hypot(l.1) < 1.0 + 1e-6,
                        "{f} Hz: |λ| = {}",
                        l.0.hypot(l.1)
                    );
                }
            }
        }
    }

    /// From an angle 1 rad off (either side) and ω̂ = 0, the observer finds the angle and the
    /// speed of a loaded machine turning at ±20 Hz, surface and salient alike; aligned, it
    /// holds them at 2, 20 and 100 Hz (no discretisation bias above 1 mrad).
    #[test]
    fn converges_from_a_wrong_initial_angle() {
        for m in machines() {
            for (f, offset) in [
                (20.0, 0.0),
                (20.0, 1.0),
                (20.0, -1.0),
                (-20.0, 1.0),
                (2.0, 0.0),
                (100.0, 0.0),
            ] {
                let w = core::f64::consts::TAU * f;
                let i_dq = Ab::new(0.0, 0.5 * m.rated_current);
                let mut est = ReducedOrderEstimator::new(config(&m)).unwrap();
                est.align(offset, machine_sample(&m, w, i_dq, 0.0, 0).1);
                let mut worst_late: f64 = 0.0;
                for n in 1..=10_000 {
                    let (v, i) = machine_sample(&m, w, i_dq, 0.0, n);
                    let out = est.step(v, i);
                    let err = wrap_angle(w * 1e-4 * f64::from(n) - out.theta).abs();
                    if n > 5_000 {
                        worst_late = worst_late.max(err).max((out.omega - w).abs() / w.abs());
                    }
                }
                assert!(
                    worst_late < 1e-3,
                    "{f} Hz, {offset} rad, ld {}: {worst_late}",
                    m.ld
                );
            }
        }
    }

    /// Non-finite, overflowing and implausible samples are refused with the state untouched,
    /// as by every baseline.
    #[test]
    fn rejects_bad_samples() {
        let config = ReducedOrderConfig::for_machine(&MachineModel::<f32>::paper());
        crate::baselines::tests::rejects_bad_samples(ReducedOrderEstimator::new(config).unwrap());
    }

    /// At standstill without current the flux poles are 0 and −2σ0: an aligned observer
    /// stays where it is (nothing to correct, nothing drifts).
    #[test]
    fn holds_an_aligned_standstill() {
        let m = MachineModel::paper();
        let mut est = ReducedOrderEstimator::new(config(&m)).unwrap();
        est.align(0.7, Ab::zero());
        for _ in 0..10_000 {
            let out = est.step(Ab::zero(), Ab::zero());
            assert!((out.theta - 0.7).abs() < 1e-12 && out.omega.abs() < 1e-12);
        }
    }
}
