//! Commissioning on the simulated plant: runs [`fado_core::commissioning::Commissioning`]
//! against the switching-resolved (or averaged) inverter, the sensors and the machine of a
//! [`PlantParams`], and compares what it identifies with the plant's truth.
//!
//! The procedure sees only what a drive sees: the measured (offset, gain error, noise, ADC)
//! phase currents and the measured DC-link voltage; it commands duties with the usual one
//! sample of computational delay (see [`crate::sim`]).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use fado_core::commissioning::{
    Commissioning, CommissioningConfig, CommissioningOutput, Identification, Phase, Status,
};
use fado_core::magnetics::{ConstantInductance, Magnetics, Saturation};
use fado_core::{Ab, MachineModel};
use serde::Serialize;

use crate::error::SimConfigError;
use crate::magnetic_accuracy::{self, MagneticAccuracy};
use crate::motor::MotorState;
use crate::saturation_verdict::{freeze_resistance_law, saturation_comment, verdict_name};
use crate::sim::{Plant, PlantParams};

/// The plant's true values of what commissioning identifies.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Truth {
    /// Rs + r_on (what the drive's model should hold), Ω.
    pub rs: f64,
    /// Ld, H.
    pub ld: f64,
    /// Lq, H.
    pub lq: f64,
    /// λf, Wb.
    pub flux_linkage: f64,
    /// J, kg·m².
    pub inertia: f64,
    /// B, N·m·s/rad.
    pub viscous_friction: f64,
    /// Per-phase inverter voltage error Td·f_sw·Vdc + V_th, V (docs/method/estimator.md §7).
    pub inverter_voltage: f64,
    /// Device threshold V_th, V.
    pub threshold_voltage: f64,
    /// The current sensors' gain ratio (1 + g_a)/(1 + g_b) (1 with the gain errors off).
    pub current_gain_ratio: f64,
}

impl Truth {
    /// The truth of a plant.
    pub fn of(p: &PlantParams) -> Self {
        let inv = &p.inverter;
        Self {
            rs: p.motor.rs + inv.on_resistance,
            ld: p.motor.ld,
            lq: p.motor.lq,
            flux_linkage: p.motor.flux_linkage,
            inertia: p.motor.inertia,
            viscous_friction: p.motor.viscous_friction,
            inverter_voltage: inv.dead_time * inv.switching_frequency * inv.dc_voltage
                + inv.threshold_voltage,
            threshold_voltage: inv.threshold_voltage,
            current_gain_ratio: {
                let s = &p.current_sensor;
                if s.enable_gain_error {
                    (1.0 + s.gain_error_a) / (1.0 + s.gain_error_b)
                } else {
                    1.0
                }
            },
        }
    }
}

/// One decimated row of the commissioning trace.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct TraceRow {
    /// Time, s.
    pub time: f64,
    /// Phase index ([`Phase::index`]).
    pub phase: u8,
    /// Measured current α, β, A.
    pub i_alpha: f64,
    /// See `i_alpha`.
    pub i_beta: f64,
    /// Commanded voltage α, β, V.
    pub v_alpha: f64,
    /// See `v_alpha`.
    pub v_beta: f64,
    /// Voltage the inverter actually applied over the previous sample (α, β), V.
    pub v_applied_alpha: f64,
    /// See `v_applied_alpha`.
    pub v_applied_beta: f64,
    /// True rotor speed, r/min.
    pub speed_rpm: f64,
    /// The procedure's back-EMF speed estimate, r/min.
    pub speed_hat_rpm: f64,
    /// True electrical angle, rad.
    pub theta: f64,
    /// The procedure's back-EMF angle estimate, rad.
    pub theta_hat: f64,
}

