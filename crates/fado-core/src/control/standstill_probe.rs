//! The loaded-standstill angle probe: a slow square-wave d current read through the speed
//! loop's torque balance, demodulated into the angle error, and fed back to the estimator as
//! a slow turn of θ̂.
//!
//! **Why.** At a loaded standstill the speed loop holds ω̂ ≈ 0, so the estimator's q-axis
//! integrand is zero and a tangential integrand error ε_q (an R̂s error of 0.01 %, an inverter
//! residual) makes the *rotor* creep unseen at ω = −ε_q/λf; the speed loop answers with
//! i_q = i_L/cos δ and the angle either stops at 0.6–0.7 rad or runs to the current limit
//! (docs/method/additions.md). The fundamental voltage model cannot observe δ
//! there; the torque balance can, under a probe.
//!
//! **Torque balance.** With δ = θ − θ̂ (the reported angle error), the currents in the
//! estimated frame (i_d̂, i_q̂) are, in the rotor's frame, i_d = i_d̂·cos δ + i_q̂·sin δ and
//! i_q = i_q̂·cos δ − i_d̂·sin δ. The speed loop holds the torque
//! 1.5·p·(λf + (Ld − Lq)·i_d)·i_q at the load. The drive turns its torque demand τ (the speed
//! PI's output, in units of the magnet's q current) into currents with its own model in the
//! estimated frame (`currents_for_torque`: λ̂a(i_d̂)·i_q̂ = λ̂f·τ), so a step Δi_d added to i_d̂
//! changes the model's torque by nothing, and the speed loop's τ moves only by what the model
//! gets wrong about the angle. Small-signal, at the operating point (i_d̂, i_q̂) with
//! λa = λf + ΔL·i_d̂, ΔL = Ld − Lq, b = ΔL·i_q̂ and tan φ = b/λa:
//!
//! λ̂f·Δτ/Δi_d = b + λa·tan(δ − φ),
//!
//! zero at δ = 0 on any rotor, λa·δ/cos²φ to first order; on a surface-magnet rotor (b = 0)
//! Δτ/Δi_d = tan δ exactly. So δ̂ = φ + atan(λ̂f·Δτ/(λ̂a·Δi_d) − tan φ) reads the angle's sign
//! and scale on a salient rotor too (the reluctance term only shifts the reading by the known
//! b, which the model's own feed-forward already removed).
//!
//! **Demodulation** (synchronous detection, Ariyur & Krstić, *Real-Time Optimization by
//! Extremum-Seeking Control*, Wiley 2003, ch. 1–2: a periodic probe, correlation with the
//! probe over whole periods): Δi_d = +A over the first half of each period, −A over the
//! second, each level reached by a ramp over the first quarter of its half (a trapezoid: a
//! step kicks the rotor through the speed loop); the torque balance is correlated with the
//! sign over the second half of each half-period (a constant load and a slow ramp of τ cancel
//! over the period), so that Δτ = mean(τ_b·s) and δ̂ follows at the end of each period.
//!
//! **Torque balance without a settled speed loop.** The speed loop's τ equals the load and
//! the probe's torque error only once the rotor has stopped accelerating; before that τ also
//! carries the rotor's acceleration. The reading removes it: τ_b = τ − c_J·dω̂/dt with
//! c_J = Ĵ/(1.5·p²·λ̂f), the torque demand per rad/s² of electrical acceleration, summed over
//! a window as c_J·(ω̂_end − ω̂_before)/Ts. The window then needs only a settled current loop
//! and speed estimate (the 35 Hz tracker's 4.5 ms time constant), not the 5 Hz speed loop's
//! 0.16 s zero: the default period is 0.1 s instead of 0.5 s, a window of 25 ms. On a
//! heavy salient rotor the speed estimate's own answer to the probe's d step outweighs the
//! rotor's acceleration in that term, and the drive lengthens the period
//! ([`crate::control::probe_period`]: 0.131 s on a drawn 140 kW IPMSM of 23.3 kg·m², whose
//! reading at 0.1 s is −3 × δ and loses the rotor, 0.64 rad in `fullrange`).
//!
//! **Amplitude** ([`amplitude`]). The probe's torque through the angle error, A·sin δ, turns a
//! light rotor: each period's amplitude is the one that would have held the last period's
//! largest |ω̂| at half the limiter band's edge, up to the configured A and grown by at most
//! 1/[`TRIPLE_POLE`] per period; the first period uses the configured A. A rotor whose speed
//! does not answer the probe beyond that bound keeps the configured A throughout.
//!
//! **Correction.** The estimator turns θ̂ at the rate g·δ̂ + ĉ (rad/s, held over the next
//! period), by that rate·Ts per sample through
//! [`crate::estimator::SensorlessEstimator::turn_angle`] (the mechanism of the no-load
//! standstill angle law of `crate::rs_adaptation`, of which this is the loaded counterpart);
//! ĉ learns the creep, ĉ ← ĉ + h·δ̂ per period. Per period, with the error x_k after period k,
//! the reading r_k = (x_(k−1) + x_k)/2 (the windows lie across the period) and the turn
//! g·r_k + ĉ_k held over the next period, the error obeys
//! 2z³ + (G + H − 4)·z² + (2 + H)·z − G = 0 with G = g·T_p and H = h·T_p. A triple pole p0
//! needs G = 2·p0³, H = 6·p0² − 2 and (p0 + 1)³ = 4: p0 = 0.587, G = 0.405, H = 0.070
//! ([`TRIPLE_POLE`], [`TRIPLE_POLE_GAIN`], [`CREEP_GAIN_RATIO`] = H/G). The error of a
//! step of creep decays by 0.587 per period, and a constant creep c leaves none (a
//! proportional turn leaves c/g). δ̂ is bounded at ±0.5 rad (the first-order reading's
//! range) and ĉ at ±0.5·g.
//!
//! **Gate.** Only at a loaded standstill: |ω*| below a small fraction of the rated speed,
//! |τ| above a fraction of the rated current, the lock supervisor running normally. The
//! arming time counts from the sample the standstill reference begins, not from limiter
//! mode: a stop that ends within it (a passage through zero, fig12's 0.3 s stops) never
//! arms the probe, and in a longer one the probe starts the first sample the estimator is
//! in limiter mode after it, so the creep of θ̂ that limiter mode lets run (ε_q/λ̂f,
//! 0.2–0.4 rad/s on the presets and made-up machines, docs/range.md) has no unwatched half
//! second in which to build while the rotor settles from a stop at the current limit.
//! Once probing, the gate no longer asks for limiter mode: the probe's own torque swings
//! the rotor by a few r/min, which on a slow motor (a 150 r/min torque motor's Fig. 3
//! threshold is 2.25 r/min) takes the estimator out of limiter mode for a few samples, and
//! a probe that stopped there would forget ĉ each time. The probe stops (Δi_d = 0, no turn,
//! ĉ forgotten) the sample the standstill ends.
//!
//! **At a brake's release** ([`StandstillProbe::arm_at_release`], from
//! `SensorlessDrive::arm_release_hold`) the arming time is one period (0.1 s) instead: the
//! standstill that follows is no passage through zero — the load was there, on the brake,
//! and the reference stays at zero — and the creep of θ̂ runs from the release on (0.45 rad/s
//! on the hub motor under its rated load, the release hold keeping θ̂, not the rotor, where it
//! was). One period lets the hold catch the falling rotor first (its largest travel comes at
//! 2/ω_h, 53 ms on the hub motor, the presets' slowest). Measured on `loaded-start`
//! (seeds 1–4, every preset): arming 0.02 s after the release the hub motor reads its first
//! period during the catch (|θ − θ̂| 0.29 rad on seeds 2 and 3); 0.05–0.1 s holds the hub motor
//! within 0.14–0.22 rad and the measured 1.1 kW map within 0.2–0.22 rad (seed 2: 0.33 and
//! 0.39 rad without it); 0.15–0.2 s leaves the 1.1 kW map 0.26–0.29 rad.
//! A heavy rotor's hold is slower than the period: the arming then lasts the hold's catch,
//! [`CATCH_TIMES`]/ω_h ([`StandstillProbe::set_release_catch`]; 0.09 s on the hub motor, so
//! every preset keeps one period). Measured on a drawn 116 kW IPMSM of 25 kg·m²
//! (`fado-sim/tests/data/drawn/ipm-2p-800v-115696w.toml`, ω_h = 8.5 rad/s, catch 0.40 s):
//! armed after one period the first reading falls in the catch, turns θ̂ at −0.87 rad/s and
//! leaves |θ − θ̂| 0.24–0.36 rad at seeds 1–6 (five of six over the 0.25 rad bound); armed
//! after the catch the probe does not start before `loaded-start`'s lift and the start keeps
//! 0.025–0.11 rad.
//!
//! **After the standstill.** When the standstill ends (the speed reference leaves it: a
//! hoist's lift after its brake's release) the probe stops, but the creep's cause does not:
//! the tangential integrand error at the load's current (R̂s's and the current sensors'
//! errors times that current, the inverter's residual) stays while the rotor leaves slowly
//! under the same load, and limiter mode observes it no better than at rest. So the turn is
//! carried while the estimator stays in limiter mode: the learned creep ĉ until the
//! estimator hands over to disturbance-feedback mode (whose observer takes the integrand
//! error), and the last reading's proportional turn g·δ̂ for 1/g, which turns θ̂ by that
//! reading once. Nothing is carried past a coast, a reset or the end of limiter mode.
//! Measured on `loaded-start` (seeds 1–4, switching-resolved): on the made-up 20-pole 48 V
//! IPMSM (`fado-sim/tests/data/ipmsm-20p-48v-saturated.toml`, 8 mWb, seed 2: a 0.5 % gain
//! mismatch of the current sensors that the start-up cannot calibrate at that angle on this
//! salient rotor creeps θ̂ at about 1 rad/s) max |θ − θ̂| 0.357 → 0.235 rad: the error
//! stays at the probe's last 0.18 rad over the lift's first 0.1 s instead of growing to
//! 0.36 rad before the estimator leaves limiter mode; the other motors' start-up rows
//! move by −0.06 to +0.035 rad (docs/results/startup.md); `fullrange` and `regen-stop` on
//! every preset within 0.002 rad.
//!
//! **Flux-magnitude hold.** While the probe runs, the drive also holds the estimate's rotor
//! flux on the model's circle, |λ̂r| = λ̂a at the last current reference
//! ([`crate::estimator::SensorlessEstimator::hold_flux_magnitude`], radially at the limiter's
//! rate k_af; the angle is untouched). The radial part of the integrand error otherwise
//! drives |λ̂r| to the limiter's radius 1.15·λ̂f, an offset of λ1 fixed in the stator frame:
//! when the rotor leaves, that offset is an angle error of up to its size over λ̂f
//! (0.1–0.15 rad, oscillating at the rotor's frequency until the disturbance observer learns
//! it). Held throughout rather than set once at the departure: measured on the presets'
//! `fullrange`, a single reset at the departure loses most of the gain (ipmsm-gem-50k
//! still loses 0.7–1.1 rad).

