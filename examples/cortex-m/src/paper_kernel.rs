//! The paper's fixed-R̂s estimator alone, hand-lean, in `f32`: a measured floor for the cost of
//! fado's step (docs/results/firmware-cost.md).
//!
//! Exactly the method fado's `EstimatorState::step_lean` runs on its paper's path
//! (`rs_adaptation`, `observer.lag_compensation`, `observer.on_rotor_flux` and
//! `limiter.recentring` all `false`, `disturbance_feedback.ramp_time` and `observer.gain_period` 0), with the
//! same discretisation and the same arithmetic in the same order, the trackers' conversions
//! between radians and fixed-point units folded into their gains (Ki·Ts·2π/2³², Ts·2³²/2π) as
//! fado's trackers fold them (unfolded, fado would multiply by the
//! unit at each conversion and the two differed at the `f32` rounding level, within 1e-6 rad).
//! The image checks, sample by sample, that the kernel's θ̂ stays within 1e-4 rad of fado's
//! and its mode equal (measured: the same θ̂ and ω̂ to the bit, docs/results/firmware-cost.md):
//!
//! - the flux integrator with the feedback of the previous sample (eq. (21) / (24)), the
//!   resistive drop on the interval's average current (docs/method/estimator.md, section 1);
//! - the disturbance observer (eq. (10), gains (16)) at ω̂ of T2S-1 with fado's discrete gains
//!   (`fado_core::observer::DiscreteGains::new`, the `f32` minimax polynomials);
//! - λ2 = λ1 − D̂ (eq. (20)), λ̂r = λ2 − L̂q·i (eq. (5)), θm = ∠λ̂r (eq. (6)) with fado's `f32`
//!   atan2 (`fado_core::approx::atan2`);
//! - T2S-1 and T2S-2 (Fig. 1) in fado's wrapping fixed point (2³² units = 2π);
//! - the mode of Fig. 3 from T2S-2's speed with the hysteresis band, the limiter of Fig. 6
//!   (eq. (24)-(25)) in the limiter mode and k_df·D̂ (eq. (21)) otherwise.
//!
//! Left out, because the paper does not have them: the plausibility bounds and the finite test
//! (a NaN or an absurd sample poisons this state for good), the lock detector and the slow
//! laws' slots, the tracker hold below 0.2·λ̂f, the active-flux terms of a salient rotor (the
//! paper's motor has Ld = Lq), the observer's lag compensation, the limiter re-centring, the
//! k_df ramp, R̂s and λ̂f adaptation. Constants and state are one record, read through one
//! pointer; the first sample's resistive drop uses its own current (as fado's does) by
//! [`PaperKernel::prime`] setting the remembered current to it.

use fado_core::approx::atan2;
use fado_core::observer::DiscreteGains;
use fado_core::{Ab, EstimatorConfig, Real};

/// Tracker angle units per radian, 2³²/2π (fado's `f32` `Real::Angle`, the same rounding).
const UNITS_PER_RAD: f32 = (4_294_967_296.0 / core::f64::consts::TAU) as f32;
/// Radians per tracker angle unit, 2π/2³².
const RAD_PER_UNIT: f32 = (core::f64::consts::TAU / 4_294_967_296.0) as f32;

/// 2π as fado's `Real` gives it (the mode band's constants are computed with it).
fn two_pi<T: Real>() -> T {
    T::two_pi()
}

/// `x` rounded half away from zero, as fado's `Real` rounds (the gains' period in samples).
fn round<T: Real>(x: T) -> T {
    x.round()
}

