//! Synchronous-frame current control of Fig. 5: one PI per axis with decoupling and back-EMF
//! feed-forward, anti-windup against the voltage the inverter could actually realise.
//!
//! Gains (docs/method/estimator.md, "The paper's motor and drive"): Kp,d = L̂d·ωc, Kp,q = L̂q·ωc, Ki = R̂s·ωc with ωc = 2π·250 Hz (paper, V).
//! The PI zero then cancels the stator pole R̂s/L̂ and the loop gain is ωc/s: a first-order
//! closed loop ωc/(s + ωc), rise time 2.2/ωc, apart from the 1.5-sample delay of computation
//! and PWM hold (which [`DelayCompensation`](super::delay_compensation) keeps out of the
//! rotating frame, but not out of the loop).
//!
//! Feed-forward (docs/method/estimator.md, "The paper's motor and drive" \[A\]), from the machine model v_d = R·i_d + L_d·di_d/dt − ω·L_q·i_q,
//! v_q = R·i_q + L_q·di_q/dt + ω·(L_d·i_d + λ_f), with the measured currents:
//! v_d,ff = −ω·L̂q·i_q, v_q,ff = ω·(L̂d·i_d + λ̂f). It turns the cross-coupled plant into two
//! independent R-L branches.
//!
//! Anti-windup: back-calculation (see [`pi`](super::pi)): `step` returns the unlimited
//! voltage, the caller limits it (to the hexagon, after rotation and compensation) and hands
//! the realisable d-q voltage back through [`CurrentController::realised`].

use crate::control::pi::{Pi, PiConfig};
use crate::error::{ConfigError, NonFiniteInput, check};
use crate::{Dq, MachineModel, Real};

/// Hard bound of the current PIs' voltage and integral in V, the least value of
/// [`CurrentControllerConfig::voltage_bound`] \[A\]: a last guard against absurd estimates,
/// far above what the modulation lets through on DC links up to 750 V. It only ever acts on
/// estimates that are wrong; on a higher DC link the bound is
/// [`CURRENT_VOLTAGE_BOUND_DC_RATIO`] × V_dc ([`voltage_bound`]).
pub const CURRENT_VOLTAGE_BOUND: f64 = 1000.0;

/// The current PIs' bound as a multiple of the DC link, where that is above
/// [`CURRENT_VOLTAGE_BOUND`]: 4/3, twice the longest voltage vector the inverter makes
/// (a hexagon vertex, 2/3·V_dc) \[A\]. A fixed bound below what the modulation realises caps
/// the machine's voltage: a 10 kV-class machine on a 14 kV link held at 1000 V stalls at a
/// sixth of its rated speed (`crates/fado-sim/tests/calibration_load_classes.rs`).
pub const CURRENT_VOLTAGE_BOUND_DC_RATIO: f64 = 4.0 / 3.0;

/// The current PIs' hard bound (V) on the DC link `dc_voltage`: the larger of
/// [`CURRENT_VOLTAGE_BOUND`] and [`CURRENT_VOLTAGE_BOUND_DC_RATIO`] × `dc_voltage` (a
/// non-finite or non-positive link gives the former).
pub fn voltage_bound<T: Real>(dc_voltage: T) -> T {
    let scaled = T::lit(CURRENT_VOLTAGE_BOUND_DC_RATIO) * dc_voltage;
    // NaN compares false: the absolute bound.
    if scaled > T::lit(CURRENT_VOLTAGE_BOUND) {
        scaled
    } else {
        T::lit(CURRENT_VOLTAGE_BOUND)
    }
}

/// Default closed-loop bandwidth of the current loop in Hz: 250 (paper, V).
pub const DEFAULT_BANDWIDTH_HZ: f64 = 250.0;

/// Default of [`CurrentControllerConfig::decoupling`]: on (docs/method/estimator.md, "The
/// paper's motor and drive" \[A\]).
pub const DEFAULT_DECOUPLING: bool = true;

/// Default back-calculation gain in units of Ki/Kp: 1, the realisable reference \[A\].
pub const DEFAULT_ANTI_WINDUP_RATIO: f64 = 1.0;

