//! The whole operating range as two scenarios scaled by a motor's ratings, `fullrange` and
//! `regen-stop`, and the model limits they aim at.
//!
//! **Limits from the model.** The steady-state machine (the drive's model: R̂s, L̂d, L̂q,
//! λ̂f) with |i| ≤ I_max (`[controller.current] limit_ratio`) and |v| ≤ m·V_dc/√3 (the field
//! weakening loop's `voltage_margin` of the inscribed circle) gives the largest torque at
//! each speed, found by a scan of i_d over [−I_max, 0] with the largest i_q both limits allow
//! ([`max_torque`]). `fullrange`'s top speed is the highest speed up to 2× the rated one at
//! which the limits still give half the rated power, and it holds min(rated power,
//! [`POWER_MARGIN`] × the limits' power) there (the margin is the loop's headroom: the
//! current loop needs voltage to move the current).

pub mod timing;

use crate::config::SimConfig;
use crate::profile::Profile;
use timing::{Phase, Timeline};

/// Share of the model's power at the top speed that `fullrange` holds: 0.8 \[A\].
pub const POWER_MARGIN: f64 = 0.8;
/// `fullrange` accelerates to at most this multiple of the rated speed (the cap).
pub const TOP_SPEED_CAP: f64 = 2.0;
/// The top speed is the highest at which the limits give at least this share of the rated
/// power: 0.5 \[A\].
pub const TOP_POWER_SHARE: f64 = 0.5;

/// What the model allows a drive configuration.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct RangeTargets {
    /// Rated speed, r/min.
    pub rated_speed_rpm: f64,
    /// Rated power (rated torque × rated speed), W.
    pub rated_power: f64,
    /// Top speed the scenario asks, r/min.
    pub top_speed_rpm: f64,
    /// Largest power the limits give at the top speed, W.
    pub limit_power_at_top: f64,
    /// Power held at the top speed, W.
    pub hold_power: f64,
}

