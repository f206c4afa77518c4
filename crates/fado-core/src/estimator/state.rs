//! [`EstimatorState`]'s start-up, alignment and run-time settings, and the estimate of the
//! last good sample.

use super::{Diagnostics, Estimate, EstimatorParams, EstimatorState, LeanEstimate};
use crate::active_flux::{ActiveFlux, ActiveFluxPoint};
use crate::error::ConfigError;
use crate::integrand_offset::IntegrandOffsetState;
use crate::lock::LockState;
use crate::magnetics::MachineMagnetics;
use crate::magnetics::{FluxLookup, FluxWarmStart};
use crate::mode::Mode;
use crate::observer::ObserverState;
use crate::ripple::{PwmRipple, RIPPLE_EVERY};
use crate::rotor_flux::{rotor_angle, rotor_flux, stator_flux};
use crate::speed_notch::SpeedNotch;
use crate::{Ab, Real};

impl<T: Real> EstimatorState<T> {
    /// The start-up state for `params` (as [`EstimatorParams::initial_state`]).
    pub fn new(params: &EstimatorParams<T>) -> Self {
        params.initial_state()
    }

    /// Back to the start-up state at `config.initial_angle` with zero current; an adapted R̂s
    /// goes back to the value the adaptation started from.
    pub fn reset(&mut self, p: &EstimatorParams<T>) {
        if self.rs_adaptation_on {
            self.rs_adaptation = p.rs_adaptation_params.initial_state(&self.rs_scale);
            self.offset = IntegrandOffsetState::default();
            self.integrator
                .set_rs_hat_unchecked(self.rs_adaptation.rs_hat);
        }
        self.align(p, p.initial_angle, Ab::zero());
    }

    /// Start-up at a known rotor angle θ0 with the present current (docs/method/estimator.md, "Start-up"):
    /// λ1 = λ̂a·e^{jθ0} + L̂q·i with the active flux λ̂a = λ̂f + (L̂d − L̂q)·i_d, D̂ = 0, θ̂ = θ0,
    /// ω̂ = 0, limiter mode. An adapted R̂s is kept (the winding is as warm as it was).
    pub fn align(&mut self, p: &EstimatorParams<T>, theta0: T, i_ab: Ab<T>) {
        let theta0 = if theta0.is_finite() {
            theta0
        } else {
            T::zero()
        };
        let (active, lq) = Self::aligned_active(p, theta0, i_ab);
        self.lq_secant = lq;
        self.flux_warm = FluxWarmStart::empty();
        self.ripple_offset = Ab::zero();
        let lambda_r = Ab::from_polar(active, theta0);
        // A current so large that L̂q·i overflows is as unusable as a NaN (found by fuzzing,
        // f32: i = 3e37 A gave λ1 = ∞): start as with zero current.
        let lambda1 = lambda_r + i_ab * lq;
        let (lambda1, i_ab) = if lambda1.is_finite() {
            (lambda1, i_ab)
        } else {
            (lambda_r, Ab::zero())
        };
        self.integrator.reset_to(lambda1);
        // The last current is also what the first sample's current step is checked against
        // (see `crate::plausibility`): an implausible one is not kept.
        self.integrator
            .set_last_current(if p.bounds.current_ok(i_ab) {
                i_ab
            } else {
                Ab::zero()
            });
        // A saturating model's observer follows a rotating vector of the low-passed active
        // flux, which starts at the aligned one (`crate::active_flux`).
        self.swing_reference = if p.active_flux.is_saturating() {
            active
        } else {
            p.flux_linkage
        };
        let reference = match p.active_flux.saturating() {
            Some(af) => af.observer_reference(active),
            None => p.flux_linkage,
        };
        self.observer = ObserverState::at(if p.observer_on_rotor_flux {
            Ab::from_polar(reference, theta0)
        } else {
            lambda1
        });
        self.kdf_gain = T::zero();
        self.mode = Mode::Limiter;
        self.t2s1 = p.t2s1.state_at(theta0, T::zero());
        self.t2s2 = p.t2s2.state_at(theta0, T::zero());
        self.lag_compensation = T::zero();
        self.speed_notch = SpeedNotch::state_at(T::zero());
        self.frame_coupled = false;
        self.offset_share = T::one();
        self.coupled_steady = 0;
        self.notch_on = false;
        self.frame_rate_gain = T::zero();
        self.active_ratio = T::one();
        // The observer's gains for ω̂ = 0, held as after any update (so that with the
        // default period they are formed in the slots after the lock detector's, which no
        // slow law uses: see `SLOW_PERIOD`).
        self.observer_gains = p.observer.gains(T::zero());
        self.gain_countdown = p.gain_hold;
        self.feedback = Ab::zero();
        self.rejected_samples = 0;
        self.lock = LockState::default();
        self.lock_status = self.lock.status();
        self.lock_mode = Mode::Limiter;
        self.slot = 0;
        self.slow_broken = 0;
        self.v_sum = Ab::zero();
        self.i_sum = Ab::zero();
        self.slow_feedback = self.offset.offset;
        self.step_allowance = p.bounds.step();
    }

