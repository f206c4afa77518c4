//! The speed loop's bandwidth from the rotor's mechanical time constant: neither a load step
//! nor a load ramp drives a light rotor out of the speed range the drive holds.
//!
//! **Why: the step.** A speed PI of bandwidth ωs has the proportional gain Ĵ·ωs (torque per
//! mechanical rad/s). A load step ΔT meets, for the first few milliseconds, only that gain
//! (the integral comes a zero ωs/`zero_ratio` later): the speed dips by about ΔT/(Ĵ·ωs). With
//! the mechanical time constant τm = Ĵ·Ω_rated/T_rated (the time the rated torque takes to
//! bring the rotor to its rated speed), a step of the rated torque at the rated speed dips it
//! by Ω_rated/(ωs·τm). On the paper's motor (τm = 0.16 s) the paper's 5 Hz loop dips by 0.19
//! of the rated speed; on a 22-pole-pair gimbal motor (4·10⁻⁵ kg·m², 0.5 N·m, 600 r/min,
//! τm = 5 ms) by 6.3 × the rated speed: `fullrange`'s step of half the rated torque reverses
//! it within 10 ms, the load drives it past the speed at which the voltage limit leaves the
//! drive its torque (−2,000 r/min), and the drive trips (measured dip with ωs raised to 20 Hz:
//! 0.77 of the rated speed against the estimate's 0.79).
//!
//! **Why: the ramp.** Under a load that ramps at r (N·m/s) the PI's proportional path alone
//! would let the error grow without bound; its integral Ki = Ĵ·ωs·ωs/`zero_ratio` holds it at
//! the steady ramp error e = r/Ki = zero_ratio·r/(Ĵ·ωs²) (mechanical rad/s), reached about
//! 1/ωz = zero_ratio/ωs after the ramp starts (0.16 s at 5 Hz). That bound falls with ωs²,
//! not ωs, so the step's rule does not cover it: a 48 V, 7-pole-pair motor of 1.2·10⁻⁴ kg·m²
//! rated 2.31 N·m at 4,000 r/min (τm = 22 ms, not a preset) needs only 3.65 Hz for its step,
//! and at the paper's 5 Hz `reversal`'s ramp of 65 % of its rated torque in 0.5 s (3.0 N·m/s)
//! leaves e = 5·3.0/(1.2·10⁻⁴·31.4²) = 127 rad/s = 1,216 r/min, six times the −240 r/min it
//! is asked for (measured: 1,266 r/min at the ramp's end, 139 r/min still 0.5 s later). In
//! units of the ratings, a ramp of the rated torque over t_r leaves
//! e/Ω_rated = zero_ratio/(ωs²·t_r·τm).
//!
//! **Rule.** ωs ≥ max(1/(d·τm), √(zero_ratio/(ε·t_r·τm))) with
//! d = `[controller.speed] load_step_dip_ratio` = 2 (a step of the rated torque from the rated
//! speed leaves the rotor within the rated speed turning the other way, where the drive has
//! the voltage for its rated torque), t_r = `load_ramp_time` = 1 s and ε =
//! `load_ramp_error_ratio` = 0.13 (a ramp of the rated torque per second leaves at most 13 % of
//! the rated speed). Where that raises the bandwidth the speed tracker T2S-2, whose ω̂ closes
//! the loop, keeps the tuning's ratio to it (the paper's 35 Hz to 5 Hz), up to Kp·Ts =
//! [`MAX_KP_TS`]; the speed loop itself up to ωs·Ts = [`MAX_SPEED_WS_TS`]. Below it (every
//! preset: the lightest, pmsyrm-5k, has τm = 59 ms and needs 1.35 Hz for its step and 4.1 Hz
//! for its ramp) the tuning is unchanged to the bit. ε·t_r = 0.13 s is the smallest that also
//! leaves a made-up 32-pole 150 r/min torque motor (τm = 39 ms, 4.98 Hz) its 5 Hz: its passage
//! through zero speed under 65 % of its rated torque in `reversal` loses the angle with a
//! faster loop (measured 0.35 rad at 5.3 Hz, 1.6 rad at 5.7 Hz, 0.07 rad at 5 Hz), a limit of
//! its loaded standstill, not of the ramp. The 48 V motor above gets 6.7 Hz: measured on
//! `reversal` (seeds 1–4) 720 r/min off while the load ramps (679 r/min predicted) and 33 r/min
//! from the load's end on, within the 80 r/min (2 % of its rated speed) the scenario asks. The
//! gimbal's step asks more than its ramp (15.8 Hz against 13.9 Hz).
//!
//! **Frame coupling.** On a saturating model the estimator's slow mode (docs/method/saturation.md,
//! "The slow mode") carries a frame error δ that moves the estimated flux magnitude by s·δ and
//! leaves only κ·δ of it visible to the observer; c = |s|/κ at the operating point
//! ([`ActiveFlux::frame_coupling`]). The speed loop closes that mode through T2S-2's ω̂: a
//! frame error the observer corrects at its own rate reaches the torque through the speed PI,
//! whose answer within its bandwidth ωs moves i_q, and with it s·δ, before T2S-2 (bandwidth
//! ωt) has separated the speed from the frame's motion. The share of the slow mode the speed
//! loop feeds back is then about c·ωs/ωt (the visible part's correction is ωt-fast, the
//! hidden part's answer ωs-fast and c times as large), and the loop keeps its margin while
//! c·ωs/ωt ≤ c_max/r with r the tuning's own ratio ωt/ωs (the paper's 35 Hz to 5 Hz, 7) and
//! c_max = [`DEFAULT_MAX_FRAME_COUPLING`] = 1: at the paper's ratio, the frame coupling at
//! which a frame error's hidden part reaches its visible part. **Rule:** where the model's c
//! at the rated torque's MTPA point (at the current limit's where that torque is beyond it,
//! [`rated_frame_coupling`]) exceeds c_max, T2S-2 is raised to r·ωs·c/c_max (at most Kp·Ts =
//! [`MAX_KP_TS`]); the speed loop keeps its bandwidth (at 4 Hz instead of 5 the same machine
//! holds `reversal` at 10–12 r/min against 4–10 with T2S-2 raised, and at 3 Hz its
//! `rated-reversal` on two seeds of four at 38 r/min, beyond the scenario's 30). Measured (switching-resolved,
//! seeds 1–4, `fado-sim run reversal`): the 4 kW ferrite PM-SyRM of
//! `crates/fado-sim/tests/data/motulator/mot-pmsyrm-4k.toml` (c = 1.08 at the 65 % of
//! `reversal`, 1.33 at rated torque) loses the angle generating near zero speed at the
//! paper's 35 Hz (3.05 and 1.77 rad on seeds 2 and 3) and holds it at 60 Hz (0.030–0.063 rad);
//! the Baldor PM-SyRM preset (c = 0.96 at rated torque) holds it at 35 Hz. Constant
//! inductances (every linear preset) and the saturated presets below c_max keep their
//! tuning to the bit.

