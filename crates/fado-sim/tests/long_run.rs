//! Long run: one simulated hour with the averaged plant and the f32 drive, (a) at a
//! constant 300 r/min under 7.5 N·m and (b) at 0 r/min under 7.5 N·m. Per simulated minute it
//! records the angle-error statistics and the magnitudes of every integrating state — the flux
//! integrator λ1, the observer's D̂, the trackers' integrators (ω̂ of T2S-1 and T2S-2, as errors
//! against the true speed), the current and speed PI integrals — and the drive's flag counts,
//! then asserts that nothing drifts or grows.
//!
//! Ignored by default (≈ 10 min of CPU per case); `scripts/long-run.sh` runs both in release
//! and prints the tables. `FADO_LONG_RUN_SECONDS` shortens the run (e.g. 120 for a smoke
//! test; the drift comparison then uses the first and last fifth instead of 10 minutes).
//! Results of the committed run: docs/method/additions.md.

use std::fmt::Write as _;

use fado_core::DriveFlags;
use fado_core::control::SensorlessDrive;
use fado_sim::config::Precision;
use fado_sim::controller::Controller;
use fado_sim::drive::DriveF32;
use fado_sim::inverter::InverterModel;
use fado_sim::profile::Profile;
use fado_sim::{SimConfig, scenario_config};

/// Start-up (alignment, offset calibration, acceleration, load ramp) excluded, s.
const SETTLE: f64 = 5.0;
const MINUTE: f64 = 60.0;

/// One simulated minute (or one window of a shortened run).
#[derive(Clone, Debug, Default)]
struct Window {
    start: f64,
    n: u64,
    max_err: f64,
    sum_err: f64,
    sum_sq_err: f64,
    max_speed_err_rpm: f64,
    max_lambda1: f64,
    max_disturbance: f64,
    max_omega1_err: f64,
    max_omega2_err: f64,
    max_current_integral: f64,
    max_speed_integral: f64,
    flags: [u64; DriveFlags::ALL.len()],
}

impl Window {
    fn mean_err(&self) -> f64 {
        self.sum_err / self.n.max(1) as f64
    }
    fn rms_err(&self) -> f64 {
        (self.sum_sq_err / self.n.max(1) as f64).sqrt()
    }
    fn count(&self, flag: DriveFlags) -> u64 {
        self.flags[flag.bits().trailing_zeros() as usize]
    }
}

fn long_config(base: &str, speed_rpm: f64, load_nm: f64, seconds: f64) -> SimConfig {
    let mut cfg = scenario_config(base, None, true).unwrap();
    cfg.inverter.model = InverterModel::Averaged;
    cfg.simulation.precision = Precision::F32;
    cfg.simulation.duration = seconds;
    cfg.simulation.decimation = 1_000_000;
    // From rest (after the 0.1 s offset calibration): to the speed in 1 s, then the load over
    // 0.5 s, then hold.
    cfg.speed_reference = Profile::from_points(&[(0.0, 0.0), (0.2, 0.0), (1.2, speed_rpm)]);
    cfg.load.torque = Profile::from_points(&[(1.5, 0.0), (2.0, load_nm)]);
    cfg.validate().unwrap();
    cfg
}

/// The PI integral magnitudes of a drive: (|current integrals| in V, |speed integral| in A).
trait PiIntegrals {
    fn pi_integrals(&self) -> (f64, f64);
}

impl PiIntegrals for DriveF32 {
    fn pi_integrals(&self) -> (f64, f64) {
        let c = self.0.current_integral();
        (
            (c.d as f64).hypot(c.q as f64),
            (self.0.speed_integral() as f64).abs(),
        )
    }
}

impl PiIntegrals for SensorlessDrive<f64> {
    fn pi_integrals(&self) -> (f64, f64) {
        let c = self.current_integral();
        (c.d.hypot(c.q), self.speed_integral().abs())
    }
}

