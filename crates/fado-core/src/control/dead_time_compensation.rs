//! Compensation of the inverter non-linearity (paper IV-B, after refs. \[14\]-\[15\]; SPEC §5).
//!
//! Dead time and device drops make each pole voltage fall short by about
//! V̂·sat(i_x/Ic) in the direction of its phase current, V̂ = Td·f_sw·Vdc + V_th (the dead
//! time's average per switching period plus the device threshold), with the band Ic where
//! the parasitic capacitances make the error ramp rather than jump. The compensation adds
//! the opposite per phase:
//!
//! v_comp,x = V̂·sat(I*·cos(θi − φx)/Ic),   θi = θ̂ + 1.5·ω̂·Ts + atan2(i_q*, i_d*),
//! φx = 0, +2π/3, −2π/3 for a, b, c (phase b lags a),
//!
//! a trapezoid in the angle of the *reference* current vector, advanced like the voltage
//! (SPEC §5 \[A\]): no chattering on noisy measured currents near their zero crossings.
//! I*·cos(θi − φx) is just phase x of the reference current rotated to the advanced angle,
//! which is how it is computed (no atan2). The classic sign(i_x) of the measured current is
//! offered as [`DeadTimeMethod::Sign`]. The Clarke transform of v_comp (its zero sequence
//! does not matter) is added to v*_ab before modulation.

use crate::control::pi::clamp;
use crate::error::{ConfigError, check};
use crate::{Ab, Abc, Dq, Real, Rotation};

/// How the compensation voltage follows the current.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum DeadTimeMethod {
    /// V̂·sat(i*_x/Ic) of the advanced reference current (SPEC §5). Default.
    #[default]
    Trapezoidal,
    /// V̂·sign(i_x) of the measured phase current: the simple textbook variant.
    Sign,
}

/// Configuration of a [`DeadTimeCompensation`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeadTimeCompensationConfig<T> {
    /// Compensate at all. Default true (paper IV-B).
    pub enabled: bool,
    /// Shape. Default [`DeadTimeMethod::Trapezoidal`] (SPEC §5 \[A\]).
    pub method: DeadTimeMethod,
    /// Dead time Td in s. Default 2.5 µs (paper, V).
    pub dead_time: T,
    /// Switching frequency f_sw in Hz. Default 5 kHz (paper, V).
    pub switching_frequency: T,
    /// Device threshold voltage V_th in V. Default 1 V (SPEC §5 \[A\]).
    pub threshold_voltage: T,
    /// Current band Ic of the trapezoid in A. Default 0.3 A (SPEC §5 \[A\]).
    pub current_band: T,
}

impl<T: Real> Default for DeadTimeCompensationConfig<T> {
    fn default() -> Self {
        Self {
            enabled: true,
            method: DeadTimeMethod::Trapezoidal,
            dead_time: T::lit(2.5e-6),
            switching_frequency: T::lit(5e3),
            threshold_voltage: T::one(),
            current_band: T::lit(0.3),
        }
    }
}

/// Per-phase dead-time compensation (module docs). Stateless.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeadTimeCompensation<T> {
    config: DeadTimeCompensationConfig<T>,
    inv_band: T,
}

impl<T: Real> DeadTimeCompensation<T> {
    /// A new compensation; every field is checked and a bad one named.
    pub fn new(config: DeadTimeCompensationConfig<T>) -> Result<Self, ConfigError> {
        let td = check::non_negative("dead_time", config.dead_time)?;
        let fsw = check::positive("switching_frequency", config.switching_frequency)?;
        check::below(
            "dead_time",
            td * fsw,
            T::lit(0.5),
            "dead_time·switching_frequency below 0.5",
        )?;
        check::non_negative("threshold_voltage", config.threshold_voltage)?;
        let ic = check::positive("current_band", config.current_band)?;
        Ok(Self {
            config,
            inv_band: T::one() / ic,
        })
    }

    /// No state.
    pub fn reset(&mut self) {}

    /// V̂ = Td·f_sw·Vdc + V_th in V (0 when disabled or for a non-finite or negative Vdc).
    #[inline]
    pub fn amplitude(&self, vdc: T) -> T {
        if !(self.config.enabled && vdc.is_finite() && vdc >= T::zero()) {
            return T::zero();
        }
        let c = &self.config;
        c.dead_time * c.switching_frequency * vdc + c.threshold_voltage
    }

    /// The trapezoid v_comp,x = V̂·sat(i_x/Ic) for phase currents `i_abc` (A).
    #[inline]
    pub fn trapezoid(&self, i_abc: Abc<T>, vdc: T) -> Abc<T> {
        let v = self.amplitude(vdc);
        let one = T::one();
        let f = |i: T| v * clamp(i * self.inv_band, -one, one);
        Abc::new(f(i_abc.a), f(i_abc.b), f(i_abc.c))
    }

    /// The sign variant v_comp,x = V̂·sign(i_x) (0 at exactly zero current).
    #[inline]
    pub fn sign(&self, i_abc: Abc<T>, vdc: T) -> Abc<T> {
        let v = self.amplitude(vdc);
        let f = |i: T| {
            if i > T::zero() {
                v
            } else if i < T::zero() {
                -v
            } else {
                T::zero()
            }
        };
        Abc::new(f(i_abc.a), f(i_abc.b), f(i_abc.c))
    }