use crate::active_flux::ActiveFlux;
use crate::control::DriveTuning;
use crate::control::saturated_references::SaturatedReferences;
use crate::control::tracker_feedforward::MAX_KP_TS;
use crate::estimator::EstimatorTuning;
use crate::machine::MachineModel;
use crate::tracker::TrackerConfig;
use crate::{Dq, Real};

/// The largest ωs·Ts the rule gives the speed loop: 0.05 \[A\], half the speed controller's
/// own refusal limit (0.1, `crate::control::speed_controller`), as [`MAX_KP_TS`] for T2S-2.
pub const MAX_SPEED_WS_TS: f64 = 0.05;

/// The frame coupling c = |s|/κ at the rated torque's MTPA point that the tuning's ratio of
/// T2S-2 to the speed loop holds (module docs, "Frame coupling") \[D\]: at the paper's ratio,
/// where a frame error's hidden part reaches its visible part; the machines measured hold
/// 0.96 (the Baldor PM-SyRM preset) and lose 1.08 (motulator's 4 kW ferrite PM-SyRM at 65 %
/// of its rated torque).
pub const DEFAULT_MAX_FRAME_COUPLING: f64 = 1.0;

/// Bisection steps of the rated torque along the MTPA curve (2⁻³⁰ of the current limit).
const RATED_POINT_BISECTIONS: usize = 30;

/// τm = Ĵ·Ω_rated/T_rated (s): the time the rated torque takes to bring the rotor from
/// standstill to its rated speed.
pub fn mechanical_time_constant<T: Real>(machine: &MachineModel<T>) -> T {
    machine.inertia * machine.rated_speed_mech() / machine.rated_torque
}

