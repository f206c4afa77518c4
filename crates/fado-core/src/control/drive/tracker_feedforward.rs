//! When the drive feeds the commanded acceleration to the estimator's speed trackers: on a
//! rotor whose acceleration at the current limit the paper's type-2 trackers cannot follow,
//! and on a rotor so heavy that a slow speed ramp takes a large share of its rated torque.
//!
//! **Why.** A type-2 tracker lags a constant electrical acceleration α by α/Ki in angle
//! ([`crate::tracker`]). At the current limit α = p·T_max/Ĵ, and in units of the ratings
//! α/Ki = ω_rated·(T_max/T_rated)/(t_m·Ki), t_m = Ĵ·ω_rated,mech/T_rated the mechanical start
//! time: the lag grows with the rated *electrical* speed. The paper's motor (4 pole pairs,
//! 1500 r/min) lags 0.21 rad behind its 60 Hz T2S-1; a 14-pole-pair multirotor motor at
//! 8000 r/min with its propeller lags 2.4 rad, and a 21-pole-pair actuator outrunner 3.0 rad:
//! a throttle step loses the rotor (measured on `motors/multirotor-mn5006-22v.toml`, 0 → 6000
//! r/min at the current limit: 2.1 rad; with the feed-forward 0.09 rad).
//!
//! **Rule.** Where the lag α/Ki at the current limit (T_max = min(`current.limit_ratio`,
//! `limits.torque_ratio`)·T_rated, Ki of T2S-1) exceeds [`TrackerFeedforwardTuning::max_lag`],
//! the drive turns on its acceleration feed-forward (`TrackerFeedforwardTuning::enabled`)
//! and gives the trackers their load integrator (`EstimatorTuning::tracker.load_pole_ratio`
//! [`LOAD_POLE_RATIO`] where the tuning leaves it at 0): without it the load the model does not
//! know would leave p·T_L/(Ĵ·Ki) of angle error. A tuning that turns them on itself is kept.
//!
//! **Threshold.** 2 rad \[A\] ([`TrackerFeedforwardTuning::max_lag`]): on the repository's
//! presets the rule turns the feed-forward on for the two fast outrunners (lags 2.4 and 3.0 rad)
//! and leaves the paper's trackers on the others (lags 0.06 to 0.68 rad). On the two strongly
//! salient presets (0.50 and 0.68 rad) the type-3 trackers lose `reversal` near zero speed
//! (measured: ipmsm-gem-50k 3.1 rad, pmsyrm-5k 0.21 rad), and a 750 W 10-pole servo (1.5–2 rad)
//! loses its loaded start with them, so a threshold below their lags would cost them.
//!
//! **A heavy rotor.** T2S-2's speed, which closes the speed loop, lags a constant electrical
//! acceleration α by α·Kp/Ki = 2ζ·α/ωn (the type-2 pair's integrator follows the ramp one
//! Kp/Ki late), and the speed PI's proportional gain Ĵ·ωs/p turns that lag into a torque
//! (2ζ·ωs/ωn)·T_acc, T_acc = Ĵ·α/p the torque that accelerates the rotor: 0.41·T_acc at the
//! tuning's 5 Hz loop and 35 Hz T2S-2, for every rotor. It steps at each end of a speed ramp
//! and the PI's integral takes it off within about zero_ratio/ωs. A ramp of a share r of the
//! rated speed per second needs T_acc = r·τm·T_rated (τm = Ĵ·Ω_rated/T_rated,
//! [`crate::control::speed_bandwidth::mechanical_time_constant`]): nothing on a light rotor,
//! half the rated torque in `stops` (4 % of the rated speed in 0.5 s, r = 0.08) on the drawn
//! 30 kW surface-magnet machine of τm = 6.1 s (17 pole pairs, 2.92 kg·m²,
//! `crates/fado-sim/tests/data/drawn/spm-17p-800v-30kw-heavy.toml`). There the stop's
//! deceleration leaves the load's 0.65 minus 0.49 of the rated torque, a q current (0.165 of
//! the rated) at the injection's I_min (0.184), where i_d* = √(I_min² − i_q*²) turns the current
//! vector by up to 90° for a small change of i_q*; the lag's torque steps at the ramp's start
//! and the speed PI rings through that corner at 8–10 Hz with i_q* between −10 and +26 A, the
//! current vector's swings move the estimated flux (|λ̂r| 0.085 → 0.111 Wb within 10 ms at one
//! onset of the injection) and `stops` ends 0.31 rad off (seeds 1 and 2), at the third stop's
//! ramp up. The outcome near that corner is erratic in the loop's bandwidth (4.5 Hz 0.06 rad,
//! 4.75 Hz 0.42, 5.25 Hz 0.10, 7 Hz 0.25). With the feed-forward T2S-2 has no lag under the
//! commanded acceleration and the run keeps 0.048 / 0.049 rad (0.08–0.15 rad at 4.75 and
//! 7 Hz). **Rule:** the drive also turns the feed-forward on where τm exceeds
//! [`TrackerFeedforwardTuning::heavy_rotor_time`], 4 s \[A\], and keeps the type-2 pair
//! (no load integrator): the load the feed-forward does not know then leaves T2S-1 an angle
//! error p·T_L/(Ĵ·Ki) = (T_L/T_rated)·ω_rated/(τm·Ki) (ω_rated electrical), below 0.05 rad at the rated load for
//! τm > 3 s up to an 800 Hz rated electrical frequency in the paper's 60 Hz T2S-1 (0.021 rad
//! on the 30 kW machine), and the third integrator costs that machine's `stops` its margin
//! (0.175 / 0.160 rad with it). Measured
//! on the 22 drawn and test machines of τm ≥ 0.9 s (`stops`, `reversal`, `rated-reversal`,
//! `loaded-start`, seeds 1 and 2): the feed-forward on all of them wins 5 runs and loses 2
//! (169 → 172 of 176 passed), the losses the loaded starts of two saturated IPM machines of
//! τm = 1.35 and 1.75 s (0.16 → 0.27 rad and 0.04 → 0.18 rad); on the six of τm ≥ 3.7 s it
//! loses none (41 → 46 of 48 passed; their `loaded-start` under 0, 0.1, 0.25 and 1 × the
//! rated torque from t = 0, seeds 1 and 2: 42 → 43 of 48, none lost).
//! The bound lies between 3.76 s and 4.55 s, the two heavy drawn machines nearest it: with
//! the dead-time compensation's followed reference
//! ([`crate::control::DeadTimeCompensation::phase_voltages_followed`]) the 192 kW saturated
//! IPMSM of τm = 3.76 s keeps `stops` within 0.109–0.127 rad and every `loaded-start` seed
//! (seed 2 0.192 rad) without the feed-forward, and with it 0.204–0.223 rad and loses
//! `loaded-start` seed 2 (0.274 rad); the 71 kW IPMSM of τm = 4.55 s is the next heavier.
//! No preset is that heavy (the heaviest, hub-hoverboard-48v, τm = 0.74 s).
//!
//! **T2S-1's bandwidth on a light rotor.** The feed-forward announces the torque the drive
//! commands, not the load's: a load step ΔT_L decelerates the rotor at α = p·ΔT_L/Ĵ, which
//! only the trackers' third integrator learns. The phase error of a type-3 tracker (poles
//! (s² + 2ζωn·s + ωn²)(s + c·ωn)) under a step α of unannounced acceleration is
//! e(s) = α/(s³ + Kp·s² + Ki·s + K3), whose peak is κ(ζ, c)·α/ωn² ([`load_step_peak`]: κ = 0.50
//! at ζ = 1/√2, c = 0.5; 1.04 for the type-2 pair, c = 0). A rated load step on the
//! 21-pole-pair cheetah outrunner (5.5·10⁴ rad/s² electrical) in the paper's 60 Hz T2S-1
//! (ωn = 183 s⁻¹) peaks at 0.82 rad (measured 0.83); half of it, `fullrange`'s step, measured
//! 0.45 rad. So where the drive runs the type-3 trackers, the rule gives T2S-1 a running
//! bandwidth (`tracker.t2s1_running_bandwidth_hz`, used in disturbance-feedback mode) at which
//! a step of the rated torque peaks at [`TrackerFeedforwardTuning::load_step_error`]:
//! ωn ≥ √(κ·p·T_rated/(Ĵ·e_max)), never below the tuning's and never beyond
//! (2ζ + c)·ωn·Ts = [`MAX_KP_TS`]. In limiter mode (standstill and low speed) T2S-1 keeps its
//! bandwidth: there the directly calculated angle carries the limiter's errors, which a wider
//! tracker passes to θ̂ (measured: a 16-pole multirotor motor with T2S-1 at 95 Hz throughout
//! loses 1.2 rad leaving standstill at the current limit; 0.1 rad with the running bandwidth).
//! T2S-2, whose speed closes the speed loop, keeps its bandwidth. On the presets the rule
//! acts only on the two outrunners (cheetah 141 Hz, multirotor 125 Hz; the others' rated
//! steps need less than 60 Hz).
//!
//! **The release hold's load.** When a brake opens under a load, the
//! [release hold](crate::control::release_hold) commands the torque that holds the rotor; fed
//! forward whole, that torque reads as an acceleration p·T*/Ĵ of a rotor that does not move,
//! and the trackers' speed runs up until their load integrator learns it (measured on the
//! multirotor preset: T2S-2 at 290 r/min over a held rotor; at the hand-over the speed loop
//! then takes the holding torque away and the rotor falls back 2 rad). So the drive feeds
//! forward p·(T* − T_hold)/Ĵ with T_hold = 1.5·p·λ̂f·i_hold, i_hold
//! ([`ReleaseHold::load`](crate::control::release_hold::ReleaseHold::load)) the hold's whole
//! command while it acts (the rotor it holds does not accelerate on average: the trackers
//! follow its small travel as a type-3 loop without feed-forward) and its integral, the load
//! it found, after the hand-over until it is armed again: the same as starting the trackers'
//! load integrator â at −p·T_hold/Ĵ. Zero where the hold never acts, so nothing else changes.
//! Measured with a feed-forward less the integral alone (the hold's proportional kick still
//! fed forward): the trackers swing ±200 r/min and the multirotor's θ̂ ends 0.3 rad off at the
//! hand-over.
//!
//! **T2S-1 at a brake's release.** When the brake opens, the rotor falls under a load the
//! drive does not know: the unannounced step of acceleration a = p·T_L/Ĵ (up to the rated
//! p·T_rated/Ĵ) that T2S-1's running bandwidth is placed against, at standstill, where T2S-1
//! keeps its standstill bandwidth. The feed-forward cannot announce it — a braked rotor's
//! currents say nothing of the load the brake takes (no motion, no back-EMF: the currents are
//! the drive's own commands), and while the hold acts the trackers are fed nothing of its
//! command — so the lag is κ·a/ωn² of the standstill ωn: on the made-up 45 µH 48 V motor
//! (7 pole pairs, 2.31 N·m, 1.2·10⁻⁴ kg·m²: a = 1.35·10⁵ rad/s²) the 60 Hz type-3 T2S-1
//! (ωn = 183 s⁻¹) would lag 2 rad before the hold catches the rotor, and it lags the hold's
//! own catch by 0.22–0.29 rad (seeds 1–4); the tracked angle also triggers the hold 0.7 ms
//! late, in which the rotor falls a further 0.1 rad. So from the brake's opening until the
//! hold hands over ([`ReleaseHoldTuning::track_fall`](crate::control::release_hold::ReleaseHoldTuning::track_fall)),
//! T2S-1 runs at its running bandwidth in limiter mode too
//! ([`SensorlessEstimator::set_release_tracking`](crate::SensorlessEstimator::set_release_tracking)):
//! 219 Hz on that motor, where the rated step peaks at `load_step_error`; measured 0.07–0.08 rad
//! and a backward travel of 0.23–0.28 rad instead of 0.37–0.48 (docs/results/startup.md). The
//! standstill's reason for the narrower tracker — the directly calculated angle carries the
//! limiter's errors, which a wider tracker passes to θ̂ — holds over seconds of standstill and
//! departure, not over the hold's 10/ω_h (23 ms on that motor), in which the direct angle
//! stays within 0.05 rad of the rotor. Where the drive derives no running bandwidth (the
//! paper's trackers, every preset but the two outrunners) nothing changes.

