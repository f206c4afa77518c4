//! Operating-envelope sweeps: one scenario run per point of a grid or of a random design over
//! model errors, sensor errors, load and profile, in parallel, with every point's outcome
//! recorded (CLI `fado-sim sweep`, Python `fado.sweep`).
//!
//! A sweep ([`SweepSpec`]) is a base scenario (with an optional TOML override and the inverter
//! model), a list of parameter names (the axes) and a list of points, one value per axis.
//! [`SweepSpec::grid`] builds the cartesian product of value lists, [`SweepSpec::random`]
//! draws uniform samples in ranges from a seed. A parameter is either any TOML key of the
//! configuration (`section.key`, e.g. `estimator.k_df`, `load.torque.points`) or one of the
//! derived [`PARAMETERS`], whose direction is fixed by their names:
//!
//! | parameter | meaning | sets |
//! |---|---|---|
//! | `rs_error` | R̂s/(Rs + r_on) − 1 | `mismatch.rs_ratio` |
//! | `lq_error` | L̂q/Lq − 1 | `mismatch.lq_ratio` |
//! | `ld_error` | L̂d/Ld − 1 | `mismatch.ld_ratio` |
//! | `flux_linkage_error` | λ̂f/λf − 1 | `mismatch.flux_linkage_ratio` |
//! | `dead_time_comp_error` | T̂d/Td − 1 of the dead-time compensation | `mismatch.dead_time_ratio` |
//! | `sensor_offset` | current-sensor offset, A: phase a +v, phase b −v/2 | `current_sensor.offset_a/_b` |
//! | `sensor_gain_error` | gain of phase a's sensor relative to phase b's, −1 | `current_sensor.gain_error_a/_b` |
//! | `load_torque` | final load torque, N·m (the load profile scaled to end there) | `load.torque` |
//! | `reversal_ramp` | slope of the speed reference's reversal, r/min per s | `speed_reference`, `simulation.duration` |
//!
//! Every point runs guarded ([`run_point`]): an invalid configuration, a run error or a panic
//! gives status `failed: <message>`, a trip or a non-finite metric gives `diverged`; the sweep
//! goes on. With an output directory ([`SweepOptions::out`]) each finished point is appended
//! and flushed to `sweep.csv` at once, the definition is kept in `sweep.json`, and a sweep
//! started again on the same directory with the same definition skips the points already in
//! the CSV (an interrupted sweep resumes). `summary.json` and `summary.md` hold the
//! [`Summary`].

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::{Rng, SeedableRng};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
pub use toml::Value;

use crate::config::SimConfig;
use crate::error::SimConfigError;
use crate::profile::Profile;
use crate::scenario;

/// The derived parameters and what they mean (see the module documentation).
pub const PARAMETERS: [(&str, &str); 9] = [
    ("rs_error", "R̂s/(Rs + r_on) − 1 (mismatch.rs_ratio − 1)"),
    ("lq_error", "L̂q/Lq − 1 (mismatch.lq_ratio − 1)"),
    ("ld_error", "L̂d/Ld − 1 (mismatch.ld_ratio − 1)"),
    (
        "flux_linkage_error",
        "λ̂f/λf − 1 (mismatch.flux_linkage_ratio − 1)",
    ),
    (
        "dead_time_comp_error",
        "T̂d/Td − 1 of the dead-time compensation (mismatch.dead_time_ratio − 1)",
    ),
    (
        "sensor_offset",
        "current-sensor offset in A: phase a +v, phase b −v/2 (before start-up calibration)",
    ),
    (
        "sensor_gain_error",
        "phase a sensor gain relative to phase b, −1 (gain_error_a = v, gain_error_b = 0)",
    ),
    (
        "load_torque",
        "final load torque in N·m (the load torque profile scaled to end there)",
    ),
    (
        "reversal_ramp",
        "slope of the speed reference's reversal in r/min per s (later points shifted)",
    ),
];

/// Metric columns of a row, after the axes and `status`, `passed`.
pub const METRICS: [&str; 9] = [
    "max_angle_error",
    "rms_angle_error",
    "max_angle_error_zero_speed",
    "rms_angle_error_zero_speed",
    "max_speed_error_rpm",
    "wall_seconds",
    "max_angle_error_run",
    "angle_error_exceeded_time",
    "lock_lost_time",
];

/// A sweep definition: base scenario and configuration, axes and points.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepSpec {
    /// Scenario name (its pass criteria judge every point).
    pub scenario: String,
    /// TOML applied over the scenario before the axes.
    pub config_toml: Option<String>,
    /// Force the averaged inverter model.
    pub averaged: bool,
    /// Parameter names, one per axis.
    pub axes: Vec<String>,
    /// One value per axis for each point.
    pub points: Vec<Vec<Value>>,
    /// How the points were made (`grid 9 × 4`, `random 50 (seed 1)`, `points`).
    pub design: String,
}

impl SweepSpec {
    /// The cartesian product of `axes` (first axis slowest).
    pub fn grid(scenario: &str, axes: Vec<(String, Vec<Value>)>) -> Self {
        let mut points: Vec<Vec<Value>> = vec![Vec::new()];
        for (_, values) in &axes {
            points = points
                .iter()
                .flat_map(|p| {
                    values.iter().map(move |v| {
                        let mut q = p.clone();
                        q.push(v.clone());
                        q
                    })
                })
                .collect();
        }
        let shape: Vec<_> = axes.iter().map(|(_, v)| v.len().to_string()).collect();
        Self {
            scenario: scenario.to_owned(),
            config_toml: None,
            averaged: false,
            design: format!("grid {}", shape.join(" × ")),
            axes: axes.into_iter().map(|(n, _)| n).collect(),
            points,
        }
    }

    /// `samples` points drawn uniformly in the ranges `(name, lo, hi)` from `seed`
    /// (xoshiro256++: the same seed gives the same points on every platform).
    pub fn random(
        scenario: &str,
        ranges: &[(String, f64, f64)],
        samples: usize,
        seed: u64,
    ) -> Self {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let points = (0..samples)
            .map(|_| {
                ranges
                    .iter()
                    .map(|&(_, lo, hi)| {
                        let u = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
                        Value::Float(lo + (hi - lo) * u)
                    })
                    .collect()
            })
            .collect();
        Self {
            scenario: scenario.to_owned(),
            config_toml: None,
            averaged: false,
            axes: ranges.iter().map(|(n, _, _)| n.clone()).collect(),
            points,
            design: format!("random {samples} (seed {seed})"),
        }
    }

