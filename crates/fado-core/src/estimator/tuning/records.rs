//! The estimator's tuning records, one per block it tunes (each a table of `[estimator]` in
//! `fado-sim`'s TOML, a nested dict in Python): their fields, defaults and sources.

use crate::Real;
use crate::plausibility;
use crate::real::cast_record;
use crate::tracker::{self, BandwidthDefinition};
use crate::{flux, integrand_offset, mode, rs_adaptation};

use super::super::OBSERVER_GAIN_PERIOD;

/// Tuning of the flux integrator (eq. (3)) (`[estimator.integrator]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct IntegratorTuning {
    /// Average the current over the interval for the resistive drop. Default true (docs/method/estimator.md §1 \[A\]).
    pub average_current: bool,
}

impl Default for IntegratorTuning {
    fn default() -> Self {
        Self {
            average_current: flux::DEFAULT_AVERAGE_CURRENT,
        }
    }
}

/// Tuning of the disturbance feedback k_df (Fig. 3) (`[estimator.disturbance_feedback]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct DisturbanceFeedbackTuning<T> {
    /// Disturbance feedback gain k_df in s⁻¹ (Fig. 3), at most 1/ts. Default 0.5 (paper, V).
    pub k_df: T,
    /// Ramp time of k_df on activation in s, 0 = abrupt as in the paper. Default 0 (docs/method/estimator.md §1 \[A\]).
    pub ramp_time: T,
}

cast_record!(DisturbanceFeedbackTuning { k_df, ramp_time ;  });

impl<T: Real> Default for DisturbanceFeedbackTuning<T> {
    fn default() -> Self {
        Self {
            k_df: T::lit(flux::DEFAULT_K_DF),
            ramp_time: T::zero(),
        }
    }
}

/// Tuning of the flux limiter (Fig. 6) (`[estimator.limiter]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct LimiterTuning<T> {
    /// Limiter gain k_af in s⁻¹ (Fig. 6), at most 1/ts (a larger step pulls λ̂r through the
    /// circle). Default 2π·100 (paper, V).
    pub k_af: T,
    /// Limiter radius as a multiple of λ̂f, at least 1. Default 1.15 (paper, V).
    pub radius_ratio: T,
    /// In limiter mode, move λ1 and the observer's λ̂1 and D̂ together by −k_df·Ts·D̂ each
    /// sample. Default true (ours \[A\]; `false` is the paper).
    ///
    /// A shift common to λ1, λ̂1 and D̂ changes nothing the estimator uses: λ2 = λ1 − D̂, λ̂r
    /// and the observer's innovation and z − d are the same. In HI mode k_df·D̂ (acting on λ1
    /// alone) pulls that common mode back; in limiter mode nothing does (the limiter sees
    /// λ̂r only), so the tangential part of a DC integrand error that the observer absorbs
    /// whenever ω̂ ≠ 0 makes λ1 and D̂ ramp together without bound while the angle stays put.
    /// Measured (fado-sim long run, 0 r/min under 7.5 N·m, averaged plant, default sensors):
    /// 0.6 mWb/s, |λ1| ≈ |D̂| ≈ 2.1 Wb after an hour, f32 and f64 alike — in f32 the flux
    /// increments (≈ 0.5 mWb per sample at standstill) would drown in the rounding of λ1
    /// after days. The shift keeps D̂ at rate/k_df instead; θ̂ is unchanged while the
    /// estimator stays in limiter mode (at a hand-over to HI mode D̂ is smaller, so the k_df
    /// transient that follows differs).
    pub recentring: bool,
}

cast_record!(LimiterTuning { k_af, radius_ratio ; recentring });

impl<T: Real> Default for LimiterTuning<T> {
    fn default() -> Self {
        Self {
            k_af: T::lit(flux::DEFAULT_K_AF),
            radius_ratio: T::lit(flux::DEFAULT_LIMITER_RADIUS_RATIO),
            recentring: true,
        }
    }
}

