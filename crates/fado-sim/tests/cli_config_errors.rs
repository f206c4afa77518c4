//! The CLI names the TOML key and its line and column in the `--config` file for syntax,
//! type, unknown-key and validation errors, and exits with status 2.

use std::path::PathBuf;
use std::process::Command;

/// Writes `text` to a fresh file and runs `fado-sim run fig11 --config FILE --dump-config`
/// (no simulation). Returns (exit code, stderr, file path).
fn run_with(name: &str, text: &str) -> (Option<i32>, String, PathBuf) {
    let dir = std::env::temp_dir().join(format!("fado-sim-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_fado-sim"))
        .args(["run", "fig11", "--dump-config", "--config"])
        .arg(&path)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        path,
    )
}

#[test]
fn validation_error_names_file_line_column_and_key() {
    let text = "# my motor\n[simulation]\nduration = 1.0\n\n[motor]\nlq = 2.63e-3\nrs = -1\n";
    let (code, stderr, path) = run_with("bad-rs.toml", text);
    assert_eq!(code, Some(2), "{stderr}");
    assert_eq!(
        stderr.trim_end(),
        format!(
            "error: {}:7:6: `motor.rs`: must be > 0, got -1",
            path.display()
        )
    );
}

#[test]
fn unknown_key_and_wrong_type_name_file_line_and_key() {
    let (code, stderr, path) = run_with("unknown.toml", "[inverter]\n\n  dead_tme = 1e-6\n");
    assert_eq!(code, Some(2), "{stderr}");
    let prefix = format!("error: {}:3:3: `inverter.dead_tme`: ", path.display());
    assert!(stderr.starts_with(&prefix), "{stderr}");
    assert!(stderr.contains("unknown field"), "{stderr}");
    assert!(stderr.contains("did you mean `dead_time`?"), "{stderr}");
    // A name unlike every key of its table gets the list alone.
    let (code, stderr, _) = run_with(
        "unlike.toml",
        "[inverter]
gear_ratio = 3
",
    );
    assert_eq!(code, Some(2), "{stderr}");
    assert!(!stderr.contains("did you mean"), "{stderr}");

    let (code, stderr, path) = run_with(
        "type.toml",
        "[estimator.disturbance_feedback]\nk_df = \"half\"\n",
    );
    assert_eq!(code, Some(2), "{stderr}");
    let prefix = format!(
        "error: {}:2:8: `estimator.disturbance_feedback.k_df`: ",
        path.display()
    );
    assert!(stderr.starts_with(&prefix), "{stderr}");
}

#[test]
fn core_validation_and_syntax_errors_are_located() {
    // A tracker bandwidth above what 10 kHz sampling allows (Jury's test in fado-core).
    let (code, stderr, path) = run_with(
        "bw.toml",
        "[estimator.tracker]\nt2s1_bandwidth_hz = 4000.0\n",
    );
    assert_eq!(code, Some(2), "{stderr}");
    let prefix = format!(
        "error: {}:2:21: `estimator.tracker.t2s1_bandwidth_hz`: ",
        path.display()
    );
    assert!(stderr.starts_with(&prefix), "{stderr}");

    let (code, stderr, path) = run_with("syntax.toml", "[motor]\nrs = 0.3\nlq = = 2\n");
    assert_eq!(code, Some(2), "{stderr}");
    let prefix = format!("error: {}:3:", path.display());
    assert!(stderr.starts_with(&prefix), "{stderr}");
}

#[test]
fn a_good_file_is_accepted() {
    // A whole motor: its circuit and ratings (the rest is derived from the ratings).
    let (code, stderr, _) = run_with(
        "good.toml",
        "[motor]\nrs = 0.3\nld = 2.63e-3\nlq = 2.63e-3\nflux_linkage = 0.088\npole_pairs = 4\n\
         rated_current = 21.78\nrated_speed_rpm = 1500.0\nrated_torque = 11.5\n",
    );
    assert_eq!(code, Some(0), "{stderr}");
    // Part of a motor is not a motor: the missing keys are named, none taken from the paper's.
    let (code, stderr, _) = run_with("partial.toml", "[motor]\nrs = 0.3\n");
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stderr.contains("`ld`, `lq`, `flux_linkage`, `pole_pairs`, `rated_current`"),
        "{stderr}"
    );
}

#[test]
fn dump_config_prints_the_plausibility_warnings_on_stderr() {
    // Swapped inductances on the paper's motor: a warning, shown before the TOML is printed
    // (the check a user runs before a run).
    let text = "[motor]\nrs = 0.327\nld = 5e-3\nlq = 2.63e-3\nflux_linkage = 0.088\n\
                pole_pairs = 4\nrated_current = 21.78\nrated_speed_rpm = 1500.0\n\
                rated_torque = 11.5\n";
    let (code, stderr, _) = run_with("swapped.toml", text);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(
        stderr.contains("warning:") && stderr.contains("swapped"),
        "{stderr}"
    );
}

#[test]
fn a_key_in_the_wrong_table_names_the_table_it_belongs_to() {
    // `switching_frequency` is the inverter's, not the motor's.
    let (code, stderr, path) = run_with(
        "wrong-table.toml",
        "[motor]\nswitching_frequency = 20000.0\n",
    );
    assert_eq!(code, Some(2), "{stderr}");
    let prefix = format!(
        "error: {}:2:1: `motor.switching_frequency`: ",
        path.display()
    );
    assert!(stderr.starts_with(&prefix), "{stderr}");
    assert!(
        stderr.contains("`switching_frequency` is a key of [inverter]"),
        "{stderr}"
    );
}

#[test]
fn a_key_outside_its_table_names_the_table_that_holds_it() {
    // `switching_frequency = 20e3` above every table header: a key of [inverter].
    let (code, stderr, path) = run_with("top.toml", "switching_frequency = 20e3\n");
    assert_eq!(code, Some(2), "{stderr}");
    let prefix = format!("error: {}:1:1: `switching_frequency`: ", path.display());
    assert!(stderr.starts_with(&prefix), "{stderr}");
    assert!(
        stderr.contains("`switching_frequency` is a key of [inverter]: write it in its table"),
        "{stderr}"
    );
    // A key no table holds gets the list of tables alone.
    let (code, stderr, _) = run_with("top-unknown.toml", "gear_ratio = 3\n");
    assert_eq!(code, Some(2), "{stderr}");
    assert!(!stderr.contains("is a key of"), "{stderr}");
}
