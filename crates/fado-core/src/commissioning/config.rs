//! [`CommissioningConfig`]: the nameplate, the sampling period, the dead time and the
//! procedure's settings.

use crate::control::gain_calibration::DEFAULT_MAX_MISMATCH;
use crate::error::{ConfigError, check};
use crate::{MachineModel, Real};

/// Configuration. Build it with [`CommissioningConfig::for_machine`]; every default is a ratio
/// of a rating or a duration in seconds (the brief's rule), stated on its field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommissioningConfig<T: 'static> {
    /// The nameplate: ratings trusted, parameters rough (module docs). Required.
    pub nameplate: MachineModel<T>,
    /// Sampling (control) period Ts in s. Required.
    pub sample_period: T,
    /// Switching frequency in Hz (for V_th = V̂ − Td·f_sw·Vdc). Default 1/(2·Ts), double
    /// update (paper §V).
    pub switching_frequency: T,
    /// The inverter's dead time Td in s (a firmware setting). Required.
    pub dead_time: T,
    /// Current limit as a fraction of the rated current. Default 0.5 (half the rated current:
    /// the tests heat the winding at most a quarter of its rated loss).
    pub current_limit_ratio: T,
    /// Over-current trip as a multiple of the current limit. Default 2 (the rated current at
    /// the default limit: the alignment's swing adds its EMF's current to the reference).
    pub trip_ratio: T,
    /// Standstill voltage limit as a fraction of Vdc/√3. Default 0.5.
    pub voltage_limit_ratio: T,
    /// Spin speed as a fraction of the rated speed. Default 0.2 (enough back-EMF against the
    /// inverter error, little energy).
    pub spin_speed_ratio: T,
    /// Torque used for the I-f acceleration, as a fraction of the rated torque, on the
    /// nameplate inertia. Default 0.1.
    pub spin_torque_ratio: T,
    /// Offset calibration in s. Default 0.1 s (1000 samples at 10 kHz).
    pub offset_time: T,
    /// Alignment in s (each of its two steps, and the hold after). Default the larger of
    /// 0.3 s and 12·τ, τ = ½(Ld + Lq)/Rs of the nameplate: across the current reference the
    /// standstill loop is in voltage mode (module docs, step 2), so the current that damps
    /// the rotor's swing settles with τ, and the swing no faster (8·τ: 2 % of a ζ = 0.7 mode
    /// at ωn = R/(√2·L)), plus margin.
    pub align_time: T,
    /// Settling before each measurement in s. Default the larger of 0.25 s (the current and
    /// the rotor settle within 0.6 of it for a nameplate R/L off by 1.6× either way on every
    /// tested motor with τ ≤ 25 ms) and 10·τ (τ as for `align_time`, with which the current
    /// across the reference settles; the 5 kW PM-SyRM preset's τ = 52 ms).
    pub settle_time: T,
    /// Averaging window of each DC level, each injection and the coast, in s. Default 0.25 s.
    pub measure_time: T,
    /// Maximum duration of any phase, in s. Default 5 s, or twice the nominal length of the
    /// longest phase (2·`align_time` + `settle_time` + `measure_time`) where that is longer:
    /// a machine with τ above ≈ 0.2 s (a 10 kV motor) has longer phases, not a bad input.
    pub phase_timeout: T,
    /// Largest current-sensor gain mismatch |k − 1| the DC test accepts as a measurement
    /// (module docs, step 3); a larger one leaves phase a uncorrected. Default the gain
    /// calibration's [`DEFAULT_MAX_MISMATCH`] (0.05), the drive's default too, so that the
    /// procedure works in the scale the drive will.
    pub max_gain_mismatch: T,
    /// The standstill identification of the magnetic model (module docs, step 5).
    pub magnetics: MagneticsTestConfig<T>,
}

/// The standstill flux-linkage pulses that identify the magnetic model (module docs of
/// [`crate::commissioning`], step 5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MagneticsTestConfig<T> {
    /// Run the pulses. Default true.
    pub enabled: bool,
    /// Peak current of the pulses as a fraction of the rated current. Default 1 (the
    /// inductances over the rated current range; each pulse lasts a few ms, so the winding's
    /// heating is negligible).
    pub current_ratio: T,
    /// Pulse voltage limit as a fraction of Vdc/√3. Default 0.9 (the short pulses of a
    /// machine with a large L·I/V turn the rotor by the square of their length: as fast as the
    /// modulator allows, with a margin for the inverter's error).
    pub voltage_ratio: T,
    /// Saturation is reported (and its model written) when the fitted model's incremental
    /// inductances change by more than this fraction over the pulses' current range. Default
    /// 0.05 (a machine whose inductances move less is run as well with constants; the linear
    /// presets' fits move 1–2 %, docs/results/commissioning-magnetics.md).
    pub detection_threshold: T,
}

