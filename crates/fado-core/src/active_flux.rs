//! The rotor flux of eq. (5)–(6) for a saturating machine: the active flux at the estimated
//! current, and the sensitivities the slow laws need from it.
//!
//! **Alignment.** With any magnetic model the stator flux is ψ_ab = e^{jθ}·ψ_dq(i). Removing
//! the secant q inductance L_q,s(i) = ψq(i)/i_q times the current,
//!
//! ```text
//!   ψ_ab − L_q,s(i)·i_ab = e^{jθ}·(ψd − L_q,s·i_d,  ψq − (ψq/i_q)·i_q) = e^{jθ}·λa(i)
//!   λa(i) = ψd(i) − L_q,s(i)·i_d      (the active flux)
//! ```
//!
//! leaves a vector on the d axis for any map: eq. (5) with L̂q the secant at the operating
//! point. For constant inductances L_q,s = Lq and λa = λf + (Ld − Lq)·i_d, eq. (5) itself. The
//! estimator does not know i_dq, only i_ab and its own angle: it evaluates L_q,s at the current
//! in the frame of λ2 − L_q,s⁻·i (L_q,s⁻ the last sample's secant), one step of the fixed point
//! λ̂r = λ2 − L_q,s(î(λ̂r))·i per sample. The secant moves with the load over tens of
//! milliseconds, so the step's L_q,s⁻ is within a sample's current change of the fixed point.
//!
//! **A map** (`MachineMagnetics::Map`) is read through its C¹ interpolant
//! ([`FluxMap::smooth_flux_and_jacobian`](crate::magnetics::FluxMap::smooth_flux_and_jacobian)),
//! since the angle reads the model's slope through κ below: a bilinear map's chord slopes jump
//! at every cell edge and lie below the tangent over part of each cell of a saturating axis.
//!
//! **The R̂s regressor** (see `crate::rs_adaptation` for the constant-inductance case). A
//! resistance error ΔR = R̂s − Rs leaves the synchronous flux error ΔR·(−i_q + j·i_d)/ω in the
//! rotor frame. Its d part changes |λ̂r| by −ΔR·i_q/ω. Its q part turns λ̂r, so the estimated
//! frame by ε, which moves î by ε·(i_q, −i_d) and with it the secant L_q,s(î), whose own q
//! part turns λ̂r further: with L_q,s = ψq/i_q, ∂L_q,s/∂i_d = L_qd/i_q and
//! ∂L_q,s/∂i_q = (L_qq − L_q,s)/i_q (L_xy the incremental inductances ∂ψx/∂i_y),
//!
//! ```text
//!   ε·κ = ΔR·i_d/ω,   κ = λa + L_qd·i_q − (L_qq − L_q,s)·i_d
//! ```
//!
//! The reference λa(î) moves with î too: by ∇ψd·Δî − ΔL_q,s·i_d − L_q,s·ε·i_q, and the ΔL_q,s
//! part cancels against |λ̂r|'s own. The flux-magnitude error is e = |λ̂r| − λa(î) = ΔR·φ with
//!
//! ```text
//!   φ = −(1/ω)·[ i_q + i_d·((L_dd − L_q,s)·i_q − L_dq·i_d)/κ ]
//! ```
//!
//! For constant inductances (L_dd = Ld, L_qq = L_q,s = Lq, L_dq = L_qd = 0, κ = λa) this is
//! the −(i_q/ω)·(1 + (Ld − Lq)·i_d/λa) of the linear law. Where κ falls towards zero, a
//! resistance error's q flux is amplified by the map's gradient without bound: the law cannot
//! tell the map's slope from a resistance, and freezes ([`KAPPA_MIN_RATIO`]).
//!
//! **The observer's reference.** The observer sees λ1 − L_q,s·i minus the swing, the active
//! flux λa(î) less a reference magnitude along the estimated axis, so that it follows a
//! rotating vector of that reference's magnitude while the drive's current moves λa. The
//! swing is removed along the estimated axis: an axis error δ leaves (λa − reference)·δ
//! across the vector, which turns it by (λa/reference − 1)·δ. With the magnet's ψd(0, 0) as
//! the reference that factor is 1.4 on the pmsyrm-baldor-5k6 preset at rated torque but 65
//! on a PM-SyRM with an 8.7 mVs magnet under a 0.57 Vs active flux, and the loop through the
//! observer's axis oscillates. The reference is therefore ψd(0, 0) or
//! [`SWING_REFERENCE_SHARE`] of λa low-passed over [`SWING_REFERENCE_TIME`], whichever is
//! more ([`ActiveFlux::observer_reference`]): the factor stays near 1 at every load.
//!
//! **The frame coupling** (the integrand-offset law's gate). In the drive the current loop
//! holds î at its reference, so a frame error δ = θ̂ − θ turns the machine's own current,
//! i = e^{jδ}·î, and λ̂r = ψ(i) − L_q,s(î)·i moves with it: it turns away from the rotor's d
//! axis by (1 − κ/λa)·δ, so that the estimator sees (κ/λa)·δ of its error, and its
//! magnitude moves by
//!
//! ```text
//!   s·δ,   s = (L_q,s − L_dd)·i_q + L_dq·i_d
//! ```
//!
//! against the fixed λa(î). The DC loop (the k_df feedback, the integrand-offset law and
//! the observer's radial input) reads that magnitude change as a flux error, c = s/κ of the
//! error it sees: [`ActiveFlux::frame_coupling`]. For constant inductances c = (Lq − Ld)·i_q/λa
//! and s/κ reduce to the same number; the saturated PM-SyRM of the pmsyrm-baldor-5k6 preset
//! reaches 0.81 at 65 % and 0.96 at its rated torque under MTPA (the IPMSM of the
//! ipmsm-2k2-qsat preset stays below 0.08). Above [`OFFSET_COUPLING_MAX`] the
//! integrand-offset law holds, and where s and ω have opposite signs (while the machine
//! generates where L_q,s exceeds L_dd) the observer runs at its speed without the
//! electrical-frequency ripple of a DC error (`crate::speed_notch`), which with this coupling
//! would make the DC loop grow (docs/method/saturation.md, "The slow mode").

