//! The type-2 system (T2S, paper Fig. 1): a PI phase-tracking loop that filters the directly
//! calculated angle of eq. (6) and estimates the speed.
//!
//! Two integrators in the open loop make it type 2: zero steady-state angle error for a
//! constant speed and a constant error α/Ki for a constant acceleration α. The closed loop is
//! T(s) = (Kp·s + Ki)/(s² + Kp·s + Ki), Kp = 2ζωn, Ki = ωn² (docs/method/estimator.md §4 \[A\]: the paper's
//! references 9 and 11 that define it are not recoverable).
//!
//! Discretisation (docs/method/estimator.md §4): e = wrap(θm − θ̂⁻); xI ← xI + Ki·Ts·e;
//! θ̂⁻ ← wrap(θ̂⁻ + Ts·(xI + Kp·e)); ω̂ = xI. Because the angle update uses the *updated* xI,
//! the poles are the roots of z² − (2 − Kp·Ts − Ki·Ts²)z + (1 − Kp·Ts). docs/method/estimator.md §4 quotes
//! z² + (Kp·Ts − 2)z + (1 − Kp·Ts + Ki·Ts²), which belongs to the variant using the old xI;
//! we keep the reconstructed recursion (docs/method/estimator.md §4) and correct the formula (the test `discrete_poles_match_formula`
//! probes the actual map). Both approach the continuous poles as ωn·Ts → 0. Wrapping the phase difference keeps the detector
//! linear over ±π, so the tracker follows the angle through its ±π wrap.
//!
//! θ̂⁻ is the *prediction* for the next sample. The angle reported for the present sample is
//! the corrected one before the prediction, θ̂ = θ̂⁻ + Kp·Ts·e (then θ̂⁻ = θ̂ + Ts·ω̂): the same
//! recursion and poles, but without the one-sample lag ω·Ts the predicted value would carry
//! (1.3e-2 rad at 20 Hz).
//!
//! **Acceleration feed-forward (type 3).** Under a constant acceleration α the type-2 loop
//! lags by α/Ki in angle and Kp·α/Ki in speed: 0.1 rad and 70 r/min on the paper's motor
//! accelerating at its current limit (60 Hz T2S-1). A drive knows the torque it commands, so
//! the tracker can be given the acceleration p·T*/Ĵ that torque causes (the mechanical model of
//! motulator's speed observer and of Lorenz's acceleration feed-forward): ω̂ ← ω̂ + Ki·Ts·e +
//! Ts·(a* + â). What the model misses, the load's torque, Ĵ's error and friction, is a slowly
//! varying acceleration â, integrated from the phase error (â ← â + K3·Ts·e): a third
//! integrator, so a constant load leaves no angle error (with the feed-forward alone it would
//! leave p·T_L/(Ĵ·Ki), 0.11 rad at the paper's rated load). The poles are the type-2 pair
//! with a real pole added at c·ωn (the estimator's `tracker.load_pole_ratio`; c = 0 keeps the
//! type-2 loop to the bit). The feed-forward removes the lag under the commanded torque; a
//! load step is a disturbance the third integrator removes at c·ωn.
//!
//! **Angles in `f32`: wrapping fixed point** ([`Real::Angle`]). In `f32` θ̂ and θ̂⁻ are kept
//! as `i32` with 2³² units = 2π (one unit is 1.46e-9 rad), so every wrap of the recursion is
//! the overflow of an integer add or subtract: e = θm − θ̂⁻ is exact modulo 2π without a
//! compare, and so are θ̂ and θ̂⁻ (the float recursion needs three [`wrap_angle`] per tracker
//! and sample, each a compare and a branch on a Cortex-M4F; docs/results/firmware-cost.md). θm enters
//! rounded towards zero to a unit, the steps Kp·Ts·e and Ts·ω̂ too, saturating at ±π (a step
//! beyond π is above the Nyquist frequency, aliased anyway; Kp·Ts·e reaches it only for
//! Kp·Ts > 1, a bandwidth above a fifth of the sampling rate). One unit is 1/165 of an
//! `f32` ulp of π, so the `f32` tracker is at least as fine as the float one; its resolution
//! is tested in `f32_fixed_point_tracker_locks_and_wraps`. `f64` keeps the float recursion
//! exactly as written above (its results unchanged to the bit).

