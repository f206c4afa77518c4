use core::cell::Cell;

use super::super::tests::{currents, ipm_table, models};
use super::super::{ConstantInductance, NEWTON_ITERATIONS, Saturation, newton, newton_checked};
use super::*;

/// A stiff made-up ferrite PM-SyRM (L_d 0.25 mH, L_q 1.4 mH unsaturated, λf 0.05 Wb as an
/// MMF, strong q and cross saturation): Newton's method from a poor start needs many steps.
fn ferrite() -> Saturation<f64> {
    // The magnet as its MMF: i_f = λf/L_d = 200 A.
    let (a_qq, a_dq) = (2.0e8, 1.0e9);
    Saturation {
        a_qq,
        t: 4.0,
        a_dq,
        u: 1.0,
        v: 1.0,
        i_f: 0.05 / 0.25e-3,
        ..Saturation::linear(0.25e-3, 1.4e-3, 0.0)
    }
}

/// Newton's evaluations of `m`'s ψ(i) from `start` (the solve of `flux_from`, counted, with
/// its restart from the linear guess where the solve from `start` does not converge) and
/// its answer.
fn counted(m: &Saturation<f64>, i: Dq<f64>, start: Dq<f64>) -> (Dq<f64>, usize) {
    let n = Cell::new(0);
    let f = |psi| {
        n.set(n.get() + 1);
        m.current_and_jacobian(psi)
    };
    let (mut psi, _, converged) = newton_checked(i, start, m.newton_scale(), f);
    if !converged {
        psi = newton(i, m.linear_flux(i), m.newton_scale(), f).0;
    }
    let expected = m.flux_from(i, start);
    assert_eq!(psi, expected, "the counted solve is flux_from's");
    (psi, n.get())
}

/// From the tangent plane at any solution of the grid (±2 × a rated current, every pair of
/// points: a sample's step and the whole range) the solve converges to the cold solve's root
/// within its tolerance: on the published fits from its start, on the stiff ferrite
/// machine from the opposite corner of the range after a restart from the linear guess.
#[test]
fn a_warm_start_from_anywhere_converges_to_the_cold_root() {
    let stiff = ("ferrite", ferrite(), 180.0);
    for (name, m, i_max) in models().into_iter().chain([stiff]) {
        let cap = if name == "ferrite" {
            2 * NEWTON_ITERATIONS
        } else {
            NEWTON_ITERATIONS
        };
        let model = Magnetics::Saturation(m);
        let mut worst = 0;
        for i0 in currents(2.0 * i_max) {
            let (_, warm) = model.flux_warm(i0, Dq::zero(), &FluxWarmStart::empty());
            assert!(warm.is_set(), "{name}");
            for i in currents(2.0 * i_max) {
                let cold = m.flux(i);
                let (psi, next) = model.flux_warm(i, Dq::zero(), &warm);
                assert!(
                    (psi - cold).norm() < 1e-13 * (1.0 + cold.norm()),
                    "{name}: {i:?} from the plane at {i0:?}: {psi:?} vs {cold:?}"
                );
                // The next plane passes through this solution.
                assert!((next.prediction(i) - psi).norm() < 1e-13 * (1.0 + psi.norm()));
                let (_, n) = counted(&m, i, warm.guess(i, Dq::zero()));
                worst = worst.max(n);
            }
        }
        assert!(worst < cap, "{name}: {worst} evaluations");
    }
}

/// A sample's current change (up to 2 % of the rated current) from the last solution: the
/// tangent plane's prediction saves the step that a start at the last flux takes to reach
/// it, at every point, and leaves at most four evaluations (two for 95 % of 0.2 % steps: one
/// step and the one that confirms it) where the model's own linear guess takes five to
/// thirteen on these models.
#[test]
fn a_sample_step_from_the_last_solution_takes_one_step_and_its_confirmation() {
    for (name, m, i_max) in models() {
        let model = Magnetics::Saturation(m);
        let (mut worst, mut cold, mut two, mut small) = (0, 0, 0, 0);
        for i0 in currents(2.0 * i_max) {
            let (psi0, warm) = model.flux_warm(i0, Dq::zero(), &FluxWarmStart::empty());
            for step in [0.002, 0.02] {
                for (a, b) in [(1.0, 0.0), (0.0, 1.0), (-0.7, 0.7), (0.3, -1.0)] {
                    let i = i0 + Dq::new(a, b) * (step * i_max);
                    let (psi, n) = counted(&m, i, warm.guess(i, Dq::zero()));
                    assert!((psi - m.flux(i)).norm() < 1e-13 * (1.0 + psi.norm()));
                    let from_last = counted(&m, i, psi0).1;
                    assert!(
                        n < from_last,
                        "{name}: {i:?} from {i0:?}: {n} vs {from_last}"
                    );
                    worst = worst.max(n);
                    cold = cold.max(counted(&m, i, m.linear_flux(i)).1);
                    if step < 0.01 {
                        small += 1;
                        two += usize::from(n <= 2);
                    }
                }
            }
        }
        assert!(worst <= 4, "{name}: {worst} evaluations");
        assert!(two * 100 >= 95 * small, "{name}: {two} of {small}");
        assert!(cold >= 5, "{name}: {cold}");
    }
}

/// Models whose ψ(i) is no iteration evaluate it directly, bit for bit, and leave the warm
/// start as it is (no plane and no Jacobian on a flux map's path).
#[test]
fn a_closed_form_model_ignores_the_warm_start() {
    let table = ipm_table::<f64>();
    let map = table.map().unwrap();
    let constant = ConstantInductance {
        ld: 0.036,
        lq: 0.051,
        flux_linkage: 0.545,
    };
    let (_, m, _) = models()[2];
    let (_, warm) =
        Magnetics::Saturation(m).flux_warm(Dq::new(-3.0, 4.0), Dq::zero(), &FluxWarmStart::empty());
    for model in [Magnetics::Map(map), Magnetics::Constant(constant)] {
        for i in currents(10.0) {
            for w in [FluxWarmStart::empty(), warm] {
                let (psi, next) = model.flux_warm(i, Dq::new(1.0, -1.0), &w);
                assert_eq!(psi, model.flux(i));
                assert_eq!(next, w);
            }
        }
    }
}

/// An empty warm start predicts nothing (a non-finite flux, so that a model starts from its
/// own guess) and falls back to the caller's guess.
#[test]
fn an_empty_warm_start_falls_back() {
    let w = FluxWarmStart::<f64>::empty();
    assert!(!w.is_set());
    assert!(!w.prediction(Dq::new(1.0, 2.0)).is_finite());
    assert_eq!(
        w.guess(Dq::new(1.0, 2.0), Dq::new(0.5, 0.1)),
        Dq::new(0.5, 0.1)
    );
    assert_eq!(w, FluxWarmStart::default());
}
