//! Inputs the fuzzer (fuzz/, scripts/fuzz.sh) found crashing, replayed as plain tests so that
//! CI checks them without nightly. Each test is the decoded case (`cargo fuzz fmt`) of the
//! file of the same name in fuzz/regressions/<target>/, with the fuzz targets' checks: every
//! output finite, θ̂ in [−π, π].

use fado_core::control::{DriveConfig, SensorlessDrive};
use fado_core::estimator::{Estimate, EstimatorConfig, EstimatorTuning, SensorlessEstimator};
use fado_core::{Ab, Abc, MachineModel, Real};

/// The default estimator configuration around the paper's motor.
fn paper<T: Real>() -> EstimatorConfig<T> {
    EstimatorConfig::for_machine(&MachineModel::paper())
}

/// The fuzz targets' output check.
fn check_estimate<T: Real>(e: &Estimate<T>) {
    let d = &e.diagnostics;
    let all = [
        e.theta,
        e.omega,
        e.omega_control,
        d.theta_direct,
        d.lambda1.alpha,
        d.lambda1.beta,
        d.disturbance.alpha,
        d.disturbance.beta,
        d.lambda2.alpha,
        d.lambda2.beta,
        d.lambda_r.alpha,
        d.lambda_r.beta,
    ];
    assert!(
        all.iter().all(|x| x.is_finite()),
        "non-finite output: {e:?}"
    );
    assert!(e.theta.abs() <= T::pi(), "θ̂ out of [−π, π]: {e:?}");
    assert!(d.theta_direct.abs() <= T::pi(), "θm out of [−π, π]: {e:?}");
}

/// fuzz/regressions/estimator_step/huge-initial-angle: a finite but huge `initial_angle`
/// was wrapped by x − 2π·round(x/2π), which has no precision left there: θ̂ = −6e234.
#[test]
fn huge_initial_angle_is_wrapped() {
    for a0 in [-5.727778756618604e250, 9.112e30, f64::MAX] {
        let mut config = paper();
        config.initial_angle = a0;
        config.tuning.observer.on_rotor_flux = false;
        let mut est = SensorlessEstimator::new(config).unwrap();
        check_estimate(&est.last());
        check_estimate(&est.step(Ab::new(1.0, 0.0), Ab::new(0.5, 0.0)));
        est.align(a0, Ab::new(1.0, 2.0));
        check_estimate(&est.last());
    }
    let est = SensorlessEstimator::<f32>::new(EstimatorConfig {
        initial_angle: f32::MAX,
        ..paper()
    })
    .unwrap();
    check_estimate(&est.last());
}

/// fuzz/regressions/drive_step/huge-align-angle: `align(9.1e30)` during the offset
/// calibration, then one sample: the drive reported θ̂ = 1.1e15.
#[test]
fn drive_align_to_a_huge_angle_is_wrapped() {
    let mut config = DriveConfig::for_machine(&MachineModel::paper());
    config.tuning.current.bandwidth_hz = 0.16;
    config.tuning.offset_calibration.time = 219.0 * config.ts; // 219 samples
    let mut drive = SensorlessDrive::new(config, EstimatorTuning::default()).unwrap();
    let w = 2.0 * core::f64::consts::PI * -21.4;
    for k in 0..16 {
        let i = Ab::from_polar(107.0, w * 100e-6 * k as f64).to_abc();
        let out = drive.step(i, 300.0, 0.0);
        check_estimate(&out.estimate);
    }
    drive.align(9112.0 * 1e27);
    let out = drive.step(Abc::new(0.0, 0.0, 0.0), 0.0, 0.0);
    check_estimate(&out.estimate);
}

