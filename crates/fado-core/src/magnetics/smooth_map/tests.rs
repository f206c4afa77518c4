use super::super::tests::{pmsyrm, syrm};
use super::*;
use crate::magnetics::{FluxTable, MagneticModel, Saturation};

/// motulator's 6.7 kW SyRM in fado's frame (axes swapped: d on the low-permeance axis) with
/// a magnet MMF of 0.5 A, tabulated as a user's 13 × 17 map over [−2, 1] × ±2 × its rated
/// 21.9 A (5.5 A nodes): the machine whose bilinear L_qq turns the estimator (module docs).
fn weak_magnet_syrm() -> Saturation<f64> {
    let s = syrm();
    Saturation {
        a_d0: s.a_q0,
        a_dd: s.a_qq,
        s: s.t,
        a_q0: s.a_d0,
        a_qq: s.a_dd,
        t: s.s,
        a_dq: s.a_dq,
        u: s.v,
        v: s.u,
        i_f: 0.5,
        ..s
    }
}

fn table<const ND: usize, const NQ: usize>(
    model: &Saturation<f64>,
    d: (f64, f64),
    q: (f64, f64),
) -> FluxTable<f64, ND, NQ> {
    let axis = |(a, b): (f64, f64), n: usize, k: usize| a + (b - a) * k as f64 / (n - 1) as f64;
    FluxTable::from_model(
        model,
        core::array::from_fn(|k| axis(d, ND, k)),
        core::array::from_fn(|k| axis(q, NQ, k)),
    )
}

fn syrm_table() -> FluxTable<f64, 13, 17> {
    let r = 21.9;
    table(&weak_magnet_syrm(), (-2.0 * r, r), (-2.0 * r, 2.0 * r))
}

/// The interpolant passes through every node, and its Jacobian is its own derivative
/// (central differences at points inside cells, near edges, and beyond the grid).
#[test]
fn it_passes_through_the_nodes_and_its_jacobian_is_its_derivative() {
    let t = syrm_table();
    let map = t.map().unwrap();
    for (k, &id) in map.i_d().iter().enumerate() {
        for (m, &iq) in map.i_q().iter().enumerate() {
            let (psi, _) = map.smooth_flux_and_jacobian(Dq::new(id, iq));
            let n = k * map.i_q().len() + m;
            assert!((psi.d - map.psi_d()[n]).abs() < 1e-14, "{k} {m}");
            assert!((psi.q - map.psi_q()[n]).abs() < 1e-14, "{k} {m}");
        }
    }
    let h = 1e-5;
    for &(d, q) in &[
        (-7.5, 6.3),
        (-5.6, 5.5),
        (-30.1, -12.3),
        (3.0, 40.0),
        (25.0, -47.0),
    ] {
        let i = Dq::new(d, q);
        let (_, l) = map.smooth_flux_and_jacobian(i);
        let f = |x: Dq<f64>| map.smooth_flux_and_jacobian(x).0;
        let dd = (f(i + Dq::new(h, 0.0)) - f(i - Dq::new(h, 0.0))) * (0.5 / h);
        let dq = (f(i + Dq::new(0.0, h)) - f(i - Dq::new(0.0, h))) * (0.5 / h);
        for (a, b) in [(l.dd, dd.d), (l.qd, dd.q), (l.dq, dq.d), (l.qq, dq.q)] {
            assert!((a - b).abs() < 1e-6 * (1.0 + b.abs()), "{d} {q}: {a} {b}");
        }
    }
}

