//! The paper's experiments (Fig. 8–12) as named scenarios with their pass criteria checked in
//! code (docs/guide/first-run.md). Loads and rates are the paper's \[P\]; the exact profiles around them
//! (start-up, load application, settling, hold times) are ours \[A\] and are stated per scenario.
//!
//! Every scenario starts at standstill with a known rotor angle (docs/method/estimator.md, "Start-up"), brings the
//! machine to the experiment's initial operating point without load, applies the load with a
//! 0.5 s ramp, lets it settle, then runs the experiment. Metrics are taken from `eval_start`.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use serde::Serialize;

use crate::config::{EstimatorKind, Precision, SimConfig};
use crate::controller::{ControlEvent, Controller};
use crate::error::SimConfigError;
use crate::inverter::InverterModel;
use crate::profile::Profile;
use crate::sim::{
    Decimated, Metrics, Plant, Probe, RunStats, Sample, Simulation, Trace, TraceSink,
};

/// A named experiment.
#[derive(Clone, Copy, Debug)]
pub struct Scenario {
    /// Name on the command line (`fig11`).
    pub name: &'static str,
    /// What the paper's figure shows.
    pub title: &'static str,
    /// Profile in words.
    pub profile: &'static str,
    /// Pass criterion in words.
    pub criterion: &'static str,
    /// The profile is scaled by the motor's ratings (rated speed and torque of `[motor]`),
    /// so that the scenario runs for any motor; otherwise it is the paper's in absolute
    /// units (r/min, N·m of its motor).
    pub scaled: bool,
    /// Judges nothing of its own, not even a trip: only the user's `[criteria]` (the
    /// `custom` scenario). Left out of `compare`'s default scenario list.
    pub neutral: bool,
    /// Sets the profile, load, duration and evaluation window on a configuration (a scaled
    /// scenario from its `[motor]` ratings).
    pub setup: fn(&mut SimConfig),
    /// Sets up what the scenario's probe records beyond the common metrics (a hold window,
    /// staircase levels).
    pub observe: fn(&SimConfig, &mut ScenarioProbe),
    /// Appends the scenario's pass criteria for a finished run (after the common "tripped").
    pub checks: fn(&SimConfig, &Metrics, &ScenarioProbe, &mut Vec<Check>),
}

