//! Inputs a user gives by slip, through the CLI: each gets an error or a warning at the
//! FILE:LINE:COLUMN of the key it blames, naming the likely cause, or runs correctly.
//! (`docs/guide/your-motor.md` describes the keys; `fado_core::machine_checks` the checks.)

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// A fresh scratch directory for `name`.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fado-slips-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `fado-sim run reversal --dump-config --config FILE` (no simulation): (exit code, stderr).
fn dump(path: &Path) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_fado-sim"))
        .args(["run", "reversal", "--dump-config", "--config"])
        .arg(path)
        .stdout(Stdio::null())
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Writes `text` as `name` in a scratch directory and dumps it.
fn dump_text(name: &str, text: &str) -> (Option<i32>, String, PathBuf) {
    let dir = scratch(name);
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let (code, err) = dump(&path);
    (code, err, path)
}

/// The 14-pole outrunner of `examples/motors/my-outrunner.toml` (Kv 100 r/min/V).
const OUTRUNNER: &str = "[motor]\nrs = 0.06\nld = 30e-6\nlq = 30e-6\nflux_linkage = 7.88e-3\n\
                         pole_pairs = 7\ninertia = 5e-4\nviscous_friction = 1.2e-4\n\
                         rated_current = 28.3\nrated_speed_rpm = 1800.0\nrated_torque = 2.34\n\
                         \n[inverter]\ndc_voltage = 24.0\nswitching_frequency = 20000.0\n";

#[test]
fn a_line_to_line_flux_on_a_strongly_salient_ipm_is_a_warning_at_its_line() {
    // motors/ipmsm-gem-50k.toml with λf × √3 (0.066 → 0.1143 Wb): 0.79 × the MTPA torque.
    let preset = include_str!("../../../motors/ipmsm-gem-50k.toml");
    let text = preset.replace("flux_linkage = 0.066 ", "flux_linkage = 0.1143 ");
    assert_ne!(text, preset);
    let line = text
        .lines()
        .position(|l| l.starts_with("flux_linkage"))
        .unwrap()
        + 1;
    let (code, err, path) = dump_text("gem-ll", &text);
    assert_eq!(code, Some(0), "{err}");
    let at = format!("{}:{line}:16: warning: ", path.display());
    assert!(err.contains(&at), "{at}\n{err}");
    assert!(err.contains("line-to-line"), "{err}");
    // The preset itself: no warning.
    let (code, err, _) = dump_text("gem", preset);
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("warning"), "{err}");
}

#[test]
fn a_kv_or_kt_key_is_pointed_to_the_datasheet_keys_and_kv_is_converted() {
    let text = OUTRUNNER.replace("flux_linkage = 7.88e-3", "Kv = 100.0");
    let (code, err, path) = dump_text("kv", &text);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.starts_with(&format!("error: {}:5:1: `motor.Kv`", path.display())),
        "{err}"
    );
    assert!(err.contains("`kv_rpm_per_volt`"), "{err}");
    // Given as the datasheet key: λf = 60/(2π·√3·p·Kv) = 7.876 mWb, printed with its rule.
    let text = OUTRUNNER
        .replace("flux_linkage = 7.88e-3", "kv_rpm_per_volt = 100.0")
        .replace("inertia = 5e-4", "inertia_kg_cm2 = 5.0");
    let dir = scratch("kv-ok");
    let path = dir.join("kv-ok.toml");
    std::fs::write(&path, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_fado-sim"))
        .args(["run", "reversal", "--dump-config", "--config"])
        .arg(&path)
        .output()
        .unwrap();
    let dumped = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{dumped}");
    let value = |key: &str| -> f64 {
        let line = dumped
            .lines()
            .find(|l| l.starts_with(&format!("{key} = ")))
            .unwrap_or_else(|| panic!("{key}: {dumped}"));
        line.split('=')
            .nth(1)
            .unwrap()
            .split('#')
            .next()
            .unwrap()
            .trim()
            .parse()
            .unwrap()
    };
    assert!((value("flux_linkage") - 7.876e-3).abs() < 1e-6);
    assert!((value("inertia") - 5e-4).abs() < 1e-12);
    assert!(dumped.contains("from kv_rpm_per_volt"), "{dumped}");
    assert!(dumped.contains("from inertia_kg_cm2"), "{dumped}");
    // No torque warning: Kv converted as the docs state agrees with the rated torque.
    assert!(!String::from_utf8_lossy(&out.stderr).contains("warning"));
}