    /// The active flux λ̂f + (L̂d − L̂q)·i_d (λ̂f exactly for L̂d = L̂q), or a saturating
    /// model's at the current in the frame aligned at `theta0`, with its secant L̂q; λ̂f and
    /// L̂q where that is not a positive finite flux.
    fn aligned_active(p: &EstimatorParams<T>, theta0: T, i_ab: Ab<T>) -> (T, T) {
        let rotor = Ab::from_polar(T::one(), theta0);
        let (active, lq) = match p.active_flux.saturating() {
            None => (p.flux_linkage + p.saliency * rotor.dot(i_ab), p.lq),
            Some(af) => {
                let point = af.point(ActiveFlux::frame_current(rotor, i_ab));
                (point.active, point.lq_secant)
            }
        };
        if active.is_finite() && active > T::zero() && lq.is_finite() {
            (active, lq)
        } else {
            (p.flux_linkage, p.lq)
        }
    }

    /// One sample (Fig. 5) with the parameters `p` this state was made for: as
    /// [`SensorlessEstimator::step`](crate::SensorlessEstimator::step).
    #[inline]
    pub fn step(&mut self, p: &EstimatorParams<T>, v_ab: Ab<T>, i_ab: Ab<T>) -> Estimate<T> {
        self.advance(p, v_ab, i_ab)
    }

    /// [`Self::step`] without the diagnostics: as [`SensorlessEstimator::step_lean`](crate::SensorlessEstimator::step_lean), the
    /// firmware step.
    #[inline]
    pub fn step_lean(
        &mut self,
        p: &EstimatorParams<T>,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) -> LeanEstimate<T> {
        self.advance(p, v_ab, i_ab)
    }

    /// [`Self::step_lean`] with the machine's model named by its type: `model` is the table
    /// `p`'s machine borrows (`MachineMagnetics::Uniform(&MAP)` with `MAP = TABLE.map()`,
    /// `model = &TABLE`), so that the saturating step is compiled for that table — its
    /// lookups inlined with the grid's shape a constant, no match on the model and no index
    /// checked (docs/results/firmware-cost.md, "Flux map"). The same estimate as
    /// [`Self::step_lean`]; where `model` is not `p`'s model (or `p`'s machine has constant
    /// inductances), [`Self::step_lean`] itself.
    #[inline]
    pub fn step_lean_in<M: FluxLookup<T>>(
        &mut self,
        p: &EstimatorParams<T>,
        model: M,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) -> LeanEstimate<T> {
        self.advance_in(p, model, v_ab, i_ab)
    }

    /// λ̂a/λ̂f = 1 + (L̂d − L̂q)·î_d/λ̂f, the active flux the limiter circle and the lock
    /// detector's bounds refer to (1 on a surface-magnet rotor, and while the trackers hold),
    /// î_d the current along λ̂r; at least the tracker's hold ratio. Formed where it is used
    /// (the limiter mode, the detector's slot), so that a salient rotor's k_df mode skips its
    /// √ and two divisions in three samples of four.
    #[inline(always)]
    pub(super) fn active_ratio(
        p: &EstimatorParams<T>,
        i_ab: Ab<T>,
        lambda_r: Ab<T>,
        saliency: T,
        tracker_hold: bool,
        point: Option<ActiveFluxPoint<T>>,
    ) -> T {
        if let Some(point) = point {
            // A saturating model: λ̂a(î)/λ̂f at the sample's operating point.
            return if tracker_hold {
                T::one()
            } else {
                crate::real::max(point.active / p.flux_linkage, p.tracker_hold_ratio)
            };
        }
        if saliency != T::zero() && !tracker_hold {
            let i_d = i_ab.dot(lambda_r) / lambda_r.norm_squared().step_sqrt();
            let ratio = T::one() + saliency * i_d / p.flux_linkage;
            crate::real::max(ratio, p.tracker_hold_ratio)
        } else {
            T::one()
        }
    }