use crate::Real;
use crate::control::DriveTuning;
use crate::estimator::EstimatorTuning;
use crate::machine::MachineModel;
use crate::real::cast_record;
use crate::tracker::TrackerConfig;

/// Load-integrator pole of the trackers the rule turns on, as a ratio of ωn: 0.5 \[A\] (the
/// range scenarios' value, docs/range.md).
pub const LOAD_POLE_RATIO: f64 = 0.5;

/// The largest Kp·Ts the bandwidth rule gives T2S-1: 0.25 \[A\], half the type-3 tracker's
/// own refusal limit (`crate::tracker`), so that the rule never builds a refused tracker and
/// the discrete poles stay near their continuous places.
pub const MAX_KP_TS: f64 = 0.25;

/// `[controller.tracker_feedforward]`: the rule of the module docs.
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
pub struct TrackerFeedforwardTuning<T> {
    /// Give the estimator's speed trackers the acceleration the commanded torque causes,
    /// p·T*/Ĵ (a mechanical-model feed-forward, see [`crate::tracker`]); use with the
    /// estimator's `tracker.load_pole_ratio` > 0, whose third integrator takes up the load.
    /// Default false (the paper's trackers) \[A\]; the drive turns it on itself on a rotor its
    /// trackers would lag by more than `max_lag` (the module docs).
    pub enabled: bool,
    /// Largest angle lag (rad) of the type-2 T2S-1 behind an acceleration at the current limit
    /// that the drive leaves without feed-forward. Default 2 rad \[A\]: the multirotor preset
    /// (2.4 rad) and the cheetah outrunner (3.0 rad) need the feed-forward; a 750 W 10-pole
    /// servo (1.5–2 rad) holds its loaded start without it and loses it with it (5 rad
    /// backward, `fado-sim/tests/loaded_start.rs`); the strongly salient presets lose their
    /// `reversal` with it. A large value (1e9) keeps the paper's trackers on every rotor.
    pub max_lag: T,
    /// Peak angle error (rad) of T2S-1 under a step of the rated load torque that the drive
    /// allows where it runs the type-3 trackers (acceleration feed-forward on, load pole > 0):
    /// T2S-1's bandwidth is raised until κ·p·T_rated/(Ĵ·ωn²) is within it (module docs).
    /// Default 0.15 rad \[A\]: the closed loop adds 20–45 % to the model's peak (the directly
    /// calculated angle lags the rotor by the observer's own dynamics; measured 0.19 and
    /// 0.22 rad on a rated step on the cheetah and 6215 outrunners, `fado-sim/tests/
    /// fast_motors.rs`), and `fullrange`'s step of half the rated torque peaks below 0.1 rad,
    /// the range scenarios' aim. A large value (1e9) keeps the tuning's bandwidth.
    pub load_step_error: T,
    /// Mechanical time constant τm = Ĵ·Ω_rated/T_rated (s) above which the drive turns the
    /// feed-forward on (the module docs, "A heavy rotor"). Default 4 s \[A\]: the drawn 30 kW
    /// surface-magnet machine of τm = 6.1 s needs it in `stops` (0.31 rad without, 0.05 with);
    /// saturated IPM machines of τm = 1.35, 1.75 and 3.76 s lose a loaded start with it. A large
    /// value (1e9) keeps the paper's trackers on every heavy rotor.
    pub heavy_rotor_time: T,
}

