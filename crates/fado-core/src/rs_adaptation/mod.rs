//! Online stator-resistance adaptation (beyond the paper): R̂s learned from the flux-magnitude
//! error while the machine turns, and from the d-axis voltage at standstill under the eq. (23)
//! injection.
//!
//! Why: the voltage model integrates v − R̂s·i, so a resistance error ΔR = Rs − R̂s adds ΔR·i
//! to the integrand. Turning, the error is synchronous with the rotor, ΔR·i/(jω): for a q-axis
//! current it lies along d, |λ̂r| − λf ≈ ΔR·i_q/ω, and the disturbance observer cannot remove
//! it (it is not constant in α-β). Below the k_df threshold the same error integrates along the
//! current, i.e. into the angle: a 5 % error loses the Fig. 11 reversal under 7.5 N·m. So R̂s is
//! learned where it is observable and carried through zero speed.
//!
//! **Rotating** (k_df mode): the classic flux-magnitude adaptation of voltage-model observers
//! (e.g. Holtz & Quan, IEEE Trans. Ind. Appl. 38(4), 2002), written as a normalised gradient
//! (Åström & Wittenmark, *Adaptive Control*, 2nd ed., §5.2):
//!
//! ```text
//!   λ̂a = λ̂f + (L̂d − L̂q)·î_d               (the active flux, the true |λ̂r| of eq. (5))
//!   φ  = −(î_q/ω̂)·(1 + (L̂d − L̂q)·î_d/λ̂a)  (∂e/∂R̂s, derived below)
//!   e  = |λ̂r| − λ̂a ≈ (R̂s − Rs)·φ
//!   χ  = φ·R0/λ̂f,  ẽ = e/λ̂f                (dimensionless; R0 = configured R̂s)
//!   dR̂s/dt = −γ·R0·ẽ·χ/(χ² + χ0²)   while |χ| ≥ χ0
//! ```
//!
//! **General rotor, i_d ≠ 0** (î_d, î_q: the current in the estimated frame, d along λ̂r).
//! The stator flux is e^{jθ}·(λf + Ld·i_d + j·Lq·i_q), so λ̂r = λ2 − L̂q·i of eq. (5) is
//! e^{jθ}·λa with the active flux λa = λf + (Ld − Lq)·i_d (Boldea, Paicu & Andreescu, IEEE
//! TPEL 23(5), 2008): on a salient rotor |λ̂r| is not λf, and a reference λ̂f would read
//! (Ld − Lq)·i_d (MTPA, field weakening, the eq. (23) injection) as a resistance error of
//! −(Ld − Lq)·i_d/φ — 9 % of Rs at −i_d = half the rated current on the 2.2 kW IPMSM of the
//! tests. So the reference is λ̂a. The regressor: turning at ω, the integrand error
//! −(R̂s − Rs)·i leaves the synchronous flux error −(R̂s − Rs)·i/(jω) (the observer removes
//! only its DC part), in the rotor frame (R̂s − Rs)·(−i_q + j·i_d)/ω: along d it changes
//! |λ̂r| by (R̂s − Rs)·(−i_q/ω); along q it turns λ̂r by ε = (R̂s − Rs)·i_d/(ω·λa), which
//! moves î_d = i_d·cos ε + i_q·sin ε, hence the reference, by (L̂d − L̂q)·i_q·ε. Together
//! ∂e/∂R̂s = −(i_q/ω)·(1 + (L̂d − L̂q)·i_d/λa) = φ above. For L̂d = L̂q both reduce to the
//! surface-magnet law (bit for bit: the branch that needs î_d is skipped). The estimator takes
//! L̂d from its machine model (`EstimatorConfig::machine`, `MachineModel::ld`).
//!
//! χ is the relative flux error a relative resistance error causes ("% of λf per % of Rs"):
//! 1.4 at −90 r/min under 7.5 N·m for the paper's motor, 0.07 at 60 r/min without load. With
//! e = (R̂s − Rs)·φ the law gives d(R̂s − Rs)/dt = −γ·χ²/(χ²+χ0²)·(R̂s − Rs): a first-order
//! decay at nearly γ wherever it runs, in both motoring and generating quadrants (φ follows the
//! sign of ω·i_q). It is valid while the adaptation is slow against the flux dynamics (γ ≪ |ω̂|:
//! 1 s⁻¹ against ≥ 8 rad/s in the k_df mode). Below χ0 it is frozen: there a flux-magnitude
//! error from any other cause (the hand-over transient, λ̂f or L̂q errors) would be read as a
//! large resistance error, e/χ.
//!
//! **The rate on a fast machine** (constant inductances). Below the k_df threshold a relative
//! R̂s error ε integrates into the angle at ε·Ω with the resistive speed Ω = R0·|i_q|/λ̂f of
//! the present current (the integrand error ε·R0·i lies along the current, across λ̂r): the
//! paper's motor has Ω = 81 rad/s at its rated current, a 12S multirotor outrunner (0.62 Ω,
//! 3.58 mWb, 10 A) 1,730 rad/s, where 0.05 % of R̂s turns θ̂ by 0.14 rad in a 300 ms loaded
//! stop. The turning law makes ε decay at γ, so an error it has not yet removed integrates
//! into ε·Ω/γ rad; the law runs at γ_Ω = Ω/[`RESISTIVE_SPEED_ANGLE`] where that exceeds the
//! configured γ, which bounds this angle at 120·ε (0.1 % → 0.12 rad) on every machine. With
//! the present current rather than the rated one, the law stays at γ without load (where an
//! R̂s error costs no angle and the hand-over transient is most of |λ̂r| − λ̂a: at 5 s⁻¹ the
//! outrunner's no-load start learned +0.6 % of Rs and lost the rotor when the load arrived).
//! The paper's motor and the presets up to the hub motor (117 rad/s at rated current) keep
//! γ.
//!
//! **The rate on a saturating model.** The saturating law waits out the hand-over's
//! transient (the λ̂f law's settling) and runs at the largest of three rates: γ; the
//! least-squares gain of the excitation it has seen, 1/(T_E + E) with E = Σ χ²/(χ² + χ0²)·Ts
//! its accumulated excitation time and T_E = [`SATURATED_PRIOR_TIME`] (0.2 s) the weight of
//! the configured R0 (the recursive least-squares gain of a prior worth T_E seconds of full
//! excitation; Åström & Wittenmark, §2.2), so that a start error the standstill test could
//! not remove is averaged out within the first second of loaded running; and the present
//! resistive speed R0·|bracket|/λ̂a over [`SATURATED_RESISTIVE_SPEED_ANGLE`] (40 rad), as the
//! linear path's floor but four times faster, the saturating law being past the hand-over's
//! transient, so that a machine whose resistance error costs much angle learns it in time.
//! With a `model_flux_uncertainty` or a `model_flux_growth` above 0 it keeps γ: the data
//! then carry the model's error, which the faster gains would take at once. Measured
//! (`saturated_rs_convergence`, `rated-reversal` started 0.7 and 1.4 times off, gain
//! calibration off): see docs/method/saturation.md, "The R̂s law's regressor". A blanket 3γ
//! also took the d-saturated SPM through, but lost a five-times cross-saturated IPMSM's
//! `rated-reversal` from the correct start (1.03 rad): an oscillation at the electrical
//! frequency after the passage, which grows slowly at γ, drove R̂s by −6 % there.
//!
//! **Sampled at ω̂·Ts.** λ̂r is formed at the sampling instant (λ2 − L̂q·i_n, eq. (5)); the
//! integrator's resistive drop uses the interval's current (i_n + i_{n−1})/2, which at a
//! steady ω is i_n·cos(x/2)·e^{−jx/2} with x = ω·Ts, half a sample behind i_n. It lies along
//! the interval's mean current i_n·e^{−jx/2}·sin(x/2)/(x/2), so λ1 is exact at
//! R̂s/Rs = tan(x/2)/(x/2) (1.004 at x = 0.22). The active flux's î_d is the current sampled
//! with λ̂r, i_n: the drop current would read î_d = i_d·cos²(x/2) + i_q·sin(x)/2, a reference
//! off by (L̂d − L̂q)·i_q·sin(x)/2, which the regressor −i_q/ω turns into
//! ΔR̂s = (L̂q − L̂d)·ω·sin(x)/2 ≈ (L̂q − L̂d)·ω²·Ts/2 whatever the load, in both quadrants:
//! +5.3 % of Rs on a 42-pole robot-joint servo (L̂q − L̂d = 0.25 mH, 1.13 Ω) at 1000 r/min and
//! Ts = 100 µs (x = 0.22), which its loaded zero-speed hold after the run-down integrates into
//! the angle. A saturating model's operating point is taken at i_n for the same reason. The
//! regressor keeps the drop current (an R̂s error enters the integrand as −ΔR̂s times it):
//! its direction sets the law's gain, not where the law settles, which is e = 0. Open loop,
//! ideal samples at x = 0.05–0.3 (`turning_rs_law_is_unbiased_at_high_omega_ts`): R̂s/Rs
//! within 2·10⁻⁵ of tan(x/2)/(x/2).
//!
//! **Standstill** (limiter mode, current along the flux, i.e. the eq. (23) injection at light
//! load): the DC test of drive commissioning, done online. At standstill v_d = Rs·i_d +
//! Ld·di_d/dt − ω·Lq·i_q, and the rotor flux induces nothing along d, so
//!
//! ```text
//!   R_dc = ∫(v_d + ω̂·L̂q·i_q − L̂d·di_d/dt) / ∫i_d    (both integrals forget at ω_m)
//!   dR̂s/dt = γ_s·(R_dc − R̂s)                         while ∫i_d·R0/λ̂f ≥ χ0 (configured λ̂f)
//! ```
//!
//! in the estimated frame (d along λ̂r), while |ω̂| is below a small speed (an angle error δ
//! leaks δ·ω·λf of back-EMF into v_d). It needs no flux estimate, so it also works while the
//! limiter clamps, and at start-up it corrects R̂s before the first rotation. The flux error
//! that the R̂s error integrated before it was corrected lies along d too (the current did):
//! if it shrank |λ̂r|, the estimator pulls |λ̂r| back up to λ̂a (a grown one is already
//! bounded by the Fig. 6 limiter's circle) — the inner side of the limiter, valid only under
//! these conditions. With a q-axis current (load at standstill) the flux error goes into the
//! angle and nothing measures it: frozen there.
//!
//! **Standstill angle** (same conditions as the DC test: limiter mode, |ω̂| below the
//! standstill speed, current along the estimated d axis). At standstill the fundamental model
//! does not observe the angle of a surface-magnet rotor (Koteich, Maloum, Duc & Sandou,
//! "Permanent magnet synchronous drives observability analysis for motion-sensorless
//! control", arXiv:1601.06130, 2016): any tangential integrand error (the 0.5 % gain error
//! of one current sensor times Rs·i is ≈ 3 mV at 4 A, 0.035 rad/s on the paper's motor)
//! walks λ̂r along its circle without bound. The eq. (23) injection's current response does
//! observe it: with no load the speed loop holds the torque at zero, so the stator current
//! settles along the rotor's d axis, and in the estimated frame i_q/i_d = −tan δ for an angle
//! error δ = θ − θ̂ (the torque balance that I-f start-up relies on, e.g. Wang, Lu &
//! Blaabjerg, IEEE TPEL 27(8), 2012). So λ̂r is turned towards the current:
//!
//! ```text
//!   x = i_q/i_d = tan(∠(i, λ̂r))
//!   dλ̂r/dt ∋ k_θ·|λ̂r|·x·(1 − 4x²)·j·λ̂r/|λ̂r|     (i.e. dθ̂/dt = k_θ·x·(1 − 4x²))
//! ```
//!
//! (times 1 − ω̂²/ω_s², ω_s the standstill speed) near δ = 0 a first-order decay of δ at k_θ
//! (`rs_adaptation.standstill_angle_rate`); the factors 1 − 4x² and 1 − ω̂²/ω_s² take the law continuously
//! to zero where the DC test's conditions i_d > 2|i_q| and |ω̂| ≤ ω_s end (no jump in dθ̂/dt
//! when the current or the speed crosses them). Under a light load i_L it
//! settles at δ = atan(i_L/i_d) instead (the torque balance then needs that angle): the law
//! assumes the eq. (23) regime, and stops where the DC test stops (i_d ≤ 2|i_q|, so at most
//! atan(½) of bias). Under load (no injection) nothing observes the angle: see
//! docs/method/additions.md for the loaded standstill.
//!
//! **Flux linkage** (k_df mode, |ω̂| above 3× the Fig. 3 threshold, past the hand-over
//! transient, and where the revolution's mean χ is below χ0/2: no load or high speed, where
//! R̂s explains little of the flux magnitude).
//! A λ̂f error biases the turning law by Δλf·ω/i_q (0.7 % of Rs per 1 % of λf at −90 r/min
//! under 7.5 N·m on the paper's motor), so λ̂f is learned where its own error dominates
//! |λ̂r| − λ̂a, each law where its parameter is observable. Two things bias that regressor
//! there and are not λ̂f's (measured on the paper's motor, fado-sim, no load, λ̂f right;
//! docs/method/additions.md):
//!
//! - the inverter's voltage error *across* the current. With the eq. (23) injection the
//!   no-load current lies along d, so the dead-time compensation's residual along the
//!   current only turns λ̂r, but its part across it, V⊥ on the q axis, shortens |λ̂r| by
//!   V⊥/ω: 4.6 mV (ideal sensors) to 7.4 mV (the 0.5 % gain mismatch of one sensor) at
//!   60–90 r/min, −0.2…−0.5 % of λf, and nothing in v* and i separates it from a λ̂f
//!   error at one speed (both are a constant back-EMF shortfall). Without dead time the
//!   bias is < 0.1 %, with an ideal plant 0.00 %: the observer, the limiter and the
//!   active-flux term add nothing in steady state;
//! - a DC error left in λ2 by the observer's transient (a voltage offset not yet learned by
//!   `crate::integrand_offset`: 0.1 V makes |λ̂r| swing by ±15 % at ω̂ for a few tenths of
//!   a second), which a per-sample law turns into a λ̂f error of ≈ γ_f·c/ω̂ at whatever phase
//!   it stops.
//!
//! So the law is
//!
//! ```text
//!   ē   = ∮(|λ̂r| − λ̂a)·|ω̂|dt / ∮|ω̂|dt          (the mean over one electrical revolution)
//!   λ̂f += min(γ_f·T_rev, 1)·ē                  while following (below)
//!   λ̂f += min(γ_f·T_rev, 1)·D(ē)               otherwise, D(ē) = ē − clamp(ē, −ε·λ̂f0, +ε·λ̂f0)
//! ```
//!
//! once per revolution (T_rev its duration; the sums restart whenever a condition fails),
//! if the revolution's mean χ (signed, ∮χ·dθ/∮dθ) is below χ0/2 in magnitude: tested per
//! sample, the current noise of a motor whose no-load current gives χ ≈ 0.1 (the hub motor
//! preset) crossed the bound every few samples and no revolution completed. The
//! angle-weighted mean removes the first harmonic of a DC error in λ2 exactly, also at a
//! changing speed. The dead zone D (the dead-zone modification of robust adaptive control:
//! Peterson & Narendra, "Bounded error adaptive control", IEEE TAC 27(6), 1982; Ioannou &
//! Sun, *Robust Adaptive Control*, 1996, §8.5.4) ignores what a bounded disturbance can
//! explain: ε = 1 % ([`FLUX_LINKAGE_DEAD_ZONE`]), twice the largest no-load bias measured.
//! Alone it would leave a large λ̂f error at ε (plus the bias), and fig11 tolerates about
//! +2 %; so a mean beyond 2ε starts *following*: λ̂f takes the whole mean until one is
//! within ε_off = 0.25 % ([`FLUX_LINKAGE_DEAD_ZONE_OFF`]; a relay with hysteresis on the
//! dead zone, ours \[A\]). A λ̂f error beyond 2ε is then learned down to the bias, one
//! between ε and 2ε (as likely a transient of a salient motor's active flux as a λ̂f error)
//! down to ε. Measured on the fig11 λ̂f × load envelope (docs/method/additions.md): 62 of 63
//! points pass, 60 with the plain dead zone, 23 without the law.
//!
//! Both laws are frozen while the trackers coast, on a mode change and on rejected samples;
//! the turning law (and the λ̂f law) also over a period that contains a sample whose voltage
//! the drive's modulator limited ([`crate::SensorlessEstimator::voltage_limited`]): on the hexagon the legs held at a rail
//! have no dead time while the drive reports the compensation as lost, and the pulses near
//! the rails are the inverter's least-modelled; the turning law read that as resistance,
//! −0.7 % of Rs over `fullrange`'s acceleration at the current limit into field weakening on
//! a 24-pole multirotor motor (1.53 mWb, 22.2 V), whose loaded standstill then turned θ̂ at
//! ΔR̂s·i/λ̂f ≈ 8 rad/s and lost the rotor (docs/range.md).
//! Voltage errors in phase with the current (the dead-time compensation residual, device drops)
//! look like resistance to both laws and are absorbed into R̂s, which is what the zero-speed
//! passage needs.

