//! What one sample returns: [`Estimate`] with its [`Diagnostics`], and the firmware's
//! [`LeanEstimate`].

use crate::lock::LockStatus;
use crate::mode::Mode;
use crate::{Ab, Real};

/// Internal signals of one sample, named as in the paper's figures.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Diagnostics<T> {
    /// λ1: the integrated stator flux (eq. (7), (21)).
    pub lambda1: Ab<T>,
    /// D̂: the estimated disturbance (eq. (10)).
    pub disturbance: Ab<T>,
    /// λ2 = λ1 − D̂ (eq. (20)).
    pub lambda2: Ab<T>,
    /// λ̂r = λ2 − L̂q·i (eq. (5)).
    pub lambda_r: Ab<T>,
    /// θm = ∠λ̂r, the directly calculated angle of eq. (6) (before the T2S).
    pub theta_direct: T,
    /// Which flux feedback is active.
    pub mode: Mode,
    /// FLAG_limit of Fig. 10: the limiter mode is active.
    pub flag_limit: bool,
    /// The limiter is pulling λ̂r back to its circle this sample.
    pub limiter_clamping: bool,
    /// The trackers coasted because |λ̂r| was too small.
    pub tracker_hold: bool,
    /// R̂s used by the integrator this sample (Ω): the configured value, or the adapted one
    /// with [`EstimatorTuning::rs_adaptation`](crate::EstimatorTuning::rs_adaptation).
    pub rs_hat: T,
    /// The flux-magnitude reference λ̂f (Wb): the configured value, or the adapted one with
    /// [`EstimatorTuning::rs_adaptation`](crate::EstimatorTuning::rs_adaptation).
    pub flux_linkage_hat: T,
    /// This sample's inputs were non-finite or implausible (see [`crate::plausibility`]) and
    /// were rejected; the state is unchanged and the other fields repeat the last good sample.
    pub input_fault: bool,
    /// Whether the estimate is trusted (see [`crate::lock`]).
    pub lock: LockStatus,
}

/// The estimator's outputs for one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate<T> {
    /// θ̂: estimated rotor angle (rad, electrical, in [−π, π]) from T2S-1.
    pub theta: T,
    /// ω̂ of T2S-1 (rad/s, electrical): the speed fed back to the observer.
    pub omega: T,
    /// ω̂ of T2S-2 (rad/s, electrical): the smoother speed for speed and current control.
    pub omega_control: T,
    /// Internal signals.
    pub diagnostics: Diagnostics<T>,
}

impl<T: Real> Estimate<T> {
    /// True when every number in it (outputs and diagnostics) is finite.
    pub fn is_finite(&self) -> bool {
        let d = &self.diagnostics;
        self.theta.is_finite()
            && self.omega.is_finite()
            && self.omega_control.is_finite()
            && d.lambda1.is_finite()
            && d.disturbance.is_finite()
            && d.lambda2.is_finite()
            && d.lambda_r.is_finite()
            && d.theta_direct.is_finite()
            && d.rs_hat.is_finite()
            && d.flux_linkage_hat.is_finite()
    }
}

/// The outputs of [`SensorlessEstimator::step_lean`](crate::SensorlessEstimator::step_lean): what a firmware control loop uses of
/// [`Estimate`], without the diagnostics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LeanEstimate<T> {
    /// θ̂: estimated rotor angle (rad, electrical, in [−π, π]) from T2S-1.
    pub theta: T,
    /// ω̂ of T2S-1 (rad/s, electrical).
    pub omega: T,
    /// ω̂ of T2S-2 (rad/s, electrical): the speed for speed and current control.
    pub omega_control: T,
    /// Which flux feedback is active (FLAG_limit of Fig. 10 is `Mode::Limiter`).
    pub mode: Mode,
    /// Whether the estimate is trusted (see [`crate::lock`]).
    pub lock: LockStatus,
    /// This sample was rejected (non-finite or implausible, see [`crate::plausibility`]); the
    /// other fields repeat the last good sample.
    pub input_fault: bool,
}

impl<T> From<Estimate<T>> for LeanEstimate<T> {
    #[inline(always)]
    fn from(e: Estimate<T>) -> Self {
        Self {
            theta: e.theta,
            omega: e.omega,
            omega_control: e.omega_control,
            mode: e.diagnostics.mode,
            lock: e.diagnostics.lock,
            input_fault: e.diagnostics.input_fault,
        }
    }
}
