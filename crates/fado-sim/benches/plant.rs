//! Time of one plant sample (sensors + inverter + machine + load) in both inverter models,
//! and of one closed-loop sample of fig11 (plant + drive + probes).

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use fado_core::{Ab, Abc, Dq};
use fado_sim::controller::Controller;
use fado_sim::inverter::InverterModel;
use fado_sim::sim::{Plant, PlantParams, Simulation};

fn bench_plant(c: &mut Criterion) {
    let duties: Vec<Abc<f64>> = (0..1000)
        .map(|k| {
            let th = k as f64 * std::f64::consts::TAU / 1000.0;
            Ab::from_polar(0.1, th).to_abc() + Abc::new(0.5, 0.5, 0.5)
        })
        .collect();
    for (name, model) in [
        (
            "plant sample, switching-resolved",
            InverterModel::SwitchingResolved,
        ),
        ("plant sample, averaged", InverterModel::Averaged),
    ] {
        let mut p = PlantParams::default();
        p.inverter.model = model;
        let mut plant = Plant::new(&p, 0.3).expect("default plant is valid");
        plant.motor_mut().set_state(Dq::new(2.0, 10.0), 0.3, 10.0);
        let mut k = 0;
        c.bench_function(name, |b| {
            b.iter(|| {
                let m = plant.measure();
                plant.step(duties[k % 1000], true);
                k += 1;
                black_box(m)
            })
        });
    }
}

fn bench_closed_loop(c: &mut Criterion) {
    for (name, averaged) in [
        ("fig11 closed-loop sample, switching-resolved", false),
        ("fig11 closed-loop sample, averaged", true),
    ] {
        let cfg = fado_sim::scenario_config("fig11", None, averaged).expect("valid scenario");
        let drive = cfg.build_drive().expect("valid drive");
        let plant = Plant::new(&cfg.plant(), cfg.simulation.initial_angle).expect("valid plant");
        let mut sim =
            Simulation::new(plant, drive, cfg.speed_reference.clone(), 0.0).expect("valid");
        // Run into the loaded reversal (t ≈ 2.5 s) before timing.
        for _ in 0..25_000 {
            sim.step();
        }
        assert!(!sim.controller().name().is_empty());
        c.bench_function(name, |b| b.iter(|| black_box(sim.step())));
    }
}

criterion_group!(benches, bench_plant, bench_closed_loop);
criterion_main!(benches);