/// Tuning of the selection between limiter and k_df (Fig. 3) (`[estimator.mode]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct ModeTuning<T> {
    /// Speed threshold between limiter and k_df as a fraction of the rated electrical
    /// frequency; threshold + hysteresis below the Nyquist frequency 1/(2·ts). Default 0.015
    /// (paper, V: 1.5 Hz of its motor's 100 Hz).
    pub threshold_ratio: T,
    /// Hysteresis half-band of the threshold as a fraction of the rated electrical frequency,
    /// at most the threshold. Default 0.002 (docs/method/estimator.md §1 \[A\]: 0.2 Hz of 100 Hz).
    pub hysteresis_ratio: T,
}

cast_record!(ModeTuning { threshold_ratio, hysteresis_ratio ;  });

impl<T: Real> Default for ModeTuning<T> {
    fn default() -> Self {
        Self {
            threshold_ratio: T::lit(mode::DEFAULT_THRESHOLD_RATIO),
            hysteresis_ratio: T::lit(mode::DEFAULT_HYSTERESIS_RATIO),
        }
    }
}

/// Tuning of the speed trackers T2S-1 and T2S-2 (`[estimator.tracker]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct TrackerTuning<T> {
    /// Bandwidth of T2S-1 (angle, observer speed) in Hz. Default 60 Hz (paper, V).
    pub t2s1_bandwidth_hz: T,
    /// Bandwidth of T2S-2 (speed for control) in Hz. Default 35 Hz (paper, V).
    pub t2s2_bandwidth_hz: T,
    /// Damping ratio of both trackers. Default 1/√2 (docs/method/estimator.md §4 \[A\]).
    pub damping: T,
    /// Meaning of the tracker bandwidths. Default −3 dB (docs/method/estimator.md §4).
    pub bandwidth_definition: BandwidthDefinition,
    /// Trackers coast (no update) while |λ̂r| is below this fraction of λ̂f. Default 0.2
    /// (docs/method/estimator.md §4 \[A\]).
    pub hold_ratio: T,
    /// The trackers' third (load-acceleration) integrator, as the ratio c of its real pole
    /// to ωn (see [`crate::tracker`], "Acceleration feed-forward"). Default 0: the paper's
    /// type-2 trackers; 0.5 \[A\] with the drive's `tracker_feedforward.enabled` (the range
    /// scenarios: a load pole at half ωn, 8 Hz on T2S-2's 35 Hz, settles a rated load step
    /// within 0.1 rad on the paper's motor, docs/range.md).
    pub load_pole_ratio: T,
    /// Bandwidth of T2S-1 in Hz while the estimator runs in disturbance-feedback mode (above
    /// the mode threshold, where the directly calculated angle comes from the voltage model);
    /// in limiter mode T2S-1 keeps `t2s1_bandwidth_hz`, whose narrower band holds θ̂ against
    /// the limiter's angle errors at standstill. Default 0: the same as `t2s1_bandwidth_hz`
    /// (the paper's one tracker). The drive sets it on a light rotor from its rated-load
    /// acceleration (`fado_core::control::tracker_feedforward`, docs/range.md).
    pub t2s1_running_bandwidth_hz: T,
}

cast_record!(TrackerTuning { t2s1_bandwidth_hz, t2s2_bandwidth_hz, damping, hold_ratio, load_pole_ratio, t2s1_running_bandwidth_hz ; bandwidth_definition });

impl<T: Real> Default for TrackerTuning<T> {
    fn default() -> Self {
        Self {
            t2s1_bandwidth_hz: T::lit(60.0),
            t2s2_bandwidth_hz: T::lit(35.0),
            damping: T::lit(tracker::DEFAULT_DAMPING),
            bandwidth_definition: BandwidthDefinition::default(),
            hold_ratio: T::lit(0.2),
            load_pole_ratio: T::zero(),
            t2s1_running_bandwidth_hz: T::zero(),
        }
    }
}

