//! Tests of [`super`]: the phase's status transitions on rotors at rest whose magnetics are
//! the flux-linkage model of [`crate::magnetics`] (the saturation of `initial_angle`'s tests),
//! behind a drive's one-sample computation delay.

use super::*;
use crate::control::gain_calibration::GainCalibration;
use crate::control::initial_angle::tests::machine;
use crate::magnetics::{MagneticModel, Saturation};
use crate::{Dq, Rotation};

const TS: f64 = 1e-4;

/// The phase on `model` at rest at `theta` (Rs `r`, DC link `vdc`) until it ends; returns the
/// phase and the statuses it went through (each once, in order).
fn run(
    mut search: AngleSearch<f64>,
    model: &Saturation<f64>,
    r: f64,
    theta: f64,
    vdc: f64,
) -> (AngleSearch<f64>, std::vec::Vec<StartupStatus>) {
    search.arm();
    let rot = Rotation::from_angle(theta);
    let mut psi = model.flux(Dq::zero());
    let mut i = Dq::zero();
    let mut pending = Ab::zero();
    let mut seen = std::vec::Vec::new();
    for _ in 0..200_000 {
        let v = pending.to_dq(rot);
        let command = search.step(i.to_ab(rot), Ab::zero(), vdc);
        if seen.last() != Some(&search.status()) {
            seen.push(search.status());
        }
        pending = match command {
            StartupCommand::Voltage(v) => v,
            StartupCommand::Align { .. } => Ab::zero(),
            StartupCommand::Start(_) | StartupCommand::Off | StartupCommand::Restart => break,
        };
        psi = Dq::new(psi.d + (v.d - r * i.d) * TS, psi.q + (v.q - r * i.q) * TS);
        i = model.current_from(psi, i);
    }
    (search, seen)
}

fn phase(ld: f64, lq: f64, rated: f64, tuning: StartupTuning<f64>) -> AngleSearch<f64> {
    let machine = MachineModel {
        ld,
        lq,
        rated_current: rated,
        ..MachineModel::paper()
    };
    AngleSearch::new(tuning, &machine, TS).unwrap()
}

fn on() -> StartupTuning<f64> {
    StartupTuning {
        find_angle: true,
        ..StartupTuning::default()
    }
}

#[test]
fn a_saturating_surface_magnet_rotor_is_found_and_the_drive_starts_from_it() {
    let m = machine(2.63e-3, 2.63e-3, 0.088, 0.01);
    for theta in [0.74, -1.49, 2.57, 0.33] {
        let (s, seen) = run(
            phase(2.63e-3, 2.63e-3, 21.78, on()),
            &m,
            0.327,
            theta,
            300.0,
        );
        assert_eq!(
            seen,
            [StartupStatus::Searching, StartupStatus::Found],
            "{theta}"
        );
        let e = crate::wrap_angle(s.angle() - theta).abs();
        assert!(e < 0.1, "θ {theta}: {} ({e})", s.angle());
        assert!(!s.active());
    }
}

#[test]
fn an_axis_without_polarity_goes_to_the_polarity_test_which_resolves_it() {
    // The 2.2 kW IPMSM with a fifth of the assumed saturation: the search's first harmonic
    // is below its threshold, the polarity test's larger current shows it.
    let m = machine(0.036, 0.051, 0.545, 0.002);
    for theta in [0.74, -1.49, 2.57] {
        let (s, seen) = run(phase(0.036, 0.051, 6.08, on()), &m, 3.6, theta, 540.0);
        let e = crate::wrap_angle(s.angle() - theta).abs();
        assert_eq!(
            seen,
            [
                StartupStatus::Searching,
                StartupStatus::TestingPolarity,
                StartupStatus::Found
            ],
            "θ {theta}: {:?} contrast {}",
            s.detection(),
            s.polarity_contrast()
        );
        assert!(e < 0.05, "θ {theta}: {} ({e})", s.angle());
    }
}

#[test]
fn a_linear_salient_rotor_ends_axis_only_and_the_drive_stays_off() {
    let m = machine(0.036, 0.051, 0.545, 0.0);
    let (s, seen) = run(phase(0.036, 0.051, 6.08, on()), &m, 3.6, 0.74, 540.0);
    let off = StartupStatus::NoAngle(InitialAngleStatus::AxisOnly);
    assert_eq!(
        seen,
        [
            StartupStatus::Searching,
            StartupStatus::TestingPolarity,
            off
        ]
    );
    assert!(
        s.polarity_contrast().abs() < 0.01,
        "{}",
        s.polarity_contrast()
    );
    assert!(s.active(), "the drive stays off");
    assert!(s.angle().is_nan());
}

