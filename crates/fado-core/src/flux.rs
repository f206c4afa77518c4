//! Stator-flux integration with its two feedbacks: the disturbance feedback k_df (Fig. 3,
//! eq. (21)-(22)) above the speed threshold and the flux limiter k_af (Fig. 6, eq. (24)-(25))
//! below it.
//!
//! Both feedbacks act on the *same* integrator state λ1 (docs/method/estimator.md §5): a hand-over only
//! changes the integrand, so λ̂r changes slope but never jumps, and neither does the angle.

use crate::error::{ConfigError, NonFiniteInput, check};
use crate::{Ab, MachineModel, Real};

/// Default of [`FluxIntegratorConfig::average_current`]: the resistive drop of the mean
/// current over the interval (docs/method/estimator.md §1 \[A\]).
pub const DEFAULT_AVERAGE_CURRENT: bool = true;

/// Default disturbance feedback gain k_df in s⁻¹ (paper, V).
pub const DEFAULT_K_DF: f64 = 0.5;

/// Default limiter gain k_af in s⁻¹: 2π·100 (paper, V).
pub const DEFAULT_K_AF: f64 = 2.0 * core::f64::consts::PI * 100.0;

/// Default limiter radius as a multiple of λ̂f (paper, V).
pub const DEFAULT_LIMITER_RADIUS_RATIO: f64 = 1.15;

/// Configuration of a [`FluxIntegrator`].
///
/// No `Default`: R̂s is the motor's and Ts the set-up's. Build it with
/// [`for_machine`](Self::for_machine); each field's "Default" is what it gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluxIntegratorConfig<T> {
    /// Sampling period Ts in s (paper, V: 100 µs). No default: the caller's.
    pub ts: T,
    /// Stator resistance estimate R̂s in Ω: the machine model's (the paper's motor: 0.327 Ω,
    /// paper V).
    pub rs_hat: T,
    /// Use (i\[n\] + i[n−1])/2 for the resistive drop, which matches the interval the applied
    /// voltage acted over (docs/method/estimator.md §1, \[A\]). Default
    /// [`DEFAULT_AVERAGE_CURRENT`] (true).
    pub average_current: bool,
}

impl<T: Real> FluxIntegratorConfig<T> {
    /// The integrator around `machine` (R̂s = [`MachineModel::rs`]) sampled every `ts`, with
    /// the averaged current ([`DEFAULT_AVERAGE_CURRENT`]).
    pub fn for_machine(machine: &MachineModel<T>, ts: T) -> Self {
        Self {
            ts,
            rs_hat: machine.rs,
            average_current: DEFAULT_AVERAGE_CURRENT,
        }
    }
}

/// The integrator's constants (the immutable half of [`FluxIntegrator`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FluxIntegratorParams<T> {
    ts: T,
    average_current: bool,
}

/// The integrator's state: λ1, the last current and R̂s (which the resistance adaptation and
/// [`FluxIntegrator::set_rs_hat`] change at run time, so it is state, not a constant).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FluxIntegratorState<T> {
    rs_hat: T,
    lambda1: Ab<T>,
    i_prev: Ab<T>,
    has_prev: bool,
}

impl<T: Real> FluxIntegratorParams<T> {
    /// The constants of `config` and the state at λ1 = 0 with its R̂s.
    pub(crate) fn new(
        config: FluxIntegratorConfig<T>,
    ) -> Result<(Self, FluxIntegratorState<T>), ConfigError> {
        check::positive("ts", config.ts)?;
        check::non_negative("rs_hat", config.rs_hat)?;
        Ok((
            Self {
                ts: config.ts,
                average_current: config.average_current,
            },
            FluxIntegratorState::new(config.rs_hat),
        ))
    }

    /// λ1 after one more sample, computed without changing the state, and the current it
    /// multiplied by R̂s (see [`Self::drop_current`]).
    #[inline(always)]
    pub(crate) fn next_flux(
        &self,
        s: &FluxIntegratorState<T>,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
        feedback: Ab<T>,
    ) -> (Ab<T>, Ab<T>) {
        let i_drop = self.drop_current(s, i_ab);
        let lambda1 = s.lambda1 + (v_ab - i_drop * s.rs_hat - feedback) * self.ts;
        (lambda1, i_drop)
    }

