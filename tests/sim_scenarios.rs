//! The paper's experiments (docs/method/estimator.md, "The experiments") in closed loop: the sensorless drive of fado-core on the
//! simulated plant with the default non-idealities (dead time, device drops, sensor offsets,
//! gain error, noise, ADC), matched model parameters. Each run is a few tenths of a second in
//! release mode, so every scenario runs switching-resolved.
//!
//! Every scenario's SPEC criteria are asserted here; fig8 and fig10, which sit nearest their
//! thresholds, on eight sensor-noise seeds.

use fado::sim::scenario::{Outcome, simulate};

fn run(name: &str, config: Option<&str>, averaged: bool) -> Outcome {
    let out = simulate(name, config, averaged, None).expect("valid scenario");
    let r = out.report();
    eprintln!(
        "{name} (averaged = {averaged}): max |θ−θ̂| {:.3} rad, near zero {:.3} rad, \
         speed error {:.1} r/min, tripped {}, checks {:?}",
        r.max_angle_error,
        r.max_angle_error_zero_speed,
        r.max_speed_error_rpm,
        r.tripped,
        r.checks
            .iter()
            .map(|c| (c.name.as_str(), c.value, c.passed))
            .collect::<Vec<_>>()
    );
    out
}

const IDEAL_CURRENT_SENSORS: &str = "[current_sensor]\nenable_offset = false\n\
    enable_gain_error = false\nenable_noise = false\nenable_quantization = false\n";

#[test]
fn fig11_reversal_under_7_5_nm_keeps_the_angle_within_0_25_rad_switching_resolved() {
    let out = run("fig11", None, false);
    assert!(out.passed, "{:?}", out.checks);
    assert!(!out.metrics.tripped);
    assert!(out.metrics.max_angle_error_zero_speed < 0.25);
    // The crossing really happened under load: time spent below 30 r/min ≈ 0.67 s.
    assert!(out.metrics.zero_speed_samples > 5_000);
}

#[test]
fn fig11_averaged_model_passes_and_agrees_with_the_switching_resolved_one() {
    let sw = run("fig11", None, false);
    let avg = run("fig11", None, true);
    assert!(avg.passed, "{:?}", avg.checks);
    let d = (sw.metrics.max_angle_error_zero_speed - avg.metrics.max_angle_error_zero_speed).abs();
    assert!(d < 0.03, "models differ by {d} rad near zero speed");
}

#[test]
fn fig11_passes_with_the_drive_in_single_precision() {
    let f64_run = run("fig11", None, false);
    let f32_run = run("fig11", Some("[simulation]\nprecision = \"f32\"\n"), false);
    assert!(f32_run.passed, "{:?}", f32_run.checks);
    let d = (f64_run.metrics.max_angle_error_zero_speed
        - f32_run.metrics.max_angle_error_zero_speed)
        .abs();
    assert!(d < 0.02, "f32 and f64 drives differ by {d} rad");
}

#[test]
fn fig9_kdf_off_drifts_then_recovers_with_the_2_s_time_constant() {
    let out = run("fig9", None, false);
    assert!(out.passed, "{:?}", out.checks);
}

#[test]
fn fig12_repeated_stops_under_7_5_nm_stay_within_0_25_rad() {
    let out = run("fig12", None, false);
    assert!(out.passed, "{:?}", out.checks);
}

#[test]
fn fig10_no_load_standstill_holds_with_ideal_current_sensors() {
    let out = run("fig10", Some(IDEAL_CURRENT_SENSORS), false);
    assert!(out.passed, "{:?}", out.checks);
}

