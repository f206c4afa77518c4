//! Tests of the configuration: defaults, partial files, errors named and located.

mod basics {
    use super::super::*;
    use crate::inverter::InverterModel;

    #[test]
    fn defaults_round_trip_through_toml() {
        let cfg = SimConfig::default();
        let text = cfg.to_toml();
        let back = SimConfig::from_toml(&text).unwrap();
        assert_eq!(back, cfg);
    }

    #[test]
    fn partial_file_overrides_only_its_keys() {
        let mut base = SimConfig::default();
        base.load.torque = Profile::constant(7.5);
        base.simulation.duration = 3.0;
        let cfg = SimConfig::from_toml_over(
            &base,
            "[inverter]\nmodel = \"averaged\"\n[mismatch]\nrs_ratio = 1.02\n",
        )
        .unwrap();
        assert_eq!(cfg.inverter.model, InverterModel::Averaged);
        assert_eq!(cfg.inverter.dead_time, 2.5e-6);
        assert_eq!(cfg.load.torque, Profile::constant(7.5));
        assert_eq!(cfg.simulation.duration, 3.0);
        assert!((cfg.estimator_config().machine.rs - 0.327 * 1.02).abs() < 1e-15);
    }

    #[test]
    fn unknown_keys_are_errors_naming_the_key() {
        let e = SimConfig::from_toml("[inverter]\ndead_tme = 1e-6\n").unwrap_err();
        assert_eq!(e.key, "inverter.dead_tme", "{e}");
        let e = SimConfig::from_toml("[motorr]\nrs = 1.0\n").unwrap_err();
        assert_eq!(e.key, "motorr", "{e}");
        let e = SimConfig::from_toml("[load.torque]\npoints = [[0.0, 1.0]]\nx = 1\n").unwrap_err();
        assert_eq!(e.key, "load.torque.x", "{e}");
    }

    #[test]
    fn wrong_types_and_impossible_values_name_the_key() {
        let e = SimConfig::from_toml("[inverter]\nmodel = \"fast\"\n").unwrap_err();
        assert_eq!(e.key, "inverter.model", "{e}");
        let e = SimConfig::from_toml("[motor]\nrs = \"big\"\n").unwrap_err();
        assert_eq!(e.key, "motor.rs", "{e}");
        let e = SimConfig::from_toml("[motor]\nrs = -0.3\n").unwrap_err();
        assert_eq!(e.key, "motor.rs", "{e}");
        let e =
            SimConfig::from_toml("[estimator.tracker]\nt2s1_bandwidth_hz = -60.0\n").unwrap_err();
        assert_eq!(e.key, "estimator.tracker.t2s1_bandwidth_hz", "{e}");
        let e = SimConfig::from_toml("[simulation]\ndecimation = 0\n").unwrap_err();
        assert_eq!(e.key, "simulation.decimation", "{e}");
        let e = SimConfig::from_toml("[simulation]\nduration = 50000.0\n").unwrap_err();
        assert_eq!(e.key, "simulation.decimation", "{e}");
        let e = SimConfig::from_toml("[speed_reference]\npoints = [[1.0, 0.0], [0.0, 1.0]]\n")
            .unwrap_err();
        assert_eq!(e.key, "speed_reference.points[1]", "{e}");
        let e = SimConfig::from_toml(
            "[[faults.stuck_current]]\nchannel = \"a\"\nstart = 1.0\nduration = -0.01\n",
        )
        .unwrap_err();
        assert_eq!(e.key, "faults.stuck_current[0].duration", "{e}");
        let e = SimConfig::from_toml("[[faults.non_finite]]\ntime = 1.0\nsignal = \"dc\"\n")
            .unwrap_err();
        // A serde type error: located at the bad value (line 3) rather than named by key.
        assert_eq!(e.location.as_ref().map(|l| l.line), Some(3), "{e}");
        assert!(e.message.contains("`dc`"), "{e}");
        let ok = SimConfig::from_toml(
            "[[faults.non_finite]]\ntime = 1.0\nsignal = \"dc_link\"\n\
             [faults.dc_link_scale]\npoints = [[1.0, 1.0], [1.1, 0.5]]\n",
        )
        .unwrap();
        assert_eq!(ok.faults.non_finite[0].samples, 1);
        assert_eq!(ok, SimConfig::from_toml(&ok.to_toml()).unwrap());
    }
}

