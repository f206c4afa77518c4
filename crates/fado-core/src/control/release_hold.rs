//! The release hold: a position loop on θ̂ that holds a rotor where the start-up left it
//! when a load turns it at zero speed reference, and hands its torque to the speed loop as
//! the pre-torque when the reference leaves zero.
//!
//! # Why
//! A holding brake releases when the drive reports ready; a gravity load then acts at once.
//! The speed loop (a PI of a few Hz, from a speed estimate that lags at standstill) starts
//! from zero torque: on a 2.2 kW IPMSM under its rated torque it builds the holding torque
//! only after ≈ 60 ms, and the rotor runs back ≈ 14 rad (electrical) first. The backward
//! travel of a rotor under an unbalanced acceleration a = p·T_L/J is a·t²/2: the holding
//! torque has to come within a few milliseconds (4–30 ms on the presets for 0.5 rad).
//!
//! # The loop
//! With b = 1.5·p²·λ̂f/Ĵ (electrical rad/s² per ampere of magnet q current), the rotor is
//! θ̈ = b·(i_q − i_L); a PID on the angle error e = θ_hold − θ̂,
//!
//! i_q = (3·ω_h²·e − 3·ω_h·ω̂)/b + ∫ ω_h³·e/b dt,
//!
//! places the three closed-loop poles at −ω_h. A step of load acceleration a moves the rotor
//! by a·t²·e^(−ω_h·t)/2 at most 0.27·a/ω_h² (at t = 2/ω_h), and the integral then takes the
//! whole load. ω_h is chosen so that the rated torque moves the rotor by
//! [`ReleaseHoldTuning::travel`]: ω_h = √(0.27·a_rated/travel) with the rated load's
//! acceleration a_rated = p·T_rated/Ĵ, at most a tenth of the
//! current loop's bandwidth and of the sampling rate. The free fall before the trigger and
//! the lag of the loop's speed filter change it: on a rigid rotor with an exact angle the
//! rated load moves the paper's rotor 0.19 rad for a 0.2 rad design, and a rotor of a
//! twelfth of its inertia, where the cap binds, 0.47 rad (the unit tests).
//!
//! # The current loop it needs
//! The hold's torque comes through the current loop, a first-order lag 1/ωc: ω_h is capped at
//! ωc/10 so that the loop stays the designed triple pole. On a light, many-pole rotor the
//! rated load's electrical acceleration p·T_rated/Ĵ is 10–40 times the paper's motor's
//! (4.4·10⁴ rad/s² on the multirotor preset, 5.5·10⁴ on the cheetah outrunner, 3.8·10³ on the
//! paper's): with the paper's 250 Hz current loop the cap binds and the rated load moves the
//! rotor by 0.27·a/(ωc/10)² = 0.48 rad on the multirotor preset (measured 0.52 rad with the
//! free fall before the trigger, against the 0.5 rad a loaded start may lose). Where the hold
//! is enabled or armed at the start-up's end (`at_start`), the drive raises the current loop's bandwidth to the 10·ω_h its design travel
//! needs ([`current_bandwidth_for_hold`]) where the cap would let the rated load move the
//! rotor by more than 1.75 times the design travel, never lowering the tuning's and at most
//! ωc·Ts = [`MAX_CURRENT_WC_TS`]. The electrical side allows it: such a motor's stator pole
//! R/L (3.7·10³ s⁻¹ on the multirotor preset) is itself above the paper's 2π·250 Hz, and its
//! PWM samples at 40 kHz or more. On the presets the rule acts only on the two outrunners
//! (multirotor 387 Hz, capped travel 2.4 times the design; cheetah 436 Hz, 3.0 times); a
//! 750 W 10-pole servo (1.6 times, 0.33 rad) keeps its 250 Hz.
//!
//! # When
//! Armed at every (re)alignment with θ_hold = the aligned angle where
//! [`ReleaseHoldTuning::enabled`] or [`ReleaseHoldTuning::at_start`] (the drive reports ready
//! there) — unless a brake holds the
//! rotor through the start-up (`StartupTuning::rotor_held`): the application then arms it as
//! it opens the brake ([`SensorlessDrive::arm_release_hold`](crate::control::SensorlessDrive::arm_release_hold)),
//! since θ̂ moving under the brake is the estimate's own start transient and the hold's
//! integral would wind up against the brake. It acts only once the angle
//! estimate has left θ_hold by [`ReleaseHoldTuning::trigger`] while the speed reference is
//! zero, within [`ReleaseHoldTuning::window`] of the arming; armed at a release on a
//! saturating machine model, once the direct angle has, the one its loop holds: the tracked
//! angle follows a rotor that starts to fall milliseconds later. On the saturated traction IPMSM
//! (`crates/fado-sim/tests/data/traction-ipm-saturated.toml`, `loaded-start` seed 2) the
//! tracked angle had moved 0.015 rad when the rotor had fallen 0.145 rad, the direct angle
//! 0.05 rad; triggered by the tracked angle the hold acts 2 ms later, the rotor runs back
//! 0.58 rad and |θ − θ̂| reaches 0.26 rad from ready, by the direct angle 0.31 and 0.10 rad
//! (with the speed step's bound, [`SPEED_STEP_ACCELERATION_RATIO`]). There it acts only on a
//! fall that reaches the trigger within [`RELEASE_WINDOW_RATIO`] times the rated load's time to
//! it: without a load the direct angle moves too, slower (`loaded-start` with no load: 9.5
//! and 17 times that time on the measured 1.1 kW PMSM and the saturated test IPMSM), and the
//! hold's loop then swings the unloaded rotor (3.8 rad back on the test IPMSM at seed 2). With
//! the bound 38 of the 44 unloaded starts of the 11 saturated machines pass, 34 without; the
//! traction IPMSM's seed 2 misses either way (its estimate drifts at rest, with the hold off
//! |θ − θ̂| reaches 0.72 rad; crates/fado-sim/tests/light_load_start.rs). On a linear model
//! the hold keeps its window: a light rotor that the release itself turns is held there
//! (the 4-pole 36 V tool motor unloaded at seed 1 runs back 0.87 rad with the bound, 0.03
//! without). It ends after 10/ω_h (the load caught and
//! settled) or at a non-zero speed reference: the speed loop's integral is then preset to
//! the hold's integral (the pre-torque: the load it found) so that the load is not dropped at
//! the hand-over. A reference that leaves zero before the hold has acted 10/ω_h may find an
//! integral that holds only part of the load (the rest is still in the loop's transient
//! terms): the hold then acts on as a motion hold ([`ReleaseHold::engage`]), the speed
//! loop's reference at zero, until the speed loop can take the rest
//! ([`HANDOVER_TRAVEL_RATIO`]), and the reference resumes from zero. A
//! brake released at ready 25 ms before the reference's ramp (a drawn 9.7 kW, 5-pole-pair
//! IPMSM of 0.14 kg·m², ω_h = 84 rad/s, `crates/fado-sim/tests/data/drawn/`, `loaded-start`
//! seed 2) handed over 13 A of the 24 A load and ran back 14.5 rad under the speed loop;
//! held on, 0.25 rad. The drive's loaded-standstill handling (the speed loop, the
//! [`standstill_probe`](crate::control::standstill_probe)) holds it from there: the hold's
//! own reference, the estimated angle, drifts at a loaded standstill like every estimate
//! there. On a light rotor it stays instead (below).
//!
//! # On a moving reference
//! The start-up takes tenths of a second, and the application's reference may already have
//! left zero when it ends (a ramp from 0.2 s stands at 6 % of the rated speed when the 1.5 kW
//! servo motor of `crates/fado-sim/tests/calibration_load_classes.rs` reports ready). Armed at
//! the start-up's end, the hold then keeps as θ_hold the furthest angle θ̂ has reached along
//! the reference, and acts once θ̂ falls back from it by [`ReleaseHoldTuning::trigger`]: a
//! rotor that follows the reference never triggers it (its lag behind the reference's angle is
//! the speed loop's to close), a load against the reference does. It then holds θ_hold as
//! after the start-up's motion test ([`ReleaseHold::engage`]): at any reference until it has
//! settled, and the reference resumes from zero. Measured there (half the rated torque 5 and
//! 20 ms after ready): without it the speed loop alone lets the rotors run back 1.0–48 rad
//! (the 48 V hub motor alone within 0.5 rad); with it every machine of the test stays within
//! the benchmark's criteria, the 12S multirotor 5 ms after ready the closest (0.37 rad back,
//! |θ − θ̂| 0.244 rad). Two parts of that are the light rotor's: the current loop the hold's
//! stiffness needs ("The current loop it needs"; at 250 Hz the multirotor runs 0.63 rad back,
//! |θ − θ̂| 0.40 rad) and T2S-1 tracking the fall from the trigger on
//! ([`ReleaseHoldTuning::track_fall`]; with the standstill's bandwidth |θ − θ̂| 0.30 rad).
//! A hold armed at a brake's release that opens on a moving reference does the same, on the
//! angle it watches: a drawn 24 kW, 6-pole-pair IPMSM of 1.01 kg·m² ready 41 / 78 ms into
//! `loaded-start`'s ramp (`crates/fado-sim/tests/data/drawn/`) runs 0.23 / 0.20 rad back under
//! the rated load; left to the speed loop, 8.5 / 8.2 rad.
//!
//! # Through the loaded standstill
//! Where the standstill probe would swing a rotor that only the speed loop holds beyond the
//! design travel, the hold acts until the speed reference leaves zero, and through the
//! probe's exit (`release_hold/standstill.rs`).
//!
//! # The light load on a salient rotor
//! Where the inverter's dead-time voltage turns a linear salient model's direct angle faster
//! than ω_h (the 50 kW IPMSM), a hold armed at a brake's release takes the stiffness for the
//! load its fall reveals: at the rated stiffness a light load's hold rings through the
//! dead-time band and loses the estimate (`release_hold/dead_time.rs`). So does a linear
//! model's hold whose ω_h is the current loop's cap (the cheetah outrunner's, ringing at the
//! current loop's bandwidth).
//!
//! # The load the fall reveals
//! Where the current loop or the sampling caps ω_h, a hold armed at a brake's release watches
//! the direct angle and starts its integral from the share of the load its capped stiffness
//! lacks, read from the fall at the trigger (`release_hold/fall.rs`: a 400 W servo's rotor).

