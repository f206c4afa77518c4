//! The two laws' constants ([`ResistanceAdaptationParams`]), what they derive from R0
//! ([`ResistanceScale`]) and one period of each law.

use super::{
    AdaptationRegime, FLUX_LINKAGE_DEAD_ZONE, FLUX_LINKAGE_DEAD_ZONE_OFF, FLUX_LINKAGE_MAX_RATIO,
    FLUX_LINKAGE_MIN_RATIO, RESISTIVE_SPEED_ANGLE, ResistanceAdaptationConfig,
    ResistanceAdaptationState, SATURATED_PRIOR_TIME, SATURATED_RESISTIVE_SPEED_ANGLE,
};
use crate::active_flux::{ActiveFlux, ActiveFluxPoint};
use crate::error::{ConfigError, check};
use crate::magnetics::FluxLookup;
use crate::real::{max, min};
use crate::{Ab, Real};

/// The laws' constants, precomputed once from a [`ResistanceAdaptationConfig`] (the
/// immutable half of [`ResistanceAdaptation`]). What scales with R0 is in
/// [`ResistanceScale`]: R0 changes at run time (the estimator's `set_rs_hat`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ResistanceAdaptationParams<T: 'static> {
    config: ResistanceAdaptationConfig<T>,
    /// γ·Ts.
    rate_ts: T,
    /// Ts/[`RESISTIVE_SPEED_ANGLE`]: γ·Ts at a resistive speed of 1 rad/s.
    speed_rate_ts: T,
    /// Ts/[`SATURATED_RESISTIVE_SPEED_ANGLE`]: a saturating model's γ·Ts at a resistive
    /// speed of 1 rad/s.
    saturated_speed_rate_ts: T,
    /// The model's flux uncertainty at zero current in Wb: `model_flux_uncertainty`·λ̂f
    /// (configured).
    model_flux: T,
    /// Its growth with the current in Wb/A²: `model_flux_growth`·λ̂f (configured).
    model_flux_growth: T,
    /// γ_s·Ts.
    standstill_gain: T,
    /// e^{−ω_m·Ts}.
    forget: T,
    /// 1/(2π·standstill_speed_hz)².
    standstill_inv_omega_sq: T,
    /// L̂d − L̂q.
    saliency: T,
    floor_sq: T,
}

/// The resistance error, as a share of R0, whose flux error the turning law must see above
/// what the model leaves open (a map's interpolation spread, `ActiveFlux::interpolation_spread`,
/// plus the configured `model_flux_uncertainty`, both times 1 + the frame coupling) to run.
/// Ours \[A\]: a model error read as resistance biases R̂s by at most about this share; 2 %
/// holds the traction IPMSM's coarse 7 × 8 map of `scripts/saturated-replay.py` (R̂s
/// 0.95–1.05 × the truth running everywhere).
pub(crate) const MAP_RESISTANCE_RESOLUTION: f64 = 0.02;

/// The frame coupling |s|/κ (`ActiveFlux::frame_coupling`) at or above which the turning law
/// stays frozen even at a steady operating point: there a frame error moves |λ̂r| by more than
/// the turn of λ̂r it leaves visible (σ/κ ≥ 1), so whatever frame error is left (a load's
/// transient, the model's own mismatch) outweighs the resistance's flux. Ours \[A\]: the
/// pmsyrm-baldor-5k6 presets' MTPA points (0.60–0.96 from 30 % to rated torque) lie below it
/// and their R̂s converges there; the weak-magnet PM-SyRMs of `saturated_replay` (1.1–1.5
/// under load), which learn a load step's transient as resistance where the law runs at
/// their coupled points, stay frozen (docs/method/saturation.md, "The offset law's gate").
pub(crate) const COUPLED_RESISTANCE_MAX: f64 = 1.0;

