//! The drive's start-up as a run saw it (`metrics.json`'s `startup`, every scenario): how it
//! ended, when the drive reported ready, how far the rotor turned before, and how often the
//! start-up saw the rotor move and began again.

use fado_core::control::{GainCalibrationStatus, InitialAngleStatus, StartupStatus};
use serde::Serialize;

use super::{Probe, Sample};

/// How the start-up ended by the run's last sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StartupVerdict {
    /// The drive reported ready (its start-up over, gates on, the rotor held) at
    /// [`StartupOutcome::ready_time`]; a controller without a start-up is ready from the first
    /// sample.
    Ready,
    /// Never ready: the start-up saw the rotor turn (offsets, angle search) and waits for it
    /// to stand still before it begins again (`StartupStatus::RotorMoving`).
    Deferred,
    /// Never ready: the drive tripped first.
    Aborted,
    /// Never ready: the machine's model gives no angle at standstill (the detection found no
    /// information, or only the axis without its polarity); the drive stays off.
    NoAngleInformation,
    /// Never ready: the angle the detection measured is implausible or inconsistent; the
    /// drive stays off.
    ImplausibleAngle,
    /// Never ready: the run ended during the start-up.
    #[default]
    NotReady,
}

/// The start-up of one run (a [`Probe`] over every sample from t = 0).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct StartupOutcome {
    /// How it ended.
    pub status: StartupVerdict,
    /// First sample the drive reported ready, s (None: never).
    pub ready_time: Option<f64>,
    /// Largest |θ − θ(0)| before ready (electrical rad): the rotor's motion during the
    /// calibrations and the angle search.
    pub motion_before_ready: f64,
    /// Times the start-up saw the rotor turn and began again (entries into
    /// `StartupStatus::RotorMoving`).
    pub deferrals: u32,
    /// The gain calibration's status at ready (or at the run's end): `Calibrated`,
    /// `RotorMoved` (a load turned the rotor during it: the drive started at once holding
    /// it), `TooSlow`, … (`fado_core::control::GainCalibrationStatus`); None for a controller
    /// without one.
    pub gain_calibration: Option<String>,
    /// The start-up's angle phase at the run's end (`fado_core::control::StartupStatus`:
    /// `Idle` where the drive starts from the angle it is given, `Found`, `NoAngle(…)`).
    pub angle_phase: String,
    #[serde(skip)]
    theta0: Option<f64>,
    #[serde(skip)]
    last: StartupStatus,
    #[serde(skip)]
    tripped: bool,
    #[serde(skip)]
    gain: Option<GainCalibrationStatus>,
}

impl Probe for StartupOutcome {
    fn observe(&mut self, s: &Sample) {
        let moving = StartupStatus::RotorMoving;
        if s.startup == moving && self.last != moving {
            self.deferrals += 1;
        }
        self.last = s.startup;
        if self.ready_time.is_some() {
            return;
        }
        self.gain = s.gain_calibration;
        if s.ready {
            self.ready_time = Some(s.time);
            return;
        }
        self.tripped |= s.act.tripped;
        let theta0 = *self.theta0.get_or_insert(s.theta);
        let moved = fado_core::wrap_angle(s.theta - theta0).abs();
        self.motion_before_ready = self.motion_before_ready.max(moved);
    }

    fn finish(&mut self) {
        self.status = if self.ready_time.is_some() {
            StartupVerdict::Ready
        } else if self.tripped {
            StartupVerdict::Aborted
        } else {
            match self.last {
                StartupStatus::RotorMoving => StartupVerdict::Deferred,
                StartupStatus::NoAngle(
                    InitialAngleStatus::NoInformation | InitialAngleStatus::AxisOnly,
                ) => StartupVerdict::NoAngleInformation,
                StartupStatus::NoAngle(_) => StartupVerdict::ImplausibleAngle,
                _ => StartupVerdict::NotReady,
            }
        };
        self.gain_calibration = self.gain.map(|g| format!("{g:?}"));
        self.angle_phase = format!("{:?}", self.last);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The outcome of `samples` (time, θ, ready, start-up phase, tripped) at 1 ms steps.
    fn outcome(samples: &[(f64, bool, StartupStatus, bool)]) -> StartupOutcome {
        let mut o = StartupOutcome::default();
        for (k, &(theta, ready, startup, tripped)) in samples.iter().enumerate() {
            let mut s = Sample {
                time: k as f64 * 1e-3,
                theta,
                ready,
                startup,
                gain_calibration: Some(GainCalibrationStatus::Calibrated),
                ..Default::default()
            };
            s.act.tripped = tripped;
            o.observe(&s);
        }
        o.finish();
        o
    }

    #[test]
    fn each_end_of_the_start_up_has_its_status() {
        use StartupStatus::*;
        let moving = RotorMoving;
        // Ready at the third sample after the rotor turned 0.2 rad; later motion is not the
        // start-up's.
        let o = outcome(&[
            (0.0, false, Idle, false),
            (0.2, false, Found, false),
            (0.1, true, Found, false),
            (2.0, true, Found, false),
        ]);
        assert_eq!(o.status, StartupVerdict::Ready);
        assert_eq!(o.ready_time, Some(2e-3));
        assert!((o.motion_before_ready - 0.2).abs() < 1e-12);
        assert_eq!(o.gain_calibration.as_deref(), Some("Calibrated"));
        assert_eq!(o.angle_phase, "Found");
        // Twice deferred, still waiting at the end.
        let o = outcome(&[
            (0.0, false, moving, false),
            (0.0, false, Searching, false),
            (0.0, false, moving, false),
        ]);
        assert_eq!(
            (o.status, o.deferrals, o.ready_time),
            (StartupVerdict::Deferred, 2, None)
        );
        let none = NoAngle(InitialAngleStatus::NoInformation);
        let o = outcome(&[(0.0, false, Searching, false), (0.0, false, none, false)]);
        assert_eq!(o.status, StartupVerdict::NoAngleInformation);
        let bad = NoAngle(InitialAngleStatus::Implausible);
        assert_eq!(
            outcome(&[(0.0, false, bad, false)]).status,
            StartupVerdict::ImplausibleAngle
        );
        let o = outcome(&[(0.0, false, Searching, true), (0.0, false, Idle, false)]);
        assert_eq!(o.status, StartupVerdict::Aborted);
        let o = outcome(&[(0.0, false, Searching, false)]);
        assert_eq!(o.status, StartupVerdict::NotReady);
        // In metrics.json: snake_case, null for no ready time.
        let json = serde_json::to_value(&o).unwrap();
        assert_eq!(json["status"], "not_ready");
        assert!(json["ready_time"].is_null());
    }
}