impl PartialEq for Scenario {
    /// Scenarios are named values: equal when their names are.
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

impl Eq for Scenario {}

/// The five scenarios of docs/guide/first-run.md in the paper's units, two of ours for the estimator
/// comparison ([`crate::compare`]): a medium-speed sanity check under load and a low-speed
/// staircase; then the paper's experiments scaled by the motor's ratings (its motor: 1500
/// r/min, 11.5 N·m), which run for any motor: `reversal` (Fig. 11), `stops` (Fig. 12) and
/// `rated-reversal` (Fig. 11 under the rated torque); `loaded-start`, a start under the
/// rated torque held by a brake until the drive is ready; `fullrange` and `regen-stop`, the
/// whole operating range and regenerating stops; and `custom`, the user's own profiles.
pub const SCENARIOS: [Scenario; 14] = [
    Scenario {
        name: "fig8",
        title: "Flux and disturbance estimation under 2 N·m (Fig. 8)",
        profile: "0 → +90 r/min, T_L → 2 N·m, then +90 → −90 r/min at 90 r/min/s",
        criterion: "λ2 centred on zero: mean of λ2 − λs over every whole electrical \
                    revolution spent above 30 r/min in HI mode < 2 % of λf; no trip; \
                    speed error < 30 r/min",
        scaled: false,
        neutral: false,
        setup: setup_fig8,
        observe: observe_nothing,
        checks: checks_fig8,
    },
    Scenario {
        name: "fig9",
        title: "k_df switched off for 2 s at −300 r/min under −3 N·m (Fig. 9)",
        profile: "0 → −300 r/min, T_L → −3 N·m, k_df off over [3 s, 5 s], run to 11 s \
                  (no start-up offset calibration)",
        criterion: "λ1 drifts while off (|ΔD̂| > 2 mWb) and recovers with τ ≈ 2 s \
                    (residual after 2 s in [0.2, 0.55]); |θ − θ̂| < 0.05 rad",
        scaled: false,
        neutral: false,
        setup: setup_fig9,
        observe: observe_nothing,
        checks: checks_fig9,
    },
    Scenario {
        name: "fig10",
        title: "No-load standstill held by the limiter (Fig. 10)",
        profile: "0 → 60 → 0 r/min without load, then 0 r/min from 1.7 s to 5.5 s",
        criterion: "|θ − θ̂| < 0.35 rad (does not diverge); |λ̂r| ≤ 1.15·λ̂f (+1 %); \
                    FLAG_limit high ≥ 95 % of the hold",
        scaled: false,
        neutral: false,
        setup: setup_fig10,
        observe: observe_fig10,
        checks: checks_fig10,
    },
    Scenario {
        name: "fig11",
        title: "Speed reversal under 7.5 N·m (Fig. 11)",
        profile: "0 → −90 r/min, T_L → +7.5 N·m, then −90 → +90 r/min at 90 r/min/s",
        criterion: "|θ − θ̂| < 0.25 rad near zero speed (|n| < 30 r/min) [P]; no trip; \
                    speed error < 30 r/min",
        scaled: false,
        neutral: false,
        setup: setup_fig11,
        observe: observe_nothing,
        checks: checks_reversal,
    },
    Scenario {
        name: "fig12",
        title: "Repeated 300 ms stops under 7.5 N·m (Fig. 12)",
        profile: "60 r/min, T_L → +7.5 N·m, then 3 × (60 → 0 at 120 r/min/s, 300 ms at 0, \
                  0 → 60, 500 ms at 60)",
        criterion: "no trip or instability [P]; |θ − θ̂| < 0.25 rad [A]; speed error < 30 r/min",
        scaled: false,
        neutral: false,
        setup: setup_fig12,
        observe: observe_nothing,
        checks: checks_stops,
    },
    Scenario {
        name: "steady300",
        title: "Steady 300 r/min under 7.5 N·m (sanity check of every estimator) [A]",
        profile: "0 → 300 r/min in 1 s, T_L → 7.5 N·m over [1.5 s, 2 s], hold to 4 s",
        criterion: "settled (from 2.5 s) |θ − θ̂| < 0.05 rad; speed error < 10 r/min; no trip",
        scaled: false,
        neutral: false,
        setup: setup_steady300,
        observe: observe_nothing,
        checks: checks_steady300,
    },
    Scenario {
        name: "lowspeed",
        title: "Lowest speed held under 7.5 N·m: a staircase 60, 30, 15, … r/min [A]",
        profile: "0 → 60 r/min, T_L → 7.5 N·m, then 2 s at each of 60, 30, 15, 7.5, 3.75, \
                  1.875, 0.9375 r/min (each reached by a 0.2 s ramp)",
        criterion: "a level is held when, over its last 1.5 s, |θ − θ̂| < 0.25 rad, \
                    |n − n*| < max(0.5·n*, 0.5 r/min) and no trip; the lowest speed held is \
                    the lowest level held together with every level above it; the scenario \
                    passes when every level is held",
        scaled: false,
        neutral: false,
        setup: setup_lowspeed,
        observe: observe_lowspeed,
        checks: checks_lowspeed,
    },
    Scenario {
        name: "reversal",
        title: "Speed reversal under 65 % of rated torque (Fig. 11, scaled by the ratings)",
        profile: "0 → −6 % of rated speed, T_L → 65.2 % of rated torque, then a reversal to \
                  +6 % at 6 % of rated speed per second (the paper's motor: fig11)",
        criterion: "|θ − θ̂| < 0.25 rad near zero speed (|n| < 2 % of rated) [P]; no trip; \
                    speed error < 2 % of rated speed",
        scaled: true,
        neutral: false,
        setup: setup_reversal,
        observe: observe_nothing,
        checks: checks_reversal,
    },
    Scenario {
        name: "stops",
        title: "Repeated 300 ms stops under 65 % of rated torque (Fig. 12, scaled)",
        profile: "4 % of rated speed, T_L → 65.2 % of rated torque, then 3 × (ramp to 0 in \
                  0.5 s, 300 ms at 0, back in 0.5 s, 500 ms at 4 %) (the paper's motor: fig12)",
        criterion: "no trip or instability [P]; |θ − θ̂| < 0.25 rad [A]; speed error < 2 % \
                    of rated speed",
        scaled: true,
        neutral: false,
        setup: setup_stops,
        observe: observe_nothing,
        checks: checks_stops,
    },
    Scenario {
        name: "rated-reversal",
        title: "Speed reversal under the rated torque (Fig. 11 at 100 % load, scaled)",
        profile: "as `reversal` with T_L → 100 % of rated torque",
        criterion: "as `reversal`",
        scaled: true,
        neutral: false,
        setup: setup_rated_reversal,
        observe: observe_nothing,
        checks: checks_reversal,
    },
    Scenario {
        name: "loaded-start",
        title: "Start under the rated torque, the rotor held by a brake until the drive is ready",
        profile: "rotor at rest at a seeded random angle, a brake holding it and a constant \
                  100 % of rated torque (gravity-like) on it; the brake releases at the \
                  drive's first ready sample (calibrations over); 0 r/min until 1 s, then a \
                  ramp to +6 % of rated speed (lifting) by 2 s, held to 3 s. The drive starts \
                  from the rotor's angle (`align`)",
        criterion: "released; backward travel after the release ≤ 0.5 rad electrical; \
                    |θ − θ̂| < 0.25 rad from the release on; commanded speed reached \
                    (|n − n*| < 2 % of rated speed over the last 0.5 s); no trip",
        scaled: true,
        neutral: false,
        setup: setup_loaded_start,
        observe: observe_loaded_start,
        checks: checks_loaded_start,
    },
    Scenario {
        name: "fullrange",
        title: "The whole operating range, scaled by the ratings and the model's limits",
        profile: "standstill under 50 % of rated torque; to rated speed at the current limit; \
                  rated load step; field weakening to the top speed the voltage and current \
                  limits allow (≤ 2× rated; half the rated power still available) holding \
                  min(rated power, 80 % of the limits' power); brake at the current limit \
                  through zero; 1 s at zero under 65 % of rated torque; to −rated speed",
        criterion: "|θ − θ̂| < 0.25 rad over the whole run; in each settled window speed within \
                    2 % of its target (of the rated speed near zero); no trip; DC voltage within \
                    the drive's limits",
        scaled: true,
        neutral: false,
        setup: setup_fullrange,
        observe: observe_fullrange,
        checks: checks_range,
    },
    Scenario {
        name: "regen-stop",
        title: "Stops regenerating into a rectifier-fed DC link (with a brake chopper)",
        profile: "rated speed, stop at the current limit; rated speed again under an overhauling \
                  rated load, stop and hold it (rectifier, chopper at 1.05 × the bus)",
        criterion: "as `fullrange`",
        scaled: true,
        neutral: false,
        setup: setup_regen_stop,
        observe: observe_regen_stop,
        checks: checks_range,
    },
    Scenario {
        name: "custom",
        title: "The user's own experiment: `[speed_reference]`, `[load]`, `[criteria]`",
        profile: "the configuration's `[speed_reference] points` and `[load]`; it runs to 1 s \
                  after the last breakpoint unless `[simulation] duration` is given",
        criterion: "only the `[criteria]` written (none: it reports and passes)",
        scaled: false,
        neutral: true,
        setup: setup_custom,
        observe: observe_nothing,
        checks: checks_nothing,
    },
];

/// Load of `loaded-start`, fraction of the rated torque: a full load (a hoist at its rated
/// load, a vehicle on its steepest slope).
pub const LOADED_START_LOAD_RATIO: f64 = 1.0;
/// Largest backward travel of the rotor after the brake's release in `loaded-start`,
/// electrical rad.
pub const LOADED_START_MAX_BACK: f64 = 0.5;
/// `loaded-start`: the speed reference is 0 until this time (s), longer than every preset's
/// start-up (offset and gain calibrations), then ramps to the target in 1 s.
const LOADED_START_RAMP_AT: f64 = 1.0;
/// `loaded-start`: duration (s); the speed is judged over its last 0.5 s.
const LOADED_START_DURATION: f64 = 3.0;

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
const LOWSPEED_RAMP_SECONDS: f64 = 0.2;
/// The last part of each level over which it is judged, s (the ramp and 0.3 s of settling
/// excluded).
pub const LOWSPEED_JUDGED_SECONDS: f64 = 1.5;
/// The first level starts here, s (after the start-up to 60 r/min and the load ramp).
const LOWSPEED_START: f64 = 2.0;
/// Angle bound of a held level, rad (the paper's fig11 bound \[P\]).
pub const LOWSPEED_ANGLE_BOUND: f64 = 0.25;

/// Speed bound of a held level at `level_rpm`: the rotor turns in the commanded direction at
/// no less than half the commanded speed (and within 0.5 r/min at the lowest levels).
pub fn lowspeed_speed_bound(level_rpm: f64) -> f64 {
    (0.5 * level_rpm.abs()).max(0.5)
}

/// The scenario called `name`.
pub fn find(name: &str) -> Option<&'static Scenario> {
    SCENARIOS.iter().find(|s| s.name == name)
}

impl Scenario {
    /// The scenario's default configuration (docs/method/estimator.md, "The paper's motor and drive" plant and drive: the paper's motor, the
    /// profile above).
    pub fn config(&self) -> SimConfig {
        self.apply(SimConfig::default())
    }

    /// `base` with this scenario's profile, load, duration and evaluation window; a scaled
    /// scenario takes them from `base.motor`'s ratings.
    pub fn apply(&self, mut c: SimConfig) -> SimConfig {
        (self.setup)(&mut c);
        c
    }

    fn probe(&self, cfg: &SimConfig) -> ScenarioProbe {
        let mut p = ScenarioProbe::new(cfg.simulation.eval_start, cfg.zero_speed_band_rpm());
        (self.observe)(cfg, &mut p);
        p
    }

