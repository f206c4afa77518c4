//! The start-up's angle phase: where the rotor is before the first current that makes torque.
//!
//! # Why
//! A drive that starts from an assumed angle (or aligns the rotor with a d current) turns a
//! loaded or braked rotor, or starts with θ̂ wrong by up to π. The phase finds the angle at
//! standstill without motion ([`initial_angle`](crate::control::initial_angle): pulse pairs in
//! twelve directions), and where the pulses give the axis but not the magnet's polarity, a
//! dedicated polarity test along that axis with a larger current (the d-axis saturation: a
//! current that adds to the magnet's flux meets the smaller incremental inductance). What it
//! cannot find it says ([`StartupStatus::NoAngle`]): the drive then stays off, or — only when
//! the application declares the rotor free to turn ([`StartupTuning::free_rotor_align`]) —
//! aligns it with a d current in two steps (a quarter turn apart, so that neither step can sit
//! at the unstable equilibrium). The drive never starts from a guessed angle.
//!
//! # Sequence
//! After the offset calibration (gates off) and before the gain calibration (which then holds
//! its d current along the angle found):
//! 1. search: [`InitialAngle`] with pulses that reach `pulse_current_ratio` × the rated current
//!    along the smaller inductance (0.75 or 0.5 of it on a saturating model whose d and q
//!    inductances meet near that current: [`pulse_current_share`]), each at most `pulse_voltage_ratio` × the largest
//!    sinusoidal voltage V_dc/√3 (longer pulses when the DC link is low);
//! 2. polarity test (status `AxisOnly` only): [`POLARITY_PAIRS`] pulse pairs along +axis and
//!    as many along −axis with `polarity_current_ratio` × the rated current; the direction
//!    whose current rises faster is the magnet's (a relative difference of at least
//!    [`DEFAULT_MIN_POLARITY`]);
//! 3. the result: `Found` → the drive starts from the angle; otherwise the free-rotor
//!    alignment or [`StartupStatus::NoAngle`].

mod motion;
mod polarity;
#[cfg(test)]
mod tests;

pub use motion::{MotionMonitor, READ_CURRENT_RATIO, RECENT_WINDOW_TIME};
pub use polarity::PolarityTest;

use crate::control::gain_calibration::GainCalibration;
use crate::control::initial_angle::{
    DEFAULT_MIN_POLARITY, DEFAULT_MIN_SALIENCY, InitialAngle, InitialAngleConfig,
    InitialAngleStatus,
};
use crate::error::{ConfigError, check};
use crate::magnetics::MagneticModel;
use crate::real::cast_record;
use crate::{Ab, Dq, MachineModel, Real};

/// Pulse pairs per direction of the polarity test (the relative difference of the two sums
/// is averaged over four pairs: its noise halves against one pair).
pub const POLARITY_PAIRS: u32 = 4;

/// Largest share of the gain calibration's current a held rotor's saliency may drive across a
/// turned axis ([`AngleSearch::gain_axis`]). 0.2 \[A\]: the 2.2 kW IPMSM (share 0.13 at its
/// seed-2 angle) is calibrated; the Baldor PM-SyRM (0.51) reads it as motion.
const MAX_CROSS_SHARE: f64 = 0.2;

/// Largest share of the gain calibration's current across a turned axis at which a held rotor
/// whose d axis is observed (some phase between `min_observability` and half the current)
/// still turns to the nearest k·π/3, where every phase carries at least half: 0.002 \[A\].
/// The current across the axis biases k by about half its share (measured on the 50 kW
/// IPMSM at 1.0 rad, 5 % across π/3: k off by 2.4e-2 against a 5e-3 mismatch; at 11–18 % a
/// 32-pole torque IPMSM and the 50 kW IPMSM lose their loaded start at seed 4): every round
/// rotor turns (nothing crosses), a salient one only within a fraction of a degree of the
/// axis, where d carries half the current in every phase anyway. The k of a phase at a fifth of the current misses the 5 %
/// plausibility bound on the 50 W flat motor of `crates/fado-sim/tests/data/unseen/`
/// (`loaded-start` seed 1, 0.74 rad: phase b at 0.217, `Implausible`), and its uncalibrated
/// 0.5 % mismatch walks θ̂ 0.34 rad from the rotor after the release; along π/3 it is
/// calibrated, 0.095 rad.
const CROSS_FREE_SHARE: f64 = 0.002;

