use super::*;
use core::f64::consts::PI;

fn comp(method: DeadTimeMethod) -> DeadTimeCompensation<f64> {
    DeadTimeCompensation::new(DeadTimeCompensationConfig {
        method,
        ripple_inductance: Dq::zero(),
        ..DeadTimeCompensationConfig::for_machine(&MachineModel::paper())
    })
    .unwrap()
}

#[test]
fn amplitude_is_dead_time_average_plus_threshold() {
    let c = comp(DeadTimeMethod::Trapezoidal);
    // 2.5 µs · 5 kHz · 300 V + 1 V
    assert!((c.amplitude(300.0) - 4.75).abs() < 1e-12);
    let off = DeadTimeCompensation::new(DeadTimeCompensationConfig {
        enabled: false,
        ..DeadTimeCompensationConfig::<f64>::for_machine(&MachineModel::paper())
    })
    .unwrap();
    assert_eq!(off.amplitude(300.0), 0.0);
    let rot = Rotation::from_angle(0.2);
    assert_eq!(
        off.step(
            rot,
            Dq::new(0.0, 10.0),
            Abc::new(1.0, 2.0, -3.0),
            Ab::zero(),
            300.0
        ),
        Ab::zero()
    );
}

#[test]
fn trapezoid_follows_spec_formula_sign_and_magnitude() {
    let c = comp(DeadTimeMethod::Trapezoidal);
    let vhat = c.amplitude(300.0);
    let (theta_adv, i_ref) = (0.4, Dq::new(1.0, 5.0));
    let rot = Rotation::from_angle(theta_adv);
    let v = c.phase_voltages(rot, i_ref, Abc::default(), Ab::zero(), 300.0);
    let theta_i = theta_adv + 5.0_f64.atan2(1.0);
    let mag = i_ref.norm();
    for (vx, phi) in [(v.a, 0.0), (v.b, 2.0 * PI / 3.0), (v.c, -2.0 * PI / 3.0)] {
        let ix = mag * (theta_i - phi).cos();
        let expected = vhat * (ix / 0.3).clamp(-1.0, 1.0);
        assert!((vx - expected).abs() < 1e-12, "{vx} vs {expected}");
    }
    // Trapezoid over one electrical turn: plateaus at ±V̂, linear through zero with slope
    // V̂/Ic per ampere, and the compensation pushes each pole towards its current.
    let mut plateau = 0;
    for k in 0..3600 {
        let th = k as f64 * 2.0 * PI / 3600.0;
        let va = c
            .phase_voltages(
                Rotation::from_angle(th),
                Dq::new(2.0, 0.0),
                Abc::default(),
                Ab::zero(),
                300.0,
            )
            .a;
        let ia = 2.0 * th.cos();
        assert!(va * ia >= 0.0 && va.abs() <= vhat + 1e-12);
        if ia.abs() >= 0.3 {
            assert!((va.abs() - vhat).abs() < 1e-12);
            plateau += 1;
        } else {
            assert!((va - vhat * ia / 0.3).abs() < 1e-12);
        }
    }
    // |cos| ≥ 0.15 over all but 2·2·asin(0.15)/2π ≈ 9.6 % of the turn.
    assert!((plateau as f64 / 3600.0 - (1.0 - 4.0 * 0.15_f64.asin() / (2.0 * PI))).abs() < 2e-3);
}

#[test]
fn sign_variant_uses_measured_currents() {
    let c = comp(DeadTimeMethod::Sign);
    let v = c.phase_voltages(
        Rotation::from_angle(0.0),
        Dq::new(10.0, 0.0),
        Abc::new(0.01, -0.02, 0.0),
        Ab::zero(),
        300.0,
    );
    assert_eq!(v, Abc::new(4.75, -4.75, 0.0));
    // Clarke: the α-β vector of the per-phase compensation.
    let ab = c.step(
        Rotation::from_angle(0.0),
        Dq::zero(),
        Abc::new(1.0, -0.5, -0.5),
        Ab::zero(),
        300.0,
    );
    assert!((ab.alpha - 4.75 * (2.0 + 2.0) / 3.0).abs() < 1e-12 && ab.beta.abs() < 1e-12);
}

fn edge(l: f64) -> DeadTimeCompensation<f64> {
    let l = Dq::new(l, l);
    DeadTimeCompensation::new(DeadTimeCompensationConfig {
        method: DeadTimeMethod::EdgeCurrent,
        ripple_inductance: l,
        ..DeadTimeCompensationConfig::for_machine(&MachineModel::paper())
    })
    .unwrap()
}

