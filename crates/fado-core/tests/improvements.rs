//! Our improvements over the paper's Fig. 5 (each an option with the paper's behaviour
//! available): the disturbance observer fed with λ1 − L̂q·i, and the start-up current-offset
//! calibration of the drive.

use fado_core::control::{DriveConfig, SensorlessDrive};
use fado_core::estimator::EstimatorTuning;
use fado_core::{Ab, Abc, Dq, EstimatorConfig, MachineModel, Rotation, SensorlessEstimator};

/// Open loop at a constant 6 Hz electrical with a rotor-frame current that swings at 5 Hz
/// (the fig8 oscillation): λs = λf·e^{jθ} + L·i, v = dλs/dt + R·i exactly (central
/// difference of the analytic flux). Returns the largest excursion of D̂ about its mean over
/// the second second (whatever constant D̂ settles to is removed from λ1 and λ2 alike).
fn disturbance_excursion(observer_on_rotor_flux: bool) -> f64 {
    let (ts, lf, l, r) = (100e-6, 0.088, 2.63e-3, 0.327);
    let w = 2.0 * std::f64::consts::PI * 6.0;
    let wm = 2.0 * std::f64::consts::PI * 5.0;
    let mut cfg = EstimatorConfig::for_machine(&MachineModel::paper());
    cfg.tuning.observer.on_rotor_flux = observer_on_rotor_flux;
    // The integrand-offset law re-centres D̂ in the k_df mode (a common shift that λ2 and λ̂r
    // do not see), which would show up as a D̂ "excursion" here: off, to compare the observer
    // inputs alone.
    cfg.tuning.offset_adaptation.rate = 0.0;
    let mut est = SensorlessEstimator::new(cfg).unwrap();
    let current = |t: f64| {
        let i_dq = Dq::new(1.3 + 1.0 * (wm * t).sin(), 3.8 + 0.3 * (wm * t).sin());
        i_dq.to_ab(Rotation::from_angle(w * t))
    };
    let flux = |t: f64| Ab::from_polar(lf, w * t) + current(t) * l;
    est.align(0.0, current(0.0));
    // Start the trackers at the right speed: run 1 s, then measure over the next second.
    let mut kept = Vec::new();
    for n in 1..=20_000 {
        let t = n as f64 * ts;
        let (t0, tm) = (t - ts, t - 0.5 * ts);
        let v = (flux(t) - flux(t0)) * (1.0 / ts) + current(tm) * r;
        let out = est.step(v, current(t));
        if t > 1.0 {
            kept.push(out.diagnostics.disturbance);
        }
    }
    let mean = kept.iter().fold(Ab::zero(), |a, &d| a + d) * (1.0 / kept.len() as f64);
    kept.iter().map(|&d| (d - mean).norm()).fold(0.0, f64::max)
}

#[test]
fn observer_on_rotor_flux_ignores_rotor_frame_current_swings() {
    // The paper's observer takes the 5 Hz swing of L·i (at 6 ± 5 Hz in α-β, 1 Hz inside its
    // DC pass band) for a disturbance; on λ1 − L̂q·i there is nothing to take.
    let paper = disturbance_excursion(false);
    let ours = disturbance_excursion(true);
    eprintln!("max |D̂ − mean D̂|: paper {paper:.2e} Wb, λ1 − L̂q·i {ours:.2e} Wb");
    assert!(paper > 5e-4, "the paper's observer should move: {paper}");
    assert!(ours < 0.1 * paper, "ours {ours} vs paper {paper}");
}

#[test]
fn offset_calibration_runs_under_the_zero_vector_then_removes_the_offsets() {
    let mut cfg = DriveConfig::<f64>::for_machine(&MachineModel::paper());
    cfg.tuning.offset_calibration.time = 20e-3; // 200 samples
    let mut drive = SensorlessDrive::new(cfg, EstimatorTuning::default()).unwrap();
    drive.align(0.3);
    let offset = Abc::new(0.02, -0.01, -0.01);
    for k in 0..200 {
        assert!(drive.is_calibrating(), "sample {k}");
        // Alternating ±5 mA noise averages out.
        let n = if k % 2 == 0 { 0.005 } else { -0.005 };
        let out = drive.step(Abc::new(offset.a + n, offset.b - n, offset.c), 300.0, 5.0);
        // The phases shorted through the low-side switches (watched for motion).
        assert!(out.gates_enabled || k == 199, "sample {k}");
        assert!(
            k == 199 || out.duty == Abc::new(0.0, 0.0, 0.0),
            "sample {k}"
        );
    }
    assert!(!drive.is_calibrating());
    let o = drive.current_offset();
    assert!((o.a - offset.a).abs() < 1e-12 && (o.b - offset.b).abs() < 1e-12);
    // Started at the aligned angle; the offset no longer reaches the controllers.
    assert!((drive.last().estimate.theta - 0.3).abs() < 1e-12);
    let out = drive.step(offset, 300.0, 0.0);
    assert!(out.gates_enabled);
    assert!(out.i_dq.d.abs() < 1e-12 && out.i_dq.q.abs() < 1e-12);
}

#[test]
fn offset_calibration_can_be_disabled_and_is_restarted_by_reset() {
    let mut off = DriveConfig::<f64>::for_machine(&MachineModel::paper());
    off.tuning.offset_calibration.time = 0.0;
    let mut drive = SensorlessDrive::new(off, EstimatorTuning::default()).unwrap();
    drive.align(0.0);
    assert!(!drive.is_calibrating());
    assert!(
        drive
            .step(Abc::new(0.0, 0.0, 0.0), 300.0, 0.0)
            .gates_enabled
    );
    let paper = DriveConfig::<f64>::for_machine(&MachineModel::paper());
    let mut drive = SensorlessDrive::new(paper, EstimatorTuning::default()).unwrap();
    assert!(drive.is_calibrating());
    // The default 0.1 s at 10 kHz.
    for _ in 0..1000 {
        drive.step(Abc::new(0.0, 0.0, 0.0), 300.0, 0.0);
    }
    assert!(!drive.is_calibrating());
    drive.reset();
    assert!(drive.is_calibrating());
    // A current above the trip level (60 A on this motor) during the calibration still trips.
    assert!((paper.trip_current() - 60.0).abs() < 1e-9);
    let out = drive.step(Abc::new(70.0, -35.0, -35.0), 300.0, 0.0);
    assert!(out.tripped && !out.gates_enabled);
}
