//! What the drive does when the estimator reports the rotor lost ([`crate::lock`]): report
//! only, switch the R̂s adaptation on and carry on (adapt), coast at zero current, or recover (coast until the estimator has found the rotor
//! again, else re-align with the start-up procedure, then restart).
//!
//! Ours \[A\], after the usual fault reactions of drive firmware: a warning, a coast-to-stop,
//! or an automatic restart with a bounded number of attempts; catching a turning machine
//! from its back-EMF before restarting is the "flying restart" of industrial drives.
//! "Coast" keeps the current loop running at i_dq* = 0 rather than switching the gates off,
//! so that the estimator still knows the applied voltage: with no current the integrand of
//! eq. (21) has no R̂s·i error left and the back-EMF alone turns λ̂r — above the mode
//! threshold of Fig. 3 that is the regime in which the paper's estimator is reliable.

use crate::Real;
use crate::error::{ConfigError, check};

/// The drive's reaction to [`LockStatus::Lost`](crate::LockStatus::Lost).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum LockReaction {
    /// Raise the flag (`DriveFlags::LOCK_LOST` or `STALLED`) and carry on.
    #[default]
    ReportOnly,
    /// Raise the flag, switch the estimator's online R̂s adaptation on (if it has one and it
    /// is off) and carry on without coasting: for an active load, which a coasting drive
    /// lets run the machine away (docs/method/lock.md).
    Adapt,
    /// Raise the flag and hold zero current (speed loop off) until `reset`/`align`.
    Coast,
    /// Coast at zero current with the detector re-armed; restart the speed loop once the
    /// estimator has run in disturbance-feedback mode (|f̂| above the Fig. 3 threshold) with
    /// no symptom for `lock.recovery_time`. A machine that does not turn by itself within
    /// `lock.recovery_timeout` is re-aligned at the present estimate with the start-up
    /// procedure (docs/method/estimator.md, "Start-up") and restarted. After `lock.recovery_attempts` losses
    /// since the last `reset`, coast for good.
    Recover,
}

/// What the drive does this sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LockAction {
    /// Normal control.
    Run,
    /// Zero current reference, speed loop held.
    Coast,
    /// Re-arm the estimator's detector (first coasting sample of a recovery); coast.
    Rearm,
    /// Re-align the estimator now and restart (this sample's output is the idle one).
    Realign,
    /// The estimator has the rotor again: clear the speed loop and restart.
    Restart,
}

/// The reaction's state machine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LockSupervisor {
    reaction: LockReaction,
    clean_samples: u32,
    timeout_samples: u32,
    max_attempts: u32,
    state: State,
    attempts: u32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum State {
    Running,
    /// Recovering: samples coasted, clean samples in a row.
    Recovering {
        coasted: u32,
        clean: u32,
    },
    /// Coasting for good.
    Stopped,
}

