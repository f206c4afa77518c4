//! d-axis current injection at light load, paper eq. (23).
//!
//! A positive i_d keeps the stator current above I_min so that the flux variation stays
//! observable, and steers the integrand errors at standstill towards the positive d-axis where
//! the rotor flux lies (paper, section V, Fig. 10 discussion).
//!
//! **The direction** ([`direction`]). The estimator follows the active flux
//! λa = ψd − L_q,s·i_d (`crate::active_flux`; λf + (Ld − Lq)·i_d for constant inductances),
//! not the magnet's flux. On a reluctance-dominated rotor with a weak magnet, a PM-assisted
//! SyRM whose (L_q − L_d)·I_min exceeds λf, a d current of I_min along +d turns λa negative:
//! the rotor flux the estimator aligns with then points along −d and the angle is off by π
//! (motulator's 6.7 kW SyRM with a 39 mVs magnet: λa = −0.16 Vs at +4 A, +0.22 Vs at −4 A;
//! `cargo test --release -p fado-core --test saturated_replay weak_magnet -- --nocapture`).
//! There the injection goes along −d, which raises λa (and is the MTPA curve's own
//! direction on such a rotor). Where +d keeps λa positive, i.e. on every rotor whose magnet
//! carries the active flux at no load (every preset), the injection is the paper's +d.

use crate::active_flux::ActiveFlux;
use crate::error::{ConfigError, check};
use crate::machine::PAPER_RATED_CURRENT;
use crate::{Dq, MachineModel, Real};

/// Default I_min of the injection as a fraction of the rated current: 4/21.78 (paper,
/// section V: 4 A on its motor).
pub const DEFAULT_CURRENT_RATIO: f64 = 4.0 / PAPER_RATED_CURRENT;

/// Configuration of [`CurrentInjection`].
///
/// No `Default`: I_min is a current of the motor. Build it with
/// [`for_machine`](Self::for_machine); the field's "Default" is what it gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurrentInjectionConfig<T> {
    /// Minimum current magnitude I_min in A. Default 4/21.78 of the rated current
    /// ([`DEFAULT_CURRENT_RATIO`]; paper, section V: 4 A on its motor).
    pub i_min: T,
}

impl<T: Real> CurrentInjectionConfig<T> {
    /// I_min for `machine` with the default ratio ([`DEFAULT_CURRENT_RATIO`], 4/21.78 of the
    /// rated current: the paper's 4 A, V).
    pub fn for_machine(machine: &MachineModel<T>) -> Self {
        Self::new(machine, T::lit(DEFAULT_CURRENT_RATIO))
    }

    /// I_min = `current_ratio` × [`MachineModel::rated_current`].
    pub fn new(machine: &MachineModel<T>, current_ratio: T) -> Self {
        Self {
            i_min: current_ratio * machine.rated_current,
        }
    }
}

/// The d direction of the injection on `machine` at the level `i_min` (A): +1 (the paper's
/// +d) unless the machine's active flux at i_dq = (+`i_min`, 0) is negative, then −1 (module
/// docs, "The direction"). The machine's magnetic model decides (its zero-current constants
/// for constant inductances: −1 where (L̂q − L̂d)·i_min > λ̂f); a non-finite active flux
/// gives +1.
pub fn direction<T: Real>(machine: &MachineModel<T>, i_min: T) -> T {
    let active = ActiveFlux::of(machine)
        .point(Dq::new(i_min, T::zero()))
        .active;
    if active < T::zero() {
        -T::one()
    } else {
        T::one()
    }
}

/// The rule of eq. (23): i_d* = √(I_min² − i_q*²) when |i_q*| < I_min, else 0, so that the
/// d-q reference vector has magnitude at least I_min (docs/method/estimator.md §6), along
/// +d or, on a rotor where +d reverses the active flux, −d ([`direction`],
/// [`CurrentInjection::along`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurrentInjection<T> {
    i_min: T,
    /// +1 (+d) or −1 (−d).
    direction: T,
}

impl<T: Real> CurrentInjection<T> {
    /// A new rule.
    pub fn new(config: CurrentInjectionConfig<T>) -> Result<Self, ConfigError> {
        Ok(Self {
            i_min: check::non_negative("i_min", config.i_min)?,
            direction: T::one(),
        })
    }

    /// The same rule along −d for a negative `direction` (else +d; [`direction`]).
    pub fn along(self, direction: T) -> Self {
        Self {
            direction: if direction < T::zero() {
                -T::one()
            } else {
                T::one()
            },
            ..self
        }
    }

    /// +1 (+d) or −1 (−d).
    pub fn direction(&self) -> T {
        self.direction
    }

    /// Stateless; exists for uniformity.
    pub fn reset(&mut self) {}

    /// i_d* for a q-axis reference `iq_ref` (A). A non-finite `iq_ref` gives 0.
    #[inline]
    pub fn step(&self, iq_ref: T) -> T {
        let rest = self.i_min * self.i_min - iq_ref * iq_ref;
        if rest > T::zero() {
            self.direction * rest.step_sqrt()
        } else {
            T::zero()
        }
    }

    /// I_min in use.
    pub fn i_min(&self) -> T {
        self.i_min
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq_23() {
        let inj = CurrentInjection::new(CurrentInjectionConfig { i_min: 4.0_f64 }).unwrap();
        assert_eq!(inj.step(0.0), 4.0);
        assert!((inj.step(-2.4) - 3.2).abs() < 1e-12);
        assert_eq!(inj.step(4.0), 0.0);
        assert_eq!(inj.step(-7.5), 0.0);
        assert_eq!(inj.step(f64::NAN), 0.0);
        assert!(CurrentInjection::new(CurrentInjectionConfig { i_min: -1.0 }).is_err());
        let minus = inj.along(-1.0);
        assert_eq!(minus.step(0.0), -4.0);
        assert!((minus.step(-2.4) + 3.2).abs() < 1e-12);
        assert_eq!(minus.step(7.5), 0.0);
    }

    /// +d on every rotor whose active flux +d keeps positive (the paper's motor, an IPMSM,
    /// the pmsyrm-5k preset's PM-SyRM), −d where (L̂q − L̂d)·I_min exceeds λ̂f.
    #[test]
    fn the_direction_keeps_the_active_flux_positive() {
        let paper = MachineModel::<f64>::paper();
        let i_min = CurrentInjectionConfig::for_machine(&paper).i_min;
        assert_eq!(direction(&paper, i_min), 1.0);
        let salient = |ld: f64, lq: f64, lf: f64| MachineModel {
            ld,
            lq,
            flux_linkage: lf,
            ..paper
        };
        // pmsyrm-5k's inductances and magnet: (L̂q − L̂d)·4 A = 0.052 Vs < 0.134 Vs.
        assert_eq!(direction(&salient(4e-3, 17e-3, 0.134), i_min), 1.0);
        // A weak magnet: (L̂q − L̂d)·I_min just above λ̂f, and just below.
        let edge = (57.5e-3 - 9.7e-3) * i_min;
        assert_eq!(
            direction(&salient(9.7e-3, 57.5e-3, 0.99 * edge), i_min),
            -1.0
        );
        assert_eq!(
            direction(&salient(9.7e-3, 57.5e-3, 1.01 * edge), i_min),
            1.0
        );
        // L̂d > L̂q: +d raises the active flux.
        assert_eq!(direction(&salient(57.5e-3, 9.7e-3, 1e-3), i_min), 1.0);
    }
}
