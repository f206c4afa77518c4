//! Running a sweep: the points in parallel on a capped thread pool, each finished one
//! appended to `sweep.csv` at once, an interrupted sweep resumed from it, the output
//! directory locked against a second sweep, a cancel flag for Ctrl-C.

use std::collections::BTreeMap;
use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::point::{PointResult, run_point_until};
use super::spec::SweepSpec;
use super::store::{csv_line, read_csv, write_csv};
use super::summary::Summary;
use crate::error::SimConfigError;
use crate::output::{AtomicFile, DirLock, OutputError};

/// How to run a sweep.
#[derive(Clone, Debug, Default)]
pub struct SweepOptions {
    /// Worker threads; 0 = all cores; capped at the cores there are ([`crate::threads`]).
    pub threads: usize,
    /// Once set (from another thread: Ctrl-C in Python), the points not started are skipped
    /// and those running stop within [`crate::sim::CANCEL_CHECK_SAMPLES`] samples; neither is
    /// recorded, so the sweep resumes where it stopped. [`run`] then returns
    /// [`SweepError::Cancelled`].
    pub cancel: Option<Arc<AtomicBool>>,
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
    /// Reading or writing the output directory, or another sweep holds it.
    Io(OutputError),
    /// The output directory holds a different sweep.
    Mismatch(String),
    /// The worker threads could not be started.
    Threads(String),
    /// Stopped by [`SweepOptions::cancel`]; the points finished are recorded.
    Cancelled,
}

impl std::fmt::Display for SweepError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SweepError::Config(e) => write!(f, "{e}"),
            SweepError::Io(e) => write!(f, "{e}"),
            SweepError::Mismatch(m) | SweepError::Threads(m) => f.write_str(m),
            SweepError::Cancelled => f.write_str("sweep interrupted"),
        }
    }
}

impl std::error::Error for SweepError {}

impl From<SimConfigError> for SweepError {
    fn from(e: SimConfigError) -> Self {
        SweepError::Config(e)
    }
}

impl From<OutputError> for SweepError {
    fn from(e: OutputError) -> Self {
        SweepError::Io(e)
    }
}

pub(crate) fn io(action: &'static str, path: &Path, e: impl Into<std::io::Error>) -> SweepError {
    SweepError::Io(OutputError::new(action, path, e.into()))
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
    let (lock, mut done, sink) = match &opts.out {
        Some(dir) => open_out(spec, dir, opts.fresh)?,
        None => (None, BTreeMap::new(), None),
    };
    let resumed = done.len();
    let todo: Vec<usize> = (0..spec.points.len())
        .filter(|k| !done.contains_key(k))
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(crate::threads::capped(opts.threads).0)
        .build()
        .map_err(|e| SweepError::Threads(format!("thread pool: {e}")))?;
    let write_error = Mutex::new(None);
    let finished = std::sync::atomic::AtomicUsize::new(resumed);
    let cancel = opts.cancel.as_deref();
    let new_rows: Vec<PointResult> = pool.install(|| {
        todo.par_iter()
            .with_max_len(1)
            .filter_map(|&k| {
                let r = run_point_until(
                    &spec.scenario,
                    &base,
                    &spec.axes,
                    &spec.points[k],
                    k,
                    cancel,
                )?;
                if let Some(sink) = &sink {
                    append(sink, &r, &write_error);
                }
                let n = finished.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                on_point(&r, n);
                Some(r)
            })
            .collect()
    });
    if let Some(e) = write_error.into_inner().unwrap_or(None) {
        return Err(e);
    }
    if cancel.is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed)) {
        // The finished points are in sweep.csv (appended and flushed one by one).
        return Err(SweepError::Cancelled);
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
        write_results(dir, &outcome)?;
    }
    drop(lock);
    Ok(outcome)
}

/// The CSV of a sweep appended to as its points finish.
type Sink = Mutex<(PathBuf, std::fs::File)>;

/// An output directory taken for a sweep: its lock, the points already finished, the CSV.
type Opened = (Option<DirLock>, BTreeMap<usize, PointResult>, Option<Sink>);

/// Takes DIR for a sweep: its lock, the points an earlier run of the same definition finished
/// (none with `fresh`), and DIR/sweep.csv rewritten with them, open for appending.
fn open_out(spec: &SweepSpec, dir: &Path, fresh: bool) -> Result<Opened, SweepError> {
    let lock = DirLock::acquire(dir)?;
    let done = prepare_resume(spec, dir, fresh)?;
    let csv_path = dir.join("sweep.csv");
    write_csv(&csv_path, spec, done.values())?;
    let file = OpenOptions::new()
        .append(true)
        .open(&csv_path)
        .map_err(|e| io("open", &csv_path, e))?;
    Ok((Some(lock), done, Some(Mutex::new((csv_path, file)))))
}

/// Appends the row of `r` to the CSV and flushes it; a failure is kept in `write_error`.
fn append(sink: &Sink, r: &PointResult, write_error: &Mutex<Option<SweepError>>) {
    let mut guard = sink.lock().unwrap_or_else(|p| p.into_inner());
    let (path, file) = &mut *guard;
    let line = csv_line(r);
    if let Err(e) = file.write_all(line.as_bytes()).and_then(|_| file.flush()) {
        *write_error.lock().unwrap_or_else(|p| p.into_inner()) = Some(io("write", path, e));
    }
}

