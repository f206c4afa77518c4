//! The samples the estimator benchmarks step through (`baselines.rs`, `paired.rs`): one
//! electrical period of an ideal machine at 300 r/min under load, the paper's motor.

use fado_core::{Ab, Dq, EstimatorConfig, MachineModel, Rotation, SensorlessEstimator};

/// Sampling period, s (10 kHz, the paper's).
pub const TS: f64 = 100e-6;
/// 300 r/min, 4 pole pairs: 20 Hz electrical, 500 samples per period.
pub const PERIOD: usize = 500;

/// One electrical period of (v applied over the interval, i sampled at its end), the paper's motor.
pub fn inputs() -> Vec<(Ab<f32>, Ab<f32>)> {
    let (rs, l, lf) = (0.327, 2.63e-3, 0.088);
    let w = core::f64::consts::TAU / (PERIOD as f64 * TS);
    let i_dq = Dq::new(0.0, 10.0);
    let sample = |n: usize| {
        let rot = Rotation::from_angle(w * TS * n as f64);
        (
            Dq::new(lf + l * i_dq.d, l * i_dq.q).to_ab(rot),
            i_dq.to_ab(rot),
        )
    };
    (1..=PERIOD)
        .map(|n| {
            let ((lambda0, i0), (lambda1, i1)) = (sample(n - 1), sample(n));
            let v = (lambda1 - lambda0) * (1.0 / TS) + (i1 + i0) * (0.5 * rs);
            (
                Ab::new(v.alpha as f32, v.beta as f32),
                Ab::new(i1.alpha as f32, i1.beta as f32),
            )
        })
        .collect()
}

/// fado on the paper's motor in `f32`, its configuration changed by `tuning`: `|_| {}` for the
/// default, `|c| c.tuning.rs_adaptation.enabled = false` for the paper's fixed R̂s (compare's
/// `fado-fixed-rs`), `|c| c.tuning = c.tuning.paper_path()` for the paper's path.
pub fn fado(tuning: impl FnOnce(&mut EstimatorConfig<f32>)) -> SensorlessEstimator<f32> {
    let mut config = EstimatorConfig::for_machine(&MachineModel::paper());
    tuning(&mut config);
    SensorlessEstimator::new(config).expect("the paper's motor is a valid configuration")
}
