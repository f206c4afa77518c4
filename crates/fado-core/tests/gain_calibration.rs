//! The drive's start-up current-sensor gain calibration through `SensorlessDrive::step`, on a
//! standstill machine (the rotor held: no swing) fed by the drive's own duties: the paper's
//! SPMSM and the 2.2 kW IPMSM. The inverter is ideal and the drive is told so (no dead time,
//! no threshold): its rotor-motion test reads the voltage that acted with the inverter's part
//! from its dead-time model, which must describe the inverter it drives.

mod common;

use fado_core::control::{DriveConfig, GainCalibrationStatus, SensorlessDrive};
use fado_core::{Ab, Abc, EstimatorTuning, MachineModel};

/// Start-up of a drive on `machine` held at `theta0`, phase a read (1 + g) high; returns the
/// drive after its calibrations, the largest true phase current and the samples taken.
fn start_up(machine: MachineModel<f64>, theta0: f64, g: f64) -> (SensorlessDrive<f64>, f64, u32) {
    let mut config = DriveConfig::for_machine(&machine);
    config.tuning.inverter.dead_time = 0.0;
    config.tuning.inverter.threshold_voltage = 0.0;
    let ts = config.ts;
    let vdc = machine.dc_voltage;
    let mut drive = SensorlessDrive::new(config, EstimatorTuning::default()).unwrap();
    drive.align(theta0);
    // Standstill RL machine: along d and q of the rotor at θ0 with L̂d, L̂q (exact steps).
    let (s, c) = theta0.sin_cos();
    let decay = |l: f64| (-machine.rs * ts / l).exp();
    let (ed, eq) = (decay(machine.ld), decay(machine.lq));
    let mut i = Ab::<f64>::zero();
    let mut duty = [Abc::new(0.5, 0.5, 0.5); 2];
    let (mut peak, mut n) = (0.0_f64, 0);
    while (drive.is_calibrating() || drive.is_calibrating_gain()) && n < 100_000 {
        let abc = i.to_abc();
        let a = (1.0 + g) * abc.a;
        let out = drive.step(Abc::new(a, abc.b, -a - abc.b), vdc, 0.0);
        // The duty computed now acts over the next period but one.
        let d = if out.gates_enabled {
            duty[1]
        } else {
            Abc::new(0.5, 0.5, 0.5)
        };
        duty = [out.duty, duty[0]];
        let v = Abc::new(d.a * vdc, d.b * vdc, d.c * vdc).to_ab();
        let (vd, vq) = (v.alpha * c + v.beta * s, -v.alpha * s + v.beta * c);
        let (id, iq) = (i.alpha * c + i.beta * s, -i.alpha * s + i.beta * c);
        let id = id * ed + (1.0 - ed) * vd / machine.rs;
        let iq = iq * eq + (1.0 - eq) * vq / machine.rs;
        i = Ab::new(id * c - iq * s, id * s + iq * c);
        peak = peak.max(
            i.to_abc()
                .a
                .abs()
                .max(i.to_abc().b.abs())
                .max(i.to_abc().c.abs()),
        );
        n += 1;
    }
    (drive, peak, n)
}

#[test]
fn the_drive_measures_and_applies_the_mismatch_on_two_motors() {
    for (name, machine) in [
        ("paper SPMSM", MachineModel::paper()),
        ("2.2 kW IPMSM", common::ipmsm_model()),
    ] {
        for theta0 in [0.0, 0.3, 1.0, 2.0, -2.0] {
            for g in [0.005, -0.02] {
                let (drive, peak, n) = start_up(machine, theta0, g);
                let k = drive.current_gain_ratio();
                println!("{name} θ0 {theta0}: g {g}, k {k:.6}, peak {peak:.2} A, {n} samples");
                assert_eq!(
                    drive.gain_calibration_status(),
                    GainCalibrationStatus::Calibrated,
                    "{name} {theta0}"
                );
                // Ideal plant and sensors: within 2e-5 (the settling and the PWM delay).
                assert!((k - (1.0 + g)).abs() < 2e-5, "{name} {theta0}: {k}");
                // The current stays within the drive's limit and the sequence ends on time.
                assert!(peak <= drive.config().i_max(), "{peak}");
                let budget = 1000 + drive.gain_calibration().duration_samples() + 2;
                assert!(n <= budget, "{n} > {budget}");
                // From then on phase a is divided by k: the drive's α-β current is the true one.
                let mut drive = drive;
                let out = drive.step(
                    Abc::new((1.0 + g) * 2.0, -1.0, -(1.0 + g) * 2.0 + 1.0),
                    311.0,
                    0.0,
                );
                assert!((out.i_ab.alpha - 2.0).abs() < 1e-4, "{:?}", out.i_ab);
            }
        }
    }
}

#[test]
fn at_a_phase_null_the_drive_starts_without_the_calibration() {
    // θ0 = π/2: no current in phase a along the axis.
    let (drive, peak, n) = start_up(MachineModel::paper(), core::f64::consts::FRAC_PI_2, 0.005);
    assert_eq!(
        drive.gain_calibration_status(),
        GainCalibrationStatus::Unobservable
    );
    assert_eq!(drive.current_gain_ratio(), 1.0);
    // The 1000 samples of the offset calibration, then the first sample finds the axis
    // unobservable and runs the drive: no calibration current has flowed.
    assert_eq!((peak, n), (0.0, 1001));
}

#[test]
fn reset_rearms_the_calibration_and_zero_time_disables_it() {
    let (mut drive, _, _) = start_up(MachineModel::paper(), 0.3, 0.005);
    drive.reset();
    assert!(drive.is_calibrating() && drive.is_calibrating_gain());
    // The ratio measured is kept until a new one is.
    assert!((drive.current_gain_ratio() - 1.005).abs() < 2e-5);
    let mut config = DriveConfig::for_machine(&MachineModel::paper());
    config.tuning.gain_calibration.time = 0.0;
    let drive = SensorlessDrive::<f64>::new(config, EstimatorTuning::default()).unwrap();
    assert!(!drive.is_calibrating_gain());
    assert_eq!(drive.gain_calibration_status(), GainCalibrationStatus::Off);
}