impl<T: Real> Default for TrackerFeedforwardTuning<T> {
    fn default() -> Self {
        Self {
            enabled: false,
            max_lag: T::lit(2.0),
            load_step_error: T::lit(0.15),
            heavy_rotor_time: T::lit(4.0),
        }
    }
}

cast_record!(TrackerFeedforwardTuning { max_lag, load_step_error, heavy_rotor_time ; enabled });

/// κ(ζ, c): the peak phase error of a tracker with poles (s² + 2ζ·s + 1)(s + c), ωn = 1,
/// after a unit step of unannounced acceleration, i.e. the peak of the impulse response of
/// 1/((s² + 2ζ·s + 1)(s + c)) (module docs; the peak error is κ·α/ωn²). Integrated by the
/// classical Runge–Kutta method over 40/ωn (the peak comes within 2π/ωn; beyond it the
/// response only decays), step 0.01/ωn.
pub fn load_step_peak<T: Real>(damping: T, c: T) -> T {
    let (kp, ki, k3) = (
        T::lit(2.0) * damping + c,
        T::one() + T::lit(2.0) * damping * c,
        c,
    );
    // x = (e, ė, ë); e⃛ = −Kp·ë − Ki·ė − K3·e; an impulse sets ë(0+) = 1.
    let f = |x: [T; 3]| [x[1], x[2], -(kp * x[2] + ki * x[1] + k3 * x[0])];
    let h = T::lit(0.01);
    let mut x = [T::zero(), T::zero(), T::one()];
    let mut peak = T::zero();
    for _ in 0..4000 {
        let k1 = f(x);
        let k2 = f(core::array::from_fn(|i| x[i] + h * T::lit(0.5) * k1[i]));
        let k3s = f(core::array::from_fn(|i| x[i] + h * T::lit(0.5) * k2[i]));
        let k4 = f(core::array::from_fn(|i| x[i] + h * k3s[i]));
        x = core::array::from_fn(|i| {
            x[i] + h / T::lit(6.0) * (k1[i] + T::lit(2.0) * (k2[i] + k3s[i]) + k4[i])
        });
        peak = crate::real::max(peak, x[0].abs());
    }
    peak
}

