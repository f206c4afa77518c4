//! The online gain-mismatch tracker's place in the drive (see
//! [`gain_tracking`](crate::control::gain_tracking)): it adapts the phase-a correction that
//! the start-up calibration sets, only where that calibration ran and did not calibrate.

use super::{DriveConfig, SensorlessDrive};
use crate::control::gain_calibration::GainCalibrationStatus;
use crate::control::gain_tracking::{GainTracking, GainTrackingConfig};
use crate::estimator::RotorAngleEstimator;
use crate::{Ab, Dq, Real, Rotation};

/// R̂s·I_rated/λ̂f (1/s) from which the drive tracks the mismatch: there a 0.5 % mismatch
/// (negative sequence ε·I/√3) walks θ̂ at a loaded standstill at R̂s·ε·I/(√3·λ̂f) ≥ 0.25 rad/s,
/// the low-speed criterion of the scenarios within a second's hold (EPS motor 226, appliance
/// motor 178, gimbal 138; the 50 kW IPMSM preset, whose calibration is also `TooSlow`, 65,
/// and it holds its `reversal` at 0.014 rad without).
pub const TRACKING_MIN_WALK_RATE: f64 = 0.25 * 1.732_050_807_568_877_2 / 0.005;

/// The tracker of `config`: its time, the model's R̂s and inductances, 5 % of the rated
/// current as its smallest load and the calibration's `max_mismatch` as its range; one that
/// never adapts (time 0) below [`TRACKING_MIN_WALK_RATE`].
pub(super) fn gain_tracking_of<T: Real>(config: &DriveConfig<T>) -> GainTracking<T> {
    let m = &config.machine;
    let t = &config.tuning.gain_calibration;
    let walk = m.rs * m.rated_current / m.flux_linkage;
    let needed = walk >= T::lit(TRACKING_MIN_WALK_RATE);
    GainTracking::new(GainTrackingConfig {
        ts: config.ts,
        time: if needed { t.online_time } else { T::zero() },
        rs: m.rs,
        ld: m.ld,
        lq: m.lq,
        min_current: T::lit(0.05) * m.rated_current,
        max_mismatch: t.max_mismatch,
    })
}

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// The tracker runs: enabled, and the start-up calibration ran (not disabled by its
    /// `time`) and ended without a ratio.
    #[inline(always)]
    fn gain_tracking_active(&self) -> bool {
        self.config.tuning.gain_calibration.online
            && matches!(
                self.gain.status(),
                GainCalibrationStatus::TooSlow
                    | GainCalibrationStatus::RotorMoved
                    | GainCalibrationStatus::Implausible
                    | GainCalibrationStatus::Unobservable
            )
    }

    /// Step 3: the measured current `i_ab` in the frame `rot` of θ̂, and with it one sample
    /// of the tracker (with the voltage that acted over the last period, the estimator's, and
    /// ω̂).
    #[inline(always)]
    pub(super) fn measured_dq(&mut self, i_ab: Ab<T>, rot: Rotation<T>, omega: T) -> Dq<T> {
        let i_dq = i_ab.to_dq(rot);
        if self.gain_tracking_active() {
            self.track_gain(i_dq, rot, omega);
        }
        i_dq
    }

    /// One sample of the tracker: the measured d-q current `i_dq` in the frame `rot` of θ̂.
    #[inline(always)]
    fn track_gain(&mut self, i_dq: Dq<T>, rot: Rotation<T>, omega: T) {
        let v = self.history[1].to_dq(rot);
        self.gain_correction =
            self.gain_tracking
                .step(i_dq, v, rot, omega, self.limited[1], self.gain_correction);
    }
}
