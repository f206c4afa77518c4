//! A free rotor turned onto a well-observed axis before the current-sensor gain calibration.
//!
//! # Why
//! The gain calibration ([`gain_calibration`](crate::control::gain_calibration)) holds its d
//! current along the rotor's d axis, the only direction in which it makes no torque. Where
//! that axis leaves one phase with less than `min_observability` of the current (within
//! ±0.2 rad of π/6 + k·π/3: 38 % of the start angles), that phase's gain is unobservable and
//! the calibration is skipped ([`GainCalibrationStatus::Unobservable`]): the mismatch stays.
//! On a motor whose resistive drop is large against its magnet flux the mismatch then loses a
//! loaded passage through zero speed. Its negative-sequence current error R̂s·Δi is a DC
//! integrand error below the mode threshold, which walks θ̂ along the flux circle; the current
//! vector turns off the q axis, the rotor stalls where the true q current equals the load, and
//! the speed loop's integral winds the current up, which raises Δi and the walk with it.
//! Measured on the `outrunner-cheetah-24v` preset (R̂s·I_rated/λ̂f = 766 rad/s; a 0.5 %
//! mismatch, `reversal`, sensor seed 1): started at 0.35–0.70 rad the calibration is skipped;
//! the reversal stalls with |θ − θ̂| = 1.2 rad at 0.35–0.60 and reaches 0.23–0.25 rad (its
//! bound 0.25) at 0.65–0.70; without the sensors' gain error every one of these angles passes
//! within 0.004 rad.
//!
//! # The rule
//! A rotor that no brake holds ([`StartupTuning::rotor_held`] false) turns with a d current:
//! that is how a drive aligns it. Where the given angle θ0 is unobservable, the drive turns the
//! d current's axis from θ0 to the nearest of the six axes k·π/3 (every phase carrying at least
//! half the current; at most π/6 away), the current loop holding the calibration's lower level
//! I₁, so the rotor follows. Then the calibration runs there, and the drive starts from there.
//!
//! The turn follows a cycloid, φ(s) = θ0 + Δ·(s − sin(2πs)/(2π)) for s from 0 to 1: its
//! acceleration is one sine period, zero at both ends. A rotor held by the d current is a
//! spring of natural frequency ω_n = √(1.5·p²·λ̂a·I₁/Ĵ) (electrical, λ̂a the active flux at
//! I₁). Driven through a cycloid of duration T the undamped spring keeps a residual swing of at
//! most |sin(π·r)|/(π·r·(r² − 1)) of Δ, with r = ω_n·T/(2π) swing periods: none for a whole
//! number r ≥ 2, and with [`TURN_SWING_PERIODS`] = 3 at most 1.3 % of Δ wherever r lands
//! near 3 (0.007 rad for the largest turn, π/6), well within what the calibration's
//! current-mode settling and its voltage-mode hold take: the hold damps the swing in time constants of the model's swing,
//! and its motion test reads a swing as motion only above 0.5 % of the rated speed's back-EMF
//! (on the cheetah preset an amplitude of 0.12 rad). A model inertia off by a factor of two
//! changes r by √2 and keeps the residual below 4.3 % of Δ. A turn longer than
//! [`MAX_TURN_TIME`] (a heavy rotor on a weak current: the paper's motor, the servo, the
//! IPMSM presets) is not made, and the calibration is skipped as `Unobservable`.
//!
//! # Limits
//! The rotor must be free to turn and unloaded: a load holds it off the turned axis by its
//! torque over the stiffness 1.5·p·λ̂a·I₁ (per electrical rad), which the drive would start
//! with as an angle error; a brake must be declared (`rotor_held`), and then the calibration
//! turns only its current ([`AngleSearch::gain_axis`]).
//!
//! [`GainCalibrationStatus::Unobservable`]: crate::control::GainCalibrationStatus::Unobservable
//! [`StartupTuning::rotor_held`]: crate::control::StartupTuning::rotor_held
//! [`AngleSearch::gain_axis`]: crate::control::AngleSearch::gain_axis

use crate::control::gain_calibration::GainCalibration;
use crate::{MachineModel, Real};

/// Duration of the turn in periods of the rotor's swing about the calibration's current
/// \[A\]: about three periods leave at most 1.3 % of the turn as a residual swing (module docs).
pub const TURN_SWING_PERIODS: f64 = 3.0;

