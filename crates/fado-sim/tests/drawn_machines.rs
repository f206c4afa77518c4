//! Machines drawn at random by `scripts/drawn-machines.py` (a battery of datasheets nobody gave
//! us: pole pairs 1–24, 12–800 V, 20 W–200 kW, surface and interior magnets, optional
//! saturation), kept in `tests/data/drawn/` where the battery found something.

use fado_core::control::startup::{MIN_AXIS_MARGIN, pulse_current_share};
use fado_sim::scenario::{scenario_config, simulate};

/// The drawn motor file `name` of `tests/data/drawn/`.
fn drawn(name: &str) -> String {
    let path = format!(
        "{}/tests/data/drawn/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(path).unwrap()
}

/// `loaded-start` on `name` at `seed`: its verdict, |θ − θ̂| at the angle found, max |θ − θ̂|
/// from ready and the backward travel (rad).
fn loaded_start(name: &str, seed: u64) -> (bool, f64, f64, f64) {
    let text = format!("{}\n[current_sensor]\nseed = {seed}\n", drawn(name));
    let out = simulate("loaded-start", Some(&text), false, None).unwrap();
    let st = out.probe.start.as_ref().unwrap();
    if !out.passed {
        println!("{name} seed {seed}: {:?}", out.checks);
    }
    let found = st.found_angle_error.unwrap_or(f64::INFINITY);
    (out.passed, found, st.max_angle_error, st.max_backward)
}

/// The drawn IPMSMs whose axes meet at the rated current (the tests below).
const AXES_MEET_AT_RATED: [&str; 3] = [
    "ipm-sat-3p-134v-127w",
    "ipm-sat-12p-170v-1558w",
    "ipm-sat-15p-800v-137kw",
];

#[test]
fn saturated_rotors_whose_axes_meet_at_the_rated_current_find_their_angle_below_it() {
    // The three machines of the test below: the pulse below the rated current finds the angle
    // within 0.05 rad on seeds 1 and 2 (the start's other criteria are the test below's).
    for name in AXES_MEET_AT_RATED {
        let cfg = scenario_config("loaded-start", Some(&drawn(name)), false).unwrap();
        let m = cfg.machine_model();
        assert_eq!(pulse_current_share(&m, m.rated_current), 0.75, "{name}");
        for seed in [1, 2] {
            let (_, found, _, _) = loaded_start(name, seed);
            assert!(found < 0.05, "{name} seed {seed}: found {found} rad off");
        }
    }
}

#[test]
fn saturated_rotors_whose_axes_meet_at_the_rated_current_pulse_below_it() {
    // Three drawn IPMSMs whose q axis saturates down to the d inductance near the rated
    // current: the model's secant inductances along d and q differ by 2.2 % (127 W, 3 pole
    // pairs), 2.1 % (1.6 kW, 12) and 4.8 % (137 kW, 15) of their sum there, below
    // `MIN_AXIS_MARGIN`; at 0.75 of it by 11 %, 11 % and 9 %. Pulsing at the rated current,
    // the 127 W machine found its angle 1.516 / 1.541 rad off at seeds 1 / 2 (the axis π/2
    // off) and ran 70 / 77 rad backwards under its load; the 137 kW one 0.071 rad at seed 1.
    // Measured at 0.75 of the rated current: found within 0.003–0.013 rad, max |θ − θ̂| from
    // ready 0.044–0.123 rad, backward travel 0.20–0.50 rad (the 127 W machine's seed 2
    // 0.498: its fall reads half its load and the hold's damping stiffens past half its design
    // travel, `fado_core::control::release_hold`; with the fall's stiffness alone 0.584).
    for name in AXES_MEET_AT_RATED {
        let cfg = scenario_config("loaded-start", Some(&drawn(name)), false).unwrap();
        let m = cfg.machine_model();
        let share = pulse_current_share(&m, m.rated_current);
        assert_eq!(
            share, 0.75,
            "{name}: margin below {MIN_AXIS_MARGIN} at I_rated"
        );
        for seed in [1, 2] {
            let (passed, found, max_error, backward) = loaded_start(name, seed);
            println!(
                "{name} seed {seed}: found {found:.3}, max {max_error:.3}, back {backward:.3} rad"
            );
            assert!(found < 0.05, "{name} seed {seed}: found {found} rad off");
            assert!(passed, "{name} seed {seed}");
        }
    }
}

/// The drawn 137 kW IPMSM (2,650 kg·m²) under its rated torque at `loaded-start` seeds 3 and
/// 4: its fall reaches the release hold's trigger late (29 ms after the release at seed 4),
/// when the speed loop already carries 307 A of the load's ≈ 280 A, and the hold starts its
/// integral from the speed loop's (`fado_core::control::release_hold`, `watch.rs`). Measured
/// (backward travel / max |θ − θ̂| from ready, rad): 0.282 / 0.082 and 0.342 / 0.050; the hold
/// started from zero dropped the torque to 14 A in a sample, 0.355 / 0.068 and 0.708 / 0.147.
#[test]
fn a_heavy_saturated_rotor_keeps_the_torque_its_speed_loop_carries_at_the_trigger() {
    let name = "ipm-sat-15p-800v-137kw";
    for seed in [3, 4] {
        let (passed, _, max_error, backward) = loaded_start(name, seed);
        println!("{name} seed {seed}: max {max_error:.3}, back {backward:.3} rad");
        assert!(
            passed,
            "{name} seed {seed}: back {backward}, max {max_error}"
        );
    }
}

#[test]
fn a_saturated_rotor_with_clear_axes_pulses_at_the_rated_current() {
    // The drawn 69 W IPMSM (Lq/Ld 2, q secant 44 % down at the rated current): the secant
    // inductances differ by 22 % of their sum at the rated current, which the search keeps.
    let cfg = scenario_config("loaded-start", Some(&drawn("ipm-sat-15p-47v-69w")), false).unwrap();
    let m = cfg.machine_model();
    assert_eq!(pulse_current_share(&m, m.rated_current), 1.0);
}

#[test]
fn a_release_shortly_before_the_speed_ramp_hands_a_settled_hold_over() {
    // Three drawn IPMSMs (draw seed 4), one linear and two saturating, whose start-up reports
    // ready at sensor seed 2 only 25, 74 and 109 ms before `loaded-start`'s ramp leaves zero
    // at 1.0 s (and a fourth, draw seed 5, 26.5 kW, 18 pole pairs, 58 ms at sensor seed 1;
    // its seed 2, ready at 1.025 s on the moving reference, is held as the brake released on
    // a moving reference below: 0.190 rad back, 0.388 with the hold disarmed at the release):
    // the brake opens at ready, the release hold catches the rated load, and the reference
    // leaves zero before the hold has acted 10/ω_h. Handing over its integral
    // then (13 of the 24 A the 9.7 kW machine's load needs), the rotors ran back 14.5 rad
    // (9.7 kW, 5 pole pairs; |θ − θ̂| 0.79 rad from ready, R̂s learned +2.9 % in the slow
    // backward run), 1.49 rad (6.8 kW, 2) and 0.56 rad (138 kW, 17). Held on until the speed
    // loop can take the rest (`release_hold::HANDOVER_TRAVEL_RATIO`): 0.249, 0.237 and
    // 0.196 rad back, |θ − θ̂| from ready 0.084, 0.061 and 0.047 rad; the 26.5 kW machine
    // 0.556 → 0.194 rad. Seed 1 of the first three (ready 0.17–0.30 s before the ramp)
    // passes either way: 0.24, 0.16, 0.20 rad.
    for name in [
        "ipm-5p-760v-9724w",
        "ipm-sat-2p-800v-6787w",
        "ipm-sat-17p-800v-138kw",
        "ipm-18p-800v-26543w",
    ] {
        for seed in [1, 2] {
            let (passed, _, max_error, backward) = loaded_start(name, seed);
            println!("{name} seed {seed}: max {max_error:.3}, back {backward:.3} rad");
            assert!(passed, "{name} seed {seed}: {backward} rad back");
        }
    }
}

#[test]
fn a_brake_released_on_a_moving_reference_is_held_against_the_fall() {
    // A drawn 24 kW IPMSM (draw seed 32: 6 pole pairs, 1.01 kg·m², 361 N·m rated) whose
    // start-up reports ready at 1.041 / 1.078 s (sensor seeds 1 / 2), after `loaded-start`'s
    // ramp has left zero at 1.0 s: the brake opens on a moving reference. A hold armed at the
    // release and disarmed by that reference leaves the rated load to the speed loop alone,
    // and the rotor runs back 8.45 / 8.18 rad (|θ − θ̂| 0.178 rad from ready). Kept armed for
    // a fall against the reference, as a hold armed at the start-up's end is, it holds the
    // fall as a motion: 0.229 / 0.204 rad back, |θ − θ̂| 0.070 / 0.041 rad from ready. The
    // same machine released on a ramp that starts at 1.5 s runs 0.227 rad back (seed 1).
    for seed in [1, 2] {
        let (passed, _, max_error, backward) = loaded_start("ipm-6p-800v-24077w", seed);
        println!("seed {seed}: max {max_error:.3}, back {backward:.3} rad");
        assert!(passed, "seed {seed}: {backward} rad back, max {max_error}");
    }
}

/// A drawn 497 W IPMSM (draw seed 202: 3 pole pairs, 6.2·10⁻⁶ kg·m², saturating), whose
/// release hold acts through the loaded standstill (`fado_core::control::release_hold`,
/// `standstill.rs`). At sensor seed 1 θ − θ̂ creeps to 0.10 rad over the standstill, and the
/// standstill probe's d current, on when `loaded-start`'s reference leaves zero, takes 1 % of
/// the rated torque with it as it goes: handed over at the reference, the rotor ran back
/// 0.956 rad under the 5.2 Hz speed loop. Held through the probe's exit: 0.177 rad back (the
/// release's catch), |θ − θ̂| from ready 0.112 rad; seed 2 0.214 / 0.076 rad either way.
#[test]
fn a_light_rotor_is_held_through_the_probes_exit() {
    for seed in [1, 2] {
        let (passed, _, max_error, backward) = loaded_start("ipm-sat-3p-201v-497w", seed);
        println!("seed {seed}: max {max_error:.3}, back {backward:.3} rad");
        assert!(passed, "seed {seed}: {backward} rad back, max {max_error}");
    }
}

/// The drawn 69 W, 15-pole-pair IPMSM (6 kHz carrier, q secant 44 % down at the rated
/// current, 47 V link) and the drawn 289 W 2-pole saturating surface-magnet motor (35 kHz),
/// held at zero speed under the rated load after the brake's release: max |θ − θ̂| from ready
/// 0.068 / 0.079 rad (69 W, seeds 1 / 2), 0.107 rad (289 W, seed 2). The same machines
/// without `[motor.saturation]` give 0.046 / 0.053 rad.
///
/// What this holds is the estimator's ripple correction (`fado_core::ripple`). The PWM
/// ripple on a current map that curves (q self-saturation with a d-axis or cross-saturation
/// term) makes the sampling interval's mean current exceed the sample taken at the carrier's
/// peak and valley by δi ≈ ½·∂²i/∂ψ²·cov(ψ ripple), a second-order term of one sign (a
/// constant inductance gives only a first-order one that alternates between the half periods
/// and cancels), plus two first-order terms that do not cancel: the ripple's own resistive
/// drop (as large as the curvature's term on these machines) and the dead time's lead (the
/// pulses lag their gates by Td/2; the opposite sign, −10 to −11.5 mA on the 69 W machine).
/// The machine drops R·i_mean; a flux integration that subtracts R·i_sample integrates R·δi at
/// zero speed. Measured on the 69 W machine, seed 1, with the half periods' mean current
/// integrated in the plant (Simpson's rule on 16 slices of every switch interval): 6.7–8.7 mA
/// along q at the hold (16.6–20.2 mA with no dead time), R·δi_q ≈ 6.8 mV, the back-EMF of
/// 1.3 rad/s; without the correction the estimate stays at zero speed while the rotor turns
/// backwards at 2.47 rad/s and the test gives 0.450 / 0.539 rad (69 W) and 0.392 rad (289 W).
/// Sensors reading the mean current instead of the sample give 0.107 / 0.113 rad on the 69 W
/// machine: the correction from the duties and the model does as well as measuring the mean.
#[test]
fn saturated_rotors_hold_the_rated_load_at_standstill() {
    for (name, seed) in [
        ("ipm-sat-15p-47v-69w", 1),
        ("ipm-sat-15p-47v-69w", 2),
        ("spm-sat-1p-147v-289w", 2),
    ] {
        let (passed, _, max_error, _) = loaded_start(name, seed);
        println!("{name} seed {seed}: max {max_error:.3} rad");
        assert!(
            passed && max_error < 0.25,
            "{name} seed {seed}: {max_error}"
        );
    }
}

/// The drawn 192 kW IPMSM of the tests below (draw seed 33: 9 pole pairs, q secant
/// saturating, 6 kHz carrier, 1275 kg·m² with its coupled load, τm = Ĵ·Ω_rated/T_rated = 3.8 s)
/// at `scenario` on sensor `seed`, its speed loop at `speed_hz` (the tuning's 5 Hz where
/// None): the outcome and the largest |i_q*| (A).
fn heavy_saturated_rotor(scenario: &str, seed: u64, speed_hz: Option<f64>) -> (bool, f64, f64) {
    let mut text = format!(
        "{}\n[current_sensor]\nseed = {seed}\n",
        drawn("ipm-sat-9p-800v-192kw")
    );
    if let Some(hz) = speed_hz {
        text += &format!("\n[controller.speed]\nbandwidth_hz = {hz}\n");
    }
    let out = simulate(scenario, Some(&text), false, None).unwrap();
    let iq_ref = out.trace.column("i_q_ref").unwrap();
    let peak = iq_ref.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    println!(
        "{scenario} seed {seed} at {speed_hz:?} Hz: max |θ − θ̂| {:.3} rad, max |i_q*| {peak:.0} A, {:?}",
        out.metrics.max_angle_error, out.checks
    );
    (out.passed, out.metrics.max_angle_error, peak)
}

/// The 192 kW IPMSM at `stops` (4 % of its 204 r/min under 65 % of its rated torque) with the
/// speed loop at its 5 Hz. Its speed PI, Kp = Ĵ·ωs/(K̂t·p) = 342 A per electrical rad/s on
/// this rotor, answers any motion of θ̂ with current: a loop that bypasses the rotor, whose
/// gain grows with Ĵ. Fed exact signals (a locked rotor, a voltage-limited current loop),
/// the estimator does not move θ̂ with i_q: a step to ±910 A moves it by 0.007 rad for a few
/// milliseconds (the secant L̂q one sample late), on the model and with the current held in
/// the estimated frame alike. What moves it is a flux error: 0.036 Wb across the d axis
/// turns θ̂ by 0.021 rad at i_q = 0 and 0.060 rad at ±910 A (κ falls with the current).
///
/// Such an error comes from the dead-time compensation. Evaluated at the reference current,
/// it crosses a phase's zero about one time constant of the current loop before the current
/// does when i_q* reverses, and the estimator integrates 2·V̂ for that time. With the
/// compensation at the reference alone (`DeadTimeCompensation::phase_voltages`), i_q*
/// swings between the current-vector limits (±910 A at i_d* = −395 A) at about 16 Hz from
/// the start-up's hand-over, each reversal adds 0.02–0.05 Wb to λ1 − ψ (0.23 Wb by 0.6 s),
/// θ̂ follows, and the rotor is lost: max
/// |θ − θ̂| 0.690 / 3.142 / 3.141 / 3.141 rad (seeds 1–4), i_q* at 95 % of its limit in 32 /
/// 17 % of the run (seeds 1 / 2); `loaded-start` seed 2 1.70 rad. The same plant without dead
/// time passes (0.046 rad, |i_q*| within 505 A, seed 2). The compensation takes the measured
/// current where the reference has run ahead of the current across a phase's band
/// (`DeadTimeCompensation::phase_voltages_followed`): 0.112 / 0.126 / 0.109 / 0.111 rad
/// (seeds 1–4), i_q* at its limit in 0.5 / 0.4 % of the run (the load's acceleration at
/// 6.9 s); `loaded-start` 0.082 / 0.192 / 0.063 / 0.068 rad, `reversal` 0.035–0.047 rad.
#[test]
fn a_heavy_saturated_rotor_holds_its_angle_through_stops() {
    for seed in [1, 2] {
        let (passed, max_error, _) = heavy_saturated_rotor("stops", seed, None);
        assert!(passed && max_error < 0.25, "seed {seed}: {max_error}");
    }
}

/// The 192 kW IPMSM of the test above with its speed loop at 2 Hz: Kp at 0.4 of the tuning's,
/// i_q* stays within 508 A in `stops` (the current-vector limit 910 A) and the angle within
/// 0.047 / 0.045 rad at seeds 1 / 2; `loaded-start` seed 2 0.094 rad (0.192 at 5 Hz). Seeds 3
/// and 4 measured alike: `stops` 0.046 / 0.046 rad, `loaded-start` 0.041 / 0.059 rad,
/// `reversal` (seeds 1–4) 0.082–0.085 rad.
#[test]
fn a_heavy_saturated_rotor_holds_its_angle_with_its_speed_loop_at_2_hz() {
    for seed in [1, 2] {
        let (passed, max_error, peak) = heavy_saturated_rotor("stops", seed, Some(2.0));
        assert!(passed && max_error < 0.25, "stops seed {seed}: {max_error}");
        assert!(peak < 700.0, "stops seed {seed}: |i_q*| reaches {peak} A");
    }
    let (passed, max_error, _) = heavy_saturated_rotor("loaded-start", 2, Some(2.0));
    assert!(
        passed && max_error < 0.25,
        "loaded-start seed 2: {max_error}"
    );
}

/// The 192 kW IPMSM through `rated-reversal` (∓6 % of its 204 r/min in 2 s under its rated torque).
/// Not the torque: the ramp asks 8,890 N·m, the current limit gives 11,900 N·m, and the speed
/// follows the ramp within 1 r/min until 3.6 s, past zero speed. Its frame coupling exceeds 0.5
/// under load, where the saturating R̂s law runs at the prior's rate 1/T_E (5 s⁻¹,
/// `fado_core::rs_adaptation`, "The rate on a saturating model") and reads a frame error as
/// resistance: while the rotor decelerates from −10.7 to −7.4 r/min at the ramp's start (2.62–2.87
/// s) |θ − θ̂| grows from 0.004 to 0.071 rad and R̂s from 0.988 to 1.030 × Rs. Through zero speed
/// ΔR·i then integrates 0.15 Wb across d in 0.7 s, θ̂ moves with i_q (0.14 rad at i_q ≈ 0, 0.24 rad
/// at the current limit), i_q* swings between 0 and the limit at 15 Hz, and the passage ends 0.251
/// / 0.271 rad and 7.3 / 7.5 r/min off at seeds 1 / 2. With the R̂s law off 0.038 / 0.040 rad; with
/// the coupled law frozen below 3 × the Fig. 3 threshold 0.062 / 0.062 rad, but then `stops` on the
/// motulator 60 kW IPMSM (whose 4 % plateau lies below that floor) ends 0.36 rad off on seeds 1–4
/// (0.135 with the law running); at the configured γ instead of the prior's rate the measured
/// PM-SyRM map does not converge from 1.4 × Rs (`saturated_rs_convergence`). A 3 s ramp passes
/// (0.096 / 0.10 rad) but leaves the law's miss in place.
#[test]
#[ignore = "open: the coupled-point R̂s law learns +3 % of Rs while the rotor decelerates towards zero speed (0.251 / 0.271 rad)"]
fn a_heavy_saturated_rotor_reverses_under_its_rated_torque() {
    for seed in [1, 2] {
        let (passed, max_error, _) = heavy_saturated_rotor("rated-reversal", seed, None);
        assert!(passed && max_error < 0.15, "seed {seed}: {max_error}");
    }
}

/// A drawn 116 kW IPMSM (draw seed 202: 2 pole pairs, Lq/Ld 1.30, 25.2 kg·m², 668 N·m rated)
/// whose release hold is slow, ω_h = 8.5 rad/s: the rated load's catch lasts
/// (2 + √2)/ω_h = 0.40 s, the rotor swinging between −8.6 and +7 r/min. The standstill probe
/// armed one period (0.1 s) after the release reads its first period inside that catch; the
/// reading (the acceleration taken out through ω̂, 4.3 A per rad/s² on this rotor) turns θ̂
/// at −0.87 rad/s from 0.93 s, carried past the lift in limiter mode: |θ − θ̂| 0.311 / 0.361
/// rad at seeds 1 / 2 (0.291, 0.240, 0.300, 0.251 at seeds 3–6). Armed after the catch, the
/// probe does not start before the lift at 1.0 s, and the start keeps 0.032 / 0.111 rad
/// (seeds 3–6: 0.029, 0.025, 0.075, 0.036), as with the probe off.
#[test]
fn a_heavy_rotor_is_not_probed_during_the_release_holds_catch() {
    for seed in [1, 2] {
        let (passed, found, max_error, backward) = loaded_start("ipm-2p-800v-115696w", seed);
        println!("seed {seed}: found {found:.3}, max {max_error:.3}, back {backward:.3} rad");
        assert!(passed, "seed {seed}: max {max_error}, back {backward}");
        assert!(max_error < 0.2, "seed {seed}: max |θ − θ̂| {max_error} rad");
    }
}

/// `stops` on the drawn 30 kW surface-magnet machine (draw seed 404: 17 pole pairs, 298 µH,
/// 86.8 mWb, 2.92 kg·m², 21 kHz, 800 V; τm = Ĵ·Ω_rated/T_rated = 6.1 s) at sensor `seed`,
/// `extra` appended to its file: the verdict and max |θ − θ̂| (rad).
fn heavy_surface_magnet_stops(seed: u64, extra: &str) -> (bool, f64) {
    let text = format!(
        "{}\n[current_sensor]\nseed = {seed}\n{extra}",
        drawn("spm-17p-800v-30kw-heavy")
    );
    let out = simulate("stops", Some(&text), false, None).unwrap();
    println!(
        "stops seed {seed} {extra:?}: max |θ − θ̂| {:.3} rad, {:?}",
        out.metrics.max_angle_error, out.checks
    );
    (out.passed, out.metrics.max_angle_error)
}

/// A rotor so heavy that `stops`' ramps (4 % of the rated speed in 0.5 s) take half its rated
/// torque: the stop's deceleration leaves 0.165 of the rated current, at the injection's
/// I_min (0.184), and T2S-2's lag under the ramp (0.41 of the accelerating torque through the
/// speed PI) steps at each ramp's start; the speed PI rings through the injection's corner at
/// 8–10 Hz and `stops` ends 0.309 / 0.314 rad off at seeds 1 / 2 with the paper's type-2
/// trackers. With the acceleration feed-forward the drive turns on for τm above
/// `[controller.tracker_feedforward] heavy_rotor_time` (4 s;
/// `fado_core::control::tracker_feedforward`, "A heavy rotor") it keeps 0.048 / 0.049 rad.
#[test]
fn a_heavy_surface_magnet_rotor_holds_its_angle_through_stops() {
    let paper = "[controller.tracker_feedforward]\nheavy_rotor_time = 1e9\n";
    for seed in [1, 2] {
        let (passed, max_error) = heavy_surface_magnet_stops(seed, "");
        assert!(passed && max_error < 0.1, "seed {seed}: {max_error}");
        let (passed, max_error) = heavy_surface_magnet_stops(seed, paper);
        assert!(
            !passed && max_error > 0.25,
            "paper's trackers, seed {seed}: {max_error}"
        );
    }
}

/// Rotors whose rated load outruns their sampling: the release hold's design
/// (`fado_core::control::release_hold`) needs a current loop of 10·ω_h beyond the cap
/// `MAX_CURRENT_WC_TS`·(1/Ts), and the rated load then moves the rotor by 0.27·a/ω_h² with ω_h
/// a tenth of the capped loop's. The drawn 69 W, 15-pole-pair IPMSM (12 kHz sampling, ω_d =
/// 448 rad/s) and the Estun 400 W servo's bare rotor (`tests/data/unseen/`, 10 kHz, ω_d =
/// 470 rad/s) stay within 1.75 times the 0.2 rad design travel, the share the hold's current
/// rule allows a capped loop: 0.20–0.23 and 0.26–0.31 rad at seeds 1–4 with the loop capped at
/// ωc·Ts = 0.35; at 0.2 they run 0.34–0.38 and 0.44–0.46 rad back.
#[test]
fn rotors_whose_rated_load_outruns_their_sampling_fall_within_the_capped_travel() {
    for (dir, name) in [
        ("drawn", "ipm-sat-15p-47v-69w"),
        ("unseen", "servo-estun-emj04-400w-310v"),
    ] {
        let path = format!(
            "{}/tests/data/{dir}/{name}.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let motor = std::fs::read_to_string(path).unwrap();
        for seed in 1..=4 {
            let text = format!("{motor}\n[current_sensor]\nseed = {seed}\n");
            let out = simulate("loaded-start", Some(&text), false, None).unwrap();
            let back = out.probe.start.as_ref().unwrap().max_backward;
            println!("{name} seed {seed}: back {back:.3} rad");
            assert!(
                out.passed && back < 0.35,
                "{name} seed {seed}: {back} rad back"
            );
        }
    }
}

/// `fullrange` on the drawn 12 kW, 1-pole-pair saturated IPMSM (draw seed 505, 3.2 g·m²) at
/// sensor `seed`: its verdict, max |θ − θ̂| (rad), the rotor's motion before ready (rad) and
/// the gain calibration's status.
fn one_pole_pair_fullrange(seed: u64) -> (bool, f64, f64, Option<String>) {
    let text = format!(
        "{}\n[current_sensor]\nseed = {seed}\n",
        drawn("ipm-sat-1p-800v-12423w")
    );
    let out = simulate("fullrange", Some(&text), false, None).unwrap();
    let st = &out.startup;
    println!(
        "seed {seed}: {} max |θ − θ̂| {:.3} rad, moved {:.3} rad before ready at {:?} s, {:?}",
        out.passed,
        out.metrics.max_angle_error,
        st.motion_before_ready,
        st.ready_time,
        st.gain_calibration
    );
    (
        out.passed,
        out.metrics.max_angle_error,
        st.motion_before_ready,
        st.gain_calibration.clone(),
    )
}

/// `fullrange`'s half rated torque rises over 0.7–1.0 s while the gain calibration's upper
/// level (34 A of d current, the rated current) holds the rotor. The load turns it against the
/// d current's stiffness at 20–30 r/min, a back-EMF of 0.3–0.4 V against the motion test's
/// 1.17 V (0.5 % of the rated speed): measured at seeds 1–4, the rotor sags 0.164–0.165 rad
/// before the release to zero current reads it (`RotorMoved` at 0.78 s), the drive starts
/// from the aligned angle plus the 0.02 rad the release read, and |θ − θ̂| reaches
/// 0.263–0.267 rad. Reading the sag from the level's own back-EMF, summed since its current
/// settled, ends the calibration at 0.745–0.749 s with the rotor 0.053–0.066 rad turned, but
/// the release hold engaged there under the 0.8 N·m the load has reached (of the 9.6 N·m its
/// stiffness is designed for) rings at about 65 Hz, its q current swinging ±25–30 A through
/// zero for 0.15 s, and the rotor creeps forward 0.2–0.3 rad while θ̂ stays: |θ − θ̂|
/// 0.187–0.356 rad, and on the drawn 17 kW 1-pole-pair IPMSM of draw seed 606 0.33–0.39 rad
/// where the later reading passes with 0.246 rad. The same ringing follows the release's
/// `RotorMoved`. With the sum and the hold's design travel at 0.1 or 0.4 rad instead of its
/// 0.2 (`[controller.release_hold] travel`) both machines stay within 0.07–0.16 rad at these
/// seeds. Not met; run with `--ignored`.
#[test]
#[ignore = "a slowly rising load sags the 1-pole-pair rotor on the d current; the hold then rings"]
fn a_slowly_rising_load_on_the_d_current_hold_of_a_one_pole_pair_rotor() {
    for seed in 1..=4 {
        let (passed, max_error, moved, status) = one_pole_pair_fullrange(seed);
        assert_eq!(status.as_deref(), Some("RotorMoved"), "seed {seed}");
        assert!(moved < 0.1, "seed {seed}: moved {moved} rad before ready");
        assert!(passed && max_error < 0.25, "seed {seed}: {max_error}");
    }
}
