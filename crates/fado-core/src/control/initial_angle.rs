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
//! then −V for n samples (the current back to about zero) and n samples, at least
//! [`MIN_REST_SAMPLES`], that return it to zero (a proportional current loop,
//! `RETURN_GAIN`), after one such pair along φ₁₁ that is not read. The rest is long enough
//! that each pulse starts from zero current: a pulse that started from its predecessor's
//! residual would take the residual's decay into its rise, and on a machine whose
//! resistance's drop is a large part of the pulse voltage (the multirotor preset: the pair
//! ends 7 A below zero after a 25 A peak) that error outweighs the saturation's first
//! harmonic and turns the angle with the rotor's position (up to 0.1 rad). The
//! rotor at rest, the current at the end of the +V pulse is
//! i_k ≈ V·t·u_kᵀ·L_inc⁻¹·u_k (u_k the unit vector of φ_k, L_inc the incremental inductance
//! along the path), and the block keeps the largest rise of the measured current's projection
//! on u_k during the pulse pair from its value before the pulse (the peak, wherever the
//! drive's computation delay puts it; the rise, so that what the rest leaves of the previous
//! pair cancels).
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
//! The twelve directions run twice, the second grid turned by 15° ([`GRIDS`]): the harmonics
//! below come from both pooled, and each grid on its own must agree ([`MAX_GRID_DISAGREEMENT`];
//! otherwise [`InitialAngleStatus::Inconsistent`]); the residual currents the pulses start
//! from must not move a rise by half the harmonic that decides (their decay, at most
//! r·n·Ts·R̂/L̂). A polarity the grids' first harmonics do not both point to, or that the
//! residuals could turn, is left to the polarity test ([`InitialAngleStatus::AxisOnly`]).
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

/// Directions of the pulses in each grid: every 30°.
pub const DIRECTIONS: usize = 12;

/// Grids of directions: k·30° and k·30° + 15°. Each gives the angle on its own; the two must
/// agree within [`MAX_GRID_DISAGREEMENT`].
pub const GRIDS: usize = 2;

/// Largest difference between the two grids' angles (rad; between their axes, modulo π, when
/// the axis decides) that the detection accepts \[A\]: 0.2 rad, five times the difference
/// the current sensor's noise and resolution leave on the multirotor preset (0.02–0.03 rad rms
/// per grid). The inverter's dead time and a residual current act on each grid differently
/// (a pulse along a phase's zero line keeps that phase in the dead-time band; the 15° grid has
/// none): where they, and not the rotor, make the harmonics, the grids disagree and the
/// detection says so ([`InitialAngleStatus::Inconsistent`]) rather than give their angle.
pub const MAX_GRID_DISAGREEMENT: f64 = 0.2;

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
    /// L̂ (H): the mean of L̂d and L̂q, for the return of the current to zero after a pair.
    pub inductance: T,
    /// R̂s (Ω): how much of a residual current at a pulse's start decays into its rise.
    pub resistance: T,
    /// Sampling period (s).
    pub ts: T,
}

/// Gain of the return to zero between pulse pairs, per sample: v = −RETURN_GAIN·(L̂/Ts)·i.
/// With the drive's one-sample computation delay the current follows
/// i[n+1] = i[n] − g·i[n−1], a double pole at 0.5 for g = 1/4 (no overshoot, the residual
/// halved every sample).
const RETURN_GAIN: f64 = 0.25;

/// Fewest samples of the rest after a pulse pair. Behind its one-sample delay the return to
/// zero (`RETURN_GAIN`) leaves (m + 1)·2⁻ᵐ of the current the pair ends with after m samples:
/// 0.6 % after 11. The pair ends with up to a quarter of its peak (the resistance's drop
/// slows the +V pulse's rise and speeds the −V pulse's fall: 7 A of 25 A on the 8 µH,
/// 30 mΩ multirotor preset), which a next pulse starting from it would read through its
/// decay as up to 3 % of its rise — twice the first harmonic that gives a surface-magnet
/// rotor's angle (1.5 % of the mean at the assumed saturation). After 11 samples it is
/// 0.15 % of the peak.
pub const MIN_REST_SAMPLES: u32 = 11;

/// Samples of a pulse pair and its rest for pulses of `n` samples: +V for n, −V for n, the
/// return to zero for n and at least [`MIN_REST_SAMPLES`]; as a non-zero divisor (no
/// division that can panic in the per-sample path).
pub(crate) fn pair_samples(n: u32) -> core::num::NonZeroU32 {
    let period = n.saturating_mul(2).saturating_add(n.max(MIN_REST_SAMPLES));
    core::num::NonZeroU32::new(period).unwrap_or(core::num::NonZeroU32::MIN)
}

/// The return of the current to zero between pulse pairs: v = −`RETURN_GAIN`·(L̂/Ts)·i
/// (a non-finite reading returns nothing).
pub(crate) fn return_voltage<T: Real>(i_ab: Ab<T>, inductance: T, ts: T) -> Ab<T> {
    let i = if i_ab.is_finite() { i_ab } else { Ab::zero() };
    i * (-T::lit(RETURN_GAIN) * inductance / ts)
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
    /// The two grids of directions give angles more than [`MAX_GRID_DISAGREEMENT`] apart:
    /// the harmonics come from the inverter (dead time) or the sensors, not from the rotor.
    Inconsistent,
}