#[test]
fn a_decimal_comma_and_a_key_given_twice_are_named() {
    let (code, err, path) = dump_text("comma", &OUTRUNNER.replace("rs = 0.06", "rs = 0,06"));
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(&format!("{}:2:7:", path.display())), "{err}");
    assert!(err.contains("decimal comma"), "{err}");
    let text = OUTRUNNER.replace("pole_pairs = 7\n", "pole_pairs = 7\npole_pairs = 14\n");
    let (code, err, path) = dump_text("twice", &text);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(&format!("{}:7:1:", path.display())), "{err}");
    assert!(err.contains("`pole_pairs` is given twice"), "{err}");
}

#[test]
fn an_empty_config_is_refused_and_one_without_a_motor_says_whose_motor_runs() {
    for (name, text) in [("empty", ""), ("comments", "# my motor\n\n# todo\n")] {
        let (code, err, path) = dump_text(name, text);
        assert_eq!(code, Some(2), "{err}");
        assert!(err.contains(&path.display().to_string()), "{err}");
        assert!(err.contains("holds no key"), "{err}");
    }
    let (code, err, path) = dump_text("no-motor", "[simulation]\nduration = 0.5\n");
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains(&format!("{} has no [motor] table", path.display())),
        "{err}"
    );
    assert!(err.contains("paper"), "{err}");
}

/// A motor file with the flux map `csv` (the first 3 × 3 nodes of a surface-magnet map).
fn with_map(name: &str, csv: &str) -> (Option<i32>, String) {
    let dir = scratch(name);
    std::fs::write(dir.join("map.csv"), csv).unwrap();
    let toml = "[motor]\nrs = 0.5\nld = 3e-3\nlq = 3e-3\nflux_linkage = 0.1\npole_pairs = 3\n\
                rated_current = 8.0\nrated_speed_rpm = 3000.0\nrated_torque = 3.6\n\
                flux_map = \"map.csv\"\n";
    let path = dir.join("motor.toml");
    std::fs::write(&path, toml).unwrap();
    dump(&path)
}

/// A linear 3 × 3 map of L = 3 mH and λf = 0.1 Wb, its rows joined by `sep` with the
/// decimal mark `dot`; `swap` exchanges the ψ columns.
fn map(sep: &str, dot: &str, swap: bool) -> String {
    let mut s = ["i_d", "i_q", "psi_d", "psi_q"].join(sep) + "\n";
    for i_d in [-10.0, 0.0, 10.0] {
        for i_q in [-10.0, 0.0, 10.0] {
            let (pd, pq) = (0.1 + 3e-3 * i_d, 3e-3 * i_q);
            let (pd, pq) = if swap { (pq, pd) } else { (pd, pq) };
            let row = [i_d, i_q, pd, pq].map(|x: f64| format!("{x:.4}").replace('.', dot));
            s += &(row.join(sep) + "\n");
        }
    }
    s
}

#[test]
fn a_flux_map_from_a_spreadsheet_or_with_swapped_columns_is_named() {
    let (code, err) = with_map("map-ok", &map(",", ".", false));
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = with_map("map-semicolon", &map(";", ",", false));
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("map.csv:1:1:"), "{err}");
    assert!(err.contains("semicolons or tabs"), "{err}");
    let (code, err) = with_map("map-swapped", &map(",", ".", true));
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("psi_d and psi_q look swapped"), "{err}");
    assert!(!err.contains("  "), "{err}");
    let upper = map(",", ".", false).replacen("i_d,i_q,psi_d,psi_q", "I_d,I_q,Psi_d,Psi_q", 1);
    let (code, err) = with_map("map-upper", &upper);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("lower case"), "{err}");
}