impl TraceRow {
    /// The column names, in field order (the `traces.csv` header, from the serde derive).
    pub const COLUMNS: [&'static str; 12] = [
        "time",
        "phase",
        "i_alpha",
        "i_beta",
        "v_alpha",
        "v_beta",
        "v_applied_alpha",
        "v_applied_beta",
        "speed_rpm",
        "speed_hat_rpm",
        "theta",
        "theta_hat",
    ];

    /// The row's values in [`Self::COLUMNS`] order (the phase index as a number).
    pub fn values(&self) -> [f64; 12] {
        [
            self.time,
            f64::from(self.phase),
            self.i_alpha,
            self.i_beta,
            self.v_alpha,
            self.v_beta,
            self.v_applied_alpha,
            self.v_applied_beta,
            self.speed_rpm,
            self.speed_hat_rpm,
            self.theta,
            self.theta_hat,
        ]
    }
}

/// What a simulated commissioning run gives.
#[derive(Clone, Debug)]
pub struct CommissionOutcome {
    /// How it ended.
    pub status: Status,
    /// The identification (when done).
    pub identification: Option<Identification<f64>>,
    /// The plant's truth.
    pub truth: Truth,
    /// Decimated trace (every `decimation`-th sample).
    pub trace: Vec<TraceRow>,
    /// Simulated time, s.
    pub simulated_seconds: f64,
    /// Wall-clock time, s.
    pub wall_seconds: f64,
    /// Largest |i| measured (true current), A.
    pub max_current: f64,
    /// Largest |i*| commanded, A.
    pub max_current_reference: f64,
    /// The procedure's current limit, A.
    pub current_limit: f64,
    /// Largest |Δθ| of the rotor during the inductance tests, rad (electrical).
    pub rotor_motion_inductance: f64,
    /// Largest |Δθ| of the rotor during the flux-linkage pulses from its angle at their
    /// start, rad (electrical): the plant's truth, which the procedure does not see. The
    /// verdict compares its own estimate of the turn over one pair with
    /// [`fado_core::commissioning::PULSE_MOTION_LIMIT`] ([`MagneticsReport::pulse_motion`]).
    pub rotor_motion_magnetics: f64,
    /// Largest |i| (true current) during the flux-linkage pulses, A.
    pub max_current_magnetics: f64,
    /// The magnetic identification against the plant (when the pulses ran to their end).
    pub magnetics: Option<MagneticsReport>,
    /// Stopped early by [`CommissionOptions::cancel`] (`status` is then `Running`).
    pub cancelled: bool,
}

/// Options of a run.
#[derive(Clone, Debug)]
pub struct CommissionOptions {
    /// Initial rotor angle (electrical), rad. Default 1.0.
    pub theta0: f64,
    /// Trace decimation. Default 10.
    pub decimation: usize,
    /// Hard stop in simulated seconds (beyond the procedure's own time-outs). Default 60 s.
    pub max_seconds: f64,
    /// Set from another thread to stop the run within [`crate::sim::CANCEL_CHECK_SAMPLES`]
    /// samples (Ctrl-C in Python). Default none.
    pub cancel: Option<Arc<AtomicBool>>,
}

impl Default for CommissionOptions {
    fn default() -> Self {
        Self {
            theta0: 1.0,
            decimation: 10,
            max_seconds: 60.0,
            cancel: None,
        }
    }
}

/// The tables of a configuration the commissioning reads: the plant's. Every other table is
/// another command's and is refused by [`refuse_unused`].
pub const PLANT_TABLES: [&str; 7] = [
    "motor",
    "inverter",
    "current_sensor",
    "dc_link_sensor",
    "load",
    "faults",
    "dc_link",
];