#[test]
fn edge_current_is_the_trapezoid_outside_the_band_and_odd() {
    let c = edge(2.63e-3);
    let t = comp(DeadTimeMethod::Trapezoidal);
    let rot = Rotation::from_angle(0.0);
    // Every phase far outside Ic + ripple: exactly the trapezoid (±V̂ per phase).
    for (i, v) in [
        (Ab::new(12.0, 3.0), Ab::new(4.0, 1.0)),
        (Ab::new(-2.0, 8.0), Ab::new(-60.0, 90.0)),
    ] {
        let i_dq = Dq::new(i.alpha, i.beta);
        let e = c.phase_voltages(rot, i_dq, Abc::default(), v, 300.0);
        let p = t.phase_voltages(rot, i_dq, Abc::default(), v, 300.0);
        assert!((e.a - p.a).abs() < 1e-12 && (e.b - p.b).abs() < 1e-12);
        assert!((e.c - p.c).abs() < 1e-12, "{e:?} vs {p:?}");
    }
    // Odd: (−i, −v) gives −v_comp; within the band it differs from the trapezoid but
    // stays within ±V̂ and pushes each pole towards its current.
    let vhat = c.amplitude(300.0);
    for ib in [-0.25, -0.1, 0.05, 0.2] {
        let i = Abc::new(-12.0 - 0.5 * ib, ib, 12.0 - 0.5 * ib).to_ab();
        let v = i * 0.327;
        let i_dq = Dq::new(i.alpha, i.beta);
        let neg = Dq::new(-i.alpha, -i.beta);
        let e = c.phase_voltages(rot, i_dq, Abc::default(), v, 300.0);
        let f = c.phase_voltages(rot, neg, Abc::default(), v * -1.0, 300.0);
        assert!(
            (e.a + f.a).abs() < 1e-9 && (e.b + f.b).abs() < 1e-9,
            "{e:?} {f:?}"
        );
        assert!(e.b.abs() <= vhat && e.b * ib >= 0.0, "{ib}: {e:?}");
    }
    // No inductance or no DC link: the trapezoid.
    let i = Dq::new(-0.1, 0.2);
    let e = edge(0.0).phase_voltages(rot, i, Abc::default(), Ab::new(1.0, 0.0), 300.0);
    assert_eq!(
        e,
        t.phase_voltages(rot, i, Abc::default(), Ab::zero(), 300.0)
    );
    assert_eq!(
        c.phase_voltages(rot, i, Abc::default(), Ab::new(1.0, 0.0), -1.0),
        Abc::default()
    );
}

/// The MAD 5010 KV110's inverter (44.4 V, 20 kHz, Td 0.625 µs, Ic 0.138 A) on 85 µH at
/// the rated DC link `vdc`.
fn kv110(vdc: f64) -> DeadTimeCompensation<f64> {
    DeadTimeCompensation::new(DeadTimeCompensationConfig {
        enabled: true,
        method: DeadTimeMethod::EdgeCurrent,
        dead_time: 0.625e-6,
        switching_frequency: 20e3,
        threshold_voltage: 44.4 / 311.0,
        current_band: 0.137_739_130_434_782_6,
        ripple_inductance: Dq::new(85e-6, 85e-6),
        dc_voltage: vdc,
    })
    .unwrap()
}

#[test]
fn the_loop_gain_chooses_the_solve_on_either_side_of_the_threshold() {
    // g = Vdc·Td/(3·min(L̂d, L̂q)·Ic): the paper's motor 311 V, 2.5 µs, 2.63 mH, 0.3 A.
    let paper = edge(2.63e-3);
    let g = 311.0 * 2.5e-6 / (3.0 * 2.63e-3 * 0.3);
    assert!((paper.loop_gain() - g).abs() < 1e-12 && !paper.solves_edges());
    // The MAD 5010 KV110 at 44.4 V: g = 0.79, the root solve.
    let kv = kv110(44.4);
    assert!((kv.loop_gain() - 0.790).abs() < 1e-3 && kv.solves_edges());
    // Either side of the threshold through the rated DC link alone.
    let at = |g: f64| kv110(44.4 * g / kv.loop_gain());
    assert!(!at(EDGE_SOLVE_LOOP_GAIN * 0.999).solves_edges());
    assert!(at(EDGE_SOLVE_LOOP_GAIN * 1.001).solves_edges());
    assert!(!kv110(0.0).solves_edges());
    // The chosen solve is the one used: standstill under 5.55 A, phase b at 0.2 A, where
    // its edge currents (the ripple ±0.33 A) are in the band.
    let rs = 0.6193;
    let ib = 0.2;
    let i = Abc::new(-5.55 - 0.5 * ib, ib, 5.55 - 0.5 * ib);
    let v = Abc::new(rs * i.a, rs * i.b, rs * i.c);
    let rot = Rotation::from_angle(0.0);
    let out = |c: &DeadTimeCompensation<f64>, (r, f): ([f64; 3], [f64; 3])| {
        let per_second = 44.4 * 20e3;
        let vth = c.config().threshold_voltage;
        let ic = c.config().current_band;
        let x = [i.a, i.b, i.c];
        [0, 1, 2].map(|k| per_second * (r[k] - f[k]) + vth * (x[k] / ic).clamp(-1.0, 1.0))
    };
    let x = [i.a, i.b, i.c];
    for (c, solved) in [(at(EDGE_SOLVE_LOOP_GAIN * 0.999), false), (kv, true)] {
        let d = if solved {
            c.edge_delays(rot, x, [v.a, v.b, v.c], 44.4)
        } else {
            c.passes_delays(rot, i, v, 44.4)
        };
        let want = out(&c, d);
        let got = c.edge_current(rot, i, v, 44.4);
        for (g, w) in [got.a, got.b, got.c].into_iter().zip(want) {
            assert!(
                (g - w).abs() < 1e-12,
                "solved {solved}: {got:?} vs {want:?}"
            );
        }
    }
    // The two solves differ there (else the test could not tell them apart).
    let d_solve = kv.edge_delays(rot, x, [v.a, v.b, v.c], 44.4);
    let d_pass = kv.passes_delays(rot, i, v, 44.4);
    let gap = (out(&kv, d_solve)[1] - out(&kv, d_pass)[1]).abs();
    assert!(gap > 0.05, "{gap} V");
}