#[test]
fn help_on_a_full_stdout_exits_3_and_on_a_closed_one_does_not_panic() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        return;
    };
    let out = Command::new(env!("CARGO_BIN_EXE_fado-sim"))
        .arg("--help")
        .stdout(full)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot write to stdout"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_fado-sim"))
        .args(["run", "--help"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{out:?}");
}

#[test]
fn a_config_saved_as_latin_1_is_named_at_its_bad_byte() {
    // "rs = 0.06   # 0.12 µ…" with µ as Latin-1's 0xb5 on line 2.
    let mut bytes = b"[motor]\nrs = 0.06   # 0.12 ".to_vec();
    bytes.push(0xb5);
    bytes.extend_from_slice(&OUTRUNNER.as_bytes()["[motor]\nrs = 0.06".len()..]);
    let dir = scratch("latin1");
    let path = dir.join("latin1.toml");
    std::fs::write(&path, bytes).unwrap();
    let (code, err) = dump(&path);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(&format!("{}:2:20:", path.display())), "{err}");
    assert!(err.contains("0xb5 is not UTF-8"), "{err}");
}

/// `text` (a flux-map CSV) with its current columns i_d, i_q divided by √2: the map of the
/// same machine written in A rms.
fn rms_currents(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let cols: Vec<&str> = line.split(',').collect();
        match cols.first().map(|c| c.trim().parse::<f64>()) {
            Some(Ok(_)) => {
                let i: Vec<f64> = cols[..2]
                    .iter()
                    .map(|c| c.trim().parse().unwrap())
                    .collect();
                let r = std::f64::consts::FRAC_1_SQRT_2;
                out += &format!("{},{},{},{}\n", i[0] * r, i[1] * r, cols[2], cols[3]);
            }
            _ => out += &format!("{line}\n"),
        }
    }
    out
}

#[test]
fn a_flux_map_in_rms_currents_is_a_warning_at_its_key_and_the_measured_maps_are_not() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../motors/saturated");
    for name in ["pmsm-gem-1k1-measured", "pmsyrm-baldor-5k6-measured"] {
        let toml = std::fs::read_to_string(root.join(format!("{name}.toml"))).unwrap();
        let csv = std::fs::read_to_string(root.join(format!("{name}.csv"))).unwrap();
        let line = toml
            .lines()
            .position(|l| l.starts_with("flux_map"))
            .unwrap()
            + 1;
        // The preset as it is: no warning.
        let dir = scratch(&format!("rms-{name}"));
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, &toml).unwrap();
        std::fs::write(dir.join(format!("{name}.csv")), &csv).unwrap();
        let (code, err) = dump(&path);
        assert_eq!(code, Some(0), "{err}");
        assert!(!err.contains("warning"), "{name}: {err}");
        // Its map in A rms: named at the flux_map key's value, as a warning.
        std::fs::write(dir.join(format!("{name}.csv")), rms_currents(&csv)).unwrap();
        let (code, err) = dump(&path);
        assert_eq!(code, Some(0), "{err}");
        let at = format!("{}:{line}:12: warning: `motor.flux_map`", path.display());
        assert!(err.contains(&at), "{at}\n{err}");
        assert!(err.contains("A rms") && err.contains("`motor.lq`"), "{err}");
    }
}

