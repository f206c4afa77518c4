//! Fault injection (`[faults]`): what goes wrong in a real drive's measurement chain and supply,
//! applied by the plant at the sample it concerns.
//!
//! * `[[faults.non_finite]]`: a sample of a phase-current channel or of the DC-link sensor
//!   replaced by NaN, +∞ or −∞ (a broken ADC read, a division by zero in a driver) for
//!   `samples` samples from `time` on.
//! * `[[faults.stuck_current]]`: a current-sensor channel (a or b) that reads `value`
//!   (default 0 A) over `[start, start + duration)` (default 10 ms): a loose connector or a
//!   sensor supply drop-out. Phase c is reconstructed from the stuck reading as −a − b, as the
//!   drive's two-sensor hardware does.
//! * `voltage_offset = [α, β]`: a constant stationary-frame voltage error in V, added to the
//!   voltage the drive (and so its estimator) believes it applies — a phase-voltage or DC-link
//!   measurement offset, an uncompensated inverter asymmetry. The plant receives the
//!   inverter's voltage minus it while the gates are enabled.
//! * `[faults.dc_link_scale]`: the DC-link voltage as a fraction of its nominal value over
//!   time, a piecewise-linear [`Profile`] (steps or ramps): a supply dip. It scales the
//!   voltage the inverter applies and what the DC-link sensor reads alike.
//!
//! A sudden load step is not a fault of the drive's own chain: it is a `[load] torque`
//! profile with two points at the same time.
//!
//! ```toml
//! [faults]
//! voltage_offset = [0.1, 0.0]
//!
//! [[faults.non_finite]]
//! time = 2.0
//! signal = "current_a"   # current_a | current_b | dc_link
//! value = "nan"          # nan | inf | neg_inf
//! samples = 1
//!
//! [[faults.stuck_current]]
//! channel = "a"          # a | b
//! start = 2.5
//! duration = 0.01
//!
//! [faults.dc_link_scale]
//! points = [[3.0, 1.0], [3.01, 0.5], [3.2, 0.5], [3.21, 1.0]]
//! ```

use fado_core::Abc;
use serde::{Deserialize, Serialize};

use crate::error::{SimConfigError, check};
use crate::profile::Profile;

/// Which measured signal a non-finite fault replaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultSignal {
    /// The phase-a current channel (and the reconstructed phase c).
    CurrentA,
    /// The phase-b current channel (and the reconstructed phase c).
    CurrentB,
    /// The DC-link voltage sensor.
    DcLink,
}

/// The non-finite value injected.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NonFiniteValue {
    /// NaN. Default.
    #[default]
    Nan,
    /// +∞.
    Inf,
    /// −∞.
    NegInf,
}

impl NonFiniteValue {
    fn value(self) -> f64 {
        match self {
            NonFiniteValue::Nan => f64::NAN,
            NonFiniteValue::Inf => f64::INFINITY,
            NonFiniteValue::NegInf => f64::NEG_INFINITY,
        }
    }
}

fn one() -> u32 {
    1
}

fn ten_ms() -> f64 {
    0.01
}

/// Non-finite samples fed to the drive.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NonFiniteFault {
    /// From the first sample at or after this time, s.
    pub time: f64,
    /// Which measurement.
    pub signal: FaultSignal,
    /// NaN or ±∞. Default NaN.
    #[serde(default)]
    pub value: NonFiniteValue,
    /// Consecutive samples replaced (≥ 1). Default 1.
    #[serde(default = "one")]
    pub samples: u32,
}

/// A phase-current channel of the two-sensor set-up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CurrentChannel {
    /// Phase a.
    A,
    /// Phase b.
    B,
}

/// A current-sensor channel stuck at a value over a window.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StuckCurrentFault {
    /// Which channel.
    pub channel: CurrentChannel,
    /// Start of the fault, s.
    pub start: f64,
    /// Length of the fault, s. Default 10 ms.
    #[serde(default = "ten_ms")]
    pub duration: f64,
    /// The reading while stuck, A. Default 0.
    #[serde(default)]
    pub value: f64,
}

