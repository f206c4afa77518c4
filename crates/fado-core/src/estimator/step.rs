//! One sample of Fig. 5, in the order of the module docs: integrate, observe, form λ̂r,
//! track, select the mode and the feedback, commit, then the lock detector and the slow laws
//! in their slots.
//!
//! Each phase is a function of its own, inlined into [`EstimatorState::advance`]: the
//! sample is computed first into a [`Candidate`] and committed only if it is finite.
//!
//! The step exists in two copies, chosen by the machine's magnetics (fixed when the
//! parameters are built): constant inductances run the closed-form arithmetic of eq. (5)
//! with no trace of a magnetic model (`SATURATING = false`, inlined into the caller), a
//! saturating model the operating-point evaluations of `crate::active_flux` (out of line).
//! One branch per sample picks the copy; within it every test of the model is resolved at
//! compile time, so that the constant-inductance path costs what it would without the
//! saturating one (docs/results/host-cost.md, docs/results/firmware-cost.md).

use super::{
    BROKEN_LIMITED, BROKEN_OFFSET, BROKEN_RS, Diagnostics, Estimate, EstimatorParams,
    EstimatorState, LOCK_PERIOD, SLOT_LOCK, SLOT_OFFSET, SLOT_RS, SLOW_PERIOD, STEADY_ACTIVE_SHARE,
};
use crate::active_flux::{ActiveFlux, ActiveFluxPoint};
use crate::magnetics::FluxLookup;
use crate::magnetics::FluxWarmStart;
use crate::magnetics::MachineMagnetics;
use crate::mode::Mode;
use crate::real::all_finite;
use crate::ripple::{PwmRipple, mean_current_offset_ab};
use crate::rotor_flux::{rotor_angle, stator_flux};
use crate::rs_adaptation::AdaptationRegime;
use crate::tracker::TrackerUpdate;
use crate::{Ab, Dq, Real, Rotation};

pub(super) mod notch;

/// The new state of one sample, computed before anything is committed.
struct Candidate<T: Real> {
    /// L̂d − L̂q, loaded once for every use in the sample.
    saliency: T,
    /// A saturating model's operating point (`crate::active_flux`), with its secant L̂q
    /// (None on the constant-inductance path).
    point: Option<ActiveFluxPoint<T>>,
    /// A saturating model's ψ(î) of this sample, the next sample's warm start
    /// (`crate::magnetics::FluxWarmStart`; empty for a model that needs none).
    flux_warm: FluxWarmStart<T>,
    /// λ1 integrated with the previous sample's feedback (eq. (21) / (24)).
    lambda1: Ab<T>,
    /// The current the integrator's resistive drop used (the slow laws' current).
    i_drop: Ab<T>,
    /// The observer's λ̂1 and D̂ (eq. (10), (16)).
    observer_flux: Ab<T>,
    disturbance: Ab<T>,
    /// λ2 = λ1 − D̂ (eq. (20)), λ̂r = λ2 − L̂q·i (eq. (5)) and its angle θm (eq. (6)).
    lambda2: Ab<T>,
    lambda_r: Ab<T>,
    theta_direct: T,
    /// |λ̂r| below the hold level: the trackers coast.
    tracker_hold: bool,
    t2s1: TrackerUpdate<T>,
    t2s2: TrackerUpdate<T>,
    mode: Mode,
    kdf_gain: T,
    /// The mode's own feedback (k_df·D̂ or the limiter's), without the slow laws' share.
    base_feedback: Ab<T>,
    /// The limiter clamps λ̂r this sample.
    clamping: bool,
    /// The feedback for the next sample: `base_feedback` plus the slow laws' share.
    feedback: Ab<T>,
}

impl<T: Real> EstimatorState<T> {
    /// The step itself, for any output that is a projection of [`Estimate`]: inlined into
    /// [`Self::step`] and [`Self::step_lean`], so that the compiler drops what the output
    /// does not keep.
    #[inline(always)]
    pub(super) fn advance<O: From<Estimate<T>>>(
        &mut self,
        p: &EstimatorParams<T>,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) -> O {
        if p.active_flux.is_saturating() {
            self.advance_saturating(p, v_ab, i_ab)
        } else {
            self.advance_with::<O, _, false>(p, &p.active_flux, v_ab, i_ab)
        }
    }

