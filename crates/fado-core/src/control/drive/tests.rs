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
    use crate::magnetics::MachineMagnetics;
    use crate::{Dq, MachineModel};
    let sat = std::boxed::Box::leak(std::boxed::Box::new(crate::magnetics::tests::pmsyrm()));
    let m = MachineModel {
        rs: 0.63,
        ld: 0.0298,
        lq: 0.1497,
        flux_linkage: 0.4767,
        pole_pairs: 2,
        rated_current: 12.45,
        rated_speed_rpm: 1800.0,
        rated_torque: 29.7,
        magnetics: MachineMagnetics::Saturation(sat),
        ..MachineModel::paper()
    };
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
            let (i, _) = drive.saturated_currents_for_torque(&s, iq_torque, guess, 0.0);
            let (new, old) = ((i.q - cold_iq).abs(), (once(guess) - cold_iq).abs());
            std::println!("{iq_torque:8.3} from {guess:8.3}: {new:.1e} A (cold {old:.1e} A)");
            assert!(
                new.max(old) < bound * m.rated_current,
                "{iq_torque}: {new} vs {old}"
            );
        }
    }
}
