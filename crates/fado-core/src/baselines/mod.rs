//! Reference estimators fado is compared against: the same inputs, the same rotor-flux angle
//! (eq. (5)-(6)) and the same type-2 trackers (T2S-1 60 Hz, T2S-2 35 Hz, [`crate::tracker`]),
//! so that a comparison isolates how the *stator flux* is obtained.
//!
//! | module | flux from | what bounds the integrator drift |
//! |---|---|---|
//! | [`lpf_integrator`] | 1/(s + ωc) with gain/phase compensation at ω̂ | the low-pass pole ωc |
//! | [`ortega`] | Lee, Hong, Nam, Ortega, Praly, Astolfi (2010) nonlinear observer | pulling \|λs − L̂·i\| to λ̂f |
//! | [`emf_observer`] | extended-EMF observer in α-β, angle = ∠ê − sgn(ω̂)·π/2 | none needed: no integrator |
//! | [`reduced_order`] | Hinkkanen et al. (2018) reduced-order observer in estimated rotor coordinates, with its own angle and speed loop | correcting ψ̂ with the flux read from the current |
//!
//! Every baseline implements [`RotorAngleEstimator`] and
//! [`Baseline`], and follows the crate's rules: its config is the [`MachineModel`], the
//! [`CommonTuning`] every estimator shares and a small record of its own settings (plain
//! numbers with documented defaults), `new(config)` naming a bad field, `step`/`align`/`reset`, allocation-free, generic over `f32`/`f64`, and a rejected
//! sample leaves the state untouched and sets `diagnostics.input_fault`. A sample is rejected
//! when it is non-finite, when it lies outside what the machine and inverter can produce (the
//! bounds of [`crate::plausibility`], with fado's `plausible_*` ratios and defaults, from each
//! machine's `rated_current`, `dc_voltage` and `lq`: until 2026-11-28 a finite 1e6 A sample
//! went through and left a baseline's angle off), or when the new state it gives overflows
//! (each step computes its whole new state and commits it only if finite, as fado's does; until
//! 2026-11-28 each step copied the whole estimator as a backup instead). [`Diagnostics`](crate::Diagnostics) fields a baseline has no
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

/// The [`Integrand`] of a baseline from its machine model and [`CommonTuning`]: R̂s, the
/// current averaging and the sample bounds.
macro_rules! integrand_of {
    ($machine:expr, $common:expr, $ts:expr) => {
        super::Integrand::new(
            $machine.rs,
            $common.average_current,
            crate::plausibility::SampleBounds::from_ratios(
                $common.plausible_current_ratio,
                $common.plausible_voltage_ratio,
                $common.plausible_current_step_ratio,
                $machine.rated_current,
                $machine.dc_voltage,
                $machine.lq,
                $ts,
            )?,
        )
    };
}

/// A baseline's [`GuardedStep`] bookkeeping: its `last` estimate, `rejected_samples` counter and
/// `integrand`.
macro_rules! guarded_state {
    () => {
        fn record(&mut self) -> (&mut Estimate<T>, &mut u32) {
            (&mut self.last, &mut self.rejected_samples)
        }
        fn integrand(&mut self) -> &mut Integrand<T> {
            &mut self.integrand
        }
    };
}

/// [`RotorAngleEstimator`] of a baseline through its own `step`, `align` and `reset`, named
/// by [`Baseline::NAME`].
macro_rules! rotor_angle_estimator {
    ($ty:ident) => {
        impl<T: Real> RotorAngleEstimator<T> for $ty<T> {
            #[inline]
            fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T> {
                $ty::step(self, v_ab, i_ab)
            }
            fn align(&mut self, theta0: T, i_ab: Ab<T>) {
                $ty::align(self, theta0, i_ab)
            }
            fn reset(&mut self) {
                $ty::reset(self)
            }
            fn name(&self) -> &'static str {
                <Self as Baseline<T>>::NAME
            }
        }
    };
}

pub mod emf_observer;
pub mod lpf_integrator;
pub mod ortega;
pub mod reduced_order;

pub use emf_observer::{EmfObserverConfig, EmfObserverEstimator, EmfObserverSettings};
pub use lpf_integrator::{LpfIntegratorConfig, LpfIntegratorEstimator, LpfIntegratorSettings};
pub use ortega::{OrtegaConfig, OrtegaEstimator, OrtegaSettings};
pub use reduced_order::{ReducedOrderConfig, ReducedOrderEstimator, ReducedOrderSettings};

