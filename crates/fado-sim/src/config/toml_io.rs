//! The configuration as TOML text: written whole, parsed over a base key by key, and its
//! errors named by the user's key and located in the user's text.

use serde::Deserialize;

use super::SimConfig;
use crate::error::SimConfigError;
use crate::magnetics_file;
use crate::source::SourceLocation;

impl SimConfig {
    /// This configuration as a TOML document.
    pub fn to_toml(&self) -> String {
        let (sat, map) = (self.motor_saturation.as_ref(), self.motor_flux_map.as_ref());
        if sat.is_none() && map.is_none() {
            // Straight from the record: its field order (a TOML table would sort the keys).
            return toml::to_string(self)
                .expect("every field of SimConfig is representable in TOML");
        }
        let mut table = toml::Table::try_from(self).expect("SimConfig is a TOML table");
        magnetics_file::insert_magnetics(&mut table, sat, map);
        toml::to_string(&table).expect("every field of SimConfig is representable in TOML")
    }

    /// Parses a partial TOML document on top of `base`, an explicit configuration (a
    /// scenario's with the user's motor, a sweep point's): tables merge, values and arrays
    /// replace, so `[motor]\nrs = 0.5` changes one key of `base`'s motor. The result is
    /// validated. Errors name the key.
    pub fn from_toml_over(base: &SimConfig, text: &str) -> Result<SimConfig, SimConfigError> {
        Self::parse_over(base, text, false)
    }

    /// Parses a user's configuration file on top of `base`: as
    /// [`from_toml_over`](Self::from_toml_over), except that a `[motor]` table describes the
    /// whole motor — every circuit key and rating required, the others derived from the
    /// ratings with the `[inverter]` keys they give (`crate::derive`), none taken from
    /// `base`'s motor.
    pub fn from_user_toml(base: &SimConfig, text: &str) -> Result<SimConfig, SimConfigError> {
        Self::parse_over(base, text, true)
    }

    fn parse_over(
        base: &SimConfig,
        text: &str,
        whole_motor: bool,
    ) -> Result<SimConfig, SimConfigError> {
        let mut user: toml::Table = text.parse().map_err(|e| located(text, e))?;
        super::moved::refuse_moved(&user).map_err(|e| e.located_in(text))?;
        let converted =
            super::datasheet_keys::convert(&mut user).map_err(|e| e.located_in(text))?;
        let (saturation, flux_map) =
            magnetics_file::take_magnetics(&mut user).map_err(|e| e.located_in(text))?;
        // Check the user's document on its own first, so that errors (unknown keys, wrong
        // types) name the key the user wrote and point at it.
        if saturation.is_some() || flux_map.is_some() || !converted.is_empty() {
            SimConfig::deserialize(toml::Value::Table(user.clone())).map_err(|e| {
                with_type_hint(with_unknown_key_hint(key_error(e))).located_in(text)
            })?;
        } else {
            toml::from_str::<SimConfig>(text).map_err(|e| located(text, e))?;
        }
        let derived = if whole_motor {
            crate::derive::complete_motor(&mut user, text)?
        } else {
            Vec::new()
        };
        let given = user.clone();
        let mut merged = toml::Table::try_from(base)
            .map_err(|e| SimConfigError::new("<base>", e.to_string()))?;
        merge(&mut merged, user);
        let mut cfg = SimConfig::deserialize(toml::Value::Table(merged))
            .map_err(|e| key_error(e).located_in(text))?;
        // What `base` derived stays derived unless the document gives it now.
        cfg.derived = base
            .derived
            .iter()
            .filter(|d| {
                let (section, key) = d.key.split_once('.').unwrap_or(("", ""));
                !given
                    .get(section)
                    .and_then(|t| t.as_table())
                    .is_some_and(|t| t.contains_key(key))
            })
            .filter(|d| !derived.iter().any(|n| n.key == d.key))
            .cloned()
            .collect();
        cfg.derived.extend(derived);
        cfg.derived.extend(converted);
        // `[motor]` has no DC link of its own (it is the inverter's).
        cfg.motor.dc_voltage = cfg.inverter.dc_voltage;
        // What stays derived follows the inputs the document gives (its carrier, DC link or
        // ratings), as it does when the document is read on its own.
        if gives_inverter_inputs(&given) {
            crate::derive::rederive_inverter(&mut cfg);
        }
        // A document giving one magnetic model replaces the base's (either).
        if saturation.is_some() || flux_map.is_some() {
            (cfg.motor_saturation, cfg.motor_flux_map) = (saturation, flux_map);
        } else {
            cfg.motor_saturation = base.motor_saturation;
            cfg.motor_flux_map = base.motor_flux_map.clone();
        }
        cfg.validate().map_err(|e| e.located_in(text))?;
        Ok(cfg)
    }