#[test]
fn fig10_sensor_offset_walks_the_estimate_along_the_limiter_circle_at_e_t_over_rho() {
    // With only the 20 mA / −10 mA offsets, the integrand error at standstill is the constant
    // e = −R̂s·offset_ab (α-β). Inside the limiter (flux at the circle ρ = 1.15·λ̂f) its radial
    // part is pulled back, its tangential part turns λ̂r — and θ̂ — at e_t/ρ relative to the
    // rotor. Check that rate over the last two seconds of the hold. The disturbance observer,
    // still running at the tiny ω̂ of the creeping estimate, absorbs part of the error, so the
    // measured walk is somewhat slower than e_t/ρ (≈ 0.75× here); sign and size must agree.
    // The start-up offset calibration is off here: it is what removes this walk (below); so is
    // the gain calibration (its later start changes the hold this measures). This
    // checks the paper's limiter, so without our R̂s adaptation (whose standstill law pulls
    // |λ̂r| to λ̂f instead of the circle) and with the paper's observer input ω̂1 (our
    // `observer.lag_compensation` feeds the observer T2S-1's proportional term as well; checked
    // at the end that it does not speed the walk up).
    let paper = "[current_sensor]\nenable_gain_error = false\nenable_noise = false\n\
               enable_quantization = false\n[controller.offset_calibration]\ntime = 0.0\n\
               [controller.gain_calibration]\ntime = 0.0\n[estimator.rs_adaptation]\nenabled = false\n";
    let cfg = format!("{paper}[estimator.observer]\nlag_compensation = false\n");
    let out = run("fig10", Some(&cfg), false);
    let c = &out.config;
    let rs_hat = c.estimator_config().machine.rs;
    let rho = c.estimator.limiter.radius_ratio * c.estimator_config().machine.flux_linkage;
    let rated = c.motor.rated_current;
    let (oa, ob) = (
        c.current_sensor.offset_a_ratio * rated,
        c.current_sensor.offset_b_ratio * rated,
    );
    // Clarke of (a, b, −a−b): α = a, β = (a + 2b)/√3.
    let e = (-rs_hat * oa, -rs_hat * (oa + 2.0 * ob) / 3f64.sqrt());
    let rows: Vec<_> = out.trace.rows.iter().filter(|r| r.time >= 3.5).collect();
    assert!(
        rows.iter().all(|r| r.flag_limit == 1),
        "limiter mode throughout the hold"
    );
    let (first, last) = (rows[0], rows[rows.len() - 1]);
    let dt = last.time - first.time;
    let measured = fado::core::wrap_angle(last.angle_error - first.angle_error) / dt;
    let predicted = -rows
        .iter()
        .map(|r| {
            let phi = r.lambda_r_beta.atan2(r.lambda_r_alpha);
            (-e.0 * phi.sin() + e.1 * phi.cos()) / rho
        })
        .sum::<f64>()
        / rows.len() as f64;
    eprintln!("d(θ − θ̂)/dt: measured {measured:.4} rad/s, predicted {predicted:.4} rad/s");
    assert!(
        predicted.abs() > 0.02,
        "the offset must produce a visible walk"
    );
    let ratio = measured / predicted;
    assert!(
        (0.6..=1.1).contains(&ratio),
        "measured {measured}, predicted {predicted}"
    );
    // With the default start-up calibration (100 ms, gates off) the same offsets leave no
    // walk worth the name.
    let cfg = "[current_sensor]\nenable_gain_error = false\nenable_noise = false\n\
               enable_quantization = false\n[estimator.rs_adaptation]\nenabled = false\n";
    let cal = run("fig10", Some(cfg), false);
    let rows: Vec<_> = cal.trace.rows.iter().filter(|r| r.time >= 3.5).collect();
    let (first, last) = (rows[0], rows[rows.len() - 1]);
    let walk =
        fado::core::wrap_angle(last.angle_error - first.angle_error) / (last.time - first.time);
    eprintln!("with calibration: d(θ − θ̂)/dt = {walk:.4} rad/s");
    assert!(walk.abs() < 0.2 * predicted.abs(), "{walk} vs {predicted}");
    // Uncalibrated again, with the lag compensation (the default). Its walk, as the
    // least-squares slope of θ − θ̂ over the last 1.5 s (after the hold's transients): 0.91×
    // the paper input's with the trapezoidal dead-time compensation, 0.99× with the
    // edge-current one. The end-point difference from 3.5 s read 0.07×
    // only because a stop transient (−0.06 → −0.38 → −0.34 rad) ended there:
    // the compensation does not slow this walk; it must not speed it up.
    let comp = run("fig10", Some(paper), false);
    let rows: Vec<_> = comp.trace.rows.iter().filter(|r| r.time >= 4.0).collect();
    let n = rows.len() as f64;
    let t_mean = rows.iter().map(|r| r.time).sum::<f64>() / n;
    let (mut e_prev, mut e_acc, mut unwrapped) = (rows[0].angle_error, 0.0, Vec::new());
    for r in &rows {
        e_acc += fado::core::wrap_angle(r.angle_error - e_prev);
        e_prev = r.angle_error;
        unwrapped.push(e_acc);
    }
    let e_mean = unwrapped.iter().sum::<f64>() / n;
    let (sxy, sxx) = rows
        .iter()
        .zip(&unwrapped)
        .fold((0.0, 0.0), |(a, b), (r, e)| {
            let dt = r.time - t_mean;
            (a + dt * (e - e_mean), b + dt * dt)
        });
    let walk = sxy / sxx;
    eprintln!("with lag compensation: d(θ − θ̂)/dt = {walk:.4} rad/s");
    assert!(walk.abs() < 1.1 * measured.abs(), "{walk} vs {measured}");
}

