//! Speed control of Fig. 5: a PI from the speed error to the q-axis current reference, and
//! the current-vector limit shared with the d-axis injection of eq. (23).
//!
//! Gains (docs/method/estimator.md, "The paper's motor and drive"): Kp = Ĵ·ωsc/K̂t, Ki = Kp·ωsc/5 with ωsc = 2π·5 Hz (paper, V) and
//! K̂t = 1.5·p·λ̂f. With an ideal current loop the open loop is ωsc·(s + ωsc/5)/s²: crossover
//! ≈ ωsc and atan(5) = 79° of phase margin. Those gains are per *mechanical* rad/s; the
//! controller works in electrical rad/s (the estimator's unit), so it divides Kp and Ki by p.

use crate::control::pi::{Pi, PiConfig};
use crate::error::{ConfigError, NonFiniteInput, check};
use crate::machine::PAPER_RATED_CURRENT;
use crate::{Dq, MachineModel, Real};

/// Default speed-loop bandwidth in Hz: 5 (paper, V).
pub const DEFAULT_BANDWIDTH_HZ: f64 = 5.0;
/// Default ratio of the crossover to the PI zero: 5 (docs/method/estimator.md, "The paper's
/// motor and drive").
pub const DEFAULT_ZERO_RATIO: f64 = 5.0;
/// Default back-calculation gain in units of Ki/Kp: 5, tracking at ωsc \[A\] (see
/// [`SpeedControllerConfig::anti_windup_ratio`]).
pub const DEFAULT_ANTI_WINDUP_RATIO: f64 = 5.0;
/// Default current limit I_max as a multiple of the rated current: 40/21.78
/// (docs/method/estimator.md, "The paper's motor and drive" \[A\]: 40 A on the paper's motor).
pub const DEFAULT_CURRENT_LIMIT_RATIO: f64 = 40.0 / PAPER_RATED_CURRENT;

/// Configuration of a [`SpeedController`].
///
/// No `Default`: Ĵ, λ̂f, p and the current limit are the motor's. Build it with
/// [`for_machine`](Self::for_machine); each field's "Default" is what it gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedControllerConfig<T> {
    /// Sampling period Ts in s (paper, V: 100 µs; the loop runs every sample).
    pub ts: T,
    /// Pole pairs p: the machine model's (the paper's motor: 4, 8 poles).
    pub pole_pairs: T,
    /// Inertia estimate Ĵ in kg·m²: the machine model's (the paper's motor: 0.012, docs/method/estimator.md, "The paper's motor and drive"
    /// \[A\]).
    pub inertia_hat: T,
    /// Magnet flux linkage estimate λ̂f in Wb, for K̂t = 1.5·p·λ̂f: the machine model's (the
    /// paper's motor: 0.088, docs/method/estimator.md, "The paper's motor and drive" \[A\]).
    pub flux_linkage_hat: T,
    /// Speed-loop bandwidth in Hz. Default [`DEFAULT_BANDWIDTH_HZ`] (5 Hz, paper V).
    pub bandwidth_hz: T,
    /// Ratio ωsc/(Ki/Kp): the PI zero sits this many times below the crossover. Default 5
    /// (docs/method/estimator.md, "The paper's motor and drive": Ki = Kp·2π·5/5; [`DEFAULT_ZERO_RATIO`]).
    pub zero_ratio: T,
    /// Output limit in A of q current (in units of the magnet's q current on a salient rotor
    /// with MTPA). Default [`DEFAULT_CURRENT_LIMIT_RATIO`] × the rated current (docs/method/estimator.md, "The paper's motor and drive"
    /// \[A\]: 40 A on the paper's motor), see [`torque_limit`](Self::torque_limit).
    pub i_max: T,
    /// Back-calculation gain as a multiple of Ki/Kp (see [`PiConfig`]; default
    /// [`DEFAULT_ANTI_WINDUP_RATIO`]). Default 5, i.e. a
    /// tracking time constant of 1/ωsc: with the realisable setting (1) the integral relaxes
    /// only with 5/ωsc = 160 ms and a long saturated acceleration leaves it near I_max,
    /// which costs a large speed overshoot \[A\].
    pub anti_windup_ratio: T,
}