    /// [`Self::advance`] with the model named by `model` (a table's own type,
    /// `crate::magnetics::FluxLookup`): where it is the parameters' model, the saturating
    /// step compiled for it, out of line; else the step of the parameters' model.
    #[inline(always)]
    pub(super) fn advance_in<O: From<Estimate<T>>, M: FluxLookup<T>>(
        &mut self,
        p: &EstimatorParams<T>,
        model: M,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) -> O {
        if p.active_flux.is_saturating() && model.is_model_of(p.active_flux.model()) {
            self.advance_typed(p, model, v_ab, i_ab)
        } else {
            self.advance_record(p, v_ab, i_ab)
        }
    }

    /// [`Self::advance`] out of line: [`Self::advance_in`]'s step where `model` is not the
    /// parameters' (its caller then carries no copy of the constant-inductance step).
    #[inline(never)]
    fn advance_record<O: From<Estimate<T>>>(
        &mut self,
        p: &EstimatorParams<T>,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) -> O {
        self.advance(p, v_ab, i_ab)
    }

    /// The saturating step compiled for the model `M`, out of line.
    #[inline(never)]
    fn advance_typed<O: From<Estimate<T>>, M: FluxLookup<T>>(
        &mut self,
        p: &EstimatorParams<T>,
        model: M,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) -> O {
        let af = p.active_flux.with_model(model);
        self.advance_with::<O, M, true>(p, &af, v_ab, i_ab)
    }

    /// The step of a saturating model: out of line, so that the constant-inductance step it
    /// stands beside stays as small as without it where it is inlined.
    #[inline(never)]
    fn advance_saturating<O: From<Estimate<T>>>(
        &mut self,
        p: &EstimatorParams<T>,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) -> O {
        self.advance_with::<O, _, true>(p, &p.active_flux, v_ab, i_ab)
    }

    /// The step with the magnetics resolved at compile time: `SATURATING` is whether
    /// `p`'s model saturates (`crate::active_flux`), `af` that model as `M` names it.
    #[inline(always)]
    fn advance_with<O: From<Estimate<T>>, M: FluxLookup<T>, const SATURATING: bool>(
        &mut self,
        p: &EstimatorParams<T>,
        af: &ActiveFlux<T, M>,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) -> O {
        // Plausibility first (a few compares; false for NaN/∞ too, see `crate::plausibility`).
        if !p.bounds.check(
            v_ab,
            i_ab,
            self.integrator.last_current(),
            self.step_allowance,
        ) {
            return self.reject(p).into();
        }
        // The whole new state is computed first and committed only if it is finite: a
        // non-finite input makes it non-finite (every input enters λ1 through Ts·v and the
        // resistive drop, or λ̂r through L̂q·i, and NaN and ±∞ propagate, 0·∞ included), finite
        // but absurd inputs can still overflow it, and a rejected sample must leave none of it
        // changed. One test at the end covers all of this (cheaper than a test per input and
        // per block, and than copying the estimator as a backup every sample).
        let c = self.candidate::<M, SATURATING>(p, af, v_ab, i_ab);
        if !Self::is_committable(&c) {
            return self.reject(p).into();
        }
        let previous_mode = self.mode;
        // The estimate is formed before the commit, with the R̂s and λ̂f this sample used;
        // the loss-of-lock status is filled in after the detector's slot.
        let rs_hat = self.integrator.rs_hat();
        let flux_linkage_hat = self.rs_adaptation.flux_linkage_hat;
        let mut estimate = Self::estimate(&c, rs_hat, flux_linkage_hat, self.lock_status);
        let shift = self.commit::<M, SATURATING>(p, af, &c, i_ab);
        self.judge_lock::<SATURATING>(p, &c, i_ab);
        self.step_allowance = p.bounds.step();
        let slot = self.slot;
        // SLOW_PERIOD is a power of two: the modulo is a mask.
        self.slot = (slot + 1) % SLOW_PERIOD;
        // 6. The slow laws in their slots (see [`SLOW_PERIOD`]): R̂s and ê for the next
        //    sample (see `rs_adaptation`, `integrand_offset`), after the commit so that the
        //    paper's path is untouched by them. A non-finite result is dropped (R̂s, ê stay).
        if self.rs_adaptation_on {
            self.run_slow_laws::<M, SATURATING>(p, af, &c, slot, previous_mode, shift, v_ab, i_ab);
        }
        estimate.diagnostics.lock = self.lock_status;
        estimate.into()
    }

