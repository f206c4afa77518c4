//! A user's motor, whole: a `[motor]` table describes one motor completely, by its circuit
//! and ratings (`fado_core::ratings::REQUIRED_MOTOR_KEYS`) and, where the file leaves them
//! out, the values its ratings give by the rules of `fado_core::ratings` — `inertia` and
//! `viscous_friction` of `[motor]`; `dc_voltage`, `switching_frequency`, `dead_time`,
//! `threshold_voltage` and `current_band` of `[inverter]`. No key is ever taken from another
//! motor (the scenario's or the paper's). Each derived value is recorded with its rule
//! ([`Derived`]), which `fado-sim run --dump-config` prints beside it.
//!
//! The rules apply to the file as read (`SimConfig::from_user_toml`, what `fado-sim --config`,
//! the presets and `fado.simulate(config=…)` use); a later override of one key
//! (`SimConfig::from_toml_over`: a sweep axis `motor.rated_torque`, a Python `config` over a
//! `Machine`) changes that key alone and keeps the values derived before.
//!
//! The other `[inverter]` keys are simulation settings with a neutral default, not a property
//! of another motor's inverter: `model` (switching-resolved), `commutation` (linear band),
//! `dc_ripple_amplitude` 0 (no ripple; `dc_ripple_frequency` then unused), `on_resistance` 0
//! (Rs holds it).

use fado_core::{MachineModel, ratings};
use serde::Serialize;

use crate::error::SimConfigError;
use crate::source::SourceLocation;

/// A key whose value was derived from the ratings.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Derived {
    /// The TOML key, `section.key`.
    pub key: String,
    /// The value.
    pub value: f64,
    /// The rule, in words (`fado_core::ratings::RULES`).
    pub rule: &'static str,
}

/// The machine keys that may be derived.
const DERIVABLE_MOTOR_KEYS: [&str; 2] = ["inertia", "viscous_friction"];

fn number(table: &toml::Table, key: &str) -> Option<f64> {
    match table.get(key)? {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(n) => Some(*n as f64),
        _ => None,
    }
}

/// Where `[section]` (or a `section.` dotted key) starts in `text`.
fn section_location(text: &str, section: &str) -> Option<SourceLocation> {
    let header = format!("[{section}]");
    let dotted = format!("{section}.");
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let t = line.trim_start();
        if t.starts_with(&header) || t.starts_with(&dotted) {
            return Some(SourceLocation::at(text, offset + line.len() - t.len()));
        }
        offset += line.len();
    }
    None
}

/// Completes the user's `[motor]` (if `user` has one) and the `[inverter]` keys its ratings
/// give; returns the derived keys. A missing circuit key or rating is an error naming every
/// missing key, located at the `[motor]` header of `text`; a given key that is not a positive
/// finite number is left to the validation, which names it at its value.
pub fn complete_motor(user: &mut toml::Table, text: &str) -> Result<Vec<Derived>, SimConfigError> {
    let Some(mut motor) = completable_motor(user) else {
        return Ok(Vec::new());
    };
    check_required(&motor, text)?;
    let mut derived = Vec::new();
    let mut put = |table: &mut toml::Table, section: &str, key: &str, value: f64| {
        table.insert(key.to_owned(), toml::Value::Float(value));
        let full = format!("{section}.{key}");
        derived.push(Derived {
            rule: ratings::rule(&full).unwrap_or(""),
            key: full,
            value,
        });
    };
    let num = |t: &toml::Table, k: &str| number(t, k).unwrap_or(0.0);
    let (torque, speed) = (num(&motor, "rated_torque"), num(&motor, "rated_speed_rpm"));
    for key in DERIVABLE_MOTOR_KEYS {
        if !motor.contains_key(key) {
            let value = match key {
                "inertia" => ratings::inertia(torque, speed),
                _ => ratings::viscous_friction(torque, speed),
            };
            put(&mut motor, "motor", key, value);
        }
    }
    let machine = machine_of(&motor);
    let mut inverter = match user.get("inverter") {
        Some(toml::Value::Table(t)) => t.clone(),
        _ => toml::Table::new(),
    };
    for (key, value) in inverter_values(&machine, &inverter) {
        put(&mut inverter, "inverter", key, value);
    }
    user.insert("motor".into(), toml::Value::Table(motor));
    user.insert("inverter".into(), toml::Value::Table(inverter));
    Ok(derived)
}