/// Configuration of a [`CurrentController`].
///
/// No `Default`: R̂s, L̂d, L̂q and λ̂f are the motor's. Build it with
/// [`for_machine`](Self::for_machine); each field's "Default" is what it gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurrentControllerConfig<T> {
    /// Sampling period Ts in s (paper, V: 100 µs).
    pub ts: T,
    /// Stator resistance estimate R̂s in Ω: the machine model's (the paper's motor: 0.327 Ω,
    /// paper V).
    pub rs_hat: T,
    /// d-axis inductance estimate L̂d in H: the machine model's (the paper's motor: 2.63 mH).
    pub ld_hat: T,
    /// q-axis inductance estimate L̂q in H: the machine model's (the paper's motor: 2.63 mH).
    pub lq_hat: T,
    /// Magnet flux linkage estimate λ̂f in Wb (back-EMF feed-forward): the machine model's
    /// (the paper's motor: 0.088 Wb, docs/method/estimator.md, "The paper's motor and drive" \[A\]).
    pub flux_linkage_hat: T,
    /// Closed-loop bandwidth in Hz. Default [`DEFAULT_BANDWIDTH_HZ`] (250 Hz, paper V). Limited to ωc·Ts ≤ 0.5 so the 1.5-sample loop
    /// delay leaves at least 47° of phase margin.
    pub bandwidth_hz: T,
    /// Add the decoupling and back-EMF feed-forward. Default true (docs/method/estimator.md, "The paper's motor and drive" \[A\]).
    pub decoupling: bool,
    /// Back-calculation gain as a multiple of Ki/Kp = R̂s/L̂ (see [`PiConfig`]). Default 1, the
    /// realisable reference \[A\].
    pub anti_windup_ratio: T,
    /// Hard bound on each axis' voltage and integral in V, a last guard against absurd
    /// estimates; the real limit is the inverter's (modulation). Default
    /// [`voltage_bound`] of the machine model's DC link: [`CURRENT_VOLTAGE_BOUND`] up to 750 V.
    pub voltage_bound: T,
}

impl<T: Real> CurrentControllerConfig<T> {
    /// The current loop for `machine` sampled every `ts`: R̂s, L̂d, L̂q and λ̂f are the machine
    /// model's, `bandwidth_hz` [`DEFAULT_BANDWIDTH_HZ`], `decoupling` [`DEFAULT_DECOUPLING`],
    /// `anti_windup_ratio` [`DEFAULT_ANTI_WINDUP_RATIO`] and `voltage_bound`
    /// [`voltage_bound`] of `machine.dc_voltage`.
    pub fn for_machine(machine: &MachineModel<T>, ts: T) -> Self {
        Self {
            ts,
            rs_hat: machine.rs,
            ld_hat: machine.ld,
            lq_hat: machine.lq,
            flux_linkage_hat: machine.flux_linkage,
            bandwidth_hz: T::lit(DEFAULT_BANDWIDTH_HZ),
            decoupling: DEFAULT_DECOUPLING,
            anti_windup_ratio: T::lit(DEFAULT_ANTI_WINDUP_RATIO),
            voltage_bound: voltage_bound(machine.dc_voltage),
        }
    }
}

/// Synchronous-frame PI current controller with decoupling (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurrentController<T> {
    config: CurrentControllerConfig<T>,
    d: Pi<T>,
    q: Pi<T>,
}

impl<T: Real> CurrentController<T> {
    /// A new controller; every field is checked and a bad one named.
    pub fn new(config: CurrentControllerConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        let rs = check::non_negative("rs_hat", config.rs_hat)?;
        let ld = check::positive("ld_hat", config.ld_hat)?;
        let lq = check::positive("lq_hat", config.lq_hat)?;
        check::non_negative("flux_linkage_hat", config.flux_linkage_hat)?;
        let wc = T::two_pi() * check::positive("bandwidth_hz", config.bandwidth_hz)?;
        if wc * ts > T::lit(0.5) {
            return Err(ConfigError::OutOfRange {
                field: "bandwidth_hz",
                expected: "2π·bandwidth_hz·ts at most 0.5",
            });
        }
        let ratio = check::non_negative("anti_windup_ratio", config.anti_windup_ratio)?;
        let bound = check::positive("voltage_bound", config.voltage_bound)?;
        let axis = |l: T| {
            Pi::new(PiConfig {
                ts,
                kp: l * wc,
                ki: rs * wc,
                output_min: -bound,
                output_max: bound,
                anti_windup_ratio: ratio,
            })
            .map_err(|e| match e.field() {
                "anti_windup_ratio" => e,
                _ => ConfigError::OutOfRange {
                    field: "bandwidth_hz",
                    expected: "finite PI gains",
                },
            })
        };
        let d = axis(ld)?;
        let q = axis(lq)?;
        Ok(Self { config, d, q })
    }

    /// Integrators back to zero.
    pub fn reset(&mut self) {
        self.d.reset();
        self.q.reset();
    }