    /// Phases 1–5 of the sample: integrate, observe, form λ̂r, track, select the mode and
    /// the feedback for the next sample. Nothing is committed.
    #[inline(always)]
    fn candidate<M: FluxLookup<T>, const SATURATING: bool>(
        &self,
        p: &EstimatorParams<T>,
        af: &ActiveFlux<T, M>,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) -> Candidate<T> {
        // L̂d − L̂q: zero on a surface-magnet rotor, where the active-flux terms vanish.
        let saliency = p.saliency;
        // 1. Integrate with the feedback of the previous sample (eq. (21) / (24)).
        let (lambda1, i_drop) = p
            .integrator
            .next_flux(&self.integrator, v_ab, i_ab, self.feedback);
        let (lambda1, i_drop) = if SATURATING {
            self.with_ripple_drop(p, lambda1, i_drop)
        } else {
            (lambda1, i_drop)
        };
        // L̂q·i of eq. (5), formed once for both of its uses (λ̂r, and the observer's input
        // on the rotor flux): what `rotor_flux` computes, bit for bit. A saturating model's
        // secant L̂q is the last sample's here (`crate::active_flux`).
        let lq_i = i_ab * if SATURATING { self.lq_secant } else { p.lq };
        // 2. Disturbance observer.
        let (observer_flux, disturbance, flux_warm) =
            self.observe::<M, SATURATING>(p, af, lambda1, lq_i, i_ab, saliency);
        // 3. Rotor flux and direct angle (eq. (20), (5), (6)); a saturating model's secant
        //    L̂q at the current in the frame of λ2 − L̂q⁻·i.
        let lambda2 = stator_flux(lambda1, disturbance);
        let (lambda_r, point, flux_warm) = if SATURATING {
            let (lambda_r, point, warm) =
                af.rotor_flux_warm(lambda2, i_ab, self.lq_secant, &flux_warm);
            (lambda_r, Some(point), warm)
        } else {
            (lambda2 - lq_i, None, flux_warm)
        };
        let tracker_hold = lambda_r.norm_squared() < p.hold_level_sq;
        let theta_direct = rotor_angle(lambda_r);
        // 4. Trackers (Fig. 1, Fig. 5).
        let (t2s1, t2s2) = self.track(p, theta_direct, tracker_hold);
        // 5. Mode from the control speed, and the feedback for the next sample.
        let mode = p.selector.next_mode(self.mode, t2s2.omega);
        let kdf_active = mode == Mode::DisturbanceFeedback && self.k_df_enabled;
        let kdf_gain = p.disturbance_feedback.next_gain(self.kdf_gain, kdf_active);
        let (base_feedback, clamping) = match mode {
            Mode::DisturbanceFeedback => (disturbance * kdf_gain, false),
            Mode::Limiter => {
                let ratio = Self::active_ratio(p, i_ab, lambda_r, saliency, tracker_hold, point);
                let l = p.limiter.step_scaled(lambda_r, ratio);
                (l.feedback, l.clamping)
            }
        };
        // The learned integrand offset ê is subtracted from the integrand in both modes, with
        // the standstill pull of the R̂s adaptation (both held between the slow laws' runs).
        // Without the R̂s adaptation both are exactly zero (nothing learns them; it cannot be
        // switched off once on), so the sum needs no test of the flag.
        let feedback = base_feedback + self.slow_feedback;
        Candidate {
            saliency,
            point,
            flux_warm,
            lambda1,
            i_drop,
            observer_flux,
            disturbance,
            lambda2,
            lambda_r,
            theta_direct,
            tracker_hold,
            t2s1,
            t2s2,
            mode,
            kdf_gain,
            base_feedback,
            clamping,
            feedback,
        }
    }

