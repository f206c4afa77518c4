//! The DC link seen from the drive: the power it may draw and return, and the over-voltage
//! controller and trip.
//!
//! **Why.** A drive fed by a battery or a rectifier is not fed by an ideal source: a battery
//! has a discharge and a charge current limit, a diode rectifier takes no power back at all,
//! and the link capacitor between them and the inverter is small (a few ms of rated power).
//! Braking at the current limit returns the kinetic energy to that capacitor; without a brake
//! chopper, a few hundred joules raise it past the devices' rating within milliseconds. Every
//! industrial drive therefore (i) limits its motoring and regenerating power by the source's
//! current limits and (ii) runs an over-voltage controller that lowers the braking torque as
//! the bus rises, so that a hard stop decelerates only as fast as the losses and the source
//! can absorb, and trips only if the bus still rises to the trip level.
//!
//! **What.** The limits act on the speed loop's torque demand τ (in units of the magnet's q
//! current, `T = 1.5·p·λ̂f·τ`), whose mechanical power at the electrical speed ω̂ is
//! `P = 1.5·λ̂f·ω̂·τ` (positive motoring):
//!
//! * motoring (τ·ω̂ > 0): `P ≤ v_dc·I_bat` (`battery_current_limit_ratio`);
//! * regenerating (τ·ω̂ < 0): `−P ≤ v_dc·I_reg` (`regeneration_current_limit_ratio`), and,
//!   above `over_voltage_start_ratio` × the nominal bus voltage, `−P` at most the power of
//!   the current limit at the present speed derated linearly to zero at
//!   `over_voltage_stop_ratio` × nominal (a proportional over-voltage controller: the
//!   regenerated power falls continuously as the bus rises, so the bus settles inside the
//!   band where the regenerated power equals what the losses and the source take);
//! * while the over-voltage controller derates (by a share s < 1 of the current limit), the
//!   drive brakes with its losses: it adds a d current −[`LOSS_BRAKING_RATIO`]·(1 − s)·I_max
//!   (no torque on a surface-magnet rotor; the drive's torque solver accounts for the
//!   reluctance torque on a salient one) and allows the regenerated power that
//!   [`LOSS_CREDIT`] of the copper losses 1.5·R̂s·|i|² take, so that a drive on a rectifier without a chopper still stops, at the
//!   rate its own resistance can absorb (flux braking; Hughes & Drury, *Electric Motors and
//!   Drives*, 5th ed., §9.4.3);
//! * the drive trips when the measured bus stays above `over_voltage_trip_ratio` × nominal
//!   for [`OVER_VOLTAGE_TRIP_SAMPLES`] samples.
//!
//! Losses come on top of the mechanical power: the copper losses make motoring draw more and
//! regeneration return less than P, so the limits err on the safe side when braking. Below
//! [`MIN_POWER_SPEED_RATIO`] of the rated speed the mechanical power is negligible and the
//! limits do not act (the torque at standstill stays available to hold a load).
//!
//! The speed loop's anti-windup sees the limited torque (`realised`), so a limited stop
//! does not wind its integrator up.

use crate::Real;
use crate::error::{ConfigError, check};
use crate::machine::MachineModel;

/// `[controller.dc_link]`: the DC-link limits of the drive, as ratios of the machine's
/// ratings and nominal bus voltage.
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
pub struct DcLinkTuning<T> {
    /// The source's discharge current limit as a multiple of the rated DC current
    /// `P_rated / V_dc` (P_rated = rated torque × rated speed). Default none (no limit) \[A\].
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub battery_current_limit_ratio: Option<T>,
    /// The source's charge (regeneration) current limit as a multiple of the rated DC current.
    /// Default none \[A\] (a rectifier needs none: the over-voltage controller stops a drive
    /// on it).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub regeneration_current_limit_ratio: Option<T>,
    /// The over-voltage controller starts derating the regenerated power at this multiple of
    /// the nominal bus voltage. Default 1.1 \[A\] (mains at +10 % stays below it).
    pub over_voltage_start_ratio: T,
    /// … and regenerates nothing at this multiple. Default 1.25 \[A\] (the 400 V class's
    /// 750 V chopper level on a 600 V bus; below the trip).
    pub over_voltage_stop_ratio: T,
    /// The drive trips when the bus stays above this multiple of the nominal voltage. Default
    /// 1.35 \[A\] (an 810 V trip on a 600 V bus, below the 900 V of 1200 V devices' margin;
    /// below the 1.5 at which a reading is refused as implausible).
    pub over_voltage_trip_ratio: T,
}

