//! The speed loop's torque demand, or the release hold's (see
//! [`release_hold`](crate::control::release_hold)).

use super::{DriveConfig, SensorlessDrive};
use crate::control::release_hold::HoldAction;
use crate::estimator::{Estimate, RotorAngleEstimator};
use crate::{Dq, Real};

/// The rated load's fall reaches the release hold's trigger within this many time
/// constants 1/ωc of the current loop at most, for the release's d-current floor to be on
/// while the brake still holds the rotor: 1.5 \[A\] (the floor raised at the opening has
/// reached 78 % of its value there). The time to the trigger is
/// t_r = √(2·trigger/a_rated), a_rated = p·T_rated/Ĵ; a hold whose current loop is raised to
/// the 10·ω_h its design needs (`release_hold`, "The current loop it needs") has
/// t_r·ωc = 10·√(2·trigger·0.27/travel) = 2.3 at the default trigger and travel; below
/// that are the rotors whose current loop the sampling caps (ωc·Ts at most
/// `release_hold::MAX_CURRENT_WC_TS`, 0.35). At that cap none of the presets and test machines
/// is below 1.5: the 400 W servo's bare rotor has 1.72 (t_r 0.49 ms at 10 kHz, ωc = 3.5·10³
/// s⁻¹), and its floor raised at the opening is in time (`loaded-start` 0.255–0.312 rad back at
/// seeds 1–4); with its loop at ωc·Ts = 0.2 it has 0.99 and, the floor raised at the opening,
/// runs 0.863 rad back at seed 2 (0.458 with the floor at the brake). The capped multirotor,
/// tool and 750 W servo motors (1.77–1.88) keep the floor from the opening. A bound between
/// the two, measured, not derived: with the floor on at the brake on every rotor, the Flipsky
/// 6215 multirotor motor (2.3) runs back 2.07 rad instead of 0.24 at `loaded-start` seed 4,
/// and the MAD 5010 kv110 keeps 0.261 rad of |θ − θ̂| instead of 0.164 at seed 2.
const FLOOR_AT_BRAKE_RISE: f64 = 1.5;

/// The release's d-current floor is on while a brake holds the rotor after the start-up
/// (`SensorlessDrive::release_current_floor`): where the rated load's fall reaches the
/// hold's trigger within [`FLOOR_AT_BRAKE_RISE`] time constants of the current loop. False
/// where the inputs give no finite time.
pub(super) fn floor_at_brake<T: Real>(c: &DriveConfig<T>) -> bool {
    let m = &c.machine;
    let p = T::lit(m.pole_pairs as f64);
    let accel = p * m.rated_torque / m.inertia;
    let to_trigger = (T::lit(2.0) * c.tuning.release_hold.trigger / accel).step_sqrt();
    let wc = T::two_pi() * c.tuning.current.bandwidth_hz;
    // NaN compares false: the floor from the opening.
    to_trigger * wc < T::lit(FLOOR_AT_BRAKE_RISE)
}

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// The torque demand (A of magnet q current) of this sample: the speed PI's, or while the
    /// release hold acts, the hold's; the speed PI starts from the hold's torque when it
    /// hands over. None when the speed PI rejects its inputs.
    #[inline(always)]
    pub(super) fn speed_or_hold(&mut self, speed_ref: T, estimate: &Estimate<T>) -> Option<T> {
        let direct = estimate.diagnostics.theta_direct;
        self.blocks.hold.set_carried(self.blocks.speed.integral());
        self.blocks.hold.set_probing(self.blocks.probe.active());
        let hold = self.blocks.hold.step(speed_ref, estimate.theta, direct);
        if let HoldAction::Handover(iq) = hold {
            self.blocks.speed.preset(iq);
        }
        // After a hold the start-up's motion test engaged, the reference resumes from zero.
        let speed_ref = self.blocks.hold.resumed(speed_ref);
        let iq = self
            .blocks
            .speed
            .step(speed_ref, estimate.omega_control)
            .ok()?;
        Some(match hold {
            HoldAction::Hold(held) => held,
            _ => iq,
        })
    }

    /// `i` with its d current at least the release's floor while a brake holds the rotor
    /// after the start-up (`StartupTuning::rotor_held`, the hold enabled) and from the
    /// application's brake opening ([`arm_release_hold`](Self::arm_release_hold)) until the
    /// rotor moves (see [`release_current`](crate::control::release_current)): no phase
    /// current inside the dead-time band at θ̂ (`theta`) when the rotor starts to fall. Once
    /// the hold acts, its q current takes the phases out of the band and its loop is the one
    /// designed (a d current would add an alignment torque that goes at the hand-over).
    ///
    /// On before the opening, not from it: the current loop takes 1/ωc and more to raise the
    /// floor (0.5 ms at the 400 W servo's 318 Hz, its 1.7 A at −1.66 rad reached after
    /// 1 ms), and a light rotor falls within that time (the servo's bare rotor under its rated
    /// load 0.045 rad in 0.8 ms). Raised at the opening, the phase across θ̂ still carried
    /// 0.05 A, inside the band: the direct angle had moved 0.022 rad of the rotor's 0.045 rad
    /// at the hold's trigger, the load the fall reveals read 1.37 A of 3.4 A, and the rotor
    /// ran back 0.863 rad (`loaded-start` seed 2,
    /// `crates/fado-sim/tests/unseen_motor_tables.rs`); with the floor on at the brake the
    /// direct angle reaches the trigger 0.6 ms after the opening, having moved 0.022 rad of
    /// the rotor's 0.024, the load reads 2.62 A and the rotor runs back 0.458 rad (0.5
    /// allowed). At the brake a d current along θ̂ turns
    /// nothing; it costs the floor's copper loss from ready to the opening. Only where the
    /// fall is that fast (`floor_at_brake`).
    #[inline(always)]
    pub(super) fn release_current_floor(&self, i: Dq<T>, theta: T, vdc: T) -> Dq<T> {
        if !(self.brake_holds || self.blocks.hold.awaiting_fall()) {
            return i;
        }
        match self
            .blocks
            .phase_band
            .release_current()
            .d_current(theta, vdc)
        {
            Some(floor) => Dq::new(i.d.step_max(floor), i.q),
            None => i,
        }
    }

    /// (Re)arms the release hold at the present θ̂: the application calls it when its brake
    /// releases later than the start-up's end (a hoist opens its brake just before the lift).
    /// The loaded-standstill probe then arms after one period instead of its arming time
    /// ([`StandstillProbe::arm_at_release`](crate::control::StandstillProbe::arm_at_release)).
    pub fn arm_release_hold(&mut self) {
        // The loaded standstill that follows: the angle probe arms after one period.
        self.blocks.probe.arm_at_release();
        let theta = self.last.estimate.theta;
        self.blocks.hold.arm_at_release(theta);
        self.brake_holds = false;
    }

    /// Times the release hold acted since the drive was built (see
    /// [`release_hold`](crate::control::release_hold)).
    pub fn release_holds(&self) -> u32 {
        self.blocks.hold.engaged()
    }
}