/// f32 as required by the issue; `FADO_LONG_RUN_PRECISION=f64` runs the f64 drive for
/// comparison.
fn run_hour(name: &str, cfg: &SimConfig) -> Vec<Window> {
    if std::env::var("FADO_LONG_RUN_PRECISION").is_ok_and(|p| p == "f64") {
        run_hour_with(name, cfg, cfg.build_drive().unwrap())
    } else {
        run_hour_with(name, cfg, cfg.build_drive_f32().unwrap())
    }
}

fn run_hour_with<C: Controller + PiIntegrals>(
    name: &str,
    cfg: &SimConfig,
    drive: C,
) -> Vec<Window> {
    let seconds = cfg.simulation.duration;
    let window = if seconds >= 20.0 * MINUTE {
        MINUTE
    } else {
        (seconds / 20.0).max(1.0)
    };
    let mut sim = cfg.simulation(drive).unwrap();
    let n = (seconds / sim.plant().sample_period()).round() as u64;
    let mut windows: Vec<Window> = Vec::new();
    let wall = std::time::Instant::now();
    for _ in 0..n {
        let s = sim.step();
        assert!(
            s.act.estimate.theta.is_finite()
                && s.act.duty.a.is_finite()
                && s.act.estimate.diagnostics.lambda1.is_finite(),
            "{name}: non-finite output at t = {}",
            s.time
        );
        assert!(!s.act.tripped, "{name}: tripped at t = {}", s.time);
        if s.time < SETTLE {
            continue;
        }
        let k = ((s.time - SETTLE) / window) as usize;
        if windows.len() <= k {
            windows.push(Window {
                start: SETTLE + k as f64 * window,
                ..Window::default()
            });
        }
        let w = windows.last_mut().unwrap();
        let d = &s.act.estimate.diagnostics;
        let omega = s.speed_rpm / 60.0 * std::f64::consts::TAU * s.pole_pairs;
        let (current_integral, speed_integral) = sim.controller().pi_integrals();
        w.n += 1;
        w.max_err = w.max_err.max(s.angle_error.abs());
        w.sum_err += s.angle_error;
        w.sum_sq_err += s.angle_error * s.angle_error;
        w.max_speed_err_rpm = w
            .max_speed_err_rpm
            .max((s.speed_ref_rpm - s.speed_rpm).abs());
        w.max_lambda1 = w.max_lambda1.max(d.lambda1.norm());
        w.max_disturbance = w.max_disturbance.max(d.disturbance.norm());
        w.max_omega1_err = w.max_omega1_err.max((s.act.estimate.omega - omega).abs());
        w.max_omega2_err = w
            .max_omega2_err
            .max((s.act.estimate.omega_control - omega).abs());
        w.max_current_integral = w.max_current_integral.max(current_integral);
        w.max_speed_integral = w.max_speed_integral.max(speed_integral);
        for (b, (flag, _)) in DriveFlags::ALL.iter().enumerate() {
            w.flags[b] += s.act.flags.contains(*flag) as u64;
        }
    }
    let wall = wall.elapsed().as_secs_f64();
    println!(
        "{}",
        table(name, &windows, seconds / wall, sim.controller().name())
    );
    windows
}

fn table(name: &str, w: &[Window], rtf: f64, controller: &str) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "\n### {name} ({controller}, averaged plant; {:.0}× real time)\n",
        rtf
    );
    let _ = writeln!(
        t,
        "| t from (s) | max abs(θ−θ̂) (rad) | mean (rad) | rms (rad) | max speed err (r/min) | \
         max abs(λ1) (Wb) | max abs(D̂) (Wb) | max abs(ω̂1−ω) (rad/s) | max abs(ω̂2−ω) (rad/s) | \
         max abs(I_cur) (V) | max abs(I_spd) (A) | sat | cur err | stuck | rejected |"
    );
    let _ = writeln!(t, "|{}", "---|".repeat(15));
    for x in w {
        let _ = writeln!(
            t,
            "| {:.0} | {:.4} | {:+.4} | {:.4} | {:.2} | {:.4} | {:.4} | {:.2} | {:.2} | {:.2} | \
             {:.2} | {} | {} | {} | {} |",
            x.start,
            x.max_err,
            x.mean_err(),
            x.rms_err(),
            x.max_speed_err_rpm,
            x.max_lambda1,
            x.max_disturbance,
            x.max_omega1_err,
            x.max_omega2_err,
            x.max_current_integral,
            x.max_speed_integral,
            x.count(DriveFlags::VOLTAGE_SATURATED),
            x.count(DriveFlags::CURRENT_ERROR),
            x.count(DriveFlags::SENSOR_STUCK),
            x.count(DriveFlags::INPUT_REJECTED),
        );
    }
    t
}

