use super::fits::Ls2;
use super::sizing::if_level;
use super::*;
use crate::MachineModel;

/// The two-window line recovers λf exactly from an EMF with a speed-independent error
/// e₀ (the inverter's residual, −0.24 V on the 50 kW IPMSM preset at the spin speed),
/// which the single-window ratio ∫E/∫ω reads as a flux error e₀/ω̄ (−2 % there).
#[test]
fn two_emf_windows_remove_a_constant_emf_error() {
    let (flux, e0, ts) = (0.066, -0.24, 5e-5);
    let mut w = [EmfWindow::<f64>::new(200); 2];
    // Decelerating windows at 157 rad/s and twice that (the coast and the inertia
    // test's top), 0.25 s each.
    for (k, w0) in [(0usize, 157.0), (1, 314.0)] {
        for n in 0..5000 {
            let omega = w0 * (1.0 - 0.2 * n as f64 / 5000.0);
            w[k].push(flux * omega + e0, omega, ts);
        }
    }
    let single = w[0].e / w[0].w;
    assert!(
        (single / flux - 1.0 - e0 / (flux * 141.3)).abs() < 2e-3,
        "{single}"
    );
    let (f, sigma, ds) = emf_line(&w[0], &w[1]);
    assert!((f / flux - 1.0).abs() < 1e-9, "{f}");
    assert!(ds > 100.0 && sigma.is_finite(), "{ds} {sigma}");
}

/// The inertia regression on window means: J and B recovered from a simulated run of
/// torque steps although the speed estimate carries a ripple of ±30 r/min at 137 Hz
/// (the back-EMF PLL's on the 50 kW IPMSM preset at low speed); the reluctance part of
/// the torque enters with λ̂f known only at the end. The same windows with the speed
/// taken at their ends (the regression before) miss J by several per cent.
#[test]
fn inertia_windows_average_out_the_speed_ripple() {
    let (j, b, flux, p, ts) = (0.0388, 5.1e-3, 0.066, 3.0, 5e-5);
    let dl = -0.83e-3;
    let n_win = libm_round(J_WINDOW / ts);
    let mut fit = JFit::<f64>::default();
    let mut win = JWindows::<f64>::default();
    // Endpoint regression: Δω between window ends on ∫Te and ∫ω over the window.
    let mut ends = Ls2::<f64>::default();
    let (mut e_k, mut e_w0, mut e_te, mut e_w) = (0u32, 0.0, 0.0, 0.0);
    let mut omega = 50.0;
    let mut t = 0.0;
    // Step up (i_q 25 A, a little i_d), a break, step down.
    for (iq, id, dur) in [(25.0, -2.0, 0.5), (0.0, 0.0, -1.0), (-25.0, 3.0, 0.5)] {
        if dur < 0.0 {
            win.reset();
            e_k = 0;
            continue;
        }
        for _ in 0..(dur / ts) as usize {
            let u = 1.5 * p * iq;
            let r = 1.5 * p * dl * id * iq;
            let ripple = 3.1 * (core::f64::consts::TAU * 137.0 * t).sin();
            let omega_hat = omega + ripple;
            win.push(omega_hat, u, r, ts, n_win, &mut fit);
            if e_k == 0 {
                (e_w0, e_te, e_w) = (omega_hat, 0.0, 0.0);
            }
            e_te += (flux * u + r) * ts;
            e_w += omega_hat * ts;
            e_k += 1;
            if e_k >= n_win {
                let (x1, x2, y) = (e_te, -e_w, omega_hat - e_w0);
                ends.a11 += x1 * x1;
                ends.a12 += x1 * x2;
                ends.a22 += x2 * x2;
                ends.b1 += x1 * y;
                ends.b2 += x2 * y;
                ends.yy += y * y;
                ends.n += 1.0;
                e_k = 0;
            }
            omega += ts * ((flux * u + r) - b * omega) / j;
            t += ts;
        }
    }
    let ((inv_j, b_over_j), _) = fit.with_flux(flux).solve().unwrap();
    assert!((1.0 / inv_j / j - 1.0).abs() < 0.01, "J {}", 1.0 / inv_j);
    assert!(
        (b_over_j / inv_j / b - 1.0).abs() < 0.2,
        "B {}",
        b_over_j / inv_j
    );
    let ((inv_j_ends, _), _) = ends.solve().unwrap();
    assert!(
        (1.0 / inv_j_ends / j - 1.0).abs() > 0.03,
        "J {}",
        1.0 / inv_j_ends
    );
}

