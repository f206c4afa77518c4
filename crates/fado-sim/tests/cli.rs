//! The `fado-sim` command line: list, run (metrics.json + traces.csv), dump-config, errors.

use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_fado-sim"))
}

fn tmp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("fado-sim-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn list_names_the_five_scenarios() {
    let out = bin().arg("list").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    for s in ["fig8", "fig9", "fig10", "fig11", "fig12"] {
        assert!(text.contains(s), "{s} missing from:\n{text}");
    }
}

#[test]
fn run_writes_metrics_json_and_traces_csv() {
    let dir = tmp_dir("run");
    let cfg = dir.join("short.toml");
    std::fs::write(&cfg, "[simulation]\nduration = 0.3\ndecimation = 100\n").unwrap();
    let out = bin()
        .args(["run", "fig11", "--averaged", "--config"])
        .arg(&cfg)
        .arg("--out")
        .arg(&dir)
        .output()
        .unwrap();
    // A 0.3 s fig11 never reaches zero speed under load: the criteria fail (exit 1), but the
    // files are written.
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).unwrap()).unwrap();
    for key in [
        "scenario",
        "passed",
        "max_angle_error",
        "rms_angle_error",
        "max_angle_error_zero_speed",
        "rms_angle_error_zero_speed",
        "max_speed_error_rpm",
        "tripped",
        "simulated_seconds",
        "wall_seconds",
    ] {
        assert!(json.get(key).is_some(), "metrics.json lacks {key}");
    }
    assert_eq!(json["scenario"], "fig11");
    assert!((json["simulated_seconds"].as_f64().unwrap() - 0.3).abs() < 1e-9);
    let csv = std::fs::read_to_string(dir.join("traces.csv")).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap();
    for col in [
        "time",
        "theta",
        "theta_hat",
        "speed_rpm",
        "i_d_ref",
        "lambda1_alpha",
        "dist_beta",
        "flag_limit",
    ] {
        assert!(
            header.split(',').any(|h| h == col),
            "traces.csv lacks {col}: {header}"
        );
    }
    assert_eq!(lines.count(), 30, "0.3 s at 10 kHz, one row in 100");
}

#[test]
fn dump_config_round_trips_and_bad_keys_are_named() {
    let out = bin()
        .args(["run", "fig9", "--dump-config"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let cfg = fado_sim::SimConfig::from_toml(&text).unwrap();
    assert_eq!(cfg, fado_sim::scenario_config("fig9", None, false).unwrap());

    let dir = tmp_dir("bad");
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[inverter]\ndead_tme = 1e-6\n").unwrap();
    let out = bin()
        .args(["run", "fig11", "--config"])
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("inverter.dead_tme"), "{err}");
    std::fs::write(&bad, "[motor]\nrs = -1.0\n").unwrap();
    let out = bin()
        .args(["run", "fig11", "--config"])
        .arg(&bad)
        .output()
        .unwrap();
    assert!(String::from_utf8(out.stderr).unwrap().contains("motor.rs"));
}

#[test]
fn sweep_runs_one_scenario_per_value_and_writes_a_csv() {
    let dir = tmp_dir("sweep");
    let cfg = dir.join("short.toml");
    std::fs::write(&cfg, "[simulation]\nduration = 0.2\n").unwrap();
    // `--set` is the old name of `--axis`.
    let sweep = |flag: &str| {
        bin()
            .args([
                "sweep",
                "fig11",
                "--averaged",
                flag,
                "mismatch.rs_ratio=0.9,1.0,1.1",
            ])
            .arg("--config")
            .arg(&cfg)
            .arg("--out")
            .arg(&dir)
            .output()
            .unwrap()
    };
    let out = sweep("--set");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let lines: Vec<_> = csv.lines().collect();
    assert_eq!(lines.len(), 4, "{csv}");
    assert!(lines[0].starts_with("point,mismatch.rs_ratio,status,passed"));
    assert!(lines[1].starts_with("0,0.9,ok,") && lines[3].starts_with("2,1.1,ok,"));
    assert!(dir.join("summary.json").exists() && dir.join("summary.md").exists());
    // Again on the same directory: everything is finished, nothing runs.
    let again = sweep("--axis");
    assert!(String::from_utf8_lossy(&again.stdout).contains("0 points run, 3 resumed"));
    let bad = bin()
        .args(["sweep", "fig11", "--set", "mismatch.rs_rato=1.0"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("mismatch.rs_rato"));
}

#[test]
fn compare_writes_json_and_markdown() {
    let dir = tmp_dir("compare");
    let cfg = dir.join("short.toml");
    std::fs::write(&cfg, "[simulation]\nduration = 2.7\n").unwrap();
    let out = bin()
        .args([
            "compare",
            "--scenarios",
            "steady300",
            "--estimators",
            "fado,ortega",
            "--averaged",
            "--config",
        ])
        .arg(&cfg)
        .arg("--out")
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let md = std::fs::read_to_string(dir.join("compare.md")).unwrap();
    assert!(md.contains("| steady300 | fado |") && md.contains("| steady300 | ortega |"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("compare.json")).unwrap()).unwrap();
    assert_eq!(json["rows"].as_array().unwrap().len(), 2);
    assert_eq!(json["summary"][1]["estimator"], "ortega");
    let bad = bin()
        .args(["compare", "--estimators", "kalman", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("kalman"));
}