/// Fewest samples of a pulse: the drive's computation delay puts the current's peak one
/// sample after the pulse's end; with three samples the rise is mostly inductive.
const MIN_PULSE_SAMPLES: usize = 3;

/// `[controller.startup]`: how the drive finds the rotor's angle before it starts (module
/// docs).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(
        deny_unknown_fields,
        default,
        bound(
            serialize = "T: serde::Serialize",
            deserialize = "T: Real + serde::Deserialize<'de>"
        )
    )
)]
pub struct StartupTuning<T> {
    /// Find the rotor's angle at standstill (this module) instead of starting from the angle
    /// given to [`align`](crate::control::SensorlessDrive::align), which is then ignored.
    /// Default false: the drive starts from the angle it is given (a known or sensed angle,
    /// the paper's figures).
    pub find_angle: bool,
    /// Peak current of the search's pulses along the smaller inductance, a multiple of the
    /// rated current. Default 1 \[A\]: a d-axis saturation shows at the currents the machine
    /// is built for (the paper's motor: 22 A gives a first harmonic of 2–9 % of the mean at
    /// half to double the assumed saturation, `initial_angle`'s tests).
    pub pulse_current_ratio: T,
    /// Largest pulse voltage as a fraction of V_dc/√3. Default 0.5 \[A\]: half the linear
    /// range, leaving room for the dead-time compensation; a pulse that would need more is
    /// made longer.
    pub pulse_voltage_ratio: T,
    /// Peak current of the polarity test, a multiple of the rated current. Default 1.5 \[A\]:
    /// deeper into the saturation than the search, below the default current limit (1.84).
    pub polarity_current_ratio: T,
    /// With no angle information, align the rotor with a d current: only for a rotor free to
    /// turn (no load, no brake). Default false: the drive stays off and says so.
    pub free_rotor_align: bool,
    /// A brake holds the rotor through the whole start-up (the application releases it only
    /// once the drive is ready): the gain calibration may then run along an axis other than
    /// the rotor's d axis, whose torque the brake takes — the nearest of the six axes k·π/3
    /// (every phase carrying at least half the current) where the d axis leaves a phase with
    /// too little (`gain_calibration_min_observability`) or where no more than 0.2 % of the
    /// level crosses that axis (a round rotor), or the rotor's q axis where a
    /// salient rotor would drive too much of the level across that axis (each level then
    /// held for L̂q's settling, 5·L̂q/R̂s, at most 0.2 s: beyond, k only). The start-up then
    /// leaves the
    /// release hold unarmed: the application arms it as it opens the brake
    /// ([`SensorlessDrive::arm_release_hold`](crate::control::SensorlessDrive::arm_release_hold)).
    /// Default false: a rotor that no brake holds is turned by any current off its d axis.
    pub rotor_held: bool,
    /// d current of the free-rotor alignment, a multiple of the rated current. Default 0.5
    /// \[A\]: half the rated torque's stiffness turns an unloaded rotor.
    pub align_current_ratio: T,
    /// Duration of each of the alignment's two steps (s). Default 0.25 s \[A\].
    pub align_time: T,
    /// Travel of the rotor (electrical rad) that the start-up reads as motion during the
    /// offset calibration and the angle search ([`MotionMonitor`]); the start-up then defers
    /// ([`StartupStatus::RotorMoving`]). Default 0.05 rad \[A\]: a tenth of the
    /// `loaded-start` bound on the backward travel, ten times the monitor's reading on the
    /// presets at rest. The monitor raises it to what its quiet current alone reads,
    /// L̂·0.1·I_rated/λ̂f, where that is larger ([`MotionMonitor::threshold`]).
    pub motion_travel: T,
    /// How long the rotor has to stay still, the phases shorted, before a deferred start-up
    /// begins again (s). Default 0.1 s \[A\]: the default offset calibration's time.
    pub quiet_time: T,
}

