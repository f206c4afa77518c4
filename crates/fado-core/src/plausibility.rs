//! Plausibility of measured samples: a current or voltage the machine and inverter cannot
//! produce is refused exactly like a non-finite one (flagged, state untouched).
//!
//! Three bounds on magnitudes, squared at construction so that a sample costs three compares
//! of squared magnitudes (no division, no square root, no absolute value; `x² < bound²` is
//! false for NaN and ±∞):
//!
//! * the α-β current's magnitude |i| below `current` (a multiple of the rated current),
//! * the α-β voltage's magnitude |v| below `voltage` (a multiple of the DC link),
//! * the change of the α-β current since the last accepted sample, |i − i_prev|, below
//!   `step` per sample since it was accepted (L·di/dt = v − R·i − e bounds the change per
//!   sample by (|v| + |e|)·Ts/L; see [`STEP_RATIO`]).
//!
//! Magnitudes are what the physics bounds (the rated current is a peak magnitude, the
//! inverter's voltage a hexagon of vertex 2/3·Vdc, the change a magnitude): the disc refuses
//! nothing the ratios below call plausible. Comparing each α-β component instead (the square
//! around the same disc) would let through magnitudes up to √2 × the bound along the
//! diagonals; three squared magnitudes cost five Cortex-M4 cycles fewer than six absolute
//! values. A finite value whose square
//! overflows (|x| above ≈ 1.8e19 in `f32`, 1.3e154 in `f64`) is refused like ∞, even by
//! [`SampleBounds::unbounded`]. The method is the ordinary
//! range-and-rate check of sensor validation (e.g. IEC 61508-7, A.7.7/A.13 "plausibility
//! checks"; ISO 26262-5 Annex D.2.10.3 "sensor rationality check"): a value outside what
//! the physics allows is a measurement fault, not a state of the machine. \[A\]

use crate::error::{ConfigError, check};
use crate::machine::MachineModel;
use crate::{Ab, Real};

/// Default bound on |i| as a multiple of the rated (peak) current: 4 \[A\]. Above the
/// over-current trip of any drive (short-time overload is 1.5–3× rated; the drive's
/// `trip_current` acts first on anything real) and below what a 12-bit ADC front end
/// scaled for the drive could ever report.
pub const CURRENT_RATIO: f64 = 4.0;

/// Default bound on |v| as a multiple of the DC-link voltage: 1.5 \[A\]. A two-level
/// inverter realises at most |v| = 2/3·Vdc (the hexagon's vertex), so 1.5·Vdc leaves
/// more than 2× margin for DC-link over-voltage and still refuses every sensor glitch of
/// the order of kV.
pub const VOLTAGE_RATIO: f64 = 1.5;

/// Default bound on |Δi| per sample, in units of `voltage·Ts/L`, L = min(L̂d, L̂q): 2 \[A\].
/// One sample changes the current by at most (|v| + |e|)·Ts/L; |v| ≤ 2/3·Vdc and the back-EMF
/// at rated speed |e| ≤ 2·Vdc/√3 ([`MachineModel::validate`]) give (0.67 + 1.15)·Vdc =
/// 1.2·(1.5·Vdc), so 2 covers it with 65 % margin (noise and ADC steps). L is the smaller
/// inductance: in steady state the α-β current turns by ω·|i|·Ts per sample, and on a rotor
/// with L̂d < L̂q the d current that field weakening adds makes that up to
/// (|v| + |e|)·Ts/L̂d; with L̂q the bound refuses the steady rotation itself
/// (pmsyrm-baldor-5k6, L̂d = L̂q/5: 1.07 A per sample at 2,700 r/min under 18.9 A against a
/// bound of 1.08 A, and the drive tripped on the refused samples).
pub const STEP_RATIO: f64 = 2.0;

/// The precomputed bounds of [`SampleBounds::check`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleBounds<T> {
    current: T,
    voltage: T,
    step: T,
    current_sq: T,
    voltage_sq: T,
}

