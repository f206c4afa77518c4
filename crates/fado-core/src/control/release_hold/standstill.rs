//! The loaded standstill after a brake's release: where the hold acts through it, and how it
//! leaves it as the standstill probe's d current goes.
//!
//! # Through the loaded standstill
//! The speed loop that takes over is a PI on the speed estimate, of 5 Hz: it has no integral
//! of the angle, and on a light many-pole rotor it hardly answers the standstill probe's d
//! current, a square wave of period T_p = 0.1 s (10 Hz). Where the angle estimate is off by δ
//! the probe's amplitude A is a torque square wave of b·A·sin δ (electrical rad/s², b =
//! 1.5·p²·λ̂f/Ĵ), which a free rotor follows with a swing of b·A·sin δ·T_p²/32 about its
//! mean. Where that swing at δ = 0.25 rad (the |θ − θ̂| a loaded start may keep) exceeds the
//! hold's design travel, the hold does not hand over after 10/ω_h but acts until the speed
//! reference leaves zero ([`holds_through_standstill`]): its integral holds the load, its
//! stiffness the probe's torque, and the probe reads its demand as it would read the speed
//! loop's. The rotor then follows θ̂, within the angle error the probe corrects. Of the
//! motors tried, the swing is 0.45 rad on the salient Flipsky 6215 (15/22 µH, 14 pole pairs:
//! with the hand-over its rotor swings back 0.98 rad at `loaded-start` seed 2, held 0.23 rad),
//! 0.34 rad on the multirotor preset (seed 2: 0.72 and 0.31 rad) and 0.43 rad on the cheetah
//! outrunner; 0.1 rad or less on every preset that is not a multirotor or outrunner (the
//! 50 kW IPMSM's 0.097 the largest), which keep the hand-over (docs/method/startup.md, "The
//! loaded standstill after the release").
//!
//! # The probe's exit
//! The probe's d current goes with the standstill, within the sample the speed reference
//! leaves it, and with it the torque it makes through the angle error: a step
//! Δi_d changes the torque demand the load needs by what the model gets wrong about the angle,
//! λ̂f·Δτ/Δi_d = b + λa·tan(δ − φ) (`standstill_probe`, "Torque balance"; zero at δ = 0),
//! the same torque whose swing makes the hold act through the standstill. Handed over at
//! the reference's first sample, the hold's integral holds the load with the probe's current
//! of that half-period, and the speed loop meets the step alone. On a saturating model a
//! hold acting through the standstill that the reference leaves while the probe's d current
//! is on therefore holds on as a motion hold (the speed loop's reference at zero, then
//! resuming from zero, [`ReleaseHold::engage`]) until 10/ω_h after the probe's last sample,
//! its integral taking the step, and then hands over.
//!
//! Only there: the probe's d current ends in a step, which moves the direct angle the loop
//! holds with the active flux, and only a saturating model's loop bounds its speed's step
//! ([`SPEED_STEP_ACCELERATION_RATIO`](super::SPEED_STEP_ACCELERATION_RATIO)). On a linear
//! model the D path passes that jump: the salient Flipsky 6215 datasheet motor
//! (`crates/fado-sim/tests/data/multirotor/`, `loaded-start` seed 4, its hold softened for
//! the inverter's error) held on through the exit rings at ≈ 190 Hz (q current 34–43 A), the
//! estimate is judged lost and the rotor runs back 6.04 rad (|θ − θ̂| 0.92 rad); handed over
//! at the reference, 0.242 rad and 0.137 rad.
//!
//! Measured on a drawn 497 W IPMSM (3 pole pairs, 6.2·10⁻⁶ kg·m², saturating;
//! `crates/fado-sim/tests/data/drawn/ipm-sat-3p-201v-497w.toml`, `loaded-start` seed 1):
//! θ − θ̂ creeps from 0.056 to 0.10 rad over the standstill after the release (the other
//! seeds end it within 0.015 rad: the probe starts one period after the release and has read
//! once when the reference leaves zero). The hold handed over with the probe's d current at
//! −0.44 A (î_d −1.28 A against the reference's −0.84 A); the torque at the same demand fell
//! from 0.268 to 0.2625 N·m against the 0.265 N·m load, 1 %, a deceleration of
//! 1.3·10³ rad/s² (electrical) on a rotor whose rated load accelerates it at 1.28·10⁵, while
//! the 5.2 Hz speed loop raised its demand by hundredths of an ampere: the rotor ran back
//! 1.04 rad over 88 ms, 0.956 rad from t = 0. Held through the probe's exit it runs back
//! 0.177 rad (the release's catch); seeds 2–4 are unchanged (0.214, 0.203, 0.216 rad).