use crate::magnetics::{
    ConstantInductance, FluxLookup, FluxWarmStart, InductanceMatrix, MachineMagnetics,
    MagneticModel,
};
use crate::{Ab, Dq, MachineModel, Real};

/// The R̂s laws freeze where κ < `KAPPA_MIN_RATIO`·λa: the angle feedback through the
/// secant's slope then more than doubles the q flux error of a resistance error (the
/// regressor's i_d term is ill-conditioned), ours \[A\].
pub const KAPPA_MIN_RATIO: f64 = 0.5;

/// The integrand-offset law holds ê, and stops re-centring, where the frame coupling
/// [`ActiveFlux::frame_coupling`] exceeds this: there the law integrates the frame error
/// that the flux magnitude carries; the observer's speed is notched there where s and ω̂ have
/// opposite signs (`crate::speed_notch`). Ours \[A\]: on the pmsyrm-baldor-5k6 presets
/// (coupling 0.6–0.96 under load) the closed loop then holds `reversal` where the law at
/// its default rate trips it; the machines whose coupling stays below it (0.08 on
/// ipmsm-2k2-qsat, 0.3 on a small 20-pole IPMSM) never reach it.
pub const OFFSET_COUPLING_MAX: f64 = 0.5;

/// [`ActiveFlux::holds_offset`] for constant inductances: with L_dd = Ld, L_qq = L_q,s = Lq
/// and no cross terms the frame coupling is s = (Lq − Ld)·i_q against κ = λa = λf + (Ld −
/// Lq)·i_d (module docs), so the integrand-offset law holds where |(Lq − Ld)·i_q| exceeds
/// [`OFFSET_COUPLING_MAX`]·λa, where λa ≤ 0 or on a NaN. `saliency` is L̂d − L̂q, `i_dq` the
/// current in the frame of λ̂r. A surface-magnet rotor (saliency 0) never holds; on the
/// salient presets the coupling at the rated MTPA point is 0.81 (ipmsm-gem-50k, Lq/Ld 3.2)
/// and 0.77 (pmsyrm-5k, Lq/Ld 4.3), 0.14 on the 2.2 kW IPMSM (ipmsm-2k2).
#[inline]
pub fn constant_inductance_holds_offset<T: Real>(lambda_f: T, saliency: T, i_dq: Dq<T>) -> bool {
    let kappa = lambda_f + saliency * i_dq.d;
    let s = saliency * i_dq.q;
    !(kappa > T::zero() && s.abs() <= T::lit(OFFSET_COUPLING_MAX) * kappa)
}