impl<T: Real> SampleBounds<T> {
    /// Bounds from their values: `current` (A) and `voltage` (V) on the α-β magnitudes
    /// (finite, positive), `step` (A per sample) on the magnitude of the current's change
    /// (positive; +∞ switches the step test off).
    pub fn new(current: T, voltage: T, step: T) -> Result<Self, ConfigError> {
        let step = if step > T::zero() {
            step
        } else {
            return Err(ConfigError::NotPositive {
                field: "plausible_current_step_ratio",
            });
        };
        let current = check::positive("plausible_current", current)?;
        let voltage = check::positive("plausible_voltage", voltage)?;
        Ok(Self {
            current,
            voltage,
            step,
            current_sq: current * current,
            voltage_sq: voltage * voltage,
        })
    }

    /// The bounds of the `plausible_*` ratios (fields of the estimators' tunings and of
    /// the baselines' configurations, which errors name): |i| below `current_ratio` ×
    /// `rated_current`, |v| below `voltage_ratio` × `dc_voltage`, |Δi| per sample below
    /// `step_ratio` × (the plausible voltage)·`ts`/`lq`, `lq` the smaller of the machine's
    /// inductances ([`STEP_RATIO`]) (0, or a step that overflows, switches
    /// the step test off). `rated_current` and `dc_voltage` must be positive (errors name
    /// them).
    pub fn from_ratios(
        current_ratio: T,
        voltage_ratio: T,
        step_ratio: T,
        rated_current: T,
        dc_voltage: T,
        lq: T,
        ts: T,
    ) -> Result<Self, ConfigError> {
        let rated_current = check::positive("rated_current", rated_current)?;
        let dc_voltage = check::positive("dc_voltage", dc_voltage)?;
        let ratio = check::non_negative("plausible_current_step_ratio", step_ratio)?;
        let current = check::positive("plausible_current_ratio", current_ratio)? * rated_current;
        let voltage = check::positive("plausible_voltage_ratio", voltage_ratio)? * dc_voltage;
        let step = ratio * voltage * ts / lq;
        let step = if ratio > T::zero() && step.is_finite() {
            step
        } else {
            T::lit(f64::INFINITY)
        };
        Self::new(current, voltage, step).map_err(|e| match e.field() {
            "plausible_current" => ConfigError::OutOfRange {
                field: "plausible_current_ratio",
                expected: "a finite bound in this precision",
            },
            "plausible_voltage" => ConfigError::OutOfRange {
                field: "plausible_voltage_ratio",
                expected: "a finite bound in this precision",
            },
            _ => e,
        })
    }

    /// The bounds of a machine with the default ratios ([`CURRENT_RATIO`],
    /// [`VOLTAGE_RATIO`], [`STEP_RATIO`]) at sampling period `ts`.
    pub fn for_machine(machine: &MachineModel<T>, ts: T) -> Result<Self, ConfigError> {
        machine.validate()?;
        Self::from_ratios(
            T::lit(CURRENT_RATIO),
            T::lit(VOLTAGE_RATIO),
            T::lit(STEP_RATIO),
            machine.rated_current,
            machine.dc_voltage,
            machine.lq.step_min(machine.ld),
            check::positive("ts", ts)?,
        )
    }

    /// Only non-finite samples are refused (and finite ones whose squared magnitude
    /// overflows, see the module docs).
    pub fn unbounded() -> Self {
        let inf = T::lit(f64::INFINITY);
        Self {
            current: inf,
            voltage: inf,
            step: inf,
            current_sq: inf,
            voltage_sq: inf,
        }
    }

    /// True when |`v_ab`| < voltage, |`i_ab`| < current and |`i_ab` − `i_prev`| <
    /// `step_allowance` (the step times the samples since `i_prev` was taken), compared
    /// squared: three compares, seven multiplies, four additions and subtractions; false for
    /// any NaN or ±∞.
    #[inline]
    pub fn check(&self, v_ab: Ab<T>, i_ab: Ab<T>, i_prev: Ab<T>, step_allowance: T) -> bool {
        (v_ab.norm_squared() < self.voltage_sq)
            & (i_ab.norm_squared() < self.current_sq)
            & ((i_ab - i_prev).norm_squared() < step_allowance * step_allowance)
    }

    /// True when `i_ab` is finite and |`i_ab`| below the current bound.
    #[inline]
    pub fn current_ok(&self, i_ab: Ab<T>) -> bool {
        i_ab.norm_squared() < self.current_sq
    }

    /// The bound on the current's magnitude (A).
    pub fn current(&self) -> T {
        self.current
    }

    /// The bound on the voltage's magnitude (V).
    pub fn voltage(&self) -> T {
        self.voltage
    }

