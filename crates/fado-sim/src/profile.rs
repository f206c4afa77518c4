//! Piecewise-linear time profiles: speed references and load torques (constant, steps, ramps).

use serde::{Deserialize, Serialize};

use crate::error::SimConfigError;

/// A piecewise-linear function of time given by `(time_s, value)` breakpoints.
///
/// Before the first point the first value holds, after the last the last value holds; two points
/// at the same time make a step. In TOML: `points = [[0.0, 0.0], [1.0, 90.0], [1.0, 0.0]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Profile {
    /// Breakpoints `[time in s, value]`, times non-decreasing.
    pub points: Vec<[f64; 2]>,
}

/// Most breakpoints a profile may have. The paper's profiles have fewer than ten; 10,000 is
/// room for a recorded drive cycle at 1 s resolution over almost three hours, and keeps a
/// configuration's memory and parse time small (an input-size cap, not a physical limit).
pub const MAX_POINTS: usize = 10_000;

impl Profile {
    /// A constant profile.
    pub fn constant(value: f64) -> Self {
        Self {
            points: vec![[0.0, value]],
        }
    }

    /// A profile from breakpoints.
    pub fn from_points(points: &[(f64, f64)]) -> Self {
        Self {
            points: points.iter().map(|&(t, v)| [t, v]).collect(),
        }
    }

    /// Checks that there is at least one point, all finite, with non-decreasing times.
    pub fn validate(&self) -> Result<(), SimConfigError> {
        if self.points.is_empty() {
            return Err(SimConfigError::new("points", "needs at least one point"));
        }
        if self.points.len() > MAX_POINTS {
            return Err(SimConfigError::new(
                "points",
                format!(
                    "has {} breakpoints, more than the {MAX_POINTS} a piecewise-linear profile may have",
                    self.points.len()
                ),
            ));
        }
        for (k, p) in self.points.iter().enumerate() {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(SimConfigError::new(
                    format!("points[{k}]"),
                    "must be finite",
                ));
            }
            if k > 0 && p[0] < self.points[k - 1][0] {
                return Err(SimConfigError::new(
                    format!("points[{k}]"),
                    "times must be non-decreasing",
                ));
            }
        }
        Ok(())
    }

    /// The largest |value| of the breakpoints (0 for none).
    pub fn largest_magnitude(&self) -> f64 {
        self.points.iter().map(|p| p[1].abs()).fold(0.0, f64::max)
    }

    /// Time of the last breakpoint.
    pub fn end_time(&self) -> f64 {
        self.points.last().map_or(0.0, |p| p[0])
    }

    /// The value at time `t` (after a step, the later value).
    pub fn value(&self, t: f64) -> f64 {
        let pts = &self.points;
        let Some(first) = pts.first() else {
            return 0.0;
        };
        if t < first[0] {
            return first[1];
        }
        // Last index whose time is ≤ t (so a step at t already took effect).
        let k = pts.partition_point(|p| p[0] <= t);
        if k >= pts.len() {
            return pts[pts.len() - 1][1];
        }
        let (a, b) = (pts[k - 1], pts[k]);
        let span = b[0] - a[0];
        if span <= 0.0 {
            b[1]
        } else {
            a[1] + (b[1] - a[1]) * (t - a[0]) / span
        }
    }

    /// [`value`](Self::value) for non-decreasing `t`, starting the search at `cursor` (kept
    /// by the caller): O(1) per call along a run instead of a binary search.
    #[inline]
    pub fn value_from(&self, t: f64, cursor: &mut usize) -> f64 {
        let pts = &self.points;
        if *cursor > pts.len() || (*cursor > 0 && pts[*cursor - 1][0] > t) {
            *cursor = 0; // time went back: restart
        }
        while *cursor < pts.len() && pts[*cursor][0] <= t {
            *cursor += 1;
        }
        let k = *cursor;
        match (k, pts.len()) {
            (_, 0) => 0.0,
            (0, _) => pts[0][1],
            (k, n) if k >= n => pts[n - 1][1],
            (k, _) => {
                let (a, b) = (pts[k - 1], pts[k]);
                let span = b[0] - a[0];
                if span <= 0.0 {
                    b[1]
                } else {
                    a[1] + (b[1] - a[1]) * (t - a[0]) / span
                }
            }
        }
    }

    /// Slope of the profile at `t` (0 on steps and outside the breakpoints).
    pub fn slope(&self, t: f64) -> f64 {
        let pts = &self.points;
        if pts.len() < 2 || t < pts[0][0] {
            return 0.0;
        }
        let k = pts.partition_point(|p| p[0] <= t);
        if k >= pts.len() {
            return 0.0;
        }
        let (a, b) = (pts[k - 1], pts[k]);
        let span = b[0] - a[0];
        if span <= 0.0 {
            0.0
        } else {
            (b[1] - a[1]) / span
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramps_steps_and_holds() {
        let p = Profile::from_points(&[(1.0, 0.0), (2.0, 10.0), (2.0, -5.0), (3.0, -5.0)]);
        p.validate().unwrap();
        assert_eq!(p.value(0.0), 0.0);
        assert!((p.value(1.5) - 5.0).abs() < 1e-12);
        assert!((p.slope(1.5) - 10.0).abs() < 1e-12);
        assert_eq!(p.value(2.0), -5.0);
        assert_eq!(p.value(10.0), -5.0);
        assert_eq!(p.slope(10.0), 0.0);
        let mut cursor = 0;
        for k in 0..400 {
            let t = k as f64 * 0.01;
            assert_eq!(p.value_from(t, &mut cursor), p.value(t), "t = {t}");
        }
        assert_eq!(p.value_from(0.5, &mut cursor), p.value(0.5));
    }

    #[test]
    fn rejects_time_going_backwards() {
        let p = Profile::from_points(&[(1.0, 0.0), (0.5, 1.0)]);
        assert_eq!(p.validate().unwrap_err().key, "points[1]");
        assert_eq!(
            Profile { points: vec![] }.validate().unwrap_err().key,
            "points"
        );
    }
}
