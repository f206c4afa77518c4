//! `commission`: identify the motor of a file or a preset on the simulated plant and compare
//! each parameter with the plant's truth.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use fado_sim::SimConfigError;
use fado_sim::commission::{self, CommissionOptions, CommissionOutcome, Comparison};
use fado_sim::identified_map::{IDENTIFIED_MAP_FILE, identified_map_csv};
use fado_sim::output::{self, AtomicFile, DirLock, OutputError};
use indicatif::{ProgressBar, ProgressStyle};

use super::Outcome;
use crate::files::{csv_error, in_file, read_file, warn_at, warn_plausibility};

/// The arguments of `commission`.
#[derive(clap::Args)]
pub struct CommissionArgs {
    /// TOML file: the plant (`[motor]` with its ratings, `[inverter]`, sensors, …).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Or a motor preset (see `motors`).
    #[arg(long)]
    motor: Option<String>,
    /// Output directory. Default `out/commission`.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Current-sensor noise seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Use the averaged inverter model.
    #[arg(long)]
    averaged: bool,
    /// TOML file whose `[motor]` is what the procedure is told (ratings set the test levels,
    /// parameters size the tests): a datasheet's values, against the plant's truth. Default
    /// the plant's own `[motor]`.
    #[arg(long)]
    nameplate: Option<PathBuf>,
}

/// Runs the commissioning of `args`' motor, writes DIR/identified.toml, DIR/metrics.json and
/// DIR/traces.csv and prints each parameter against the truth; exit 1 when nothing was
/// identified.
pub fn commission(args: CommissionArgs) -> Outcome {
    let config = args.config.as_deref();
    let (text, mut cfg) = load(config, args.motor.as_deref())?;
    cfg.current_sensor.seed = args.seed;
    if args.averaged {
        cfg.inverter.model = fado_sim::inverter::InverterModel::Averaged;
    }
    // The directory is held from before the run to the last rename, as `run` holds it.
    let dir = args
        .out
        .unwrap_or_else(|| PathBuf::from("out").join("commission"));
    let lock = DirLock::acquire(&dir)?;
    let told = match &args.nameplate {
        Some(path) => Some((path.clone(), nameplate(path)?)),
        None => None,
    };
    let o = identify(&cfg, told.as_ref().map(|t| &t.1.1), &text, config)?;
    let rows = o
        .identification
        .as_ref()
        .map(|id| commission::compare(id, &o.truth))
        .unwrap_or_default();
    write_outputs(&dir, &text, &o, &rows, args.seed)?;
    drop(lock);
    outln!(
        "commissioning: {:?} after {:.2} s simulated",
        o.status,
        o.simulated_seconds
    );
    if let fado_core::commissioning::Status::Aborted(reason) = o.status {
        outln!("  {reason}");
    }
    if let (None, Some(m)) = (&o.identification, &o.magnetics) {
        print_magnetics(m, o.rotor_motion_magnetics);
    }
    if o.identification.is_none() {
        outln!("wrote {}/metrics.json and traces.csv", dir.display());
        return Ok(ExitCode::from(1));
    }
    print_parameters(&rows);
    if let Some(id) = &o.identification {
        // The nameplate's resistance against the measured one.
        let (file, source, motor) = match &told {
            Some((path, (text, motor))) => (Some(path.as_path()), Some(text.as_str()), motor),
            None => (config, Some(text.as_str()), &cfg.motor),
        };
        if let Some(w) =
            fado_sim::nameplate_agreement::resistance("motor.rs", motor.rs, id.model.rs)
        {
            warn_at(file, source, "motor.rs", &w);
        }
    }
    if let Some(m) = &o.magnetics {
        print_magnetics(m, o.rotor_motion_magnetics);
    }
    outln!(
        "wrote {}/identified.toml, metrics.json and traces.csv",
        dir.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// The text and the configuration of `--config FILE` (which must describe its `[motor]`) or
/// of `--motor PRESET`.
fn load(
    config: Option<&Path>,
    motor: Option<&str>,
) -> Result<(String, fado_sim::SimConfig), Box<dyn std::error::Error>> {
    match (config, motor) {
        (Some(path), None) => {
            let text = read_file(path)?;
            let cfg = fado_sim::SimConfig::from_toml(&text)
                .map_err(|e| in_file(e, &Some(path.to_path_buf())))?;
            commission::refuse_unused(&text, "`fado-sim commission`")
                .map_err(|e| in_file(e, &Some(path.to_path_buf())))?;
            // The procedure identifies the file's motor: it never falls back on another's.
            let has_motor = text
                .parse::<toml::Table>()
                .is_ok_and(|t| t.contains_key("motor"));
            if !has_motor {
                return Err(SimConfigError::new(
                    "motor",
                    format!(
                        "{} has no [motor] table: commissioning identifies the motor the file \
                         describes (rs, ld, lq, flux_linkage, pole_pairs as rough values and \
                         the ratings rated_current, rated_speed_rpm, rated_torque)",
                        path.display()
                    ),
                )
                .into());
            }
            warn_plausibility(&cfg, Some(path), Some(&text));
            Ok((text, cfg))
        }
        (None, Some(name)) => {
            let preset = fado_sim::presets::find(name)
                .ok_or_else(|| format!("no motor preset `{name}` (see `fado-sim motors`)"))?;
            Ok((preset.toml.to_owned(), preset.config()?))
        }
        _ => Err("give exactly one of --config FILE and --motor PRESET".into()),
    }
}

/// The text and the `[motor]` record of `--nameplate FILE`.
fn nameplate(
    path: &Path,
) -> Result<(String, fado_core::MachineModel<f64>), Box<dyn std::error::Error>> {
    let text = read_file(path)?;
    let cfg =
        fado_sim::SimConfig::from_toml(&text).map_err(|e| in_file(e, &Some(path.to_path_buf())))?;
    warn_plausibility(&cfg, Some(path), Some(&text));
    Ok((text, cfg.plant().motor))
}

/// Runs the procedure on the plant of `cfg`, told `nameplate` (default the plant's `[motor]`
/// record; parameters only size the tests) with the inverter's DC link, with a progress bar;
/// an error is located in `text`, the file `config` (if any).
fn identify(
    cfg: &fado_sim::SimConfig,
    nameplate: Option<&fado_core::MachineModel<f64>>,
    text: &str,
    config: Option<&Path>,
) -> Result<CommissionOutcome, Box<dyn std::error::Error>> {
    let plant = cfg.plant();
    let nameplate = nameplate
        .unwrap_or(&plant.motor)
        .with_dc_voltage(plant.inverter.dc_voltage);
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg:<14} [{bar:40}] {percent:>3}%")?
            .progress_chars("=> "),
    );
    let mut cb = |f: f64, phase: fado_core::commissioning::Phase| {
        bar.set_message(phase.name());
        bar.set_position((f * 1000.0) as u64);
    };
    let o = commission::commission(
        &plant,
        nameplate,
        CommissionOptions::default(),
        |_| {},
        Some(&mut cb),
    )
    .map_err(|e| match config {
        Some(p) => e.located_in(text).in_file(p.display().to_string()),
        None => e,
    })?;
    bar.finish_and_clear();
    Ok(o)
}