/// The observer's reference magnitude is at least this share of the low-passed active flux
/// ([`ActiveFlux::observer_reference`]): the swing the observer's input removes, λa(î) minus
/// the reference along the estimated axis, then turns the vector the observer follows by at
/// most about its own angle error (module docs, "The observer's reference"). Ours \[A\]:
/// 0.5 holds the weak-magnet PM-SyRM's generating replays (0.002–0.022 rad, against 0.3–0.6
/// rad at ψd(0, 0)), and the PM-SyRM preset's current-limited stop within 0.074 rad (0.103
/// with 0.7; `saturated_replay`).
pub const SWING_REFERENCE_SHARE: f64 = 0.5;

/// The time constant of the low-passed active flux the observer's reference follows, s.
/// Ours \[A\]: slow against the observer's settling at the reversal's speed, fast against the
/// load's changes; 0.05 s holds the weak-magnet PM-SyRM's rated-torque replay within
/// 0.022 rad (0.29 rad with 0.2 s) and the PM-SyRM preset's stop (0.142 rad with 0.02 s
/// tracking the whole active flux).
pub const SWING_REFERENCE_TIME: f64 = 0.05;

/// A saturating model as the estimator uses it, with the constants it falls back to. `M` is
/// how the model is named: the machine record's [`MachineMagnetics`] (any model, chosen at
/// run time), or a table's own type ([`ActiveFlux::with_model`], [`FluxLookup`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActiveFlux<T: 'static, M = MachineMagnetics<T>> {
    /// The model, borrowed (two words: the estimator's parameters stay small enough to be
    /// built in place in a freestanding image).
    model: M,
    /// What `model` stands for if it is `Linear` (never, as built; see [`ActiveFlux::new`]).
    linear: ConstantInductance<T>,
    /// The secant is the incremental ∂ψq/∂i_q below this |i_q| (A).
    small_current: T,
    /// ψd(0, 0), Wb.
    magnet_flux: T,
    /// The incremental L_qq at i = 0 (the secant's limit there), H.
    lq_zero: T,
}

/// The active flux at one operating point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ActiveFluxPoint<T> {
    /// The current in the estimated rotor frame (d along λ̂r), A.
    pub i_dq: Dq<T>,
    /// L_q,s(î), H.
    pub lq_secant: T,
    /// λa(î) = ψd − L_q,s·î_d, Wb.
    pub active: T,
}

impl<T: Real> ActiveFlux<T> {
    /// The estimator's view of `machine`'s magnetic model, if it saturates (see
    /// [`ActiveFlux::of`]).
    pub fn new(machine: &MachineModel<T>) -> Option<Self> {
        Self::of(machine).saturating().copied()
    }

    /// The estimator's view of `machine`'s magnetic model, held whatever the model (the
    /// parameters keep it without an `Option`, whose niche in a borrowed model made a
    /// freestanding image copy them with `memcpy`); [`ActiveFlux::saturating`] tells. The
    /// rated current scales the small-current threshold (10⁻³ of it).
    pub fn of(machine: &MachineModel<T>) -> Self {
        let model = machine.magnetic_model();
        Self {
            model: machine.magnetics,
            linear: machine.constant_inductance(),
            small_current: T::lit(1e-3) * machine.rated_current,
            magnet_flux: model.magnet_flux(),
            lq_zero: model.incremental_inductance(Dq::zero()).qq,
        }
    }

    /// The machine record's model.
    #[inline]
    pub fn model(&self) -> &MachineMagnetics<T> {
        &self.model
    }

    /// The same view with the model named by `model` (the same model as the record's,
    /// [`FluxLookup::is_model_of`]; the caller checks).
    #[inline(always)]
    pub fn with_model<N: FluxLookup<T>>(&self, model: N) -> ActiveFlux<T, N> {
        ActiveFlux {
            model,
            linear: self.linear,
            small_current: self.small_current,
            magnet_flux: self.magnet_flux,
            lq_zero: self.lq_zero,
        }
    }
}

