//! The machine model: one record of the motor's parameters and ratings, used by the estimator,
//! the drive, every baseline and (in `fado-sim`) the plant alike — the motulator pattern of one
//! machine-parameter type for plant and controller.
//!
//! A drive's *belief* about the motor (R̂s, L̂d, L̂q, λ̂f, Ĵ) and the motor's *ratings* (rated
//! current, speed, torque, DC-link voltage) are the only motor-specific numbers fado needs:
//! every default that used to be an absolute current, voltage or speed (I_min of eq. (23),
//! the current limit, the trip level, the mode threshold of Fig. 3/6, …) is a ratio of a rating
//! here, so that a new motor needs its data and nothing else. The paper's motor is the named
//! preset [`MachineModel::paper`]; no constructor assumes it silently.
//!
//! Units: SI, per phase, amplitude-invariant Park transform (peak values); the rated speed is
//! the datasheet's r/min (a rating, converted once by [`MachineModel::rated_speed`]).

use crate::error::{ConfigError, check};
use crate::magnetics::{ConstantInductance, MachineMagnetics, Magnetics};
use crate::{Dq, Real};

/// The motor's parameters and ratings (a drive's model of it, or a simulated plant).
///
/// `rs` includes everything in series with the winding that the drive's model should see (the
/// inverter's on-resistance, cables). With the `serde` feature the record maps one-to-one onto
/// a TOML `[motor]`/`[model]` table; `dc_voltage` is not part of it (it is the inverter's: the
/// simulator's `[inverter] dc_voltage`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct MachineModel<T: 'static> {
    /// Stator resistance Rs in Ω (per phase).
    pub rs: T,
    /// d-axis inductance Ld in H.
    pub ld: T,
    /// q-axis inductance Lq in H (= Ld for a surface-magnet rotor).
    pub lq: T,
    /// Magnet flux linkage λf in Wb (peak, per phase).
    pub flux_linkage: T,
    /// Pole pairs p.
    pub pole_pairs: u32,
    /// Shaft inertia J in kg·m² (motor and load).
    pub inertia: T,
    /// Viscous friction B in N·m·s/rad.
    pub viscous_friction: T,
    /// Rated current in A, peak of the phase current (= |i_dq| at rating).
    pub rated_current: T,
    /// Rated speed in r/min (mechanical), as datasheets give it.
    pub rated_speed_rpm: T,
    /// Rated torque in N·m.
    pub rated_torque: T,
    /// Nominal DC-link voltage in V (the inverter's rating; not a TOML key of the motor).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub dc_voltage: T,
    /// The magnetic model: [`MachineMagnetics::Linear`] (the default) is `ld`, `lq` and
    /// `flux_linkage`; a saturating model makes the estimator and the drive evaluate the flux
    /// at the present current (docs/method/saturation.md). `ld`, `lq` and `flux_linkage` then
    /// stay the model's zero-current values (incremental inductances and ψd at i = 0), the
    /// constants a block falls back to. Not a TOML key: `fado-sim` reads `[model.saturation]`
    /// and `[model] flux_map` itself.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub magnetics: MachineMagnetics<T>,
}

/// The empty record: every field 0, which [`MachineModel::validate`] refuses naming the first
/// field (`rs`). It exists for partial records (a serde table that gives some keys, merged over
/// a base); nothing runs on it.
impl<T: Real> Default for MachineModel<T> {
    fn default() -> Self {
        Self {
            rs: T::zero(),
            ld: T::zero(),
            lq: T::zero(),
            flux_linkage: T::zero(),
            pole_pairs: 0,
            inertia: T::zero(),
            viscous_friction: T::zero(),
            rated_current: T::zero(),
            rated_speed_rpm: T::zero(),
            rated_torque: T::zero(),
            dc_voltage: T::zero(),
            magnetics: MachineMagnetics::Linear,
        }
    }
}