/// Constants and state of the paper's estimator: 28 `f32`/`i32` fields and the mode.
#[derive(Clone, Copy)]
pub struct PaperKernel {
    // Constants (from the configuration, computed as fado computes them).
    ts: f32,
    rs: f32,
    lq: f32,
    k_df: f32,
    k_af: f32,
    radius: f32,
    radius_sq: f32,
    /// |ω̂2| above which the k_df mode starts, below which the limiter mode does (rad/s).
    enter: f32,
    leave: f32,
    /// Ts·2³²/2π: θ̂⁻ − θ̂ in fixed-point units per rad/s of ω̂.
    ts_units: f32,
    /// Kp·Ts (units per unit of phase error) and Ki·Ts·2π/2³² (rad/s per unit) of T2S-1, T2S-2.
    kp_ts1: f32,
    ki_ts1: f32,
    kp_ts2: f32,
    ki_ts2: f32,
    // State.
    lambda1_a: f32,
    lambda1_b: f32,
    i_prev_a: f32,
    i_prev_b: f32,
    z_a: f32,
    z_b: f32,
    d_a: f32,
    d_b: f32,
    fb_a: f32,
    fb_b: f32,
    /// T2S-1: θ̂⁻ (fixed point) and ω̂.
    pred1: i32,
    omega1: f32,
    /// T2S-2: θ̂⁻ and ω̂.
    pred2: i32,
    omega2: f32,
    /// k_df mode (true) or limiter mode.
    kdf_mode: bool,
    // Held gains ([`paper_kernel_held_step`] only): a, ℓ1, ℓ2 of eq. (16) and the samples
    // they are still held for, as fado's `observer.gain_period` holds them.
    /// Samples the gains are held after the one that forms them (period/Ts − 1).
    gain_hold: u32,
    gain_countdown: u32,
    g_a: Ab<f32>,
    g_l1: Ab<f32>,
    g_l2: Ab<f32>,
}

/// θ̂ and ω̂ of T2S-1, ω̂ of T2S-2 and the mode after a step ([`PaperKernel::output`]).
#[derive(Clone, Copy)]
pub struct PaperOutput {
    pub theta: f32,
    pub omega: f32,
    pub omega_control: f32,
    pub limiter: bool,
}

impl PaperKernel {
    /// The start-up state of fado's estimator for `config` (θ̂ = 0, λ1 = λ̂f, D̂ = 0, limiter
    /// mode), with the constants computed from `config` as `EstimatorParams::new` computes
    /// them (the same `f32` operations).
    pub fn new(config: &EstimatorConfig<f32>) -> Self {
        let ts = config.ts;
        let m = &config.machine;
        let t = &config.tuning;
        let tracker = |bandwidth_hz| {
            let (kp, ki) = config.tracker_config(bandwidth_hz).gains();
            (ts * kp, ki * ts * RAD_PER_UNIT)
        };
        let (kp_ts1, ki_ts1) = tracker(t.tracker.t2s1_bandwidth_hz);
        let (kp_ts2, ki_ts2) = tracker(t.tracker.t2s2_bandwidth_hz);
        let (th, h) = (config.mode_threshold_hz(), config.mode_hysteresis_hz());
        let radius = t.limiter.radius_ratio * m.flux_linkage;
        // As `EstimatorParams::new` rounds `observer.gain_period` to samples.
        let periods = round(t.observer.gain_period / ts) - 1.0;
        let gain_hold = if periods > 0.0 { periods as u32 } else { 0 };
        let g = DiscreteGains::new(0.0, ts);
        Self {
            ts,
            rs: m.rs,
            lq: m.lq,
            k_df: t.disturbance_feedback.k_df,
            k_af: t.limiter.k_af,
            radius,
            radius_sq: radius * radius,
            enter: two_pi::<f32>() * (th + h),
            leave: two_pi::<f32>() * (th - h),
            kp_ts1,
            ki_ts1,
            ts_units: ts * UNITS_PER_RAD,
            kp_ts2,
            ki_ts2,
            lambda1_a: m.flux_linkage,
            lambda1_b: 0.0,
            i_prev_a: 0.0,
            i_prev_b: 0.0,
            z_a: m.flux_linkage,
            z_b: 0.0,
            d_a: 0.0,
            d_b: 0.0,
            fb_a: 0.0,
            fb_b: 0.0,
            pred1: 0,
            omega1: 0.0,
            pred2: 0,
            omega2: 0.0,
            kdf_mode: false,
            gain_hold,
            gain_countdown: gain_hold,
            g_a: g.a,
            g_l1: g.l1,
            g_l2: g.l2,
        }
    }

