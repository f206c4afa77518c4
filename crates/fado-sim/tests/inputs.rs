//! Inputs a user can trust: no value taken silently from another motor, and every slip of a
//! motor file refused or warned about by its real cause, naming each key involved. One test
//! per input a new user tried (the multirotor outrunner, the 10 kV motor, the slips).

use fado_core::MachineModel;
use fado_core::machine_checks::Severity;
use fado_sim::SimConfig;

/// A 24 V multirotor outrunner from its circuit and ratings alone: 14 pole pairs, 25 µH,
/// 6000 r/min (ω_rated = 8796 rad/s), 30 A, 0.69 N·m (λf = 1.1 mWb: 1.5·14·1.1e-3·30 A).
const DRONE: &str = "[motor]\nrs = 0.05\nld = 25e-6\nlq = 25e-6\nflux_linkage = 1.1e-3\n\
                     pole_pairs = 14\nrated_current = 30.0\nrated_speed_rpm = 6000.0\n\
                     rated_torque = 0.69\n";

/// `DRONE` with `key = value` in place of its own line (or added).
fn drone_with(key: &str, value: &str) -> String {
    let mut text: String = DRONE
        .lines()
        .filter(|l| !l.starts_with(&format!("{key} =")))
        .map(|l| format!("{l}\n"))
        .collect();
    if ["dc_voltage", "switching_frequency"].contains(&key) {
        text.push_str(&format!("[inverter]\n{key} = {value}\n"));
    } else {
        text = text.replacen("[motor]\n", &format!("[motor]\n{key} = {value}\n"), 1);
    }
    text
}