    /// (L̂d − L̂q)·î_d·e^{jθ̂}: the part of the active flux λ̂a·e^{jθ} = (λ̂f + (L̂d − L̂q)·i_d)·e^{jθ}
    /// that the drive's own i_d moves (the eq. (23) injection, MTPA, a load change under
    /// MTPA). The d axis is the observer's own rotating vector λ̂1 − D̂ of the last sample
    /// (≈ λ̂f·e^{jθ̂}, no extra state), î_d the current along it. Zero while that vector is
    /// below the tracker's hold level (no usable axis).
    #[inline]
    pub(super) fn active_flux_swing<M: FluxLookup<T>, const SATURATING: bool>(
        &self,
        p: &EstimatorParams<T>,
        af: &ActiveFlux<T, M>,
        i_ab: Ab<T>,
        saliency: T,
    ) -> (Ab<T>, FluxWarmStart<T>) {
        let axis = self.observer.flux() - self.observer.disturbance();
        let n2 = axis.norm_squared();
        if SATURATING {
            // A saturating model: λ̂a(î) less the observer's reference along the axis, î in
            // its frame (`ActiveFlux::observer_reference`).
            return if n2 > p.hold_level_sq {
                // The axis is the estimated active flux: the last sample's solution (in a
                // frame within a sample's turn of this one) starts the model's flux, else
                // ψ(î) ≈ axis + L̂q,s·î.
                let i_dq = ActiveFlux::frame_current(axis, i_ab);
                let guess = ActiveFlux::frame_current(axis, axis + i_ab * self.lq_secant);
                let (point, warm) = af.point_warm(i_dq, guess, &self.flux_warm);
                let reference = af.observer_reference(self.swing_reference);
                let swing = axis * ((point.active - reference) / n2.step_sqrt());
                (swing, warm)
            } else {
                (Ab::zero(), self.flux_warm)
            };
        }
        let swing = if n2 > p.hold_level_sq {
            axis * (saliency * i_ab.dot(axis) / n2)
        } else {
            Ab::zero()
        };
        (swing, self.flux_warm)
    }

    #[cold]
    pub(super) fn reject(&mut self, p: &EstimatorParams<T>) -> Estimate<T> {
        self.rejected_samples = self.rejected_samples.saturating_add(1);
        self.step_allowance += p.bounds.step();
        let mut out = self.last(p);
        out.diagnostics.input_fault = true;
        out
    }

    /// The estimate of the last good sample (or of the last `align`/`reset`), recomputed from
    /// the state: as [`SensorlessEstimator::last`](crate::SensorlessEstimator::last).
    pub fn last(&self, p: &EstimatorParams<T>) -> Estimate<T> {
        let lambda1 = self.integrator.flux();
        let disturbance = self.observer.disturbance();
        let lambda2 = stator_flux(lambda1, disturbance);
        let lambda_r = rotor_flux(lambda2, self.integrator.last_current(), self.lq_secant);
        let mode = self.mode;
        Estimate {
            theta: self.t2s1.angle(),
            omega: self.t2s1.speed(),
            omega_control: self.t2s2.speed(),
            diagnostics: Diagnostics {
                lambda1,
                disturbance,
                lambda2,
                lambda_r,
                theta_direct: rotor_angle(lambda_r),
                mode,
                flag_limit: mode == Mode::Limiter,
                limiter_clamping: mode == Mode::Limiter && p.limiter.step(lambda_r).clamping,
                tracker_hold: lambda_r.norm_squared() < p.hold_level_sq,
                rs_hat: self.integrator.rs_hat(),
                flux_linkage_hat: self.rs_adaptation.flux_linkage_hat,
                input_fault: false,
                lock: self.lock.status(),
            },
        }
    }

    /// Number of samples rejected since the last reset.
    pub fn rejected_samples(&self) -> u32 {
        self.rejected_samples
    }

    /// As [`SensorlessEstimator::set_disturbance_feedback_enabled`](crate::SensorlessEstimator::set_disturbance_feedback_enabled).
    pub fn set_disturbance_feedback_enabled(&mut self, enabled: bool) {
        self.k_df_enabled = enabled;
    }

    /// As [`SensorlessEstimator::set_release_tracking`](crate::SensorlessEstimator::set_release_tracking).
    pub fn set_release_tracking(&mut self, on: bool) {
        self.release_tracking = on;
    }