impl<T: Real> MachineModel<T> {
    /// The same record in another precision (e.g. an f64 configuration for an f32 drive):
    /// every real rounded to `U`. A borrowed flux map cannot change precision without
    /// allocating: it becomes [`MachineMagnetics::Linear`] unless `U` is `T` (build the map in
    /// the drive's precision and set it with [`MachineModel::with_magnetics`]).
    pub fn cast<U: Real>(&self) -> MachineModel<U> {
        MachineModel {
            rs: U::lit(self.rs.to_f64()),
            ld: U::lit(self.ld.to_f64()),
            lq: U::lit(self.lq.to_f64()),
            flux_linkage: U::lit(self.flux_linkage.to_f64()),
            pole_pairs: self.pole_pairs,
            inertia: U::lit(self.inertia.to_f64()),
            viscous_friction: U::lit(self.viscous_friction.to_f64()),
            rated_current: U::lit(self.rated_current.to_f64()),
            rated_speed_rpm: U::lit(self.rated_speed_rpm.to_f64()),
            rated_torque: U::lit(self.rated_torque.to_f64()),
            dc_voltage: U::lit(self.dc_voltage.to_f64()),
            magnetics: self.magnetics.cast().unwrap_or_default(),
        }
    }

    /// This record on the DC link `dc_voltage` (V): a motor's record from its own table
    /// with the inverter's `[inverter] dc_voltage`, which is not a motor key.
    pub fn with_dc_voltage(mut self, dc_voltage: T) -> Self {
        self.dc_voltage = dc_voltage;
        self
    }

    /// This record with the magnetic model `magnetics`.
    pub fn with_magnetics(mut self, magnetics: MachineMagnetics<T>) -> Self {
        self.magnetics = magnetics;
        self
    }

