//! `fado-sim`: run the paper's experiments on the simulated drive.
//!
//! ```text
//! fado-sim list
//! fado-sim run fig11 [--config FILE] [--out DIR] [--averaged] [--dump-config]
//! fado-sim sweep fig11 --set mismatch.rs_ratio=0.98,0.99,1,1.01,1.02 [--averaged]
//! fado-sim compare [--scenarios fig8,...] [--estimators fado,lpf-integrator,ortega,emf-observer]
//!                  [--out DIR] [--averaged] [--config FILE] [--criterion target/criterion]
//! ```

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use fado_sim::compare;
use fado_sim::scenario::{self, SCENARIOS};
use fado_sim::{SimConfig, SimConfigError};
use indicatif::{ProgressBar, ProgressStyle};

#[derive(Parser)]
#[command(
    name = "fado-sim",
    version,
    about = "Closed-loop simulation of the FADO sensorless PMSM drive (Park & Sul)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the scenarios.
    List,
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
    /// Run a scenario once per value of one key and tabulate the results (robustness sweeps),
    /// e.g. `sweep fig11 --set mismatch.rs_ratio=0.98,0.99,1,1.01,1.02`. Writes DIR/sweep.csv.
    Sweep {
        /// Scenario name.
        scenario: String,
        /// `section.key=v1,v2,...` (TOML values; bare words are taken as strings).
        #[arg(long)]
        set: String,
        /// TOML file applied before the swept key.
        #[arg(long)]
        config: Option<PathBuf>,
        /// Output directory. Default `out/<scenario>-sweep`.
        #[arg(long)]
        out: Option<PathBuf>,
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
        /// Comma-separated estimators. Default: fado,lpf-integrator,ortega,emf-observer.
        #[arg(long, value_delimiter = ',')]
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

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli) -> Result<ExitCode, Box<dyn std::error::Error>> {
    match cli.command {
        Command::List => {
            for s in &SCENARIOS {
                println!(
                    "{:<7} {}\n        profile:   {}\n        criterion: {}",
                    s.name, s.title, s.profile, s.criterion
                );
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
                Some(p) => Some(
                    std::fs::read_to_string(p)
                        .map_err(|e| format!("cannot read {}: {e}", p.display()))?,
                ),
                None => None,
            };
            let cfg = scenario::scenario_config(&name, text.as_deref(), averaged)
                .map_err(|e| in_file(e, &config))?;
            if dump_config {
                print!("{}", cfg.to_toml());
                return Ok(ExitCode::SUCCESS);
            }
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
            let outcome = scenario::run_config(&name, cfg, Some(&mut cb))?;
            bar.finish_and_clear();
            let dir = out.unwrap_or_else(|| PathBuf::from("out").join(&name));
            std::fs::create_dir_all(&dir)?;
            let report = outcome.report();
            std::fs::write(
                dir.join("metrics.json"),
                serde_json::to_string_pretty(&report)?,
            )?;
            outcome
                .trace
                .write_csv(std::fs::File::create(dir.join("traces.csv"))?)?;
            print_table(&report);
            println!("wrote {}/metrics.json and traces.csv", dir.display());
            Ok(if report.passed {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            })
        }
        Command::Sweep {
            scenario: name,
            set,
            config,
            out,
            averaged,
        } => sweep(&name, &set, config, out, averaged),
        Command::Compare {
            scenarios,
            estimators,
            config,
            out,
            averaged,
            criterion,
            threads,
        } => {
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
                opts.config_toml = Some(
                    std::fs::read_to_string(p)
                        .map_err(|e| format!("cannot read {}: {e}", p.display()))?,
                );
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
            std::fs::create_dir_all(&dir)?;
            std::fs::write(
                dir.join("compare.json"),
                serde_json::to_string_pretty(&result)?,
            )?;
            let md = result.to_markdown();
            std::fs::write(dir.join("compare.md"), &md)?;
            print!("{md}");
            println!(
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
fn in_file(e: SimConfigError, config: &Option<PathBuf>) -> SimConfigError {
    match config {
        Some(p) => e.in_file(p.display().to_string()),
        None => e,
    }
}

fn sweep(
    name: &str,
    set: &str,
    config: Option<PathBuf>,
    out: Option<PathBuf>,
    averaged: bool,
) -> Result<ExitCode, Box<dyn std::error::Error>> {
    let (key, values) = set
        .split_once('=')
        .ok_or("--set must look like section.key=v1,v2,...")?;
    let (section, field) = key
        .rsplit_once('.')
        .ok_or("--set key must be section.key")?;
    let text = match &config {
        Some(p) => Some(std::fs::read_to_string(p)?),
        None => None,
    };
    let base = scenario::scenario_config(name, text.as_deref(), averaged)
        .map_err(|e| in_file(e, &config))?;
    let mut overrides = Vec::new();
    for v in values.split(',').map(str::trim).filter(|v| !v.is_empty()) {
        // A TOML value as written, else a bare word as a string.
        let value = if format!("x = {v}").parse::<toml::Table>().is_ok() {
            v.to_owned()
        } else {
            format!("{v:?}")
        };
        let snippet = format!("[{section}]\n{field} = {value}\n");
        // The snippet is ours, not a file of the user's: no line numbers from it.
        let cfg = SimConfig::from_toml_over(&base, &snippet).map_err(|mut e| {
            e.location = None;
            e.message = format!("--set {key}={v}: {}", e.message);
            e
        })?;
        overrides.push((v.to_owned(), cfg));
    }
    // Two at a time: the machine has two cores.
    let results: Vec<_> = std::thread::scope(|sc| {
        let handles: Vec<_> = overrides
            .chunks(overrides.len().div_ceil(2).max(1))
            .map(|chunk| {
                sc.spawn(move || {
                    chunk
                        .iter()
                        .map(|(v, cfg)| (v.clone(), scenario::run_config(name, cfg.clone(), None)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("sweep worker panicked"))
            .collect()
    });
    let dir = out.unwrap_or_else(|| PathBuf::from("out").join(format!("{name}-sweep")));
    std::fs::create_dir_all(&dir)?;
    let mut csv = csv::Writer::from_path(dir.join("sweep.csv"))?;
    csv.write_record([
        key,
        "passed",
        "max_angle_error",
        "max_angle_error_zero_speed",
        "rms_angle_error_zero_speed",
        "max_speed_error_rpm",
        "tripped",
    ])?;
    println!("{key:>24}  passed  max|θ−θ̂|  near 0   rms near 0  speed err  tripped");
    for (v, r) in results {
        let r = r?.report();
        println!(
            "{v:>24}  {:<6}  {:>8.4}  {:>7.4}  {:>10.4}  {:>9.2}  {}",
            r.passed,
            r.max_angle_error,
            r.max_angle_error_zero_speed,
            r.rms_angle_error_zero_speed,
            r.max_speed_error_rpm,
            r.tripped
        );
        csv.write_record([
            v,
            r.passed.to_string(),
            r.max_angle_error.to_string(),
            r.max_angle_error_zero_speed.to_string(),
            r.rms_angle_error_zero_speed.to_string(),
            r.max_speed_error_rpm.to_string(),
            r.tripped.to_string(),
        ])?;
    }
    csv.flush()?;
    println!("wrote {}/sweep.csv", dir.display());
    Ok(ExitCode::SUCCESS)
}

fn print_table(r: &scenario::Report) {
    println!(
        "scenario            {} ({:?} inverter)",
        r.scenario, r.inverter_model
    );
    println!("max |θ−θ̂|           {:.4} rad", r.max_angle_error);
    println!("rms θ−θ̂             {:.4} rad", r.rms_angle_error);
    println!(
        "max |θ−θ̂| |n|<{:<4}  {:.4} rad",
        r.zero_speed_band_rpm, r.max_angle_error_zero_speed
    );
    println!(
        "rms θ−θ̂ near zero   {:.4} rad",
        r.rms_angle_error_zero_speed
    );
    println!("max speed error     {:.2} r/min", r.max_speed_error_rpm);
    println!("tripped             {}", r.tripped);
    println!(
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
        println!(
            "  [{}] {:<40} {:>10.4}  {}",
            if c.passed { "pass" } else { "FAIL" },
            c.name,
            c.value,
            lim
        );
    }
    println!("PASSED              {}", r.passed);
}