    /// The bound on the current's change per sample, a magnitude (A).
    pub fn step(&self) -> T {
        self.step
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The steady rotation of the α-β current, ω·|i|·Ts per sample, passes the step bound at
    /// twice the rated speed and 1.5 × the rated current on rotors with L̂d < L̂q (the bound
    /// uses the smaller inductance, [`STEP_RATIO`]): a PM-SyRM with L̂d = L̂q/5 and an IPMSM
    /// with L̂d = 0.6·L̂q, through the estimator's bounds and [`SampleBounds::for_machine`].
    #[test]
    fn the_steady_rotation_of_a_salient_rotor_passes_the_step_bound() {
        let paper = MachineModel::<f64>::paper();
        let pmsyrm = crate::magnetics::tests::pmsyrm_machine();
        let ipmsm = MachineModel {
            ld: 0.6 * paper.lq,
            ..paper
        };
        let ts = 100e-6;
        for m in [pmsyrm, ipmsm] {
            let config = crate::estimator::EstimatorConfig::for_machine(&m);
            for b in [
                config.sample_bounds().unwrap(),
                SampleBounds::for_machine(&m, ts).unwrap(),
            ] {
                let step = 2.0 * m.rated_speed() * 1.5 * m.rated_current * ts;
                assert!(b.step() > 1.5 * step, "{} vs {step}", b.step());
                let i = Ab::new(1.5 * m.rated_current, 0.0);
                let (s, c) = (2.0 * m.rated_speed() * ts).sin_cos();
                let turned = Ab::new(i.alpha * c, i.alpha * s);
                assert!(b.check(Ab::new(100.0, 0.0), turned, i, b.step()));
            }
        }
    }

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
        // (1e19)² is finite in f32; (1e20)² is not and is refused like ∞.
        assert!(!u.check(Ab::new(1e20, 0.0), Ab::zero(), Ab::zero(), f32::INFINITY));
        assert!(u.check(
            Ab::new(1e19, 0.0),
            Ab::new(1e19, 0.0),
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
    fn bounds_are_on_magnitudes() {
        // Each component 0.8 of the bound: inside the square, outside the disc (|x| = 1.13×).
        let b = SampleBounds::new(10.0, 100.0, 1.0).unwrap();
        let z = Ab::<f64>::zero();
        assert!(!b.check(z, Ab::new(8.0, -8.0), Ab::new(8.0, -8.0), 1.0));
        assert!(!b.check(Ab::new(-80.0, 80.0), z, z, 1.0));
        assert!(!b.check(z, Ab::new(0.8, 0.8), z, 1.0));
        assert!(!b.current_ok(Ab::new(8.0, 8.0)));
        // Just inside the disc, at any angle; and exactly on it is refused (strict).
        for k in 0..64 {
            let a = k as f64 * core::f64::consts::TAU / 64.0;
            let i = Ab::from_polar(9.99, a);
            assert!(b.check(
                Ab::from_polar(99.9, a),
                i,
                i - Ab::from_polar(0.999, a),
                1.0
            ));
            assert!(b.current_ok(i));
            assert!(!b.check(z, Ab::from_polar(0.999, a) * 3.0, z, 2.0), "{k}");
            assert!(b.check(z, Ab::from_polar(0.999, a) * 3.0, z, 3.0), "{k}");
        }
        assert!(!b.check(Ab::new(100.0, 0.0), z, z, 1.0));
        assert!(!b.check(z, Ab::new(0.0, 10.0), z, 1.0));
        assert!(!b.check(z, Ab::new(1.0, 0.0), z, 1.0));
        // f32: the same, and NaN in either component of any vector.
        let b = SampleBounds::<f32>::new(10.0, 100.0, 1.0).unwrap();
        let z = Ab::<f32>::zero();
        assert!(!b.check(z, Ab::new(8.0, 8.0), Ab::new(8.0, 8.0), 1.0));
        assert!(b.check(
            Ab::new(70.0, 70.0),
            Ab::new(7.0, 7.0),
            Ab::new(6.5, 6.5),
            1.0
        ));
        for n in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            assert!(!b.check(Ab::new(0.0, n), z, z, 1.0));
            assert!(!b.check(z, Ab::new(n, 0.0), Ab::new(n, 0.0), f32::INFINITY));
            assert!(!b.check(z, z, Ab::new(0.0, n), 1.0));
        }
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
