//! The profiles scaled by the motor's ratings: `lowspeed`, `reversal`, `rated-reversal`,
//! `stops`, `loaded-start`, `fullrange` and `regen-stop`, with their ratios.

use crate::config::SimConfig;
use crate::profile::Profile;

/// Load of `loaded-start`, fraction of the rated torque: a full load (a hoist at its rated
/// load, a vehicle on its steepest slope).
pub const LOADED_START_LOAD_RATIO: f64 = 1.0;
/// Largest backward travel of the rotor after the brake's release in `loaded-start`,
/// electrical rad.
pub const LOADED_START_MAX_BACK: f64 = 0.5;
/// `loaded-start`: the speed reference is 0 until this time (s), longer than every preset's
/// start-up (offset and gain calibrations), then ramps to the target in 1 s.
pub(super) const LOADED_START_RAMP_AT: f64 = 1.0;
/// `loaded-start`: the brake opens this long (s) before the lift, once the drive is ready
/// (a hoist's brake sequence: open, hold, lift), so that the loaded rotor does not stand on
/// the drive alone for however long its start-up left. 0.1 s \[A\]: the release hold's
/// settling (10/ω_h) on every preset.
pub const LOADED_START_BRAKE_LEAD: f64 = 0.3;
/// `loaded-start`: duration (s); the speed is judged over its last 0.5 s.
pub(super) const LOADED_START_DURATION: f64 = 3.0;

/// The rotor's start angle of `loaded-start` for a seed: electrical rad in [−π, π), spread by
/// the golden ratio (seeds 1, 2, 3, 4: 0.74, −1.49, 2.57, 0.33 rad).
pub fn loaded_start_angle(seed: u64) -> f64 {
    let x = (seed as f64 * 0.618_033_988_749_894_9).fract();
    std::f64::consts::TAU * x - std::f64::consts::PI
}

/// Load of the scaled `reversal` and `stops`, as a fraction of the rated torque: the paper's
/// 7.5 N·m of 11.5 N·m (65.2 %, section V \[P\]).
pub const SCALED_LOAD_RATIO: f64 = 7.5 / 11.5;
/// Speed of the scaled `reversal`, fraction of the rated speed: 90 of 1500 r/min (±6 %, the
/// paper's "less than ±10 % of its rated speed" \[P\]); the reversal ramp is this per second.
pub const REVERSAL_SPEED_RATIO: f64 = 90.0 / 1500.0;
/// Top speed of the scaled `stops`: 60 of 1500 r/min (4 %, Fig. 12 \[A\]).
pub const STOPS_SPEED_RATIO: f64 = 60.0 / 1500.0;
/// The scaled `reversal`'s evaluation start, s (fig11's, 0.3 s after the load's ramp), unless
/// the drive's speed loop settles that ramp later (`load_settling`).
pub const REVERSAL_EVAL_START: f64 = 2.0;
/// Speed-error bound of the scaled scenarios, fraction of the rated speed: 30 of 1500 r/min.
pub const SCALED_SPEED_ERROR_RATIO: f64 = 30.0 / 1500.0;

/// Speed levels of the `lowspeed` staircase, r/min: 4 % of the rated speed halved six times
/// (the paper's motor: 60, 30, …, 0.9375 r/min).
pub fn lowspeed_levels_rpm(rated_speed_rpm: f64) -> [f64; 7] {
    let mut levels = [STOPS_SPEED_RATIO * rated_speed_rpm; 7];
    for k in 1..7 {
        levels[k] = 0.5 * levels[k - 1];
    }
    levels
}
/// Time the `lowspeed` staircase spends at each level (ramp included), s.
pub const LOWSPEED_LEVEL_SECONDS: f64 = 2.0;
/// Ramp from one level to the next, s.
pub(super) const LOWSPEED_RAMP_SECONDS: f64 = 0.2;
/// The last part of each level over which it is judged, s (the ramp and 0.3 s of settling
/// excluded).
pub const LOWSPEED_JUDGED_SECONDS: f64 = 1.5;
/// The first level starts here, s (after the start-up to 60 r/min and the load ramp).
pub(super) const LOWSPEED_START: f64 = 2.0;
/// Angle bound of a held level, rad (the paper's fig11 bound \[P\]).
pub const LOWSPEED_ANGLE_BOUND: f64 = 0.25;

