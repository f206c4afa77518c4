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
//! | voltage too small | max \|v\| < 0.1 × R̂s·max \|i\| while current flows (max \|i\| ≥ 5 % of `rated_current`, `FLOW_SHARE`) | kV for V |
//! | constant column | every sample of one column equal while its partner varies | a dead channel, a column taken twice |
//! | non-finite samples | over 1 % of samples NaN or ±∞, or a run of them lasting 1 ms or more (`BURST_SECONDS`) | a gap in the logger |
//! | start angle | \|θ0\| > 2π | degrees for radians |
//! | voltage equation | the active flux misfits λf, and fits with a slip undone | the currents' sign reversed, the voltage and current columns exchanged, the currents' (or the voltages') α and β exchanged ([`crate::recording_model`]) |
//! | voltage equation | the active flux misfits λf in every reading | another machine's parameters, a unit slip in `rs`, `ld`, `lq` or `flux_linkage`, a saturating machine without its magnetic model |
//! | negative sequence | every turning window turns backwards | α and β swapped, if the motor turned forward |

use std::borrow::Cow;
use std::sync::atomic::AtomicBool;

use fado_core::MachineModel;
use fado_core::plausibility::SampleBounds;
use pyo3::prelude::*;

use crate::inputs::{ColumnSlice, SIGNAL_NAMES};
use crate::interrupt::{self, Cancelled, poll_at};

/// Share of samples above which refused samples are reported: 1 %.
const REFUSED_SHARE: f64 = 0.01;

/// Share of `rated_current` from which the largest current counts as flowing for the
/// voltage-too-small finding: 5 %. Below it the currents are the sensors' offsets and noise
/// (a gates-off offset calibration reads 0.1–0.5 % of the rated current on the presets, and a
/// drive's ADC offset is rarely above 2 %), with no voltage to go with them: a recording of a
/// start-up's first 0.1 s is not a voltage in kV.
const FLOW_SHARE: f64 = 0.05;

/// Duration of a run of consecutive non-finite samples in one column from which it is
/// reported whatever its share: 1 ms (10 samples at 10 kHz). A glitching ADC gives single
/// samples; a run is a gap in the logger, over which the estimator coasts on its speed
/// estimate with no flux measured.
const BURST_SECONDS: f64 = 1e-3;

/// The non-finite samples of `c`: (their count, the first sample and the length of their
/// longest run), in one pass.
fn count_non_finite(
    c: &[f64],
    cancel: Option<&AtomicBool>,
) -> Result<(usize, (usize, usize)), Cancelled> {
    let (mut bad, mut best, mut start, mut len) = (0, (0, 0), 0, 0);
    for (k, x) in c.iter().enumerate() {
        poll_at(cancel, k)?;
        if x.is_finite() {
            len = 0;
            continue;
        }
        bad += 1;
        if len == 0 {
            start = k;
        }
        len += 1;
        if len > best.1 {
            best = (start, len);
        }
    }
    Ok((bad, best))
}

/// The non-finite samples of column `k`: a finding when they are over [`REFUSED_SHARE`] of
/// the samples or a run of them lasts [`BURST_SECONDS`] or more (`ts` the sampling period).
fn non_finite(
    c: &[f64],
    k: usize,
    ts: f64,
    cancel: Option<&AtomicBool>,
    out: &mut Vec<String>,
) -> Result<(), Cancelled> {
    let n = c.len();
    let (bad, (first, run)) = count_non_finite(c, cancel)?;
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
    Ok(())
}

