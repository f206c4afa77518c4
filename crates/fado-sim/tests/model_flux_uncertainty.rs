//! The figure commissioning writes for the identified model's flux uncertainty,
//! `[estimator.rs_adaptation] model_flux_uncertainty` + `model_flux_uncertainty_rated`·|i|²/I_rated²
//! (`Identification::model_flux_uncertainty`, `Identification::model_flux_uncertainty_rated`),
//! against the identified model's flux error at the plant's MTPA operating points (0, 30, 65 and
//! 100 % of rated torque), both as a share of the identified λ̂f: what the online R̂s law takes
//! the model's flux error to be at the current where it runs (docs/method/saturation.md, "The
//! offset law's gate").
//!
//! Measured (`cargo test --release -p fado-sim --test model_flux_uncertainty -- --include-ignored
//! --nocapture`, sensor seed 1), the loaded error (less the magnet's) at 30 / 65 / 100 % of rated
//! torque against the figure there: ipmsm-2k2-qsat 0.0003 / 0.0005 / 0.0008 against 0.0008 /
//! 0.0010 / 0.0015; pmsm-gem-1k1-measured 0.0035 / 0.0062 / 0.0105 against 0.0078 / 0.0100 /
//! 0.0139; pmsyrm-baldor-5k6 0.0069 / 0.0129 / 0.0175 against 0.0192 / 0.0264 / 0.0362;
//! pmsyrm-baldor-5k6-measured 0.0227 / 0.0054 / 0.0039 against 0.0297 / 0.0347 / 0.0417;
//! ipmsm-test-saturated 0.0005 / 0.0003 / 0.0001 against 0.0051 / 0.0058 / 0.0068; the six
//! saturated test machines below at most 0.0028, each below its figure (at least 0.0011 there). The constant figure
//! alone (the first term, the fit's RMS current residual times its larger inductance) falls
//! short at rated torque on three of the five presets (0.0008, 0.0105, 0.0175 against 0.0007,
//! 0.0072, 0.0160); the growth, the fit's worst RMS flux residual in a quarter of the pulses'
//! current range, covers it.
//!
//! The magnet's error, the error at zero current, is outside the figure: it is the identified
//! λ̂f's (the back-EMF windows read ψd(−c, 0) + L̂d·c at the coast's d current −c, which on a
//! saturating machine is not ψd(0, 0)), which the λ̂f law learns online. With it the error is
//! 0.081–0.086 of λ̂f on the PM-SyRM's measured map (figure 0.027–0.042), 0.030–0.046 on its
//! algebraic model (0.016–0.036), 0.034–0.037 on the traction IPMSM (0.018–0.028), 0.0072 on
//! the made-up IPMSM (0.0050–0.0068), 0.0088 on the servo SPM (0.0028–0.0051):
//! [`the_written_figure_bounds_the_magnets_flux_error_too`] is ignored. The model's own
//! prediction of that error, its d flux at −c less at zero plus L̂d·c, has the right size on
//! the PM-SyRMs (0.024 and 0.058 against 0.030 and 0.083) but the wrong sign on
//! pmsm-gem-1k1-measured (+0.013 against −0.003), whose law it would freeze.
//!
//! A constant figure that bounds the loaded error costs the law its reach: the fit's largest
//! flux residual over all the pulses (0.0191 on pmsm-gem-1k1-measured) freezes the law at most
//! loaded points there, whose commissioned model then cannot learn a winding 1.3 or 0.8 times
//! its commissioned resistance ([`a_commissioned_model_learns_a_changed_winding_resistance`]:
//! R̂s ends at 0.952 / 1.030 × Rs, `rated-reversal` lost at 0.82 / 1.04 rad; with a constant
//! figure set by hand 0.0105 passes, 0.016 fails). The growing figure, 0.0072 at zero current
//! and 0.0139 at the rated one, keeps that reach.

use fado_core::Dq;
use fado_core::magnetics::{MagneticModel, Magnetics};
use fado_sim::commission::commission_on_own_nameplate;
use fado_sim::magnetic_accuracy::plant_model;
use fado_sim::scenario::{run_config, scenario_config};