/// What every baseline shares with [`crate::EstimatorConfig`] besides the machine model: the
/// sampling period, the two type-2 trackers, the current averaging of the integrand, the
/// sample bounds and the start-up angle. One record, so that a comparison gives every
/// estimator the same values (`fado-sim` fills it from `[estimator]`). Defaults are fado's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommonTuning<T> {
    /// Sampling period Ts in s. Default 100 µs (paper, V).
    pub ts: T,
    /// Bandwidth of T2S-1 (angle, and the speed the baseline feeds back to itself) in Hz.
    /// Default 60 Hz (paper, V), as fado.
    pub t2s1_bandwidth_hz: T,
    /// Bandwidth of T2S-2 (speed for control) in Hz. Default 35 Hz (paper, V), as fado.
    pub t2s2_bandwidth_hz: T,
    /// Damping ratio of both trackers. Default 1/√2 (docs/method/estimator.md §4 \[A\]).
    pub tracker_damping: T,
    /// Meaning of the tracker bandwidths. Default −3 dB (docs/method/estimator.md §4).
    pub bandwidth_definition: BandwidthDefinition,
    /// Trackers coast while the estimated rotor flux is below this fraction of λ̂f. Default
    /// 0.2 (docs/method/estimator.md §4 \[A\]).
    pub tracker_hold_ratio: T,
    /// Average the current over the interval for the resistive drop. Default true (docs/method/estimator.md §1
    /// \[A\]).
    pub average_current: bool,
    /// Samples with |i| above this × the machine's `rated_current` are refused (see
    /// [`crate::plausibility`]). Default 4, as fado's
    /// ([`crate::plausibility::CURRENT_RATIO`]).
    pub plausible_current_ratio: T,
    /// Samples with |v| above this × the machine's `dc_voltage` are refused. Default 1.5, as
    /// fado's.
    pub plausible_voltage_ratio: T,
    /// A current that moved by more than this × (plausible voltage)·ts/L̂q per sample is
    /// refused; 0 switches the test off. Default 2, as fado's.
    pub plausible_current_step_ratio: T,
    /// Rotor angle assumed at reset (rad). Default 0 (docs/method/estimator.md §1 \[A\]).
    pub initial_angle: T,
}

impl<T: Real> Default for CommonTuning<T> {
    fn default() -> Self {
        Self {
            ts: T::lit(100e-6),
            t2s1_bandwidth_hz: T::lit(60.0),
            t2s2_bandwidth_hz: T::lit(35.0),
            tracker_damping: T::lit(core::f64::consts::FRAC_1_SQRT_2),
            bandwidth_definition: BandwidthDefinition::Minus3Db,
            tracker_hold_ratio: T::lit(0.2),
            average_current: true,
            plausible_current_ratio: T::lit(crate::plausibility::CURRENT_RATIO),
            plausible_voltage_ratio: T::lit(crate::plausibility::VOLTAGE_RATIO),
            plausible_current_step_ratio: T::lit(crate::plausibility::STEP_RATIO),
            initial_angle: T::zero(),
        }
    }
}

impl<T: Real> CommonTuning<T> {
    /// The two trackers of a baseline whose hold level is `tracker_hold_ratio` × λ̂f.
    fn trackers(&self, flux_linkage_hat: T) -> Result<AngleTrackers<T>, ConfigError> {
        let ts = check::positive("ts", self.ts)?;
        AngleTrackers::new(TrackerSettings {
            ts,
            t2s1_bandwidth_hz: self.t2s1_bandwidth_hz,
            t2s2_bandwidth_hz: self.t2s2_bandwidth_hz,
            damping: self.tracker_damping,
            definition: self.bandwidth_definition,
            hold_ratio: self.tracker_hold_ratio,
            flux_linkage_hat,
        })
    }
}

/// The configuration of a baseline: the drive's [`MachineModel`] (its R̂s, L̂q, λ̂f, rated
/// current and DC link), the [`CommonTuning`] every estimator shares, and the baseline's own
/// settings `S` (plain numbers whose defaults do not depend on the machine).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BaselineConfig<T: 'static, S> {
    /// The drive's model of the machine.
    pub machine: MachineModel<T>,
    /// Sampling, trackers, integrand and sample bounds, as fado's.
    pub common: CommonTuning<T>,
    /// The baseline's own settings.
    pub settings: S,
}

impl<T: Real, S: Default> BaselineConfig<T, S> {
    /// The default tuning around `machine`, sampled at 10 kHz.
    pub fn for_machine(machine: &MachineModel<T>) -> Self {
        Self {
            machine: *machine,
            common: CommonTuning::default(),
            settings: S::default(),
        }
    }
}

