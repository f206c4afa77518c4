//! The rotor-motion test of the gain calibration (see the module docs, "Rotor motion"):
//! in voltage mode a turning rotor's back-EMF drives a current across the axis.

use super::{GainCalibration, Stage};
use crate::{Ab, MachineModel, Real};

/// Speed, as a fraction of the rated speed, at which the rotor-motion test of the gain
/// calibration fires: its back-EMF ω·λ̂f is the test's threshold
/// ([`GainCalibrationConfig::motion_voltage`](super::GainCalibrationConfig::motion_voltage)) \[A\]. 1 % of the rated speed is over ten
/// times the speed of the rotor's own swing about the calibration's current and the slow
/// settling of the current across the axis after a level step (both measured on the presets
/// at below 0.1 % of the rated speed), and a load of half the rated torque reaches it within
/// milliseconds: on the 2.2 kW IPMSM, 7 N·m turns the rotor 0.01 rad before it is noticed.
pub const MOTION_SPEED_RATIO: f64 = 0.01;

/// Low-pass time constant (s) of the current across the axis in the rotor-motion test \[A\]:
/// its derivative times L̂q is the back-EMF's inductive part, whose sample-to-sample noise
/// (the current sensor's noise and resolution over Ts) the filter averages over ten 10 kHz
/// samples.
pub const MOTION_FILTER_TIME: f64 = 1e-3;

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
        }
        let delta = cross - self.cross_ref;
        let tf = T::lit(MOTION_FILTER_TIME);
        let a = self.config.ts / (tf + self.config.ts);
        self.cross_filtered += a * (delta - self.cross_filtered);
        // d/dt of the filtered current is (Δi⊥ − filtered)/τ_f.
        self.config.rs_hat * self.cross_filtered
            + self.config.lq_hat * (delta - self.cross_filtered) / tf
    }
}