    /// Checks the definition (scenario known, axis names valid and distinct, one value per
    /// axis in every point) and returns the base configuration.
    pub fn base_config(&self) -> Result<SimConfig, SimConfigError> {
        let base =
            scenario::scenario_config(&self.scenario, self.config_toml.as_deref(), self.averaged)?;
        let keys = toml::Table::try_from(&base)
            .map_err(|e| SimConfigError::new("<base>", e.to_string()))?;
        let mut seen = Vec::new();
        for name in &self.axes {
            check_parameter_name(name, &keys)?;
            if seen.contains(&name) {
                return Err(SimConfigError::new(name.clone(), "axis given twice"));
            }
            seen.push(name);
        }
        if let Some(k) = self.points.iter().position(|p| p.len() != self.axes.len()) {
            return Err(SimConfigError::new(
                format!("points[{k}]"),
                format!(
                    "has {} values for {} axes",
                    self.points[k].len(),
                    self.axes.len()
                ),
            ));
        }
        Ok(base)
    }

    /// A stable fingerprint of the definition and of the base configuration it resolves to
    /// (FNV-1a 64): `sweep.json` keeps it so that a resumed sweep is known to be the same
    /// sweep, also after a change of the scenario's defaults.
    pub fn fingerprint(&self) -> String {
        let json = serde_json::to_string(self).expect("a sweep definition serialises");
        let base = self.base_config().map(|c| c.to_toml()).unwrap_or_default();
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in json.bytes().chain(base.bytes()) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        format!("{h:016x}")
    }

    /// The configuration of point `k` (`base` from [`SweepSpec::base_config`]).
    pub fn point_config(&self, base: &SimConfig, k: usize) -> Result<SimConfig, SimConfigError> {
        point_config(base, &self.axes, &self.points[k])
    }
}

/// A derived parameter, or a key of the configuration (`keys`: the base configuration as a
/// TOML table, which holds every key): a misspelt axis is an error before anything runs.
fn check_parameter_name(name: &str, keys: &toml::Table) -> Result<(), SimConfigError> {
    if PARAMETERS.iter().any(|(n, _)| *n == name) {
        return Ok(());
    }
    // Walk the tables; the key must end on a value, not on a table or past a value.
    let mut table = Some(keys);
    let mut found = false;
    for part in name.split('.') {
        let Some(value) = table.and_then(|t| t.get(part)) else {
            found = false;
            break;
        };
        (table, found) = match value {
            Value::Table(t) => (Some(t), false),
            _ => (None, true),
        };
    }
    if found && name.contains('.') && !name.ends_with('.') {
        return Ok(());
    }
    let names: Vec<_> = PARAMETERS.iter().map(|(n, _)| *n).collect();
    Err(SimConfigError::new(
        name.to_owned(),
        format!("not a configuration key `section.key` (see --dump-config) nor one of {names:?}"),
    ))
}

/// Parses one value list: `lo:hi:n` (n values evenly spaced, ends included) or `v1,v2,...`
/// (TOML values; bare words are taken as strings).
pub fn parse_values(text: &str) -> Result<Vec<Value>, SimConfigError> {
    let text = text.trim();
    let parts: Vec<_> = text.split(':').collect();
    if parts.len() == 3 {
        let num = |s: &str| s.trim().parse::<f64>().ok().filter(|x| x.is_finite());
        let (Some(lo), Some(hi), Ok(n)) = (
            num(parts[0]),
            num(parts[1]),
            parts[2].trim().parse::<usize>(),
        ) else {
            return Err(SimConfigError::new(
                text.to_owned(),
                "`lo:hi:n` needs two finite numbers and a count",
            ));
        };
        if n == 0 {
            return Err(SimConfigError::new(text.to_owned(), "count must be ≥ 1"));
        }
        return Ok((0..n)
            .map(|k| {
                let v = if n == 1 {
                    lo
                } else {
                    lo + (hi - lo) * k as f64 / (n - 1) as f64
                };
                // Round off the last-bit noise of the linspace (0.30000000000000004).
                Value::Float((v * 1e12).round() / 1e12)
            })
            .collect());
    }
    let values: Vec<_> = text
        .split(',')
        .map(str::trim)
        .filter(|v| !v.is_empty())
        .map(parse_value)
        .collect();
    if values.is_empty() {
        return Err(SimConfigError::new(text.to_owned(), "no values"));
    }
    Ok(values)
}

/// A TOML value as written (`0.5`, `3`, `true`, `[[0.0, 1.0]]`), else the text as a string.
pub fn parse_value(text: &str) -> Value {
    format!("x = {text}")
        .parse::<toml::Table>()
        .ok()
        .and_then(|mut t| t.remove("x"))
        .unwrap_or_else(|| Value::String(text.to_owned()))
}

/// Parses a range `lo..hi` of a random design.
pub fn parse_range(text: &str) -> Result<(f64, f64), SimConfigError> {
    let bad = || SimConfigError::new(text.to_owned(), "a range must be `lo..hi` with lo ≤ hi");
    let (a, b) = text.split_once("..").ok_or_else(bad)?;
    let (lo, hi) = (
        a.trim().parse::<f64>().map_err(|_| bad())?,
        b.trim().parse::<f64>().map_err(|_| bad())?,
    );
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return Err(bad());
    }
    Ok((lo, hi))
}

/// The configuration of one point: `base` with each `(name, value)` applied in order, then
/// validated. Errors name the parameter.
pub fn point_config(
    base: &SimConfig,
    names: &[String],
    values: &[Value],
) -> Result<SimConfig, SimConfigError> {
    let mut cfg = base.clone();
    for (name, value) in names.iter().zip(values) {
        cfg = apply(cfg, name, value)?;
    }
    cfg.validate()?;
    Ok(cfg)
}

fn number(name: &str, value: &Value) -> Result<f64, SimConfigError> {
    match value {
        Value::Float(x) if x.is_finite() => Ok(*x),
        Value::Integer(i) => Ok(*i as f64),
        _ => Err(SimConfigError::new(
            name.to_owned(),
            format!("needs a finite number, got {value}"),
        )),
    }
}

