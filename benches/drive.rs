//! Time of one `SensorlessDrive::step` (estimator + speed/current PI + compensations + SVPWM),
//! the whole 10 kHz interrupt's worth of control, in f32 (firmware) and f64.

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use fado::core::control::{DriveConfig, SensorlessDrive};
use fado::core::estimator::EstimatorTuning;
use fado::core::{Ab, Abc, MachineModel, Real};

/// A steady 300 r/min operating point: a 10 A current vector turning at 20 Hz electrical.
fn currents<T: Real>(samples: usize) -> Vec<Abc<T>> {
    (0..samples)
        .map(|n| {
            let th = core::f64::consts::TAU * 20.0 * 100e-6 * n as f64;
            let i = Ab::from_polar(10.0, th + 1.5).to_abc();
            Abc::new(T::lit(i.a), T::lit(i.b), T::lit(i.c))
        })
        .collect()
}

fn bench_step<T: Real>(c: &mut Criterion, name: &str, stall_symptom: bool) {
    let mut config = DriveConfig::for_machine(&MachineModel::paper());
    if !stall_symptom {
        config.tuning.stall.speed_ratio = T::zero();
    }
    let mut drive = SensorlessDrive::<T>::new(config, EstimatorTuning::default())
        .expect("default configuration is valid");
    drive.align(T::zero());
    let input = currents::<T>(5000);
    let (vdc, speed) = (T::lit(300.0), T::lit(31.4));
    // Warm the estimator and the loops into a running state.
    for i in &input {
        drive.step(*i, vdc, speed);
    }
    let mut k = 0;
    c.bench_function(name, |b| {
        b.iter(|| {
            k = (k + 1) % input.len();
            black_box(drive.step(black_box(input[k]), black_box(vdc), black_box(speed)))
        })
    });
}

fn drive_step(c: &mut Criterion) {
    bench_step::<f32>(c, "drive_step_f32", true);
    bench_step::<f64>(c, "drive_step_f64", true);
    // The loss-of-lock stall symptom's share: the same step without it.
    bench_step::<f32>(c, "drive_step_f32_no_stall_symptom", false);
}

criterion_group!(benches, drive_step);
criterion_main!(benches);