    /// Checks the pass criteria on a finished run.
    pub fn evaluate(&self, cfg: &SimConfig, m: &Metrics, p: &ScenarioProbe) -> Vec<Check> {
        let mut checks = if self.neutral {
            Vec::new()
        } else {
            vec![Check::at_most("tripped", m.tripped as u8 as f64, 0.0)]
        };
        (self.checks)(cfg, m, p, &mut checks);
        checks.extend(cfg.criteria.checks(cfg.motor.rated_speed_rpm, m));
        checks
    }
}

/// No probe beyond the common one.
fn observe_nothing(_cfg: &SimConfig, _p: &mut ScenarioProbe) {}

/// `fig10`: the standstill hold, from 2 s to the end.
fn observe_fig10(cfg: &SimConfig, p: &mut ScenarioProbe) {
    p.hold = Some((2.0, cfg.simulation.duration));
}

/// `lowspeed`: the judged window of each staircase level.
fn observe_loaded_start(cfg: &SimConfig, p: &mut ScenarioProbe) {
    p.start = Some(StartStats::new(cfg.simulation.duration - 0.5));
}

fn observe_lowspeed(cfg: &SimConfig, p: &mut ScenarioProbe) {
    p.levels = lowspeed_levels_rpm(cfg.motor.rated_speed_rpm)
        .iter()
        .enumerate()
        .map(|(k, &level)| {
            let to = LOWSPEED_START + (k + 1) as f64 * LOWSPEED_LEVEL_SECONDS;
            LevelStats::new(level, to - LOWSPEED_JUDGED_SECONDS, to)
        })
        .collect();
}

/// `fullrange`: see [`crate::range`].
fn setup_fullrange(c: &mut SimConfig) {
    crate::range::setup_fullrange(c);
}

/// `regen-stop`: see [`crate::range`].
fn setup_regen_stop(c: &mut SimConfig) {
    crate::range::setup_regen_stop(c);
}

fn holds_to_levels(holds: Vec<crate::range::Hold>) -> Vec<LevelStats> {
    holds
        .into_iter()
        .map(|(level, from, to)| LevelStats::new(level, from, to))
        .collect()
}

/// `fullrange`: its settled windows.
fn observe_fullrange(cfg: &SimConfig, p: &mut ScenarioProbe) {
    p.levels = holds_to_levels(crate::range::fullrange_holds(cfg));
}

/// `regen-stop`: its settled windows.
fn observe_regen_stop(cfg: &SimConfig, p: &mut ScenarioProbe) {
    p.levels = holds_to_levels(crate::range::regen_stop_holds(cfg));
}

/// `fullrange` and `regen-stop`: the angle over the run, the speed in each settled window
/// within 2 % of its target (of the rated speed near zero), the DC link within the drive's
/// limits.
fn checks_range(cfg: &SimConfig, m: &Metrics, p: &ScenarioProbe, checks: &mut Vec<Check>) {
    let rated = cfg.motor.rated_speed_rpm;
    checks.push(Check::at_most("max |θ − θ̂| (rad)", m.max_angle_error, 0.25));
    for l in &p.levels {
        let bound = 0.02 * l.level_rpm.abs().max(rated);
        checks.push(Check::at_most(
            &format!(
                "speed error at {:.0} r/min, {:.1}–{:.1} s (r/min)",
                l.level_rpm, l.from, l.to
            ),
            l.max_speed_error_rpm,
            bound,
        ));
    }
    let v = cfg.inverter.dc_voltage;
    checks.push(Check::at_most(
        "max DC-link voltage (V)",
        m.max_dc_voltage,
        cfg.controller.dc_link.over_voltage_trip_ratio * v,
    ));
    checks.push(Check::at_least(
        "min DC-link voltage (V)",
        m.min_dc_voltage,
        cfg.controller.dc_link_min_ratio * v,
    ));
    if p.levels.len() == 5 {
        let t = crate::range::targets(cfg);
        checks.push(Check::at_least(
            &format!(
                "mean speed at the top (r/min; model: {:.0})",
                t.top_speed_rpm
            ),
            p.levels[2].mean_speed_rpm,
            0.98 * t.top_speed_rpm,
        ));
        checks.push(Check::at_least(
            &format!(
                "power held at the top (W; model limit {:.0}, rated {:.0})",
                t.limit_power_at_top, t.rated_power
            ),
            cfg.load.torque.value(7.5) * p.levels[2].mean_speed_rpm * std::f64::consts::TAU / 60.0,
            0.98 * t.hold_power,
        ));
    }
}

/// `custom`: the user's profiles as they are; the run lasts until 1 s after the last
/// breakpoint of the speed reference or the load (the user's `[simulation] duration`, applied
/// after this, wins).
fn setup_custom(c: &mut SimConfig) {
    let end = [
        c.speed_reference.end_time(),
        c.load.torque.end_time(),
        c.load.speed_rpm.end_time(),
    ]
    .into_iter()
    .fold(0.0, f64::max);
    c.simulation.duration = end + CUSTOM_TAIL_SECONDS;
}

/// What `custom` runs after the last breakpoint of its profiles, s: the settling of a step.
pub const CUSTOM_TAIL_SECONDS: f64 = 1.0;

/// No criterion of the scenario's own.
fn checks_nothing(_cfg: &SimConfig, _m: &Metrics, _p: &ScenarioProbe, _checks: &mut Vec<Check>) {}

/// `fig8`: profile, load, duration, evaluation window.
fn setup_fig8(c: &mut SimConfig) {
    let pts = Profile::from_points;
    c.speed_reference = pts(&[
        (0.0, 0.0),
        (0.5, 0.0),
        (1.5, 90.0),
        (3.0, 90.0),
        (5.0, -90.0),
    ]);
    c.load.torque = pts(&[(1.5, 0.0), (2.0, 2.0)]);
    c.simulation.duration = 6.5;
    c.simulation.eval_start = 2.5;
}

/// `fig9`: profile, load, duration, evaluation window.
fn setup_fig9(c: &mut SimConfig) {
    let pts = Profile::from_points;
    c.speed_reference = pts(&[(0.0, 0.0), (0.3, 0.0), (1.3, -300.0)]);
    c.load.torque = pts(&[(1.3, 0.0), (1.8, -3.0)]);
    c.simulation.duration = 11.0;
    c.simulation.eval_start = 2.0;
    c.simulation.disturbance_feedback_off = vec![[3.0, 5.0]];
    // Fig. 9 shows what k_df does against an integrand error; the start-up offset
    // calibration is off so that the uncalibrated 20 / −10 mA sensor offsets
    // provide one of visible size \[A\]. (Calibrated, λ1 drifts only 1–3 mWb in
    // the 2 s: too little for the drift check, and the recovery ratio is then
    // dominated by noise.)
    c.controller.offset_calibration_time = 0.0;
    // For the same reason the learned integrand offset is off: it removes that error while
    // turning, so with k_df off λ1 would have nothing to drift from (measured: 0.2 mWb
    // instead of 21 mWb in the 2 s) \[A\].
    c.estimator.offset_adaptation_rate = 0.0;
}