    /// Whether the configuration holds the observer's gains over several samples (then
    /// [`paper_kernel_held_step`] is the kernel of the same method).
    pub fn holds_gains(&self) -> bool {
        self.gain_hold > 0
    }

    /// Before the first sample: its resistive drop uses its own current `i_ab` alone.
    pub fn prime(&mut self, i_ab: Ab<f32>) {
        self.i_prev_a = i_ab.alpha;
        self.i_prev_b = i_ab.beta;
    }
}

/// a, ℓ1, ℓ2 of eq. (16), the gains the observer's update uses.
struct Gains {
    a: Ab<f32>,
    l1: Ab<f32>,
    l2: Ab<f32>,
}

/// The sample both kernels compute, with the observer's gains (16) `g` (a, ℓ1, ℓ2) given:
/// formed for this sample ([`paper_kernel_step`]) or held ([`paper_kernel_held_step`]).
#[inline(always)]
fn kernel_sample(k: &mut PaperKernel, v_ab: Ab<f32>, i_ab: Ab<f32>, g: &Gains) -> f32 {
    let (va, vb, ia, ib) = (v_ab.alpha, v_ab.beta, i_ab.alpha, i_ab.beta);
    // Flux integrator, eq. (21)/(24): λ1 += Ts·(v − R̂s·ī − feedback).
    let da = (ia + k.i_prev_a) * 0.5;
    let db = (ib + k.i_prev_b) * 0.5;
    let l1a = k.lambda1_a + (va - da * k.rs - k.fb_a) * k.ts;
    let l1b = k.lambda1_b + (vb - db * k.rs - k.fb_b) * k.ts;
    // Disturbance observer, eq. (10) with the gains (16) `g`.
    let (ea, eb) = (l1a - k.z_a, l1b - k.z_b);
    let (wa, wb) = (k.z_a - k.d_a, k.z_b - k.d_b);
    let za = k.d_a + (g.a.alpha * wa - g.a.beta * wb) + (g.l1.alpha * ea - g.l1.beta * eb);
    let zb = k.d_b + (g.a.alpha * wb + g.a.beta * wa) + (g.l1.alpha * eb + g.l1.beta * ea);
    let dna = k.d_a + (g.l2.alpha * ea - g.l2.beta * eb);
    let dnb = k.d_b + (g.l2.alpha * eb + g.l2.beta * ea);
    // λ2 = λ1 − D̂ (20), λ̂r = λ2 − L̂q·i (5), θm = ∠λ̂r (6).
    let ra = (l1a - dna) - ia * k.lq;
    let rb = (l1b - dnb) - ib * k.lq;
    let theta_m = (atan2(rb, ra) * UNITS_PER_RAD) as i32;
    // T2S-1 and T2S-2 (Fig. 1), fixed point: e = θm − θ̂⁻, ω̂ += Ki·Ts·e, θ̂ = θ̂⁻ + Kp·Ts·e,
    // θ̂⁻ = θ̂ + Ts·ω̂, e in units (the unit conversions are in the gains).
    let e1 = theta_m.wrapping_sub(k.pred1) as f32;
    let omega1 = k.omega1 + k.ki_ts1 * e1;
    let theta1 = k.pred1.wrapping_add((k.kp_ts1 * e1) as i32);
    let e2 = theta_m.wrapping_sub(k.pred2) as f32;
    let omega2 = k.omega2 + k.ki_ts2 * e2;
    let theta2 = k.pred2.wrapping_add((k.kp_ts2 * e2) as i32);
    k.pred1 = theta1.wrapping_add((k.ts_units * omega1) as i32);
    k.pred2 = theta2.wrapping_add((k.ts_units * omega2) as i32);
    k.omega1 = omega1;
    k.omega2 = omega2;
    // Mode (Fig. 3) with hysteresis, and the feedback for the next sample.
    let w = omega2.abs();
    // (`!(w < leave)`, not `w >= leave`: a NaN keeps the mode, as in fado.)
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    let kdf_mode = if k.kdf_mode {
        !(w < k.leave)
    } else {
        w > k.enter
    };
    k.kdf_mode = kdf_mode;
    if kdf_mode {
        // k_df·D̂ (21).
        k.fb_a = dna * k.k_df;
        k.fb_b = dnb * k.k_df;
    } else {
        // The limiter (24)-(25): k_af·(|λ̂r| − ρ)·λ̂r/|λ̂r| outside the circle.
        let n2 = ra * ra + rb * rb;
        if n2 > k.radius_sq {
            let n = fado_core::approx::sqrt(n2);
            let s = k.k_af * (n - k.radius) / n;
            k.fb_a = ra * s;
            k.fb_b = rb * s;
        } else {
            k.fb_a = 0.0;
            k.fb_b = 0.0;
        }
    }
    k.lambda1_a = l1a;
    k.lambda1_b = l1b;
    k.i_prev_a = ia;
    k.i_prev_b = ib;
    k.z_a = za;
    k.z_b = zb;
    k.d_a = dna;
    k.d_b = dnb;
    theta1 as f32 * RAD_PER_UNIT
}