/// The regressor's bracket and the frame coupling at `point` (None: frozen). Below
/// `OFFSET_COUPLING_MAX` the bracket's turned part must be smaller than its direct part i_q
/// (`ActiveFlux::resistance_regressor_coupled`); above it (the estimator runs the law there
/// only at a steady operating point, `crate::estimator`) the coupling must stay below
/// [`COUPLED_RESISTANCE_MAX`], and a turned part that adds to i_q may reach twice it (the
/// bracket is then larger than i_q, not ill-conditioned: at the PM-SyRM's rated MTPA point it
/// reaches i_q).
#[inline(always)]
fn coupled_bracket<T: Real, M: FluxLookup<T>>(
    af: &ActiveFlux<T, M>,
    point: &ActiveFluxPoint<T>,
) -> Option<(T, T)> {
    let (direct, turned, coupling) = af.resistance_regressor_parts(point)?;
    let conditioned = turned.abs() < direct.abs();
    let usable = if coupling > T::lit(crate::active_flux::OFFSET_COUPLING_MAX) {
        let adds = turned * direct >= T::zero() && turned.abs() < (direct + direct).abs();
        coupling < T::lit(COUPLED_RESISTANCE_MAX) && (conditioned || adds)
    } else {
        conditioned
    };
    usable.then_some((direct + turned, coupling))
}

/// 1/(2π·`hz`)²: |ω̂| ≤ 2π·`hz` is ω̂²·(that) ≤ 1; `hz` = 0 allows ω̂ = 0 only (1e30: no
/// ∞·0).
fn inverse_square_speed<T: Real>(hz: T) -> T {
    if hz > T::zero() {
        let w = T::two_pi() * hz;
        T::one() / (w * w)
    } else {
        T::lit(1e30)
    }
}

/// What the laws derive from R0, the resistance they start from and scale with: mutable
/// (R0 is replaced at run time), so kept with the state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ResistanceScale<T> {
    /// R0, Ω.
    r0: T,
    /// γ·Ts·R0.
    gain: T,
    /// R0/λ̂f (the configured λ̂f).
    chi_per_phi: T,
    rs_min: T,
    rs_max: T,
}

impl<T: Real> ResistanceAdaptationParams<T> {
    /// Checks every field of `config` (the error names it) and precomputes the constants.
    /// R0 = 0 is allowed: it scales the law and its bounds to nothing (R̂s stays 0).
    pub(crate) fn new(config: ResistanceAdaptationConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        check::non_negative("rs_initial", config.rs_initial)?;
        check::positive("flux_linkage_hat", config.flux_linkage_hat)?;
        check::non_negative("lq_hat", config.lq_hat)?;
        check::non_negative("ld_hat", config.ld_hat)?;
        check::finite("ld_hat", config.ld_hat - config.lq_hat)?;
        let flux_rate_f = check::non_negative("flux_linkage_rate", config.flux_linkage_rate)?;
        check::below(
            "flux_linkage_rate",
            flux_rate_f * ts,
            T::one(),
            "with flux_linkage_rate·ts below 1",
        )?;
        let rate = check::non_negative("rate", config.rate)?;
        check::below("rate", rate * ts, T::one(), "with rate·ts below 1")?;
        let floor = check::positive("excitation_floor", config.excitation_floor)?;
        let rate_s = check::non_negative("standstill_rate", config.standstill_rate)?;
        check::below(
            "standstill_rate",
            rate_s * ts,
            T::one(),
            "with standstill_rate·ts below 1",
        )?;
        let memory_w =
            T::two_pi() * check::positive("standstill_memory_hz", config.standstill_memory_hz)?;
        check::below(
            "standstill_memory_hz",
            memory_w * ts,
            T::one(),
            "with 2π·f·ts below 1",
        )?;
        let standstill_hz = check::non_negative("standstill_speed_hz", config.standstill_speed_hz)?;
        let flux_rate = check::non_negative("standstill_flux_rate", config.standstill_flux_rate)?;
        check::below(
            "standstill_flux_rate",
            flux_rate * ts,
            T::one(),
            "with standstill_flux_rate·ts below 1",
        )?;
        let angle_rate =
            check::non_negative("standstill_angle_rate", config.standstill_angle_rate)?;
        check::below(
            "standstill_angle_rate",
            angle_rate * ts,
            T::one(),
            "with standstill_angle_rate·ts below 1",
        )?;
        check::non_negative("flux_linkage_min_speed", config.flux_linkage_min_speed)?;
        let uncertainty =
            check::non_negative("model_flux_uncertainty", config.model_flux_uncertainty)?;
        let growth = check::non_negative("model_flux_growth", config.model_flux_growth)?;
        let min = check::positive("min_ratio", config.min_ratio)?;
        if min > T::one() {
            return Err(ConfigError::OutOfRange {
                field: "min_ratio",
                expected: "at most 1",
            });
        }
        let max = check::finite("max_ratio", config.max_ratio)?;
        if max < T::one() {
            return Err(ConfigError::OutOfRange {
                field: "max_ratio",
                expected: "at least 1",
            });
        }
        Ok(Self {
            config,
            rate_ts: rate * ts,
            speed_rate_ts: ts / T::lit(RESISTIVE_SPEED_ANGLE),
            saturated_speed_rate_ts: ts / T::lit(SATURATED_RESISTIVE_SPEED_ANGLE),
            model_flux: uncertainty * config.flux_linkage_hat,
            model_flux_growth: growth * config.flux_linkage_hat,
            standstill_gain: rate_s * ts,
            forget: (-(memory_w * ts)).exp(),
            standstill_inv_omega_sq: inverse_square_speed(standstill_hz),
            saliency: config.ld_hat - config.lq_hat,
            floor_sq: floor * floor,
        })
    }

