//! `sweep`: one scenario over a grid or a random design of configuration keys and derived
//! parameters.

use std::path::PathBuf;
use std::process::ExitCode;

use fado_sim::sweep::{self, SweepOptions, SweepSpec};
use indicatif::{ProgressBar, ProgressStyle};

use super::Outcome;
use crate::axes;
use crate::files::{in_file, read_file, warn_plausibility};

/// The arguments of `sweep`.
#[derive(clap::Args)]
pub struct SweepArgs {
    /// Scenario name.
    scenario: String,
    /// `name=lo:hi:n` (n values, ends included) or `name=v1,v2,...` (TOML values); with
    /// `--random`, `name=lo..hi`. Repeat for more axes (grid: the cartesian product).
    #[arg(long = "axis", alias = "set", required = true)]
    axes: Vec<String>,
    /// Draw this many points uniformly in the `lo..hi` ranges instead of a grid.
    #[arg(long)]
    random: Option<usize>,
    /// Seed of `--random`.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// TOML file applied over the scenario before the axes (e.g. estimator settings).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Output directory. Default `out/<scenario>-sweep`.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Use the averaged inverter model.
    #[arg(long)]
    averaged: bool,
    /// Worker threads (0: all cores).
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Discard the results of an earlier sweep in DIR instead of resuming it.
    #[arg(long)]
    fresh: bool,
}

/// Builds the sweep of `args` (a bad `--config` file is reported at its FILE:LINE:COLUMN
/// before anything runs) and runs it.
pub fn sweep(args: SweepArgs) -> Outcome {
    let mut spec = design(&args)?;
    spec.averaged = args.averaged;
    if let Some(p) = &args.config {
        spec.config_toml = Some(read_file(p)?);
    }
    let base = spec.base_config().map_err(|e| in_file(e, &args.config))?;
    warn_plausibility(&base, args.config.as_deref(), spec.config_toml.as_deref());
    let dir = args
        .out
        .unwrap_or_else(|| PathBuf::from("out").join(format!("{}-sweep", args.scenario)));
    run_sweep(&spec, dir, args.threads, args.fresh)
}

/// The points of `--axis`: their cartesian product, or `--random` draws in their ranges.
fn design(args: &SweepArgs) -> Result<SweepSpec, Box<dyn std::error::Error>> {
    Ok(match args.random {
        None => {
            let mut grid = Vec::new();
            for a in &args.axes {
                let (name, values) = split_axis(a)?;
                grid.push((name.to_owned(), axes::parse_values(values)?));
            }
            SweepSpec::grid(&args.scenario, grid)
        }
        Some(n) => {
            let mut ranges = Vec::new();
            for a in &args.axes {
                let (name, range) = split_axis(a)?;
                let (lo, hi) = axes::parse_range(range)?;
                ranges.push((name.to_owned(), lo, hi));
            }
            SweepSpec::random(&args.scenario, &ranges, n, args.seed)
        }
    })
}

/// `name=values` as (name, values).
fn split_axis(arg: &str) -> Result<(&str, &str), String> {
    arg.split_once('=')
        .map(|(n, v)| (n.trim(), v))
        .ok_or_else(|| format!("--axis `{arg}` must look like name=values"))
}

/// Runs the points of `spec` not yet finished in `dir` with a progress bar, then prints the
/// summary.
fn run_sweep(spec: &SweepSpec, dir: PathBuf, threads: usize, fresh: bool) -> Outcome {
    spec.base_config()?;
    let bar = ProgressBar::new(spec.points.len() as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} {msg} [{bar:40}] {pos}/{len} points, {elapsed} elapsed, eta {eta}",
        )?
        .progress_chars("=> "),
    );
    bar.set_message(format!("{} {}", spec.scenario, spec.design));
    let (threads, warning) = fado_sim::threads::capped(threads);
    if let Some(w) = warning {
        eprintln!("warning: {w}");
    }
    let opts = SweepOptions {
        threads,
        out: Some(dir.clone()),
        fresh,
        cancel: None,
    };
    let started_bar = std::sync::Once::new();
    let outcome = sweep::run(spec, &opts, &|r, finished| {
        if let sweep::Status::Failed(m) = &r.status {
            bar.suspend(|| eprintln!("point {} failed: {m}", r.index));
        }
        // Resumed points do not count for the rate.
        started_bar.call_once(|| {
            bar.set_position(finished as u64 - 1);
            bar.reset_eta();
        });
        bar.set_position(finished as u64);
    });
    bar.finish_and_clear();
    let outcome = outcome?;
    out!("{}", outcome.summary.to_markdown());
    outln!(
        "{} points run, {} resumed, in {:.1} s ({:.1} points/min); wrote {}/sweep.csv, summary.json, summary.md",
        outcome.ran,
        outcome.resumed,
        outcome.wall_seconds,
        outcome.ran as f64 * 60.0 / outcome.wall_seconds.max(1e-9),
        dir.display()
    );
    Ok(ExitCode::SUCCESS)
}
