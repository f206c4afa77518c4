//! `sweep.csv`: one row per finished point (header: `point`, the axes, `status`, `passed`,
//! `tripped`, the metrics, `failed_checks`), written whole through a temporary file and read
//! back to resume, rows cut short or foreign dropped.

use std::collections::BTreeMap;
use std::fs::File;
use std::path::Path;

use super::Value;
use super::point::{METRICS, PointResult, Status};
use super::runner::{SweepError, io};
use super::spec::SweepSpec;
use crate::output::AtomicFile;

/// The CSV header: `point` (the index), the axes, `status`, `passed`, `tripped`, the [`METRICS`],
/// `failed_checks`.
pub fn csv_header(spec: &SweepSpec) -> Vec<String> {
    let mut h = vec!["point".to_owned()];
    h.extend(spec.axes.iter().cloned());
    h.extend(["status", "passed", "tripped"].map(str::to_owned));
    h.extend(METRICS.map(str::to_owned));
    h.push("failed_checks".to_owned());
    h
}

/// A value as a CSV cell: numbers in Rust's shortest round-trip form, strings bare.
pub(crate) fn cell(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Float(x) => format!("{x:?}"),
        other => other.to_string(),
    }
}

pub(crate) fn csv_record(r: &PointResult) -> Vec<String> {
    let mut rec = vec![r.index.to_string()];
    rec.extend(r.values.iter().map(cell));
    rec.push(r.status.to_string());
    rec.push(r.passed.to_string());
    rec.push(r.tripped.to_string());
    rec.extend(r.metrics().map(|x| {
        if x.is_nan() {
            String::new()
        } else {
            format!("{x:?}")
        }
    }));
    rec.push(r.failed_checks.clone());
    rec
}

pub(crate) fn csv_line(r: &PointResult) -> String {
    let mut w = csv::WriterBuilder::new().from_writer(Vec::new());
    w.write_record(csv_record(r))
        .expect("writing to a Vec cannot fail");
    String::from_utf8(w.into_inner().expect("writing to a Vec cannot fail"))
        .expect("the record is UTF-8")
}

/// Writes `rows` with the header to `path` (through a temporary file, so an interruption
/// leaves the old file).
pub(crate) fn write_csv<'a>(
    path: &Path,
    spec: &SweepSpec,
    rows: impl Iterator<Item = &'a PointResult>,
) -> Result<(), SweepError> {
    let csv_error = |e: csv::Error| match e.into_kind() {
        csv::ErrorKind::Io(e) => io("write", path, e),
        other => io("write", path, std::io::Error::other(format!("{other:?}"))),
    };
    let mut w = csv::Writer::from_writer(AtomicFile::create(path)?);
    w.write_record(csv_header(spec)).map_err(csv_error)?;
    for r in rows {
        w.write_record(csv_record(r)).map_err(csv_error)?;
    }
    let file = w
        .into_inner()
        .map_err(|e| io("write", path, e.into_error()))?;
    Ok(file.commit()?)
}

/// Reads the rows of `sweep.csv` written for `spec`: the finished points by index. Rows cut
/// short by an interruption, or not belonging to `spec`, are dropped (they will be rerun).
/// The point values come from `spec`, so they round-trip exactly.
pub fn read_csv(path: &Path, spec: &SweepSpec) -> Result<BTreeMap<usize, PointResult>, SweepError> {
    let file = File::open(path).map_err(|e| io("open", path, e))?;
    let mut rd = csv::ReaderBuilder::new().flexible(true).from_reader(file);
    let header: Vec<String> = rd
        .headers()
        .map_err(|e| io("read", path, std::io::Error::other(e)))?
        .iter()
        .map(str::to_owned)
        .collect();
    if header != csv_header(spec) {
        return Err(SweepError::Mismatch(format!(
            "{}: the header does not match the sweep's axes",
            path.display()
        )));
    }
    let n_axes = spec.axes.len();
    let mut out = BTreeMap::new();
    for rec in rd.records() {
        let Ok(rec) = rec else { continue };
        if rec.len() != header.len() {
            continue;
        }
        let Ok(index) = rec[0].parse::<usize>() else {
            continue;
        };
        let Some(values) = spec.points.get(index) else {
            continue;
        };
        if values
            .iter()
            .map(cell)
            .ne(rec.iter().skip(1).take(n_axes).map(str::to_owned))
        {
            continue;
        }
        let f = |k: usize| -> Option<f64> {
            let s = &rec[1 + n_axes + 3 + k];
            if s.is_empty() {
                Some(f64::NAN)
            } else {
                s.parse().ok()
            }
        };
        let b = |k: usize| rec[1 + n_axes + k].parse::<bool>().ok();
        let (Some(passed), Some(tripped)) = (b(1), b(2)) else {
            continue;
        };
        let m: Option<Vec<f64>> = (0..METRICS.len()).map(f).collect();
        let Some(m) = m else { continue };
        out.insert(
            index,
            PointResult {
                index,
                values: values.clone(),
                status: Status::parse(&rec[1 + n_axes]),
                passed,
                failed_checks: rec[header.len() - 1].to_owned(),
                max_angle_error: m[0],
                rms_angle_error: m[1],
                max_angle_error_zero_speed: m[2],
                rms_angle_error_zero_speed: m[3],
                max_speed_error_rpm: m[4],
                tripped,
                wall_seconds: m[5],
                max_angle_error_run: m[6],
                angle_error_exceeded_time: m[7],
                lock_lost_time: m[8],
                loss_onset_time: m[9],
                loss_settled_time: m[10],
                lock_detection_delay: m[11],
                lock_late_delay: m[12],
                stall_time: m[13],
                lock_lost_detection_delay: m[14],
            },
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::test_support::{floats, short, tmp_dir};
    use crate::sweep::{SweepOptions, run};

    #[test]
    fn csv_round_trips() {
        let dir = tmp_dir("csv");
        let spec = short(SweepSpec::grid(
            "fig11",
            vec![
                ("rs_error".into(), floats(&[-2.0, 0.01])),
                (
                    "simulation.precision".into(),
                    vec![Value::String("f32".into())],
                ),
            ],
        ));
        let opts = SweepOptions {
            threads: 1,
            out: Some(dir.clone()),
            fresh: false,
            cancel: None,
        };
        let out = run(&spec, &opts, &|_, _| {}).unwrap();
        let back: Vec<PointResult> = read_csv(&dir.join("sweep.csv"), &spec)
            .unwrap()
            .into_values()
            .collect();
        assert_eq!(back.len(), 2);
        for (a, b) in out.rows.iter().zip(&back) {
            assert_eq!(csv_record(a), csv_record(b));
            assert_eq!((&a.values, &a.status), (&b.values, &b.status));
        }
        assert!(matches!(back[0].status, Status::Failed(_)) && back[0].max_angle_error.is_nan());
        // NaN-aware equality (the loss-of-lock times of a run that never lost lock are NaN).
        assert_eq!(format!("{:?}", back[1]), format!("{:?}", out.rows[1]));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
