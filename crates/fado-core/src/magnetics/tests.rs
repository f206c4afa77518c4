use std::string::ToString;

use super::*;
use crate::MachineModel;

/// The 6.7 kW SyRM of motulator's algebraic-model examples (Hinkkanen et al. 2017's fit).
pub(crate) fn syrm() -> Saturation<f64> {
    Saturation {
        a_d0: 17.4,
        a_dd: 373.0,
        s: 5.0,
        a_q0: 52.1,
        a_qq: 658.0,
        t: 1.0,
        a_dq: 1120.0,
        u: 1.0,
        v: 0.0,
        ..Saturation::default()
    }
}

/// The pmsyrm-baldor-5k6 preset's machine model with its saturating model [`pmsyrm`] (leaked:
/// a test's `'static` model).
pub(crate) fn pmsyrm_machine() -> MachineModel<f64> {
    let sat = std::boxed::Box::leak(std::boxed::Box::new(pmsyrm()));
    MachineModel {
        rs: 0.63,
        ld: 0.0298,
        lq: 0.1497,
        flux_linkage: 0.4767,
        pole_pairs: 2,
        inertia: 0.05,
        viscous_friction: 1.6e-3,
        rated_current: 12.45,
        rated_speed_rpm: 1800.0,
        rated_torque: 29.7,
        dc_voltage: 540.0,
        magnetics: MachineMagnetics::Saturation(sat),
    }
}

/// The 5.6 kW PM-SyRM (Baldor ECS101M0H7EF4) fit of motulator's example, with the rib (the
/// pmsyrm-baldor-5k6 preset's model; the other test modules take it from here).
pub(crate) fn pmsyrm() -> Saturation<f64> {
    Saturation {
        a_d0: 3.96,
        a_dd: 28.5,
        s: 4.0,
        a_q0: 5.89,
        a_qq: 2.67,
        t: 6.0,
        a_dq: 41.5,
        u: 1.0,
        v: 1.0,
        psi_n: 0.804,
        a_b: 81.75,
        a_bp: 1.0,
        w: 2.0,
        k_q: 0.1,
        ..Saturation::default()
    }
}

/// An interior-magnet machine (Ld 36 mH, Lq 51 mH, λf 0.545 Wb) with q saturation and a
/// cross term, saturating around the magnet's flux.
fn ipm() -> Saturation<f64> {
    Saturation {
        a_qq: 40.0,
        t: 2.0,
        a_dq: 30.0,
        u: 1.0,
        v: 1.0,
        ..Saturation::linear(0.036, 0.051, 0.545)
    }
}

/// The same interior-magnet machine with the magnet as an MMF (i_f = λf/Ld) and d
/// self-saturation: ψd falls with i_q at i_d = 0 (cross-saturation) and positive i_d saturates.
fn ipm_mmf() -> Saturation<f64> {
    Saturation {
        a_d0: 1.0 / 0.036,
        a_dd: 20.0,
        s: 2.0,
        a_q0: 11.0,
        a_qq: 4000.0,
        t: 4.0,
        a_dq: 58.0,
        i_f: 0.545 / 0.036,
        ..Saturation::default()
    }
}