use crate::error::ConfigError;
use crate::mode;
use crate::real::all_finite;
use crate::{Ab, MachineModel, Real};

mod laws;

pub(crate) use laws::{ResistanceAdaptationParams, ResistanceScale};

/// Lower bound of the adapted λ̂f as a multiple of the configured one (NdFeB loses ≈ 0.1 %/K,
/// so the physical range is about ±15 %).
pub const FLUX_LINKAGE_MIN_RATIO: f64 = 0.85;
/// Upper bound of the adapted λ̂f as a multiple of the configured one: below the Fig. 6
/// limiter's 1.15, whose circle stays at the configured λ̂f, so that the standstill pull towards
/// λ̂f never pushes against the limiter.
pub const FLUX_LINKAGE_MAX_RATIO: f64 = 1.14;

/// The λ̂f law runs above this multiple of the Fig. 3 threshold speed (see
/// [`ResistanceAdaptationConfig::flux_linkage_min_speed`]).
pub const FLUX_LINKAGE_SPEED_THRESHOLDS: f64 = 3.0;

/// Dead zone ε of the λ̂f law as a multiple of the configured λ̂f: a revolution mean of
/// |λ̂r| − λ̂a within ±ε moves nothing (module docs). 1 % (ours \[A\]): twice the largest
/// no-load bias measured on the paper's motor with λ̂f right (−0.54 %, the dead-time
/// compensation's residual across the current, fig8's run-up); fig11 tolerates a λ̂f error
/// of about ±2 % (docs/method/additions.md).
pub const FLUX_LINKAGE_DEAD_ZONE: f64 = 0.01;