/// Speed bound of a held level at `level_rpm`: the rotor turns in the commanded direction at
/// no less than half the commanded speed (and within 0.5 r/min at the lowest levels).
pub fn lowspeed_speed_bound(level_rpm: f64) -> f64 {
    (0.5 * level_rpm.abs()).max(0.5)
}

/// `fullrange`: see [`crate::range`].
pub(super) fn setup_fullrange(c: &mut SimConfig) {
    crate::range::setup_fullrange(c);
}

/// `regen-stop`: see [`crate::range`].
pub(super) fn setup_regen_stop(c: &mut SimConfig) {
    crate::range::setup_regen_stop(c);
}

/// `lowspeed`: profile, load, duration, evaluation window.
pub(super) fn setup_lowspeed(c: &mut SimConfig) {
    let pts = Profile::from_points;
    let n_rated = c.motor.rated_speed_rpm;
    let t_rated = c.motor.rated_torque;
    let levels = lowspeed_levels_rpm(n_rated);
    let mut p = vec![(0.0, 0.0), (0.2, 0.0), (0.9, levels[0])];
    let mut t = LOWSPEED_START;
    let mut prev = levels[0];
    for level in levels {
        p.extend([(t, prev), (t + LOWSPEED_RAMP_SECONDS, level)]);
        prev = level;
        t += LOWSPEED_LEVEL_SECONDS;
    }
    p.push((t, prev));
    c.speed_reference = pts(&p);
    c.load.torque = pts(&[(0.9, 0.0), (1.4, SCALED_LOAD_RATIO * t_rated)]);
    c.simulation.duration = t;
    c.simulation.eval_start = LOWSPEED_START;
}

/// fig11 in units of the ratings under `load` × the rated torque.
pub(super) fn setup_reversal_under(c: &mut SimConfig, load: f64) {
    let pts = Profile::from_points;
    let n_rated = c.motor.rated_speed_rpm;
    let t_rated = c.motor.rated_torque;
    // fig11 in units of the ratings: 90 r/min = 6 %, 7.5 N·m = 65.2 %.
    let n = REVERSAL_SPEED_RATIO * n_rated;
    c.speed_reference = pts(&[(0.0, 0.0), (0.2, 0.0), (1.2, -n), (2.5, -n), (4.5, n)]);
    c.load.torque = pts(&[(1.2, 0.0), (1.7, load * t_rated)]);
    c.simulation.duration = 5.5;
    // Judged from 2.0 s, or from where the drive's own speed loop has brought the load ramp's
    // error back within the band, at the latest the reversal's start (`load_settling`).
    let band = SCALED_SPEED_ERROR_RATIO * n_rated;
    let settled = super::load_settling::instant(
        c,
        1.2,
        1.7,
        load * t_rated,
        super::load_settling::SETTLED_BAND_SHARE * band,
    );
    c.simulation.eval_start = if settled.is_nan() {
        REVERSAL_EVAL_START
    } else {
        settled.clamp(REVERSAL_EVAL_START, 2.5)
    };
}

/// `reversal`: fig11 scaled, 65.2 % load.
pub(super) fn setup_reversal(c: &mut SimConfig) {
    setup_reversal_under(c, SCALED_LOAD_RATIO);
}

/// `rated-reversal`: fig11 scaled, 100 % load.
pub(super) fn setup_rated_reversal(c: &mut SimConfig) {
    setup_reversal_under(c, 1.0);
}

