//! Keys of the flat `[estimator]` and `[controller]` tables of earlier configuration files,
//! which live in the nested tables of their blocks (`[estimator.lock]`, `[controller.stall]`,
//! …): refused with their new place, and the names by which fado-core's configuration errors
//! (flat names) are reported.

use fado_core::control::tuning::MOVED_KEYS as CONTROLLER;
use fado_core::estimator::tuning::MOVED_KEYS as ESTIMATOR;

use crate::error::SimConfigError;

/// Every section whose flat keys moved, with fado-core's table of (flat key, nested path).
const SECTIONS: &[(&str, &[(&str, &str)])] =
    &[("estimator", ESTIMATOR), ("controller", CONTROLLER)];

/// The path below `section` where the flat key `key` lives now, if it moved.
pub(crate) fn moved(section: &str, key: &str) -> Option<&'static str> {
    SECTIONS
        .iter()
        .find(|(s, _)| *s == section)?
        .1
        .iter()
        .find(|(old, _)| *old == key)
        .map(|(_, new)| *new)
}

/// The error for the flat key `section.key` that moved to `section.path`: it names the table
/// and the key to write instead.
pub(crate) fn moved_error(section: &str, key: &str, path: &str) -> SimConfigError {
    let (table, field) = path.rsplit_once('.').unwrap_or(("", path));
    SimConfigError::new(
        format!("{section}.{key}"),
        format!(
            "`{section}.{key}` belongs in `[{section}.{table}]`: write it as `[{section}.{table}] {field}`"
        ),
    )
}

/// Refuses the first flat key of the user's document `user` that moved, naming its new place.
pub(super) fn refuse_moved(user: &toml::Table) -> Result<(), SimConfigError> {
    for (section, _) in SECTIONS {
        let Some(toml::Value::Table(table)) = user.get(*section) else {
            continue;
        };
        // `rs_adaptation`, `standstill_probe`, … are a flat key (a bool) and a table: only a
        // value that is not a table is the flat key.
        for (key, value) in table {
            if let (Some(path), false) = (moved(section, key), value.is_table()) {
                return Err(moved_error(section, key, path));
            }
        }
    }
    Ok(())
}