#[test]
fn a_line_to_line_resistance_on_the_nameplate_is_named_once_commission_measures_it() {
    // The paper's motor told a nameplate with rs = 2 × 0.327 Ω (a terminal-to-terminal value).
    let preset = include_str!("../../../motors/paper.toml");
    let text = preset.replace("rs = 0.327 ", "rs = 0.654 ");
    assert_ne!(text, preset);
    let line = text.lines().position(|l| l.starts_with("rs ")).unwrap() + 1;
    let dir = scratch("nameplate-ll");
    let path = dir.join("nameplate.toml");
    std::fs::write(&path, &text).unwrap();
    let commission = |nameplate: &Path, out: &str| {
        let o = Command::new(env!("CARGO_BIN_EXE_fado-sim"))
            .args(["commission", "--motor", "paper", "--nameplate"])
            .arg(nameplate)
            .arg("--out")
            .arg(dir.join(out))
            .stdout(Stdio::null())
            .output()
            .unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (code, err) = commission(&path, "ll");
    assert_eq!(code, Some(0), "{err}");
    let at = format!("{}:{line}:6: warning: `motor.rs`", path.display());
    assert!(err.contains(&at), "{at}\n{err}");
    assert!(err.contains("line-to-line"), "{err}");
    // The measured value is what identified.toml holds.
    let identified = std::fs::read_to_string(dir.join("ll/identified.toml")).unwrap();
    assert!(identified.contains("rs = 0.32"), "{identified}");
    // The preset's own record as the nameplate: nothing to say.
    let own = dir.join("paper.toml");
    std::fs::write(&own, preset).unwrap();
    let (code, err) = commission(&own, "own");
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("warning"), "{err}");
}

#[test]
fn a_paper_figure_on_the_users_motor_says_its_loads_are_the_papers_not_scaled() {
    let dir = scratch("absolute");
    let path = dir.join("outrunner.toml");
    std::fs::write(&path, OUTRUNNER).unwrap();
    let note = |scenario: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_fado-sim"))
            .args(["run", scenario, "--dump-config", "--config"])
            .arg(&path)
            .stdout(Stdio::null())
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0));
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    // fig11 loads 7.5 N·m, the paper motor's 65 %: 3.21 × this 2.34 N·m outrunner's rating.
    let err = note("fig11");
    assert!(err.contains("`fig11` is the paper's experiment"), "{err}");
    assert!(err.contains("loads up to 7.5 N·m"), "{err}");
    assert!(err.contains("3.21 × its `motor.rated_torque`"), "{err}");
    assert!(
        err.contains("scaled by the ratings: lowspeed, reversal, stops"),
        "{err}"
    );
    // The scaled scenarios take the ratings' loads: no note.
    for scenario in ["reversal", "lowspeed", "custom"] {
        assert!(!note(scenario).contains("note:"), "{scenario}");
    }
}

#[test]
fn a_speed_in_electrical_rpm_and_a_load_in_n_cm_are_warnings_at_their_lines() {
    // The outrunner's rated 1,800 r/min given as electrical r/min (× 7 pole pairs), its rated
    // 2.34 N·m as 234 N·cm: both beyond what its 24 V link and current limit give.
    let text = format!(
        "{OUTRUNNER}\n[speed_reference]\npoints = [[0.0, 0.0], [1.0, 12600.0]]\n\
         \n[load.torque]\npoints = [[0.0, 0.0], [1.0, 234.0]]\n"
    );
    let (code, err, path) = dump_text("reach", &text);
    assert_eq!(code, Some(0), "{err}");
    let line = |key: &str| {
        let after = text.find(key).unwrap();
        text[after..]
            .find("points")
            .map(|p| text[..after + p].lines().count() + 1)
            .unwrap()
    };
    let speed = format!(
        "{}:{}:10: warning: ",
        path.display(),
        line("[speed_reference]")
    );
    let load = format!("{}:{}:10: warning: ", path.display(), line("[load.torque]"));
    assert!(
        err.contains(&speed) && err.contains("electrical r/min"),
        "{speed}\n{err}"
    );
    assert!(err.contains(&load) && err.contains("N·cm"), "{load}\n{err}");
    // The same motor with its own ratings-scaled reference and load: no such warning.
    let (_, err, _) = dump_text("reach-ok", OUTRUNNER);
    assert!(
        !err.contains("speed_reference") && !err.contains("load.torque"),
        "{err}"
    );
}

#[test]
fn a_motor_without_a_rated_torque_is_refused_with_the_magnet_torque_to_write() {
    // A multirotor datasheet gives a Kv and a current, no torque: 1.5·7·7.88 mWb·28.3 A.
    let text = OUTRUNNER.replace("rated_torque = 2.34\n", "");
    assert_ne!(text, OUTRUNNER);
    let (code, err, _) = dump_text("no-torque", &text);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("lacks `rated_torque`"), "{err}");
    assert!(err.contains("`rated_torque = 2.3415`"), "{err}");
}