mod located_errors {
    use super::super::*;

    /// (key, line, column, message) of the error `text` gives.
    fn err(text: &str) -> (String, usize, usize, String) {
        let e = SimConfig::from_toml(text).unwrap_err();
        let loc = e
            .location
            .clone()
            .unwrap_or_else(|| panic!("not located: {e}"));
        (e.key.clone(), loc.line, loc.column, e.to_string())
    }

    #[test]
    fn semantic_errors_name_key_line_and_column() {
        let text = "[simulation]\nduration = 1.0\n\n[motor]\nlq = 2e-3\nrs   = -1\n";
        let (key, line, col, msg) = err(text);
        assert_eq!((key.as_str(), line, col), ("motor.rs", 6, 8));
        assert_eq!(msg, "line 6, column 8: `motor.rs`: must be > 0, got -1");
        let e = SimConfig::from_toml(text)
            .unwrap_err()
            .in_file("config.toml");
        assert_eq!(
            e.to_string(),
            "config.toml:6:8: `motor.rs`: must be > 0, got -1"
        );
        // Estimator and drive checks of fado-core, renamed to their TOML keys.
        let (key, line, col, _) =
            err("[estimator.tracker]\ndamping = 0.7\nt2s1_bandwidth_hz = -60.0\n");
        assert_eq!(
            (key.as_str(), line, col),
            ("estimator.tracker.t2s1_bandwidth_hz", 3, 21)
        );
        let (key, line, _, _) = err("[estimator.mode]\nhysteresis_ratio = 0.03\n");
        assert_eq!((key.as_str(), line), ("estimator.mode.hysteresis_ratio", 2));
        // A key of the flat `[estimator]` table names its new place.
        let (key, line, col, message) =
            err("[motor]\nrs = 0.3\n[estimator]\nlock_heal_time = 0.2\n");
        assert_eq!(
            (key.as_str(), line, col),
            ("estimator.lock_heal_time", 4, 18)
        );
        assert!(
            message.ends_with(
                "`estimator.lock_heal_time` belongs in `[estimator.lock]`: write it as `[estimator.lock] heal_time`"
            ),
            "{message}"
        );
        let (key, line, _, _) = err("[estimator.mode]\nhysteresis_ratio = 0.03\n");
        assert_eq!((key.as_str(), line), ("estimator.mode.hysteresis_ratio", 2));
        // A key of the flat `[controller]` table names its new place; a flat switch that is a
        // table now (`standstill_probe`) too.
        let (key, line, col, message) =
            err("[motor]\nrs = 0.3\n[controller]\nlock_stall_time = 0.01\n");
        assert_eq!(
            (key.as_str(), line, col),
            ("controller.lock_stall_time", 4, 19)
        );
        assert!(
            message.ends_with(
                "`controller.lock_stall_time` belongs in `[controller.stall]`: write it as `[controller.stall] time`"
            ),
            "{message}"
        );
        let (key, line, _, message) = err("[controller]\nmtpa = true\nstandstill_probe = false\n");
        assert_eq!((key.as_str(), line), ("controller.mtpa", 2));
        assert!(
            message.ends_with("write it as `[controller.mtpa] enabled`"),
            "{message}"
        );
        let (key, _, _, message) = err("controller.acceleration_feedforward = true\n");
        assert_eq!(key, "controller.acceleration_feedforward");
        assert!(
            message.ends_with("write it as `[controller.tracker_feedforward] enabled`"),
            "{message}"
        );
        // fado-core's drive checks (flat field names) are named by the nested key.
        let (key, line, col, _) = err("[controller.stall]\ntime = -1.0\n");
        assert_eq!((key.as_str(), line, col), ("controller.stall.time", 2, 8));
        let (key, line, _, _) = err("[controller.current]\nlimit_ratio = 0.0\n");
        assert_eq!((key.as_str(), line), ("controller.current.limit_ratio", 2));
        // Array elements and dotted keys.
        let (key, line, col, _) =
            err("[simulation]\ndisturbance_feedback_off = [[0.0, 1.0], [2.0, 1.0]]\n");
        assert_eq!(
            (key.as_str(), line, col),
            ("simulation.disturbance_feedback_off[1]", 2, 41)
        );
        let (key, line, col, _) = err("motor.rs = nan\n");
        assert_eq!((key.as_str(), line, col), ("motor.rs", 1, 12));
    }

