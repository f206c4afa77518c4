//! `fado_sim::compare`: the comparison runs each estimator exactly as an individual
//! `simulate` with `[estimator] kind` would, and no baseline in it is broken.

use fado_sim::compare::{CompareOptions, compare};
use fado_sim::estimators::{ESTIMATORS, find};
use fado_sim::simulate;

#[test]
fn compare_gives_the_numbers_of_individual_simulate_runs() {
    // fig11 cut after the zero crossing (3.8 s): short, yet through the loaded reversal.
    let short = "[simulation]\nduration = 3.8\n";
    let opts = CompareOptions {
        scenarios: vec!["fig11".into()],
        estimators: vec![find("fado").unwrap(), find("ortega").unwrap()],
        averaged: true,
        config_toml: Some(short.into()),
        ..Default::default()
    };
    let result = compare(&opts).unwrap();
    assert_eq!(result.rows.len(), 2);
    for e in &opts.estimators {
        let alone = simulate(
            "fig11",
            Some(&format!("{short}estimator = \"{}\"\n", e.key())),
            true,
            None,
        )
        .unwrap();
        let row = result.row("fig11", e.name).unwrap();
        let m = &alone.metrics;
        assert!(
            m.zero_speed_samples > 1000,
            "the cut run reaches zero speed"
        );
        // Same plant, seed and drive: bit-identical, not merely close.
        assert_eq!(row.max_angle_error_zero_speed, m.max_angle_error_zero_speed);
        assert_eq!(row.rms_angle_error_zero_speed, m.rms_angle_error_zero_speed);
        assert_eq!(row.max_angle_error, m.max_angle_error);
        assert_eq!(row.rms_angle_error, m.rms_angle_error);
        assert_eq!(row.max_speed_error_rpm, m.max_speed_error_rpm);
        assert_eq!(row.zero_speed_samples, m.zero_speed_samples);
        assert_eq!(row.passed, alone.passed);
    }
    // The two estimators really differ (the kind was applied).
    let (a, b) = (&result.rows[0], &result.rows[1]);
    assert_ne!(a.max_angle_error_zero_speed, b.max_angle_error_zero_speed);
}

#[test]
fn every_estimator_holds_the_angle_at_300_rpm_under_load() {
    // The sanity check behind every comparison: at medium speed each baseline is sound.
    let opts = CompareOptions {
        scenarios: vec!["steady300".into()],
        averaged: true,
        ..Default::default()
    };
    let result = compare(&opts).unwrap();
    assert_eq!(result.rows.len(), ESTIMATORS.len());
    for r in &result.rows {
        assert!(
            r.passed && !r.tripped,
            "{}: max |θ−θ̂| {:.4} rad, speed error {:.2} r/min, checks {:?}",
            r.estimator,
            r.max_angle_error,
            r.max_speed_error_rpm,
            r.checks
        );
        assert!(r.max_angle_error < 0.05, "{}", r.estimator);
    }
}

#[test]
fn thread_count_does_not_change_the_numbers() {
    let opts = |threads| CompareOptions {
        scenarios: vec!["steady300".into()],
        estimators: vec![
            find("lpf-integrator").unwrap(),
            find("emf_observer").unwrap(),
        ],
        averaged: true,
        config_toml: Some("[simulation]\nduration = 2.7\n".into()),
        threads,
        ..Default::default()
    };
    let one = compare(&opts(1)).unwrap();
    let two = compare(&opts(2)).unwrap();
    for (a, b) in one.rows.iter().zip(&two.rows) {
        assert_eq!(a.estimator, b.estimator);
        assert_eq!(a.max_angle_error, b.max_angle_error);
        assert_eq!(a.rms_angle_error, b.rms_angle_error);
    }
    let md = two.to_markdown();
    assert!(md.contains("| steady300 | lpf-integrator |"), "{md}");
}