use crate::error::{ConfigError, NonFiniteInput, check};
use crate::{Real, wrap_angle};

/// How the tracker's bandwidth parameter is interpreted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum BandwidthDefinition {
    /// The −3 dB frequency of T(s) (docs/method/estimator.md §4 default): ωn = ω_bw / √(1 + 2ζ² + √((1+2ζ²)² + 1)),
    /// i.e. ωn = ω_bw / 2.058 for ζ = 1/√2.
    #[default]
    Minus3Db,
    /// The natural frequency ωn itself.
    NaturalFrequency,
}

/// Default damping ratio ζ of a tracker: 1/√2 (docs/method/estimator.md §4 \[A\]).
pub const DEFAULT_DAMPING: f64 = core::f64::consts::FRAC_1_SQRT_2;

/// Configuration of a [`TypeTwoTracker`].
///
/// No `Default`: the sampling period is the set-up's and the bandwidth the loop's. Build it
/// with [`new`](Self::new); "Default" below is what it gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackerConfig<T> {
    /// Sampling period Ts in s (paper, V: 100 µs).
    pub ts: T,
    /// Bandwidth in Hz (paper, V: 60 Hz for T2S-1, 35 Hz for T2S-2). No default: the loop's.
    pub bandwidth_hz: T,
    /// Damping ratio ζ. Default [`DEFAULT_DAMPING`] (1/√2, docs/method/estimator.md §4 \[A\]).
    pub damping: T,
    /// How `bandwidth_hz` is defined. Default −3 dB (docs/method/estimator.md §4;
    /// [`BandwidthDefinition::default`]).
    pub definition: BandwidthDefinition,
}

impl<T: Real> TrackerConfig<T> {
    /// A tracker of `bandwidth_hz` sampled every `ts`, with the default damping and
    /// bandwidth definition (ζ = 1/√2, −3 dB; docs/method/estimator.md §4).
    pub fn new(bandwidth_hz: T, ts: T) -> Self {
        Self {
            ts,
            bandwidth_hz,
            damping: T::lit(DEFAULT_DAMPING),
            definition: BandwidthDefinition::default(),
        }
    }

    /// The PI gains (Kp in s⁻¹, Ki in s⁻²) this configuration gives.
    pub fn gains(&self) -> (T, T) {
        let w_bw = T::two_pi() * self.bandwidth_hz;
        let z = self.damping;
        let wn = match self.definition {
            BandwidthDefinition::NaturalFrequency => w_bw,
            BandwidthDefinition::Minus3Db => {
                let one = T::one();
                let two = T::lit(2.0);
                let a = one + two * z * z;
                w_bw / (a + (a * a + one).sqrt()).sqrt()
            }
        };
        (T::lit(2.0) * z * wn, wn * wn)
    }
}

/// The tracker's constants, precomputed once from a [`TrackerConfig`] (the immutable half of
/// [`TypeTwoTracker`], see [`crate::estimator`]'s "parameters and state").
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TrackerParams<T> {
    ts: T,
    kp: T,
    /// Ts·Kp, precomputed (the same product the recursion formed every sample).
    kp_ts: T,
    ki_ts: T,
    /// Ts in angle units per rad/s and Ki·Ts in rad/s per angle unit ([`Real::angle_unit`]):
    /// the unit conversions of the recursion folded into its gains (`f64`: Ts and Ki·Ts).
    ts_units: T,
    ki_ts_units: T,
    /// K3·Ts in rad/s² per angle unit: the load-acceleration integrator of the type-3 form
    /// ([`TrackerParams::with_load_pole`]); 0 keeps the type-2 loop.
    k3_ts_units: T,
}

/// The tracker's mutable state: θ̂⁻, θ̂ and ω̂; the commanded acceleration fed forward and
/// the integrated load acceleration â of the type-3 form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TrackerState<T: Real> {
    /// θ̂⁻: the angle predicted for the next sample ([`Real::Angle`]).
    predicted: T::Angle,
    /// θ̂: the angle estimate for the last sample.
    theta: T::Angle,
    omega: T,
    /// The acceleration the drive commands, rad/s² (electrical), fed forward into ω̂.
    acceleration: T,
    /// â: what the feed-forward misses (the load's acceleration), rad/s².
    load: T,
}