/// The pulse sequence and its evaluation (module docs). Allocation-free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialAngle<T> {
    config: InitialAngleConfig<T>,
    /// Sample within the whole sequence.
    sample: u32,
    peaks: [[T; DIRECTIONS]; GRIDS],
    start: [[T; DIRECTIONS]; GRIDS],
    status: InitialAngleStatus,
    angle: T,
    /// a₁/m and a₂/m of the last evaluation.
    harmonics: (T, T),
    /// Each grid's angle (NaN where it gives none).
    grid_angles: [T; GRIDS],
}

impl<T: Real> InitialAngle<T> {
    /// A new detection, armed; every field is checked and a bad one named.
    pub fn new(config: InitialAngleConfig<T>) -> Result<Self, ConfigError> {
        check::positive("voltage", config.voltage)?;
        check::positive("inductance", config.inductance)?;
        check::non_negative("resistance", config.resistance)?;
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
            peaks: [[T::zero(); DIRECTIONS]; GRIDS],
            start: [[T::zero(); DIRECTIONS]; GRIDS],
            status: InitialAngleStatus::Running,
            angle: T::zero() / T::zero(),
            harmonics: (T::zero(), T::zero()),
            grid_angles: [T::zero() / T::zero(); GRIDS],
        })
    }

    /// Samples of the whole sequence.
    pub fn duration_samples(&self) -> u32 {
        pair_samples(self.config.pulse_samples).get() * SLOTS
    }

    /// Re-arms the detection.
    pub fn arm(&mut self) {
        self.sample = 0;
        self.peaks = [[T::zero(); DIRECTIONS]; GRIDS];
        self.status = InitialAngleStatus::Running;
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

    /// Each grid's angle (electrical rad; modulo π where the axis decides; NaN where the grid
    /// gives none): their difference against [`MAX_GRID_DISAGREEMENT`].
    pub fn grid_angles(&self) -> [T; GRIDS] {
        self.grid_angles
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
        // pulse then starts after a pair and its rest, as the first one does.
        let period = pair_samples(n);
        let slot = (self.sample / period) as usize;
        if slot >= SLOTS as usize {
            self.evaluate();
            return Ab::zero();
        }
        // Each grid: one pair along its last direction that is not read, then its twelve.
        let (grid, within) = (slot / (DIRECTIONS + 1), slot % (DIRECTIONS + 1));
        let k = (within + DIRECTIONS - 1) % DIRECTIONS;
        let phase = self.sample % period;
        let u = direction::<T>(k, grid, 1);
        // The peak over the pulse pair and the rest that follows (the computation delay).
        let along = u.dot(i_ab);
        let read = within > 0;
        if read && phase == 0 {
            // The current before the pulse acts (the computation delay): the rise is read
            // from it, so that what is left of the previous pulses cancels.
            self.start[grid][k] = along;
        }
        let rise = along - self.start[grid][k];
        if read && (rise > self.peaks[grid][k] || !rise.is_finite()) {
            self.peaks[grid][k] = rise;
        }
        self.sample += 1;
        let v = self.config.voltage;
        if phase < n {
            u * v
        } else if phase < 2 * n {
            u * (-v)
        } else {
            // The rest: the current back to zero (the resistance's drop leaves a residual
            // that would decay only with L/R).
            return_voltage(i_ab, self.config.inductance, self.config.ts)
        }
    }

    /// The harmonics of the peaks and the decision (module docs): both grids pooled, each
    /// grid's angle against the other's.
    fn evaluate(&mut self) {
        let pooled = Harmonics::of(&self.peaks, &[0, 1]);
        let Some((a1, a2)) = pooled.amplitudes() else {
            self.status = InitialAngleStatus::Implausible;
            return;
        };
        self.harmonics = (a1, a2);
        let grids = [
            Harmonics::of(&self.peaks, &[0]),
            Harmonics::of(&self.peaks, &[1]),
        ];
        let effect = self.residual_effect() / pooled.mean;
        let half = T::lit(0.5);
        let bound = T::lit(0.5 * MAX_GRID_DISAGREEMENT);
        let d_larger = self.config.d_larger;
        let (status, angle) = if a2 >= self.config.min_saliency {
            // The axis: each grid's within half the bound (modulo π), the residuals' effect
            // within half the harmonic.
            let axis = pooled.axis(d_larger);
            let mut ok = effect <= half * a2;
            for (g, one) in grids.iter().enumerate() {
                self.grid_angles[g] = one.axis(d_larger);
                ok &= angle_apart(self.grid_angles[g], axis, T::pi()) <= bound;
            }
            // Its polarity where every grid's first harmonic points the same way and the
            // residuals cannot turn it; otherwise the polarity test decides.
            let theta = pooled.angle(d_larger);
            let polarity = a1 >= self.config.min_polarity
                && effect <= half * a1
                && grids.iter().all(|one| one.points_along(theta));
            match (ok, polarity) {
                (false, _) => (InitialAngleStatus::Inconsistent, T::zero() / T::zero()),
                (true, true) => (InitialAngleStatus::Found, theta),
                (true, false) => (InitialAngleStatus::AxisOnly, axis),
            }
        } else if a1 >= self.config.min_polarity {
            let theta = pooled.polarity_angle();
            let mut ok = effect <= half * a1;
            for (g, one) in grids.iter().enumerate() {
                self.grid_angles[g] = one.polarity_angle();
                ok &= angle_apart(self.grid_angles[g], theta, T::lit(2.0) * T::pi()) <= bound;
            }
            if ok {
                (InitialAngleStatus::Found, theta)
            } else {
                (InitialAngleStatus::Inconsistent, T::zero() / T::zero())
            }
        } else {
            (InitialAngleStatus::NoInformation, T::zero() / T::zero())
        };
        self.status = status;
        self.angle = angle;
    }

    /// The largest change a residual current at a pulse's start can make to its rise (A): a
    /// residual r decays by up to r·n·Ts·R̂/L̂ over the pulse (where the return could not
    /// bring it to zero: the dead-time band holds it).
    fn residual_effect(&self) -> T {
        let n = T::lit(self.config.pulse_samples as f64);
        let decay = (n * self.config.ts * self.config.resistance / self.config.inductance)
            .step_min(T::one());
        let mut residual = T::zero();
        for start in self.start.iter().flatten() {
            residual = residual.step_max(start.abs());
        }
        residual * decay
    }
}

