//! The values of `--axis name=...`: `lo:hi:n`, `v1,v2,...` (grid) and `lo..hi` (random).

use fado_sim::SimConfigError;
use fado_sim::sweep::Value;

/// Parses one value list: `lo:hi:n` (n values evenly spaced, ends included) or `v1,v2,...`
/// (TOML values; bare words are taken as strings).
pub fn parse_values(text: &str) -> Result<Vec<Value>, SimConfigError> {
    let text = text.trim();
    let parts: Vec<_> = text.split(':').collect();
    if parts.len() == 3 {
        let num = |s: &str| s.trim().parse::<f64>().ok().filter(|x| x.is_finite());
        let (Some(lo), Some(hi), Ok(n)) = (
            num(parts[0]),
            num(parts[1]),
            parts[2].trim().parse::<usize>(),
        ) else {
            return Err(SimConfigError::new(
                text.to_owned(),
                "`lo:hi:n` needs two finite numbers and a count",
            ));
        };
        if n == 0 {
            return Err(SimConfigError::new(text.to_owned(), "count must be ≥ 1"));
        }
        return Ok((0..n)
            .map(|k| {
                let v = if n == 1 {
                    lo
                } else {
                    lo + (hi - lo) * k as f64 / (n - 1) as f64
                };
                // Round off the last-bit noise of the linspace (0.30000000000000004).
                Value::Float((v * 1e12).round() / 1e12)
            })
            .collect());
    }
    let values: Vec<_> = text
        .split(',')
        .map(str::trim)
        .filter(|v| !v.is_empty())
        .map(parse_value)
        .collect();
    if values.is_empty() {
        return Err(SimConfigError::new(text.to_owned(), "no values"));
    }
    Ok(values)
}

/// A TOML value as written (`0.5`, `3`, `true`, `[[0.0, 1.0]]`), else the text as a string.
pub fn parse_value(text: &str) -> Value {
    format!("x = {text}")
        .parse::<toml::Table>()
        .ok()
        .and_then(|mut t| t.remove("x"))
        .unwrap_or_else(|| Value::String(text.to_owned()))
}

/// Parses a range `lo..hi` of a random design.
pub fn parse_range(text: &str) -> Result<(f64, f64), SimConfigError> {
    let bad = || SimConfigError::new(text.to_owned(), "a range must be `lo..hi` with lo ≤ hi");
    let (a, b) = text.split_once("..").ok_or_else(bad)?;
    let (lo, hi) = (
        a.trim().parse::<f64>().map_err(|_| bad())?,
        b.trim().parse::<f64>().map_err(|_| bad())?,
    );
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return Err(bad());
    }
    Ok((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn floats(v: &[f64]) -> Vec<Value> {
        v.iter().map(|&x| Value::Float(x)).collect()
    }

    #[test]
    fn value_lists_and_ranges_parse() {
        assert_eq!(
            parse_values("-0.5:0.5:3").unwrap(),
            floats(&[-0.5, 0.0, 0.5])
        );
        assert_eq!(
            parse_values("0,7.5").unwrap(),
            vec![Value::Integer(0), Value::Float(7.5)]
        );
        // linspace ends included, last-bit noise rounded off
        assert_eq!(
            parse_values("0:0.3:4").unwrap(),
            floats(&[0.0, 0.1, 0.2, 0.3])
        );
        assert_eq!(
            parse_values("a,true").unwrap(),
            vec![Value::String("a".into()), Value::Boolean(true)]
        );
        assert!(parse_values("0:1:0").is_err());
        assert!(parse_values(" , ").is_err());
        assert!(parse_range("1..0").is_err());
        assert!(parse_range("0..inf").is_err());
        assert_eq!(parse_range("-0.5..0.5").unwrap(), (-0.5, 0.5));
    }
}