impl<T: Real, M: FluxLookup<T>> ActiveFlux<T, M> {
    /// Itself for a saturating model; None for constant inductances (the blocks keep their
    /// closed-form arithmetic).
    #[inline]
    pub fn saturating(&self) -> Option<&Self> {
        self.is_saturating().then_some(self)
    }

    /// Whether the model saturates (false for constant inductances).
    #[inline]
    pub fn is_saturating(&self) -> bool {
        !self.model.is_linear()
    }

    /// Whether the model at the operating point is a map's extension beyond its data (more
    /// than the edge cell beyond its grid): there the model's slope is a guess, and the laws
    /// that read a model error as resistance or magnet flux freeze.
    #[inline]
    pub fn beyond_data(&self, point: &ActiveFluxPoint<T>) -> bool {
        self.model.beyond_data(point.i_dq)
    }

    /// ψ(i) of the model.
    #[inline]
    pub fn flux(&self, i: Dq<T>) -> Dq<T> {
        self.model.flux_at(self.linear, i)
    }

    /// The incremental inductance ∂ψ/∂i of the model at `i`.
    #[inline]
    pub fn incremental_inductance(&self, i: Dq<T>) -> InductanceMatrix<T> {
        self.model.inductance_at(self.linear, i)
    }

    /// ψd(0, 0), Wb.
    pub fn magnet_flux(&self) -> T {
        self.magnet_flux
    }

    /// The incremental L_qq at zero current, H (the start-up secant).
    pub fn lq_zero(&self) -> T {
        self.lq_zero
    }

    /// L_q,s = (ψq − ψq(i_d, 0))/i_q ([`MagneticModel::secant_q`]) and λa at the
    /// current `i_dq` of the rotor frame. A secant that is not a positive finite number is
    /// replaced by L_qq(0).
    #[inline]
    pub fn point(&self, i_dq: Dq<T>) -> ActiveFluxPoint<T> {
        self.point_at(i_dq, self.flux(i_dq))
    }
}

impl<T: Real> ActiveFlux<T> {
    /// [`ActiveFlux::point`] with the model's ψ(i_dq) solved from `psi_guess`, a flux near it
    /// in the same frame (the estimated stator flux there): one or two Newton steps where the
    /// model's ψ(i) is an inversion ([`MagneticModel::flux_from`]).
    #[inline]
    pub fn point_from(&self, i_dq: Dq<T>, psi_guess: Dq<T>) -> ActiveFluxPoint<T> {
        let psi = self.model.resolve(self.linear).flux_from(i_dq, psi_guess);
        self.point_at(i_dq, psi)
    }
}

impl<T: Real, M: FluxLookup<T>> ActiveFlux<T, M> {
    /// [`ActiveFlux::point_from`] with an iterative ψ(i) started from `warm`, the last
    /// solution in a frame near this one (`psi_guess` while it is empty), and the warm start
    /// holding this solution ([`Magnetics::flux_warm`](crate::magnetics::Magnetics::flux_warm)):
    /// the same point to the solver's tolerance in one or two Newton steps.
    #[inline]
    pub fn point_warm(
        &self,
        i_dq: Dq<T>,
        psi_guess: Dq<T>,
        warm: &FluxWarmStart<T>,
    ) -> (ActiveFluxPoint<T>, FluxWarmStart<T>) {
        let (psi, warm) = self.model.flux_warm(self.linear, i_dq, psi_guess, warm);
        (self.point_at(i_dq, psi), warm)
    }

    #[inline]
    fn point_at(&self, i_dq: Dq<T>, psi: Dq<T>) -> ActiveFluxPoint<T> {
        // ψq(î_d, 0) removed (zero unless a map is not odd in i_q): λ̂r then lies within
        // atan(ψq(î_d, 0)/λa) of d, where ψq/i_q would grow without bound near i_q = 0.
        let secant = if i_dq.q.abs() > self.small_current {
            (psi.q - self.model.q_flux_offset(self.linear, i_dq.d)) / i_dq.q
        } else {
            self.incremental_inductance(i_dq).qq
        };
        let lq_secant = if secant.is_finite() && secant > T::zero() {
            secant
        } else {
            self.lq_zero
        };
        ActiveFluxPoint {
            i_dq,
            lq_secant,
            active: psi.d - lq_secant * i_dq.d,
        }
    }
}