pub(crate) fn models() -> [(&'static str, Saturation<f64>, f64); 4] {
    // (name, model, rated-ish current in A)
    [
        ("syrm", syrm(), 22.0),
        ("pmsyrm", pmsyrm(), 12.5),
        ("ipm", ipm(), 6.0),
        ("ipm_mmf", ipm_mmf(), 6.0),
    ]
}

#[test]
fn a_magnet_mmf_gives_cross_saturation_and_asymmetric_d_saturation() {
    let m = ipm_mmf();
    m.validate().unwrap();
    let psi0 = m.flux(Dq::zero()).d;
    // ψd at i_d = 0 falls with i_q.
    let psi_q6 = m.flux(Dq::new(0.0, 6.0)).d;
    assert!(psi_q6 < 0.99 * psi0, "{psi0} -> {psi_q6}");
    // Positive d current meets a lower incremental inductance than negative.
    let up = m.incremental_inductance(Dq::new(6.0, 0.0)).dd;
    let down = m.incremental_inductance(Dq::new(-6.0, 0.0)).dd;
    assert!(up < 0.95 * down, "{up} vs {down}");
}

pub(crate) fn currents(i_max: f64) -> impl Iterator<Item = Dq<f64>> {
    (-4..=4).flat_map(move |a| {
        (-4..=4).map(move |b| {
            Dq::new(
                0.4 * i_max * a as f64 / 4.0 + 0.013,
                0.5 * i_max * b as f64 / 2.0 - 0.007,
            )
        })
    })
}

#[test]
fn constant_inductance_is_the_machine_model_bit_for_bit() {
    let m = MachineModel::<f64> {
        ld: 2.0e-3,
        lq: 5.0e-3,
        ..MachineModel::paper()
    };
    let c = ConstantInductance {
        ld: m.ld,
        lq: m.lq,
        flux_linkage: m.flux_linkage,
    };
    for i in currents(20.0) {
        assert_eq!(c.flux(i), m.flux_dq(i));
        assert!((c.current(c.flux(i)) - i).norm() < 1e-12);
        let t = c.torque(m.pole_pairs, i);
        assert!(
            (t - m.torque(i)).abs() < 1e-12 * (1.0 + t.abs()),
            "{t} vs {}",
            m.torque(i)
        );
        assert!((c.active_flux(i) - m.active_flux(i.d)).abs() < 1e-15);
    }
    // The algebraic form with no saturation is the same machine.
    let s = Saturation::linear(m.ld, m.lq, m.flux_linkage);
    for i in currents(20.0) {
        assert!((s.flux(i) - c.flux(i)).norm() < 1e-14, "{i:?}");
    }
}

#[test]
fn inverse_of_forward_is_the_identity() {
    for (name, m, i_max) in models() {
        m.validate().unwrap();
        for i in currents(2.0 * i_max) {
            let psi = m.flux(i);
            assert!(psi.is_finite(), "{name}: {i:?}");
            let back = m.current(psi);
            assert!(
                (back - i).norm() < 1e-9 * (1.0 + i.norm()),
                "{name}: {i:?} -> {back:?}"
            );
        }
    }
}

/// A warm-started ψ(i) (from a nearby current's flux, from a far one, from a non-finite guess)
/// is the cold solve's to the solver's tolerance, and the inductance it returns with it is the
/// incremental inductance at ψ(i); `flux_and_inductance` is the two separate calls bit for bit.
#[test]
fn a_strong_cross_term_is_solved_from_the_linear_guess_at_every_angle() {
    // ipm-cross20 of scripts/saturated-replay.py: all of q's saturation from the cross term.
    // From the linear guess the plain Newton iteration overshoots into the steep region at
    // some angles of the rated current (near +q); the damped fallback solves them all
    // (half and full rated current at every angle, twice the rated current where i_d ≤ 0).
    let s = Saturation {
        a_dq: 4000.0,
        u: 0.0,
        v: 1.0,
        i_f: 25.0,
        ..Saturation::linear(12e-3, 30e-3, 0.0)
    };
    let mut worst = 0.0f64;
    for k in 0..=720 {
        let b = k as f64 * core::f64::consts::PI / 720.0;
        for magnitude in [6.0, 12.0, 24.0] {
            // At twice the rated current with i_d > 0 the model itself folds (its energy is
            // not convex where ψd and |ψq| are both large): no solve can invert it there.
            if magnitude > 12.0 && k > 360 {
                continue;
            }
            let i = Dq::new(-magnitude * b.cos(), magnitude * b.sin());
            worst = worst.max((s.current(s.flux(i)) - i).norm());
            let warm = s.flux_from(i, s.linear_flux(i));
            worst = worst.max((s.current(warm) - i).norm());
        }
    }
    assert!(worst < 1e-9, "{worst}");
}

#[test]
fn warm_started_flux_is_the_cold_solve() {
    for (name, m, i_max) in models() {
        let far = m.flux(Dq::new(-i_max, 2.0 * i_max));
        for i in currents(2.0 * i_max) {
            let cold = m.flux(i);
            let l = m.incremental_inductance(i);
            assert_eq!(m.flux_and_inductance(i), (cold, l), "{name}: {i:?}");
            let near = m.flux(i + Dq::new(0.01 * i_max, -0.01 * i_max));
            for guess in [near, far, cold, Dq::new(f64::NAN, 0.0)] {
                let (psi, lw) = m.flux_and_inductance_from(i, guess);
                assert!(
                    (psi - cold).norm() < 1e-13 * (1.0 + cold.norm()),
                    "{name}: {i:?} from {guess:?}: {psi:?} vs {cold:?}"
                );
                assert_eq!(m.flux_from(i, guess), psi, "{name}: {i:?}");
                assert!(close(lw, l, 1e-7), "{name}: {i:?}: {lw:?} vs {l:?}");
            }
        }
    }
}

/// Central differences of `f` at `x` with step `h` along d and q: the Jacobian.
fn fd(f: impl Fn(Dq<f64>) -> Dq<f64>, x: Dq<f64>, h: f64) -> InductanceMatrix<f64> {
    let dd = (f(x + Dq::new(h, 0.0)) - f(x - Dq::new(h, 0.0))) * (0.5 / h);
    let dq = (f(x + Dq::new(0.0, h)) - f(x - Dq::new(0.0, h))) * (0.5 / h);
    InductanceMatrix {
        dd: dd.d,
        dq: dq.d,
        qd: dd.q,
        qq: dq.q,
    }
}

fn close(a: InductanceMatrix<f64>, b: InductanceMatrix<f64>, rel: f64) -> bool {
    let scale = a.dd.abs().max(a.qq.abs());
    [a.dd - b.dd, a.dq - b.dq, a.qd - b.qd, a.qq - b.qq]
        .iter()
        .all(|e| e.abs() <= rel * scale)
}

#[test]
fn incremental_inductance_matches_finite_differences_and_is_reciprocal() {
    for (name, m, i_max) in models() {
        for i in currents(1.5 * i_max) {
            let l = m.incremental_inductance(i);
            let num = fd(|x| m.flux(x), i, 1e-4 * i_max);
            assert!(close(l, num, 1e-5), "{name} at {i:?}: {l:?} vs {num:?}");
            // Reciprocity, from the forward map's values alone.
            assert!(
                (num.dq - num.qd).abs() <= 1e-5 * num.dd.abs().max(num.qq.abs()),
                "{name} at {i:?}: ∂ψd/∂iq {} vs ∂ψq/∂id {}",
                num.dq,
                num.qd
            );
            // The inverse Jacobian ∂i/∂ψ against the current map's differences.
            let psi = m.flux(i);
            let (_, g) = m.current_and_jacobian(psi);
            let num_g = fd(|p| m.current(p), psi, 1e-6);
            assert!(
                close(g, num_g, 1e-5),
                "{name} at {psi:?}: {g:?} vs {num_g:?}"
            );
        }
    }
}

/// Magnetic energy 1.5·∫ i·dψ from `psi0` to `psi` along the straight line (Gauss–Legendre,
/// 5 points on each of 64 pieces).
fn energy(m: &impl MagneticModel<f64>, psi0: Dq<f64>, psi: Dq<f64>) -> f64 {
    let (x, w) = (
        [
            0.0,
            -0.538_469_310_105_683_1,
            0.538_469_310_105_683_1,
            -0.906_179_845_938_664,
            0.906_179_845_938_664,
        ],
        [
            0.568_888_888_888_888_9,
            0.478_628_670_499_366_5,
            0.478_628_670_499_366_5,
            0.236_926_885_056_189_1,
            0.236_926_885_056_189_1,
        ],
    );
    let dpsi = psi - psi0;
    let n = 64;
    let mut e = 0.0;
    for piece in 0..n {
        for (xk, wk) in x.iter().zip(w) {
            let s = (piece as f64 + 0.5 + 0.5 * xk) / n as f64;
            let i = m.current(psi0 + dpsi * s);
            e += wk * 0.5 / n as f64 * (i.d * dpsi.d + i.q * dpsi.q);
        }
    }
    1.5 * e
}

#[test]
fn torque_is_the_co_energy_derivative_and_the_energy_is_path_independent() {
    for (name, m, i_max) in models() {
        let p = 2;
        let psi_ref = m.flux(Dq::zero());
        for i in currents(1.2 * i_max).step_by(7) {
            let psi = m.flux(i);
            // Virtual work at constant stator flux: rotating the rotor by δ (mechanical δ/p)
            // turns ψ_dq by −δ; T = −∂W/∂θ_mech.
            let delta = 1e-5;
            let rot = |a: f64| {
                Dq::new(
                    psi.d * a.cos() + psi.q * a.sin(),
                    -psi.d * a.sin() + psi.q * a.cos(),
                )
            };
            let dw = energy(&m, psi_ref, rot(delta)) - energy(&m, psi_ref, rot(-delta));
            let t_virtual = -dw / (2.0 * delta / p as f64);
            let t = m.torque(p, i);
            assert!(
                (t - t_virtual).abs() < 1e-6 * (1.0 + t.abs()),
                "{name} at {i:?}: {t} vs virtual work {t_virtual}"
            );
            // Around a closed loop the energy returns (a reciprocal, conservative model).
            let corner = Dq::new(psi_ref.d, psi.q);
            let loop_w =
                energy(&m, psi_ref, corner) + energy(&m, corner, psi) - energy(&m, psi_ref, psi);
            assert!(
                loop_w.abs() < 1e-9 * (1.0 + energy(&m, psi_ref, psi).abs()),
                "{name}: {loop_w}"
            );
        }
    }
}

#[test]
fn secant_q_inductance_puts_the_active_flux_on_d() {
    for (name, m, i_max) in models() {
        for i in currents(i_max) {
            let psi = m.flux(i);
            let lqs = m.secant_q(i);
            let q = psi.q - lqs * i.q;
            assert!(q.abs() < 1e-12, "{name}: {q}");
            assert!((m.active_flux(i) - (psi.d - lqs * i.d)).abs() < 1e-15);
        }
        // The q secant inductance falls with q current (self-saturation).
        let l0 = m.secant_q(Dq::new(0.0, 0.0));
        let l1 = m.secant_q(Dq::new(0.0, i_max));
        assert!(l1 < 0.97 * l0, "{name}: {l0} -> {l1}");
    }
    // The SyRM's published unsaturated inductances: 1/a_d0, 1/a_q0.
    let s = syrm();
    assert!((s.incremental_inductance(Dq::zero()).dd - 1.0 / 17.4).abs() < 1e-12);
    assert!((s.secant_q(Dq::zero()) - 1.0 / 52.1).abs() < 1e-12);
}

/// A map that is not odd in i_q (a measured map's ψq(i_d, 0) ≠ 0, here −4 % of the magnet's
/// flux, varying with i_d): the secant without the offset stays finite and continuous through
/// i_q = 0 and ψ − L_q,s·i = (λa, ψq(i_d, 0)), i.e. the rotor flux lies at
/// atan(ψq(i_d, 0)/λa) from d; the plain ψq/i_q grows without bound there.
#[test]
fn the_secant_of_a_map_not_odd_in_i_q_removes_its_q_flux_at_zero_q_current() {
    let mut table = ipm_table::<f64>();
    let offset = |id: f64| -0.04 * 0.545 * (1.0 + 0.02 * id);
    for (k, &id) in table.i_d.iter().enumerate() {
        for q in table.psi_q[k].iter_mut() {
            *q += offset(id);
        }
    }
    let map = table.map().unwrap();
    for i in currents(9.0) {
        let psi = map.flux(i);
        let lqs = map.secant_q(i);
        assert!(
            (map.q_flux_offset(i.d) - offset(i.d)).abs() < 1e-15,
            "{i:?}"
        );
        assert!(lqs.is_finite() && lqs > 0.0, "{i:?}: {lqs}");
        let rotor = psi - Dq::new(lqs * i.d, lqs * i.q);
        assert!((rotor.d - map.active_flux(i)).abs() < 1e-15);
        assert!((rotor.q - offset(i.d)).abs() < 1e-12, "{i:?}: {rotor:?}");
        // The angle from d is the stated one, under 0.05 rad here.
        assert!((rotor.q / rotor.d).atan().abs() < 0.05, "{i:?}");
    }
    // Continuous through i_q = 0: the secant there is the incremental L_qq, its limit.
    for id in [-9.0, -2.0, 0.0, 3.0] {
        let at = |iq: f64| map.secant_q(Dq::new(id, iq));
        let l = map.incremental_inductance(Dq::new(id, 0.0)).qq;
        for iq in [1e-7, 1e-4, -1e-4, 1e-2] {
            assert!(
                (at(iq) - l).abs() < 1e-3 * l,
                "{id} {iq}: {} vs {l}",
                at(iq)
            );
        }
        // Without the offset the secant would be off by ψq(i_d, 0)/i_q: 22 H at 1 mA.
        assert!((map.flux(Dq::new(id, 1e-3)).q / 1e-3 - l).abs() > 10.0);
    }
    // Odd models have no offset: the constant and algebraic ones, a table of an odd model.
    let odd = ipm_table::<f64>();
    let odd_map = odd.map().unwrap();
    for id in [-9.0, -0.5, 4.0] {
        assert_eq!(ipm().q_flux_offset(id), 0.0);
        assert!(odd_map.q_flux_offset(id).abs() < 1e-15);
    }
}

pub(crate) fn ipm_table<T: Real>() -> FluxTable<T, 16, 16> {
    let m = ipm().cast::<T>();
    let axis = |a: f64, b: f64| core::array::from_fn(|k| T::lit(a + (b - a) * k as f64 / 15.0));
    FluxTable::from_model(&m, axis(-12.0, 6.0), axis(-12.0, 12.0))
}

#[test]
fn a_flux_map_interpolates_inverts_and_differentiates() {
    let table = ipm_table::<f64>();
    let map = table.map().unwrap();
    let truth = ipm();
    for (k, &id) in table.i_d.iter().enumerate() {
        for (m, &iq) in table.i_q.iter().enumerate() {
            // The nodes to rounding (the cell fraction of a uniform axis is (x − x₀)/Δ − k).
            let psi = map.flux(Dq::new(id, iq));
            let node = Dq::new(table.psi_d[k][m], table.psi_q[k][m]);
            assert!((psi - node).norm() < 1e-15, "{psi:?} vs {node:?}");
        }
    }
    for i in currents(9.0) {
        let psi = map.flux(i);
        // Bilinear between nodes: close to the model it tabulates.
        assert!((psi - truth.flux(i)).norm() < 2e-3, "{i:?}");
        let back = map.current(psi);
        assert!(
            (back - i).norm() < 1e-9 * (1.0 + i.norm()),
            "{i:?} -> {back:?}"
        );
        let warm = map.current_from(psi, i + Dq::new(0.3, -0.2));
        assert!((warm - i).norm() < 1e-9 * (1.0 + i.norm()));
        // Incremental inductance against differences taken inside the cell.
        let num = fd(|x| map.flux(x), i, 1e-7);
        assert!(close(map.incremental_inductance(i), num, 1e-6), "{i:?}");
        assert!(close(
            map.incremental_inductance(i),
            truth.incremental_inductance(i),
            0.05
        ));
    }
    // Beyond the grid, the edge cells extend linearly and still invert.
    let far = Dq::new(-15.0, 14.0);
    assert!((map.current(map.flux(far)) - far).norm() < 1e-9);
    // A linear machine's map is exact everywhere (bilinear reproduces affine maps).
    let lin = ConstantInductance {
        ld: 0.036,
        lq: 0.051,
        flux_linkage: 0.545,
    };
    let ax: [f64; 3] = [-10.0, -1.0, 4.0];
    let lt = FluxTable::from_model(&lin, ax, [-5.0, 0.0, 5.0]);
    let lm = lt.map().unwrap();
    for i in currents(20.0) {
        assert!((lm.flux(i) - lin.flux(i)).norm() < 1e-14);
        assert!((lm.torque(3, i) - lin.torque(3, i)).abs() < 1e-12);
    }
}

/// The closed-form inverse, cell by cell, is the inverse: ψ(i(ψ)) = ψ to rounding inside and
/// beyond the grid, from a warm start in any cell, on uniform and non-uniform axes of a map
/// with strong self- and cross-saturation (twisted cells); it agrees with Newton's method.
#[test]
fn a_flux_map_inverts_in_closed_form_from_any_cell() {
    let model = pmsyrm();
    let uniform: [f64; 13] = core::array::from_fn(|k| -30.0 + 5.0 * k as f64);
    // Nodes crowded towards zero current: every cell a different width.
    let skewed: [f64; 13] = core::array::from_fn(|k| {
        let x = (k as f64 - 6.0) / 6.0;
        30.0 * x * (0.4 + 0.6 * x.abs())
    });
    for (i_d, i_q) in [(uniform, uniform), (skewed, uniform), (skewed, skewed)] {
        let table = FluxTable::from_model(&model, i_d, i_q);
        let map = table.map().unwrap();
        let guesses = [Dq::zero(), Dq::new(-29.0, 29.0), Dq::new(40.0, -40.0)];
        for i in currents(36.0).chain([Dq::new(-45.0, 3.0), Dq::new(2.0, 44.0)]) {
            let psi = map.flux(i);
            for g in guesses.iter().copied().chain([i + Dq::new(0.4, -0.3)]) {
                let back = cell_inverse::invert(&map, psi, g).expect("a closed-form inverse");
                let err = (map.flux(back) - psi).norm();
                assert!(
                    err < 1e-14 * (1.0 + psi.norm()),
                    "{i:?} from {g:?}: {err:e}"
                );
                assert!(
                    (back - i).norm() < 1e-9 * (1.0 + i.norm()),
                    "{i:?}: {back:?}"
                );
                assert_eq!(map.current_from(psi, g), back);
            }
            // Newton's method from a warm start (it need not converge from a far one).
            let near = i + Dq::new(0.4, -0.3);
            let newton = newton(psi, near, 1e-6, |x| map.flux_and_jacobian(x)).0;
            assert!((newton - i).norm() < 1e-9 * (1.0 + i.norm()), "{i:?}");
        }
    }
    // A non-finite flux has no root: None, and the fallback's answer is not finite either.
    let map = FluxTable::from_model(&model, uniform, uniform);
    let map = map.map().unwrap();
    let nan = Dq::new(f64::NAN, 0.1);
    assert!(cell_inverse::invert(&map, nan, Dq::zero()).is_none());
    assert!(!map.current_from(nan, Dq::zero()).is_finite());
}

/// The cached inverse ([`InverseCache`]) is the map's own `current_from`, bit for bit: along a
/// plant's trajectory (four inversions per warm start, the current crossing cell edges, a jump
/// across the map, beyond the grid) on uniform and non-uniform axes and on a uniform table.
#[test]
fn the_cached_inverse_is_the_inverse_bit_for_bit() {
    let model = pmsyrm();
    let uniform: [f64; 13] = core::array::from_fn(|k| -30.0 + 5.0 * k as f64);
    let skewed: [f64; 13] = core::array::from_fn(|k| {
        let x = (k as f64 - 6.0) / 6.0;
        30.0 * x * (0.4 + 0.6 * x.abs())
    });
    let path = |k: usize| {
        // A rotating current of growing amplitude, a far jump halfway, an excursion beyond.
        let t = k as f64 * 0.013;
        let a = if k == 400 {
            44.0
        } else {
            2.0 + 0.06 * k as f64
        };
        Dq::new(a * t.cos(), a * t.sin())
    };
    let check = |model: &Magnetics<'_, f64>| {
        let mut cache = InverseCache::new();
        let mut guess = Dq::zero();
        for k in 0..700 {
            let psi = model.flux(path(k));
            for stage in [0.5, 0.75, 0.9, 1.0] {
                let p = model.flux(guess) + (psi - model.flux(guess)) * stage;
                let cached = model.current_from_cached(p, guess, &mut cache);
                assert_eq!(cached, model.current_from(p, guess), "step {k}, {stage}");
            }
            guess = model.current_from_cached(psi, guess, &mut cache);
        }
    };
    for (i_d, i_q) in [(uniform, uniform), (skewed, uniform), (skewed, skewed)] {
        let table = FluxTable::from_model(&model, i_d, i_q);
        check(&Magnetics::Map(table.map().unwrap()));
    }
    let table = ipm_table::<f64>();
    let uniform_table = UniformFluxTable::new(&table).unwrap();
    check(&Magnetics::Uniform(uniform_table.map()));
}

