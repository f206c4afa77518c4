//! Reference estimators fado is compared against: the same inputs, the same rotor-flux angle
//! (eq. (5)-(6)) and the same type-2 trackers (T2S-1 60 Hz, T2S-2 35 Hz, [`crate::tracker`]),
//! so that a comparison isolates how the *stator flux* is obtained.
//!
//! | module | flux from | what bounds the integrator drift |
//! |---|---|---|
//! | [`lpf_integrator`] | 1/(s + ωc) with gain/phase compensation at ω̂ | the low-pass pole ωc |
//! | [`ortega`] | Lee, Hong, Nam, Ortega, Praly, Astolfi (2010) nonlinear observer | pulling \|λs − L̂·i\| to λ̂f |
//! | [`emf_observer`] | extended-EMF observer in α-β, angle = ∠ê − sgn(ω̂)·π/2 | none needed: no integrator |
//!
//! Every baseline implements [`RotorAngleEstimator`](crate::RotorAngleEstimator) and follows
//! the crate's rules: a flat config with documented defaults, `new(config)` naming a bad
//! field, `step`/`align`/`reset`, allocation-free, generic over `f32`/`f64`, and a rejected
//! non-finite (or overflowing) sample leaves the state untouched and sets
//! `diagnostics.input_fault`. [`Diagnostics`](crate::Diagnostics) fields a baseline has no
//! counterpart for stay at their defaults (`mode`, `flag_limit`, `limiter_clamping`,
//! `disturbance`).
//!
//! # Where the baselines are expected to fail
//! They are sound at medium speed (tests: ±300 r/min, 4 pole pairs, loaded and unloaded,
//! settled |θ − θ̂| well below 0.05 rad with an exact machine). Each module documents its
//! own failure region; in short, all three lose the angle at and near standstill, where
//! fado's limiter and d-axis injection (Fig. 6, eq. (23)) take over:
//! - the compensated LPF cannot integrate below ~ωc and turns a DC integrand error ε (current
//!   offsets, R̂s error on a DC current, dead time) into a standing flux error ε/ωc;
//! - the Ortega observer corrects only the flux *magnitude*: its tangential error decays at
//!   ω²/ω_obs, a q-axis voltage error or a wrong λ̂f enters the angle amplified by ω_obs/ω, and
//!   beyond ω²/ω_obs² of λf the estimate slips poles (so the default gain is scheduled,
//!   ω_obs = 2|ω̂|, as VESC does in spirit); at standstill it is an open integrator;
//! - the EMF observer has nothing to measure at zero speed (e = jω·λf) and needs the sign of
//!   ω̂, so a reversal through zero flips its angle reference.

pub mod emf_observer;
pub mod lpf_integrator;
pub mod ortega;

pub use emf_observer::{EmfObserverConfig, EmfObserverEstimator};
pub use lpf_integrator::{LpfIntegratorConfig, LpfIntegratorEstimator};
pub use ortega::{OrtegaConfig, OrtegaEstimator};

/// The current an `align` may start from: a non-finite one, or one so large that the start-up
/// flux λ̂f·e^{jθ0} + L̂q·i would overflow (found by fuzzing, f32 with L̂q = 3e37 H), is
/// taken as zero.
pub(crate) fn usable_align_current<T: Real>(i_ab: Ab<T>, lq_hat: T, flux_linkage_hat: T) -> Ab<T> {
    let li = i_ab * lq_hat;
    let bound = Ab::new(
        li.alpha.abs() + flux_linkage_hat,
        li.beta.abs() + flux_linkage_hat,
    );
    if bound.is_finite() { i_ab } else { Ab::zero() }
}

/// The sample-rejection rule every baseline shares (the same contract as
/// [`crate::SensorlessEstimator::step`]): a non-finite input is refused, and a finite but absurd
/// one that overflows a state is rolled back, so the state is never poisoned; either way the
/// last good estimate is returned with `input_fault` set and the sample is counted.
pub(crate) trait GuardedStep<T: Real>: Copy {
    /// The estimator's own update; `None` when a new state came out non-finite.
    fn step_unchecked(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Option<crate::Estimate<T>>;
    /// The last good estimate and the rejected-sample counter.
    fn record(&mut self) -> (&mut crate::Estimate<T>, &mut u32);

    /// One guarded sample.
    #[inline]
    fn guarded_step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> crate::Estimate<T> {
        if !(v_ab.is_finite() && i_ab.is_finite()) {
            return self.reject();
        }
        let backup = *self;
        match self.step_unchecked(v_ab, i_ab) {
            Some(out) => {
                *self.record().0 = out;
                out
            }
            None => {
                *self = backup;
                self.reject()
            }
        }
    }

    /// Counts the sample and repeats the last good estimate, flagged.
    fn reject(&mut self) -> crate::Estimate<T> {
        let (last, rejected) = self.record();
        *rejected = rejected.saturating_add(1);
        let mut out = *last;
        out.diagnostics.input_fault = true;
        out
    }
}

use crate::error::{ConfigError, check};
use crate::tracker::{BandwidthDefinition, TrackerConfig, TypeTwoTracker};
use crate::{Ab, Real};

/// Renames the field of a sub-block's error to the flat config's field name.
fn renamed(field: &'static str) -> impl Fn(ConfigError) -> ConfigError {
    move |e| match e {
        ConfigError::OutOfRange { expected, .. } => ConfigError::OutOfRange { field, expected },
        ConfigError::NotFinite { .. } => ConfigError::NotFinite { field },
        ConfigError::NotPositive { .. } => ConfigError::NotPositive { field },
        ConfigError::Negative { .. } => ConfigError::Negative { field },
    }
}

/// The integrand v* − R̂s·i of eq. (3) over one sampling interval, with the same forward
/// rectangle and optional current averaging as [`crate::flux::FluxIntegrator`] (SPEC §1), so
/// that every estimator sees the same voltage-model input.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Integrand<T> {
    rs_hat: T,
    average_current: bool,
    i_prev: Ab<T>,
    has_prev: bool,
}

