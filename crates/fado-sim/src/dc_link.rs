//! The DC link behind the inverter: a source, the link capacitor and an optional brake chopper.
//!
//! ```text
//!   source E ──R──┬──────┬──────── inverter (draws i_inv = P / v)
//!                 │      │
//!                 C    chopper (R_ch, on above chopper_voltage)
//! ```
//!
//! * `stiff` (default): v = E (`[inverter] dc_voltage`, its ripple and a fault's dip), whatever
//!   the inverter draws or returns; the capacitor and chopper are not modelled.
//! * `battery`: E behind `internal_resistance`; it takes regenerated power back.
//! * `rectifier`: E behind `internal_resistance` through a diode bridge: current flows only
//!   from the source (a regenerating drive charges the capacitor until it stops, a chopper
//!   burns the energy, or the bus trips).
//!
//! The inverter's DC current is its AC power over the bus voltage, `i_inv = 1.5·v_αβ·i_αβ / v`
//! (amplitude-invariant Clarke, peak values; the switching devices' losses are in the
//! machine-side voltage), held over one sample. The linear part of
//! `C·dv/dt = (E − v)/R − v/R_ch − i_inv` is advanced exactly over the sample (the link's
//! time constant R·C is often shorter than the 100 µs sample, where forward Euler would be
//! unstable); the bridge and the chopper switch at sample boundaries.

use serde::{Deserialize, Serialize};

use crate::error::{SimConfigError, check};

/// What feeds the DC link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DcSource {
    /// An ideal voltage source: the bus voltage is `[inverter] dc_voltage`.
    #[default]
    Stiff,
    /// A battery: `dc_voltage` behind `internal_resistance`, bidirectional.
    Battery,
    /// A diode rectifier: `dc_voltage` behind `internal_resistance`, motoring only.
    Rectifier,
}

/// `[dc_link]`: the source, capacitor and brake chopper.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DcLinkParams {
    /// What feeds the link. Default stiff.
    pub source: DcSource,
    /// Link capacitance, F. Default: the capacitor holds [`HOLD_UP_TIME`] of the motor's
    /// rated power at `dc_voltage` (C = 2·P·t/V²).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capacitance: Option<f64>,
    /// Source resistance (battery internal resistance, or the line and rectifier's), Ω.
    /// Default: a [`SOURCE_DROP_RATIO`] drop of `dc_voltage` at the rated power
    /// (R = ratio·V²/P).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub internal_resistance: Option<f64>,
    /// The brake chopper switches its resistor on above this bus voltage, V (and off again
    /// [`CHOPPER_HYSTERESIS_RATIO`] below it). Default none: no chopper.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub chopper_voltage: Option<f64>,
    /// Brake resistor, Ω. Default: it takes 1.5 × the rated power at `chopper_voltage`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub chopper_resistance: Option<f64>,
}

impl Default for DcLinkParams {
    fn default() -> Self {
        Self {
            source: DcSource::Stiff,
            capacitance: None,
            internal_resistance: None,
            chopper_voltage: None,
            chopper_resistance: None,
        }
    }
}

/// Default capacitor hold-up time at rated power, s: 5 ms \[A\] (a bulk capacitor of
/// 100–200 µF/kW at 300–600 V, the range of industrial drives, stores 2.5–20 ms).
pub const HOLD_UP_TIME: f64 = 5e-3;
/// Default source drop at rated power, fraction of the source voltage: 5 % \[A\] (a battery's
/// internal resistance, or a rectifier's line impedance, at its rated current).
pub const SOURCE_DROP_RATIO: f64 = 0.05;
/// The chopper switches off this fraction of `chopper_voltage` below it: 2 % \[A\].
pub const CHOPPER_HYSTERESIS_RATIO: f64 = 0.02;
/// Default chopper resistor: it dissipates this × the rated power at `chopper_voltage` \[A\].
pub const CHOPPER_POWER_RATIO: f64 = 1.5;