/// Near the cache's last solution (a Runge–Kutta step's end beside its last stage) the
/// refined inverse is the inverse to 10⁻⁹ of a cell, farther (two Newton steps) too; far from
/// it, the cached inverse itself.
#[test]
fn the_refined_inverse_is_the_inverse_near_the_last_solution() {
    let uniform: [f64; 13] = core::array::from_fn(|k| -30.0 + 5.0 * k as f64);
    let table = FluxTable::from_model(&pmsyrm(), uniform, uniform);
    let model = Magnetics::Map(table.map().unwrap());
    let mut cache = InverseCache::new();
    let mut guess = Dq::zero();
    for k in 0..300 {
        let t = k as f64 * 0.021;
        let psi = model.flux(Dq::new(14.0 * t.cos(), 14.0 * t.sin()));
        let last = model.current_from_cached(psi, guess, &mut cache);
        let near = psi + Dq::new(1e-7, -1e-7);
        let refined = model.current_near_cached(near, guess, &mut cache);
        let exact = model.current_from(near, guess);
        assert!(
            (refined - exact).norm() < 1e-8,
            "step {k}: {refined:?} {exact:?}"
        );
        // Farther, a second Newton step may still reach the tolerance; farther still, the
        // steps leave the cell or miss it.
        let far = psi + Dq::new(0.02, -0.02);
        let second = model.current_near_cached(far, guess, &mut cache);
        assert!(
            (second - model.current_from(far, guess)).norm() < 1e-8,
            "step {k}"
        );
        let farther = psi + Dq::new(0.2, -0.2);
        let refused = model.current_near_cached(farther, guess, &mut cache);
        assert_eq!(refused, model.current_from(farther, guess), "step {k}");
        guess = last;
    }
}