    /// The magnetic model in effect: the saturating one, or this record's constant
    /// inductances ([`MachineModel::constant_inductance`]) for [`MachineMagnetics::Linear`].
    #[inline]
    pub fn magnetic_model(&self) -> Magnetics<'static, T> {
        self.magnetics.resolve(self.constant_inductance())
    }

    /// The paper's motor (section V \[P\]: 8-pole SMPMSM, 11.5 N·m, 1500 r/min, Rs = 0.327 Ω,
    /// Ld = Lq = 2.63 mH; DC link rectified from 3 × 220 V rms: 311 V) with docs/method/estimator.md, "The paper's motor and drive"'s assumptions
    /// (λf = 0.088 Wb, J = 0.012 kg·m², B = 1e-3 N·m·s/rad) and the rated current its torque
    /// implies, 11.5 N·m / (1.5·4·0.088 Wb) = 21.78 A peak.
    pub fn paper() -> Self {
        Self {
            rs: T::lit(0.327),
            ld: T::lit(2.63e-3),
            lq: T::lit(2.63e-3),
            flux_linkage: T::lit(0.088),
            pole_pairs: 4,
            inertia: T::lit(0.012),
            viscous_friction: T::lit(1e-3),
            rated_current: T::lit(PAPER_RATED_CURRENT),
            rated_speed_rpm: T::lit(1500.0),
            rated_torque: T::lit(11.5),
            dc_voltage: T::lit(311.0),
            magnetics: MachineMagnetics::Linear,
        }
    }

    /// Checks every field; the error names the first bad one. Besides signs and finiteness it
    /// refuses what [`crate::machine_checks::check`] finds an error: a field beyond any motor,
    /// the rated torque outside 0.3–3× of what the model gives at rated current (or half of it
    /// with an even pole-pair count: a pole count), the back-EMF at rated speed above twice
    /// the phase voltage the DC link can make (Vdc/√3), an inductance or resistance hundreds
    /// of times its plausible per-unit value, ratings that use under a tenth of the DC link.
    pub fn validate(&self) -> Result<(), ConfigError> {
        check::positive("rs", self.rs)?;
        check::positive("ld", self.ld)?;
        check::positive("lq", self.lq)?;
        check::positive("flux_linkage", self.flux_linkage)?;
        if self.pole_pairs == 0 {
            return Err(ConfigError::OutOfRange {
                field: "pole_pairs",
                expected: "at least 1",
            });
        }
        check::positive("inertia", self.inertia)?;
        check::non_negative("viscous_friction", self.viscous_friction)?;
        check::positive("rated_current", self.rated_current)?;
        check::positive("rated_speed_rpm", self.rated_speed_rpm)?;
        check::positive("rated_torque", self.rated_torque)?;
        check::positive("dc_voltage", self.dc_voltage)?;
        // The cross-checks of the data against each other and the DC link
        // (`crate::machine_checks`): its errors, named by the likeliest culprit.
        crate::machine_checks::validate_real(self)
    }

    /// Rated speed in rad/s mechanical.
    pub fn rated_speed_mech(&self) -> T {
        self.rated_speed_rpm * T::lit(core::f64::consts::PI / 30.0)
    }

    /// Rated speed in rad/s electrical.
    pub fn rated_speed(&self) -> T {
        self.rated_speed_mech() * T::lit(self.pole_pairs as f64)
    }

    /// Rated electrical frequency in Hz.
    pub fn rated_frequency_hz(&self) -> T {
        self.rated_speed_rpm * T::lit(self.pole_pairs as f64 / 60.0)
    }

    /// Magnet torque constant K_t = 1.5·p·λf in N·m/A (peak).
    pub fn torque_constant(&self) -> T {
        T::lit(1.5 * self.pole_pairs as f64) * self.flux_linkage
    }

    /// Electromagnetic torque 1.5·p·(λf·i_q + (Ld − Lq)·i_d·i_q) in N·m.
    pub fn torque(&self, i_dq: Dq<T>) -> T {
        T::lit(1.5 * self.pole_pairs as f64)
            * (self.flux_linkage * i_dq.q + (self.ld - self.lq) * i_dq.d * i_dq.q)
    }

    /// Stator flux linkage in the rotor frame (Ld·i_d + λf, Lq·i_q) in Wb.
    pub fn flux_dq(&self, i_dq: Dq<T>) -> Dq<T> {
        Dq::new(self.ld * i_dq.d + self.flux_linkage, self.lq * i_dq.q)
    }

    /// This record's inductances and magnet flux as a [`ConstantInductance`] magnetic model
    /// (the same arithmetic as [`MachineModel::flux_dq`]).
    pub fn constant_inductance(&self) -> ConstantInductance<T> {
        ConstantInductance {
            ld: self.ld,
            lq: self.lq,
            flux_linkage: self.flux_linkage,
        }
    }

    /// Magnitude of the active flux λf + (Ld − Lq)·i_d (Boldea, Paicu & Andreescu, "Active
    /// flux concept for motion-sensorless unified AC drives", IEEE TPEL 23(5), 2008): the
    /// stator flux minus L̂q·i, aligned with the d axis for any rotor. For a surface-magnet
    /// rotor it is λf; it is the |λ̂r| of eq. (5) when L̂q is used there.
    pub fn active_flux(&self, i_d: T) -> T {
        self.flux_linkage + (self.ld - self.lq) * i_d
    }

    /// True when Ld and Lq differ by more than 2 % (an interior-magnet rotor).
    pub fn is_salient(&self) -> bool {
        (self.lq - self.ld).abs() > T::lit(0.02) * self.ld.step_max(self.lq)
    }

    /// The maximum-torque-per-ampere d current for a q current `i_q` (Morimoto et al.,
    /// "Expansion of operating limits for permanent magnet motor by current vector control
    /// considering inverter capacity", IEEE TIA 26(5), 1990). Maximising the torque on a
    /// current circle gives ΔL·i_d² − λf·i_d − ΔL·i_q² = 0 (ΔL = Lq − Ld), so
    /// i_d = a − √(a² + i_q²) with a = λf/(2ΔL), written in the cancellation-free form
    /// −i_q²/(a + √(a² + i_q²)). 0 for a non-salient rotor (and for Lq < Ld, where MTPA
    /// would ask for positive i_d).
    pub fn mtpa_id(&self, i_q: T) -> T {
        let dl = self.lq - self.ld;
        if !self.is_salient() || dl <= T::zero() {
            return T::zero();
        }
        let a = self.flux_linkage / (T::lit(2.0) * dl);
        let h = i_q * i_q;
        -h / (a + (a * a + h).step_sqrt())
    }
}