impl<T: Real> TrackerParams<T> {
    /// The constants of `config`. Refuses gains whose discrete poles leave the unit circle
    /// (Jury's test on the polynomial in the module docs: 0 < Kp·Ts < 2 and
    /// 2·Kp·Ts + Ki·Ts² < 4).
    pub(crate) fn new(config: TrackerConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        check::positive("bandwidth_hz", config.bandwidth_hz)?;
        check::positive("damping", config.damping)?;
        let (kp, ki) = config.gains();
        let kpt = kp * ts;
        let kit = ki * ts * ts;
        if !(kpt < T::lit(2.0) && T::lit(2.0) * kpt + kit < T::lit(4.0)) {
            return Err(ConfigError::OutOfRange {
                field: "bandwidth_hz",
                expected: "a bandwidth whose discrete tracker poles stay inside the unit circle",
            });
        }
        Ok(Self {
            ts,
            kp,
            kp_ts: ts * kp,
            ki_ts: ki * ts,
            ts_units: ts * T::angle_units_per_rad(),
            ki_ts_units: ki * ts * T::angle_unit(),
            k3_ts_units: T::zero(),
        })
    }

    /// The type-3 form for an acceleration feed-forward (see the module docs): a third
    /// integrator â ← â + K3·Ts·e of the acceleration the feed-forward misses, with the poles
    /// of the type-2 loop kept and a real pole added at `ratio`·ωn: (s² + 2ζωn·s + ωn²)·
    /// (s + c·ωn) gives Kp = (2ζ + c)·ωn, Ki = (1 + 2ζc)·ωn², K3 = c·ωn³. `ratio` = 0 leaves
    /// the type-2 tracker unchanged (to the bit).
    pub(crate) fn with_load_pole(
        mut self,
        config: &TrackerConfig<T>,
        ratio: T,
    ) -> Result<Self, ConfigError> {
        let c = check::non_negative("tracker_load_pole_ratio", ratio)?;
        if c == T::zero() {
            return Ok(self);
        }
        let (kp0, ki0) = config.gains();
        let wn = ki0.sqrt();
        let zeta2 = kp0 / wn;
        let kp = (zeta2 + c) * wn;
        let ki = (T::one() + zeta2 * c) * wn * wn;
        let k3 = c * wn * wn * wn;
        let ts = self.ts;
        let (a1, a2, a3) = (kp * ts, ki * ts * ts, k3 * ts * ts * ts);
        // The discrete loop is stable when the poles of the sampled triple stay inside the
        // unit circle; at ωn·Ts ≪ 1 they are e^{−p·Ts}. Refuse gains beyond a tenth of the
        // sampling rate (the type-2 limit's margin).
        if !(a1 < T::lit(0.5) && a2 < T::lit(0.1) && a3 < T::lit(0.02)) {
            return Err(ConfigError::OutOfRange {
                field: "tracker_load_pole_ratio",
                expected: "a load pole whose tracker stays well below the sampling rate",
            });
        }
        self.kp = kp;
        self.kp_ts = ts * kp;
        self.ki_ts = ki * ts;
        self.ki_ts_units = ki * ts * T::angle_unit();
        self.k3_ts_units = k3 * ts * T::angle_unit();
        Ok(self)
    }

    /// The state at a known angle and speed.
    pub(crate) fn state_at(&self, theta: T, omega: T) -> TrackerState<T> {
        let theta = T::angle_from(wrap_angle(theta));
        TrackerState {
            predicted: theta,
            theta,
            omega,
            acceleration: T::zero(),
            load: T::zero(),
        }
    }

    /// The update after one sample with the measurement θm ∈ [−π, π] (eq. (6)'s range).
    #[inline(always)]
    pub(crate) fn next_state(&self, s: &TrackerState<T>, theta_measured: T) -> TrackerUpdate<T> {
        self.next_state_with(s, theta_measured, self.ts_units)
    }