/// The paper's motor file with `key = value` in place of its own line.
fn paper_with(key: &str, value: &str) -> String {
    let text = fado_sim::presets::find("paper").unwrap().toml;
    let mut out = String::new();
    for line in text.lines() {
        if line.starts_with(&format!("{key} ")) || line.starts_with(&format!("{key}=")) {
            out.push_str(&format!("{key} = {value}\n"));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    assert!(out.contains(&format!("{key} = {value}\n")), "{key}");
    out
}

fn refused(text: &str) -> fado_sim::SimConfigError {
    SimConfig::from_toml(text).expect_err("refused")
}

fn warnings(text: &str) -> Vec<String> {
    SimConfig::from_toml(text).expect("accepted").warnings()
}

#[test]
fn friction_and_switching_frequency_come_from_the_ratings_not_the_papers_motor() {
    let cfg = SimConfig::from_toml(DRONE).unwrap();
    // 1 % of 0.69 N·m at 628 rad/s, not the paper's 1e-3 N·m·s (its whole rated torque).
    let b = cfg.motor.viscous_friction * cfg.motor.rated_speed_mech();
    assert!((b / cfg.motor.rated_torque - 0.01).abs() < 1e-12, "{b}");
    // ω_rated·Ts ≤ 0.2: 22 kHz, not the paper's 5 kHz (ω·Ts 0.88).
    assert_eq!(cfg.inverter.switching_frequency, 22_000.0);
    assert!(cfg.motor.rated_speed() * cfg.inverter.sample_period() <= 0.2);
    // Every derived key is recorded with its rule and printed by --dump-config.
    let dump = cfg.to_toml_annotated();
    for key in [
        "inertia",
        "viscous_friction",
        "dc_voltage",
        "switching_frequency",
        "dead_time",
    ] {
        assert!(
            dump.lines()
                .any(|l| l.starts_with(&format!("{key} = ")) && l.contains("# derived: ")),
            "{key}: {dump}"
        );
    }
    assert!(cfg.warnings().is_empty(), "{:?}", cfg.warnings());
}

#[test]
fn a_motor_without_ratings_is_refused_naming_them() {
    let text: String = DRONE.lines().take(6).map(|l| format!("{l}\n")).collect();
    let e = refused(&text);
    assert_eq!(e.key, "motor.rated_current");
    for k in ["rated_current", "rated_speed_rpm", "rated_torque"] {
        assert!(e.message.contains(k), "{e}");
    }
}

#[test]
fn commissioning_refuses_a_sampling_too_slow_for_the_motor() {
    let cfg = SimConfig::from_toml(&drone_with("switching_frequency", "5000.0")).unwrap();
    // A warning for a run …
    assert!(
        cfg.warnings()
            .iter()
            .any(|w| w.contains("inverter.switching_frequency")),
        "{:?}",
        cfg.warnings()
    );
    // … and a refusal for the commissioning, which would report parameters off by %.
    let plant = cfg.plant();
    let nameplate = plant.motor.with_dc_voltage(plant.inverter.dc_voltage);
    let e = fado_sim::commission::commission(&plant, nameplate, Default::default(), |_| {}, None)
        .map(|_| ())
        .unwrap_err();
    assert_eq!(e.key, "inverter.switching_frequency", "{e}");
    assert!(e.message.contains("22000 Hz"), "{e}");
}

#[test]
fn commissioning_refuses_a_current_sensor_too_coarse() {
    let mut cfg = SimConfig::from_toml(fado_sim::presets::find("paper").unwrap().toml).unwrap();
    cfg.current_sensor.adc_bits = 6;
    let plant = cfg.plant();
    let nameplate = plant.motor.with_dc_voltage(plant.inverter.dc_voltage);
    let e = fado_sim::commission::commission(&plant, nameplate, Default::default(), |_| {}, None)
        .map(|_| ())
        .unwrap_err();
    assert_eq!(e.key, "current_sensor.adc_bits", "{e}");
}

#[test]
fn absurd_magnitudes_blame_their_own_key() {
    for (key, value) in [
        ("flux_linkage", "1e300"),
        ("pole_pairs", "4000000000"),
        ("rated_speed_rpm", "1e6"),
    ] {
        let e = refused(&paper_with(key, value));
        assert_eq!(e.key, format!("motor.{key}"), "{e}");
        assert!(e.location.is_some(), "{e}");
    }
}

/// A current limit of 1e9 × the rated current (blamed `protection.trip_current_ratio`), a DC-link warning
/// level above the DC link (the flag on for the whole run, which still passed).
#[test]
fn drive_settings_that_cannot_work_blame_their_own_key() {
    for (table, key) in [
        ("current", "limit_ratio = 1e9"),
        ("protection", "dc_link_min_ratio = 2.0"),
    ] {
        let e = refused(&format!(
            "{}[controller.{table}]\n{key}\n",
            fado_sim::presets::find("paper").unwrap().toml
        ));
        let name = key.split(' ').next().unwrap();
        assert_eq!(e.key, format!("controller.{table}.{name}"), "{e}");
    }
}

#[test]
fn a_pole_count_given_as_pole_pairs_is_named() {
    let e = refused(&drone_with("pole_pairs", "28"));
    assert_eq!(e.key, "motor.pole_pairs", "{e}");
    assert!(
        e.message
            .contains("`motor.pole_pairs` = 28 looks like a pole count: 14?"),
        "{e}"
    );
    assert!(e.message.contains("motor.rated_torque"), "{e}");
}

#[test]
fn an_inductance_in_mh_is_named() {
    let e = refused(&paper_with("ld", "2.63").replace("lq = 2.63e-3", "lq = 2.63"));
    assert_eq!(e.key, "motor.ld", "{e}");
    assert!(e.message.contains("mH where H is meant"), "{e}");
}

#[test]
fn swapped_inductances_are_a_warning_naming_both() {
    let text = fado_sim::presets::find("ipmsm-2k2")
        .unwrap()
        .toml
        .replace("ld = 0.036", "ld = 0.051_0")
        .replace("lq = 0.051 ", "lq = 0.036 ")
        .replace("0.051_0", "0.051");
    let w = warnings(&text);
    assert!(
        w.iter()
            .any(|w| w.contains("`motor.ld`") && w.contains("`motor.lq`") && w.contains("swapped")),
        "{w:?}"
    );
}

#[test]
fn ratings_divided_by_ten_are_refused_against_the_dc_link() {
    let text = paper_with("rated_current", "2.178")
        .replace("rated_speed_rpm = 1500.0", "rated_speed_rpm = 150.0")
        .replace("rated_torque = 11.5", "rated_torque = 1.15");
    let e = refused(&text);
    assert_eq!(e.key, "motor.rated_speed_rpm", "{e}");
    for k in [
        "motor.rated_current",
        "motor.rated_torque",
        "inverter.dc_voltage",
    ] {
        assert!(e.message.contains(k), "{e}");
    }
    assert!(e.message.contains("divided by 10"), "{e}");
}

#[test]
fn a_sampling_period_in_ms_is_refused_naming_ts() {
    let m = MachineModel::<f64>::paper();
    let e = fado_core::SensorlessEstimator::new(fado_core::EstimatorConfig {
        ts: 0.025,
        machine: m,
        initial_angle: 0.0,
        tuning: Default::default(),
    })
    .map(|_| ())
    .unwrap_err();
    assert_eq!(e.field(), "ts", "{e}");
}

/// A 10 kV, 1 MW-class motor (τ = 0.25 s): commissioned with phases that scale with τ
/// instead of refusing `commissioning.phase_timeout`, which no user sets.
#[test]
fn a_10_kv_motor_is_not_refused_by_a_key_no_user_can_set() {
    let m = MachineModel::<f64> {
        rs: 0.1,
        ld: 25e-3,
        lq: 25e-3,
        flux_linkage: 7.35,
        pole_pairs: 4,
        inertia: 60.0,
        viscous_friction: 0.4,
        rated_current: 144.0,
        rated_speed_rpm: 1500.0,
        rated_torque: 6350.0,
        dc_voltage: 10_000.0,
        magnetics: Default::default(),
    };
    let findings = fado_core::machine_checks::check(&m, Some(100e-6));
    assert!(findings.is_empty(), "{findings:?}");
    let c = fado_core::commissioning::CommissioningConfig::for_machine(m, 100e-6, 2.5e-6);
    c.validate().unwrap();
    assert!(c.phase_timeout > 2.0 * c.align_time + c.settle_time + c.measure_time);
}

#[test]
fn the_presets_raise_no_finding() {
    for p in fado_sim::presets::PRESETS {
        let cfg = p.config().unwrap();
        let f = cfg.machine_findings();
        assert!(f.is_empty(), "{}: {f:?}", p.name);
        assert!(!f.iter().any(|(s, ..)| *s == Severity::Error));
    }
}

#[test]
fn an_inductance_in_mh_on_a_minimal_file_blames_the_inductance_not_the_derived_dc_link() {
    // The drone motor with 2.5 mH entered as 2.5 (H): the DC link left out is derived from the
    // rated point, which this inductance puts at 1.4 MV. The inductance is named at its own
    // line, not the DC link nobody wrote.
    let e = refused(&drone_with("ld", "2.5").replace("lq = 25e-6", "lq = 2.5"));
    assert_eq!(e.key, "motor.ld", "{e}");
    assert!(e.message.contains("per unit"), "{e}");
}

#[test]
fn a_derived_dc_link_beyond_any_drive_names_the_ratings_it_follows_from() {
    // A 10 kV-class motor (λf 11.7 Wb, p 4) with its ratings × 10 (15,000 r/min): the rated
    // point needs 636 kV. The derived `inverter.dc_voltage` is not the user's key.
    let text = "[motor]\nrs = 0.1\nld = 25e-3\nlq = 25e-3\nflux_linkage = 11.7\npole_pairs = 4\n\
                rated_current = 1810.0\nrated_speed_rpm = 15000.0\nrated_torque = 127000.0\n";
    let e = refused(text);
    assert_eq!(e.key, "motor.rated_speed_rpm", "{e}");
    assert!(
        e.message.contains("is not in the file: it is derived"),
        "{e}"
    );
    assert!(e.message.contains("`motor.flux_linkage`"), "{e}");
}

#[test]
fn a_threshold_voltage_beyond_the_dc_link_is_refused() {
    // 1e4 V of device threshold on a derived 17 V link: the drive trips at once.
    let e = refused(&format!("{DRONE}[inverter]\nthreshold_voltage = 1e4\n"));
    assert_eq!(e.key, "inverter.threshold_voltage", "{e}");
}

#[test]
fn a_current_given_rms_is_a_warning_saying_so() {
    // 30 A peak entered as 21.2 A rms: the rated torque is 1.41 × the model's.
    let w = warnings(&drone_with("rated_current", "21.21"));
    assert!(
        w.iter().any(|w| w.contains("rms where peak is meant")),
        "{w:?}"
    );
}