/// The user's `[motor]` when it is to be completed: none when there is no motor table (or one
/// holding only `[motor.saturation]`, taken out before: the scenario's motor), nor when a given
/// value is not usable (the validation names it at its own value).
fn completable_motor(user: &toml::Table) -> Option<toml::Table> {
    // No motor table, or one holding only `[motor.saturation]` (taken out before): the
    // scenario's motor.
    let Some(toml::Value::Table(motor)) = user.get("motor").filter(|m| {
        m.as_table()
            .is_some_and(|t| t.keys().any(|k| k != "saturation"))
    }) else {
        return None;
    };
    let motor = motor.clone();
    // A given value that is not usable is named by the validation at its own value.
    let given_ok = |k: &str| {
        let max = fado_core::machine_checks::RANGES
            .iter()
            .find(|(key, ..)| *key == k)
            .map_or(f64::INFINITY, |r| r.1);
        number(&motor, k).is_some_and(|x| x.is_finite() && x > 0.0 && x <= max)
    };
    for key in ratings::REQUIRED_MOTOR_KEYS {
        if motor.contains_key(key) && !given_ok(key) {
            return None;
        }
    }
    let given_bad = |k: &str| {
        motor.contains_key(k) && !number(&motor, k).is_some_and(|x| x.is_finite() && x >= 0.0)
    };
    if DERIVABLE_MOTOR_KEYS.iter().any(|k| given_bad(k)) {
        return None;
    }
    Some(motor)
}

/// Every circuit key and rating is given: else an error naming every missing key, located at
/// the `[motor]` header of `text`.
fn check_required(motor: &toml::Table, text: &str) -> Result<(), SimConfigError> {
    let missing: Vec<&str> = ratings::REQUIRED_MOTOR_KEYS
        .iter()
        .copied()
        .filter(|k| !motor.contains_key(*k))
        .collect();
    if !missing.is_empty() {
        let names = missing
            .iter()
            .map(|k| format!("`{k}`"))
            .collect::<Vec<_>>()
            .join(", ");
        let ratings_missing = missing.iter().any(|k| ratings::RATING_KEYS.contains(k));
        let mut message = format!(
            "the motor lacks {names}. A [motor] table describes the whole motor: rs, ld, lq, \
             flux_linkage, pole_pairs and the ratings are required (inertia and \
             viscous_friction are derived from the ratings when left out); no value is taken \
             from another motor"
        );
        if ratings_missing {
            message.push_str(
                ". The ratings are on the datasheet: rated_current (A peak), rated_speed_rpm \
                 (r/min), rated_torque (N·m); the drive's limits, the scenarios' speeds and \
                 loads and the commissioning's test levels are ratios of them",
            );
        }
        message.push_str(&torque_hint(motor, &missing));
        let mut e = SimConfigError::new(format!("motor.{}", missing[0]), message);
        e.location = section_location(text, "motor");
        return Err(e);
    }
    Ok(())
}

/// For a motor whose datasheet gives no rated torque (a multirotor motor's gives a Kv and a
/// current): the magnet torque 1.5·p·λf·I at its `rated_current`, the value to write when that
/// current is the continuous one; empty when the torque is given or cannot be computed.
fn torque_hint(motor: &toml::Table, missing: &[&str]) -> String {
    let positive = |k: &str| number(motor, k).filter(|x| x.is_finite() && *x > 0.0);
    let (Some(flux), Some(pairs), Some(current)) = (
        positive("flux_linkage"),
        positive("pole_pairs"),
        positive("rated_current"),
    ) else {
        return String::new();
    };
    if !missing.contains(&"rated_torque") {
        return String::new();
    }
    let torque = 1.5 * pairs * flux * current;
    format!(
        ". Without a rated torque on the datasheet: the magnet torque 1.5·p·λf·I at \
         `rated_current` is {torque:.4} N·m (`rated_torque = {torque:.4}` where that current is \
         the continuous one)"
    )
}