/// Tuning of the disturbance observer (Fig. 5) (`[estimator.observer]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct ObserverTuning<T> {
    /// Feed the disturbance observer with λ1 − L̂q·i instead of λ1. Default true (our
    /// improvement \[A\]; `false` is the paper's Fig. 5, where the observer sees λ1).
    ///
    /// The observer's internal model (eq. (9)) is "a constant plus a vector rotating at ω".
    /// λ1 = λem·e^{jθ} + L·i + D: the current term L·i only rotates with the rotor while the
    /// current is constant in the rotor frame. A rotor-frame current modulation at f_m (a
    /// speed-loop oscillation, a load step, the i_d* swing at the eq. (23) knee) appears in
    /// α-β at f ± f_m; near standstill-to-low speed f − f_m is close to DC, falls into the
    /// observer's DC pass-band (d/y = ω(ω + js)/(s + |ω|)², docs/method/estimator.md §2) and is taken for a
    /// disturbance: D̂ moves, λ2 = λ1 − D̂ loses part of L·Δi, λ̂r turns, and the loop closes
    /// through θ̂ and the current controller. Subtracting the known L̂q·i first leaves the
    /// observer exactly its model (λ̂r is a rotating vector plus the DC disturbance), so D̂ no
    /// longer responds to current transients. λ2 = λ1 − D̂ and λ̂r = λ2 − L̂q·i are unchanged
    /// in form (eq. (20), (5)); in steady state L̂q·i has no DC, so D̂ is the same. Measured
    /// (fado-sim fig8, switching-resolved, with the drive's offset calibration): the ≈ 5 Hz
    /// oscillation after the 2 N·m step disappears and the worst revolution's DC of λ2 − λs
    /// drops from 6.0 % to 2.1 % of λf, the rest being the observer's speed lag through the
    /// reversal (see `observer.lag_compensation`;
    /// crates/fado-sim/README.md).
    pub on_rotor_flux: bool,
    /// Drive the observer's gains (16) and its internal model's rotation with ω̂1 + c, c the
    /// T2S-1 proportional term Kp·e through a first-order low-pass at the Fig. 3 threshold
    /// frequency, instead of ω̂1 alone. Default true (ours \[A\]; `false` is the paper's
    /// Fig. 5, and gives its results bit for bit with `observer.gain_period` = 0).
    ///
    /// The observer's model (eq. (9)) rotates the flux by ω between samples and places its
    /// notch (eq. (18)-(19)) at ω. Under a constant acceleration α the type-2 tracker's
    /// integrator ω̂1 lags the flux's frequency by Kp·α/Ki = 2ζα/ωn (7.7 ms × α with the
    /// paper's 60 Hz), while the rate of θ̂, ω̂1 + Kp·e, does not (θ̂ − θ is the constant
    /// α/Ki, see [`crate::tracker`]). With the notch off by Δω the observer passes the
    /// rotating flux into D̂ by d/y(jω) = ω̂(ω̂ − ω)/(jω + |ω̂|)², |D̂| ≈ λf·|Δω|/(2|ω|):
    /// growing as 1/|ω| towards zero speed, frozen where ω̂ crosses zero, and then a DC error
    /// of λ2 = λ1 − D̂ that the observer removes only with its time constant 1/|ω̂| after the
    /// LO→HI hand-over. The low-pass keeps Kp·e's ripple out of the observer (unfiltered, the
    /// loop θm → e → observer speed → D̂ → θm doubled fig9's angle ripple), and its time
    /// constant is the observer's own at the hand-over, so that the compensation follows a
    /// change of acceleration as fast as the observer needs it. Measured (fado-sim fig8, the
    /// ramp through zero at 90 r/min/s): the worst revolution's DC of λ2 − λs drops from
    /// 1.67 % to 0.33 % of λf with an averaged inverter without dead time or device drop and
    /// ideal sensors, and from 1.57–2.17 % to 0.29–0.72 % with the default non-idealities on
    /// sensor seeds 1–8 (0.27–0.87 % with a fixed R̂s); the loaded one-hour standstill then
    /// runs to the current limit on four of five seeds instead of one (docs/method/additions.md).
    pub lag_compensation: bool,
    /// The observer's gains (16) are recomputed from its speed once every this many seconds
    /// (rounded to whole samples, at least every sample) and held in between; 0 = every
    /// sample, as in the paper. Default 0.4 ms (4 samples at the paper's 10 kHz) \[A\].
    ///
    /// The gains depend only on the speed the observer runs at, ω̂1 (+ the lag
    /// compensation), which T2S-1's 60 Hz bandwidth keeps from moving much within a
    /// millisecond; forming them (four polynomials, 19 multiplies) is a tenth of the `f32`
    /// step on a Cortex-M4F (docs/results/firmware-cost.md). Held over N samples, the internal model
    /// rotates and the notch sits at the speed of the last update: under an acceleration α
    /// they lag the speed by at most α·(N − 1)·Ts, 0.3 ms × α by default, 4 % of the lag
    /// 2ζ/ωn·α = 7.7 ms × α of T2S-1's own ω̂1 that `observer.lag_compensation` corrects
    /// (through a 106 ms low-pass). The poles stay at the held speed's r = e^{−|ω|Ts}: the
    /// observer is a fixed stable filter between updates. Keep it well below T2S-1's time
    /// constant 1/(2π·`tracker.t2s1_bandwidth_hz`) (2.7 ms at 60 Hz); above 1 s it is refused as a
    /// mistake. Measured (fado-sim fig8–fig12,
    /// sensor seeds 1–8): every run passes, the means of the worst angle error move by at
    /// most 1.1e-3 rad (fig10 0.0562 and 0.0573 rad with the gains every sample and held; docs/method/additions.md).
    pub gain_period: T,
    /// With a saturating magnetic model: run the observer at its speed without the ripple at
    /// the electrical frequency (a notch at |ω̂|, `crate::speed_notch`) where the frame
    /// coupling of `crate::active_flux` exceeds `active_flux::OFFSET_COUPLING_MAX` with the
    /// sign opposite to ω̂ (while the machine generates where L_q,s exceeds L_dd), on a
    /// saturating model or a salient rotor with constant inductances (coupling
    /// (L̂q − L̂d)·î_q/λ̂a). Default true (ours \[A\]; no effect on a surface-magnet
    /// rotor).
    ///
    /// A DC error of λ2 turns θ̂ by a ripple at the electrical frequency; at low speed T2S-1
    /// passes its rate into the observer's speed, which leaks the rotating flux into D̂, and
    /// with a frame coupling near 1 that loop grows while the machine generates
    /// (docs/method/saturation.md, "The slow mode"). Measured (`saturated_replay`, exact
    /// signals at ±6 % of rated speed): with the notch every slow-mode rate is negative at
    /// 30, 65 and 100 % of rated torque on the PM-SyRM preset, a made-up automotive IPMSM and
    /// a made-up ferrite PM-SyRM (frame coupling up to 1.12); without it the PM-SyRM's grows
    /// while generating at rated torque.
    pub frame_ripple_notch: bool,
}