    /// The compensation for one sample as per-phase voltages: `rotation` is e^{j(θ̂+1.5ω̂Ts)}
    /// (the delay-compensated angle), `i_dq_ref` the current reference, `i_abc` the measured
    /// phase currents (used by [`DeadTimeMethod::Sign`] only). Zero when disabled; a
    /// non-finite input gives zero.
    #[inline]
    pub fn phase_voltages(
        &self,
        rotation: Rotation<T>,
        i_dq_ref: Dq<T>,
        i_abc: Abc<T>,
        vdc: T,
    ) -> Abc<T> {
        let out = match self.config.method {
            _ if !self.config.enabled => return Abc::default(),
            DeadTimeMethod::Trapezoidal => self.trapezoid(i_dq_ref.to_ab(rotation).to_abc(), vdc),
            DeadTimeMethod::Sign => self.sign(i_abc, vdc),
        };
        if out.is_finite() { out } else { Abc::default() }
    }

    /// The compensation as an α-β vector (Clarke of [`phase_voltages`](Self::phase_voltages)),
    /// to add to v*_ab before modulation.
    #[inline]
    pub fn step(&self, rotation: Rotation<T>, i_dq_ref: Dq<T>, i_abc: Abc<T>, vdc: T) -> Ab<T> {
        self.phase_voltages(rotation, i_dq_ref, i_abc, vdc).to_ab()
    }

    /// The configuration in use.
    pub fn config(&self) -> &DeadTimeCompensationConfig<T> {
        &self.config
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    fn comp(method: DeadTimeMethod) -> DeadTimeCompensation<f64> {
        DeadTimeCompensation::new(DeadTimeCompensationConfig {
            method,
            ..DeadTimeCompensationConfig::default()
        })
        .unwrap()
    }

    #[test]
    fn amplitude_is_dead_time_average_plus_threshold() {
        let c = comp(DeadTimeMethod::Trapezoidal);
        // 2.5 µs · 5 kHz · 300 V + 1 V
        assert!((c.amplitude(300.0) - 4.75).abs() < 1e-12);
        let off = DeadTimeCompensation::new(DeadTimeCompensationConfig {
            enabled: false,
            ..DeadTimeCompensationConfig::<f64>::default()
        })
        .unwrap();
        assert_eq!(off.amplitude(300.0), 0.0);
        let rot = Rotation::from_angle(0.2);
        assert_eq!(
            off.step(rot, Dq::new(0.0, 10.0), Abc::new(1.0, 2.0, -3.0), 300.0),
            Ab::zero()
        );
    }

    #[test]
    fn trapezoid_follows_spec_formula_sign_and_magnitude() {
        let c = comp(DeadTimeMethod::Trapezoidal);
        let vhat = c.amplitude(300.0);
        let (theta_adv, i_ref) = (0.4, Dq::new(1.0, 5.0));
        let rot = Rotation::from_angle(theta_adv);
        let v = c.phase_voltages(rot, i_ref, Abc::default(), 300.0);
        let theta_i = theta_adv + 5.0_f64.atan2(1.0);
        let mag = i_ref.norm();
        for (vx, phi) in [(v.a, 0.0), (v.b, 2.0 * PI / 3.0), (v.c, -2.0 * PI / 3.0)] {
            let ix = mag * (theta_i - phi).cos();
            let expected = vhat * (ix / 0.3).clamp(-1.0, 1.0);
            assert!((vx - expected).abs() < 1e-12, "{vx} vs {expected}");
        }
        // Trapezoid over one electrical turn: plateaus at ±V̂, linear through zero with slope
        // V̂/Ic per ampere, and the compensation pushes each pole towards its current.
        let mut plateau = 0;
        for k in 0..3600 {
            let th = k as f64 * 2.0 * PI / 3600.0;
            let va = c
                .phase_voltages(
                    Rotation::from_angle(th),
                    Dq::new(2.0, 0.0),
                    Abc::default(),
                    300.0,
                )
                .a;
            let ia = 2.0 * th.cos();
            assert!(va * ia >= 0.0 && va.abs() <= vhat + 1e-12);
            if ia.abs() >= 0.3 {
                assert!((va.abs() - vhat).abs() < 1e-12);
                plateau += 1;
            } else {
                assert!((va - vhat * ia / 0.3).abs() < 1e-12);
            }
        }
        // |cos| ≥ 0.15 over all but 2·2·asin(0.15)/2π ≈ 9.6 % of the turn.
        assert!(
            (plateau as f64 / 3600.0 - (1.0 - 4.0 * 0.15_f64.asin() / (2.0 * PI))).abs() < 2e-3
        );
    }

    #[test]
    fn sign_variant_uses_measured_currents() {
        let c = comp(DeadTimeMethod::Sign);
        let v = c.phase_voltages(
            Rotation::from_angle(0.0),
            Dq::new(10.0, 0.0),
            Abc::new(0.01, -0.02, 0.0),
            300.0,
        );
        assert_eq!(v, Abc::new(4.75, -4.75, 0.0));
        // Clarke: the α-β vector of the per-phase compensation.
        let ab = c.step(
            Rotation::from_angle(0.0),
            Dq::zero(),
            Abc::new(1.0, -0.5, -0.5),
            300.0,
        );
        assert!((ab.alpha - 4.75 * (2.0 + 2.0) / 3.0).abs() < 1e-12 && ab.beta.abs() < 1e-12);
    }

    #[test]
    fn bad_config_names_field() {
        let bad = |f: fn(&mut DeadTimeCompensationConfig<f64>)| {
            let mut cfg = DeadTimeCompensationConfig::default();
            f(&mut cfg);
            DeadTimeCompensation::new(cfg).unwrap_err().field()
        };
        assert_eq!(bad(|c| c.dead_time = -1e-6), "dead_time");
        assert_eq!(bad(|c| c.dead_time = 1e-3), "dead_time");
        assert_eq!(bad(|c| c.switching_frequency = 0.0), "switching_frequency");
        assert_eq!(bad(|c| c.threshold_voltage = f64::NAN), "threshold_voltage");
        assert_eq!(bad(|c| c.current_band = 0.0), "current_band");
    }
}