/// The plant's MTPA current for `torque` (N·m): the smallest current magnitude whose best
/// angle (i_d ≤ 0, 0.25° steps) reaches it, by bisection.
fn mtpa(model: &impl MagneticModel<f64>, pole_pairs: f64, torque: f64, i_max: f64) -> Dq<f64> {
    let best = |i: f64| {
        (0..=360)
            .map(|k| {
                let beta = core::f64::consts::FRAC_PI_2 * (1.0 + k as f64 / 360.0);
                let c = Dq::new(i * beta.cos(), i * beta.sin());
                let psi = model.flux(c);
                (1.5 * pole_pairs * (psi.d * c.q - psi.q * c.d), c)
            })
            .fold(
                (f64::MIN, Dq::new(0.0, 0.0)),
                |a, b| if b.0 > a.0 { b } else { a },
            )
    };
    if torque <= 0.0 {
        return Dq::new(0.0, 0.0);
    }
    let (mut lo, mut hi) = (0.0, i_max);
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if best(mid).0 >= torque {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    best(hi).1
}

/// What [`measure`] finds on one machine, as shares of the identified λ̂f at 0, 30, 65 and
/// 100 % of rated torque.
struct Measured {
    /// The identified model's flux error |ψ̂ − ψ|.
    error: [f64; 4],
    /// The same less its error at zero current (the magnet's, the identified λ̂f's).
    loaded: [f64; 4],
    /// The written figure at the operating point's current: `model_flux_uncertainty` +
    /// `model_flux_uncertainty_rated`·|i|²/I_rated².
    figure: [f64; 4],
}

/// The identified model's flux errors and the written figure at the plant's MTPA points.
fn measure(path: &str) -> Measured {
    let text = std::fs::read_to_string(path).unwrap();
    let cfg = fado_sim::SimConfig::from_toml(&text).unwrap();
    let plant = cfg.plant();
    let o = commission_on_own_nameplate(&plant).unwrap();
    let id = o.identification.unwrap();
    let report = o.magnetics.unwrap();
    assert!(report.saturation_detected, "{path}: {}", report.verdict);
    let identified = Magnetics::<f64>::Saturation(report.fitted);
    let truth = plant_model(&plant);
    let m = &plant.motor;
    let zero = Dq::new(0.0, 0.0);
    let magnet = identified.flux(zero) - truth.flux(zero);
    let points = [0.0, 0.3, 0.65, 1.0].map(|load| {
        mtpa(
            &truth,
            m.pole_pairs as f64,
            load * m.rated_torque,
            2.0 * m.rated_current,
        )
    });
    let error = |i: Dq<f64>| identified.flux(i) - truth.flux(i);
    let lf = id.model.flux_linkage;
    let (u0, rated) = (
        id.model_flux_uncertainty().unwrap(),
        id.model_flux_uncertainty_rated().unwrap(),
    );
    let i_n = id.model.rated_current;
    Measured {
        error: points.map(|i| error(i).norm() / lf),
        loaded: points.map(|i| (error(i) - magnet).norm() / lf),
        figure: points.map(|i| u0 + rated * (i.d * i.d + i.q * i.q) / (i_n * i_n)),
    }
}

/// The saturated presets and the saturated test machines (made-up algebraic models of other
/// classes: the traction IPMSM, a ribbed IPMSM, twenty times the cross-saturation, a 20-pole
/// 48 V IPMSM, a 2-pole inrunner, a d-saturated servo SPM with a light rotor).
fn machines() -> Vec<String> {
    let root = env!("CARGO_MANIFEST_DIR");
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/saturated");
    fado_sim::magnetics_file::set_config_dir(Some(std::path::Path::new(dir)));
    [
        "ipmsm-2k2-qsat",
        "pmsm-gem-1k1-measured",
        "pmsyrm-baldor-5k6",
        "pmsyrm-baldor-5k6-measured",
    ]
    .iter()
    .map(|name| format!("{dir}/{name}.toml"))
    .chain(
        [
            "ipmsm-test-saturated",
            "traction-ipm-saturated",
            "ipm-rib-saturated",
            "ipm-cross20-saturated",
            "ipmsm-20p-48v-saturated",
            "inrunner-2p-saturated",
            "spm-dq-sat-saturated",
        ]
        .iter()
        .map(|name| format!("{root}/tests/data/{name}.toml")),
    )
    .collect()
}

fn row(a: [f64; 4]) -> String {
    format!("{:.4} / {:.4} / {:.4} / {:.4}", a[0], a[1], a[2], a[3])
}

/// The machines on which `error` (of [`Measured`]) exceeds the figure at some load, each
/// printed with its errors and figure.
fn short_of(what: &str, error: impl Fn(&Measured) -> [f64; 4]) -> Vec<String> {
    let mut short = Vec::new();
    for path in machines() {
        let r = measure(&path);
        let name = path.rsplit('/').next().unwrap();
        let (e, u) = (row(error(&r)), row(r.figure));
        println!("{name}: {what} {e} of λ̂f against the figure {u}");
        if error(&r).iter().zip(&r.figure).any(|(e, u)| e > u) {
            short.push(format!("{name}: {e} against {u}"));
        }
    }
    short
}

/// The figure at the operating point's current bounds the loaded flux error (less the
/// magnet's, which the λ̂f law learns) at 0, 30, 65 and 100 % of rated torque on every
/// machine (figures in the module docs).
#[test]
fn the_written_figure_bounds_the_models_flux_error_at_every_load() {
    let short = short_of("flux error less the magnet's", |r| r.loaded);
    assert!(short.is_empty(), "{short:?}");
}

/// The figure does not bound the magnet's flux error, the identified λ̂f's (module docs): the
/// back-EMF windows read ψd(−c, 0) + L̂d·c at the coast's d current −c with the injection
/// tests' L̂d, which on a saturating machine is not ψd(0, 0).
#[test]
#[ignore = "the magnet's flux error (the identified λ̂f's) is outside the figure: 0.081-0.086 against 0.027-0.042 of λ̂f on the PM-SyRM's measured map, 0.030-0.046 against 0.016-0.036 on its algebraic model, 0.0072 against 0.0050-0.0068 on the made-up IPMSM (module docs)"]
fn the_written_figure_bounds_the_magnets_flux_error_too() {
    let short = short_of("flux error", |r| r.error);
    assert!(short.is_empty(), "{short:?}");
}

/// The written figure leaves the R̂s law the reach to learn a winding's temperature: the
/// commissioned model of pmsm-gem-1k1-measured (current-sensor seed 1, `identified.toml` as
/// written, figure 0.0072 at zero current growing by 0.0067 to the rated current) drives the
/// plant with its winding resistance 1.3 and 0.8 times the commissioned one (gain calibration
/// off, so that only the turning law can learn it) through `rated-reversal`: R̂s ends within
/// 2 % of the plant's and the scenario passes. Measured: 0.990 / 0.998 × Rs, 0.14 / 0.25 rad
/// near zero speed (0.991 / 0.997 ×, 0.07 / 0.19 rad with the constant 0.0072 alone). With the
/// constant bounding figure of the module docs (0.0191) the law freezes at most loaded points:
/// 0.952 / 1.030 × Rs and the rotor lost (0.82 / 1.04 rad).
#[test]
fn a_commissioned_model_learns_a_changed_winding_resistance() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/saturated");
    fado_sim::magnetics_file::set_config_dir(Some(std::path::Path::new(dir)));
    let text = std::fs::read_to_string(format!("{dir}/pmsm-gem-1k1-measured.toml")).unwrap();
    let plant = fado_sim::SimConfig::from_toml(&text).unwrap().plant();
    let o = commission_on_own_nameplate(&plant).unwrap();
    let id = o.identification.unwrap();
    let doc = fado_sim::commission::identified_toml(&text, &id).unwrap();
    let mut failed = Vec::new();
    for warm in [1.3, 0.8] {
        let mut table: toml::Table = doc.parse().unwrap();
        let motor = table["motor"].as_table_mut().unwrap();
        let rs = motor["rs"].as_float().unwrap() * warm;
        motor.insert("rs".into(), toml::Value::Float(rs));
        let hot = format!(
            "{}\n[controller.gain_calibration]\ntime = 0.0\n",
            toml::to_string(&table).unwrap()
        );
        let cfg = scenario_config("rated-reversal", Some(&hot), false).unwrap();
        let truth = cfg.motor.rs + cfg.inverter.on_resistance;
        let out = run_config("rated-reversal", cfg, None).unwrap();
        let end = out.trace.rows.last().unwrap().rs_hat / truth;
        println!(
            "winding × {warm}: R̂s ends at {end:.3} × Rs, passed {}, {:.3} rad near zero speed",
            out.passed, out.metrics.max_angle_error_zero_speed
        );
        if !((end - 1.0).abs() < 0.02 && out.passed) {
            failed.push(warm);
        }
    }
    assert!(failed.is_empty(), "{failed:?}");
}
