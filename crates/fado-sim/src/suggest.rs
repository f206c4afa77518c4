//! The key a user most likely meant when the one they wrote does not exist: the nearest of the
//! keys the table takes by edit distance (optimal string alignment, so that two swapped letters
//! are one edit, case ignored), and only when that distance is at most a third of the longer
//! name (at least one edit). So `rss` finds `rs`, `swiching_frequency` finds
//! `switching_frequency`, `rated_speed` finds `rated_speed_rpm` and `limter` finds `limiter`,
//! while a name unlike every key finds nothing and the error lists the keys instead.

/// The candidate nearest to `given` within the bound of the module doc; the first of equally
/// near ones.
pub fn closest<'a>(given: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let given_lower = given.to_lowercase();
    let mut best: Option<(usize, &'a str)> = None;
    for candidate in candidates {
        let distance = strsim::osa_distance(&given_lower, &candidate.to_lowercase());
        let longer = given.chars().count().max(candidate.chars().count());
        if distance > (longer / 3).max(1) || candidate == given {
            continue;
        }
        if best.is_none_or(|(d, _)| distance < d) {
            best = Some((distance, candidate));
        }
    }
    best.map(|(_, c)| c)
}

/// `"; did you mean `key`?"` for the [`closest`] candidate, or an empty string.
pub fn did_you_mean<'a>(given: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    closest(given, candidates)
        .map(|c| format!("; did you mean `{c}`?"))
        .unwrap_or_default()
}

/// The tables of the simulator's configuration that hold `key` (`inverter` for
/// `switching_frequency`, `motor` and `model` for `rs`), depth first, as dotted paths.
pub fn tables_holding(key: &str) -> Vec<String> {
    let mut places = Vec::new();
    if let Ok(defaults) = crate::config::SimConfig::default()
        .to_toml()
        .parse::<toml::Table>()
    {
        tables_with_key(&defaults, "", key, &mut places);
    }
    places
}

/// Every table path below `prefix` in `table` that holds `key`, depth first.
fn tables_with_key(table: &toml::Table, prefix: &str, key: &str, out: &mut Vec<String>) {
    for (k, v) in table {
        if let toml::Value::Table(t) = v {
            let path = if prefix.is_empty() {
                k.clone()
            } else {
                format!("{prefix}.{k}")
            };
            if t.contains_key(key) {
                out.push(path.clone());
            }
            tables_with_key(t, &path, key, out);
        }
    }
}

/// For a key given outside any table (`switching_frequency = 20e3` at the top of a file, or
/// `{"switching_frequency": 20e3}` as a Python config): the tables that hold it and how to
/// write it there, as a sentence to append; None when no table holds it.
pub fn top_level_hint(key: &str) -> Option<String> {
    let places = tables_holding(key);
    let first = places.first()?;
    let names: Vec<String> = places.iter().map(|p| format!("[{p}]")).collect();
    Some(format!(
        "; `{key}` is a key of {}: write it in its table (`[{first}]` then `{key} = …` in \
         TOML, `{{\"{first}\": {{\"{key}\": …}}}}` as a Python dict)",
        names.join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    const INVERTER: [&str; 5] = [
        "dc_voltage",
        "switching_frequency",
        "dead_time",
        "current_band",
        "threshold_voltage",
    ];

    #[test]
    fn a_slip_finds_the_key_it_was_meant_to_be() {
        assert_eq!(
            closest("swiching_frequency", INVERTER),
            Some("switching_frequency")
        );
        assert_eq!(closest("deadtime", INVERTER), Some("dead_time"));
        assert_eq!(closest("DC_Voltage", INVERTER), Some("dc_voltage"));
        assert_eq!(closest("rss", ["rs", "ld", "lq"]), Some("rs"));
        assert_eq!(
            closest("rated_speed", ["rated_speed_rpm", "rated_torque"]),
            Some("rated_speed_rpm")
        );
        assert_eq!(closest("k_aff", ["k_af", "radius_ratio"]), Some("k_af"));
        assert_eq!(closest("ldd", ["rs", "ld", "lq"]), Some("ld"));
    }

    #[test]
    fn a_name_unlike_every_key_finds_nothing() {
        assert_eq!(closest("gear_ratio", INVERTER), None);
        assert_eq!(closest("x", ["rs", "ld"]), None);
        assert_eq!(did_you_mean("flux", ["flux_linkage", "pole_pairs"]), "");
    }

    #[test]
    fn the_hint_names_the_key() {
        assert_eq!(
            did_you_mean("limter", ["integrator", "limiter", "mode"]),
            "; did you mean `limiter`?"
        );
    }

    #[test]
    fn a_key_outside_its_table_is_sent_to_the_table_that_holds_it() {
        assert_eq!(tables_holding("switching_frequency"), ["inverter"]);
        let hint = top_level_hint("switching_frequency").unwrap_or_default();
        assert!(hint.contains("[inverter]"), "{hint}");
        assert!(
            hint.contains("{\"inverter\": {\"switching_frequency\": …}}"),
            "{hint}"
        );
        assert_eq!(top_level_hint("gear_ratio"), None);
    }
}