/// One sample of the paper's estimator (Fig. 5): `v_ab` the voltage over the last interval,
/// `i_ab` the current now; returns θ̂ (rad, in [−π, π]).
#[inline(never)]
// Unmangled in the image, where the cost script finds it by name; the host build
// (`dev/src/bin/estimator-step-workload.rs`, `ESTIMATOR=paper-kernel`) has no such need.
#[cfg_attr(target_os = "none", unsafe(no_mangle))]
pub fn paper_kernel_step(k: &mut PaperKernel, v_ab: Ab<f32>, i_ab: Ab<f32>) -> f32 {
    let g = DiscreteGains::new(k.omega1, k.ts);
    kernel_sample(
        k,
        v_ab,
        i_ab,
        &Gains {
            a: g.a,
            l1: g.l1,
            l2: g.l2,
        },
    )
}

/// [`paper_kernel_step`] with the observer's gains (16) held over `observer.gain_period`, as
/// fado holds them by default (0.4 ms: formed once in four samples at 10 kHz, at the end of
/// the sample, from the new ω̂ of T2S-1): the floor of the method at fado's default gain
/// period (docs/results/firmware-cost.md).
#[inline(never)]
// Unmangled in the image, where the cost script finds it by name; the host build
// (`dev/src/bin/estimator-step-workload.rs`, `ESTIMATOR=paper-kernel`) has no such need.
#[cfg_attr(target_os = "none", unsafe(no_mangle))]
pub fn paper_kernel_held_step(k: &mut PaperKernel, v_ab: Ab<f32>, i_ab: Ab<f32>) -> f32 {
    let held = Gains {
        a: k.g_a,
        l1: k.g_l1,
        l2: k.g_l2,
    };
    let theta = kernel_sample(k, v_ab, i_ab, &held);
    // The gains for the next samples' speed, once every `gain_hold` + 1 samples.
    if k.gain_countdown == 0 {
        let g = DiscreteGains::new(k.omega1, k.ts);
        (k.g_a, k.g_l1, k.g_l2) = (g.a, g.l1, g.l2);
        k.gain_countdown = k.gain_hold;
    } else {
        k.gain_countdown -= 1;
    }
    theta
}

impl PaperKernel {
    /// The outputs of the last step, `theta` the θ̂ it returned (the step returns θ̂ alone;
    /// the speeds and the mode are state).
    pub fn output(&self, theta: f32) -> PaperOutput {
        PaperOutput {
            theta,
            omega: self.omega1,
            omega_control: self.omega2,
            limiter: !self.kdf_mode,
        }
    }
}