use crate::error::{ConfigError, check};
use crate::{MachineModel, Real};

pub use dead_time::DEAD_TIME_RATE_RATIO;
pub use standstill::holds_through_standstill;
#[cfg(test)]
use standstill::{PROBE_ANGLE_SIN, standstill_swing};
pub use tuning::ReleaseHoldTuning;

/// The loop's speed filter on a saturating machine model: 1/(4·ω_h) \[A\] instead of
/// 1/(5·ω_h). The direct angle moves with the currents' transients, and on a saturating
/// model by more (its active flux removes the secant L̂q·i, the stator flux follows the
/// incremental one). Above the filter's corner r·ω_h the loop passes that motion to the q
/// current with a gain of (1 + r)·K_p (K_d·r·ω_h = r·K_p): 6·K_p at 5·ω_h, 5·K_p at 4·ω_h.
/// Measured on `crates/fado-sim/tests/data/traction-ipm-saturated.toml` `loaded-start`: at
/// 5·ω_h the hold's q current swings by 200 A at ≈ 750 Hz from the release on and the rotor
/// is lost at seeds 1 and 3 (|θ − θ̂| 3.1 rad); at 4·ω_h seeds 1, 3 and 4 keep |θ − θ̂| within
/// 0.10, 0.19 and 0.09 rad (2·ω_h: 0.14, 0.13, 0.09), at 1·ω_h the loop's damping is lost
/// (0.88 rad at seed 1); with the bound on the speed's step and the trigger on the direct
/// angle ([`SPEED_STEP_ACCELERATION_RATIO`]) 0.065, 0.056 and 0.083 rad at 4·ω_h. A lower ratio costs a rotor that the hold must stop quickly: the
/// made-up 20-pole 48 V IPMSM (`tests/data/ipmsm-20p-48v-saturated.toml`) seed 2 keeps
/// 0.236 rad at 5·ω_h, 0.242 at 4·ω_h and loses its 0.25 rad bound (0.289) at 2·ω_h. The
/// other saturated presets keep their margins (max |θ − θ̂| from ready 0.03–0.17 rad at
/// seeds 1–4).
pub const SATURATING_SPEED_FILTER_RATIO: f64 = 4.0;