#[test]
fn fig8_lambda2_is_centred_in_steady_state() {
    // In the steady −90 r/min stretch at the end, λ2 − λs averages to < 0.5 % of λf over each
    // electrical revolution; D̂ carries the DC of λ1.
    let out = run("fig8", None, false);
    assert!(!out.metrics.tripped);
    let lf = out.config.motor.flux_linkage;
    let tail: Vec<_> = out
        .probe
        .revolutions
        .iter()
        .filter(|(t, _)| *t > 5.5)
        .collect();
    assert!(tail.len() >= 4);
    for (t, dc) in tail {
        assert!(
            *dc < 0.005 * lf,
            "revolution ending at {t:.2} s: DC {dc:.2e} Wb"
        );
    }
}

/// The configuration of sensor-noise seed `seed` with every other setting at its default.
fn seed(seed: u64) -> String {
    format!("[current_sensor]\nseed = {seed}\n")
}

#[test]
fn fig8_paper_criterion_on_eight_sensor_seeds() {
    // fig8 < 2 % on seeds 1–8 (the worst revolution's DC of λ2 − λs over λf). It
    // failed on 2–3 of 8 seeds (2.03–2.23 %) until the observer's speed input carried
    // T2S-1's proportional term (`observer.lag_compensation`): 0.29–0.72 % measured since.
    for s in 1..=8 {
        let out = run("fig8", Some(&seed(s)), false);
        assert!(out.passed, "seed {s}: {:?}", out.checks);
    }
}

#[test]
fn fig10_paper_criterion_on_eight_sensor_seeds_and_the_0_25_rad_bound() {
    // the method's 0.35 rad [A] and fado's tighter 0.25 rad, seeds 1–8 (measured 0.059–0.062).
    for s in 1..=8 {
        let out = run("fig10", Some(&seed(s)), false);
        assert!(out.passed, "seed {s}: {:?}", out.checks);
        assert!(
            out.metrics.max_angle_error < 0.25,
            "seed {s}: {}",
            out.metrics.max_angle_error
        );
    }
}

#[test]
fn integrator_and_emf_baselines_lose_the_angle_at_the_loaded_reversal_where_fado_keeps_it() {
    // The same drive, plant and profile with the estimator swapped (fado_core::baselines): the
    // compensated LPF cannot integrate near zero frequency and the EMF observer has nothing
    // to measure there, so both lose the angle crossing zero under 7.5 N·m: beyond twice the
    // 0.25 rad criterion (measured 1.23 and 0.86 rad, fado 0.009 rad).
    let fado = run("fig11", None, false);
    assert!(fado.metrics.max_angle_error_zero_speed < 0.25);
    for kind in ["lpf_integrator", "emf_observer"] {
        let cfg = format!("[simulation]\nestimator = \"{kind}\"\n");
        let out = run("fig11", Some(&cfg), false);
        assert_eq!(out.report().estimator, out.config.simulation.estimator);
        assert!(!out.passed, "{kind} passed fig11");
        assert!(
            out.metrics.max_angle_error > 0.5,
            "{kind}: {}",
            out.metrics.max_angle_error
        );
    }
    let e = fado::sim::simulate(
        "fig11",
        Some("[simulation]\nestimator = \"ortega\"\nprecision = \"f32\"\n"),
        false,
        None,
    )
    .unwrap_err();
    assert_eq!(e.key, "simulation.estimator");
}

#[test]
fn a_trip_disables_the_gates_and_the_machine_coasts_on_its_diodes() {
    // A failed phase-a sensor reading 70 A trips the drive (60 A) at the first sample; the
    // inverter's diodes block (the line back-EMF stays below Vdc), the currents stay zero, and
    // the load torque drives the shaft backwards.
    // 70 A of the paper's 21.78 A rated current.
    let cfg = "[current_sensor]\noffset_a_ratio = 3.2139\nenable_quantization = false\n\
               [simulation]\nduration = 1.5\n";
    let out = run("fig11", Some(cfg), false);
    assert!(out.metrics.tripped);
    assert!(!out.passed);
    let last = out.trace.rows.last().unwrap();
    assert_eq!(last.tripped, 1);
    assert!(
        last.i_d_true.abs() < 1e-9 && last.i_q_true.abs() < 1e-9,
        "{last:?}"
    );
    // Load torque 7.5 N·m with no drive torque: the shaft is driven negative.
    assert!(last.speed_rpm < -100.0, "{}", last.speed_rpm);
}

#[test]
fn fig9_without_its_kdf_window_reports_instead_of_panicking() {
    let out = run(
        "fig9",
        Some("[simulation]\ndisturbance_feedback_off = []\nduration = 3.0\n"),
        true,
    );
    assert!(!out.passed);
    assert!(
        out.checks
            .iter()
            .any(|c| c.name == "k_df-off windows configured" && !c.passed)
    );
}