    /// [`Self::next_state`] with Ts in angle units given: `ts_units` must be this tracker's
    /// own (the estimator passes T2S-1's to T2S-2, the same product of the same Ts, so that
    /// it is loaded once).
    #[inline(always)]
    pub(crate) fn next_state_with(
        &self,
        s: &TrackerState<T>,
        theta_measured: T,
        ts_units: T,
    ) -> TrackerUpdate<T> {
        // In angle units ([`Real::angle_unit`]): Kp·Ts is dimensionless, the conversions of
        // Ki·Ts·e and Ts·ω̂ are in `ki_ts_units` and `ts_units` (`f32`: one rounding fewer
        // than converting e and the increments, and no multiply per conversion).
        let e = T::angle_diff_units(T::angle_from(theta_measured), s.predicted);
        let (omega, load) = if s.acceleration == T::zero() && self.k3_ts_units == T::zero() {
            (s.omega + self.ki_ts_units * e, s.load)
        } else {
            let load = s.load + self.k3_ts_units * e;
            (
                s.omega + self.ki_ts_units * e + self.ts * (s.acceleration + load),
                load,
            )
        };
        let theta = T::angle_add_units(s.predicted, self.kp_ts * e);
        TrackerUpdate {
            predicted: T::angle_add_units(theta, ts_units * omega),
            theta,
            omega,
            innovation: e,
            load,
        }
    }

    /// The update after one coasting sample.
    #[inline(always)]
    pub(crate) fn coasted_state(&self, s: &TrackerState<T>) -> TrackerUpdate<T> {
        let theta = s.predicted;
        // Coasting, ω̂ follows the commanded acceleration and the last â (the model alone).
        let omega = if s.acceleration == T::zero() && s.load == T::zero() {
            s.omega
        } else {
            s.omega + self.ts * (s.acceleration + s.load)
        };
        TrackerUpdate {
            predicted: T::angle_add_units(theta, self.ts_units * s.omega),
            theta,
            omega,
            innovation: T::zero(),
            load: s.load,
        }
    }

    /// Ts in tracker angle units per rad/s (Ts·2³²/2π in `f32`, Ts in `f64`).
    #[inline(always)]
    pub(crate) fn ts_units(&self) -> T {
        self.ts_units
    }

    /// Kp in s⁻¹ (see [`TypeTwoTracker::kp`]).
    #[inline(always)]
    pub(crate) fn kp(&self) -> T {
        self.kp
    }
}

impl<T: Real> TrackerState<T> {
    /// Takes an update computed by [`TrackerParams::next_state`] or
    /// [`TrackerParams::coasted_state`].
    #[inline(always)]
    pub(crate) fn commit(&mut self, next: TrackerUpdate<T>) {
        self.predicted = next.predicted;
        self.theta = next.theta;
        self.omega = next.omega;
        self.load = next.load;
    }

    /// Sets the acceleration fed forward from the next sample on, rad/s² (electrical).
    #[inline(always)]
    pub(crate) fn set_acceleration(&mut self, acceleration: T) {
        self.acceleration = acceleration;
    }

    /// [`Self::commit`] without θ̂: for a tracker whose angle nobody reads (the estimator's
    /// T2S-2, whose ω̂ alone is used; its θ̂ stays the one set by `state_at`). One store and
    /// one live register fewer.
    #[inline(always)]
    pub(crate) fn commit_speed(&mut self, next: TrackerUpdate<T>) {
        self.predicted = next.predicted;
        self.omega = next.omega;
        self.load = next.load;
    }

    /// θ̂ for the last sample, in [−π, π].
    #[inline(always)]
    pub(crate) fn angle(&self) -> T {
        T::angle_to(self.theta)
    }

    /// ω̂ in rad/s.
    #[inline(always)]
    pub(crate) fn speed(&self) -> T {
        self.omega
    }
}

/// Type-2 angle and speed tracker (Fig. 1): its constants and its state together.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TypeTwoTracker<T: Real> {
    params: TrackerParams<T>,
    state: TrackerState<T>,
}

impl<T: Real> TypeTwoTracker<T> {
    /// A new tracker at θ̂ = 0, ω̂ = 0. Refuses gains whose discrete poles leave the unit
    /// circle (Jury's test on the polynomial in the module docs: 0 < Kp·Ts < 2 and
    /// 2·Kp·Ts + Ki·Ts² < 4).
    pub fn new(config: TrackerConfig<T>) -> Result<Self, ConfigError> {
        let params = TrackerParams::new(config)?;
        Ok(Self {
            params,
            state: params.state_at(T::zero(), T::zero()),
        })
    }