use crate::Real;
use crate::error::{ConfigError, check};

pub mod amplitude;

/// The probe's settings in absolute units (its user resolves them from its own ratios of the
/// machine's ratings).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StandstillProbeConfig<T> {
    /// Sampling period, s.
    pub ts: T,
    /// Probe amplitude A (A, d current): the largest; each period's follows the speed
    /// estimate's swing over the last ([`amplitude`]).
    pub amplitude: T,
    /// The largest |ω̂| over a period (electrical rad/s) that the probe's amplitude allows
    /// ([`amplitude`]); 0: the amplitude is fixed.
    pub swing: T,
    /// Probe period T_p (s).
    pub period: T,
    /// Correction gain g (s⁻¹): θ̂ turns at g·δ̂.
    pub gain: T,
    /// The gate's speed bound on the reference |ω*| (electrical rad/s).
    pub max_speed: T,
    /// The gate's load bound on |τ| (A, in units of the magnet's q current).
    pub min_load: T,
    /// Ĵ/(1.5·p²·λ̂f) (A per rad/s² electrical): the torque demand that accelerates the rotor
    /// at one rad/s², by which the reading removes the rotor's acceleration from τ (the
    /// torque balance of a speed loop that has not settled). 0: the settled balance alone.
    pub inertia: T,
    /// Time the gate holds before the probe starts (s): not in a passage through zero or a
    /// short stop.
    pub arm_time: T,
}