/// At a Runge–Kutta stage's distance from the cache's last solution (a few % of a 5 A cell)
/// the refined inverse to a stage's tolerance (10⁻⁵ of the cell) is the inverse to that
/// tolerance, Newton's steps on most of the path.
#[test]
fn a_stage_is_newton_steps_to_its_tolerance() {
    let uniform: [f64; 13] = core::array::from_fn(|k| -30.0 + 5.0 * k as f64);
    let table = FluxTable::from_model(&pmsyrm(), uniform, uniform);
    let model = Magnetics::Map(table.map().unwrap());
    let (mut cache, mut guess, mut taken) = (InverseCache::new(), Dq::zero(), 0);
    for k in 0..300 {
        let t = k as f64 * 0.021;
        let psi = model.flux(Dq::new(14.0 * t.cos(), 14.0 * t.sin()));
        let last = model.current_from_cached(psi, guess, &mut cache);
        let stage = psi + Dq::new(2e-3, -2e-3);
        let refined = model.current_near_cached_to(stage, guess, &mut cache, 1e-5);
        let exact = model.current_from(stage, guess);
        assert!(
            (refined - exact).norm() < 1e-4,
            "step {k}: {refined:?} {exact:?}"
        );
        taken += usize::from(refined != exact);
        guess = last;
    }
    std::println!("Newton's steps taken at 300 stages: {taken}");
    assert!(taken > 200, "{taken}");
}