/// |a − b| for angles known modulo `period` (2π, or π for an axis).
fn angle_apart<T: Real>(a: T, b: T, period: T) -> T {
    let scale = T::lit(2.0) * T::pi() / period;
    let d = (crate::wrap_angle((a - b) * scale) / scale).abs();
    if d.is_finite() { d } else { T::pi() }
}

/// The mean and the first two harmonics of the peaks of some grids (module docs).
struct Harmonics<T> {
    mean: T,
    h1: Ab<T>,
    h2: Ab<T>,
}

impl<T: Real> Harmonics<T> {
    fn of(peaks: &[[T; DIRECTIONS]; GRIDS], grids: &[usize]) -> Self {
        let (mut mean, mut h1, mut h2) = (T::zero(), Ab::<T>::zero(), Ab::<T>::zero());
        let mut readings = 0;
        // `get` rather than indexing: no bounds-check panic in the firmware's step.
        for (g, row) in grids.iter().filter_map(|&g| Some((g, peaks.get(g)?))) {
            for (k, &p) in row.iter().enumerate() {
                mean += p;
                h1 += direction::<T>(k, g, 1) * p;
                h2 += direction::<T>(k, g, 2) * p;
                readings += 1;
            }
        }
        let scale = T::one() / T::from_index(readings.max(1));
        Self {
            mean: mean * scale,
            h1: h1 * (scale * T::lit(2.0)),
            h2: h2 * (scale * T::lit(2.0)),
        }
    }

    /// (a₁/m, a₂/m), None for a non-finite or non-positive reading.
    fn amplitudes(&self) -> Option<(T, T)> {
        let (a1, a2) = (self.h1.norm(), self.h2.norm());
        (self.mean > T::zero() && a1.is_finite() && a2.is_finite())
            .then(|| (a1 / self.mean, a2 / self.mean))
    }

    /// The first harmonic's angle: the magnet's polarity alone.
    fn polarity_angle(&self) -> T {
        self.h1.beta.step_atan2(self.h1.alpha)
    }

    /// The second harmonic's axis (modulo π), turned by π/2 where the model's L̂d > L̂q.
    fn axis(&self, d_larger: bool) -> T {
        let mut theta2 = T::lit(0.5) * self.h2.beta.step_atan2(self.h2.alpha);
        if d_larger {
            theta2 += T::lit(core::f64::consts::FRAC_PI_2);
        }
        crate::wrap_angle(theta2)
    }

    /// The first harmonic points along `theta` (not against it).
    fn points_along(&self, theta: T) -> bool {
        let (s, c) = theta.step_sin_cos_any();
        self.h1.alpha * c + self.h1.beta * s >= T::zero()
    }

    /// The axis with the polarity the first harmonic points at.
    fn angle(&self, d_larger: bool) -> T {
        let theta2 = self.axis(d_larger);
        if self.points_along(theta2) {
            theta2
        } else {
            crate::wrap_angle(theta2 + T::pi())
        }
    }
}

/// Pulse pairs of the whole sequence: each grid's twelve and its unread first.
const SLOTS: u32 = (GRIDS * (DIRECTIONS + 1)) as u32;

/// The unit vector at `harmonic` × the direction k·π/6 + grid·π/12.
fn direction<T: Real>(k: usize, grid: usize, harmonic: usize) -> Ab<T> {
    let phi = T::lit((2 * k + grid) as f64) * T::pi() / T::lit(12.0);
    let (s, c) = (phi * T::lit(harmonic as f64)).step_sin_cos_any();
    Ab::new(c, s)
}

#[cfg(test)]
pub(crate) mod tests;
