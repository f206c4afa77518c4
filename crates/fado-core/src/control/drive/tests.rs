/// The stall band's default torque ratio is what its documentation derives it from: the
/// torque deficit 1 − cos δ of an estimate δ = 0.25 rad off.
#[test]
fn stall_torque_band_default_is_the_deficit_of_the_clean_threshold() {
    let deficit = 1.0 - nalgebra::ComplexField::cos(0.25_f64);
    assert!((super::STALL_TORQUE_BAND_RATIO - deficit).abs() < 1e-16);
}

/// The saturated torque solve (warm-started flux, the slope from the incremental inductance)
/// gives the currents of the cold solve (a fresh flux solve per evaluation, the secant slope,
/// iterated to convergence) on the PM-SyRM's model as closely as the cold solve's own three
/// steps do.
#[test]
fn saturated_torque_solve_is_the_cold_solve() {
    use crate::Dq;
    let m = crate::magnetics::tests::pmsyrm_machine();
    let config = super::DriveConfig::for_machine(&m);
    let tuning = crate::estimator::EstimatorTuning::default();
    let drive = super::SensorlessDrive::new(config, tuning).unwrap();
    let s = drive.resolved.saturated.unwrap();
    for k in -8..=8 {
        let iq_torque = 1.5 * m.rated_current * k as f64 / 8.0;
        // The cold solve: the solve's own path of i_d, τ from a fresh flux solve per point.
        let id_of = |iq: f64| drive.blocks.injection.step(iq) + s.mtpa_id(iq);
        let f = |iq: f64| s.torque_flux(Dq::new(id_of(iq), iq)) - m.flux_linkage * iq_torque;
        // Its three steps repeated to convergence (from i_q,t three leave up to 1e-4 A).
        let mut cold_iq = iq_torque;
        for _ in 0..4 {
            cold_iq = super::SensorlessDrive::<f64>::solve_torque(
                f,
                iq_torque,
                cold_iq,
                m.rated_current,
                m.flux_linkage,
            );
        }
        let once = |guess: f64| {
            let (i_rated, flux) = (m.rated_current, m.flux_linkage);
            super::SensorlessDrive::<f64>::solve_torque(f, iq_torque, guess, i_rated, flux)
        };
        // From the last sample's current (1 % off: within 1e-8 of the rated current, both
        // solves, 1e-15 away from the injection's corner at |i_q| = I_min) and from the demand
        // itself (up to 3× off on this rotor: three steps do not converge, up to 4e-4 of the
        // rated current, both solves alike).
        for (guess, bound) in [(1.01 * cold_iq, 1e-7), (iq_torque, 1e-3)] {
            let (i, _, _, _) = drive.saturated_currents_for_torque(&s, iq_torque, guess, 0.0);
            let (new, old) = ((i.q - cold_iq).abs(), (once(guess) - cold_iq).abs());
            std::println!("{iq_torque:8.3} from {guess:8.3}: {new:.1e} A (cold {old:.1e} A)");
            assert!(
                new.max(old) < bound * m.rated_current,
                "{iq_torque}: {new} vs {old}"
            );
        }
    }
}

/// On a rotor whose d current adds torque (L_d > L_q here; a measured map with ψq(i_d, 0) < 0
/// alike) the eq. (23) injection makes the torque path non-monotone: a local maximum below
/// I_min, then a dip to the torque at |i_q| = I_min. The solve, from the last sample's i_q*
/// as in the drive, reaches every torque of a ramp up to the limit and back, both directions.
#[test]
fn the_torque_solve_reaches_every_torque_on_a_non_monotone_path() {
    use crate::injection::{CurrentInjection, CurrentInjectionConfig};
    let (ld, lq, flux, i_rated) = (0.010, 0.002, 0.05, 10.0);
    let i_min = 2.0;
    let inj = CurrentInjection::new(CurrentInjectionConfig { i_min }).unwrap();
    let tau = |iq: f64| (flux + (ld - lq) * inj.step(iq)) * iq / flux;
    // The path is not monotone: its slope falls below zero just under I_min.
    let h = 1e-4;
    let min_slope = (0..20_000)
        .map(|k| (tau(k as f64 * h + h) - tau(k as f64 * h)) / h)
        .fold(f64::INFINITY, f64::min);
    assert!(min_slope < -1.0, "{min_slope}");
    let limit = tau(2.0 * i_rated);
    for sign in [1.0, -1.0] {
        let n = 4000;
        let (mut iq, mut worst) = (0.0, 0.0f64);
        for k in (0..=n).chain((0..n).rev()) {
            let target = sign * limit * k as f64 / n as f64;
            let f = |x: f64| (tau(x) - target) * flux;
            iq = super::SensorlessDrive::<f64>::solve_torque(f, target, iq, i_rated, flux);
            worst = worst.max((tau(iq) - target).abs() / limit);
        }
        std::println!("min slope {min_slope:.2}, worst residual {worst:.1e} of the limit");
        assert!(worst < 1e-3, "{sign}: {worst}");
    }
}