/// `fig10`: profile, load, duration, evaluation window.
fn setup_fig10(c: &mut SimConfig) {
    let pts = Profile::from_points;
    c.speed_reference = pts(&[(0.0, 0.0), (0.2, 0.0), (0.7, 60.0), (1.2, 60.0), (1.7, 0.0)]);
    c.simulation.duration = 5.5;
    c.simulation.eval_start = 0.2;
}

/// `fig11`: profile, load, duration, evaluation window.
fn setup_fig11(c: &mut SimConfig) {
    let pts = Profile::from_points;
    c.speed_reference = pts(&[
        (0.0, 0.0),
        (0.2, 0.0),
        (1.2, -90.0),
        (2.5, -90.0),
        (4.5, 90.0),
    ]);
    c.load.torque = pts(&[(1.2, 0.0), (1.7, 7.5)]);
    c.simulation.duration = 5.5;
    c.simulation.eval_start = 2.0;
}

/// `fig12`: profile, load, duration, evaluation window.
fn setup_fig12(c: &mut SimConfig) {
    let pts = Profile::from_points;
    let mut p = vec![(0.0, 0.0), (0.2, 0.0), (0.9, 60.0), (2.0, 60.0)];
    let mut t = 2.0;
    for _ in 0..3 {
        p.extend([
            (t + 0.5, 0.0),
            (t + 0.8, 0.0),
            (t + 1.3, 60.0),
            (t + 1.8, 60.0),
        ]);
        t += 1.8;
    }
    c.speed_reference = pts(&p);
    c.load.torque = pts(&[(0.9, 0.0), (1.4, 7.5)]);
    c.simulation.duration = t;
    c.simulation.eval_start = 1.8;
}

/// `steady300`: profile, load, duration, evaluation window.
fn setup_steady300(c: &mut SimConfig) {
    let pts = Profile::from_points;
    c.speed_reference = pts(&[(0.0, 0.0), (0.2, 0.0), (1.2, 300.0)]);
    c.load.torque = pts(&[(1.5, 0.0), (2.0, 7.5)]);
    c.simulation.duration = 4.0;
    c.simulation.eval_start = 2.5;
}

/// `lowspeed`: profile, load, duration, evaluation window.
fn setup_lowspeed(c: &mut SimConfig) {
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
fn setup_reversal_under(c: &mut SimConfig, load: f64) {
    let pts = Profile::from_points;
    let n_rated = c.motor.rated_speed_rpm;
    let t_rated = c.motor.rated_torque;
    // fig11 in units of the ratings: 90 r/min = 6 %, 7.5 N·m = 65.2 %.
    let n = REVERSAL_SPEED_RATIO * n_rated;
    c.speed_reference = pts(&[(0.0, 0.0), (0.2, 0.0), (1.2, -n), (2.5, -n), (4.5, n)]);
    c.load.torque = pts(&[(1.2, 0.0), (1.7, load * t_rated)]);
    c.simulation.duration = 5.5;
    c.simulation.eval_start = 2.0;
}

/// `reversal`: fig11 scaled, 65.2 % load.
fn setup_reversal(c: &mut SimConfig) {
    setup_reversal_under(c, SCALED_LOAD_RATIO);
}

/// `rated-reversal`: fig11 scaled, 100 % load.
fn setup_rated_reversal(c: &mut SimConfig) {
    setup_reversal_under(c, 1.0);
}

/// `loaded-start`: brake, seeded angle, the rated torque from t = 0 (on the brake until the
/// release), the lifting ramp.
fn setup_loaded_start(c: &mut SimConfig) {
    let n = REVERSAL_SPEED_RATIO * c.motor.rated_speed_rpm;
    let t0 = LOADED_START_RAMP_AT;
    c.simulation.brake = true;
    c.simulation.initial_angle = loaded_start_angle(c.current_sensor.seed);
    c.speed_reference = Profile::from_points(&[(0.0, 0.0), (t0, 0.0), (t0 + 1.0, n)]);
    c.load.torque = Profile::constant(LOADED_START_LOAD_RATIO * c.motor.rated_torque);
    c.simulation.duration = LOADED_START_DURATION;
    c.simulation.eval_start = 0.0;
}

/// `stops`: profile, load, duration, evaluation window.
fn setup_stops(c: &mut SimConfig) {
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

/// `fig8`: pass criteria.
fn checks_fig8(cfg: &SimConfig, m: &Metrics, p: &ScenarioProbe, checks: &mut Vec<Check>) {
    checks.push(Check::at_most(
        "max |DC(λ2 − λs)| / λf",
        p.max_block_dc / cfg.motor.flux_linkage,
        0.02,
    ));
    checks.push(Check::at_least(
        "revolutions evaluated",
        p.blocks as f64,
        4.0,
    ));
    // No loss of control: without it an estimator that runs the machine away
    // (as the EMF baseline does) could still show a centred λ2.
    checks.push(Check::at_most(
        "max speed error (r/min)",
        m.max_speed_error_rpm,
        30.0,
    ));
}

/// `fig9`: pass criteria.
fn checks_fig9(cfg: &SimConfig, m: &Metrics, p: &ScenarioProbe, checks: &mut Vec<Check>) {
    if let Some(&[t_off, t_on]) = cfg.simulation.disturbance_feedback_off.first() {
        let d = |t: f64| p.disturbance_at(t);
        let end = d(cfg.simulation.duration);
        let drift = (d(t_on) - d(t_off)).norm();
        let residual = (d(t_on + 2.0) - end).norm() / (d(t_on) - end).norm().max(1e-12);
        checks.push(Check::at_least("λ1 drift while k_df off (Wb)", drift, 2e-3));
        checks.push(Check::within(
            "recovery residual after 2 s",
            residual,
            0.2,
            0.55,
        ));
    } else {
        // Without the k_df-off window there is no Fig. 9 experiment to judge.
        checks.push(Check::at_least("k_df-off windows configured", 0.0, 1.0));
    }
    checks.push(Check::at_most("max |θ − θ̂| (rad)", m.max_angle_error, 0.05));
}

/// `fig10`: pass criteria.
fn checks_fig10(cfg: &SimConfig, m: &Metrics, p: &ScenarioProbe, checks: &mut Vec<Check>) {
    checks.push(Check::at_most("max |θ − θ̂| (rad)", m.max_angle_error, 0.35));
    checks.push(Check::at_most(
        "max |λ̂r| / (1.15·λ̂f)",
        p.max_lambda_r / (cfg.estimator.limiter_radius_ratio * cfg.machine_model().flux_linkage),
        1.01,
    ));
    checks.push(Check::at_least(
        "FLAG_limit fraction of the hold",
        p.flag_fraction(),
        0.95,
    ));
}

/// `steady300`: pass criteria.
fn checks_steady300(_cfg: &SimConfig, m: &Metrics, _p: &ScenarioProbe, checks: &mut Vec<Check>) {
    checks.push(Check::at_most(
        "settled max |θ − θ̂| (rad)",
        m.max_angle_error,
        0.05,
    ));
    checks.push(Check::at_most(
        "max speed error (r/min)",
        m.max_speed_error_rpm,
        10.0,
    ));
}

/// `lowspeed`: pass criteria.
fn checks_lowspeed(_cfg: &SimConfig, _m: &Metrics, p: &ScenarioProbe, checks: &mut Vec<Check>) {
    checks.push(Check::at_least(
        "levels held from 4 % of rated speed down",
        p.levels_held_in_a_row() as f64,
        p.levels.len() as f64,
    ));
}

/// `reversal`, `rated-reversal` and `fig11`: pass criteria (on the paper's motor: 30 r/min,
/// 1000 samples of 100 µs, as the paper's fig11).
fn checks_reversal(cfg: &SimConfig, m: &Metrics, _p: &ScenarioProbe, checks: &mut Vec<Check>) {
    let band = SCALED_SPEED_ERROR_RATIO * cfg.motor.rated_speed_rpm;
    checks.push(Check::at_most(
        "max |θ − θ̂| near zero speed (rad)",
        m.max_angle_error_zero_speed,
        0.25,
    ));
    // 0.1 s of samples at least in the band (fig11: 0.67 s).
    checks.push(Check::at_least(
        "samples near zero speed",
        m.zero_speed_samples as f64,
        0.1 / cfg.inverter.sample_period(),
    ));
    checks.push(Check::at_most(
        "max speed error (r/min)",
        m.max_speed_error_rpm,
        band,
    ));
}

/// `stops` and `fig12`: pass criteria (on the paper's motor: 30 r/min, as fig12).
fn checks_stops(cfg: &SimConfig, m: &Metrics, _p: &ScenarioProbe, checks: &mut Vec<Check>) {
    let band = SCALED_SPEED_ERROR_RATIO * cfg.motor.rated_speed_rpm;
    checks.push(Check::at_most("max |θ − θ̂| (rad)", m.max_angle_error, 0.25));
    checks.push(Check::at_most(
        "max speed error (r/min)",
        m.max_speed_error_rpm,
        band,
    ));
}

/// `loaded-start`: pass criteria.
fn checks_loaded_start(cfg: &SimConfig, _m: &Metrics, p: &ScenarioProbe, checks: &mut Vec<Check>) {
    let band = SCALED_SPEED_ERROR_RATIO * cfg.motor.rated_speed_rpm;
    let st = p.start.clone().unwrap_or_default();
    let bounds = [
        (
            "brake released (time, s; never: ∞)",
            st.release_time.unwrap_or(f64::INFINITY),
            cfg.simulation.duration,
        ),
        (
            "backward travel after the release (rad)",
            st.max_backward,
            LOADED_START_MAX_BACK,
        ),
        (
            "max |θ − θ̂| from the release on (rad)",
            st.max_angle_error,
            0.25,
        ),
        ("speed error at the end (r/min)", st.end_speed_error(), band),
    ];
    checks.extend(bounds.map(|(name, value, max)| Check::at_most(name, value, max)));
}

/// What `loaded-start` measures about the start-up and the release.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StartStats {
    /// When the brake released (the drive's first ready sample), s.
    pub release_time: Option<f64>,
    /// Largest backward travel of the rotor after the release (electrical rad, ≥ 0; backward
    /// is against the lifting direction, negative angles).
    pub max_backward: f64,
    /// Largest |θ − θ̂| from the release on, rad.
    pub max_angle_error: f64,
    /// Largest |n − n*| from `end_from` on, r/min (see [`end_speed_error`](Self::end_speed_error)).
    pub max_end_speed_error_rpm: f64,
    /// Start of the end window, s.
    pub end_from: f64,
    travel: f64,
    last_theta: Option<f64>,
    end_samples: u64,
}

impl StartStats {
    fn new(end_from: f64) -> Self {
        Self {
            end_from,
            ..Self::default()
        }
    }

    fn observe(&mut self, s: &Sample) {
        if s.brake_engaged {
            return;
        }
        if self.release_time.is_none() {
            self.release_time = Some(s.time);
        }
        if let Some(prev) = self.last_theta {
            self.travel += fado_core::wrap_angle(s.theta - prev);
        }
        self.last_theta = Some(s.theta);
        self.max_backward = self.max_backward.max(-self.travel);
        self.max_angle_error = self.max_angle_error.max(s.angle_error.abs());
        if s.time >= self.end_from {
            self.end_samples += 1;
            self.max_end_speed_error_rpm = self
                .max_end_speed_error_rpm
                .max((s.speed_rpm - s.speed_ref_rpm).abs());
        }
    }

    /// The end window's largest speed error, r/min; ∞ when the run never got there released.
    pub fn end_speed_error(&self) -> f64 {
        if self.end_samples == 0 {
            f64::INFINITY
        } else {
            self.max_end_speed_error_rpm
        }
    }
}

/// One pass criterion and how the run did against it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Check {
    /// What is measured.
    pub name: String,
    /// Measured value.
    pub value: f64,
    /// Lower limit (inclusive), if any.
    pub min: Option<f64>,
    /// Upper limit (exclusive for errors), if any.
    pub max: Option<f64>,
    /// The value is within its limits.
    pub passed: bool,
}

