//! The inverter's and DC link's parameters: switching, dead time, threshold drops, the
//! commutation model and the DC voltage profile.

use serde::{Deserialize, Serialize};

use crate::error::{SimConfigError, check};

use super::{Commutation, InverterModel, sat};

/// Inverter and DC-link parameter record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InverterParams {
    /// Which model to run. Default switching-resolved.
    pub model: InverterModel,
    /// Mean DC-link voltage in V. Default 311 V (rectified 3-phase 220 Vrms, paper §V \[P\];
    /// docs/method/estimator.md §7 says ≈ 300 V \[A\]).
    pub dc_voltage: f64,
    /// Peak amplitude of the DC-link ripple in V (sinusoidal model). Default 0 \[A\].
    pub dc_ripple_amplitude: f64,
    /// Ripple frequency in Hz. Default 360 Hz (6-pulse rectifier on 60 Hz) \[A\].
    pub dc_ripple_frequency: f64,
    /// Switching (carrier) frequency in Hz; sampling is at twice this. Default 5 kHz (paper §V
    /// \[P\]).
    pub switching_frequency: f64,
    /// Dead time Td in s. Default 2.5 µs (paper §V \[P\]).
    pub dead_time: f64,
    /// Current band Ic in A over which the dead-time and threshold errors go through zero
    /// (parasitic capacitance). Default 0.3 A (docs/method/estimator.md §7 \[A\]).
    pub current_band: f64,
    /// Commutation model of the helping edge (switching-resolved model). Default the docs/method/estimator.md §7
    /// linear band.
    pub commutation: Commutation,
    /// Device threshold (knee) voltage V_th in V, IGBT and diode alike. Default 1 V (docs/method/estimator.md §7 \[A\]).
    pub threshold_voltage: f64,
    /// Device on-resistance r_on in Ω. Default 0 \[A\]: a linear drop is indistinguishable from
    /// Rs, so a non-zero value is an R̂s mismatch of the same size.
    pub on_resistance: f64,
}

impl Default for InverterParams {
    fn default() -> Self {
        Self {
            model: InverterModel::SwitchingResolved,
            dc_voltage: 311.0,
            dc_ripple_amplitude: 0.0,
            dc_ripple_frequency: 360.0,
            switching_frequency: 5000.0,
            dead_time: 2.5e-6,
            current_band: 0.3,
            commutation: Commutation::LinearBand,
            threshold_voltage: 1.0,
            on_resistance: 0.0,
        }
    }
}

/// Largest device threshold (knee) voltage as a fraction of the DC link: 0.1 (the paper
/// inverter's 1 V of 311 V is 0.3 %; a tenth of the DC link lost at every current reversal
/// leaves a drive no voltage to control with).
pub const MAX_THRESHOLD_DC_RATIO: f64 = 0.1;

impl InverterParams {
    /// Checks every field; the error names the key.
    pub fn validate(&self) -> Result<(), SimConfigError> {
        check::positive("dc_voltage", self.dc_voltage)?;
        check::in_range(
            "dc_ripple_amplitude",
            self.dc_ripple_amplitude,
            0.0,
            0.5 * self.dc_voltage,
        )?;
        check::non_negative("dc_ripple_frequency", self.dc_ripple_frequency)?;
        check::in_range("switching_frequency", self.switching_frequency, 100.0, 1e6)?;
        let half_period = 0.5 / self.switching_frequency;
        check::in_range("dead_time", self.dead_time, 0.0, 0.25 * half_period)?;
        check::positive("current_band", self.current_band)?;
        // A device's knee voltage is volts against a DC link of tens to thousands: a tenth
        // of the DC link is already beyond any bridge (the drive would lose its voltage).
        check::in_range(
            "threshold_voltage",
            self.threshold_voltage,
            0.0,
            MAX_THRESHOLD_DC_RATIO * self.dc_voltage,
        )?;
        check::non_negative("on_resistance", self.on_resistance)?;
        Ok(())
    }

    /// Sampling period Ts = 1/(2·f_sw) (double update).
    pub fn sample_period(&self) -> f64 {
        0.5 / self.switching_frequency
    }

    /// DC-link voltage at time `t`.
    pub fn dc_voltage_at(&self, t: f64) -> f64 {
        if self.dc_ripple_amplitude == 0.0 {
            return self.dc_voltage;
        }
        self.dc_voltage
            + self.dc_ripple_amplitude
                * (std::f64::consts::TAU * self.dc_ripple_frequency * t).cos()
    }

    /// Equivalent pole capacitance C = Ic·Td/(2·Vdc) of [`Commutation::Capacitor`].
    pub fn pole_capacitance(&self) -> f64 {
        self.current_band * self.dead_time / (2.0 * self.dc_voltage)
    }

    /// Delay from the gate command to the equivalent pole-voltage step for one edge
    /// (switching-resolved model, see the module docs). `rising` = low → high, `i` the phase
    /// current (positive out of the inverter) at the edge, `vdc` the DC-link voltage.
    pub fn edge_delay(&self, rising: bool, i: f64, vdc: f64) -> f64 {
        let td = self.dead_time;
        let opposes = if rising { i > 0.0 } else { i < 0.0 };
        if opposes || td == 0.0 {
            return td;
        }
        let ia = i.abs();
        match self.commutation {
            Commutation::LinearBand => td * (1.0 - ia / self.current_band).max(0.0),
            Commutation::Capacitor => {
                // Ramp time t_r = C·Vdc/|i|; compare Td/t_r = Td·|i|/(C·Vdc).
                let ratio = td * ia / (self.pole_capacitance() * vdc);
                if ratio <= 1.0 {
                    td * (1.0 - 0.5 * ratio)
                } else {
                    0.5 * td / ratio
                }
            }
        }
    }

    /// Average pole-voltage error of the averaged model for phase current `i` and the leg's
    /// `duty` (docs/method/estimator.md §7): −(Td·f_sw·Vdc + V_th)·sat(i/Ic) on a leg that
    /// switches, −V_th·sat(i/Ic) on one held at duty 0 or 1 (no edge, no dead time).
    pub fn averaged_error(&self, i: f64, vdc: f64, duty: f64) -> f64 {
        let dead = if duty > 0.0 && duty < 1.0 {
            self.dead_time * self.switching_frequency * vdc
        } else {
            0.0
        };
        -(dead + self.threshold_voltage) * sat(i / self.current_band)
    }
}