    /// The decoupling and back-EMF feed-forward at electrical speed `omega` for the measured
    /// currents `i_dq` (zero when `decoupling` is off).
    #[inline]
    pub fn feedforward(&self, i_dq: Dq<T>, omega: T) -> Dq<T> {
        if self.config.decoupling {
            let c = &self.config;
            Dq::new(
                -omega * c.lq_hat * i_dq.q,
                omega * (c.ld_hat * i_dq.d + c.flux_linkage_hat),
            )
        } else {
            Dq::zero()
        }
    }

    /// One sample: reference and measured d-q currents (A) in the estimated rotor frame and the
    /// electrical speed `omega` (rad/s, T2S-2 in the drive). Returns the *unlimited* d-q
    /// voltage reference v*_dq; limit it and call [`realised`](Self::realised). A non-finite
    /// input is rejected with the state untouched.
    #[inline]
    pub fn step(
        &mut self,
        reference: Dq<T>,
        measured: Dq<T>,
        omega: T,
    ) -> Result<Dq<T>, NonFiniteInput> {
        if !(reference.is_finite() && measured.is_finite() && omega.is_finite()) {
            return Err(NonFiniteInput);
        }
        let ff = self.feedforward(measured, omega);
        self.step_with_feedforward(reference, measured, ff)
    }

    /// [`step`](Self::step) with the decoupling and back-EMF feed-forward from a magnetic
    /// model's flux linkage `flux` (ψd, ψq in Wb, estimated frame): (−ω·ψq, ω·ψd), zero when
    /// `decoupling` is off. On a saturating machine the flux is not L̂·i + λ̂f for any one pair
    /// of inductances: the PM-SyRM's secant L_q falls from 150 mH at zero current to 83 mH
    /// at the rated one, and its incremental one to 51 mH, the current loop's gain
    /// (`SensorlessDrive` takes the rated point's), which as a decoupling leaves ω·ψq a third
    /// short at small currents (docs/range.md).
    #[inline]
    pub fn step_with_flux(
        &mut self,
        reference: Dq<T>,
        measured: Dq<T>,
        omega: T,
        flux: Dq<T>,
    ) -> Result<Dq<T>, NonFiniteInput> {
        if !(reference.is_finite() && measured.is_finite() && omega.is_finite() && flux.is_finite())
        {
            return Err(NonFiniteInput);
        }
        let ff = if self.config.decoupling {
            Dq::new(-omega * flux.q, omega * flux.d)
        } else {
            Dq::zero()
        };
        self.step_with_feedforward(reference, measured, ff)
    }

    #[inline(always)]
    fn step_with_feedforward(
        &mut self,
        reference: Dq<T>,
        measured: Dq<T>,
        ff: Dq<T>,
    ) -> Result<Dq<T>, NonFiniteInput> {
        let e = reference - measured;
        let (d0, q0) = (self.d, self.q);
        let vd = self.d.step(e.d, ff.d)?;
        let vq = match self.q.step(e.q, ff.q) {
            Ok(v) => v,
            Err(err) => {
                (self.d, self.q) = (d0, q0);
                return Err(err);
            }
        };
        Ok(Dq::new(vd, vq))
    }

    /// Anti-windup: the d-q voltage that was actually realisable after limiting the output of
    /// the last `step` (back-calculation, see [`Pi::realised`]). Ignored if not finite.
    #[inline]
    pub fn realised(&mut self, v_dq: Dq<T>) {
        if v_dq.is_finite() {
            self.d.realised(v_dq.d);
            self.q.realised(v_dq.q);
        }
    }

    /// Convenience for a circular limit (e.g. the hexagon's inscribed circle Vdc/√3): steps,
    /// scales the vector into |v| ≤ `v_max` keeping its angle, feeds that back and returns it.
    #[inline]
    pub fn step_limited(
        &mut self,
        reference: Dq<T>,
        measured: Dq<T>,
        omega: T,
        v_max: T,
    ) -> Result<Dq<T>, NonFiniteInput> {
        if !v_max.is_finite() {
            return Err(NonFiniteInput);
        }
        let v = self.step(reference, measured, omega)?;
        let v_max = v_max.step_max(T::zero());
        let n = v.norm();
        let limited = if n > v_max { v * (v_max / n) } else { v };
        self.realised(limited);
        Ok(limited)
    }

    /// Proportional gains (Kp,d, Kp,q) in V/A.
    pub fn kp(&self) -> Dq<T> {
        Dq::new(self.d.config().kp, self.q.config().kp)
    }