    /// Step 2: the disturbance observer at ω̂ of T2S-1 (eq. (10), (16)), on λ1 or on λ1 − L̂q·i (see
    /// `EstimatorTuning::observer_on_rotor_flux`): (λ̂1, D̂), and the warm start of the model's
    /// ψ(î) after the active flux's swing (the last sample's where the swing solves none).
    #[inline(always)]
    fn observe<M: FluxLookup<T>, const SATURATING: bool>(
        &self,
        p: &EstimatorParams<T>,
        af: &ActiveFlux<T, M>,
        lambda1: Ab<T>,
        lq_i: Ab<T>,
        i_ab: Ab<T>,
        saliency: T,
    ) -> (Ab<T>, Ab<T>, FluxWarmStart<T>) {
        let (observer_input, warm) = if p.observer_on_rotor_flux {
            let active = lambda1 - lq_i;
            if saliency != T::zero() {
                let (swing, warm) = self.active_flux_swing::<M, SATURATING>(p, af, i_ab, saliency);
                (active - swing, warm)
            } else {
                (active, self.flux_warm)
            }
        } else {
            (lambda1, self.flux_warm)
        };
        // With `observer.lag_compensation` ω̂1 plus T2S-1's low-passed Kp·e (the rate of
        // θ̂), not the lagging ω̂1 alone. Its gains were formed for that speed at the end of
        // a previous sample (the last one, or up to `observer.gain_period` earlier).
        let (observer_flux, disturbance) =
            p.observer
                .next_state_with(&self.observer, &self.observer_gains, observer_input);
        (observer_flux, disturbance, warm)
    }

    /// Step 4: both trackers on the direct angle θm, or coasting while |λ̂r| is below the hold
    /// level; T2S-1 with its running gains in disturbance-feedback mode.
    #[inline(always)]
    fn track(
        &self,
        p: &EstimatorParams<T>,
        theta_direct: T,
        tracker_hold: bool,
    ) -> (TrackerUpdate<T>, TrackerUpdate<T>) {
        if tracker_hold {
            (
                p.t2s1.coasted_state(&self.t2s1),
                p.t2s2.coasted_state(&self.t2s2),
            )
        } else {
            // Above the mode threshold T2S-1 runs at its running bandwidth (the last
            // sample's mode: the one this sample's angle was integrated in), and at a
            // brake's release (`set_release_tracking`).
            let t2s1 = if self.mode == Mode::DisturbanceFeedback || self.release_tracking {
                &p.t2s1_running
            } else {
                &p.t2s1
            };
            (
                t2s1.next_state(&self.t2s1, theta_direct),
                // Both trackers have the same Ts: T2S-1's Ts in angle units, loaded once.
                p.t2s2
                    .next_state_with(&self.t2s2, theta_direct, p.t2s1.ts_units()),
            )
        }
    }

    /// The one finite test of the sample.
    #[inline(always)]
    fn is_committable(c: &Candidate<T>) -> bool {
        // Which values the one test needs (the others follow from them, so the test is
        // exact, not approximate): a non-finite v or i makes λ1 non-finite (Ts·v, and R̂s·i
        // with R̂s ≥ 0: ∞·R̂s = ∞, 0·∞ = NaN, ∞ − ∞ = NaN); a tracker's ω̂ = ω̂ + Ki·Ts·e is
        // finite only if its phase error e = wrap(…) is, and then θ̂ and θ̂⁻ (wrapped sums of
        // finite values) are finite too. λ̂r and the feedback can overflow on their own.
        // λ1 and D̂ need no test of their own: λ̂r = (λ1 − D̂) − L̂q·i (eq. (20), (5)) with a
        // finite L̂q·i (the bounds passed) is finite only if both are (a difference with an
        // ∞ or NaN operand is ∞ or NaN).
        all_finite([
            c.observer_flux.alpha,
            c.observer_flux.beta,
            c.lambda_r.alpha,
            c.lambda_r.beta,
            c.feedback.alpha,
            c.feedback.beta,
            c.t2s1.omega,
            c.t2s2.omega,
        ])
    }

