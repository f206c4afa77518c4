//! The generalised eq. (5)–(6): alignment of λ̂r for saturating models, the fixed point the
//! estimator iterates, and the R̂s regressor against a numerical derivative.

use std::boxed::Box;

use super::*;
use crate::Rotation;
use crate::magnetics::{FluxTable, Magnetics, Saturation};

/// The estimator's view of `model` (leaked, as a firmware model lives in a `static`), with a
/// machine's rated current.
fn active(model: Magnetics<'static, f64>, rated: f64) -> Option<ActiveFlux<f64>> {
    let magnetics = match model {
        Magnetics::Constant(_) => MachineMagnetics::Linear,
        Magnetics::Saturation(s) => MachineMagnetics::Saturation(Box::leak(Box::new(s))),
        Magnetics::Map(m) => MachineMagnetics::Map(Box::leak(Box::new(m))),
        Magnetics::Uniform(m) => MachineMagnetics::Uniform(Box::leak(Box::new(m))),
    };
    let machine = MachineModel {
        rated_current: rated,
        magnetics,
        ..MachineModel::paper()
    };
    ActiveFlux::new(&machine)
}

/// The ipmsm-2k2-qsat preset's model: q self-saturation, 5 % cross-saturation, the magnet as
/// an MMF.
fn ipm_qsat(a_dq: f64) -> Magnetics<'static, f64> {
    Magnetics::Saturation(Saturation {
        a_d0: 1.0 / 0.036,
        a_q0: 11.0,
        a_qq: 4000.0,
        t: 4.0,
        a_dq,
        i_f: 0.545 / 0.036,
        ..Saturation::default()
    })
}

/// The pmsyrm-baldor-5k6 preset's model (motulator's fit, with the rib).
fn baldor() -> Magnetics<'static, f64> {
    Magnetics::Saturation(crate::magnetics::tests::pmsyrm())
}

/// A 17 × 17 flux map of the Baldor model over ±25 A (twice its rated current), leaked as a
/// firmware table would live in flash. The tests take the machine's flux from the
/// estimator's own view of its model ([`ActiveFlux::flux`]: a map's C¹ interpolant).
fn baldor_map() -> Magnetics<'static, f64> {
    let axis: [f64; 17] = core::array::from_fn(|k| -25.0 + 50.0 * k as f64 / 16.0);
    let table: &'static FluxTable<f64, 17, 17> =
        Box::leak(Box::new(FluxTable::from_model(&baldor(), axis, axis)));
    Magnetics::Map(table.map().unwrap())
}

fn models() -> [(&'static str, Magnetics<'static, f64>, f64); 4] {
    [
        ("ipmsm-2k2-qsat", ipm_qsat(58.0), 6.08),
        ("ipmsm-2k2 strong cross", ipm_qsat(300.0), 6.08),
        ("baldor", baldor(), 12.45),
        ("baldor map", baldor_map(), 12.45),
    ]
}

/// Operating points over the rated circle: MTPA-like (i_d ≤ 0), both signs of i_q, the
/// eq. (23) injection (i_d > 0), where the active flux is at least a quarter of the magnet's
/// (eq. (6) needs λa > 0: a strongly salient rotor's positive i_d cancels it).
fn points(rated: f64, model: Magnetics<'static, f64>) -> impl Iterator<Item = Dq<f64>> {
    let af = active(model, rated).unwrap();
    (0..=8)
        .flat_map(move |k| {
            let r = rated * (0.05 + 0.95 * k as f64 / 8.0);
            [-2.6, -1.9, -1.2, -0.3, 0.0, 0.4, 1.2, 1.9].map(|b: f64| {
                let beta = b + core::f64::consts::FRAC_PI_2;
                Dq::new(r * beta.cos(), r * beta.sin())
            })
        })
        .filter(move |&i| af.point(i).active > 0.25 * af.magnet_flux())
}

