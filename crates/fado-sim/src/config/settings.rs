//! The run settings (`[simulation]`), the drive's inverter data (`[inverter_model]`) and the
//! model mismatch (`[mismatch]`).

use serde::{Deserialize, Serialize};

use super::EstimatorKind;
use crate::error::{SimConfigError, check};

/// Run settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimulationSettings {
    /// Simulated time in s. Default 5 s.
    pub duration: f64,
    /// Keep one sample in this many in `traces.csv`. Default 10 (1 kHz).
    pub decimation: u32,
    /// True initial electrical rotor angle in rad. Default 0.3 \[A\].
    pub initial_angle: f64,
    /// Error of the start-up alignment (the drive starts at θ0 + this), rad. Default 0.
    pub align_error: f64,
    /// Metrics are evaluated from this time on, s (start-up excluded). Default 0.
    pub eval_start: f64,
    /// "Near zero speed" means |true speed| below this fraction of the rated speed. Default
    /// 0.02 \[A\] (30 r/min of the paper's 1500 r/min: 2 Hz electrical, just above its 1.5 Hz
    /// mode threshold).
    pub zero_speed_band_ratio: f64,
    /// Scalar type of the drive (estimator and control). Default f64.
    pub precision: Precision,
    /// Which rotor-angle estimator the drive runs. Default fado; the baselines run with an
    /// f64 drive only.
    pub estimator: EstimatorKind,
    /// Windows `[t_off, t_on]` in s during which the k_df feedback is switched off (Fig. 9).
    pub disturbance_feedback_off: Vec<[f64; 2]>,
    /// A holding brake holds the rotor from the start until the drive reports ready (its
    /// calibrations over, gates on); the load acts on the brake until then (a hoist, a
    /// vehicle on a slope). Default false.
    pub brake: bool,
    /// The brake releases at the first ready sample from this time on (s): a hoist's brake
    /// opens shortly before the lift, once the drive holds the rotor. Default 0: at the first
    /// ready sample.
    pub brake_release_at: f64,
}

impl Default for SimulationSettings {
    fn default() -> Self {
        Self {
            duration: 5.0,
            decimation: 10,
            initial_angle: 0.3,
            align_error: 0.0,
            eval_start: 0.0,
            zero_speed_band_ratio: 0.02,
            precision: Precision::F64,
            estimator: EstimatorKind::FADO,
            disturbance_feedback_off: Vec::new(),
            brake: false,
            brake_release_at: 0.0,
        }
    }
}

impl SimulationSettings {
    pub(super) fn validate(&self) -> Result<(), SimConfigError> {
        check::in_range("duration", self.duration, 0.0, 1e5)?;
        if self.duration <= 0.0 {
            return Err(SimConfigError::new(
                "duration",
                format!("must be > 0, got {}", self.duration),
            ));
        }
        if self.decimation == 0 {
            return Err(SimConfigError::new("decimation", "must be ≥ 1"));
        }
        check::finite("initial_angle", self.initial_angle)?;
        check::finite("align_error", self.align_error)?;
        check::finite("brake_release_at", self.brake_release_at)?;
        check::non_negative("eval_start", self.eval_start)?;
        check::positive("zero_speed_band_ratio", self.zero_speed_band_ratio)?;
        for (k, w) in self.disturbance_feedback_off.iter().enumerate() {
            if !(w[0].is_finite() && w[1].is_finite() && w[0] <= w[1]) {
                return Err(SimConfigError::new(
                    format!("disturbance_feedback_off[{k}]"),
                    "must be [t_off, t_on] with t_off ≤ t_on",
                ));
            }
        }
        Ok(())
    }
}

/// Scalar type the drive runs in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Precision {
    /// f64 (analysis).
    #[default]
    F64,
    /// f32, as on the paper's TMS320F28335 (single-precision FPU).
    F32,
}

/// `[inverter_model]`: what the drive's dead-time compensation is told of the inverter, as
/// identified (e.g. by `fado_core::commissioning`) rather than derived from the plant.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InverterModel {
    /// Device threshold voltage V̂_th of the compensation, V (instead of `[inverter]
    /// threshold_voltage` × `[mismatch] threshold_voltage_ratio`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub threshold_voltage: Option<f64>,
}

impl InverterModel {
    pub(super) fn validate(&self) -> Result<(), SimConfigError> {
        if let Some(v) = self.threshold_voltage {
            check::non_negative("threshold_voltage", v)?;
        }
        Ok(())
    }
}

/// The drive's model of the plant as ratios to the true values (1 = matched). The robustness
/// sweep of docs/guide/first-run.md varies these.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Mismatch {
    /// R̂s / (Rs + r_on). Default 1.
    pub rs_ratio: f64,
    /// L̂d / Ld. Default 1.
    pub ld_ratio: f64,
    /// L̂q / Lq. Default 1.
    pub lq_ratio: f64,
    /// λ̂f / λf. Default 1.
    pub flux_linkage_ratio: f64,
    /// Ĵ / J. Default 1.
    pub inertia_ratio: f64,
    /// T̂d / Td of the dead-time compensation. Default 1.
    pub dead_time_ratio: f64,
    /// V̂_th / V_th of the dead-time compensation. Default 1.
    pub threshold_voltage_ratio: f64,
    /// Îc / Ic of the dead-time compensation. Default 1.
    pub current_band_ratio: f64,
}

impl Default for Mismatch {
    fn default() -> Self {
        Self {
            rs_ratio: 1.0,
            ld_ratio: 1.0,
            lq_ratio: 1.0,
            flux_linkage_ratio: 1.0,
            inertia_ratio: 1.0,
            dead_time_ratio: 1.0,
            threshold_voltage_ratio: 1.0,
            current_band_ratio: 1.0,
        }
    }
}

impl Mismatch {
    pub(super) fn validate(&self) -> Result<(), SimConfigError> {
        for (k, v) in [
            ("rs_ratio", self.rs_ratio),
            ("ld_ratio", self.ld_ratio),
            ("lq_ratio", self.lq_ratio),
            ("flux_linkage_ratio", self.flux_linkage_ratio),
            ("inertia_ratio", self.inertia_ratio),
            ("current_band_ratio", self.current_band_ratio),
        ] {
            check::positive(k, v)?;
        }
        check::non_negative("dead_time_ratio", self.dead_time_ratio)?;
        check::non_negative("threshold_voltage_ratio", self.threshold_voltage_ratio)?;
        Ok(())
    }
}
