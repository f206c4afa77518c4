//! Machines entered from public parameter sheets as a user writes them (only the sheet's keys;
//! `tests/data/unseen/*.toml`, each naming its source), of classes the presets cover thinly: a
//! 15 kW PM-assisted synchronous-reluctance motor (Lq/Ld 6.7), a 7 kW 560 V servo, a 42-pole
//! 12S multirotor outrunner with no carrier given (derived 30 kHz) and a 50 W 12 V flat motor
//! with a 13.5 g·cm² rotor. Each passes `reversal`, `stops`, `rated-reversal`, `loaded-start`,
//! `fullrange` and `regen-stop` at the sensor seeds 1 and 2 on its own criteria, and its
//! commissioned `identified.toml` passes `reversal`; the PM-SyRM also on the 520 V link its name
//! suggests (`fullrange`).
//!
//! Measured (seeds 1–4, the largest |θ − θ̂| of each run): servo reversal 0.022, stops 0.054,
//! rated-reversal 0.018–0.020, fullrange 0.063, regen-stop 0.041–0.043 rad (a round rotor: its
//! loaded start ends with the drive's no-angle status at seeds 1, 2, 4); PMSRM 0.013–0.016,
//! 0.084–0.086, 0.010–0.012, loaded-start 0.056–0.069, 0.062–0.064, 0.055–0.067 rad; U8
//! 0.010–0.020, 0.016–0.071, 0.007–0.019, 0.067–0.187, 0.089–0.090, 0.108–0.115 rad; the flat
//! motor 0.008–0.024, 0.027 (stops), loaded-start 0.074 at seed 2 (seed 1 below). Identified
//! models' reversal: 0.031 / 0.009 / 0.102 / 0.071 rad.
//!
//! Four more classes, each at seed 1 only (CI time): a 46-pole 48 V direct-drive e-bike hub
//! (every scenario; seeds 1–2: reversal 0.016–0.030, stops 0.059–0.104, rated-reversal
//! 0.012–0.051, loaded-start 0.066–0.081, fullrange 0.073–0.074, regen-stop 0.089 rad; its
//! identified model's reversal 0.054, stops 0.100 rad) and a 10-pole 20 kW IPMSM on a 560 V
//! link (reversal 0.025–0.034, stops 0.038–0.054, rated-reversal 0.028–0.029, loaded-start
//! 0.159 at seed 1; identified reversal 0.031, stops 0.030 rad) pass, and so does a 42-pole
//! 48 V robot-joint motor (a resistive drop 0.71 × its rated back-EMF) in `reversal`, `stops`,
//! `loaded-start`, `fullrange` and `regen-stop` at seeds 1 and 2, and the IPMSM in its run down
//! from its 6500 r/min top (`fullrange`, `regen-stop`); a 14-pole gimbal motor (1.9 ×)
//! commissions (Ĵ −0.6 %, λ̂f +0.9 % at seed 1) and misses its low-speed scenarios, in the
//! ignored tests below with their figures. The 7.2 kW servo with a
//! 3e-3 kg·m² rotor commissions (its flux pulses bounded by their back-EMF,
//! `fado_core::commissioning`).

use fado_core::commissioning::Status;
use fado_sim::commission::{commission_on_own_nameplate, identified_toml};
use fado_sim::scenario::simulate;

mod unseen_common;
use unseen_common::{SCENARIOS, file};

/// `scenario` on machine `name` with the current sensors' noise `seed`: whether it met its
/// criteria, printed with its checks.
fn passes(name: &str, scenario: &str, seed: u64) -> bool {
    let text = format!("{}\n[current_sensor]\nseed = {seed}\n", file(name));
    let out = simulate(scenario, Some(&text), false, None).unwrap();
    if !out.passed {
        eprintln!("{name} {scenario} seed {seed}: {:?}", out.checks);
    }
    out.passed
}

/// Every scenario at seeds 1 and 2 but those `skip`ped; the misses listed together.
fn every_scenario(name: &str, skip: &[(&str, u64)]) {
    let mut missed = Vec::new();
    for scenario in SCENARIOS {
        for seed in [1, 2] {
            if !skip.contains(&(scenario, seed)) && !passes(name, scenario, seed) {
                missed.push(format!("{scenario} seed {seed}"));
            }
        }
    }
    assert!(missed.is_empty(), "{name} missed: {missed:?}");
}