use super::{ReleaseHold, ReleaseHoldTuning};
use crate::{MachineModel, Real};

/// sin 0.25: the angle error at which the standstill probe's torque is weighed, 0.25 rad \[A\],
/// the largest |θ − θ̂| a loaded start may keep from ready on (the `loaded-start` criterion).
pub(super) const PROBE_ANGLE_SIN: f64 = 0.247_403_959_254_522_93;

/// The hold stays through the loaded standstill, until the speed reference leaves zero, where
/// the standstill probe would swing a rotor that only the speed loop holds by more than the
/// hold's design travel (module docs): its d-current square
/// wave of amplitude `probe_amplitude` (A) and period `probe_period` (s) at an angle error of
/// 0.25 rad is a torque square wave of b·A·sin 0.25 (electrical rad/s², b = 1.5·p²·λ̂f/Ĵ),
/// which a free rotor follows with a swing of b·A·sin 0.25·T_p²/32 about its mean (the
/// probe's period lies near the 5 Hz speed loop's bandwidth, which hardly answers it). False
/// where the hold is disabled, the probe off, or the inputs not finite.
pub fn holds_through_standstill<T: Real>(
    tuning: &ReleaseHoldTuning<T>,
    machine: &MachineModel<T>,
    probe_amplitude: T,
    probe_period: T,
) -> bool {
    let p = T::lit(machine.pole_pairs as f64);
    let b = T::lit(1.5) * p * p * machine.flux_linkage / machine.inertia;
    let swing = standstill_swing(b, probe_amplitude, probe_period);
    // NaN compares false: the hand-over after 10/ω_h.
    tuning.enabled && swing > tuning.travel
}

/// The free rotor's swing (electrical rad) about its mean under the probe's torque at the
/// weighed angle error: a square wave of acceleration ±a with half-period T_p/2 drives a
/// triangular speed of peak a·T_p/4 and a position swing of a·T_p²/32.
pub(super) fn standstill_swing<T: Real>(b: T, amplitude: T, period: T) -> T {
    b * amplitude * T::lit(PROBE_ANGLE_SIN) * period * period / T::lit(32.0)
}

impl<T: Real> ReleaseHold<T> {
    /// Keeps the hold acting until the speed reference leaves zero instead of handing over
    /// after 10/ω_h: the rule of [`holds_through_standstill`].
    pub fn set_through_standstill(&mut self, on: bool) {
        self.through_standstill = on;
    }

    /// Whether the standstill probe's d current was on at the last sample (`on`): on a
    /// saturating model a hold acting through the loaded standstill that the reference leaves
    /// while it is on holds until 10/ω_h after it has gone (module docs, "The probe's exit").
    pub fn set_probing(&mut self, on: bool) {
        self.probing = on;
    }

    /// On a saturating model (its speed's step bounded), a hold acting through the loaded
    /// standstill that the reference leaves (`moving_ref`) while the probe's d current is on
    /// holds as a motion hold until 10/ω_h after that current has gone (module docs, "The
    /// probe's exit").
    pub(super) fn through_probe_exit(&mut self, moving_ref: bool) {
        let bounded = self.omega_step > T::zero();
        if moving_ref && bounded && self.through_standstill && self.active && self.probing {
            self.engaged_by_motion = true;
            self.held = 0;
        }
    }
}