/// The release hold's catch in units of 1/ω_h, 2 + √2 \[D\]: a load step's response of the
/// hold's triple pole, x = a·t²·e^(−ω_h·t)/2, accelerates the rotor as
/// a·(2 − 4u + u²)·e^(−u)/2 (u = ω_h·t), whose last change of sign is at u = 2 + √2; from there
/// on the acceleration stays within 2.4 % of the load's, where before it swings from +1 to
/// −0.21 times it. The probe's reading removes the acceleration through ω̂, whose lag
/// and limiter-mode error leave a share of that swing in the torque balance.
pub const CATCH_TIMES: f64 = 3.414_213_562_373_095;

/// Largest angle reading (rad) the correction acts on (the small-signal reading's range).
const MAX_READING: f64 = 0.5;

/// The creep integrator's gain per period as a multiple of g (module docs, "Correction"):
/// with g·T_p = 2·p0³ and h·T_p = 6·p0² − 2, p0 = 4^(1/3) − 1, the loop has a triple pole at
/// p0 = 0.587 per period; h/g = (3·p0² − 1)/p0³.
pub const CREEP_GAIN_RATIO: f64 = 0.173_280_699_929_914;

/// The triple pole p0 = 4^(1/3) − 1 of the correction loop per period, for g·T_p =
/// [`TRIPLE_POLE_GAIN`] and the creep gain [`CREEP_GAIN_RATIO`]·g.
pub const TRIPLE_POLE: f64 = 0.587_401_051_968_199_5;