/// Once a revolution mean has left the dead zone, the λ̂f law follows the whole mean until one
/// is within this multiple of the configured λ̂f (module docs). 0.25 % (ours \[A\]).
pub const FLUX_LINKAGE_DEAD_ZONE_OFF: f64 = 0.0025;

/// Default γ in s⁻¹ ([`ResistanceAdaptationConfig::rate`]): 1 (ours \[A\], see the field).
pub const DEFAULT_RATE: f64 = 1.0;

/// The turning law on a machine with constant inductances runs at least at the present
/// resistive speed R0·|î_q|/λ̂f (rad/s) divided by this many radians: 120 (module docs, "The
/// rate on a fast machine"; ours \[A\]). A relative R̂s error ε then integrates into at most
/// 120·ε rad of angle while it decays (0.1 % into 0.12 rad).
pub const RESISTIVE_SPEED_ANGLE: f64 = 120.0;
/// The weight of the configured R0 in the saturating turning law's least-squares rate, in
/// seconds of full excitation: 0.2 s (module docs, "The rate on a saturating model"; ours
/// \[A\]). The law starts at 1/(0.2 s) = 5 s⁻¹ and falls to the default γ after 0.8 s of
/// full excitation. 0.05 s (20 s⁻¹ at first) doubled the saturated presets' largest `stops`
/// error from the correct start (ipmsm-2k2-qsat 0.052 → 0.080 rad, pmsm-gem-1k1-measured
/// 0.047 → 0.097): the first loaded moments' transient then weighs as much as R0.
pub const SATURATED_PRIOR_TIME: f64 = 0.2;