impl<T: Real> Default for DcLinkTuning<T> {
    fn default() -> Self {
        Self {
            battery_current_limit_ratio: None,
            regeneration_current_limit_ratio: None,
            over_voltage_start_ratio: T::lit(1.1),
            over_voltage_stop_ratio: T::lit(1.25),
            over_voltage_trip_ratio: T::lit(1.35),
        }
    }
}

impl<T: Real> DcLinkTuning<T> {
    /// The same tuning in another scalar type.
    pub fn cast<U: Real>(&self) -> DcLinkTuning<U> {
        DcLinkTuning {
            battery_current_limit_ratio: self
                .battery_current_limit_ratio
                .map(|x| U::lit(x.to_f64())),
            regeneration_current_limit_ratio: self
                .regeneration_current_limit_ratio
                .map(|x| U::lit(x.to_f64())),
            over_voltage_start_ratio: U::lit(self.over_voltage_start_ratio.to_f64()),
            over_voltage_stop_ratio: U::lit(self.over_voltage_stop_ratio.to_f64()),
            over_voltage_trip_ratio: U::lit(self.over_voltage_trip_ratio.to_f64()),
        }
    }
}

/// Samples the bus must stay above the trip level before the drive trips: 10 (1 ms at
/// 10 kHz) \[A\], so that one glitch of the sensor does not trip.
pub const OVER_VOLTAGE_TRIP_SAMPLES: u16 = 10;
/// The loss-braking d current at a full derating, as a fraction of the current limit: 0.8
/// \[A\] (leaves 0.6·I_max for the braking torque on the current circle).
pub const LOSS_BRAKING_RATIO: f64 = 0.8;
/// The share of the model's copper losses the over-voltage controller counts on: 0.5 \[A\].
/// An angle error δ turns the loss-braking d current into δ·i_d of extra q current, and R̂s
/// may be low: at a full bus, counting on all of them let the paper's motor push
/// 150 W more into the link than its losses took (a 6 % error of a 0.33 Ω R̂s, 0.065 rad at
/// 32 A), enough to reach the trip level within 15 ms on its 187 µF.
pub const LOSS_CREDIT: f64 = 0.5;
/// Below this fraction of the rated speed the power limits do not act: 2 % \[A\].
pub const MIN_POWER_SPEED_RATIO: f64 = 0.02;

/// The DC-link limiter and over-voltage trip.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DcLinkLimit<T> {
    /// 1.5·λ̂f: power per (rad/s · A of τ).
    power_per_torque: T,
    /// R̂s/λ̂f: the copper losses 1.5·R̂s·|i|² over 1.5·λ̂f.
    loss_per_torque: T,
    /// The current limit I_max, A.
    current_limit: T,
    battery_current: T,
    regeneration_current: T,
    v_start: T,
    v_stop: T,
    v_trip: T,
    /// τ at the current limit (the speed loop's own limit).
    torque_limit: T,
    min_speed: T,
    above_trip: u16,
    /// Filter gain of the bus voltage's rate (a first-order low-pass of
    /// [`RATE_FILTER_TIME`]).
    rate_gain: T,
    /// 1/Ts.
    inv_ts: T,
    /// Last bus voltage, V (NaN before the first).
    last_vdc: T,
    /// Filtered rate of rise of the bus, V/s.
    rate: T,
}