    /// The current multiplied by R̂s in the sample ending with `i_ab`: the interval's average
    /// (with `integrator.average_current`) or `i_ab`.
    #[inline(always)]
    pub(crate) fn drop_current(&self, s: &FluxIntegratorState<T>, i_ab: Ab<T>) -> Ab<T> {
        if self.average_current && s.has_prev {
            (i_ab + s.i_prev) * T::lit(0.5)
        } else {
            i_ab
        }
    }
}

impl<T: Real> FluxIntegratorState<T> {
    /// λ1 = 0, no remembered current, R̂s = `rs_hat` (checked by the caller).
    pub(crate) fn new(rs_hat: T) -> Self {
        Self {
            rs_hat,
            lambda1: Ab::zero(),
            i_prev: Ab::zero(),
            has_prev: false,
        }
    }

    /// Starts from a known flux λ1 (docs/method/estimator.md, "Start-up": λf·e^{jθ0} + L̂q·i), R̂s kept.
    pub(crate) fn reset_to(&mut self, lambda1: Ab<T>) {
        self.lambda1 = lambda1;
        self.i_prev = Ab::zero();
        self.has_prev = false;
    }

    /// Sets R̂s from a value already checked (by the resistance adaptation's bounds).
    #[inline(always)]
    pub(crate) fn set_rs_hat_unchecked(&mut self, rs_hat: T) {
        self.rs_hat = rs_hat;
    }

    /// Replaces R̂s. Refuses non-finite or negative values.
    pub(crate) fn set_rs_hat(&mut self, rs_hat: T) -> Result<(), ConfigError> {
        self.rs_hat = check::non_negative("rs_hat", rs_hat)?;
        Ok(())
    }

    /// R̂s in use (Ω).
    #[inline(always)]
    pub(crate) fn rs_hat(&self) -> T {
        self.rs_hat
    }

    /// Takes λ1 computed by [`FluxIntegratorParams::next_flux`] for the sample with current
    /// `i_ab`.
    #[inline(always)]
    pub(crate) fn commit(&mut self, lambda1: Ab<T>, i_ab: Ab<T>) {
        self.lambda1 = lambda1;
        self.i_prev = i_ab;
        self.has_prev = true;
    }

    /// λ1, the integrated stator flux.
    #[inline(always)]
    pub(crate) fn flux(&self) -> Ab<T> {
        self.lambda1
    }

    /// The current of the last sample (zero after a reset, or what [`Self::set_last_current`]
    /// set).
    #[inline(always)]
    pub(crate) fn last_current(&self) -> Ab<T> {
        self.i_prev
    }

    /// Records the current present at a reset, not for the resistive drop (the first sample
    /// after a reset still uses its own current alone): the estimator reports it and checks
    /// the first sample's current step against it.
    #[inline(always)]
    pub(crate) fn set_last_current(&mut self, i_ab: Ab<T>) {
        self.i_prev = i_ab;
    }
}

/// The voltage-model integrator λ1 ← λ1 + Ts·(v* − R̂s·i − fb) (eq. (3), (21), (24)),
/// forward rectangle: v* is the voltage that acted over the *last* interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluxIntegrator<T> {
    params: FluxIntegratorParams<T>,
    state: FluxIntegratorState<T>,
}

impl<T: Real> FluxIntegrator<T> {
    /// A new integrator at λ1 = 0.
    pub fn new(config: FluxIntegratorConfig<T>) -> Result<Self, ConfigError> {
        let (params, state) = FluxIntegratorParams::new(config)?;
        Ok(Self { params, state })
    }

    /// λ1 = 0, no remembered current.
    pub fn reset(&mut self) {
        self.reset_to(Ab::zero());
    }

    /// Starts from a known flux λ1 (docs/method/estimator.md, "Start-up": λf·e^{jθ0} + L̂q·i).
    pub fn reset_to(&mut self, lambda1: Ab<T>) {
        self.state.reset_to(lambda1);
    }

