//! What a recording's columns say about their units, before `fado.estimate` replays them: a
//! warning (`UserWarning`) naming the column and the likely slip where the samples cannot come
//! from the machine the call describes. The estimator refuses such samples one by one
//! (`fado_core::plausibility`), and a recording in mA, in kV, with a dead channel or a burst of
//! NaN would otherwise come back as a result whose angle is simply wrong.
//!
//! | finding | condition | likely slip |
//! |---|---|---|
//! | current beyond the bound | over 1 % of samples with \|i\| ≥ the plausible current | mA for A (max × 1000), the voltage columns in the current slots |
//! | voltage beyond the bound | over 1 % of samples with \|v\| ≥ the plausible voltage | mV for V, the current columns in the voltage slots |
//! | voltage too small | max \|v\| < 0.1 × R̂s·max \|i\| while current flows | kV for V |
//! | constant column | every sample of one column equal while its partner varies | a dead channel, a column taken twice |
//! | non-finite samples | over 1 % of samples NaN or ±∞, or a run of them lasting 1 ms or more (`BURST_SECONDS`) | a gap in the logger |
//! | start angle | \|θ0\| > 2π | degrees for radians |
//! | voltage equation | the active flux misfits λf, and fits with a slip undone | the currents' sign reversed, the voltage and current columns exchanged, the currents' (or the voltages') α and β exchanged ([`crate::recording_model`]) |
//! | voltage equation | the active flux misfits λf in every reading | another machine's parameters, a unit slip in `rs`, `ld`, `lq` or `flux_linkage`, a saturating machine without its magnetic model |
//! | negative sequence | every turning window turns backwards | α and β swapped, if the motor turned forward |

use fado_core::MachineModel;
use fado_core::plausibility::SampleBounds;
use pyo3::prelude::*;

use crate::inputs::{ColumnSlice, SIGNAL_NAMES, Signals};

/// Share of samples above which refused samples are reported: 1 %.
const REFUSED_SHARE: f64 = 0.01;

/// Duration of a run of consecutive non-finite samples in one column from which it is
/// reported whatever its share: 1 ms (10 samples at 10 kHz). A glitching ADC gives single
/// samples; a run is a gap in the logger, over which the estimator coasts on its speed
/// estimate with no flux measured.
const BURST_SECONDS: f64 = 1e-3;

/// The longest run of consecutive non-finite samples of `c`: (first sample, length).
fn longest_burst(c: &[f64]) -> (usize, usize) {
    let (mut best, mut start, mut len) = ((0, 0), 0, 0);
    for (k, x) in c.iter().enumerate() {
        if x.is_finite() {
            len = 0;
            continue;
        }
        if len == 0 {
            start = k;
        }
        len += 1;
        if len > best.1 {
            best = (start, len);
        }
    }
    best
}

/// The non-finite samples of column `k`: a finding when they are over [`REFUSED_SHARE`] of
/// the samples or a run of them lasts [`BURST_SECONDS`] or more (`ts` the sampling period).
fn non_finite(c: &[f64], k: usize, ts: f64, out: &mut Vec<String>) {
    let n = c.len();
    let bad = c.iter().filter(|x| !x.is_finite()).count();
    let (first, run) = longest_burst(c);
    let burst = run > 1 && run as f64 * ts >= BURST_SECONDS * (1.0 - 1e-9);
    if bad as f64 > REFUSED_SHARE * n as f64 || burst {
        out.push(format!(
            "`{}` has {bad} non-finite samples of {n} ({:.1} %), the longest run {run} \
             samples from sample {first} ({:.4} ms): each is refused as a measurement fault \
             and the estimator coasts over them on its speed estimate (a gap in the logger?)",
            SIGNAL_NAMES[k],
            100.0 * bad as f64 / n as f64,
            1e3 * run as f64 * ts
        ));
    }
}

/// The samples of `c` as f64.
fn values(c: ColumnSlice<'_>) -> Vec<f64> {
    match c {
        ColumnSlice::F64(x) => x.to_vec(),
        ColumnSlice::F32(x) => x.iter().map(|&v| f64::from(v)).collect(),
    }
}

/// Issues `text` as a `UserWarning` at the caller's line.
fn warn(py: Python<'_>, text: &str) -> PyResult<()> {
    PyErr::warn(
        py,
        &py.get_type::<pyo3::exceptions::PyUserWarning>(),
        &std::ffi::CString::new(text).unwrap_or_default(),
        2,
    )
}