/// The `[faults]` section. Default: no fault.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FaultParams {
    /// DC-link voltage as a fraction of its nominal value over time (plant and sensor).
    /// Default constant 1.
    pub dc_link_scale: Profile,
    /// Non-finite samples.
    pub non_finite: Vec<NonFiniteFault>,
    /// Stuck current-sensor channels.
    pub stuck_current: Vec<StuckCurrentFault>,
    /// Constant α-β voltage error of the drive's voltage, V (the true voltage is the drive's
    /// minus this). Default [0, 0].
    pub voltage_offset: [f64; 2],
}

impl Default for FaultParams {
    fn default() -> Self {
        Self {
            dc_link_scale: Profile::constant(1.0),
            non_finite: Vec::new(),
            stuck_current: Vec::new(),
            voltage_offset: [0.0, 0.0],
        }
    }
}

impl FaultParams {
    /// Checks every entry; the error names the key (`non_finite[1].samples`).
    pub fn validate(&self) -> Result<(), SimConfigError> {
        self.dc_link_scale
            .validate()
            .map_err(|e| e.in_section("dc_link_scale"))?;
        for (k, p) in self.dc_link_scale.points.iter().enumerate() {
            if !(p[1] > 0.0 && p[1] <= 2.0) {
                return Err(SimConfigError::new(
                    format!("dc_link_scale.points[{k}]"),
                    "the scale must be in (0, 2]",
                ));
            }
        }
        for (k, v) in self.voltage_offset.iter().enumerate() {
            check::finite("voltage_offset", *v)
                .map_err(|e| SimConfigError::new(format!("voltage_offset[{k}]"), e.message))?;
        }
        for (k, f) in self.non_finite.iter().enumerate() {
            let key = |field: &str| format!("non_finite[{k}].{field}");
            check::non_negative("time", f.time)
                .map_err(|e| SimConfigError::new(key("time"), e.message))?;
            if !(1..=1_000_000).contains(&f.samples) {
                return Err(SimConfigError::new(
                    key("samples"),
                    "must be in 1..=1000000",
                ));
            }
        }
        for (k, f) in self.stuck_current.iter().enumerate() {
            let key = |field: &str| format!("stuck_current[{k}].{field}");
            check::non_negative("start", f.start)
                .map_err(|e| SimConfigError::new(key("start"), e.message))?;
            check::positive("duration", f.duration)
                .map_err(|e| SimConfigError::new(key("duration"), e.message))?;
            check::finite("value", f.value)
                .map_err(|e| SimConfigError::new(key("value"), e.message))?;
        }
        Ok(())
    }

    /// True when no fault is configured.
    pub fn is_empty(&self) -> bool {
        self.non_finite.is_empty()
            && self.stuck_current.is_empty()
            && self.dc_link_scale.points.iter().all(|p| p[1] == 1.0)
            && self.voltage_offset == [0.0, 0.0]
    }
}

/// The faults of a run, applied sample by sample.
#[derive(Clone, Debug)]
pub struct Faults {
    params: FaultParams,
    ts: f64,
    scale_cursor: usize,
}

impl Faults {
    /// Faults for a plant sampled every `ts` seconds.
    pub fn new(params: FaultParams, ts: f64) -> Result<Self, SimConfigError> {
        params.validate()?;
        Ok(Self {
            params,
            ts,
            scale_cursor: 0,
        })
    }

    /// The constant α-β voltage error of the drive's voltage, V.
    pub fn voltage_offset(&self) -> fado_core::Ab<f64> {
        fado_core::Ab::new(self.params.voltage_offset[0], self.params.voltage_offset[1])
    }

    /// The parameters.
    pub fn params(&self) -> &FaultParams {
        &self.params
    }

    /// DC-link scale at time `t` (non-decreasing along a run).
    pub fn dc_link_scale(&mut self, t: f64) -> f64 {
        self.params
            .dc_link_scale
            .value_from(t, &mut self.scale_cursor)
    }