/// A saturating model's turning law runs at least at the present resistive speed
/// R0·|bracket|/λ̂a (rad/s; the bracket of `crate::active_flux`'s regressor) divided by this
/// many radians: 40 (module docs, "The rate on a saturating model"; ours \[A\]), so that a
/// relative R̂s error ε integrates into at most 40·ε rad of angle while it decays. Machines at
/// or below 40 rad/s at their current keep γ there (ipmsm-2k2-qsat: 40 rad/s at its rated
/// 6.08 A); the d-saturated SPM test machine (94 rad/s at its rated 6 A) runs at 2.3 s⁻¹.
pub const SATURATED_RESISTIVE_SPEED_ANGLE: f64 = 40.0;

/// Default χ0 ([`ResistanceAdaptationConfig::excitation_floor`]): 0.2 (ours \[A\]).
pub const DEFAULT_EXCITATION_FLOOR: f64 = 0.2;
/// Default lower bound of R̂s as a multiple of R0 ([`ResistanceAdaptationConfig::min_ratio`]):
/// 0.5 (ours \[A\]).
pub const DEFAULT_MIN_RATIO: f64 = 0.5;
/// Default upper bound of R̂s as a multiple of R0 ([`ResistanceAdaptationConfig::max_ratio`]):
/// 2 (ours \[A\]).
pub const DEFAULT_MAX_RATIO: f64 = 2.0;
/// Default γ_f in s⁻¹ ([`ResistanceAdaptationConfig::flux_linkage_rate`]): 5 (ours \[A\]).
pub const DEFAULT_FLUX_LINKAGE_RATE: f64 = 5.0;
/// Default k_θ in s⁻¹ ([`ResistanceAdaptationConfig::standstill_angle_rate`]): 2 (ours \[A\]).
pub const DEFAULT_STANDSTILL_ANGLE_RATE: f64 = 2.0;

