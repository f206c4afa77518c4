//! The block configurations have no `Default` (it would be one motor's numbers); their
//! `for_machine` constructors must give the paper's values on the paper's motor and scale with
//! any other motor's model and ratings, and they must build what the estimator and the drive
//! build (both call the same constructors, so the drive's speed and current gains are checked
//! here against the docs/method/estimator.md, "The paper's motor and drive" formulas on both motors).

mod common;

use common::*;
use fado_core::control::{
    CurrentController, CurrentControllerConfig, DeadTimeCompensationConfig, DeadTimeMethod,
    DelayCompensationConfig, DriveTuning, SpeedController, SpeedControllerConfig,
};
use fado_core::flux::{DisturbanceFeedbackConfig, FluxIntegratorConfig, FluxLimiterConfig};
use fado_core::injection::CurrentInjectionConfig;
use fado_core::integrand_offset::IntegrandOffsetConfig;
use fado_core::mode::ModeSelectorConfig;
use fado_core::rs_adaptation::ResistanceAdaptationConfig;
use fado_core::tracker::{BandwidthDefinition, TrackerConfig};
use fado_core::{EstimatorTuning, MachineModel};
use std::f64::consts::{FRAC_1_SQRT_2, TAU};

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

#[test]
fn the_paper_motor_gets_the_paper_values() {
    let m = MachineModel::<f64>::paper();
    // Paper, V and docs/method/estimator.md, "The paper's motor and drive": I_min 4 A, I_max 40 A, ρ = 1.15·0.088 Wb, 1.5 Hz ± 0.2 Hz.
    assert!(close(CurrentInjectionConfig::for_machine(&m).i_min, 4.0));
    assert!(close(
        SpeedControllerConfig::for_machine(&m, TS).i_max,
        40.0
    ));
    assert!(close(
        FluxLimiterConfig::for_machine(&m).radius,
        1.15 * 0.088
    ));
    let mode = ModeSelectorConfig::for_machine(&m);
    assert!(close(mode.threshold_hz, 1.5) && close(mode.hysteresis_hz, 0.2));
    let offset = IntegrandOffsetConfig::for_machine(&m, TS);
    assert!(close(offset.limit, 0.088 * TAU * 1.5));
    assert!(close(offset.settle_time, 5.0 / (TAU * 1.5)));
    let rs = ResistanceAdaptationConfig::for_machine(&m, TS);
    assert!(close(rs.flux_linkage_min_speed, TAU * 4.5));
    assert_eq!(
        (rs.rs_initial, rs.flux_linkage_hat, rs.ld_hat, rs.lq_hat),
        (RS, LF, L, L)
    );
    assert_eq!(FluxIntegratorConfig::for_machine(&m, TS).rs_hat, RS);
    let dt = DeadTimeCompensationConfig::for_machine(&m);
    assert_eq!(
        (dt.dead_time, dt.switching_frequency, dt.method),
        (2.5e-6, 5e3, DeadTimeMethod::EdgeCurrent)
    );
    // Speed PI (docs/method/estimator.md, "The paper's motor and drive"): Kp = Ĵ·ωsc/K̂t per mechanical rad/s = 0.714 A·s/rad.
    let speed = SpeedController::new(SpeedControllerConfig::for_machine(&m, TS)).unwrap();
    assert!((speed.kp() * 4.0 - 0.714).abs() < 1e-3);
}