/// The largest ωc·Ts the hold's current-loop rule gives ([`current_bandwidth_for_hold`]):
/// 0.35 \[A\], with the loop's 1.5-sample delay a phase margin of 90° − 0.525 rad = 60°
/// (the current loop refuses ωc·Ts above 0.5, 47°). The cap binds on a rotor whose rated load
/// accelerates it faster than its sampling follows: the rated load's travel grows as
/// 1/ωc², so the cap sets how far it falls. Measured (`loaded-start` backward travel, seeds
/// 1–4, rad; at ωc·Ts = 0.2 in brackets): the Estun EMJ-04 400 W servo's bare rotor
/// (`crates/fado-sim/tests/data/unseen/`, 10 kHz sampling) 0.255 / 0.312 / 0.261 / 0.259
/// (0.447 / 0.457 / 0.451 / 0.440); the drawn 69 W IPMSM (`tests/data/drawn/`, 12 kHz)
/// 0.203 / 0.204 / 0.220 / 0.226 (0.359 / 0.343 / 0.377 / 0.370), max |θ − θ̂| from ready
/// within 0.064–0.102 rad either way; a drawn 31 W, 3-pole-pair SPM (`python3
/// scripts/drawn-machines.py draw DIR --seed 606`, its seventh: 6.3·10⁻⁸ kg·m², its rated
/// load 9.2·10⁵ rad/s² electrical at 24 kHz sampling) falls 0.26–0.33 rad within 20 ms of the
/// release at seeds 1–4 (0.49–0.72; seed 2 0.724 rad back, past the 0.5 allowed). Leaving
/// its loaded standstill is another matter: where the reference ramps from zero under the
/// rated load it loses seeds 1, 3 and 4 at 0.35 (|θ − θ̂| 0.322 rad from ready; 18 and 16 rad
/// back) and seeds 3 and 4 at 0.2 (0.82 and 4.8 rad back).
pub const MAX_CURRENT_WC_TS: f64 = 0.35;

/// The loop's speed changes in a sample by at most this many times b·i_max·Ts (b =
/// 1.5·p²·λ̂f/Ĵ, i_max the torque demand's limit): 2 \[A\], the acceleration of the hold's
/// whole torque against a load as large. A rotor cannot change its speed faster; the direct
/// angle the loop differentiates can, since it moves with the currents' transients. On a
/// saturating rotor it sees only κ/λa of a frame error (`crate::active_flux`, "The frame
/// coupling"), a share that moves with the current: 0.35 at the 460 A limit of
/// `crates/fado-sim/tests/data/traction-ipm-saturated.toml`, 0.59 at its rated 250 A, 1 at
/// zero current. With θ̂ 0.09 rad off the rotor its direct angle jumps by 0.08 rad within
/// 0.5 ms as the hold's current leaves the limit, a rate of ≈ 800 rad/s that the speed filter
/// (1/(4·ω_h)) would pass as 35 rad/s in one sample, 340 A through the D path: the output
/// flips from the limit to the opposite limit and the rotor is lost (`loaded-start` seed 3,
/// with the trigger on the direct angle). Limited to the 3.3 rad/s a sample can hold there,
/// seed 3 keeps 0.056 rad from ready and seed 2 0.10 rad.
pub const SPEED_STEP_ACCELERATION_RATIO: f64 = 2.0;

/// How far beyond its design travel the current loop's cap may let the rated load move the
/// rotor before the hold's rule raises the loop: 1.75 \[A\] (0.35 rad for the default 0.2 rad
/// design: the free fall before the trigger adds 0.05–0.1 rad on the presets, which leaves it
/// within the 0.5 rad a loaded start may lose; a 24-pole multirotor motor at 2.0 lost
/// 0.48–0.54 rad). A tuning that holds the rotor is left as it is.
const CAPPED_TRAVEL_RATIO: f64 = 1.75;