impl<T: Real> Integrand<T> {
    fn new(rs_hat: T, average_current: bool) -> Result<Self, ConfigError> {
        Ok(Self {
            rs_hat: check::non_negative("rs_hat", rs_hat)?,
            average_current,
            i_prev: Ab::zero(),
            has_prev: false,
        })
    }

    fn reset(&mut self) {
        self.i_prev = Ab::zero();
        self.has_prev = false;
    }

    /// Starts with a known current at the beginning of the first interval.
    fn reset_to(&mut self, i_ab: Ab<T>) {
        self.i_prev = i_ab;
        self.has_prev = true;
    }

    /// The current sampled at the start of the coming interval, when known.
    fn previous_current(&self) -> Option<Ab<T>> {
        self.has_prev.then_some(self.i_prev)
    }

    /// The current the resistive drop of the last interval is computed with.
    #[inline]
    fn interval_current(&mut self, i_ab: Ab<T>) -> Ab<T> {
        let i = if self.average_current && self.has_prev {
            (i_ab + self.i_prev) * T::lit(0.5)
        } else {
            i_ab
        };
        self.i_prev = i_ab;
        self.has_prev = true;
        i
    }

    /// v* − R̂s·i for the interval that ends at this sample.
    #[inline]
    fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Ab<T> {
        let i = self.interval_current(i_ab);
        v_ab - i * self.rs_hat
    }
}

/// The tracker settings every baseline shares with [`crate::EstimatorConfig`].
#[derive(Clone, Copy, Debug)]
struct TrackerSettings<T> {
    ts: T,
    t2s1_bandwidth_hz: T,
    t2s2_bandwidth_hz: T,
    damping: T,
    definition: BandwidthDefinition,
    hold_ratio: T,
    flux_linkage_hat: T,
}

/// One sample of the two trackers.
#[derive(Clone, Copy, Debug)]
struct Tracked<T> {
    theta: T,
    omega: T,
    omega_control: T,
    theta_direct: T,
    hold: bool,
}

/// T2S-1 (angle, and the speed the baseline feeds back to itself) and T2S-2 (control speed),
/// fed with ∠λ̂r and coasting while |λ̂r| is below the hold level (SPEC §3), exactly as in
/// [`crate::SensorlessEstimator`].
#[derive(Clone, Copy, Debug, PartialEq)]
struct AngleTrackers<T: Real> {
    t2s1: TypeTwoTracker<T>,
    t2s2: TypeTwoTracker<T>,
    hold_level_sq: T,
}

impl<T: Real> AngleTrackers<T> {
    fn new(s: TrackerSettings<T>) -> Result<Self, ConfigError> {
        check::positive("tracker_damping", s.damping)?;
        let hold = check::non_negative("tracker_hold_ratio", s.hold_ratio)?;
        check::below("tracker_hold_ratio", hold, T::one(), "below 1")?;
        let tracker = |bandwidth_hz| TrackerConfig {
            ts: s.ts,
            bandwidth_hz,
            damping: s.damping,
            definition: s.definition,
        };
        let t2s1 = TypeTwoTracker::new(tracker(s.t2s1_bandwidth_hz))
            .map_err(renamed("t2s1_bandwidth_hz"))?;
        let t2s2 = TypeTwoTracker::new(tracker(s.t2s2_bandwidth_hz))
            .map_err(renamed("t2s2_bandwidth_hz"))?;
        let level = hold * s.flux_linkage_hat;
        Ok(Self {
            t2s1,
            t2s2,
            hold_level_sq: level * level,
        })
    }

    fn reset_to(&mut self, theta0: T) {
        self.t2s1.reset_to(theta0, T::zero());
        self.t2s2.reset_to(theta0, T::zero());
    }

    /// ω̂ of T2S-1 (rad/s).
    #[inline]
    fn speed(&self) -> T {
        self.t2s1.speed()
    }

    /// θ̂ of T2S-1 (rad).
    fn angle(&self) -> T {
        self.t2s1.angle()
    }

    /// (Kp, Ki) of T2S-1.
    fn t2s1_gains(&self) -> (T, T) {
        self.t2s1.gains()
    }