#[test]
fn every_motor_dependent_value_scales_with_the_motor() {
    let paper = MachineModel::<f64>::paper();
    let ipm = ipmsm_model();
    let (est, drive) = (
        EstimatorTuning::<f64>::default(),
        DriveTuning::<f64>::default(),
    );
    // I_min: the same fraction of each rated current (4/21.78 of 6 A = 1.10 A).
    let i_min = |m: &MachineModel<f64>| CurrentInjectionConfig::for_machine(m).i_min;
    assert!(close(
        i_min(&ipm) / ipm.rated_current,
        i_min(&paper) / paper.rated_current
    ));
    assert!(close(i_min(&ipm), drive.injection.current_ratio * 6.0));
    // Limiter circle and integrand-offset bound follow λ̂f and the rated frequency (75 Hz).
    assert!(close(
        FluxLimiterConfig::for_machine(&ipm).radius,
        1.15 * 0.545
    ));
    let f_th = est.mode.threshold_ratio * 75.0;
    let mode = ModeSelectorConfig::for_machine(&ipm);
    assert!(close(mode.threshold_hz, f_th) && close(mode.threshold_hz, 1.125));
    assert!(close(mode.hysteresis_hz, est.mode.hysteresis_ratio * 75.0));
    let offset = IntegrandOffsetConfig::for_machine(&ipm, TS);
    assert!(close(offset.limit, 0.545 * TAU * f_th));
    assert!(close(offset.settle_time, 5.0 / (TAU * f_th)));
    let rs = ResistanceAdaptationConfig::for_machine(&ipm, 4.0 * TS);
    assert!(close(rs.flux_linkage_min_speed, 3.0 * TAU * f_th));
    assert_eq!(
        (
            rs.ts,
            rs.rs_initial,
            rs.flux_linkage_hat,
            rs.ld_hat,
            rs.lq_hat
        ),
        (4.0 * TS, 3.6, 0.545, 36e-3, 51e-3)
    );
    assert_eq!(FluxIntegratorConfig::for_machine(&ipm, TS).rs_hat, 3.6);
    assert_eq!(
        DeadTimeCompensationConfig::for_machine(&ipm).ripple_inductance,
        fado_core::Dq::new(36e-3, 51e-3)
    );
    // Speed loop: Kp = Ĵ·ωsc/(1.5·p·λ̂f)/p with the IPMSM's J 0.02, p 3, λf 0.545; on this
    // salient rotor with MTPA the limit is the MTPA torque on |i| = I_max in units of the
    // magnet's q current, above I_max.
    let sc = SpeedControllerConfig::for_machine(&ipm, TS);
    let speed = SpeedController::new(sc).unwrap();
    let kp_mech = 0.02 * TAU * drive.speed.bandwidth_hz / (1.5 * 3.0 * 0.545);
    assert!(close(speed.kp() * 3.0, kp_mech));
    let i_max = drive.current.limit_ratio * 6.0;
    assert!(sc.i_max > i_max, "{} against {i_max}", sc.i_max);
    let no_mtpa = SpeedControllerConfig::new(&ipm, i_max, false, TS);
    assert!(close(no_mtpa.i_max, i_max));
    // Current loop (docs/method/estimator.md, "The paper's motor and drive"): Kp,d = L̂d·ωc, Ki = R̂s·ωc from the model.
    let cc = CurrentControllerConfig::for_machine(&ipm, TS);
    assert_eq!((cc.rs_hat, cc.ld_hat, cc.lq_hat), (3.6, 36e-3, 51e-3));
    assert_eq!(cc.flux_linkage_hat, 0.545);
    assert!(CurrentController::new(cc).is_ok());
}

#[test]
fn motor_independent_blocks_take_the_sampling_period_and_the_tuning() {
    let est = EstimatorTuning::<f64>::default();
    for ts in [50e-6, 100e-6, 125e-6] {
        let t = TrackerConfig::new(est.tracker.t2s1_bandwidth_hz, ts);
        assert_eq!(t.ts, ts);
        assert_eq!(t.damping, FRAC_1_SQRT_2);
        assert_eq!(t.definition, BandwidthDefinition::Minus3Db);
        let fb = DisturbanceFeedbackConfig::with_ts(ts);
        assert_eq!(
            (fb.ts, fb.k_df, fb.ramp_time),
            (
                ts,
                est.disturbance_feedback.k_df,
                est.disturbance_feedback.ramp_time
            )
        );
        let d = DelayCompensationConfig::with_ts(ts);
        assert_eq!((d.ts, d.factor), (ts, 1.5));
    }
}