    /// A new tracker of the type-3 form with a load pole at `ratio`·ωn (see
    /// `TrackerParams::with_load_pole` in the module docs), for an acceleration
    /// feed-forward ([`Self::set_acceleration`]).
    pub fn with_load_pole(config: TrackerConfig<T>, ratio: T) -> Result<Self, ConfigError> {
        let params = TrackerParams::new(config)?.with_load_pole(&config, ratio)?;
        Ok(Self {
            params,
            state: params.state_at(T::zero(), T::zero()),
        })
    }

    /// The acceleration fed forward into ω̂ from the next sample on, rad/s²: the drive's
    /// commanded torque through the mechanical model, p·T*/Ĵ.
    pub fn set_acceleration(&mut self, acceleration: T) {
        self.state.set_acceleration(acceleration);
    }

    /// θ̂ = ω̂ = 0.
    pub fn reset(&mut self) {
        self.reset_to(T::zero(), T::zero());
    }

    /// Starts from a known angle and speed.
    pub fn reset_to(&mut self, theta: T, omega: T) {
        self.state = self.params.state_at(theta, omega);
    }

    /// One sample with the measured angle θm (rad, any range). Returns (θ̂, ω̂).
    #[inline]
    pub fn step(&mut self, theta_measured: T) -> Result<(T, T), NonFiniteInput> {
        if !theta_measured.is_finite() {
            return Err(NonFiniteInput);
        }
        let next = self
            .params
            .next_state(&self.state, wrap_angle(theta_measured));
        self.state.commit(next);
        Ok((next.angle(), next.omega))
    }

    /// One sample without a measurement: θ̂ coasts at ω̂ and the integrator holds (used when
    /// |λ̂r| is too small for eq. (6) to mean anything, docs/method/estimator.md §4 \[A\]).
    #[inline]
    pub fn coast(&mut self) -> (T, T) {
        let next = self.params.coasted_state(&self.state);
        self.state.commit(next);
        (next.angle(), next.omega)
    }

    /// θ̂ for the last sample, in [−π, π].
    #[inline]
    pub fn angle(&self) -> T {
        self.state.angle()
    }

    /// θ̂⁻, the angle predicted for the next sample, in [−π, π].
    #[inline]
    pub fn predicted_angle(&self) -> T {
        T::angle_to(self.state.predicted)
    }

    /// ω̂ in rad/s.
    #[inline]
    pub fn speed(&self) -> T {
        self.state.omega
    }

    /// Kp in s⁻¹. The rate of θ̂ over a sample is ω̂ + Kp·e (θ̂⁻ advances by Ts·(ω̂ + Kp·e)):
    /// under a constant acceleration α it is the input's rate, while ω̂ lags it by Kp·α/Ki
    /// (see the module docs).
    #[inline]
    pub fn kp(&self) -> T {
        self.params.kp
    }

    /// (Kp, Ki) in use.
    pub fn gains(&self) -> (T, T) {
        (self.params.kp, self.params.ki_ts / self.params.ts)
    }
}

/// The tracker's state after a sample, computed before it is committed, with the sample's
/// phase error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TrackerUpdate<T: Real> {
    /// θ̂⁻ for the next sample.
    pub predicted: T::Angle,
    /// θ̂.
    pub theta: T::Angle,
    /// ω̂.
    pub omega: T,
    /// The phase error e = wrap(θm − θ̂⁻) of this sample in angle units (0 when coasting):
    /// × [`Real::angle_unit`] for radians.
    pub innovation: T,
    /// â after the sample, rad/s².
    pub load: T,
}