impl<T: Real> ActiveFlux<T> {
    /// The current `i_ab` (or any α-β vector) in the frame whose d axis is `axis` (any length;
    /// zero for a zero or non-finite axis).
    #[inline]
    pub fn frame_current(axis: Ab<T>, i_ab: Ab<T>) -> Dq<T> {
        let n = axis.norm_squared().step_sqrt();
        if n > T::zero() && n.is_finite() {
            let k = T::one() / n;
            Dq::new(axis.dot(i_ab) * k, axis.cross(i_ab) * k)
        } else {
            Dq::zero()
        }
    }
}

impl<T: Real, M: FluxLookup<T>> ActiveFlux<T, M> {
    /// λ̂r = λ2 − L_q,s(î)·i with î in the frame of λ2 − `lq_prev`·i (module docs), and the
    /// operating point it used.
    #[inline]
    pub fn rotor_flux(
        &self,
        lambda2: Ab<T>,
        i_ab: Ab<T>,
        lq_prev: T,
    ) -> (Ab<T>, ActiveFluxPoint<T>) {
        let (lambda_r, point, _) =
            self.rotor_flux_warm(lambda2, i_ab, lq_prev, &FluxWarmStart::empty());
        (lambda_r, point)
    }

    /// [`ActiveFlux::rotor_flux`] with the model's ψ(î) started from `warm`
    /// ([`ActiveFlux::point_warm`]), and the warm start holding this solution.
    #[inline]
    pub fn rotor_flux_warm(
        &self,
        lambda2: Ab<T>,
        i_ab: Ab<T>,
        lq_prev: T,
        warm: &FluxWarmStart<T>,
    ) -> (Ab<T>, ActiveFluxPoint<T>, FluxWarmStart<T>) {
        let axis = lambda2 - i_ab * lq_prev;
        let i_dq = ActiveFlux::<T>::frame_current(axis, i_ab);
        // λ2 in the same frame is the estimated ψ(î): the model's flux starts there without
        // a warm start.
        let (point, warm) =
            self.point_warm(i_dq, ActiveFlux::<T>::frame_current(axis, lambda2), warm);
        (lambda2 - i_ab * point.lq_secant, point, warm)
    }

    /// The bracket of the R̂s regressor φ = −(that)/ω (module docs) at the operating point,
    /// with the incremental inductances there; None where the law freezes
    /// ([`ActiveFlux::resistance_regressor_coupled`]).
    #[inline]
    pub fn resistance_regressor(&self, point: &ActiveFluxPoint<T>) -> Option<T> {
        self.resistance_regressor_coupled(point)
            .map(|(bracket, _)| bracket)
    }

    /// [`ActiveFlux::resistance_regressor`]'s bracket and the frame coupling |s|/κ there
    /// ([`ActiveFlux::frame_coupling`], from the same incremental inductances); None where
    /// κ < [`KAPPA_MIN_RATIO`]·λa, λa ≤ 0 or the bracket's turned part (its i_d term) is not
    /// smaller than its direct part i_q (the law freezes).
    #[inline]
    pub fn resistance_regressor_coupled(&self, point: &ActiveFluxPoint<T>) -> Option<(T, T)> {
        let (direct, turned, coupling) = self.resistance_regressor_parts(point)?;
        // Where the turned part reaches the resistance's own d-axis flux i_q (no load, the
        // current along d: cross-saturation alone), any angle error reads as resistance:
        // frozen.
        (turned.abs() < direct.abs()).then_some((direct + turned, coupling))
    }

    /// The R̂s regressor's bracket in its two parts, the direct i_q and the part the frame's
    /// turn carries through the map's slope (module docs), with the frame coupling |s|/κ;
    /// None where κ < [`KAPPA_MIN_RATIO`]·λa or λa ≤ 0.
    #[inline]
    pub fn resistance_regressor_parts(&self, point: &ActiveFluxPoint<T>) -> Option<(T, T, T)> {
        let i = point.i_dq;
        let l = self.incremental_inductance(i);
        let lqs = point.lq_secant;
        let kappa = point.active + l.qd * i.q - (l.qq - lqs) * i.d;
        let floor = T::lit(KAPPA_MIN_RATIO) * point.active;
        if !(point.active > T::zero() && kappa >= floor) {
            return None;
        }
        let turned = i.d * ((l.dd - lqs) * i.q - l.dq * i.d) / kappa;
        let s = (lqs - l.dd) * i.q + l.dq * i.d;
        Some((i.q, turned, s.abs() / kappa))
    }

