//! The DC link in the loop: a hard stop from the rated speed on a rectifier (no regeneration
//! into the source, the default 5 ms link capacitor, no chopper) ends without an over-voltage
//! trip because the drive's over-voltage controller derates the braking and brakes with the
//! motor's losses; the controller's band sets where the bus peaks.

use fado_sim::scenario::simulate;

const STOP: &str = "[speed_reference]
points = [[0.0, 0.0], [0.7, 0.0], [1.7, 1500.0], [2.5, 1500.0], [2.6, 0.0]]
[simulation]
duration = 3.6
[dc_link]
source = \"rectifier\"
";

#[test]
fn a_hard_stop_on_a_rectifier_ends_without_an_over_voltage_trip() {
    let out = simulate("custom", Some(STOP), false, None).unwrap();
    let m = &out.metrics;
    let nominal = 311.0;
    assert!(!m.tripped, "{m:?}");
    // Below the controller's stop level (1.25 × nominal) and above its source minus the drop.
    assert!(
        m.max_dc_voltage > 1.1 * nominal && m.max_dc_voltage < 1.25 * nominal,
        "{}",
        m.max_dc_voltage
    );
    assert!(m.min_dc_voltage > 0.95 * nominal, "{}", m.min_dc_voltage);
    assert!(m.max_angle_error < 0.25, "{}", m.max_angle_error);
    // Stopped within 1 s of the reference: the losses absorbed the 148 J of the rotor.
    let last = out.trace.rows.last().unwrap();
    assert!(last.speed_rpm.abs() < 5.0, "{}", last.speed_rpm);
}

#[test]
fn the_controller_band_sets_the_peak_of_the_bus() {
    let text = format!(
        "{STOP}[controller.dc_link]\nover_voltage_start_ratio = 1.3\n\
         over_voltage_stop_ratio = 1.4\nover_voltage_trip_ratio = 1.49\n"
    );
    let out = simulate("custom", Some(&text), false, None).unwrap();
    let v = out.metrics.max_dc_voltage / 311.0;
    assert!(!out.metrics.tripped);
    assert!(v > 1.3 && v < 1.4, "{v}");
}

#[test]
fn a_battery_takes_the_braking_energy_back() {
    let text = STOP.replace("rectifier", "battery");
    let out = simulate("custom", Some(&text), false, None).unwrap();
    let m = &out.metrics;
    assert!(!m.tripped);
    // The battery's 5 % resistance: the bus rises a few per cent while braking at the
    // current limit, far from the controller's band, and the stop follows the reference.
    assert!(m.max_dc_voltage < 1.1 * 311.0, "{}", m.max_dc_voltage);
    assert!(m.max_dc_voltage > 311.0);
}
