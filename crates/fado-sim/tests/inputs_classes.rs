//! Motor files of classes and slips beyond the presets, each with the outcome a user needs:
//! a 10 kV machine whose derived inverter is a medium-voltage one, a pure synchronous
//! reluctance motor refused with its reason, and the ratings or λf slips that a derived DC link
//! cannot catch named by the machine's own cross-checks.

use fado_sim::SimConfig;

/// A 10 kV-class machine (1.4 MW at 1500 r/min) from its circuit and ratings alone.
const MV: &str = "[motor]\nrs = 0.5\nld = 20e-3\nlq = 20e-3\nflux_linkage = 20.0\n\
                  pole_pairs = 2\nrated_current = 150.0\nrated_speed_rpm = 1500.0\n\
                  rated_torque = 9000.0\n";

/// The 2.2 kW IPMSM of motulator's examples (motors/ipmsm-2k2.toml) without its inverter.
fn ipm(current: f64, speed: f64, torque: f64, flux: f64) -> String {
    format!(
        "[motor]\nrs = 3.6\nld = 0.036\nlq = 0.051\nflux_linkage = {flux}\npole_pairs = 3\n\
         rated_current = {current}\nrated_speed_rpm = {speed}\nrated_torque = {torque}\n"
    )
}

#[test]
fn a_10_kv_motor_gets_a_medium_voltage_inverter() {
    let cfg = SimConfig::from_toml(MV).unwrap();
    assert!(
        cfg.inverter.dc_voltage > 10e3,
        "{}",
        cfg.inverter.dc_voltage
    );
    // The medium-voltage floor (2 kHz, 6.25 µs), not a 1,200 V bridge's 5 kHz and 2.5 µs.
    assert_eq!(cfg.inverter.switching_frequency, 2000.0);
    assert_eq!(cfg.inverter.dead_time, 6.25e-6);
    assert!(cfg.warnings().is_empty(), "{:?}", cfg.warnings());
    let dump = cfg.to_toml_annotated();
    assert!(dump.contains("2 kHz on a DC link above 1.2 kV"), "{dump}");
}

#[test]
fn a_carrier_too_slow_for_the_current_loop_names_the_switching_frequency() {
    let e = SimConfig::from_toml(&format!("{MV}[inverter]\nswitching_frequency = 1000.0\n"))
        .unwrap_err();
    assert_eq!(e.key, "inverter.switching_frequency", "{e}");
    assert!(e.message.contains("at least 1571 Hz"), "{e}");
    // A bandwidth the file raises is named itself.
    let e = SimConfig::from_toml(&format!(
        "{MV}[controller.current]\nbandwidth_hz = 2000.0\n"
    ))
    .unwrap_err();
    assert_eq!(e.key, "controller.current.bandwidth_hz", "{e}");
}

#[test]
fn a_pure_synchronous_reluctance_motor_is_refused_saying_why() {
    let text = "[motor]\nrs = 0.6\nld = 50e-3\nlq = 10e-3\nflux_linkage = 0.0\npole_pairs = 2\n\
                rated_current = 15.0\nrated_speed_rpm = 1500.0\nrated_torque = 10.0\n";
    let e = SimConfig::from_toml(text).unwrap_err();
    assert_eq!(e.key, "motor.flux_linkage", "{e}");
    assert!(e.message.contains("synchronous reluctance"), "{e}");
}

#[test]
fn ratings_scaled_on_a_file_with_a_derived_dc_link_are_named() {
    let ok = SimConfig::from_toml(&ipm(6.08, 1500.0, 14.0, 0.545)).unwrap();
    assert!(ok.warnings().is_empty(), "{:?}", ok.warnings());
    let low = SimConfig::from_toml(&ipm(0.608, 150.0, 1.4, 0.545)).unwrap();
    assert!(
        low.warnings().iter().any(|w| w.contains("divided by 10")),
        "{:?}",
        low.warnings()
    );
    // Ten times the ratings ask for a carrier no inverter of their DC link's class has: the
    // refusal names the ratings' slip as its likely cause.
    let high = SimConfig::from_toml(&ipm(60.8, 15000.0, 140.0, 0.545)).unwrap_err();
    assert_eq!(high.key, "motor.rated_speed_rpm", "{high}");
    assert!(high.message.contains("multiplied by 10"), "{high}");
}

#[test]
fn a_flux_linkage_given_rms_or_line_to_line_on_an_ipm_is_named() {
    let rms = SimConfig::from_toml(&ipm(6.08, 1500.0, 14.0, 0.545 / 2f64.sqrt())).unwrap();
    assert!(
        rms.warnings().iter().any(|w| w.contains("rms where peak")),
        "{:?}",
        rms.warnings()
    );
    let ll = SimConfig::from_toml(&ipm(6.08, 1500.0, 14.0, 0.545 * 3f64.sqrt())).unwrap();
    let w = ll.warnings();
    assert!(w.iter().any(|w| w.contains("line-to-line")), "{w:?}");
    assert!(!w.iter().any(|w| w.contains("pole count")), "{w:?}");
}
