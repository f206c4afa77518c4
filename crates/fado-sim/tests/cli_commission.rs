//! `fado-sim commission` under hostile conditions, as `cli_outputs.rs` does for `run`: two
//! commissions into one directory, `kill -9` at any moment, a full disk, a closed stdout.
//! After each, the directory holds the previous whole results or the new whole results
//! (traces.csv, identified.toml and metrics.json of one run), never a mix; I/O errors name the
//! path and exit with code 3.

mod common;

use common::no_temporaries;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_fado-sim");

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fado-commission-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The paper's motor on a 40 kHz inverter: a commissioning of about half a second of wall
/// time (four times the samples of the 5 kHz preset), long enough to be caught running.
fn slow_config(dir: &Path) -> PathBuf {
    let text = fado_sim::presets::find("paper").unwrap().toml.replace(
        "switching_frequency = 5000.0",
        "switching_frequency = 40000.0",
    );
    assert!(text.contains("40000.0"));
    let path = dir.join("slow.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn commission(cfg: &Path, out: &Path, seed: u64) -> Command {
    let mut c = Command::new(BIN);
    c.args(["commission", "--config"])
        .arg(cfg)
        .arg("--out")
        .arg(out)
        .args(["--seed", &seed.to_string()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    c
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The result files of a directory, metrics.json without its wall-clock time (the one value
/// that differs between two runs of one configuration).
fn results(out: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut files = BTreeMap::new();
    for name in ["traces.csv", "identified.toml", "metrics.json"] {
        if let Ok(mut bytes) = std::fs::read(out.join(name)) {
            if name == "metrics.json" {
                let mut v: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
                v.as_object_mut().unwrap().remove("wall_seconds");
                bytes = v.to_string().into_bytes();
            }
            files.insert(name.to_owned(), bytes);
        }
    }
    files
}

/// A whole, passed commissioning's results: the three files, metrics.json passed.
fn assert_whole(files: &BTreeMap<String, Vec<u8>>) {
    assert_eq!(files.len(), 3, "{:?}", files.keys());
    let metrics: serde_json::Value = serde_json::from_slice(&files["metrics.json"]).unwrap();
    assert_eq!(metrics["passed"], true);
    let traces = String::from_utf8_lossy(&files["traces.csv"]);
    assert!(traces.ends_with('\n'));
    let columns = traces.lines().next().unwrap().split(',').count();
    assert!(traces.lines().all(|l| l.split(',').count() == columns));
}

#[test]
fn a_second_commission_into_the_same_directory_is_refused_and_the_first_completes() {
    let dir = scratch("concurrent");
    let out = dir.join("out");
    let cfg = slow_config(&dir);
    let first = commission(&cfg, &out, 1).spawn().unwrap();
    let started = Instant::now();
    while !out.join(".fado.lock").exists() && started.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(2));
    }
    let second = commission(&cfg, &out, 2).output().unwrap();
    let first = first.wait_with_output().unwrap();
    assert_eq!(second.status.code(), Some(3), "{}", stderr(&second));
    let msg = stderr(&second);
    assert!(msg.contains(&out.display().to_string()), "{msg}");
    assert!(msg.contains("another fado-sim"), "{msg}");
    assert_eq!(first.status.code(), Some(0), "{}", stderr(&first));
    let files = results(&out);
    assert_whole(&files);
    let metrics: serde_json::Value = serde_json::from_slice(&files["metrics.json"]).unwrap();
    assert_eq!(metrics["seed"], 1);
    assert!(no_temporaries(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_commission_killed_at_any_moment_leaves_whole_results() {
    let dir = scratch("kill");
    let cfg = slow_config(&dir);
    // The two possible whole states: the previous run's (seed 1) and the new run's (seed 2).
    let (old, new) = (dir.join("old"), dir.join("new"));
    for (out, seed) in [(&old, 1), (&new, 2)] {
        let o = commission(&cfg, out, seed).output().unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let (old_files, new_files) = (results(&old), results(&new));
    assert_whole(&old_files);
    assert_whole(&new_files);
    assert_ne!(old_files["traces.csv"], new_files["traces.csv"]);
    let out = dir.join("out");
    let o = commission(&cfg, &out, 1).output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let wall = {
        let t = Instant::now();
        commission(&cfg, &dir.join("timing"), 2).output().unwrap();
        t.elapsed()
    };
    // Kills spread over the whole run, its writes and renames included.
    let mut seen_new = false;
    for k in 0..12 {
        let mut victim = commission(&cfg, &out, 2).spawn().unwrap();
        std::thread::sleep(wall.mul_f64(k as f64 / 8.0));
        victim.kill().unwrap(); // SIGKILL (or nothing, when it already exited)
        victim.wait().unwrap();
        let now = results(&out);
        if now.contains_key("metrics.json") {
            // metrics.json is renamed last: where it is, its run's files are whole.
            assert!(
                now == old_files || now == new_files,
                "mixed results after kill {k}"
            );
        }
        seen_new |= now == new_files;
        if now == new_files {
            // Back to the previous results for the next kill.
            let o = commission(&cfg, &out, 1).output().unwrap();
            assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
            assert_eq!(results(&out), old_files);
        }
    }
    // Under load the last kills may still come before the end; say where they came.
    eprintln!("a kill came after the run's renames: {seen_new}");
    // The next run takes the directory and clears the killed runs' temporary files.
    let o = commission(&cfg, &out, 1).output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(results(&out), old_files);
    assert!(no_temporaries(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_full_disk_fails_with_the_path_and_exit_3_and_keeps_the_previous_results() {
    let dir = scratch("full");
    let out = dir.join("small");
    // A tmpfs with room for one run's results (1.0 MB) but not for a second beside it.
    let cfg = dir.join("paper.toml");
    std::fs::write(&cfg, fado_sim::presets::find("paper").unwrap().toml).unwrap();
    common::on_small_tmpfs(&out, "1500k", || {
        let first = commission(&cfg, &out, 1).output().unwrap();
        assert_eq!(first.status.code(), Some(0), "{}", stderr(&first));
        let before = results(&out);
        assert_whole(&before);
        let full = commission(&cfg, &out, 2).output().unwrap();
        let msg = stderr(&full);
        assert_eq!(full.status.code(), Some(3), "{msg}");
        assert!(msg.contains(&out.display().to_string()), "{msg}");
        assert!(msg.contains("No space left"), "{msg}");
        assert_eq!(results(&out), before);
        assert!(no_temporaries(&out));
    });
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs `args` with its stdout a pipe whose reading end is closed at once (`… | true`).
fn with_closed_stdout(args: &[&str]) -> Output {
    let mut child = Command::new(BIN)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    child.wait_with_output().unwrap()
}

#[test]
fn no_command_panics_on_a_closed_or_full_stdout() {
    let dir = scratch("stdout");
    let out = dir.join("c");
    let o = with_closed_stdout(&[
        "commission",
        "--motor",
        "paper",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
    // Its results are written whole before anything is printed.
    assert_whole(&results(&out));
    let short = dir.join("short.toml");
    std::fs::write(&short, "[simulation]\nduration = 0.05\n").unwrap();
    let short = short.to_str().unwrap();
    let run_out = dir.join("r");
    let sweep_out = dir.join("s");
    for args in [
        vec!["motors"],
        vec!["list"],
        vec![
            "run",
            "fig11",
            "--averaged",
            "--config",
            short,
            "--out",
            run_out.to_str().unwrap(),
        ],
        vec!["run", "fig11", "--config", short, "--dump-config"],
        vec![
            "sweep",
            "fig11",
            "--averaged",
            "--config",
            short,
            "--axis",
            "rs_error=0,0.1",
            "--threads",
            "1",
            "--out",
            sweep_out.to_str().unwrap(),
        ],
    ] {
        let o = with_closed_stdout(&args);
        // 0 or 1 (a 0.05 s fig11 misses its criteria), never a panic's 101.
        assert!(
            matches!(o.status.code(), Some(0 | 1)),
            "{args:?}: {}",
            stderr(&o)
        );
        assert!(!stderr(&o).contains("panicked"), "{args:?}: {}", stderr(&o));
    }
    assert!(run_out.join("metrics.json").exists());
    assert!(sweep_out.join("summary.json").exists());
    // A full stdout (a full disk) is an I/O error naming stdout, exit 3, after the files.
    if let Ok(full) = std::fs::File::create("/dev/full") {
        let out = dir.join("c-full");
        let o = Command::new(BIN)
            .args([
                "commission",
                "--motor",
                "paper",
                "--out",
                out.to_str().unwrap(),
            ])
            .stdout(full)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
        assert!(stderr(&o).contains("stdout"), "{}", stderr(&o));
        assert_whole(&results(&out));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn commission_io_errors_name_the_path_with_exit_3() {
    let dir = scratch("unwritable");
    let blocker = dir.join("file");
    std::fs::write(&blocker, b"not a directory").unwrap();
    let out = blocker.join("out");
    let o = Command::new(BIN)
        .args(["commission", "--motor", "paper", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&out.display().to_string()),
        "{}",
        stderr(&o)
    );
    let missing = dir.join("missing.toml");
    let o = Command::new(BIN)
        .args(["commission", "--config"])
        .arg(&missing)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&missing.display().to_string()),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A saturated machine's identified model is also written as a flux map beside
/// identified.toml, which names it by a relative path: the directory moved elsewhere still
/// resolves it (`run --dump-config` from another working directory). A machine without
/// saturation commissioned into the same directory leaves no map behind.
#[test]
fn the_identified_flux_map_sits_beside_identified_toml_and_goes_with_it() {
    use fado_sim::identified_map::IDENTIFIED_MAP_FILE;
    let dir = scratch("map");
    let out = dir.join("out");
    let cfg = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/ipmsm-test-saturated.toml");
    let o = commission(&cfg, &out, 1).output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let csv = std::fs::read_to_string(out.join(IDENTIFIED_MAP_FILE)).unwrap();
    let header = csv.lines().find(|l| !l.starts_with('#')).unwrap();
    assert_eq!(header, "i_d,i_q,psi_d,psi_q");
    let doc = std::fs::read_to_string(out.join("identified.toml")).unwrap();
    assert!(
        doc.contains(&format!("flux_map = \"{IDENTIFIED_MAP_FILE}\"")),
        "{doc}"
    );
    assert!(doc.contains("#   [model.saturation]"), "{doc}");
    assert!(no_temporaries(&out));
    let moved = dir.join("moved");
    std::fs::rename(&out, &moved).unwrap();
    let dump = Command::new(BIN)
        .args(["run", "reversal", "--dump-config", "--config"])
        .arg(moved.join("identified.toml"))
        .current_dir(std::env::temp_dir())
        .output()
        .unwrap();
    assert_eq!(dump.status.code(), Some(0), "{}", stderr(&dump));
    let text = String::from_utf8_lossy(&dump.stdout);
    let resolved = moved.join(IDENTIFIED_MAP_FILE).display().to_string();
    assert!(text.contains(&resolved), "{text}");
    let linear = dir.join("paper.toml");
    std::fs::write(&linear, fado_sim::presets::find("paper").unwrap().toml).unwrap();
    let o = commission(&linear, &moved, 1).output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!moved.join(IDENTIFIED_MAP_FILE).exists());
    let doc = std::fs::read_to_string(moved.join("identified.toml")).unwrap();
    assert!(!doc.contains("flux_map"), "{doc}");
    std::fs::remove_dir_all(&dir).unwrap();
}