impl<T: Real> SpeedControllerConfig<T> {
    /// The speed loop for `machine` sampled every `ts` with the default bandwidth, zero and
    /// back-calculation ([`DEFAULT_BANDWIDTH_HZ`], [`DEFAULT_ZERO_RATIO`],
    /// [`DEFAULT_ANTI_WINDUP_RATIO`]) and the default current limit
    /// [`DEFAULT_CURRENT_LIMIT_RATIO`] × the rated current with MTPA. Same as
    /// [`new`](Self::new)`(machine, DEFAULT_CURRENT_LIMIT_RATIO × rated current, true, ts)`.
    pub fn for_machine(machine: &MachineModel<T>, ts: T) -> Self {
        let i_max = T::lit(DEFAULT_CURRENT_LIMIT_RATIO) * machine.rated_current;
        Self::new(machine, i_max, true, ts)
    }

    /// The speed loop for `machine` under the current limit `i_max` (A), sampled every `ts`,
    /// with the default bandwidth, zero and back-calculation. p, Ĵ and λ̂f are the machine
    /// model's; `i_max` is [`torque_limit`](Self::torque_limit)`(machine, i_max, mtpa)`.
    pub fn new(machine: &MachineModel<T>, i_max: T, mtpa: bool, ts: T) -> Self {
        let m = machine;
        Self {
            ts,
            pole_pairs: T::lit(m.pole_pairs as f64),
            inertia_hat: m.inertia,
            flux_linkage_hat: m.flux_linkage,
            bandwidth_hz: T::lit(DEFAULT_BANDWIDTH_HZ),
            zero_ratio: T::lit(DEFAULT_ZERO_RATIO),
            i_max: Self::torque_limit(m, i_max, mtpa),
            anti_windup_ratio: T::lit(DEFAULT_ANTI_WINDUP_RATIO),
        }
    }

    /// The output limit for the current limit `i_max` (A): `i_max`, raised on a salient rotor
    /// with `mtpa` to the torque of the MTPA point on the circle |i| = I_max, in units of the
    /// magnet's q current (see the field), so that saturation still reaches I_max.
    pub fn torque_limit(machine: &MachineModel<T>, i_max: T, mtpa: bool) -> T {
        let m = machine;
        // i_d = (λ̂f − √(λ̂f² + 8·ΔL²·I_max²))/(4·ΔL), ΔL = L̂q − L̂d (Morimoto et al. 1990).
        let dl = m.lq - m.ld;
        if mtpa && m.is_salient() && dl > T::zero() {
            let lf = m.flux_linkage;
            let id = (lf - (lf * lf + T::lit(8.0) * dl * dl * i_max * i_max).step_sqrt())
                / (T::lit(4.0) * dl);
            let iq = (i_max * i_max - id * id).step_max(T::zero()).step_sqrt();
            (m.active_flux(id) * iq / lf).step_max(i_max)
        } else {
            i_max
        }
    }
}

/// Speed PI: electrical speed error in, q-axis current reference out (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedController<T> {
    config: SpeedControllerConfig<T>,
    pi: Pi<T>,
}

impl<T: Real> SpeedController<T> {
    /// A new controller; every field is checked and a bad one named.
    pub fn new(config: SpeedControllerConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        let p = check::positive("pole_pairs", config.pole_pairs)?;
        let j = check::positive("inertia_hat", config.inertia_hat)?;
        let lf = check::positive("flux_linkage_hat", config.flux_linkage_hat)?;
        let wsc = T::two_pi() * check::positive("bandwidth_hz", config.bandwidth_hz)?;
        check::below(
            "bandwidth_hz",
            wsc * ts,
            T::lit(0.1),
            "2π·bandwidth_hz·ts below 0.1",
        )?;
        let zr = check::positive("zero_ratio", config.zero_ratio)?;
        let i_max = check::positive("i_max", config.i_max)?;
        let ratio = check::non_negative("anti_windup_ratio", config.anti_windup_ratio)?;
        let kt = T::lit(1.5) * p * lf;
        let kp_mech = j * wsc / kt;
        let kp = kp_mech / p;
        let pi = Pi::new(PiConfig {
            ts,
            kp,
            ki: kp * wsc / zr,
            output_min: -i_max,
            output_max: i_max,
            anti_windup_ratio: ratio,
        })
        .map_err(|e| match e.field() {
            "anti_windup_ratio" => e,
            _ => ConfigError::OutOfRange {
                field: "inertia_hat",
                expected: "finite, non-zero speed PI gains",
            },
        })?;
        Ok(Self { config, pi })
    }