impl DcLinkParams {
    /// Checks every field; the error names the key.
    pub fn validate(&self) -> Result<(), SimConfigError> {
        if let Some(c) = self.capacitance {
            check::positive("capacitance", c)?;
        }
        if let Some(r) = self.internal_resistance {
            check::positive("internal_resistance", r)?;
        }
        if let Some(v) = self.chopper_voltage {
            check::positive("chopper_voltage", v)?;
        }
        if let Some(r) = self.chopper_resistance {
            check::positive("chopper_resistance", r)?;
        }
        Ok(())
    }

    /// The resolved values for a source of `dc_voltage` (V) and a motor of rated power
    /// `rated_power` (W): (C, R, chopper on-voltage, chopper R).
    pub fn resolve(&self, dc_voltage: f64, rated_power: f64) -> (f64, f64, Option<f64>, f64) {
        let v2 = dc_voltage * dc_voltage;
        let c = self
            .capacitance
            .unwrap_or(2.0 * rated_power * HOLD_UP_TIME / v2);
        let r = self
            .internal_resistance
            .unwrap_or(SOURCE_DROP_RATIO * v2 / rated_power);
        let r_ch = self.chopper_resistance.unwrap_or_else(|| {
            let vc = self.chopper_voltage.unwrap_or(dc_voltage);
            vc * vc / (CHOPPER_POWER_RATIO * rated_power)
        });
        (c, r, self.chopper_voltage, r_ch)
    }
}

/// The DC link's state.
#[derive(Clone, Debug)]
pub struct DcLink {
    source: DcSource,
    capacitance: f64,
    resistance: f64,
    chopper_on_voltage: Option<f64>,
    chopper_resistance: f64,
    voltage: f64,
    chopper_on: bool,
}

impl DcLink {
    /// A link at `dc_voltage` (V), sized for a motor of rated power `rated_power` (W).
    pub fn new(
        params: &DcLinkParams,
        dc_voltage: f64,
        rated_power: f64,
    ) -> Result<Self, SimConfigError> {
        params.validate()?;
        let (c, r, v_ch, r_ch) = params.resolve(dc_voltage, rated_power);
        Ok(Self {
            source: params.source,
            capacitance: c,
            resistance: r,
            chopper_on_voltage: v_ch,
            chopper_resistance: r_ch,
            voltage: dc_voltage,
            chopper_on: false,
        })
    }

    /// The link is an ideal source (the bus voltage is the source's).
    pub fn is_stiff(&self) -> bool {
        self.source == DcSource::Stiff
    }

    /// Bus voltage, V.
    pub fn voltage(&self) -> f64 {
        self.voltage
    }

    /// The chopper's resistor is on.
    pub fn chopper_on(&self) -> bool {
        self.chopper_on
    }