impl<T: Real> Default for MagneticsTestConfig<T> {
    fn default() -> Self {
        Self {
            enabled: true,
            current_ratio: T::one(),
            voltage_ratio: T::lit(0.9),
            detection_threshold: T::lit(0.05),
        }
    }
}

impl<T: Real> MagneticsTestConfig<T> {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        check::positive("magnetics.current_ratio", self.current_ratio)?;
        if self.current_ratio > T::lit(2.0) {
            return Err(ConfigError::OutOfRange {
                field: "magnetics.current_ratio",
                expected: "at most 2 (twice the rated current)",
            });
        }
        check::positive("magnetics.voltage_ratio", self.voltage_ratio)?;
        if self.voltage_ratio > T::one() {
            return Err(ConfigError::OutOfRange {
                field: "magnetics.voltage_ratio",
                expected: "at most 1",
            });
        }
        check::positive("magnetics.detection_threshold", self.detection_threshold)?;
        Ok(())
    }
}

impl<T: Real> CommissioningConfig<T> {
    /// The defaults for a nameplate, sampling period and dead time.
    pub fn for_machine(nameplate: MachineModel<T>, sample_period: T, dead_time: T) -> Self {
        let tau = T::lit(0.5) * (nameplate.ld + nameplate.lq) / nameplate.rs;
        let align_time = T::lit(0.3).max(T::lit(12.0) * tau);
        let settle_time = T::lit(0.25).max(T::lit(10.0) * tau);
        Self {
            nameplate,
            sample_period,
            switching_frequency: T::lit(0.5) / sample_period,
            dead_time,
            current_limit_ratio: T::lit(0.5),
            trip_ratio: T::lit(2.0),
            voltage_limit_ratio: T::lit(0.5),
            spin_speed_ratio: T::lit(0.2),
            spin_torque_ratio: T::lit(0.1),
            offset_time: T::lit(0.1),
            align_time,
            settle_time,
            measure_time: T::lit(0.25),
            // 5 s, or twice the longest phase of a slow machine (the phases scale with τ).
            phase_timeout: T::lit(5.0)
                .max(T::lit(2.0) * (T::lit(2.0) * align_time + settle_time + T::lit(0.25))),
            max_gain_mismatch: T::lit(DEFAULT_MAX_MISMATCH),
            magnetics: MagneticsTestConfig::default(),
        }
    }

    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.nameplate.validate()?;
        check::positive("sample_period", self.sample_period)?;
        check::positive("switching_frequency", self.switching_frequency)?;
        check::non_negative("dead_time", self.dead_time)?;
        check::positive("current_limit_ratio", self.current_limit_ratio)?;
        if self.current_limit_ratio > T::one() {
            return Err(ConfigError::OutOfRange {
                field: "current_limit_ratio",
                expected: "at most 1 (the rated current)",
            });
        }
        check::positive("trip_ratio", self.trip_ratio)?;
        if self.trip_ratio <= T::one() {
            return Err(ConfigError::OutOfRange {
                field: "trip_ratio",
                expected: "above 1",
            });
        }
        check::positive("voltage_limit_ratio", self.voltage_limit_ratio)?;
        if self.voltage_limit_ratio > T::one() {
            return Err(ConfigError::OutOfRange {
                field: "voltage_limit_ratio",
                expected: "at most 1",
            });
        }
        check::positive("spin_speed_ratio", self.spin_speed_ratio)?;
        if self.spin_speed_ratio > T::lit(0.5) {
            return Err(ConfigError::OutOfRange {
                field: "spin_speed_ratio",
                expected: "at most 0.5 (the inertia test reaches 1.5× it)",
            });
        }
        check::positive("spin_torque_ratio", self.spin_torque_ratio)?;
        check::positive("offset_time", self.offset_time)?;
        check::positive("align_time", self.align_time)?;
        check::positive("settle_time", self.settle_time)?;
        check::positive("measure_time", self.measure_time)?;
        check::positive("phase_timeout", self.phase_timeout)?;
        check::positive("max_gain_mismatch", self.max_gain_mismatch)?;
        self.magnetics.validate()?;
        let min_phase = T::lit(2.0) * self.align_time + self.settle_time + self.measure_time;
        if self.phase_timeout < min_phase || self.phase_timeout < self.offset_time {
            return Err(ConfigError::OutOfRange {
                field: "phase_timeout",
                expected: "at least the nominal duration of every phase",
            });
        }
        if self.measure_time < T::lit(40.0) * self.sample_period {
            return Err(ConfigError::OutOfRange {
                field: "measure_time",
                expected: "at least 40 samples",
            });
        }
        Ok(())
    }
}