    /// Integral gain Ki in V/(A·s), the same on both axes.
    pub fn ki(&self) -> T {
        self.d.config().ki
    }

    /// The integral states (V).
    pub fn integral(&self) -> Dq<T> {
        Dq::new(self.d.integral(), self.q.integral())
    }

    /// The configuration in use.
    pub fn config(&self) -> &CurrentControllerConfig<T> {
        &self.config
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The flux form of the feed-forward is the linear one for the linear model's flux
    /// (λ̂f + L̂d·i_d, L̂q·i_q), and on a saturating machine it is what holds the current: a plant
    /// whose q flux is 3 × L̂q·i_q (the PM-SyRM's secant against its rated incremental L_q at
    /// small currents) is within 0.06 A of a 2 A step 10 ms after it with the flux form, 0.56 A
    /// off with the linear form (ω·(ψq − L̂q·i_q) = 20 V left to the integrator in d).
    #[test]
    fn flux_feedforward_matches_the_linear_one_and_decouples_a_saturating_plant() {
        let mut m = MachineModel::<f64>::paper();
        m.ld = 0.018;
        m.lq = 0.051;
        m.flux_linkage = 0.4767;
        m.rs = 0.63;
        let ts = 1e-4;
        let config = CurrentControllerConfig::for_machine(&m, ts);
        let (reference, measured, omega) = (Dq::new(0.5, -1.5), Dq::new(0.3, -1.2), 100.0);
        let linear = Dq::new(m.flux_linkage + m.ld * measured.d, m.lq * measured.q);
        let mut a = CurrentController::new(config).unwrap();
        let mut b = a;
        let va = a.step(reference, measured, omega).unwrap();
        let vb = b
            .step_with_flux(reference, measured, omega, linear)
            .unwrap();
        assert!((va - vb).norm() < 1e-12, "{va:?} {vb:?}");
        // A plant whose q flux is 3·L̂q·i_q (and d as the model): v = R·i + dψ/dt + ω·J·ψ,
        // stepped at a constant speed; the error 10 ms after a q-current reference step.
        let settle = |flux_form: bool| {
            let mut c = CurrentController::new(config).unwrap();
            let mut i = Dq::new(0.0, 0.0);
            let target = Dq::new(0.0, 2.0);
            let lq_true = 3.0 * m.lq;
            for _ in 0..100 {
                let psi = Dq::new(m.flux_linkage + m.ld * i.d, lq_true * i.q);
                let v = if flux_form {
                    let model = Dq::new(m.flux_linkage + m.ld * target.d, lq_true * target.q);
                    c.step_with_flux(target, i, omega, model).unwrap()
                } else {
                    c.step(target, i, omega).unwrap()
                };
                // L di/dt = v − R·i − ω·J·ψ (incremental L as the plant's secant here).
                let emf = Dq::new(-omega * psi.q, omega * psi.d);
                i.d += ts * (v.d - m.rs * i.d - emf.d) / m.ld;
                i.q += ts * (v.q - m.rs * i.q - emf.q) / lq_true;
            }
            (target - i).norm()
        };
        let (with, without) = (settle(true), settle(false));
        assert!(with < 0.1 && without > 5.0 * with, "{with} {without}");
    }

    /// The PIs' bound leaves every voltage the inverter makes through: the absolute 1000 V on
    /// DC links up to 750 V, 4/3·V_dc (twice a hexagon vertex) above; a machine model
    /// without a DC link keeps the absolute bound. A 10 kV-class machine whose back-EMF at a
    /// fifth of its rated speed is 1.5 kV on a 14 kV link is not capped at 1 kV.
    #[test]
    fn the_voltage_bound_scales_with_a_high_dc_link() {
        assert_eq!(voltage_bound(24.0), CURRENT_VOLTAGE_BOUND);
        assert_eq!(voltage_bound(750.0), CURRENT_VOLTAGE_BOUND);
        assert_eq!(voltage_bound(f64::NAN), CURRENT_VOLTAGE_BOUND);
        assert_eq!(voltage_bound(0.0), CURRENT_VOLTAGE_BOUND);
        let high = voltage_bound(14_000.0);
        assert!(high >= 2.0 / 3.0 * 14_000.0 * 2.0 - 1e-9, "{high}");
        let mut m = MachineModel::<f64>::paper();
        m.dc_voltage = 14_000.0;
        assert_eq!(
            CurrentControllerConfig::for_machine(&m, 1e-4).voltage_bound,
            high
        );
    }
}
