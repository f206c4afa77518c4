//! Operating-envelope sweeps: one scenario run per point of a grid or of a random design over
//! model errors, sensor errors, load and profile, in parallel, with every point's outcome
//! recorded (CLI `fado-sim sweep`, Python `fado.sweep`).
//!
//! A sweep ([`SweepSpec`]) is a base scenario (with an optional TOML override and the inverter
//! model), a list of parameter names (the axes) and a list of points, one value per axis.
//! [`SweepSpec::grid`] builds the cartesian product of value lists, [`SweepSpec::random`]
//! draws uniform samples in ranges from a seed. A parameter is either any TOML key of the
//! configuration (`section.key`, e.g. `estimator.disturbance_feedback.k_df`, `load.torque.points`) or one of the
//! derived [`PARAMETERS`], whose direction is fixed by their names:
//!
//! | parameter | meaning | sets |
//! |---|---|---|
//! | `rs_error` | R̂s/(Rs + r_on) − 1 | `mismatch.rs_ratio` |
//! | `lq_error` | L̂q/Lq − 1 | `mismatch.lq_ratio` |
//! | `ld_error` | L̂d/Ld − 1 | `mismatch.ld_ratio` |
//! | `flux_linkage_error` | λ̂f/λf − 1 | `mismatch.flux_linkage_ratio` |
//! | `dead_time_comp_error` | T̂d/Td − 1 of the dead-time compensation | `mismatch.dead_time_ratio` |
//! | `sensor_offset` | current-sensor offset, A: phase a +v, phase b −v/2 | `current_sensor.offset_a_ratio/_b_ratio` (÷ rated current) |
//! | `sensor_gain_error` | gain of phase a's sensor relative to phase b's, −1 | `current_sensor.gain_error_a/_b` |
//! | `load_torque` | final load torque, N·m (the load profile scaled to end there) | `load.torque` |
//! | `reversal_ramp` | slope of the speed reference's reversal, r/min per s | `speed_reference`, `simulation.duration` |
//!
//! Every point runs guarded ([`run_point`]): an invalid configuration, a run error or a panic
//! gives status `failed: <message>`, a trip or a non-finite metric gives `diverged`; the sweep
//! goes on. With an output directory ([`SweepOptions::out`]) each finished point is appended
//! and flushed to `sweep.csv` at once, the definition is kept in `sweep.json`, and a sweep
//! started again on the same directory with the same definition skips the points already in
//! the CSV (an interrupted sweep resumes). `summary.json` and `summary.md` hold the
//! [`Summary`].

//!
//! Modules, one concept each: [`spec`] (the definition and its designs), [`point`] (applying a
//! point to a configuration and running it guarded), [`runner`] (the parallel, resumable run
//! over an output directory), [`store`] (`sweep.csv`), [`summary`] (`summary.json`/`.md`).
//! Parsing the CLI's `--axis` values is the binary's business (`src/bin/fado-sim/axes.rs`).

pub mod point;
pub mod runner;
pub mod spec;
pub mod store;
pub mod summary;

pub use point::{METRICS, PointResult, Status, point_config, run_point, run_point_until};
pub use runner::{SweepError, SweepOptions, SweepOutcome, run};
pub use spec::{PARAMETERS, SweepSpec};
pub use store::{csv_header, read_csv};
pub use summary::{AxisPass, AxisSummary, Summary};
pub use toml::Value;

#[cfg(test)]
pub(crate) mod test_support {
    use std::path::PathBuf;

    use super::{SweepSpec, Value};

    /// fig11 cut to its start-up (0.3 s) on the averaged plant: a point runs in milliseconds.
    pub(crate) fn short(spec: SweepSpec) -> SweepSpec {
        SweepSpec {
            config_toml: Some("[simulation]\nduration = 0.3\neval_start = 0.0\n".to_owned()),
            averaged: true,
            ..spec
        }
    }

    pub(crate) fn floats(v: &[f64]) -> Vec<Value> {
        v.iter().map(|&x| Value::Float(x)).collect()
    }

    pub(crate) fn tmp_dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("fado-sweep-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }
}