fn apply(mut cfg: SimConfig, name: &str, value: &Value) -> Result<SimConfig, SimConfigError> {
    let derived = PARAMETERS.iter().any(|(n, _)| *n == name);
    if !derived {
        let (section, key) = name
            .rsplit_once('.')
            .ok_or_else(|| SimConfigError::new(name.to_owned(), "must be section.key"))?;
        let snippet = format!("[{section}]\n{key} = {value}\n");
        return SimConfig::from_toml_over(&cfg, &snippet);
    }
    let v = number(name, value)?;
    match name {
        "rs_error" => cfg.mismatch.rs_ratio = 1.0 + v,
        "lq_error" => cfg.mismatch.lq_ratio = 1.0 + v,
        "ld_error" => cfg.mismatch.ld_ratio = 1.0 + v,
        "flux_linkage_error" => cfg.mismatch.flux_linkage_ratio = 1.0 + v,
        "dead_time_comp_error" => cfg.mismatch.dead_time_ratio = 1.0 + v,
        "sensor_offset" => {
            cfg.current_sensor.offset_a = v;
            cfg.current_sensor.offset_b = -0.5 * v;
            cfg.current_sensor.enable_offset = true;
        }
        "sensor_gain_error" => {
            cfg.current_sensor.gain_error_a = v;
            cfg.current_sensor.gain_error_b = 0.0;
            cfg.current_sensor.enable_gain_error = true;
        }
        "load_torque" => cfg.load.torque = scaled_to_end_at(&cfg.load.torque, v),
        "reversal_ramp" => set_reversal_ramp(&mut cfg, v)?,
        _ => unreachable!("every derived parameter is handled"),
    }
    Ok(cfg)
}

/// The profile scaled so that its last value is `end` (a profile ending at 0 gets its last
/// point moved to `end`).
fn scaled_to_end_at(p: &Profile, end: f64) -> Profile {
    let mut q = p.clone();
    let last = q.points.last().map_or(0.0, |x| x[1]);
    if last != 0.0 {
        for x in &mut q.points {
            x[1] *= end / last;
        }
    } else if let Some(x) = q.points.last_mut() {
        x[1] = end;
    }
    q
}

/// Rewrites the speed reference's reversal (the first segment whose end points have opposite
/// signs) to slope `rate` r/min per s, keeping its start; later points and the run's end move
/// by the change of its duration.
fn set_reversal_ramp(cfg: &mut SimConfig, rate: f64) -> Result<(), SimConfigError> {
    if rate <= 0.0 {
        return Err(SimConfigError::new(
            "reversal_ramp",
            "must be > 0 r/min per s",
        ));
    }
    let pts = &mut cfg.speed_reference.points;
    let k = (1..pts.len())
        .find(|&k| pts[k - 1][1] * pts[k][1] < 0.0)
        .ok_or_else(|| {
            SimConfigError::new(
                "reversal_ramp",
                "the scenario's speed reference has no reversal (segment changing sign)",
            )
        })?;
    let (a, b) = (pts[k - 1], pts[k]);
    let shift = (b[1] - a[1]).abs() / rate - (b[0] - a[0]);
    for p in &mut pts[k..] {
        p[0] += shift;
    }
    cfg.simulation.duration = (cfg.simulation.duration + shift).max(0.0);
    Ok(())
}

/// How a point ended.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Status {
    /// Ran to the end with finite metrics and no trip (it may still fail the criteria).
    Ok,
    /// Tripped, or a metric is not finite.
    Diverged,
    /// Invalid configuration, run error or panic.
    Failed(String),
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Status::Ok => f.write_str("ok"),
            Status::Diverged => f.write_str("diverged"),
            Status::Failed(m) => write!(f, "failed: {m}"),
        }
    }
}

impl Status {
    fn parse(s: &str) -> Self {
        match s {
            "ok" => Status::Ok,
            "diverged" => Status::Diverged,
            _ => Status::Failed(s.strip_prefix("failed: ").unwrap_or(s).to_owned()),
        }
    }
}

/// One point's outcome: a row of `sweep.csv`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PointResult {
    /// Index of the point in [`SweepSpec::points`].
    pub index: usize,
    /// The point's values, one per axis.
    pub values: Vec<Value>,
    /// How it ended.
    pub status: Status,
    /// Every criterion of the scenario passed (false unless `Ok`).
    pub passed: bool,
    /// Names of the failed criteria, `; `-separated.
    pub failed_checks: String,
    /// max |θ − θ̂| over the evaluation window, rad (NaN when failed).
    pub max_angle_error: f64,
    /// RMS of θ − θ̂, rad.
    pub rms_angle_error: f64,
    /// max |θ − θ̂| near zero speed, rad.
    pub max_angle_error_zero_speed: f64,
    /// RMS of θ − θ̂ near zero speed, rad.
    pub rms_angle_error_zero_speed: f64,
    /// max |n* − n|, r/min.
    pub max_speed_error_rpm: f64,
    /// The drive tripped.
    pub tripped: bool,
    /// Wall time of the point, s.
    pub wall_seconds: f64,
    /// max |θ − θ̂| over the whole run with the gates on, rad (loss-of-lock label).
    pub max_angle_error_run: f64,
    /// First time |θ − θ̂| > 0.5 rad, s (NaN: never).
    pub angle_error_exceeded_time: f64,
    /// First time the drive reported the rotor lost, s (NaN: never).
    pub lock_lost_time: f64,
}

impl PointResult {
    fn failed(index: usize, values: &[Value], message: String, wall_seconds: f64) -> Self {
        Self {
            index,
            values: values.to_vec(),
            status: Status::Failed(message),
            passed: false,
            failed_checks: String::new(),
            max_angle_error: f64::NAN,
            rms_angle_error: f64::NAN,
            max_angle_error_zero_speed: f64::NAN,
            rms_angle_error_zero_speed: f64::NAN,
            max_speed_error_rpm: f64::NAN,
            tripped: false,
            wall_seconds,
            max_angle_error_run: f64::NAN,
            angle_error_exceeded_time: f64::NAN,
            lock_lost_time: f64::NAN,
        }
    }