/// Longest turn made, s \[A\]: the budget of one of the calibration's holds
/// (`GAIN_CALIBRATION_MAX_HOLD_TIME`). The turn delays the start, and a rotor too heavy for
/// it gains little from it: on the paper's motor (three swing periods 0.43 s) the mismatch
/// left walks θ̂ at 0.26 rad/s, and `stops` from θ0 = 0.5 passes at 0.111 rad unturned but
/// at 0.355 rad turned, its start pushed into the scenario's load step. The multirotor and
/// outrunner motors turn in 0.10–0.15 s.
pub const MAX_TURN_TIME: f64 = 0.2;

/// The nearest of the six axes k·π/3 to `theta` (electrical rad, any finite value): every
/// phase carries at least half of a current along it.
pub fn well_observed_axis<T: Real>(theta: T) -> T {
    let sixth = T::pi() / T::lit(3.0);
    // (−π, π] + π → (0, 2π]: k in 0..=6, k·π/3 − π a multiple of π/3.
    let k = ((crate::wrap_angle(theta) + T::pi()) / sixth + T::lit(0.5)).index_floor(6);
    T::from_index(k) * sixth - T::pi()
}

/// The natural frequency ω_n (electrical rad/s) of a rotor held by the d current `i_d` (A):
/// √(1.5·p²·λ̂a·i_d/Ĵ), λ̂a the model's active flux at `i_d` (the damping left out).
pub fn swing_frequency<T: Real>(machine: &MachineModel<T>, i_d: T) -> T {
    let p = T::from_index(machine.pole_pairs as usize);
    let stiffness = T::lit(1.5) * p * p * machine.active_flux(i_d) * i_d;
    (stiffness / machine.inertia)
        .step_max(T::zero())
        .step_sqrt()
}

/// The turn of a free rotor from an unobservable angle onto [`well_observed_axis`] (module
/// docs). Allocation-free; [`step`](Self::step) once per sample until it returns `None`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CalibrationTurn<T> {
    from: T,
    delta: T,
    samples: u32,
    total: u32,
    current: T,
}

impl<T: Real> CalibrationTurn<T> {
    /// The turn for a rotor at `theta0` held by the d current `current` (A, the calibration's
    /// lower level) at sampling period `ts`: `None` where none is needed (`theta0` observable
    /// to `min_observability`, or not finite) or possible (a swing too slow for
    /// [`MAX_TURN_TIME`], or no stiffness).
    pub fn plan(
        machine: &MachineModel<T>,
        theta0: T,
        current: T,
        min_observability: T,
        ts: T,
    ) -> Option<Self> {
        // NaN compares false: a non-finite angle or share plans no turn.
        if !theta0.is_finite() || GainCalibration::observability(theta0) >= min_observability {
            return None;
        }
        let omega_n = swing_frequency(machine, current);
        let time = T::lit(TURN_SWING_PERIODS) * T::two_pi() / omega_n;
        if !(time <= T::lit(MAX_TURN_TIME) && ts > T::zero()) {
            return None;
        }
        let to = well_observed_axis(theta0);
        let total = (time / ts).index_floor(u32::MAX as usize) as u32 + 1;
        Some(Self {
            from: theta0,
            delta: crate::wrap_angle(to - theta0),
            samples: 0,
            total,
            current,
        })
    }

    /// The axis the turn ends at (electrical rad).
    pub fn target(&self) -> T {
        self.from + self.delta
    }

    /// The d current that turns the rotor (A).
    pub fn current(&self) -> T {
        self.current
    }

    /// The turn's duration in samples.
    pub fn duration_samples(&self) -> u32 {
        self.total
    }