    #[test]
    fn type_errors_and_unknown_keys_name_key_line_and_column() {
        let (key, line, col, msg) = err("[motor]\nrs = \"big\"\n");
        assert_eq!((key.as_str(), line, col), ("motor.rs", 2, 6));
        assert!(msg.starts_with("line 2, column 6: `motor.rs`: "), "{msg}");
        let (key, line, col, _) = err("[inverter]\n\ndead_tme = 1e-6\n");
        assert_eq!((key.as_str(), line, col), ("inverter.dead_tme", 3, 1));
        let (key, line, _, msg) = err("[inverter]\nmodel = \"fast\"\n");
        assert_eq!((key.as_str(), line), ("inverter.model", 2));
        assert!(msg.contains("fast"), "{msg}");
        let (key, line, col, _) = err("[motorr]\nrs = 1.0\n");
        assert_eq!((key.as_str(), line, col), ("motorr", 1, 2));
        let (key, line, _, _) = err("[simulation]\ndecimation = 2.5\n");
        assert_eq!((key.as_str(), line), ("simulation.decimation", 2));
    }

    /// The paper's motor as a whole `[motor]` table whose first key is `first` (which
    /// replaces the paper's value of that key).
    pub(crate) fn paper_motor_with(first: &str) -> String {
        let key = first.split('=').next().unwrap_or("").trim();
        let m = MachineModel::<f64>::paper();
        let mut text = format!("[motor]\n{first}\n");
        for (k, v) in [
            ("rs", m.rs),
            ("ld", m.ld),
            ("lq", m.lq),
            ("flux_linkage", m.flux_linkage),
            ("pole_pairs", m.pole_pairs as f64),
            ("inertia", m.inertia),
            ("viscous_friction", m.viscous_friction),
            ("rated_current", m.rated_current),
            ("rated_speed_rpm", m.rated_speed_rpm),
            ("rated_torque", m.rated_torque),
        ] {
            if k != key {
                if k == "pole_pairs" {
                    text.push_str(&format!("{k} = {}\n", v as u32));
                } else {
                    text.push_str(&format!("{k} = {v:?}\n"));
                }
            }
        }
        text.push_str("[inverter]\ndc_voltage = 311.0\nswitching_frequency = 5000.0\n");
        text
    }

    #[test]
    fn derived_limits_name_the_users_own_key() {
        // Each of these keys is refused naming itself, not `controller.current.anti_windup_ratio`.
        let (key, line, col, _) = err(&paper_motor_with("rs = 1e300"));
        assert_eq!((key.as_str(), line, col), ("motor.rs", 2, 6));
        let (key, line, _, _) = err(&paper_motor_with("ld = 1e-300"));
        assert_eq!((key.as_str(), line), ("motor.ld", 2));
        let (key, line, _, _) = err("[mismatch]\nrs_ratio = 1e300\n");
        assert_eq!((key.as_str(), line), ("mismatch.rs_ratio", 2));
        let (key, line, _, msg) = err("[simulation]\nduration = 0.0\n");
        assert_eq!((key.as_str(), line), ("simulation.duration", 2), "{msg}");
    }