/// Refuses a table of the user's configuration `text` that commissioning does not use (a
/// scenario's `[speed_reference]`, a `[model]` commissioning is to identify, the drive's
/// `[controller]`), naming what takes it, so that no key is silently ignored; `function` is
/// the command or function the user called.
pub fn refuse_unused(text: &str, function: &str) -> Result<(), SimConfigError> {
    let Ok(table) = text.parse::<toml::Table>() else {
        return Ok(()); // a syntax error is the parser's to name
    };
    let Some(key) = table.keys().find(|k| !PLANT_TABLES.contains(&k.as_str())) else {
        return Ok(());
    };
    let outside = (!table[key].is_table()).then(|| crate::suggest::top_level_hint(key));
    if let Some(hint) = outside.flatten() {
        let message = format!("`{key}` is outside its table{hint}");
        return Err(SimConfigError::new(key.clone(), message).located_in(text));
    }
    let takes = match key.as_str() {
        "model" => "commissioning identifies the drive's model: it writes the [model] table \
                    (identified.toml) that `run` and `simulate` then take"
            .to_owned(),
        _ => format!(
            "it is a setting of the simulated drive and its scenarios, which `fado-sim run`, \
             `sweep` and `compare` (fado.simulate, fado.sweep, fado.compare) take; \
             commissioning reads only the plant ([{}])",
            PLANT_TABLES.join("], [")
        ),
    };
    Err(SimConfigError::new(
        key.clone(),
        format!("`{key}` is not used by {function}: {takes}"),
    )
    .located_in(text))
}

/// [`commission`] on `plant_params` told its own motor record on its DC link (what a user of
/// the simulated motor reads off its nameplate), with the default options, the procedure's
/// configuration as derived and no progress report.
pub fn commission_on_own_nameplate(
    plant_params: &PlantParams,
) -> Result<CommissionOutcome, SimConfigError> {
    let nameplate = plant_params
        .motor
        .with_dc_voltage(plant_params.inverter.dc_voltage);
    commission(
        plant_params,
        nameplate,
        CommissionOptions::default(),
        |_| {},
        None,
    )
}

/// Runs the procedure on a plant. `nameplate` is what the user tells the procedure (ratings
/// and rough parameters); `config` adjusts the procedure's defaults (its `nameplate`,
/// `sample_period` and `dead_time` are set from the arguments and the plant's inverter).
pub fn commission(
    plant_params: &PlantParams,
    nameplate: MachineModel<f64>,
    options: CommissionOptions,
    adjust: impl FnOnce(&mut CommissioningConfig<f64>),
    mut progress: Option<&mut dyn FnMut(f64, Phase)>,
) -> Result<CommissionOutcome, SimConfigError> {
    let mut plant = Plant::new(plant_params, options.theta0)?;
    let ts = plant.sample_period();
    let mut cfg = CommissioningConfig::for_machine(nameplate, ts, plant_params.inverter.dead_time);
    cfg.switching_frequency = plant_params.inverter.switching_frequency;
    adjust(&mut cfg);
    let mut proc = Commissioning::new(cfg).map_err(|e| procedure_error(&e))?;
    preconditions(plant_params, &cfg)?;
    let pp = plant_params.motor.pole_pairs as f64;
    let start = Instant::now();
    let n_max = (options.max_seconds / ts) as u64;
    let mut trace = Vec::new();
    let mut watch = Watch::default();
    let mut last_progress = -1.0;
    let mut k = 0u64;
    let mut cancelled = false;
    let status = loop {
        let (i_abc, vdc, _) = plant.measure();
        let out = proc.step(i_abc, vdc);
        let st = *plant.motor().state();
        watch.observe(&st, &out);
        if k.is_multiple_of(options.decimation.max(1) as u64) {
            trace.push(TraceRow::of(&plant, &out, i_abc.to_ab(), &st, pp));
        }
        if let Some(cb) = progress.as_mut()
            && out.progress - last_progress >= 0.005
        {
            last_progress = out.progress;
            cb(out.progress, out.phase);
        }
        if out.status != Status::Running {
            break out.status;
        }
        plant.step(out.duty, out.gates_enabled);
        k += 1;
        if k >= n_max {
            break Status::Running;
        }
        if let Some(flag) = &options.cancel
            && k.is_multiple_of(crate::sim::CANCEL_CHECK_SAMPLES)
            && flag.load(Ordering::Relaxed)
        {
            cancelled = true;
            break Status::Running;
        }
    };
    let identification = proc.result().copied();
    Ok(CommissionOutcome {
        status,
        identification,
        magnetics: MagneticsReport::of(&proc, plant_params, &nameplate),
        truth: Truth::of(plant_params),
        trace,
        simulated_seconds: k as f64 * ts,
        wall_seconds: start.elapsed().as_secs_f64(),
        max_current: watch.max_i,
        max_current_reference: watch.max_ref,
        current_limit: proc.current_limit(),
        rotor_motion_inductance: watch.motion,
        rotor_motion_magnetics: watch.motion_pulses,
        max_current_magnetics: watch.max_i_pulses,
        cancelled,
    })
}