cast_record!(ObserverTuning { gain_period ; on_rotor_flux, lag_compensation, frame_ripple_notch });

impl<T: Real> Default for ObserverTuning<T> {
    fn default() -> Self {
        Self {
            on_rotor_flux: true,
            lag_compensation: true,
            gain_period: T::lit(OBSERVER_GAIN_PERIOD),
            frame_ripple_notch: true,
        }
    }
}

/// Tuning of the online R̂s law (`[estimator.rs_adaptation]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct RsAdaptationTuning<T> {
    /// Adapt R̂s online (our extension \[A\], see [`crate::rs_adaptation`]): from the d-axis
    /// voltage at standstill under the eq. (23) injection, and from the flux-magnitude error
    /// while turning. `false` keeps R̂s fixed as in the paper. Default true.
    ///
    /// Why on by default: with a fixed R̂s the loaded zero-speed passages of Fig. 11 and
    /// Fig. 12 are lost for a resistance error of a few per cent (the winding's resistance moves
    /// by 30 % between cold and hot). Measured in fado-sim (switching-resolved, default
    /// non-idealities): both pass for a plant resistance from 0.8× to 1.3× the configured one,
    /// the Fig. 11 reversal also under the rated 11.5 N·m, and with matched parameters the
    /// worst zero-speed angle error drops from 0.16 to 0.12 rad (Fig. 11) and from 0.18 to
    /// 0.09 rad (Fig. 12).
    pub enabled: bool,
    /// γ of the R̂s adaptation in s⁻¹. Default as [`ResistanceAdaptationConfig::rate`](crate::rs_adaptation::ResistanceAdaptationConfig::rate).
    pub rate: T,
    /// χ0 of the R̂s adaptation. Default as [`ResistanceAdaptationConfig::excitation_floor`](crate::rs_adaptation::ResistanceAdaptationConfig::excitation_floor).
    pub excitation_floor: T,
    /// Lower bound of the adapted R̂s as a multiple of `rs_hat`. Default as
    /// [`ResistanceAdaptationConfig::min_ratio`](crate::rs_adaptation::ResistanceAdaptationConfig::min_ratio).
    pub min_ratio: T,
    /// Upper bound of the adapted R̂s as a multiple of `rs_hat`. Default as
    /// [`ResistanceAdaptationConfig::max_ratio`](crate::rs_adaptation::ResistanceAdaptationConfig::max_ratio).
    pub max_ratio: T,
    /// With `rs_adaptation.enabled`: rate k_θ in s⁻¹ at which, at standstill under the eq. (23)
    /// injection (the current along the estimated d axis, light load), λ̂r is turned towards
    /// the stator current (ours \[A\], see [`crate::rs_adaptation`]); 0 = off. Default as
    /// [`ResistanceAdaptationConfig::standstill_angle_rate`](crate::rs_adaptation::ResistanceAdaptationConfig::standstill_angle_rate) (2 s⁻¹).
    ///
    /// Measured (fado-sim fig10, switching-resolved, sensor seeds 1–8): the worst angle error
    /// over the run drops from 0.384 rad (off) to 0.308 rad, and during the hold the error
    /// decays instead of walking; what remains is the swing at the stop, before the law acts
    /// (0.5, 1, 4 and 8 s⁻¹ and a 1 Hz filter on i_q/i_d were worse: docs/method/additions.md).
    pub standstill_angle_rate: T,
    /// How far the magnetic model's flux may be from the machine's, as a share of the model's
    /// λ̂f: on a saturating model the turning law freezes where what the model leaves open
    /// exceeds the flux error of a 2 % resistance error (ours \[A\], see
    /// [`ResistanceAdaptationConfig::model_flux_uncertainty`](crate::rs_adaptation::ResistanceAdaptationConfig::model_flux_uncertainty)).
    /// Default 0: the model is the machine's (a measured map, the machine's own algebraic
    /// model); the `identified.toml` of `fado-sim commission` sets its identified model's
    /// figure. The figure at zero current: the law adds `model_flux_uncertainty_rated` times
    /// the present current's square over the rated current's.
    pub model_flux_uncertainty: T,
    /// How much the model's flux uncertainty grows up to the rated current, as a share of the
    /// model's λ̂f: at the current î the turning law takes the model's flux to be off the
    /// machine's by (`model_flux_uncertainty` + `model_flux_uncertainty_rated`·|î|²/I_rated²)
    /// of λ̂f (ours \[A\], see
    /// [`ResistanceAdaptationConfig::model_flux_growth`](crate::rs_adaptation::ResistanceAdaptationConfig::model_flux_growth)).
    /// Default 0; the `identified.toml` of `fado-sim commission` sets its identified model's
    /// figure (`fado_core::commissioning::Identification::model_flux_uncertainty_rated`).
    pub model_flux_uncertainty_rated: T,
}

