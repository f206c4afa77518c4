//! `compare`: every estimator in every scenario on the same plant, seed and controllers.

use std::path::PathBuf;
use std::process::ExitCode;

use fado_sim::compare::{self, CompareOptions};
use fado_sim::output::{AtomicFile, DirLock};

use super::Outcome;
use crate::files::{in_file, read_file};

/// The arguments of `compare`.
#[derive(clap::Args)]
pub struct CompareArgs {
    /// Comma-separated scenario names. Default: all (see `list`).
    #[arg(long, value_delimiter = ',')]
    scenarios: Option<Vec<String>>,
    /// Comma-separated estimators (see `list`). Default: all.
    #[arg(long, value_delimiter = ',', help = estimators_help())]
    estimators: Option<Vec<String>>,
    /// TOML file applied over every scenario (its `[estimator] kind` is replaced).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Output directory. Default `out/compare`.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Use the averaged inverter model.
    #[arg(long)]
    averaged: bool,
    /// criterion's output directory of `cargo bench --bench baselines` (e.g.
    /// `target/criterion`): the f32 step costs are read from its saved estimates.
    #[arg(long)]
    criterion: Option<PathBuf>,
    /// Worker threads.
    #[arg(long, default_value_t = 2)]
    threads: usize,
}

/// `compare --estimators`' help: the names of the registry.
fn estimators_help() -> String {
    format!(
        "Comma-separated estimators. Default: all of {} (fado-fixed-rs: fado with the paper's \
         fixed R̂s; see `list`)",
        fado_sim::estimators::names().join(",")
    )
}

/// Runs the comparison of `args`, with the step costs of `--criterion`; writes
/// DIR/compare.md and DIR/compare.json and prints the table.
pub fn compare(args: CompareArgs) -> Outcome {
    let opts = options(&args)?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join("compare"));
    // Taken before the runs: an output directory that cannot be created or that another
    // command holds is reported at once, not after the comparison.
    let _lock = DirLock::acquire(&dir)?;
    let mut result = compare::compare(&opts).map_err(|e| in_file(e, &args.config))?;
    if let Some(dir) = &args.criterion {
        let costs = compare::read_criterion_step_costs(dir, &opts.estimators);
        if costs.is_empty() {
            eprintln!(
                "warning: no criterion estimates under {} (run `cargo bench --bench baselines`)",
                dir.display()
            );
        }
        result.set_step_costs(costs);
    }
    let md = result.to_markdown();
    AtomicFile::write(&dir.join("compare.md"), md.as_bytes())?;
    AtomicFile::write(
        &dir.join("compare.json"),
        serde_json::to_string_pretty(&result)?.as_bytes(),
    )?;
    out!("{md}");
    outln!(
        "\n{} runs in {:.1} s; wrote {}/compare.json and compare.md",
        result.rows.len(),
        result.wall_seconds,
        dir.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// The comparison's options: threads (capped), scenarios, estimators and `--config`.
fn options(args: &CompareArgs) -> Result<CompareOptions, Box<dyn std::error::Error>> {
    let (threads, warning) = fado_sim::threads::capped(args.threads);
    if let Some(w) = warning {
        eprintln!("warning: {w}");
    }
    let mut opts = CompareOptions {
        averaged: args.averaged,
        threads,
        ..Default::default()
    };
    if let Some(s) = &args.scenarios {
        opts.scenarios = s.clone();
    }
    if let Some(e) = &args.estimators {
        opts.estimators = e
            .iter()
            .map(|n| compare::parse_estimator(n))
            .collect::<Result<_, _>>()?;
    }
    if let Some(p) = &args.config {
        opts.config_toml = Some(read_file(p)?);
    }
    Ok(opts)
}