/// The magnetic identification on the simulated plant: what the pulses gave and its errors
/// against the plant's model ([`magnetic_accuracy`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MagneticsReport {
    /// Saturation detected: `[model.saturation]` written.
    pub saturation_detected: bool,
    /// The best-fitting algebraic model (written only when saturation is detected).
    pub fitted: Saturation<f64>,
    /// The fitted model's largest relative incremental-inductance change over the pulses'
    /// range.
    pub inductance_change: f64,
    /// The fit's RMS current residual, A.
    pub residual_rms: f64,
    /// The constant-inductance model's RMS current residual, A.
    pub linear_residual_rms: f64,
    /// The pulses' peak current, A.
    pub pulse_current: f64,
    /// The magnet's flux the fit used: the identified λ̂f, or the nameplate's when the
    /// procedure aborted after the pulses (`flux_from_nameplate`), Wb.
    pub flux_linkage: f64,
    /// See `flux_linkage`.
    pub flux_from_nameplate: bool,
    /// The rotor's largest turn over one pair of pulses as the procedure estimated it from
    /// the flux, rad (electrical): the figure the verdict compares with
    /// [`fado_core::commissioning::PULSE_MOTION_LIMIT`].
    pub pulse_motion: f64,
    /// What the pulses say ([`fado_core::commissioning::SaturationVerdict`]): `detected`,
    /// `not_detected`, `inconclusive` (a fit of large change that does not explain the data)
    /// or `rotor_moved` (the rotor turned beyond
    /// [`fado_core::commissioning::PULSE_MOTION_LIMIT`]).
    pub verdict: &'static str,
    /// The model the drive gets (the fitted one when saturation is detected, else constant
    /// inductances: the identified ones, or the nameplate's after an abort) against the
    /// plant's over the rated current range.
    pub accuracy: MagneticAccuracy,
}

impl MagneticsReport {
    /// The report of a finished (or aborted) procedure; None when the pulses did not end.
    fn of(
        proc: &Commissioning<f64>,
        p: &PlantParams,
        nameplate: &MachineModel<f64>,
    ) -> Option<Self> {
        let id = proc.result();
        let model = id.map_or(nameplate, |id| &id.model);
        let fit = proc.magnetic_model(model.flux_linkage)?;
        let constants = ConstantInductance {
            ld: model.ld,
            lq: model.lq,
            flux_linkage: model.flux_linkage,
        };
        let drive = if fit.detected {
            Magnetics::Saturation(fit.model)
        } else {
            Magnetics::Constant(constants)
        };
        let truth = magnetic_accuracy::plant_model(p);
        Some(Self {
            saturation_detected: fit.detected,
            fitted: fit.model,
            inductance_change: fit.change,
            residual_rms: fit.residual,
            linear_residual_rms: fit.linear_residual,
            pulse_current: proc.pulse_current(),
            flux_linkage: model.flux_linkage,
            flux_from_nameplate: id.is_none(),
            pulse_motion: fit.motion,
            verdict: verdict_name(fit.verdict()),
            accuracy: magnetic_accuracy::compare(&truth, &drive, p.motor.rated_current),
        })
    }
}

