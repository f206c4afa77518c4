//! The light load where the inverter outruns the hold: where the inverter's dead-time voltage
//! turns the direct angle faster than the hold's ω_h, or where ω_h is the current loop's cap,
//! a hold armed at a brake's release on a linear model takes the stiffness for the load its
//! fall reveals.
//!
//! # Why
//! A light load's hold at the rated load's stiffness swings its q current through zero; on a
//! salient rotor the active flux, and with it |λ̂r|, is smallest there (the 50 kW IPMSM's
//! release d current of +40 A leaves 0.033 Wb of its 0.066 Wb magnet), and the swing carries
//! every phase current through the inverter's dead-time band, where the compensation's
//! residual is a voltage error of up to the dead time's 13 V. The direct angle then moves by
//! that error over |λ̂r| (0.027 rad in one 50 µs sample at 0.069 Wb, the rotor 0.0007 rad),
//! and the loop's D path turns it into the opposite limit: on the 50 kW IPMSM at a quarter of
//! its rated torque (`loaded-start` seed 2) the hold rings between −100 and +220 A of q
//! current at ≈ 90 Hz from the trigger, and the estimate is lost after the hand-over (with
//! `[inverter] dead_time = 0` the same loop settles within 20 ms). Armed at a brake's release
//! on a linear salient model the hold therefore takes the stiffness for the load its fall
//! reveals ([`ReleaseHold::set_dead_time_voltage`], `fall.rs`), read from the direct
//! angle's travel at the trigger (the tracked angle lags the fall: from
//! its travel the rated load's stiffness comes out at ≈ 0.45 and the rated load runs the 50 kW
//! rotor back 0.76–1.15 rad). Measured (`loaded-start`, a constant load from t = 0, backward
//! travel rad, seeds 1–4; the rated stiffness in brackets): the 50 kW IPMSM at 0.1 of its
//! rated torque 0.353, 0.257, 0.180, 0.215 (0.214, 3.42, 0.056 with |θ − θ̂| 1.08, 0.245 with
//! 0.291), at 0.25 0.300, 0.264, 0.156, 0.278 (0.355, lost, lost, 0.661), at 0.5 0.19–0.32
//! (0.15–0.21), at the rated torque 0.340, 0.316, 0.241, 0.271 (0.332, 0.305, 0.241, 0.271).
//! A softened hold lets every load run back by about its design travel, more than the rated
//! stiffness lets a light load (the 2.2 kW IPMSM at a quarter load 0.20–0.24 rad instead of
//! 0.07, the 5 kW PM-SyRM's quarter load at seed 2 0.536 rad instead of 0.126), so only a rotor
//! whose dead-time voltage turns the direct angle faster than ω_h softens
//! ([`DEAD_TIME_RATE_RATIO`]): of the presets the 50 kW IPMSM. Of the datasheet test machines
//! the salient Flipsky 6215 12S multirotor motor softens too
//! (`crates/fado-sim/tests/data/multirotor/flipsky-6215-kv170-12s.toml`, seeds 1–4, backward
//! travel / max |θ − θ̂| from ready, rad; the rated stiffness in brackets): a quarter of its
//! rated torque 0.181/0.065, 0.200/0.065, 0.223/0.136, 0.196/0.068 (0.902/1.224, lost,
//! 0.070/2.264, 0.262/0.632), a tenth 0.212/0.082, 0.215/0.026, 0.281/0.315, 0.221/0.222 (every
//! seed lost or beyond 1.1 rad), no load 0.007/0.015, 1.975/0.867, 0/0.041, 0/0.035 (every
//! seed beyond 1.1 rad), the rated torque 0.224–0.242 rad back, |θ − θ̂| 0.07–0.14
//! (0.221–0.240, 0.07–0.22).
//!
//! # Surface magnets
//! A surface-magnet rotor keeps |λ̂r| = λ̂f at any d current, but a low-voltage multirotor
//! motor's magnet flux is small against its inverter's dead-time voltage, and its light
//! load's hold rings the same way. Its softened hold stiffens its damping past half the
//! design travel as a saturating model's does (`fall.rs`, `STIFFEN_ONSET_RATIO`): the fall's
//! damping alone is kept on a salient rotor, whose |λ̂r| the release's d current shrinks. Measured on the multirotor datasheet test machines
//! (`crates/fado-sim/tests/data/multirotor/`, `loaded-start` without a load and under a tenth
//! and a quarter of the rated torque, seeds 1–4, starts passing; the rated stiffness in
//! brackets): the MAD 5010 kv370 12 of 12 (3), the MAD M6C12 kv150 11 of 12 (2), the T-motor
//! MN4004 kv300 10 of 12 (1), the MN4006 kv380 10 of 12 (1), the U8 kv150 11 of 12 (3); at
//! the rated torque every seed passes either way, its figures within 0.01 rad. The machines
//! that the current loop caps soften through the cap (`fall.rs`) and are unchanged by that
//! damping, as is every preset.
//!
//! # At the current loop's cap
//! Where ω_h is the current loop's cap ωc/10 (the rule that raises the current loop for the
//! hold puts it there, `current_bandwidth_for_hold`), the loop's speed filter has its corner
//! 5·ω_h at half the current loop's bandwidth, and a dead-time voltage far below λ̂f·ω_h
//! rings the light load's hold at the current loop's own frequency. The cheetah outrunner
//! (`motors/outrunner-cheetah-24v.toml`: 30 µH, ω_h = 274 rad/s = ωc/10 with ωc raised to
//! 436 Hz, V̂/λ̂f = 82 rad/s = 0.30·ω_h) at the rated stiffness: from the trigger its q current
//! swings between about ±6 A at ≈ 430 Hz, θ̂ stays where it was while the rotor turns at
//! ≈ 1 rad/s, and |θ − θ̂| from ready reaches 0.25–0.31 rad by the speed ramp (`loaded-start`
//! without a load seed 3, under a tenth of its rated torque seeds 2–4); with `[inverter]
//! dead_time = 0` every seed passes (at most 0.148 rad). Softened there (backward travel / max
//! |θ − θ̂| from ready, rad, seeds 1–4; the rated stiffness in brackets): no load 0.084/0.034,
//! 0.044/0.096, 0.032/0.018, 0.027/0.005 (0.219/0.054, 0.071/0.172, 1.100/0.278, 0.186/0.184),
//! a tenth 0.186/0.046, 0.203/0.016, 0.178/0.029, 0.180/0.207 (0.267/0.235, 0.201/0.286,
//! 0.047/0.254, 0.315/0.313), a quarter 0.178/0.063, 0.222/0.027, 0.206/0.139, 0.175/0.037
//! (0.080/0.070, 0.092/0.034, 0.080/0.108, 0.079/0.043), the rated torque 0.243/0.104,
//! 0.359/0.107, 0.245/0.071, 0.242/0.080 (0.241/0.105, 0.316/0.103, 0.242/0.073,
//! 0.240/0.080). A drawn 4-pole 279 V 871 W SPM at the cap (`scripts/drawn-machines.py`, draw
//! 404, machine 10) without a load at seed 1 0/0.016 (0.237/0.254), under a tenth at seed 2
//! 0.193/0.020 (0.096/0.256). A wider rule, the D path's answer to the false speed
//! K_d·V̂/λ̂f = 3·ω_h·V̂/(λ̂f·b) above the rated load's q current, softens the hub motor, the
//! paper's motor and the Siemens servo too (their ω_h a 20th to a 40th of ωc) and loses the
//! servo's tenth-load seed 3 (|θ − θ̂| 0.285 rad; 0.168 at the rated stiffness). Without a
//! dead-time voltage (V̂ = 0) nothing rings and the hold keeps the rated stiffness.