cast_record!(RsAdaptationTuning { rate, excitation_floor, min_ratio, max_ratio, standstill_angle_rate, model_flux_uncertainty, model_flux_uncertainty_rated ; enabled });

impl<T: Real> Default for RsAdaptationTuning<T> {
    fn default() -> Self {
        Self {
            enabled: true,
            rate: T::lit(rs_adaptation::DEFAULT_RATE),
            excitation_floor: T::lit(rs_adaptation::DEFAULT_EXCITATION_FLOOR),
            min_ratio: T::lit(rs_adaptation::DEFAULT_MIN_RATIO),
            max_ratio: T::lit(rs_adaptation::DEFAULT_MAX_RATIO),
            standstill_angle_rate: T::lit(rs_adaptation::DEFAULT_STANDSTILL_ANGLE_RATE),
            model_flux_uncertainty: T::zero(),
            model_flux_uncertainty_rated: T::zero(),
        }
    }
}

/// Tuning of the λ̂f law (`[estimator.flux_linkage_adaptation]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct FluxLinkageAdaptationTuning<T> {
    /// With `rs_adaptation.enabled`: rate at which the flux-magnitude reference λ̂f is learned where R̂s
    /// is not observable, s⁻¹ (0 = the configured λ̂f throughout). Default as
    /// [`ResistanceAdaptationConfig::flux_linkage_rate`](crate::rs_adaptation::ResistanceAdaptationConfig::flux_linkage_rate) (5 s⁻¹).
    ///
    /// Measured (fado-sim fig11, switching-resolved, default settings otherwise): with λ̂f
    /// −10 % / +10 % / −5 % and R̂s +10 % the worst near-zero-speed angle error drops from
    /// 1.02 / 1.21 / 0.98 rad (off) to 0.03 / 0.15 / 0.09 rad; with λ̂f right nothing moves
    /// (fig8, fig10 on seeds 1–8, fig12: the same results, the revolution means stay inside
    /// the law's 1 % dead zone; docs/method/additions.md).
    pub rate: T,
}

