//! `fado-sim`: run the paper's experiments on the simulated drive.
//!
//! ```text
//! fado-sim list
//! fado-sim run fig11 [--config FILE] [--out DIR] [--averaged] [--dump-config]
//! fado-sim sweep fig11 --axis rs_error=-0.3:0.3:7 --axis load_torque=0,2.5,5,7.5
//!                [--random N --seed S] [--config FILE] [--out DIR] [--averaged]
//!                [--threads N] [--fresh]
//! fado-sim compare [--scenarios fig8,...] [--estimators fado,ortega,...]
//!                  [--out DIR] [--averaged] [--config FILE] [--criterion target/criterion]
//! ```

mod axes;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

use clap::{Parser, Subcommand};
use fado_sim::SimConfigError;
use fado_sim::compare;
use fado_sim::estimators::ESTIMATORS;
use fado_sim::output::{self, AtomicFile, DirLock, OutputError};
use fado_sim::scenario::{self, SCENARIOS};
use fado_sim::scenario::{RunOptions, TraceOutput};
use fado_sim::sim::{CsvTraceWriter, TraceRow, TraceSink};
use fado_sim::sweep::{self, SweepError, SweepOptions, SweepSpec};
use indicatif::{ProgressBar, ProgressStyle};

#[derive(Parser)]
#[command(
    name = "fado-sim",
    version,
    about = "Closed-loop simulation of the FADO sensorless PMSM drive (Park & Sul)",
    after_help = "Exit codes: 0 passed, 1 ran but missed the scenario's criteria, 2 configuration \
                  or usage error, 3 a file could not be read or written (named in the message) \
                  or another run holds the output directory."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the scenarios and the estimators.
    List,
    /// List the motor presets of `motors/` (each a valid `--config` file), one line each.
    Motors,
    /// Run a scenario, print its metrics, write DIR/metrics.json and DIR/traces.csv.
    Run {
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
    },
    /// Run a scenario once per point of a grid or random design over configuration keys and
    /// derived parameters (operating-envelope sweeps); write DIR/sweep.csv (one row per point,
    /// appended as points finish), DIR/sweep.json (the definition), DIR/summary.json and
    /// DIR/summary.md. Started again on the same DIR with the same definition, it skips the
    /// points already finished.
    ///
    /// Parameters: any TOML key `section.key`, or rs_error (R̂s/(Rs+r_on) − 1), lq_error,
    /// ld_error, flux_linkage_error (λ̂f/λf − 1), dead_time_comp_error (T̂d/Td − 1),
    /// sensor_offset (A), sensor_gain_error, load_torque (final value, N·m), reversal_ramp
    /// (r/min per s). See `fado_sim::sweep`.
    Sweep {
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
    },
    /// Identify the motor of FILE's `[motor]` (with `rated_current`, `rated_speed_rpm`,
    /// `rated_torque`) on the simulated plant with `fado_core::commissioning`; print each
    /// parameter against the plant's truth; write DIR/identified.toml (`[model]`),
    /// DIR/metrics.json and DIR/traces.csv, as `run` writes: under the directory's lock, each
    /// whole or not at all. Refused before it runs when the set-up cannot be measured
    /// (ω_rated·Ts above 0.2, a current sensor coarser than 1 % of its current limit).
    Commission {
        /// TOML file: the plant (`[motor]` with its ratings, `[inverter]`, sensors, …).
        #[arg(long)]
        config: Option<PathBuf>,
        /// Or a motor preset (see `motors`).
        #[arg(long)]
        motor: Option<String>,
        /// Output directory. Default `out/commission`.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Current-sensor noise seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Use the averaged inverter model.
        #[arg(long)]
        averaged: bool,
    },
    /// Run every estimator in every scenario on the same plant, seed and controllers; print
    /// the table, write DIR/compare.json and DIR/compare.md.
    Compare {
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
    },
}

/// `compare --estimators`' help: the names of the registry.
fn estimators_help() -> String {
    format!(
        "Comma-separated estimators. Default: all of {} (fado-fixed-rs: fado with the paper's \
         fixed R̂s; see `list`)",
        fado_sim::estimators::names().join(",")
    )
}