/// Writes DIR/traces.csv, DIR/identified.toml (the input file with its `[model]` replaced by
/// the identified one) and DIR/metrics.json (the parameters of `rows` against the truth).
fn write_outputs(
    dir: &Path,
    text: &str,
    o: &CommissionOutcome,
    rows: &[Comparison],
    seed: u64,
) -> Result<(), Box<dyn std::error::Error>> {
    let metrics = serde_json::json!({
        "passed": o.identification.is_some(),
        "status": format!("{:?}", o.status),
        "simulated_seconds": o.simulated_seconds,
        "wall_seconds": o.wall_seconds,
        "max_current": o.max_current,
        "max_current_reference": o.max_current_reference,
        "current_limit": o.current_limit,
        "rotor_motion_inductance": o.rotor_motion_inductance,
        "rotor_motion_magnetics": o.rotor_motion_magnetics,
        "max_current_magnetics": o.max_current_magnetics,
        "magnetics": o.magnetics,
        "seed": seed,
        "parameters": rows,
    });
    // Every output is complete and synced under a temporary name before any is renamed into
    // place (`fado_sim::output`): the previous metrics.json and identified.toml go first,
    // traces.csv is renamed, then identified.toml, then metrics.json last, so a metrics.json
    // always sits beside its own traces and identified model; a kill, a full disk or a second
    // writer leave the previous results whole.
    let traces_path = dir.join("traces.csv");
    let mut csv = csv::Writer::from_writer(AtomicFile::create(&traces_path)?);
    for r in &o.trace {
        csv.serialize(r).map_err(|e| csv_error(e, &traces_path))?;
    }
    let traces = csv
        .into_inner()
        .map_err(|e| OutputError::new("write", &traces_path, e.into_error()))?
        .finish()?;
    // The identified saturation as a flux map beside identified.toml, which names it by its
    // relative path: the input file with its [model] replaced by the identified one, runnable
    // as is (`fado-sim run reversal --config DIR/identified.toml`).
    let map_path = dir.join(IDENTIFIED_MAP_FILE);
    let (map, identified) = match &o.identification {
        Some(id) => {
            // A model that does not tabulate as a monotonic map over the drive's range (its
            // extrapolation far beyond the pulses' current) stays the algebraic one.
            let map = match identified_map_csv(id) {
                Some(Ok(csv)) => Some(write_whole(&map_path, &csv)?),
                Some(Err(e)) => {
                    eprintln!(
                        "warning: the identified magnetic model does not tabulate as a flux map \
                         ({e}); identified.toml keeps it as [model.saturation]"
                    );
                    None
                }
                None => None,
            };
            let file = map.as_ref().map(|_| IDENTIFIED_MAP_FILE);
            let doc = commission::identified_toml_with_map(text, id, file)?;
            (map, Some(write_whole(&dir.join("identified.toml"), &doc)?))
        }
        None => (None, None),
    };
    let mut m = AtomicFile::create(&dir.join("metrics.json"))?;
    serde_json::to_writer_pretty(&mut m, &metrics).map_err(|e| m.error(e.into()))?;
    let m = m.finish()?;
    output::remove_if_present(&dir.join("metrics.json"))?;
    output::remove_if_present(&dir.join("identified.toml"))?;
    output::remove_if_present(&map_path)?;
    traces.rename()?;
    if let Some(f) = map {
        f.rename()?;
    }
    if let Some(f) = identified {
        f.rename()?;
    }
    m.rename()?;
    Ok(())
}