    /// Advances the link by `ts` with the source at `source_voltage` (V) while the inverter
    /// takes `power` (W, negative when the machine regenerates); returns the bus voltage.
    pub fn step(&mut self, source_voltage: f64, power: f64, ts: f64) -> f64 {
        if self.is_stiff() {
            self.voltage = source_voltage;
            return self.voltage;
        }
        let v = self.voltage;
        if let Some(von) = self.chopper_on_voltage {
            if v > von {
                self.chopper_on = true;
            } else if v < von * (1.0 - CHOPPER_HYSTERESIS_RATIO) {
                self.chopper_on = false;
            }
        }
        let i_inv = if power.is_finite() {
            power / v.max(1e-3 * source_voltage)
        } else {
            0.0
        };
        let g_ch = if self.chopper_on {
            1.0 / self.chopper_resistance
        } else {
            0.0
        };
        let g_s = 1.0 / self.resistance;
        let next = |g_source: f64| -> f64 {
            let g = g_source + g_ch;
            if g > 0.0 {
                let v_inf = (g_source * source_voltage - i_inv) / g;
                v_inf + (v - v_inf) * (-ts * g / self.capacitance).exp()
            } else {
                v - ts * i_inv / self.capacitance
            }
        };
        self.voltage = match self.source {
            DcSource::Stiff => source_voltage,
            DcSource::Battery => next(g_s),
            DcSource::Rectifier => {
                // The bridge conducts while the bus is below the source, and blocks above it;
                // a crossing within the sample is settled at the source voltage.
                let (conducting, blocked) = (next(g_s), next(0.0));
                let e = source_voltage;
                match (v <= e, conducting <= e, blocked >= e) {
                    (true, true, _) => conducting,
                    (true, false, _) => blocked.max(e),
                    (false, _, true) => blocked,
                    (false, _, false) => conducting.max(blocked),
                }
            }
        }
        .max(0.0);
        self.voltage
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn link(source: DcSource) -> DcLink {
        let p = DcLinkParams {
            source,
            capacitance: Some(1e-3),
            internal_resistance: Some(0.5),
            ..Default::default()
        };
        DcLink::new(&p, 300.0, 2000.0).unwrap()
    }

    #[test]
    fn battery_sags_under_load_and_rises_when_charged() {
        let mut b = link(DcSource::Battery);
        for _ in 0..1000 {
            b.step(300.0, 3000.0, 1e-4);
        }
        // Steady state: v = E − R·P/v, i.e. v² − E·v + R·P = 0.
        let v = 0.5 * (300.0 + (300.0f64 * 300.0 - 4.0 * 0.5 * 3000.0).sqrt());
        assert!((b.voltage() - v).abs() < 1e-6, "{} vs {v}", b.voltage());
        for _ in 0..1000 {
            b.step(300.0, -3000.0, 1e-4);
        }
        assert!(
            b.voltage() > 300.0 && b.voltage() < 306.0,
            "{}",
            b.voltage()
        );
    }

    #[test]
    fn rectifier_takes_no_regenerated_power() {
        let mut r = link(DcSource::Rectifier);
        // 1 kW regenerated for 10 ms into 1 mF: ½·C·(v² − E²) = 10 J.
        for _ in 0..100 {
            r.step(300.0, -1000.0, 1e-4);
        }
        let v = (300.0f64 * 300.0 + 2.0 * 10.0 / 1e-3).sqrt();
        assert!((r.voltage() - v).abs() < 0.3, "{} vs {v}", r.voltage());
        // Motoring again, it comes back to the source level (minus the drop).
        for _ in 0..2000 {
            r.step(300.0, 1000.0, 1e-4);
        }
        assert!(
            r.voltage() < 300.0 && r.voltage() > 297.0,
            "{}",
            r.voltage()
        );
    }

    #[test]
    fn chopper_holds_the_bus_below_its_voltage_band() {
        let p = DcLinkParams {
            source: DcSource::Rectifier,
            capacitance: Some(1e-3),
            internal_resistance: Some(0.5),
            chopper_voltage: Some(380.0),
            chopper_resistance: Some(40.0),
        };
        let mut r = DcLink::new(&p, 300.0, 2000.0).unwrap();
        let mut vmax: f64 = 0.0;
        // 2 kW regenerated for 1 s: 2 kJ would take 1 mF to 2 kV without the chopper.
        for _ in 0..10_000 {
            vmax = vmax.max(r.step(300.0, -2000.0, 1e-4));
        }
        // 380²/40 = 3.6 kW > 2 kW: it never passes the on-voltage by more than a sample's
        // charge (2000/380 A × 100 µs / 1 mF = 0.5 V).
        assert!(vmax < 381.0 && vmax > 370.0, "{vmax}");
    }

    #[test]
    fn stiff_link_is_the_source() {
        let mut s = DcLink::new(&DcLinkParams::default(), 311.0, 1806.0).unwrap();
        assert_eq!(s.step(311.0, -5000.0, 1e-4), 311.0);
        assert_eq!(s.step(300.0, 5000.0, 1e-4), 300.0);
        let (c, r, _, _) = DcLinkParams::default().resolve(311.0, 1806.0);
        // 5 ms of 1.8 kW at 311 V: 187 µF; 5 % drop: 2.68 Ω.
        assert!((c - 186.8e-6).abs() < 1e-7, "{c}");
        assert!((r - 2.678).abs() < 1e-3, "{r}");
    }
}