    /// Commits the candidate: λ1 and the observer (re-centred), the lag compensation, the
    /// observer's gains when due, the trackers, the mode and the feedback. Returns the
    /// re-centring shift of D̂.
    #[inline(always)]
    fn commit<M: FluxLookup<T>, const SATURATING: bool>(
        &mut self,
        p: &EstimatorParams<T>,
        af: &ActiveFlux<T, M>,
        c: &Candidate<T>,
        i_ab: Ab<T>,
    ) -> Ab<T> {
        // Limiter mode: re-centre the common mode (see `LimiterTuning::recentring`).
        // With the integrand-offset law, the k_df mode re-centres too, at k_e (see
        // `crate::integrand_offset`: D̂ then decays at k_df + k_e instead of k_df, and the
        // ramp k_df·D̂ that the observer has to follow goes with it).
        // A gain switched off is 0 and its shift D̂·0 = 0 changes nothing: no test of it.
        let shift = c.disturbance
            * match c.mode {
                Mode::Limiter => p.limiter_recentring_gain,
                Mode::DisturbanceFeedback => self.offset_recentring_gain,
            };
        self.integrator.commit(c.lambda1 - shift, i_ab);
        self.observer
            .commit(c.observer_flux - shift, c.disturbance - shift);
        // The observer's lag compensation: Kp·e of T2S-1 through the first-order low-pass
        // (see `EstimatorTuning::observer_lag_compensation_hz`).
        if p.lag_compensation {
            self.lag_compensation =
                p.lag_keep * self.lag_compensation + p.lag_input * c.t2s1.innovation;
        }
        let observer_speed = c.t2s1.omega + self.lag_compensation;
        // The notch where the frame coupling can be large: a saturating model, or a salient
        // rotor with constant inductances (on a surface-magnet rotor the coupling is zero).
        let observer_speed = if SATURATING || c.saliency != T::zero() {
            self.notch_speed(p, af, c, i_ab, observer_speed)
        } else {
            observer_speed
        };
        // The observer's gains for the next sample's speed, once every `gain_hold` + 1
        // samples (see `EstimatorTuning::observer_gain_period`).
        if self.gain_countdown == 0 {
            self.observer_gains = p.observer.gains(observer_speed);
            self.gain_countdown = p.gain_hold;
        } else {
            self.gain_countdown -= 1;
        }
        self.t2s1.commit(c.t2s1);
        // T2S-2's θ̂ is never read (its ω̂ is the control speed): not stored.
        self.t2s2.commit_speed(c.t2s2);
        if let Some(point) = c.point {
            self.lq_secant = point.lq_secant;
            self.flux_warm = c.flux_warm;
            if self.ripple_phase == 2 {
                self.ripple_offset = self.ripple_offset_at(p, c, point.i_dq);
            }
            self.swing_reference = self.swing_reference
                + p.swing_reference_gain * (point.active - self.swing_reference);
        }
        self.mode = c.mode;
        self.kdf_gain = c.kdf_gain;
        self.feedback = c.feedback;
        shift
    }

    /// A saturating model's drop with the interval's mean current: the sample plus the PWM
    /// ripple's bias (`crate::ripple`; zero for a flux map), λ1 and the drop current moved by it.
    #[inline(always)]
    fn with_ripple_drop(
        &self,
        p: &EstimatorParams<T>,
        lambda1: Ab<T>,
        i_drop: Ab<T>,
    ) -> (Ab<T>, Ab<T>) {
        let d = self.ripple_offset;
        (
            lambda1 - d * (self.integrator.rs_hat() * p.ts()),
            i_drop + d,
        )
    }

    /// The PWM ripple's current bias (`crate::ripple`) at this sample's operating point, in
    /// α-β for the next samples' drop: the algebraic model's sigma points about ψ(î), the
    /// ripple's own resistive drop and the dead time's lead through the warm start's
    /// incremental inductance, in the frame of λ̂r; zero for another model, without a ripple,
    /// or where λ̂r is too small to give a frame (the trackers coast there).
    #[inline(always)]
    fn ripple_offset_at(&self, p: &EstimatorParams<T>, c: &Candidate<T>, i_dq: Dq<T>) -> Ab<T> {
        let MachineMagnetics::Saturation(model) = p.active_flux.model() else {
            return Ab::zero();
        };
        if c.tracker_hold || self.ripple == PwmRipple::zero() {
            return Ab::zero();
        }
        let inv = T::one() / c.lambda_r.norm_squared().step_sqrt();
        let rot = Rotation {
            cos: c.lambda_r.alpha * inv,
            sin: c.lambda_r.beta * inv,
        };
        let psi = c.flux_warm.prediction(i_dq);
        let l = c.flux_warm.inductance();
        let rs_ts = self.integrator.rs_hat() * p.ts();
        let d = mean_current_offset_ab(model, psi, &l, &self.ripple, rs_ts, rot);
        if d.is_finite() { d } else { Ab::zero() }
    }