/// The hold's stiffness ω_h (rad/s) before the caps: the rated load moves the rotor by
/// `travel`, ω_h = √(0.27·a_rated/travel) with a_rated = p·T_rated/Ĵ (module docs). The
/// rated torque, not the magnet's 1.5·p·λ̂f·I_rated: on a salient rotor whose reluctance
/// adds torque the rated load accelerates the rotor 2.1–2.3 times faster (the 5 kW PM-SyRM,
/// the 50 kW IPMSM), and a loop designed for the magnet's torque let the 50 kW IPMSM's
/// rated load move the rotor by 0.43 rad instead of 0.2 after the trigger.
fn design_omega<T: Real>(machine: &MachineModel<T>, travel: T) -> T {
    let p = T::lit(machine.pole_pairs as f64);
    let accel = p * machine.rated_torque / machine.inertia;
    (T::lit(PEAK_TRAVEL) * accel / travel).step_sqrt()
}

/// The current loop's bandwidth (Hz) the release hold needs on `machine` sampled every `ts`:
/// 10·ω_h/2π for its design travel where the hold is enabled or armed at the start-up's end
/// (`at_start`) and the cap ω_h ≤ ωc/10 of
/// `current_hz` (the tuning's) would let the rated load move the rotor by more than 1.75
/// times that travel (ω_h² > 1.75·(ωc/10)²), at most ωc·Ts = [`MAX_CURRENT_WC_TS`]; `current_hz`
/// otherwise (module docs, "The current loop it needs"). A non-finite result keeps
/// `current_hz`.
pub fn current_bandwidth_for_hold<T: Real>(
    tuning: &ReleaseHoldTuning<T>,
    machine: &MachineModel<T>,
    ts: T,
    current_hz: T,
) -> T {
    if !(tuning.enabled || tuning.at_start) {
        return current_hz;
    }
    let omega = design_omega(machine, tuning.travel);
    let capped = T::two_pi() * current_hz / T::lit(10.0);
    // NaN compares false: the tuning's.
    let needs_wider_loop = omega * omega > T::lit(CAPPED_TRAVEL_RATIO) * capped * capped;
    if !needs_wider_loop {
        return current_hz;
    }
    let wc = T::lit(10.0) * omega;
    let wc = crate::real::min(wc, T::lit(MAX_CURRENT_WC_TS) / ts);
    let hz = wc / T::two_pi();
    // NaN compares false: the tuning's.
    if hz > current_hz { hz } else { current_hz }
}

/// The hold armed at a brake's release on a saturating model acts only on a fall that reaches
/// the trigger within this many times the time t_r = √(2·trigger/a_rated) the rated load's
/// fall takes to reach it (a_rated = p·T_rated/Ĵ, electrical): 8 \[A\]. A constant load of a
/// fraction k of the rated torque reaches it at t_r/√k, 8·t_r for k = 1/64; the rated load
/// triggers the hold at 1.0–2.1·t_r, a quarter of it at 2.0–4.3·t_r (the estimate's lag
/// included). What moves the direct angle slower at the release is no load the hold can take
/// (module docs, "When").
pub const RELEASE_WINDOW_RATIO: f64 = 8.0;

/// The triple pole's gains at ω_h `omega` for b (electrical rad/s² per A) sampled every `ts`:
/// K_p = 3·ω_h²/b, K_d = 3·ω_h/b and K_i·Ts = ω_h³·Ts/b (module docs, "The loop").
fn loop_gains<T: Real>(omega: T, b: T, ts: T) -> (T, T, T) {
    let (kp, kd) = (T::lit(3.0) * omega * omega / b, T::lit(3.0) * omega / b);
    (kp, kd, omega * omega * omega * ts / b)
}

/// ω_h at or above this share of the current loop's cap ωc/10 counts as at the cap
/// (`dead_time.rs`, "At the current loop's cap"): 0.999 \[A\], a rounding margin (the rule
/// that raises the current loop for the hold puts ω_h at the cap exactly).
const AT_CAP_SHARE: f64 = 0.999;

/// Peak of t²·e^(−t)/2 (at t = 2): the largest travel of the triple-pole loop per a/ω_h².
const PEAK_TRAVEL: f64 = 0.270_670_566_473_225_4;

/// Time the hold acts, in units of 1/ω_h: the triple pole's response to a load step has
/// decayed to e^(−10)·(1 + 10 + 50) = 0.3 % by then, and its integral holds the load.
const SETTLE_TIMES: f64 = 10.0;

/// The travel (a share of the design travel, [`ReleaseHoldTuning::travel`]) the speed loop
/// may let the rotor run back after a hand-over at a reference that leaves zero: 0.25 \[A\]
/// (0.05 rad of the default 0.2 rad design). The speed loop starts from the hold's integral
/// (the pre-torque); the torque still in the hold's transient terms, Δi = output − integral,
/// is a load step for the speed PI (Kp = Ĵ·ωs, Ki = Ĵ·ωs²/z), which lets the rotor run back
/// by b·Δi·z/ωs² (electrical rad, b = 1.5·p²·λ̂f/Ĵ; the final value of the PI's position
/// error under a step, ΔT/Ki). A hold the reference leaves within a fraction of 10/ω_h acts
/// on until that is within this share: on a drawn 9.7 kW IPMSM (ω_h = 84 rad/s, 5 Hz speed
/// loop) the integral held 13 A of the 24 A load 22 ms after the trigger, b·Δi·z/ωs² = 8 rad
/// (measured 14.5 rad back), and even a 5 % rest costs 1.4 rad; a heavy rotor's speed loop
/// takes the rest at once (a drawn 137 kW IPMSM of 2,650 kg·m², ω_h = 6 rad/s: 10/ω_h =
/// 1.7 s, b·Δi·z/ωs² of its 5 % rest 0.01 rad), where waiting for 10/ω_h would leave the
/// rotor at rest while the reference ramps (`loaded-start`: 14 r/min behind at the end
/// against the 5.3 allowed).
pub const HANDOVER_TRAVEL_RATIO: f64 = 0.25;

