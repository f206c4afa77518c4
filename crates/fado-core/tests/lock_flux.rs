//! The flux-magnitude symptom of the loss-of-lock detector (`fado_core::lock`) on the ideal
//! machine: its lower bound is `lock.flux_low_ratio` (0.7) below the mode hand-over band
//! (`mode.threshold_ratio` − `mode.hysteresis_ratio` = 0.013 of the rated speed) and
//! `lock.flux_low_fast_ratio` (0.6) from there on (docs/method/lock.md, 2026-11-24). The estimator's
//! λ̂f is set to λf / r, so that a locked estimate shows |λ̂r| = r·λ̂f; two motors (the paper's
//! SPMSM and the 2.2 kW IPMSM).

mod common;

use common::*;
use fado_core::estimator::EstimatorTuning;
use fado_core::{Ab, Dq, EstimatorConfig, LockStatus, MachineModel, SensorlessEstimator};

/// The status over the last second of 4 s at a constant `speed_ratio` × rated speed, with
/// λ̂f = λf / `ratio`: whether it was ever lost there, and |λ̂r|/λ̂f at the end. (Below the
/// band, in limiter mode, |λ̂r| swings about r·λ̂f for the first 2–3 s after the alignment at
/// λ̂f; the last second is settled within ±0.02.)
fn lost_at(
    m: Machine,
    model: MachineModel<f64>,
    speed_ratio: f64,
    ratio: f64,
    tuning: impl FnOnce(&mut EstimatorTuning<f64>),
) -> (bool, f64) {
    let mut config = EstimatorConfig::for_machine(&model);
    config.machine.flux_linkage = model.flux_linkage / ratio;
    // The model's ratings agree with its λ̂f (a λ̂f 1.5–2× the rating's, with an even pole
    // count, reads as a pole-count slip to `machine_checks`).
    config.machine.rated_torque = model.rated_torque / ratio;
    config.tuning.rs_adaptation.enabled = false;
    tuning(&mut config.tuning);
    let omega = speed_ratio * model.rated_speed_rpm * m.pp * core::f64::consts::TAU / 60.0;
    let i_dq = Dq::new(0.0, 0.3 * model.rated_current);
    let theta0 = 0.4;
    let mut est = SensorlessEstimator::<f64>::new(EstimatorConfig {
        initial_angle: theta0,
        ..config
    })
    .unwrap();
    let (_, i0) = m.flux_and_current(theta0, i_dq);
    est.align(theta0, i0);
    let n = (4.0 / TS) as usize;
    let (mut lost, mut last) = (false, 0.0);
    for (k, s) in
        machine_profile(m, theta0, n, |_| omega, |_| i_dq, Ab::zero(), Ab::zero()).enumerate()
    {
        let d = est.step(s.v, s.i).diagnostics;
        if k as f64 * TS > 3.0 {
            lost |= d.lock == LockStatus::Lost;
            last = d.lambda_r.norm() / config.machine.flux_linkage;
        }
    }
    (lost, last)
}

#[test]
fn the_lower_flux_bound_is_0_7_below_the_hand_over_band_and_0_6_above() {
    let paper = Machine::PAPER;
    for (m, model) in [
        (paper, MachineModel::paper()),
        (Machine::IPMSM, ipmsm_model()),
    ] {
        // Below the band (0.008 of rated, limiter mode): 0.65·λ̂f is a symptom, 0.75 is not.
        let (lost, r) = lost_at(m, model, 0.008, 0.65, |_| {});
        assert!(
            lost,
            "λf {}: |λ̂r| {r:.3}·λ̂f at 0.008·rated not flagged",
            m.lf
        );
        assert!((r - 0.65).abs() < 0.03, "{r}");
        let (lost, r) = lost_at(m, model, -0.008, 0.75, |_| {});
        assert!(!lost, "λf {}: |λ̂r| {r:.3}·λ̂f at −0.008·rated flagged", m.lf);
        // Above it (0.05 of rated, k_df mode): 0.65·λ̂f is not a symptom, 0.55 is; with the
        // fast bound at the slow one's 0.7 (one bound at every speed, before 2026-11-24),
        // 0.65 is flagged again.
        for speed in [0.05, -0.05] {
            let (lost, r) = lost_at(m, model, speed, 0.65, |_| {});
            assert!(
                !lost,
                "λf {}: |λ̂r| {r:.3}·λ̂f at {speed}·rated flagged",
                m.lf
            );
            assert!((r - 0.65).abs() < 0.03, "{r}");
            let (lost, r) = lost_at(m, model, speed, 0.55, |_| {});
            assert!(
                lost,
                "λf {}: |λ̂r| {r:.3}·λ̂f at {speed}·rated not flagged",
                m.lf
            );
            let (lost, _) = lost_at(m, model, speed, 0.65, |t| {
                t.lock.flux_low_fast_ratio = t.lock.flux_low_ratio
            });
            assert!(lost, "λf {}: one bound, 0.65·λ̂f at {speed}·rated", m.lf);
        }
    }
}
