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

#[macro_use]
mod stdout;
mod axes;
mod commands;
mod files;

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use fado_sim::output::OutputError;
use fado_sim::sweep::SweepError;

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
    Run(commands::run::RunArgs),
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
    Sweep(commands::sweep::SweepArgs),
    /// Identify the motor of FILE's `[motor]` (with `rated_current`, `rated_speed_rpm`,
    /// `rated_torque`) on the simulated plant with `fado_core::commissioning`; print each
    /// parameter against the plant's truth; write DIR/identified.toml (`[model]`),
    /// DIR/metrics.json and DIR/traces.csv, as `run` writes: under the directory's lock, each
    /// whole or not at all. Refused before it runs when the set-up cannot be measured
    /// (ω_rated·Ts above 0.2, a current sensor coarser than 1 % of its current limit).
    Commission(commands::commission::CommissionArgs),
    /// Run every estimator in every scenario on the same plant, seed and controllers; print
    /// the table, write DIR/compare.json and DIR/compare.md.
    Compare(commands::compare::CompareArgs),
}

/// Exit code of a configuration or usage error (a bad key, value, scenario or axis).
const EXIT_CONFIG: u8 = 2;
/// Exit code of an output error: a file that cannot be read or written (the message names
/// it), or an output directory that another run holds.
const EXIT_IO: u8 = 3;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // `--help` and `--version` print through `out!` (a closed or full stdout never panics
        // and a full one exits 3, as every command's output).
        Err(e) if !e.use_stderr() => {
            out!("{}", e.render());
            return match stdout::take_error() {
                Some(err) => {
                    eprintln!("error: cannot write to stdout: {err}");
                    ExitCode::from(EXIT_IO)
                }
                None => ExitCode::SUCCESS,
            };
        }
        Err(e) => e.exit(),
    };
    let code = match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            let io = e.downcast_ref::<OutputError>().is_some()
                || matches!(e.downcast_ref::<SweepError>(), Some(SweepError::Io(_)));
            ExitCode::from(if io { EXIT_IO } else { EXIT_CONFIG })
        }
    };
    if let Some(e) = stdout::take_error() {
        eprintln!("error: cannot write to stdout: {e}");
        return ExitCode::from(EXIT_IO);
    }
    code
}

/// Runs the command of `cli`.
fn run(cli: Cli) -> commands::Outcome {
    match cli.command {
        Command::Motors => commands::list::motors(),
        Command::List => commands::list::scenarios_and_estimators(),
        Command::Run(args) => commands::run::run(args),
        Command::Sweep(args) => commands::sweep::sweep(args),
        Command::Commission(args) => commands::commission::commission(args),
        Command::Compare(args) => commands::compare::compare(args),
    }
}