    /// One sample: `v_ab` applied over the last interval, `i_ab` sampled now, `feedback` the
    /// k_df·D̂ or k_af·(λ̂r − λ̂r_lim) term (V). Returns λ1\[n\].
    #[inline]
    pub fn step(
        &mut self,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
        feedback: Ab<T>,
    ) -> Result<Ab<T>, NonFiniteInput> {
        if !(v_ab.is_finite() && i_ab.is_finite() && feedback.is_finite()) {
            return Err(NonFiniteInput);
        }
        let (lambda1, _) = self.params.next_flux(&self.state, v_ab, i_ab, feedback);
        self.state.commit(lambda1, i_ab);
        Ok(lambda1)
    }

    /// λ1, the integrated stator flux.
    #[inline]
    pub fn flux(&self) -> Ab<T> {
        self.state.flux()
    }

    /// The configuration in use (with the R̂s in use now).
    pub fn config(&self) -> FluxIntegratorConfig<T> {
        FluxIntegratorConfig {
            ts: self.params.ts,
            rs_hat: self.state.rs_hat,
            average_current: self.params.average_current,
        }
    }

    /// Replaces R̂s (for online resistance adaptation). Refuses non-finite or negative values.
    pub fn set_rs_hat(&mut self, rs_hat: T) -> Result<(), ConfigError> {
        self.state.set_rs_hat(rs_hat)
    }
}

/// Configuration of a [`DisturbanceFeedback`].
///
/// No `Default`: Ts is the set-up's. Build it with [`with_ts`](Self::with_ts); each field's
/// "Default" is what it gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisturbanceFeedbackConfig<T> {
    /// Sampling period Ts in s (paper, V: 100 µs). No default: the caller's.
    pub ts: T,
    /// Disturbance feedback gain k_df in s⁻¹ (Fig. 3, eq. (21)). Default [`DEFAULT_K_DF`]
    /// (0.5, paper V).
    pub k_df: T,
    /// Time to ramp k_df from 0 to its value on activation, s; 0 switches it abruptly as the
    /// paper does. A ramp softens the re-activation distortion of Fig. 9 (docs/method/estimator.md §1 \[A\]).
    /// Default 0.
    pub ramp_time: T,
}

impl<T: Real> DisturbanceFeedbackConfig<T> {
    /// The feedback sampled every `ts` with the default k_df ([`DEFAULT_K_DF`], 0.5 s⁻¹,
    /// paper V) and no ramp, as the paper.
    pub fn with_ts(ts: T) -> Self {
        Self {
            ts,
            k_df: T::lit(DEFAULT_K_DF),
            ramp_time: T::zero(),
        }
    }
}

/// The k_df feedback's constants (the immutable half of [`DisturbanceFeedback`]; its state
/// is the gain in effect alone).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DisturbanceFeedbackParams<T> {
    k_df: T,
    ramp_increment: T,
    /// A ramp is configured (`ramp_time` > 0). Without one the gain is k_df at once:
    /// min(g + k_df, k_df) = k_df exactly for every g ≥ 0, so the step skips the add and the
    /// compare.
    ramped: bool,
}

impl<T: Real> DisturbanceFeedbackParams<T> {
    /// The constants of `config`, checked.
    pub(crate) fn new(config: DisturbanceFeedbackConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        let k_df = check::non_negative("k_df", config.k_df)?;
        let ramp = check::non_negative("ramp_time", config.ramp_time)?;
        // k_df·D̂ is integrated with Ts: one step must not remove more than the disturbance.
        check::below("k_df", k_df * ts, T::lit(1.0 + 1e-6), "k_df·ts at most 1")?;
        let ramp_increment = if ramp > T::zero() {
            k_df * ts / ramp
        } else {
            k_df
        };
        Ok(Self {
            k_df,
            ramp_increment,
            ramped: ramp > T::zero(),
        })
    }

    /// The gain the next sample uses after `gain`.
    #[inline(always)]
    pub(crate) fn next_gain(&self, gain: T, active: bool) -> T {
        if !active {
            T::zero()
        } else if self.ramped {
            crate::real::min(gain + self.ramp_increment, self.k_df)
        } else {
            // The gain is never negative: min(g + k_df, k_df) is k_df.
            self.k_df
        }
    }
}