/// The speed loop's bandwidth (Hz) the rule asks: the larger of the step's 1/(2π·d·τm), d =
/// `speed.load_step_dip_ratio`, and the ramp's √(zero_ratio/(ε·t_r·τm))/(2π), ε =
/// `speed.load_ramp_error_ratio`, t_r = `speed.load_ramp_time` (module docs); NaN or 0 where
/// the model lacks the ratings (no rule).
pub fn required_bandwidth_hz<T: Real>(machine: &MachineModel<T>, drive: &DriveTuning<T>) -> T {
    let tau = mechanical_time_constant(machine);
    let s = &drive.speed;
    let two_pi = T::lit(core::f64::consts::TAU);
    let step = T::one() / (two_pi * s.load_step_dip_ratio * tau);
    let ramp =
        (s.zero_ratio / (s.load_ramp_error_ratio * s.load_ramp_time * tau)).step_sqrt() / two_pi;
    // A NaN τm makes both NaN: the step's NaN is returned (no rule).
    if ramp > step { ramp } else { step }
}

/// Applies the rules (module docs) to the drive's and the estimator's tuning, in place: raises
/// the speed loop's bandwidth to [`required_bandwidth_hz`] where it is below, and T2S-2's with
/// it in the tuning's ratio; then T2S-2's by the model's [`rated_frame_coupling`] over
/// [`DEFAULT_MAX_FRAME_COUPLING`] where that is above 1 (each at most the bandwidth of Kp·Ts =
/// [`MAX_KP_TS`]).
pub fn apply<T: Real>(
    machine: &MachineModel<T>,
    drive: &mut DriveTuning<T>,
    estimator: &mut EstimatorTuning<T>,
    ts: T,
) {
    raise_for_the_load(machine, drive, estimator, ts);
    raise_for_the_frame_coupling(machine, drive, estimator, ts);
}