/// g·T_p = 2·p0³ that places the triple pole (module docs, "Correction").
pub const TRIPLE_POLE_GAIN: f64 = 0.405_353_713_070_718_7;

/// The probe's state (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StandstillProbe<T> {
    config: StandstillProbeConfig<T>,
    /// Samples per period (even, ≥ 4).
    period_samples: u32,
    /// Samples the gate holds before the probe starts (≥ 1).
    arm_samples: u32,
    /// The standstill a brake's release begins: armed after one period (module docs).
    release: bool,
    /// The release hold's catch in samples ([`Self::set_release_catch`]): the release's
    /// arming lasts at least this long (0: one period).
    release_samples: u32,
    /// Samples the standstill has held since it last ended (saturating at the arming time).
    gated: u32,
    /// Probing: armed, and the estimator has been in limiter mode since.
    probing: bool,
    /// Sample index within the running period.
    phase: u32,
    /// Σ s·τ over the settled windows.
    sum: T,
    /// Σ i_d̂*, Σ i_q̂* over the period (the operating point of the reading).
    sum_id: T,
    sum_iq: T,
    /// The last period's reading δ̂ (rad) and the turn rate in use (rad/s).
    reading: T,
    rate: T,
    /// The learned creep ĉ (rad/s): the integral part of the turn rate.
    creep: T,
    /// The running period's amplitude (A, [`amplitude`]).
    amplitude: T,
    /// The largest |ω̂| over the running period (rad/s).
    speed_max: T,
    /// The trapezoid's level in units of A, and its step per sample on the ramp.
    level: T,
    ramp_step: T,
    /// 1/(samples per period) and 1/(samples correlated per period), resolved once (no
    /// integer-to-float conversion in the step: no soft double on the f32 path).
    inv_period: T,
    inv_count: T,
    /// ω̂ at the sample before the running correlation window (rad/s).
    omega_mark: T,
    /// The turn carried past the standstill's end (module docs, "After the standstill").
    carry: Carry<T>,
    /// Samples over which the carried proportional turn g·δ̂ spends the last reading:
    /// 1/(g·Ts).
    spend_samples: u32,
}

/// The turn carried past the standstill's end while the estimator stays in limiter mode:
/// the learned creep ĉ, and for `left` more samples the last reading's proportional turn.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Carry<T> {
    creep: T,
    proportional: T,
    left: u32,
}