/// `text` complete and synced under a temporary name beside `path`, to be renamed.
fn write_whole(path: &Path, text: &str) -> Result<output::Finished, OutputError> {
    let mut f = AtomicFile::create(path)?;
    std::io::Write::write_all(&mut f, text.as_bytes()).map_err(|e| f.error(e))?;
    f.finish()
}

/// The magnetic model: detected or not, and its errors over the rated current range. The
/// rotor's turn printed is the one the verdict compares with `PULSE_MOTION_LIMIT`: the
/// procedure's own estimate over one pair of pulses; `plant_motion`, the plant's largest turn
/// from the pulses' start, follows it labelled as the plant's.
fn print_magnetics(m: &fado_sim::commission::MagneticsReport, plant_motion: f64) {
    let a = &m.accuracy;
    let limit = fado_core::commissioning::PULSE_MOTION_LIMIT;
    let verdict = match m.verdict {
        "rotor_moved" => "saturation not identified: the rotor turned beyond the limit within \
                          which the pulses tell saturation (constant inductances)"
            .to_owned(),
        "inconclusive" => format!(
            "saturation not identified: the best fit does not explain the flux linkage \
             (residual {:.3} of constant inductances'; constant inductances)",
            m.residual_rms / m.linear_residual_rms
        ),
        "detected" => "saturation detected (the fitted algebraic model)".to_owned(),
        _ => "no saturation detected (constant inductances)".to_owned(),
    };
    outln!(
        "magnetics: {verdict} (inductances change {:.1} % up to {:.3} A)",
        100.0 * m.inductance_change,
        m.pulse_current
    );
    outln!(
        "  rotor turn over a pair of pulses (drive's flux estimate): {:.3} rad, limit {limit} rad; \
         plant's turn from the pulses' start: {plant_motion:.3} rad",
        m.pulse_motion
    );
    let pc = |s: &fado_sim::magnetic_accuracy::ErrorStats| {
        format!("max {:.2} %, rms {:.2} %", 100.0 * s.max, 100.0 * s.rms)
    };
    outln!(
        "  over |i| <= {:.3} A: incremental Ld {}, Lq {}; secant Ld {}, Lq {}; flux {}",
        a.rated_current,
        pc(&a.incremental_ld),
        pc(&a.incremental_lq),
        pc(&a.secant_ld),
        pc(&a.secant_lq),
        pc(&a.flux)
    );
}

/// Each identified parameter against the truth: relative errors in %, absolute ones for the
/// parameters that may be zero.
fn print_parameters(rows: &[Comparison]) {
    outln!(
        "{:<18} {:>14} {:>14} {:>10} {:>10}",
        "parameter",
        "identified",
        "truth",
        "error",
        "1-sigma"
    );
    for r in rows {
        let relative = !matches!(
            r.parameter,
            "viscous_friction" | "inverter_voltage" | "threshold_voltage"
        );
        if relative {
            outln!(
                "{:<18} {:>14.6e} {:>14.6e} {:>+9.3}% {:>9.3}%",
                r.parameter,
                r.identified,
                r.truth,
                100.0 * r.error,
                100.0 * r.confidence
            );
        } else {
            outln!(
                "{:<18} {:>14.6e} {:>14.6e} {:>+10.3e} {:>10.3e}",
                r.parameter,
                r.identified,
                r.truth,
                r.error,
                r.confidence
            );
        }
    }
}