/// The drift verdict: the last part of the run against the first (10 minutes each for the
/// full hour, a fifth of a shortened run).
fn assert_no_drift(name: &str, w: &[Window]) {
    assert!(w.len() >= 5, "{name}: too few windows ({})", w.len());
    let part = (w.len() / 5).clamp(1, 10);
    let (first, last) = (&w[..part], &w[w.len() - part..]);
    let max = |ws: &[Window], f: fn(&Window) -> f64| ws.iter().map(f).fold(0.0, f64::max);
    let mean = |ws: &[Window]| ws.iter().map(Window::mean_err).sum::<f64>() / ws.len() as f64;
    // Angle error: its mean (a slow drift of θ̂) may not move by more than 0.02 rad
    // (≈ 1.1° electrical, a tenth of the fig11 bound of 0.25 rad), and its worst value may not
    // grow by more than 25 % + 0.01 rad (the noise of a max over ~600 000 samples).
    let mut verdicts = Vec::new();
    let mut failed = false;
    let mut check = |label: &str, a: f64, b: f64, ok: bool| {
        failed |= !ok;
        let mark = if ok { "ok  " } else { "FAIL" };
        verdicts.push(format!("{mark} {label}: {a:.4} → {b:.4}"));
    };
    let (m0, m1) = (mean(first), mean(last));
    check("mean θ−θ̂ (rad)", m0, m1, (m1 - m0).abs() < 0.02);
    let (e0, e1) = (max(first, |x| x.max_err), max(last, |x| x.max_err));
    check("max |θ−θ̂| (rad)", e0, e1, e1 <= 1.25 * e0 + 0.01);
    // Integrating states: bounded by what they were at the start, with the same 25 % margin
    // and an absolute floor for states that sit near zero (their noise, not their level).
    for (label, f, floor) in [
        (
            "max |λ1| (Wb)",
            (|x: &Window| x.max_lambda1) as fn(&Window) -> f64,
            1e-3,
        ),
        ("max |D̂| (Wb)", |x| x.max_disturbance, 1e-3),
        ("max |ω̂1 − ω| (rad/s)", |x| x.max_omega1_err, 1.0),
        ("max |ω̂2 − ω| (rad/s)", |x| x.max_omega2_err, 1.0),
        ("max |I_cur| (V)", |x| x.max_current_integral, 0.5),
        ("max |I_spd| (A)", |x| x.max_speed_integral, 0.5),
        ("max speed error (r/min)", |x| x.max_speed_err_rpm, 1.0),
    ] {
        let (a, b) = (max(first, f), max(last, f));
        check(label, a, b, b <= 1.25 * a + floor);
    }
    let report = format!(
        "{name}: first {part} vs last {part} windows\n{}",
        verdicts.join("\n")
    );
    println!("{report}\n");
    assert!(
        !failed,
        "{name}: a drift criterion failed (see the verdicts above)"
    );
}

fn seconds() -> f64 {
    std::env::var("FADO_LONG_RUN_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3600.0)
}

#[test]
#[ignore = "one simulated hour, ≈ 10 min in release: run by scripts/long-run.sh"]
fn long_run_constant_speed_300_rpm_under_7_5_nm() {
    let cfg = long_config("steady300", 300.0, 7.5, seconds());
    let w = run_hour("300 r/min, 7.5 N·m", &cfg);
    assert_no_drift("300 r/min", &w);
}

#[test]
#[ignore = "one simulated hour, ≈ 10 min in release: run by scripts/long-run.sh"]
fn long_run_zero_speed_under_7_5_nm() {
    let cfg = long_config("fig10", 0.0, 7.5, seconds());
    let w = run_hour("0 r/min, 7.5 N·m", &cfg);
    assert_no_drift("0 r/min", &w);
}