cast_record!(FluxLinkageAdaptationTuning { rate ;  });

impl<T: Real> Default for FluxLinkageAdaptationTuning<T> {
    fn default() -> Self {
        Self {
            rate: T::lit(rs_adaptation::DEFAULT_FLUX_LINKAGE_RATE),
        }
    }
}

/// Tuning of the integrand-offset law (`[estimator.offset_adaptation]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct OffsetAdaptationTuning<T> {
    /// With `rs_adaptation.enabled`: rate k_e in s⁻¹ at which a constant integrand error (a voltage
    /// offset) is learned while turning and subtracted from the integrand in both modes
    /// (ours \[A\], see [`crate::integrand_offset`]); 0 = off. Default as
    /// [`IntegrandOffsetConfig::rate`](crate::integrand_offset::IntegrandOffsetConfig::rate) (2 s⁻¹).
    ///
    /// Measured (fado-sim fig11, switching-resolved, 0.1 V on the α voltage): the worst
    /// near-zero-speed angle error drops from 1.21 rad (off) to 0.13 rad (docs/method/additions.md).
    pub rate: T,
    /// The law learns only while an electrical revolution spans at least this many samples,
    /// |ω̂|·Ts ≤ 2π/N (it holds ê above that speed; the re-centring goes on). Default
    /// [`MIN_REVOLUTION_SAMPLES`](crate::integrand_offset::MIN_REVOLUTION_SAMPLES) (64; see
    /// there: an error locked to the rotor and the carrier aliases onto the DC the law reads).
    pub min_revolution_samples: T,
}

