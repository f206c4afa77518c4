//! One module per subcommand: its arguments and what it does.

pub mod commission;
pub mod compare;
pub mod list;
pub mod run;
pub mod sweep;

/// What a command returns: its exit code, or the error `main` reports (exit 2 or 3).
pub type Outcome = Result<std::process::ExitCode, Box<dyn std::error::Error>>;