    #[inline]
    fn step(&mut self, lambda_r: Ab<T>) -> Option<Tracked<T>> {
        let hold = lambda_r.norm_squared() < self.hold_level_sq;
        // eq. (6)'s atan2 as fado's step computes it (`libm` in `f64`, the tested `f32`
        // approximation in `f32`): the baselines and fado pay the same for the same angle.
        let theta_direct = crate::rotor_flux::rotor_angle(lambda_r);
        let (theta, omega, omega_control) = if hold {
            let (th, w) = self.t2s1.coast();
            (th, w, self.t2s2.coast().1)
        } else {
            let (th, w) = self.t2s1.step(theta_direct).ok()?;
            (th, w, self.t2s2.step(theta_direct).ok()?.1)
        };
        Some(Tracked {
            theta,
            omega,
            omega_control,
            theta_direct,
            hold,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MachineModel;
    use crate::RotorAngleEstimator;

    /// Warms `est` up on a rotating machine-like input, then checks that a non-finite and an
    /// overflowing sample are both refused with the state left exactly as it was.
    fn rejects_bad_samples<E: RotorAngleEstimator<f32> + Clone>(mut est: E) {
        let (w, ts) = (125.0_f32, 1e-4_f32);
        let mut last = None;
        for n in 0..200 {
            let th = w * ts * n as f32;
            let v = Ab::from_polar(11.0, th + 1.6);
            let i = Ab::from_polar(5.0, th + 1.5);
            last = Some(est.step(v, i));
        }
        let mut last = last.unwrap();
        for (v, i) in [
            (Ab::new(f32::NAN, 0.0), Ab::new(1.0, 0.0)),
            (Ab::new(1.0, 0.0), Ab::new(0.0, f32::INFINITY)),
            // Finite but absurd: v − R̂s·i overflows f32.
            (Ab::new(3e38, 0.0), Ab::new(-3e38, 0.0)),
        ] {
            let mut twin = est.clone();
            let out = est.step(v, i);
            assert!(out.diagnostics.input_fault, "{}", est.name());
            assert_eq!(out.theta, last.theta);
            assert_eq!(out.diagnostics.lambda_r, last.diagnostics.lambda_r);
            let good = (Ab::new(2.0, 3.0), Ab::new(1.0, -1.0));
            let next = est.step(good.0, good.1);
            assert_eq!(next, twin.step(good.0, good.1));
            assert!(!next.diagnostics.input_fault);
            last = next;
        }
    }

    #[test]
    fn every_baseline_rejects_non_finite_and_overflowing_samples() {
        rejects_bad_samples(
            LpfIntegratorEstimator::new(LpfIntegratorConfig::for_machine(&MachineModel::paper()))
                .unwrap(),
        );
        rejects_bad_samples(
            OrtegaEstimator::new(OrtegaConfig::for_machine(&MachineModel::paper())).unwrap(),
        );
        rejects_bad_samples(
            EmfObserverEstimator::new(EmfObserverConfig::for_machine(&MachineModel::paper()))
                .unwrap(),
        );
    }

    #[test]
    fn names_are_distinct() {
        let names = [
            LpfIntegratorEstimator::<f64>::new(LpfIntegratorConfig::for_machine(
                &MachineModel::paper(),
            ))
            .unwrap()
            .name(),
            OrtegaEstimator::<f64>::new(OrtegaConfig::for_machine(&MachineModel::paper()))
                .unwrap()
                .name(),
            EmfObserverEstimator::<f64>::new(
                EmfObserverConfig::for_machine(&MachineModel::paper()),
            )
            .unwrap()
            .name(),
        ];
        assert_eq!(names, ["lpf-integrator", "ortega", "emf-observer"]);
    }

    #[test]
    fn align_sets_angle_and_reset_returns_to_the_configured_start() {
        fn check<E: RotorAngleEstimator<f64>>(mut est: E, initial: f64) {
            est.align(1.0, Ab::new(3.0, -2.0));
            for _ in 0..50 {
                est.step(Ab::new(5.0, 1.0), Ab::new(3.0, -2.0));
            }
            est.reset();
            // At reset ω̂ = 0 and no voltage: the first estimate sits at the configured angle.
            let out = est.step(Ab::zero(), Ab::zero());
            assert!(
                (out.theta - initial).abs() < 1e-9,
                "{}: {}",
                est.name(),
                out.theta
            );
        }
        check(
            LpfIntegratorEstimator::new(LpfIntegratorConfig {
                initial_angle: 0.3,
                ..LpfIntegratorConfig::for_machine(&MachineModel::paper())
            })
            .unwrap(),
            0.3,
        );
        check(
            OrtegaEstimator::new(OrtegaConfig {
                initial_angle: 0.3,
                ..OrtegaConfig::for_machine(&MachineModel::paper())
            })
            .unwrap(),
            0.3,
        );
        check(
            EmfObserverEstimator::new(EmfObserverConfig {
                initial_angle: 0.3,
                ..EmfObserverConfig::for_machine(&MachineModel::paper())
            })
            .unwrap(),
            0.3,
        );
    }
}