    fn metrics(&self) -> [f64; 9] {
        [
            self.max_angle_error,
            self.rms_angle_error,
            self.max_angle_error_zero_speed,
            self.rms_angle_error_zero_speed,
            self.max_speed_error_rpm,
            self.wall_seconds,
            self.max_angle_error_run,
            self.angle_error_exceeded_time,
            self.lock_lost_time,
        ]
    }
}

/// Runs one point guarded: never returns an error and never panics (a configuration error,
/// a run error or a panic of the run is the row's `failed` status).
pub fn run_point(
    scenario: &str,
    base: &SimConfig,
    names: &[String],
    values: &[Value],
    index: usize,
) -> PointResult {
    let started = Instant::now();
    let cfg = match point_config(base, names, values) {
        Ok(c) => c,
        Err(e) => return PointResult::failed(index, values, e.to_string(), 0.0),
    };
    let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        scenario::run_config(scenario, cfg, None)
    }));
    let wall = started.elapsed().as_secs_f64();
    let outcome = match run {
        Ok(Ok(o)) => o,
        Ok(Err(e)) => return PointResult::failed(index, values, e.to_string(), wall),
        Err(panic) => {
            let msg = panic
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_owned());
            return PointResult::failed(index, values, format!("panic: {msg}"), wall);
        }
    };
    let m = &outcome.metrics;
    let mut r = PointResult {
        index,
        values: values.to_vec(),
        status: Status::Ok,
        passed: outcome.passed,
        failed_checks: outcome
            .checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>()
            .join("; "),
        max_angle_error: m.max_angle_error,
        rms_angle_error: m.rms_angle_error,
        max_angle_error_zero_speed: m.max_angle_error_zero_speed,
        rms_angle_error_zero_speed: m.rms_angle_error_zero_speed,
        max_speed_error_rpm: m.max_speed_error_rpm,
        tripped: m.tripped,
        wall_seconds: wall,
        max_angle_error_run: m.max_angle_error_run,
        angle_error_exceeded_time: m.angle_error_exceeded_time.unwrap_or(f64::NAN),
        lock_lost_time: m.lock_lost_time.unwrap_or(f64::NAN),
    };
    // The zero-speed metrics are NaN-free by construction only when the band was visited;
    // judge divergence on the overall ones.
    let finite = [r.max_angle_error, r.rms_angle_error, r.max_speed_error_rpm]
        .iter()
        .all(|x| x.is_finite());
    if r.tripped || !finite {
        r.status = Status::Diverged;
        r.passed = false;
    }
    r
}

/// How to run a sweep.
#[derive(Clone, Debug, Default)]
pub struct SweepOptions {
    /// Worker threads; 0 = all cores.
    pub threads: usize,
    /// Directory for `sweep.csv`, `sweep.json`, `summary.json`, `summary.md` (None: in
    /// memory only, nothing resumed).
    pub out: Option<PathBuf>,
    /// Start afresh even if `out` holds a different or the same sweep.
    pub fresh: bool,
}

/// Errors that stop a sweep before or around the runs (never a point's own failure).
#[derive(Debug)]
pub enum SweepError {
    /// The definition is invalid (unknown scenario, bad axis name, base TOML).
    Config(SimConfigError),
    /// Reading or writing the output directory.
    Io(String),
    /// The output directory holds a different sweep.
    Mismatch(String),
}

