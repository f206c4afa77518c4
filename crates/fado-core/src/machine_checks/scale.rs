//! Ratings scaled together: `rated_current`, `rated_speed_rpm` and `rated_torque` all divided or
//! multiplied by 10 keep the torque, the resistance and a DC link derived from them consistent.
//! What they change is the machine's size as the ratings state it against the size its
//! windings show:
//!
//! - the armature reaction L_max·I/ψ and the reactance at rated speed over the resistance
//!   ω·L_min/R, which a rewinding of the same machine leaves unchanged and a common scale k of
//!   the ratings multiplies by k each (their product by k²);
//! - the rated power P = T_rated·ω_rated,mech (× k²) against the electrical time constant
//!   τ = L_min/R, which the ratings leave alone and which grows with a machine's size: about as
//!   P^0.75 (τ ∝ size², P ∝ size^2.5–3 at a given cooling).
//!
//! A machine's data are reported as ratings / 10 where τ is long for its rated power and the
//! product is below 1 (τ > [`TAU_PER_KW_HIGH`]·(P/1 kW)^0.75, or half that with the product
//! below [`SCALE_LOW`]), and as ratings × 10 where τ is short for its rated power and the
//! product is above 3 (τ < [`TAU_PER_KW_LOW`]·(P/1 kW)^0.75), or the product alone is above
//! [`SCALE_HIGH`].
//!
//! Measured on the repository's presets and test machines (`crates/fado-sim/tests/data/**`,
//! from a 31 W gimbal motor to a 2 MW machine) and the datasheet machines of
//! `crates/fado-sim/tests/data/datasheets/`: the machines with a product below 1 have τ at
//! most 0.46 × the long bound (the gimbal motor and the 48 V hub); those with a product above 3
//! have τ at least 3.4 × the short bound (the 10 kV machine). A slotless 40 W motor (maxon
//! EC 22: 85 µs, product 0.006) sits at 0.06 × the long bound: the product alone, which
//! separated / 10 from real machines above 0.03, takes it for ratings / 10. Every preset and
//! test machine with its ratings / 10 or × 10 is caught, but for four: ratings × 10 on the
//! Baldor PM-SyRM and the 32-pole torque IPM (caught by the product) and ratings / 10 on three
//! multirotor motors (caught by the product and the half bound); a slotless motor × 10
//! (product 0.6, the size of a real high-speed machine) is not.

use super::{Finding, MachineModel, Sink};
use crate::Real;

/// (L·I/ψ)·(ω·L/R) below which, with τ above half [`TAU_PER_KW_HIGH`]'s bound, the ratings
/// look divided by 10: 0.03 (real machines with a longer τ have ≥ 0.049, a gimbal motor).
pub const SCALE_LOW: f64 = 0.03;

/// (L·I/ψ)·(ω·L/R) above which the ratings look multiplied by 10: 200 (real machines ≤ 61,
/// a 2 MW machine; the presets × 10 are 23–4,200).
pub const SCALE_HIGH: f64 = 200.0;

/// The longest electrical time constant of a machine of 1 kW rated power, s: 10 ms (the bound
/// scales as P^0.75; real machines with a product below 1 reach 0.46 of it).
pub const TAU_PER_KW_HIGH: f64 = 10e-3;

/// The shortest electrical time constant of a machine of 1 kW rated power with a product above
/// 3, s: 0.25 ms (the bound scales as P^0.75; real machines have at least 3.4 × it).
pub const TAU_PER_KW_LOW: f64 = 0.25e-3;

/// (P/1 kW)^0.75.
fn size(power: f64) -> f64 {
    let p = power / 1e3;
    p.step_sqrt() * p.step_sqrt().step_sqrt()
}

/// [`Finding::RatingScale`] when the ratings of `m` look scaled.
pub(super) fn scaled(m: &MachineModel<f64>) -> Option<Finding> {
    let reaction = m.ld.max(m.lq) * m.rated_current / super::flux_base(m);
    let x_over_r = m.rated_speed() * m.ld.min(m.lq) / m.rs;
    let product = reaction * x_over_r;
    let tau = m.ld.min(m.lq) / m.rs;
    let power = m.rated_torque * m.rated_speed_mech();
    let (long, short) = tau_bounds(power);
    let divided = (product < 1.0 && tau > long) || (product < SCALE_LOW && tau > 0.5 * long);
    let multiplied = product > SCALE_HIGH || (product > 3.0 && tau < short);
    (divided || multiplied).then_some(Finding::RatingScale {
        reaction,
        x_over_r,
        tau,
        power,
        divided,
    })
}

/// Pushes [`Finding::RatingScale`] when [`scaled`].
pub(super) fn check(m: &MachineModel<f64>, out: &mut impl Sink) {
    if let Some(f) = scaled(m) {
        out.push(f);
    }
}

/// The bounds on τ for a rated power (long, short), s.
pub(super) fn tau_bounds(power: f64) -> (f64, f64) {
    (TAU_PER_KW_HIGH * size(power), TAU_PER_KW_LOW * size(power))
}
