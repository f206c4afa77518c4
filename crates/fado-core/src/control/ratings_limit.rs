//! The speed, torque and power limits of the drive, from the motor's ratings.
//!
//! A motor's ratings bound more than its current: its mechanical speed (bearings, rotor
//! retention, the back-EMF an inverter must survive after a trip), the torque its shaft or
//! gearbox carries, the power its cooling and its supply take. The drive clamps the speed
//! reference to `speed_ratio` × the rated speed, and the speed loop's torque demand to
//! `torque_ratio` × the rated torque and to `power_ratio` × the rated power (the rated torque
//! at the rated speed) divided by the speed ω̂. Each default is 2 × the rating \[A\]: the
//! field-weakening range to twice the rated speed that `fullrange` exercises, and an overload
//! above the current limit's (`current.limit_ratio`, 1.84 × on the paper's motor), so that
//! the current limit, not these, sets the transients of a surface-magnet motor; on an
//! interior-magnet motor the torque limit caps the reluctance torque MTPA adds at the current
//! limit. Below the limits the torque demand passes bit for bit.
//!
//! The torque demand is in units of the magnet's q current, τ (A; T = 1.5·p·λ̂f·τ, see
//! `crate::control::drive`), so the bounds are resolved once into amperes of τ:
//! `|τ| ≤ T_max/(1.5·p·λ̂f)` and `|τ| ≤ P_max/(1.5·λ̂f·|ω̂|)` (ω̂ electrical). The speed
//! loop's back-calculation sees the limited demand through the current reference it
//! realises, so it does not wind up.

use crate::Real;
use crate::error::{ConfigError, check};
use crate::machine::MachineModel;
use crate::real::cast_record;

/// `[controller.limits]`: the drive's speed, torque and power limits as multiples of the
/// motor's ratings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(
        deny_unknown_fields,
        default,
        bound(
            serialize = "T: serde::Serialize",
            deserialize = "T: Real + serde::Deserialize<'de>"
        )
    )
)]
pub struct RatingsLimitTuning<T> {
    /// Largest |speed reference| as a multiple of the rated speed. Default 2 \[A\].
    pub speed_ratio: T,
    /// Largest |torque| as a multiple of the rated torque. Default 2 \[A\].
    pub torque_ratio: T,
    /// Largest |mechanical power| as a multiple of the rated power (rated torque × rated
    /// speed). Default 2 \[A\].
    pub power_ratio: T,
}

impl<T: Real> Default for RatingsLimitTuning<T> {
    fn default() -> Self {
        Self {
            speed_ratio: T::lit(2.0),
            torque_ratio: T::lit(2.0),
            power_ratio: T::lit(2.0),
        }
    }
}

cast_record!(RatingsLimitTuning { speed_ratio, torque_ratio, power_ratio ;  });

/// The limits resolved in the drive's units (stateless).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RatingsLimit<T> {
    /// Largest |ω*|, rad/s electrical.
    max_speed: T,
    /// Largest |τ|, A.
    max_tau: T,
    /// P_max/(1.5·λ̂f): |τ|·|ω̂| ≤ this, A·rad/s.
    max_tau_speed: T,
}

impl<T: Real> RatingsLimit<T> {
    /// The limits of `machine` (its rated speed, torque and λ̂f); each ratio must be positive.
    pub fn new(t: &RatingsLimitTuning<T>, machine: &MachineModel<T>) -> Result<Self, ConfigError> {
        let speed = check::positive("limits.speed_ratio", t.speed_ratio)?;
        let torque = check::positive("limits.torque_ratio", t.torque_ratio)?;
        let power = check::positive("limits.power_ratio", t.power_ratio)?;
        let p = T::lit(machine.pole_pairs as f64);
        let kt = T::lit(1.5) * p * machine.flux_linkage;
        let rated_power = machine.rated_torque * machine.rated_speed_mech();
        Ok(Self {
            max_speed: speed * machine.rated_speed(),
            max_tau: torque * machine.rated_torque / kt,
            max_tau_speed: power * rated_power * p / kt,
        })
    }

    /// The speed reference `speed_ref` (rad/s electrical) within the speed limit.
    #[inline]
    pub fn speed(&self, speed_ref: T) -> T {
        if speed_ref.abs() > self.max_speed {
            self.max_speed * speed_ref.signum()
        } else {
            speed_ref
        }
    }

    /// The torque demand `tau` (A of τ) within the torque limit and, at the speed `omega`
    /// (rad/s electrical), the power limit; `tau` bit for bit below both.
    #[inline]
    pub fn torque(&self, tau: T, omega: T) -> T {
        let power_bound = self.max_tau_speed / omega.abs();
        // (A NaN bound compares false: the torque limit alone then.)
        let bound = if power_bound < self.max_tau {
            power_bound
        } else {
            self.max_tau
        };
        if tau.abs() > bound {
            bound * tau.signum()
        } else {
            tau
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_of_the_paper_motor() {
        let m = MachineModel::<f64>::paper();
        let l = RatingsLimit::new(&RatingsLimitTuning::default(), &m).unwrap();
        let p = 4.0;
        let kt = 1.5 * p * m.flux_linkage;
        let w_rated = m.rated_speed();
        // Speed: 2 × rated, both directions; inside, bit for bit.
        assert_eq!(l.speed(3.0 * w_rated), 2.0 * w_rated);
        assert_eq!(l.speed(-3.0 * w_rated), -2.0 * w_rated);
        assert_eq!(l.speed(0.3 * w_rated), 0.3 * w_rated);
        // Torque: 2 × 11.5 N·m up to the speed where 2 × the rated power takes over.
        let tau_max = 2.0 * m.rated_torque / kt;
        assert!((l.torque(1e3, 0.5 * w_rated) - tau_max).abs() < 1e-9);
        assert!((l.torque(-1e3, 0.0) + tau_max).abs() < 1e-9);
        assert_eq!(l.torque(10.0, 0.5 * w_rated), 10.0);
        // At 4 × rated speed: T·ω_mech = 2 × rated power, so T = rated torque / 2.
        let t = l.torque(1e3, 4.0 * w_rated) * kt;
        assert!((t - 0.5 * m.rated_torque).abs() < 1e-9, "{t}");
        assert_eq!(l.torque(3.0, f64::NAN), 3.0);
        let bad = RatingsLimitTuning {
            power_ratio: 0.0,
            ..Default::default()
        };
        assert!(RatingsLimit::new(&bad, &m).is_err());
    }
}
