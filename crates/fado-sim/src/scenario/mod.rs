//! The paper's experiments (Fig. 8–12) as named scenarios with their pass criteria checked in
//! code (docs/guide/first-run.md). Loads and rates are the paper's \[P\]; the exact profiles around them
//! (start-up, load application, settling, hold times) are ours \[A\] and are stated per scenario.
//!
//! Every scenario starts at standstill with a known rotor angle (docs/method/estimator.md, "Start-up"), brings the
//! machine to the experiment's initial operating point without load, applies the load with a
//! 0.5 s ramp, lets it settle, then runs the experiment. Metrics are taken from `eval_start`.

mod checks;
mod load_settling;
mod probe;
mod profiles;
mod report;
mod run;
mod scaled;
mod table;
#[cfg(test)]
mod tests;

use crate::config::SimConfig;
use crate::sim::Metrics;

pub use checks::Check;
pub use probe::{LevelStats, ScenarioProbe, StartStats};
pub use profiles::CUSTOM_TAIL_SECONDS;
pub use report::{Outcome, Report};
pub use run::{
    MAX_CONFIG_BYTES, RunOptions, TraceOutput, run_config, run_config_with, scenario_config,
    simulate, trace_rows,
};
pub use scaled::{
    LOADED_START_LOAD_RATIO, LOADED_START_MAX_BACK, LOWSPEED_ANGLE_BOUND, LOWSPEED_JUDGED_SECONDS,
    LOWSPEED_LEVEL_SECONDS, REVERSAL_SPEED_RATIO, SCALED_LOAD_RATIO, SCALED_SPEED_ERROR_RATIO,
    STOPS_SPEED_RATIO, loaded_start_angle, lowspeed_levels_rpm, lowspeed_speed_bound,
};
pub use table::SCENARIOS;

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

    /// For a paper experiment in its motor's units (`fig8`–`fig12`, `steady300`) run on
    /// `cfg`, which holds another motor: the words saying so, with the largest load (N·m) and
    /// speed (r/min) of its profile against that motor's ratings and the scenarios scaled by
    /// them. None for a scaled scenario, for `custom` and on a motor with the paper motor's
    /// ratings.
    pub fn units_note(&self, cfg: &SimConfig) -> Option<String> {
        let paper = crate::motor::MotorParams::paper();
        let m = &cfg.motor;
        let papers =
            m.rated_torque == paper.rated_torque && m.rated_speed_rpm == paper.rated_speed_rpm;
        if self.scaled || self.neutral || papers {
            return None;
        }
        let load = cfg.load.torque.largest_magnitude();
        let speed = cfg.speed_reference.largest_magnitude();
        let scaled: Vec<&str> = SCENARIOS
            .iter()
            .filter(|s| s.scaled)
            .map(|s| s.name)
            .collect();
        Some(format!(
            "`{}` is the paper's experiment in its motor's units (loads up to {load} N·m, \
             speeds up to {speed} r/min), not scaled to this [motor]: {:.2} × its \
             `motor.rated_torque` ({} N·m) and {:.3} × its `motor.rated_speed_rpm` ({} r/min); \
             scaled by the ratings: {}",
            self.name,
            load / m.rated_torque,
            m.rated_torque,
            speed / m.rated_speed_rpm,
            m.rated_speed_rpm,
            scaled.join(", ")
        ))
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
