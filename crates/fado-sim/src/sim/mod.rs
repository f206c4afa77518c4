//! The closed loop, one sample at a time: sense → control → switch → move.
//!
//! At sample n (time n·Ts, a carrier peak or valley) the sensors read the true currents and the
//! DC link, the controller computes the duty for n+1, and the plant integrates [n, n+1] with
//! the duty the controller computed at n−1 (one sample of computational delay). Each sample is
//! handed to [`Probe`]s: the metrics, the decimated trace and the scenarios' criteria.

mod loss;
mod metrics;
mod plant;
mod sample;
mod simulation;
mod startup_outcome;
#[cfg(test)]
mod tests;
mod trace;
mod trace_row;

pub use metrics::Metrics;
pub use plant::{Plant, PlantParams};
pub use sample::{Probe, Sample};
pub use simulation::{CANCEL_CHECK_SAMPLES, RunStats, Simulation};
pub use startup_outcome::{StartupOutcome, StartupVerdict};
pub use trace::{CsvTraceWriter, Decimated, Trace, TraceColumns, TraceSink};
pub use trace_row::TraceRow;

const RPM_PER_RAD_S: f64 = 60.0 / std::f64::consts::TAU;