/// Largest torque (N·m) of the model at the electrical speed `omega` (rad/s) with
/// |i| ≤ `i_max` (A) and |v| ≤ `v_max` (V), steady state.
pub fn max_torque(cfg: &SimConfig, omega: f64, i_max: f64, v_max: f64) -> f64 {
    let m = cfg.machine_model();
    let p = m.pole_pairs as f64;
    let voltage = |id: f64, iq: f64| {
        let vd = m.rs * id - omega * m.lq * iq;
        let vq = m.rs * iq + omega * (m.flux_linkage + m.ld * id);
        (vd * vd + vq * vq).sqrt()
    };
    let mut best: f64 = 0.0;
    let steps = 400;
    for k in 0..=steps {
        let id = -i_max * k as f64 / steps as f64;
        let iq_cur = (i_max * i_max - id * id).max(0.0).sqrt();
        if voltage(id, 0.0) > v_max {
            continue;
        }
        // |v| grows with i_q (motoring) here: bisect for the voltage limit.
        let (mut lo, mut hi) = (0.0, iq_cur);
        if voltage(id, hi) <= v_max {
            lo = hi;
        } else {
            for _ in 0..50 {
                let mid = 0.5 * (lo + hi);
                if voltage(id, mid) <= v_max {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
        }
        let torque = 1.5 * p * (m.flux_linkage + (m.ld - m.lq) * id) * lo;
        best = best.max(torque);
    }
    best
}

/// The model's limits for `cfg`'s drive: (the current limit |i| ≤ I_max, A; the voltage
/// limit |v| ≤ the field-weakening loop's `voltage_margin` × V_dc/√3, V).
pub fn limits(cfg: &SimConfig) -> (f64, f64) {
    let i_max = cfg.controller.current.limit_ratio * cfg.machine_model().rated_current;
    let v_max =
        cfg.controller.field_weakening.voltage_margin * cfg.inverter.dc_voltage / 3f64.sqrt();
    (i_max, v_max)
}

/// The targets of `fullrange` for `cfg`'s motor and drive.
pub fn targets(cfg: &SimConfig) -> RangeTargets {
    let m = cfg.machine_model();
    let rated = m.rated_speed_rpm;
    let w_mech = |rpm: f64| rpm * std::f64::consts::TAU / 60.0;
    let p = m.pole_pairs as f64;
    let rated_power = m.rated_torque * w_mech(rated);
    let (i_max, v_max) = limits(cfg);
    let power = |rpm: f64| max_torque(cfg, p * w_mech(rpm), i_max, v_max) * w_mech(rpm);
    // Highest speed (1 % steps of the rated speed) up to the cap with half the rated power.
    let mut top = rated;
    let mut k = 100;
    while k as f64 <= TOP_SPEED_CAP * 100.0 {
        let n = rated * k as f64 / 100.0;
        if power(n) >= TOP_POWER_SHARE * rated_power {
            top = n;
        } else {
            break;
        }
        k += 1;
    }
    let limit = power(top);
    RangeTargets {
        rated_speed_rpm: rated,
        rated_power,
        top_speed_rpm: top,
        limit_power_at_top: limit,
        hold_power: rated_power.min(POWER_MARGIN * limit),
    }
}

/// A settled window of a scenario: the reference holds `level_rpm` over `[from, to]`.
pub type Hold = (f64, f64, f64);

/// `fullrange`'s phases in the base timeline: to the rated speed under half the rated torque,
/// the rated load step, field weakening to the top speed, braking through zero to a
/// standstill under 65 % of the rated torque, the rated speed reversed.
fn fullrange_phases(c: &SimConfig, t: &RangeTargets) -> [Phase; 5] {
    let n = c.motor.rated_speed_rpm;
    let top = t.top_speed_rpm;
    let phase = Phase::new;
    [
        phase(1.2, 2.0, 2.5, n),
        phase(2.5, 3.0, 3.5, n),
        phase(3.5, 7.0, 8.0, top),
        phase(8.0, 9.0, 10.0, 0.0),
        phase(10.0, 11.0, 12.0, -n),
    ]
}

/// `fullrange`'s (speed, load) profiles for the targets `t` on the timeline `line`.
fn fullrange_profiles(c: &SimConfig, t: &RangeTargets, line: &Timeline) -> (Profile, Profile) {
    let n = t.rated_speed_rpm;
    let top = t.top_speed_rpm;
    let rated_torque = c.motor.rated_torque;
    let top_torque = t.hold_power / (top * std::f64::consts::TAU / 60.0);
    let (s, w) = (&line.start, &line.window);
    // Ramps of 0.1 s ask for more than the current limit gives: the drive accelerates and
    // brakes at its limit.
    let speed = [
        (0.0, 0.0),
        (1.2 + s[0], 0.0),
        (1.3 + s[0], n), // at the current limit to the rated speed, under 50 %
        (3.5 + s[2], n),
        (5.5 + s[2], top), // field weakening (at the limit if it cannot follow)
        (8.0 + s[3], top),
        (8.1 + s[3], 0.0), // brake through zero at the current limit
        (10.0 + s[4], 0.0),
        (10.1 + s[4], -n), // and the other way
        (12.0 + w[4], -n),
    ];
    let load = [
        (0.0, 0.0),
        (0.7, 0.0),
        (1.0, 0.5 * rated_torque),
        (2.5 + s[1], 0.5 * rated_torque),
        (2.5 + s[1], rated_torque), // rated load step at rated speed
        (3.5 + s[2], rated_torque),
        (5.5 + s[2], top_torque),
        (8.0 + s[3], top_torque),
        (8.1 + s[3], 0.65 * rated_torque),
        (12.0 + w[4], 0.65 * rated_torque),
    ];
    (Profile::from_points(&speed), Profile::from_points(&load))
}

/// `fullrange`'s timeline on `c`: the base one, or longer where the rotor needs it
/// ([`timing`]).
pub fn fullrange_timeline(c: &SimConfig) -> Timeline {
    fullrange_plan(c).2
}

/// `fullrange`'s targets, phases and timeline on `c`, each found once.
fn fullrange_plan(c: &SimConfig) -> (RangeTargets, [Phase; 5], Timeline) {
    let t = targets(c);
    let phases = fullrange_phases(c, &t);
    let top = t.top_speed_rpm.max(c.motor.rated_speed_rpm);
    let line = timing::plan(c, &phases, top, |line| fullrange_profiles(c, &t, line));
    (t, phases, line)
}

/// `fullrange`'s profile on `c` (scaled by its ratings, its model's limits and its rotor's
/// time to reach each speed); returns the settled windows judged.
pub fn setup_fullrange(c: &mut SimConfig) -> Vec<Hold> {
    let (t, phases, line) = fullrange_plan(c);
    let profiles = fullrange_profiles(c, &t, &line);
    apply(c, profiles, 12.0 + line.window[4]);
    holds(&phases, &line)
}

/// Sets a range scenario's (speed, load) profiles and its duration (s) on `c`, judged from
/// 0.7 s, with the feed-forward the scenario's transients need.
fn apply(c: &mut SimConfig, (speed, load): (Profile, Profile), duration: f64) {
    c.speed_reference = speed;
    c.load.torque = load;
    c.simulation.duration = duration;
    c.simulation.eval_start = 0.7;
    enable_feedforward(c);
}

/// The settled windows of `phases` on `line`.
fn holds(phases: &[Phase], line: &Timeline) -> Vec<Hold> {
    phases
        .iter()
        .zip(&line.window)
        .map(|(p, w)| (p.level_rpm, p.from + w, p.to + w))
        .collect()
}

/// `fullrange`'s settled windows (the second half of each hold of the reference, after the
/// load has settled): rated speed before and after the load step, the top speed, standstill
/// under 65 % of the rated torque, the rated speed reversed.
pub fn fullrange_holds(c: &SimConfig) -> Vec<Hold> {
    let (_, phases, line) = fullrange_plan(c);
    holds(&phases, &line)
}

/// `regen-stop`'s phases in the base timeline: to the rated speed, a stop at the current
/// limit, the rated speed under the overhauling load, a stop against it.
fn regen_stop_phases(c: &SimConfig) -> [Phase; 4] {
    let n = c.motor.rated_speed_rpm;
    let phase = Phase::new;
    [
        phase(0.7, 2.0, 2.5, n),
        phase(2.5, 3.5, 4.0, 0.0),
        phase(4.0, 5.5, 6.0, n),
        phase(6.0, 7.0, 8.0, 0.0),
    ]
}

/// `regen-stop`'s (speed, load) profiles on the timeline `line`.
fn regen_stop_profiles(c: &SimConfig, line: &Timeline) -> (Profile, Profile) {
    let n = c.motor.rated_speed_rpm;
    let rated_torque = c.motor.rated_torque;
    let (s, w) = (&line.start, &line.window);
    let speed = [
        (0.0, 0.0),
        (0.7, 0.0),
        (1.7, n),
        (2.5 + s[1], n),
        (2.6 + s[1], 0.0), // stop at the current limit
        (4.0 + s[2], 0.0),
        (5.0 + s[2], n),
        (6.0 + s[3], n),
        (6.1 + s[3], 0.0), // stop against the overhauling load, then hold it
        (8.0 + w[3], 0.0),
    ];
    let load = [
        (0.0, 0.0),
        (4.0 + s[2], 0.0),
        (4.5 + s[2], -rated_torque),
        (8.0 + w[3], -rated_torque),
    ];
    (Profile::from_points(&speed), Profile::from_points(&load))
}

/// `regen-stop`'s timeline on `c` ([`timing`]).
pub fn regen_stop_timeline(c: &SimConfig) -> Timeline {
    let phases = regen_stop_phases(c);
    timing::plan(c, &phases, c.motor.rated_speed_rpm, |line| {
        regen_stop_profiles(c, line)
    })
}

/// `regen-stop`'s profile on `c`: a rectifier with a brake chopper; a stop from the rated
/// speed at the current limit, then a stop from the rated speed against an overhauling rated
/// load (it pulls towards positive rotation); returns the settled windows judged.
pub fn setup_regen_stop(c: &mut SimConfig) -> Vec<Hold> {
    c.dc_link.source = crate::dc_link::DcSource::Rectifier;
    if c.dc_link.chopper_voltage.is_none() {
        c.dc_link.chopper_voltage = Some(CHOPPER_RATIO * c.inverter.dc_voltage);
    }
    let line = regen_stop_timeline(c);
    let profiles = regen_stop_profiles(c, &line);
    apply(c, profiles, 8.0 + line.window[3]);
    holds(&regen_stop_phases(c), &line)
}

/// `regen-stop`'s settled windows: rated speed, standstill after the first stop, rated speed
/// under the overhauling load, standstill holding it.
pub fn regen_stop_holds(c: &SimConfig) -> Vec<Hold> {
    holds(&regen_stop_phases(c), &regen_stop_timeline(c))
}

/// `regen-stop`'s chopper switches on at this multiple of the nominal bus: 1.05 \[A\] (below
/// the over-voltage controller's 1.1 start).
pub const CHOPPER_RATIO: f64 = 1.05;

/// The acceleration feed-forward and the type-3 trackers (`crate::scenario` docs): what a
/// drive needs through current-limited transients.
fn enable_feedforward(c: &mut SimConfig) {
    c.controller.tracker_feedforward.enabled = true;
    if c.estimator.tracker.load_pole_ratio == 0.0 {
        c.estimator.tracker.load_pole_ratio = 0.5;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_limits_of_the_paper_motor() {
        let c = SimConfig::default();
        let t = targets(&c);
        // λf/Ld = 33.5 A < I_max = 40 A: an infinite-speed machine, top speed the 2× cap,
        // and the rated power within its limits there.
        assert_eq!(t.top_speed_rpm, 3000.0);
        assert!(t.limit_power_at_top > t.rated_power, "{t:?}");
        assert_eq!(t.hold_power, t.rated_power);
        // At standstill the limit is the current limit's torque: 1.5·p·λf·I_max.
        let m = c.machine_model();
        let i_max = c.controller.current.limit_ratio * m.rated_current;
        let t0 = max_torque(&c, 0.0, i_max, 1e3);
        assert!((t0 - 1.5 * 4.0 * m.flux_linkage * i_max).abs() < 1e-9 * t0);
        // Above the voltage limit's corner the torque falls.
        let v = 0.92 * 311.0 / 3f64.sqrt();
        let corner = v / m.flux_linkage; // no-load corner, rad/s electrical
        assert!(max_torque(&c, 2.0 * corner, i_max, v) < 0.8 * t0);
    }
}
