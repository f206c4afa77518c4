//! A stop at the current limit from the rated speed on the PM-SyRM (`pmsyrm-baldor-5k6`, its
//! fitted algebraic model and its measured flux map), `regen-stop`'s first stop: a rectifier
//! with a brake chopper, the range scenarios' acceleration feed-forward, switching-resolved
//! with the default non-idealities, the current-sensor seeds 1–4. The machine generates at
//! twice its rated torque down to 300 r/min and the speed loop then leaves the current limit,
//! where the deceleration falls by 2,000 rad/s² (electrical) at 10–3 Hz electrical: the observer's
//! notched speed (`fado_core::speed_notch`, "The chirp") removes nothing of that change and
//! the angle holds within 0.25 rad down to the Fig. 3 threshold (2.75 s), with no trip.

use fado_sim::scenario::simulate;

fn preset(name: &str) -> String {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/saturated/");
    // The measured preset's map path is relative to its file: resolve it as the CLI does.
    fado_sim::magnetics_file::set_config_dir(Some(std::path::Path::new(root)));
    std::fs::read_to_string(format!("{root}{name}")).unwrap()
}

/// `regen-stop`'s profile up to the end of the first stop (the speed below the Fig. 3
/// threshold of 1.5 % of the rated speed at 2.74–2.75 s).
const STOP: &str = "[speed_reference]\n\
    points = [[0.0, 0.0], [0.7, 0.0], [1.7, 1800.0], [2.5, 1800.0], [2.6, 0.0], [3.0, 0.0]]\n\
    [dc_link]\nsource = \"rectifier\"\nchopper_voltage = 567.0\n\
    [controller.tracker_feedforward]\nenabled = true\n\
    [estimator.tracker]\nload_pole_ratio = 0.5\n\
    [simulation]\nduration = 2.75\neval_start = 0.7\n";

#[test]
fn the_pm_syrm_holds_the_angle_through_a_stop_at_the_current_limit() {
    for name in ["pmsyrm-baldor-5k6.toml", "pmsyrm-baldor-5k6-measured.toml"] {
        let motor = preset(name);
        for seed in 1..=4 {
            let text = format!("{motor}\n{STOP}[current_sensor]\nseed = {seed}\n");
            let out = simulate("custom", Some(&text), false, None).unwrap();
            let m = &out.metrics;
            println!(
                "{name} seed {seed}: max |θ − θ̂| {:.3} rad",
                m.max_angle_error
            );
            assert!(!m.tripped, "{name} seed {seed} tripped");
            assert!(
                m.max_angle_error < 0.25,
                "{name} seed {seed}: {}",
                m.max_angle_error
            );
        }
    }
}