cast_record!(OffsetAdaptationTuning { rate, min_revolution_samples ;  });

impl<T: Real> Default for OffsetAdaptationTuning<T> {
    fn default() -> Self {
        Self {
            rate: T::lit(integrand_offset::DEFAULT_RATE),
            min_revolution_samples: T::lit(integrand_offset::MIN_REVOLUTION_SAMPLES),
        }
    }
}

/// Tuning of the sample bounds (`[estimator.plausibility]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct PlausibilityTuning<T> {
    /// A sample whose α-β current's magnitude reaches this multiple of the rated current is
    /// refused like a non-finite one (see [`crate::plausibility`]). Default
    /// [`plausibility::CURRENT_RATIO`] (4; 87.1 A for the paper's motor) \[A\].
    pub current_ratio: T,
    /// A sample whose α-β voltage's magnitude reaches this multiple of the DC-link voltage
    /// is refused. Default [`plausibility::VOLTAGE_RATIO`] (1.5; 450 V for the
    /// paper's 300 V link) \[A\].
    pub voltage_ratio: T,
    /// A current whose α-β vector moved by this × (plausible voltage)·ts/L̂q per sample or
    /// more since the last accepted one is refused; 0 disables the test. Default
    /// [`plausibility::STEP_RATIO`] (2) \[A\].
    pub current_step_ratio: T,
}

cast_record!(PlausibilityTuning { current_ratio, voltage_ratio, current_step_ratio ;  });

impl<T: Real> Default for PlausibilityTuning<T> {
    fn default() -> Self {
        Self {
            current_ratio: T::lit(plausibility::CURRENT_RATIO),
            voltage_ratio: T::lit(plausibility::VOLTAGE_RATIO),
            current_step_ratio: T::lit(plausibility::STEP_RATIO),
        }
    }
}

