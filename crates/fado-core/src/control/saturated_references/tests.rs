//! MTPA from the model against a search on the current circle, the torque limit, and the
//! rated point's incremental inductances.

use std::boxed::Box;

use super::*;
use crate::magnetics::{MachineMagnetics, Saturation};

fn machine(a_dq: f64) -> MachineModel<f64> {
    let sat = Saturation {
        a_d0: 1.0 / 0.036,
        a_q0: 11.0,
        a_qq: 4000.0,
        t: 4.0,
        a_dq,
        i_f: 0.545 / 0.036,
        ..Saturation::default()
    };
    MachineModel {
        rs: 3.6,
        ld: 0.036,
        lq: 0.051,
        flux_linkage: 0.545,
        pole_pairs: 3,
        inertia: 0.015,
        viscous_friction: 8.9e-4,
        rated_current: 6.08,
        rated_speed_rpm: 1500.0,
        rated_torque: 14.0,
        dc_voltage: 540.0,
        magnetics: MachineMagnetics::Saturation(Box::leak(Box::new(sat))),
    }
}

fn baldor() -> MachineModel<f64> {
    crate::magnetics::tests::pmsyrm_machine()
}

#[test]
fn mtpa_table_maximises_torque_per_ampere() {
    for (name, m) in [
        ("ipmsm-2k2-qsat", machine(58.0)),
        ("strong cross", machine(300.0)),
        ("baldor", baldor()),
    ] {
        let i_max = 2.0 * m.rated_current;
        let r = SaturatedReferences::new(&m, i_max).unwrap();
        let model = m.magnetic_model();
        for frac in [0.1, 0.3, 0.65, 1.0, 1.5] {
            let current = frac * m.rated_current;
            // The best torque on the circle by a fine search over the current angle.
            let best = (0..=4000)
                .map(|k| {
                    let beta = k as f64 / 4000.0 * core::f64::consts::FRAC_PI_2;
                    torque_flux(&model, Dq::new(-current * beta.sin(), current * beta.cos()))
                })
                .fold(f64::MIN, f64::max);
            let at = r.mtpa_on_circle(current);
            assert!((at.norm() - current).abs() < 1e-6 * current, "{name}");
            let got = r.torque_flux(at);
            // Within 0.1 % of the rated torque (the table's interpolation, module docs).
            let rated = m.rated_torque / (1.5 * m.pole_pairs as f64);
            assert!(
                got > best - 1e-3 * rated,
                "{name} {frac}: MTPA {got}, best {best}"
            );
        }
        // Even in i_q, never positive, zero at zero current.
        assert_eq!(r.mtpa_id(-3.0), r.mtpa_id(3.0));
        assert!(r.mtpa_id(5.0) <= 0.0);
        assert_eq!(r.mtpa_id(0.0), 0.0);
    }
}

#[test]
fn torque_limit_and_rated_inductances_follow_the_model() {
    let m = baldor();
    let r = SaturatedReferences::new(&m, 2.0 * m.rated_current).unwrap();
    // At the rated current the model's MTPA torque is 31.5 N·m (the preset's note).
    let t_rated = 1.5 * 2.0 * r.torque_flux(r.mtpa_on_circle(m.rated_current));
    assert!((t_rated - 31.5).abs() < 0.5, "{t_rated}");
    let limit = r.torque_limit(m.rated_current, m.flux_linkage);
    assert!((limit * 1.5 * 2.0 * m.flux_linkage - t_rated).abs() < 1e-9);
    // Saturation: the rated point's incremental L_qq is well below the zero-current one.
    let (ld, lq) = r.rated_incremental(m.rated_current);
    assert!(lq < 0.7 * m.lq && lq > 0.0 && ld > 0.0, "{ld} {lq}");
    // Constant inductances have no saturated references.
    assert!(SaturatedReferences::new(&MachineModel::<f64>::paper(), 40.0).is_none());
}