    /// `[inverter_model] threshold_voltage` (what `fado-sim commission` writes) replaces the
    /// compensation's V̂th derived from `[inverter]` × `[mismatch]`; a bad one is refused by
    /// its own key.
    #[test]
    fn the_inverter_model_sets_the_compensation_threshold() {
        let cfg = SimConfig::from_toml(
            "[inverter]\nthreshold_voltage = 1.0\n[mismatch]\nthreshold_voltage_ratio = 2.0\n",
        )
        .unwrap();
        assert_eq!(cfg.drive_config().tuning.inverter.threshold_voltage, 2.0);
        let cfg = SimConfig::from_toml(
            "[mismatch]\nthreshold_voltage_ratio = 2.0\n[inverter_model]\nthreshold_voltage = 0.93\n",
        )
        .unwrap();
        assert_eq!(cfg.drive_config().tuning.inverter.threshold_voltage, 0.93);
        assert_eq!(cfg.inverter.threshold_voltage, 1.0);
        let (key, line, col, _) = err("[inverter_model]\nthreshold_voltage = -0.1\n");
        assert_eq!(
            (key.as_str(), line, col),
            ("inverter_model.threshold_voltage", 2, 21)
        );
        let (key, line, _, _) = err("[inverter_model]\nthreshold_voltage = nan\n");
        assert_eq!(
            (key.as_str(), line),
            ("inverter_model.threshold_voltage", 2)
        );
        let (key, ..) = err("[inverter_model]\ndead_time = 1e-6\n");
        assert_eq!(key, "inverter_model.dead_time");
    }

    /// A baseline's settings are its table `[baselines.<name>]`; errors name the key there,
    /// and a setting in the old flat place is refused with its new one.
    #[test]
    fn baseline_settings_live_in_their_own_tables() {
        let cfg = SimConfig::from_toml(
            "[simulation]\nestimator = \"ortega\"\n[baselines.ortega]\nobserver_speed_ratio = 0.0\n",
        )
        .unwrap();
        assert_eq!(cfg.simulation.estimator.name(), "ortega");
        assert_eq!(
            cfg.baselines["ortega"]["observer_speed_ratio"].as_float(),
            Some(0.0)
        );
        // The other settings of the table keep their defaults (tables merge).
        assert!(cfg.baselines["ortega"].get("observer_bandwidth").is_some());
        assert_eq!(SimConfig::from_toml(&cfg.to_toml()).unwrap(), cfg);
        let (key, line, col, _) = err("[baselines.ortega]\nobserver_bandwidth = -1.0\n");
        assert_eq!(
            (key.as_str(), line, col),
            ("baselines.ortega.observer_bandwidth", 2, 22)
        );
        let (key, line, _, _) = err("[baselines.lpf_integrator]\ncutoff = 1.0\n");
        assert_eq!((key.as_str(), line), ("baselines.lpf_integrator.cutoff", 2));
        let (key, line, _, msg) = err("[baselines]\nlpf_cutoff_hz = 3.0\n");
        assert_eq!((key.as_str(), line), ("baselines.lpf_cutoff_hz", 2));
        assert!(
            msg.contains(
                "a setting of `[baselines.lpf_integrator]`: write it as `cutoff_hz` there"
            ),
            "{msg}"
        );
        let (key, _, _, msg) = err("[baselines.kalman]\ngain = 1.0\n");
        assert_eq!(key, "baselines.kalman");
        assert!(msg.contains("ortega"), "{msg}");
        let (key, line, _, msg) = err("[simulation]\nestimator = \"kalman\"\n");
        assert_eq!((key.as_str(), line), ("simulation.estimator", 2));
        assert!(msg.contains("lpf_integrator"), "{msg}");
        // A machine-model field a baseline refuses is named by the user's own key.
        let e = SimConfig::from_toml("[motor]\nflux_linkage = 0.0\n").unwrap_err();
        assert!(e.key.starts_with("motor."), "{e}");
    }