/// The uniform table is the flux map of the same table: values and Jacobians to rounding
/// inside and beyond the grid, its inverse; the compiler's build is the run-time one; a
/// non-uniform axis is refused.
#[test]
fn a_uniform_table_is_the_flux_map() {
    let table = ipm_table::<f64>();
    let (map, uniform) = (table.map().unwrap(), UniformFluxTable::new(&table).unwrap());
    for i in currents(9.0).chain([Dq::new(-15.0, 14.0), Dq::new(7.0, -13.0)]) {
        let (a, la) = map.flux_and_jacobian(i);
        let (b, lb) = uniform.flux_and_jacobian(i);
        assert!((a - b).norm() < 1e-14, "{i:?}: {a:?} vs {b:?}");
        assert!(close(la, lb, 1e-12), "{i:?}");
        assert_eq!(uniform.flux(i), b);
        assert!(
            (uniform.current(b) - i).norm() < 1e-9 * (1.0 + i.norm()),
            "{i:?}"
        );
        // Borrowed with its shape at run time (a machine record's form): the same, bit for bit.
        let view = uniform.map();
        assert_eq!(view.flux_and_jacobian(i), (b, lb));
        assert_eq!(view.flux(i), b);
        assert_eq!(view.current(b), uniform.current(b));
        let model = Magnetics::Uniform(view);
        assert_eq!(model.flux_and_inductance(i), (b, lb));
        assert_eq!(model.current_from(b, i), uniform.current_from(b, i));
    }
    let t32 = ipm_table::<f32>();
    assert_eq!(
        UniformFluxTable::from_f32_table(&t32),
        UniformFluxTable::new(&t32).unwrap()
    );
    let mut skewed = table;
    skewed.i_d[3] += 0.1;
    assert!(UniformFluxTable::new(&skewed).is_none());
}