/// The machine model of a completed `[motor]` (no DC link).
fn machine_of(motor: &toml::Table) -> MachineModel<f64> {
    let num = |t: &toml::Table, k: &str| number(t, k).unwrap_or(0.0);
    MachineModel::<f64> {
        rs: num(motor, "rs"),
        ld: num(motor, "ld"),
        lq: num(motor, "lq"),
        flux_linkage: num(motor, "flux_linkage"),
        pole_pairs: num(motor, "pole_pairs") as u32,
        inertia: num(motor, "inertia"),
        viscous_friction: num(motor, "viscous_friction"),
        rated_current: num(motor, "rated_current"),
        rated_speed_rpm: num(motor, "rated_speed_rpm"),
        rated_torque: num(motor, "rated_torque"),
        dc_voltage: 0.0,
        magnetics: Default::default(),
    }
}

/// The `[inverter]` keys `given` lacks that `machine`'s ratings give, in dependency order
/// (the DC link, then the switching frequency, the dead time from it, the threshold from the
/// DC link, the current band).
pub fn inverter_values(
    machine: &MachineModel<f64>,
    given: &toml::Table,
) -> Vec<(&'static str, f64)> {
    let mut out = Vec::new();
    let dc = match number(given, "dc_voltage") {
        Some(v) => v,
        None => {
            let v = ratings::dc_voltage(machine);
            out.push(("dc_voltage", v));
            v
        }
    };
    let f_sw = match number(given, "switching_frequency") {
        Some(f) => f,
        None => {
            let f = ratings::switching_frequency_of(&machine.with_dc_voltage(dc));
            out.push(("switching_frequency", f));
            f
        }
    };
    if !given.contains_key("dead_time") {
        out.push(("dead_time", ratings::dead_time(f_sw)));
    }
    if !given.contains_key("threshold_voltage") {
        out.push(("threshold_voltage", ratings::threshold_voltage(dc)));
    }
    if !given.contains_key("current_band") {
        out.push(("current_band", ratings::current_band(machine.rated_current)));
    }
    out
}

/// The `[inverter]` keys of `cfg` still derived (in `cfg.derived`) derived again from its
/// present machine and the inverter keys it gives: a configuration laid over a base that
/// derived them (a `fado.Machine`'s inverter, a scenario's) and that gives the carrier, the
/// DC link or the ratings changes what they follow from: a 5 kHz carrier given over the
/// light servo SPM of `tests/data/spm-dq-sat-saturated.toml` (whose ratings derive 10 kHz)
/// gives it the 2.5 µs dead time of 5 kHz from Python as from its file, not the 1.25 µs of
/// 10 kHz. Unchanged inputs give the same values.
pub fn rederive_inverter(cfg: &mut crate::SimConfig) {
    let machine = cfg.motor.with_dc_voltage(cfg.inverter.dc_voltage);
    let mut given = toml::Table::new();
    for key in INVERTER_DERIVED {
        let full = format!("inverter.{key}");
        if let Some(value) = inverter_slot(&mut cfg.inverter, key)
            && !cfg.derived.iter().any(|d| d.key == full)
        {
            given.insert(key.into(), toml::Value::Float(*value));
        }
    }
    for (key, value) in inverter_values(&machine, &given) {
        let Some(slot) = inverter_slot(&mut cfg.inverter, key) else {
            continue;
        };
        *slot = value;
        let full = format!("inverter.{key}");
        if let Some(d) = cfg.derived.iter_mut().find(|d| d.key == full) {
            d.value = value;
        }
    }
}

/// The `[inverter]` keys that [`inverter_values`] derives when a file leaves them out.
const INVERTER_DERIVED: [&str; 5] = [
    "dc_voltage",
    "switching_frequency",
    "dead_time",
    "threshold_voltage",
    "current_band",
];