/// What a run watches beyond the procedure's output: the largest current and current
/// reference, and the rotor's motion during the inductance tests.
#[derive(Default)]
struct Watch {
    max_i: f64,
    max_ref: f64,
    motion: f64,
    /// The rotor's angle at the start of the inductance tests.
    theta_l: Option<f64>,
    motion_pulses: f64,
    max_i_pulses: f64,
    /// The rotor's angle at the start of the flux-linkage pulses.
    theta_p: Option<f64>,
}

impl Watch {
    fn observe(&mut self, st: &MotorState, out: &CommissioningOutput<f64>) {
        self.max_i = self.max_i.max(st.i_dq.norm());
        self.max_ref = self.max_ref.max(out.current_reference.norm());
        if matches!(out.phase, Phase::InductanceD | Phase::InductanceQ) {
            let t0 = *self.theta_l.get_or_insert(st.theta);
            self.motion = self.motion.max(fado_core::wrap_angle(st.theta - t0).abs());
        }
        if out.phase == Phase::Magnetics {
            let t0 = *self.theta_p.get_or_insert(st.theta);
            let d = fado_core::wrap_angle(st.theta - t0).abs();
            self.motion_pulses = self.motion_pulses.max(d);
            self.max_i_pulses = self.max_i_pulses.max(st.i_dq.norm());
        }
    }
}

impl TraceRow {
    /// The row of the sample the plant has just measured (`i`: the measured α-β current) and
    /// the procedure's `out`; `pp` pole pairs.
    fn of(
        plant: &Plant,
        out: &CommissioningOutput<f64>,
        i: Ab<f64>,
        st: &MotorState,
        pp: f64,
    ) -> Self {
        let rpm = 60.0 / std::f64::consts::TAU;
        TraceRow {
            time: plant.time(),
            phase: out.phase.index() as u8,
            i_alpha: i.alpha,
            i_beta: i.beta,
            v_alpha: out.v_ab.alpha,
            v_beta: out.v_ab.beta,
            v_applied_alpha: plant.last_outcome().v_ab_avg.alpha,
            v_applied_beta: plant.last_outcome().v_ab_avg.beta,
            speed_rpm: st.omega_mech * rpm,
            speed_hat_rpm: out.speed / pp * rpm,
            theta: st.theta,
            theta_hat: out.angle,
        }
    }
}

/// A refusal of the procedure's configuration, named by the key the user writes: the
/// nameplate's fields are `[motor]`'s (the DC link `[inverter]`'s), the timing and dead time
/// `[inverter]`'s; only the procedure's own settings are `commissioning.*`.
fn procedure_error(e: &fado_core::ConfigError) -> SimConfigError {
    let field = e.field();
    let key = match field {
        "dc_voltage" | "switching_frequency" | "dead_time" => format!("inverter.{field}"),
        "sample_period" | "ts" => "inverter.switching_frequency".to_owned(),
        "rs" | "ld" | "lq" | "flux_linkage" | "pole_pairs" | "inertia" | "viscous_friction"
        | "rated_current" | "rated_speed_rpm" | "rated_torque" => format!("motor.{field}"),
        other => format!("commissioning.{other}"),
    };
    SimConfigError::new(key, e.to_string())
}

/// Largest ADC step of the current sensor as a fraction of the procedure's current limit:
/// 1 % (the injection and DC levels are fractions of that limit; the default 12-bit sensor
/// has 0.22 %).
pub const MAX_CURRENT_LSB_RATIO: f64 = 0.01;