/// The Jacobian is continuous across cell edges (where the bilinear one jumps) and across
/// the grid's border into the linear extension.
#[test]
fn its_jacobian_is_continuous_across_cell_edges() {
    let t = syrm_table();
    let map = t.map().unwrap();
    let e = 1e-9;
    let edge_q = map.i_q()[9];
    let edge_d = map.i_d()[8];
    let border_q = map.i_q()[16];
    for (a, b) in [
        (Dq::new(-7.5, edge_q - e), Dq::new(-7.5, edge_q + e)),
        (Dq::new(edge_d - e, 6.3), Dq::new(edge_d + e, 6.3)),
        (Dq::new(-7.5, border_q - e), Dq::new(-7.5, border_q + e)),
    ] {
        let (la, lb) = (
            map.smooth_flux_and_jacobian(a).1,
            map.smooth_flux_and_jacobian(b).1,
        );
        let (ba, bb) = (map.flux_and_jacobian(a).1, map.flux_and_jacobian(b).1);
        for (x, y) in [
            (la.dd, lb.dd),
            (la.dq, lb.dq),
            (la.qd, lb.qd),
            (la.qq, lb.qq),
        ] {
            assert!((x - y).abs() < 1e-6, "{a:?}: {x} {y}");
        }
        if a.q != border_q - e {
            let jump = (ba.qq - bb.qq).abs() + (ba.dd - bb.dd).abs() + (ba.dq - bb.dq).abs();
            assert!(jump > 1e-4, "the bilinear Jacobian jumps there: {jump}");
        }
    }
}

/// On the weak-magnet SyRM's 13 × 17 map the interpolant's incremental inductances follow
/// the machine's over the rated current range with 0.6 of the bilinear map's RMS error
/// (whose chord slopes are off by up to a quarter: L_qq at 30 % of the rated torque 0.028 H
/// against 0.038 H), and its flux is closer too. Both miss the tangent at the nodes by what
/// three nodes cannot tell (L_qq at i_q = 0: the chord 0.048 H against 0.057 H).
#[test]
fn it_follows_the_machine_closer_than_the_bilinear_map() {
    let model = weak_magnet_syrm();
    let t = syrm_table();
    let map = t.map().unwrap();
    let (mut l_smooth, mut l_bilinear) = (0.0_f64, 0.0_f64);
    let (mut flux_smooth, mut flux_bilinear) = (0.0_f64, 0.0_f64);
    let rel = |a: InductanceMatrix<f64>, b: InductanceMatrix<f64>| {
        ((a.dd - b.dd) / b.dd).powi(2) + ((a.qq - b.qq) / b.qq).powi(2)
    };
    let n = 21;
    for a in 0..n {
        for b in 0..n {
            let x = |k: usize| k as f64 / (n - 1) as f64;
            let i = Dq::new(-22.0 + 22.0 * x(a), -22.0 + 44.0 * x(b));
            let truth = model.incremental_inductance(i);
            let psi = model.flux(i);
            let (ps, ls) = map.smooth_flux_and_jacobian(i);
            let (pb, lb) = map.flux_and_jacobian(i);
            l_smooth += rel(ls, truth);
            l_bilinear += rel(lb, truth);
            flux_smooth = flux_smooth.max((ps - psi).norm());
            flux_bilinear = flux_bilinear.max((pb - psi).norm());
        }
    }
    let rms = |s: f64| (s / (2 * n * n) as f64).sqrt();
    let (l_smooth, l_bilinear) = (rms(l_smooth), rms(l_bilinear));
    std::println!(
        "L_dd, L_qq RMS relative error: smooth {l_smooth:.3}, bilinear {l_bilinear:.3}; \
         worst flux error: smooth {flux_smooth:.2e} Vs, bilinear {flux_bilinear:.2e} Vs"
    );
    assert!(l_smooth < 0.7 * l_bilinear, "{l_smooth} {l_bilinear}");
    assert!(
        flux_smooth < 0.5 * flux_bilinear,
        "{flux_smooth} {flux_bilinear}"
    );
}