/// The uniform table's ψq(i_d, 0) (the secant's offset, one 1-D lookup on the line
/// i_q = 0) is its own 2-D interpolant's value there, inside and beyond the grid, on a map
/// whose q flux at zero q current is not zero; the compiler's build is the run-time one.
#[test]
fn a_uniform_tables_q_offset_is_its_interpolant_at_zero_q_current() {
    let mut table = ipm_table::<f64>();
    for (row, &i_d) in table.psi_q.iter_mut().zip(&table.i_d) {
        row.iter_mut().for_each(|p| *p += 0.02 + 1e-3 * i_d);
    }
    let uniform = UniformFluxTable::new(&table).unwrap();
    let view = uniform.map();
    for i_d in (-40..=20).map(|k| 0.37 * k as f64) {
        let two_d = uniform.flux(Dq::new(i_d, 0.0)).q;
        let offset = uniform.q_flux_offset(i_d);
        assert!((offset - two_d).abs() < 1e-15, "{i_d}: {offset} vs {two_d}");
        assert!(
            (offset - (0.02 + 1e-3 * i_d)).abs() < 1e-3,
            "{i_d}: {offset}"
        );
        assert_eq!(view.q_flux_offset(i_d), offset);
    }
    let f = |x: &f64| *x as f32;
    let t32 = FluxTable {
        i_d: table.i_d.map(|x| f(&x)),
        i_q: table.i_q.map(|x| f(&x)),
        psi_d: table.psi_d.map(|r| r.map(|x| f(&x))),
        psi_q: table.psi_q.map(|r| r.map(|x| f(&x))),
    };
    assert_eq!(
        UniformFluxTable::from_f32_table(&t32),
        UniformFluxTable::new(&t32).unwrap()
    );
}