impl Check {
    pub(crate) fn at_most(name: &str, value: f64, max: f64) -> Self {
        Self {
            name: name.into(),
            value,
            min: None,
            max: Some(max),
            passed: value <= max,
        }
    }
    pub(crate) fn at_least(name: &str, value: f64, min: f64) -> Self {
        Self {
            name: name.into(),
            value,
            min: Some(min),
            max: None,
            passed: value >= min,
        }
    }
    fn within(name: &str, value: f64, min: f64, max: f64) -> Self {
        Self {
            name: name.into(),
            value,
            min: Some(min),
            max: Some(max),
            passed: (min..=max).contains(&value),
        }
    }
}

/// One level of the `lowspeed` staircase, judged over its last
/// [`LOWSPEED_JUDGED_SECONDS`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LevelStats {
    /// Commanded speed, r/min.
    pub level_rpm: f64,
    /// Judged window start, s.
    pub from: f64,
    /// Judged window end, s.
    pub to: f64,
    /// Samples in the window.
    pub samples: u64,
    /// max |θ − θ̂| in the window, rad.
    pub max_angle_error: f64,
    /// max |n − n*| in the window, r/min.
    pub max_speed_error_rpm: f64,
    /// Mean true speed in the window, r/min.
    pub mean_speed_rpm: f64,
    /// The drive tripped at or before the end of the window.
    pub tripped: bool,
    #[serde(skip)]
    speed_sum: f64,
}

impl LevelStats {
    /// An empty window `[from, to]` at `level_rpm`.
    pub fn new(level_rpm: f64, from: f64, to: f64) -> Self {
        Self {
            level_rpm,
            from,
            to,
            samples: 0,
            max_angle_error: 0.0,
            max_speed_error_rpm: 0.0,
            mean_speed_rpm: 0.0,
            tripped: false,
            speed_sum: 0.0,
        }
    }

    /// Accumulates one sample (ignored outside the window; a trip before the window's end
    /// counts).
    pub fn observe(&mut self, time: f64, angle_error: f64, speed_rpm: f64, tripped: bool) {
        if time <= self.to {
            self.tripped |= tripped;
        }
        if time < self.from || time > self.to {
            return;
        }
        self.samples += 1;
        self.max_angle_error = self.max_angle_error.max(angle_error.abs());
        self.max_speed_error_rpm = self
            .max_speed_error_rpm
            .max((speed_rpm - self.level_rpm).abs());
        self.speed_sum += speed_rpm;
        self.mean_speed_rpm = self.speed_sum / self.samples as f64;
    }