/// `commission` on the plant of the configuration `text`, told its own record; then
/// `reversal` on the `identified.toml` it writes, which must pass. The identification.
fn commissioned_text(name: &str, text: &str) -> fado_core::commissioning::Identification<f64> {
    let plant = fado_sim::SimConfig::from_toml(text).unwrap().plant();
    let o = commission_on_own_nameplate(&plant).unwrap();
    assert_eq!(o.status, Status::Done, "{name}");
    let id = o.identification.unwrap();
    let identified = identified_toml(text, &id).unwrap();
    let r = simulate("reversal", Some(&identified), false, None).unwrap();
    eprintln!(
        "{name}: identified reversal {:.3} rad near zero speed",
        r.metrics.max_angle_error_zero_speed
    );
    assert!(r.passed, "{name}: {:?}", r.checks);
    id
}

/// [`commissioned_text`] on `name`'s file.
fn commissioned_reversal(name: &str) {
    commissioned_text(name, &file(name));
}

#[test]
fn a_15_kw_pm_syrm_from_its_parameter_sheet_passes_every_scenario() {
    every_scenario("pmsrm-15kw-520v", &[]);
    commissioned_reversal("pmsrm-15kw-520v");
}

#[test]
fn a_7_kw_560_v_servo_from_its_data_sheet_passes_every_scenario() {
    every_scenario("servo-6sm107s-3000", &[]);
    commissioned_reversal("servo-6sm107s-3000");
}

#[test]
fn a_42_pole_12s_outrunner_with_a_derived_carrier_passes_every_scenario() {
    every_scenario("tmotor-u8-kv150-12s", &[]);
    commissioned_reversal("tmotor-u8-kv150-12s");
}

/// Its loaded start at seed 1 is [`a_50_w_flat_motor_seed_1_holds_its_angle_after_release`].
#[test]
fn a_50_w_12_v_flat_motor_passes_every_scenario() {
    every_scenario("maxon-ec45flat-50w-12v", &[("loaded-start", 1)]);
    commissioned_reversal("maxon-ec45flat-50w-12v");
}

/// The flat motor's loaded start at seed 1 (a 13.5 g·cm² rotor under its rated 0.087 N·m,
/// mechanical time constant of the load alone 4.5 ms; start angle 0.74 rad). Along its d axis
/// phase b carries 0.217 of the gain calibration's current and the k measured there misses
/// the 5 % plausibility bound (`Implausible`): the sensors' 0.5 % mismatch, uncalibrated,
/// walks θ̂ from the rotor after the release (0.344 rad from ready). The brake holds the
/// rotor, so the calibration turns to π/3, across which this round rotor drives nothing
/// (`fado_core::control::startup`, `gain_axis`). Measured: 0.242 rad back, max |θ − θ̂| from
/// ready 0.095 rad; seed 2 0.235 / 0.074 rad.
#[test]
fn a_50_w_flat_motor_seed_1_holds_its_angle_after_release() {
    assert!(passes("maxon-ec45flat-50w-12v", "loaded-start", 1));
}

/// `scenarios` at seed 1 on machine `name`, the misses listed together.
fn at_seed_1(name: &str, scenarios: &[&str]) {
    let missed: Vec<_> = scenarios.iter().filter(|s| !passes(name, s, 1)).collect();
    assert!(missed.is_empty(), "{name} missed: {missed:?}");
}

#[test]
fn a_46_pole_48_v_e_bike_hub_passes_every_scenario() {
    at_seed_1("ebike-hub-dd-23pp-48v", &SCENARIOS);
    commissioned_reversal("ebike-hub-dd-23pp-48v");
}

#[test]
fn a_20_kw_ipmsm_on_a_560_v_link_passes_its_low_speed_scenarios() {
    at_seed_1(
        "ipmsm-20kw-10p-560v",
        &["reversal", "stops", "rated-reversal", "loaded-start"],
    );
    commissioned_reversal("ipmsm-20kw-10p-560v");
}