impl std::fmt::Display for SweepError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SweepError::Config(e) => write!(f, "{e}"),
            SweepError::Io(m) | SweepError::Mismatch(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for SweepError {}

impl From<SimConfigError> for SweepError {
    fn from(e: SimConfigError) -> Self {
        SweepError::Config(e)
    }
}

fn io(path: &Path, e: impl std::fmt::Display) -> SweepError {
    SweepError::Io(format!("{}: {e}", path.display()))
}

/// A finished sweep.
#[derive(Clone, Debug, Serialize)]
pub struct SweepOutcome {
    /// The definition.
    pub spec: SweepSpec,
    /// One row per point, by index.
    pub rows: Vec<PointResult>,
    /// Points taken from an earlier, interrupted run of the same sweep.
    pub resumed: usize,
    /// Points run now.
    pub ran: usize,
    /// Wall time of this invocation, s.
    pub wall_seconds: f64,
    /// Counts, worst point, pass fractions.
    pub summary: Summary,
}

/// Runs a sweep (see the module documentation). `on_point` is called from the workers after
/// each point run now (not for resumed ones) with the point and the number of points
/// finished so far, resumed ones included — for progress bars and counting.
pub fn run(
    spec: &SweepSpec,
    opts: &SweepOptions,
    on_point: &(dyn Fn(&PointResult, usize) + Sync),
) -> Result<SweepOutcome, SweepError> {
    let started = Instant::now();
    let base = spec.base_config()?;
    let mut done: BTreeMap<usize, PointResult> = BTreeMap::new();
    let mut sink = None;
    if let Some(dir) = &opts.out {
        std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
        done = prepare_resume(spec, dir, opts.fresh)?;
        let csv_path = dir.join("sweep.csv");
        write_csv(&csv_path, spec, done.values())?;
        let file = OpenOptions::new()
            .append(true)
            .open(&csv_path)
            .map_err(|e| io(&csv_path, e))?;
        sink = Some(Mutex::new((csv_path, file)));
    }
    let resumed = done.len();
    let todo: Vec<usize> = (0..spec.points.len())
        .filter(|k| !done.contains_key(k))
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .map_err(|e| SweepError::Io(format!("thread pool: {e}")))?;
    let write_error = Mutex::new(None);
    let finished = std::sync::atomic::AtomicUsize::new(resumed);
    let new_rows: Vec<PointResult> = pool.install(|| {
        todo.par_iter()
            .with_max_len(1)
            .map(|&k| {
                let r = run_point(&spec.scenario, &base, &spec.axes, &spec.points[k], k);
                if let Some(sink) = &sink {
                    let mut guard = sink.lock().unwrap_or_else(|p| p.into_inner());
                    let (path, file) = &mut *guard;
                    let line = csv_line(&r);
                    if let Err(e) = file.write_all(line.as_bytes()).and_then(|_| file.flush()) {
                        *write_error.lock().unwrap_or_else(|p| p.into_inner()) = Some(io(path, e));
                    }
                }
                let n = finished.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                on_point(&r, n);
                r
            })
            .collect()
    });
    if let Some(e) = write_error.into_inner().unwrap_or(None) {
        return Err(e);
    }
    let ran = new_rows.len();
    done.extend(new_rows.into_iter().map(|r| (r.index, r)));
    let rows: Vec<PointResult> = done.into_values().collect();
    let summary = Summary::of(spec, &rows);
    let outcome = SweepOutcome {
        spec: spec.clone(),
        rows,
        resumed,
        ran,
        wall_seconds: started.elapsed().as_secs_f64(),
        summary,
    };
    if let Some(dir) = &opts.out {
        // The final CSV is in index order.
        write_csv(&dir.join("sweep.csv"), spec, outcome.rows.iter())?;
        let json_path = dir.join("summary.json");
        let json = serde_json::to_string_pretty(&outcome.summary).map_err(|e| io(&json_path, e))?;
        std::fs::write(&json_path, json).map_err(|e| io(&json_path, e))?;
        let md_path = dir.join("summary.md");
        std::fs::write(&md_path, outcome.summary.to_markdown()).map_err(|e| io(&md_path, e))?;
    }
    Ok(outcome)
}

#[derive(Serialize, Deserialize)]
struct Sidecar {
    fingerprint: String,
    spec: SweepSpec,
}

/// Reads the finished points of an earlier run of the same sweep in `dir` and writes
/// `sweep.json` for this one.
fn prepare_resume(
    spec: &SweepSpec,
    dir: &Path,
    fresh: bool,
) -> Result<BTreeMap<usize, PointResult>, SweepError> {
    let json_path = dir.join("sweep.json");
    let csv_path = dir.join("sweep.csv");
    let fingerprint = spec.fingerprint();
    let mut done = BTreeMap::new();
    if !fresh && json_path.exists() {
        let text = std::fs::read_to_string(&json_path).map_err(|e| io(&json_path, e))?;
        let old: Sidecar = serde_json::from_str(&text).map_err(|e| io(&json_path, e))?;
        if old.fingerprint != fingerprint {
            return Err(SweepError::Mismatch(format!(
                "{} holds a different sweep ({}, {} over {:?}); use another output directory or start afresh (`--fresh`, `fresh=True`)",
                dir.display(),
                old.spec.scenario,
                old.spec.design,
                old.spec.axes
            )));
        }
        if csv_path.exists() {
            done = read_csv(&csv_path, spec)?;
        }
    }
    let sidecar = Sidecar {
        fingerprint,
        spec: spec.clone(),
    };
    let text = serde_json::to_string_pretty(&sidecar).map_err(|e| io(&json_path, e))?;
    std::fs::write(&json_path, text).map_err(|e| io(&json_path, e))?;
    Ok(done)
}

/// The CSV header: `point` (the index), the axes, `status`, `passed`, `tripped`, the [`METRICS`],
/// `failed_checks`.
pub fn csv_header(spec: &SweepSpec) -> Vec<String> {
    let mut h = vec!["point".to_owned()];
    h.extend(spec.axes.iter().cloned());
    h.extend(["status", "passed", "tripped"].map(str::to_owned));
    h.extend(METRICS.map(str::to_owned));
    h.push("failed_checks".to_owned());
    h
}

/// A value as a CSV cell: numbers in Rust's shortest round-trip form, strings bare.
fn cell(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Float(x) => format!("{x:?}"),
        other => other.to_string(),
    }
}

fn csv_record(r: &PointResult) -> Vec<String> {
    let mut rec = vec![r.index.to_string()];
    rec.extend(r.values.iter().map(cell));
    rec.push(r.status.to_string());
    rec.push(r.passed.to_string());
    rec.push(r.tripped.to_string());
    rec.extend(r.metrics().map(|x| {
        if x.is_nan() {
            String::new()
        } else {
            format!("{x:?}")
        }
    }));
    rec.push(r.failed_checks.clone());
    rec
}

fn csv_line(r: &PointResult) -> String {
    let mut w = csv::WriterBuilder::new().from_writer(Vec::new());
    w.write_record(csv_record(r))
        .expect("writing to a Vec cannot fail");
    String::from_utf8(w.into_inner().expect("writing to a Vec cannot fail"))
        .expect("the record is UTF-8")
}

/// Writes `rows` with the header to `path` (through a temporary file, so an interruption
/// leaves the old file).
fn write_csv<'a>(
    path: &Path,
    spec: &SweepSpec,
    rows: impl Iterator<Item = &'a PointResult>,
) -> Result<(), SweepError> {
    let tmp = path.with_extension("csv.tmp");
    let mut w = csv::Writer::from_path(&tmp).map_err(|e| io(&tmp, e))?;
    w.write_record(csv_header(spec)).map_err(|e| io(&tmp, e))?;
    for r in rows {
        w.write_record(csv_record(r)).map_err(|e| io(&tmp, e))?;
    }
    w.flush().map_err(|e| io(&tmp, e))?;
    drop(w);
    std::fs::rename(&tmp, path).map_err(|e| io(path, e))
}