/// Configuration of [`ResistanceAdaptation`].
///
/// No `Default`: R0, λ̂f, L̂d and L̂q are the motor's. Build it with
/// [`for_machine`](Self::for_machine) (or [`new`](Self::new)); the
/// "Default" of each field below is what those constructors give.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResistanceAdaptationConfig<T> {
    /// Period of the law in s: the sampling period Ts if it runs every sample, N·Ts in the
    /// estimator, which runs it once every N samples (see `SensorlessEstimator`'s slow
    /// laws). No default: the caller's sampling period.
    pub ts: T,
    /// Initial (configured) R̂s = R0 in Ω, the start value and the scale of the law. From the
    /// machine model ([`MachineModel::rs`]; the paper's motor: 0.327 Ω, paper V).
    pub rs_initial: T,
    /// λ̂f in Wb: the start value of the flux-magnitude reference. From the machine model
    /// ([`MachineModel::flux_linkage`]; the paper's motor: 0.088 Wb, docs/method/estimator.md, "The paper's motor and drive" \[A\]).
    pub flux_linkage_hat: T,
    /// γ_f in s⁻¹: rate at which the flux-magnitude reference λ̂f follows the revolution
    /// mean of |λ̂r| − λ̂a (beyond its dead zone) while turning without resistance excitation
    /// (the revolution's mean |χ| < χ0/2: no load, or high speed); λ̂f moves once per
    /// electrical revolution by min(γ_f·T_rev, 1) of it (module docs). 0 = fixed λ̂f (bounds
    /// [`FLUX_LINKAGE_MIN_RATIO`]–[`FLUX_LINKAGE_MAX_RATIO`]·λ̂f). Default 5 s⁻¹ (ours \[A\]:
    /// 0.83 of the error per revolution at the 6 Hz of the paper's ±90 r/min, so that the
    /// ≈ 0.25 s at no load above the gate speed before fig11's load learns a 10 % error;
    /// measured there with λ̂f −10 % / +10 % / −5 % and R̂s +10 %: 2 s⁻¹ 0.94 / 0.46 / 0.13
    /// rad (two fail), 5 s⁻¹ 0.028 / 0.152 / 0.087, 10 s⁻¹ (deadbeat at 6 Hz) 0.033 / 0.151 /
    /// 0.094; docs/method/additions.md).
    pub flux_linkage_rate: T,
    /// γ in s⁻¹: decay rate of the relative R̂s error under full excitation while turning.
    /// Default 1 s⁻¹ (ours \[A\]: the winding heats over minutes, so the law can be slow; at
    /// 5 s⁻¹ the hand-over's magnitude ripple at the 2–4 Hz electrical frequency moved R̂s by
    /// ≈ 1.5 %, enough to lose the Fig. 12 stops, at 1 s⁻¹ by ≈ 0.3 %). The fast correction
    /// at start-up is the standstill law's. With constant inductances the law runs at least
    /// at the present resistive speed R0·|î_q|/λ̂f over [`RESISTIVE_SPEED_ANGLE`] (module
    /// docs, "The rate on a fast machine"); with a saturating model at the least-squares rate
    /// of the excitation seen so far or at its resistive speed over
    /// [`SATURATED_RESISTIVE_SPEED_ANGLE`] where either exceeds this rate (module docs, "The
    /// rate on a saturating model"). 0 turns the turning law off.
    pub rate: T,
    /// χ0: the excitation (relative flux error per relative resistance error) below which the
    /// turning law is frozen, and the scale of its normalisation χ/(χ² + χ0²); the standstill
    /// law waits until ∫i_d·R0/λ̂f (configured λ̂f) reaches it. Default 0.2 (ours \[A\]: a 1 % R̂s error then
    /// moves |λ̂r| by 0.2 %, the size of the estimator's ripple).
    pub excitation_floor: T,
    /// L̂q in H, for the d-axis voltage at standstill (the ω̂·L̂q·i_q term). From the machine
    /// model ([`MachineModel::lq`]; the paper's motor: 2.63 mH, paper V).
    pub lq_hat: T,
    /// L̂d in H: the active flux λ̂f + (L̂d − L̂q)·i_d is the flux-magnitude reference of both
    /// laws, and L̂d·di_d/dt the inductive d-axis voltage at standstill. From the machine model
    /// ([`MachineModel::ld`]; the paper's motor: 2.63 mH, paper V, = L̂q for its surface-magnet
    /// rotor).
    pub ld_hat: T,
    /// γ_s in s⁻¹: rate at which R̂s follows the standstill estimate R_dc. Default 20 s⁻¹ (ours
    /// \[A\]: settles within the 0.1 s of injection before the paper's profiles start to turn).
    pub standstill_rate: T,
    /// ω_m/2π in Hz: forgetting of the standstill integrals. Default 0.5 Hz (ours \[A\]: a
    /// memory of ≈ 0.3 s, long against the current noise, short against heating).
    pub standstill_memory_hz: T,
    /// The standstill law runs only below this |f̂| in Hz electrical. Default 0.25 Hz (ours
    /// \[A\]: with an angle error δ the back-EMF leaks δ·ω·λf into v_d; at 0.1 rad, 4 A and
    /// 0.25 Hz that reads as 1 % of R0).
    pub standstill_speed_hz: T,
    /// k_m in s⁻¹: while the standstill law runs, the estimator also pulls a shrunken |λ̂r|
    /// back up to λ̂f at this rate, removing the radial flux error that the R̂s error
    /// integrated before it was corrected. Default 2π·5 s⁻¹ (ours \[A\]: 32 ms, within the
    /// start-up injection).
    pub standstill_flux_rate: T,
    /// The λ̂f law runs only above this |ω̂|, rad/s: below it the voltage errors' share of
    /// |λ̂r| − λ̂f (the dead-time residual and the other voltage errors over ω) is not small
    /// against a λ̂f error. Default [`FLUX_LINKAGE_SPEED_THRESHOLDS`] (3) times the Fig. 3
    /// threshold speed 2π·`mode.threshold_ratio`·f_rated (ours \[A\]; 2π·4.5 Hz on the
    /// paper's motor).
    pub flux_linkage_min_speed: T,
    /// k_θ in s⁻¹: while the standstill DC test runs, the estimator also turns λ̂r towards
    /// the stator current at this rate (see the module docs: with the eq. (23) injection and
    /// no load, the speed loop holds the torque at zero, so the current lies along the rotor's
    /// d axis). 0 = off. Default 2 s⁻¹ (ours \[A\]: a 0.5 s time constant, a tenth of the
    /// 5 Hz speed loop's 31 rad/s, so that the loop re-balances the torque as θ̂ turns).
    pub standstill_angle_rate: T,
    /// How far the magnetic model's flux may be from the machine's, as a share of λ̂f
    /// (`flux_linkage_hat`): the turning law on a saturating model freezes where this flux,
    /// with the map's interpolation spread, times 1 + the frame coupling, exceeds the flux error
    /// of a 2 % resistance error at the operating point (docs/method/saturation.md, "The R̂s
    /// law's regressor"). 0 for the machine's own model (a measured map, an algebraic model of
    /// the machine). Default 0; `fado-sim commission` writes its identified model's figure
    /// (`fado_core::commissioning::Identification::model_flux_uncertainty`). The figure at
    /// zero current: the law takes `model_flux_uncertainty` + `model_flux_growth`·|î|² at the
    /// present current î.
    pub model_flux_uncertainty: T,
    /// How much the model's flux uncertainty grows with the current, as a share of λ̂f per A²:
    /// at the current î the law takes the model's flux to be off the machine's by
    /// (`model_flux_uncertainty` + `model_flux_growth`·|î|²)·λ̂f (a saturating model's error
    /// grows with the current, docs/method/saturation.md, "The offset law's gate"). Default 0;
    /// the estimator sets it from `[estimator.rs_adaptation] model_flux_uncertainty_rated`
    /// over the rated current squared.
    pub model_flux_growth: T,
    /// Lower bound of R̂s as a multiple of R0. Default 0.5 (ours \[A\]).
    pub min_ratio: T,
    /// Upper bound of R̂s as a multiple of R0. Default 2 (ours \[A\]: copper from −40 °C to
    /// 200 °C spans 0.7–1.7).
    pub max_ratio: T,
}

