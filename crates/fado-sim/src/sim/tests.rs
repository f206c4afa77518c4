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
