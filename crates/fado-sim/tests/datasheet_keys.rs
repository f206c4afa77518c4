//! `[motor]` in the datasheet's units (`fado_core::datasheet`): converted when the file is
//! read to the values a hand conversion gives, printed with their conversion by
//! `--dump-config`, and refused naming both keys where a value is given both ways.

use fado_sim::SimConfig;

/// The 310 V 4-pole servo of tests/data/datasheets/servo-310v-2pp.toml, as its table states it.
const SERVO: &str = "[motor]\nrs_line_to_line = 3.07\nl_line_to_line = 6.57e-3\n\
                     ke_vll_peak_per_krpm = 51.0\npole_pairs = 2\nrated_current = 5.22\n\
                     rated_speed_rpm = 4600.0\nrated_torque = 2.2\ninertia = 1.8e-4\n\
                     [inverter]\ndc_voltage = 310.0\n";

#[test]
fn datasheet_keys_give_the_hand_converted_motor() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/datasheets/servo-310v-2pp.toml"
    );
    let by_hand = SimConfig::from_toml(&std::fs::read_to_string(path).unwrap()).unwrap();
    let cfg = SimConfig::from_toml(SERVO).unwrap();
    let (a, b) = (cfg.motor, by_hand.motor);
    assert_eq!(a.rs, b.rs);
    assert_eq!((a.ld, a.lq), (b.ld, b.lq));
    assert!(
        (a.flux_linkage / b.flux_linkage - 1.0).abs() < 1e-4,
        "{a:?}"
    );
    assert!(cfg.warnings().is_empty(), "{:?}", cfg.warnings());
    let dump = cfg.to_toml_annotated();
    assert!(
        dump.contains("# derived: from ke_vll_peak_per_krpm"),
        "{dump}"
    );
    // The dump reads back as the same motor.
    let again = SimConfig::from_toml(&dump).unwrap();
    assert_eq!(again.motor.flux_linkage, a.flux_linkage);
}

#[test]
fn a_value_given_both_ways_is_refused_at_its_line_naming_both() {
    let text = SERVO.replace("pole_pairs = 2\n", "pole_pairs = 2\nflux_linkage = 0.14\n");
    let e = SimConfig::from_toml(&text).unwrap_err();
    assert_eq!(e.key, "motor.flux_linkage", "{e}");
    assert!(e.message.contains("`motor.ke_vll_peak_per_krpm`"), "{e}");
    assert!(e.to_string().contains("line 6"), "{e}");
    let text = SERVO.replace("pole_pairs = 2\n", "");
    let e = SimConfig::from_toml(&text).unwrap_err();
    assert_eq!(e.key, "motor.pole_pairs", "{e}");
}