/// The field of `inv` that the `[inverter]` key `key` sets, if it is one of
/// [`INVERTER_DERIVED`].
fn inverter_slot<'a>(
    inv: &'a mut crate::inverter::InverterParams,
    key: &str,
) -> Option<&'a mut f64> {
    Some(match key {
        "dc_voltage" => &mut inv.dc_voltage,
        "switching_frequency" => &mut inv.switching_frequency,
        "dead_time" => &mut inv.dead_time,
        "threshold_voltage" => &mut inv.threshold_voltage,
        "current_band" => &mut inv.current_band,
        _ => return None,
    })
}

/// `toml` (a [`crate::SimConfig::to_toml`] document) with each derived key's line followed by
/// its rule as a comment, and a header saying so.
pub fn annotate(toml: &str, derived: &[Derived]) -> String {
    if derived.is_empty() {
        return toml.to_owned();
    }
    let mut out = String::from(
        "# Keys marked `derived` are not in the configuration file: their values follow from\n\
         # the motor's ratings (fado_core::ratings) or the drive's own rules, by the rule given.\n",
    );
    let mut section = String::new();
    for line in toml.lines() {
        out.push_str(line);
        let t = line.trim();
        if t.starts_with('[') {
            section = t.trim_matches(|c| c == '[' || c == ']').to_owned();
        } else if let Some((key, _)) = t.split_once(" = ") {
            let full = format!("{section}.{}", key.trim());
            if let Some(d) = derived.iter().find(|d| d.key == full) {
                out.push_str("  # derived: ");
                out.push_str(d.rule);
            }
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const MINIMAL: &str = "[motor]\nrs = 0.105\nld = 30e-6\nlq = 30e-6\nflux_linkage = 0.0024\n\
                           pole_pairs = 21\nrated_current = 17.5\nrated_speed_rpm = 1800.0\n\
                           rated_torque = 1.32\n";

    #[test]
    fn a_minimal_motor_gets_every_other_value_from_its_ratings() {
        let mut user: toml::Table = MINIMAL.parse().unwrap();
        let d = complete_motor(&mut user, MINIMAL).unwrap();
        let keys: Vec<_> = d.iter().map(|d| d.key.as_str()).collect();
        assert_eq!(
            keys,
            [
                "motor.inertia",
                "motor.viscous_friction",
                "inverter.dc_voltage",
                "inverter.switching_frequency",
                "inverter.dead_time",
                "inverter.threshold_voltage",
                "inverter.current_band"
            ]
        );
        assert!(d.iter().all(|d| !d.rule.is_empty() && d.value > 0.0));
        // 21 pole pairs at 1800 r/min: 3958 rad/s → 10 kHz by ω_rated·Ts; its 30 µH on the
        // derived DC link ask for 14 kHz by the ripple (≤ 0.6 × 17.5 A).
        let value = |key: &str| d.iter().find(|d| d.key.ends_with(key)).unwrap().value;
        let (f, vdc) = (value("switching_frequency"), value("dc_voltage"));
        assert_eq!(ratings::switching_frequency(21, 1800.0, vdc), 10_000.0);
        assert_eq!(f, 14_000.0);
        let bound = ratings::MAX_RIPPLE_CURRENT_RATIO * 17.5;
        assert!(ratings::ripple_current(vdc, 30e-6, f) <= bound);
        assert!(ratings::ripple_current(vdc, 30e-6, f - 1000.0) > bound);
    }

    #[test]
    fn missing_ratings_are_named_at_the_motor_header() {
        let text =
            "# m\n[motor]\nrs = 0.1\nld = 1e-3\nlq = 1e-3\nflux_linkage = 0.01\npole_pairs = 4\n";
        let mut user: toml::Table = text.parse().unwrap();
        let e = complete_motor(&mut user, text).unwrap_err();
        assert_eq!(e.key, "motor.rated_current");
        for k in ratings::RATING_KEYS {
            assert!(e.message.contains(k), "{e}");
        }
        assert_eq!(e.location.map(|l| l.line), Some(2));
    }
}