/// The model's frame coupling c = |s|/κ ([`ActiveFlux::frame_coupling`]) at the MTPA point of
/// the rated torque, or of the current limit `drive.current.limit_ratio` × the rated current
/// where the rated torque is beyond it: the load the drive meets. None for constant
/// inductances or a model without ratings; not finite where κ ≤ 0.
pub fn rated_frame_coupling<T: Real>(
    machine: &MachineModel<T>,
    drive: &DriveTuning<T>,
) -> Option<T> {
    let i_max = drive.current.limit_ratio * machine.rated_current;
    let (Some(refs), Some(flux)) = (
        SaturatedReferences::new(machine, i_max),
        ActiveFlux::new(machine),
    ) else {
        return None;
    };
    let target = machine.rated_torque / (T::lit(1.5) * T::from_index(machine.pole_pairs as usize));
    let (mut lo, mut hi) = (T::zero(), i_max);
    for _ in 0..RATED_POINT_BISECTIONS {
        let mid = T::lit(0.5) * (lo + hi);
        if refs.torque_flux(refs.mtpa_on_circle(mid)) >= target {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let i: Dq<T> = refs.mtpa_on_circle(hi);
    let (s, kappa) = flux.frame_coupling(&flux.point(i));
    Some(s.abs() / kappa)
}

/// T2S-2's bandwidth (Hz) at most Kp·Ts = [`MAX_KP_TS`]: `candidate`, or the bandwidth of that
/// Kp where `candidate`'s is above it.
fn tracker_within_cap<T: Real>(estimator: &EstimatorTuning<T>, candidate: T, ts: T) -> T {
    let t = &estimator.tracker;
    // Kp = (2ζ + c)·ωn of the tracker (its load pole adds c·ωn), proportional to the
    // bandwidth in either of its definitions.
    let (kp2, _) = TrackerConfig {
        damping: t.damping,
        definition: t.bandwidth_definition,
        ..TrackerConfig::new(candidate, ts)
    }
    .gains();
    let kp = kp2 * (T::one() + t.load_pole_ratio / (T::lit(2.0) * t.damping));
    crate::real::min(candidate, candidate * T::lit(MAX_KP_TS) / (kp * ts))
}

/// The frame coupling's rule (module docs): T2S-2 at least r·ωs·c/c_max where the model's
/// [`rated_frame_coupling`] c exceeds c_max = [`DEFAULT_MAX_FRAME_COUPLING`].
fn raise_for_the_frame_coupling<T: Real>(
    machine: &MachineModel<T>,
    drive: &DriveTuning<T>,
    estimator: &mut EstimatorTuning<T>,
    ts: T,
) {
    let Some(c) = rated_frame_coupling(machine, drive) else {
        return;
    };
    let c = c / T::lit(DEFAULT_MAX_FRAME_COUPLING);
    // NaN compares false, and κ ≤ 0 (an infinite or negative c) is a model the drive's
    // checks name: no rule.
    if !(c > T::one() && c.is_finite()) {
        return;
    }
    let candidate = estimator.tracker.t2s2_bandwidth_hz * c;
    let tracker = tracker_within_cap(estimator, candidate, ts);
    if tracker > estimator.tracker.t2s2_bandwidth_hz {
        estimator.tracker.t2s2_bandwidth_hz = tracker;
    }
}

/// The load step's and ramp's rule (module docs): the speed loop at [`required_bandwidth_hz`]
/// where it is below, T2S-2 with it in the tuning's ratio.
fn raise_for_the_load<T: Real>(
    machine: &MachineModel<T>,
    drive: &mut DriveTuning<T>,
    estimator: &mut EstimatorTuning<T>,
    ts: T,
) {
    let required = required_bandwidth_hz(machine, drive);
    let own = drive.speed.bandwidth_hz;
    // NaN compares false: the tuning's bandwidth; an invalid one (≤ 0) is left for the
    // drive's checks to name.
    let raise = required.is_finite() && own > T::zero() && required > own;
    if !raise {
        return;
    }
    // ωs·Ts at most MAX_SPEED_WS_TS, and the PI's anti-windup step (anti_windup_ratio·Ki/Kp·Ts
    // = anti_windup_ratio·ωs·Ts/zero_ratio, refused above 1) at most a half.
    let s = &drive.speed;
    let ws_ts = crate::real::min(
        T::lit(MAX_SPEED_WS_TS),
        T::lit(0.5) * s.zero_ratio / crate::real::max(s.anti_windup_ratio, T::lit(1e-9)),
    );
    let needed = crate::real::min(required, ws_ts / (T::lit(core::f64::consts::TAU) * ts));
    let raise = needed > own;
    if !raise {
        return;
    }
    let ratio = estimator.tracker.t2s2_bandwidth_hz / own;
    let tracker = tracker_within_cap(estimator, needed * ratio, ts);
    drive.speed.bandwidth_hz = needed;
    if tracker > estimator.tracker.t2s2_bandwidth_hz {
        estimator.tracker.t2s2_bandwidth_hz = tracker;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gimbal() -> MachineModel<f64> {
        MachineModel {
            pole_pairs: 22,
            flux_linkage: 0.0042,
            ld: 120e-6,
            lq: 120e-6,
            rs: 0.35,
            rated_current: 3.6,
            rated_torque: 0.5,
            rated_speed_rpm: 600.0,
            inertia: 4e-5,
            ..MachineModel::paper()
        }
    }

    /// A 48 V, 7-pole-pair motor of 1.2·10⁻⁴ kg·m², 2.31 N·m at 4,000 r/min (τm = 22 ms).
    fn fast_48v() -> MachineModel<f64> {
        MachineModel {
            pole_pairs: 7,
            flux_linkage: 0.0055,
            ld: 45e-6,
            lq: 45e-6,
            rs: 0.035,
            rated_current: 40.0,
            rated_torque: 2.31,
            rated_speed_rpm: 4000.0,
            inertia: 1.2e-4,
            ..MachineModel::paper()
        }
    }

    /// The tuning with only the step's rule (the ramp's ε out of reach).
    fn step_rule_only() -> DriveTuning<f64> {
        let mut d = DriveTuning::<f64>::default();
        d.speed.load_ramp_error_ratio = 1e9;
        d
    }

    /// The paper's motor keeps its tuning to the bit under both rules; the gimbal motor gets
    /// the bandwidth at which a rated step dips the speed by d·Ω_rated (first order), and
    /// T2S-2 the paper's ratio to it.
    #[test]
    fn light_rotor_gets_the_bandwidth_of_its_load_step() {
        let (d0, e0) = (
            DriveTuning::<f64>::default(),
            EstimatorTuning::<f64>::default(),
        );
        let (mut d, mut e) = (d0, e0);
        apply(&MachineModel::paper(), &mut d, &mut e, 100e-6);
        assert_eq!((d, e), (d0, e0));
        let d0 = step_rule_only();
        let (mut d, mut e) = (d0, e0);
        let m = gimbal();
        let tau = mechanical_time_constant(&m);
        assert!((tau - 4e-5 * 62.83185307 / 0.5).abs() < 1e-9, "{tau}");
        apply(&m, &mut d, &mut e, 50e-6);
        let ws = core::f64::consts::TAU * d.speed.bandwidth_hz;
        // The first-order dip of a rated step from rated speed: Ω_rated/(ωs·τm) = d.
        assert!((1.0 / (ws * tau) - d.speed.load_step_dip_ratio).abs() < 1e-9);
        assert!(
            (d.speed.bandwidth_hz - 15.83).abs() < 0.01,
            "{}",
            d.speed.bandwidth_hz
        );
        let d1 = d;
        let ratio = e0.tracker.t2s2_bandwidth_hz / d0.speed.bandwidth_hz;
        assert!((e.tracker.t2s2_bandwidth_hz - ratio * d.speed.bandwidth_hz).abs() < 1e-9);
        // T2S-2's Kp·Ts cap at a slower sampling rate (the speed loop still below its own),
        // for a tuning whose T2S-2 is 14 × its speed loop.
        let (mut d, mut e) = (d0, e0);
        e.tracker.t2s2_bandwidth_hz = 70.0;
        apply(&m, &mut d, &mut e, 4e-4);
        assert_eq!(d.speed.bandwidth_hz, d1.speed.bandwidth_hz);
        let (kp, _) = TrackerConfig {
            damping: e.tracker.damping,
            definition: e.tracker.bandwidth_definition,
            ..TrackerConfig::new(e.tracker.t2s2_bandwidth_hz, 4e-4)
        }
        .gains();
        assert!((kp * 4e-4 - MAX_KP_TS).abs() < 1e-9, "{kp}");
        // And the speed loop's ωs·Ts cap at a slower one still.
        let (mut d, mut e) = (d0, e0);
        apply(&m, &mut d, &mut e, 1e-3);
        let ws_ts = core::f64::consts::TAU * d.speed.bandwidth_hz * 1e-3;
        assert!((ws_ts - MAX_SPEED_WS_TS).abs() < 1e-12, "{ws_ts}");
    }

    /// The steady error of the speed PI under a load ramp, e = zero_ratio·r/(Ĵ·ωs²), by
    /// simulating the loop (PI on a rigid rotor, Euler at 10 µs): the formula the ramp's rule
    /// rests on. Then the 48 V motor, whose step asks 3.65 Hz, gets the bandwidth at which a
    /// ramp of the rated torque over t_r leaves ε·Ω_rated.
    #[test]
    fn light_rotor_gets_the_bandwidth_of_its_load_ramp() {
        let m = fast_48v();
        let d0 = DriveTuning::<f64>::default();
        let (j, z) = (m.inertia, d0.speed.zero_ratio);
        let ws = core::f64::consts::TAU * d0.speed.bandwidth_hz;
        let (kp, ki) = (j * ws, j * ws * ws / z);
        // A ramp of 65 % of the rated torque in 0.5 s (`reversal`'s), held on to 3 s.
        let r = 0.652 * m.rated_torque / 0.5;
        let (dt, mut omega, mut integral, mut peak) = (1e-5, 0.0_f64, 0.0_f64, 0.0_f64);
        for k in 0..300_000 {
            let t = k as f64 * dt;
            let load = r * t;
            let error = -omega;
            integral += ki * error * dt;
            omega += (kp * error + integral - load) / j * dt;
            peak = peak.max(omega.abs());
        }
        let steady = z * r / (j * ws * ws);
        assert!(
            (omega.abs() - steady).abs() < 1e-3 * steady,
            "{omega} {steady}"
        );
        assert!(peak <= steady * (1.0 + 1e-9), "{peak} {steady}");
        let tau = mechanical_time_constant(&m);
        let step = required_bandwidth_hz(&m, &step_rule_only());
        assert!((step - 3.65).abs() < 0.01, "{step}");
        let (mut d, mut e) = (d0, EstimatorTuning::<f64>::default());
        apply(&m, &mut d, &mut e, 25e-6);
        let ws = core::f64::consts::TAU * d.speed.bandwidth_hz;
        let s = &d.speed;
        // A ramp of the rated torque over t_r: e/Ω_rated = zero_ratio/(ωs²·t_r·τm) = ε.
        let ratio = s.zero_ratio / (ws * ws * s.load_ramp_time * tau);
        assert!((ratio - s.load_ramp_error_ratio).abs() < 1e-9, "{ratio}");
        assert!(
            (d.speed.bandwidth_hz - 6.69).abs() < 0.01,
            "{}",
            d.speed.bandwidth_hz
        );
        let t2s2 = d0.speed.bandwidth_hz;
        let expected = EstimatorTuning::<f64>::default().tracker.t2s2_bandwidth_hz / t2s2;
        assert!((e.tracker.t2s2_bandwidth_hz / d.speed.bandwidth_hz - expected).abs() < 1e-9);
    }
}