/// Exit code of a configuration or usage error (a bad key, value, scenario or axis).
const EXIT_CONFIG: u8 = 2;
/// Exit code of an output error: a file that cannot be read or written (the message names
/// it), or an output directory that another run holds.
const EXIT_IO: u8 = 3;

/// Set once writing to stdout failed: later writes are skipped.
static STDOUT_FAILED: AtomicBool = AtomicBool::new(false);
/// The first stdout error other than a closed pipe (a full disk): reported at exit.
static STDOUT_ERROR: std::sync::Mutex<Option<std::io::Error>> = std::sync::Mutex::new(None);

/// Writes to stdout without ever panicking: a reader that went away (`fado-sim … | head`)
/// ends the printing silently, any other error (a full disk) is reported at exit with code 3.
/// Every command has written its files before it prints.
fn print_out(args: std::fmt::Arguments<'_>) {
    use std::io::Write;
    if STDOUT_FAILED.load(Ordering::Relaxed) {
        return;
    }
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.flush()) {
        STDOUT_FAILED.store(true, Ordering::Relaxed);
        if e.kind() != std::io::ErrorKind::BrokenPipe
            && let Ok(mut slot) = STDOUT_ERROR.lock()
        {
            slot.get_or_insert(e);
        }
    }
}

/// `println!` through [`print_out`].
macro_rules! outln {
    () => { print_out(format_args!("\n")) };
    ($($arg:tt)*) => { print_out(format_args!("{}\n", format_args!($($arg)*))) };
}

/// `print!` through [`print_out`].
macro_rules! out {
    ($($arg:tt)*) => { print_out(format_args!($($arg)*)) };
}

fn main() -> ExitCode {
    let code = match run(Cli::parse()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            let io = e.downcast_ref::<OutputError>().is_some()
                || matches!(e.downcast_ref::<SweepError>(), Some(SweepError::Io(_)));
            ExitCode::from(if io { EXIT_IO } else { EXIT_CONFIG })
        }
    };
    if let Some(e) = STDOUT_ERROR.lock().ok().and_then(|mut s| s.take()) {
        eprintln!("error: cannot write to stdout: {e}");
        return ExitCode::from(EXIT_IO);
    }
    code
}

/// Prints the plausibility warnings of `cfg`'s motor on stderr, naming the file.
fn warn_plausibility(cfg: &fado_sim::SimConfig, config: Option<&Path>) {
    for w in cfg.warnings() {
        match config {
            Some(p) => eprintln!("warning: {}: {w}", p.display()),
            None => eprintln!("warning: {w}"),
        }
    }
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

/// The text of an input file; an error names it (exit 3).
/// Reads a `--config` file, refusing one longer than [`scenario::MAX_CONFIG_BYTES`] before
/// reading more of it (`--config /dev/zero` stops after 1 MiB, not at the end of memory).
fn read_file(path: &Path) -> Result<String, Box<dyn std::error::Error>> {
    use std::io::Read;
    // Paths in the file (`[motor] flux_map`) are relative to it.
    fado_sim::magnetics_file::set_config_dir(path.parent());
    let file = std::fs::File::open(path).map_err(|e| OutputError::new("read", path, e))?;
    let limit = scenario::MAX_CONFIG_BYTES as u64;
    let mut bytes = Vec::new();
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| OutputError::new("read", path, e))?;
    if bytes.len() as u64 > limit {
        return Err(SimConfigError::new(
            "<config>",
            format!(
                "{} is longer than the {limit} bytes a configuration may have (not read further)",
                path.display()
            ),
        )
        .into());
    }
    String::from_utf8(bytes).map_err(|e| {
        OutputError::new(
            "read",
            path,
            std::io::Error::new(std::io::ErrorKind::InvalidData, e),
        )
        .into()
    })
}

/// A CSV write error as the output error naming `path`.
fn csv_error(e: csv::Error, path: &Path) -> OutputError {
    let source = match e.into_kind() {
        csv::ErrorKind::Io(e) => e,
        other => std::io::Error::other(format!("{other:?}")),
    };
    OutputError::new("write", path, source)
}

