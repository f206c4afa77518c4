//! Online estimate of a constant integrand error ê (a stationary-frame voltage offset, beyond
//! the paper), learned while turning and subtracted from the flux integrand in both modes.
//!
//! Why: a constant error e in the voltage the estimator is given (a phase-voltage or DC-link
//! measurement offset, an inverter asymmetry, R̂s times a current-sensor offset) is a DC
//! integrand error. Turning, the disturbance observer takes it as the DC disturbance and the
//! k_df feedback balances it (D̂ → e/k_df, eq. (21)-(22)); but below the Fig. 3 threshold the
//! limiter mode has nothing against it: its radial part is clamped by the Fig. 6 circle, its
//! tangential part turns λ̂r at e_t/|λ̂r| (0.1 V on the paper's motor: 1.1 rad/s), so a
//! 0.1 V offset costs the Fig. 11 reversal over a radian.
//!
//! The error is observable while turning, where the observer separates the DC from the rotating
//! flux: with the integrand v − R̂s·i − k_df·D̂ − ê, the DC balance of λ1 (which D̂ tracks,
//! its observer poles being at |ω̂| ≫ the rates here) is dD̂/dt = e − ê − k_df·D̂, so
//! dD̂/dt + k_df·D̂ measures e − ê. The law
//!
//! ```text
//!   ê[n] = ê[n−1] + k_e·((D̂[n] − D̂[n−1]) + k_df·Ts·D̂[n])      (k_df mode, turning)
//! ```
//!
//! gives dê/dt = k_e·(e − ê): a first-order estimate of e at rate k_e, independent of k_df.
//! Seen from λ1 it is a PI disturbance feedback (k_df + k_e)·D̂ + k_e·k_df·∫D̂ whose DC loop
//! (s + k_df)(s + k_e) has two real poles — the integral action that drift-compensated flux
//! estimators add against offsets (Holtz & Quan, "Drift- and parameter-compensated flux
//! estimator for persistent zero-stator-frequency operation of sensorless-controlled
//! induction motors", IEEE TIA 39(4), 2003, estimate the offset vector from the flux
//! trajectory's centre the same way). At the rotating frequency D̂ does not respond, so the
//! paper's exact integration at ω (docs/method/estimator.md §2) is kept. In the limiter mode ê is held and still
//! subtracted: the offset learned at speed no longer walks the angle at standstill. What it
//! cannot know are DC errors that appear only at standstill (the dead-time residual and R̂s
//! errors times a current that is constant in α-β there); those are the limiter's, as before.
//!
//! **Only where an electrical revolution spans many samples.** An error that repeats with the
//! rotor's angle *and* with the carrier (the inverter's dead-time and ripple pattern, whose
//! shape depends on where each sample falls in the electrical period) is a constant in α-β
//! only on average over many revolutions; when the electrical frequency is a whole fraction
//! of the sampling frequency, f_s/f_e = N samples per revolution (or a ratio of small whole
//! numbers), the pattern stops sliding and its components of order N alias onto DC: a real
//! DC integrand error, but one of that speed alone. The law learns it at that speed and
//! carries it to standstill, where it turns θ̂ at ê/λ̂f, and R̂s drops what the start's
//! standstill test read of it (`crate::rs_adaptation`). Measured (fado-sim `fullrange`,
//! switching-resolved): a 10-pole 750 W servo held at 6,000 r/min with 20 kHz sampling
//! (N = 40) learns 0.15 V and R̂s falls by 15 %; a 4-pole spindle at 48,000 r/min with 40 kHz
//! sampling (N = 12.5, locked over two revolutions) raises R̂s by 10 %; 1 % off those speeds
//! nothing moves. An offset of the measurement chain is the same at every speed and is
//! learned at lower ones, and in the k_df mode the observer removes a DC error whatever ê
//! is: so the law learns only while |ω̂|·Ts ≤ 2π/[`MIN_REVOLUTION_SAMPLES`] and holds ê
//! above (`[estimator.offset_adaptation] min_revolution_samples`).
//!
//! |ê| is bounded by the back-EMF at the Fig. 3 threshold speed, λ̂f·2π·f_th: a larger offset
//! would make the limiter mode useless anyway, and the bound keeps a hand-over transient from
//! leaving a large ê behind.