impl<T: Real> Default for StartupTuning<T> {
    fn default() -> Self {
        Self {
            find_angle: false,
            pulse_current_ratio: T::one(),
            pulse_voltage_ratio: T::lit(0.5),
            polarity_current_ratio: T::lit(1.5),
            free_rotor_align: false,
            rotor_held: false,
            align_current_ratio: T::lit(0.5),
            align_time: T::lit(0.25),
            motion_travel: T::lit(0.05),
            quiet_time: T::lit(0.1),
        }
    }
}

impl<T: Real> StartupTuning<T> {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        check::positive("startup.pulse_current_ratio", self.pulse_current_ratio)?;
        check::below(
            "startup.pulse_voltage_ratio",
            check::positive("startup.pulse_voltage_ratio", self.pulse_voltage_ratio)?,
            T::lit(1.0 + 1e-9),
            "in (0, 1]",
        )?;
        check::positive(
            "startup.polarity_current_ratio",
            self.polarity_current_ratio,
        )?;
        check::positive("startup.align_current_ratio", self.align_current_ratio)?;
        check::non_negative("startup.align_time", self.align_time)?;
        check::positive("startup.motion_travel", self.motion_travel)?;
        check::positive("startup.quiet_time", self.quiet_time)?;
        Ok(())
    }
}

cast_record!(StartupTuning {
    pulse_current_ratio, pulse_voltage_ratio, polarity_current_ratio, align_current_ratio,
    align_time, motion_travel, quiet_time ; find_angle, free_rotor_align, rotor_held
});

/// Whether the drive's magnetic model meets a larger incremental d inductance along +d (with
/// the magnet) than along −d over the pulse's path from 0 to `current`: then the faster rise
/// points against the magnet (a PM-assisted synchronous reluctance rotor whose bridges the
/// magnet saturates and a negative d current relieves). A constant-inductance model gives no
/// sign: false, the usual case of a magnet rotor whose d-axis iron saturates further with
/// the magnet's flux (the polarity tests of drives, `initial_angle`'s module docs).
pub fn inverted_polarity<T: Real>(machine: &MachineModel<T>, current: T) -> bool {
    if machine.magnetics.is_linear() || !current.is_finite() || current <= T::zero() {
        return false;
    }
    let m = machine.magnetic_model();
    let (mut plus, mut minus) = (T::zero(), T::zero());
    for k in 1..=4 {
        let i = current * T::from_index(k) * T::lit(0.25);
        plus += m.incremental_inductance(Dq::new(i, T::zero())).dd;
        minus += m.incremental_inductance(Dq::new(-i, T::zero())).dd;
    }
    plus > minus
}

/// Whether the pulses that reach `current` along the smaller small-signal inductance meet a
/// larger inductance along d than along q: the model's L̂d > L̂q for constant inductances; for
/// a saturating model (a flux map) the secant inductances along ±d and ±q over the current
/// each axis reaches with the pulses' flux L̂min·`current`, which the search's second
/// harmonic reads (a measured map may turn the order of the small-signal values).
pub fn d_axis_larger<T: Real>(machine: &MachineModel<T>, current: T) -> bool {
    match axis_secants(machine, current) {
        Some((d, q)) => d > q,
        None => machine.ld > machine.lq,
    }
}