/// The samples of `c` as f64: float64 columns borrowed, float32 ones converted.
fn values<'a>(
    c: ColumnSlice<'a>,
    cancel: Option<&AtomicBool>,
) -> Result<Cow<'a, [f64]>, Cancelled> {
    match c {
        ColumnSlice::F64(x) => Ok(Cow::Borrowed(x)),
        ColumnSlice::F32(x) => {
            let mut v = Vec::with_capacity(x.len());
            for (k, &s) in x.iter().enumerate() {
                poll_at(cancel, k)?;
                v.push(f64::from(s));
            }
            Ok(Cow::Owned(v))
        }
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

/// The findings on the columns `signals` (v_α, v_β, i_α, i_β) against the estimator's
/// `bounds`, its machine `m` sampled every `ts` and start angle `theta0`, as texts (empty:
/// nothing unusual); Err once `cancel` is set (looked at every
/// [`fado_sim::sim::CANCEL_CHECK_SAMPLES`] samples of each pass).
pub fn findings(
    signals: [ColumnSlice<'_>; 4],
    bounds: &SampleBounds<f64>,
    m: &MachineModel<f64>,
    ts: f64,
    theta0: Option<f64>,
    cancel: Option<&AtomicBool>,
) -> Result<Vec<String>, Cancelled> {
    let mut out = Vec::new();
    if let Some(t) = theta0.filter(|t| t.abs() > std::f64::consts::TAU) {
        out.push(format!(
            "theta0 = {t} rad is more than a turn: degrees where radians are meant \
             ({:.4} rad)?",
            t.to_radians()
        ));
    }
    if signals[0].is_empty() {
        return Ok(out);
    }
    let [va, vb, ia, ib] = signals;
    let owned = [
        values(va, cancel)?,
        values(vb, cancel)?,
        values(ia, cancel)?,
        values(ib, cancel)?,
    ];
    let cols: [&[f64]; 4] = [&owned[0], &owned[1], &owned[2], &owned[3]];
    for (k, c) in cols.iter().enumerate() {
        non_finite(c, k, ts, cancel, &mut out)?;
    }
    constant_columns(&cols, cancel, &mut out)?;
    magnitudes(&cols, bounds, m, cancel, &mut out)?;
    out.extend(crate::recording_model::findings(&cols, m, ts, cancel)?);
    Ok(out)
}

/// The lowest finite sample of `c` and the spread of its finite samples.
fn spread(c: &[f64], cancel: Option<&AtomicBool>) -> Result<(f64, f64), Cancelled> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (k, &x) in c.iter().enumerate() {
        poll_at(cancel, k)?;
        if x.is_finite() {
            lo = lo.min(x);
            hi = hi.max(x);
        }
    }
    Ok((lo, hi - lo))
}

/// A column whose every finite sample is equal while its partner's vary.
fn constant_columns(
    cols: &[&[f64]; 4],
    cancel: Option<&AtomicBool>,
    out: &mut Vec<String>,
) -> Result<(), Cancelled> {
    let spreads = [
        spread(cols[0], cancel)?,
        spread(cols[1], cancel)?,
        spread(cols[2], cancel)?,
        spread(cols[3], cancel)?,
    ];
    for (k, partner) in [(0, 1), (1, 0), (2, 3), (3, 2)] {
        let (value, s) = spreads[k];
        let (_, sp) = spreads[partner];
        if cols[k].len() >= 100 && s == 0.0 && sp > 0.0 {
            out.push(format!(
                "`{}` is {value} in every sample while `{}` varies: a dead channel, or a \
                 column given twice?",
                SIGNAL_NAMES[k], SIGNAL_NAMES[partner]
            ));
        }
    }
    Ok(())
}

/// What [`magnitudes`] reads from one pass over a pair of columns.
#[derive(Default)]
struct Magnitude {
    /// The largest finite |x + jy|.
    max: f64,
    /// Samples with |x + jy| at or above the bound.
    over: usize,
    /// The largest finite |x + jy| below the bound.
    max_below: f64,
}

/// The magnitudes |x + jy| of the pair `x`, `y` against `bound`, in one pass.
fn magnitude(
    x: &[f64],
    y: &[f64],
    bound: f64,
    cancel: Option<&AtomicBool>,
) -> Result<Magnitude, Cancelled> {
    let mut m = Magnitude::default();
    for (k, (a, b)) in x.iter().zip(y).enumerate() {
        poll_at(cancel, k)?;
        let r = a.hypot(*b);
        if !r.is_finite() {
            continue;
        }
        m.max = m.max.max(r);
        if r >= bound {
            m.over += 1;
        } else {
            m.max_below = m.max_below.max(r);
        }
    }
    Ok(m)
}

/// Current and voltage magnitudes against the bounds and against each other.
fn magnitudes(
    cols: &[&[f64]; 4],
    b: &SampleBounds<f64>,
    m: &MachineModel<f64>,
    cancel: Option<&AtomicBool>,
    out: &mut Vec<String>,
) -> Result<(), Cancelled> {
    let n = cols[0].len() as f64;
    let i = magnitude(cols[2], cols[3], b.current(), cancel)?;
    let v = magnitude(cols[0], cols[1], b.voltage(), cancel)?;
    let (i_max, v_max) = (i.max, v.max);
    if i.over as f64 > REFUSED_SHARE * n {
        let hint = if i_max > 100.0 * b.current() {
            "a current in mA where A is meant"
        } else {
            "the voltage columns in the current slots, or `rated_current` too small"
        };
        out.push(format!(
            "{:.1} % of the samples have |i| (`i_alpha`, `i_beta`) at or above the plausible \
             {:.4} A (4 × `rated_current`; max {i_max:.4e} A) and are refused as measurement \
             faults: {hint}?",
            100.0 * i.over as f64 / n,
            b.current()
        ));
    }
    if v.over as f64 > REFUSED_SHARE * n {
        out.push(format!(
            "{:.1} % of the samples have |v| (`v_alpha`, `v_beta`) at or above the plausible \
             {:.4} V (1.5 × `dc_voltage`; max {v_max:.4e} V) and are refused as measurement \
             faults: a voltage in mV where V is meant, or the current columns in the voltage \
             slots?",
            100.0 * v.over as f64 / n,
            b.voltage()
        ));
    }
    let drop = m.rs * i.max_below;
    if i.max_below >= FLOW_SHARE * m.rated_current && v_max < 0.1 * drop {
        out.push(format!(
            "the voltages (`v_alpha`, `v_beta`) reach {v_max:.4e} V only, a tenth of the \
             resistive drop R̂s·|i| = {drop:.4e} V of the currents alone: a voltage in kV \
             where V is meant, or the voltage and current columns exchanged?"
        ));
    }
    Ok(())
}

/// [`findings`] issued as warnings; the passes run with the GIL released and stop on Ctrl-C
/// ([`interrupt::run`], which then raises `KeyboardInterrupt`).
pub fn warn_all(
    py: Python<'_>,
    signals: [ColumnSlice<'_>; 4],
    bounds: &SampleBounds<f64>,
    m: &MachineModel<f64>,
    ts: f64,
    theta0: Option<f64>,
) -> PyResult<()> {
    let texts = interrupt::run(py, |cancel| {
        findings(signals, bounds, m, ts, theta0, Some(cancel.as_ref()))
    })?;
    // Err only when cancelled, and then `interrupt::run` raised.
    let texts = texts.map_err(|Cancelled| {
        pyo3::exceptions::PyKeyboardInterrupt::new_err("estimate interrupted")
    })?;
    for text in texts {
        warn(py, &text)?;
    }
    Ok(())
}