/// The torque solve's slope (the model's incremental inductance along the path
/// i_d = i_d(i_q)) is the torque's derivative: central differences of the cold τ, on both
/// presets' models, along the MTPA path and with a d current that moves with i_q.
#[test]
fn torque_slope_is_the_derivative_along_the_path() {
    for (name, m) in [("ipmsm-2k2-qsat", machine(58.0)), ("baldor", baldor())] {
        let i_max = 2.0 * m.rated_current;
        let r = SaturatedReferences::new(&m, i_max).unwrap();
        for k in 1..=8 {
            // Between the MTPA table's nodes (its path is piecewise linear).
            let iq = i_max * (k as f64 - 0.37) / 8.0;
            for (path, id_of) in [
                ("mtpa", &(|q: f64| r.mtpa_id(q)) as &dyn Fn(f64) -> f64),
                ("injection", &|q: f64| -0.05 * q * q - 0.4),
            ] {
                let h = 1e-5 * m.rated_current;
                let i = Dq::new(id_of(iq), iq);
                let did = (id_of(iq + h) - id_of(iq - h)) / (2.0 * h);
                // Started from a solution 0.36 A away.
                let (_, mut warm) = r.warm_start(i + Dq::new(0.3, -0.2));
                let (tau, slope, psi) = r.torque_flux_slope(i, did, &mut warm);
                let tau_at = |q: f64| r.torque_flux(Dq::new(id_of(q), q));
                let fd = (tau_at(iq + h) - tau_at(iq - h)) / (2.0 * h);
                assert!((tau - r.torque_flux(i)).abs() < 1e-12, "{name} {path}");
                assert!((psi - r.flux(i)).norm() < 1e-13, "{name} {path}");
                assert!(
                    (slope - fd).abs() < 1e-6 * fd.abs(),
                    "{name} {path} at {iq}: {slope} vs {fd}"
                );
            }
        }
    }
}

/// Within a settled step (10⁻⁶ of the rated current) of the tangent plane's own current the
/// plane alone is the solved flux to 10⁻¹² of it on both algebraic machines; beyond the reach
/// it is `torque_flux_warm` to the bit.
#[test]
fn the_tangent_plane_near_its_current_is_the_solved_flux() {
    for (name, m) in [("ipmsm-2k2-qsat", machine(58.0)), ("baldor", baldor())] {
        let r = SaturatedReferences::new(&m, 2.0 * m.rated_current).unwrap();
        let reach = 1e-6 * m.rated_current;
        for k in 0..12 {
            let angle = 0.5 + 0.2 * k as f64;
            let at = Dq::new(-angle.sin(), angle.cos()) * (0.15 * m.rated_current * k as f64);
            let (_, plane) = r.warm_start(at);
            let near = at + Dq::new(0.6, -0.8) * (0.5 * reach);
            let (mut a, mut b) = (plane, plane);
            let (tau, psi) = r.torque_flux_near(near, at, reach, &mut a);
            assert_eq!(psi, plane.prediction(near), "{name} {k}: the plane's own");
            let (tau_solved, psi_solved) = r.torque_flux_warm(near, &mut b);
            let size = psi_solved.norm() * (1.0 + near.norm());
            assert!(
                (psi - psi_solved).norm() < 1e-12 * psi_solved.norm(),
                "{name} {k}: {psi:?} vs {psi_solved:?}"
            );
            assert!((tau - tau_solved).abs() < 1e-12 * size, "{name} {k}");
            assert!((a.prediction(at) - b.prediction(at)).norm() < 1e-12 * size);
            let far = at + Dq::new(0.6, -0.8) * (2.0 * reach);
            let (mut a, mut b) = (plane, plane);
            assert_eq!(
                r.torque_flux_near(far, at, reach, &mut a),
                r.torque_flux_warm(far, &mut b),
                "{name} {k}"
            );
            assert_eq!(a, b);
        }
    }
}