/// The type-2 gains (Kp, Ki) of a tracker of the estimator's tuning at `bandwidth_hz`,
/// sampled every `ts`.
fn tracker_gains<T: Real>(estimator: &EstimatorTuning<T>, bandwidth_hz: T, ts: T) -> (T, T) {
    let t = &estimator.tracker;
    TrackerConfig {
        damping: t.damping,
        definition: t.bandwidth_definition,
        ..TrackerConfig::new(bandwidth_hz, ts)
    }
    .gains()
}

/// T2S-1's running bandwidth (Hz, in the tuning's own definition; `tracker.
/// t2s1_running_bandwidth_hz`) at which a step of the rated load torque peaks at
/// `load_step_error` in the type-3 tracker (module docs); the tuning's own (its running
/// bandwidth, else `t2s1_bandwidth_hz`) where that is already enough, at most the one of
/// Kp·Ts = [`MAX_KP_TS`].
pub fn load_step_bandwidth<T: Real>(
    machine: &MachineModel<T>,
    drive: &DriveTuning<T>,
    estimator: &EstimatorTuning<T>,
    ts: T,
) -> T {
    let t = &estimator.tracker;
    let own = if t.t2s1_running_bandwidth_hz > T::zero() {
        t.t2s1_running_bandwidth_hz
    } else {
        t.t2s1_bandwidth_hz
    };
    let wn = tracker_gains(estimator, own, ts).1.sqrt();
    let alpha = T::lit(machine.pole_pairs as f64) * machine.rated_torque / machine.inertia;
    let kappa = load_step_peak(t.damping, t.load_pole_ratio);
    let wn_needed = (kappa * alpha / drive.tracker_feedforward.load_step_error).sqrt();
    let wn_max = T::lit(MAX_KP_TS) / ((T::lit(2.0) * t.damping + t.load_pole_ratio) * ts);
    let wn_new = crate::real::min(wn_needed, wn_max);
    // NaN compares false: the tuning's bandwidth.
    if wn_new > wn { own * wn_new / wn } else { own }
}