/// `loaded-start`: brake, seeded angle, the rated torque from t = 0 (on the brake until the
/// release), the lifting ramp.
pub(super) fn setup_loaded_start(c: &mut SimConfig) {
    let n = REVERSAL_SPEED_RATIO * c.motor.rated_speed_rpm;
    let t0 = LOADED_START_RAMP_AT;
    c.simulation.brake = true;
    c.simulation.brake_release_at = t0 - LOADED_START_BRAKE_LEAD;
    c.controller.release_hold.enabled = true;
    c.controller.startup.find_angle = true;
    c.controller.startup.rotor_held = true;
    c.simulation.initial_angle = loaded_start_angle(c.current_sensor.seed);
    with_assumed_d_saturation(c);
    c.speed_reference = Profile::from_points(&[(0.0, 0.0), (t0, 0.0), (t0 + 1.0, n)]);
    c.load.torque = Profile::constant(LOADED_START_LOAD_RATIO * c.motor.rated_torque);
    c.simulation.duration = LOADED_START_DURATION;
    c.simulation.eval_start = 0.0;
}

/// The d-axis saturation `loaded-start` gives a plant whose magnetics are constant
/// inductances: κ = a_dd·λf⁴·Ld (`fado_core::control::initial_angle`'s tests' measure), the
/// relative fall of the inverse incremental inductance per relative rise of the d flux over 20
/// at the magnet's flux. 0.01 \[A\]: no presets' d-axis curve is published; the start-up's
/// detection is shown at half and double it (docs/startup.md).
pub const LOADED_START_D_SATURATION: f64 = 0.01;

/// A plant with constant inductances gets [`LOADED_START_D_SATURATION`] around its magnet
/// (the algebraic model of `fado_core::magnetics::Saturation`, the magnet as the d current
/// i_f: at zero current ψd = λf and the incremental inductances are the datasheet's L_d,
/// L_q); the drive's model stays the datasheet's constants (times any `[mismatch]`).
fn with_assumed_d_saturation(c: &mut SimConfig) {
    if c.motor_saturation.is_some() || c.motor_flux_map.is_some() {
        return;
    }
    let m = &c.motor;
    let (ld, lq, lf) = (m.ld, m.lq, m.flux_linkage);
    let kappa = LOADED_START_D_SATURATION;
    let a_dd = kappa / ld / lf.powi(4);
    let a_d0 = (1.0 - 5.0 * kappa) / ld;
    c.motor_saturation = Some(fado_core::magnetics::Saturation {
        a_d0,
        a_dd,
        s: 4.0,
        a_q0: 1.0 / lq,
        i_f: (a_d0 + a_dd * lf.powi(4)) * lf,
        ..fado_core::magnetics::Saturation::default()
    });
    let r = &c.mismatch;
    let model = c.model.get_or_insert_with(toml::Table::new);
    for (key, value) in [
        ("ld", ld * r.ld_ratio),
        ("lq", lq * r.lq_ratio),
        ("flux_linkage", lf * r.flux_linkage_ratio),
    ] {
        model.entry(key).or_insert(toml::Value::Float(value));
    }
}

/// `stops`: profile, load, duration, evaluation window.
pub(super) fn setup_stops(c: &mut SimConfig) {
    let pts = Profile::from_points;
    let n_rated = c.motor.rated_speed_rpm;
    let t_rated = c.motor.rated_torque;
    // fig12 in units of the ratings: 60 r/min = 4 %, 7.5 N·m = 65.2 %.
    let n = STOPS_SPEED_RATIO * n_rated;
    let mut p = vec![(0.0, 0.0), (0.2, 0.0), (0.9, n), (2.0, n)];
    let mut t = 2.0;
    for _ in 0..3 {
        p.extend([(t + 0.5, 0.0), (t + 0.8, 0.0), (t + 1.3, n), (t + 1.8, n)]);
        t += 1.8;
    }
    c.speed_reference = pts(&p);
    c.load.torque = pts(&[(0.9, 0.0), (1.4, SCALED_LOAD_RATIO * t_rated)]);
    c.simulation.duration = t;
    c.simulation.eval_start = 1.8;
}