impl<T: Real> TrackerUpdate<T> {
    /// θ̂ in rad, in [−π, π].
    #[inline(always)]
    pub fn angle(&self) -> T {
        T::angle_to(self.theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    #[test]
    fn paper_bandwidths_give_spec_gains() {
        let t1 = TrackerConfig::<f64>::new(60.0, 100e-6);
        let (kp, ki) = t1.gains();
        assert!(
            (kp - 259.0).abs() < 0.5 && (ki - 33_551.0).abs() < 30.0,
            "{kp} {ki}"
        );
        let t2 = TrackerConfig {
            bandwidth_hz: 35.0,
            ..t1
        };
        let (kp, ki) = t2.gains();
        assert!(
            (kp - 151.0).abs() < 0.5 && (ki - 11_416.0).abs() < 15.0,
            "{kp} {ki}"
        );
    }

    #[test]
    fn minus_3db_point_is_at_the_bandwidth() {
        let c = TrackerConfig::<f64>::new(60.0, 100e-6);
        let (kp, ki) = c.gains();
        let w = 2.0 * PI * 60.0;
        // |T(jw)|² = (Ki² + Kp²w²)/((Ki − w²)² + Kp²w²)
        let t2 = (ki * ki + kp * kp * w * w) / ((ki - w * w).powi(2) + kp * kp * w * w);
        assert!((t2 - 0.5).abs() < 1e-9, "{t2}");
    }

    #[test]
    fn constant_speed_zero_error_and_wraps() {
        let mut t = TypeTwoTracker::new(TrackerConfig::<f64>::new(60.0, 100e-6)).unwrap();
        let w = -2.0 * PI * 20.0;
        let ts = 1e-4;
        let mut err = 1.0;
        for n in 0..20_000 {
            let th = wrap_angle(w * ts * n as f64);
            let (est, _) = t.step(th).unwrap();
            err = wrap_angle(th - est).abs();
            assert!(est.abs() <= PI + 1e-12);
        }
        assert!(err < 1e-9, "{err}");
        assert!((t.speed() - w).abs() < 1e-6);
    }

    #[test]
    fn speed_ramp_gives_constant_lag_alpha_over_ki() {
        // Type 2: a constant acceleration α leaves the constant angle error α/Ki and ω̂ tracks.
        let mut t = TypeTwoTracker::new(TrackerConfig::<f64>::new(60.0, 100e-6)).unwrap();
        let (_, ki) = t.gains();
        let ts = 1e-4;
        let alpha = 37.7; // 90 r/min/s, 4 pole pairs
        let w0 = -2.0 * PI * 6.0;
        let mut err = 0.0;
        for n in 0..40_000 {
            let tn = ts * n as f64;
            let th = w0 * tn + 0.5 * alpha * tn * tn;
            let (est, _) = t.step(wrap_angle(th)).unwrap();
            err = wrap_angle(th - est);
        }
        let tn = ts * 39_999.0;
        // α/Ki (the input at the last sample), plus the known half-sample offset of the
        // backward-rectangle integration, both tiny.
        assert!(
            (err - alpha / ki).abs() < 0.05 * alpha / ki + 1e-9,
            "{err} vs {}",
            alpha / ki
        );
        // ω̂ = xI lags by Kp·α/Ki (the proportional path carries the rest of the slope).
        let (kp, _) = t.gains();
        let lag = kp * alpha / ki;
        assert!(
            (t.speed() - (w0 + alpha * tn - lag)).abs() < 0.02,
            "{}",
            t.speed()
        );
        // The rate of θ̂, ω̂ + Kp·e (the advance of θ̂⁻ over one more sample, divided by Ts),
        // does not lag (what the estimator's observer lag compensation uses): within 1 % of
        // the lag, against the input's rate half a sample later (the trapezoid of θ̂⁻).
        let before = t.predicted_angle();
        let th = w0 * (tn + ts) + 0.5 * alpha * (tn + ts) * (tn + ts);
        t.step(wrap_angle(th)).unwrap();
        let rate = wrap_angle(t.predicted_angle() - before) / ts;
        assert!(
            (rate - (w0 + alpha * (tn + ts))).abs() < 0.01 * lag,
            "{rate} vs {}",
            w0 + alpha * (tn + ts)
        );
    }

    #[test]
    fn discrete_poles_match_formula() {
        // The map (θ̂⁻, ω̂) → (θ̂⁻⁺, ω̂⁺) with θm = 0 is linear: probe its matrix and check its
        // characteristic polynomial is z² − (2 − KpTs − KiTs²)z + (1 − KpTs).
        let c = TrackerConfig::<f64>::new(60.0, 100e-6);
        let (kp, ki) = c.gains();
        let ts = c.ts;
        let mut t = TypeTwoTracker::new(c).unwrap();
        let mut column = |th: f64, w: f64| {
            t.reset_to(th, w);
            t.step(0.0).unwrap();
            (t.predicted_angle(), t.speed())
        };
        let (m00, m10) = column(1e-3, 0.0);
        let (m01, m11) = column(0.0, 1.0);
        let (m00, m10) = (m00 / 1e-3, m10 / 1e-3);
        let trace = m00 + m11;
        let det = m00 * m11 - m01 * m10;
        assert!(
            (trace - (2.0 - kp * ts - ki * ts * ts)).abs() < 1e-12,
            "{trace}"
        );
        assert!((det - (1.0 - kp * ts)).abs() < 1e-12, "{det}");
    }

    #[test]
    fn f32_fixed_point_tracker_locks_and_wraps() {
        // The fixed-point angle arithmetic is the wrap of the float formula: differences and
        // steps across ±π, against f64, to the rounding of the f32 conversions (each rounds
        // x·2³²/2π to 24 bits: at most 1.9e-7 rad, an f32 half-ulp of π) and a unit each.
        let unit = 2.0 * PI / 4_294_967_296.0;
        for k in -200..=200 {
            let a = wrap_angle(k as f64 * 0.0157 * PI);
            for d in [-3.1, -1.0, -1e-3, -1e-7, 0.0, 2e-6, 0.3, 3.1] {
                let (af, df) = (a as f32, d as f32);
                let fa = <f32 as Real>::angle_from(af);
                let sum = <f32 as Real>::angle_to(<f32 as Real>::angle_add(fa, df)) as f64;
                let exact = wrap_angle(af as f64 + df as f64);
                let err = wrap_angle(sum - exact).abs();
                assert!(err <= 3.0 * unit + 5e-7, "{a} + {d}: {sum} vs {exact}");
                let fb = <f32 as Real>::angle_from(df);
                let diff = <f32 as Real>::angle_diff(fa, fb) as f64;
                let exact = wrap_angle(af as f64 - df as f64);
                assert!(
                    wrap_angle(diff - exact).abs() <= 3.0 * unit + 5e-7,
                    "{a} - {d}"
                );
                assert!(diff.abs() <= core::f32::consts::PI as f64);
            }
        }
        // The f32 tracker locks on a constant speed through thousands of ±π wraps, both
        // directions, as closely as the same recursion in f32 floats with `wrap_angle` (what
        // f32 ran before), over the last 2000 samples.
        for w in [
            -2.0 * PI * 700.0,
            -2.0 * PI * 20.0,
            2.0 * PI * 1.5,
            2.0 * PI * 400.0,
        ] {
            let mut t = TypeTwoTracker::new(TrackerConfig::<f32>::new(60.0, 100e-6)).unwrap();
            let (kp, ki) = t.gains();
            let ts = 1e-4_f32;
            let (kp_ts, ki_ts) = (ts * kp, ki * ts);
            let (mut predicted, mut omega) = (0.0_f32, 0.0_f32);
            let (mut err, mut err_float) = (0.0_f64, 0.0_f64);
            for n in 0..20_000 {
                let th = wrap_angle(w * 1e-4 * n as f64);
                let (est, _) = t.step(th as f32).unwrap();
                assert!(est.abs() <= core::f32::consts::PI);
                let e = wrap_angle(th as f32 - predicted);
                omega += ki_ts * e;
                let theta = wrap_angle(predicted + kp_ts * e);
                predicted = wrap_angle(theta + ts * omega);
                if n >= 18_000 {
                    err = err.max(wrap_angle(th - est as f64).abs());
                    err_float = err_float.max(wrap_angle(th - theta as f64).abs());
                }
            }
            // At speed f32's ω̂ sets both: its ulp (4.9e-4 rad/s at 700 Hz) leaves Ts·ω̂
            // off by up to half of it per sample, which the proportional path corrects.
            assert!(
                err <= 1.5 * err_float + 1e-7,
                "{w}: {err} vs float {err_float}"
            );
            assert!((t.speed() as f64 - w).abs() < 1e-2, "{w}: {}", t.speed());
        }
    }

    #[test]
    fn rejects_unstable_bandwidth() {
        let c = TrackerConfig {
            bandwidth_hz: 5_000.0,
            ..TrackerConfig::<f64>::new(60.0, 100e-6)
        };
        assert_eq!(TypeTwoTracker::new(c).unwrap_err().field(), "bandwidth_hz");
    }

    /// θ of a rotor accelerating at `alpha` from rest, sampled at `ts`.
    fn accelerating(alpha: f64, n: usize, ts: f64) -> f64 {
        let t = n as f64 * ts;
        0.5 * alpha * t * t
    }

    #[test]
    fn load_pole_zero_is_the_type_two_tracker() {
        let c = TrackerConfig::<f64>::new(60.0, 100e-6);
        let mut a = TypeTwoTracker::new(c).unwrap();
        let mut b = TypeTwoTracker::with_load_pole(c, 0.0).unwrap();
        assert_eq!(a.gains(), b.gains());
        for n in 0..2000 {
            let th = accelerating(3000.0, n, 1e-4);
            assert_eq!(a.step(th).unwrap(), b.step(th).unwrap());
        }
    }

    #[test]
    fn type_three_tracker_follows_a_constant_acceleration_without_error() {
        let (ts, alpha) = (1e-4, 3000.0); // rad/s²: the paper's motor at its current limit
        let c = TrackerConfig::<f64>::new(60.0, ts);
        let mut t2 = TypeTwoTracker::new(c).unwrap();
        let mut t3 = TypeTwoTracker::with_load_pole(c, 0.5).unwrap();
        let (mut e2, mut e3) = (0.0, 0.0);
        for n in 1..=10_000 {
            let th = accelerating(alpha, n, ts);
            e2 = wrap_angle(th - t2.step(th).unwrap().0);
            e3 = wrap_angle(th - t3.step(th).unwrap().0);
        }
        // Type 2: α/Ki (Ki = 33,551 s⁻²: 0.089 rad); type 3: none after 1 s.
        let (_, ki) = c.gains();
        assert!((e2 - alpha / ki).abs() < 0.05 * alpha / ki, "{e2}");
        assert!(e3.abs() < 1e-6, "{e3}");
    }

    #[test]
    fn acceleration_feed_forward_removes_the_transient_lag() {
        let (ts, alpha) = (1e-4, 3000.0);
        let c = TrackerConfig::<f64>::new(60.0, ts);
        let mut plain = TypeTwoTracker::with_load_pole(c, 0.5).unwrap();
        let mut fed = TypeTwoTracker::with_load_pole(c, 0.5).unwrap();
        fed.set_acceleration(alpha);
        let (mut worst_plain, mut worst_fed): (f64, f64) = (0.0, 0.0);
        for n in 1..=2000 {
            // The angle integrates the speed over each sample; the tracker's ω̂ advances by
            // Ts·α per sample as the rotor's does.
            let th = accelerating(alpha, n, ts);
            worst_plain = worst_plain.max(wrap_angle(th - plain.step(th).unwrap().0).abs());
            worst_fed = worst_fed.max(wrap_angle(th - fed.step(th).unwrap().0).abs());
        }
        assert!(worst_plain > 0.03, "{worst_plain}");
        // Only the discretisation of the ramp (half a sample of α·Ts) remains.
        assert!(worst_fed < 1e-3, "{worst_fed}");
        // A wrong feed-forward (Ĵ 30 % low, or a load) is a constant acceleration the third
        // integrator takes up: the error decays to zero.
        let mut off = TypeTwoTracker::with_load_pole(c, 0.5).unwrap();
        off.set_acceleration(1.3 * alpha);
        let mut e = 0.0;
        for n in 1..=20_000 {
            let th = accelerating(alpha, n, ts);
            e = wrap_angle(th - off.step(th).unwrap().0);
        }
        assert!(e.abs() < 1e-6, "{e}");
    }

    #[test]
    fn type_three_discrete_loop_is_stable_and_refuses_a_fast_pole() {
        let ts = 1e-4;
        let c = TrackerConfig::<f64>::new(60.0, ts);
        let mut t = TypeTwoTracker::with_load_pole(c, 0.5).unwrap();
        // Impulse response of the angle loop: a 0.1 rad step of the measurement settles.
        let mut e = 0.0;
        for _ in 0..5000 {
            e = 0.1 - t.step(0.1).unwrap().0;
        }
        assert!(e.abs() < 1e-9 && t.speed().abs() < 1e-6, "{e}");
        let fast = TrackerConfig::<f64>::new(800.0, ts);
        assert!(TypeTwoTracker::with_load_pole(fast, 4.0).is_err());
        assert!(TypeTwoTracker::with_load_pole(c, -1.0).is_err());
    }
}