/// A map built by the compiler from a `static` table is the checked map of the same table.
#[test]
fn a_const_map_is_the_checked_map() {
    static TABLE: FluxTable<f32, 16, 16> = FluxTable {
        i_d: [0.0; 16],
        i_q: [0.0; 16],
        psi_d: [[0.0; 16]; 16],
        psi_q: [[0.0; 16]; 16],
    };
    let table = ipm_table::<f32>();
    assert_eq!(table.const_map(), table.map().unwrap());
    // Non-uniform axes too.
    let mut skewed = ipm_table::<f32>();
    skewed.i_d[3] += 0.1;
    assert_eq!(skewed.const_map(), skewed.map().unwrap());
    // An unchecked table does not build (in a `static`, at compile time).
    assert!(std::panic::catch_unwind(|| TABLE.const_map()).is_err());
}

#[test]
fn a_flux_map_runs_in_f32_from_a_static_table() {
    static TABLE: FluxTable<f32, 2, 2> = FluxTable {
        i_d: [-10.0, 10.0],
        i_q: [-10.0, 10.0],
        psi_d: [[0.1, 0.1], [0.9, 0.9]],
        psi_q: [[-0.5, 0.5], [-0.5, 0.5]],
    };
    let map: Magnetics<'static, f32> = Magnetics::Map(TABLE.map().unwrap());
    let psi = map.flux(Dq::new(5.0, 2.0));
    assert!(
        (psi.d - 0.7).abs() < 1e-6 && (psi.q - 0.1).abs() < 1e-6,
        "{psi:?}"
    );
    assert!((map.current(psi) - Dq::new(5.0, 2.0)).norm() < 1e-4);
    let t16 = ipm_table::<f32>();
    let m16 = t16.map().unwrap();
    let i = Dq::new(-3.0f32, 4.0);
    let back = m16.current(m16.flux(i));
    assert!((back - i).norm() < 1e-4, "{back:?}");
    assert!(!map.is_linear());
}