/// What the hold does at a sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HoldAction<T> {
    /// Not acting: the speed loop's torque is used.
    Idle,
    /// Holding: this torque demand (A of magnet q current) replaces the speed loop's.
    Hold(T),
    /// The hold ends at this sample: the speed loop starts from this torque demand.
    Handover(T),
}

/// The release hold's state (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReleaseHold<T> {
    enabled: bool,
    /// [`ReleaseHoldTuning::at_start`].
    at_start: bool,
    /// [`ReleaseHoldTuning::track_fall`].
    track_fall: bool,
    ts: T,
    trigger: T,
    window_samples: u32,
    /// Samples after a brake's release within which a fall triggers the hold on a saturating
    /// model: at most `window_samples`, [`RELEASE_WINDOW_RATIO`] times the time the rated
    /// load's fall takes to reach the trigger (a NaN time compares false: `window_samples`).
    release_window_samples: u32,
    /// Samples the hold acts before it hands over: [`SETTLE_TIMES`]/ω_h.
    hold_samples: u32,
    /// Acting until the speed reference leaves zero ([`holds_through_standstill`]).
    through_standstill: bool,
    held: u32,
    /// 3·ω_h²/b, 3·ω_h/b, ω_h³·Ts/b.
    kp: T,
    kd: T,
    ki_ts: T,
    i_max: T,
    armed: bool,
    /// Armed by [`arm_at_release`](Self::arm_at_release) (the brake opened).
    released: bool,
    /// Engaged by [`engage`](Self::engage) (the start-up saw the rotor move): acts at any
    /// speed reference until it has settled.
    engaged_by_motion: bool,
    /// Left by the reference while the speed loop could not take the rest of its torque:
    /// hands over once it can.
    carrying: bool,
    /// b = 1.5·p²·λ̂f/Ĵ (electrical rad/s² per A).
    b: T,
    /// The rotor's run-back per A of torque the speed loop takes over, z/ωs²·b (electrical
    /// rad per A; zero until [`set_speed_loop`](Self::set_speed_loop): hands over at once).
    handover_gain: T,
    /// [`HANDOVER_TRAVEL_RATIO`] × the design travel (electrical rad).
    handover_travel: T,
    active: bool,
    elapsed: u32,
    theta_hold: T,
    integral: T,
    output: T,
    /// θ̂ of the last sample and the speed from its differences, low-passed (electrical).
    theta_last: T,
    omega: T,
    /// Per-sample gain Ts/(τ + Ts) of that low-pass, τ = 1/(5·ω_h).
    omega_gain: T,
    /// The most that low-passed speed changes in a sample (electrical rad/s) on a saturating
    /// model, [`SPEED_STEP_ACCELERATION_RATIO`]·b·i_max·Ts; zero (unbounded) otherwise.
    omega_step: T,
    /// [`SPEED_STEP_ACCELERATION_RATIO`]·b·i_max·Ts, which [`set_saturating`](Self::set_saturating)
    /// makes `omega_step`.
    /// Samples after the arming within which a fall triggers it (`arm_after_release`).
    arm_window: u32,
    saturating_omega_step: T,
    /// Armed at a brake's release, triggered by the direct angle (a saturating model, see
    /// [`set_saturating`](Self::set_saturating)) instead of the tracked one.
    release_on_direct: bool,
    /// Times the hold acted since the drive was built.
    engaged: u32,
    /// The resumed reference's step per sample (electrical rad/s): the rated speed over
    /// `resume_time`.
    resume_step: T,
    /// The speed reference resumes from zero after a motion hold's hand-over.
    resuming: bool,
    /// Time since a brake's release while the hold awaits the fall, s.
    fall_time: T,
    /// The share of the load the capped loop lacks over b, A per electrical rad/s² (`fall`).
    fall_gain: T,
    /// That share of the rated load, at most `i_max` (A).
    max_fall_load: T,
    /// The resumed reference (electrical rad/s).
    resumed: T,
    /// The stiffness for the load the fall reveals (`fall`, [`Softening`](fall::Softening)).
    soft: fall::Softening<T>,
    /// The speed loop's integral of the last sample (A), the torque the hold replaces at its
    /// trigger ([`set_carried`](Self::set_carried)).
    carried: T,
    /// The standstill probe's d current was on at the last sample
    /// ([`set_probing`](Self::set_probing)).
    probing: bool,
}

