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

/// Runs `fado-sim run custom` on `config` (a file of the repository's `examples/experiments`
/// or a text written to a temporary file) and returns (exit code, metrics.json).
fn run_custom(name: &str, config: &std::path::Path) -> (Option<i32>, serde_json::Value) {
    let dir = tmp_dir(name);
    let out = bin()
        .args(["run", "custom", "--config"])
        .arg(config)
        .arg("--out")
        .arg(&dir)
        .output()
        .unwrap();
    let json =
        serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).unwrap()).unwrap();
    (out.status.code(), json)
}

fn example(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/experiments")
        .join(name)
}

#[test]
fn custom_runs_a_propeller_and_a_hoist_judged_by_their_own_criteria() {
    for file in ["propeller.toml", "hoist.toml"] {
        let (code, json) = run_custom(file, &example(file));
        assert_eq!(code, Some(0), "{file}: {json}");
        let names: Vec<&str> = json["checks"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["name"].as_str().unwrap())
            .collect();
        // Exactly the three criteria the file writes, in the order of `[criteria]`'s keys.
        assert_eq!(
            names,
            [
                "max |θ − θ̂| (rad)",
                "max speed error / rated speed",
                "tripped"
            ],
            "{file}"
        );
        assert!(json["max_angle_error"].as_f64().unwrap() < 0.25, "{file}");
        // A stiff source: the bus is the source's 311 V throughout.
        assert_eq!(json["max_dc_voltage"].as_f64(), Some(311.0));
        assert_eq!(json["min_dc_voltage"].as_f64(), Some(311.0));
    }
}

#[test]
fn custom_without_criteria_reports_and_passes_and_a_missed_criterion_fails() {
    let dir = tmp_dir("custom-none");
    // 2,000 r/min asked of the paper's motor in 0.2 s under a large fan load: the speed is
    // far from the reference, yet with no criterion written the run passes.
    let text = "[speed_reference]\npoints = [[0.0, 0.0], [0.7, 0.0], [0.9, 2000.0]]\n\
                [load]\nmode = \"quadratic\"\ncoefficient = 2e-3\n";
    let cfg = dir.join("none.toml");
    std::fs::write(&cfg, text).unwrap();
    let (code, json) = run_custom("custom-none-run", &cfg);
    assert_eq!(code, Some(0), "{json}");
    assert_eq!(json["checks"].as_array().unwrap().len(), 0);
    assert!(
        json["max_speed_error_rpm"].as_f64().unwrap() > 300.0,
        "{json}"
    );
    // Runs to 1 s after the last breakpoint.
    assert!((json["simulated_seconds"].as_f64().unwrap() - 1.9).abs() < 1e-9);
    let judged = dir.join("judged.toml");
    std::fs::write(
        &judged,
        format!("{text}[criteria]\nmax_speed_error_ratio = 0.02\n"),
    )
    .unwrap();
    let (code, json) = run_custom("custom-judged-run", &judged);
    assert_eq!(code, Some(1), "{json}");
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[criteria]\nmax_angle_eror = 0.25\n").unwrap();
    let out = bin()
        .args(["run", "custom", "--config"])
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("criteria.max_angle_eror"), "{err}");
}