    /// How far the map's two interpolants of the same nodes disagree on λa at the operating
    /// point (|λa of the C¹ one − λa of the bilinear one|, Wb): what the nodes leave open
    /// between them, zero on a node and for any model but a map read through its C¹
    /// interpolant.
    #[inline]
    pub fn interpolation_spread(&self, point: &ActiveFluxPoint<T>) -> T {
        match self.model.bilinear_flux(point.i_dq) {
            Some(psi) => (self.point_at(point.i_dq, psi).active - point.active).abs(),
            None => T::zero(),
        }
    }

    /// The frame coupling's (s, κ) at the operating point (module docs): while the current
    /// loop holds î, a frame error δ moves |λ̂r| by s·δ and leaves (κ/λa)·δ of it visible.
    #[inline]
    pub fn frame_coupling(&self, point: &ActiveFluxPoint<T>) -> (T, T) {
        let i = point.i_dq;
        let l = self.incremental_inductance(i);
        let lqs = point.lq_secant;
        let s = (lqs - l.dd) * i.q + l.dq * i.d;
        let kappa = point.active + l.qd * i.q - (l.qq - lqs) * i.d;
        (s, kappa)
    }

    /// The share of its configured rate at which the integrand-offset law learns at the
    /// operating point: 1 − (|s|/κ)/[`OFFSET_COUPLING_MAX`], down to 0 where the law holds
    /// ([`Self::holds_offset`]), so that the loop gain through the law falls continuously with
    /// the frame coupling into the hold; 0 where κ ≤ 0 or on a NaN. Why: the law integrates
    /// c = |s|/κ of a frame error back into the flux (module docs, "The frame coupling"); on
    /// the 2.2 kW IPMSM with five times its cross-saturation (c = 0.35 at rated i_q, below the
    /// hold) the full rate grows a 5 Hz oscillation under rated load at ±90 r/min
    /// (`rated-reversal` speed error 26.9 r/min, θ error ±0.17 rad; 8.6 r/min, 0.028 rad with
    /// the taper; docs/method/saturation.md, "The offset law's gate"). Machines of small
    /// coupling keep nearly all of it (ipmsm-2k2-qsat, below 0.08: at least 0.84).
    #[inline]
    pub fn offset_rate_share(&self, point: &ActiveFluxPoint<T>) -> T {
        let (s, kappa) = self.frame_coupling(point);
        let share = T::one() - s.abs() / kappa / T::lit(OFFSET_COUPLING_MAX);
        if kappa > T::zero() && share > T::zero() {
            share
        } else {
            T::zero()
        }
    }

    /// Whether the integrand-offset law holds at the operating point: |s|/κ above
    /// [`OFFSET_COUPLING_MAX`], κ ≤ 0 or not a number.
    #[inline]
    pub fn holds_offset(&self, point: &ActiveFluxPoint<T>) -> bool {
        let (s, kappa) = self.frame_coupling(point);
        !(kappa > T::zero() && s.abs() <= T::lit(OFFSET_COUPLING_MAX) * kappa)
    }

    /// The magnitude of the observer's rotating vector for a low-passed active flux
    /// `active_lp`: ψd(0, 0), or `SWING_REFERENCE_SHARE` of `active_lp` where that is more.
    #[inline]
    pub fn observer_reference(&self, active_lp: T) -> T {
        crate::real::max(self.magnet_flux, active_lp * T::lit(SWING_REFERENCE_SHARE))
    }

    /// The incremental L_dd at the operating point (the standstill law's inductive voltage).
    #[inline]
    pub fn ld_incremental(&self, i_dq: Dq<T>) -> T {
        self.incremental_inductance(i_dq).dd
    }
}

#[cfg(test)]
mod tests;
