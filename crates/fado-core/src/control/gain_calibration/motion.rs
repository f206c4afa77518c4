//! The rotor-motion test of the gain calibration (see the module docs, "Rotor motion"):
//! in voltage mode a turning rotor's back-EMF drives a current across the axis.

use super::{GainCalibration, Stage};
use crate::{Ab, MachineModel, Real};

/// Speed, as a fraction of the rated speed, at which the rotor-motion test of the gain
/// calibration fires: its back-EMF ω·λ̂f is the test's threshold
/// ([`GainCalibrationConfig::motion_voltage`](super::GainCalibrationConfig::motion_voltage)) \[A\].
/// At rest the test reads the rotor's own swing about the calibration's current, the slow
/// settling of the current across the axis after a level step and the sensors' noise: at most
/// 0.59 of this threshold on the presets at four angles (the 2.2 kW IPMSM; `crates/fado-sim/
/// tests/gain_calibration.rs`). A load of half the rated torque reaches it within
/// milliseconds, and the earlier the test fires the less the rotor has turned: on a light
/// 21-pole-pair multirotor motor (`crates/fado-sim/tests/calibration_load_classes.rs`) the
/// rotor runs back 0.41 rad with 0.5 %, 0.68 rad with 1 % of the rated speed.
pub const MOTION_SPEED_RATIO: f64 = 0.005;

/// Low-pass time constant (s) of the current across the axis in the rotor-motion test \[A\]:
/// its derivative times L̂q is the back-EMF's inductive part, whose sample-to-sample noise
/// (the current sensor's noise and resolution over Ts) the filter averages over ten 10 kHz
/// samples.
pub const MOTION_FILTER_TIME: f64 = 1e-3;

/// Share of the motion threshold above which the back-EMF across the axis counts towards the
/// rotor's turn ([`GainCalibration::motion_flux`]) \[A\]: above the 0.59 of the threshold the
/// presets read at rest, so that a level's noise adds nothing; a rotor that accelerates from
/// rest turns by a·t²/2 = 0.245·ω_t²/a before its back-EMF reaches it (ω_t the threshold's
/// speed, a the load's acceleration), 0.003 rad on the 21-pole-pair multirotor of
/// `crates/fado-sim/tests/calibration_load_classes.rs` under half its rated torque.
pub const MOTION_TRAVEL_SHARE: f64 = 0.7;

/// The rotor-motion threshold (V) of [`GainCalibrationConfig::motion_voltage`](super::GainCalibrationConfig::motion_voltage) for a
/// machine: [`MOTION_SPEED_RATIO`] × the rated electrical speed × λ̂f.
pub fn motion_voltage<T: Real>(m: &MachineModel<T>) -> T {
    let omega_rated = m.rated_speed_rpm * T::two_pi() / T::lit(60.0) * T::lit(m.pole_pairs as f64);
    T::lit(MOTION_SPEED_RATIO) * omega_rated * m.flux_linkage
}

impl<T: Real> GainCalibration<T> {
    /// The back-EMF across the axis (V) at this voltage-mode sample of finite `i_ab`:
    /// R̂s·Δi⊥ + L̂q·dΔi⊥/dt, Δi⊥ the change of the current across the axis since the
    /// level's first sample, low-passed over [`MOTION_FILTER_TIME`].
    pub(super) fn motion_emf(&mut self, i_ab: Ab<T>) -> T {
        let cross = self.axis.cross(i_ab);
        // The reference is the level's first sample (the voltage just frozen or stepped).
        let level_start = matches!(self.stage, Stage::HoldLower | Stage::HoldUpper)
            && self.remaining == self.hold_samples;
        if level_start {
            self.cross_ref = cross;
            self.cross_filtered = T::zero();
            self.motion_flux = T::zero();
        }
        let delta = cross - self.cross_ref;
        let tf = T::lit(MOTION_FILTER_TIME);
        let a = self.config.ts / (tf + self.config.ts);
        self.cross_filtered += a * (delta - self.cross_filtered);
        // d/dt of the filtered current is (Δi⊥ − filtered)/τ_f.
        let emf = self.config.rs_hat * self.cross_filtered
            + self.config.lq_hat * (delta - self.cross_filtered) / tf;
        let share = emf.abs() / self.config.motion_voltage;
        if share > T::lit(MOTION_TRAVEL_SHARE) {
            self.motion_flux += emf * self.config.ts;
        }
        if share > self.motion_peak {
            self.motion_peak = share;
        }
        emf
    }

    /// The largest back-EMF across the axis the motion test has read since the calibration
    /// started, as a share of its threshold `motion_voltage` (1 or more: the rotor moved).
    pub fn motion_peak(&self) -> T {
        self.motion_peak
    }

    /// The rotor's turn since the level's voltage was frozen, read from its back-EMF, times
    /// the rotor's d-axis flux (V·s; zero unless the rotor turned): R̂s·Δi⊥ + L̂q·dΔi⊥/dt =
    /// −ω·ψd across the axis in voltage mode (module docs), ψd = λ̂f + L̂d·i_d at the level's
    /// current i_d, summed over the samples where it exceeded [`MOTION_TRAVEL_SHARE`] of the
    /// threshold. The turn is −motion_flux/ψd electrical rad; after
    /// [`GainCalibrationStatus::RotorMoved`](super::GainCalibrationStatus::RotorMoved) the
    /// drive starts from the aligned angle plus it.
    pub fn motion_flux(&self) -> T {
        self.motion_flux
    }

    /// The rotor's turn (electrical rad) that ended the calibration with
    /// [`GainCalibrationStatus::RotorMoved`](super::GainCalibrationStatus::RotorMoved):
    /// −[`motion_flux`](Self::motion_flux)/ψd with ψd = `flux_linkage` + `ld`·i_d at the
    /// level's current (the model's λ̂f and L̂d); zero when the rotor did not move or ψd is
    /// not positive.
    pub fn motion_travel(&self, flux_linkage: T, ld: T) -> T {
        self.per_flux(self.motion_flux, flux_linkage, ld)
    }

    /// The rotor's electrical speed (rad/s) when the calibration ended with
    /// [`GainCalibrationStatus::RotorMoved`](super::GainCalibrationStatus::RotorMoved): the
    /// back-EMF that ended it over ψd ([`motion_travel`](Self::motion_travel)); zero
    /// otherwise.
    pub fn motion_speed(&self, flux_linkage: T, ld: T) -> T {
        self.per_flux(self.motion_emf, flux_linkage, ld)
    }

    /// −`x`/ψd after a motion, ψd = `flux_linkage` + `ld`·i_d of the level; zero otherwise.
    fn per_flux(&self, x: T, flux_linkage: T, ld: T) -> T {
        let psi_d = flux_linkage + ld * self.motion_current;
        // NaN compares false: nothing.
        if self.status == super::GainCalibrationStatus::RotorMoved && psi_d > T::zero() {
            -x / psi_d
        } else {
            T::zero()
        }
    }
}
