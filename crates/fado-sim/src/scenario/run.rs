//! Running a scenario: its configuration, the simulation with the sensorless drive, where the
//! trace goes.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use crate::config::SimConfig;
use crate::controller::{ControlEvent, Controller};
use crate::error::SimConfigError;
use crate::inverter::InverterModel;
use crate::sim::{Decimated, Metrics, Plant, Simulation, StartupOutcome, Trace, TraceSink};

use super::{Outcome, SCENARIOS, Scenario, find};

/// The configuration a scenario runs with: its defaults, overridden by `config_toml` (if
/// any), then by `averaged` (forces the averaged inverter model).
pub fn scenario_config(
    scenario: &str,
    config_toml: Option<&str>,
    averaged: bool,
) -> Result<SimConfig, SimConfigError> {
    let sc = find(scenario).ok_or_else(|| {
        let names: Vec<_> = SCENARIOS.iter().map(|s| s.name).collect();
        SimConfigError::new(
            "scenario",
            format!("unknown `{scenario}`; one of {names:?}"),
        )
    })?;
    if let Some(text) = config_toml
        && text.len() > MAX_CONFIG_BYTES
    {
        let mut e = SimConfigError::new(
            "<config>",
            format!(
                "is {} bytes long, more than the {MAX_CONFIG_BYTES} accepted",
                text.len()
            ),
        );
        e.location = Some(crate::source::SourceLocation::at(text, 0));
        return Err(e);
    }
    let mut cfg = match config_toml {
        // The user's motor first (a scaled scenario needs its ratings), then the scenario,
        // then the user's keys again, so that any of them wins over the scenario's.
        Some(text) => {
            let user = SimConfig::from_user_toml(&SimConfig::default(), text)?;
            SimConfig::from_toml_over(&sc.apply(user), text)?
        }
        None => sc.config(),
    };
    if averaged {
        cfg.inverter.model = InverterModel::Averaged;
    }
    cfg.validate().map_err(|e| match config_toml {
        Some(text) => e.located_in(text),
        None => e,
    })?;
    Ok(cfg)
}

/// Runs a scenario with the sensorless drive: the entry point for the CLI and the Python
/// bindings. `progress` receives the completed fraction.
pub fn simulate(
    scenario: &str,
    config_toml: Option<&str>,
    averaged: bool,
    progress: Option<&mut dyn FnMut(f64)>,
) -> Result<Outcome, SimConfigError> {
    let cfg = scenario_config(scenario, config_toml, averaged)?;
    run_config(scenario, cfg, progress)
}

impl SimConfig {
    /// The closed loop of this configuration around `controller`: the plant at rest at
    /// `simulation.initial_angle`, the speed reference, the k_df-off events; the controller
    /// aligned (with `simulation.align_error`). Step it or [`Simulation::run`] it.
    pub fn simulation<C: Controller>(
        &self,
        controller: C,
    ) -> Result<Simulation<C>, SimConfigError> {
        let mut plant = Plant::new(&self.plant(), self.simulation.initial_angle)?;
        if self.simulation.brake {
            plant.engage_brake();
        }
        let mut events = Vec::new();
        for w in &self.simulation.disturbance_feedback_off {
            events.push((w[0], ControlEvent::DisturbanceFeedback(false)));
            events.push((w[1], ControlEvent::DisturbanceFeedback(true)));
        }
        Ok(Simulation::new(
            plant,
            controller,
            self.speed_reference.clone(),
            self.simulation.align_error,
        )?
        .with_events(events)
        .with_brake_release_at(self.simulation.brake_release_at))
    }
}

/// Where a run's decimated trace goes.
pub enum TraceOutput<'a> {
    /// Kept in memory in [`Outcome::trace`].
    Keep,
    /// Not kept at all (sweeps: only the metrics matter).
    Discard,
    /// Handed row by row to a sink as it is produced (a file for the CLI, columns for
    /// Python); [`Outcome::trace`] stays empty and memory does not grow with the duration.
    Sink(&'a mut dyn TraceSink),
}

