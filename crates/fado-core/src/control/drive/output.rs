//! [`DriveOutput`]: what one sample of the drive returns.

use crate::control::monitor::DriveFlags;
use crate::estimator::Estimate;
use crate::{Ab, Abc, Dq, Real};

/// The drive's outputs for one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriveOutput<T> {
    /// Duty cycles of the upper switches in [0, 1], to be loaded at the next sample.
    pub duty: Abc<T>,
    /// False after a trip: the gates must be switched off.
    pub gates_enabled: bool,
    /// The realised α-β voltage reference before dead-time compensation (V): what the
    /// estimator will be told acted over [n+1, n+2].
    pub v_ref_ab: Ab<T>,
    /// The measured current in the estimated rotor frame (A).
    pub i_dq: Dq<T>,
    /// The current reference (A).
    pub i_dq_ref: Dq<T>,
    /// The estimator's output for this sample.
    pub estimate: Estimate<T>,
    /// The drive has tripped (latched until `reset`).
    pub tripped: bool,
    /// This sample's inputs were non-finite: the last duty is held and the controllers are
    /// untouched.
    pub input_fault: bool,
    /// The realised voltage reference in the delay-compensated d-q frame (V).
    pub v_dq_ref: Dq<T>,
    /// The voltage reference (with dead-time compensation) had to be limited.
    pub voltage_saturated: bool,
    /// The status word of this sample: faults and warnings (see [`DriveFlags`]).
    pub flags: DriveFlags,
    /// The α-β current the estimator was given this sample (A): the measurement with the
    /// calibrated offsets removed, phase a divided by the calibrated gain ratio, and a stuck
    /// channel reconstructed (the last good current
    /// after a non-finite one; the raw measurement while calibrating or tripped).
    pub i_ab: Ab<T>,
}

impl<T: Real> DriveOutput<T> {
    /// True when every number in the output is finite (the drive guarantees it; tests check).
    pub fn is_finite(&self) -> bool {
        self.duty.is_finite()
            && self.v_ref_ab.is_finite()
            && self.i_dq.is_finite()
            && self.i_dq_ref.is_finite()
            && self.v_dq_ref.is_finite()
            && self.i_ab.is_finite()
            && self.estimate.is_finite()
    }

    pub(super) fn idle(estimate: Estimate<T>) -> Self {
        let half = T::lit(0.5);
        Self {
            duty: Abc::new(half, half, half),
            gates_enabled: true,
            v_ref_ab: Ab::zero(),
            i_dq: Dq::zero(),
            i_dq_ref: Dq::zero(),
            estimate,
            tripped: false,
            input_fault: false,
            v_dq_ref: Dq::zero(),
            voltage_saturated: false,
            flags: DriveFlags::NONE,
            i_ab: Ab::zero(),
        }
    }
}

impl<T: Real> Default for DriveOutput<T> {
    /// Duties ½ (zero voltage), gates enabled, everything else zero.
    fn default() -> Self {
        Self::idle(Estimate::default())
    }
}