/// DIR/sweep.csv in index order, DIR/summary.md and DIR/summary.json.
fn write_results(dir: &Path, outcome: &SweepOutcome) -> Result<(), SweepError> {
    write_csv(&dir.join("sweep.csv"), &outcome.spec, outcome.rows.iter())?;
    let json_path = dir.join("summary.json");
    let json =
        serde_json::to_string_pretty(&outcome.summary).map_err(|e| io("write", &json_path, e))?;
    AtomicFile::write(
        &dir.join("summary.md"),
        outcome.summary.to_markdown().as_bytes(),
    )?;
    AtomicFile::write(&json_path, json.as_bytes())?;
    Ok(())
}

#[derive(Serialize, Deserialize)]
struct Sidecar {
    fingerprint: String,
    spec: SweepSpec,
}

/// Reads the finished points of an earlier run of the same sweep in `dir` and writes
/// `sweep.json` for this one. A `sweep.csv` without its `sweep.json` cannot be told apart
/// from another sweep's rows: refused unless `fresh`.
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
        let text = std::fs::read_to_string(&json_path).map_err(|e| io("read", &json_path, e))?;
        let old: Sidecar = serde_json::from_str(&text).map_err(|e| io("parse", &json_path, e))?;
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
    } else if !fresh && csv_path.exists() {
        return Err(SweepError::Mismatch(format!(
            "{} holds a sweep.csv without its definition (sweep.json), so its rows cannot be \
             matched to this sweep; use another output directory or start afresh (`--fresh`, \
             `fresh=True`) to discard them",
            dir.display()
        )));
    }
    let sidecar = Sidecar {
        fingerprint,
        spec: spec.clone(),
    };
    let text = serde_json::to_string_pretty(&sidecar).map_err(|e| io("write", &json_path, e))?;
    AtomicFile::write(&json_path, text.as_bytes())?;
    Ok(done)
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicUsize, Ordering};

    use super::*;
    use crate::sweep::Status;
    use crate::sweep::test_support::{floats, short, tmp_dir};

    #[test]
    fn failed_and_diverged_points_are_recorded_and_the_sweep_goes_on() {
        // L̂q five times Lq makes a 700 Hz current loop unstable: its current overshoots the
        // current limit (0.8 of the rated current here) and trips at 0.9, where the matched
        // model's run stays within 0.4.
        let mut spec = short(SweepSpec::grid(
            "fig11",
            vec![
                ("rs_error".into(), floats(&[-2.0, 0.0])),
                ("lq_error".into(), floats(&[0.0, 4.0])),
            ],
        ));
        spec.config_toml = Some(format!(
            "{}[controller.current]\nbandwidth_hz = 700.0\nlimit_ratio = 0.8\n[controller.protection]\ntrip_current_ratio = 0.9\n",
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
            cancel: None,
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
    fn a_sweep_csv_without_its_definition_is_refused_unless_fresh() {
        let dir = tmp_dir("orphan");
        let spec = short(SweepSpec::grid(
            "fig11",
            vec![("rs_error".into(), floats(&[0.0]))],
        ));
        let opts = SweepOptions {
            threads: 1,
            out: Some(dir.clone()),
            ..Default::default()
        };
        run(&spec, &opts, &|_, _| {}).unwrap();
        std::fs::remove_file(dir.join("sweep.json")).unwrap();
        let other = short(SweepSpec::grid(
            "fig11",
            vec![("lq_error".into(), floats(&[0.1]))],
        ));
        let e = run(&other, &opts, &|_, _| {}).unwrap_err();
        assert!(matches!(e, SweepError::Mismatch(_)), "{e}");
        assert!(e.to_string().contains("without its definition"), "{e}");
        // The rows are still there; --fresh discards them.
        assert_eq!(
            std::fs::read_to_string(dir.join("sweep.csv"))
                .unwrap()
                .lines()
                .count(),
            2
        );
        let fresh = SweepOptions {
            fresh: true,
            ..opts
        };
        assert_eq!(run(&other, &fresh, &|_, _| {}).unwrap().ran, 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_second_sweep_on_a_locked_directory_is_refused_and_a_cancelled_one_resumes() {
        let dir = tmp_dir("locked");
        let spec = short(SweepSpec::grid(
            "fig11",
            vec![("rs_error".into(), floats(&[0.0, 0.01, 0.02]))],
        ));
        let held = DirLock::acquire(&dir).unwrap();
        let cancel = Arc::new(AtomicBool::new(false));
        let opts = SweepOptions {
            threads: 1,
            out: Some(dir.clone()),
            fresh: false,
            cancel: Some(cancel.clone()),
        };
        let e = run(&spec, &opts, &|_, _| {}).unwrap_err();
        assert!(matches!(&e, SweepError::Io(o) if o.is_busy()), "{e}");
        drop(held);
        // Cancelled after the first point: it is recorded, the others are not.
        let e = run(&spec, &opts, &|_, _| {
            cancel.store(true, std::sync::atomic::Ordering::Relaxed)
        })
        .unwrap_err();
        assert!(matches!(e, SweepError::Cancelled), "{e}");
        cancel.store(false, std::sync::atomic::Ordering::Relaxed);
        let resumed = run(&spec, &opts, &|_, _| {}).unwrap();
        assert_eq!((resumed.resumed, resumed.ran), (1, 2));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