    #[test]
    fn syntax_errors_are_located() {
        let (key, line, col, msg) = err("[motor]\nrs = 0.3\nlq = = 2\n");
        assert_eq!((key.as_str(), line), ("<file>", 3));
        assert!(col >= 5, "{msg}");
    }

    #[test]
    fn derived_values_are_named_but_not_located() {
        // rs_hat is motor.rs·mismatch.rs_ratio: nothing in the file to point at.
        let e = SimConfig::from_toml("[estimator.limiter]\nk_af = 1e6\n").unwrap_err();
        assert_eq!(e.key, "estimator.limiter.k_af");
        assert_eq!(e.location.map(|l| l.line), Some(2));
        let e = SimConfigError::new("estimator.rs_hat", "x").located_in("[motor]\nrs = 1\n");
        assert_eq!(e.location, None);
        assert_eq!(e.to_string(), "`estimator.rs_hat`: x");
    }
}

/// `--dump-config` shows the acceleration feed-forward, the trackers' load pole and T2S-1's
/// bandwidth as the drive uses them: set by `fado_core::control::tracker_feedforward` on the
/// multirotor preset, whose trackers would lag 2.4 rad at the current limit, and left off on
/// the paper's.
#[test]
fn the_dump_shows_the_feedforward_the_drive_turns_on() {
    let dump = |name: &str| {
        let preset = crate::presets::find(name).unwrap();
        super::SimConfig::from_toml(preset.toml)
            .unwrap()
            .to_toml_annotated()
    };
    let fast = dump("multirotor-mn5006-22v");
    let on =
        "[controller.tracker_feedforward]\nenabled = true  # derived: on where the type-2 T2S-1";
    assert!(fast.contains(on), "{fast}");
    assert!(
        fast.contains("load_pole_ratio = 0.5  # derived: 0.5 with the acceleration"),
        "{fast}"
    );
    assert!(
        fast.contains("  # derived: T2S-1's bandwidth in k_df mode"),
        "{fast}"
    );
    let paper = dump("paper");
    assert!(
        paper.contains("[controller.tracker_feedforward]\nenabled = false\n"),
        "{paper}"
    );
    assert!(paper.contains("load_pole_ratio = 0.0\n"), "{paper}");
}

mod dead_time_method {
    use super::super::*;
    use crate::inverter::InverterModel as Plant;
    use fado_core::control::DeadTimeMethod::{EdgeCurrent, Sign, Trapezoidal};

    #[test]
    fn edge_current_is_the_trapezoid_on_the_ripple_free_averaged_plant() {
        let method = |model: Plant, asked| {
            let mut c = SimConfig::default();
            c.inverter.model = model;
            c.controller.dead_time_compensation.method = asked;
            c.drive_config().tuning.dead_time_compensation.method
        };
        assert_eq!(
            SimConfig::default()
                .drive_config()
                .tuning
                .dead_time_compensation
                .method,
            EdgeCurrent
        );
        assert_eq!(method(Plant::SwitchingResolved, EdgeCurrent), EdgeCurrent);
        assert_eq!(method(Plant::Averaged, EdgeCurrent), Trapezoidal);
        assert_eq!(method(Plant::Averaged, Sign), Sign);
        assert_eq!(method(Plant::SwitchingResolved, Trapezoidal), Trapezoidal);
    }

