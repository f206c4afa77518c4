//! The time a rotor needs: `fullrange` and `regen-stop` judged where the rotor can be.
//!
//! Both scenarios ask for transients at the drive's limits (to the rated speed at the current
//! limit, field weakening to the top speed, braking through zero) and judge the speed in
//! settled windows after them. How long such a transient lasts is set by the rotor, not by
//! the drive: an ideal drive at the current limit needs J·ω/(T_max − T_L) to change the speed
//! by ω, which on a coupled load of a few times the rotor's own inertia (a vehicle, a
//! flywheel, a hoist's drum) is many seconds. A timeline fixed in seconds would judge such a
//! rotor while it is still accelerating, a failure of the scenario rather than of the drive.
//!
//! Each scenario is a sequence of [`Phase`]s, each with its transient and one judged window.
//! A phase's window opens at its base offset (the paper's-motor timing, which every preset
//! meets with room) or, where the rotor needs longer, at the end of the reference's ramp +
//! [`TIME_MARGIN`] × the ideal drive's lag behind it + [`SETTLE_PERIODS`] / ω_s, whichever is
//! later; every later phase moves by the same amount. The ideal drive
//! ([`IdealRotor`]) is the rigid rotor (`motor.inertia`, `motor.viscous_friction`) under the
//! speed loop's proportional action at its bandwidth ω_s (`controller.speed.bandwidth_hz`)
//! with the acceleration feed-forward, its torque clamped to the model's steady-state limit
//! at that speed ([`super::max_torque`], the motoring limit also bounding braking, which the
//! voltage limit allows more of), times the share of it a saturating model gives at the
//! current limit ([`saturated_share`]), and bounded by the drive's own ratings limits
//! (`[controller.limits]`: `torque_ratio` × the rated torque, `power_ratio` × the rated
//! power over the speed; in field weakening on a motor whose model allows more than twice its
//! rated power, the power limit, not the model, sets the acceleration to the top speed: a
//! drawn 88 kW 1-pole-pair IPMSM reaches its 17,721 r/min top 0.8 s after the model's limit
//! says); the reach time is when its speed enters half the window's
//! criterion band (1 % of the rated speed or of the level) for good. A rotor that meets the
//! base timing keeps it exactly, and with it its traces.

use super::{limits, max_torque};
use crate::config::SimConfig;
use crate::profile::Profile;
use fado_core::control::RatingsLimit;

/// Margin on the ideal drive's lag behind the reference: 1.25 \[A\] (the plant's saturation, losses and the
/// dead time take torque the steady-state model gives).
pub const TIME_MARGIN: f64 = 1.25;

/// Speed-loop time constants 1/ω_s between the ideal drive's reach and the window: 8 \[A\]
/// (the integral action's recovery from the limit; 0.25 s at the default 5 Hz).
pub const SETTLE_PERIODS: f64 = 8.0;

/// Integration step of the ideal drive, s.
pub const STEP: f64 = 1e-3;

/// Longest transient the ideal drive is followed for, s: beyond it the window stays at its
/// base offset and the run's criteria say what the rotor did.
pub const HORIZON: f64 = 600.0;

/// One phase of a scaled scenario: its start and judged window in the base timeline (s) and
/// the speed (r/min) it judges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phase {
    /// Start of the phase (its reference's first change), s.
    pub start: f64,
    /// Base opening of its judged window, s.
    pub from: f64,
    /// Base close of its judged window and the end of the phase, s.
    pub to: f64,
    /// Speed the window judges, r/min.
    pub level_rpm: f64,
}

impl Phase {
    /// The phase starting at `start` whose window judges `level_rpm` over `[from, to]`.
    pub const fn new(start: f64, from: f64, to: f64, level_rpm: f64) -> Self {
        Self {
            start,
            from,
            to,
            level_rpm,
        }
    }
}

/// The rigid rotor under an ideal, limited drive.
pub struct IdealRotor {
    inertia: f64,
    friction: f64,
    omega_s: f64,
    /// The torque limit at |ω_mech| = k·`table_step` (the model's, the drive's ratings
    /// limits), N·m.
    table: Vec<f64>,
    table_step: f64,
}

