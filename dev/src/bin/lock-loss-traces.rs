//! Diagnostic: re-runs points of a `fado-sim sweep fig11` CSV at full rate and
//! dumps every trace column (f32, little-endian, `TraceRow::COLUMNS` order) in a time window,
//! one `DIR/point-N.f32` per point, to study loss-of-lock symptoms offline.
//!
//! usage: lock-loss-traces CONFIG.toml SWEEP.csv OUT_DIR T_START T_END [POINT ...]   (no point: all)
use fado_sim::sim::{TraceRow, TraceSink};
use fado_sim::sweep::{Value, point_config};
use std::io::Write;

struct Window {
    t0: f64,
    t1: f64,
    out: Vec<u8>,
}

impl TraceSink for Window {
    fn push(&mut self, row: &TraceRow) {
        if row.time >= self.t0 && row.time < self.t1 {
            for v in row.values() {
                self.out.extend_from_slice(&(v as f32).to_le_bytes());
            }
        }
    }
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let toml = std::fs::read_to_string(&a[1]).unwrap();
    let mut base = fado_sim::scenario_config("fig11", Some(&toml), false).unwrap();
    base.simulation.decimation = 1;
    let text = std::fs::read_to_string(&a[2]).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let names: Vec<String> = header[1..5].iter().map(|s| s.to_string()).collect();
    let out = std::path::Path::new(&a[3]);
    std::fs::create_dir_all(out).unwrap();
    let (t0, t1): (f64, f64) = (a[4].parse().unwrap(), a[5].parse().unwrap());
    let wanted: Vec<usize> = a[6..].iter().map(|s| s.parse().unwrap()).collect();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let index: usize = f[0].parse().unwrap();
        if !wanted.is_empty() && !wanted.contains(&index) {
            continue;
        }
        let values: Vec<Value> = f[1..5]
            .iter()
            .map(|s| Value::Float(s.parse().unwrap()))
            .collect();
        let cfg = point_config(&base, &names, &values).unwrap();
        let mut w = Window {
            t0,
            t1,
            out: Vec::new(),
        };
        let r = fado_sim::scenario::run_config_with(
            "fig11",
            cfg,
            fado_sim::scenario::RunOptions {
                trace: fado_sim::scenario::TraceOutput::Sink(&mut w),
                ..Default::default()
            },
        );
        if r.is_err() {
            eprintln!("point {index}: {:?}", r.err());
            continue;
        }
        let mut file = std::fs::File::create(out.join(format!("point-{index}.f32"))).unwrap();
        file.write_all(&w.out).unwrap();
    }
}