/// The 7.2 kW 6SM107S servo with a 3e-3 kg·m² rotor (its nameplate's inertia): full-length
/// flux pulses turn it 0.118 rad per pair with a back-EMF 0.41 of the pulse voltage at the
/// pair's peak speed, swing it between ±300 r/min and trip at 41 A (OverCurrent in
/// `Magnetics`). Bounded by the back-EMF (`EMF_LIMIT`) the pairs turn it 0.064 rad
/// (2e-3 / 5e-3 kg·m²: 0.061 / 0.073 rad), Ĵ within 0.2 % and L̂d, L̂q within 0.4 %.
/// The 20 kW IPMSM's loaded start at seed 2 (start angle −1.66 rad): the d axis leaves phase
/// a at 0.087 of the current and the nearest k·π/3 axis would drive 26 % of the level across
/// this Lq/Ld = 2 rotor, so the start-up calibrates the sensors' gain along the held rotor's
/// q axis. Measured: 0.309 rad back, max |θ − θ̂| from ready 0.146 rad (uncalibrated: θ̂
/// walks to 0.18 rad after the release hold's hand-over and the rotor rolls back 0.81 rad).
#[test]
fn a_20_kw_ipmsm_lifts_its_load_from_a_start_angle_that_starves_a_phase() {
    assert!(passes("ipmsm-20kw-10p-560v", "loaded-start", 2));
}

#[test]
fn a_7_kw_servo_with_a_light_rotor_is_commissioned() {
    let text = file("servo-6sm107s-3000").replace("[motor]\n", "[motor]\ninertia = 3e-3\n");
    let id = commissioned_text("servo-6sm107s-3000 at 3e-3 kg·m²", &text);
    let j = id.model.inertia;
    assert!((j / 3e-3 - 1.0).abs() < 0.05, "Ĵ {j}");
}

/// The 20 kW IPMSM's runs down from its 6500 r/min top through zero speed: `fullrange`
/// 0.090 / 0.090 rad, `regen-stop` 0.054 / 0.072 rad (seeds 1 / 2). At its top its 10 poles
/// turn 0.13 rad per sample of its derived 13 kHz carrier (ω·Ts); the turning R̂s law's
/// active flux takes î_d from the current sampled with λ̂r (`fado_core::rs_adaptation`, "Sampled at ω̂·Ts"): from the
/// drop current, half a sample behind, R̂s would settle (L̂q − L̂d)·ω²·Ts/2 high and the
/// zero-speed passage would lose 0.93 rad (`fullrange`) and 0.87 rad (`regen-stop`).
#[test]
fn a_20_kw_ipmsm_runs_down_from_its_top_speed() {
    at_seed_1("ipmsm-20kw-10p-560v", &["fullrange", "regen-stop"]);
}

/// A 42-pole robot-joint motor (GL80 KV30, Rs·I/(ω·λf) 0.71) on 48 V: `reversal` 0.051 /
/// 0.018, `stops` 0.092 / 0.067, `loaded-start` 0.072 / 0.073 rad (seeds 1 / 2; rated-reversal
/// 0.027 / 0.243). Its low-speed angle rests on R̂s·i: the start-up calibration of the current
/// sensors' gains removes the 0.5 % mismatch whose negative-sequence drop walks θ̂ at
/// ≈ 1.5 rad/s under 65 % of its rated torque (uncalibrated: `reversal` 0.32–0.33, `stops`
/// 0.93–0.95 rad); its rotor's swing (2J/c = 0.26 s) is held for the calibration's 0.2 s
/// budget and averaged over a 0.10 s window (`fado_core::control::drive::DriveConfig::
/// gain_calibration_config`).
#[test]
fn a_42_pole_robot_joint_motor_passes_its_low_speed_scenarios() {
    let name = "robot-joint-gl80-kv30-48v";
    let mut missed = Vec::new();
    for scenario in ["reversal", "stops", "loaded-start"] {
        for seed in [1, 2] {
            if !passes(name, scenario, seed) {
                missed.push(format!("{scenario} seed {seed}"));
            }
        }
    }
    assert!(missed.is_empty(), "{name} missed: {missed:?}");
}

