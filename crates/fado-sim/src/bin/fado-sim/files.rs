//! The command line's inputs and their errors: `--config` files, plausibility warnings,
//! errors located in a file.

use std::path::{Path, PathBuf};

use fado_sim::SimConfigError;
use fado_sim::output::OutputError;
use fado_sim::scenario;

/// Prints the plausibility warnings of `cfg`'s motor on stderr, naming the file.
pub fn warn_plausibility(cfg: &fado_sim::SimConfig, config: Option<&Path>) {
    for w in cfg.warnings() {
        match config {
            Some(p) => eprintln!("warning: {}: {w}", p.display()),
            None => eprintln!("warning: {w}"),
        }
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
