//! [`SensorlessEstimator`], the owner of the parameters and the state, and the
//! [`RotorAngleEstimator`] interface a drive steps any estimator through.

use super::{Estimate, EstimatorConfig, EstimatorParams, EstimatorState, LeanEstimate};
use crate::error::ConfigError;
use crate::{Ab, Real};

/// The sensorless estimator of Fig. 5, generic over `f32` and `f64`, allocation-free: the
/// owner of its [`EstimatorParams`] and its [`EstimatorState`] (firmware may keep the two
/// apart, the parameters in a `static`; both step identically).
///
/// ```
/// use fado_core::{Ab, EstimatorConfig, MachineModel, SensorlessEstimator};
/// let config = EstimatorConfig::for_machine(&MachineModel::paper());
/// let mut est = SensorlessEstimator::<f32>::new(config).unwrap();
/// // In the 10 kHz ISR: the voltage applied over the last interval and the sampled currents.
/// let out = est.step(Ab::new(1.2, -0.3), Ab::new(4.0, 0.1));
/// assert!(!out.diagnostics.input_fault);
/// let _angle = out.theta;
/// ```
///
/// The same with the parameters apart from the state (the firmware pattern):
///
/// ```
/// use fado_core::{Ab, EstimatorConfig, EstimatorParams, EstimatorState, MachineModel};
/// let config = EstimatorConfig::for_machine(&MachineModel::paper());
/// let params = EstimatorParams::<f32>::new(config).unwrap(); // once, e.g. into a `static`
/// let mut state = EstimatorState::new(&params);
/// let out = state.step_lean(&params, Ab::new(1.2, -0.3), Ab::new(4.0, 0.1));
/// assert!(!out.input_fault);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorlessEstimator<T: Real> {
    pub(super) params: EstimatorParams<T>,
    pub(super) state: EstimatorState<T>,
}

impl<T: Real> SensorlessEstimator<T> {
    /// Builds the estimator; every field of `config` is checked and a bad one is named.
    pub fn new(config: EstimatorConfig<T>) -> Result<Self, ConfigError> {
        // Built into the result in place (a freestanding image has no `memcpy` for a copy of
        // the parameters).
        EstimatorParams::new(config).map(|params| Self {
            state: params.initial_state(),
            params,
        })
    }

    /// The estimator's parameters (immutable after `new`).
    pub fn params(&self) -> &EstimatorParams<T> {
        &self.params
    }

    /// The estimator's state.
    pub fn state(&self) -> &EstimatorState<T> {
        &self.state
    }

    /// Back to the start-up state at `config.initial_angle` with zero current; an adapted R̂s
    /// goes back to the value the adaptation started from (the configured one, or the last
    /// [`Self::set_rs_hat`]).
    pub fn reset(&mut self) {
        self.state.reset(&self.params);
    }

    /// Start-up at a known rotor angle θ0 with the present current (docs/method/estimator.md, "Start-up"):
    /// λ1 = λ̂a·e^{jθ0} + L̂q·i with the active flux λ̂a = λ̂f + (L̂d − L̂q)·i_d, D̂ = 0, θ̂ = θ0, ω̂ = 0, limiter mode. An adapted R̂s is kept
    /// (the winding is as warm as it was).
    pub fn align(&mut self, theta0: T, i_ab: Ab<T>) {
        self.state.align(&self.params, theta0, i_ab);
    }

    /// One 10 kHz sample (Fig. 5).
    ///
    /// `v_ab` is the voltage reference that was applied over the last sampling interval (with
    /// a one-sample computational delay, the one computed two samples ago, before dead-time
    /// compensation); `i_ab` the currents sampled now. A non-finite or implausible input (see
    /// [`crate::plausibility`]) is rejected: the state is untouched and [`Self::last`] is
    /// returned with `input_fault` set.
    #[inline]
    pub fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T> {
        self.state.advance(&self.params, v_ab, i_ab)
    }