/// Smallest relative difference |L̂d,s − L̂q,s| / (L̂d,s + L̂q,s) of the secant inductances
/// of [`d_axis_larger`] (the second harmonic the model predicts, per unit of the mean) at
/// which the search pulses at its configured current: 0.05 \[A\], 2.5 × the search's
/// `min_saliency`. Closer, the model's order of the two axes is the order the machine turns
/// at that current, and a model slightly off (or the pulses' own resistance drop and cross
/// terms) reads the axis π/2 off: a drawn 127 W IPMSM of `crates/fado-sim/tests/data/drawn/`
/// (q saturating to the d inductance at its rated current: 0.022) found its angle 1.52 rad
/// off at seeds 1 and 2 and ran 70 rad backwards under its load; at 0.75 of that current
/// (−0.113) the angle is found within 0.013 rad.
pub const MIN_AXIS_MARGIN: f64 = 0.05;

/// Fractions of the configured pulse current the search tries, in order, where the model's
/// axis order is unclear ([`MIN_AXIS_MARGIN`]): never more current than configured, and at
/// least half of it (the first harmonic, the polarity, falls with the current).
const PULSE_CURRENT_STEPS: [f64; 3] = [1.0, 0.75, 0.5];

/// The share of `current` (the configured `pulse_current_ratio` × the rated current) the
/// search's pulses reach on `machine`: 1 where the model's secant inductances along d and q
/// differ by at least [`MIN_AXIS_MARGIN`] there (always on a constant-inductance model), else
/// the largest of 0.75 and 0.5 at which they do, else 1.
pub fn pulse_current_share<T: Real>(machine: &MachineModel<T>, current: T) -> T {
    for step in PULSE_CURRENT_STEPS {
        let share = T::lit(step);
        match axis_secants(machine, current * share) {
            None => return T::one(),
            Some((d, q)) => {
                let gap = crate::real::max(d - q, q - d);
                if gap >= T::lit(MIN_AXIS_MARGIN) * (d + q) {
                    return share;
                }
            }
        }
    }
    T::one()
}

/// The sums of the secant inductances along ±d and along ±q over the currents the pulses'
/// flux L̂min·`current` reaches on each, or None on a constant-inductance model (or a
/// current that is not a positive number).
fn axis_secants<T: Real>(machine: &MachineModel<T>, current: T) -> Option<(T, T)> {
    if machine.magnetics.is_linear() || !current.is_finite() || current <= T::zero() {
        return None;
    }
    let flux = crate::real::min(machine.ld, machine.lq) * current;
    let m = machine.magnetic_model();
    let secant = |axis: Dq<T>, l0: T| {
        let mut l = l0;
        for _ in 0..3 {
            let peak = flux / l;
            let mut sum = T::zero();
            for k in 0..8 {
                let i = peak * (T::from_index(k) + T::lit(0.5)) * T::lit(0.125);
                let inc = m.incremental_inductance(Dq::new(axis.d * i, axis.q * i));
                sum += inc.dd * axis.d * axis.d + inc.qq * axis.q * axis.q;
            }
            let next = sum * T::lit(0.125);
            if !next.is_finite() || next <= T::zero() {
                return l0;
            }
            l = next;
        }
        l
    };
    let one = T::one();
    let d =
        secant(Dq::new(one, T::zero()), machine.ld) + secant(Dq::new(-one, T::zero()), machine.ld);
    let q =
        secant(Dq::new(T::zero(), one), machine.lq) + secant(Dq::new(T::zero(), -one), machine.lq);
    Some((d, q))
}

/// Where the start-up's angle phase stands.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StartupStatus {
    /// Not armed: the drive starts from the angle it was given (`find_angle` off), or the
    /// phase has not begun (offsets still being measured).
    #[default]
    Idle,
    /// The twelve-direction pulses.
    Searching,
    /// The polarity test along the axis found.
    TestingPolarity,
    /// The free-rotor alignment (d current, two steps).
    Aligning,
    /// The angle is known (found, or the free rotor aligned): the drive starts from it.
    Found,
    /// The rotor turned during the offset calibration or the angle search
    /// ([`MotionMonitor`]): the drive shorts the phases (the zero vector, whose current
    /// brakes the rotor) and begins the start-up again once the rotor has stood still for
    /// `quiet_time`. Not ready meanwhile.
    RotorMoving,
    /// No usable angle: the drive stays off (gates off, not ready). The detection's verdict:
    /// `AxisOnly` (the axis, its polarity not even with the polarity test), `NoInformation`
    /// or `Implausible`.
    NoAngle(InitialAngleStatus),
}