use crate::error::{ConfigError, check};
use crate::mode;
use crate::{Ab, MachineModel, Real};

/// Default k_e in s⁻¹ ([`IntegrandOffsetConfig::rate`]): 2 (ours \[A\], see the field).
pub const DEFAULT_RATE: f64 = 2.0;

/// The fewest samples per electrical revolution at which the estimator's law learns ê (module
/// docs, "Only where an electrical revolution spans many samples"): 64 (ours \[A\]). Measured
/// on the locked speeds of `fullrange`: 40 (a 750 W servo at 6,000 r/min, 20 kHz) and 12.5
/// (a spindle at 48,000 r/min, 40 kHz) learn a DC that is not an offset; 48, 50 and 60 on the
/// servo learn none. 64 keeps a margin above the largest count seen to alias, and every
/// speed of the paper's profiles (fig8–fig12: at least 970 samples per revolution) below it.
pub const MIN_REVOLUTION_SAMPLES: f64 = 64.0;

/// Configuration of [`IntegrandOffset`].
///
/// No `Default`: the bound is the motor's. Build it with [`for_machine`](Self::for_machine)
/// (or [`new`](Self::new)); each field's "Default" is what they give.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegrandOffsetConfig<T> {
    /// Period of the law in s: the sampling period Ts if it runs every sample, N·Ts in the
    /// estimator, which runs it once every N samples (see `SensorlessEstimator`'s slow
    /// laws). No default: the caller's sampling period.
    pub ts: T,
    /// k_e in s⁻¹: the rate at which ê follows the integrand's DC error while turning, 0 = off.
    /// Default ([`DEFAULT_RATE`]) 2 s⁻¹ (ours \[A\]: ≈ 5 time constants within the 2.5 s the Fig. 11 profile
    /// turns before its reversal; well below the observer's |ω̂| ≥ 2π·1.3 rad/s in the k_df
    /// mode, so that D̂ tracks the DC of λ1 as the law assumes).
    pub rate: T,
    /// The law starts only after this long in the k_df mode without interruption, s: D̂
    /// re-converges after each hand-over with the observer's poles at |ω̂| (docs/method/estimator.md §2), and
    /// that transient is not an integrand error. Default 5/(2π·f_th), five observer
    /// time constants at the Fig. 3 threshold f_th (ours \[A\]; 0.53 s on the paper's motor,
    /// f_th = 1.5 Hz).
    pub settle_time: T,
    /// Bound of |ê| in V. Default λ̂f·2π·f_th, the back-EMF at the Fig. 3 threshold (0.83 V
    /// on the paper's motor).
    pub limit: T,
}

impl<T: Real> IntegrandOffsetConfig<T> {
    /// The law around `machine` with the default rate ([`DEFAULT_RATE`]) and the default
    /// Fig. 3 threshold ([`mode::DEFAULT_THRESHOLD_RATIO`]), run with period `ts`.
    pub fn for_machine(machine: &MachineModel<T>, ts: T) -> Self {
        Self::new(
            machine,
            T::lit(DEFAULT_RATE),
            T::lit(mode::DEFAULT_THRESHOLD_RATIO),
            ts,
        )
    }

    /// The law around `machine` learning at `rate` (s⁻¹), run with period `ts`, for the
    /// Fig. 3 threshold f_th = `threshold_ratio`·f_rated: `settle_time` 5/(2π·f_th) (five
    /// observer time constants at the threshold, ours \[A\]) and `limit` λ̂f·2π·f_th (the
    /// back-EMF at the threshold, module docs).
    pub fn new(machine: &MachineModel<T>, rate: T, threshold_ratio: T, ts: T) -> Self {
        let threshold_hz = threshold_ratio * machine.rated_frequency_hz();
        Self {
            ts,
            rate,
            settle_time: T::lit(5.0) / (T::two_pi() * threshold_hz),
            limit: machine.flux_linkage * T::two_pi() * threshold_hz,
        }
    }
}

/// State of the offset estimate after one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IntegrandOffsetState<T> {
    /// ê in V (α-β).
    pub offset: Ab<T>,
    /// D̂ of the last learning sample, Wb.
    pub disturbance_prev: Ab<T>,
    /// Samples in the learning regime without interruption (saturating).
    pub learning_samples: u32,
}

