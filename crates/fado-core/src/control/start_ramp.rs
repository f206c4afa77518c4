//! The speed reference at the drive's start: from the rotor's speed at the start-up's end
//! towards the user's reference at a bounded acceleration, then the user's reference itself.
//!
//! # Why
//! The start-up (offset and gain calibrations, the angle search) takes tenths of a second,
//! during which the application's speed profile may already have left zero: a ramp that
//! starts at t = 0.2 s and reaches 20 % of the rated speed at 1 s stands at 6.4 % (195 r/min
//! on a 3000 r/min servo motor) when the drive starts at 0.46 s. Stepped to it, the speed loop
//! asks for the current limit and the rotor accelerates at several times its rated
//! acceleration from standstill, where the estimator's speed trackers lag most: on the 1.5 kW
//! servo motor of `crates/fado-sim/tests/calibration_load_classes.rs` (its inertia derived
//! from its ratings) |θ − θ̂| reaches 0.26 rad after the step; on a ramp from zero, 0.25 rad
//! at the rated torque's acceleration, 0.20 rad at 0.15 of it and 0.14 rad at 0.1 of it; with
//! this module's defaults (a step of 7 Hz, then 0.05 of the rated acceleration) 0.16 rad. Drives start a
//! motor on a speed ramp of their own for the same reason (ST's MCSDK: the start-up's speed
//! ramp before the observer's handover; VESC and ODrive: a rate-limited speed or velocity
//! ramp of their own, `vel_ramp_rate`).
//!
//! # The rule
//! At the start-up's end ([`StartRamp::arm`]) the ramp starts from the rotor's speed as the
//! drive knows it there (zero for a rotor at rest; the estimate starts from zero). A user's
//! reference within 2π·[`StartRampTuning::step_hz`] (electrical rad/s) of it passes at once;
//! one further away is stepped to by that much and then approached at the reference's own
//! rate of change plus at most [`StartRampTuning::accel_ratio`] × the rated acceleration
//! a_rated = p·T_rated/Ĵ (electrical) per second: the gap left after the step closes at that
//! acceleration whatever the reference does meanwhile, so a user's ramp faster than the
//! bound is caught up with rather than chased. Once the ramp meets the reference it ends:
//! from then on the reference passes bit for bit.
//!
//! The step is an electrical speed because what it has to stay within is the estimator's
//! speed tracker (T2S-2, a type-2 loop of natural frequency ωn = 2π·35 Hz/2.058 = 107 rad/s
//! at its default bandwidth): a speed step Δω lags it by at most 0.456·Δω/ωn (ζ = 1/√2),
//! 0.19 rad for the default 7 Hz (44 rad/s). The servo motor above (4 pole pairs) follows
//! steps of 42, 63 and 84 rad/s (100, 150 and 200 r/min) with 0.094, 0.176 and 0.240 rad. The
//! scenarios of the paper start into references of at most 27.5 rad/s (fig9: −65.7 r/min on
//! 4 pole pairs), the presets' `reversal` and `stops` of at most 38 rad/s (the 1FT6084 servo:
//! −90.5 r/min on 4): none of them meets a ramp. A user's own reference later in the run is
//! never limited.

use crate::Real;
use crate::error::{ConfigError, check};
use crate::machine::MachineModel;
use crate::real::cast_record;

/// `[controller.start_ramp]`: the bounded acceleration of the speed reference from the
/// rotor's speed at the start-up's end to the user's (module docs).
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
pub struct StartRampTuning<T> {
    /// Largest acceleration of the start's speed reference, a multiple of the rated
    /// acceleration p·T_rated/Ĵ. Default 0.05 \[A\] (the rated speed in 3 s where Ĵ is derived
    /// from the ratings): on the 1.5 kW servo motor of the module docs |θ − θ̂| stays at
    /// 0.16 rad from a start into a reference already at 6.4 % of the rated speed (0.21 rad
    /// at 0.1, 0.26 rad stepped). 0 disables the ramp (the reference is stepped to).
    pub accel_ratio: T,
    /// Largest step of the start's speed reference from the rotor's speed, electrical Hz.
    /// Default 7 Hz \[A\]: 0.41 of the default T2S-2 tracker's natural frequency, a step it
    /// follows within 0.19 rad (0.094 rad measured after 42 rad/s; module docs).
    pub step_hz: T,
}

impl<T: Real> Default for StartRampTuning<T> {
    fn default() -> Self {
        Self {
            accel_ratio: T::lit(0.05),
            step_hz: T::lit(7.0),
        }
    }
}

cast_record!(StartRampTuning { accel_ratio, step_hz ; });

/// The start's speed ramp (module docs). Allocation-free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StartRamp<T> {
    /// Largest change of the reference per sample (electrical rad/s); 0: off.
    step: T,
    /// Largest step from the rotor's speed at the start (electrical rad/s, at least `step`).
    jump: T,
    /// The ramp's reference (electrical rad/s).
    value: T,
    /// The user's reference of the previous sample (electrical rad/s): the ramp closes its
    /// gap at `step` per sample on top of the reference's own change.
    last_reference: Option<T>,
    active: bool,
}