#[test]
fn a_linear_surface_magnet_rotor_says_so_and_is_aligned_only_when_free() {
    let m = machine(2.63e-3, 2.63e-3, 0.088, 0.0);
    let (s, seen) = run(phase(2.63e-3, 2.63e-3, 21.78, on()), &m, 0.327, 0.74, 300.0);
    let off = StartupStatus::NoAngle(InitialAngleStatus::NoInformation);
    assert_eq!(seen, [StartupStatus::Searching, off]);
    assert!(s.active() && s.angle().is_nan());
    let free = StartupTuning {
        free_rotor_align: true,
        ..on()
    };
    let (s, seen) = run(phase(2.63e-3, 2.63e-3, 21.78, free), &m, 0.327, 0.74, 300.0);
    let expected = [
        StartupStatus::Searching,
        StartupStatus::Aligning,
        StartupStatus::Found,
    ];
    assert_eq!(seen, expected);
    assert!((s.angle() - core::f64::consts::FRAC_PI_2).abs() < 1e-12);
}

#[test]
fn off_by_default_and_bad_settings_are_named() {
    let mut s = phase(2.63e-3, 2.63e-3, 21.78, StartupTuning::default());
    s.arm();
    assert!(!s.active());
    assert_eq!(s.status(), StartupStatus::Idle);
    let bad = StartupTuning {
        pulse_voltage_ratio: 1.5,
        ..on()
    };
    let machine = MachineModel::paper();
    let e = AngleSearch::new(bad, &machine, TS).unwrap_err();
    assert_eq!(e.field(), "startup.pulse_voltage_ratio");
}

/// The start-up of a rotor a brake holds (`startup.rotor_held`), as [`phase`] otherwise.
fn held_phase(ld: f64, lq: f64, rated_current: f64) -> AngleSearch<f64> {
    phase(
        ld,
        lq,
        rated_current,
        StartupTuning {
            rotor_held: true,
            ..on()
        },
    )
}

#[test]
fn a_held_rotor_gets_the_nearest_well_observed_gain_axis_and_a_free_one_its_d_axis() {
    let free = phase(2.63e-3, 2.63e-3, 21.78, on());
    let held = held_phase(2.63e-3, 2.63e-3, 21.78);
    let third = core::f64::consts::FRAC_PI_3;
    // −1.49 rad leaves phase a 8 % of the current: the held rotor's axis is −π/2 ± π/6's
    // nearest multiple of π/3, −π/3; 0.74 rad is observed (22 %), and this round rotor, which
    // drives nothing across a turned axis, still turns to π/3 (every phase at half or more).
    assert_eq!(free.gain_axis(-1.49, 0.2), -1.49);
    assert_eq!(free.gain_axis(0.74, 0.2), 0.74);
    assert!((held.gain_axis(-1.49, 0.2) + third).abs() < 1e-12);
    assert!((held.gain_axis(0.74, 0.2) - third).abs() < 1e-12);
    for k in -3..=3 {
        let axis = held.gain_axis(k as f64 * third + 0.5, 0.99);
        let share = GainCalibration::observability(axis);
        assert!(share > 0.49, "{k}: {axis} {share}");
    }
}

#[test]
fn a_held_salient_rotor_whose_nearest_axis_would_cross_calibrates_along_q() {
    // Lq/Ld = 2 (saliency 1/3): at −1.66 rad (phase a at 8.7 % of the d current) the nearest
    // k·π/3, −2π/3, is 0.44 rad off d and would drive 0.33·sin 0.87 = 26 % of the level
    // across it; the q axis −1.66 + π/2 carries phase a at 99.6 % and b, c at about half.
    let held = held_phase(0.12e-3, 0.24e-3, 105.0);
    let (axis, on_q) = held.gain_axis_on_q(-1.66, 0.2);
    assert!(on_q);
    assert!((axis - (-1.66 + core::f64::consts::FRAC_PI_2)).abs() < 1e-12);
    assert!(GainCalibration::observability(axis) > 0.4);
    // Where d is observed (0.74 rad) it stays: π/3 would carry 19 % of the level across it.
    assert_eq!(held.gain_axis_on_q(0.74, 0.2), (0.74, false));
    // 0.047 rad from π/3 (3 % across) it stays; within 0.002 rad (0.2 %) it turns there.
    let third = core::f64::consts::FRAC_PI_3;
    assert_eq!(held.gain_axis_on_q(1.0, 0.2), (1.0, false));
    let (near, q) = held.gain_axis_on_q(third - 0.002, 0.2);
    assert!(!q && (near - third).abs() < 1e-12);
    let round = held_phase(2.63e-3, 2.63e-3, 21.78);
    assert!(!round.gain_axis_on_q(-1.66, 0.2).1);
}

#[test]
fn the_motion_monitor_reads_the_rotors_travel_under_the_zero_vector() {
    // A non-salient machine (R, L, λf) shorted (v = 0), its rotor turning at 20 rad/s from
    // θ0 = 1: the current obeys L·di/dt = −R·i − jω·λf·e^(jθ). The monitor's reading is the
    // travel 2·sin(|Δθ|/2) ≈ |Δθ| whatever θ0, within 1 %.
    let (r, l, lf, omega) = (3.6, 0.04, 0.5, 20.0);
    let mut m = MotionMonitor::new(r, l, lf, 6.0, TS);
    m.restart(Ab::zero());
    let (mut theta, mut i) = (1.0_f64, Ab::<f64>::zero());
    for _ in 0..500 {
        let (s, c) = theta.sin_cos();
        let e = Ab::new(-omega * lf * s, omega * lf * c);
        i += (i * (-r) - e) * (TS / l);
        theta += omega * TS;
        m.step(Ab::zero(), i);
    }
    let travel = 2.0 * ((theta - 1.0) / 2.0).sin();
    assert!(
        (m.travel() - travel).abs() < 0.01 * travel,
        "{} {travel}",
        m.travel()
    );
    assert!(!m.quiet(0.05));
}