    #[test]
    fn motor_saturation_is_read_checked_and_written_back() {
        // A whole [motor] (9 lines) with its saturation.
        const M: &str = "[motor]\nrs = 0.327\nld = 2.63e-3\nlq = 2.63e-3\nflux_linkage = 0.088\npole_pairs = 4\nrated_current = 21.78\nrated_speed_rpm = 1500.0\nrated_torque = 11.5\n";
        let text =
            "[motor.saturation]\na_d0 = 380.2\na_q0 = 380.2\npsi_f = 0.088\na_qq = 1e5\nt = 2\n";
        let cfg = SimConfig::from_toml(&format!("{M}{text}")).unwrap();
        let sat = cfg.motor_saturation.unwrap();
        assert_eq!((sat.a_qq, sat.t, sat.psi_f), (1e5, 2.0, 0.088));
        assert!(cfg.plant().magnetics.is_some());
        // --dump-config round trip keeps it.
        let back = SimConfig::from_toml(&cfg.to_toml()).unwrap();
        assert_eq!(back.motor_saturation, cfg.motor_saturation);
        // Without the table the plant keeps its constant inductances.
        assert!(SimConfig::default().plant().magnetics.is_none());
        // Errors name the key and point at it.
        let e = SimConfig::from_toml(&format!(
            "{M}[motor.saturation]\na_d0 = 380.2\na_q0 = -1.0\n"
        ))
        .unwrap_err();
        assert_eq!(e.key, "motor.saturation.a_q0", "{e}");
        assert_eq!(e.location.as_ref().map(|l| l.line), Some(12), "{e}");
        let e = SimConfig::from_toml(&format!(
            "{M}[motor.saturation]\na_d0 = 380.2\na_qqq = 1.0\n"
        ))
        .unwrap_err();
        assert!(e.key.starts_with("motor.saturation"), "{e}");
        assert!(e.to_string().contains("a_qqq"), "{e}");
        let e = SimConfig::from_toml(
            "[motor]\nrs = -1.0\n[motor.saturation]\na_d0 = 1.0\na_q0 = 1.0\n",
        )
        .unwrap_err();
        assert_eq!(e.key, "motor.rs", "{e}");
    }
}

/// A document laid over a machine's derived inverter (`SimConfig::for_machine`, Python's
/// `fado.Machine`) that gives the carrier or the DC link gets the dead time, threshold and
/// current band the same keys derive in a motor file (`fado-sim --config`): the light servo
/// SPM's ratings derive 10 kHz; given 5 kHz its dead time is 2.5 µs, not 10 kHz's 1.25 µs.
#[test]
fn values_derived_over_a_machine_follow_the_document_s_carrier_and_link() {
    use super::SimConfig;
    let motor = "[motor]\nrs = 1.1\nld = 1.5e-3\nlq = 3e-3\nflux_linkage = 0.07\n\
                 pole_pairs = 5\ninertia = 2e-4\nrated_current = 6.0\nrated_speed_rpm = 3000.0\n\
                 rated_torque = 3.1\n";
    let file = |inverter: &str| SimConfig::from_toml(&format!("{motor}[inverter]\n{inverter}"));
    let machine = file("dc_voltage = 320.0\n").unwrap();
    let base = SimConfig::for_machine(&fado_core::MachineModel {
        dc_voltage: 320.0,
        ..machine.motor
    });
    assert_eq!(base.inverter.switching_frequency, 10e3);
    for (given, whole) in [
        (
            "switching_frequency = 5000.0\n",
            "dc_voltage = 320.0\nswitching_frequency = 5000.0\n",
        ),
        ("dc_voltage = 250.0\n", "dc_voltage = 250.0\n"),
    ] {
        let over = SimConfig::from_toml_over(&base, &format!("[inverter]\n{given}")).unwrap();
        let alone = file(whole).unwrap();
        let (a, b) = (&over.inverter, &alone.inverter);
        assert_eq!(
            (
                a.switching_frequency,
                a.dead_time,
                a.threshold_voltage,
                a.current_band
            ),
            (
                b.switching_frequency,
                b.dead_time,
                b.threshold_voltage,
                b.current_band
            ),
            "{given}"
        );
        let derived = |key: &str| over.derived.iter().find(|d| d.key == key).map(|d| d.value);
        assert_eq!(derived("inverter.dead_time"), Some(a.dead_time), "{given}");
    }
    // A document that gives nothing the inverter follows from leaves its values as they are.
    let other = SimConfig::from_toml_over(&base, "[current_sensor]\nseed = 3\n").unwrap();
    assert_eq!(other.inverter.dead_time, base.inverter.dead_time);
}