    /// Loss-of-lock symptoms (see `lock`), in the detector's slot: |λ̂r| against λ̂f (the
    /// lower bound chosen by the control speed ω̂ of the mode selector), the T2S-1
    /// innovation. Stepped after the finite test, so that one slot test both computes and
    /// commits it (a rejected sample never reaches this point). Outside its slot the
    /// detector's state is neither copied nor written back.
    #[inline(always)]
    fn judge_lock<const SATURATING: bool>(
        &mut self,
        p: &EstimatorParams<T>,
        c: &Candidate<T>,
        i_ab: Ab<T>,
    ) {
        // The innovation is T2S-1's phase error of this sample (0 when the trackers coasted).
        // The round-robin's slot, read only now: nothing before the commit needs it.
        if self.slot % LOCK_PERIOD != SLOT_LOCK {
            return;
        }
        // λ̂f as this sample used it (the slow laws have not run yet).
        let flux_hat = self.rs_adaptation.flux_linkage_hat;
        let active_ratio =
            Self::active_ratio(p, i_ab, c.lambda_r, c.saliency, c.tracker_hold, c.point);
        // A hand-over since the last judged sample (the mode sampled every LOCK_PERIOD
        // samples: two hand-overs within them would need ω̂ to cross the hysteresis band
        // twice in 0.4 ms, and count as none).
        let handover = c.mode != self.lock_mode;
        self.lock_mode = c.mode;
        let lock = p.lock.next_state(
            self.lock,
            c.lambda_r.norm_squared(),
            flux_hat * flux_hat * active_ratio * active_ratio,
            c.t2s1.innovation * T::angle_unit(),
            c.t2s2.omega,
            c.clamping,
            handover,
        );
        self.lock = lock;
        self.lock_status = lock.status();
    }

