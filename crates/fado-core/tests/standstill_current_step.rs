//! A locked saturated rotor under steps of i_q, fed exact signals: does the angle estimate
//! move with the current when the rotor does not? The drawn 192 kW IPMSM of fado-sim's
//! `drawn_machines` tests (9 pole pairs, q secant saturating, 800 V), its rotor held at
//! 0.4 rad, i_d = −395 A and i_q stepping between ±910 A (the current-vector limit its speed
//! PI swings between) every 0.3 s, through a current loop of 250 Hz whose voltage is limited
//! to 0.9·Vdc/√3 (a step faster than the link allows is refused by the estimator's
//! plausibility test, which is not what a drive sees). The current is held in the estimated
//! frame, as the drive's current loop holds it: a frame error turns the machine's own current.

use fado_core::magnetics::{MachineMagnetics, MagneticModel, Saturation};
use fado_core::{Ab, Dq, EstimatorConfig, MachineModel, Rotation, SensorlessEstimator, wrap_angle};

fn machine() -> MachineModel<f64> {
    let sat = Saturation {
        a_d0: 964.24,
        a_dd: 16.5218,
        s: 2.0,
        a_q0: 284.743,
        a_qq: 370.309,
        t: 4.0,
        a_dq: 190.748,
        u: 0.0,
        v: 0.0,
        i_f: 944.47,
        ..Saturation::default()
    };
    let model = MachineMagnetics::Saturation(Box::leak(Box::new(sat)));
    let linear = fado_core::magnetics::ConstantInductance {
        ld: 1.0,
        lq: 1.0,
        flux_linkage: 1.0,
    };
    let (ld, lq, flux_linkage) =
        fado_core::magnetics::zero_current_constants(&model.resolve(linear));
    MachineModel {
        rs: 0.00692873,
        ld,
        lq,
        flux_linkage,
        pole_pairs: 9,
        inertia: 1274.95,
        viscous_friction: 3.388,
        rated_current: 540.014,
        rated_speed_rpm: 204.503,
        rated_torque: 7255.64,
        dc_voltage: 800.0,
        magnetics: model,
    }
}

/// The locked-rotor run with a flux error `eps` (α-β, Wb) put into λ1 by one sample's
/// voltage at 0.1 s: max |θ − θ̂| over [0.2, 0.3) s (i_q = 0) and over the plateaus at
/// ±910 A (their last 0.2 s).
fn locked_rotor(eps: Ab<f64>) -> (f64, f64) {
    let m = machine();
    let ts = 1.0 / 12000.0;
    let magnetics = m.magnetic_model();
    let mut config = EstimatorConfig::for_machine(&m);
    config.ts = ts;
    let mut est = SensorlessEstimator::new(config).unwrap();
    let theta = 0.4_f64;
    let rot = Rotation::from_angle(theta);
    let target = |t: f64| {
        let q = match t {
            t if t < 0.3 => 0.0,
            t if (((t - 0.3) / 0.3) as i64) % 2 == 0 => 910.0,
            _ => -910.0,
        };
        Dq::new(-395.0, q)
    };
    let a = (-2.0 * std::f64::consts::PI * 250.0 * ts).exp();
    let vmax = 0.9 * m.dc_voltage / 3f64.sqrt();
    let mut i_dq = target(0.0);
    let mut psi_dq = magnetics.flux(i_dq);
    let mut i_prev = i_dq.to_ab(rot);
    est.align(theta, i_prev);
    let mut theta_hat = theta;
    let (mut at_zero, mut at_limit) = (0.0_f64, 0.0_f64);
    for k in 1..=(1.5 / ts) as usize {
        let t = k as f64 * ts;
        let goal = target(t).to_ab(Rotation::from_angle(theta_hat)).to_dq(rot);
        let step = (magnetics.flux(goal) - psi_dq) * (1.0 - a);
        let len = (step.d * step.d + step.q * step.q).sqrt();
        let step = step
            * if len > vmax * ts {
                vmax * ts / len
            } else {
                1.0
            };
        psi_dq += step;
        i_dq = magnetics.current_from(psi_dq, i_dq);
        let i_ab = i_dq.to_ab(rot);
        let mut v = step.to_ab(rot) * (1.0 / ts) + (i_ab + i_prev) * (0.5 * m.rs);
        if k == (0.1 / ts) as usize {
            v += eps * (1.0 / ts);
        }
        theta_hat = est.step(v, i_ab).theta;
        i_prev = i_ab;
        let error = wrap_angle(theta - theta_hat).abs();
        if (0.2..0.3).contains(&t) {
            at_zero = at_zero.max(error);
        } else if t > 0.3 && (t - 0.3) % 0.3 > 0.1 {
            at_limit = at_limit.max(error);
        }
    }
    (at_zero, at_limit)
}

#[test]
fn a_locked_saturated_rotor_keeps_its_angle_through_current_steps() {
    // Measured: 0.0000 rad at i_q = 0, 0.0007 rad on the plateaus (0.007 rad for a few
    // milliseconds in each step, the secant L̂q one sample late).
    let (at_zero, at_limit) = locked_rotor(Ab::zero());
    println!("exact signals: {at_zero:.4} rad at i_q = 0, {at_limit:.4} rad at ±910 A");
    assert!(at_zero < 0.005 && at_limit < 0.005, "{at_zero}, {at_limit}");
}

#[test]
fn a_flux_error_turns_the_angle_more_at_the_current_limit() {
    // What does move θ̂: a flux error across the d axis, turned into an angle by κ, which
    // falls with the current. Measured: 0.036 Wb gives 0.019 rad at i_q = 0 and 0.060 rad
    // at ±910 A (the linear twin 0.021 rad at both).
    let (at_zero, at_limit) = locked_rotor(Ab::new(0.003, -0.036));
    println!("0.036 Wb: {at_zero:.4} rad at i_q = 0, {at_limit:.4} rad at ±910 A");
    assert!(
        at_zero > 0.01 && at_limit > 2.0 * at_zero,
        "{at_zero}, {at_limit}"
    );
}