/// The findings on `signals` against the estimator's `bounds`, its machine `m` sampled every
/// `ts` and start angle `theta0`, as texts (empty: nothing unusual).
pub fn findings(
    signals: &Signals<'_>,
    bounds: &SampleBounds<f64>,
    m: &MachineModel<f64>,
    ts: f64,
    theta0: Option<f64>,
) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(t) = theta0.filter(|t| t.abs() > std::f64::consts::TAU) {
        out.push(format!(
            "theta0 = {t} rad is more than a turn: degrees where radians are meant \
             ({:.4} rad)?",
            t.to_radians()
        ));
    }
    let n = signals.len();
    if n == 0 {
        return out;
    }
    let cols: Vec<Vec<f64>> = signals.slices().into_iter().map(values).collect();
    for (k, c) in cols.iter().enumerate() {
        non_finite(c, k, ts, &mut out);
    }
    constant_columns(&cols, &mut out);
    magnitudes(&cols, bounds, m.rs, &mut out);
    out.extend(crate::recording_model::findings(&cols, m, ts));
    out
}

/// A column whose every finite sample is equal while its partner's vary.
fn constant_columns(cols: &[Vec<f64>], out: &mut Vec<String>) {
    let spread = |c: &Vec<f64>| {
        let f = c.iter().copied().filter(|x| x.is_finite());
        let (lo, hi) = f.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(x), h.max(x))
        });
        (lo, hi - lo)
    };
    for (k, partner) in [(0, 1), (1, 0), (2, 3), (3, 2)] {
        let (value, s) = spread(&cols[k]);
        let (_, sp) = spread(&cols[partner]);
        if cols[k].len() >= 100 && s == 0.0 && sp > 0.0 {
            out.push(format!(
                "`{}` is {value} in every sample while `{}` varies: a dead channel, or a \
                 column given twice?",
                SIGNAL_NAMES[k], SIGNAL_NAMES[partner]
            ));
        }
    }
}

/// Current and voltage magnitudes against the bounds and against each other.
fn magnitudes(cols: &[Vec<f64>], b: &SampleBounds<f64>, rs: f64, out: &mut Vec<String>) {
    let n = cols[0].len() as f64;
    let mag = |a: &Vec<f64>, c: &Vec<f64>| -> Vec<f64> {
        a.iter()
            .zip(c)
            .map(|(x, y)| x.hypot(*y))
            .filter(|m| m.is_finite())
            .collect()
    };
    let (i, v) = (mag(&cols[2], &cols[3]), mag(&cols[0], &cols[1]));
    let max = |m: &Vec<f64>| m.iter().copied().fold(0.0_f64, f64::max);
    let (i_max, v_max) = (max(&i), max(&v));
    let over_i = i.iter().filter(|&&m| m >= b.current()).count() as f64;
    if over_i > REFUSED_SHARE * n {
        let hint = if i_max > 100.0 * b.current() {
            "a current in mA where A is meant"
        } else {
            "the voltage columns in the current slots, or `rated_current` too small"
        };
        out.push(format!(
            "{:.1} % of the samples have |i| (`i_alpha`, `i_beta`) at or above the plausible \
             {:.4} A (4 × `rated_current`; max {i_max:.4e} A) and are refused as measurement \
             faults: {hint}?",
            100.0 * over_i / n,
            b.current()
        ));
    }
    let over_v = v.iter().filter(|&&m| m >= b.voltage()).count() as f64;
    if over_v > REFUSED_SHARE * n {
        out.push(format!(
            "{:.1} % of the samples have |v| (`v_alpha`, `v_beta`) at or above the plausible \
             {:.4} V (1.5 × `dc_voltage`; max {v_max:.4e} V) and are refused as measurement \
             faults: a voltage in mV where V is meant, or the current columns in the voltage \
             slots?",
            100.0 * over_v / n,
            b.voltage()
        ));
    }
    let drop = rs
        * i.iter()
            .copied()
            .filter(|&m| m < b.current())
            .fold(0.0, f64::max);
    if drop > 0.0 && v_max < 0.1 * drop {
        out.push(format!(
            "the voltages (`v_alpha`, `v_beta`) reach {v_max:.4e} V only, a tenth of the \
             resistive drop R̂s·|i| = {drop:.4e} V of the currents alone: a voltage in kV \
             where V is meant, or the voltage and current columns exchanged?"
        ));
    }
}

/// [`findings`] issued as warnings.
pub fn warn_all(
    py: Python<'_>,
    signals: &Signals<'_>,
    bounds: &SampleBounds<f64>,
    m: &MachineModel<f64>,
    ts: f64,
    theta0: Option<f64>,
) -> PyResult<()> {
    for text in findings(signals, bounds, m, ts, theta0) {
        warn(py, &text)?;
    }
    Ok(())
}
