//! Configuration errors of the simulator: every error names the offending key by its TOML path.

use std::fmt;

use crate::source::{self, SourceLocation};

/// A configuration value was refused. `key` is the TOML path, e.g. `motor.rs`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SimConfigError {
    /// TOML path of the offending key (`section.field`), or the file for parse errors.
    pub key: String,
    /// What is wrong with it.
    pub message: String,
    /// Where the key's value is in the TOML text the user gave, when it is there.
    pub location: Option<SourceLocation>,
}

impl SimConfigError {
    /// An error about `key`.
    pub fn new(key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            message: message.into(),
            location: None,
        }
    }

    /// Locates the key in `text`, the TOML the user wrote (no change when it is not there,
    /// e.g. a value derived from other keys, or already located).
    pub fn located_in(mut self, text: &str) -> Self {
        if self.location.is_none() {
            self.location = source::value_span(text, &self.key)
                .map(|span| SourceLocation::at(text, span.start));
        }
        self
    }

    /// Names the file the located text came from (for `file:line:column:` messages); a
    /// location in another file (a flux map's CSV) keeps its own.
    pub fn in_file(mut self, file: impl Into<String>) -> Self {
        if let Some(loc) = &mut self.location
            && loc.file.is_none()
        {
            loc.file = Some(file.into());
        }
        self
    }

    /// Prefixes the key with a section name (`field` → `section.field`).
    pub fn in_section(mut self, section: &str) -> Self {
        self.key = if self.key.is_empty() {
            section.to_owned()
        } else {
            format!("{section}.{}", self.key)
        };
        self
    }
}

impl fmt::Display for SimConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.location {
            Some(SourceLocation {
                file: Some(file),
                line,
                column,
            }) => write!(f, "{file}:{line}:{column}: ")?,
            Some(SourceLocation { line, column, .. }) => {
                write!(f, "line {line}, column {column}: ")?
            }
            None => {}
        }
        write!(f, "`{}`: {}", self.key, self.message)
    }
}

impl std::error::Error for SimConfigError {}

impl From<fado_core::ConfigError> for SimConfigError {
    fn from(e: fado_core::ConfigError) -> Self {
        let message = e.to_string();
        Self::new(e.field(), message)
    }
}

/// Field checks used by every parameter record's `validate`.
pub(crate) mod check {
    use super::SimConfigError;

    pub fn finite(key: &str, x: f64) -> Result<f64, SimConfigError> {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(SimConfigError::new(key, format!("must be finite, got {x}")))
        }
    }

    pub fn positive(key: &str, x: f64) -> Result<f64, SimConfigError> {
        if finite(key, x)? > 0.0 {
            Ok(x)
        } else {
            Err(SimConfigError::new(key, format!("must be > 0, got {x}")))
        }
    }

    pub fn non_negative(key: &str, x: f64) -> Result<f64, SimConfigError> {
        if finite(key, x)? >= 0.0 {
            Ok(x)
        } else {
            Err(SimConfigError::new(key, format!("must be ≥ 0, got {x}")))
        }
    }

    pub fn in_range(key: &str, x: f64, lo: f64, hi: f64) -> Result<f64, SimConfigError> {
        if finite(key, x)? >= lo && x <= hi {
            Ok(x)
        } else {
            Err(SimConfigError::new(
                key,
                format!("must be in [{lo}, {hi}], got {x}"),
            ))
        }
    }
}