/// The k_df·D̂ feedback of Fig. 3 with an optional activation ramp.
///
/// With it the flux loop is λ1 = u / (s + k_df·G(s)), G = D̂/λ1 (eq. (22)): stable for all
/// ±ω, a DC gain 1/k_df instead of an integrator's infinite one (bounded drift), and an
/// exact integrator at ω (docs/method/estimator.md §2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisturbanceFeedback<T> {
    params: DisturbanceFeedbackParams<T>,
    gain: T,
}

impl<T: Real> DisturbanceFeedback<T> {
    /// A new feedback, inactive.
    pub fn new(config: DisturbanceFeedbackConfig<T>) -> Result<Self, ConfigError> {
        Ok(Self {
            params: DisturbanceFeedbackParams::new(config)?,
            gain: T::zero(),
        })
    }

    /// Back to inactive (gain 0).
    pub fn reset(&mut self) {
        self.gain = T::zero();
    }

    /// One sample: returns k_df·D̂ when `active`, 0 otherwise (the gain ramps on activation).
    #[inline]
    pub fn step(&mut self, active: bool, disturbance: Ab<T>) -> Ab<T> {
        self.gain = self.params.next_gain(self.gain, active);
        disturbance * self.gain
    }

    /// The gain in effect after the last step.
    pub fn gain(&self) -> T {
        self.gain
    }
}

/// Configuration of a [`FluxLimiter`].
///
/// No `Default`: the radius is the motor's. Build it with [`for_machine`](Self::for_machine);
/// each field's "Default" is what it gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluxLimiterConfig<T> {
    /// Convergence gain k_af in s⁻¹ (Fig. 6, eq. (24)-(25)). Default [`DEFAULT_K_AF`] (2π·100,
    /// paper V).
    pub k_af: T,
    /// Radius ρ of the limiting circle in Wb. Default 1.15·λ̂f (paper, V: 1.15 times the flux
    /// linkage; [`DEFAULT_LIMITER_RADIUS_RATIO`]), 0.1012 Wb on the paper's motor.
    pub radius: T,
}

impl<T: Real> FluxLimiterConfig<T> {
    /// The limiter around `machine` with the paper's gain and radius: k_af = 2π·100 s⁻¹ and
    /// ρ = 1.15·λ̂f (paper, V; [`DEFAULT_K_AF`], [`DEFAULT_LIMITER_RADIUS_RATIO`]).
    pub fn for_machine(machine: &MachineModel<T>) -> Self {
        Self::new(
            machine,
            T::lit(DEFAULT_K_AF),
            T::lit(DEFAULT_LIMITER_RADIUS_RATIO),
        )
    }

    /// The limiter around `machine` with gain `k_af` (s⁻¹) and radius `radius_ratio` × λ̂f
    /// ([`MachineModel::flux_linkage`]).
    pub fn new(machine: &MachineModel<T>, k_af: T, radius_ratio: T) -> Self {
        Self {
            k_af,
            radius: radius_ratio * machine.flux_linkage,
        }
    }
}

/// Output of the flux limiter for one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimiterOutput<T> {
    /// The feedback k_af·(λ̂r − Π(λ̂r)) to subtract from the integrand (V).
    pub feedback: Ab<T>,
    /// True when |λ̂r| exceeded the radius, i.e. the limiter pulled the flux back.
    pub clamping: bool,
}

/// The flux limiter of Fig. 6 (eq. (24)-(25)).
///
/// Π(x) = x·min(1, ρ/|x|) is the radial projection onto the disc of radius ρ (docs/method/estimator.md §1 \[A\]):
/// inside the circle the integrator is pure, outside the excess is pulled back radially with
/// time constant 1/k_af (1.6 ms by default), and the angle is never constrained.
/// Stateless apart from its configuration; `step` and `reset` exist for uniformity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluxLimiter<T> {
    config: FluxLimiterConfig<T>,
}

impl<T: Real> FluxLimiter<T> {
    /// A new limiter.
    pub fn new(config: FluxLimiterConfig<T>) -> Result<Self, ConfigError> {
        check::non_negative("k_af", config.k_af)?;
        check::positive("radius", config.radius)?;
        Ok(Self { config })
    }

    /// No state to clear.
    pub fn reset(&mut self) {}