/// The robot-joint motor through its whole range: `fullrange` 0.067 / 0.066 rad, `regen-stop`
/// 0.085 / 0.079 rad (seeds 1 / 2), both largest at the loaded zero-speed hold after a run at
/// speed. This winding tolerates 0.3 % of Rs·I of drop error near zero speed
/// (`fado_core::machine_checks::low_speed_limit`), and at 1000 r/min its 5 kHz carrier samples
/// 0.22 rad of rotation (ω·Ts): the turning R̂s law takes its active flux's î_d from the
/// current sampled with λ̂r, so R̂s stays within 0.15 % of the 1.13 Ω there (at most 1.1317 Ω;
/// taken from the interval's drop current, half a sample behind, î_d would be off by
/// i_q·ω·Ts/2, R̂s would settle (L̂q − L̂d)·ω²·Ts/2 above Rs, at 1.173 Ω, and the hold would
/// turn θ̂ by 0.68–0.71 rad; `fado_core::rs_adaptation`, "Sampled at ω̂·Ts").
#[test]
fn a_42_pole_robot_joint_motor_holds_zero_speed_after_its_top_speed() {
    let name = "robot-joint-gl80-kv30-48v";
    let mut missed = Vec::new();
    for scenario in ["fullrange", "regen-stop"] {
        for seed in [1, 2] {
            if !passes(name, scenario, seed) {
                missed.push(format!("{scenario} seed {seed}"));
            }
        }
    }
    assert!(missed.is_empty(), "{name} missed: {missed:?}");
}

/// A 14-pole gimbal motor (GBM5208-200T, 8.5 Ω, Rs·I/(ω·λf) 1.9) on 4S: reversal 0.31–1.58,
/// stops 0.49–0.58, rated-reversal 1.30–1.31 rad, fullrange π off (seeds 1, 2); its loaded
/// start ends with the no-angle status. The miss is the current sensors' 0.5 % gain mismatch,
/// which its start-up calibration leaves (`TooSlow`: the rotor's swing, 2J/c = 0.56 s, needs
/// a 0.9 s window after the 0.2 s hold at the least observable axis, 0.50 s at its 0.3 rad
/// start, against the 0.2 s budget; with a 1 s budget it ends `RotorMoved`, at 0.78 s at seed
/// 1 and 0.11 s at seed 2, its motion threshold 0.5 % of 100 r/min, and `reversal` reads
/// 0.58 / 0.73 rad): with the gains calibrated (`startup.rotor_held`)
/// `reversal` is 0.014 / 0.092 rad, with matched sensors 0.016 / 0.023 rad. The drive's
/// online gain tracker (`fado_core::control::gain_tracking`) runs on it (R̂s·I/λ̂f 138/s) but
/// learns only from 12/τ = 120 rad/s electrical, above its rated 100 r/min (73 rad/s):
/// `reversal` 0.81 / 0.74, `stops` 0.60 / 0.49, `rated-reversal` 1.31 / 1.31 rad, the first
/// two the same with the tracker off. A 0.3 % voltage
/// error costs 0.25 rad below 2.3 % of its rated speed, beyond the scenarios' 2 % band; the
/// plausibility warning on `rs` says so (`fado_core::machine_checks::low_speed_limit`). Its
/// commissioning: the test below.
#[test]
#[ignore = "gimbal motor with a resistive drop 1.9 × its back-EMF: 0.3-1.6 rad reversal"]
fn a_14_pole_gimbal_motor_passes_its_low_speed_scenarios() {
    at_seed_1("gimbal-gbm5208-200t-4s", &["reversal", "stops"]);
}

