//! `fado-sim run` under hostile conditions: two writers on one directory, `kill -9` in the
//! middle of a write, a full disk; `compare` on a held directory. After each, every output is the previous whole file, the
//! new whole file, or absent with a clear error naming the path (exit code 3).

mod common;

use common::no_temporaries;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_fado-sim");
/// Columns of traces.csv.
const COLUMNS: usize = fado_sim::sim::TraceRow::COLUMNS.len();

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fado-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A config file running fig11 for `duration` s, every sample traced.
fn config(dir: &Path, duration: f64) -> PathBuf {
    let path = dir.join(format!("d{duration}.toml"));
    std::fs::write(
        &path,
        format!("[simulation]\nduration = {duration}\ndecimation = 1\n"),
    )
    .unwrap();
    path
}

fn run(cfg: &Path, out: &Path) -> Command {
    let mut c = Command::new(BIN);
    c.args(["run", "fig11", "--averaged", "--config"])
        .arg(cfg)
        .arg("--out")
        .arg(out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    c
}

/// The outputs of a finished run are whole and belong together: metrics.json parses and
/// says how long the run was, traces.csv has a header and one full row per sample of it.
fn check_whole_run(out: &Path) -> (f64, usize) {
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    let seconds = metrics["simulated_seconds"].as_f64().unwrap();
    let text = std::fs::read_to_string(out.join("traces.csv")).unwrap();
    assert!(text.ends_with('\n'));
    let mut lines = text.lines();
    assert_eq!(lines.next().unwrap().split(',').count(), COLUMNS);
    let mut rows = 0;
    for line in lines {
        assert_eq!(line.split(',').count(), COLUMNS, "cut or mixed row: {line}");
        rows += 1;
    }
    // Ts = 100 µs, decimation 1.
    assert_eq!(rows, (seconds / 100e-6).round() as usize);
    (seconds, rows)
}

/// The run went through (exit 0: criteria met, 1: not met; short runs miss fig11's).
fn ran(o: &Output) -> bool {
    matches!(o.status.code(), Some(0 | 1))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn a_second_run_into_the_same_directory_is_refused_and_the_first_completes() {
    let dir = scratch("concurrent");
    let out = dir.join("out");
    let long = config(&dir, 4.0);
    let first = run(&long, &out).spawn().unwrap();
    // Wait until the first run holds the directory (its lock file appears at once).
    let started = Instant::now();
    while !out.join(".fado.lock").exists() && started.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(5));
    }
    std::thread::sleep(Duration::from_millis(50));
    let second = run(&config(&dir, 0.05), &out).output().unwrap();
    assert_eq!(second.status.code(), Some(3), "{}", stderr(&second));
    let msg = stderr(&second);
    assert!(msg.contains(&out.display().to_string()), "{msg}");
    assert!(msg.contains("another fado-sim command"), "{msg}");
    let first = first.wait_with_output().unwrap();
    assert!(ran(&first), "{}", stderr(&first));
    assert_eq!(check_whole_run(&out).0, 4.0);
    assert!(no_temporaries(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_run_killed_mid_write_leaves_the_previous_run_whole() {
    let dir = scratch("kill");
    let out = dir.join("out");
    let done = run(&config(&dir, 0.2), &out).output().unwrap();
    assert!(ran(&done), "{}", stderr(&done));
    let before = (
        std::fs::read(out.join("metrics.json")).unwrap(),
        std::fs::read(out.join("traces.csv")).unwrap(),
    );
    // 6 s traced at every sample: ~60,000 rows streamed over ~0.5 s; killed mid-stream.
    let mut victim = run(&config(&dir, 6.0), &out).spawn().unwrap();
    let started = Instant::now();
    let tmp_written = || {
        std::fs::read_dir(&out).unwrap().any(|e| {
            let e = e.unwrap();
            e.file_name().to_string_lossy().contains("traces.csv.tmp-")
                && e.metadata().unwrap().len() > 1 << 20
        })
    };
    while !tmp_written() && started.elapsed() < Duration::from_secs(20) {
        std::thread::sleep(Duration::from_millis(2));
    }
    assert!(tmp_written(), "the run never started writing");
    victim.kill().unwrap(); // SIGKILL
    victim.wait().unwrap();
    assert_eq!(std::fs::read(out.join("metrics.json")).unwrap(), before.0);
    assert_eq!(std::fs::read(out.join("traces.csv")).unwrap(), before.1);
    check_whole_run(&out);
    // The next run takes the directory, clears the killed run's temporary file, replaces both.
    let again = run(&config(&dir, 0.1), &out).output().unwrap();
    assert!(ran(&again), "{}", stderr(&again));
    assert_eq!(check_whole_run(&out).0, 0.1);
    assert!(no_temporaries(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_full_disk_fails_with_the_path_and_exit_3_and_keeps_the_previous_run() {
    let dir = scratch("full");
    let out = dir.join("small");
    // A 2 MiB tmpfs.
    common::on_small_tmpfs(&out, "2m", || {
        // ~0.3 MB of traces fits.
        let fits = run(&config(&dir, 0.05), &out).output().unwrap();
        assert!(ran(&fits), "{}", stderr(&fits));
        let before = (
            std::fs::read(out.join("metrics.json")).unwrap(),
            std::fs::read(out.join("traces.csv")).unwrap(),
        );
        // ~6 MB does not.
        let started = Instant::now();
        let full = run(&config(&dir, 1.0), &out).output().unwrap();
        let msg = stderr(&full);
        assert_eq!(full.status.code(), Some(3), "{msg}");
        assert!(
            msg.contains(&out.join("traces.csv").display().to_string()),
            "{msg}"
        );
        assert!(msg.contains("No space left"), "{msg}");
        // The run stopped at the failed write instead of simulating on.
        assert!(started.elapsed() < Duration::from_secs(5));
        assert_eq!(std::fs::read(out.join("metrics.json")).unwrap(), before.0);
        assert_eq!(std::fs::read(out.join("traces.csv")).unwrap(), before.1);
        assert!(no_temporaries(&out));
    });
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_unwritable_output_directory_is_an_io_error_naming_it() {
    let dir = scratch("unwritable");
    let blocker = dir.join("file");
    std::fs::write(&blocker, b"not a directory").unwrap();
    let out = blocker.join("out");
    let o = run(&config(&dir, 0.01), &out).output().unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&out.display().to_string()),
        "{}",
        stderr(&o)
    );
    // A configuration error keeps exit code 2.
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[simulation]\nduraton = 1\n").unwrap();
    let o = run(&bad, &dir.join("o")).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn compare_reports_a_held_output_directory_before_it_runs() {
    // The directory is held by another command; the comparison's own configuration fails
    // only once the runs start (a negative duration): the lock is the error reported (exit 3,
    // naming the directory), so nothing ran.
    let dir = scratch("compare-held");
    let out = dir.join("out");
    let lock = fado_sim::output::DirLock::acquire(&out).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[simulation]\nduration = -1.0\n").unwrap();
    let compare = || {
        Command::new(BIN)
            .args([
                "compare",
                "--scenarios",
                "fig11",
                "--estimators",
                "fado",
                "--averaged",
            ])
            .arg("--config")
            .arg(&bad)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap()
    };
    let o = compare();
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&out.display().to_string()),
        "{}",
        stderr(&o)
    );
    drop(lock);
    // Free, the same command reaches the configuration's error (exit 2).
    assert_eq!(compare().status.code(), Some(2));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_long_run_keeps_its_memory_flat() {
    // Peak RSS of the whole process, read from /proc after the run (Linux only): a run ten
    // times longer must not need more than twice the memory (the trace goes to disk).
    if !Path::new("/proc/self/status").exists() {
        eprintln!("SKIPPED: no /proc");
        return;
    }
    let dir = scratch("rss");
    let peak = |duration: f64| -> u64 {
        // GNU time's %M: the peak resident set size in kB, on the last line of stderr.
        let o = Command::new("/usr/bin/time")
            .args(["-f", "%M", BIN, "run", "fig11", "--averaged", "--config"])
            .arg(config(&dir, duration))
            .arg("--out")
            .arg(dir.join("out"))
            .output();
        o.ok()
            .and_then(|o| {
                String::from_utf8_lossy(&o.stderr)
                    .lines()
                    .last()
                    .and_then(|l| l.trim().parse().ok())
            })
            .unwrap_or(0)
    };
    let short = peak(0.5);
    if short == 0 {
        eprintln!("SKIPPED: no `time` program to measure the peak RSS");
        std::fs::remove_dir_all(&dir).unwrap();
        return;
    }
    let long = peak(5.0);
    assert!(long <= 2 * short, "peak RSS {long} kB vs {short} kB");
    std::fs::remove_dir_all(&dir).unwrap();
}