    /// As [`SensorlessEstimator::set_pwm_ripple`](crate::SensorlessEstimator::set_pwm_ripple).
    pub fn set_pwm_ripple(&mut self, p: &EstimatorParams<T>, v_ab: Ab<T>, vdc: T, dead_time: T) {
        if let MachineMagnetics::Saturation(_) = p.active_flux.model() {
            self.ripple_phase = (self.ripple_phase + 1) % RIPPLE_EVERY;
            if self.ripple_phase == 0 {
                self.ripple = PwmRipple::from_voltage(v_ab, vdc, p.ts(), dead_time);
            }
        }
    }

    /// As [`SensorlessEstimator::set_rs_hat`](crate::SensorlessEstimator::set_rs_hat).
    pub fn set_rs_hat(&mut self, p: &EstimatorParams<T>, rs_hat: T) -> Result<(), ConfigError> {
        self.integrator.set_rs_hat(rs_hat)?;
        if self.rs_adaptation_on {
            // R̂s ≥ 0 was just checked: the adaptation restarts around it.
            self.rs_scale = p.rs_adaptation_params.scale(rs_hat);
            self.rs_adaptation = p.rs_adaptation_params.initial_state(&self.rs_scale);
        }
        Ok(())
    }

    /// As [`SensorlessEstimator::enable_rs_adaptation`](crate::SensorlessEstimator::enable_rs_adaptation).
    pub fn enable_rs_adaptation(&mut self, p: &EstimatorParams<T>) {
        if self.rs_adaptation_on {
            return;
        }
        self.rs_adaptation_on = true;
        self.offset_recentring_gain = p.offset_recentring_gain;
        let rs_hat = self.integrator.rs_hat();
        self.rs_scale = p.rs_adaptation_params.scale(rs_hat);
        self.rs_adaptation = p.rs_adaptation_params.initial_state(&self.rs_scale);
        self.offset = IntegrandOffsetState::default();
        self.slow_feedback = Ab::zero();
    }

    /// As [`SensorlessEstimator::turn_angle`](crate::SensorlessEstimator::turn_angle).
    pub fn turn_angle(&mut self, _p: &EstimatorParams<T>, angle: T) {
        if !angle.is_finite() || self.mode != Mode::Limiter {
            return;
        }
        let lambda1 = self.integrator.flux();
        let lambda2 = stator_flux(lambda1, self.observer.disturbance());
        let lambda_r = rotor_flux(lambda2, self.integrator.last_current(), self.lq_secant);
        let turned = lambda1 + lambda_r.mul_j() * angle;
        if turned.is_finite() {
            self.integrator
                .commit(turned, self.integrator.last_current());
        }
    }

    /// Pulls |λ̂r| towards `magnitude` in limiter mode by k_af·Ts of the difference, along λ̂r
    /// (the angle is untouched): the loaded standstill's flux-magnitude hold (see
    /// [`crate::control::standstill_probe`]).
    pub fn hold_flux_magnitude(&mut self, p: &EstimatorParams<T>, magnitude: T) {
        if !magnitude.is_finite() || magnitude <= T::zero() || self.mode != Mode::Limiter {
            return;
        }
        let lambda1 = self.integrator.flux();
        let lambda2 = stator_flux(lambda1, self.observer.disturbance());
        let lambda_r = rotor_flux(lambda2, self.integrator.last_current(), self.lq_secant);
        let n = lambda_r.norm_squared().step_sqrt();
        if n <= T::zero() || !n.is_finite() {
            return;
        }
        let pull = p.limiter.config().k_af * p.ts * (magnitude - n) / n;
        let held = lambda1 + lambda_r * pull.step_max(-T::one()).step_min(T::one());
        if held.is_finite() {
            self.integrator.commit(held, self.integrator.last_current());
        }
    }

    /// Clears a loss-of-lock verdict (as [`RotorAngleEstimator::rearm_lock_detector`](crate::estimator::RotorAngleEstimator::rearm_lock_detector)).
    pub fn rearm_lock_detector(&mut self) {
        self.lock = LockState::default();
        self.lock_status = self.lock.status();
        self.lock_mode = self.mode;
    }

    /// ê, the learned integrand offset (V, α-β; zero without `rs_adaptation`).
    pub fn integrand_offset(&self) -> Ab<T> {
        self.offset.offset
    }

    /// R̂s in use now (Ω).
    pub fn rs_hat(&self) -> T {
        self.integrator.rs_hat()
    }

    /// Whether the R̂s adaptation runs.
    pub fn rs_adaptation_enabled(&self) -> bool {
        self.rs_adaptation_on
    }
}