/// What the phase asks of the drive at a sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StartupCommand<T> {
    /// Apply this α-β voltage (a pulse).
    Voltage(Ab<T>),
    /// Hold this d current along this angle with the current loop (the free-rotor
    /// alignment).
    Align {
        /// Electrical rad.
        angle: T,
        /// A.
        current_d: T,
    },
    /// The phase is over: start from this angle.
    Start(T),
    /// The phase is over without an angle: gates off.
    Off,
    /// The rotor stood still for `quiet_time` after it moved: the start-up begins again from
    /// the offset calibration.
    Restart,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Stage<T> {
    Idle,
    Search(InitialAngle<T>),
    Polarity(PolarityTest<T>),
    Align {
        samples: u32,
        axis: T,
    },
    /// The zero vector after a motion, `samples` into the present quiet window.
    Defer {
        samples: u32,
    },
    Done,
}

/// The angle phase's state machine (module docs). Allocation-free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngleSearch<T> {
    tuning: StartupTuning<T>,
    ts: T,
    rated_current: T,
    l_min: T,
    l_max: T,
    l_mean: T,
    /// R̂s (Ω).
    rs: T,
    /// The search's peak current as a multiple of the rated current: `pulse_current_ratio`
    /// times [`pulse_current_share`].
    pulse_ratio: T,
    d_larger: bool,
    /// The model's d axis meets the larger incremental inductance along +d than along −d
    /// ([`inverted_polarity`]): the faster rise then points against the magnet.
    inverted: bool,
    align_samples: u32,
    quiet_samples: u32,
    monitor: MotionMonitor<T>,
    stage: Stage<T>,
    status: StartupStatus,
    angle: T,
    /// The search's detection verdict and (a₁/m, a₂/m); the polarity test's relative
    /// difference.
    detection: (InitialAngleStatus, (T, T)),
    polarity_contrast: T,
    armed: bool,
}

impl<T: Real> AngleSearch<T> {
    /// The phase for `machine` sampled at `ts`, not armed.
    pub fn new(
        tuning: StartupTuning<T>,
        machine: &MachineModel<T>,
        ts: T,
    ) -> Result<Self, ConfigError> {
        tuning.validate()?;
        let align_samples = crate::lock::samples("startup.align_time", tuning.align_time, ts)?;
        let quiet_samples = crate::lock::samples("startup.quiet_time", tuning.quiet_time, ts)?;
        let l_mean = T::lit(0.5) * (machine.ld + machine.lq);
        let configured = tuning.pulse_current_ratio * machine.rated_current;
        let share = pulse_current_share(machine, configured);
        let current = configured * share;
        Ok(Self {
            tuning,
            ts,
            rated_current: machine.rated_current,
            l_min: crate::real::min(machine.ld, machine.lq),
            l_max: crate::real::max(machine.ld, machine.lq),
            l_mean,
            rs: machine.rs,
            pulse_ratio: tuning.pulse_current_ratio * share,
            d_larger: d_axis_larger(machine, current),
            inverted: inverted_polarity(machine, current),
            align_samples,
            quiet_samples: quiet_samples.max(1),
            monitor: MotionMonitor::new(
                machine.rs,
                l_mean,
                machine.flux_linkage,
                machine.rated_current,
                ts,
            ),
            stage: Stage::Idle,
            status: StartupStatus::Idle,
            angle: T::zero() / T::zero(),
            detection: (InitialAngleStatus::Running, (T::zero(), T::zero())),
            polarity_contrast: T::zero(),
            armed: false,
        })
    }

    /// Arms the phase (when `find_angle` is on): it begins at the next [`step`](Self::step).
    pub fn arm(&mut self) {
        self.stage = Stage::Idle;
        self.armed = self.tuning.find_angle;
        self.status = StartupStatus::Idle;
        self.angle = T::zero() / T::zero();
        self.monitor.stop();
    }