impl<T: Real> ResistanceAdaptationConfig<T> {
    /// The laws around `machine` with the default rates and bounds (the `DEFAULT_*` constants
    /// of this module) and the default Fig. 3 threshold ([`mode::DEFAULT_THRESHOLD_RATIO`]),
    /// run with period `ts` (the sampling period if the law runs every sample; the estimator
    /// runs it every `SLOW_PERIOD` samples). Same as
    /// [`new`](Self::new)`(machine, DEFAULT_THRESHOLD_RATIO, ts)`.
    pub fn for_machine(machine: &MachineModel<T>, ts: T) -> Self {
        Self::new(machine, T::lit(mode::DEFAULT_THRESHOLD_RATIO), ts)
    }

    /// The laws around `machine` for the Fig. 3 threshold `threshold_ratio`·f_rated, run with
    /// period `ts`, with the default rates and bounds. Where each value comes from:
    /// - `rs_initial`, `flux_linkage_hat`, `lq_hat`, `ld_hat`: the machine model (R̂s, λ̂f,
    ///   L̂q, L̂d).
    /// - `rate`, `excitation_floor`, `min_ratio`, `max_ratio`, `flux_linkage_rate`,
    ///   `rs_adaptation.standstill_angle_rate`: [`DEFAULT_RATE`], [`DEFAULT_EXCITATION_FLOOR`],
    ///   [`DEFAULT_MIN_RATIO`], [`DEFAULT_MAX_RATIO`], [`DEFAULT_FLUX_LINKAGE_RATE`] and
    ///   [`DEFAULT_STANDSTILL_ANGLE_RATE`] (their reasons in the fields' docs here).
    /// - `flux_linkage_min_speed`: three times the Fig. 3 threshold speed,
    ///   3·2π·`threshold_ratio`·f_rated (ours \[A\], see the field).
    /// - `standstill_rate` 20 s⁻¹, `standstill_memory_hz` 0.5 Hz, `standstill_speed_hz`
    ///   0.25 Hz, `standstill_flux_rate` 2π·5 s⁻¹: fixed rates and durations of the standstill
    ///   law (ours \[A\], see the fields), the same for every motor.
    pub fn new(machine: &MachineModel<T>, threshold_ratio: T, ts: T) -> Self {
        let threshold_hz = threshold_ratio * machine.rated_frequency_hz();
        Self {
            ts,
            rs_initial: machine.rs,
            flux_linkage_hat: machine.flux_linkage,
            flux_linkage_rate: T::lit(DEFAULT_FLUX_LINKAGE_RATE),
            rate: T::lit(DEFAULT_RATE),
            excitation_floor: T::lit(DEFAULT_EXCITATION_FLOOR),
            lq_hat: machine.lq,
            ld_hat: machine.ld,
            standstill_rate: T::lit(20.0),
            standstill_memory_hz: T::lit(0.5),
            standstill_speed_hz: T::lit(0.25),
            standstill_flux_rate: T::lit(2.0 * core::f64::consts::PI * 5.0),
            standstill_angle_rate: T::lit(DEFAULT_STANDSTILL_ANGLE_RATE),
            flux_linkage_min_speed: T::lit(FLUX_LINKAGE_SPEED_THRESHOLDS)
                * T::two_pi()
                * threshold_hz,
            model_flux_uncertainty: T::zero(),
            model_flux_growth: T::zero(),
            min_ratio: T::lit(DEFAULT_MIN_RATIO),
            max_ratio: T::lit(DEFAULT_MAX_RATIO),
        }
    }
}