#[test]
fn the_root_solve_runs_below_a_loop_gain_of_one_where_the_middle_pole_follows() {
    // The MAD 5010 KV110 (g = 0.79) at standstill under 0.5 A, phase b at 0.05 A: the
    // references plus the trapezoid 0.6–1.6 V apart, under 4·Td·f_sw·Vdc = 2.22 V: the
    // passes; under 5.55 A, b at 0.2 A, ≥ 3 V apart: the root solve. At g = 1.01: passes.
    let kv = kv110(44.4);
    let at_one = kv110(44.4 * 1.01 / kv.loop_gain());
    assert!(kv.solves_edges() && at_one.loop_gain() >= 1.0 && !at_one.solves_edges());
    assert!(!kv110(44.4 * 1.0001 / kv.loop_gain()).solves_edges());
    assert!(kv110(44.4 * 0.99 / kv.loop_gain()).solves_edges());
    let rot = Rotation::from_angle(0.0);
    for (load, ib, kv_solves) in [(0.5, 0.05, false), (5.55, 0.2, true)] {
        let i = Abc::new(-load - 0.5 * ib, ib, load - 0.5 * ib);
        let v = Abc::new(0.6193 * i.a, 0.6193 * i.b, 0.6193 * i.c);
        let x = [i.a, i.b, i.c];
        let out = |c: &DeadTimeCompensation<f64>, (r, f): ([f64; 3], [f64; 3])| {
            let per_second = 44.4 * 20e3;
            let vth = c.config().threshold_voltage;
            let ic = c.config().current_band;
            [0, 1, 2].map(|k| per_second * (r[k] - f[k]) + vth * (x[k] / ic).clamp(-1.0, 1.0))
        };
        let passes = out(&kv, kv.passes_delays(rot, i, v, 44.4));
        let solve = out(&kv, kv.edge_delays(rot, x, [v.a, v.b, v.c], 44.4));
        assert!((passes[1] - solve[1]).abs() > 0.01, "{passes:?} {solve:?}");
        let kv_want = if kv_solves { solve } else { passes };
        for (c, want) in [(&kv, kv_want), (&at_one, passes)] {
            let got = c.edge_current(rot, i, v, 44.4);
            for (g, w) in [got.a, got.b, got.c].into_iter().zip(want) {
                assert!((g - w).abs() < 1e-12, "{load} A: {got:?} vs {want:?}");
            }
        }
    }
}

#[test]
fn bad_config_names_field() {
    let bad = |f: fn(&mut DeadTimeCompensationConfig<f64>)| {
        let mut cfg = DeadTimeCompensationConfig::for_machine(&MachineModel::paper());
        f(&mut cfg);
        DeadTimeCompensation::new(cfg).unwrap_err().field()
    };
    assert_eq!(bad(|c| c.dead_time = -1e-6), "dead_time");
    assert_eq!(bad(|c| c.dead_time = 1e-3), "dead_time");
    assert_eq!(bad(|c| c.switching_frequency = 0.0), "switching_frequency");
    assert_eq!(bad(|c| c.threshold_voltage = f64::NAN), "threshold_voltage");
    assert_eq!(bad(|c| c.current_band = 0.0), "current_band");
    assert_eq!(
        bad(|c| c.ripple_inductance = Dq::new(1e-3, -1e-3)),
        "ripple_inductance"
    );
    assert_eq!(bad(|c| c.dc_voltage = -1.0), "dc_voltage");
}