#[test]
fn secant_flux_is_aligned_with_d_for_any_model() {
    for (name, model, rated) in models() {
        let af = active(model, rated).unwrap();
        for i in points(rated, model) {
            let theta = 2.1;
            let rot = Rotation::from_angle(theta);
            let psi = af.flux(i).to_ab(rot);
            let pt = af.point(i);
            let lr = psi - i.to_ab(rot) * pt.lq_secant;
            let err = crate::wrap_angle(lr.angle() - theta);
            assert!(err.abs() < 1e-9, "{name} {i:?}: {err}");
            assert!((lr.norm() - pt.active).abs() < 1e-9, "{name} {i:?}");
            // The secant and the incremental inductance are one map: ψq = L_q,s·i_q, and
            // L_q,s's slope is (L_qq − L_q,s)/i_q (finite differences of the model).
            if i.q.abs() > 0.1 {
                assert!((pt.lq_secant * i.q - af.flux(i).q).abs() < 1e-12);
                let h = 1e-5 * rated;
                let up = af.point(Dq::new(i.d, i.q + h)).lq_secant;
                let dn = af.point(Dq::new(i.d, i.q - h)).lq_secant;
                let slope = (up - dn) / (2.0 * h);
                let l = af.incremental_inductance(i);
                let expected = (l.qq - pt.lq_secant) / i.q;
                let tol = if name.contains("map") { 1e-3 } else { 1e-5 };
                assert!(
                    (slope - expected).abs() < tol * pt.lq_secant / i.q.abs().max(1.0),
                    "{name} {i:?}: {slope} {expected}"
                );
            }
        }
    }
}

#[test]
fn per_sample_fixed_point_converges_to_the_rotor_angle() {
    for (name, model, rated) in models() {
        let af = active(model, rated).unwrap();
        for i in points(rated, model) {
            let theta = -0.7;
            let rot = Rotation::from_angle(theta);
            let psi = af.flux(i).to_ab(rot);
            let i_ab = i.to_ab(rot);
            // From the zero-current secant, as after a start-up.
            let mut lq = af.lq_zero();
            let mut lr = Ab::zero();
            for _ in 0..400 {
                let (r, pt) = af.rotor_flux(psi, i_ab, lq);
                lr = r;
                lq = pt.lq_secant;
            }
            let err = crate::wrap_angle(lr.angle() - theta);
            // A bilinear map's kinks leave the iteration within a few µrad.
            assert!(err.abs() < 1e-5, "{name} {i:?}: {err}");
        }
    }
}

/// e = |λ̂r| − λa(î) after a resistance error's flux ΔR·(−i_q + j·i_d)/ω (at the fixed point
/// of the estimator's iteration) against ΔR·φ of the module docs, φ = −bracket/ω.
#[test]
fn resistance_regressor_matches_the_flux_error_of_a_resistance_error() {
    let omega = 20.0;
    for (name, model, rated) in models() {
        let af = active(model, rated).unwrap();
        let mut checked = 0;
        for i in points(rated, model) {
            let theta = 0.9;
            let rot = Rotation::from_angle(theta);
            let i_ab = i.to_ab(rot);
            let pt = af.point(i);
            let Some(bracket) = af.resistance_regressor(&pt) else {
                continue;
            };
            let error_at = |dr: f64| {
                let flux_error = Dq::new(-i.q, i.d) * (dr / omega);
                let lambda2 = (af.flux(i) + flux_error).to_ab(rot);
                let mut lq = pt.lq_secant;
                let mut out = (Ab::zero(), pt);
                for _ in 0..400 {
                    out = af.rotor_flux(lambda2, i_ab, lq);
                    lq = out.1.lq_secant;
                }
                out.0.norm() - out.1.active
            };
            let dr = 1e-4 * rated.recip();
            let slope = (error_at(dr) - error_at(-dr)) / (2.0 * dr);
            let phi = -bracket / omega;
            let scale = (i.norm() / omega).max(1e-3);
            let tol = if name.contains("map") { 2e-3 } else { 1e-5 };
            assert!(
                (slope - phi).abs() < tol * scale,
                "{name} {i:?}: numerical {slope}, regressor {phi}"
            );
            checked += 1;
        }
        assert!(
            checked > 40,
            "{name}: only {checked} points outside the freeze"
        );
    }
}

#[test]
fn constant_inductances_give_the_linear_regressor() {
    let model = Magnetics::Saturation(Saturation::linear(0.036, 0.051, 0.545));
    let af = active(model, 6.08).unwrap();
    for i in points(6.08, model) {
        let pt = af.point(i);
        let lambda_a = 0.545 + (0.036 - 0.051) * i.d;
        assert!((pt.active - lambda_a).abs() < 1e-12);
        let bracket = af.resistance_regressor(&pt).unwrap();
        let linear = i.q * (1.0 + (0.036 - 0.051) * i.d / lambda_a);
        assert!((bracket - linear).abs() < 1e-9, "{i:?}: {bracket} {linear}");
    }
}

#[test]
fn constant_inductance_models_are_not_wrapped() {
    use crate::magnetics::ConstantInductance;
    let c = ConstantInductance {
        ld: 0.036,
        lq: 0.051,
        flux_linkage: 0.545,
    };
    assert!(active(Magnetics::Constant(c), 6.08).is_none());
}

