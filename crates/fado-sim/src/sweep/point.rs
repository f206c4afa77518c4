//! One point of a sweep: its values applied to the base configuration (TOML keys and the
//! derived [`PARAMETERS`]), run guarded, its outcome a [`PointResult`].

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::Value;
use super::spec::PARAMETERS;
use crate::config::SimConfig;
use crate::error::SimConfigError;
use crate::profile::Profile;
use crate::scenario;

/// Metric columns of a row, after the axes and `status`, `passed`.
pub const METRICS: [&str; 15] = [
    "max_angle_error",
    "rms_angle_error",
    "max_angle_error_zero_speed",
    "rms_angle_error_zero_speed",
    "max_speed_error_rpm",
    "wall_seconds",
    "max_angle_error_run",
    "angle_error_exceeded_time",
    "lock_lost_time",
    "loss_onset_time",
    "loss_settled_time",
    "lock_detection_delay",
    "lock_late_delay",
    "stall_time",
    "lock_lost_detection_delay",
];

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

pub(crate) fn number(name: &str, value: &Value) -> Result<f64, SimConfigError> {
    match value {
        Value::Float(x) if x.is_finite() => Ok(*x),
        Value::Integer(i) => Ok(*i as f64),
        _ => Err(SimConfigError::new(
            name.to_owned(),
            format!("needs a finite number, got {value}"),
        )),
    }
}

pub(crate) fn apply(
    mut cfg: SimConfig,
    name: &str,
    value: &Value,
) -> Result<SimConfig, SimConfigError> {
    let derived = PARAMETERS.iter().any(|(n, _)| *n == name);
    if !derived {
        let (section, key) = name
            .rsplit_once('.')
            .ok_or_else(|| SimConfigError::new(name.to_owned(), "must be section.key"))?;
        let snippet = format!("[{section}]\n{key} = {value}\n");
        // The snippet is the sweep's, not the user's file: no line and column in it, but the
        // axis value that caused the refusal.
        return SimConfig::from_toml_over(&cfg, &snippet).map_err(|mut e| {
            e.location = None;
            e.message = format!("{} (the sweep's value {name} = {value})", e.message);
            e
        });
    }
    let v = number(name, value)?;
    match name {
        "rs_error" => cfg.mismatch.rs_ratio = 1.0 + v,
        "lq_error" => cfg.mismatch.lq_ratio = 1.0 + v,
        "ld_error" => cfg.mismatch.ld_ratio = 1.0 + v,
        "flux_linkage_error" => cfg.mismatch.flux_linkage_ratio = 1.0 + v,
        "dead_time_comp_error" => cfg.mismatch.dead_time_ratio = 1.0 + v,
        "sensor_offset" => {
            cfg.current_sensor.offset_a_ratio = v / cfg.motor.rated_current;
            cfg.current_sensor.offset_b_ratio = -0.5 * v / cfg.motor.rated_current;
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
/// signs) to slope `rate` r/min per s, keeping its start; later points, and the run's end if
/// it lies after the reversal, move by the change of its duration.
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
    // A run that ends before the reversal's end keeps its duration (it never sees the change).
    if cfg.simulation.duration >= b[0] {
        cfg.simulation.duration += shift;
    }
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
    pub(crate) fn parse(s: &str) -> Self {
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
    /// Index of the point in [`SweepSpec::points`](super::SweepSpec::points).
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
    /// First time the drive reported the estimate lost (`LOCK_LOST`), s (NaN: never).
    pub lock_lost_time: f64,
    /// Onset of the loss (0.5 rad crossing of the excursion beyond 1 rad), s (NaN: no loss).
    pub loss_onset_time: f64,
    /// Last time |θ − θ̂| < 0.25 rad before the onset, s (NaN: none).
    pub loss_settled_time: f64,
    /// Rise of the flag up at onset + 20 ms minus the onset, s (NaN: down then); see
    /// [`crate::sim::Metrics::lock_detection_delay`].
    pub lock_detection_delay: f64,
    /// First rise of the flag after the onset minus the onset, s (NaN: none).
    pub lock_late_delay: f64,
    /// First time the drive reported a stall (`STALLED`), s (NaN: never).
    pub stall_time: f64,
    /// `lock_detection_delay` for `LOCK_LOST` alone, s (NaN: down then).
    pub lock_lost_detection_delay: f64,
}

impl PointResult {
    pub(crate) fn failed(
        index: usize,
        values: &[Value],
        message: String,
        wall_seconds: f64,
    ) -> Self {
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
            loss_onset_time: f64::NAN,
            loss_settled_time: f64::NAN,
            lock_detection_delay: f64::NAN,
            lock_late_delay: f64::NAN,
            stall_time: f64::NAN,
            lock_lost_detection_delay: f64::NAN,
        }
    }

    pub(crate) fn metrics(&self) -> [f64; 15] {
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
            self.loss_onset_time,
            self.loss_settled_time,
            self.lock_detection_delay,
            self.lock_late_delay,
            self.stall_time,
            self.lock_lost_detection_delay,
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
    run_point_until(scenario, base, names, values, index, None)
        .expect("a run without a cancel flag is never cancelled")
}

/// [`run_point`] that gives up (None) once `cancel` is set, before or during the run.
pub fn run_point_until(
    scenario: &str,
    base: &SimConfig,
    names: &[String],
    values: &[Value],
    index: usize,
    cancel: Option<&AtomicBool>,
) -> Option<PointResult> {
    if cancel.is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed)) {
        return None;
    }
    let started = Instant::now();
    let cfg = match point_config(base, names, values) {
        Ok(c) => c,
        Err(e) => return Some(PointResult::failed(index, values, e.to_string(), 0.0)),
    };
    let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        scenario::run_config_with(
            scenario,
            cfg,
            scenario::RunOptions {
                trace: scenario::TraceOutput::Discard,
                cancel,
                ..Default::default()
            },
        )
    }));
    let wall = started.elapsed().as_secs_f64();
    let outcome = match run {
        Ok(Ok(o)) if o.stats.cancelled => return None,
        Ok(Ok(o)) => o,
        Ok(Err(e)) => return Some(PointResult::failed(index, values, e.to_string(), wall)),
        Err(panic) => {
            let msg = panic
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_owned());
            return Some(PointResult::failed(
                index,
                values,
                format!("panic: {msg}"),
                wall,
            ));
        }
    };
    Some(PointResult::of(&outcome, index, values, wall))
}