    /// Step 6: the R̂s adaptation (with its λ̂f law) and the integrand-offset law, each in its
    /// slot of the round-robin (see [`SLOW_PERIOD`]).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn run_slow_laws<M: FluxLookup<T>, const SATURATING: bool>(
        &mut self,
        p: &EstimatorParams<T>,
        af: &ActiveFlux<T, M>,
        c: &Candidate<T>,
        slot: u8,
        previous_mode: Mode,
        shift: Ab<T>,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) {
        // An interruption marks both laws' periods broken: with the two bits there are,
        // slow_broken | (both) is both, so the byte is written only then (and by the law
        // that runs in its slot), not in every free slot.
        if c.tracker_hold || previous_mode != c.mode {
            self.slow_broken = BROKEN_RS | BROKEN_OFFSET;
        }
        let broken = self.slow_broken;
        if slot == SLOT_RS {
            self.adapt_resistance::<M, SATURATING>(p, af, c, broken, v_ab, i_ab);
        } else if c.mode == Mode::Limiter {
            // Only the standstill law uses the means, and only after a whole period in the
            // limiter mode (else its regime is `Frozen`).
            self.v_sum += v_ab;
            self.i_sum += c.i_drop;
        }
        if slot == SLOT_OFFSET {
            self.learn_offset(p, c, broken, shift);
        }
    }

    /// Which R̂s law applies in this slot, and whether a frame-coupled operating point has
    /// been steady long enough for the turning law (then also its `settled`).
    #[inline(always)]
    fn resistance_regime<M: FluxLookup<T>, const SATURATING: bool>(
        &self,
        p: &EstimatorParams<T>,
        af: &ActiveFlux<T, M>,
        c: &Candidate<T>,
        broken: u8,
    ) -> (AdaptationRegime, bool) {
        // A saturating model's frame coupling above `active_flux::OFFSET_COUPLING_MAX` freezes
        // the turning law as it holds the offset law: with the current loop holding î, a
        // frame error moves |λ̂r| by σ·δ, which the law would read as resistance (a model
        // error's angle, or a load step's transient, amplified; docs/method/saturation.md,
        // "The offset law's gate").
        // Steady there, for as long as the λ̂f law waits after a hand-over, it runs: the
        // coupling then carries no load transient, and the law models the rest (the model's
        // flux uncertainty times 1 + the coupling, `crate::rs_adaptation`).
        let coupled_settled = SATURATING
            && self.frame_coupled
            && u32::from(self.coupled_steady) >= p.flux_settle_periods;
        let coupled = SATURATING
            && self.frame_coupled
            && c.mode == Mode::DisturbanceFeedback
            && !coupled_settled;
        // Beyond a map's data the model's slope is its edge cells' extension: the law would
        // learn that guess's error as resistance (docs/results/saturated-replay.md: a map that
        // ends at 0.6 × rated current, 0.32 rad at rated torque with the law, 0.004 frozen).
        let beyond = SATURATING && c.point.is_some_and(|point| af.beyond_data(&point));
        let regime = if broken & BROKEN_RS != 0 || coupled || beyond {
            AdaptationRegime::Frozen
        } else {
            match c.mode {
                // A limited voltage in the period (`SensorlessEstimator::voltage_limited`).
                Mode::DisturbanceFeedback if broken & BROKEN_LIMITED != 0 => {
                    AdaptationRegime::Frozen
                }
                Mode::DisturbanceFeedback => AdaptationRegime::Rotating,
                Mode::Limiter => AdaptationRegime::Standstill,
            }
        };
        (regime, coupled_settled)
    }

    /// The R̂s adaptation's slot: R̂s, λ̂f and the standstill pull for the next period.
    #[inline(always)]
    fn adapt_resistance<M: FluxLookup<T>, const SATURATING: bool>(
        &mut self,
        p: &EstimatorParams<T>,
        af: &ActiveFlux<T, M>,
        c: &Candidate<T>,
        broken: u8,
        v_ab: Ab<T>,
        i_ab: Ab<T>,
    ) {
        let (regime, coupled_settled) = self.resistance_regime::<M, SATURATING>(p, af, c, broken);
        // The standstill law sees the voltage without the learned offset, and the voltage
        // and current averaged over the period.
        let per_sample = T::one() / T::lit(SLOW_PERIOD as f64);
        let v_mean = (self.v_sum + v_ab) * per_sample;
        let i_mean = (self.i_sum + c.i_drop) * per_sample;
        self.v_sum = Ab::zero();
        self.i_sum = Ab::zero();
        let (state, pull) = p.rs_adaptation_params.next_state::<M, SATURATING>(
            &self.rs_scale,
            &self.rs_adaptation,
            v_mean - self.offset.offset,
            c.i_drop,
            i_mean,
            i_ab,
            c.lambda_r,
            c.t2s1.omega,
            regime,
            self.offset.learning_samples >= p.flux_settle_periods || coupled_settled,
            Some(af),
        );
        // The pull acts until the law runs again (one period), with ê.
        let slow_feedback = self.offset.offset + pull;
        let feedback = c.base_feedback + slow_feedback;
        // R̂s and λ̂f leave the adaptation clamped by compare-and-select, which turns a NaN
        // into the bound: always finite.
        if all_finite([
            state.charge_d,
            state.volt_seconds_d,
            state.i_d_prev,
            state.offset_sensitivity.alpha,
            state.offset_sensitivity.beta,
            state.standstill_share,
            state.flux_error_angle,
            state.flux_excitation,
            state.flux_angle,
            state.flux_time,
            state.excitation_time,
            feedback.alpha,
            feedback.beta,
        ]) {
            self.rs_adaptation = state;
            self.integrator.set_rs_hat_unchecked(state.rs_hat);
            self.feedback = feedback;
            self.slow_feedback = slow_feedback;
        }
        self.slow_broken = broken & !(BROKEN_RS | BROKEN_LIMITED);
    }

    /// The integrand-offset law's slot: ê, and R̂s without what earlier standstill tests
    /// read of it.
    #[inline(always)]
    fn learn_offset(&mut self, p: &EstimatorParams<T>, c: &Candidate<T>, broken: u8, shift: Ab<T>) {
        // D̂ decays over the period by k_df·N·Ts, and by the N − 1 re-centring shifts
        // k_e·Ts·D̂ of the samples since the law last ran (see
        // `IntegrandOffset::next_state`).
        let n = T::lit(SLOW_PERIOD as f64);
        let decay = c.kdf_gain * (p.ts * n) + self.offset_recentring_gain * (n - T::one());
        // A saturating model's frame coupling (`crate::active_flux`): where the flux magnitude
        // carries the frame error the law holds ê and the k_df mode stops re-centring at k_e
        // until the next period; below that both run at a share of k_e that falls with the
        // coupling (`ActiveFlux::offset_rate_share`).
        let holds = self.frame_coupled;
        if (c.point.is_some() || c.saliency != T::zero()) && self.rs_adaptation_on {
            self.offset_recentring_gain = if holds {
                T::zero()
            } else {
                p.offset_recentring_gain * self.offset_share
            };
        }
        let regime = broken & BROKEN_OFFSET == 0 && c.mode == Mode::DisturbanceFeedback;
        let learning = regime && !holds;
        // A coupled point's steadiness (`coupled_steady`): the active flux near its low-pass.
        let steady = regime
            && holds
            && c.point.is_some_and(|point| {
                (point.active - self.swing_reference).abs()
                    <= T::lit(STEADY_ACTIVE_SHARE) * self.swing_reference
            });
        self.coupled_steady = if steady {
            self.coupled_steady.saturating_add(1)
        } else {
            0
        };
        let mut offset = p.offset.next_state(
            &self.offset,
            c.disturbance,
            decay,
            shift,
            learning,
            self.offset_share,
        );
        // Above the speed of the shortest revolution the law trusts it holds ê (an error
        // locked to the rotor and the carrier aliases onto DC there; the count of settled
        // samples goes on, the λ̂f law waits on it).
        if c.t2s1.omega.abs() > p.offset_max_speed {
            offset.offset = self.offset.offset;
        }
        // R̂s drops what earlier standstill tests read of the offset ê learns now.
        let change = offset.offset - self.offset.offset;
        let (rs_hat, standstill_share) =
            self.rs_adaptation
                .rs_after_offset_change(&self.rs_scale, change, c.point.is_some());
        let slow_feedback = self.slow_feedback + change;
        let feedback = c.base_feedback + slow_feedback;
        if all_finite([
            offset.offset.alpha,
            offset.offset.beta,
            offset.disturbance_prev.alpha,
            offset.disturbance_prev.beta,
            feedback.alpha,
            feedback.beta,
        ]) {
            self.offset = offset;
            self.rs_adaptation.rs_hat = rs_hat;
            self.rs_adaptation.standstill_share = standstill_share;
            self.integrator.set_rs_hat_unchecked(rs_hat);
            self.feedback = feedback;
            self.slow_feedback = slow_feedback;
        }
        self.slow_broken = broken & !BROKEN_OFFSET;
    }

    /// The sample's estimate, with the R̂s and λ̂f it used.
    #[inline(always)]
    fn estimate(
        c: &Candidate<T>,
        rs_hat: T,
        flux_linkage_hat: T,
        lock: crate::LockStatus,
    ) -> Estimate<T> {
        Estimate {
            theta: c.t2s1.angle(),
            omega: c.t2s1.omega,
            omega_control: c.t2s2.omega,
            diagnostics: Diagnostics {
                lambda1: c.lambda1,
                disturbance: c.disturbance,
                lambda2: c.lambda2,
                lambda_r: c.lambda_r,
                theta_direct: c.theta_direct,
                mode: c.mode,
                flag_limit: c.mode == Mode::Limiter,
                limiter_clamping: c.clamping,
                tracker_hold: c.tracker_hold,
                rs_hat,
                flux_linkage_hat,
                input_fault: false,
                lock,
            },
        }
    }
}