/// The frame coupling against the closed loop it describes: the current held at î in the
/// estimated frame, the machine's own current e^{jδ}·î, λ̂r = ψ(i) − L_q,s(î)·i. A frame
/// error δ moves |λ̂r| by s·δ and turns it from the rotor's d axis by (1 − κ/λa)·δ
/// (numerical derivatives), and the
/// offset law holds where |s|/κ exceeds the bound: on the Baldor PM-SyRM at its rated MTPA
/// point, not on the IPMSM's.
#[test]
fn frame_coupling_matches_the_closed_loop_flux_change() {
    for (name, model, rated) in models() {
        let af = active(model, rated).unwrap();
        for i in points(rated, model) {
            let pt = af.point(i);
            let (s, kappa) = af.frame_coupling(&pt);
            let seen = |delta: f64| {
                let (sin, cos) = delta.sin_cos();
                let turned = Dq::new(i.d * cos - i.q * sin, i.d * sin + i.q * cos);
                let psi = af.flux(turned);
                let r = Dq::new(
                    psi.d - pt.lq_secant * turned.d,
                    psi.q - pt.lq_secant * turned.q,
                );
                (r.d.hypot(r.q), r.q.atan2(r.d))
            };
            let h = 1e-5;
            let ((m1, a1), (m0, a0)) = (seen(h), seen(-h));
            let (magnitude, angle) = ((m1 - m0) / (2.0 * h), (a1 - a0) / (2.0 * h));
            // A bilinear map's incremental inductance is one-sided on its grid lines.
            let tol = if name.contains("map") { 5e-2 } else { 1e-5 };
            assert!(
                (magnitude - s).abs() < tol * pt.active,
                "{name} {i:?}: d|λr|/dδ {magnitude}, s {s}"
            );
            assert!(
                (angle - (1.0 - kappa / pt.active)).abs() < tol,
                "{name} {i:?}: dangle/dδ {angle}, 1 − κ/λa {}",
                1.0 - kappa / pt.active
            );
        }
    }
    // The rated MTPA points (crate::control::saturated_references at 12.45 A and 6.08 A).
    let baldor = active(baldor(), 12.45).unwrap();
    assert!(baldor.holds_offset(&baldor.point(Dq::new(-8.26, 8.54))));
    assert!(!baldor.holds_offset(&baldor.point(Dq::new(2.0, 0.5))));
    let ipm = active(ipm_qsat(58.0), 6.08).unwrap();
    assert!(!ipm.holds_offset(&ipm.point(Dq::new(-0.08, 5.99))));
}

/// motulator's 6.7 kW SyRM in fado's frame with a magnet MMF of `i_f` A (the weak-magnet
/// PM-SyRM of `saturated_replay`).
fn weak_magnet(i_f: f64) -> Magnetics<'static, f64> {
    Magnetics::Saturation(Saturation {
        a_d0: 52.1,
        a_dd: 658.0,
        s: 1.0,
        a_q0: 17.4,
        a_qq: 373.0,
        t: 5.0,
        a_dq: 1120.0,
        u: 0.0,
        v: 1.0,
        i_f,
        ..Saturation::default()
    })
}

/// At no load with the injection along −d (the current along d) the weak-magnet PM-SyRM's
/// regressor is the map's slope turned by the frame (cross-saturation alone at i_q = 0): the
/// law freezes there. The IPMSM's regressor at a loaded point stays.
#[test]
fn the_regressor_freezes_where_the_maps_slope_carries_it() {
    let af = active(weak_magnet(0.5), 21.9).unwrap();
    for i_q in [0.0, -0.0] {
        let pt = af.point(Dq::new(-4.0, i_q));
        assert!(pt.active > 0.1, "{pt:?}");
        assert!(af.resistance_regressor(&pt).is_none(), "{i_q}");
    }
    let ipm = active(ipm_qsat(58.0), 6.08).unwrap();
    assert!(
        ipm.resistance_regressor(&ipm.point(Dq::new(-1.0, 5.0)))
            .is_some()
    );
}

/// The observer's reference: the magnet's ψd(0, 0) until half the low-passed active flux
/// exceeds it.
#[test]
fn the_observer_reference_is_the_magnet_or_half_the_active_flux() {
    let af = active(weak_magnet(0.5), 21.9).unwrap();
    let magnet = af.magnet_flux();
    assert!((magnet - 8.7e-3).abs() < 0.5e-3, "{magnet}");
    assert_eq!(af.observer_reference(0.01), magnet);
    assert_eq!(af.observer_reference(0.5), 0.5 * SWING_REFERENCE_SHARE);
    let baldor = active(baldor(), 12.45).unwrap();
    let lf = baldor.magnet_flux();
    assert_eq!(baldor.observer_reference(1.9 * lf), lf);
}