/// The procedure's preconditions, checked before it runs (it never reports `passed` on a
/// set-up it cannot measure): the rotor turns at most `fado_core::ratings::MAX_OMEGA_TS` per
/// sample at rated speed (the estimator's and the identification's discretisation, see
/// `fado_core::ratings`), and the current sensor resolves 1 % of the procedure's current
/// limit ([`MAX_CURRENT_LSB_RATIO`]). The ratings themselves are required by the motor file
/// (`crate::derive`). Errors name the key to change and the value that passes.
pub fn preconditions(
    plant: &PlantParams,
    cfg: &CommissioningConfig<f64>,
) -> Result<(), SimConfigError> {
    let m = &cfg.nameplate;
    let x = m.rated_speed() * cfg.sample_period;
    if x > fado_core::ratings::MAX_OMEGA_TS * (1.0 + 1e-9) {
        let f = fado_core::ratings::switching_frequency_of(m);
        return Err(SimConfigError::new(
            "inverter.switching_frequency",
            format!(
                "the rotor turns ω_rated·Ts = {x:.3} rad per sample at rated speed, more than \
                 the {} the estimator's discretisation is accurate to 0.5 % at (the identified \
                 parameters would be off by up to {:.1} %): commissioning needs \
                 switching_frequency ≥ {f} Hz for this motor",
                fado_core::ratings::MAX_OMEGA_TS,
                100.0 * (1.0 - (0.5 * x).cos())
            ),
        ));
    }
    let sensor = &plant.current_sensor;
    if sensor.enable_quantization {
        let full_scale = sensor.adc_full_scale_ratio * m.rated_current;
        let lsb = 2.0 * full_scale / 2f64.powi(sensor.adc_bits.min(62) as i32);
        let limit = cfg.current_limit_ratio * m.rated_current;
        if lsb > MAX_CURRENT_LSB_RATIO * limit {
            return Err(SimConfigError::new(
                "current_sensor.adc_bits",
                format!(
                    "the current sensor's step {lsb:.3e} A ({} bits over ±{full_scale:.3e} A) \
                     is {:.1} % of the commissioning's current limit {limit:.3e} A; it must \
                     resolve 1 % (more bits, or a smaller adc_full_scale_ratio)",
                    sensor.adc_bits,
                    100.0 * lsb / limit
                ),
            ));
        }
    }
    Ok(())
}

/// The configuration document `input` with its `[model]` table replaced by the identified
/// model (the keys of `[motor]`, i.e. of [`MachineModel`]) and its `[inverter_model]` by the
/// identified threshold voltage (for the drive's dead-time compensation), headed by comments
/// giving the uncertainties, the inverter's voltage error and the sensors' gain ratio.
pub fn identified_toml(input: &str, id: &Identification<f64>) -> Result<String, SimConfigError> {
    identified_toml_with_map(input, id, None)
}