impl IdealRotor {
    /// The rotor and drive of `cfg`, its torque limit tabulated up to `top_rpm`.
    pub fn new(cfg: &SimConfig, top_rpm: f64) -> Self {
        let m = cfg.machine_model();
        let (i_max, v_max) = limits(cfg);
        let pole_pairs = m.pole_pairs as f64;
        let top = 1.2 * top_rpm.abs().max(1.0) * std::f64::consts::TAU / 60.0;
        let points = 200;
        let table_step = top / points as f64;
        let share = saturated_share(cfg, i_max);
        // The drive's own bounds from the ratings (`[controller.limits]`, the drive's
        // `RatingsLimit` in amperes of τ, T = 1.5·p·λ̂f·τ): the torque and the power its speed
        // loop may ask for, whichever is lower than the model's.
        let ratings = RatingsLimit::new(&cfg.controller.limits, &m).ok();
        let kt = 1.5 * pole_pairs * m.flux_linkage;
        let table = (0..=points)
            .map(|k| {
                let w_e = pole_pairs * k as f64 * table_step;
                let model = share * max_torque(cfg, w_e, i_max, v_max);
                let drive = ratings.map_or(f64::INFINITY, |r| kt * r.torque(f64::INFINITY, w_e));
                model.min(drive)
            })
            .collect();
        Self {
            inertia: cfg.motor.inertia,
            friction: cfg.motor.viscous_friction,
            omega_s: std::f64::consts::TAU * cfg.controller.speed.bandwidth_hz.max(0.1),
            table,
            table_step,
        }
    }

    /// The speed loop's settling after the reach, s.
    pub fn settle(&self) -> f64 {
        SETTLE_PERIODS / self.omega_s
    }

    fn torque_limit(&self, omega: f64) -> f64 {
        let x = omega.abs() / self.table_step;
        let k = x.floor() as usize;
        if k + 1 >= self.table.len() {
            return *self.table.last().unwrap_or(&0.0);
        }
        let f = x - k as f64;
        self.table[k] * (1.0 - f) + self.table[k + 1] * f
    }

    /// Follows `speed` (r/min) under `load` (N·m) from `t0` at the mechanical speed `omega`
    /// (rad/s) and returns the time (from `t0`) at which the speed stays within `band_rpm` of
    /// `level_rpm` for the speed loop's settling, with the speed there; `None` past
    /// [`HORIZON`].
    pub fn reach(
        &self,
        speed: &Profile,
        load: &Profile,
        t0: f64,
        omega: f64,
        level_rpm: f64,
        band_rpm: f64,
    ) -> Option<(f64, f64)> {
        let rpm = std::f64::consts::TAU / 60.0;
        let (level, band) = (level_rpm * rpm, band_rpm * rpm);
        let mut w = omega;
        let mut t = t0;
        let mut entered: Option<f64> = None;
        while t - t0 < HORIZON {
            let w_ref = speed.value(t) * rpm;
            let accel_ref = (speed.value(t + STEP) - speed.value(t)) * rpm / STEP;
            let t_load = load.value(t);
            let wanted = self.inertia * (accel_ref + self.omega_s * (w_ref - w))
                + t_load
                + self.friction * w;
            let limit = self.torque_limit(w);
            let torque = wanted.clamp(-limit, limit);
            w += STEP * (torque - t_load - self.friction * w) / self.inertia;
            t += STEP;
            if (w - level).abs() <= band {
                let first = *entered.get_or_insert(t);
                if t - first > self.settle() {
                    return Some((first - t0, w));
                }
            } else {
                entered = None;
            }
        }
        None
    }
}