impl<T: Real> StartRamp<T> {
    /// The ramp of `machine` (its rated torque and Ĵ) sampled at `ts`, not armed. A machine
    /// without an inertia (Ĵ = 0) or ratings gives no ramp.
    pub fn new(
        tuning: &StartRampTuning<T>,
        machine: &MachineModel<T>,
        ts: T,
    ) -> Result<Self, ConfigError> {
        let ratio = check::non_negative("start_ramp.accel_ratio", tuning.accel_ratio)?;
        let step_hz = check::non_negative("start_ramp.step_hz", tuning.step_hz)?;
        let p = T::lit(machine.pole_pairs as f64);
        let accel = p * machine.rated_torque / machine.inertia;
        // NaN compares false: no ramp.
        let step = if accel.is_finite() && accel > T::zero() {
            ratio * accel * ts
        } else {
            T::zero()
        };
        let jump = crate::real::max(T::two_pi() * step_hz, step);
        Ok(Self {
            step,
            jump: if jump.is_finite() { jump } else { step },
            value: T::zero(),
            last_reference: None,
            active: false,
        })
    }

    /// Starts the ramp from `speed` (electrical rad/s): the start-up's end.
    pub fn arm(&mut self, speed: T) {
        self.active = self.step > T::zero() && speed.is_finite();
        self.value = speed;
        self.last_reference = None;
    }

    /// Ends the ramp (the user's reference passes).
    pub fn disarm(&mut self) {
        self.active = false;
    }

    /// Still ramping.
    pub fn active(&self) -> bool {
        self.active
    }

    /// The speed reference of this sample for the user's `reference` (electrical rad/s):
    /// `reference` itself once the ramp has met it.
    #[inline(always)]
    pub fn step(&mut self, reference: T) -> T {
        if !self.active {
            return reference;
        }
        // The first sample after `arm` may step by `jump`; later ones close the gap at `step`
        // beyond the reference's own change since the last sample, so a reference that moves
        // on (a user's ramp) is caught up with, never chased.
        let limit = match self.last_reference {
            None => self.jump,
            Some(last) => {
                let moved = (reference - last).abs();
                if moved.is_finite() {
                    self.step + moved
                } else {
                    self.step
                }
            }
        };
        self.last_reference = Some(reference);
        let gap = reference - self.value;
        // NaN compares false: the reference passes.
        let beyond = gap.abs() > limit;
        if !beyond {
            self.active = false;
            return reference;
        }
        self.value += if gap > T::zero() { limit } else { -limit };
        self.value
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> StartRamp<f64> {
        let mut m = MachineModel::<f64>::paper();
        m.inertia = 0.01;
        // a_rated = 4 · 10 / 0.01 = 4000 rad/s²; 0.1 of it at 1 ms: 0.4 rad/s a sample.
        m.pole_pairs = 4;
        m.rated_torque = 10.0;
        // A step of 1 rad/s.
        let tuning = StartRampTuning {
            step_hz: 0.5 / core::f64::consts::PI,
            accel_ratio: 0.1,
        };
        StartRamp::new(&tuning, &m, 1e-3).unwrap()
    }

    #[test]
    fn a_reference_that_moves_on_is_caught_up_with() {
        // The user's ramp rises 1 rad/s a sample, faster than the ramp's own 0.4: the ramp
        // follows the reference's change plus 0.4, so the 9 rad/s gap left after the first
        // step closes at 0.4 a sample: met at the 24th sample after the step.
        let mut r = ramp();
        r.arm(0.0);
        let mut n = 0;
        while r.active() && n < 100 {
            let reference = 10.0 + n as f64;
            let out = r.step(reference);
            assert!(out <= reference, "{n}: {out} > {reference}");
            n += 1;
        }
        assert_eq!(n, 24, "caught up after {n} samples");
    }

    #[test]
    fn a_reference_ahead_at_the_start_is_reached_at_the_bounded_acceleration() {
        let mut r = ramp();
        r.arm(0.0);
        let mut out = [0.0; 5];
        for o in &mut out {
            *o = r.step(2.0);
        }
        assert!(
            (out[0] - 1.0).abs() < 1e-12 && (out[1] - 1.4).abs() < 1e-12,
            "{out:?}"
        );
        assert!((out[2] - 1.8).abs() < 1e-12, "{out:?}");
        assert_eq!(out[3], 2.0);
        assert!(!r.active());
        // Then the reference passes bit for bit, a step too.
        assert_eq!(r.step(123.456), 123.456);
    }

    #[test]
    fn a_reference_at_the_rotors_speed_passes_at_once() {
        let mut r = ramp();
        r.arm(0.0);
        assert_eq!(r.step(0.0), 0.0);
        assert!(!r.active());
        let mut r = ramp();
        r.arm(-2.0);
        assert_eq!(r.step(-1.0), -1.0);
    }

    #[test]
    fn the_ramp_runs_downwards_and_is_off_without_inertia_or_ratio() {
        let mut r = ramp();
        r.arm(1.0);
        assert!((r.step(-1.0) - 0.0).abs() < 1e-12);
        assert!((r.step(-1.0) + 0.4).abs() < 1e-12);
        let mut m = MachineModel::<f64>::paper();
        m.inertia = 0.0;
        let mut off = StartRamp::new(&StartRampTuning::default(), &m, 1e-3).unwrap();
        off.arm(0.0);
        assert_eq!(off.step(100.0), 100.0);
        let zero = StartRampTuning {
            accel_ratio: 0.0,
            ..StartRampTuning::default()
        };
        let mut off = StartRamp::new(&zero, &MachineModel::<f64>::paper(), 1e-3).unwrap();
        off.arm(0.0);
        assert_eq!(off.step(100.0), 100.0);
        let negative = StartRampTuning {
            accel_ratio: -1.0,
            ..StartRampTuning::default()
        };
        assert!(StartRamp::new(&negative, &m, 1e-3).is_err());
    }
}