    /// Parses a user's TOML document over the defaults (see
    /// [`from_user_toml`](Self::from_user_toml)).
    pub fn from_toml(text: &str) -> Result<SimConfig, SimConfigError> {
        Self::from_user_toml(&SimConfig::default(), text)
    }

    /// This configuration as TOML with each derived key's rule beside it (`--dump-config`),
    /// with the values the drive's build-time rules set (`drive_rules`).
    pub fn to_toml_annotated(&self) -> String {
        let shown = super::drive_rules::with_drive_rules(self);
        crate::derive::annotate(&shown.to_toml(), &shown.derived)
    }
}

/// Whether the document `given` holds a key the derived `[inverter]` values follow from: an
/// `[inverter]` key or a `[motor]` one (the ratings and the circuit set the carrier and the
/// current band).
fn gives_inverter_inputs(given: &toml::Table) -> bool {
    ["inverter", "motor"].iter().any(|s| {
        given
            .get(*s)
            .and_then(|t| t.as_table())
            .is_some_and(|t| t.values().any(|v| !v.is_table()))
    })
}

pub(super) fn merge(base: &mut toml::Table, over: toml::Table) {
    for (k, v) in over {
        match (base.get_mut(&k), v) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge(b, o),
            (_, v) => {
                base.insert(k, v);
            }
        }
    }
}

/// An error of parsing or deserialising the user's `text`: named by the key at its span (or
/// as `key_error` does), located at the span.
fn located(text: &str, e: toml::de::Error) -> SimConfigError {
    let start = e.span().map(|s| s.start);
    let key = start.and_then(|at| crate::source::key_at(text, at));
    let mut err = match key {
        Some(key) => SimConfigError::new(key, e.message().trim_end().to_owned()),
        None => {
            let mut k = key_error(e.clone());
            k.message = e.message().trim_end().to_owned();
            k
        }
    };
    err = with_type_hint(with_unknown_key_hint(err));
    if let Some(at) = start {
        syntax_hint(text, at, &mut err);
    }
    err.location = start.map(|at| SourceLocation::at(text, at));
    err
}

/// `err` (an unknown key) with the places the key belongs to: another table
/// ([`wrong_table_hint`]), the key of its table it looks like a slip of ([`meant_key_hint`]) or,
/// in `[motor]`, the datasheet's keys ([`datasheet_hint`]).
pub(crate) fn with_unknown_key_hint(mut err: SimConfigError) -> SimConfigError {
    if !err.message.starts_with("unknown field") {
        return err;
    }
    let hint = wrong_table_hint(&err.key)
        .or_else(|| meant_key_hint(&err.key, &err.message))
        .or_else(|| datasheet_hint(&err.key));
    if let Some(hint) = hint {
        err.message.push_str(&hint);
    }
    err
}

/// `err` (a value of the wrong type) with its usual cause: a number in quotes (`rs = "0.5"`),
/// a unit written into the value (`rs = "0.5 ohm"`), a whole number written with a fraction
/// (`pole_pairs = 7.0`).
pub(crate) fn with_type_hint(mut err: SimConfigError) -> SimConfigError {
    let Some(rest) = err.message.strip_prefix("invalid type: ") else {
        return err;
    };
    let whole = rest.ends_with("expected u32") || rest.ends_with("expected u64");
    let hint = if let Some(value) = rest
        .strip_prefix("string \"")
        .and_then(|s| s.split_once("\", expected"))
        .map(|(v, _)| v.trim().to_owned())
    {
        let number: String = value
            .chars()
            .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E'))
            .collect();
        if value.parse::<f64>().is_ok() {
            Some(format!(
                ": a number in quotes? Write it without them ({value})"
            ))
        } else if !number.is_empty() && number.parse::<f64>().is_ok() {
            Some(format!(
                ": a unit written into the value? Write the number alone ({number}), in the \
                 key's SI unit (docs/guide/your-motor.md)"
            ))
        } else {
            None
        }
    } else if let Some(value) = rest
        .strip_prefix("floating point `")
        .and_then(|s| s.split_once('`'))
        .map(|(v, _)| v)
        .filter(|_| whole)
    {
        match value.parse::<f64>() {
            Ok(v) if v.fract() == 0.0 && v > 0.0 => Some(format!(
                ": a whole number is meant: write {v:.0} (without the decimal point)"
            )),
            _ => Some(": a whole number is meant (for `pole_pairs`: half the pole count)".into()),
        }
    } else {
        None
    };
    if let Some(hint) = hint {
        err.message.push_str(&hint);
    }
    err
}