    /// Π(λ̂r), the limited rotor flux λ̂r_lim of Fig. 6.
    #[inline]
    pub fn project(&self, lambda_r: Ab<T>) -> Ab<T> {
        let n2 = lambda_r.norm_squared();
        let rho = self.config.radius;
        if n2 > rho * rho {
            lambda_r * (rho / n2.step_sqrt())
        } else {
            lambda_r
        }
    }

    /// The feedback for the next integration step.
    #[inline]
    pub fn step(&self, lambda_r: Ab<T>) -> LimiterOutput<T> {
        self.step_scaled(lambda_r, T::one())
    }

    /// [`Self::step`] with the radius scaled by `scale`: on a salient rotor the circle follows
    /// the active flux λ̂a = λ̂f + (L̂d − L̂q)·i_d that |λ̂r| equals (the paper sets the radius
    /// "under the consideration of λ_em in (5)"), `scale` = λ̂a/λ̂f.
    #[inline]
    pub fn step_scaled(&self, lambda_r: Ab<T>, scale: T) -> LimiterOutput<T> {
        let n2 = lambda_r.norm_squared();
        let rho = self.config.radius * scale;
        if n2 > rho * rho {
            let n = n2.step_sqrt();
            LimiterOutput {
                feedback: lambda_r * (self.config.k_af * (n - rho) / n),
                clamping: true,
            }
        } else {
            LimiterOutput {
                feedback: Ab::zero(),
                clamping: false,
            }
        }
    }

    /// The configuration in use.
    pub fn config(&self) -> &FluxLimiterConfig<T> {
        &self.config
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrator_integrates_and_averages_current() {
        let mut int = FluxIntegrator::new(FluxIntegratorConfig {
            ts: 1e-4_f64,
            rs_hat: 1.0,
            average_current: true,
        })
        .unwrap();
        int.step(Ab::new(1.0, 0.0), Ab::new(0.0, 0.0), Ab::zero())
            .unwrap();
        let l = int
            .step(Ab::new(1.0, 0.0), Ab::new(0.5, 0.0), Ab::zero())
            .unwrap();
        // 1e-4·1 + 1e-4·(1 − 0.25)
        assert!((l.alpha - 1.75e-4).abs() < 1e-15);
    }

    #[test]
    fn feedback_ramps_and_switches_off() {
        let mut fb = DisturbanceFeedback::new(DisturbanceFeedbackConfig {
            ts: 1e-4_f64,
            k_df: 0.5,
            ramp_time: 0.1,
        })
        .unwrap();
        for _ in 0..500 {
            fb.step(true, Ab::new(1.0, 0.0));
        }
        assert!((fb.gain() - 0.25).abs() < 1e-9);
        for _ in 0..1000 {
            fb.step(true, Ab::new(1.0, 0.0));
        }
        assert_eq!(fb.gain(), 0.5);
        assert_eq!(fb.step(false, Ab::new(1.0, 0.0)), Ab::zero());
    }

    #[test]
    fn limiter_projects_radially() {
        let lim = FluxLimiter::new(FluxLimiterConfig {
            k_af: 100.0_f64,
            radius: 0.1,
        })
        .unwrap();
        let x = Ab::new(0.3, 0.4);
        let p = lim.project(x);
        assert!((p.norm() - 0.1).abs() < 1e-15);
        assert!((p.angle() - x.angle()).abs() < 1e-15);
        let out = lim.step(x);
        assert!(out.clamping);
        assert!((out.feedback.norm() - 100.0 * 0.4).abs() < 1e-12);
        assert_eq!(lim.project(Ab::new(0.05, 0.0)), Ab::new(0.05, 0.0));
        assert!(!lim.step(Ab::new(0.05, 0.0)).clamping);
    }

    #[test]
    fn bad_config_names_field() {
        let e = FluxLimiter::new(FluxLimiterConfig {
            k_af: 1.0,
            radius: 0.0,
        })
        .unwrap_err();
        assert_eq!(e.field(), "radius");
        let e = FluxIntegrator::new(FluxIntegratorConfig {
            ts: 1e-4_f64,
            rs_hat: f64::NAN,
            average_current: true,
        })
        .unwrap_err();
        assert_eq!(e.field(), "rs_hat");
    }
}