/// fuzz/regressions/estimator_step/align-current-overflow-f32: f32, L̂q = 69.39 H,
/// `align(2.9e37, i = (2.9e37, 2.9e37))`: λ1 = λ̂f·e^{jθ0} + L̂q·i overflowed to ∞ and the
/// start-up estimate carried it. Such an L̂q is beyond any motor's range and is refused
/// (`fado_core::machine_checks::RANGES`); on a machine inside the ranges the largest f32
/// current still starts a finite estimate.
#[test]
fn align_with_an_overflowing_current_starts_finite() {
    let mut config = paper::<f32>();
    config.machine.lq = 69.39;
    assert_eq!(
        SensorlessEstimator::new(config).err().unwrap().field(),
        "lq"
    );
    let mut config = paper::<f32>();
    config.initial_angle = -6.41;
    config.tuning.integrator.average_current = false;
    config.tuning.observer.on_rotor_flux = false;
    let mut est = SensorlessEstimator::new(config).unwrap();
    let huge = f32::MAX * 0.9;
    est.align(huge, Ab::new(huge, huge));
    check_estimate(&est.last());
    check_estimate(&est.step(Ab::new(huge, huge), Ab::new(0.0, 0.0)));
    check_estimate(&est.step(Ab::zero(), Ab::zero()));
    // A current representable in f64 is used.
    let config = paper::<f64>();
    let lq = config.machine.lq;
    let mut est = SensorlessEstimator::new(config).unwrap();
    est.align(0.0, Ab::new(1e37, 0.0));
    assert!((est.last().diagnostics.lambda1.alpha - lq * 1e37).abs() < 1e-9 * lq * 1e37);
}

/// A λ̂f beyond any motor's range (the fuzzer's 1.26e30 Wb, whose squared limiter and hold
/// circles overflow in f32) is refused naming `flux_linkage`, whether or not the ratings
/// agree with it.
#[test]
fn flux_linkage_too_large_for_the_precision_is_refused() {
    let mut c = paper::<f32>();
    c.machine.flux_linkage = 1.26e30;
    let e = SensorlessEstimator::new(c).err().unwrap();
    assert_eq!(e.field(), "flux_linkage");
    let huge = |lf: f32| {
        let mut c = paper::<f32>();
        c.machine.flux_linkage = lf;
        c.machine.rated_torque = c.machine.torque_constant() * c.machine.rated_current;
        c.machine.dc_voltage = 2.0 * c.machine.rated_speed() * lf;
        c
    };
    for lf in [1.26e30, 1e18] {
        let e = SensorlessEstimator::new(huge(lf)).err().unwrap();
        assert_eq!(e.field(), "flux_linkage", "{lf}");
    }
}

/// fuzz/regressions/baseline_step/align-current-overflow-f32: the reference estimators had
/// the same start-up overflow as `align_with_an_overflowing_current_starts_finite` (found on
/// Ortega–Praly, f32, L̂q = 2.85e37 H).
#[test]
fn baselines_align_with_an_overflowing_current_start_finite() {
    use fado_core::RotorAngleEstimator;
    use fado_core::baselines::{
        EmfObserverConfig, EmfObserverEstimator, LpfIntegratorConfig, LpfIntegratorEstimator,
        OrtegaConfig, OrtegaEstimator,
    };
    fn run<E: RotorAngleEstimator<f32>>(mut e: E) {
        e.align(28527.0 * 1e31, Ab::new(28527.0 * 1e31, 28527.0 * 1e31));
        let out = e.step(Ab::zero(), Ab::zero());
        check_estimate(&out);
        let out = e.step(Ab::new(f32::NAN, 0.0), Ab::zero());
        assert!(out.diagnostics.input_fault);
        check_estimate(&out);
    }
    let lq = 28527.0 * 1e31;
    run(OrtegaEstimator::new(OrtegaConfig {
        settings: fado_core::baselines::OrtegaSettings {
            observer_bandwidth_min: 285.27,
            flux_adaptation_ratio: 28527.0 * 1e31,
            ..Default::default()
        },
        ..OrtegaConfig::for_machine(&MachineModel {
            lq,
            ..MachineModel::paper()
        })
    })
    .unwrap());
    run(
        LpfIntegratorEstimator::new(LpfIntegratorConfig::for_machine(&MachineModel {
            lq,
            ..MachineModel::paper()
        }))
        .unwrap(),
    );
    run(
        EmfObserverEstimator::new(EmfObserverConfig::for_machine(&MachineModel {
            lq,
            ..MachineModel::paper()
        }))
        .unwrap(),
    );
}
