//! The drive's magnetic model (`[model]`): which saturating model the estimator and the drive
//! evaluate, and the `'static` flux maps they borrow.
//!
//! The rule, as for every other key of `[model]`: the drive's model is the plant's unless the
//! file says otherwise. `[model.saturation]` gives an algebraic model of its own, `[model]
//! flux_map = "FILE.csv"` a flux map (the CSV of `crate::magnetics_file`, a relative path
//! relative to the TOML file). A `[model]`
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

use fado_core::MachineModel;
use fado_core::magnetics::{FluxMap, MachineMagnetics, Saturation};
use serde::Deserialize;

use crate::config::{SimConfig, key_error};
use crate::error::SimConfigError;
use crate::magnetics::{FluxMapData, PlantMagnetics};
use crate::magnetics_file::{FLUX_MAP_KEY, FluxMapFile};

/// The keys of `[model]` that are not `fado_core::MachineModel`'s: taken out of the table
/// before it is read as one.
pub const MODEL_MAGNETICS_KEYS: [&str; 2] = ["saturation", "flux_map"];

/// The models leaked so far (see the module docs): maps with their f64 and f32 forms,
/// saturation models in f64 and f32.
#[derive(Default)]
struct Interned {
    maps: Vec<(&'static FluxMapData, &'static FluxMap<'static, f64>)>,
    maps_f32: Vec<(&'static FluxMapData, &'static FluxMap<'static, f32>)>,
    saturation: Vec<&'static Saturation<f64>>,
    saturation_f32: Vec<&'static Saturation<f32>>,
}
static INTERNED: Mutex<Interned> = Mutex::new(Interned {
    maps: Vec::new(),
    maps_f32: Vec::new(),
    saturation: Vec::new(),
    saturation_f32: Vec::new(),
});

fn leak<T: Copy>(v: impl Iterator<Item = T>) -> &'static [T] {
    Box::leak(v.collect::<Vec<T>>().into_boxed_slice())
}

fn interned() -> std::sync::MutexGuard<'static, Interned> {
    INTERNED.lock().unwrap_or_else(|e| e.into_inner())
}

/// `s` as a `'static` model (leaked once per distinct model).
pub fn interned_saturation(s: &Saturation<f64>) -> &'static Saturation<f64> {
    let mut i = interned();
    if let Some(m) = i.saturation.iter().find(|m| **m == s) {
        return m;
    }
    let m: &'static Saturation<f64> = Box::leak(Box::new(*s));
    i.saturation.push(m);
    m
}

/// `s` rounded to f32 as a `'static` model (leaked once per distinct model).
fn interned_saturation_f32(s: &Saturation<f64>) -> &'static Saturation<f32> {
    let s32 = s.cast::<f32>();
    let mut i = interned();
    if let Some(m) = i.saturation_f32.iter().find(|m| ***m == s32) {
        return m;
    }
    let m: &'static Saturation<f32> = Box::leak(Box::new(s32));
    i.saturation_f32.push(m);
    m
}

/// `map` as a `'static` map in f64 (leaked once per distinct map).
pub fn interned_map(map: &FluxMapData) -> &'static FluxMap<'static, f64> {
    let mut i = interned();
    if let Some((_, m)) = i.maps.iter().find(|(d, _)| *d == map) {
        return m;
    }
    let data: &'static FluxMapData = Box::leak(Box::new(*map));
    let m: &'static FluxMap<'static, f64> = Box::leak(Box::new(data.map()));
    i.maps.push((data, m));
    m
}

/// `map` rounded to f32 as a `'static` map (leaked once per distinct map); None if the
/// rounding breaks its monotonicity (a map too fine for single precision).
fn interned_map_f32(map: &'static FluxMapData) -> Option<&'static FluxMap<'static, f32>> {
    let mut i = interned();
    if let Some((_, m)) = i.maps_f32.iter().find(|(d, _)| *d == map) {
        return Some(m);
    }
    let m64 = map.map();
    let f = |x: &[f64]| leak(x.iter().map(|&v| v as f32));
    let m = FluxMap::new(f(m64.i_d()), f(m64.i_q()), f(m64.psi_d()), f(m64.psi_q())).ok()?;
    let m: &'static FluxMap<'static, f32> = Box::leak(Box::new(m));
    i.maps_f32.push((map, m));
    Some(m)
}

/// The plant's magnetic model as the drive holds it.
pub fn plant_model(plant: &PlantMagnetics) -> MachineMagnetics<f64> {
    match plant {
        PlantMagnetics::Saturation(s) => MachineMagnetics::Saturation(interned_saturation(s)),
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
        return Ok(MachineMagnetics::Saturation(interned_saturation(&s)));
    }
    if let Some(value) = table.and_then(|t| t.get("flux_map")) {
        let Some(written) = value.as_str() else {
            return Err(SimConfigError::new(
                "model.flux_map",
                "a file name (a CSV `i_d,i_q,psi_d,psi_q`) is expected",
            ));
        };
        let file = FluxMapFile::read(written).map_err(|mut e| {
            if e.key == FLUX_MAP_KEY {
                e.key = "model.flux_map".into();
            }
            e
        })?;
        return Ok(MachineMagnetics::Map(interned_map(&file.data)));
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

/// The drive's model derived from the plant (`SimConfig::derived_model`) with its magnetic
/// model (module docs), and the `[model]` table without the magnetic keys (what
/// `fado_core::MachineModel` reads).
pub fn split(cfg: &SimConfig) -> Result<(MachineModel<f64>, Option<toml::Table>), SimConfigError> {
    let magnetics = drive_model(cfg, cfg.model.as_ref())?;
    let table = cfg.model.clone().map(|mut t| {
        for key in MODEL_MAGNETICS_KEYS {
            t.remove(key);
        }
        t
    });
    Ok((cfg.derived_model().with_magnetics(magnetics), table))
}

/// A drive model's magnetics in f32: the saturation model rounded, a map rounded and
/// interned (None if rounding breaks it, or for a map this module did not intern: the caller
/// refuses the configuration).
pub fn to_f32(m: &MachineMagnetics<f64>) -> Option<MachineMagnetics<f32>> {
    match *m {
        MachineMagnetics::Linear => Some(MachineMagnetics::Linear),
        MachineMagnetics::Saturation(s) => {
            Some(MachineMagnetics::Saturation(interned_saturation_f32(s)))
        }
        MachineMagnetics::Map(map) => {
            let data = {
                let i = interned();
                i.maps
                    .iter()
                    .find(|(_, m)| std::ptr::eq(*m, map))
                    .map(|(d, _)| *d)?
            };
            interned_map_f32(data).map(MachineMagnetics::Map)
        }
        // Only firmware builds a uniform table (a `static` of its own precision).
        MachineMagnetics::Uniform(_) => None,
    }
}

/// Resolves a `[model] flux_map` path where the file is read (relative to the TOML file,
/// `crate::magnetics_file::resolve`), so that the configuration names the same file on any
/// thread that later builds the drive from it.
pub fn resolve_model_paths(user: &mut toml::Table) {
    let Some(toml::Value::Table(table)) = user.get_mut("model") else {
        return;
    };
    if let Some(toml::Value::String(written)) = table.get("flux_map") {
        let resolved = crate::magnetics_file::resolve(written);
        table.insert(
            "flux_map".into(),
            toml::Value::String(resolved.display().to_string()),
        );
    }
}