#[test]
fn a_reference_off_by_its_own_uncertainty_reads_no_motion() {
    // The MAD 5010 KV200 datasheet motor (0.152 Ω, 26.5 µH, 1.97 mWb, 20 A, 40 kHz) at rest
    // under the zero vector: the true current is 0, the reference 7 mA off (ten samples of a
    // 12-bit sensor). Over a 0.1 s window the offset reads R·δ·t/λf = 0.054 rad, past the
    // tuning's 0.05; with the reference's uncertainty (3 standard errors, 10 mA) allowed for,
    // the rotor stands still, and a rotor turning at 20 rad/s still reads as moving.
    let ts = 25e-6;
    let (r, l, lf) = (0.1523, 26.49e-6, 1.969e-3);
    let n = (0.1 / ts) as usize;
    let read = |delta: f64, omega: f64| {
        let mut m = MotionMonitor::new(r, l, lf, 20.0, ts);
        m.set_reference_error(delta);
        m.restart(Ab::new(0.007, 0.0));
        let (mut theta, mut i) = (0.3_f64, Ab::<f64>::zero());
        for _ in 0..n {
            let (s, c) = theta.sin_cos();
            let e = Ab::new(-omega * lf * s, omega * lf * c);
            i += (i * (-r) - e) * (ts / l);
            theta += omega * ts;
            m.step(Ab::zero(), i);
        }
        m
    };
    let blind = read(0.0, 0.0);
    assert!(
        blind.travel() > 0.05 && !blind.quiet(0.05),
        "{}",
        blind.travel()
    );
    let still = read(0.010, 0.0);
    assert!(
        still.quiet(0.05),
        "{} {}",
        still.travel(),
        still.threshold(0.05)
    );
    let turning = read(0.010, 20.0);
    assert!(!turning.quiet(0.05), "{}", turning.travel());
    // A non-finite uncertainty counts as none.
    let mut m = MotionMonitor::new(r, l, lf, 20.0, ts);
    m.set_reference_error(f64::NAN);
    m.restart(Ab::zero());
    assert_eq!(m.threshold(0.05), 0.05);
}

#[test]
fn a_load_arriving_late_is_read_over_the_recent_window() {
    // The MAD 5010 KV200 datasheet motor of the test above, its reference 7 mA off and
    // allowed 10 mA: at rest for 0.1 s the recent window reads no motion; a rotor that a load
    // accelerates at 3·10⁴ rad/s² (electrical) from 80 ms on reads as moving over the recent
    // window by 0.1 rad of travel, where the whole window's drift allowance (R·δ·t/λf, 0.06
    // rad by then, plus the tuning's 0.05) has not yet been passed.
    let ts = 25e-6;
    let (r, l, lf) = (0.1523, 26.49e-6, 1.969e-3);
    let run = |accel: f64| {
        let mut m = MotionMonitor::new(r, l, lf, 20.0, ts);
        m.set_reference_error(0.010);
        m.restart(Ab::new(0.007, 0.0));
        let (mut theta, mut omega, mut i) = (0.3_f64, 0.0, Ab::<f64>::zero());
        for k in 0..(0.1 / ts) as usize {
            let (s, c) = theta.sin_cos();
            let e = Ab::new(-omega * lf * s, omega * lf * c);
            i += (i * (-r) - e) * (ts / l);
            if k as f64 * ts >= 0.08 {
                omega += accel * ts;
            }
            theta += omega * ts;
            m.step(Ab::zero(), i);
            if m.moved_recently(0.05) {
                return Some((theta - 0.3, m.travel() > m.threshold(0.05)));
            }
        }
        assert!(m.recent_travel() < 0.05, "{}", m.recent_travel());
        None
    };
    assert_eq!(run(0.0), None);
    let (travel, whole) = run(3e4).expect("the load's motion is read");
    assert!(travel < 0.1 && !whole, "{travel} {whole}");
}

#[test]
fn a_constant_inductance_model_pulses_at_its_configured_current() {
    // `pulse_current_share` moves the search only on a saturating model whose axes meet:
    // the paper's salient motor, and a round rotor (no axis order at all), keep share 1.
    let paper = MachineModel::<f64>::paper();
    assert_eq!(pulse_current_share(&paper, paper.rated_current), 1.0);
    let round = MachineModel {
        lq: paper.ld,
        ..MachineModel::paper()
    };
    assert_eq!(pulse_current_share(&round, round.rated_current), 1.0);
}