/// The angle (rad) by which the type-2 T2S-1 of `estimator`, sampled every `ts`, lags the
/// electrical acceleration p·T_max/Ĵ of `machine` at the drive's current limit (module docs).
pub fn current_limit_lag<T: Real>(
    machine: &MachineModel<T>,
    drive: &DriveTuning<T>,
    estimator: &EstimatorTuning<T>,
    ts: T,
) -> T {
    let (_, ki) = tracker_gains(estimator, estimator.tracker.t2s1_bandwidth_hz, ts);
    let ratio = crate::real::min(drive.current.limit_ratio, drive.limits.torque_ratio);
    let p = T::lit(machine.pole_pairs as f64);
    p * ratio * machine.rated_torque / (machine.inertia * ki)
}

/// Applies the rules of the module docs (the feed-forward, then T2S-1's bandwidth) to the drive's and the estimator's tuning, in place.
pub fn apply<T: Real>(
    machine: &MachineModel<T>,
    drive: &mut DriveTuning<T>,
    estimator: &mut EstimatorTuning<T>,
    ts: T,
) {
    // NaN compares false: no feed-forward.
    if current_limit_lag(machine, drive, estimator, ts) > drive.tracker_feedforward.max_lag {
        drive.tracker_feedforward.enabled = true;
        if estimator.tracker.load_pole_ratio == T::zero() {
            estimator.tracker.load_pole_ratio = T::lit(LOAD_POLE_RATIO);
        }
    }
    // A heavy rotor: the feed-forward alone, the type-2 pair kept (module docs).
    if crate::control::speed_bandwidth::mechanical_time_constant(machine)
        > drive.tracker_feedforward.heavy_rotor_time
    {
        drive.tracker_feedforward.enabled = true;
    }
    if drive.tracker_feedforward.enabled && estimator.tracker.load_pole_ratio > T::zero() {
        let running = load_step_bandwidth(machine, drive, estimator, ts);
        if running != estimator.tracker.t2s1_bandwidth_hz {
            estimator.tracker.t2s1_running_bandwidth_hz = running;
        }
    }
}