/// Which law applies this sample (chosen by the estimator from its mode).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AdaptationRegime {
    /// No adaptation; the standstill integrals restart (trackers coasting, a mode change).
    Frozen,
    /// k_df mode: the flux-magnitude law.
    Rotating,
    /// Limiter mode: the standstill d-axis law (it freezes itself unless the current lies
    /// along the flux).
    Standstill,
}

/// State of the adaptation after one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ResistanceAdaptationState<T> {
    /// R̂s in Ω.
    pub rs_hat: T,
    /// λ̂f, the flux-magnitude reference, in Wb.
    pub flux_linkage_hat: T,
    /// Standstill: forgetting integral of i_d, A·s.
    pub charge_d: T,
    /// Standstill: forgetting integral of v_d + ω̂·L̂q·i_q − L̂d·di_d/dt, V·s.
    pub volt_seconds_d: T,
    /// Standstill: i_d sampled at the end of the last period, A (for L̂d·Δi_d); 0 = none
    /// yet (a test starts by recording it).
    pub i_d_prev: T,
    /// ∂R̂s/∂ê in 1/A: how much of R̂s still comes from standstill DC tests, each of which
    /// read a voltage offset ê along its d axis as ⟨ê, d̂⟩/i_d of resistance. Built by the
    /// standstill law (unit/i_d at its rate), forgotten at the turning law's rate; when the
    /// integrand-offset estimate ê moves by Δê, R̂s moves by −⟨Δê, ∂R̂s/∂ê⟩.
    pub offset_sensitivity: Ab<T>,
    /// R̂s − (R̂s without the standstill tests), Ω: what the tests still contribute to R̂s.
    /// Built with R̂s by the standstill law, forgotten with ∂R̂s/∂ê; it bounds what a change
    /// of ê takes back (`rs_after_offset_change`): no more than the tests put in.
    pub standstill_share: T,
    /// λ̂f law: ∫(|λ̂r| − λ̂a)·|ω̂|dt over the revolution under way, Wb·rad.
    pub flux_error_angle: T,
    /// λ̂f law: Σ a·sgn(ω̂)·Ts ≈ λ̂f·∫|χ|dθ over the revolution under way (module docs), Wb·rad.
    pub flux_excitation: T,
    /// λ̂f law: ∫|ω̂|dt, the angle of the revolution under way, rad.
    pub flux_angle: T,
    /// λ̂f law: the time of the revolution under way, s.
    pub flux_time: T,
    /// The turning law's accumulated excitation time E = Σ χ²/(χ² + χ0²)·Ts, s: a saturating
    /// model's law runs at the least-squares rate 1/([`SATURATED_PRIOR_TIME`] + E) while
    /// that exceeds γ.
    pub excitation_time: T,
    /// λ̂f law: a revolution mean left the dead zone and has not yet come within
    /// [`FLUX_LINKAGE_DEAD_ZONE_OFF`] of λ̂f.
    pub flux_learning: bool,
}

