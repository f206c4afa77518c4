//! Every numeric TOML key of the simulator is validated: walking the
//! default configuration's keys, `key = nan`, `key = inf` and `key = -inf` are refused naming
//! exactly that key and pointing at its line and column; −1 and 0 are accepted or refused
//! naming the key (or, for a cross-key constraint, another key of the same section).

use fado_sim::SimConfig;

/// Dotted paths of every float (and integer) leaf of the default configuration.
fn numeric_keys() -> Vec<(String, bool)> {
    fn walk(prefix: &str, table: &toml::Table, out: &mut Vec<(String, bool)>) {
        for (k, v) in table {
            let path = if prefix.is_empty() {
                k.clone()
            } else {
                format!("{prefix}.{k}")
            };
            match v {
                toml::Value::Table(t) => walk(&path, t, out),
                toml::Value::Float(_) => out.push((path, true)),
                toml::Value::Integer(_) => out.push((path, false)),
                _ => {}
            }
        }
    }
    let table: toml::Table = SimConfig::default().to_toml().parse().unwrap();
    let mut out = Vec::new();
    walk("", &table, &mut out);
    out
}

#[test]
fn every_numeric_key_is_validated_and_located() {
    let keys = numeric_keys();
    assert!(keys.len() > 50, "only {} numeric keys found", keys.len());
    let mut failures = Vec::new();
    let mut cases = 0;
    for (key, is_float) in &keys {
        let section = key.split('.').next().unwrap();
        let bad: &[&str] = if *is_float {
            &["nan", "inf", "-inf"]
        } else {
            &["1.5", "\"x\""]
        };
        for value in bad {
            cases += 1;
            let text = format!("# {value}\n{key} = {value}\n");
            match SimConfig::from_toml(&text) {
                Ok(_) => failures.push(format!("{key} = {value} was accepted")),
                Err(e) => {
                    let at = e.location.as_ref().map(|l| (l.line, l.column));
                    if e.key != *key || at != Some((2, key.chars().count() + 4)) {
                        failures.push(format!("{key} = {value}: {e} (at {at:?})"));
                    }
                }
            }
        }
        if *is_float {
            for value in ["-1.0", "0.0"] {
                cases += 1;
                let text = format!("{key} = {value}\n");
                if let Err(e) = SimConfig::from_toml(&text)
                    && e.key != *key
                    && !e.key.starts_with(&format!("{section}."))
                {
                    failures.push(format!("{key} = {value}: names another section: {e}"));
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {cases} cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
