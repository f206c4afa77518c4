//! The drive's magnetic model (`[model]`): which saturating model the estimator and the drive
//! evaluate, and the `'static` flux maps they borrow.
//!
//! The rule, as for every other key of `[model]`: the drive's model is the plant's unless the
//! file says otherwise. `[model.saturation]` gives an algebraic model of its own, `[model]
//! flux_map = "FILE.csv"` a flux map of its own (`crate::magnetics_file`: the format, the
//! refusals, the path relative to the TOML file). A `[model]`
//! that sets `ld`, `lq` or `flux_linkage`, or a `[mismatch]` ratio of one of them other than 1,
//! describes a constant-inductance model (the drive then runs the constant-inductance
//! arithmetic, as with a linear plant). Otherwise the drive's model is the plant's
//! `[motor.saturation]` or `[motor] flux_map` — the true model, as `ld`, `lq` and
//! `flux_linkage` default to the true values.
//!
//! `fado_core::MachineModel` borrows a map for the program's life (a firmware table in
//! flash). Here a map is interned: each distinct map is leaked once, in each precision, and
//! every configuration that uses it borrows that copy (a sweep's thousands of points share
//! one).

use std::sync::Mutex;

use fado_core::magnetics::{FluxMap, MachineMagnetics, Saturation};
use serde::Deserialize;

use crate::config::{SimConfig, key_error};
use crate::error::SimConfigError;
use crate::magnetics::{FluxMapData, PlantMagnetics};

/// The keys of `[model]` that are not `fado_core::MachineModel`'s: taken out of the table
/// before it is read as one.
pub const MODEL_MAGNETICS_KEYS: [&str; 2] = ["saturation", "flux_map"];

/// The maps leaked so far, in f64 and in f32 (see the module docs).
type Interned = (
    Vec<(&'static FluxMapData, FluxMap<'static, f64>)>,
    Vec<(&'static FluxMapData, FluxMap<'static, f32>)>,
);
static INTERNED: Mutex<Interned> = Mutex::new((Vec::new(), Vec::new()));

fn leak<T: Copy>(v: impl Iterator<Item = T>) -> &'static [T] {
    Box::leak(v.collect::<Vec<T>>().into_boxed_slice())
}

/// `map` as a `'static` map in f64 (leaked once per distinct map).
pub fn interned_map(map: &FluxMapData) -> FluxMap<'static, f64> {
    let mut interned = INTERNED.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, m)) = interned.0.iter().find(|(d, _)| *d == map) {
        return *m;
    }
    let data: &'static FluxMapData = Box::leak(Box::new(map.clone()));
    let m = data.map();
    interned.0.push((data, m));
    m
}

/// `map` rounded to f32 as a `'static` map (leaked once per distinct map); None if the
/// rounding breaks its monotonicity (a map too fine for single precision).
pub fn interned_map_f32(map: &FluxMapData) -> Option<FluxMap<'static, f32>> {
    let mut interned = INTERNED.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, m)) = interned.1.iter().find(|(d, _)| *d == map) {
        return Some(*m);
    }
    let m64 = map.map();
    let f = |x: &[f64]| leak(x.iter().map(|&v| v as f32));
    let m = FluxMap::new(f(m64.i_d()), f(m64.i_q()), f(m64.psi_d()), f(m64.psi_q())).ok()?;
    let data: &'static FluxMapData = Box::leak(Box::new(map.clone()));
    interned.1.push((data, m));
    Some(m)
}

/// The plant's magnetic model as the drive holds it.
pub fn plant_model(plant: &PlantMagnetics) -> MachineMagnetics<f64> {
    match plant {
        PlantMagnetics::Saturation(s) => MachineMagnetics::Saturation(*s),
        PlantMagnetics::Map(m) => MachineMagnetics::Map(interned_map(m)),
    }
}

/// The drive's magnetic model for `cfg` with the `[model]` table `table` (module docs);
/// a `[model.saturation]` that does not parse or validate is refused naming its key.
pub fn drive_model(
    cfg: &SimConfig,
    table: Option<&toml::Table>,
) -> Result<MachineMagnetics<f64>, SimConfigError> {
    if let Some(value) = table.and_then(|t| t.get("saturation")) {
        let s = Saturation::<f64>::deserialize(value.clone())
            .map_err(|e| key_error(e).in_section("model.saturation"))?;
        s.validate().map_err(|e| {
            SimConfigError::new(format!("model.saturation.{}", e.field()), e.to_string())
        })?;
        return Ok(MachineMagnetics::Saturation(s));
    }
    if let Some(value) = table.and_then(|t| t.get("flux_map")) {
        return model_flux_map(value);
    }
    let gives_constants = table.is_some_and(|t| {
        ["ld", "lq", "flux_linkage"]
            .iter()
            .any(|k| t.contains_key(*k))
    });
    let m = &cfg.mismatch;
    let mismatched = [m.ld_ratio, m.lq_ratio, m.flux_linkage_ratio]
        .iter()
        .any(|&r| r != 1.0);
    if gives_constants || mismatched {
        return Ok(MachineMagnetics::Linear);
    }
    Ok(cfg
        .plant()
        .magnetics
        .as_deref()
        .map_or(MachineMagnetics::Linear, plant_model))
}

/// `[model] flux_map`: the map read, checked and interned; errors name `model.flux_map`.
fn model_flux_map(value: &toml::Value) -> Result<MachineMagnetics<f64>, SimConfigError> {
    let rename = |mut e: SimConfigError| {
        e.key = "model.flux_map".to_owned();
        e
    };
    let Some(written) = value.as_str() else {
        return Err(SimConfigError::new(
            "model.flux_map",
            format!(
                "must be the path of a CSV file (a string), got a {}",
                value.type_str()
            ),
        ));
    };
    let file = crate::magnetics_file::FluxMapFile::read(written).map_err(rename)?;
    Ok(MachineMagnetics::Map(interned_map(&file.data)))
}

/// The data of an interned f64 map (`[model] flux_map` or the plant's).
fn interned_data(map: &FluxMap<'static, f64>) -> Option<&'static FluxMapData> {
    let interned = INTERNED.lock().unwrap_or_else(|e| e.into_inner());
    interned.0.iter().find(|(_, m)| m == map).map(|(d, _)| *d)
}

/// A drive model's magnetics in f32: the saturation model rounded, a map rounded and
/// interned (None if rounding breaks it: the caller refuses the configuration).
pub fn to_f32(m: &MachineMagnetics<f64>) -> Option<MachineMagnetics<f32>> {
    match m {
        MachineMagnetics::Map(map) => {
            interned_map_f32(interned_data(map)?).map(MachineMagnetics::Map)
        }
        other => other.cast(),
    }
}