/// Reads the rows of `sweep.csv` written for `spec`: the finished points by index. Rows cut
/// short by an interruption, or not belonging to `spec`, are dropped (they will be rerun).
/// The point values come from `spec`, so they round-trip exactly.
pub fn read_csv(path: &Path, spec: &SweepSpec) -> Result<BTreeMap<usize, PointResult>, SweepError> {
    let file = File::open(path).map_err(|e| io(path, e))?;
    let mut rd = csv::ReaderBuilder::new().flexible(true).from_reader(file);
    let header: Vec<String> = rd
        .headers()
        .map_err(|e| io(path, e))?
        .iter()
        .map(str::to_owned)
        .collect();
    if header != csv_header(spec) {
        return Err(SweepError::Mismatch(format!(
            "{}: the header does not match the sweep's axes",
            path.display()
        )));
    }
    let n_axes = spec.axes.len();
    let mut out = BTreeMap::new();
    for rec in rd.records() {
        let Ok(rec) = rec else { continue };
        if rec.len() != header.len() {
            continue;
        }
        let Ok(index) = rec[0].parse::<usize>() else {
            continue;
        };
        let Some(values) = spec.points.get(index) else {
            continue;
        };
        if values
            .iter()
            .map(cell)
            .ne(rec.iter().skip(1).take(n_axes).map(str::to_owned))
        {
            continue;
        }
        let f = |k: usize| -> Option<f64> {
            let s = &rec[1 + n_axes + 3 + k];
            if s.is_empty() {
                Some(f64::NAN)
            } else {
                s.parse().ok()
            }
        };
        let b = |k: usize| rec[1 + n_axes + k].parse::<bool>().ok();
        let (Some(passed), Some(tripped)) = (b(1), b(2)) else {
            continue;
        };
        let m: Option<Vec<f64>> = (0..METRICS.len()).map(f).collect();
        let Some(m) = m else { continue };
        out.insert(
            index,
            PointResult {
                index,
                values: values.clone(),
                status: Status::parse(&rec[1 + n_axes]),
                passed,
                failed_checks: rec[header.len() - 1].to_owned(),
                max_angle_error: m[0],
                rms_angle_error: m[1],
                max_angle_error_zero_speed: m[2],
                rms_angle_error_zero_speed: m[3],
                max_speed_error_rpm: m[4],
                tripped,
                wall_seconds: m[5],
                max_angle_error_run: m[6],
                angle_error_exceeded_time: m[7],
                lock_lost_time: m[8],
            },
        );
    }
    Ok(out)
}

/// Pass fraction of the points sharing one value (or value bin) of one axis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AxisPass {
    /// The value (or `lo..hi` bin of a random design).
    pub value: String,
    /// Points with it.
    pub points: usize,
    /// Of which passed.
    pub passed: usize,
}

/// Pass fractions along one axis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AxisSummary {
    /// The axis (parameter name).
    pub axis: String,
    /// One entry per value (or bin), ascending for numbers.
    pub values: Vec<AxisPass>,
}

/// What `summary.json` holds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// Scenario.
    pub scenario: String,
    /// Design (`grid 9 × 4`).
    pub design: String,
    /// Axes.
    pub axes: Vec<String>,
    /// Points in the sweep.
    pub points: usize,
    /// Points with a result.
    pub finished: usize,
    /// Passed every criterion.
    pub passed: usize,
    /// Ran, but failed a criterion (status ok).
    pub failed_criteria: usize,
    /// Tripped or non-finite.
    pub diverged: usize,
    /// Could not run (configuration, error, panic).
    pub failed: usize,
    /// Index of the point with the largest max |θ − θ̂| among those that ran (diverged
    /// points first).
    pub worst_index: Option<usize>,
    /// Its values, `name=value`.
    pub worst_point: String,
    /// Its max |θ − θ̂|, rad.
    pub worst_max_angle_error: Option<f64>,
    /// Pass fraction per value of each axis, in axis order.
    pub per_axis: Vec<AxisSummary>,
    /// Sum of the points' wall times, s.
    pub point_seconds: f64,
}

impl Summary {
    /// Summarises `rows` (the finished points of `spec`).
    pub fn of(spec: &SweepSpec, rows: &[PointResult]) -> Self {
        let count = |f: &dyn Fn(&PointResult) -> bool| rows.iter().filter(|r| f(r)).count();
        let worst = rows
            .iter()
            .filter(|r| !matches!(r.status, Status::Failed(_)))
            .max_by(|a, b| {
                let key = |r: &PointResult| {
                    let e = if r.max_angle_error.is_nan() {
                        f64::INFINITY
                    } else {
                        r.max_angle_error
                    };
                    (r.status == Status::Diverged, e)
                };
                let (ka, kb) = (key(a), key(b));
                ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
            });
        let per_axis = (spec.axes.iter().enumerate())
            .map(|(k, name)| AxisSummary {
                axis: name.clone(),
                values: axis_pass(rows, k, spec.design.starts_with("random")),
            })
            .collect();
        Summary {
            scenario: spec.scenario.clone(),
            design: spec.design.clone(),
            axes: spec.axes.clone(),
            points: spec.points.len(),
            finished: rows.len(),
            passed: count(&|r| r.passed),
            failed_criteria: count(&|r| r.status == Status::Ok && !r.passed),
            diverged: count(&|r| r.status == Status::Diverged),
            failed: count(&|r| matches!(r.status, Status::Failed(_))),
            worst_index: worst.map(|r| r.index),
            worst_point: worst.map_or(String::new(), |r| {
                spec.axes
                    .iter()
                    .zip(&r.values)
                    .map(|(n, v)| format!("{n}={}", cell(v)))
                    .collect::<Vec<_>>()
                    .join(", ")
            }),
            worst_max_angle_error: worst.map(|r| r.max_angle_error),
            per_axis,
            point_seconds: rows.iter().map(|r| r.wall_seconds).sum(),
        }
    }

    /// The summary as Markdown (`summary.md`).
    pub fn to_markdown(&self) -> String {
        let mut s = format!(
            "# Sweep of {} ({}, axes {})\n\n\
             | points | finished | passed | failed criteria | diverged | failed to run |\n\
             |---:|---:|---:|---:|---:|---:|\n| {} | {} | {} | {} | {} | {} |\n\n",
            self.scenario,
            self.design,
            self.axes.join(", "),
            self.points,
            self.finished,
            self.passed,
            self.failed_criteria,
            self.diverged,
            self.failed
        );
        if let (Some(k), Some(e)) = (self.worst_index, self.worst_max_angle_error) {
            s += &format!(
                "Worst point: #{k} ({}), max |θ−θ̂| = {e:.4} rad.\n\n",
                self.worst_point
            );
        }
        for AxisSummary {
            axis: name,
            values: rows,
        } in &self.per_axis
        {
            s += &format!("| {name} | points | passed | pass fraction |\n|---|---:|---:|---:|\n");
            for r in rows {
                s += &format!(
                    "| {} | {} | {} | {:.2} |\n",
                    r.value,
                    r.points,
                    r.passed,
                    r.passed as f64 / r.points.max(1) as f64
                );
            }
            s += "\n";
        }
        s
    }
}