/// A baseline as a registry builds it: from the machine model, the [`CommonTuning`] and its
/// own settings.
pub trait Baseline<T: Real>: RotorAngleEstimator<T> + Sized {
    /// Its own settings (`[baselines.<name>]` in `fado-sim`'s TOML).
    type Settings: Copy + Default + PartialEq + core::fmt::Debug;
    /// Its name in tables, as [`RotorAngleEstimator::name`] gives it (`ortega`).
    const NAME: &'static str;
    /// Builds it; a bad value is named by its field (a machine field by the machine's name:
    /// `rs`, `lq`, `flux_linkage`, ...).
    fn from_config(config: BaselineConfig<T, Self::Settings>) -> Result<Self, ConfigError>;

    /// Builds it from its parts.
    fn build(
        machine: &MachineModel<T>,
        common: &CommonTuning<T>,
        settings: &Self::Settings,
    ) -> Result<Self, ConfigError> {
        Self::from_config(BaselineConfig {
            machine: *machine,
            common: *common,
            settings: *settings,
        })
    }
}

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
/// [`crate::SensorlessEstimator::step`]): a non-finite input, or one outside what the machine
/// and the inverter can produce ([`crate::plausibility`], the same bounds as fado's), is
/// refused, and a finite one that still overflows a state is not committed, so the state is never poisoned; either way the
/// last good estimate is returned with `input_fault` set and the sample is counted.
pub(crate) trait GuardedStep<T: Real> {
    /// The estimator's own update: it computes the whole new state first and commits it only
    /// if it is finite, returning `None` (and changing nothing) when it is not.
    fn step_unchecked(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Option<crate::Estimate<T>>;
    /// The last good estimate and the rejected-sample counter.
    fn record(&mut self) -> (&mut crate::Estimate<T>, &mut u32);
    /// The integrand, which holds the sample bounds and the last accepted current.
    fn integrand(&mut self) -> &mut Integrand<T>;

    /// One guarded sample.
    #[inline]
    fn guarded_step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> crate::Estimate<T> {
        if !self.integrand().plausible(v_ab, i_ab) {
            return self.reject();
        }
        match self.step_unchecked(v_ab, i_ab) {
            Some(out) => {
                *self.record().0 = out;
                out
            }
            None => self.reject(),
        }
    }

    /// Counts the sample and repeats the last good estimate, flagged.
    fn reject(&mut self) -> crate::Estimate<T> {
        self.integrand().refused();
        let (last, rejected) = self.record();
        *rejected = rejected.saturating_add(1);
        let mut out = *last;
        out.diagnostics.input_fault = true;
        out
    }
}

use crate::error::{ConfigError, check};
use crate::plausibility::SampleBounds;
use crate::tracker::{BandwidthDefinition, TrackerConfig, TypeTwoTracker};
use crate::{Ab, MachineModel, Real, RotorAngleEstimator};

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
/// rectangle and optional current averaging as [`crate::flux::FluxIntegrator`] (docs/method/estimator.md §1), so
/// that every estimator sees the same voltage-model input.
///
/// It is also where the measured samples enter, so it holds their plausibility bounds
/// ([`crate::plausibility`]) and the last accepted current the current step is checked
/// against, as [`crate::SensorlessEstimator`] does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Integrand<T> {
    rs_hat: T,
    average_current: bool,
    /// The last accepted current (zero, or the `align` current, after a reset).
    i_prev: Ab<T>,
    /// Whether `i_prev` was sampled at the start of the coming interval (averaging uses it).
    has_prev: bool,
    bounds: SampleBounds<T>,
    /// The current step the next sample may take from `i_prev`: one bound per sample since
    /// `i_prev` was accepted (so that a burst of refused samples cannot lock the estimator out).
    allowance: T,
}

impl<T: Real> Integrand<T> {
    fn new(rs_hat: T, average_current: bool, bounds: SampleBounds<T>) -> Result<Self, ConfigError> {
        let rs_hat = check::non_negative("rs", rs_hat)?;
        Ok(Self {
            rs_hat,
            average_current,
            i_prev: Ab::zero(),
            has_prev: false,
            bounds,
            allowance: bounds.step(),
        })
    }

    fn reset(&mut self) {
        self.i_prev = Ab::zero();
        self.has_prev = false;
        self.allowance = self.bounds.step();
    }

