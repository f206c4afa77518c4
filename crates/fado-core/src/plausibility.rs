//! Plausibility of measured samples: a current or voltage the machine and inverter cannot
//! produce is refused exactly like a non-finite one (flagged, state untouched).
//!
//! Three bounds, precomputed at construction so that a sample costs a few compares (no
//! division, no square root — the same budget as the non-finite test it replaces, since
//! `x.abs() < bound` is false for NaN and ±∞):
//!
//! * every α-β current component within ±`current` (a multiple of the rated current),
//! * every α-β voltage component within ±`voltage` (a multiple of the DC link),
//! * every α-β current component within ±`step` of the last accepted one, per sample since
//!   it was accepted (L·di/dt = v − R·i − e bounds the change per sample by
//!   (|v| + |e|)·Ts/L; see [`STEP_RATIO`]).
//!
//! Components are compared, not magnitudes: the box holds the circle of the same radius, so
//! nothing plausible is refused, and it costs no square root. The method is the ordinary
//! range-and-rate check of sensor validation (e.g. IEC 61508-7, A.7.7/A.13 "plausibility
//! checks"; ISO 26262-5 Annex D.2.10.3 "sensor rationality check"): a value outside what
//! the physics allows is a measurement fault, not a state of the machine. \[A\]

use crate::error::{ConfigError, check};
use crate::machine::MachineModel;
use crate::{Ab, Real};

/// Default current bound as a multiple of the rated (peak) current: 4 \[A\]. Above the
/// over-current trip of any drive (short-time overload is 1.5–3× rated; the drive's
/// `trip_current` acts first on anything real) and below what a 12-bit ADC front end
/// scaled for the drive could ever report.
pub const CURRENT_RATIO: f64 = 4.0;

/// Default voltage bound as a multiple of the DC-link voltage: 1.5 \[A\]. A two-level
/// inverter realises at most 2/3·Vdc per α-β component (hexagon vertex), so 1.5·Vdc leaves
/// more than 2× margin for DC-link over-voltage and still refuses every sensor glitch of
/// the order of kV.
pub const VOLTAGE_RATIO: f64 = 1.5;

/// Default current-step bound, in units of `voltage·Ts/L̂q`: 2 \[A\]. One sample changes the
/// current by at most (|v| + |e|)·Ts/L; |v| ≤ 2/3·Vdc and the back-EMF at rated speed
/// |e| ≤ 2·Vdc/√3 ([`MachineModel::validate`]) give (0.67 + 1.15)·Vdc = 1.2·(1.5·Vdc), so 2
/// covers it with 65 % margin (also L̂d down to 0.6·L̂q, noise and ADC steps).
pub const STEP_RATIO: f64 = 2.0;

/// The precomputed bounds of [`SampleBounds::check`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleBounds<T> {
    current: T,
    voltage: T,
    step: T,
}

impl<T: Real> SampleBounds<T> {
    /// Bounds from their values: `current` (A) and `voltage` (V) per α-β component (finite,
    /// positive), `step` (A per sample) per component (positive; +∞ switches the step test
    /// off).
    pub fn new(current: T, voltage: T, step: T) -> Result<Self, ConfigError> {
        let step = if step > T::zero() {
            step
        } else {
            return Err(ConfigError::NotPositive {
                field: "plausible_current_step_ratio",
            });
        };
        Ok(Self {
            current: check::positive("plausible_current", current)?,
            voltage: check::positive("plausible_voltage", voltage)?,
            step,
        })
    }

    /// The bounds of a machine with the default ratios ([`CURRENT_RATIO`],
    /// [`VOLTAGE_RATIO`], [`STEP_RATIO`]) at sampling period `ts`.
    pub fn for_machine(machine: &MachineModel<T>, ts: T) -> Result<Self, ConfigError> {
        machine.validate()?;
        let ts = check::positive("ts", ts)?;
        let voltage = T::lit(VOLTAGE_RATIO) * machine.dc_voltage;
        Self::new(
            T::lit(CURRENT_RATIO) * machine.rated_current,
            voltage,
            T::lit(STEP_RATIO) * voltage * ts / machine.lq,
        )
    }