/// Monotonic where the nodes are: ψd rises with i_d and ψq with i_q everywhere on the
/// PM-SyRM preset's model (its rib bends ψd sharply at small i_d) tabulated on a coarse 9 × 9
/// grid, as on the finer SyRM map.
#[test]
fn it_is_monotonic_in_its_own_current() {
    let coarse: FluxTable<f64, 9, 9> = table(&pmsyrm(), (-25.0, 25.0), (-25.0, 25.0));
    let fine = syrm_table();
    for map in [coarse.map().unwrap(), fine.map().unwrap()] {
        let (d0, d1) = (map.i_d()[0], map.i_d()[map.i_d().len() - 1]);
        let (q0, q1) = (map.i_q()[0], map.i_q()[map.i_q().len() - 1]);
        for a in 0..=60 {
            for b in 0..=60 {
                let i = Dq::new(
                    d0 + (d1 - d0) * a as f64 / 60.0,
                    q0 + (q1 - q0) * b as f64 / 60.0,
                );
                let (_, l) = map.smooth_flux_and_jacobian(i);
                assert!(l.dd > 0.0 && l.qq > 0.0, "{i:?}: {l:?}");
            }
        }
    }
}

#[test]
fn its_q_flux_offset_is_the_surface_at_zero_q_current() {
    let table = syrm_table();
    let map = table.map().unwrap();
    for k in -40..=40 {
        let i_d = 0.71 * k as f64;
        let full = map.smooth_flux_and_jacobian(Dq::new(i_d, 0.0)).0.q;
        let offset = map.smooth_q_flux_offset(i_d);
        assert!((full - offset).abs() < 1e-12, "{i_d}: {full} vs {offset}");
    }
}

/// The node slopes a map carries are the ones a lookup finds: the same interpolant bit for
/// bit, inside and beyond the grid; the flux alone is the full lookup's flux bit for bit;
/// slopes that are not the map's own are refused.
#[test]
fn carried_node_slopes_give_the_same_interpolant() {
    let t = syrm_table();
    let map = t.map().unwrap();
    let mut slopes = std::vec![0.0; 2 * map.psi_d().len()];
    assert!(map.fill_node_slopes(&mut slopes));
    assert!(!map.fill_node_slopes(&mut slopes[1..]));
    let carrying = map.with_node_slopes(&slopes).unwrap();
    for a in 0..=40 {
        for b in 0..=40 {
            let i = Dq::new(-50.0 + 1.9 * a as f64, -50.0 + 2.5 * b as f64);
            let full = map.smooth_flux_and_jacobian(i);
            assert_eq!(carrying.smooth_flux_and_jacobian(i), full, "{i:?}");
            assert_eq!(carrying.smooth_flux(i), full.0, "{i:?}");
            assert_eq!(map.smooth_flux(i), full.0, "{i:?}");
        }
    }
    let mut wrong = slopes.clone();
    wrong[5] += 1e-3;
    assert!(map.with_node_slopes(&wrong).is_err());
    assert!(map.with_node_slopes(&slopes[1..]).is_err());
}

/// A map made odd in i_q (its i_q = 0 column zero at every node) is found so when built, and
/// its q flux offset is the full surface's ψq(i_d, 0), zero, inside and beyond the grid; one
/// node of that column off zero and the offset is the surface's again, not zero.
#[test]
fn a_map_odd_in_q_current_has_no_q_flux_offset() {
    let mut table = syrm_table();
    let m0 = table.i_q.iter().position(|&x| x == 0.0).unwrap();
    assert!(table.psi_q.iter().all(|row| row[m0] == 0.0));
    let map = table.map().unwrap();
    assert!(map.q_offset_zero());
    for k in -40..=40 {
        let i_d = 0.71 * k as f64;
        let full = map.smooth_flux_and_jacobian(Dq::new(i_d, 0.0)).0.q;
        assert_eq!(map.smooth_q_flux_offset(i_d), full, "{i_d}");
        assert_eq!(full, 0.0, "{i_d}");
    }
    assert!(map.smooth_q_flux_offset(f64::NAN).is_nan());
    table.psi_q[6][m0] = 1e-4;
    let map = table.map().unwrap();
    assert!(!map.q_offset_zero());
    let i_d = table.i_d[6];
    let offset = map.smooth_q_flux_offset(i_d);
    let full = map.smooth_flux_and_jacobian(Dq::new(i_d, 0.0)).0.q;
    assert!((offset - 1e-4).abs() < 1e-12 && (full - offset).abs() < 1e-12);
}