impl<T: Real> StandstillProbe<T> {
    /// Checks the configuration (amplitude, gain, bounds ≥ 0 and finite; the period at least
    /// four samples).
    pub fn new(config: StandstillProbeConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        check::non_negative("standstill_probe_current_ratio", config.amplitude)?;
        check::non_negative("standstill_probe_swing_ratio", config.swing)?;
        check::non_negative("standstill_probe_gain", config.gain)?;
        check::non_negative("standstill_probe_speed_ratio", config.max_speed)?;
        check::non_negative("standstill_probe_load_ratio", config.min_load)?;
        check::non_negative("inertia", config.inertia)?;
        let n = check::positive("standstill_probe_period", config.period)? / ts;
        check::below(
            "standstill_probe_period",
            n,
            T::lit(4e9),
            "below 4e9 sampling periods",
        )?;
        let half = (n * T::lit(0.5)).round().to_f64() as u32;
        if half < 2 {
            return Err(ConfigError::OutOfRange {
                field: "standstill_probe_period",
                expected: "at least four sampling periods",
            });
        }
        let arm = check::non_negative("standstill_probe_arm_time", config.arm_time)? / ts;
        check::below(
            "standstill_probe_arm_time",
            arm,
            T::lit(4e9),
            "below 4e9 sampling periods",
        )?;
        let mut probe = Self::new_idle(config, 2 * half);
        probe.arm_samples = (arm.round().to_f64() as u32).max(1);
        probe.ramp_step = T::lit(2.0 / ((half / 4) + 1) as f64);
        probe.inv_period = T::lit(1.0 / (2 * half) as f64);
        probe.inv_count = T::lit(1.0 / (2 * (half - half / 2)) as f64);
        let spend = T::one() / (config.gain * ts);
        probe.spend_samples = if spend.is_finite() && spend < T::lit(4e9) {
            spend.round().to_f64() as u32
        } else {
            0
        };
        Ok(probe)
    }

    /// A brake opens now: the standstill that follows arms the probe after one period (or
    /// the release hold's catch, [`Self::set_release_catch`]) instead of the arming time
    /// (module docs, "At a brake's release"), until the probe starts or the speed reference
    /// `omega_ref` leaves the standstill ([`Self::leave_release`]).
    pub fn arm_at_release(&mut self) {
        self.release = true;
    }

    /// The release hold of stiffness `omega_h` (rad/s, its three poles at −ω_h) catches the
    /// rotor at a brake's release: the release's arming lasts at least [`CATCH_TIMES`]/ω_h
    /// (module docs, "At a brake's release"). A non-finite or non-positive ω_h keeps one
    /// period.
    pub fn set_release_catch(&mut self, omega_h: T) {
        let n = T::lit(CATCH_TIMES) / (omega_h * self.config.ts);
        // NaN compares false: one period.
        self.release_samples = if omega_h > T::zero() && n < T::lit(4e9) {
            n.round().to_f64() as u32
        } else if omega_h > T::zero() {
            u32::MAX
        } else {
            0
        };
    }

    /// Ends the release's short arming once the speed reference `omega_ref` (rad/s
    /// electrical) leaves the standstill.
    #[inline]
    pub fn leave_release(&mut self, omega_ref: T) {
        if self.release && omega_ref.abs() > self.config.max_speed {
            self.release = false;
        }
    }

    /// Back to idle (no probe, no turn, nothing carried).
    pub fn reset(&mut self) {
        *self = Self {
            ramp_step: self.ramp_step,
            inv_period: self.inv_period,
            inv_count: self.inv_count,
            arm_samples: self.arm_samples,
            release: self.release,
            release_samples: self.release_samples,
            spend_samples: self.spend_samples,
            ..Self::new_idle(self.config, self.period_samples)
        };
    }

    /// A sample outside the standstill: the probe stops, and its turn is carried while the
    /// estimator stays in limiter mode (module docs, "After the standstill").
    fn carry_past_end(&mut self, limiter_mode: bool) {
        let mut carry = self.carry;
        if self.probing {
            carry = Carry {
                creep: self.creep,
                proportional: self.rate - self.creep,
                left: self.spend_samples,
            };
        } else if !limiter_mode {
            carry = Carry::default();
        } else {
            carry.left = carry.left.saturating_sub(1);
        }
        if self.gated != 0 || self.rate != T::zero() {
            self.reset();
        }
        self.carry = carry;
    }