impl<T: Real> ReleaseHold<T> {
    /// The hold for `machine` sampled every `ts`, with the current loop's bandwidth (Hz) and
    /// the torque demand's limit `i_max` (A).
    pub fn new(
        tuning: &ReleaseHoldTuning<T>,
        machine: &MachineModel<T>,
        ts: T,
        current_bandwidth_hz: T,
        i_max: T,
    ) -> Result<Self, ConfigError> {
        let travel = check::positive("release_hold.travel", tuning.travel)?;
        let resume_time = check::positive("release_hold.resume_time", tuning.resume_time)?;
        let p = T::lit(machine.pole_pairs as f64);
        let resume_step =
            machine.rated_speed_rpm * T::two_pi() / T::lit(60.0) * p * ts / resume_time;
        let trigger = check::positive("release_hold.trigger", tuning.trigger)?;
        let n = check::non_negative("release_hold.window", tuning.window)? / ts;
        check::below("release_hold.window", n, T::lit(4e9), "below 4e9 samples")?;
        let b = T::lit(1.5) * p * p * machine.flux_linkage / machine.inertia;
        let release_n = watch::release_window(machine, trigger) / ts;
        let design = design_omega(machine, travel);
        let current_cap = T::two_pi() * current_bandwidth_hz / T::lit(10.0);
        let omega = design.step_min(current_cap).step_min(T::lit(0.1) / ts);
        let at_cap = omega >= current_cap * T::lit(AT_CAP_SHARE);
        let a_rated = p * machine.rated_torque / machine.inertia;
        let share = fall::fall_share(omega, design);
        let (kp, kd, ki_ts) = loop_gains(omega, b, ts);
        if !(kp.is_finite() && kd.is_finite() && ki_ts.is_finite() && resume_step.is_finite()) {
            return Err(ConfigError::OutOfRange {
                field: "release_hold.travel",
                expected: "finite hold gains for the machine model",
            });
        }
        Ok(Self {
            enabled: tuning.enabled,
            at_start: tuning.at_start,
            track_fall: tuning.track_fall,
            ts,
            trigger,
            window_samples: n.round().to_f64() as u32,
            release_window_samples: if release_n < n {
                release_n.round().to_f64() as u32
            } else {
                n.round().to_f64() as u32
            },
            hold_samples: (T::lit(SETTLE_TIMES) / (omega * ts)).round().to_f64() as u32,
            through_standstill: false,
            held: 0,
            kp,
            kd,
            ki_ts,
            i_max,
            armed: false,
            released: false,
            engaged_by_motion: false,
            carrying: false,
            b,
            handover_gain: T::zero(),
            handover_travel: travel * T::lit(HANDOVER_TRAVEL_RATIO),
            active: false,
            elapsed: 0,
            theta_hold: T::zero(),
            integral: T::zero(),
            output: T::zero(),
            theta_last: T::zero(),
            omega: T::zero(),
            omega_gain: ts / (T::one() / (T::lit(5.0) * omega) + ts),
            omega_step: T::zero(),
            saturating_omega_step: T::lit(SPEED_STEP_ACCELERATION_RATIO) * b * i_max * ts,
            arm_window: n.round().to_f64() as u32,
            release_on_direct: false,
            engaged: 0,
            resume_step,
            resuming: false,
            resumed: T::zero(),
            fall_time: T::zero(),
            fall_gain: share / b,
            max_fall_load: (share * a_rated / b).step_min(i_max),
            soft: fall::Softening::new(a_rated, design, omega * ts, travel, at_cap),
            carried: T::zero(),
            probing: false,
        })
    }

    /// Low-passes the loop's speed over 1/(`ratio`·ω_h) instead of 1/(5·ω_h)
    /// ([`SATURATING_SPEED_FILTER_RATIO`] on a saturating machine model).
    pub fn set_speed_filter_ratio(&mut self, ratio: T) {
        let omega = self.stiffness();
        let gain = self.ts / (T::one() / (ratio * omega) + self.ts);
        if gain.is_finite() && gain > T::zero() {
            self.omega_gain = gain;
        }
    }

    /// On a saturating machine model (`on`), where the direct angle sees a share κ/λa of a
    /// frame error that moves with the current (`crate::active_flux`, "The frame coupling"):
    /// the loop's speed changes in a sample by at most the acceleration a rotor can have
    /// ([`SPEED_STEP_ACCELERATION_RATIO`]), and a hold armed at a brake's release triggers on
    /// the direct angle within [`RELEASE_WINDOW_RATIO`] times the rated load's time to the
    /// trigger (module docs, "When").
    pub fn set_saturating(&mut self, on: bool) {
        self.omega_step = if on {
            self.saturating_omega_step
        } else {
            T::zero()
        };
        self.release_on_direct = on;
    }

    /// The speed loop that takes over at the hand-over, of bandwidth `bandwidth_hz` (Hz) and
    /// zero ratio `zero_ratio`: a reference that leaves zero hands the hold over once that
    /// loop lets the torque still in the hold's transient terms run the rotor back by at most
    /// [`HANDOVER_TRAVEL_RATIO`] of the design travel. Not set (or not finite): at once.
    pub fn set_speed_loop(&mut self, bandwidth_hz: T, zero_ratio: T) {
        let ws = T::two_pi() * bandwidth_hz;
        let gain = self.b * zero_ratio / (ws * ws);
        if gain.is_finite() && gain > T::zero() {
            self.handover_gain = gain;
        }
    }

    /// The speed loop's integral `iq` (A of magnet q current) of this sample: the torque it
    /// carries, which a hold armed at a brake's release on a saturating model starts its
    /// integral from when it triggers (`watch.rs`).
    pub fn set_carried(&mut self, iq: T) {
        self.carried = iq;
    }

    /// Arms the hold at the angle `theta_hold` (the alignment's).
    pub fn arm(&mut self, theta_hold: T) {
        self.armed = (self.enabled || self.at_start) && theta_hold.is_finite();
        self.arm_window = self.window_samples;
        self.released = false;
        self.engaged_by_motion = false;
        self.carrying = false;
        self.resuming = false;
        self.active = false;
        self.elapsed = 0;
        self.held = 0;
        self.theta_hold = theta_hold;
        self.integral = T::zero();
        self.output = T::zero();
        self.theta_last = theta_hold;
        self.omega = T::zero();
        self.fall_time = T::zero();
        self.hold_samples = self.soft.reset();
    }

