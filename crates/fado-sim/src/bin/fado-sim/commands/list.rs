//! `list` and `motors`: the scenarios, the estimators and the motor presets.

use std::process::ExitCode;

use fado_sim::estimators::ESTIMATORS;
use fado_sim::scenario::SCENARIOS;

use super::Outcome;

/// `motors`: one line per preset.
pub fn motors() -> Outcome {
    for p in fado_sim::presets::PRESETS {
        outln!("{:<22} {}", p.name, p.description());
    }
    Ok(ExitCode::SUCCESS)
}

/// `list`: each scenario with its profile and criterion, then each estimator with its
/// settings' section.
pub fn scenarios_and_estimators() -> Outcome {
    for s in &SCENARIOS {
        outln!(
            "{:<7} {}\n        profile:   {}\n        criterion: {}",
            s.name,
            s.title,
            s.profile,
            s.criterion
        );
    }
    outln!("\nEstimators (`[simulation] estimator`, `compare --estimators`):");
    for e in ESTIMATORS {
        let settings = if e.own_settings {
            format!("[baselines.{}]", e.key())
        } else {
            "[estimator]".to_owned()
        };
        outln!("{:<15} {} — settings {settings}", e.name, e.summary);
    }
    Ok(ExitCode::SUCCESS)
}