    /// Held: the whole window was seen, |θ − θ̂| < [`LOWSPEED_ANGLE_BOUND`], |n − n*| <
    /// [`lowspeed_speed_bound`], no trip.
    pub fn held(&self) -> bool {
        self.samples > 0
            && !self.tripped
            && self.max_angle_error < LOWSPEED_ANGLE_BOUND
            && self.max_speed_error_rpm < lowspeed_speed_bound(self.level_rpm)
    }
}

/// Full-rate accumulations the criteria need beyond [`Metrics`].
///
/// The DC of λ2 (Fig. 8) is the mean of λ2 − λs (estimate minus the true stator flux) over
/// whole electrical revolutions: every error synchronous with the rotor (dead-time and
/// gain-error harmonics) averages out over a revolution, the offset that D̂ should have removed
/// does not.
#[derive(Clone, Debug)]
pub struct ScenarioProbe {
    eval_start: f64,
    band_rpm: f64,
    rev_angle: f64,
    rev_sum: fado_core::Ab<f64>,
    rev_n: u64,
    rev_valid: bool,
    last_theta: Option<f64>,
    /// Largest |mean(λ2 − λs)| over the revolutions spent entirely above the band in HI mode,
    /// Wb.
    pub max_block_dc: f64,
    /// Number of such revolutions.
    pub blocks: u64,
    /// Every such revolution: (end time in s, |mean(λ2 − λs)| in Wb).
    pub revolutions: Vec<(f64, f64)>,
    /// D̂ every 10 ms: (time, D̂).
    pub disturbance: Vec<(f64, fado_core::Ab<f64>)>,
    /// Window for the standstill statistics (fig10).
    pub hold: Option<(f64, f64)>,
    /// Largest |λ̂r| in the hold window, Wb.
    pub max_lambda_r: f64,
    /// The `lowspeed` staircase levels (empty for the other scenarios).
    pub levels: Vec<LevelStats>,
    /// The `loaded-start` start-up and release (None for the other scenarios).
    pub start: Option<StartStats>,
    hold_n: u64,
    hold_flag: u64,
    next_disturbance_sample: f64,
}

impl ScenarioProbe {
    fn new(eval_start: f64, band_rpm: f64) -> Self {
        Self {
            eval_start,
            band_rpm,
            rev_angle: 0.0,
            rev_sum: fado_core::Ab::zero(),
            rev_n: 0,
            rev_valid: true,
            last_theta: None,
            max_block_dc: 0.0,
            blocks: 0,
            revolutions: Vec::new(),
            disturbance: Vec::new(),
            hold: None,
            max_lambda_r: 0.0,
            levels: Vec::new(),
            start: None,
            hold_n: 0,
            hold_flag: 0,
            next_disturbance_sample: 0.0,
        }
    }

    /// D̂ at (just before) time `t`, from the 10 ms series.
    pub fn disturbance_at(&self, t: f64) -> fado_core::Ab<f64> {
        let k = self.disturbance.partition_point(|(ti, _)| *ti <= t);
        self.disturbance
            .get(k.saturating_sub(1))
            .map_or(fado_core::Ab::zero(), |x| x.1)
    }

    /// Fraction of the hold window with FLAG_limit high.
    pub fn flag_fraction(&self) -> f64 {
        self.hold_flag as f64 / self.hold_n.max(1) as f64
    }

    /// Number of staircase levels held, counted from the top until the first one that is
    /// not.
    pub fn levels_held_in_a_row(&self) -> usize {
        self.levels.iter().take_while(|l| l.held()).count()
    }

    /// The lowest speed held under load, r/min: the lowest staircase level held together
    /// with every level above it; `None` when not even the first was held (or no staircase).
    pub fn lowest_speed_held_rpm(&self) -> Option<f64> {
        self.levels_held_in_a_row()
            .checked_sub(1)
            .map(|k| self.levels[k].level_rpm)
    }

    fn restart_revolution(&mut self) {
        self.rev_angle = 0.0;
        self.rev_sum = fado_core::Ab::zero();
        self.rev_n = 0;
        self.rev_valid = true;
    }
}

impl Probe for ScenarioProbe {
    fn observe(&mut self, s: &Sample) {
        let d = &s.act.estimate.diagnostics;
        for level in &mut self.levels {
            level.observe(s.time, s.angle_error, s.speed_rpm, s.act.tripped);
        }
        if let Some(st) = &mut self.start {
            st.observe(s);
        }
        if s.time >= self.next_disturbance_sample {
            self.disturbance.push((s.time, d.disturbance));
            self.next_disturbance_sample += 0.01;
        }
        if let Some((a, b)) = self.hold
            && s.time >= a
            && s.time <= b
        {
            self.hold_n += 1;
            self.hold_flag += d.flag_limit as u64;
            self.max_lambda_r = self.max_lambda_r.max(d.lambda_r.norm());
        }
        let dtheta = self.last_theta.map_or(0.0, |prev| {
            let d = s.theta - prev;
            if d.abs() > std::f64::consts::PI {
                fado_core::wrap_angle(d)
            } else {
                d
            }
        });
        self.last_theta = Some(s.theta);
        if s.time < self.eval_start {
            return;
        }
        if s.speed_rpm.abs() < self.band_rpm || d.flag_limit {
            self.rev_valid = false;
        }
        self.rev_sum += d.lambda2 - s.flux_ab_true;
        self.rev_n += 1;
        self.rev_angle += dtheta;
        if self.rev_angle.abs() >= std::f64::consts::TAU {
            if self.rev_valid {
                let mean = self.rev_sum * (1.0 / self.rev_n as f64);
                self.max_block_dc = self.max_block_dc.max(mean.norm());
                self.blocks += 1;
                self.revolutions.push((s.time, mean.norm()));
            }
            self.restart_revolution();
        } else if !self.rev_valid {
            self.restart_revolution();
            self.rev_valid = true;
            // A revolution only counts if it starts valid: wait for the next sample.
            self.rev_n = 0;
        }
    }
}

/// Everything a scenario run produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The scenario's own accumulations (revolution DC, D̂ series, hold statistics).
    pub probe: ScenarioProbe,
    /// Scenario name.
    pub scenario: String,
    /// The configuration run.
    pub config: SimConfig,
    /// All criteria passed.
    pub passed: bool,
    /// The criteria.
    pub checks: Vec<Check>,
    /// Angle and speed metrics.
    pub metrics: Metrics,
    /// Timing.
    pub stats: RunStats,
    /// Decimated trace.
    pub trace: Trace,
}

