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
//! 0.16 s zero: the default period is 0.1 s instead of 0.5 s, a window of 25 ms.
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

/// The probe's settings in absolute units (its user resolves them from its own ratios of the
/// machine's ratings).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StandstillProbeConfig<T> {
    /// Sampling period, s.
    pub ts: T,
    /// Probe amplitude A (A, d current).
    pub amplitude: T,
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
    /// The trapezoid's level in units of A, and its step per sample on the ramp.
    level: T,
    ramp_step: T,
    /// 1/(samples per period) and 1/(samples correlated per period), resolved once (no
    /// integer-to-float conversion in the step: no soft double on the f32 path).
    inv_period: T,
    inv_count: T,
    /// ω̂ at the sample before the running correlation window (rad/s).
    omega_mark: T,
}

impl<T: Real> StandstillProbe<T> {
    /// Checks the configuration (amplitude, gain, bounds ≥ 0 and finite; the period at least
    /// four samples).
    pub fn new(config: StandstillProbeConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        check::non_negative("standstill_probe_current_ratio", config.amplitude)?;
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
        Ok(probe)
    }

    /// A brake opens now: the standstill that follows arms the probe after one period
    /// instead of the arming time (module docs, "At a brake's release"), until the probe
    /// starts or the speed reference `omega_ref` leaves the standstill
    /// ([`Self::leave_release`]).
    pub fn arm_at_release(&mut self) {
        self.release = true;
    }

    /// Ends the release's short arming once the speed reference `omega_ref` (rad/s
    /// electrical) leaves the standstill.
    #[inline]
    pub fn leave_release(&mut self, omega_ref: T) {
        if self.release && omega_ref.abs() > self.config.max_speed {
            self.release = false;
        }
    }

    /// Back to idle (no probe, no turn).
    pub fn reset(&mut self) {
        *self = Self {
            ramp_step: self.ramp_step,
            inv_period: self.inv_period,
            inv_count: self.inv_count,
            arm_samples: self.arm_samples,
            release: self.release,
            ..Self::new_idle(self.config, self.period_samples)
        };
    }

