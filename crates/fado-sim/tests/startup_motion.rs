//! The start-up's motion monitor (`fado_core::control::startup::MotionMonitor`) in closed loop
//! with the plant: a load present from t = 0 without a brake is noticed during the offset
//! calibration (run under the zero vector when the drive finds the angle itself), the drive
//! defers with `StartupStatus::RotorMoving` and never reports ready while the rotor turns; a
//! rotor that comes to rest starts again; a braked rotor is never read as moving.

use fado_core::control::StartupStatus;
use fado_sim::profile::Profile;
use fado_sim::scenario::scenario_config;

/// `loaded-start` on preset `name` without its brake: `load` × the rated torque from t = 0
/// until `load_until` (s), speed reference 0.
fn unbraked(name: &str, load: f64, load_until: f64) -> fado_sim::config::SimConfig {
    let toml = fado_sim::presets::find(name).unwrap().toml;
    let mut cfg = scenario_config("loaded-start", Some(toml), false).unwrap();
    cfg.simulation.brake = false;
    let t = load * cfg.motor.rated_torque;
    cfg.load.torque = Profile::from_points(&[(0.0, t), (load_until, t), (load_until, 0.0)]);
    cfg.speed_reference = Profile::constant(0.0);
    cfg
}

/// What a start-up did: when the drive first said `RotorMoving` (s) and the rotor's travel
/// from its start angle then (rad), when it was first ready (s), |θ − θ̂| then (rad), the
/// largest monitor reading outside a deferral (rad), whether it tripped.
#[derive(Debug, Default)]
struct Start {
    moving_at: Option<(f64, f64)>,
    ready_at: Option<(f64, f64)>,
    max_reading: f64,
    tripped: bool,
}

fn run(cfg: &fado_sim::config::SimConfig, duration: f64) -> Start {
    let theta0 = cfg.simulation.initial_angle;
    let mut sim = cfg.simulation(cfg.build_drive().unwrap()).unwrap();
    let mut st = Start::default();
    loop {
        let s = sim.step();
        let d = sim.controller();
        if s.startup == StartupStatus::RotorMoving {
            st.moving_at
                .get_or_insert((s.time, fado_core::wrap_angle(s.theta - theta0).abs()));
        } else if st.moving_at.is_none() {
            st.max_reading = st.max_reading.max(d.angle_search().motion().travel());
        }
        if d.ready() && st.ready_at.is_none() {
            st.ready_at = Some((s.time, s.angle_error.abs()));
        }
        st.tripped |= s.act.tripped;
        if s.time >= duration {
            return st;
        }
    }
}

#[test]
fn a_load_from_t0_without_a_brake_is_noticed_and_the_drive_is_never_ready() {
    // 65 % of the rated torque from t = 0, no brake, the angle unknown: the offset
    // calibration runs under the zero vector, the monitor reads the rotor's travel from the
    // short-circuit current and the drive defers; the shorted phases brake the rotor, the
    // drive is never ready, nothing trips. The monitor omits the uncompensated dead time's
    // share of the braking voltage and reads less than the true travel: the rotor has turned
    // 0.17 rad (2.2 kW IPMSM, noticed at 14 ms) when the monitor reads 0.05, and on the
    // servo motor, whose small resistance leaves the dead time most of the braking, 1.75 rad
    // (noticed at 38 ms): the bound on the travel holds for the IPMSM only.
    for (name, max_time, max_travel) in [("ipmsm-2k2", 0.02, 0.25), ("servo-1ft6084", 0.05, 2.0)] {
        let cfg = unbraked(name, 0.65, 10.0);
        let st = run(&cfg, 0.5);
        println!("{name}: {st:?}");
        let (t, travel) = st.moving_at.expect("motion noticed");
        assert!(t < max_time, "{name}: {t}");
        assert!(travel < max_travel, "{name}: {travel}");
        assert!(st.ready_at.is_none(), "{name}: {:?}", st.ready_at);
        assert!(!st.tripped, "{name}");
    }
}

#[test]
fn a_rotor_that_comes_to_rest_starts_again_and_is_held() {
    // The load goes after 50 ms: the shorted phases stop the rotor, which then stands still
    // for `quiet_time`; the start-up begins again and the drive is ready with its angle.
    let name = "ipmsm-2k2";
    let cfg = unbraked(name, 0.65, 0.05);
    let st = run(&cfg, 1.5);
    println!("{name}: {st:?}");
    assert!(st.moving_at.is_some(), "{name}");
    let (t, err) = st.ready_at.expect("ready");
    assert!(t < 1.2, "{name}: {t}");
    assert!(err < 0.25, "{name}: {err}");
    assert!(!st.tripped, "{name}");
}

#[test]
fn a_braked_rotor_is_never_read_as_moving() {
    // `loaded-start` as it is (the brake holds the rated torque until ready): the monitor
    // reads below its threshold (0.05 rad) through the offsets (measured: 0.002–0.011 rad,
    // 0.036 on the multirotor preset).
    for name in [
        "paper",
        "ipmsm-2k2",
        "servo-1ft6084",
        "hub-hoverboard-48v",
        "ipmsm-gem-50k",
        "multirotor-mn5006-22v",
    ] {
        let toml = fado_sim::presets::find(name).unwrap().toml;
        let cfg = scenario_config("loaded-start", Some(toml), false).unwrap();
        let st = run(&cfg, 0.7);
        println!("{name}: largest reading {:.4} rad", st.max_reading);
        assert!(st.moving_at.is_none(), "{name}: {:?}", st.moving_at);
        assert!(st.max_reading < 0.04, "{name}: {}", st.max_reading);
    }
}