    /// The sensor readings at time `t` after the faults: the phase currents (a, b measured,
    /// c = −a − b) and the DC-link voltage.
    pub fn corrupt(&self, t: f64, i: Abc<f64>, vdc: f64) -> (Abc<f64>, f64) {
        let (mut a, mut b, mut vdc) = (i.a, i.b, vdc);
        let mut changed = false;
        for f in &self.params.stuck_current {
            if t >= f.start && t < f.start + f.duration {
                match f.channel {
                    CurrentChannel::A => a = f.value,
                    CurrentChannel::B => b = f.value,
                }
                changed = true;
            }
        }
        let n = (t / self.ts).round();
        for f in &self.params.non_finite {
            let first = (f.time / self.ts - 1e-9).ceil();
            if n >= first && n < first + f.samples as f64 {
                let v = f.value.value();
                match f.signal {
                    FaultSignal::CurrentA => a = v,
                    FaultSignal::CurrentB => b = v,
                    FaultSignal::DcLink => vdc = v,
                }
                changed = true;
            }
        }
        if changed {
            (Abc::new(a, b, -a - b), vdc)
        } else {
            (i, vdc)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> FaultParams {
        FaultParams {
            dc_link_scale: Profile::from_points(&[(1.0, 1.0), (1.0, 0.5), (1.2, 0.5), (1.2, 1.0)]),
            non_finite: vec![NonFiniteFault {
                time: 0.5,
                signal: FaultSignal::DcLink,
                value: NonFiniteValue::Inf,
                samples: 3,
            }],
            stuck_current: vec![StuckCurrentFault {
                channel: CurrentChannel::B,
                start: 2.0,
                duration: 0.01,
                value: 0.0,
            }],
            voltage_offset: [0.0, 0.0],
        }
    }

    #[test]
    fn voltage_offset_is_a_fault_and_must_be_finite() {
        let mut p = FaultParams {
            voltage_offset: [0.1, 0.0],
            ..FaultParams::default()
        };
        assert!(!p.is_empty());
        let f = Faults::new(p.clone(), 1e-4).unwrap();
        assert_eq!(f.voltage_offset(), fado_core::Ab::new(0.1, 0.0));
        p.voltage_offset[1] = f64::NAN;
        assert_eq!(p.validate().unwrap_err().key, "voltage_offset[1]");
    }

    #[test]
    fn faults_act_exactly_on_their_samples() {
        let ts = 1e-4;
        let mut f = Faults::new(params(), ts).unwrap();
        let i = Abc::new(3.0, -1.0, -2.0);
        // Non-finite DC link on samples 5000, 5001, 5002 only.
        for n in 4998..5005 {
            let t = n as f64 * ts;
            let (io, v) = f.corrupt(t, i, 300.0);
            assert_eq!(io, i);
            assert_eq!(v.is_infinite(), (5000..5003).contains(&n), "n = {n}");
        }
        // Stuck b over [2.0, 2.01): 100 samples; c follows as −a − b.
        let stuck = (19_990..20_110)
            .filter(|&n| f.corrupt(n as f64 * ts, i, 300.0).0.b == 0.0)
            .count();
        assert_eq!(stuck, 100);
        assert_eq!(f.corrupt(2.005, i, 300.0).0, Abc::new(3.0, 0.0, -3.0));
        // DC-link dip to half over [1.0, 1.2).
        assert_eq!(f.dc_link_scale(0.9), 1.0);
        assert_eq!(f.dc_link_scale(1.1), 0.5);
        assert_eq!(f.dc_link_scale(1.3), 1.0);
        assert!(!f.params().is_empty() && FaultParams::default().is_empty());
    }

    #[test]
    fn validation_names_the_entry() {
        let mut p = params();
        p.stuck_current[0].duration = 0.0;
        assert_eq!(p.validate().unwrap_err().key, "stuck_current[0].duration");
        let mut p = params();
        p.non_finite[0].samples = 0;
        assert_eq!(p.validate().unwrap_err().key, "non_finite[0].samples");
        let mut p = params();
        p.non_finite[0].time = f64::NAN;
        assert_eq!(p.validate().unwrap_err().key, "non_finite[0].time");
        let mut p = params();
        p.dc_link_scale = Profile::constant(0.0);
        assert_eq!(p.validate().unwrap_err().key, "dc_link_scale.points[0]");
    }
}
