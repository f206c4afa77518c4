//! The rotor angle at standstill without motion: voltage pulses in twelve directions, the
//! current each one reaches read as an inductance, the magnet's axis from the inductance's
//! second harmonic (saliency) and its polarity from the first (d-axis saturation).
//!
//! # Why
//! A start-up that aligns the rotor with a d current turns it; under a load or a brake it
//! cannot. At standstill the back-EMF is zero and only the inductance sees the rotor: on a
//! salient rotor it varies with the angle, and on any rotor a current that adds to the
//! magnet's flux saturates the d-axis iron, one that opposes it relieves it (the polarity
//! tests of drives: TI's IPD, ST's polarity detection).
//!
//! # The measurement
//! For each direction φ_k = k·π/6 (k = 0 … 11) a voltage pulse +V along φ_k for n samples,
//! then −V for n samples (the current back to about zero) and n samples that return it to
//! zero (a proportional loop on the current predicted past the computation delay,
//! `return_voltage`),
//! after one such pair along φ₁₁ that is not read (each read pair then starts from its
//! predecessor's residual current, 30° behind, the first one included). The
//! rotor at rest, the current at the end of the +V pulse is
//! i_k ≈ V·t·u_kᵀ·L_inc⁻¹·u_k (u_k the unit vector of φ_k, L_inc the incremental inductance
//! along the path), and the block keeps the largest rise of the measured current's projection
//! on u_k during the pulse pair from its value before the pulse (the peak, wherever the
//! drive's computation delay puts it; the rise, because after a pulse pair the resistance's
//! drop leaves a residual current that decays only with L/R).
//! With Γ = L_inc⁻¹ in the rotor frame (d at angle θ),
//!
//! u_kᵀ·Γ·u_k = (Γd + Γq)/2 + (Γd − Γq)/2·cos 2(φ_k − θ),
//!
//! so the second harmonic of i_k is at 2θ (Γd > Γq: Ld < Lq, or a d axis saturated by the
//! magnet), which gives θ modulo π. The pulse along +d adds to the magnet's flux and meets a
//! smaller incremental inductance than the one along −d (on a machine whose d axis
//! saturates): the first harmonic of i_k points at the magnet, which resolves the N/S
//! ambiguity and, alone, gives the angle of a rotor with no saliency.
//!
//! # Decision
//! With m the mean of i_k and a₁, a₂ the amplitudes of the first and second harmonics
//! (2/12·|Σ i_k·e^(−jnφ_k)|): the axis is known when a₂/m ≥ `min_saliency`, the polarity when
//! a₁/m ≥ `min_polarity`. Both: θ = the axis angle turned by π when the first harmonic points
//! the other way ([`InitialAngleStatus::Found`]); the polarity only: θ = the first harmonic's
//! angle ([`InitialAngleStatus::Found`]); the axis only: [`InitialAngleStatus::AxisOnly`] (θ
//! modulo π: the drive may align only a rotor free to turn); neither:
//! [`InitialAngleStatus::NoInformation`]. A machine model with L̂d > L̂q turns the axis by
//! π/2 (the second harmonic then points at q).

use crate::error::{ConfigError, check};
use crate::{Ab, Real};

/// Directions of the pulses: every 30°.
pub const DIRECTIONS: usize = 12;

/// Default `min_saliency` \[A\]: a second harmonic of 2 % of the mean, ten times the spread of
/// the peak readings of a sensor of 0.3 % of the pulse's current (noise and resolution),
/// averaged over the twelve directions.
pub const DEFAULT_MIN_SALIENCY: f64 = 0.02;
/// Default `min_polarity` \[A\]: a first harmonic of 1 % of the mean (half of the saliency's
/// threshold: it decides a sign, not an angle).
pub const DEFAULT_MIN_POLARITY: f64 = 0.01;

/// Configuration of an [`InitialAngle`] detection, in absolute units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialAngleConfig<T> {
    /// Pulse voltage V (V, α-β amplitude).
    pub voltage: T,
    /// Samples of each pulse (+V, then −V, then rest), ≥ 1.
    pub pulse_samples: u32,
    /// Smallest a₂/m that gives the axis, in (0, 1).
    pub min_saliency: T,
    /// Smallest a₁/m that gives the polarity, in (0, 1).
    pub min_polarity: T,
    /// The machine model's L̂d > L̂q (the second harmonic then points at q).
    pub d_larger: bool,
    /// L̂ (H) of the return of the current to zero after a pair: √(L̂d·L̂q) from the drive
    /// (`RETURN_GAIN`'s loop then stays damped along both axes).
    pub inductance: T,
    /// Sampling period (s).
    pub ts: T,
}