    /// [`Self::step`] for firmware: the same sample, the same new state, but only the
    /// outputs a control loop uses ([`LeanEstimate`]: θ̂, ω̂, ω̂ for control, the mode, the
    /// lock status and the input-fault flag). The diagnostics of [`Estimate`] (λ1, D̂, λ2,
    /// λ̂r, θm, R̂s, λ̂f, flags) are not formed: on a Cortex-M4F that saves about 65 of the
    /// step's cycles (docs/results/firmware-cost.md). [`Self::last`] still gives them for the last sample
    /// (recomputed from the state).
    #[inline]
    pub fn step_lean(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> LeanEstimate<T> {
        self.state.advance(&self.params, v_ab, i_ab)
    }

    /// The estimate of the last good sample (or of the last `align`/`reset`), recomputed from
    /// the state: the estimator keeps no copy of its output (64 bytes written every sample in
    /// `f32`; a caller that needs the output keeps what `step` returned).
    ///
    /// θ̂, ω̂, ω̂ for control, the mode and FLAG_limit are those of that sample exactly. The
    /// diagnostics are recomputed: λ1 and D̂ as stored (after the limiter re-centring, see
    /// [`LimiterTuning::recentring`](crate::estimator::tuning::LimiterTuning::recentring)), λ2 = λ1 − D̂, λ̂r = λ2 − L̂q·i with that
    /// sample's current, θm = ∠λ̂r, the limiter and hold flags from this λ̂r, R̂s and λ̂f as
    /// they will be used next.
    pub fn last(&self) -> Estimate<T> {
        self.state.last(&self.params)
    }

    /// Number of samples rejected since the last reset.
    pub fn rejected_samples(&self) -> u32 {
        self.state.rejected_samples()
    }

    /// Enables or disables the k_df feedback at run time regardless of speed (the experiment
    /// of Fig. 9 switches it off on purpose). Enabled after `new`.
    pub fn set_disturbance_feedback_enabled(&mut self, enabled: bool) {
        self.state.set_disturbance_feedback_enabled(enabled);
    }

    /// Replaces R̂s at run time, as if it had been configured (an external estimate, or a
    /// value saved from the last run): the integrator uses it from the next sample, and with
    /// [`EstimatorTuning::rs_adaptation`](crate::EstimatorTuning::rs_adaptation) the adaptation restarts from it, scaled and bounded
    /// around it (a learned λ̂f goes back to the configured one too). Refuses bad values and
    /// then changes nothing.
    pub fn set_rs_hat(&mut self, rs_hat: T) -> Result<(), ConfigError> {
        self.state.set_rs_hat(&self.params, rs_hat)
    }

    /// Switches the R̂s adaptation ([`EstimatorTuning::rs_adaptation`](crate::EstimatorTuning::rs_adaptation), with its integrand-
    /// offset law) on at run time, starting from the R̂s in use now; nothing changes if it is
    /// on already. The drive's `recover` reaction does this after the paper's fixed R̂s lost
    /// the rotor (see [`crate::control::lock_reaction`]). It stays on through
    /// [`Self::reset`] and [`Self::align`]; a rebuilt estimator starts as configured.
    pub fn enable_rs_adaptation(&mut self) {
        self.state.enable_rs_adaptation(&self.params);
    }

    /// Turns θ̂ by `angle` (rad, positive: θ̂ increases) in limiter mode: an external angle
    /// correction such as the drive's loaded-standstill probe
    /// ([`crate::control::standstill_probe`]), called once per sample with rate·Ts. λ1 moves by
    /// j·λ̂r·angle, tangentially to the last λ̂r = λ1 − D̂ − L̂q·i, as the tangential integrand
    /// feedback of the R̂s adaptation's no-load standstill angle law (`rs_adaptation`) moves
    /// it; θ̂ follows through the trackers. Off the step's path (no cost in the step); does
    /// nothing outside limiter mode or for a non-finite angle or result.
    pub fn turn_angle(&mut self, angle: T) {
        self.state.turn_angle(&self.params, angle);
    }

    /// Pulls the rotor-flux magnitude |λ̂r| towards `magnitude` (Wb, the model's active flux
    /// at the present current) in limiter mode, radially at the limiter's rate k_af: at a
    /// loaded standstill the drive holds the estimate on the model's flux circle, so that the
    /// radial part of the integrand error does not sit in λ1 as an offset the departure turns
    /// into an angle error ([`crate::control::standstill_probe`]). Off the step's path; does
    /// nothing outside limiter mode or for a non-finite or non-positive magnitude.
    pub fn hold_flux_magnitude(&mut self, magnitude: T) {
        self.state.hold_flux_magnitude(&self.params, magnitude);
    }

    /// While `on`, T2S-1 runs at its running bandwidth (`tracker.t2s1_running_bandwidth_hz`)
    /// in limiter mode too: the drive sets it from a brake's opening until its release hold
    /// hands over, since the rotor's fall under the load the brake held is the unannounced
    /// step of the rated torque that bandwidth is designed for
    /// ([`crate::control::tracker_feedforward`], "T2S-1 at a brake's release"). Without a
    /// running bandwidth nothing changes. Call before [`step`](Self::step).
    pub fn set_release_tracking(&mut self, on: bool) {
        self.state.set_release_tracking(on);
    }

    /// The voltage `v_ab` realised over this sample's interval by min-max SVPWM on the dc link
    /// `vdc` (V) through an inverter with the dead time `dead_time` (s): on the algebraic
    /// saturating model, the PWM ripple's terms over the interval, from which the estimator
    /// adds the interval's mean current minus the sampled one to its resistive drop
    /// ([`crate::ripple`]; refreshed every [`RIPPLE_EVERY`](crate::ripple::RIPPLE_EVERY)
    /// samples). Nothing for another model. Call before [`step`](Self::step).
    pub fn set_pwm_ripple(&mut self, v_ab: Ab<T>, vdc: T, dead_time: T) {
        self.state
            .set_pwm_ripple(&self.params, v_ab, vdc, dead_time);
    }

    /// The voltage of this sample's interval was limited by the modulator (the drive's
    /// hexagon): R̂s's turning law (and its λ̂f law) does not adapt over the period that
    /// contains it. On a limited sample the realised voltage the drive
    /// reports carries the inverter's least-modelled errors (legs held at a rail without
    /// dead time, pulses near the rails), which the turning law would read as resistance
    /// ([`crate::rs_adaptation`]). Call before [`step`](Self::step).
    pub fn voltage_limited(&mut self) {
        self.state.slow_broken |= super::BROKEN_LIMITED;
    }

    /// ê, the learned integrand offset (V, α-β; zero without `rs_adaptation`).
    pub fn integrand_offset(&self) -> Ab<T> {
        self.state.integrand_offset()
    }

    /// R̂s in use now (Ω).
    pub fn rs_hat(&self) -> T {
        self.state.rs_hat()
    }

    /// The sampling period Ts in use, s. (The estimator keeps what its step needs of its
    /// [`EstimatorConfig`], not the record: the caller keeps that.)
    pub fn ts(&self) -> T {
        self.params.ts
    }

    /// Whether the R̂s adaptation runs ([`EstimatorTuning::rs_adaptation`](crate::EstimatorTuning::rs_adaptation), or switched on
    /// by [`Self::enable_rs_adaptation`]).
    pub fn rs_adaptation_enabled(&self) -> bool {
        self.state.rs_adaptation_enabled()
    }

    /// The Fig. 3 mode threshold in use and its hysteresis half-band, Hz electrical
    /// ([`EstimatorConfig::mode_threshold_hz`], [`EstimatorConfig::mode_hysteresis_hz`]).
    pub fn mode_threshold_hz(&self) -> (T, T) {
        self.params.mode_threshold_hz()
    }
}

/// What a drive needs from a rotor-angle estimator. Implemented by [`SensorlessEstimator`]
/// and by the reference observers fado is compared against, so that one drive and one set of
/// scenarios can run any of them.
pub trait RotorAngleEstimator<T: Real> {
    /// One sample: `v_ab` applied over the last interval, `i_ab` sampled now. Fields of
    /// [`Diagnostics`](crate::Diagnostics) an estimator does not have are left at their defaults.
    fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T>;
    /// Start-up at a known rotor angle with the present current.
    fn align(&mut self, theta0: T, i_ab: Ab<T>);
    /// Back to the configured start-up state.
    fn reset(&mut self);
    /// A short name for tables and plots.
    fn name(&self) -> &'static str;
    /// Clears a loss-of-lock verdict ([`Diagnostics::lock`](crate::Diagnostics::lock)) without touching the
    /// estimate, so that the detector judges afresh (the drive's recovery, see
    /// [`crate::control::lock_reaction`]). Default: nothing to clear.
    fn rearm_lock_detector(&mut self) {}
    /// Switches an online R̂s adaptation on, if the estimator has one (the drive's recovery
    /// after a loss with a fixed R̂s, see [`crate::control::lock_reaction`]). Default:
    /// nothing to switch.
    fn enable_rs_adaptation(&mut self) {}
    /// The stator resistance measured at start-up (Ω; the drive's two-point DC test, see
    /// [`crate::control::gain_calibration`]): an estimator that adapts R̂s online starts its
    /// adaptation from it. Default: nothing (a fixed R̂s stays as configured, so the paper's
    /// path is unchanged).
    fn start_from_measured_rs(&mut self, _rs: T) {}
    /// Turns θ̂ by `angle` (rad) now, if the estimator can (the drive's loaded-standstill
    /// probe, see [`crate::control::standstill_probe`]). Default: nothing.
    fn turn_angle(&mut self, _angle: T) {}
    /// Pulls |λ̂r| towards `magnitude` (Wb) now, if the estimator can (the drive's loaded
    /// standstill, see [`crate::control::standstill_probe`]). Default: nothing.
    fn hold_flux_magnitude(&mut self, _magnitude: T) {}
    /// The acceleration the drive commands, rad/s² (electrical), for the estimator's speed
    /// trackers to feed forward (see [`crate::tracker`]). Default: not used.
    fn set_acceleration(&mut self, _acceleration: T) {}
    /// Switches a disturbance feedback (fado's k_df, Fig. 9) on or off, if the estimator has
    /// one. Default: nothing to switch.
    fn set_disturbance_feedback(&mut self, _enabled: bool) {}
    /// The voltage the next [`step`](Self::step) integrates was limited by the modulator
    /// (see [`SensorlessEstimator::voltage_limited`]). Default: nothing.
    fn voltage_limited(&mut self) {}
    /// A brake has opened and the rotor may fall: track it with the bandwidth its fall needs
    /// (see [`SensorlessEstimator::set_release_tracking`]). Default: nothing.
    fn set_release_tracking(&mut self, _on: bool) {}
    /// The interval's voltage, dc link and the inverter's dead time for the PWM ripple's
    /// current bias (see [`SensorlessEstimator::set_pwm_ripple`]). Default: nothing.
    fn set_pwm_ripple(&mut self, _v_ab: Ab<T>, _vdc: T, _dead_time: T) {}
}

impl<T: Real> RotorAngleEstimator<T> for SensorlessEstimator<T> {
    #[inline]
    fn step(&mut self, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T> {
        SensorlessEstimator::step(self, v_ab, i_ab)
    }
    fn align(&mut self, theta0: T, i_ab: Ab<T>) {
        SensorlessEstimator::align(self, theta0, i_ab)
    }
    fn reset(&mut self) {
        SensorlessEstimator::reset(self)
    }
    fn name(&self) -> &'static str {
        "fado"
    }
    fn set_acceleration(&mut self, acceleration: T) {
        self.state.t2s1.set_acceleration(acceleration);
        self.state.t2s2.set_acceleration(acceleration);
    }
    fn rearm_lock_detector(&mut self) {
        self.state.rearm_lock_detector();
    }
    fn enable_rs_adaptation(&mut self) {
        SensorlessEstimator::enable_rs_adaptation(self)
    }
    fn turn_angle(&mut self, angle: T) {
        SensorlessEstimator::turn_angle(self, angle);
    }
    fn hold_flux_magnitude(&mut self, magnitude: T) {
        SensorlessEstimator::hold_flux_magnitude(self, magnitude);
    }
    fn set_disturbance_feedback(&mut self, enabled: bool) {
        self.set_disturbance_feedback_enabled(enabled);
    }
    fn voltage_limited(&mut self) {
        SensorlessEstimator::voltage_limited(self);
    }
    fn set_release_tracking(&mut self, on: bool) {
        SensorlessEstimator::set_release_tracking(self, on);
    }
    fn set_pwm_ripple(&mut self, v_ab: Ab<T>, vdc: T, dead_time: T) {
        SensorlessEstimator::set_pwm_ripple(self, v_ab, vdc, dead_time);
    }
    /// With [`EstimatorTuning::rs_adaptation`](crate::EstimatorTuning::rs_adaptation): [`SensorlessEstimator::set_rs_hat`] (a bad
    /// value changes nothing); with the paper's fixed R̂s: nothing.
    fn start_from_measured_rs(&mut self, rs: T) {
        if self.state.rs_adaptation_on {
            let _ = self.set_rs_hat(rs);
        }
    }
}