use super::ReleaseHold;
use crate::Real;

/// A linear model's hold softens to the load its fall reveals where the inverter's
/// dead-time voltage over the magnet's flux, V̂/λ̂f, a false speed of the direct angle, exceeds
/// this many times ω_h: 1 \[A\], measured, not derived (module docs). The presets: the
/// 50 kW IPMSM 14 V / 0.066 Wb = 212 rad/s against ω_h = 130 rad/s (1.6: it softens), the
/// 5 kW PM-SyRM 36 against 110 rad/s (0.33) and the 2.2 kW IPMSM 14 against 62 rad/s (0.23),
/// which keep the rated stiffness.
pub const DEAD_TIME_RATE_RATIO: f64 = 1.0;

impl<T: Real> ReleaseHold<T> {
    /// On a linear model whose inverter's dead-time voltage `dead_time_voltage`
    /// (V̂ = Td·f_sw·Vdc + V_th, V) over the magnet's flux `flux` (Wb) is a false speed of the
    /// direct angle above the loop's ω_h ([`DEAD_TIME_RATE_RATIO`]), or is positive where ω_h
    /// is the current loop's cap ωc/10 (module docs, "At the current loop's cap"), the hold
    /// armed at a brake's release takes the stiffness for the load the direct angle's travel
    /// at the trigger reveals, as on a saturating model (module docs); the tracked angle still
    /// triggers it.
    /// On a `salient` rotor it keeps the fall's damping at any error (module docs, "Surface
    /// magnets"). Non-finite inputs leave the rated stiffness.
    pub fn set_dead_time_voltage(&mut self, dead_time_voltage: T, flux: T, salient: bool) {
        let rate = dead_time_voltage / flux;
        // NaN compares false: the rated stiffness.
        let outruns = rate > T::lit(DEAD_TIME_RATE_RATIO) * self.stiffness();
        let capped = self.soft.at_current_cap && rate > T::zero();
        self.soft.linear = outruns || capped;
        self.soft.keep_damping = self.soft.linear && salient;
    }
}