impl LockSupervisor {
    /// `recovery_time` and `timeout` (s) at sampling period `ts`; `attempts` recoveries
    /// before coasting for good.
    pub fn new<T: Real>(
        reaction: LockReaction,
        ts: T,
        recovery_time: T,
        timeout: T,
        attempts: u32,
    ) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", ts)?;
        let samples = |field, t: T| {
            let t = check::non_negative(field, t)?;
            // Longer than 2^32 samples is "never": saturate.
            Ok((t / ts).round().to_f64().min(u32::MAX as f64) as u32)
        };
        let clean_samples = samples("lock_recovery_time", recovery_time)?;
        let timeout_samples = samples("lock_recovery_timeout", timeout)?;
        Ok(Self {
            reaction,
            clean_samples,
            timeout_samples,
            max_attempts: attempts,
            state: State::Running,
            attempts: 0,
        })
    }

    /// Back to running, attempts forgotten (`reset` of the drive).
    pub fn reset(&mut self) {
        self.state = State::Running;
        self.attempts = 0;
    }

    /// Back to running after an `align`, attempts kept.
    pub fn restart(&mut self) {
        self.state = State::Running;
    }

    /// The action for this sample: `lost` = the estimator reports the rotor lost,
    /// `healthy` = it reports no symptom and runs in disturbance-feedback mode.
    pub fn step(&mut self, lost: bool, healthy: bool) -> LockAction {
        match self.state {
            State::Stopped => LockAction::Coast,
            State::Recovering { coasted, clean } => {
                let clean = if healthy { clean + 1 } else { 0 };
                let coasted = coasted.saturating_add(1);
                if clean >= self.clean_samples.max(1) {
                    self.state = State::Running;
                    LockAction::Restart
                } else if coasted >= self.timeout_samples {
                    self.state = State::Running;
                    LockAction::Realign
                } else {
                    self.state = State::Recovering { coasted, clean };
                    LockAction::Coast
                }
            }
            State::Running if !lost => LockAction::Run,
            State::Running => match self.reaction {
                LockReaction::ReportOnly | LockReaction::Adapt => LockAction::Run,
                LockReaction::Recover if self.attempts < self.max_attempts => {
                    self.attempts += 1;
                    self.state = State::Recovering {
                        coasted: 0,
                        clean: 0,
                    };
                    LockAction::Rearm
                }
                LockReaction::Coast | LockReaction::Recover => {
                    self.state = State::Stopped;
                    LockAction::Coast
                }
            },
        }
    }

    /// True while coasting because of a loss (the reason: `DriveFlags::LOCK_LOST`).
    pub fn coasting(&self) -> bool {
        self.state != State::Running
    }

    /// True while a recovery waits for the estimator (coasting, not for good).
    pub fn recovering(&self) -> bool {
        matches!(self.state, State::Recovering { .. })
    }

    /// Recoveries started since the last reset.
    pub fn attempts(&self) -> u32 {
        self.attempts
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recover_coasts_until_healthy_or_realigns_and_gives_up() {
        let mut s = LockSupervisor::new(LockReaction::Recover, 1e-4, 2e-4, 5e-4, 2).unwrap();
        assert_eq!(s.step(false, true), LockAction::Run);
        assert_eq!(s.step(true, false), LockAction::Rearm);
        assert!(s.coasting());
        // Healthy for 2 samples in a row restarts; a relapse starts the count again.
        assert_eq!(s.step(false, true), LockAction::Coast);
        assert_eq!(s.step(false, false), LockAction::Coast);
        assert_eq!(s.step(false, true), LockAction::Coast);
        assert_eq!(s.step(false, true), LockAction::Restart);
        assert!(!s.coasting());
        // Second loss: never healthy, re-aligned at the timeout (5 samples).
        assert_eq!(s.step(true, false), LockAction::Rearm);
        for _ in 0..4 {
            assert_eq!(s.step(false, false), LockAction::Coast);
        }
        assert_eq!(s.step(false, false), LockAction::Realign);
        s.restart();
        assert_eq!(s.attempts(), 2);
        // Third loss: attempts used up, coast for good.
        assert_eq!(s.step(true, false), LockAction::Coast);
        for _ in 0..100 {
            assert_eq!(s.step(false, true), LockAction::Coast);
        }
        s.reset();
        assert_eq!(s.step(false, true), LockAction::Run);
        let mut r = LockSupervisor::new(LockReaction::ReportOnly, 1e-4, 0.0, 0.0, 1).unwrap();
        assert_eq!(r.step(true, false), LockAction::Run);
        let mut a = LockSupervisor::new(LockReaction::Adapt, 1e-4, 0.0, 0.0, 1).unwrap();
        assert_eq!(a.step(true, false), LockAction::Run);
        assert!(!a.coasting());
        let mut c = LockSupervisor::new(LockReaction::Coast, 1e-4, 0.0, 0.0, 1).unwrap();
        assert_eq!(c.step(true, false), LockAction::Coast);
        assert_eq!(c.step(false, true), LockAction::Coast);
        let e = LockSupervisor::new(LockReaction::Coast, 1e-4, -1.0, 0.0, 1).unwrap_err();
        assert_eq!(e.field(), "lock_recovery_time");
    }
}
