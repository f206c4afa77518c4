//! `[controller.release_hold]`: the release hold's settings (the loop: [`super`]).

use crate::Real;
use crate::real::cast_record;

/// `[controller.release_hold]`: the release hold's settings (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(
        deny_unknown_fields,
        default,
        bound(
            serialize = "T: serde::Serialize",
            deserialize = "T: Real + serde::Deserialize<'de>"
        )
    )
)]
pub struct ReleaseHoldTuning<T> {
    /// Hold a rotor that a load turns after an application's brake opens
    /// ([`SensorlessDrive::arm_release_hold`](crate::control::SensorlessDrive::arm_release_hold)),
    /// raise the current loop where the hold needs it and hold through a light rotor's loaded
    /// standstill. Default false: under a wrong machine model (L̂q +25 % on the 50 kW IPMSM)
    /// it triggers on the estimate's own start-up drift and loses the rotor earlier;
    /// `fado-sim`'s `loaded-start` turns it on. The start-up's own end is `at_start`'s.
    pub enabled: bool,
    /// Hold a rotor that a load turns within `window` of the start-up's end (a free rotor,
    /// not `StartupTuning::rotor_held`), whether `enabled` or not: at zero speed reference
    /// once θ̂ leaves the aligned angle by `trigger`, on a moving reference once it falls
    /// back against it by `trigger` from the furthest angle it reached (module docs, "On a
    /// moving reference"). Default false: the speed loop alone lets half the rated torque
    /// arriving 5–20 ms after ready turn the light rotors of
    /// `crates/fado-sim/tests/calibration_load_classes.rs` back 1.0–48 rad, which this hold
    /// keeps within the benchmark's criteria (module docs, "On a moving reference"), yet
    /// on a strongly salient rotor with a weak magnet it engages on the start's own estimate
    /// transient at zero reference and its position loop loses the rotor: the saturated
    /// PM-SyRM `motors/saturated/pmsyrm-baldor-5k6.toml` (Lq/Ld ≈ 5) then loses `fullrange`
    /// (3.14 rad at seeds 2–4 and 0.143 rad at seed 1; 0.141–0.148 rad without it: the hold
    /// triggers 20 ms after ready on the unloaded rotor, and its loop on the direct angle,
    /// whose rate there runs against the rotor's, swings the rotor with a growing amplitude
    /// until the estimate is lost). An application that knows its rotor is light
    /// and its model right turns it on.
    pub at_start: bool,
    /// Backward travel (electrical rad) the rated torque causes, which sets the loop's
    /// stiffness. Default 0.2 rad \[A\]: 40 % of the 0.5 rad a loaded start may lose.
    pub travel: T,
    /// Angle (electrical rad) θ̂ leaves the aligned angle by before the hold acts. Default
    /// 0.02 rad \[A\]: well above θ̂'s own movement at an unloaded standstill, a tenth of
    /// `travel`.
    pub trigger: T,
    /// Time after the alignment (s) within which a turning rotor triggers the hold. Default
    /// 0.05 s \[A\]: a brake releasing at ready lets a rated load move the rotor by the
    /// trigger within 6 ms on the presets (the hub motor's 0.11 kg·m² the slowest); a start-up
    /// that drifts later (an estimate lost under a wrong model) is left to the speed loop.
    pub window: T,
    /// From the brake's opening (or, armed at the start-up's end, from the trigger) until the
    /// hold hands over, the estimator's T2S-1 tracks at
    /// its running bandwidth in limiter mode too (where the drive has derived one,
    /// [`tracker_feedforward`](crate::control::tracker_feedforward), "T2S-1 at a brake's
    /// release"): the fall is the unannounced step of the rated load that bandwidth is placed
    /// against. Default true \[A\]: measured on the made-up 45 µH 48 V motor (`loaded-start`
    /// seeds 1–4), max |θ − θ̂| from ready 0.22–0.29 rad with the standstill's 60 Hz,
    /// 0.07–0.08 rad with it (docs/results/startup.md).
    pub track_fall: bool,
    /// After a motion hold ([`ReleaseHold::engage`](super::ReleaseHold::engage), or a hold
    /// the reference left before it settled), the time (s) in which the speed loop's
    /// reference rises from zero to the rated speed until it meets the application's
    /// reference. Default 2 s \[A\]: the rotor leaves the held standstill
    /// at half its rated speed per second, within what the estimator follows from rest
    /// (measured on a 1.5 kW servo of 0.15 s mechanical start time, no load: 0.075 rad at
    /// 1/3 of its rated speed per second, 0.20 rad at 1, 0.25 rad after a step of 6.4 % of
    /// its rated speed; `crates/fado-sim/tests/calibration_load_classes.rs`).
    pub resume_time: T,
}

impl<T: Real> Default for ReleaseHoldTuning<T> {
    fn default() -> Self {
        Self {
            enabled: false,
            at_start: false,
            travel: T::lit(0.2),
            trigger: T::lit(0.02),
            window: T::lit(0.05),
            track_fall: true,
            resume_time: T::lit(2.0),
        }
    }
}

cast_record!(ReleaseHoldTuning { travel, trigger, window, resume_time ; enabled, at_start, track_fall });