/// [`identified_toml`] whose magnetic model, when saturation was identified, is the flux map
/// `map_file` (a path relative to the document: `[model] flux_map`, the table that
/// [`crate::identified_map`] writes) instead of `[model.saturation]`, whose values the header
/// keeps as comments (one magnetic model per `[model]`; uncommented in place of `flux_map`
/// they give the algebraic model itself). Without saturation, or with `map_file` None, it is
/// [`identified_toml`].
pub fn identified_toml_with_map(
    input: &str,
    id: &Identification<f64>,
    map_file: Option<&str>,
) -> Result<String, SimConfigError> {
    let mut doc: toml::Table = input
        .parse()
        .map_err(|e: toml::de::Error| SimConfigError::new("<config>", e.to_string()))?;
    // The plant's flux map, named where the file was read: the identified.toml written
    // elsewhere still finds it.
    if let Some(toml::Value::Table(motor)) = doc.get_mut("motor")
        && let Some(toml::Value::String(written)) = motor.get("flux_map")
    {
        let resolved = crate::magnetics_file::resolve(written)
            .display()
            .to_string();
        motor.insert("flux_map".into(), toml::Value::String(resolved));
    }
    let (model, saturation_lines) = model_table(id, map_file)?;
    doc.insert("model".into(), toml::Value::Table(model));
    // The identified threshold to the drive's dead-time compensation (its dead time is the
    // configured one, as the procedure's); a slightly negative result (noise about a zero
    // threshold) is written as 0, the least the compensation accepts.
    let mut inverter_model = toml::Table::new();
    inverter_model.insert(
        "threshold_voltage".into(),
        toml::Value::Float(id.threshold_voltage.max(0.0)),
    );
    doc.insert("inverter_model".into(), toml::Value::Table(inverter_model));
    let frozen = freeze_resistance_law(&mut doc, id);
    let uncertain = crate::saturation_verdict::model_uncertainty(&mut doc, id);
    let c = id.confidence;
    let head = format!(
        "# [model] identified by `fado-sim commission` (fado_core::commissioning) in {:.2} s.\n\
         # Relative 1-sigma statistical uncertainty: rs {:.2e}, ld {:.2e}, lq {:.2e}, \
         flux_linkage {:.2e}, inertia {:.2e}.\n\
         # Inverter voltage error {:.4} V per phase (threshold {:.4} V at {:.1} V DC link), \
         saliency Lq/Ld {:.4}.\n\
         # Current sensors' gain ratio k = {:.5} (1-sigma {:.1e}): phase a was divided by it, \
         so the model is in phase b's scale, the drive's after its start-up gain calibration.\n\
         {}{}{}{}",
        id.duration,
        c.rs,
        c.ld,
        c.lq,
        c.flux_linkage,
        c.inertia,
        id.inverter_voltage,
        id.threshold_voltage,
        id.dc_voltage,
        id.saliency,
        id.current_gain_ratio,
        c.current_gain_ratio,
        saturation_comment(id),
        saturation_lines,
        frozen,
        uncertain,
    );
    let body = toml::to_string(&doc).map_err(|e| SimConfigError::new("<config>", e.to_string()))?;
    Ok(head + &body)
}

/// The identified `[model]` table (the keys of [`MachineModel`], and the magnetic model as
/// [`identified_toml_with_map`] says) and the header's comment lines of the algebraic model
/// when the table names its map instead.
fn model_table(
    id: &Identification<f64>,
    map_file: Option<&str>,
) -> Result<(toml::Table, String), SimConfigError> {
    let m = id.model;
    let mut model = toml::Table::new();
    for (k, v) in [
        ("rs", m.rs),
        ("ld", m.ld),
        ("lq", m.lq),
        ("flux_linkage", m.flux_linkage),
        ("inertia", m.inertia),
        ("viscous_friction", m.viscous_friction),
        ("rated_current", m.rated_current),
        ("rated_speed_rpm", m.rated_speed_rpm),
        ("rated_torque", m.rated_torque),
    ] {
        model.insert(k.into(), toml::Value::Float(v));
    }
    model.insert(
        "pole_pairs".into(),
        toml::Value::Integer(i64::from(m.pole_pairs)),
    );
    let mut saturation_lines = String::new();
    if let Some(s) = &id.saturation {
        let table = toml::Value::try_from(s)
            .map_err(|e| SimConfigError::new("model.saturation", e.to_string()))?;
        match map_file {
            Some(file) => {
                model.insert("flux_map".into(), toml::Value::String(file.into()));
                saturation_lines = commented_saturation(table)?;
            }
            None => {
                model.insert("saturation".into(), table);
            }
        }
    }
    Ok((model, saturation_lines))
}

/// The algebraic model's `[model.saturation]` table as comment lines (for the header of a
/// document whose `[model]` names the model's flux map).
fn commented_saturation(table: toml::Value) -> Result<String, SimConfigError> {
    let mut doc = toml::Table::new();
    let mut model = toml::Table::new();
    model.insert("saturation".into(), table);
    doc.insert("model".into(), toml::Value::Table(model));
    let text = toml::to_string(&doc).map_err(|e| SimConfigError::new("<config>", e.to_string()))?;
    let mut out = String::from(
        "# [model] flux_map tabulates this algebraic model (identified; in place of flux_map it \
         gives the model itself):\n",
    );
    for line in text.lines().filter(|l| !l.trim().is_empty()) {
        out.push_str(&format!("#   {line}\n"));
    }
    Ok(out)
}