/// The voltage ellipse (`voltage_ellipse`): while the field-weakening loop weakens, a current
/// reference whose model flux exceeds the voltage's ψ_max = (Vdc/√3)/|ω̂| has its q current
/// cut to |ψ| = ψ_max within 2 % (the fixed point's three steps, from above), on the saturated PM-SyRM
/// (its model's flux) and on a constant-inductance IPMSM (λ̂f + L̂d·i_d, L̂q·i_q); a reference
/// inside the ellipse, and any reference below the weakening speed, is left alone.
#[test]
fn voltage_ellipse_cuts_the_q_current_to_the_voltage() {
    use crate::{Dq, MachineModel};
    let pmsyrm = crate::magnetics::tests::pmsyrm_machine();
    let ipmsm = MachineModel {
        ld: 0.6 * MachineModel::<f64>::paper().lq,
        ..MachineModel::paper()
    };
    for m in [pmsyrm, ipmsm] {
        let config = super::DriveConfig::for_machine(&m);
        let tuning = crate::estimator::EstimatorTuning::default();
        let mut drive = super::SensorlessDrive::new(config, tuning).unwrap();
        let vdc = m.dc_voltage;
        let flux = |i: Dq<f64>| match &drive.resolved.saturated {
            Some(s) => s.flux(i),
            None => Dq::new(m.flux_linkage + m.ld * i.d, m.lq * i.q),
        };
        let i = Dq::new(-0.8 * m.flux_linkage / m.ld, 1.5 * m.rated_current);
        // The speed at which the voltage allows half of the reference's flux.
        let omega = vdc / 3f64.sqrt() / (0.5 * flux(i).norm());
        // Below the weakening speed: unchanged.
        assert_eq!(drive.voltage_ellipse(i, vdc, omega), i);
        // Weakening: the loop's Δi_d < 0 after a sample above its margin.
        drive.blocks.field_weakening.update(vdc * vdc, vdc, omega);
        let psi_max = vdc / 3f64.sqrt() / omega;
        let cut = drive.voltage_ellipse(i, vdc, omega);
        let psi = flux(cut);
        assert_eq!(cut.d, i.d);
        assert!(cut.q < i.q && cut.q > 0.0, "{cut:?}");
        let n = (psi.d * psi.d + psi.q * psi.q).sqrt();
        assert!((n - psi_max).abs() < 0.02 * psi_max, "{n} vs {psi_max}");
        let brake = drive.voltage_ellipse(Dq::new(i.d, -i.q), vdc, omega);
        assert!(
            (brake.q + cut.q).abs() < 0.05 * cut.q,
            "{brake:?} vs {cut:?}"
        );
        let inside = Dq::new(i.d, 0.5 * cut.q);
        assert_eq!(drive.voltage_ellipse(inside, vdc, omega), inside);
    }
}

/// The release's floor is on at the brake on the 400 W servo's rotor of half its inertia (the
/// rated load's fall reaches the hold's trigger in 0.34 ms, t_r·ωc = 1.2 with the current loop
/// the hold raises to ωc·Ts = 0.35), not on its bare rotor (0.49 ms, 1.72), the paper's motor
/// (t_r 2.3 ms at its 250 Hz loop) nor on the light rotor with the hold off.
#[test]
fn the_floor_is_on_at_the_brake_only_where_the_fall_outruns_the_current_loop() {
    let mut servo = crate::MachineModel::paper();
    servo.rs = 2.3679;
    servo.ld = 8.3655e-3;
    servo.lq = 8.3655e-3;
    servo.flux_linkage = 62.155e-3;
    servo.pole_pairs = 4;
    servo.inertia = 3.1e-5;
    servo.rated_current = 3.405;
    servo.rated_speed_rpm = 3000.0;
    servo.rated_torque = 1.27;
    let built = |m: &crate::MachineModel<f64>, enabled: bool| {
        let mut c = super::DriveConfig::for_machine(m);
        c.tuning.release_hold.enabled = enabled;
        c.apply_build_rules(&mut crate::estimator::EstimatorTuning::default());
        c
    };
    let c = built(&servo, true);
    assert!((c.tuning.current.bandwidth_hz - 557.04).abs() < 0.01);
    assert!(!super::hold::floor_at_brake(&c));
    servo.inertia = 1.5e-5;
    let c = built(&servo, true);
    assert!((c.tuning.current.bandwidth_hz - 557.04).abs() < 0.01);
    assert!(super::hold::floor_at_brake(&c));
    assert!(!super::hold::floor_at_brake(&built(
        &crate::MachineModel::paper(),
        true
    )));
    // Through the drive: on from the start-up's end with a brake that holds the rotor and
    // the hold enabled, off once the application opens it; never with the hold off.
    for enabled in [true, false] {
        let mut c = built(&servo, enabled);
        c.tuning.startup.rotor_held = true;
        let tuning = crate::estimator::EstimatorTuning::default();
        let mut drive = super::SensorlessDrive::new(c, tuning).unwrap();
        drive.align(0.3);
        assert_eq!(drive.brake_holds, enabled);
        drive.arm_release_hold();
        assert!(!drive.brake_holds);
    }
}