impl PointResult {
    /// The row of a finished run `outcome` of point `index` at `values`, `wall` seconds long;
    /// a trip or a non-finite overall metric makes it `Diverged`.
    fn of(outcome: &scenario::Outcome, index: usize, values: &[Value], wall: f64) -> Self {
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
            loss_onset_time: m.loss_onset_time.unwrap_or(f64::NAN),
            loss_settled_time: m.loss_settled_time.unwrap_or(f64::NAN),
            lock_detection_delay: m.lock_detection_delay.unwrap_or(f64::NAN),
            lock_late_delay: m.lock_late_delay.unwrap_or(f64::NAN),
            stall_time: m.stall_time.unwrap_or(f64::NAN),
            lock_lost_detection_delay: m.lock_lost_detection_delay.unwrap_or(f64::NAN),
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::test_support::floats;
    use crate::sweep::{PARAMETERS, SweepSpec};

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
        let rated = c.motor.rated_current;
        assert!(close(c.current_sensor.offset_a_ratio * rated, 0.04));
        assert!(close(c.current_sensor.offset_b_ratio * rated, -0.02));
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
        let c = point_config(
            &base,
            &["estimator.disturbance_feedback.k_df".into()],
            &[Value::Float(0.25)],
        )
        .unwrap();
        assert_eq!(c.estimator.disturbance_feedback.k_df, 0.25);
        // Bad values are errors naming the parameter.
        let e = point_config(&base, &["rs_error".into()], &[Value::Float(-1.5)]).unwrap_err();
        assert!(e.to_string().contains("rs_ratio"), "{e}");
        let e = point_config(&base, &["reversal_ramp".into()], &[Value::Float(0.0)]).unwrap_err();
        assert_eq!(e.key, "reversal_ramp");
        // A TOML axis value the configuration refuses names the value, not a line and column
        // of the sweep's own snippet.
        let e = point_config(&base, &["motor.rs".into()], &[Value::Float(1200.0)]).unwrap_err();
        assert_eq!(e.key, "motor.rs", "{e}");
        assert!(e.location.is_none(), "{e}");
        assert!(
            e.to_string().contains("the sweep's value motor.rs = 1200"),
            "{e}"
        );
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
}