    /// A saturating model's operating point at the current `i` in the frame of `lambda_r`
    /// (None for constant inductances: `SATURATING` false).
    #[inline(always)]
    fn operating_point<M: FluxLookup<T>, const SATURATING: bool>(
        active_flux: Option<&ActiveFlux<T, M>>,
        lambda_r: Ab<T>,
        i: Ab<T>,
    ) -> Option<(&ActiveFlux<T, M>, ActiveFluxPoint<T>)> {
        if !SATURATING {
            return None;
        }
        let af = active_flux?;
        let point = af.point(ActiveFlux::<T>::frame_current(lambda_r, i));
        Some((af, point))
    }

    /// The values scaled by R0 = `r0` (checked non-negative by the caller; the products are
    /// the ones the unsplit block formed, bit for bit).
    pub(crate) fn scale(&self, r0: T) -> ResistanceScale<T> {
        let c = &self.config;
        ResistanceScale {
            r0,
            gain: c.rate * c.ts * r0,
            chi_per_phi: r0 / c.flux_linkage_hat,
            rs_min: c.min_ratio * r0,
            rs_max: c.max_ratio * r0,
        }
    }

    /// The state at R̂s = R0 of `scale`, λ̂f as configured, the standstill integrals zero.
    pub(crate) fn initial_state(&self, scale: &ResistanceScale<T>) -> ResistanceAdaptationState<T> {
        ResistanceAdaptationState {
            rs_hat: scale.r0,
            flux_linkage_hat: self.config.flux_linkage_hat,
            ..ResistanceAdaptationState::default()
        }
    }

    /// The configuration the constants were computed from.
    pub(crate) fn config(&self) -> &ResistanceAdaptationConfig<T> {
        &self.config
    }