/// The machine model of the `multirotor-mn5006-22v` preset's ratings (14 pole pairs,
/// 0.875 mWb, 34 A, 0.625 N·m, 8000 r/min, 2e-4 kg·m²; the paper's R and L), for the tests of
/// the fast-motor rules.
#[cfg(test)]
pub(crate) fn multirotor_model() -> MachineModel<f64> {
    MachineModel {
        pole_pairs: 14,
        flux_linkage: 8.75e-4,
        rated_current: 34.0,
        rated_torque: 0.625,
        rated_speed_rpm: 8000.0,
        inertia: 2.0e-4,
        ..MachineModel::paper()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn resolve(
        m: &MachineModel<f64>,
        mut d: DriveTuning<f64>,
        mut e: EstimatorTuning<f64>,
        ts: f64,
    ) -> (DriveTuning<f64>, EstimatorTuning<f64>) {
        apply(m, &mut d, &mut e, ts);
        (d, e)
    }

    #[test]
    fn the_lag_grows_with_the_rated_electrical_speed_and_turns_the_feedforward_on() {
        let d = DriveTuning::<f64>::default();
        let e = EstimatorTuning::<f64>::default();
        // The paper's motor (with its dynamometer, 0.012 kg·m²): 4·(40/21.78)·11.5/0.012 =
        // 7.0e3 rad/s² against Ki = (2π·60/2.058)² = 3.36e4 s⁻²: 0.21 rad, type-2 kept.
        let m = MachineModel::<f64>::paper();
        let lag = current_limit_lag(&m, &d, &e, 100e-6);
        assert!((lag - 0.21).abs() < 0.01, "{lag}");
        let (d2, e2) = resolve(&m, d, e, 100e-6);
        assert!(!d2.tracker_feedforward.enabled && e2.tracker.load_pole_ratio == 0.0);
        assert_eq!((d2, e2), (d, e));
        // A 14-pole-pair multirotor motor with its propeller: 2.4 rad, feed-forward on.
        let fast = multirotor_model();
        let lag = current_limit_lag(&fast, &d, &e, 25e-6);
        assert!((lag - 2.4).abs() < 0.05, "{lag}");
        let (d2, e2) = resolve(&fast, d, e, 25e-6);
        assert!(d2.tracker_feedforward.enabled);
        assert_eq!(e2.tracker.load_pole_ratio, LOAD_POLE_RATIO);
        // A tuning's own load pole is kept; an infinite threshold keeps the paper's trackers.
        let mut own = e;
        own.tracker.load_pole_ratio = 0.3;
        assert_eq!(resolve(&fast, d, own, 25e-6).1.tracker.load_pole_ratio, 0.3);
        let mut off = d;
        off.tracker_feedforward.max_lag = 1e9;
        assert!(!resolve(&fast, off, e, 25e-6).0.tracker_feedforward.enabled);
    }

    #[test]
    fn a_heavy_rotor_gets_the_feedforward_with_the_type_2_pair() {
        let d = DriveTuning::<f64>::default();
        let e = EstimatorTuning::<f64>::default();
        // The drawn 30 kW surface-magnet machine: 2.92 kg·m², 119.2 N·m at 2,367.85 r/min,
        // τm = 2.92·247.96/119.2 = 6.08 s; its current-limit lag 0.04 rad.
        let heavy = MachineModel {
            pole_pairs: 17,
            flux_linkage: 0.0867633,
            rated_current: 53.8655,
            rated_torque: 119.175,
            rated_speed_rpm: 2367.85,
            inertia: 2.92478,
            ..MachineModel::<f64>::paper()
        };
        let ts = 1.0 / 21e3;
        let tau = crate::control::speed_bandwidth::mechanical_time_constant(&heavy);
        assert!((tau - 6.085).abs() < 0.01, "{tau}");
        assert!(current_limit_lag(&heavy, &d, &e, ts) < d.tracker_feedforward.max_lag);
        let (d2, e2) = resolve(&heavy, d, e, ts);
        assert!(d2.tracker_feedforward.enabled);
        assert_eq!(e2, e);
        // The same rotor at τm = 3.9 s, below the 4 s threshold, and with an infinite
        // threshold: the paper's trackers.
        let light = MachineModel {
            inertia: heavy.inertia * 3.9 / tau,
            ..heavy
        };
        assert_eq!(resolve(&light, d, e, ts), (d, e));
        let mut off = d;
        off.tracker_feedforward.heavy_rotor_time = 1e9;
        assert_eq!(resolve(&heavy, off, e, ts), (off, e));
    }

    #[test]
    fn the_load_step_peak_is_the_impulse_response_peak() {
        let z = crate::tracker::DEFAULT_DAMPING;
        // c = 0: the type-2 pair's lag α/ωn² with the step response's overshoot
        // 1 + exp(−πζ/√(1 − ζ²)) = 1.0432.
        let k0 = load_step_peak(z, 0.0);
        assert!(
            (k0 - (1.0 + (-core::f64::consts::PI * z / (1.0 - z * z).sqrt()).exp())).abs() < 1e-3,
            "{k0}"
        );
        // The load pole shortens the lag: 0.50 at c = 0.5, falling with c.
        let k = load_step_peak(z, 0.5);
        assert!((k - 0.50).abs() < 0.01, "{k}");
        assert!(load_step_peak(z, 1.0) < k && load_step_peak(z, 2.0) < load_step_peak(z, 1.0));
    }

    /// The discrete type-3 T2S-1 at the rule's bandwidth, fed the angle of a rotor that a
    /// step `alpha` of unannounced acceleration starts to decelerate at speed `omega0`: the
    /// largest phase error after the step.
    fn discrete_step_error(bw: f64, ratio: f64, ts: f64, omega0: f64, alpha: f64) -> f64 {
        let cfg = TrackerConfig::new(bw, ts);
        let mut t = crate::tracker::TypeTwoTracker::with_load_pole(cfg, ratio).unwrap();
        // Locked before the step: the prediction for the first sample is the rotor's angle.
        t.reset_to(omega0 * ts, omega0);
        let mut peak = 0.0f64;
        for k in 1..(0.2 / ts) as usize {
            let time = k as f64 * ts;
            let theta = omega0 * time - 0.5 * alpha * time * time;
            t.step(crate::wrap_angle(theta)).unwrap();
            peak = peak.max(crate::wrap_angle(theta - t.angle()).abs());
        }
        peak
    }

    #[test]
    fn a_light_rotor_gets_the_t2s1_bandwidth_its_rated_load_step_needs() {
        // The cheetah outrunner preset: 21 pole pairs, 1.32 N·m, 5e-4 kg·m², Ts = 25 µs.
        let cheetah = MachineModel {
            pole_pairs: 21,
            flux_linkage: 0.0024,
            rated_current: 17.5,
            rated_torque: 1.32,
            rated_speed_rpm: 1800.0,
            inertia: 5e-4,
            ..MachineModel::<f64>::paper()
        };
        let ts = 25e-6;
        let (d, e) = resolve(
            &cheetah,
            DriveTuning::default(),
            EstimatorTuning::default(),
            ts,
        );
        assert!(d.tracker_feedforward.enabled);
        let bw = e.tracker.t2s1_running_bandwidth_hz;
        assert!((bw - 141.0).abs() < 2.0, "{bw}");
        assert_eq!(e.tracker.t2s1_bandwidth_hz, 60.0);
        assert_eq!(e.tracker.t2s2_bandwidth_hz, 35.0);
        // The discrete tracker meets the bound (and not by a wide margin) under the rated
        // step at rated speed; the paper's 60 Hz does not.
        let alpha = 21.0 * 1.32 / 5e-4;
        let omega0 = 1800.0 * 21.0 * core::f64::consts::PI / 30.0;
        let err = discrete_step_error(bw, LOAD_POLE_RATIO, ts, omega0, alpha);
        assert!(err < 0.15 && err > 0.135, "{err}");
        let err60 = discrete_step_error(60.0, LOAD_POLE_RATIO, ts, omega0, alpha);
        assert!(err60 > 0.8, "{err60}");
        // The paper's motor with the feed-forward on keeps its 60 Hz to the bit (its rated
        // step peaks at 0.057 rad), and without the feed-forward nothing changes.
        let mut on = DriveTuning::default();
        on.tracker_feedforward.enabled = true;
        let mut e3 = EstimatorTuning::default();
        e3.tracker.load_pole_ratio = LOAD_POLE_RATIO;
        let paper = MachineModel::<f64>::paper();
        assert_eq!(resolve(&paper, on, e3, 100e-6).1, e3);
        // A limit of 1e9 keeps the tuning's bandwidth; an absurd rotor is capped at Kp·Ts.
        let mut keep = DriveTuning::default();
        keep.tracker_feedforward.load_step_error = 1e9;
        let e_keep = resolve(&cheetah, keep, EstimatorTuning::default(), ts).1;
        assert_eq!(e_keep.tracker.t2s1_running_bandwidth_hz, 0.0);
        let feather = MachineModel {
            inertia: 1e-9,
            ..cheetah
        };
        let e_cap = resolve(
            &feather,
            DriveTuning::default(),
            EstimatorTuning::default(),
            ts,
        )
        .1;
        let cfg = TrackerConfig::new(e_cap.tracker.t2s1_running_bandwidth_hz, ts);
        let kp_ts = (2.0 * cfg.damping + LOAD_POLE_RATIO) * cfg.gains().1.sqrt() * ts;
        assert!((kp_ts - MAX_KP_TS).abs() < 1e-9, "{kp_ts}");
        assert!(crate::tracker::TypeTwoTracker::with_load_pole(cfg, LOAD_POLE_RATIO).is_ok());
    }
}