impl<T: Real> IntegrandOffsetState<T> {
    /// True when every field is finite.
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.offset.is_finite() && self.disturbance_prev.is_finite()
    }
}

/// The law's constants, precomputed once from an [`IntegrandOffsetConfig`] (the immutable
/// half of [`IntegrandOffset`]; its state is [`IntegrandOffsetState`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct IntegrandOffsetParams<T> {
    config: IntegrandOffsetConfig<T>,
    limit_sq: T,
    /// `settle_time` in samples (at least 1, so that `disturbance_prev` is valid).
    settle_samples: u32,
}

impl<T: Real> IntegrandOffsetParams<T> {
    /// Checks every field of `config` (the error names it).
    pub(crate) fn new(config: IntegrandOffsetConfig<T>) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", config.ts)?;
        let rate = check::non_negative("rate", config.rate)?;
        check::below("rate", rate * ts, T::one(), "with rate·ts below 1")?;
        let limit = check::non_negative("limit", config.limit)?;
        // A float-to-integer `as` saturates: an absurdly long wait is u32::MAX samples.
        let settle = check::non_negative("settle_time", config.settle_time)? / ts;
        Ok(Self {
            config,
            limit_sq: limit * limit,
            settle_samples: (settle.ceil().to_f64() as u32).max(1),
        })
    }

    /// The configuration the constants were computed from.
    pub(crate) fn config(&self) -> &IntegrandOffsetConfig<T> {
        &self.config
    }

    /// The state after one more period `ts` of the law: `disturbance` is D̂ now, `decay`
    /// what D̂ lost over the period besides its own dynamics, as a fraction of D̂ (the k_df
    /// feedback, k_df·ts, plus the estimator's common-mode shifts between two runs of the
    /// law, see below), `shift` the common-mode shift the estimator applies to λ1, the
    /// observer and D̂ now (D̂ afterwards is `disturbance − shift`), `learning` whether the
    /// law runs (the k_df mode, turning, throughout the period), `share` the share of the
    /// configured rate it learns at (1 but where a saturating model's frame coupling tapers it,
    /// `crate::active_flux::ActiveFlux::offset_rate_share`).
    ///
    /// Run once per sample (ts = the sampling period), `decay` = k_df·Ts. The estimator runs
    /// it once every N samples (ts = N·Ts, see `SensorlessEstimator`'s slow laws): then
    /// D̂ − D̂_prev telescopes over the N samples exactly, except for the N − 1 shifts
    /// k_e·Ts·D̂ applied in between, which `decay` adds back with the k_df term
    /// (k_df·N·Ts + (N − 1)·k_e·Ts, with D̂ now for the intermediate samples' D̂: the
    /// error is second order in the law's step k_e·N·Ts).
    #[inline]
    pub(crate) fn next_state(
        &self,
        st: &IntegrandOffsetState<T>,
        disturbance: Ab<T>,
        decay: T,
        shift: Ab<T>,
        learning: bool,
        share: T,
    ) -> IntegrandOffsetState<T> {
        let mut next = IntegrandOffsetState {
            offset: st.offset,
            disturbance_prev: disturbance - shift,
            learning_samples: if learning {
                st.learning_samples.saturating_add(1)
            } else {
                0
            },
        };
        if learning && st.learning_samples >= self.settle_samples && self.config.rate > T::zero() {
            let innovation = (disturbance - st.disturbance_prev) + disturbance * decay;
            let offset = st.offset + innovation * (self.config.rate * share);
            let n2 = offset.norm_squared();
            next.offset = if n2 > self.limit_sq {
                offset * (self.limit_sq / n2).step_sqrt()
            } else {
                offset
            };
        }
        next
    }
}

/// The law of the module docs: its constants and its state together.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegrandOffset<T> {
    params: IntegrandOffsetParams<T>,
    state: IntegrandOffsetState<T>,
}

impl<T: Real> IntegrandOffset<T> {
    /// Checks every field (the error names it) and starts at ê = 0.
    pub fn new(config: IntegrandOffsetConfig<T>) -> Result<Self, ConfigError> {
        Ok(Self {
            params: IntegrandOffsetParams::new(config)?,
            state: IntegrandOffsetState::default(),
        })
    }