    /// The state after one more period of the law (`ts`), computed without changing this
    /// one. `i_drop` is the current the integrator's resistive drop used this sample (the
    /// turning law's regressor: an R̂s error enters the integrand as −ΔR̂s·`i_drop`);
    /// `i_now` the current sampled now, with λ̂r (the turning law's active flux î_d and a
    /// saturating model's operating point; at standstill its d component at the ends of the
    /// period gives the inductive voltage's integral L̂d·Δi_d); `v_ab` and `i_mean` are the voltage and
    /// current averaged over the period (the
    /// standstill law integrates them: run once per sample, the samples themselves; run once
    /// every N samples, their means over the N samples, so that its integrals stay those of
    /// every sample — a sampled v_d would add the noise of the samples left out, and alias
    /// whatever the current loop puts at multiples of 1/(N·Ts) to DC). `settled`: the k_df
    /// mode has lasted long enough for the λ̂f law (past the hand-over transient).
    /// `SATURATING` with `active_flux`: a saturating model (`crate::active_flux`), whose
    /// active flux at the estimated current gives the reference λ̂a, the regressor φ and the
    /// standstill law's inductances (the laws frozen where φ is ill-conditioned); else the
    /// constant L̂d, L̂q of the configuration (the constant-inductance copy of the
    /// estimator's step passes `SATURATING` false: no test of the model in it). The
    /// returned pull (V) acts until the next run (the estimator holds it over the period).
    /// Always inlined: the estimator's step is its one caller per sample (an out-of-line
    /// copy costs a call and the spills around it on a Cortex-M4F, docs/results/firmware-cost.md).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn next_state<M: FluxLookup<T>, const SATURATING: bool>(
        &self,
        scale: &ResistanceScale<T>,
        st: &ResistanceAdaptationState<T>,
        v_ab: Ab<T>,
        i_drop: Ab<T>,
        i_mean: Ab<T>,
        i_now: Ab<T>,
        lambda_r: Ab<T>,
        omega: T,
        regime: AdaptationRegime,
        settled: bool,
        active_flux: Option<&ActiveFlux<T, M>>,
    ) -> (ResistanceAdaptationState<T>, Ab<T>) {
        let mut next = ResistanceAdaptationState {
            rs_hat: st.rs_hat,
            flux_linkage_hat: st.flux_linkage_hat,
            flux_learning: st.flux_learning,
            offset_sensitivity: st.offset_sensitivity,
            standstill_share: st.standstill_share,
            excitation_time: st.excitation_time,
            ..ResistanceAdaptationState::default()
        };
        let mag_sq = lambda_r.norm_squared();
        if regime == AdaptationRegime::Frozen || mag_sq <= T::zero() {
            return (next, Ab::zero());
        }
        let mag = mag_sq.step_sqrt();
        let pull = if regime == AdaptationRegime::Rotating {
            // The operating point at the current sampled with λ̂r (module docs, "Sampled at
            // ω̂·Ts").
            let point = Self::operating_point::<M, SATURATING>(active_flux, lambda_r, i_now);
            if !self.rotating(
                scale,
                st,
                &mut next,
                (i_drop, i_now),
                lambda_r,
                mag,
                omega,
                settled,
                point,
            ) {
                return (next, Ab::zero());
            }
            Ab::zero()
        } else {
            let standstill = self.standstill::<M, SATURATING>(
                scale,
                st,
                &mut next,
                v_ab,
                i_mean,
                i_now,
                lambda_r,
                mag,
                omega,
                active_flux,
            );
            match standstill {
                Some(pull) => pull,
                None => return (next, Ab::zero()),
            }
        };
        next.rs_hat = min(max(next.rs_hat, scale.rs_min), scale.rs_max);
        (next, pull)
    }

    /// The turning law (and, settled and fast enough, the flux-linkage law) into `next`;
    /// false when the active flux is no usable reference (nothing adapts).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn rotating<M: FluxLookup<T>>(
        &self,
        scale: &ResistanceScale<T>,
        st: &ResistanceAdaptationState<T>,
        next: &mut ResistanceAdaptationState<T>,
        (i_drop, i_now): (Ab<T>, Ab<T>),
        lambda_r: Ab<T>,
        mag: T,
        omega: T,
        settled: bool,
        point: Option<(&ActiveFlux<T, M>, ActiveFluxPoint<T>)>,
    ) -> bool {
        let lf = st.flux_linkage_hat;
        let dl = self.saliency;
        if let Some((af, point)) = point {
            // A saturating model (`crate::active_flux`): λ̂a(î) shifted by the learned λ̂f,
            // the regressor's bracket at î; frozen where it is ill-conditioned, and until the
            // hand-over's transient has settled (`settled`, as the λ̂f law): there the angle
            // error turns î, and the regressor judged at î is not the machine's.
            if !settled {
                return false;
            }
            let Some((bracket, coupling)) = coupled_bracket(af, &point) else {
                return false;
            };
            // Frozen where what the model leaves open (the map's interpolation spread, the
            // configured model flux uncertainty at î) times 1 + the frame coupling (a model
            // error's q part turns the frame, moving |λ̂r| by the coupling times it) exceeds
            // the flux of a resistance error of `MAP_RESISTANCE_RESOLUTION`·R0,
            // R0·|bracket|/|ω̂| times it: the law would learn the model's error as resistance.
            let model_flux = self.model_flux + self.model_flux_growth * i_now.norm_squared();
            let open = af.interpolation_spread(&point) + model_flux * (T::one() + coupling);
            if open * omega.abs() >= T::lit(MAP_RESISTANCE_RESOLUTION) * scale.r0 * bracket.abs() {
                return false;
            }
            let reference = point.active + (lf - self.config.flux_linkage_hat);
            // χ relative to the active flux where it exceeds λ̂f (a reluctance rotor's |λ̂r|
            // is many times its magnet's flux: relative to λ̂f a weak magnet's χ would pass
            // χ0 on the map's slope alone at no load).
            // ẽ relative to the same flux: ẽ·χ is then (ΔR/R0)·χ², and R̂s decays at
            // γ·χ²/(χ² + χ0²) as on any other rotor (relative to λ̂f it would decay
            // reference/λ̂f times faster, 22 times on a PM-SyRM with an 8.7 mVs magnet, and
            // learn a map's interpolation error or a load step's transient as resistance
            // within milliseconds).
            let relative_to = crate::real::max(lf, reference);
            let a = -(mag * bracket) * scale.chi_per_phi * (lf / relative_to);
            let (gain, rate_ts) = self.saturated_rate(scale, st, a, mag, coupling);
            return self.rotating_step(
                st,
                next,
                (reference, relative_to),
                (a, gain, rate_ts),
                mag,
                omega,
                settled,
            );
        }
        // The reference is the active flux λ̂a = λ̂f + (L̂d − L̂q)·î_d and φ carries the
        // sensitivity factor 1 + (L̂d − L̂q)·î_d/λ̂a (module docs); for L̂d = L̂q both are
        // exactly λ̂f and 1, and the division for î_d is skipped. î_d is the current sampled
        // with λ̂r, not the interval's drop current, which lags it by ω̂·Ts/2 (module docs,
        // "Sampled at ω̂·Ts").
        let (reference, sensitivity) = if dl == T::zero() {
            (lf, T::one())
        } else {
            let i_d = lambda_r.dot(i_now) / mag;
            let active = lf + dl * i_d;
            // A non-positive (or NaN) reference: nothing to compare with.
            if active.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Greater) {
                return false;
            }
            (active, T::one() + dl * i_d / active)
        };
        // χ = φ·R0/λ̂f with φ = −(i_q/ω̂)·sensitivity and i_q = (λ̂r × i)/|λ̂r|, as
        // χ = a/b: then χ/(χ² + χ0²) = a·b/(a² + χ0²·b²) costs one division, and
        // χ² ≥ χ0² is a² ≥ χ0²·b² (false for ω̂ = 0, which also rules out 0/0).
        let a = -lambda_r.cross(i_drop) * scale.chi_per_phi * sensitivity;
        let law = self.linear_rate(scale, a, mag);
        self.rotating_step(st, next, (reference, lf), law, mag, omega, settled)
    }

    /// `a` with the linear path's γ·Ts·R0 and γ·Ts this period: γ at least the present resistive
    /// speed R0·|î_q|/λ̂f (times the sensitivity) per [`RESISTIVE_SPEED_ANGLE`] (module docs,
    /// "The rate on a fast machine"); |a|/|λ̂r| is that speed. At or below it the configured
    /// γ, bit for bit; γ = 0 stays 0.
    #[inline(always)]
    fn linear_rate(&self, scale: &ResistanceScale<T>, a: T, mag: T) -> (T, T, T) {
        // At most half the error per period, whatever the data (9.4 s⁻¹ at 8 samples of
        // 12.5 µs, the outrunner of the module docs under load, is 0.1 % per period).
        let rate_ts = min(a.abs() * self.speed_rate_ts / mag, T::lit(0.5));
        if rate_ts > self.rate_ts && self.rate_ts > T::zero() {
            (a, rate_ts * scale.r0, rate_ts)
        } else {
            (a, scale.gain, self.rate_ts)
        }
    }

    /// A saturating model's γ·Ts·R0 and γ·Ts this period: the least-squares gain of the
    /// excitation the turning law has seen, Ts/(T_E + E) with E its accumulated excitation time
    /// Σ χ²/(χ² + χ0²)·Ts and T_E = [`SATURATED_PRIOR_TIME`] the weight of the configured R0
    /// (module docs, "The rate on a saturating model"), and at least the configured γ; at most
    /// half the error per period. The configured γ with a model flux uncertainty above 0
    /// (the data then carry the model's error, which the gain would take at once); γ = 0 stays
    /// 0. At a frame-coupled point (`coupling` above `OFFSET_COUPLING_MAX`, where the estimator
    /// runs the law only at a steady operating point) the gain is the prior's 1/T_E whatever
    /// the excitation seen: the least-squares gain's 1/t decay would leave most of a start
    /// error in place through the one or two loaded seconds before a zero-speed passage (the
    /// PM-SyRM's measured map started 1.4 × off: R̂s 1.085 × at `rated-reversal`'s passage,
    /// 0.974 × with the prior's rate, `saturated_rs_convergence`).
    #[inline(always)]
    fn saturated_rate(
        &self,
        scale: &ResistanceScale<T>,
        st: &ResistanceAdaptationState<T>,
        a: T,
        mag: T,
        coupling: T,
    ) -> (T, T) {
        if self.rate_ts <= T::zero() || self.model_flux + self.model_flux_growth > T::zero() {
            return (scale.gain, self.rate_ts);
        }
        let ts = self.config.ts;
        let seen = if coupling > T::lit(crate::active_flux::OFFSET_COUPLING_MAX) {
            T::zero()
        } else {
            st.excitation_time
        };
        let least_squares = ts / (T::lit(SATURATED_PRIOR_TIME) + seen);
        let resistive = a.abs() * self.saturated_speed_rate_ts / mag;
        let rate_ts = min(
            max(max(least_squares, resistive), self.rate_ts),
            T::lit(0.5),
        );
        (rate_ts * scale.r0, rate_ts)
    }

    /// The turning law's step (and the λ̂f law's) with the reference λ̂a, the flux the error
    /// is taken relative to (λ̂f, or a saturating rotor's active flux where that is more), the
    /// numerator `a` of χ = a/(|λ̂r|·ω̂) and the law's gain γ·Ts·R0 and γ·Ts this period.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn rotating_step(
        &self,
        st: &ResistanceAdaptationState<T>,
        next: &mut ResistanceAdaptationState<T>,
        (reference, relative_to): (T, T),
        (a, gain, rate_ts): (T, T, T),
        mag: T,
        omega: T,
        settled: bool,
    ) -> bool {
        let b = mag * omega;
        let (a_sq, floor_b_sq) = (a * a, self.floor_sq * b * b);
        if a_sq >= floor_b_sq && floor_b_sq > T::zero() {
            // ẽ·χ/(χ² + χ0²) with ẽ = (|λ̂r| − λ̂a)/`relative_to`, in one division.
            let weight = a_sq / (a_sq + floor_b_sq);
            next.rs_hat -= gain * (mag - reference) * a * b / (relative_to * (a_sq + floor_b_sq));
            // The turning law replaces what the standstill tests contributed.
            let keep = T::one() - rate_ts * weight;
            next.excitation_time = st.excitation_time + weight * self.config.ts;
            next.offset_sensitivity = st.offset_sensitivity * keep;
            next.standstill_share = st.standstill_share * keep;
        }
        if settled && omega.abs() >= self.config.flux_linkage_min_speed {
            self.flux_law(st, next, a, mag - reference, omega);
        }
        true
    }

    /// The flux-linkage law's step into `next`: `a` the turning law's numerator of χ,
    /// `deviation` the sample's |λ̂r| − λ̂a.
    #[inline(always)]
    fn flux_law(
        &self,
        st: &ResistanceAdaptationState<T>,
        next: &mut ResistanceAdaptationState<T>,
        a: T,
        deviation: T,
        omega: T,
    ) {
        let lf = st.flux_linkage_hat;
        // The λ̂f law (module docs): the mean of |λ̂r| − λ̂a over one electrical
        // revolution (angle-weighted, so exact at a changing speed: a DC error left in
        // λ2 by the observer's transient makes |λ̂r| swing at ω̂, which the mean
        // removes), used where the revolution's mean |χ| is below χ0/2 (R̂s explains
        // too little of it; per sample, current noise would cross any bound).
        // χ·dθ = a/(|λ̂r|·ω̂)·|ω̂|·Ts ≈ a·sgn(ω̂)·Ts/λ̂f: the sum of a·sgn(ω̂)·Ts is
        // compared with χ0/2·λ̂f·∮dθ at the end, no division per sample.
        let step_angle = omega.abs() * self.config.ts;
        let chi_step = if omega < T::zero() { -a } else { a } * self.config.ts;
        next.flux_error_angle = st.flux_error_angle + deviation * step_angle;
        next.flux_excitation = st.flux_excitation + chi_step;
        next.flux_angle = st.flux_angle + step_angle;
        next.flux_time = st.flux_time + self.config.ts;
        if next.flux_angle >= T::two_pi() {
            let bound = T::lit(0.5) * self.config.excitation_floor * lf * next.flux_angle;
            let excess_chi = next.flux_excitation.abs() >= bound;
            let lf0 = self.config.flux_linkage_hat;
            let error = next.flux_error_angle / next.flux_angle;
            // Dead zone with hysteresis (module docs): a mean beyond ±ε starts the
            // law, which then follows the whole mean until it is within ±ε_off.
            let zone = lf0 * T::lit(FLUX_LINKAGE_DEAD_ZONE);
            let excess = error - min(max(error, -zone), zone);
            let on = st.flux_learning || error.abs() > zone + zone;
            let gain = if excess_chi {
                T::zero()
            } else {
                min(self.config.flux_linkage_rate * next.flux_time, T::one())
            };
            if !excess_chi {
                next.flux_learning = on && error.abs() > lf0 * T::lit(FLUX_LINKAGE_DEAD_ZONE_OFF);
            }
            let step = if on { error } else { excess };
            next.flux_linkage_hat = min(
                max(lf + gain * step, lf0 * T::lit(FLUX_LINKAGE_MIN_RATIO)),
                lf0 * T::lit(FLUX_LINKAGE_MAX_RATIO),
            );
            next.flux_error_angle = T::zero();
            next.flux_excitation = T::zero();
            next.flux_angle = T::zero();
            next.flux_time = T::zero();
        }
    }

    /// The standstill law into `next`, and its pull (V); None outside its conditions
    /// (nothing adapts, no pull).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn standstill<M: FluxLookup<T>, const SATURATING: bool>(
        &self,
        scale: &ResistanceScale<T>,
        st: &ResistanceAdaptationState<T>,
        next: &mut ResistanceAdaptationState<T>,
        v_ab: Ab<T>,
        i_mean: Ab<T>,
        i_now: Ab<T>,
        lambda_r: Ab<T>,
        mag: T,
        omega: T,
        active_flux: Option<&ActiveFlux<T, M>>,
    ) -> Option<Ab<T>> {
        let lf = st.flux_linkage_hat;
        let dl = self.saliency;
        // Standstill: only at standstill and while the current lies along the flux (the
        // estimated rotor frame: d along λ̂r).
        let unit = lambda_r * (T::one() / mag);
        let i_d = unit.dot(i_mean);
        let i_q = unit.cross(i_mean);
        let speed_sq = omega * omega * self.standstill_inv_omega_sq;
        if i_d <= (i_q + i_q).abs() || speed_sq > T::one() {
            return None;
        }
        let ts = self.config.ts;
        let inv_i_d = T::one() / i_d;
        // L̂q·i_q (the q flux), L̂d (the d inductance a step of i_d meets) and the rotor's
        // active flux: a saturating model's at the estimated current, else the constants.
        let (rotation_emf, ld, active) =
            match Self::operating_point::<M, SATURATING>(active_flux, lambda_r, i_mean) {
                Some((af, point)) => (
                    omega * (point.lq_secant * i_q),
                    af.ld_incremental(point.i_dq),
                    point.active + (lf - self.config.flux_linkage_hat),
                ),
                None => (
                    omega * self.config.lq_hat * i_q,
                    self.config.ld_hat,
                    lf + dl * i_d,
                ),
            };
        let v_d = unit.dot(v_ab) + rotation_emf;
        // L̂d·di_d/dt integrates to L̂d·Δi_d between the ends of the period, from the
        // current sampled there (`i_now`); the first period of a test only records it
        // (its inductive voltage would otherwise be read as resistance).
        let i_d_now = unit.dot(i_now);
        next.i_d_prev = i_d_now;
        if st.i_d_prev != T::zero() {
            let di_d = i_d_now - st.i_d_prev;
            next.charge_d = st.charge_d * self.forget + i_d * ts;
            next.volt_seconds_d = st.volt_seconds_d * self.forget + v_d * ts - ld * di_d;
        }
        if next.charge_d * scale.chi_per_phi >= self.config.excitation_floor {
            let r_dc = next.volt_seconds_d / next.charge_d;
            let step = self.standstill_gain * (r_dc - next.rs_hat);
            next.rs_hat += step;
            next.standstill_share += step;
            let sensitivity = unit * inv_i_d;
            next.offset_sensitivity +=
                (sensitivity - next.offset_sensitivity) * self.standstill_gain;
        }
        // The current only moved λ̂r radially, and the rotor flux is the active flux λ̂a:
        // pull a shrunken λ̂r back out (outside, the Fig. 6 limiter already bounds it at
        // its circle; pulling it further in would only speed up the walk of a tangential
        // integrand error along the circle, which goes as e_t/|λ̂r|).
        let shortfall = min(mag - active, T::zero());
        let mut pull = unit * (self.config.standstill_flux_rate * shortfall);
        // The injection's current response: at standstill with no load the speed loop
        // holds the torque at zero, so the current lies along the rotor's d axis; turn
        // λ̂r towards it at k_θ·x·(1 − 4x²), x = i_q/i_d = tan(∠(i, λ̂r)) (module docs).
        let x = i_q * inv_i_d;
        let turn = self.config.standstill_angle_rate
            * mag
            * x
            * (T::one() - T::lit(4.0) * x * x)
            * (T::one() - speed_sq);
        pull += Ab::new(unit.beta, -unit.alpha) * turn;
        Some(pull)
    }
}