    fn new_idle(config: StandstillProbeConfig<T>, period_samples: u32) -> Self {
        Self {
            config,
            period_samples,
            arm_samples: 1,
            release: false,
            gated: 0,
            probing: false,
            phase: 0,
            sum: T::zero(),
            sum_id: T::zero(),
            sum_iq: T::zero(),
            reading: T::zero(),
            rate: T::zero(),
            creep: T::zero(),
            level: T::zero(),
            ramp_step: T::zero(),
            inv_period: T::zero(),
            inv_count: T::zero(),
            omega_mark: T::zero(),
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
            if self.gated != 0 || self.rate != T::zero() {
                self.reset();
            }
            return T::zero();
        }
        let n = self.period_samples;
        let arm = if self.release {
            self.arm_samples.min(n)
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
        sign * self.level * self.config.amplitude
    }

    /// δ̂ from the period's correlation and the new turn rate.
    fn finish_period(&mut self, flux_linkage: T, saliency: T) {
        let delta_tau = self.sum * self.inv_count;
        let (i_d, i_q) = (self.sum_id * self.inv_period, self.sum_iq * self.inv_period);
        let reading = angle_reading(
            delta_tau,
            self.config.amplitude,
            i_d,
            i_q,
            flux_linkage,
            saliency,
        );
        let bound = T::lit(MAX_READING);
        let reading = if reading.is_finite() {
            reading.step_max(-bound).step_min(bound)
        } else {
            T::zero()
        };
        self.reading = reading;
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

    /// The turn rate of θ̂ for the estimator (rad/s; 0 when idle).
    pub fn rate(&self) -> T {
        self.rate
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
mod tests {
    use super::*;

    /// A synthetic loaded standstill: a rotor (λf, Ld − Lq) at angle error δ = θ − θ̂ under a
    /// load `load` (torque in units of 1.5·p, i.e. Wb·A), with the drive's model feed-forward
    /// λ̂a(i_d̂)·i_q̂ = λf·τ and a settled speed loop: τ is whatever makes the true torque
    /// (λf + ΔL·i_d)·i_q equal the load, i_d = i_d̂·cos δ + i_q̂·sin δ,
    /// i_q = i_q̂·cos δ − i_d̂·sin δ.
    struct Balance {
        flux: f64,
        saliency: f64,
        delta: f64,
        load: f64,
    }

    impl Balance {
        fn currents(&self, tau: f64, i_d_hat: f64) -> (f64, f64) {
            let i_q_hat = self.flux * tau / (self.flux + self.saliency * i_d_hat);
            (i_d_hat, i_q_hat)
        }
        fn torque(&self, tau: f64, i_d_hat: f64) -> f64 {
            let (dh, qh) = self.currents(tau, i_d_hat);
            let (s, c) = self.delta.sin_cos();
            let (i_d, i_q) = (dh * c + qh * s, qh * c - dh * s);
            (self.flux + self.saliency * i_d) * i_q
        }
        /// The settled torque demand for a d reference `i_d_hat` (bisection).
        fn tau(&self, i_d_hat: f64) -> f64 {
            let (mut lo, mut hi) = (0.0, 10.0 * self.load / self.flux);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if self.torque(mid, i_d_hat) < self.load {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            0.5 * (lo + hi)
        }
    }

    fn probe(amplitude: f64) -> StandstillProbe<f64> {
        StandstillProbe::new(StandstillProbeConfig {
            ts: 1e-3,
            amplitude,
            period: 0.2,
            gain: 0.25,
            max_speed: 1.0,
            min_load: 1.0,
            inertia: 0.0,
            arm_time: 0.2,
        })
        .unwrap()
    }

    /// Runs the probe against the balance (τ lags the settled value with a first-order
    /// time constant `lag` in samples, the speed loop) for the arming period and one probe
    /// period; returns the reading.
    fn read(b: &Balance, i_d0: f64, amplitude: f64, lag: f64) -> f64 {
        let mut p = probe(amplitude);
        let mut tau = b.tau(i_d0);
        let mut id = i_d0;
        for _ in 0..400 {
            let iq = b.currents(tau, id).1;
            let did = p.step(true, true, tau, 0.0, (id, iq), b.flux, b.saliency);
            id = i_d0 + did;
            tau += (b.tau(id) - tau) / lag;
        }
        assert!(p.active());
        p.reading()
    }

    #[test]
    fn surface_magnet_reading_is_the_angle_error_with_its_sign() {
        // The paper's motor: λf 0.1 Wb, 14 A of load, 2.2 A probe.
        for delta in [-0.4, -0.2, -0.05, 0.0, 0.05, 0.2, 0.4] {
            let b = Balance {
                flux: 0.1,
                saliency: 0.0,
                delta,
                load: 1.4,
            };
            let r = read(&b, 0.0, 2.2, 1.0);
            assert!(
                (r - delta).abs() < 0.01 * delta.abs() + 1e-6,
                "δ {delta}: read {r}"
            );
            // With the speed loop's lag (time constant 10 of the 100-sample half-period):
            let r = read(&b, 0.0, 2.2, 10.0);
            assert!(
                (r - delta).abs() < 0.02 * delta.abs() + 1e-6,
                "δ {delta}: lagged {r}"
            );
        }
        // No response to the probe (δ = 0 held by a stiff τ): no reading, no turn.
        let mut p = probe(2.2);
        let tau = b_tau_zero();
        for _ in 0..400 {
            p.step(true, true, tau, 0.0, (0.0, tau), 0.1, 0.0);
        }
        assert!(p.active() && p.reading() == 0.0 && p.rate() == 0.0);
    }

    fn b_tau_zero() -> f64 {
        14.0
    }

    #[test]
    fn interior_magnet_reading_accounts_for_the_reluctance_torque() {
        // The 2.2 kW IPMSM: λf 0.545 Wb, Ld − Lq = −15 mH, half load (3.3 A) with
        // i_d = −0.5 A, a 0.6 A probe. The reluctance torque alone would read
        // atan(ΔL·i_q/λa) = −0.09 rad at δ = 0; the reading removes it. The ±A step is a
        // finite difference of the balance, not its derivative: 3.5 % of δ at δ = −0.3.
        for delta in [-0.3, -0.1, 0.0, 0.1, 0.3] {
            let b = Balance {
                flux: 0.545,
                saliency: -0.015,
                delta,
                load: 0.545 * 3.3,
            };
            let r = read(&b, -0.5, 0.6, 1.0);
            assert!(
                (r - delta).abs() < 0.05 * delta.abs() + 1e-4,
                "δ {delta}: read {r}"
            );
            let r = read(&b, -0.5, 0.6, 10.0);
            assert!(
                (r - delta).abs() < 0.06 * delta.abs() + 1e-4,
                "δ {delta}: lagged {r}"
            );
        }
    }

    #[test]
    fn angle_reading_inverts_the_small_signal_balance() {
        // λ̂f·Δτ/Δi_d = b + λa·tan(δ − φ) (module docs), for both rotors.
        for (flux, saliency, i_d, i_q) in [(0.1, 0.0, 0.0, 14.0), (0.545, -0.015, -0.5, 3.3)] {
            let lambda_a: f64 = flux + saliency * i_d;
            let b = saliency * i_q;
            let phi = (b / lambda_a).atan();
            for delta in [-0.4, 0.0, 0.25] {
                let dtau = (b + lambda_a * (delta - phi).tan()) / flux;
                let r = angle_reading(dtau, 1.0, i_d, i_q, flux, saliency);
                assert!((r - delta).abs() < 1e-12, "{r} vs {delta}");
            }
        }
    }

    #[test]
    fn the_gate_stops_the_probe_and_the_turn() {
        let b = Balance {
            flux: 0.1,
            saliency: 0.0,
            delta: 0.3,
            load: 1.4,
        };
        let mut p = probe(2.2);
        let mut id = 0.0;
        let mut tau = b.tau(0.0);
        for _ in 0..400 {
            id = p.step(true, true, tau, 0.0, (id, tau), 0.1, 0.0);
            tau = b.tau(id);
        }
        let first = 0.25 * (1.0 + CREEP_GAIN_RATIO) * p.reading();
        assert!(p.rate() > 0.0 && (p.rate() - first).abs() < 1e-12);
        assert!(p.gate(0.5, 5.0, true) && p.gate(-0.5, -5.0, true));
        assert!(!p.gate(2.0, 5.0, true) && !p.gate(0.0, 0.5, true));
        assert!(!p.gate(0.0, 5.0, false));
        assert_eq!(p.step(false, true, tau, 0.0, (0.0, tau), 0.1, 0.0), 0.0);
        assert_eq!((p.rate(), p.active()), (0.0, false));
        assert_eq!(p.step(true, true, f64::NAN, 0.0, (0.0, tau), 0.1, 0.0), 0.0);
        // Off (amplitude 0): never gated.
        assert!(!probe(0.0).gate(0.0, 5.0, true));
    }

    /// A rigid rotor under the speed PI (5 Hz, zero at a fifth of it), period 0.1 s: the
    /// speed loop has not settled within a half-period, so τ alone under-reads the torque
    /// balance; with the rotor's acceleration removed (`inertia`) the reading is the angle.
    #[test]
    fn inertia_term_reads_an_unsettled_speed_loop() {
        let (flux, c_j, ts) = (0.1, 2e-3, 1e-4);
        let read = |delta: f64, inertia: f64| {
            let b = Balance {
                flux,
                saliency: 0.0,
                delta,
                load: 1.4,
            };
            let mut p = StandstillProbe::new(StandstillProbeConfig {
                ts,
                amplitude: 2.2,
                period: 0.1,
                gain: 0.0,
                max_speed: 1.0,
                min_load: 1.0,
                inertia,
                arm_time: 0.1,
            })
            .unwrap();
            let w_s = 2.0 * core::f64::consts::PI * 5.0;
            let (kp, ki) = (c_j * w_s, c_j * w_s * w_s / 5.0);
            let (mut omega, mut integral, mut id) = (0.0, b.tau(0.0), 0.0);
            for _ in 0..3000 {
                let tau = kp * -omega + integral;
                id = p.step(true, true, tau, omega, (id, tau), flux, 0.0);
                let torque = b.torque(tau, id) / flux;
                omega += ts * (torque - b.load / flux) / c_j;
                integral += ts * ki * -omega;
            }
            p.reading()
        };
        for delta in [-0.2, 0.1, 0.3] {
            let (with, without) = (read(delta, c_j), read(delta, 0.0));
            assert!(
                (with - delta).abs() < 0.05 * delta.abs(),
                "δ {delta}: {with}"
            );
            assert!(
                (without - delta).abs() > 0.2 * delta.abs(),
                "δ {delta}: {without}"
            );
        }
    }

    /// The correction loop per period (module docs, "Correction"): the error x after period
    /// k, the reading r_k = (x_{k−1} + x_k)/2, the turn over the next period g·r_k + ĉ_k with
    /// ĉ_k = ĉ_{k−1} + h·r_k: 2z³ + (G + H − 4)·z² + (2 + H)·z − G = 0 (G = g·T_p,
    /// H = h·T_p) has its triple root at p0.
    #[test]
    fn correction_loop_has_its_triple_pole() {
        let (g, h) = (TRIPLE_POLE_GAIN, CREEP_GAIN_RATIO * TRIPLE_POLE_GAIN);
        let z = TRIPLE_POLE;
        let f = 2.0 * z * z * z + (g + h - 4.0) * z * z + (2.0 + h) * z - g;
        let df = 6.0 * z * z + 2.0 * (g + h - 4.0) * z + 2.0 + h;
        let d2f = 12.0 * z + 2.0 * (g + h - 4.0);
        assert!(f.abs() < 1e-12 && df.abs() < 1e-12 && d2f.abs() < 1e-12);
        assert!((TRIPLE_POLE - (4f64.cbrt() - 1.0)).abs() < 1e-15);
    }

    /// A constant creep of θ̂ (0.5 rad/s) at a settled loaded standstill: the probe's turn
    /// learns it: after 1.5 s (14 periods) the angle error stays below 5 % of the c/g a
    /// proportional turn would leave.
    #[test]
    fn creep_is_learned_and_leaves_no_angle_error() {
        let (ts, period, creep) = (1e-3, 0.1, 0.5);
        let gain = TRIPLE_POLE_GAIN / period;
        let mut p = StandstillProbe::new(StandstillProbeConfig {
            ts,
            amplitude: 2.2,
            period,
            gain,
            max_speed: 1.0,
            min_load: 1.0,
            inertia: 0.0,
            arm_time: period,
        })
        .unwrap();
        let mut b = Balance {
            flux: 0.1,
            saliency: 0.0,
            delta: 0.0,
            load: 1.4,
        };
        let mut id = 0.0;
        let mut worst_late = 0.0f64;
        for n in 0..3000 {
            let tau = b.tau(id);
            id = p.step(true, true, tau, 0.0, (id, tau), b.flux, 0.0);
            // δ = θ − θ̂: the creep turns θ̂ away, the probe's turn brings it back.
            b.delta += ts * (creep - p.rate());
            if n > 1500 {
                worst_late = worst_late.max(b.delta.abs());
            }
        }
        assert!(worst_late < 0.05 * creep / gain, "{worst_late} rad");
    }

    /// The arming time counts the standstill whatever the estimator's mode; the armed probe
    /// starts the first sample in limiter mode and then holds when limiter mode drops (its
    /// own swing of the rotor), until the standstill ends.
    #[test]
    fn arming_counts_the_standstill_and_the_probe_holds_out_of_limiter_mode() {
        let (tau, flux) = (14.0, 0.1);
        let mut p = probe(2.2); // arming time 0.2 s = 200 samples
        let step = |p: &mut StandstillProbe<f64>, gate: bool, limiter: bool| {
            p.step(gate, limiter, tau, 0.0, (0.0, tau), flux, 0.0)
        };
        for _ in 0..300 {
            assert_eq!(step(&mut p, true, false), 0.0);
        }
        assert!(p.gated() && !p.active(), "armed, not yet in limiter mode");
        assert_ne!(
            step(&mut p, true, true),
            0.0,
            "starts at once in limiter mode"
        );
        assert!(p.active());
        for _ in 0..50 {
            step(&mut p, true, false);
        }
        assert!(p.active(), "holds out of limiter mode");
        assert_eq!(step(&mut p, false, true), 0.0);
        assert!(!p.active() && !p.gated(), "stops with the standstill");
        // A stop shorter than the arming time never probes, even in limiter mode.
        for _ in 0..150 {
            assert_eq!(step(&mut p, true, true), 0.0);
        }
        step(&mut p, false, true);
        for _ in 0..150 {
            assert_eq!(step(&mut p, true, true), 0.0);
        }
        assert!(!p.active());
    }

    /// At a brake's release the probe arms after one period (0.2 s here) instead of the
    /// arming time (0.5 s), and keeps probing once started; a speed reference that leaves
    /// the standstill before it starts ends the short arming.
    #[test]
    fn a_brake_release_arms_the_probe_after_one_period() {
        let (tau, flux) = (14.0, 0.1);
        let config = StandstillProbeConfig {
            arm_time: 0.5,
            ..probe(2.2).config
        };
        let step =
            |p: &mut StandstillProbe<f64>| p.step(true, true, tau, 0.0, (0.0, tau), flux, 0.0);
        let mut p = StandstillProbe::new(config).unwrap();
        p.arm_at_release();
        p.leave_release(0.5); // within the standstill's speed bound (1 rad/s)
        for _ in 0..200 {
            assert_eq!(step(&mut p), 0.0);
        }
        assert_ne!(step(&mut p), 0.0, "armed after one period");
        assert!(p.active());
        let probed = (0..1000).filter(|_| step(&mut p) != 0.0).count();
        assert!(p.active() && probed > 500, "{probed}");
        // Left before it started: the arming time again.
        let mut q = StandstillProbe::new(config).unwrap();
        q.arm_at_release();
        q.leave_release(2.0);
        for _ in 0..400 {
            assert_eq!(step(&mut q), 0.0);
        }
        assert!(!q.active());
    }
}