    /// Only non-finite samples are refused.
    pub fn unbounded() -> Self {
        let inf = T::lit(f64::INFINITY);
        Self {
            current: inf,
            voltage: inf,
            step: inf,
        }
    }

    /// True when `v_ab` and `i_ab` are finite and within the magnitude bounds, and `i_ab`
    /// within `samples`·step of `i_prev` (`samples` ≥ 1: samples since `i_prev` was taken).
    /// Six compares and two subtractions; false for any NaN or ±∞.
    #[inline]
    pub fn check(&self, v_ab: Ab<T>, i_ab: Ab<T>, i_prev: Ab<T>, step_allowance: T) -> bool {
        let (i, v) = (self.current, self.voltage);
        (v_ab.alpha.abs() < v)
            & (v_ab.beta.abs() < v)
            & (i_ab.alpha.abs() < i)
            & (i_ab.beta.abs() < i)
            & ((i_ab.alpha - i_prev.alpha).abs() < step_allowance)
            & ((i_ab.beta - i_prev.beta).abs() < step_allowance)
    }

    /// True when `i_ab` is finite and within the current bound.
    #[inline]
    pub fn current_ok(&self, i_ab: Ab<T>) -> bool {
        (i_ab.alpha.abs() < self.current) & (i_ab.beta.abs() < self.current)
    }

    /// The current bound per component (A).
    pub fn current(&self) -> T {
        self.current
    }

    /// The voltage bound per component (V).
    pub fn voltage(&self) -> T {
        self.voltage
    }

    /// The current-step bound per component and sample (A).
    pub fn step(&self) -> T {
        self.step
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_absurd_and_non_finite_samples() {
        let m = MachineModel::<f64>::paper();
        let b = SampleBounds::for_machine(&m, 100e-6).unwrap();
        // 4 × 21.78 A, 1.5 × Vdc, 2·1.5·Vdc·100 µs/2.63 mH per sample.
        assert!((b.current() - 87.1).abs() < 0.1);
        assert!((b.voltage() - 1.5 * m.dc_voltage).abs() < 1e-9);
        assert!((b.step() - 3.0 * m.dc_voltage * 100e-6 / 2.63e-3).abs() < 1e-9);
        let z = Ab::zero();
        let s = b.step();
        assert!(b.check(
            Ab::new(200.0, -200.0),
            Ab::new(20.0, -20.0),
            Ab::new(15.0, -15.0),
            s
        ));
        for i in [1e4, 1e5, 1e6, 1e300, f64::INFINITY, f64::NAN] {
            assert!(!b.check(z, Ab::new(i, 0.0), z, s), "{i}");
            assert!(!b.check(z, Ab::new(0.0, -i), z, s), "{i}");
        }
        for v in [1e4, -1e4, f64::NAN, f64::NEG_INFINITY] {
            assert!(!b.check(Ab::new(0.0, v), z, z, s), "{v}");
        }
        // A jump the machine cannot make in one sample, but can in three.
        assert!(!b.check(z, Ab::new(50.0, 0.0), z, s));
        assert!(b.check(z, Ab::new(50.0, 0.0), z, 3.0 * s));
        // The paper's drive: the hexagon vertex 2/3·311 V and the trip level pass.
        assert!(b.check(
            Ab::new(207.4, 0.0),
            Ab::new(60.0, 0.0),
            Ab::new(40.0, 0.0),
            s
        ));
        let u = SampleBounds::<f32>::unbounded();
        assert!(u.check(
            Ab::new(1e30, 0.0),
            Ab::new(1e30, 0.0),
            Ab::zero(),
            f32::INFINITY
        ));
        assert!(!u.check(
            Ab::new(f32::NAN, 0.0),
            Ab::zero(),
            Ab::zero(),
            f32::INFINITY
        ));
    }

    #[test]
    fn bounds_must_be_positive() {
        assert_eq!(
            SampleBounds::new(0.0, 1.0, 1.0).unwrap_err().field(),
            "plausible_current"
        );
        assert_eq!(
            SampleBounds::new(1.0, f64::NAN, 1.0).unwrap_err().field(),
            "plausible_voltage"
        );
    }
}