/// The `metrics.json` document.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Scenario name.
    pub scenario: String,
    /// Inverter model run.
    pub inverter_model: InverterModel,
    /// Scalar type of the drive.
    pub precision: Precision,
    /// Which rotor-angle estimator ran.
    pub estimator: EstimatorKind,
    /// All criteria passed.
    pub passed: bool,
    /// max |θ − θ̂| over the evaluation window, rad.
    pub max_angle_error: f64,
    /// RMS angle error, rad.
    pub rms_angle_error: f64,
    /// max |θ − θ̂| near zero speed, rad.
    pub max_angle_error_zero_speed: f64,
    /// RMS angle error near zero speed, rad.
    pub rms_angle_error_zero_speed: f64,
    /// Zero-speed band, r/min.
    pub zero_speed_band_rpm: f64,
    /// max speed error, r/min.
    pub max_speed_error_rpm: f64,
    /// Tripped.
    pub tripped: bool,
    /// Highest true DC-link voltage over the run, V.
    pub max_dc_voltage: f64,
    /// Lowest true DC-link voltage over the run, V.
    pub min_dc_voltage: f64,
    /// Simulated seconds.
    pub simulated_seconds: f64,
    /// Wall seconds.
    pub wall_seconds: f64,
    /// The criteria.
    pub checks: Vec<Check>,
}

impl Outcome {
    /// The `metrics.json` document of this run.
    pub fn report(&self) -> Report {
        let m = &self.metrics;
        Report {
            scenario: self.scenario.clone(),
            inverter_model: self.config.inverter.model,
            precision: self.config.simulation.precision,
            estimator: self.config.simulation.estimator,
            passed: self.passed,
            max_angle_error: m.max_angle_error,
            rms_angle_error: m.rms_angle_error,
            max_angle_error_zero_speed: m.max_angle_error_zero_speed,
            rms_angle_error_zero_speed: m.rms_angle_error_zero_speed,
            zero_speed_band_rpm: m.zero_speed_band_rpm,
            max_speed_error_rpm: m.max_speed_error_rpm,
            tripped: m.tripped,
            max_dc_voltage: m.max_dc_voltage,
            min_dc_voltage: m.min_dc_voltage,
            simulated_seconds: self.stats.simulated_seconds,
            wall_seconds: self.stats.wall_seconds,
            checks: self.checks.clone(),
        }
    }
}

/// The configuration a scenario runs with: its defaults, overridden by `config_toml` (if
/// any), then by `averaged` (forces the averaged inverter model).
pub fn scenario_config(
    scenario: &str,
    config_toml: Option<&str>,
    averaged: bool,
) -> Result<SimConfig, SimConfigError> {
    let sc = find(scenario).ok_or_else(|| {
        let names: Vec<_> = SCENARIOS.iter().map(|s| s.name).collect();
        SimConfigError::new(
            "scenario",
            format!("unknown `{scenario}`; one of {names:?}"),
        )
    })?;
    if let Some(text) = config_toml
        && text.len() > MAX_CONFIG_BYTES
    {
        let mut e = SimConfigError::new(
            "<config>",
            format!(
                "is {} bytes long, more than the {MAX_CONFIG_BYTES} accepted",
                text.len()
            ),
        );
        e.location = Some(crate::source::SourceLocation::at(text, 0));
        return Err(e);
    }
    let mut cfg = match config_toml {
        // The user's motor first (a scaled scenario needs its ratings), then the scenario,
        // then the user's keys again, so that any of them wins over the scenario's.
        Some(text) => {
            let user = SimConfig::from_user_toml(&SimConfig::default(), text)?;
            SimConfig::from_toml_over(&sc.apply(user), text)?
        }
        None => sc.config(),
    };
    if averaged {
        cfg.inverter.model = InverterModel::Averaged;
    }
    cfg.validate().map_err(|e| match config_toml {
        Some(text) => e.located_in(text),
        None => e,
    })?;
    Ok(cfg)
}

/// Runs a scenario with the sensorless drive: the entry point for the CLI and the Python
/// bindings. `progress` receives the completed fraction.
pub fn simulate(
    scenario: &str,
    config_toml: Option<&str>,
    averaged: bool,
    progress: Option<&mut dyn FnMut(f64)>,
) -> Result<Outcome, SimConfigError> {
    let cfg = scenario_config(scenario, config_toml, averaged)?;
    run_config(scenario, cfg, progress)
}

impl SimConfig {
    /// The closed loop of this configuration around `controller`: the plant at rest at
    /// `simulation.initial_angle`, the speed reference, the k_df-off events; the controller
    /// aligned (with `simulation.align_error`). Step it or [`Simulation::run`] it.
    pub fn simulation<C: Controller>(
        &self,
        controller: C,
    ) -> Result<Simulation<C>, SimConfigError> {
        let mut plant = Plant::new(&self.plant(), self.simulation.initial_angle)?;
        if self.simulation.brake {
            plant.engage_brake();
        }
        let mut events = Vec::new();
        for w in &self.simulation.disturbance_feedback_off {
            events.push((w[0], ControlEvent::DisturbanceFeedback(false)));
            events.push((w[1], ControlEvent::DisturbanceFeedback(true)));
        }
        Ok(Simulation::new(
            plant,
            controller,
            self.speed_reference.clone(),
            self.simulation.align_error,
        )?
        .with_events(events))
    }
}

/// Where a run's decimated trace goes.
pub enum TraceOutput<'a> {
    /// Kept in memory in [`Outcome::trace`].
    Keep,
    /// Not kept at all (sweeps: only the metrics matter).
    Discard,
    /// Handed row by row to a sink as it is produced (a file for the CLI, columns for
    /// Python); [`Outcome::trace`] stays empty and memory does not grow with the duration.
    Sink(&'a mut dyn TraceSink),
}

/// How [`run_config_with`] runs.
pub struct RunOptions<'a> {
    /// Called with the completed fraction about a hundred times.
    pub progress: Option<&'a mut dyn FnMut(f64)>,
    /// Where the trace goes.
    pub trace: TraceOutput<'a>,
    /// Stops the run early once set ([`Simulation::run_until`]): the outcome then has
    /// `stats.cancelled` and its checks are not evaluated.
    pub cancel: Option<&'a AtomicBool>,
}

impl Default for RunOptions<'_> {
    fn default() -> Self {
        Self {
            progress: None,
            trace: TraceOutput::Keep,
            cancel: None,
        }
    }
}

/// Number of rows the trace of `cfg` will have (one sample in `simulation.decimation`).
pub fn trace_rows(cfg: &SimConfig) -> u64 {
    let samples = (cfg.simulation.duration / cfg.inverter.sample_period())
        .round()
        .max(0.0) as u64;
    samples.div_ceil(cfg.simulation.decimation.max(1) as u64)
}

/// Largest configuration text accepted (bytes): 1 MiB is 350 times the largest scenario's
/// `--dump-config` and three times a profile of [`crate::profile::MAX_POINTS`] breakpoints,
/// and parses in about 0.3 s and 60 MB (measured: 4 MiB took 2 s and 240 MB; an input-size
/// cap, not a limit of the model).
pub const MAX_CONFIG_BYTES: usize = 1 << 20;

/// Runs a scenario's criteria on an explicit configuration, keeping the trace in memory.
pub fn run_config(
    scenario: &str,
    cfg: SimConfig,
    progress: Option<&mut dyn FnMut(f64)>,
) -> Result<Outcome, SimConfigError> {
    run_config_with(
        scenario,
        cfg,
        RunOptions {
            progress,
            ..Default::default()
        },
    )
}