/// Pass counts per distinct value of axis `k`, or per fifth of its range for a random design
/// (`binned`) or more than 64 distinct values.
fn axis_pass(rows: &[PointResult], k: usize, binned: bool) -> Vec<AxisPass> {
    let mut distinct: Vec<&Value> = Vec::new();
    for r in rows {
        if !distinct.contains(&&r.values[k]) {
            distinct.push(&r.values[k]);
        }
    }
    let nums: Option<Vec<f64>> = rows.iter().map(|r| number("", &r.values[k]).ok()).collect();
    if (binned || distinct.len() > 64)
        && let Some(nums) = nums
    {
        let lo = nums.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = nums.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let bins = 5;
        let width = (hi - lo) / bins as f64;
        return (0..bins)
            .map(|b| {
                let (a, z) = (lo + width * b as f64, lo + width * (b + 1) as f64);
                let inside: Vec<_> = rows
                    .iter()
                    .zip(&nums)
                    .filter(|(_, x)| **x >= a && (**x < z || b == bins - 1))
                    .collect();
                AxisPass {
                    value: format!("{a:.4}..{z:.4}"),
                    points: inside.len(),
                    passed: inside.iter().filter(|(r, _)| r.passed).count(),
                }
            })
            .collect();
    }
    if nums.is_some() {
        distinct.sort_by(|a, b| {
            number("", a)
                .unwrap_or(0.0)
                .total_cmp(&number("", b).unwrap_or(0.0))
        });
    }
    distinct
        .into_iter()
        .map(|v| {
            let with: Vec<_> = rows.iter().filter(|r| &r.values[k] == v).collect();
            AxisPass {
                value: cell(v),
                points: with.len(),
                passed: with.iter().filter(|r| r.passed).count(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// fig11 cut to its start-up (0.3 s) on the averaged plant: a point runs in milliseconds.
    fn short(spec: SweepSpec) -> SweepSpec {
        SweepSpec {
            config_toml: Some("[simulation]\nduration = 0.3\neval_start = 0.0\n".to_owned()),
            averaged: true,
            ..spec
        }
    }

    fn floats(v: &[f64]) -> Vec<Value> {
        v.iter().map(|&x| Value::Float(x)).collect()
    }

    fn tmp_dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("fado-sweep-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn grid_is_the_cartesian_product_first_axis_slowest() {
        let spec = SweepSpec::grid(
            "fig11",
            vec![
                ("rs_error".into(), parse_values("-0.5:0.5:3").unwrap()),
                ("load_torque".into(), parse_values("0,7.5").unwrap()),
            ],
        );
        assert_eq!(spec.design, "grid 3 × 2");
        let got: Vec<(f64, f64)> = spec
            .points
            .iter()
            .map(|p| (number("", &p[0]).unwrap(), number("", &p[1]).unwrap()))
            .collect();
        assert_eq!(
            got,
            [
                (-0.5, 0.0),
                (-0.5, 7.5),
                (0.0, 0.0),
                (0.0, 7.5),
                (0.5, 0.0),
                (0.5, 7.5)
            ]
        );
        // linspace ends included, last-bit noise rounded off
        assert_eq!(
            parse_values("0:0.3:4").unwrap(),
            floats(&[0.0, 0.1, 0.2, 0.3])
        );
        assert_eq!(
            parse_values("a,true").unwrap()[0],
            Value::String("a".into())
        );
        assert!(parse_values("0:1:0").is_err());
        assert!(parse_range("1..0").is_err());
        assert_eq!(parse_range("-0.5..0.5").unwrap(), (-0.5, 0.5));
    }

    #[test]
    fn random_design_is_deterministic_and_inside_the_ranges() {
        let ranges = [
            ("rs_error".to_owned(), -0.5, 0.5),
            ("load_torque".to_owned(), 0.0, 11.5),
        ];
        let a = SweepSpec::random("fig11", &ranges, 200, 7);
        assert_eq!(a, SweepSpec::random("fig11", &ranges, 200, 7));
        assert_ne!(a.points, SweepSpec::random("fig11", &ranges, 200, 8).points);
        let xs: Vec<f64> = a
            .points
            .iter()
            .map(|p| number("", &p[0]).unwrap())
            .collect();
        assert!(xs.iter().all(|x| (-0.5..0.5).contains(x)));
        // uniform: both halves of the range are visited about equally
        let below = xs.iter().filter(|x| **x < 0.0).count();
        assert!(
            (70..130).contains(&below),
            "{below} of 200 below the middle"
        );
    }

    #[test]
    fn derived_parameters_set_the_configuration() {
        let base = scenario::scenario_config("fig11", None, true).unwrap();
        let names: Vec<String> = PARAMETERS.iter().map(|(n, _)| (*n).to_owned()).collect();
        let values = floats(&[-0.1, 0.2, 0.05, -0.15, 0.3, 0.04, 0.01, 5.0, 45.0]);
        let c = point_config(&base, &names, &values).unwrap();
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(close(c.mismatch.rs_ratio, 0.9));
        assert!(close(c.mismatch.lq_ratio, 1.2));
        assert!(close(c.mismatch.ld_ratio, 1.05));
        assert!(close(c.mismatch.flux_linkage_ratio, 0.85));
        assert!(close(c.mismatch.dead_time_ratio, 1.3));
        assert_eq!(
            (c.current_sensor.offset_a, c.current_sensor.offset_b),
            (0.04, -0.02)
        );
        assert_eq!(
            (c.current_sensor.gain_error_a, c.current_sensor.gain_error_b),
            (0.01, 0.0)
        );
        assert_eq!(c.load.torque.points, vec![[1.2, 0.0], [1.7, 5.0]]);
        // fig11 reverses −90 → 90 r/min from 2.5 s: at 45 r/min/s it takes 4 s, not 2.
        assert_eq!(c.speed_reference.points[3], [2.5, -90.0]);
        assert_eq!(c.speed_reference.points[4], [6.5, 90.0]);
        assert!(close(c.simulation.duration, base.simulation.duration + 2.0));
        // A TOML key as an axis.
        let c = point_config(&base, &["estimator.k_df".into()], &[Value::Float(0.25)]).unwrap();
        assert_eq!(c.estimator.k_df, 0.25);
        // Bad values are errors naming the parameter.
        let e = point_config(&base, &["rs_error".into()], &[Value::Float(-1.5)]).unwrap_err();
        assert!(e.to_string().contains("rs_ratio"), "{e}");
        let e = point_config(&base, &["reversal_ramp".into()], &[Value::Float(0.0)]).unwrap_err();
        assert_eq!(e.key, "reversal_ramp");
        // A misspelt axis is a definition error, before anything runs.
        for bad in [
            "mismatch.rs_rato",
            "mismatch",
            "rs_eror",
            "mismatch.rs_ratio.x",
        ] {
            let spec = SweepSpec::grid("fig11", vec![(bad.into(), floats(&[1.0]))]);
            assert_eq!(spec.base_config().unwrap_err().key, bad);
        }
        let spec = SweepSpec::grid("fig11", vec![("load.torque.points".into(), floats(&[1.0]))]);
        assert!(spec.base_config().is_ok());
        let fig10 = scenario::scenario_config("fig10", None, true).unwrap();
        assert!(point_config(&fig10, &["reversal_ramp".into()], &[Value::Float(90.0)]).is_err());
    }

    #[test]
    fn failed_and_diverged_points_are_recorded_and_the_sweep_goes_on() {
        // L̂q five times Lq makes a 700 Hz current loop unstable: it trips at 41 A.
        let mut spec = short(SweepSpec::grid(
            "fig11",
            vec![
                ("rs_error".into(), floats(&[-2.0, 0.0])),
                ("lq_error".into(), floats(&[0.0, 4.0])),
            ],
        ));
        spec.config_toml = Some(format!(
            "{}[controller]\ncurrent_bandwidth_hz = 700.0\ntrip_current_ratio = 1.88\n",
            spec.config_toml.unwrap()
        ));
        let out = run(&spec, &SweepOptions::default(), &|_, _| {}).unwrap();
        let status: Vec<String> = out.rows.iter().map(|r| r.status.to_string()).collect();
        assert!(
            status[0].starts_with("failed: ") && status[0].contains("rs_ratio"),
            "{status:?}"
        );
        assert!(status[1].starts_with("failed: "));
        assert_eq!(out.rows[2].status, Status::Ok, "{status:?}");
        assert!(out.rows[2].passed, "{:?}", out.rows[2]);
        assert_eq!(out.rows[3].status, Status::Diverged);
        assert!(out.rows[3].tripped && !out.rows[3].passed);
        let s = &out.summary;
        assert_eq!((s.failed, s.diverged, s.passed, s.finished), (2, 1, 1, 4));
        assert_eq!(s.worst_index, Some(3));
    }

    #[test]
    fn an_interrupted_sweep_resumes_without_rerunning_finished_points() {
        let dir = tmp_dir("resume");
        let spec = short(SweepSpec::grid(
            "fig11",
            vec![
                ("rs_error".into(), floats(&[-0.02, 0.0, 0.02])),
                ("load_torque".into(), floats(&[0.0, 7.5])),
            ],
        ));
        let opts = SweepOptions {
            threads: 2,
            out: Some(dir.clone()),
            fresh: false,
        };
        let runs = AtomicUsize::new(0);
        let count = |_: &PointResult, _: usize| {
            runs.fetch_add(1, Ordering::Relaxed);
        };
        let full = run(&spec, &opts, &count).unwrap();
        assert_eq!(runs.load(Ordering::Relaxed), 6);
        // Interrupt: keep the header, two finished rows and half of a third.
        let csv_path = dir.join("sweep.csv");
        let text = std::fs::read_to_string(&csv_path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let cut = format!(
            "{}\n{}\n{}\n{}",
            lines[0],
            lines[2],
            lines[5],
            &lines[3][..10]
        );
        std::fs::write(&csv_path, cut).unwrap();
        runs.store(0, Ordering::Relaxed);
        let resumed = run(&spec, &opts, &count).unwrap();
        assert_eq!(runs.load(Ordering::Relaxed), 4);
        assert_eq!((resumed.resumed, resumed.ran), (2, 4));
        // Seeded and deterministic: the same rows as the uninterrupted sweep.
        let same = |a: &PointResult, b: &PointResult| {
            (a.index, &a.status, a.passed, a.max_angle_error.to_bits())
                == (b.index, &b.status, b.passed, b.max_angle_error.to_bits())
        };
        assert!(full.rows.iter().zip(&resumed.rows).all(|(a, b)| same(a, b)));
        // Finished: nothing more to run.
        runs.store(0, Ordering::Relaxed);
        run(&spec, &opts, &count).unwrap();
        assert_eq!(runs.load(Ordering::Relaxed), 0);
        // A different sweep in the same directory is refused, unless fresh.
        let other = short(SweepSpec::grid(
            "fig11",
            vec![("rs_error".into(), floats(&[0.1]))],
        ));
        assert!(matches!(
            run(&other, &opts, &count),
            Err(SweepError::Mismatch(_))
        ));
        let fresh = SweepOptions {
            fresh: true,
            ..opts
        };
        assert_eq!(run(&other, &fresh, &count).unwrap().ran, 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn csv_round_trips() {
        let dir = tmp_dir("csv");
        let spec = short(SweepSpec::grid(
            "fig11",
            vec![
                ("rs_error".into(), floats(&[-2.0, 0.01])),
                (
                    "simulation.precision".into(),
                    vec![Value::String("f32".into())],
                ),
            ],
        ));
        let opts = SweepOptions {
            threads: 1,
            out: Some(dir.clone()),
            fresh: false,
        };
        let out = run(&spec, &opts, &|_, _| {}).unwrap();
        let back: Vec<PointResult> = read_csv(&dir.join("sweep.csv"), &spec)
            .unwrap()
            .into_values()
            .collect();
        assert_eq!(back.len(), 2);
        for (a, b) in out.rows.iter().zip(&back) {
            assert_eq!(csv_record(a), csv_record(b));
            assert_eq!((&a.values, &a.status), (&b.values, &b.status));
        }
        assert!(matches!(back[0].status, Status::Failed(_)) && back[0].max_angle_error.is_nan());
        // NaN-aware equality (the loss-of-lock times of a run that never lost lock are NaN).
        assert_eq!(format!("{:?}", back[1]), format!("{:?}", out.rows[1]));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
