//! Measured report of simulation speed (not a test): the plant alone in both inverter models,
//! the drive alone, and the full fig11 scenario (with metrics, probes and a 1 kHz trace), as simulated seconds per second of wall time and of CPU time
//! (CPU time from /proc/thread-self/schedstat on Linux, robust when the machine is shared).
//!
//! `cargo run --release -p fado-sim --example sim_speed`

use std::time::Instant;

use fado_core::{Abc, Dq};
use fado_sim::inverter::InverterModel;
use fado_sim::sim::{Plant, PlantParams};

fn cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns * 1e-9)
}

fn report(what: &str, simulated: f64, wall: f64, cpu: f64) {
    println!(
        "{what:<40} {:>8.0}× real time (wall)  {:>8.0}× (CPU)  {:>7.0} ns/sample (CPU)",
        simulated / wall,
        simulated / cpu,
        cpu / simulated * 1e-4 * 1e9
    );
}

fn main() {
    for model in [InverterModel::SwitchingResolved, InverterModel::Averaged] {
        let mut p = PlantParams::default();
        p.inverter.model = model;
        let mut plant = Plant::new(&p, 0.3).unwrap();
        plant.motor_mut().set_state(Dq::new(2.0, 10.0), 0.3, 10.0);
        let n = 400_000;
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let mut acc = 0.0;
        // Duties of a 6.4 Hz rotating voltage, precomputed: the loop times the plant only.
        let duties: Vec<Abc<f64>> = (0..1000)
            .map(|k| {
                let th = k as f64 * std::f64::consts::TAU / 1000.0;
                Abc::new(
                    0.5 + 0.1 * th.cos(),
                    0.5 + 0.1 * (th - 2.1).cos(),
                    0.5 + 0.1 * (th + 2.1).cos(),
                )
            })
            .collect();
        for k in 0..n {
            let d = duties[k % 1000];
            let (i, _, _) = plant.measure();
            acc += i.a;
            plant.step(d, true);
        }
        std::hint::black_box(acc);
        let sim = n as f64 * plant.sample_period();
        report(
            &format!("plant only, {model:?}"),
            sim,
            t0.elapsed().as_secs_f64(),
            cpu_seconds() - c0,
        );
    }
    {
        // The drive alone on synthetic 10 A currents at 6 Hz.
        let cfg = fado_sim::scenario::scenario_config("fig11", None, false).unwrap();
        let mut drive = cfg.build_drive().unwrap();
        drive.align(0.3);
        let n = 400_000;
        let currents: Vec<Abc<f64>> = (0..1000)
            .map(|k| {
                let th = k as f64 * std::f64::consts::TAU / 1000.0;
                fado_core::Ab::from_polar(10.0, th).to_abc()
            })
            .collect();
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let mut acc = 0.0;
        for k in 0..n {
            acc += drive.step(currents[k % 1000], 311.0, 1.0).duty.a;
        }
        std::hint::black_box(acc);
        report(
            "drive only (estimator + control)",
            n as f64 * 1e-4,
            t0.elapsed().as_secs_f64(),
            cpu_seconds() - c0,
        );
    }
    for averaged in [false, true] {
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let out = fado_sim::scenario::simulate("fig11", None, averaged, None).unwrap();
        report(
            &format!("fig11 closed loop, averaged = {averaged}"),
            out.stats.simulated_seconds,
            t0.elapsed().as_secs_f64(),
            cpu_seconds() - c0,
        );
    }
}