/// For an unknown key: the key of its table it most likely means
/// ([`crate::suggest::closest`] among the keys serde's message lists as expected).
fn meant_key_hint(full: &str, message: &str) -> Option<String> {
    let key = full.rsplit('.').next().unwrap_or(full);
    let expected = message.split_once("expected one of ")?.1;
    let keys = expected.split(", ").map(|k| k.trim().trim_matches('`'));
    let hint = crate::suggest::did_you_mean(key, keys);
    (!hint.is_empty()).then_some(hint)
}

/// For an unknown `motor.key`: the datasheet key it most likely means (a Kv, Kt, Ke or an
/// inertia in kg·cm²), else the list of the datasheet keys `[motor]` takes.
fn datasheet_hint(full: &str) -> Option<String> {
    let key = full.strip_prefix("motor.")?.to_ascii_lowercase();
    let keys: Vec<String> = fado_core::datasheet::ALTERNATIVES
        .iter()
        .map(|a| format!("`{}` ({})", a.key, a.unit))
        .collect();
    let meant = if key.starts_with("kv") {
        Some("kv_rpm_per_volt")
    } else if key.starts_with("kt") {
        Some("kt_nm_per_arms")
    } else if key.starts_with("ke") {
        Some("ke_vll_rms_per_krpm` or `ke_vll_peak_per_krpm")
    } else if key.starts_with("inertia") || key == "j" {
        Some("inertia_kg_cm2` (kg·cm²) or `inertia")
    } else {
        None
    };
    Some(match meant {
        Some(k) => format!(
            "; a datasheet's constant is given as `{k}` (converted to fado's key; \
             docs/guide/your-motor.md), and [motor] also takes {}",
            keys.join(", ")
        ),
        None => format!(
            "; [motor] also takes a datasheet's keys: {}",
            keys.join(", ")
        ),
    })
}

/// A hint for a syntax error at `at` that has a usual cause: a decimal comma (`rs = 0,06`),
/// a key given twice (named).
fn syntax_hint(text: &str, at: usize, err: &mut SimConfigError) {
    let bytes = text.as_bytes();
    let digit = |i: Option<usize>| i.and_then(|i| bytes.get(i)).is_some_and(u8::is_ascii_digit);
    if bytes.get(at) == Some(&b',') && digit(at.checked_sub(1)) && digit(Some(at + 1)) {
        err.message
            .push_str(": a decimal comma? TOML numbers take a point (0.06, not 0,06)");
    } else if err.message.starts_with("duplicate key") {
        let rest = text.get(at..).unwrap_or("");
        let name: String = rest
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == '-')
            .collect();
        if !name.is_empty() {
            err.message.push_str(&format!(
                ": `{name}` is given twice in its table (keep one)"
            ));
        }
    }
}

/// For an unknown `section.key`: the tables of the configuration where `key` is a key (a key
/// written in the wrong table, `[inverter] rs`), as a sentence to append; for a key outside
/// any table (`switching_frequency` at the top), the table that holds it
/// ([`crate::suggest::top_level_hint`]); None when there is none.
fn wrong_table_hint(full: &str) -> Option<String> {
    let Some((section, key)) = full.rsplit_once('.') else {
        return crate::suggest::top_level_hint(full);
    };
    let mut places = crate::suggest::tables_holding(key);
    places.retain(|p| p != section);
    if places.is_empty() {
        return None;
    }
    let names: Vec<String> = places.iter().map(|p| format!("[{p}]")).collect();
    Some(format!(
        "; `{key}` is a key of {}: written in the wrong table?",
        names.join(", ")
    ))
}

/// A serde error from a `toml::Value` carries "in `path`"; unknown fields name the field.
pub(crate) fn key_error(e: toml::de::Error) -> SimConfigError {
    let msg = e.to_string();
    let path = msg
        .split("in `")
        .nth(1)
        .and_then(|s| s.split('`').next())
        .unwrap_or("")
        .to_owned();
    let field = msg
        .split("unknown field `")
        .nth(1)
        .and_then(|s| s.split('`').next());
    let key = match (field, path.is_empty()) {
        (Some(f), true) => f.to_owned(),
        (Some(f), false) => format!("{path}.{f}"),
        (None, _) => path,
    };
    let first_line = msg.lines().next().unwrap_or("").to_owned();
    SimConfigError::new(
        if key.is_empty() { "<file>".into() } else { key },
        first_line,
    )
}