    /// The offset calibration runs under the zero vector and watched for motion
    /// ([`MotionMonitor`]): always, since any rotor may carry a load that no brake holds; at
    /// rest no current flows (the offsets are those of gates off), and a turning rotor drives
    /// a short-circuit current that brakes it and shows its travel.
    pub fn watches_offsets(&self) -> bool {
        true
    }

    /// The motion monitor (its travel since its last restart).
    pub fn motion(&self) -> &MotionMonitor<T> {
        &self.monitor
    }

    /// Starts watching the offset calibration from reference current `reference` (the
    /// mean raw current of its first samples, A), uncertain by `reference_error` (A:
    /// [`MotionMonitor::set_reference_error`]).
    pub fn watch_offsets(&mut self, reference: Ab<T>, reference_error: T) {
        self.monitor.set_reference_error(reference_error);
        self.monitor.restart(reference);
    }

    /// One watched offset-calibration sample (raw current, the zero vector applied; `v_ab`
    /// the voltage it sets, the devices' drop): true when the rotor has moved, the start-up
    /// then deferred (`find_angle`).
    pub fn offset_sample(&mut self, i_ab: Ab<T>, v_ab: Ab<T>) -> bool {
        if !self.monitor.running() {
            return false;
        }
        let moving = self.monitor.threshold(self.tuning.motion_travel);
        let travel = self.monitor.step(v_ab, i_ab);
        if travel > moving || self.monitor.moved_recently(self.tuning.motion_travel) {
            // A rotor of unknown angle: wait until it stands still. With its start angle
            // known (`find_angle` off) the drive starts from where it has turned to.
            if self.tuning.find_angle {
                self.defer();
            }
            return true;
        }
        false
    }

    /// The rotor moved: the zero vector until it stands still (see
    /// [`StartupStatus::RotorMoving`]).
    fn defer(&mut self) {
        self.armed = false;
        self.stage = Stage::Defer { samples: 0 };
        self.status = StartupStatus::RotorMoving;
        self.monitor.restart(Ab::zero());
    }

    /// The phase has work to do (armed, or running a stage) or holds the drive off.
    pub fn active(&self) -> bool {
        self.armed
            || !matches!(self.stage, Stage::Idle | Stage::Done)
            || matches!(self.status, StartupStatus::NoAngle(_))
    }

    /// Where the phase stands.
    pub fn status(&self) -> StartupStatus {
        self.status
    }

    /// The angle the drive starts from (electrical rad), NaN until one is known.
    pub fn angle(&self) -> T {
        self.angle
    }

    /// The search's verdict and its harmonics (a₁/m, a₂/m): the margins against
    /// [`DEFAULT_MIN_POLARITY`] and [`DEFAULT_MIN_SALIENCY`].
    pub fn detection(&self) -> (InitialAngleStatus, (T, T)) {
        self.detection
    }

    /// The polarity test's relative difference (+axis − −axis)/mean (0 when it did not run).
    pub fn polarity_contrast(&self) -> T {
        self.polarity_contrast
    }

    /// The tuning.
    pub fn tuning(&self) -> &StartupTuning<T> {
        &self.tuning
    }

    /// The gain calibration's axis for a rotor at `theta` (see
    /// [`StartupTuning::rotor_held`]): `theta`, or with `rotor_held` and a share of the
    /// current in some phase below `min_observability` there, the nearest k·π/3, or on a
    /// salient rotor that would drive more than 20 % of the level across that axis, the q
    /// axis θ + π/2. A held rotor observed at `theta` also turns to the nearest k·π/3 where
    /// at most 0.2 % of the level crosses it (`CROSS_FREE_SHARE`: every round rotor).
    pub fn gain_axis(&self, theta: T, min_observability: T) -> T {
        self.gain_axis_on_q(theta, min_observability).0
    }