/// The over-voltage controller acts on the bus voltage predicted this far ahead, s: 1 ms
/// \[A\], the lag from the torque demand to the regenerated power (one sample of computation,
/// the 1.5-sample voltage advance and the current loop's 0.64 ms time constant at 250 Hz).
/// A link capacitor of 5 ms of rated power rises by ~30 V in that time under a braking at
/// 1.8× the rated power on the paper's motor: without the lead the bus overshoots the
/// controller's band by that much.
pub const LEAD_TIME: f64 = 1e-3;
/// Low-pass time constant of the measured rate of rise, s: 0.5 ms \[A\] (five samples
/// average the PWM-synchronous ripple of the bus current).
pub const RATE_FILTER_TIME: f64 = 0.5e-3;

impl<T: Real> DcLinkLimit<T> {
    /// The limiter of `machine` (ratings, λ̂f, nominal bus voltage) with the speed loop's
    /// torque limit `torque_limit` (A of τ).
    pub fn new(
        t: &DcLinkTuning<T>,
        machine: &MachineModel<T>,
        torque_limit: T,
        current_limit: T,
        ts: T,
    ) -> Result<Self, ConfigError> {
        let ts = check::positive("ts", ts)?;
        let v = machine.dc_voltage;
        let rated_power = machine.rated_torque * machine.rated_speed_mech();
        let i_dc = rated_power / v;
        // Keys as `[controller]` names them; no limit is +∞ here.
        let limit = |field: &'static str, x: Option<T>| match x {
            Some(x) => check::non_negative(field, x),
            None => Ok(T::lit(f64::INFINITY)),
        };
        let bat = limit(
            "dc_link.battery_current_limit_ratio",
            t.battery_current_limit_ratio,
        )?;
        let reg = limit(
            "dc_link.regeneration_current_limit_ratio",
            t.regeneration_current_limit_ratio,
        )?;
        let start = check::positive(
            "dc_link.over_voltage_start_ratio",
            t.over_voltage_start_ratio,
        )?;
        let stop = check::positive("dc_link.over_voltage_stop_ratio", t.over_voltage_stop_ratio)?;
        let trip = check::positive("dc_link.over_voltage_trip_ratio", t.over_voltage_trip_ratio)?;
        if stop <= start || trip < stop {
            return Err(ConfigError::OutOfRange {
                field: "dc_link.over_voltage_stop_ratio",
                expected: "between over_voltage_start_ratio and over_voltage_trip_ratio",
            });
        }
        Ok(Self {
            power_per_torque: T::lit(1.5) * machine.flux_linkage,
            loss_per_torque: T::lit(LOSS_CREDIT) * machine.rs / machine.flux_linkage,
            current_limit,
            battery_current: bat * i_dc,
            regeneration_current: reg * i_dc,
            v_start: start * v,
            v_stop: stop * v,
            v_trip: trip * v,
            torque_limit,
            min_speed: T::lit(MIN_POWER_SPEED_RATIO) * machine.rated_speed(),
            above_trip: 0,
            rate_gain: ts / (T::lit(RATE_FILTER_TIME) + ts),
            inv_ts: T::one() / ts,
            last_vdc: T::lit(f64::NAN),
            rate: T::zero(),
        })
    }

    /// The torque demand `tau` (A of τ) limited for the bus voltage `vdc` (V, measured, one
    /// call per sample) at the electrical speed `omega` (rad/s, estimated), with the current
    /// reference of the last sample `i_last` (A, for its copper losses); and the loss-braking
    /// d current to add (A, ≤ 0). Returns `(tau, 0)`, `tau` bit for bit, when no limit acts.
    #[inline]
    pub fn limit(&mut self, tau: T, vdc: T, omega: T, i_last: T) -> (T, T) {
        if vdc.is_finite() {
            if self.last_vdc.is_finite() {
                let r = (vdc - self.last_vdc) * self.inv_ts;
                self.rate += self.rate_gain * (r - self.rate);
            }
            self.last_vdc = vdc;
        }
        let w = omega.abs();
        // (NaN speeds compare false: no limit then either.)
        if w.partial_cmp(&self.min_speed) != Some(core::cmp::Ordering::Greater) || !vdc.is_finite()
        {
            return (tau, T::zero());
        }
        let per_ampere = self.power_per_torque * w;
        let clamp = |tau: T, bound: T| {
            if tau.abs() > bound {
                bound * tau.signum()
            } else {
                tau
            }
        };
        if tau * omega > T::zero() {
            // Motoring: P = per_ampere·|τ| ≤ v·I_bat.
            return (
                clamp(tau, vdc * self.battery_current / per_ampere),
                T::zero(),
            );
        }
        let bound = vdc * self.regeneration_current / per_ampere;
        let v = vdc + T::lit(LEAD_TIME) * self.rate.step_max(T::zero());
        if v <= self.v_start {
            return (clamp(tau, bound), T::zero());
        }
        let share = ((self.v_stop - v) / (self.v_stop - self.v_start)).step_max(T::zero());
        let brake_id = -T::lit(LOSS_BRAKING_RATIO) * (T::one() - share) * self.current_limit;
        // What the copper losses take, as τ: 1.5·R̂s·|i|² / (1.5·λ̂f·|ω̂|).
        let i_sq = i_last * i_last;
        let losses = if i_sq.is_finite() {
            self.loss_per_torque * i_sq / w
        } else {
            T::zero()
        };
        let bound = bound.step_min(share * self.torque_limit + losses);
        (clamp(tau, bound), brake_id)
    }

    /// One sample of the over-voltage trip: true once the bus has stayed above the trip level
    /// for [`OVER_VOLTAGE_TRIP_SAMPLES`] samples.
    #[inline]
    pub fn over_voltage(&mut self, vdc: T) -> bool {
        if vdc > self.v_trip {
            self.above_trip = self.above_trip.saturating_add(1);
        } else {
            self.above_trip = 0;
        }
        self.above_trip >= OVER_VOLTAGE_TRIP_SAMPLES
    }

    /// Clears the trip counter.
    pub fn reset(&mut self) {
        self.above_trip = 0;
        self.last_vdc = T::lit(f64::NAN);
        self.rate = T::zero();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One call on a steady bus (no rate of rise).
    fn once(l: &mut DcLinkLimit<f64>, tau: f64, vdc: f64, w: f64) -> f64 {
        l.reset();
        l.limit(tau, vdc, w, 0.0).0
    }

    fn limiter(t: DcLinkTuning<f64>) -> (DcLinkLimit<f64>, MachineModel<f64>) {
        let m = MachineModel::<f64>::paper();
        (DcLinkLimit::new(&t, &m, 40.0, 40.0, 1e-4).unwrap(), m)
    }

    #[test]
    fn no_limit_by_default_at_the_nominal_bus() {
        let (mut l, m) = limiter(DcLinkTuning::default());
        let v = m.dc_voltage;
        for (tau, w) in [(40.0, 600.0), (-40.0, 600.0), (40.0, -600.0), (-12.3, 1.0)] {
            assert_eq!(once(&mut l, tau, v, w), tau);
            assert_eq!(once(&mut l, tau, 1.09 * v, w), tau);
        }
    }

    #[test]
    fn source_current_limits_bound_the_power() {
        let t = DcLinkTuning {
            battery_current_limit_ratio: Some(1.0),
            regeneration_current_limit_ratio: Some(0.5),
            ..Default::default()
        };
        let (mut l, m) = limiter(t);
        let v = m.dc_voltage;
        let p_rated = m.rated_torque * m.rated_speed_mech();
        let w = m.rated_speed();
        let p = |tau: f64| 1.5 * m.flux_linkage * w * tau;
        // Motoring at the current limit is capped at the rated power; regenerating at half.
        assert!((p(once(&mut l, 40.0, v, w)) - p_rated).abs() < 1e-9 * p_rated);
        assert!((p(once(&mut l, -40.0, v, w)) + 0.5 * p_rated).abs() < 1e-9 * p_rated);
        // Under the limits nothing changes; at standstill nothing either.
        assert_eq!(once(&mut l, 1.0, v, w), 1.0);
        assert_eq!(once(&mut l, -40.0, v, 0.0), -40.0);
    }

    #[test]
    fn over_voltage_controller_derates_regeneration_only_and_linearly() {
        let (mut l, m) = limiter(DcLinkTuning::default());
        let v = m.dc_voltage;
        let w = -m.rated_speed();
        // Braking a negative speed: τ > 0 regenerates.
        assert_eq!(once(&mut l, 40.0, 1.1 * v, w), 40.0);
        assert!((once(&mut l, 40.0, 1.175 * v, w) - 20.0).abs() < 1e-9);
        assert_eq!(once(&mut l, 40.0, 1.25 * v, w), 0.0);
        assert_eq!(once(&mut l, 40.0, 1.3 * v, w), 0.0);
        // Motoring is not derated by a high bus.
        assert_eq!(once(&mut l, -40.0, 1.3 * v, w), -40.0);
        // A bus rising at 30 V/ms is derated as if it were up to LEAD_TIME ahead (30 V once
        // the filtered rate has settled): more than its present level alone asks.
        l.reset();
        let (mut vdc, mut tau) = (v, 0.0);
        for _ in 0..12 {
            vdc += 30e3 * 1e-4;
            tau = l.limit(40.0, vdc, w, 0.0).0;
        }
        let now = (1.25 * v - vdc) / (0.15 * v) * 40.0;
        let ahead = (1.25 * v - vdc - 30.0) / (0.15 * v) * 40.0;
        assert!(
            tau < now - 10.0 && tau >= ahead && tau > 0.0,
            "{tau}: {ahead}..{now}"
        );
    }

    #[test]
    fn a_full_bus_brakes_with_the_copper_losses() {
        let (mut l, m) = limiter(DcLinkTuning::default());
        let (v, w) = (1.3 * m.dc_voltage, m.rated_speed());
        l.reset();
        // No room left in the bus: the braking torque is what R̂s·|i|² takes, and the d
        // current is the full loss-braking current.
        let (tau, id) = l.limit(-40.0, v, w, 30.0);
        let p_cu = LOSS_CREDIT * 1.5 * m.rs * 30.0 * 30.0;
        assert!(
            (1.5 * m.flux_linkage * w * tau + p_cu).abs() < 1e-9 * p_cu,
            "{tau}"
        );
        assert!((id + LOSS_BRAKING_RATIO * 40.0).abs() < 1e-12);
        // Half-way through the band: half the current limit plus the losses, half the d
        // current.
        let (tau, id) = l.limit(-40.0, 1.175 * m.dc_voltage, w, 30.0);
        let expected = 20.0 + LOSS_CREDIT * m.rs * 900.0 / (m.flux_linkage * w);
        assert!((tau + expected).abs() < 1e-6, "{tau} vs {expected}");
        assert!((id + 0.5 * LOSS_BRAKING_RATIO * 40.0).abs() < 1e-6);
        // Motoring on a full bus: no derating, no braking current.
        assert_eq!(l.limit(40.0, v, w, 30.0), (40.0, 0.0));
    }

    #[test]
    fn over_voltage_trips_after_a_millisecond_above_the_level() {
        let (mut l, m) = limiter(DcLinkTuning::default());
        let high = 1.36 * m.dc_voltage;
        for _ in 0..OVER_VOLTAGE_TRIP_SAMPLES - 1 {
            assert!(!l.over_voltage(high));
        }
        assert!(!l.over_voltage(m.dc_voltage), "a dip resets the count");
        for k in 0..OVER_VOLTAGE_TRIP_SAMPLES {
            assert_eq!(l.over_voltage(high), k + 1 == OVER_VOLTAGE_TRIP_SAMPLES);
        }
        let bad = DcLinkTuning {
            over_voltage_stop_ratio: 1.05,
            ..DcLinkTuning::<f64>::default()
        };
        let e = DcLinkLimit::new(&bad, &m, 40.0, 40.0, 1e-4).unwrap_err();
        assert_eq!(e.field(), "dc_link.over_voltage_stop_ratio");
    }
}