/// The I-f current keeps the rotor's lag stable and the active flux at least λf/2 on a
/// salient rotor (the 50 kW IPMSM preset: λf 0.066 Wb, Lq − Ld 0.83 mH, limit 120 A),
/// and is the usual 90 % of the limit on a non-salient one.
#[test]
fn the_if_current_respects_the_reluctance_limit() {
    let gem = MachineModel {
        rs: 0.018,
        ld: 0.37e-3,
        lq: 1.2e-3,
        flux_linkage: 0.066,
        ..MachineModel::<f64>::paper()
    };
    let i = if_level(&gem, gem.ld, gem.lq, 120.0);
    assert!(
        i <= 0.5 * gem.flux_linkage / (gem.lq - gem.ld) + 1e-12,
        "{i}"
    );
    assert!(gem.flux_linkage + (gem.ld - gem.lq) * i >= 0.5 * gem.flux_linkage - 1e-12);
    let paper = MachineModel::<f64>::paper();
    assert_eq!(if_level(&paper, paper.ld, paper.lq, 10.0), 9.0);
}

/// The pulses' plan (module docs, step 5): a heavy rotor keeps 16-sample rises and single
/// pairs; the 750 W servo SPM's light rotor (2e-4 kg·m², 5 pole pairs, 3.1 N·m at 6 A) gets
/// rises of about 5 samples, each pair repeated an even number of times (its order
/// alternating, so the rotor returns), about as many samples as one full pair; rises never
/// below 4 samples, and a nameplate that gives no number keeps the full ones.
#[test]
fn light_rotors_get_short_alternating_pulses() {
    use super::flux_pulses::pulse_plan;
    let servo = MachineModel {
        rs: 1.1,
        ld: 1.5e-3,
        lq: 3e-3,
        flux_linkage: 0.07,
        pole_pairs: 5,
        inertia: 2e-4,
        viscous_friction: 0.0,
        rated_current: 6.0,
        rated_speed_rpm: 3000.0,
        rated_torque: 3.1,
        dc_voltage: 320.0,
        ..MachineModel::<f64>::paper()
    };
    let plan = |inertia: f64| {
        let np = MachineModel { inertia, ..servo };
        pulse_plan(&CommissioningConfig::for_machine(np, 1e-4, 2.5e-6), 6.0)
    };
    let (n, repeats) = plan(2e-4);
    // 2·p·T_p·(N·Ts)²/J = 0.05 rad: T_p = 1.5·5·(0.07 + 1.5e-3·6)·6 = 3.56 N·m.
    let expected = (0.05f64 * 2e-4 / (2.0 * 5.0 * 3.555)).sqrt() / 1e-4;
    assert!(
        (n - expected).abs() < 1e-9 && (5.0..6.0).contains(&n),
        "{n}"
    );
    assert_eq!(repeats, 4);
    assert!(n * repeats as f64 >= 16.0);
    assert_eq!(plan(2e-2), (16.0, 1));
    // Full-length rises would turn a 1.3e-3 kg·m² rotor by 0.07 rad, below four times the
    // target, but its back-EMF at the pair's peak speed would be 0.07·λf/(2·L̂d·I_p) = 0.27 of
    // the pulse voltage: the rise is the one that keeps it at 0.2 (a turn of 0.0514 rad).
    let emf_turn: f64 = 0.4 * 1.5e-3 * 6.0 / 0.07;
    let expected = (emf_turn * 1.3e-3 / (2.0 * 5.0 * 3.555)).sqrt() / 1e-4;
    let (n, repeats) = plan(1.3e-3);
    assert!(
        (n - expected).abs() < 1e-9 && (13.0..14.0).contains(&n),
        "{n}"
    );
    assert_eq!(repeats, 2);
    // A rotor of 2e-3 kg·m² keeps it below 0.2 with full-length rises.
    assert_eq!(plan(2e-3), (16.0, 1));
    assert_eq!(plan(1e-7), (4.0, 4));
    assert_eq!(plan(f64::NAN), (16.0, 1));
}

/// The verdict names the cause: a rotor that turned is never "not detected", nor is a fit
/// whose inductances change by more than a quarter without explaining the data.
#[test]
fn the_saturation_verdict_names_the_cause() {
    use super::flux_pulses::verdict;
    use SaturationVerdict::*;
    assert_eq!(verdict(false, 0.53, 0.76), RotorMoved);
    assert_eq!(verdict(true, 0.53, 0.76), RotorMoved);
    assert_eq!(verdict(true, 0.53, 0.01), Detected);
    assert_eq!(verdict(false, 0.53, 0.01), Inconclusive);
    assert_eq!(verdict(false, 0.11, 0.01), NotDetected);
    assert_eq!(verdict(false, f64::NAN, f64::NAN), NotMeasured);
}