/// The share of the constant inductances' torque at the current limit `i_max` (A) that the
/// model's magnetics give: 1 on a linear model, below it where saturation takes torque
/// (the best current angle of each, scanned in 0.5° steps).
pub fn saturated_share(cfg: &SimConfig, i_max: f64) -> f64 {
    use fado_core::magnetics::MagneticModel;
    let m = cfg.machine_model();
    if m.magnetics.is_linear() {
        return 1.0;
    }
    let model = m.magnetics.resolve(m.constant_inductance());
    let p = 1.5 * m.pole_pairs as f64;
    let (mut linear, mut saturated) = (0.0f64, 0.0f64);
    for k in 0..=360 {
        let beta = (k as f64 * 0.5).to_radians();
        let i = fado_core::Dq::new(-i_max * beta.sin(), i_max * beta.cos());
        let psi = model.flux(i);
        saturated = saturated.max(p * (psi.d * i.q - psi.q * i.d));
        linear = linear.max(m.torque(i));
    }
    if linear > 0.0 {
        (saturated / linear).clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// Where each phase of a scaled scenario lies: the shift (s) of its start and of its window
/// from the base timeline. A phase's window moves by what its transient needs beyond its base
/// offset; the next phase starts where that window ends.
#[derive(Clone, Debug, PartialEq)]
pub struct Timeline {
    /// Shift of each phase's start (and of its transient's points), s.
    pub start: Vec<f64>,
    /// Shift of each phase's window (and of the points at its close), s.
    pub window: Vec<f64>,
}

impl Timeline {
    /// The base timeline of `n` phases: no shift.
    pub fn base(n: usize) -> Self {
        Self {
            start: vec![0.0; n],
            window: vec![0.0; n],
        }
    }
}

/// The timeline of `phases` on `cfg`, whose profiles (speed, load) `build` makes from a
/// timeline; `top_rpm` bounds the speeds the phases ask.
pub fn plan(
    cfg: &SimConfig,
    phases: &[Phase],
    top_rpm: f64,
    build: impl Fn(&Timeline) -> (Profile, Profile),
) -> Timeline {
    let rotor = IdealRotor::new(cfg, top_rpm);
    let rated = cfg.motor.rated_speed_rpm;
    let mut line = Timeline::base(phases.len());
    let mut omega = 0.0;
    for (i, p) in phases.iter().enumerate() {
        // The phases after this one out of the way while its transient is followed.
        let mut trial = line.clone();
        for k in i + 1..phases.len() {
            trial.start[k] = HORIZON + p.to;
            trial.window[k] = HORIZON + p.to;
        }
        trial.window[i] = HORIZON + p.to;
        let (speed, load) = build(&trial);
        let start = p.start + line.start[i];
        let band = 0.01 * p.level_rpm.abs().max(rated);
        // The reference's own ramp, which the drive follows where it can.
        let mut ramp = 0.0;
        while ramp < HORIZON && (speed.value(start + ramp) - p.level_rpm).abs() > band {
            ramp += STEP;
        }
        let extra = match rotor.reach(&speed, &load, start, omega, p.level_rpm, band) {
            Some((t, w)) => {
                omega = w;
                let lag = (t - ramp).max(0.0);
                (ramp + TIME_MARGIN * lag + rotor.settle() - (p.from - p.start)).max(0.0)
            }
            None => {
                omega = p.level_rpm * std::f64::consts::TAU / 60.0;
                0.0
            }
        };
        line.window[i] = line.start[i] + extra;
        if i + 1 < phases.len() {
            line.start[i + 1] = line.window[i];
        }
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::range::{fullrange_timeline, regen_stop_timeline};
    use crate::scenario::scenario_config;

    fn paper(scenario: &str, extra: &str) -> SimConfig {
        scenario_config(scenario, Some(extra), true).unwrap()
    }

    #[test]
    fn a_rotor_that_meets_the_base_timing_keeps_it_exactly() {
        let c = paper("fullrange", "");
        assert_eq!(fullrange_timeline(&c), Timeline::base(5));
        assert_eq!(regen_stop_timeline(&c), Timeline::base(4));
    }

    #[test]
    fn the_ideal_drive_accelerates_at_the_torque_limit() {
        // The paper's motor with 200 × its inertia: the first phase (to the rated speed under
        // half the rated torque) lasts J·ω/(T_max − T_L), T_max between its value at the
        // rated speed and at standstill (the friction's torque taken at the rated speed), less
        // the last 1 % (the band it is judged in).
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/");
        let text = std::fs::read_to_string(format!("{dir}paper.toml")).unwrap();
        let c = paper(
            "fullrange",
            &text.replace("inertia = 0.012 ", "inertia = 2.4 "),
        );
        assert_eq!(c.motor.inertia, 2.4);
        let (i_max, v_max) = limits(&c);
        let m = c.machine_model();
        let w = m.rated_speed_rpm * std::f64::consts::TAU / 60.0;
        let load = 0.5 * m.rated_torque + m.viscous_friction * w;
        let at = |rpm: f64| {
            let e = rpm * std::f64::consts::TAU / 60.0 * m.pole_pairs as f64;
            max_torque(&c, e, i_max, v_max)
        };
        let fastest = m.inertia * w / (at(0.0) - load);
        let slowest = m.inertia * w / (at(m.rated_speed_rpm) - load);
        let line = fullrange_timeline(&c);
        let rotor = IdealRotor::new(&c, 2.0 * m.rated_speed_rpm);
        // The window opens at 1.2 s + the shift + 0.8 s; undo the margin and the settling.
        let reach = (line.window[0] + 0.8 - 0.1 - rotor.settle()) / TIME_MARGIN + 0.1;
        assert!(
            (0.97 * fastest..=1.01 * slowest).contains(&reach),
            "{fastest} ≤ {reach} ≤ {slowest}"
        );
        // Every later phase starts where the one before it ends, and none shrinks.
        for k in 1..5 {
            assert_eq!(line.start[k], line.window[k - 1]);
            assert!(line.window[k] >= line.start[k]);
        }
    }

    #[test]
    fn the_ideal_drive_keeps_the_drives_ratings_limits() {
        // The paper's motor with `[controller.limits]` below its model's torque: at each speed
        // the ideal drive's torque is the lowest of the model's, torque_ratio × the rated
        // torque and power_ratio × the rated power over the speed.
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/");
        let text = std::fs::read_to_string(format!("{dir}paper.toml")).unwrap();
        let free = paper("fullrange", &text);
        let limited = paper(
            "fullrange",
            &format!("{text}\n[controller.limits]\ntorque_ratio = 1.2\npower_ratio = 0.9\n"),
        );
        let m = free.machine_model();
        let w_rated = m.rated_speed_rpm * std::f64::consts::TAU / 60.0;
        let (a, b) = (
            IdealRotor::new(&free, m.rated_speed_rpm),
            IdealRotor::new(&limited, m.rated_speed_rpm),
        );
        for share in [0.0, 0.3, 0.6, 0.9, 1.1] {
            let w = share * w_rated;
            let power = if w > 0.0 {
                0.9 * m.rated_torque * w_rated / w
            } else {
                f64::INFINITY
            };
            let expected = a.torque_limit(w).min(1.2 * m.rated_torque).min(power);
            // Within the table's linear interpolation of 1/ω between its points.
            assert!(
                (b.torque_limit(w) - expected).abs() <= 1e-4 * expected,
                "{share}: {} against {expected}",
                b.torque_limit(w)
            );
            assert!(b.torque_limit(w) < a.torque_limit(w), "{share}");
        }
    }

    #[test]
    fn saturation_takes_its_share_of_the_torque() {
        let linear = paper("fullrange", "");
        assert_eq!(saturated_share(&linear, 40.0), 1.0);
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/saturated/");
        let text = std::fs::read_to_string(format!("{dir}ipmsm-2k2-qsat.toml")).unwrap();
        let c = paper("fullrange", &text);
        let i_rated = c.machine_model().rated_current;
        let share = saturated_share(&c, 1.5 * i_rated);
        assert!(share < 0.95 && share > 0.3, "{share}");
        // Deeper in saturation, a smaller share.
        assert!(saturated_share(&c, 0.5 * i_rated) > share);
    }
}
