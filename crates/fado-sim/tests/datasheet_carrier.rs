//! The derived switching frequency (`fado_core::ratings::switching_frequency_of`) bounds the
//! PWM current ripple as well as ω_rated·Ts: a slotless motor entered from its datasheet
//! without `switching_frequency` runs `reversal` and `stops` at the carrier its file derives,
//! and at the carrier that ω_rated·Ts and L/R alone gave it, its ripple above its rated
//! current, it does not.

use fado_sim::SimConfig;
use fado_sim::scenario::simulate;

const MAXON: &str = include_str!("data/datasheets/maxon-ec22-40w-24v.toml");

fn run(scenario: &str, text: &str, seed: u64) -> fado_sim::scenario::Outcome {
    let text = format!("{text}\n[current_sensor]\nseed = {seed}\n");
    simulate(scenario, Some(&text), false, None).unwrap()
}

/// The file's derived carrier and its rule, as `--dump-config` prints them.
#[test]
fn the_slotless_maxon_derives_its_carrier_from_its_ripple() {
    let cfg = SimConfig::from_toml(MAXON).unwrap();
    let f = cfg.inverter.switching_frequency;
    assert_eq!(f, 67_000.0);
    let ripple = fado_core::ratings::ripple_current(cfg.inverter.dc_voltage, cfg.motor.ld, f);
    assert!(ripple <= fado_core::ratings::MAX_RIPPLE_CURRENT_RATIO * cfg.motor.rated_current);
    let dump = cfg.to_toml_annotated();
    let line = dump
        .lines()
        .find(|l| l.starts_with("switching_frequency"))
        .unwrap();
    assert!(
        line.contains("derived") && line.contains("0.6·rated_current"),
        "{line}"
    );
}

/// Measured (largest |θ − θ̂|): at the derived 67 kHz `stops` 0.028–0.034 rad and
/// `reversal` 0.015–0.019 rad at seeds 1–4; at 12 kHz (ΔI_pp 3.3 times the rated current)
/// `stops` loses the rotor (0.96 rad at seed 1).
#[test]
fn the_slotless_maxon_runs_at_its_derived_carrier_and_not_at_the_speed_bound_alone() {
    for (scenario, seed) in [("stops", 1), ("stops", 2), ("stops", 3), ("reversal", 4)] {
        let out = run(scenario, MAXON, seed);
        assert!(out.passed, "{scenario} seed {seed}: {:?}", out.checks);
    }
    let slow = MAXON.replace(
        "[inverter]\n",
        "[inverter]\nswitching_frequency = 12000.0\n",
    );
    assert_ne!(slow, MAXON);
    let out = run("stops", &slow, 1);
    assert!(!out.passed, "{:?}", out.checks);
}

/// The carrier rule's rows (`fado_core::ratings::check_carrier`), as the command line reads a
/// motor file: a derived carrier above the ceiling of realistic carriers is refused, naming the
/// bound's keys and the carrier it needs; one in the band of fast inverters is a warning; a
/// given carrier whose ripple is above 1.2 times the rated current is a warning naming it.
#[test]
fn the_carrier_rule_refuses_what_no_inverter_has_and_warns_below() {
    // A tenth of the maxon's inductance: the ripple asks for 664 kHz.
    let thin = MAXON
        .replace("ld = 27.3e-6", "ld = 2.73e-6")
        .replace("lq = 27.3e-6", "lq = 2.73e-6");
    assert_ne!(thin, MAXON);
    let e = SimConfig::from_toml(&thin).unwrap_err();
    assert_eq!(e.key, "motor.ld", "{e}");
    let text = e.to_string();
    for part in [
        "664 kHz",
        "100 kHz",
        "`motor.lq`",
        "`inverter.dc_voltage`",
        "`motor.rated_current`",
        "`inverter.switching_frequency`",
    ] {
        assert!(text.contains(part), "{part}: {text}");
    }
    // Given the inverter's carrier (a GaN bridge beyond the ceiling), the same motor runs:
    // its ripple (2.7 times the rated current at 150 kHz) is a warning.
    let given = thin.replace(
        "[inverter]\n",
        "[inverter]\nswitching_frequency = 150000.0\n",
    );
    let cfg = SimConfig::from_toml(&given).unwrap();
    assert!(
        cfg.warnings()
            .iter()
            .any(|w| w.starts_with("`inverter.switching_frequency` = 150000 Hz")),
        "{:?}",
        cfg.warnings()
    );
    // The maxon's own 67 kHz: a warning (a GaN inverter), the run goes on.
    let cfg = SimConfig::from_toml(MAXON).unwrap();
    let w = cfg.warnings();
    assert!(
        w.iter().any(|w| w.contains("67 kHz") && w.contains("GaN")),
        "{w:?}"
    );
    // A given 12 kHz (ripple 3.3 times the rated current): a warning naming the key and the
    // carrier the rule gives; 40 kHz (1.0 times): none.
    let given = |f: &str| {
        let text = MAXON.replace(
            "[inverter]\n",
            &format!("[inverter]\nswitching_frequency = {f}\n"),
        );
        SimConfig::from_toml(&text).unwrap().warnings()
    };
    let w = given("12000.0");
    assert!(
        w.iter()
            .any(|w| w.contains("`inverter.switching_frequency` = 12000 Hz")
                && w.contains("67000 Hz")),
        "{w:?}"
    );
    let w = given("40000.0");
    assert!(
        !w.iter().any(|w| w.contains("switching_frequency")),
        "{w:?}"
    );
    // `--dump-config` states the ceiling with the rule.
    let dump = SimConfig::from_toml(MAXON).unwrap().to_toml_annotated();
    let line = dump
        .lines()
        .find(|l| l.starts_with("switching_frequency"))
        .unwrap();
    assert!(line.contains("refused above 100 kHz"), "{line}");
}
