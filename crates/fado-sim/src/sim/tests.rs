//! The trace's columns.

use fado_core::Dq;

use super::*;

#[test]
fn csv_header_is_the_column_list_and_values_follow_it() {
    let mut t = Trace::new(1);
    let mut s = Sample {
        time: 0.25,
        speed_rpm: -12.0,
        pole_pairs: 4.0,
        ..Default::default()
    };
    s.act.estimate.omega = -2.0 * std::f64::consts::TAU; // −30 r/min with 4 pole pairs
    s.act.estimate.diagnostics.flag_limit = true;
    s.act.i_dq_ref = Dq::new(4.0, -1.5);
    s.act.v_ref_ab = fado_core::Ab::new(12.5, -3.0);
    s.i_ab_measured = fado_core::Ab::new(0.75, 2.0);
    t.observe(&s);
    let mut buf = Vec::new();
    t.write_csv(&mut buf).unwrap();
    let text = String::from_utf8(buf).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next().unwrap(), TraceRow::COLUMNS.join(","));
    let values: Vec<f64> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(values, t.rows[0].values().to_vec());
    assert_eq!(t.column("i_q_ref").unwrap(), vec![-1.5]);
    assert_eq!(t.column("flag_limit").unwrap(), vec![1.0]);
    assert_eq!(t.column("speed_rpm").unwrap(), vec![-12.0]);
    assert_eq!(t.column("v_beta_ref").unwrap(), vec![-3.0]);
    assert_eq!(t.column("i_alpha").unwrap(), vec![0.75]);
    assert!((t.column("speed_hat1_rpm").unwrap()[0] + 30.0).abs() < 1e-12);
    assert!(t.column("nope").is_none());
}

/// A float of every kind `traces.csv` can meet: any bit pattern (every exponent, subnormals,
/// NaN, infinities), values of a trace's magnitudes, integers and the edges where the printed
/// form turns to exponent notation.
fn any_float(rng: &mut rand_xoshiro::Xoshiro256PlusPlus) -> f64 {
    use rand_xoshiro::rand_core::Rng;
    let bits = rng.next_u64();
    let unit = (bits >> 11) as f64 / (1u64 << 53) as f64;
    let sign = if bits & 1 == 0 { 1.0 } else { -1.0 };
    match bits % 7 {
        0 => f64::from_bits(rng.next_u64()),
        1 => sign * 10f64.powf(24.0 * unit - 12.0),
        2 => sign * (unit * 1e4).round(),
        3 => [
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            1e16,
            1e15,
            9.999999999999998e15,
            1e-5,
            1e-6,
            1e-7,
            0.1 + 0.2,
        ][(bits >> 8) as usize % 15],
        4 => sign * 10f64.powi((bits >> 8) as i32 % 40 - 20) * (1.0 + unit),
        5 => sign * unit * 1e-3,
        _ => sign * unit * 500.0,
    }
}

#[test]
fn csv_bytes_are_the_csv_crates_for_every_kind_of_value() {
    use rand_xoshiro::rand_core::{Rng, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(29);
    let mut rows = Vec::new();
    for _ in 0..20_000 {
        let mut f = || any_float(&mut rng);
        let row = TraceRow {
            time: f(),
            theta: f(),
            theta_hat: f(),
            angle_error: f(),
            speed_rpm: f(),
            speed_hat_rpm: f(),
            speed_hat1_rpm: f(),
            speed_ref_rpm: f(),
            i_d: f(),
            i_q: f(),
            i_d_ref: f(),
            i_q_ref: f(),
            i_d_true: f(),
            i_q_true: f(),
            lambda1_alpha: f(),
            lambda1_beta: f(),
            dist_alpha: f(),
            dist_beta: f(),
            lambda2_alpha: f(),
            lambda2_beta: f(),
            lambda_r_alpha: f(),
            lambda_r_beta: f(),
            flux_alpha_true: f(),
            flux_beta_true: f(),
            torque: f(),
            load_torque: f(),
            v_alpha_ref: f(),
            v_beta_ref: f(),
            v_alpha_applied: f(),
            v_beta_applied: f(),
            i_alpha: f(),
            i_beta: f(),
            rs_hat: f(),
            flux_linkage_hat: f(),
            ..Default::default()
        };
        let word = rng.next_u64();
        rows.push(TraceRow {
            flag_limit: (word & 1) as u8,
            limiter_clamping: (word >> 1 & 1) as u8,
            tracker_hold: (word >> 2 & 1) as u8,
            tripped: (word >> 3) as u8,
            fault_flags: (word >> 16) as u16,
            lock: (word >> 40) as u8,
            ..row
        });
    }
    let mut ours = CsvTraceWriter::new(Vec::new());
    let mut theirs = csv::Writer::from_writer(Vec::new());
    for row in &rows {
        ours.push(row);
        theirs.serialize(row).unwrap();
    }
    let (ours, theirs) = (ours.finish().unwrap(), theirs.into_inner().unwrap());
    for (k, (a, b)) in ours
        .split(|&c| c == b'\n')
        .zip(theirs.split(|&c| c == b'\n'))
        .enumerate()
    {
        assert_eq!(
            String::from_utf8_lossy(a),
            String::from_utf8_lossy(b),
            "line {k}"
        );
    }
    assert_eq!(ours, theirs);
    // An empty trace: the header line alone, as csv writes it.
    let empty = CsvTraceWriter::new(Vec::new()).finish().unwrap();
    assert_eq!(
        empty,
        format!("{}\n", TraceRow::COLUMNS.join(",")).into_bytes()
    );
}