/// Three motors entered from their datasheets (`tests/data/datasheets/`): a 400 W 220 V
/// servo, a 100 W 24 V flat robot-joint motor and a 24 V robot-joint outrunner.
const DATASHEETS: [(&str, &str); 3] = [
    (
        "delta",
        include_str!("data/datasheets/delta-ecma-c20604-400w-220v.toml"),
    ),
    (
        "ec60",
        include_str!("data/datasheets/maxon-ec60flat-100w-24v.toml"),
    ),
    (
        "d6374",
        include_str!("data/datasheets/odrive-d6374-150kv-24v.toml"),
    ),
];

/// `text` with `key`'s value multiplied by `k` (or replaced by `value` when given).
fn with_key(text: &str, key: &str, f: impl Fn(f64) -> String) -> String {
    let prefix = format!("{key} = ");
    let out: Vec<String> = text
        .lines()
        .map(|l| match l.strip_prefix(&prefix) {
            Some(v) => format!("{prefix}{}", f(v.trim().parse().unwrap())),
            None => l.to_owned(),
        })
        .collect();
    let out = out.join("\n") + "\n";
    assert_ne!(out, text, "{key}");
    out
}

/// The 1-based line of `key = ` in `text`.
fn line_of(text: &str, key: &str) -> usize {
    let prefix = format!("{key} = ");
    text.lines().position(|l| l.starts_with(&prefix)).unwrap() + 1
}

/// One slip: its name, the text with it, the key it must be named at, whether it is an
/// error (`None`: an error on one motor, a warning on another, as the slip's size there
/// makes it), and a piece of the cause the message must give.
type Slip = (
    &'static str,
    String,
    &'static str,
    Option<bool>,
    &'static str,
);

/// The slips of a user entering `text` by hand, one per row.
fn slips(text: &str) -> Vec<Slip> {
    let x = |k: f64| move |v: f64| format!("{:e}", v * k);
    let sqrt = f64::sqrt;
    let pi = std::f64::consts::PI;
    let lq = |t: &str| -> f64 {
        let l = t.lines().find(|l| l.starts_with("lq = ")).unwrap();
        l[5..].trim().parse().unwrap()
    };
    let ld_swapped = format!("{:e}", 1.5 * lq(text));
    vec![
        (
            "mH",
            with_key(&with_key(text, "ld", x(1e3)), "lq", x(1e3)),
            "ld",
            Some(true),
            "mH where H is meant",
        ),
        (
            "pole count",
            with_key(text, "pole_pairs", |p| format!("{}", 2.0 * p)),
            "pole_pairs",
            Some(true),
            "looks like a pole count",
        ),
        (
            "Ke rms as peak",
            with_key(text, "flux_linkage", x(sqrt(1.5))),
            "flux_linkage",
            Some(false),
            "line-to-line rms back-EMF taken as the phase peak",
        ),
        (
            "Ke line-to-line",
            with_key(text, "flux_linkage", x(sqrt(3.0))),
            "flux_linkage",
            Some(false),
            "line-to-line constant",
        ),
        (
            "current rms",
            with_key(text, "rated_current", x(1.0 / sqrt(2.0))),
            "rated_torque",
            Some(false),
            "rms where peak is meant",
        ),
        (
            "rad/s",
            with_key(text, "rated_speed_rpm", x(pi / 30.0)),
            "rated_speed_rpm",
            None,
            "in rad/s where r/min is meant",
        ),
        (
            "kHz",
            with_key(text, "switching_frequency", x(1e-3)),
            "switching_frequency",
            Some(true),
            "kHz where Hz is meant",
        ),
        (
            "swapped",
            with_key(text, "ld", |_| ld_swapped.clone()),
            "ld",
            Some(false),
            "swapped",
        ),
        (
            "kg·cm²",
            with_key(text, "inertia", x(1e4)),
            "inertia",
            Some(false),
            "kg·cm²",
        ),
        (
            "typo",
            text.replace("rated_current =", "rated_curent ="),
            "rated_curent",
            Some(true),
            "did you mean `rated_current`",
        ),
        (
            "table",
            text.replace("switching_frequency", "#")
                .replace("[motor]\n", "[motor]\nswitching_frequency = 2e4\n"),
            "switching_frequency",
            Some(true),
            "is a key of [inverter]",
        ),
        (
            "quoted",
            with_key(text, "rs", |v| format!("\"{v}\"")),
            "rs",
            Some(true),
            "a number in quotes",
        ),
        (
            "unit",
            with_key(text, "rs", |v| format!("\"{v} ohm\"")),
            "rs",
            Some(true),
            "a unit written into the value",
        ),
        (
            "fraction",
            with_key(text, "pole_pairs", |p| format!("{p:.1}")),
            "pole_pairs",
            Some(true),
            "a whole number is meant",
        ),
    ]
}