    /// [`gain_axis`](Self::gain_axis), and whether it is the rotor's q axis (its current
    /// then settles with L̂q, not L̂d).
    pub fn gain_axis_on_q(&self, theta: T, min_observability: T) -> (T, bool) {
        if !self.tuning.rotor_held || !theta.is_finite() {
            return (theta, false);
        }
        let sixth = T::pi() / T::lit(3.0);
        // (−π, π] + π → (0, 2π]: k in 0..=6, k·π/3 − π a multiple of π/3.
        let k = ((crate::wrap_angle(theta) + T::pi()) / sixth + T::lit(0.5)).index_floor(6);
        let axis = T::from_index(k) * sixth - T::pi();
        // Off the d axis a salient rotor drives a current across the calibration's axis
        // (its share (L̂q − L̂d)/(L̂q + L̂d)·sin 2Δ of the level), which the calibration's
        // motion test reads as a turning rotor: the axis turns only while that share stays
        // below MAX_CROSS_SHARE.
        let (s2, _) = (T::lit(2.0) * (axis - theta)).step_sin_cos_any();
        let saliency = (self.l_max - self.l_min) / (self.l_max + self.l_min);
        let cross = saliency * s2.abs();
        if GainCalibration::observability(theta) >= min_observability {
            // Observed: the axis turns to k·π/3 only where nothing crosses it.
            return if cross <= T::lit(CROSS_FREE_SHARE) {
                (axis, false)
            } else {
                (theta, false)
            };
        }
        if cross <= T::lit(MAX_CROSS_SHARE) {
            return (axis, false);
        }
        // The q axis is the rotor's other principal axis: no current across it whatever the
        // saliency, and it lies within asin(min_observability) of the phase the d axis
        // leaves without current, every phase carrying at least half of it there.
        let q = crate::wrap_angle(theta + T::lit(core::f64::consts::FRAC_PI_2));
        if GainCalibration::observability(q) >= min_observability {
            (q, true)
        } else {
            (theta, false)
        }
    }

    /// Pulse voltage and samples for a peak of `ratio` × the rated current along the smaller
    /// inductance at DC link `vdc`.
    fn pulse(&self, ratio: T, vdc: T) -> (T, u32) {
        let flux = self.l_min * ratio * self.rated_current;
        let v_max = self.tuning.pulse_voltage_ratio * vdc * T::lit(0.577_350_269_189_625_8);
        let n = if v_max > T::zero() {
            (flux / (v_max * self.ts)).index_floor(100_000) + 1
        } else {
            MIN_PULSE_SAMPLES
        };
        let n = n.max(MIN_PULSE_SAMPLES);
        (flux / (T::from_index(n) * self.ts), n as u32)
    }

    /// One sample: `i_ab` the measured current (offsets removed), `v_ab` the voltage that
    /// acted over the last period (the realised reference: the motion monitor's input while
    /// deferring), `vdc` the DC link.
    pub fn step(&mut self, i_ab: Ab<T>, v_ab: Ab<T>, vdc: T) -> StartupCommand<T> {
        if self.armed {
            self.armed = false;
            self.status = StartupStatus::Searching;
            let (voltage, pulse_samples) = self.pulse(self.pulse_ratio, vdc);
            let config = InitialAngleConfig {
                voltage,
                pulse_samples,
                min_saliency: T::lit(DEFAULT_MIN_SALIENCY),
                min_polarity: T::lit(DEFAULT_MIN_POLARITY),
                d_larger: self.d_larger,
                inductance: self.l_mean,
                resistance: self.rs,
                ts: self.ts,
            };
            self.monitor.restart(Ab::zero());
            match InitialAngle::new(config) {
                Ok(block) => self.stage = Stage::Search(block),
                Err(_) => return self.refuse(InitialAngleStatus::Implausible),
            }
        }
        match &mut self.stage {
            Stage::Search(block) => {
                let v = block.step(i_ab);
                if block.running() {
                    return StartupCommand::Voltage(v);
                }
                let (status, angle) = (block.status(), block.angle());
                self.detection = (status, block.harmonics());
                self.searched(status, angle, vdc)
            }
            Stage::Polarity(test) => {
                let v = test.step(i_ab);
                if let Some(result) = test.result() {
                    self.polarity_contrast = test.contrast();
                    let axis = test.axis();
                    return match result {
                        Some(angle) => self.found(angle),
                        None => self.unresolved(InitialAngleStatus::AxisOnly, axis),
                    };
                }
                StartupCommand::Voltage(v)
            }
            Stage::Align { samples, axis } => {
                self.monitor.stop();
                let (n, axis) = (*samples, *axis);
                *samples += 1;
                if n >= 2 * self.align_samples {
                    return self.found(axis + T::lit(core::f64::consts::FRAC_PI_2));
                }
                let step = if n < self.align_samples {
                    T::zero()
                } else {
                    T::lit(core::f64::consts::FRAC_PI_2)
                };
                StartupCommand::Align {
                    angle: axis + step,
                    current_d: self.tuning.align_current_ratio * self.rated_current,
                }
            }
            Stage::Defer { .. } => self.deferred(i_ab, v_ab),
            Stage::Done => match self.status {
                StartupStatus::Found => StartupCommand::Start(self.angle),
                _ => StartupCommand::Off,
            },
            Stage::Idle => StartupCommand::Off,
        }
    }