    /// The d current's axis at this sample (electrical rad), or `None` once the turn is over.
    pub fn step(&mut self) -> Option<T> {
        if self.samples > self.total {
            return None;
        }
        let s = T::from_index(self.samples as usize) / T::from_index(self.total as usize);
        self.samples += 1;
        let (sin, _) = (T::two_pi() * s).step_sin_cos_any();
        Some(self.from + self.delta * (s - sin / T::two_pi()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::{FRAC_PI_3, FRAC_PI_6, PI};

    /// The `outrunner-cheetah-24v` preset's model.
    fn cheetah() -> MachineModel<f64> {
        MachineModel {
            rs: 0.105,
            ld: 30e-6,
            lq: 30e-6,
            flux_linkage: 0.0024,
            pole_pairs: 21,
            inertia: 5e-4,
            viscous_friction: 7e-5,
            rated_current: 17.5,
            rated_speed_rpm: 1800.0,
            rated_torque: 1.32,
            dc_voltage: 24.0,
            ..MachineModel::paper()
        }
    }

    #[test]
    fn the_axis_is_the_nearest_sixth_and_every_phase_carries_half() {
        for k in -3..=3 {
            for off in [-0.5, -0.2, 0.0, 0.2, 0.5] {
                let axis = k as f64 * FRAC_PI_3;
                let found = well_observed_axis(axis + off);
                let d = crate::wrap_angle(found - axis);
                assert!(d.abs() < 1e-12, "{k} {off}: {found}");
                assert!((GainCalibration::observability(found) - 0.5).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn only_an_unobservable_angle_is_turned_and_by_at_most_a_twelfth_turn() {
        let m = cheetah();
        let plan = |theta: f64| CalibrationTurn::plan(&m, theta, 8.75, 0.2, 25e-6);
        // Observable angles (share ≥ 0.2) stay; the zero of a phase's share is turned.
        for theta in [0.0, 0.3, 0.75, 1.0, -2.0] {
            assert!(plan(theta).is_none(), "{theta}");
        }
        for k in 0..6 {
            let zero = FRAC_PI_6 + k as f64 * FRAC_PI_3;
            for off in [-0.15, 0.0, 0.15] {
                let turn = plan(zero + off).unwrap();
                let d = crate::wrap_angle(turn.target() - (zero + off));
                assert!(d.abs() <= FRAC_PI_6 + 1e-12, "{zero} {off}: {d}");
                assert!((GainCalibration::observability(turn.target()) - 0.5).abs() < 1e-9);
            }
        }
        assert!(plan(f64::NAN).is_none());
        // The paper's motor: three swing periods at its I₁ take 0.43 s, beyond the budget.
        let paper = MachineModel::<f64>::paper();
        let i1 = 0.5 * paper.rated_current;
        let periods = TURN_SWING_PERIODS * 2.0 * PI / swing_frequency(&paper, i1);
        assert!((periods - 0.43).abs() < 0.01, "{periods}");
        assert!(CalibrationTurn::plan(&paper, 0.5, i1, 0.2, 1e-4).is_none());
    }

    #[test]
    fn the_cycloid_starts_and_ends_at_rest_and_lasts_three_swing_periods() {
        let m = cheetah();
        let mut turn = CalibrationTurn::plan(&m, 0.5, 8.75, 0.2, 25e-6).unwrap();
        // ω_n = √(1.5·21²·2.4e-3·8.75/5e-4) = 166.7 rad/s: three periods 0.113 s.
        let omega_n = swing_frequency(&m, 8.75);
        assert!((omega_n - 166.7).abs() < 0.1, "{omega_n}");
        let n = turn.duration_samples();
        assert!((n as f64 * 25e-6 - 6.0 * PI / omega_n).abs() < 25e-6, "{n}");
        let mut angles = [0.0; 3];
        let mut count = 0;
        let mut last = 0.0;
        while let Some(a) = turn.step() {
            if count < 3 {
                angles[count] = a;
            }
            count += 1;
            last = a;
        }
        assert_eq!(count, n as usize + 1);
        assert_eq!(angles[0], 0.5);
        assert!((last - turn.target()).abs() < 1e-12);
        assert!(turn.target().abs() < 1e-12, "{}", turn.target());
        // Zero velocity and acceleration at the start: the second step is third-order small.
        let step = (angles[1] - angles[0]).abs();
        assert!(step < 1e-6, "{step}");
        assert!(turn.step().is_none());
    }

    /// The residual swing of an undamped spring driven through the cycloid, integrated with
    /// small steps: none at three periods, and within its bound 1/(π·r·(r² − 1)), below 4.3 %,
    /// with the inertia off by two either way (module docs).
    #[test]
    fn the_residual_swing_of_a_spring_is_within_its_bound() {
        let residual = |r: f64| {
            let (omega, h) = (1.0, 1e-3);
            let t_turn = r * 2.0 * PI / omega;
            let (mut x, mut v, mut t) = (0.0_f64, 0.0_f64, 0.0_f64);
            let target = |t: f64| {
                let s = (t / t_turn).min(1.0);
                s - (2.0 * PI * s).sin() / (2.0 * PI)
            };
            let mut amp: f64 = 0.0;
            while t < t_turn + 4.0 * PI / omega {
                // Semi-implicit Euler on x'' = ω²·(φ(t) − x).
                v += h * omega * omega * (target(t) - x);
                x += h * v;
                t += h;
                if t > t_turn {
                    amp = amp.max((x - 1.0).abs());
                }
            }
            amp
        };
        assert!(residual(3.0) < 0.003, "{}", residual(3.0));
        for r in [3.0 / 2.0_f64.sqrt(), 3.0 * 2.0_f64.sqrt()] {
            let bound = 1.0 / (PI * r * (r * r - 1.0));
            let res = residual(r);
            assert!(
                res <= 1.02 * bound && res > 0.1 * bound && bound < 0.045,
                "{r}: {res}"
            );
        }
    }
}