    /// Integrator back to zero.
    pub fn reset(&mut self) {
        self.pi.reset();
    }

    /// One sample: reference and estimated speed in electrical rad/s (T2S-2 in the drive).
    /// Returns i_q* in A, within ±I_max. A non-finite input is rejected, state untouched.
    #[inline]
    pub fn step(&mut self, omega_ref: T, omega: T) -> Result<T, NonFiniteInput> {
        self.pi.step(omega_ref - omega, T::zero())
    }

    /// Presets the integral to `iq` (A, clamped to ±I_max): a bumpless start from a known
    /// torque demand (the release hold's pre-torque).
    pub fn preset(&mut self, iq: T) {
        self.pi.reset_to(iq);
    }

    /// Anti-windup for a further limit of i_q* downstream (the current-vector limit with
    /// the d-axis injection): the q current that was finally used.
    #[inline]
    pub fn realised(&mut self, iq_ref: T) {
        self.pi.realised(iq_ref);
    }

    /// Kp in A per electrical rad/s.
    pub fn kp(&self) -> T {
        self.pi.config().kp
    }

    /// Ki in A per electrical rad.
    pub fn ki(&self) -> T {
        self.pi.config().ki
    }

    /// Integral state (A).
    pub fn integral(&self) -> T {
        self.pi.integral()
    }

    /// The configuration in use.
    pub fn config(&self) -> &SpeedControllerConfig<T> {
        &self.config
    }
}