    /// Acts at once, holding `theta_hold` from the rotor's electrical speed `omega` (rad/s:
    /// the loop's damping acts from the first sample), whether the hold is enabled or not: the start-up
    /// saw a load turn the rotor during a calibration
    /// ([`GainCalibrationStatus::RotorMoved`](crate::control::GainCalibrationStatus::RotorMoved)).
    /// It holds at any speed reference until it has settled (10/ω_h; through the loaded
    /// standstill where [`holds_through_standstill`] says so, while the reference is zero),
    /// then hands its integral, the load it found, to the speed loop. The estimator tracks the
    /// fall as after a brake's release ([`tracking_fall`](Self::tracking_fall)).
    pub fn engage(&mut self, theta_hold: T, omega: T) {
        let enabled = self.enabled;
        self.enabled = true;
        self.arm(theta_hold);
        self.enabled = enabled;
        if omega.is_finite() {
            self.omega = omega;
        }
        if self.armed {
            self.released = true;
            self.engaged_by_motion = true;
            self.active = true;
            self.engaged = self.engaged.saturating_add(1);
        }
    }

    /// Arms the hold at `theta_hold`, enabled or not, for at least 10/ω_h: the motion test fired
    /// in the gain calibration's release (`GainCalibration::moved_in_release`). Engaged at once
    /// on the unloaded 32-pole torque motor (`tests/data/torque-ipm-32p.toml`) its current flips
    /// sign and rings at 94 Hz; armed, it acts on the load's fall, one-signed.
    pub fn arm_after_release(&mut self, theta_hold: T) {
        let enabled = self.enabled;
        self.enabled = true;
        self.arm(theta_hold);
        self.enabled = enabled;
        self.arm_window = self.window_samples.max(self.hold_samples);
    }

    /// The speed loop's reference for the application's `speed_ref` (electrical rad/s): zero
    /// while a hold the start-up's motion test engaged acts, then rising from zero by the
    /// rated speed per `resume_time` until it meets `speed_ref`; `speed_ref` itself
    /// otherwise.
    pub fn resumed(&mut self, speed_ref: T) -> T {
        if self.active && self.engaged_by_motion {
            return T::zero();
        }
        if !self.resuming {
            return speed_ref;
        }
        let step = self.resume_step;
        let gap = speed_ref - self.resumed;
        // NaN compares false: a non-finite reference ends the ramp (the speed loop refuses it).
        let beyond = gap.abs() > step;
        if !beyond {
            self.resuming = false;
            return speed_ref;
        }
        self.resumed += if gap > T::zero() { step } else { -step };
        self.resumed
    }

    /// Disarmed and not acting (the next [`arm`](Self::arm) re-arms it).
    pub fn disarm(&mut self) {
        self.armed = false;
        self.active = false;
    }

    /// Armed by [`arm_at_release`](Self::arm_at_release) and not acting: from the
    /// application's brake opening until the rotor moves or the trigger window closes.
    pub fn awaiting_fall(&self) -> bool {
        self.released && self.armed && !self.active
    }

    /// [`arm`](Self::arm) at the moment the application opens its brake.
    pub fn arm_at_release(&mut self, theta_hold: T) {
        self.arm(theta_hold);
        self.armed = self.armed && self.enabled;
        self.released = self.armed;
    }

    /// The estimator should track the rotor's fall ([`ReleaseHoldTuning::track_fall`]): from
    /// the application's brake opening until the hold hands over (or its trigger window
    /// closes without a fall), and while a hold armed at the start-up's end acts (a load that
    /// arrives after ready is the same unannounced step).
    pub fn tracking_fall(&self) -> bool {
        self.track_fall && self.armed && (self.released || self.active)
    }

    /// Holding now.
    pub fn active(&self) -> bool {
        self.active
    }

    /// Times the hold acted since the drive was built.
    pub fn engaged(&self) -> u32 {
        self.engaged
    }

    /// The torque the hold stands for, A of magnet q current: its command while it acts, then
    /// its integral (the load it found), kept after the hand-over until the next
    /// [`arm`](Self::arm); zero if it never acted.
    /// The drive's tracker feed-forward takes it off the commanded torque (see
    /// [`tracker_feedforward`](crate::control::tracker_feedforward), "The release hold's
    /// load").
    pub fn load(&self) -> T {
        if self.active {
            self.output
        } else {
            self.integral
        }
    }

    /// The loop's sampling period, s.
    pub fn ts(&self) -> T {
        self.ts
    }

    /// The loop's stiffness ω_h (rad/s) after the caps: its three poles at −ω_h.
    pub fn stiffness(&self) -> T {
        self.kp / self.kd
    }

    /// Armed (at the start-up's end or at a brake's release) on a moving reference `speed_ref`
    /// and not acting: the held angle follows the watched angle (`watched`) wherever it goes
    /// further along the reference (module docs, "On a moving reference"). The reference's
    /// direction, ±1; 0 at a zero or non-finite reference or after a motion the start-up saw.
    fn follow(&mut self, speed_ref: T, watched: T) -> T {
        let follows = speed_ref != T::zero() && !self.engaged_by_motion;
        // NaN compares false: a non-finite reference has no direction.
        let sense = if !follows || !speed_ref.is_finite() {
            T::zero()
        } else if speed_ref > T::zero() {
            T::one()
        } else {
            -T::one()
        };
        if sense != T::zero() && !self.active {
            let ahead = crate::wrap_angle(watched - self.theta_hold) * sense;
            // NaN compares false: a non-finite watched angle leaves it.
            if ahead > T::zero() {
                self.theta_hold = crate::wrap_angle(watched);
            }
        }
        sense
    }