impl<T: Real> ResistanceAdaptationState<T> {
    /// True when every field is finite.
    #[inline]
    pub fn is_finite(&self) -> bool {
        all_finite([
            self.rs_hat,
            self.flux_linkage_hat,
            self.charge_d,
            self.volt_seconds_d,
            self.i_d_prev,
            self.offset_sensitivity.alpha,
            self.offset_sensitivity.beta,
            self.standstill_share,
            self.flux_error_angle,
            self.flux_excitation,
            self.flux_angle,
            self.flux_time,
            self.excitation_time,
        ])
    }
}

/// The two laws of the module docs: their constants, their R0 scaling and their state
/// together. `step` advances them; the estimator uses the parameters' `next_state` on its own
/// state so that a rejected sample changes nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResistanceAdaptation<T: 'static> {
    params: ResistanceAdaptationParams<T>,
    scale: ResistanceScale<T>,
    state: ResistanceAdaptationState<T>,
}

impl<T: Real> ResistanceAdaptation<T> {
    /// Checks every field (the error names it) and starts at R̂s = R0.
    pub fn new(config: ResistanceAdaptationConfig<T>) -> Result<Self, ConfigError> {
        let params = ResistanceAdaptationParams::new(config)?;
        let scale = params.scale(config.rs_initial);
        Ok(Self {
            params,
            scale,
            state: params.initial_state(&scale),
        })
    }

    /// R̂s back to R0, the standstill integrals to zero.
    pub fn reset(&mut self) {
        self.state = self.params.initial_state(&self.scale);
    }

    /// One sample: `v_ab` and `i_drop` the voltage and current the integrator used this sample,
    /// `lambda_r` the rotor flux it produced, `omega` the estimated speed (rad/s), `regime`
    /// which law applies. Returns R̂s for the next sample. Non-finite inputs change nothing.
    pub fn step(
        &mut self,
        v_ab: Ab<T>,
        i_drop: Ab<T>,
        lambda_r: Ab<T>,
        omega: T,
        regime: AdaptationRegime,
    ) -> T {
        let inputs_finite =
            v_ab.is_finite() && i_drop.is_finite() && lambda_r.is_finite() && omega.is_finite();
        if !inputs_finite {
            return self.state.rs_hat;
        }
        let (next, _) = self
            .params
            .next_state::<crate::magnetics::MachineMagnetics<T>, false>(
                &self.scale,
                &self.state,
                v_ab,
                i_drop,
                i_drop,
                i_drop,
                lambda_r,
                omega,
                regime,
                true,
                None,
            );
        if next.is_finite() {
            self.state = next;
        }
        self.state.rs_hat
    }

    /// R̂s now, Ω.
    #[inline]
    pub fn rs_hat(&self) -> T {
        self.state.rs_hat
    }

    /// λ̂f, the flux-magnitude reference, now, Wb.
    #[inline]
    pub fn flux_linkage_hat(&self) -> T {
        self.state.flux_linkage_hat
    }

    /// The state now.
    pub fn state(&self) -> &ResistanceAdaptationState<T> {
        &self.state
    }

    /// The configuration in use.
    pub fn config(&self) -> &ResistanceAdaptationConfig<T> {
        self.params.config()
    }
}

#[cfg(test)]
mod tests;