    fn new_idle(config: StandstillProbeConfig<T>, period_samples: u32) -> Self {
        Self {
            config,
            period_samples,
            arm_samples: 1,
            release: false,
            release_samples: 0,
            gated: 0,
            probing: false,
            phase: 0,
            sum: T::zero(),
            sum_id: T::zero(),
            sum_iq: T::zero(),
            reading: T::zero(),
            rate: T::zero(),
            creep: T::zero(),
            amplitude: config.amplitude,
            speed_max: T::zero(),
            level: T::zero(),
            ramp_step: T::zero(),
            inv_period: T::zero(),
            inv_count: T::zero(),
            omega_mark: T::zero(),
            carry: Carry::default(),
            spend_samples: 0,
        }
    }

    /// Whether the drive is at a loaded standstill: |ω*| ≤ the speed bound, |τ| ≥ the load
    /// bound and `running` (the lock supervisor's normal run). Not |ω̂| itself: the probe
    /// moves the rotor by ±1–1.5 r/min on the paper's motor, which a tight bound on ω̂ would
    /// read as motion. The arming time counts while it holds; the probe starts in limiter
    /// mode ([`Self::step`]).
    pub fn gate(&self, omega_ref: T, tau: T, running: bool) -> bool {
        let c = &self.config;
        c.amplitude > T::zero()
            && running
            && omega_ref.abs() <= c.max_speed
            && tau.abs() >= c.min_load
    }