#[test]
fn bad_maps_are_refused_naming_the_node() {
    let (id, iq) = ([0.0, 1.0, 2.0], [-1.0, 1.0]);
    let good_d = [0.5, 0.5, 0.6, 0.6, 0.7, 0.7];
    let good_q = [-0.1, 0.1, -0.1, 0.1, -0.1, 0.1];
    assert!(FluxMap::new(&id, &iq, &good_d, &good_q).is_ok());
    let e = FluxMap::new(&id, &iq, &good_d[..5], &good_q).unwrap_err();
    assert_eq!(e, FluxMapError::Ragged { table: "psi_d" });
    let mut d = good_d;
    d[4] = 0.55; // ψd falls from i_d = 1 to 2 at i_q = −1
    let e = FluxMap::new(&id, &iq, &d, &good_q).unwrap_err();
    assert_eq!(
        e,
        FluxMapError::NotMonotonic {
            table: "psi_d",
            k: 2,
            m: 0
        }
    );
    let mut q = good_q;
    q[3] = f64::NAN;
    let e = FluxMap::new(&id, &iq, &good_d, &q).unwrap_err();
    assert_eq!(
        e,
        FluxMapError::NotFinite {
            table: "psi_q",
            k: 1,
            m: 1
        }
    );
    // A half map (i_q ≤ 0 only) and a map away from zero d current.
    let e = FluxMap::new(&id, &[-2.0, 0.0], &good_d, &good_q).unwrap_err();
    assert_eq!(e, FluxMapError::NoZeroCurrent { axis: "i_q" });
    assert!(e.to_string().contains("symmetry"), "{e}");
    let e = FluxMap::new(&[1.0, 2.0, 3.0], &iq, &good_d, &good_q).unwrap_err();
    assert_eq!(e, FluxMapError::NoZeroCurrent { axis: "i_d" });
    let e = FluxMap::new(&[0.0, 0.0, 1.0], &iq, &good_d, &good_q).unwrap_err();
    assert_eq!(
        e,
        FluxMapError::Axis {
            axis: "i_d",
            index: 1
        }
    );
    let e = FluxMap::<f64>::new(&[0.0], &iq, &[0.0, 0.0], &[0.0, 1.0]).unwrap_err();
    assert_eq!(e, FluxMapError::TooFewNodes { axis: "i_d" });
    assert!(e.to_string().contains("i_d"));
}

#[test]
fn saturation_parameters_are_checked_naming_the_field() {
    let mut m = syrm();
    m.a_dq = -1.0;
    assert_eq!(m.validate().unwrap_err().field(), "a_dq");
    let mut m = pmsyrm();
    m.w = 1.0;
    assert_eq!(m.validate().unwrap_err().field(), "w");
    assert_eq!(
        Saturation::<f64>::default().validate().unwrap_err().field(),
        "a_d0"
    );
    // Non-finite flux gives a non-finite current, never a panic.
    assert!(!syrm().current(Dq::new(f64::NAN, 0.1)).is_finite());
    assert!(!ipm().flux(Dq::new(f64::INFINITY, 0.1)).is_finite());
}