/// The paper motor's rated current in A peak: 11.5 N·m / (1.5·4·0.088 Wb) (docs/method/estimator.md, "The paper's motor and drive").
pub const PAPER_RATED_CURRENT: f64 = 11.5 / (1.5 * 4.0 * 0.088);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_preset_is_valid_and_consistent() {
        let m = MachineModel::<f64>::paper();
        m.validate().unwrap();
        assert!((m.rated_current - 21.78).abs() < 0.01);
        assert!((m.torque_constant() * m.rated_current - 11.5).abs() < 1e-12);
        assert!((m.rated_frequency_hz() - 100.0).abs() < 1e-12);
        assert!(!m.is_salient());
        assert_eq!(m.mtpa_id(10.0), 0.0);
    }

    #[test]
    fn mtpa_maximises_torque_per_ampere() {
        // 2.2 kW IPMSM of the "any motor" issue: p 3, Ld 36 mH, Lq 51 mH, λf 0.545 Wb.
        let m = MachineModel::<f64> {
            rs: 3.6,
            ld: 36e-3,
            lq: 51e-3,
            flux_linkage: 0.545,
            pole_pairs: 3,
            inertia: 0.01,
            viscous_friction: 0.0,
            rated_current: 6.0,
            rated_speed_rpm: 1500.0,
            rated_torque: 14.7,
            dc_voltage: 540.0,
            magnetics: Default::default(),
        };
        m.validate().unwrap();
        for i in [1.0, 4.0, 6.0, 12.0] {
            // Along the circle |i| = i, the torque peaks at the MTPA angle.
            let best = (0..=2000)
                .map(|k| {
                    let beta = k as f64 * 1e-4 * core::f64::consts::FRAC_PI_2;
                    let idq = Dq::new(-i * beta.sin(), i * beta.cos());
                    (m.torque(idq), idq.d)
                })
                .fold((f64::MIN, 0.0), |a, b| if b.0 > a.0 { b } else { a });
            // The q current of that optimum, and the formula's d current for it.
            let iq = (i * i - best.1 * best.1).sqrt();
            assert!((m.mtpa_id(iq) - best.1).abs() < 2e-3 * i, "{i}: {best:?}");
        }
        // Symmetric in the sign of i_q, never positive, cancellation-free at tiny currents.
        assert_eq!(m.mtpa_id(-3.0), m.mtpa_id(3.0));
        assert!(m.mtpa_id(1e-9) <= 0.0 && m.mtpa_id(1e-9) > -1e-15);
    }

    #[test]
    fn unit_slips_are_refused_naming_the_field() {
        let mut m = MachineModel::<f64>::paper();
        m.flux_linkage = 88.0; // mWb entered as Wb
        let e = m.validate().unwrap_err();
        assert!(matches!(e.field(), "rated_torque" | "flux_linkage"), "{e}");
        let mut m = MachineModel::<f64>::paper();
        m.rated_current = 21.78 * 40.0;
        assert_eq!(m.validate().unwrap_err().field(), "rated_torque");
        let mut m = MachineModel::<f64>::paper();
        m.pole_pairs = 0;
        assert_eq!(m.validate().unwrap_err().field(), "pole_pairs");
        let mut m = MachineModel::<f64>::paper();
        m.dc_voltage = 24.0;
        assert_eq!(m.validate().unwrap_err().field(), "flux_linkage");
        let mut m = MachineModel::<f32>::paper();
        m.ld = f32::NAN;
        assert_eq!(m.validate().unwrap_err().field(), "ld");
    }
}