/// The current-vector limit |i_dq*| ≤ I_max with priority to d (docs/method/estimator.md §6, §6): i_d* (the
/// injection of eq. (23)) is kept within ±I_max and i_q* is cut to √(I_max² − i_d*²).
/// With I_min ≤ I_max the injection alone never needs the cut (|i_dq*| = I_min while it is
/// active), but any larger d-axis demand does.
#[inline]
pub fn limit_current_d_priority<T: Real>(i_dq: Dq<T>, i_max: T) -> Dq<T> {
    let d = crate::control::pi::clamp(i_dq.d, -i_max, i_max);
    let room = (i_max * i_max - d * d).step_max(T::zero()).step_sqrt();
    Dq::new(d, crate::control::pi::clamp(i_dq.q, -room, room))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::injection::{CurrentInjection, CurrentInjectionConfig};

    #[test]
    fn gains_follow_spec_6() {
        let c = SpeedController::<f64>::new(SpeedControllerConfig::for_machine(
            &MachineModel::paper(),
            100e-6,
        ))
        .unwrap();
        let kt = 1.5 * 4.0 * 0.088;
        let kp_mech = 0.012 * 2.0 * core::f64::consts::PI * 5.0 / kt;
        assert!(
            (kp_mech - 0.714).abs() < 1e-3,
            "the paper's motor (docs/method/estimator.md) quotes 0.714"
        );
        assert!((c.kp() * 4.0 - kp_mech).abs() < 1e-12);
        assert!((c.ki() / c.kp() - 2.0 * core::f64::consts::PI).abs() < 1e-12);
    }

    /// Speed loop around an ideal current loop and a rigid rotor: crossover at 5 Hz.
    #[test]
    fn small_step_matches_design_and_big_step_recovers() {
        let run = |step_mech: f64, ratio: f64| {
            let mut c = SpeedController::new(SpeedControllerConfig {
                anti_windup_ratio: ratio,
                ..SpeedControllerConfig::for_machine(&MachineModel::paper(), 100e-6)
            })
            .unwrap();
            let (p, j, kt, ts) = (4.0, 0.012, 1.5 * 4.0 * 0.088, 100e-6);
            let (mut w_mech, mut peak, mut t_rise) = (0.0_f64, 0.0_f64, None);
            for n in 0..20_000 {
                let iq = c.step(p * step_mech, p * w_mech).unwrap();
                w_mech += ts * kt * iq / j;
                peak = peak.max(w_mech);
                if t_rise.is_none() && w_mech >= 0.9 * step_mech {
                    t_rise = Some(n as f64 * ts);
                }
            }
            assert!((w_mech - step_mech).abs() < 1e-3 * step_mech);
            (peak / step_mech - 1.0, t_rise.unwrap())
        };
        // Linear: a 10 rad/s step needs 10·Kp·p = 23 A < 40 A.
        let (overshoot, t90) = run(10.0, 5.0);
        // ωsc(s + ωsc/5)/(s² + ωsc·s + ωsc²/5): real poles at −8.7 and −22.7 s⁻¹ and the PI
        // zero at −6.3 s⁻¹ give ≈ 12 % overshoot and 90 % after ≈ 50 ms.
        assert!(overshoot > 0.08 && overshoot < 0.16, "{overshoot}");
        assert!(t90 > 0.04 && t90 < 0.065, "{t90}");
        // Saturated at 40 A for ~80 ms. Without anti-windup the overshoot is ≈ 20 %, with the
        // realisable reference ≈ 11 %, with the default tracking at ωsc it vanishes.
        let (big, _) = run(150.0, 5.0);
        let (realisable, _) = run(150.0, 1.0);
        let (naive, _) = run(150.0, 0.0);
        assert!(big < 0.02, "{big}");
        assert!(
            big < realisable && realisable < naive,
            "{big} {realisable} {naive}"
        );
    }

    #[test]
    fn injection_interplay_keeps_vector_within_limit() {
        let inj = CurrentInjection::new(CurrentInjectionConfig::<f64>::for_machine(
            &MachineModel::paper(),
        ))
        .unwrap();
        for k in -100..=100 {
            let iq = 0.5 * k as f64;
            let ref_dq = limit_current_d_priority(Dq::new(inj.step(iq), iq), 40.0);
            assert!(ref_dq.norm() <= 40.0 + 1e-12);
            if iq.abs() < 4.0 {
                // eq. (23): the vector magnitude is exactly I_min, d positive.
                assert!((ref_dq.norm() - 4.0).abs() < 1e-12 && ref_dq.d > 0.0);
            } else {
                assert_eq!(ref_dq.d, 0.0);
            }
        }
        // A d demand near the limit cuts q, not d.
        let cut = limit_current_d_priority(Dq::new(30.0, -40.0_f64), 40.0);
        assert_eq!(cut.d, 30.0);
        assert!((cut.q + (40.0_f64 * 40.0 - 900.0).sqrt()).abs() < 1e-12);
        let over = limit_current_d_priority(Dq::new(50.0, 1.0_f64), 40.0);
        assert_eq!(over, Dq::new(40.0, 0.0));
    }

    #[test]
    fn bad_config_names_field() {
        let bad = |f: fn(&mut SpeedControllerConfig<f64>)| {
            let mut cfg = SpeedControllerConfig::for_machine(&MachineModel::paper(), 100e-6);
            f(&mut cfg);
            SpeedController::new(cfg).unwrap_err().field()
        };
        assert_eq!(bad(|c| c.pole_pairs = 0.0), "pole_pairs");
        assert_eq!(bad(|c| c.inertia_hat = f64::NAN), "inertia_hat");
        assert_eq!(bad(|c| c.i_max = -1.0), "i_max");
        assert_eq!(bad(|c| c.bandwidth_hz = 1e3), "bandwidth_hz");
        assert_eq!(bad(|c| c.zero_ratio = 0.0), "zero_ratio");
        assert_eq!(bad(|c| c.anti_windup_ratio = 1e9), "anti_windup_ratio");
    }
}
