//! Angle and speed accuracy over the evaluation window.

use serde::{Deserialize, Serialize};

use super::loss::LossTracker;
use super::{Probe, Sample};

/// Angle and speed accuracy over an evaluation window.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Evaluation starts at this time, s (start-up excluded).
    pub eval_start: f64,
    /// |speed| below this (true, r/min) counts as "near zero speed".
    pub zero_speed_band_rpm: f64,
    /// Samples evaluated.
    pub samples: u64,
    /// Samples near zero speed.
    pub zero_speed_samples: u64,
    /// max |θ − θ̂|, rad (electrical).
    pub max_angle_error: f64,
    /// RMS of θ − θ̂, rad.
    pub rms_angle_error: f64,
    /// max |θ − θ̂| near zero speed, rad.
    pub max_angle_error_zero_speed: f64,
    /// RMS of θ − θ̂ near zero speed, rad.
    pub rms_angle_error_zero_speed: f64,
    /// max |n* − n| (reference minus true speed), r/min.
    pub max_speed_error_rpm: f64,
    /// The controller tripped (at any time, also before the window).
    pub tripped: bool,
    /// Highest true DC-link voltage over the whole run, V.
    pub max_dc_voltage: f64,
    /// Lowest true DC-link voltage over the whole run, V.
    pub min_dc_voltage: f64,
    /// max |θ − θ̂| over the whole run while the gates are on (start-up included), rad:
    /// the label of the loss-of-lock evaluation (docs/method/lock.md).
    pub max_angle_error_run: f64,
    /// First time |θ − θ̂| exceeded 0.5 rad with the gates on, s (None: never).
    pub angle_error_exceeded_time: Option<f64>,
    /// First time the drive reported the estimate lost (`DriveFlags::LOCK_LOST`), s.
    pub lock_lost_time: Option<f64>,
    /// First time the drive reported a stall (`DriveFlags::STALLED`: the speed does not
    /// follow the torque; a real stall or an estimate lost near zero speed), s.
    pub stall_time: Option<f64>,
    /// Onset of the loss, s: the first time |θ − θ̂| exceeded 0.5 rad in the excursion (from
    /// the last time it had settled below 0.25 rad, i.e. stayed there for 0.1 s, on) that
    /// first took it beyond 1 rad (None: it never exceeded 1 rad). Equal to
    /// `angle_error_exceeded_time` unless an earlier excursion beyond 0.5 rad settled again.
    pub loss_onset_time: Option<f64>,
    /// The last time |θ − θ̂| was below 0.25 rad before that onset, s (None: never).
    pub loss_settled_time: Option<f64>,
    /// The loss-of-lock labels below judge the drive's loss evidence, `LOCK_LOST` or
    /// `STALLED` (either up counts as the flag; docs/method/lock.md).
    ///
    /// If the flag (a live status) is up 20 ms after the onset: the time it last rose
    /// minus the onset, s (negative: raised before the error reached 0.5 rad; docs/method/lock.md
    /// counts it as a detection if it rose less than 1 s before). None: down then.
    pub lock_detection_delay: Option<f64>,
    /// First rise of the flag at or after the onset, while the error has not settled
    /// below 0.25 rad again, minus the onset, s (the late detections). None: no rise.
    pub lock_late_delay: Option<f64>,
    /// `lock_detection_delay` for `LOCK_LOST` alone (the estimator's verdict, without the
    /// drive's stall symptom), s.
    pub lock_lost_detection_delay: Option<f64>,
    #[serde(skip)]
    loss: LossTracker,
    #[serde(skip)]
    loss_lock_only: LossTracker,
    #[serde(skip)]
    sum_sq: f64,
    #[serde(skip)]
    sum_sq_zero: f64,
}

impl Metrics {
    /// Metrics from `eval_start` on, with the given zero-speed band.
    pub fn new(eval_start: f64, zero_speed_band_rpm: f64) -> Self {
        Self {
            eval_start,
            zero_speed_band_rpm,
            min_dc_voltage: f64::INFINITY,
            ..Self::default()
        }
    }
}

impl Probe for Metrics {
    fn finish(&mut self) {
        self.rms_angle_error = (self.sum_sq / self.samples.max(1) as f64).sqrt();
        self.rms_angle_error_zero_speed =
            (self.sum_sq_zero / self.zero_speed_samples.max(1) as f64).sqrt();
    }

    fn observe(&mut self, s: &Sample) {
        self.tripped |= s.act.tripped;
        self.max_dc_voltage = self.max_dc_voltage.max(s.dc_voltage);
        self.min_dc_voltage = self.min_dc_voltage.min(s.dc_voltage);
        if s.act.gates_enabled {
            let e = s.angle_error.abs();
            self.max_angle_error_run = self.max_angle_error_run.max(e);
            if e > 0.5 && self.angle_error_exceeded_time.is_none() {
                self.angle_error_exceeded_time = Some(s.time);
            }
        }
        use fado_core::DriveFlags;
        let flags = s.act.flags;
        if self.lock_lost_time.is_none() && flags.contains(DriveFlags::LOCK_LOST) {
            self.lock_lost_time = Some(s.time);
        }
        if self.stall_time.is_none() && flags.contains(DriveFlags::STALLED) {
            self.stall_time = Some(s.time);
        }
        let flag = flags.intersects(DriveFlags::LOCK_LOST | DriveFlags::STALLED);
        let e = s.act.gates_enabled.then(|| s.angle_error.abs());
        self.loss.observe(s.time, e, flag);
        self.loss_lock_only
            .observe(s.time, e, flags.contains(DriveFlags::LOCK_LOST));
        if let Some(x) = self.loss_lock_only.loss {
            self.lock_lost_detection_delay = x.up_at_deadline.flatten().map(|t| t - x.onset);
        }
        if let Some(x) = self.loss.loss {
            self.loss_onset_time = Some(x.onset);
            self.loss_settled_time = x.settled.is_finite().then_some(x.settled);
            self.lock_detection_delay = x.up_at_deadline.flatten().map(|t| t - x.onset);
            self.lock_late_delay = x.first_rise.map(|t| t - x.onset);
        }
        if s.time < self.eval_start {
            return;
        }
        let e = s.angle_error;
        self.samples += 1;
        self.sum_sq += e * e;
        self.max_angle_error = self.max_angle_error.max(e.abs());
        if s.speed_rpm.abs() < self.zero_speed_band_rpm {
            self.zero_speed_samples += 1;
            self.sum_sq_zero += e * e;
            self.max_angle_error_zero_speed = self.max_angle_error_zero_speed.max(e.abs());
        }
        self.max_speed_error_rpm = self
            .max_speed_error_rpm
            .max((s.speed_ref_rpm - s.speed_rpm).abs());
    }
}