/// The gimbal motor commissions (seed 1): Ĵ within the 10 % and λ̂f within the 2 % the
/// presets are held to. Its inertia test's torque steps hold the coast's d current (its
/// R̂s·I, 2.1 V, exceeds the 0.45 V back-EMF at its 20 r/min spin speed): with the steps
/// at zero d current the PLL's angle swung 0.2 rad at 13–40 r/min and the step up ended at
/// 18 r/min read as 40; and no speed check or step end lies within the 30 ms of the PLL's
/// transient after a torque step (38 then −10 r/min at a 13 r/min coast). Measured, seeds
/// 1 / 2 / 3: Ĵ −0.58 / +1.10 / +1.68 %, λ̂f +0.87 / +0.78 / +0.85 %, B̂ +5 / −24 / −30 %,
/// 11.7–11.8 s simulated.
#[test]
fn the_gimbal_motor_commissions() {
    let name = "gimbal-gbm5208-200t-4s";
    let plant = fado_sim::SimConfig::from_toml(&file(name)).unwrap().plant();
    let o = commission_on_own_nameplate(&plant).unwrap();
    assert_eq!(o.status, Status::Done, "{name}");
    let m = o.identification.unwrap().model;
    let j = m.inertia / plant.motor.inertia - 1.0;
    let flux = m.flux_linkage / plant.motor.flux_linkage - 1.0;
    eprintln!("{name}: J {:+.2} %, λf {:+.2} %", 100.0 * j, 100.0 * flux);
    assert!(j.abs() < 0.10, "{name}: J {j:+.4}");
    assert!(flux.abs() < 0.02, "{name}: λf {flux:+.4}");
}

/// The gimbal motor with its current sensors calibrated: told that a brake holds the rotor
/// through the start-up (`[controller.startup] rotor_held`, each calibration level held for
/// the current's settling alone), it passes `reversal` (0.014 / 0.092 rad near zero speed) at
/// seeds 1 / 2 with its rotor free: the method holds its angle through a reversal on a winding
/// whose drop is 1.9 × its back-EMF once the sensors' gains are matched. Its `stops` reach
/// 0.166 / 0.264 rad over the run (0.25 allowed; seed 2 misses).
#[test]
fn the_gimbal_motor_with_calibrated_sensors_passes_its_reversal() {
    let name = "gimbal-gbm5208-200t-4s";
    let mut missed = Vec::new();
    for seed in [1, 2] {
        let text = format!(
            "{}\n[current_sensor]\nseed = {seed}\n[controller.startup]\nrotor_held = true\n",
            file(name)
        );
        let out = simulate("reversal", Some(&text), false, None).unwrap();
        if !out.passed {
            missed.push(format!("reversal seed {seed}: {:?}", out.checks));
        }
    }
    assert!(missed.is_empty(), "{name} missed: {missed:?}");
}

/// The gimbal motor's configuration is run with the warning on `rs` that names its ratio,
/// the keys and the speed (2.3 % of rated) below which its low-speed angle is beyond the
/// criterion.
#[test]
fn the_gimbal_motor_is_warned_of_its_low_speed_limit() {
    let text = file("gimbal-gbm5208-200t-4s");
    let config = fado_sim::SimConfig::from_toml(&text).unwrap();
    let plant = config.plant();
    let m = plant.motor.with_dc_voltage(plant.inverter.dc_voltage);
    let warning = fado_core::machine_checks::check(&m, None)
        .iter()
        .find(|f| f.key() == "rs")
        .map(|f| f.to_string())
        .expect("a warning on rs");
    for part in ["1.876", "`rated_current`", "below 2.3 % of the rated speed"] {
        assert!(warning.contains(part), "{part}: {warning}");
    }
}

/// The 15 kW PM-SyRM on the 520 V link its name suggests (its sheet's 500 V rms line-to-line
/// is a 707 V link): the rated point on MTPA needs 421 V phase peak of the 300 V the link
/// makes, which the drive reaches by field weakening. At `fullrange`'s top, 4800 r/min (1.6 ×
/// rated, where the model's limits give 8070 W), its d current stops at the current limit
/// (λ̂f/L̂d = 145 A is beyond I_max = 58.9 A), which is no MTPV point: the q current is bounded
/// by the current limit and the voltage ellipse, not cut to the loop's own target
/// (`fado_core::control::field_weakening::FieldWeakening::iq_limit`). Measured: 4800.0 r/min,
/// 0.19 r/min off, 6456 W held (≥ 6327), |θ − θ̂| 0.057 rad; with the cut 4678 r/min, 122 r/min
/// off, 6292 W (i_q 3.3 A where the model's optimum has 3.7 A).
#[test]
fn a_15_kw_pm_syrm_on_a_520_v_link_holds_the_fullrange_top() {
    let text = file("pmsrm-15kw-520v").replace("dc_voltage = 707.0", "dc_voltage = 520.0");
    let out = simulate("fullrange", Some(&text), false, None).unwrap();
    assert!(out.passed, "{:?}", out.checks);
}