/// Tuning of the loss-of-lock detector (`[estimator.lock]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields, default)
)]
pub struct LockTuning<T> {
    /// Loss of lock (see [`crate::lock`]): |λ̂r| below this multiple of λ̂f is a symptom while
    /// |ω̂| is below the mode hand-over band (`mode.threshold_ratio` −
    /// `mode.hysteresis_ratio`, 0.013 of the rated speed; above it,
    /// `lock.flux_low_fast_ratio`). Default 0.7 \[A\] (chosen on the fig11 envelope sweep,
    /// docs/method/lock.md). 0.65 no longer flags the start-up of fig11 with R̂s +10 % (|λ̂r| below
    /// 0.7·λ̂f from 0.298 s at ω̂ −12 r/min, down to 0.67·λ̂f; the error passes 0.5 rad at
    /// 0.40 s), the flag
    /// with which the `recover` reaction switches the R̂s adaptation on in time for the
    /// loaded reversal; flagged only at the loss, that run coasts under its active load and
    /// runs away. The same start-up dip precedes the 0.5 rad start-up excursions of the
    /// envelope (57 of 67 flagged within 20 ms on seeds 7–14).
    pub flux_low_ratio: T,
    /// Loss of lock: |λ̂r| below this multiple of λ̂f is a symptom while |ω̂| is at or above
    /// the lower edge of the mode hand-over band (`mode.threshold_ratio` −
    /// `mode.hysteresis_ratio`). Default 0.6 \[A\] (docs/method/lock.md, 2026-11-24): accelerating
    /// out of the reversal at light load, runs that keep the rotor dip to 0.67–0.70·λ̂f
    /// around the limiter → k_df hand-over (at 17–29 r/min on the paper's motor; 0.7 flagged
    /// them: 3 of 809 passing runs on seeds 7–14), while the losses this half of the symptom
    /// alone catches go through 0.42–0.53·λ̂f; 0.55–0.65 measured alike, 0 missed 4 losses.
    /// Equal to `lock.flux_low_ratio`, one bound at every speed (before 2026-11-24).
    pub flux_low_fast_ratio: T,
    /// Loss of lock: |λ̂r| above this multiple of λ̂f is a symptom; 0 switches it off.
    /// Default 1.5 \[A\]: above the limiter circle (1.15) and the 1.20–1.22·λ̂f overshoot
    /// after a limiter → k_df hand-over in runs that keep the rotor (a bound of 1.2
    /// false-alarmed there, 1.3 still 2–3 times per 400 runs, 1.4 once per 400 after the
    /// reversal, |λ̂r| 1.41·λ̂f with a 0.26 rad error), within the 1.4–1.6·λ̂f of a fixed-R̂s
    /// drive that an active load runs away with in k_df mode (those losses the drive's stall
    /// symptom now sees too: 1.5 detects as many as 1.4, docs/method/lock.md). The voltage of a
    /// machine turning the other way gives 1.3–4.8·λ̂f.
    pub flux_high_ratio: T,
    /// Loss of lock: a T2S-1 innovation |θm − θ̂⁻| above this (rad) is a symptom. Default
    /// 0.5 rad \[A\] (the angle error the drive must not reach, docs/method/lock.md).
    pub innovation_limit: T,
    /// Loss of lock: net symptomatic time (s) before [`LockStatus::Lost`](crate::LockStatus::Lost); 0 disables the
    /// detector. Default 5 ms \[A\] (a quarter of the 20 ms detection target; 5–20 ms made
    /// no difference on the envelope, docs/method/lock.md).
    pub detection_time: T,
    /// Loss of lock: net clean time (s) after which [`LockStatus::Lost`](crate::LockStatus::Lost) clears (the status
    /// is live; the drive's reaction latches, [`crate::control::lock_reaction`]). Default
    /// 0.1 s \[A\]: twenty detection times, so that the intermittent symptoms of a lost
    /// estimate keep it up, and short against the seconds between a start-up transient and a
    /// later loss (docs/method/lock.md).
    pub heal_time: T,
    /// Loss of lock: in limiter mode, a sample in which the limiter clamps is a symptom.
    /// Default false \[A\]: a rotor lost in limiter mode clamps continuously (fig11 with
    /// λ̂f +10 %) and a matched drive never clamps, but an adapted R̂s biased by a λ̂f error
    /// makes the limiter clamp through passages it survives (false alarms, docs/method/lock.md).
    pub limiter_clamping: bool,
    /// Loss of lock: a rate of mode hand-overs (Fig. 3) of this many per
    /// `lock.handover_time` is a symptom (a leaky count, see [`crate::lock`], symptom 3);
    /// 0 switches it off. Default 5 \[A\] (docs/method/lock.md): a
    /// sustained 50 hand-overs a second, or a burst of five. On the reversal envelopes of the
    /// seven presets the count of runs that keep the rotor within 0.25 rad stays at 1.0–1.9
    /// on five, and reaches 3.9 on pmsyrm-5k and 4.0 on ipmsm-gem-50k; most start-up limit
    /// cycles that lose ipmsm-gem-50k's rotor reach 5–28.
    pub handover_count: T,
    /// Loss of lock: the time constant of the hand-over count's decay, s. Default 0.1 s
    /// \[A\] (docs/method/lock.md).
    pub handover_time: T,
}

cast_record!(LockTuning { flux_low_ratio, flux_low_fast_ratio, flux_high_ratio, innovation_limit, detection_time, heal_time, handover_count, handover_time ; limiter_clamping });

impl<T: Real> Default for LockTuning<T> {
    fn default() -> Self {
        Self {
            flux_low_ratio: T::lit(0.7),
            flux_low_fast_ratio: T::lit(0.6),
            flux_high_ratio: T::lit(1.5),
            innovation_limit: T::lit(0.5),
            detection_time: T::lit(5e-3),
            heal_time: T::lit(0.1),
            limiter_clamping: false,
            handover_count: T::lit(5.0),
            handover_time: T::lit(0.1),
        }
    }
}