/// Gain of the return to zero between pulse pairs, per sample, on the current predicted
/// past the voltage still pending ([`return_voltage`]). 1/2 \[A\]: the residual halved every
/// sample (poles 0 and 1 − g with the model's inductance), the loop stable for a true
/// inductance down to a third of L̂ (z² + (g − 1)·z + g·(L̂/L − 1) = 0). With L̂ = √(L̂d·L̂q)
/// the slowest pole along either axis is 0.84 at L̂q = 5·L̂d (the Baldor PM-SyRM) and 0.5 on a
/// round rotor.
const RETURN_GAIN: f64 = 0.5;

/// The voltage that returns the current to zero after a pulse pair: v = −g·(L̂/Ts)·î with
/// î = i + (Ts/L̂)·`pending`, the current once the voltage commanded at the last sample has
/// acted (the drive's one-sample computation delay). A loop on the measured current alone
/// first sees the pair's last −V pulse as not yet applied (a residual of one sample's
/// current step, V·Ts/L, the whole pulse current over `pulse_samples`), drives the current
/// past zero by a quarter of that step and leaves it to the next pair's start: on a
/// multirotor motor with three-sample pulses 3 A of 34 A, a residual that depends on the
/// direction before (its inductance) and turns the first harmonic by up to 0.08 rad.
pub(crate) fn return_voltage<T: Real>(i_ab: Ab<T>, pending: Ab<T>, inductance: T, ts: T) -> Ab<T> {
    let i = if i_ab.is_finite() { i_ab } else { Ab::zero() };
    let predicted = i + pending * (ts / inductance);
    predicted * (-T::lit(RETURN_GAIN) * inductance / ts)
}

/// Where the detection stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InitialAngleStatus {
    /// Armed or applying its pulses.
    Running,
    /// The angle is known: axis and polarity (or polarity alone).
    Found,
    /// The axis is known, its polarity not (θ modulo π).
    AxisOnly,
    /// The machine shows no angle at standstill at this pulse: no saliency, no saturation.
    NoInformation,
    /// A non-finite or zero reading: nothing decided.
    Implausible,
}

/// The pulse sequence and its evaluation (module docs). Allocation-free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialAngle<T> {
    config: InitialAngleConfig<T>,
    /// Sample within the whole sequence.
    sample: u32,
    peaks: [T; DIRECTIONS],
    start: [T; DIRECTIONS],
    status: InitialAngleStatus,
    angle: T,
    /// a₁/m and a₂/m of the last evaluation.
    harmonics: (T, T),
    /// The voltage returned at the last sample (acting over the next period).
    pending: Ab<T>,
}

impl<T: Real> InitialAngle<T> {
    /// A new detection, armed; every field is checked and a bad one named.
    pub fn new(config: InitialAngleConfig<T>) -> Result<Self, ConfigError> {
        check::positive("voltage", config.voltage)?;
        check::positive("inductance", config.inductance)?;
        check::positive("ts", config.ts)?;
        if config.pulse_samples == 0 {
            return Err(ConfigError::OutOfRange {
                field: "pulse_samples",
                expected: "at least 1",
            });
        }
        for (field, x) in [
            ("min_saliency", config.min_saliency),
            ("min_polarity", config.min_polarity),
        ] {
            check::below(field, check::positive(field, x)?, T::one(), "in (0, 1)")?;
        }
        Ok(Self {
            config,
            sample: 0,
            peaks: [T::zero(); DIRECTIONS],
            start: [T::zero(); DIRECTIONS],
            status: InitialAngleStatus::Running,
            angle: T::zero() / T::zero(),
            harmonics: (T::zero(), T::zero()),
            pending: Ab::zero(),
        })
    }

    /// Samples of the whole sequence.
    pub fn duration_samples(&self) -> u32 {
        3 * self.config.pulse_samples * (DIRECTIONS as u32 + 1)
    }

    /// Re-arms the detection.
    pub fn arm(&mut self) {
        self.sample = 0;
        self.peaks = [T::zero(); DIRECTIONS];
        self.status = InitialAngleStatus::Running;
        self.pending = Ab::zero();
    }

    /// Applying pulses.
    pub fn running(&self) -> bool {
        self.status == InitialAngleStatus::Running
    }

    /// The status.
    pub fn status(&self) -> InitialAngleStatus {
        self.status
    }

