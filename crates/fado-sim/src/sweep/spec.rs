//! A sweep definition ([`SweepSpec`]): base scenario and configuration, parameter names
//! (the axes, checked before anything runs) and the points, from a grid or a random design.

use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};

use super::Value;
use super::point::point_config;
use crate::config::SimConfig;
use crate::error::SimConfigError;
use crate::scenario;

/// The derived parameters and what they mean (see the module documentation).
pub const PARAMETERS: [(&str, &str); 9] = [
    ("rs_error", "R̂s/(Rs + r_on) − 1 (mismatch.rs_ratio − 1)"),
    ("lq_error", "L̂q/Lq − 1 (mismatch.lq_ratio − 1)"),
    ("ld_error", "L̂d/Ld − 1 (mismatch.ld_ratio − 1)"),
    (
        "flux_linkage_error",
        "λ̂f/λf − 1 (mismatch.flux_linkage_ratio − 1)",
    ),
    (
        "dead_time_comp_error",
        "T̂d/Td − 1 of the dead-time compensation (mismatch.dead_time_ratio − 1)",
    ),
    (
        "sensor_offset",
        "current-sensor offset in A: phase a +v, phase b −v/2 (before start-up calibration)",
    ),
    (
        "sensor_gain_error",
        "phase a sensor gain relative to phase b, −1 (gain_error_a = v, gain_error_b = 0)",
    ),
    (
        "load_torque",
        "final load torque in N·m (the load torque profile scaled to end there)",
    ),
    (
        "reversal_ramp",
        "slope of the speed reference's reversal in r/min per s (later points shifted)",
    ),
];

/// A sweep definition: base scenario and configuration, axes and points.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepSpec {
    /// Scenario name (its pass criteria judge every point).
    pub scenario: String,
    /// TOML applied over the scenario before the axes.
    pub config_toml: Option<String>,
    /// Force the averaged inverter model.
    pub averaged: bool,
    /// Parameter names, one per axis.
    pub axes: Vec<String>,
    /// One value per axis for each point.
    pub points: Vec<Vec<Value>>,
    /// How the points were made (`grid 9 × 4`, `random 50 (seed 1)`, `points`).
    pub design: String,
}

impl SweepSpec {
    /// The cartesian product of `axes` (first axis slowest).
    pub fn grid(scenario: &str, axes: Vec<(String, Vec<Value>)>) -> Self {
        let mut points: Vec<Vec<Value>> = vec![Vec::new()];
        for (_, values) in &axes {
            points = points
                .iter()
                .flat_map(|p| {
                    values.iter().map(move |v| {
                        let mut q = p.clone();
                        q.push(v.clone());
                        q
                    })
                })
                .collect();
        }
        let shape: Vec<_> = axes.iter().map(|(_, v)| v.len().to_string()).collect();
        Self {
            scenario: scenario.to_owned(),
            config_toml: None,
            averaged: false,
            design: format!("grid {}", shape.join(" × ")),
            axes: axes.into_iter().map(|(n, _)| n).collect(),
            points,
        }
    }

    /// `samples` points drawn uniformly in the ranges `(name, lo, hi)` from `seed`
    /// (xoshiro256++: the same seed gives the same points on every platform).
    pub fn random(
        scenario: &str,
        ranges: &[(String, f64, f64)],
        samples: usize,
        seed: u64,
    ) -> Self {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let points = (0..samples)
            .map(|_| {
                ranges
                    .iter()
                    .map(|&(_, lo, hi)| {
                        let u = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
                        Value::Float(lo + (hi - lo) * u)
                    })
                    .collect()
            })
            .collect();
        Self {
            scenario: scenario.to_owned(),
            config_toml: None,
            averaged: false,
            axes: ranges.iter().map(|(n, _, _)| n.clone()).collect(),
            points,
            design: format!("random {samples} (seed {seed})"),
        }
    }