    /// After [`Self::reset`]: the current present at the reset, which the first sample's
    /// current step is checked against (not used for the resistive drop); an implausible one
    /// is not kept.
    fn note_current(&mut self, i_ab: Ab<T>) {
        if self.bounds.current_ok(i_ab) {
            self.i_prev = i_ab;
        }
    }

    /// Starts with a known current at the beginning of the first interval (an implausible one
    /// is not kept: the first interval then uses its own current alone).
    fn reset_to(&mut self, i_ab: Ab<T>) {
        self.reset();
        if self.bounds.current_ok(i_ab) {
            self.i_prev = i_ab;
            self.has_prev = true;
        }
    }

    /// Whether a sample is plausible (and finite): see [`SampleBounds::check`].
    #[inline]
    fn plausible(&self, v_ab: Ab<T>, i_ab: Ab<T>) -> bool {
        self.bounds.check(v_ab, i_ab, self.i_prev, self.allowance)
    }

    /// A sample was refused: the next may move one more step from the last accepted current.
    fn refused(&mut self) {
        self.allowance += self.bounds.step();
    }

    /// The current sampled at the start of the coming interval, when known.
    fn previous_current(&self) -> Option<Ab<T>> {
        self.has_prev.then_some(self.i_prev)
    }

    /// The current the resistive drop of the last interval is computed with.
    #[inline]
    fn interval_current(&self, i_ab: Ab<T>) -> Ab<T> {
        if self.average_current && self.has_prev {
            (i_ab + self.i_prev) * T::lit(0.5)
        } else {
            i_ab
        }
    }

    /// v* − R̂s·i for the interval that ends at this sample (the state is not changed: see
    /// [`Self::accept`]).
    #[inline]
    fn next(&self, v_ab: Ab<T>, i_ab: Ab<T>) -> Ab<T> {
        v_ab - self.interval_current(i_ab) * self.rs_hat
    }

    /// Commits an accepted sample's current: the start of the next interval, and what the
    /// next sample's current step is checked against.
    #[inline]
    fn accept(&mut self, i_ab: Ab<T>) {
        self.i_prev = i_ab;
        self.has_prev = true;
        self.allowance = self.bounds.step();
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
/// fed with ∠λ̂r and coasting while |λ̂r| is below the hold level (docs/method/estimator.md §4), exactly as in
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

    /// Warms `est` up on a rotating machine-like input, then checks that non-finite,
    /// overflowing and implausible samples are refused with the state left exactly as it was.
    pub(super) fn rejects_bad_samples<E: RotorAngleEstimator<f32> + Clone>(mut est: E) {
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
            // Finite, no overflow, but beyond what the machine and inverter can produce (issue
            // 14: before the bounds, 1e6 A left the baselines' angle off for good): 4 × the
            // rated current, 1.5 × the DC link, a 50 A jump in 100 µs on 2.63 mH.
            (Ab::new(1.0, 0.0), Ab::new(1e4, 0.0)),
            (Ab::new(1.0, 0.0), Ab::new(0.0, -1e5)),
            (Ab::new(1.0, 0.0), Ab::new(1e6, 1e6)),
            (Ab::new(1e4, 0.0), Ab::new(1.0, -1.0)),
            (Ab::new(2.0, 3.0), Ab::new(51.0, -1.0)),
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
        // A real step refused for one sample (its allowance grows per refused sample) is
        // accepted once the allowance covers it: a burst of refusals cannot lock it out.
        let far = Ab::new(40.0, -1.0);
        let v = Ab::new(2.0, 3.0);
        assert!(est.step(v, far).diagnostics.input_fault, "{}", est.name());
        assert!(!est.step(v, far).diagnostics.input_fault, "{}", est.name());
    }

    #[test]
    fn every_baseline_rejects_non_finite_overflowing_and_implausible_samples() {
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
                common: CommonTuning {
                    initial_angle: 0.3,
                    ..Default::default()
                },
                ..LpfIntegratorConfig::for_machine(&MachineModel::paper())
            })
            .unwrap(),
            0.3,
        );
        check(
            OrtegaEstimator::new(OrtegaConfig {
                common: CommonTuning {
                    initial_angle: 0.3,
                    ..Default::default()
                },
                ..OrtegaConfig::for_machine(&MachineModel::paper())
            })
            .unwrap(),
            0.3,
        );
        check(
            EmfObserverEstimator::new(EmfObserverConfig {
                common: CommonTuning {
                    initial_angle: 0.3,
                    ..Default::default()
                },
                ..EmfObserverConfig::for_machine(&MachineModel::paper())
            })
            .unwrap(),
            0.3,
        );
    }
}