impl<T: Real> ResistanceAdaptationState<T> {
    /// R̂s and the standstill tests' remaining share of it after the integrand-offset estimate
    /// ê (`crate::integrand_offset`) moved by `offset_change` (V): R̂s drops what standstill
    /// tests read of it, −⟨Δê, ∂R̂s/∂ê⟩, and, `bounded` (a saturating model), never more
    /// than the tests put in (the change clamped between zero and −`standstill_share`, which
    /// it then reduces), within R̂s's bounds (compare-and-select: a NaN becomes a bound, so
    /// R̂s stays finite).
    ///
    /// Why the bound: ∂R̂s/∂ê is 1/i_d of the test's current, and the R̂s error it leaves
    /// acts at the load's current, |i|/i_d times the offset's own voltage. A Δê that is not
    /// the offset the test read (the offset law's transient through a load's arrival, a few
    /// mV) would otherwise move R̂s past anything the test measured: on the traction IPMSM
    /// (`crates/fado-sim/tests/data/traction-ipm-saturated.toml`, tests at 22 A, loaded at
    /// 247 A) 4 mV move R̂s by −0.9 %, which the zero-speed passage integrates into the angle
    /// at ΔR̂s·|i|/λa (docs/method/saturation.md, "The offset's re-attribution"). Bounded
    /// on a saturating model only: there the offset law learns through the frame coupling
    /// (up to `active_flux::OFFSET_COUPLING_MAX`), so a load's arrival leaves a share of its
    /// frame error in ê; with constant inductances the transfer is the unbounded one, and
    /// fig8–fig12 and the linear presets' runs stay as they are (bounded, fig8's largest
    /// error near zero speed is 0.0064 rad instead of 0.0037).
    #[inline(always)]
    pub(crate) fn rs_after_offset_change(
        &self,
        scale: &ResistanceScale<T>,
        offset_change: Ab<T>,
        bounded: bool,
    ) -> (T, T) {
        let share = self.standstill_share;
        let wanted = offset_change.dot(self.offset_sensitivity);
        // Bounded, the change −taken lies between 0 and −share: taken between 0 and share.
        let taken = if bounded {
            min(max(wanted, min(share, T::zero())), max(share, T::zero()))
        } else {
            wanted
        };
        (
            min(max(self.rs_hat - taken, scale.rs_min), scale.rs_max),
            share - taken,
        )
    }
}