    /// One sample: `gate` from [`Self::gate`], `limiter_mode` the estimator's mode (the
    /// armed probe starts in limiter mode, which bounds |ω̂| by the Fig. 3 threshold, and then
    /// holds until the gate opens), `tau` the speed loop's torque demand of this
    /// sample (units of the magnet's q current), `omega` the speed estimate of the speed loop
    /// (electrical rad/s), `i_dq_prev` the last sample's current reference (d, q) in the
    /// estimated frame, `flux_linkage` λ̂f, `saliency` L̂d − L̂q.
    /// Returns Δi_d for this sample's d-current reference (A); [`Self::rate`] is the turn
    /// for the estimator.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        gate: bool,
        limiter_mode: bool,
        tau: T,
        omega: T,
        i_dq_prev: (T, T),
        flux_linkage: T,
        saliency: T,
    ) -> T {
        if !gate || !tau.is_finite() {
            self.carry_past_end(limiter_mode);
            return T::zero();
        }
        self.carry = Carry::default();
        let n = self.period_samples;
        let arm = if self.release {
            self.arm_samples.min(n).max(self.release_samples)
        } else {
            self.arm_samples
        };
        if !self.probing && self.gated < arm {
            // Armed after the gate has held for the arming time: no probe yet.
            self.gated += 1;
            return T::zero();
        }
        if !self.probing {
            if !limiter_mode {
                return T::zero();
            }
            self.probing = true;
            self.release = false;
        }
        let half = n / 2;
        let (sign, in_half) = if self.phase < half {
            (T::one(), self.phase)
        } else {
            (-T::one(), self.phase - half)
        };
        // Correlate over the settled second half of each half-period (the first sample of
        // the period sees last period's probe through the one-sample delay of τ; it lies in
        // the skipped part).
        if in_half >= half / 2 {
            self.sum += sign * tau;
        }
        // The rotor's acceleration over the window, in torque demand: Ĵ·Δω̂/(1.5·p²·λ̂f·Ts)
        // summed over its samples is c_J·(ω̂_end − ω̂_before)/Ts.
        if in_half + 1 == half / 2 {
            self.omega_mark = omega;
        } else if in_half + 1 == half && self.config.inertia > T::zero() {
            let accel = (omega - self.omega_mark) / self.config.ts;
            if accel.is_finite() {
                self.sum -= sign * self.config.inertia * accel;
            }
        }
        self.sum_id += i_dq_prev.0;
        self.sum_iq += i_dq_prev.1;
        self.track_speed(omega);
        let amplitude = self.amplitude;
        self.phase += 1;
        if self.phase == n {
            self.finish_period(flux_linkage, saliency);
        }
        // The reference ramps from the last half's level to this half's over the first
        // quarter of the half-period (a step kicks the rotor: the torque error A·sin δ
        // steps with it, and the 5 Hz speed loop lets the rotor swing ±9 r/min on the
        // paper's motor); it is flat where the correlation runs.
        if in_half == 0 {
            self.level = -T::one();
        }
        self.level = if in_half < half / 4 {
            self.level + self.ramp_step
        } else {
            T::one()
        };
        sign * self.level * amplitude
    }

    /// The largest |ω̂| over the running period, for the next period's amplitude.
    #[inline(always)]
    fn track_speed(&mut self, omega: T) {
        let speed = omega.abs();
        self.speed_max = if self.phase == 0 {
            speed
        } else {
            self.speed_max.step_max(speed)
        };
    }

    /// δ̂ from the period's correlation and the new turn rate.
    fn finish_period(&mut self, flux_linkage: T, saliency: T) {
        let delta_tau = self.sum * self.inv_count;
        let (i_d, i_q) = (self.sum_id * self.inv_period, self.sum_iq * self.inv_period);
        let reading = angle_reading(delta_tau, self.amplitude, i_d, i_q, flux_linkage, saliency);
        let bound = T::lit(MAX_READING);
        let reading = if reading.is_finite() {
            reading.step_max(-bound).step_min(bound)
        } else {
            T::zero()
        };
        self.reading = reading;
        self.amplitude = amplitude::next_amplitude(
            self.config.amplitude,
            self.amplitude,
            self.config.swing,
            self.speed_max,
        );
        // A proportional-integral turn (module docs, "Correction"): the integral learns the
        // creep, so that a constant creep leaves no angle error.
        let g = self.config.gain;
        let bound = g * T::lit(MAX_READING);
        self.creep = (self.creep + T::lit(CREEP_GAIN_RATIO) * g * reading)
            .step_max(-bound)
            .step_min(bound);
        self.rate = g * reading + self.creep;
        self.phase = 0;
        self.sum = T::zero();
        self.sum_id = T::zero();
        self.sum_iq = T::zero();
    }

    /// The turn rate of θ̂ for the estimator (rad/s): the probe's while it runs, the carried
    /// turn after the standstill (0 when idle).
    pub fn rate(&self) -> T {
        if self.probing {
            self.rate
        } else if self.carry.left > 0 {
            self.carry.creep + self.carry.proportional
        } else {
            self.carry.creep
        }
    }

    /// The last period's angle reading δ̂ = θ − θ̂ (rad; 0 when idle).
    pub fn reading(&self) -> T {
        self.reading
    }

    /// The gate held at the last sample (a loaded standstill, probing or arming).
    pub fn gated(&self) -> bool {
        self.gated != 0
    }

    /// Probing now (armed, and in limiter mode since).
    pub fn active(&self) -> bool {
        self.probing
    }
}

/// The angle error δ = θ − θ̂ the torque balance implies for a speed-loop response `delta_tau`
/// (torque demand in units of the magnet's q current, per probe step `amplitude` of i_d) at
/// the operating point (`i_d`, `i_q`) of the estimated frame, with λ̂f = `flux_linkage` and
/// L̂d − L̂q = `saliency` (module docs): δ = φ + atan(λ̂f·Δτ/(λ̂a·A) − tan φ),
/// tan φ = (L̂d − L̂q)·i_q/λ̂a.
pub fn angle_reading<T: Real>(
    delta_tau: T,
    amplitude: T,
    i_d: T,
    i_q: T,
    flux_linkage: T,
    saliency: T,
) -> T {
    let lambda_a = flux_linkage + saliency * i_d;
    let tan_phi = saliency * i_q / lambda_a;
    let x = flux_linkage * delta_tau / (lambda_a * amplitude) - tan_phi;
    x.step_atan2(T::one()) + tan_phi.step_atan2(T::one())
}

#[cfg(test)]
mod tests;