/// How [`run_config_with`] runs.
pub struct RunOptions<'a> {
    /// Called with the completed fraction about a hundred times.
    pub progress: Option<&'a mut dyn FnMut(f64)>,
    /// Where the trace goes.
    pub trace: TraceOutput<'a>,
    /// Stops the run early once set ([`Simulation::run_until`]): the outcome then has
    /// `stats.cancelled` and its checks are not evaluated.
    pub cancel: Option<&'a AtomicBool>,
}

impl Default for RunOptions<'_> {
    fn default() -> Self {
        Self {
            progress: None,
            trace: TraceOutput::Keep,
            cancel: None,
        }
    }
}

/// Number of rows the trace of `cfg` will have (one sample in `simulation.decimation`).
pub fn trace_rows(cfg: &SimConfig) -> u64 {
    let samples = (cfg.simulation.duration / cfg.inverter.sample_period())
        .round()
        .max(0.0) as u64;
    samples.div_ceil(cfg.simulation.decimation.max(1) as u64)
}

/// Largest configuration text accepted (bytes): 1 MiB is 350 times the largest scenario's
/// `--dump-config` and three times a profile of [`crate::profile::MAX_POINTS`] breakpoints,
/// and parses in about 0.3 s and 60 MB (measured: 4 MiB took 2 s and 240 MB; an input-size
/// cap, not a limit of the model).
pub const MAX_CONFIG_BYTES: usize = 1 << 20;

/// Runs a scenario's criteria on an explicit configuration, keeping the trace in memory.
pub fn run_config(
    scenario: &str,
    cfg: SimConfig,
    progress: Option<&mut dyn FnMut(f64)>,
) -> Result<Outcome, SimConfigError> {
    run_config_with(
        scenario,
        cfg,
        RunOptions {
            progress,
            ..Default::default()
        },
    )
}

/// Runs a scenario's criteria on an explicit configuration, with the trace going where
/// `opts` says and an optional cancel flag.
pub fn run_config_with(
    scenario: &str,
    cfg: SimConfig,
    opts: RunOptions<'_>,
) -> Result<Outcome, SimConfigError> {
    let sc = find(scenario)
        .ok_or_else(|| SimConfigError::new("scenario", format!("unknown `{scenario}`")))?;
    let estimator = cfg.simulation.estimator.estimator();
    let mut cfg = cfg;
    (estimator.prepare)(&mut cfg);
    cfg.validate()?;
    let started = Instant::now();
    let drive = (estimator.build)(&cfg)?;
    run_with(sc, cfg, drive, started, opts)
}

fn run_with<C: Controller>(
    sc: &Scenario,
    cfg: SimConfig,
    drive: C,
    started: Instant,
    opts: RunOptions<'_>,
) -> Result<Outcome, SimConfigError> {
    let mut sim = cfg.simulation(drive)?;
    let mut metrics = Metrics::new(cfg.simulation.eval_start, cfg.zero_speed_band_rpm());
    let mut trace = Trace::new(cfg.simulation.decimation);
    let mut probe = sc.probe(&cfg);
    let mut startup = StartupOutcome::default();
    let duration = cfg.simulation.duration;
    let mut stats = match opts.trace {
        TraceOutput::Keep => sim.run_until(
            duration,
            &mut [&mut metrics, &mut trace, &mut probe, &mut startup],
            opts.progress,
            opts.cancel,
        ),
        TraceOutput::Discard => sim.run_until(
            duration,
            &mut [&mut metrics, &mut probe, &mut startup],
            opts.progress,
            opts.cancel,
        ),
        TraceOutput::Sink(sink) => {
            let mut rows = Decimated::new(cfg.simulation.decimation, sink);
            sim.run_until(
                duration,
                &mut [&mut metrics, &mut rows, &mut probe, &mut startup],
                opts.progress,
                opts.cancel,
            )
        }
    };
    stats.wall_seconds = started.elapsed().as_secs_f64();
    let checks = if stats.cancelled {
        Vec::new()
    } else {
        sc.evaluate(&cfg, &metrics, &probe)
    };
    Ok(Outcome {
        probe,
        scenario: sc.name.to_owned(),
        passed: !stats.cancelled && checks.iter().all(|c| c.passed),
        checks,
        metrics,
        startup,
        stats,
        trace,
        config: cfg,
    })
}
