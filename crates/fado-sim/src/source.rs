//! Where a key is in the TOML text the user wrote: line and column for error messages
//! (`config.toml:12:6: `motor.rs`: must be > 0, got -1`).
//!
//! The spans come from the toml crate's own span-preserving parse (`toml::de::DeTable`), so
//! they are exact for every TOML spelling (dotted keys, inline tables, arrays of tables).

use std::ops::Range;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// A position in a TOML source: 1-based line and column (in characters).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SourceLocation {
    /// The file, when known (the CLI sets it; library callers pass text).
    pub file: Option<String>,
    /// 1-based line.
    pub line: usize,
    /// 1-based column, counted in characters.
    pub column: usize,
}

impl SourceLocation {
    /// The line and column of byte `offset` in `text`.
    pub fn at(text: &str, offset: usize) -> Self {
        let offset = offset.min(text.len());
        let before = text.get(..offset).unwrap_or(text);
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        Self {
            file: None,
            line: before.matches('\n').count() + 1,
            column: before[line_start..].chars().count() + 1,
        }
    }
}

/// The span of the value of the dotted `key` (`motor.rs`, `speed_reference.points[2]`) in
/// `text`, if the text sets it.
pub fn value_span(text: &str, key: &str) -> Option<Range<usize>> {
    let root = DeTable::parse(text).ok()?;
    let mut segments = key.split('.');
    let first = segments.next()?;
    let mut value = lookup_in_table(root.get_ref(), first)?;
    for segment in segments {
        value = match value.get_ref() {
            DeValue::Table(t) => lookup_in_table(t, segment)?,
            _ => return None,
        };
    }
    Some(value.span())
}

/// `name` or `name[i]` (repeated indices allowed) in a table.
fn lookup_in_table<'a, 'i>(
    table: &'a DeTable<'i>,
    segment: &str,
) -> Option<&'a Spanned<DeValue<'i>>> {
    let (name, mut rest) = segment
        .find('[')
        .map_or((segment, ""), |i| (&segment[..i], &segment[i..]));
    let mut value = table
        .iter()
        .find(|(k, _)| k.get_ref().as_ref() == name)
        .map(|(_, v)| v)?;
    while let Some(r) = rest.strip_prefix('[') {
        let (index, after) = r.split_once(']')?;
        let index: usize = index.parse().ok()?;
        value = match value.get_ref() {
            DeValue::Array(a) => a.get(index)?,
            _ => return None,
        };
        rest = after;
    }
    Some(value)
}

/// The dotted key whose key or value in `text` contains byte `offset` (the innermost one):
/// names the key a deserialisation error points at.
pub fn key_at(text: &str, offset: usize) -> Option<String> {
    let root = DeTable::parse(text).ok()?;
    let mut path = Vec::new();
    find_in_table(root.get_ref(), offset, &mut path).then(|| path.join("."))
}

fn find_in_table(table: &DeTable<'_>, offset: usize, path: &mut Vec<String>) -> bool {
    for (k, v) in table.iter() {
        let in_key = k.span().contains(&offset);
        // An array of tables (`[[faults.non_finite]]`) has no span of its own around its
        // tables' keys: look inside arrays as inside tables.
        let container = matches!(v.get_ref(), DeValue::Table(_) | DeValue::Array(_));
        if in_key || v.span().contains(&offset) || container {
            path.push(k.get_ref().to_string());
            if find_in_value(v, offset, path) || in_key || v.span().contains(&offset) {
                return true;
            }
            path.pop();
        }
    }
    false
}

fn find_in_value(v: &Spanned<DeValue<'_>>, offset: usize, path: &mut Vec<String>) -> bool {
    match v.get_ref() {
        DeValue::Table(t) => find_in_table(t, offset, path),
        DeValue::Array(a) => {
            for (i, item) in a.iter().enumerate() {
                if item.span().contains(&offset) || matches!(item.get_ref(), DeValue::Table(_)) {
                    if let Some(last) = path.last_mut() {
                        last.push_str(&format!("[{i}]"));
                    }
                    if find_in_value(item, offset, path) || item.span().contains(&offset) {
                        return true;
                    }
                    if let Some(last) = path.last_mut() {
                        let cut = last.rfind('[').unwrap_or(last.len());
                        last.truncate(cut);
                    }
                }
            }
            false
        }
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "# comment\n[motor]\nrs = 0.3\nlq = 2e-3\n\n[speed_reference]\n\
                        points = [[0.0, 0.0], [1.0, 500.0]]\n[load.torque]\nx = 1\n";

    fn loc(key: &str) -> (usize, usize) {
        let s = SourceLocation::at(TEXT, value_span(TEXT, key).unwrap().start);
        (s.line, s.column)
    }

    #[test]
    fn values_are_found_by_dotted_key() {
        assert_eq!(loc("motor.rs"), (3, 6));
        assert_eq!(loc("motor.lq"), (4, 6));
        assert_eq!(loc("speed_reference.points"), (7, 10));
        assert_eq!(loc("speed_reference.points[1]"), (7, 23));
        assert_eq!(loc("load.torque.x"), (9, 5));
        assert_eq!(value_span(TEXT, "motor.ld"), None);
        assert_eq!(value_span(TEXT, "speed_reference.points[5]"), None);
    }

    #[test]
    fn offsets_map_back_to_keys() {
        let at = |needle: &str| key_at(TEXT, TEXT.find(needle).unwrap());
        assert_eq!(at("rs =").as_deref(), Some("motor.rs"));
        assert_eq!(at("2e-3").as_deref(), Some("motor.lq"));
        assert_eq!(at("500.0").as_deref(), Some("speed_reference.points[1][1]"));
        assert_eq!(at("x = 1").as_deref(), Some("load.torque.x"));
        assert_eq!(at("# comment"), None);
    }

    #[test]
    fn columns_count_characters() {
        let text = "[motor]\n# λ̂f\nrs = -1\n";
        let s = SourceLocation::at(text, value_span(text, "motor.rs").unwrap().start);
        assert_eq!((s.line, s.column), (3, 6));
    }

    #[test]
    fn keys_inside_arrays_of_tables_get_their_full_path() {
        let text = "[motor]\nrs = 0.3\n\n[[faults.non_finite]]\ntime = 1.0\nsignal = \"x\"\n\n\
                    [[faults.non_finite]]\ntime = 2.0\nsignl = \"current_a\"\n";
        let at = |needle: &str| text.find(needle).unwrap();
        assert_eq!(
            key_at(text, at("\"x\"")).as_deref(),
            Some("faults.non_finite[0].signal")
        );
        assert_eq!(
            key_at(text, at("signl")).as_deref(),
            Some("faults.non_finite[1].signl")
        );
        assert_eq!(key_at(text, at("0.3")).as_deref(), Some("motor.rs"));
    }
}
