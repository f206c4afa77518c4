//! `run`: one scenario, its trace written as it is produced, its metrics and criteria.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

use fado_sim::SimConfig;
use fado_sim::output::{self, AtomicFile, DirLock};
use fado_sim::scenario::{self, Report, RunOptions, TraceOutput};
use fado_sim::sim::{CsvTraceWriter, TraceRow, TraceSink};
use indicatif::{ProgressBar, ProgressStyle};

use super::Outcome;
use crate::files::{
    csv_error, in_file, note_absolute_scenario, note_scenario_motor, read_file, warn_plausibility,
};

/// The arguments of `run`.
#[derive(clap::Args)]
pub struct RunArgs {
    /// Scenario name (see `list`).
    scenario: String,
    /// TOML file overriding the scenario's configuration key by key.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Output directory. Default `out/<scenario>`.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Use the averaged inverter model (fast) instead of the switching-resolved one.
    #[arg(long)]
    averaged: bool,
    /// Print the effective configuration as TOML and exit without running.
    #[arg(long)]
    dump_config: bool,
}

/// Runs `args.scenario` (or prints its configuration with `--dump-config`); exit 1 when it
/// missed its criteria.
pub fn run(args: RunArgs) -> Outcome {
    let text = match &args.config {
        Some(p) => Some(read_file(p)?),
        None => None,
    };
    let cfg = scenario::scenario_config(&args.scenario, text.as_deref(), args.averaged)
        .map_err(|e| in_file(e, &args.config))?;
    warn_plausibility(&cfg, args.config.as_deref(), text.as_deref());
    note_scenario_motor(text.as_deref(), args.config.as_deref());
    note_absolute_scenario(&args.scenario, &cfg, text.as_deref());
    if args.dump_config {
        out!("{}", cfg.to_toml_annotated());
        return Ok(ExitCode::SUCCESS);
    }
    let dir = args
        .out
        .unwrap_or_else(|| PathBuf::from("out").join(&args.scenario));
    let lock = DirLock::acquire(&dir)?;
    let report = run_into(&args.scenario, cfg, &dir)?;
    drop(lock);
    print_table(&report);
    outln!("wrote {}/metrics.json and traces.csv", dir.display());
    Ok(if report.passed {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// A progress bar for the run of `name`, shown only once the run has taken a second.
fn progress_bar(name: &str) -> Result<ProgressBar, Box<dyn std::error::Error>> {
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg} [{bar:40}] {percent:>3}% eta {eta}")?
            .progress_chars("=> "),
    );
    bar.set_message(name.to_owned());
    bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    Ok(bar)
}

/// Runs the scenario `name` on `cfg` with its trace streamed to DIR/traces.csv, then puts
/// DIR/traces.csv and DIR/metrics.json in place (the caller holds the directory).
fn run_into(name: &str, cfg: SimConfig, dir: &Path) -> Result<Report, Box<dyn std::error::Error>> {
    let bar = progress_bar(name)?;
    let start = std::time::Instant::now();
    let mut shown = false;
    let mut cb = |f: f64| {
        if !shown && start.elapsed().as_secs_f64() > 1.0 {
            bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
            shown = true;
        }
        bar.set_position((f * 1000.0) as u64);
    };
    let traces_path = dir.join("traces.csv");
    let stop = AtomicBool::new(false);
    let mut sink = FileSink {
        csv: CsvTraceWriter::new(AtomicFile::create(&traces_path)?),
        failed: &stop,
    };
    let outcome = scenario::run_config_with(
        name,
        cfg,
        RunOptions {
            progress: Some(&mut cb),
            trace: TraceOutput::Sink(&mut sink),
            cancel: Some(&stop),
        },
    )?;
    bar.finish_and_clear();
    // Every output is complete and on disk before any is renamed into place; the old
    // metrics.json goes first, so a metrics.json always sits beside its own traces.
    let traces = sink
        .csv
        .finish()
        .map_err(|e| csv_error(e, &traces_path))?
        .finish()?;
    let report = outcome.report();
    let mut metrics = AtomicFile::create(&dir.join("metrics.json"))?;
    serde_json::to_writer_pretty(&mut metrics, &report).map_err(|e| metrics.error(e.into()))?;
    let metrics = metrics.finish()?;
    output::remove_if_present(&dir.join("metrics.json"))?;
    traces.rename()?;
    metrics.rename()?;
    Ok(report)
}

/// The trace file of `run`: rows go to disk as they are produced; a failed write stops the
/// run at once (through its cancel flag) instead of simulating on for nothing.
struct FileSink<'a> {
    csv: CsvTraceWriter<AtomicFile>,
    failed: &'a AtomicBool,
}

impl TraceSink for FileSink<'_> {
    fn push(&mut self, row: &TraceRow) {
        self.csv.push(row);
        if self.csv.failed() {
            self.failed.store(true, Ordering::Relaxed);
        }
    }
}

/// The run's metrics and criteria, one per line.
fn print_table(r: &scenario::Report) {
    outln!(
        "scenario            {} ({:?} inverter)",
        r.scenario,
        r.inverter_model
    );
    outln!("max |θ−θ̂|           {:.4} rad", r.max_angle_error);
    outln!("rms θ−θ̂             {:.4} rad", r.rms_angle_error);
    outln!(
        "max |θ−θ̂| |n|<{:<4}  {:.4} rad",
        r.zero_speed_band_rpm,
        r.max_angle_error_zero_speed
    );
    outln!(
        "rms θ−θ̂ near zero   {:.4} rad",
        r.rms_angle_error_zero_speed
    );
    outln!("max speed error     {:.2} r/min", r.max_speed_error_rpm);
    outln!("tripped             {}", r.tripped);
    outln!(
        "simulated / wall    {:.2} s / {:.3} s ({:.0}× real time)",
        r.simulated_seconds,
        r.wall_seconds,
        r.simulated_seconds / r.wall_seconds.max(1e-9)
    );
    for c in &r.checks {
        let lim = match (c.min, c.max) {
            (Some(a), Some(b)) => format!("in [{a}, {b}]"),
            (Some(a), None) => format!("≥ {a}"),
            (None, Some(b)) => format!("≤ {b}"),
            (None, None) => String::new(),
        };
        outln!(
            "  [{}] {:<40} {:>10.4}  {}",
            if c.passed { "pass" } else { "FAIL" },
            c.name,
            c.value,
            lim
        );
    }
    outln!("PASSED              {}", r.passed);
}