/// Runs a scenario's criteria on an explicit configuration, with the trace going where
/// `opts` says and an optional cancel flag.
pub fn run_config_with(
    scenario: &str,
    cfg: SimConfig,
    opts: RunOptions<'_>,
) -> Result<Outcome, SimConfigError> {
    let sc = find(scenario)
        .ok_or_else(|| SimConfigError::new("scenario", format!("unknown `{scenario}`")))?;
    let estimator = cfg.simulation.estimator.estimator();
    let mut cfg = cfg;
    (estimator.prepare)(&mut cfg);
    cfg.validate()?;
    let started = Instant::now();
    let drive = (estimator.build)(&cfg)?;
    run_with(sc, cfg, drive, started, opts)
}

fn run_with<C: Controller>(
    sc: &Scenario,
    cfg: SimConfig,
    drive: C,
    started: Instant,
    opts: RunOptions<'_>,
) -> Result<Outcome, SimConfigError> {
    let mut sim = cfg.simulation(drive)?;
    let mut metrics = Metrics::new(cfg.simulation.eval_start, cfg.zero_speed_band_rpm());
    let mut trace = Trace::new(cfg.simulation.decimation);
    let mut probe = sc.probe(&cfg);
    let duration = cfg.simulation.duration;
    let mut stats = match opts.trace {
        TraceOutput::Keep => sim.run_until(
            duration,
            &mut [&mut metrics, &mut trace, &mut probe],
            opts.progress,
            opts.cancel,
        ),
        TraceOutput::Discard => sim.run_until(
            duration,
            &mut [&mut metrics, &mut probe],
            opts.progress,
            opts.cancel,
        ),
        TraceOutput::Sink(sink) => {
            let mut rows = Decimated::new(cfg.simulation.decimation, sink);
            sim.run_until(
                duration,
                &mut [&mut metrics, &mut rows, &mut probe],
                opts.progress,
                opts.cancel,
            )
        }
    };
    stats.wall_seconds = started.elapsed().as_secs_f64();
    let checks = if stats.cancelled {
        Vec::new()
    } else {
        sc.evaluate(&cfg, &metrics, &probe)
    };
    Ok(Outcome {
        probe,
        scenario: sc.name.to_owned(),
        passed: !stats.cancelled && checks.iter().all(|c| c.passed),
        checks,
        metrics,
        stats,
        trace,
        config: cfg,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scenario_config_is_valid_and_round_trips_through_toml() {
        for sc in &SCENARIOS {
            let cfg = scenario_config(sc.name, None, false).unwrap();
            let back = SimConfig::from_toml(&cfg.to_toml()).unwrap();
            assert_eq!(back, cfg, "{}", sc.name);
            assert!(
                cfg.simulation.duration >= cfg.speed_reference.end_time(),
                "{}",
                sc.name
            );
            let avg = scenario_config(sc.name, None, true).unwrap();
            assert_eq!(avg.inverter.model, InverterModel::Averaged);
        }
        let e = scenario_config("fig99", None, false).unwrap_err();
        assert_eq!(e.key, "scenario");
        let e = scenario_config("fig11", Some("[mismatch]\nrs_rato = 1.0\n"), false).unwrap_err();
        assert_eq!(e.key, "mismatch.rs_rato");
        // Input-size caps: the text, then the breakpoints of a profile.
        let huge = format!("# {}\n", "x".repeat(MAX_CONFIG_BYTES));
        let e = scenario_config("fig11", Some(&huge), true).unwrap_err();
        assert_eq!(
            (e.key.as_str(), e.location.map(|l| l.line)),
            ("<config>", Some(1))
        );
        let points: Vec<String> = (0..=crate::profile::MAX_POINTS)
            .map(|k| format!("[{k}.0, 0.0]"))
            .collect();
        let many = format!("[speed_reference]\npoints = [{}]\n", points.join(", "));
        let e = scenario_config("fig11", Some(&many), true).unwrap_err();
        assert_eq!(e.key, "speed_reference.points", "{e}");
        assert!(e.to_string().contains("10001 breakpoints"), "{e}");
    }

    #[test]
    fn lowspeed_staircase_levels_are_judged_on_their_settled_window() {
        let cfg = find("lowspeed").unwrap().config();
        let probe = find("lowspeed").unwrap().probe(&cfg);
        assert_eq!(probe.levels.len(), lowspeed_levels_rpm(1500.0).len());
        for (l, &level) in probe.levels.iter().zip(&lowspeed_levels_rpm(1500.0)) {
            // The reference sits at the level over the whole judged window, under full load.
            for t in [l.from, 0.5 * (l.from + l.to), l.to] {
                assert_eq!(cfg.speed_reference.value(t), level, "t = {t}");
                assert_eq!(cfg.load.torque.value(t), 7.5);
            }
        }
        assert!(cfg.simulation.duration >= probe.levels.last().unwrap().to);

        // Synthetic runs: held down to 3.75 r/min, lost at 1.875, "held" again at 0.9375.
        let mut p = probe.clone();
        for (k, l) in probe.levels.iter().enumerate() {
            let (err, speed) = match k {
                0..=4 => (0.1, l.level_rpm * 1.2),
                5 => (0.3, l.level_rpm),
                _ => (0.0, l.level_rpm),
            };
            for n in 0..=100 {
                let t = l.from + (l.to - l.from) * n as f64 / 100.0;
                for level in &mut p.levels {
                    level.observe(t, err, speed, false);
                }
            }
        }
        assert!(p.levels[4].held() && !p.levels[5].held() && p.levels[6].held());
        assert_eq!(p.levels_held_in_a_row(), 5);
        assert_eq!(p.lowest_speed_held_rpm(), Some(3.75));

        // Too slow (below half the level) is not held, and neither is anything after a trip.
        let mut q = probe.clone();
        let first = q.levels[0].clone();
        q.levels[0].observe(first.from, 0.0, 0.45 * first.level_rpm, false);
        assert!(!q.levels[0].held());
        assert_eq!(q.lowest_speed_held_rpm(), None);
        let mut r = probe.clone();
        let (t0, t1) = (r.levels[0].from, r.levels[1].from);
        r.levels[1].observe(t0 - 1.0, 0.0, 0.0, true);
        r.levels[1].observe(t1, 0.0, 30.0, false);
        assert!(!r.levels[1].held());
        // The speed bound floors at 0.5 r/min for the slowest levels.
        assert_eq!(lowspeed_speed_bound(0.9375), 0.5);
        assert_eq!(lowspeed_speed_bound(30.0), 15.0);
    }

    #[test]
    fn fig11_profile_is_the_papers_reversal() {
        let cfg = find("fig11").unwrap().config();
        let p = &cfg.speed_reference;
        // −90 → +90 r/min at 90 r/min/s under +7.5 N·m (paper §V-B).
        assert_eq!(p.value(2.5), -90.0);
        assert!((p.slope(3.5) - 90.0).abs() < 1e-9);
        assert_eq!(p.value(4.5), 90.0);
        assert_eq!(cfg.load.torque.value(2.5), 7.5);
    }
}