    /// Checks the definition (scenario known, axis names valid and distinct, one value per
    /// axis in every point) and returns the base configuration.
    pub fn base_config(&self) -> Result<SimConfig, SimConfigError> {
        let base =
            scenario::scenario_config(&self.scenario, self.config_toml.as_deref(), self.averaged)?;
        let keys = toml::Table::try_from(&base)
            .map_err(|e| SimConfigError::new("<base>", e.to_string()))?;
        let mut seen = Vec::new();
        for name in &self.axes {
            check_parameter_name(name, &keys)?;
            if seen.contains(&name) {
                return Err(SimConfigError::new(name.clone(), "axis given twice"));
            }
            seen.push(name);
        }
        if let Some(k) = self.points.iter().position(|p| p.len() != self.axes.len()) {
            return Err(SimConfigError::new(
                format!("points[{k}]"),
                format!(
                    "has {} values for {} axes",
                    self.points[k].len(),
                    self.axes.len()
                ),
            ));
        }
        Ok(base)
    }

    /// A stable fingerprint of the definition and of the base configuration it resolves to
    /// (FNV-1a 64): `sweep.json` keeps it so that a resumed sweep is known to be the same
    /// sweep, also after a change of the scenario's defaults.
    pub fn fingerprint(&self) -> String {
        let json = serde_json::to_string(self).expect("a sweep definition serialises");
        let base = self.base_config().map(|c| c.to_toml()).unwrap_or_default();
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in json.bytes().chain(base.bytes()) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        format!("{h:016x}")
    }

    /// The configuration of point `k` (`base` from [`SweepSpec::base_config`]).
    pub fn point_config(&self, base: &SimConfig, k: usize) -> Result<SimConfig, SimConfigError> {
        point_config(base, &self.axes, &self.points[k])
    }
}

/// A derived parameter, or a key of the configuration (`keys`: the base configuration as a
/// TOML table, which holds every key): a misspelt axis is an error before anything runs.
fn check_parameter_name(name: &str, keys: &toml::Table) -> Result<(), SimConfigError> {
    if PARAMETERS.iter().any(|(n, _)| *n == name) {
        return Ok(());
    }
    // Walk the tables; the key must end on a value, not on a table or past a value.
    let mut table = Some(keys);
    let mut found = false;
    for part in name.split('.') {
        let Some(value) = table.and_then(|t| t.get(part)) else {
            found = false;
            break;
        };
        (table, found) = match value {
            Value::Table(t) => (Some(t), false),
            _ => (None, true),
        };
    }
    if found && name.contains('.') && !name.ends_with('.') {
        return Ok(());
    }
    let names: Vec<_> = PARAMETERS.iter().map(|(n, _)| *n).collect();
    Err(SimConfigError::new(
        name.to_owned(),
        format!("not a configuration key `section.key` (see --dump-config) nor one of {names:?}"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::point::number;
    use crate::sweep::test_support::floats;

    #[test]
    fn grid_is_the_cartesian_product_first_axis_slowest() {
        let spec = SweepSpec::grid(
            "fig11",
            vec![
                ("rs_error".into(), floats(&[-0.5, 0.0, 0.5])),
                ("load_torque".into(), floats(&[0.0, 7.5])),
            ],
        );
        assert_eq!(spec.design, "grid 3 × 2");
        let got: Vec<(f64, f64)> = spec
            .points
            .iter()
            .map(|p| (number("", &p[0]).unwrap(), number("", &p[1]).unwrap()))
            .collect();
        assert_eq!(
            got,
            [
                (-0.5, 0.0),
                (-0.5, 7.5),
                (0.0, 0.0),
                (0.0, 7.5),
                (0.5, 0.0),
                (0.5, 7.5)
            ]
        );
    }

    #[test]
    fn random_design_is_deterministic_and_inside_the_ranges() {
        let ranges = [
            ("rs_error".to_owned(), -0.5, 0.5),
            ("load_torque".to_owned(), 0.0, 11.5),
        ];
        let a = SweepSpec::random("fig11", &ranges, 200, 7);
        assert_eq!(a, SweepSpec::random("fig11", &ranges, 200, 7));
        assert_ne!(a.points, SweepSpec::random("fig11", &ranges, 200, 8).points);
        let xs: Vec<f64> = a
            .points
            .iter()
            .map(|p| number("", &p[0]).unwrap())
            .collect();
        assert!(xs.iter().all(|x| (-0.5..0.5).contains(x)));
        // uniform: both halves of the range are visited about equally
        let below = xs.iter().filter(|x| **x < 0.0).count();
        assert!(
            (70..130).contains(&below),
            "{below} of 200 below the middle"
        );
    }
}
