//! The loaded standstill of `fullrange` (a stop at the current limit through zero, the hold
//! at zero speed under 65 % of the rated torque, the departure at the current limit) in
//! closed loop, switching-resolved, default non-idealities: the drive's loaded-standstill
//! handling (the angle probe and the flux-magnitude hold,
//! `fado_core::control::standstill_probe`) keeps |θ − θ̂| below 0.25 rad from the stop to
//! 0.5 s after the departure on two interior-magnet presets whose standstill loses the angle
//! without it, and on the saturating 2.2 kW IPMSM.

use fado_sim::scenario::simulate;

fn motor(file: &str) -> String {
    std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../motors")
            .join(file),
    )
    .unwrap()
}

/// The largest |θ − θ̂| (rad) from the stop at zero speed reference after the top speed to
/// 0.5 s after the reference leaves zero again, and whether the run tripped.
fn standstill(file: &str, extra: &str) -> (f64, bool) {
    let text = format!("{}\n{extra}", motor(file));
    let out = simulate("fullrange", Some(&text), false, None).unwrap();
    let rows = &out.trace.rows;
    let top = rows
        .iter()
        .max_by(|a, b| a.speed_ref_rpm.total_cmp(&b.speed_ref_rpm))
        .unwrap()
        .time;
    let stop = rows
        .iter()
        .find(|r| r.time > top && r.speed_ref_rpm == 0.0)
        .unwrap()
        .time;
    let depart = rows
        .iter()
        .find(|r| r.time > stop && r.speed_ref_rpm != 0.0)
        .unwrap()
        .time;
    let worst = rows
        .iter()
        .filter(|r| r.time >= stop && r.time <= depart + 0.5)
        .map(|r| r.angle_error.abs())
        .fold(0.0, f64::max);
    (worst, out.metrics.tripped)
}

#[test]
fn loaded_standstill_and_departure_hold_the_angle_on_interior_magnet_rotors() {
    for file in ["ipmsm-gem-50k.toml", "pmsyrm-5k.toml"] {
        let (with, tripped) = standstill(file, "");
        let (without, _) = standstill(file, "[controller]\nstandstill_probe = false\n");
        println!("{file}: {with:.3} rad (without the standstill handling {without:.3})");
        assert!(with < 0.25 && !tripped, "{file}: {with} rad");
        assert!(
            without > 0.25,
            "{file}: the case does not need the handling"
        );
    }
}

#[test]
fn loaded_standstill_and_departure_hold_the_angle_on_a_saturating_rotor() {
    let (with, tripped) = standstill("saturated/ipmsm-2k2-qsat.toml", "");
    println!("ipmsm-2k2-qsat: {with:.3} rad");
    assert!(with < 0.25 && !tripped, "{with} rad");
}
