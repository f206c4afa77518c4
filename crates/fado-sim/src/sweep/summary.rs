//! What `summary.json` and `summary.md` hold: counts, the worst point, pass fractions along
//! each axis.

use serde::Serialize;

use super::Value;
use super::point::{PointResult, Status, number};
use super::spec::SweepSpec;
use super::store::cell;

/// Pass fraction of the points sharing one value (or value bin) of one axis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AxisPass {
    /// The value (or `lo..hi` bin of a random design).
    pub value: String,
    /// Points with it.
    pub points: usize,
    /// Of which passed.
    pub passed: usize,
}

/// Pass fractions along one axis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AxisSummary {
    /// The axis (parameter name).
    pub axis: String,
    /// One entry per value (or bin), ascending for numbers.
    pub values: Vec<AxisPass>,
}

/// What `summary.json` holds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// Scenario.
    pub scenario: String,
    /// Design (`grid 9 × 4`).
    pub design: String,
    /// Axes.
    pub axes: Vec<String>,
    /// Points in the sweep.
    pub points: usize,
    /// Points with a result.
    pub finished: usize,
    /// Passed every criterion.
    pub passed: usize,
    /// Ran, but failed a criterion (status ok).
    pub failed_criteria: usize,
    /// Tripped or non-finite.
    pub diverged: usize,
    /// Could not run (configuration, error, panic).
    pub failed: usize,
    /// Index of the point with the largest max |θ − θ̂| among those that ran (diverged
    /// points first).
    pub worst_index: Option<usize>,
    /// Its values, `name=value`.
    pub worst_point: String,
    /// Its max |θ − θ̂|, rad.
    pub worst_max_angle_error: Option<f64>,
    /// Pass fraction per value of each axis, in axis order.
    pub per_axis: Vec<AxisSummary>,
    /// Sum of the points' wall times, s.
    pub point_seconds: f64,
}

impl Summary {
    /// Summarises `rows` (the finished points of `spec`).
    pub fn of(spec: &SweepSpec, rows: &[PointResult]) -> Self {
        let count = |f: &dyn Fn(&PointResult) -> bool| rows.iter().filter(|r| f(r)).count();
        let worst = rows
            .iter()
            .filter(|r| !matches!(r.status, Status::Failed(_)))
            .max_by(|a, b| {
                let key = |r: &PointResult| {
                    let e = if r.max_angle_error.is_nan() {
                        f64::INFINITY
                    } else {
                        r.max_angle_error
                    };
                    (r.status == Status::Diverged, e)
                };
                let (ka, kb) = (key(a), key(b));
                ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
            });
        let per_axis = (spec.axes.iter().enumerate())
            .map(|(k, name)| AxisSummary {
                axis: name.clone(),
                values: axis_pass(rows, k, spec.design.starts_with("random")),
            })
            .collect();
        Summary {
            scenario: spec.scenario.clone(),
            design: spec.design.clone(),
            axes: spec.axes.clone(),
            points: spec.points.len(),
            finished: rows.len(),
            passed: count(&|r| r.passed),
            failed_criteria: count(&|r| r.status == Status::Ok && !r.passed),
            diverged: count(&|r| r.status == Status::Diverged),
            failed: count(&|r| matches!(r.status, Status::Failed(_))),
            worst_index: worst.map(|r| r.index),
            worst_point: worst.map_or(String::new(), |r| {
                spec.axes
                    .iter()
                    .zip(&r.values)
                    .map(|(n, v)| format!("{n}={}", cell(v)))
                    .collect::<Vec<_>>()
                    .join(", ")
            }),
            worst_max_angle_error: worst.map(|r| r.max_angle_error),
            per_axis,
            point_seconds: rows.iter().map(|r| r.wall_seconds).sum(),
        }
    }

    /// The summary as Markdown (`summary.md`).
    pub fn to_markdown(&self) -> String {
        let mut s = format!(
            "# Sweep of {} ({}, axes {})\n\n\
             | points | finished | passed | failed criteria | diverged | failed to run |\n\
             |---:|---:|---:|---:|---:|---:|\n| {} | {} | {} | {} | {} | {} |\n\n",
            self.scenario,
            self.design,
            self.axes.join(", "),
            self.points,
            self.finished,
            self.passed,
            self.failed_criteria,
            self.diverged,
            self.failed
        );
        if let (Some(k), Some(e)) = (self.worst_index, self.worst_max_angle_error) {
            s += &format!(
                "Worst point: #{k} ({}), max |θ−θ̂| = {e:.4} rad.\n\n",
                self.worst_point
            );
        }
        for AxisSummary {
            axis: name,
            values: rows,
        } in &self.per_axis
        {
            s += &format!("| {name} | points | passed | pass fraction |\n|---|---:|---:|---:|\n");
            for r in rows {
                s += &format!(
                    "| {} | {} | {} | {:.2} |\n",
                    r.value,
                    r.points,
                    r.passed,
                    r.passed as f64 / r.points.max(1) as f64
                );
            }
            s += "\n";
        }
        s
    }
}

/// Pass counts per distinct value of axis `k`, or per fifth of its range for a random design
/// (`binned`) or more than 64 distinct values.
fn axis_pass(rows: &[PointResult], k: usize, binned: bool) -> Vec<AxisPass> {
    let mut distinct: Vec<&Value> = Vec::new();
    for r in rows {
        if !distinct.contains(&&r.values[k]) {
            distinct.push(&r.values[k]);
        }
    }
    let nums: Option<Vec<f64>> = rows.iter().map(|r| number("", &r.values[k]).ok()).collect();
    if (binned || distinct.len() > 64)
        && let Some(nums) = nums
    {
        let lo = nums.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = nums.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let bins = 5;
        let width = (hi - lo) / bins as f64;
        return (0..bins)
            .map(|b| {
                let (a, z) = (lo + width * b as f64, lo + width * (b + 1) as f64);
                let inside: Vec<_> = rows
                    .iter()
                    .zip(&nums)
                    .filter(|(_, x)| **x >= a && (**x < z || b == bins - 1))
                    .collect();
                AxisPass {
                    value: format!("{a:.4}..{z:.4}"),
                    points: inside.len(),
                    passed: inside.iter().filter(|(r, _)| r.passed).count(),
                }
            })
            .collect();
    }
    if nums.is_some() {
        distinct.sort_by(|a, b| {
            number("", a)
                .unwrap_or(0.0)
                .total_cmp(&number("", b).unwrap_or(0.0))
        });
    }
    distinct
        .into_iter()
        .map(|v| {
            let with: Vec<_> = rows.iter().filter(|r| &r.values[k] == v).collect();
            AxisPass {
                value: cell(v),
                points: with.len(),
                passed: with.iter().filter(|r| r.passed).count(),
            }
        })
        .collect()
}