    /// The detected angle (electrical rad, in (−π, π]; modulo π with `AxisOnly`), NaN otherwise.
    pub fn angle(&self) -> T {
        self.angle
    }

    /// (a₁/m, a₂/m) of the last evaluation: the margins against the thresholds.
    pub fn harmonics(&self) -> (T, T) {
        self.harmonics
    }

    /// One sample: `i_ab` the current measured now (offsets removed). Returns the α-β voltage
    /// to apply (zero once the sequence has ended).
    pub fn step(&mut self, i_ab: Ab<T>) -> Ab<T> {
        if self.status != InitialAngleStatus::Running {
            return Ab::zero();
        }
        let n = self.config.pulse_samples;
        // Slot 0 is a pulse pair along the last direction that is not read: every read
        // pulse then starts from the residual current of the one before it, 30° behind
        // (after a pair the current is not quite zero: the resistance's drop).
        // The pair's length as a non-zero divisor (`new` refuses 0 samples): no division
        // that can panic in the per-sample path.
        let period =
            core::num::NonZeroU32::new(n.saturating_mul(3)).unwrap_or(core::num::NonZeroU32::MIN);
        let slot = (self.sample / period) as usize;
        if slot > DIRECTIONS {
            self.evaluate();
            return Ab::zero();
        }
        let k = (slot + DIRECTIONS - 1) % DIRECTIONS;
        let phase = self.sample % period;
        let u = direction::<T>(k);
        // The peak over the pulse pair and the rest that follows (the computation delay).
        let along = u.dot(i_ab);
        if slot > 0 && phase == 0 {
            // The current before the pulse acts (the computation delay): the rise is read
            // from it, so that what is left of the previous pulses cancels.
            self.start[k] = along;
        }
        let rise = along - self.start[k];
        if slot > 0 && (rise > self.peaks[k] || !rise.is_finite()) {
            self.peaks[k] = rise;
        }
        self.sample += 1;
        let v = self.config.voltage;
        self.pending = if phase < n {
            u * v
        } else if phase < 2 * n {
            u * (-v)
        } else {
            // The rest: the current back to zero (the resistance's drop leaves a residual
            // that would decay only with L/R).
            let c = &self.config;
            return_voltage(i_ab, self.pending, c.inductance, c.ts)
        };
        self.pending
    }

    /// The harmonics of the peaks and the decision (module docs).
    fn evaluate(&mut self) {
        let mut mean = T::zero();
        let (mut h1, mut h2) = (Ab::<T>::zero(), Ab::<T>::zero());
        for (k, &p) in self.peaks.iter().enumerate() {
            mean += p;
            h1 += direction::<T>(k) * p;
            h2 += direction::<T>(2 * k) * p;
        }
        let scale = T::one() / T::lit(DIRECTIONS as f64);
        mean *= scale;
        let (a1, a2) = (
            h1.norm() * scale * T::lit(2.0),
            h2.norm() * scale * T::lit(2.0),
        );
        if !(mean > T::zero() && a1.is_finite() && a2.is_finite()) {
            self.status = InitialAngleStatus::Implausible;
            return;
        }
        self.harmonics = (a1 / mean, a2 / mean);
        let polarity = a1 >= self.config.min_polarity * mean;
        let axis = a2 >= self.config.min_saliency * mean;
        let theta1 = h1.beta.step_atan2(h1.alpha);
        let mut theta2 = T::lit(0.5) * h2.beta.step_atan2(h2.alpha);
        if self.config.d_larger {
            theta2 += T::lit(core::f64::consts::FRAC_PI_2);
        }
        let (status, angle) = match (axis, polarity) {
            (true, true) => {
                let (s, c) = theta2.step_sin_cos_any();
                let theta = if h1.alpha * c + h1.beta * s >= T::zero() {
                    theta2
                } else {
                    theta2 + T::pi()
                };
                (InitialAngleStatus::Found, crate::wrap_angle(theta))
            }
            (false, true) => (InitialAngleStatus::Found, theta1),
            (true, false) => (InitialAngleStatus::AxisOnly, crate::wrap_angle(theta2)),
            (false, false) => (InitialAngleStatus::NoInformation, T::zero() / T::zero()),
        };
        self.status = status;
        self.angle = angle;
    }
}

/// The unit vector at k·π/6.
fn direction<T: Real>(k: usize) -> Ab<T> {
    let (s, c) = (T::lit(k as f64) * T::pi() / T::lit(6.0)).step_sin_cos_any();
    Ab::new(c, s)
}

#[cfg(test)]
pub(crate) mod tests;