    /// The loop's speed from the direct angle `theta`: its rate low-passed, the change in a
    /// sample at most `omega_step` where that is positive ([`set_saturating`](Self::set_saturating);
    /// zero, or non-finite from an unbounded torque demand, leaves the low-pass as it is).
    fn track_speed(&mut self, theta: T) {
        let rate = crate::wrap_angle(theta - self.theta_last) / self.ts;
        self.theta_last = theta;
        if !rate.is_finite() {
            return;
        }
        let lim = self.omega_step;
        let change = self.omega_gain * (rate - self.omega);
        self.omega += if lim > T::zero() {
            crate::control::pi::clamp(change, -lim, lim)
        } else {
            change
        };
    }

    /// Whether an acting hold ends at this sample: after 10/ω_h (while the reference is zero,
    /// not where it holds through the loaded standstill), or, where the reference left zero
    /// before that while the speed loop could not take the rest of its torque
    /// ([`set_speed_loop`](Self::set_speed_loop); then a motion hold, the speed loop's
    /// reference at zero), once it can (module docs, "When"); held through the loaded
    /// standstill, 10/ω_h after the probe's d current has gone (`standstill.rs`).
    fn settles(&mut self, moving_ref: bool) -> bool {
        let run_back = self.handover_gain * (self.output - self.integral).abs();
        // NaN compares false: not carried.
        let carried = run_back <= self.handover_travel;
        let young = self.active && !self.engaged_by_motion && self.held < self.hold_samples;
        if moving_ref && young && !carried {
            self.engaged_by_motion = true;
            self.carrying = true;
        }
        self.through_probe_exit(moving_ref);
        let standstill_hold = self.through_standstill && !(self.engaged_by_motion && moving_ref);
        let done = self.held >= self.hold_samples || (self.carrying && carried);
        self.active && !standstill_hold && done
    }

    /// One sample: the speed reference `speed_ref`, the estimator's tracked angle θ̂
    /// (`theta_tracked`, which triggers the hold unless it was armed at a brake's release)
    /// and its direct rotor-flux angle (`theta`, which the loop holds and which triggers a
    /// hold armed at a release), electrical. The loop's speed is the direct angle's own rate,
    /// low-passed over 1/(5·ω_h) (1/(4·ω_h) on a saturating model,
    /// [`SATURATING_SPEED_FILTER_RATIO`]), its change in a sample bounded by the acceleration
    /// a rotor can have ([`SPEED_STEP_ACCELERATION_RATIO`]): the tracked angle and the speed
    /// outputs lag a rotor that starts to turn from rest by milliseconds, which the loop's
    /// damping cannot afford; the direct angle moves with the currents' transients at the
    /// first current too (0.02 rad on the 50 kW IPMSM's 44 A injection step, the rotor at
    /// rest), which the tracked angle smooths out and the bound keeps from the D path.
    pub fn step(&mut self, speed_ref: T, theta_tracked: T, theta: T) -> HoldAction<T> {
        if !self.armed {
            return HoldAction::Idle;
        }
        self.track_speed(theta);
        // Engaged by the start-up's motion test, the hold keeps the rotor at any reference
        // until it has settled; armed at a release, a reference hands over a settled hold at
        // once; armed at the start-up's end, a moving reference leaves it armed for a fall
        // against it (module docs, "On a moving reference").
        let moving_ref = speed_ref != T::zero();
        // Armed at a brake's release on a saturating model or capped (`fall`), the hold
        // watches the direct angle its loop holds (the tracked one lags a falling rotor by
        // milliseconds; module docs, "When").
        let on_direct = self.released && (self.release_on_direct || self.fall_gain > T::zero());
        let watched = if on_direct { theta } else { theta_tracked };
        let sense = self.follow(speed_ref, watched);
        let e = crate::wrap_angle(self.theta_hold - theta);
        let omega = self.omega;
        let settled = self.settles(moving_ref);
        // A settled hold triggered at zero reference hands over as the reference leaves zero;
        // one armed and not acting stays armed for a fall against the reference.
        let leave = moving_ref && !self.engaged_by_motion && self.active;
        if leave || settled || !e.is_finite() || !omega.is_finite() {
            let was = self.active;
            if was && self.engaged_by_motion {
                self.resuming = true;
                self.resumed = T::zero();
            }
            self.disarm();
            return if was {
                HoldAction::Handover(self.integral)
            } else {
                HoldAction::Idle
            };
        }
        if !self.active && !self.watch(sense, watched, theta_tracked, e) {
            return HoldAction::Idle;
        }
        self.held = self.held.saturating_add(1);
        let lim = self.i_max;
        self.soft.track(e);
        let (kp, kd, ki_ts) = self.soft.gains(self.kp, self.kd, self.ki_ts);
        self.integral = crate::control::pi::clamp(self.integral + ki_ts * e, -lim, lim);
        let out = kp * e - kd * omega + self.integral;
        self.output = crate::control::pi::clamp(out, -lim, lim);
        HoldAction::Hold(self.output)
    }
}

mod dead_time;
mod fall;
mod standstill;
mod tuning;
mod watch;

#[cfg(test)]
mod tests;