    /// ê back to 0.
    pub fn reset(&mut self) {
        self.state = IntegrandOffsetState::default();
    }

    /// The state after one more period `ts` of the law, without changing this one (see
    /// the module docs; the arguments are those of the estimator's use, described there).
    #[inline]
    pub fn next_state(
        &self,
        disturbance: Ab<T>,
        decay: T,
        shift: Ab<T>,
        learning: bool,
    ) -> IntegrandOffsetState<T> {
        self.params
            .next_state(&self.state, disturbance, decay, shift, learning, T::one())
    }

    /// Takes a state computed by [`Self::next_state`] (which the caller checked is finite).
    #[inline]
    pub fn commit(&mut self, state: IntegrandOffsetState<T>) {
        self.state = state;
    }

    /// True once the k_df mode has lasted `settle_time` without interruption (D̂ and |λ̂r|
    /// are past the hand-over transient).
    #[inline]
    pub fn settled(&self) -> bool {
        self.state.learning_samples >= self.params.settle_samples
    }

    /// Samples in the k_df mode without interruption so far (saturating).
    #[inline]
    pub fn learning_samples(&self) -> u32 {
        self.state.learning_samples
    }

    /// ê now, V.
    #[inline]
    pub fn offset(&self) -> Ab<T> {
        self.state.offset
    }

    /// The configuration in use.
    pub fn config(&self) -> &IntegrandOffsetConfig<T> {
        self.params.config()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn follows_the_dc_balance_at_its_rate_and_is_bounded() {
        // A pure DC loop: dλ/dt = e − ê − k_df·λ, D̂ = λ. ê must reach e at rate k_e.
        let (ts, k_df, e) = (1e-4_f64, 0.5, Ab::new(0.1, -0.05));
        let mut law = IntegrandOffset::new(IntegrandOffsetConfig {
            settle_time: 0.0,
            ..IntegrandOffsetConfig::for_machine(&MachineModel::paper(), ts)
        })
        .unwrap();
        let mut lambda = Ab::zero();
        let n = (1.0 / ts) as usize;
        for _ in 0..n {
            lambda += (e - law.offset() - lambda * k_df) * ts;
            let s = law.next_state(lambda, k_df * ts, Ab::zero(), true);
            law.commit(s);
        }
        // After 1 s at k_e = 2 s⁻¹ the error is e^{−2} of e (to the Euler step).
        let left = (e - law.offset()).norm() / e.norm();
        assert!((left - (-2.0f64).exp()).abs() < 0.01, "{left}");
        // Run once every 4 samples with its period 4·ts (the estimator runs it every 8 with
        // 8·ts, the same construction), the same continuous-time rate: D̂ − D̂_prev
        // telescopes, k_df·4·ts·D̂ the decay.
        let mut slow = IntegrandOffset::new(IntegrandOffsetConfig {
            settle_time: 0.0,
            ..IntegrandOffsetConfig::for_machine(&MachineModel::paper(), 4.0 * ts)
        })
        .unwrap();
        let mut lambda = Ab::zero();
        for k in 0..n {
            lambda += (e - slow.offset() - lambda * k_df) * ts;
            if k % 4 == 3 {
                let s = slow.next_state(lambda, k_df * 4.0 * ts, Ab::zero(), true);
                slow.commit(s);
            }
        }
        let left_slow = (e - slow.offset()).norm() / e.norm();
        assert!(
            (left_slow - left).abs() < 0.005,
            "{left_slow} against {left}"
        );
        // Bounded: a huge error saturates at the limit.
        let s = law.next_state(Ab::new(1e3, 0.0), k_df * ts, Ab::zero(), true);
        assert!((s.offset.norm() - law.config().limit).abs() < 1e-12);
        // Not learning: held.
        let s = law.next_state(Ab::new(1e3, 0.0), k_df * ts, Ab::zero(), false);
        assert_eq!(s.offset, law.offset());
        assert!(
            IntegrandOffset::<f64>::new(IntegrandOffsetConfig {
                rate: -1.0,
                ..IntegrandOffsetConfig::for_machine(&MachineModel::paper(), 1e-4)
            })
            .is_err()
        );
    }
}
