//! The rating-scale check (`fado_core::machine_checks::scale`) on every motor file the
//! repository holds — the presets, the test machines and the datasheet machines entered as
//! their datasheets state them: none is taken for scaled ratings, and each with its
//! `rated_current`, `rated_speed_rpm` and `rated_torque` divided or multiplied by 10 (the DC
//! link left to be derived, as a file without `dc_voltage` has it) is named, but for the
//! listed exceptions that the module documentation explains.

use std::path::{Path, PathBuf};

use fado_core::MachineModel;
use fado_core::machine_checks::{Finding, check};
use fado_sim::SimConfig;

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files(&p, out);
        } else if p.extension().is_some_and(|x| x == "toml") {
            out.push(p);
        }
    }
}

/// Every motor file: `motors/**` and `crates/fado-sim/tests/data/**`.
fn motor_files() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    files(&root.join("../../motors"), &mut out);
    files(&root.join("tests/data"), &mut out);
    out.sort();
    out
}

/// `Some(true)` when `m` (its DC link derived) looks like ratings / 10, `Some(false)` × 10;
/// an error that names a rating (a rated speed beyond any motor) or the DC link derived from
/// them counts as the expected one.
fn scale(m: &MachineModel<f64>, expected: bool) -> Option<bool> {
    let m = MachineModel {
        dc_voltage: fado_core::ratings::dc_voltage(m),
        ..*m
    };
    let findings = check(&m, None);
    if let Some(e) = findings.error() {
        // The derived DC link's error names the ratings it follows from (`SimConfig`).
        let rating = fado_core::ratings::RATING_KEYS.contains(&e.key());
        return (rating || e.key() == "dc_voltage").then_some(expected);
    }
    findings.iter().find_map(|f| match f {
        Finding::RatingScale { divided, .. } => Some(*divided),
        _ => None,
    })
}

fn times(m: &MachineModel<f64>, k: f64) -> MachineModel<f64> {
    MachineModel {
        rated_current: m.rated_current * k,
        rated_speed_rpm: m.rated_speed_rpm * k,
        rated_torque: m.rated_torque * k,
        ..*m
    }
}

/// (file name, factor) pairs the check misses: a slotless motor × 10 is the size of a real
/// high-speed machine (see `machine_checks::scale`); the maxon EC 45 flat of [`WARNED`] × 10
/// sits inside the bands its own ratings leave, and so does the gimbal motor of [`WARNED`];
/// the 20 kW IPMSM of `tests/data/unseen/` / 10 (3 N·m at 650 r/min, 204 W, τ 0.89 ms) is a
/// plausible small servo by these bands (the DC link check refuses it: 4.2 % of the link);
/// the drawn 289 W 2-pole motor of `tests/data/drawn/` (28,160 r/min) × 10 is a 29 kW
/// machine at 282,000 r/min and 4.7 kHz, the class of the 240,000 r/min turbo compressor;
/// two heavy drawn surface-magnet machines of `tests/data/drawn/` / 10 are direct-drive
/// torque motors (the 17-pole-pair 30 kW one 11.9 N·m at 237 r/min, 295 W; the 4-pole-pair
/// 168 kW one 155 N·m at 103 r/min, 1.7 kW), whose magnet flux and inductance suit a slow,
/// high-torque winding as well; the drawn 88 kW 1-pole-pair IPMSM / 10 (9.5 N·m at
/// 886 r/min, 880 W, τ 8.1 ms against the 9.1 ms bound at 880 W, product 0.055) is a slow
/// 2-pole machine the bands allow.
const MISSED: [(&str, f64); 8] = [
    ("ipm-1p-800v-88kw.toml", 0.1),
    ("ipmsm-20kw-10p-560v.toml", 0.1),
    ("spm-17p-800v-30kw-heavy.toml", 0.1),
    ("spm-4p-800v-168kw.toml", 0.1),
    ("spm-sat-1p-147v-289w.toml", 10.0),
    ("maxon-ec22-40w-24v.toml", 10.0),
    ("maxon-ec45flat-50w-12v.toml", 10.0),
    ("gimbal-gbm5208-200t-4s.toml", 10.0),
];

/// Files whose own ratings the check takes for ratings / 10 (a warning): the maxon EC 45 flat
/// of `tests/data/unseen/`, whose rated point is assumed, not from its sheet (0.087 N·m at
/// 3,000 r/min, 27 W): a flat 16-pole motor has a long electrical time constant for its power
/// (0.694 ms against the 0.672 ms the check allows at 27 W), unusual but possible, so warned
/// and run; the GBM5208 gimbal motor of `tests/data/unseen/` (0.162 N·m at an assumed
/// 100 r/min, 1.7 W, 8.5 Ω and 5.4 mH: τ 0.64 ms where the check allows 0.084 ms at 1.7 W), a
/// motor wound for holding torque at near-zero speed.
const WARNED: [&str; 2] = ["maxon-ec45flat-50w-12v.toml", "gimbal-gbm5208-200t-4s.toml"];

#[test]
fn no_motor_file_is_taken_for_scaled_ratings_and_each_scaled_one_is_named() {
    let mut checked = 0;
    let mut caught = 0;
    for path in motor_files() {
        let text = std::fs::read_to_string(&path).unwrap();
        if !text.contains("[motor]") {
            continue;
        }
        let Ok(cfg) = SimConfig::from_toml(&text) else {
            continue; // a file of an error test
        };
        let name = path.file_name().unwrap().to_str().unwrap();
        let m = cfg.motor;
        if WARNED.contains(&name) {
            assert_eq!(
                scale(&m, false),
                Some(true),
                "{name} is not warned: update WARNED"
            );
        } else {
            assert_eq!(scale(&m, false), None, "{name}");
        }
        checked += 1;
        for (k, divided) in [(0.1, true), (10.0, false)] {
            let found = scale(&times(&m, k), divided);
            if MISSED.contains(&(name, k)) {
                assert_ne!(
                    found,
                    Some(divided),
                    "{name} × {k} is caught: update MISSED"
                );
            } else {
                assert_eq!(found, Some(divided), "{name} × {k}");
                caught += 1;
            }
        }
    }
    // Every file's scaled variants named but the MISSED ones.
    assert!(checked >= 35, "{checked} files");
    assert_eq!(caught, 2 * checked - MISSED.len());
}