fn run(cli: Cli) -> Result<ExitCode, Box<dyn std::error::Error>> {
    match cli.command {
        Command::Motors => {
            for p in fado_sim::presets::PRESETS {
                outln!("{:<22} {}", p.name, p.description());
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::List => {
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
        Command::Run {
            scenario: name,
            config,
            out,
            averaged,
            dump_config,
        } => {
            let text = match &config {
                Some(p) => Some(read_file(p)?),
                None => None,
            };
            let cfg = scenario::scenario_config(&name, text.as_deref(), averaged)
                .map_err(|e| in_file(e, &config))?;
            if dump_config {
                out!("{}", cfg.to_toml_annotated());
                return Ok(ExitCode::SUCCESS);
            }
            warn_plausibility(&cfg, config.as_deref());
            let bar = ProgressBar::new(1000);
            bar.set_style(
                ProgressStyle::with_template("{spinner} {msg} [{bar:40}] {percent:>3}% eta {eta}")?
                    .progress_chars("=> "),
            );
            bar.set_message(name.clone());
            // Only show the bar on runs longer than a second.
            bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
            let start = std::time::Instant::now();
            let mut shown = false;
            let mut cb = |f: f64| {
                if !shown && start.elapsed().as_secs_f64() > 1.0 {
                    bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
                    shown = true;
                }
                bar.set_position((f * 1000.0) as u64);
            };
            let dir = out.unwrap_or_else(|| PathBuf::from("out").join(&name));
            let lock = DirLock::acquire(&dir)?;
            let traces_path = dir.join("traces.csv");
            let stop = AtomicBool::new(false);
            let mut sink = FileSink {
                csv: CsvTraceWriter::new(AtomicFile::create(&traces_path)?),
                failed: &stop,
            };
            let outcome = scenario::run_config_with(
                &name,
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
            serde_json::to_writer_pretty(&mut metrics, &report)
                .map_err(|e| metrics.error(e.into()))?;
            let metrics = metrics.finish()?;
            output::remove_if_present(&dir.join("metrics.json"))?;
            traces.rename()?;
            metrics.rename()?;
            drop(lock);
            print_table(&report);
            outln!("wrote {}/metrics.json and traces.csv", dir.display());
            Ok(if report.passed {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            })
        }
        Command::Sweep {
            scenario,
            axes,
            random,
            seed,
            config,
            out,
            averaged,
            threads,
            fresh,
        } => {
            let mut spec = match random {
                None => {
                    let mut grid = Vec::new();
                    for a in &axes {
                        let (name, values) = split_axis(a)?;
                        grid.push((name.to_owned(), axes::parse_values(values)?));
                    }
                    SweepSpec::grid(&scenario, grid)
                }
                Some(n) => {
                    let mut ranges = Vec::new();
                    for a in &axes {
                        let (name, range) = split_axis(a)?;
                        let (lo, hi) = axes::parse_range(range)?;
                        ranges.push((name.to_owned(), lo, hi));
                    }
                    SweepSpec::random(&scenario, &ranges, n, seed)
                }
            };
            spec.averaged = averaged;
            if let Some(p) = &config {
                spec.config_toml = Some(read_file(p)?);
            }
            // A bad --config file is reported at its FILE:LINE:COLUMN before anything runs.
            spec.base_config().map_err(|e| in_file(e, &config))?;
            let dir = out.unwrap_or_else(|| PathBuf::from("out").join(format!("{scenario}-sweep")));
            run_sweep(&spec, dir, threads, fresh)
        }
        Command::Commission {
            config,
            motor,
            out,
            seed,
            averaged,
        } => run_commission(config.as_deref(), motor.as_deref(), out, seed, averaged),
        Command::Compare {
            scenarios,
            estimators,
            config,
            out,
            averaged,
            criterion,
            threads,
        } => {
            let (threads, warning) = fado_sim::threads::capped(threads);
            if let Some(w) = warning {
                eprintln!("warning: {w}");
            }
            let mut opts = compare::CompareOptions {
                averaged,
                threads,
                ..Default::default()
            };
            if let Some(s) = scenarios {
                opts.scenarios = s;
            }
            if let Some(e) = estimators {
                opts.estimators = e
                    .iter()
                    .map(|n| compare::parse_estimator(n))
                    .collect::<Result<_, _>>()?;
            }
            if let Some(p) = &config {
                opts.config_toml = Some(read_file(p)?);
            }
            let mut result = compare::compare(&opts).map_err(|e| in_file(e, &config))?;
            if let Some(dir) = &criterion {
                let costs = compare::read_criterion_step_costs(dir, &opts.estimators);
                if costs.is_empty() {
                    eprintln!(
                        "warning: no criterion estimates under {} (run `cargo bench --bench baselines`)",
                        dir.display()
                    );
                }
                result.set_step_costs(costs);
            }
            let dir = out.unwrap_or_else(|| PathBuf::from("out").join("compare"));
            let _lock = DirLock::acquire(&dir)?;
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
    }
}

/// A configuration error located in the `--config` file reads `FILE:LINE:COLUMN: `key`: …`.
fn run_commission(
    config: Option<&std::path::Path>,
    motor: Option<&str>,
    out: Option<PathBuf>,
    seed: u64,
    averaged: bool,
) -> Result<ExitCode, Box<dyn std::error::Error>> {
    use fado_sim::commission::{self, CommissionOptions};
    let (text, mut cfg) = match (config, motor) {
        (Some(path), None) => {
            let text = read_file(path)?;
            let cfg = fado_sim::SimConfig::from_toml(&text)
                .map_err(|e| in_file(e, &Some(path.to_path_buf())))?;
            // The procedure identifies the file's motor: it never falls back on another's.
            let has_motor = text
                .parse::<toml::Table>()
                .is_ok_and(|t| t.contains_key("motor"));
            if !has_motor {
                return Err(SimConfigError::new(
                    "motor",
                    format!(
                        "{} has no [motor] table: commissioning identifies the motor the file \
                         describes (rs, ld, lq, flux_linkage, pole_pairs as rough values and \
                         the ratings rated_current, rated_speed_rpm, rated_torque)",
                        path.display()
                    ),
                )
                .into());
            }
            warn_plausibility(&cfg, Some(path));
            (text, cfg)
        }
        (None, Some(name)) => {
            let preset = fado_sim::presets::find(name)
                .ok_or_else(|| format!("no motor preset `{name}` (see `fado-sim motors`)"))?;
            (preset.toml.to_owned(), preset.config()?)
        }
        _ => return Err("give exactly one of --config FILE and --motor PRESET".into()),
    };
    cfg.current_sensor.seed = seed;
    if averaged {
        cfg.inverter.model = fado_sim::inverter::InverterModel::Averaged;
    }
    let plant = cfg.plant();
    // The nameplate the procedure is told: the [motor] record (parameters only size the
    // tests) with the inverter's DC link.
    let nameplate = fado_core::MachineModel {
        dc_voltage: plant.inverter.dc_voltage,
        ..plant.motor
    };
    // The directory is held from before the run to the last rename, as `run` holds it.
    let dir = out.unwrap_or_else(|| PathBuf::from("out").join("commission"));
    let lock = DirLock::acquire(&dir)?;
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg:<14} [{bar:40}] {percent:>3}%")?
            .progress_chars("=> "),
    );
    let mut cb = |f: f64, phase: fado_core::commissioning::Phase| {
        bar.set_message(phase.name());
        bar.set_position((f * 1000.0) as u64);
    };
    let o = commission::commission(
        &plant,
        nameplate,
        CommissionOptions::default(),
        |_| {},
        Some(&mut cb),
    )
    .map_err(|e| match config {
        Some(p) => e.located_in(&text).in_file(p.display().to_string()),
        None => e,
    })?;
    bar.finish_and_clear();
    let rows = o
        .identification
        .as_ref()
        .map(|id| commission::compare(id, &o.truth))
        .unwrap_or_default();
    let metrics = serde_json::json!({
        "passed": o.identification.is_some(),
        "status": format!("{:?}", o.status),
        "simulated_seconds": o.simulated_seconds,
        "wall_seconds": o.wall_seconds,
        "max_current": o.max_current,
        "max_current_reference": o.max_current_reference,
        "current_limit": o.current_limit,
        "rotor_motion_inductance": o.rotor_motion_inductance,
        "seed": seed,
        "parameters": rows,
    });
    // Every output is complete and synced under a temporary name before any is renamed into
    // place (`fado_sim::output`): the previous metrics.json and identified.toml go first,
    // traces.csv is renamed, then identified.toml, then metrics.json last, so a metrics.json
    // always sits beside its own traces and identified model; a kill, a full disk or a second
    // writer leave the previous results whole.
    let traces_path = dir.join("traces.csv");
    let mut csv = csv::Writer::from_writer(AtomicFile::create(&traces_path)?);
    for r in &o.trace {
        csv.serialize(r).map_err(|e| csv_error(e, &traces_path))?;
    }
    let traces = csv
        .into_inner()
        .map_err(|e| OutputError::new("write", &traces_path, e.into_error()))?
        .finish()?;
    // The input file with its [model] replaced by the identified one: runnable as is
    // (`fado-sim run reversal --config DIR/identified.toml`).
    let identified = match &o.identification {
        Some(id) => {
            let doc = commission::identified_toml(&text, id)?;
            let mut f = AtomicFile::create(&dir.join("identified.toml"))?;
            std::io::Write::write_all(&mut f, doc.as_bytes()).map_err(|e| f.error(e))?;
            Some(f.finish()?)
        }
        None => None,
    };
    let mut m = AtomicFile::create(&dir.join("metrics.json"))?;
    serde_json::to_writer_pretty(&mut m, &metrics).map_err(|e| m.error(e.into()))?;
    let m = m.finish()?;
    output::remove_if_present(&dir.join("metrics.json"))?;
    output::remove_if_present(&dir.join("identified.toml"))?;
    traces.rename()?;
    if let Some(f) = identified {
        f.rename()?;
    }
    m.rename()?;
    drop(lock);
    outln!(
        "commissioning: {:?} after {:.2} s simulated",
        o.status,
        o.simulated_seconds
    );
    if o.identification.is_none() {
        outln!("wrote {}/metrics.json and traces.csv", dir.display());
        return Ok(ExitCode::from(1));
    }
    outln!(
        "{:<18} {:>14} {:>14} {:>10} {:>10}",
        "parameter",
        "identified",
        "truth",
        "error",
        "1-sigma"
    );
    for r in &rows {
        let relative = !matches!(
            r.parameter,
            "viscous_friction" | "inverter_voltage" | "threshold_voltage"
        );
        if relative {
            outln!(
                "{:<18} {:>14.6e} {:>14.6e} {:>+9.3}% {:>9.3}%",
                r.parameter,
                r.identified,
                r.truth,
                100.0 * r.error,
                100.0 * r.confidence
            );
        } else {
            outln!(
                "{:<18} {:>14.6e} {:>14.6e} {:>+10.3e} {:>10.3e}",
                r.parameter,
                r.identified,
                r.truth,
                r.error,
                r.confidence
            );
        }
    }
    outln!(
        "wrote {}/identified.toml, metrics.json and traces.csv",
        dir.display()
    );
    Ok(ExitCode::SUCCESS)
}

fn in_file(e: SimConfigError, config: &Option<PathBuf>) -> SimConfigError {
    match config {
        Some(p) => e.in_file(p.display().to_string()),
        None => e,
    }
}

fn split_axis(arg: &str) -> Result<(&str, &str), String> {
    arg.split_once('=')
        .map(|(n, v)| (n.trim(), v))
        .ok_or_else(|| format!("--axis `{arg}` must look like name=values"))
}

fn run_sweep(
    spec: &SweepSpec,
    dir: PathBuf,
    threads: usize,
    fresh: bool,
) -> Result<ExitCode, Box<dyn std::error::Error>> {
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