/// One row of the identified-vs-truth comparison.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// Parameter name (a `[model]` key, `inverter_voltage`/`threshold_voltage`, or
    /// `current_gain_ratio`).
    pub parameter: &'static str,
    /// Identified value.
    pub identified: f64,
    /// The plant's value.
    pub truth: f64,
    /// identified/truth − 1 (absolute difference in V for the inverter voltages).
    pub error: f64,
    /// Relative 1-σ statistical uncertainty (absolute in V for the inverter voltage).
    pub confidence: f64,
}

/// The identified values against the truth.
pub fn compare(id: &Identification<f64>, t: &Truth) -> Vec<Comparison> {
    let m = id.model;
    let c = id.confidence;
    let rel = |p, a: f64, b: f64, s| Comparison {
        parameter: p,
        identified: a,
        truth: b,
        error: a / b - 1.0,
        confidence: s,
    };
    let abs = |p, a: f64, b: f64, s| Comparison {
        parameter: p,
        identified: a,
        truth: b,
        error: a - b,
        confidence: s,
    };
    vec![
        rel("rs", m.rs, t.rs, c.rs),
        rel("ld", m.ld, t.ld, c.ld),
        rel("lq", m.lq, t.lq, c.lq),
        rel(
            "flux_linkage",
            m.flux_linkage,
            t.flux_linkage,
            c.flux_linkage,
        ),
        rel("inertia", m.inertia, t.inertia, c.inertia),
        abs(
            "viscous_friction",
            m.viscous_friction,
            t.viscous_friction,
            c.viscous_friction,
        ),
        abs(
            "inverter_voltage",
            id.inverter_voltage,
            t.inverter_voltage,
            c.inverter_voltage,
        ),
        abs(
            "threshold_voltage",
            id.threshold_voltage,
            t.threshold_voltage,
            c.inverter_voltage,
        ),
        rel(
            "current_gain_ratio",
            id.current_gain_ratio,
            t.current_gain_ratio,
            c.current_gain_ratio,
        ),
    ]
}

#[cfg(test)]
mod trace_row_tests {
    use super::{TraceRow, refuse_unused};

    #[test]
    fn tables_commissioning_does_not_read_are_refused_naming_what_takes_them() {
        let plant = "[motor]\nrs = 1.0\n[inverter]\ndead_time = 1e-6\n";
        assert!(refuse_unused(plant, "fado.commission").is_ok());
        for (table, says) in [
            (
                "[speed_reference]\npoints = [[0.0, 0.0]]\n",
                "fado.simulate",
            ),
            ("[model]\nrs = 1.0\n", "identified.toml"),
            ("[simulation]\nduration = 1.0\n", "fado-sim run"),
            ("[controller.speed]\nbandwidth_hz = 3.0\n", "fado-sim run"),
        ] {
            let e = refuse_unused(&format!("{plant}{table}"), "fado.commission").unwrap_err();
            assert!(table.contains(&format!("[{}", e.key)), "{e}");
            assert!(e.message.contains("not used by fado.commission"), "{e}");
            assert!(e.message.contains(says), "{e}");
        }
    }

    #[test]
    fn columns_are_the_csv_header_and_values_follow_them() {
        let mut w = csv::Writer::from_writer(Vec::new());
        let row = TraceRow {
            time: 1.0,
            phase: 2,
            theta_hat: 3.0,
            ..Default::default()
        };
        w.serialize(row).unwrap();
        let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
        let header = text.lines().next().unwrap();
        assert_eq!(header, TraceRow::COLUMNS.join(","));
        let v = row.values();
        assert_eq!((v[0], v[1], v[11]), (1.0, 2.0, 3.0));
    }
}
