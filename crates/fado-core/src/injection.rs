//! d-axis current injection at light load, paper eq. (23).
//!
//! A positive i_d keeps the stator current above I_min so that the flux variation stays
//! observable, and steers the integrand errors at standstill towards the positive d-axis where
//! the rotor flux lies (paper, section V, Fig. 10 discussion).

use crate::error::{ConfigError, check};
use crate::machine::PAPER_RATED_CURRENT;
use crate::{MachineModel, Real};

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

/// The rule of eq. (23): i_d* = √(I_min² − i_q*²) when |i_q*| < I_min, else 0, so that the
/// d-q reference vector has magnitude at least I_min (docs/method/estimator.md §6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurrentInjection<T> {
    i_min: T,
}

impl<T: Real> CurrentInjection<T> {
    /// A new rule.
    pub fn new(config: CurrentInjectionConfig<T>) -> Result<Self, ConfigError> {
        Ok(Self {
            i_min: check::non_negative("i_min", config.i_min)?,
        })
    }

    /// Stateless; exists for uniformity.
    pub fn reset(&mut self) {}

    /// i_d* for a q-axis reference `iq_ref` (A). A non-finite `iq_ref` gives 0.
    #[inline]
    pub fn step(&self, iq_ref: T) -> T {
        let rest = self.i_min * self.i_min - iq_ref * iq_ref;
        if rest > T::zero() {
            rest.step_sqrt()
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
    }
}