    /// A deferral's sample: the zero vector, and at the end of each `quiet_time` window the
    /// restart when the rotor stood still through it.
    fn deferred(&mut self, i_ab: Ab<T>, v_ab: Ab<T>) -> StartupCommand<T> {
        let Stage::Defer { samples } = &mut self.stage else {
            return StartupCommand::Off;
        };
        *samples += 1;
        let done = *samples >= self.quiet_samples;
        self.monitor.step(v_ab, i_ab);
        if !done {
            return StartupCommand::Voltage(Ab::zero());
        }
        if self.monitor.quiet(self.tuning.motion_travel) {
            self.arm();
            return StartupCommand::Restart;
        }
        self.stage = Stage::Defer { samples: 0 };
        self.monitor.restart(Ab::zero());
        StartupCommand::Voltage(Ab::zero())
    }

    /// The search's verdict: start, test the polarity, align or refuse.
    fn searched(&mut self, status: InitialAngleStatus, angle: T, vdc: T) -> StartupCommand<T> {
        match status {
            InitialAngleStatus::Found => self.found(angle),
            InitialAngleStatus::AxisOnly => {
                let (voltage, n) = self.pulse(self.tuning.polarity_current_ratio, vdc);
                let test = PolarityTest::new(angle, voltage, n, self.l_mean, self.ts);
                self.stage = Stage::Polarity(test);
                self.status = StartupStatus::TestingPolarity;
                StartupCommand::Voltage(Ab::zero())
            }
            other => self.unresolved(other, T::zero()),
        }
    }

    /// `angle`: the direction of the faster rise (the magnet's unless the model says
    /// otherwise).
    fn found(&mut self, angle: T) -> StartupCommand<T> {
        let angle = if self.inverted {
            angle + T::pi()
        } else {
            angle
        };
        self.angle = crate::wrap_angle(angle);
        self.status = StartupStatus::Found;
        self.stage = Stage::Done;
        StartupCommand::Start(self.angle)
    }

    /// No usable angle: the free-rotor alignment from `axis`, or off.
    fn unresolved(&mut self, status: InitialAngleStatus, axis: T) -> StartupCommand<T> {
        if self.tuning.free_rotor_align && status != InitialAngleStatus::Implausible {
            self.stage = Stage::Align { samples: 0, axis };
            self.status = StartupStatus::Aligning;
            return StartupCommand::Voltage(Ab::zero());
        }
        self.refuse(status)
    }

    fn refuse(&mut self, status: InitialAngleStatus) -> StartupCommand<T> {
        self.stage = Stage::Done;
        self.status = StartupStatus::NoAngle(status);
        StartupCommand::Off
    }
}