/// The interpolation spread (what the R̂s law compares with a resistance error's flux) is
/// zero on a map's nodes and on a model that is no map, and grows between the nodes where
/// the map bends: on the Baldor 17 × 17 map at mid-cell under load it is a few mVs.
#[test]
fn the_interpolation_spread_is_zero_on_the_nodes_and_opens_between_them() {
    let map = active(baldor_map(), 12.45).unwrap();
    let model = active(baldor(), 12.45).unwrap();
    let node = Dq::new(-6.25, 9.375);
    let mid = Dq::new(-7.8125, 10.9375);
    assert!(map.interpolation_spread(&map.point(node)) < 1e-12);
    assert_eq!(model.interpolation_spread(&model.point(mid)), 0.0);
    let spread = map.interpolation_spread(&map.point(mid));
    std::println!(
        "Baldor 17x17 map: λa spread at mid-cell {:.2} mVs",
        spread * 1e3
    );
    assert!(
        spread > 1e-4 && spread < 0.02 * map.point(mid).active,
        "{spread}"
    );
}

/// The constant-inductance coupling test agrees with the general one on the same machine
/// written as an algebraic model (`Saturation::linear`), over the rated circle of a strongly
/// salient rotor (the ipmsm-gem-50k preset's inductances, Lq/Ld 3.2, where it holds at the
/// rated MTPA point and not without load) and of the 2.2 kW IPMSM (Lq/Ld 1.4); a surface
/// rotor never holds; a NaN current holds.
#[test]
fn constant_inductances_hold_the_offset_where_the_algebraic_model_does() {
    let machines = [(0.37e-3, 1.2e-3, 0.066, 240.0), (0.036, 0.051, 0.545, 6.08)];
    for (ld, lq, lf, rated) in machines {
        let model = Magnetics::Saturation(Saturation::linear(ld, lq, lf));
        let af = active(model, rated).unwrap();
        for i in points(rated, model) {
            let general = af.holds_offset(&af.point(i));
            let constant = constant_inductance_holds_offset(lf, ld - lq, i);
            assert_eq!(general, constant, "Ld {ld} Lq {lq} at {i:?}");
            assert!(
                !constant_inductance_holds_offset(lf, 0.0, i),
                "surface at {i:?}"
            );
        }
    }
    let gem =
        |i_d, i_q| constant_inductance_holds_offset(0.066, 0.37e-3 - 1.2e-3, Dq::new(i_d, i_q));
    assert!(gem(-151.0, 187.0), "rated MTPA point");
    assert!(!gem(20.0, 0.0), "the injection without load");
    assert!(gem(f64::NAN, 1.0));
}

/// The integrand-offset law's share of its rate: 1 − (|s|/κ)/`OFFSET_COUPLING_MAX`, within
/// 0..1, and 0 wherever the law holds (continuous into the hold), on every model.
#[test]
fn the_offset_rate_tapers_into_the_hold() {
    for (name, model, rated) in models() {
        let af = active(model, rated).unwrap();
        for i in points(rated, model) {
            let pt = af.point(i);
            let (s, kappa) = af.frame_coupling(&pt);
            let share = af.offset_rate_share(&pt);
            assert!((0.0..=1.0).contains(&share), "{name} {i:?}: {share}");
            let expected = (1.0 - s.abs() / kappa / OFFSET_COUPLING_MAX).max(0.0);
            assert!((share - expected).abs() < 1e-12, "{name} {i:?}: {share}");
            if af.holds_offset(&pt) {
                assert_eq!(share, 0.0, "{name} {i:?}: held, share {share}");
            }
        }
    }
    // Five times the preset's cross-saturation at the rated q current: s < 0 (L_q,s below
    // L_dd), coupling 0.35, so the law runs at 0.3 of its rate; the preset itself (coupling
    // 0.002 there) at nearly all of it; on the PM-SyRM's rated MTPA point not at all.
    let strong = active(ipm_qsat(300.0), 6.08).unwrap();
    let pt = strong.point(Dq::new(0.0, 6.3));
    let (s, kappa) = strong.frame_coupling(&pt);
    assert!(
        s < 0.0 && (s.abs() / kappa - 0.35).abs() < 0.02,
        "{s} {kappa}"
    );
    assert!((strong.offset_rate_share(&pt) - 0.3).abs() < 0.04);
    let preset = active(ipm_qsat(58.0), 6.08).unwrap();
    assert!(preset.offset_rate_share(&preset.point(Dq::new(0.0, 6.3))) > 0.95);
    let baldor = active(baldor(), 12.45).unwrap();
    assert_eq!(
        baldor.offset_rate_share(&baldor.point(Dq::new(-8.26, 8.54))),
        0.0
    );
}
