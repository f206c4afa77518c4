//! The command line's inputs and their errors: `--config` files, plausibility warnings,
//! errors located in a file.

use std::path::{Path, PathBuf};

use fado_sim::SimConfigError;
use fado_sim::output::OutputError;
use fado_sim::scenario;

/// Prints the plausibility warnings of `cfg`'s motor and of its profiles
/// ([`fado_sim::reach`]) on stderr, each at the
/// FILE:LINE:COLUMN of the key it blames first when `text` (the file's) holds it, else naming
/// the file.
pub fn warn_plausibility(cfg: &fado_sim::SimConfig, config: Option<&Path>, text: Option<&str>) {
    use fado_core::machine_checks::Severity;
    for (_, key, w) in cfg
        .machine_findings()
        .into_iter()
        .filter(|(s, ..)| *s == Severity::Warning)
    {
        warn_at(config, text, &key, &w);
    }
    for (key, w) in fado_sim::reach::findings(cfg) {
        warn_at(config, text, &key, &w);
    }
}

/// Prints the warning `w` on stderr at the FILE:LINE:COLUMN of `key`'s value in `text`, the
/// file `config` (as much of that as is known).
pub fn warn_at(config: Option<&Path>, text: Option<&str>, key: &str, w: &str) {
    let at = text
        .and_then(|t| fado_sim::source::value_span(t, key).map(|s| (t, s.start)))
        .map(|(t, start)| fado_sim::source::SourceLocation::at(t, start));
    match (config, at) {
        (Some(p), Some(at)) => eprintln!("{}:{}:{}: warning: {w}", p.display(), at.line, at.column),
        (Some(p), None) => eprintln!("warning: {}: {w}", p.display()),
        (None, _) => eprintln!("warning: {w}"),
    }
}

/// The text of an input file; an error names it (exit 3).
/// Reads a `--config` file, refusing one longer than [`scenario::MAX_CONFIG_BYTES`] before
/// reading more of it (`--config /dev/zero` stops after 1 MiB, not at the end of memory).
pub fn read_file(path: &Path) -> Result<String, Box<dyn std::error::Error>> {
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
    let text = String::from_utf8(bytes).map_err(|e| not_utf8(path, &e))?;
    if is_blank(&text) {
        return Err(SimConfigError::new(
            "<config>",
            format!(
                "{} holds no key (empty, or only comments): give the motor's [motor] table \
                 (docs/guide/your-motor.md), or leave out --config to run the scenario's own \
                 motor",
                path.display()
            ),
        )
        .into());
    }
    Ok(text)
}

/// The error of a `--config` file that is not UTF-8, at the line and column of its first bad
/// byte (a file saved as Latin-1 or Windows-1252, often for a `Ω` or `µ` in a comment).
fn not_utf8(path: &Path, e: &std::string::FromUtf8Error) -> SimConfigError {
    let at = e.utf8_error().valid_up_to();
    let good = String::from_utf8_lossy(&e.as_bytes()[..at]).into_owned();
    let mut err = SimConfigError::new(
        "<config>",
        format!(
            "byte 0x{:02x} is not UTF-8: TOML files are UTF-8 (saved as Latin-1 or \
             Windows-1252, for a `Ω` or `µ` in a comment?); save it as UTF-8",
            e.as_bytes()[at]
        ),
    );
    err.location = Some(fado_sim::source::SourceLocation::at(&good, good.len()));
    err.in_file(path.display().to_string())
}

/// True when `text` has nothing but whitespace, comments and a byte-order mark.
fn is_blank(text: &str) -> bool {
    text.trim_start_matches('\u{feff}')
        .lines()
        .map(str::trim)
        .all(|l| l.is_empty() || l.starts_with('#'))
}

/// A note on stderr when the `--config` file `text` has no `[motor]` table: the scenario's
/// own motor runs (the paper's for the paper's figures and the ratings-scaled scenarios).
pub fn note_scenario_motor(text: Option<&str>, config: Option<&Path>) {
    let (Some(text), Some(path)) = (text, config) else {
        return;
    };
    let has_motor = text
        .parse::<toml::Table>()
        .is_ok_and(|t| t.contains_key("motor"));
    if !has_motor {
        eprintln!(
            "note: {} has no [motor] table: the scenario's own motor runs (the paper's, \
             motors/paper.toml, unless the scenario names another)",
            path.display()
        );
    }
}

/// A note on stderr when the `--config` file `text` gives its own `[motor]` to one of the
/// paper's experiments in its motor's units (`Scenario::units_note`).
pub fn note_absolute_scenario(name: &str, cfg: &fado_sim::SimConfig, text: Option<&str>) {
    let has_motor = text
        .and_then(|t| t.parse::<toml::Table>().ok())
        .is_some_and(|t| t.contains_key("motor"));
    if let Some(note) = scenario::find(name).and_then(|s| s.units_note(cfg))
        && has_motor
    {
        eprintln!("note: {note}");
    }
}

/// A CSV write error as the output error naming `path`.
pub fn csv_error(e: csv::Error, path: &Path) -> OutputError {
    let source = match e.into_kind() {
        csv::ErrorKind::Io(e) => e,
        other => std::io::Error::other(format!("{other:?}")),
    };
    OutputError::new("write", path, source)
}

/// `e` located in the `--config` file, if one was given.
pub fn in_file(e: SimConfigError, config: &Option<PathBuf>) -> SimConfigError {
    match config {
        Some(p) => e.in_file(p.display().to_string()),
        None => e,
    }
}
