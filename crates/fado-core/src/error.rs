//! Errors: a typed configuration error naming the field, and the per-sample input fault.

use core::fmt;

/// Why a configuration was refused. Every variant names the offending field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigError {
    /// The field is NaN or infinite.
    NotFinite {
        /// Name of the field, as written in the config struct.
        field: &'static str,
    },
    /// The field must be strictly positive.
    NotPositive {
        /// Name of the field, as written in the config struct.
        field: &'static str,
    },
    /// The field must not be negative.
    Negative {
        /// Name of the field, as written in the config struct.
        field: &'static str,
    },
    /// The field is finite but outside the range the maths allows.
    OutOfRange {
        /// Name of the field, as written in the config struct.
        field: &'static str,
        /// Which range, in words.
        expected: &'static str,
    },
}

impl ConfigError {
    /// The name of the offending field.
    pub fn field(&self) -> &'static str {
        match *self {
            ConfigError::NotFinite { field }
            | ConfigError::NotPositive { field }
            | ConfigError::Negative { field }
            | ConfigError::OutOfRange { field, .. } => field,
        }
    }
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ConfigError::NotFinite { field } => write!(f, "`{field}` must be finite"),
            ConfigError::NotPositive { field } => write!(f, "`{field}` must be positive"),
            ConfigError::Negative { field } => write!(f, "`{field}` must not be negative"),
            ConfigError::OutOfRange { field, expected } => {
                write!(f, "`{field}` is out of range: expected {expected}")
            }
        }
    }
}

impl core::error::Error for ConfigError {}

/// A sample was refused because an input was NaN or infinite; the state was left untouched.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NonFiniteInput;

impl fmt::Display for NonFiniteInput {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("non-finite input sample rejected; state unchanged")
    }
}

impl core::error::Error for NonFiniteInput {}

/// Field checks shared by every config's `validate`.
pub(crate) mod check {
    use super::ConfigError;
    use crate::Real;

    pub fn finite<T: Real>(field: &'static str, x: T) -> Result<T, ConfigError> {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(ConfigError::NotFinite { field })
        }
    }

    pub fn positive<T: Real>(field: &'static str, x: T) -> Result<T, ConfigError> {
        if finite(field, x)? > T::zero() {
            Ok(x)
        } else {
            Err(ConfigError::NotPositive { field })
        }
    }

    pub fn non_negative<T: Real>(field: &'static str, x: T) -> Result<T, ConfigError> {
        if finite(field, x)? >= T::zero() {
            Ok(x)
        } else {
            Err(ConfigError::Negative { field })
        }
    }

    pub fn below<T: Real>(
        field: &'static str,
        x: T,
        limit: T,
        expected: &'static str,
    ) -> Result<T, ConfigError> {
        if x < limit {
            Ok(x)
        } else {
            Err(ConfigError::OutOfRange { field, expected })
        }
    }

    /// A duration `time` (s) as a whole number of sampling periods `ts`, rounded; `field`
    /// names a negative, non-finite or too long one (4e9 periods: about 5 days at 10 kHz).
    pub fn samples<T: Real>(field: &'static str, time: T, ts: T) -> Result<u32, ConfigError> {
        let n = non_negative(field, time)? / ts;
        below(field, n, T::lit(4e9), "below 4e9 sampling periods")?;
        Ok(n.round().to_f64() as u32)
    }
}