/// Each datasheet motor entered correctly is accepted without a word (its closed-loop runs:
/// `datasheet_motors.rs`); each slip a user makes entering it is named at its key's line with
/// its cause, as an error where the run would be wrong by far, a warning where the value is
/// possible.
#[test]
fn datasheet_motors_are_accepted_and_each_slip_is_named_at_its_line_with_its_cause() {
    for (name, text) in DATASHEETS {
        let (code, err, _) = dump_text(name, text);
        assert_eq!(code, Some(0), "{name}: {err}");
        assert!(!err.contains("warning"), "{name}: {err}");
        for (slip, slipped, key, error, cause) in slips(text) {
            let (code, err, path) = dump_text(
                &format!("{name}-{}", slip.replace(['/', '·', '²'], "")),
                &slipped,
            );
            let expected = match error {
                Some(true) => code == Some(2),
                Some(false) => code == Some(0),
                None => matches!(code, Some(0 | 2)),
            };
            assert!(expected, "{name} {slip}: {code:?} {err}");
            let error = code == Some(2);
            let what = if error { "error: " } else { "warning: " };
            let line = line_of(&slipped, key);
            let at = format!("{}:{line}:", path.display());
            let named = err.lines().any(|l| {
                let l = l.strip_prefix("error: ").unwrap_or(l);
                l.starts_with(&at) && (error || l.contains(what)) && l.contains(cause)
            });
            assert!(named, "{name} {slip}: {at} {what}{cause}\n{err}");
        }
    }
}

/// A datasheet motor without `switching_frequency` or `viscous_friction` runs with both
/// derived, `--dump-config` printing each with its rule; without its ratings it is refused
/// naming them.
#[test]
fn datasheet_motors_without_carrier_friction_or_ratings_are_derived_or_refused() {
    for (name, text) in DATASHEETS {
        let bare: String = text
            .lines()
            .filter(|l| !l.starts_with("switching_frequency") && !l.starts_with("inertia"))
            .map(|l| format!("{l}\n"))
            .collect();
        let dir = scratch(&format!("{name}-bare"));
        let path = dir.join("m.toml");
        std::fs::write(&path, &bare).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_fado-sim"))
            .args(["run", "reversal", "--dump-config", "--config"])
            .arg(&path)
            .output()
            .unwrap();
        let dumped = String::from_utf8_lossy(&out.stdout);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        for key in ["switching_frequency", "viscous_friction", "inertia"] {
            let line = dumped
                .lines()
                .find(|l| l.starts_with(&format!("{key} = ")))
                .unwrap_or_else(|| panic!("{name}: {key}\n{dumped}"));
            assert!(line.contains("# derived: "), "{name}: {line}");
        }
        let unrated: String = text
            .lines()
            .filter(|l| !l.starts_with("rated_"))
            .map(|l| format!("{l}\n"))
            .collect();
        let (code, err, _) = dump_text(&format!("{name}-unrated"), &unrated);
        assert_eq!(code, Some(2), "{name}: {err}");
        for key in ["`rated_current`", "`rated_speed_rpm`", "`rated_torque`"] {
            assert!(err.contains(key), "{name}: {key}\n{err}");
        }
    }
}
