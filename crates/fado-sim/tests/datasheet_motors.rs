//! Three motors entered by hand from their datasheets (`tests/data/datasheets/`: a Delta
//! ECMA-C20604 400 W 220 V servo, a maxon EC 60 flat 100 W 24 V motor and an ODrive D6374
//! 150 Kv outrunner on 24 V) pass `reversal`, `stops` and `loaded-start` at the sensor seed 1
//! on their own criteria. Measured, the largest |θ − θ̂|: reversal 0.009 / 0.014 / 0.007 rad,
//! stops 0.010 / 0.022 / 0.015 rad, loaded-start 0.067 / — / 0.067 rad, the round-rotor,
//! unsaturated EC 60 flat ending its loaded start with the drive's no-angle status (its model
//! gives no angle information at standstill). `cli_input_slips.rs` enters them with the
//! usual slips.

use fado_sim::scenario::simulate;

const MOTORS: [(&str, &str); 3] = [
    (
        "delta-ecma-c20604",
        include_str!("data/datasheets/delta-ecma-c20604-400w-220v.toml"),
    ),
    (
        "maxon-ec60flat",
        include_str!("data/datasheets/maxon-ec60flat-100w-24v.toml"),
    ),
    (
        "odrive-d6374",
        include_str!("data/datasheets/odrive-d6374-150kv-24v.toml"),
    ),
];

/// `reversal`, `stops` and `loaded-start` at seed 1 on `text`: the scenarios it missed.
fn misses(name: &str, text: &str) -> Vec<String> {
    let mut missed = Vec::new();
    for scenario in ["reversal", "stops", "loaded-start"] {
        let config = format!("{text}\n[current_sensor]\nseed = 1\n");
        let out = simulate(scenario, Some(&config), false, None).unwrap();
        if !out.passed {
            missed.push(format!("{name} {scenario}: {:?}", out.checks));
        }
    }
    missed
}

#[test]
fn three_datasheet_motors_pass_reversal_stops_and_loaded_start() {
    let runs: Vec<_> = MOTORS
        .iter()
        .map(|&(name, text)| std::thread::spawn(move || misses(name, text)))
        .collect();
    let missed: Vec<String> = runs.into_iter().flat_map(|r| r.join().unwrap()).collect();
    assert!(missed.is_empty(), "{missed:#?}");
}
