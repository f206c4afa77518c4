//! What a motor's ratings give: the value of every motor and inverter key a user may leave
//! out, each derived from the ratings by a stated rule — never another motor's number.
//!
//! A motor is described by its circuit (Rs, Ld, Lq, λf, pole pairs) and its ratings (rated
//! current, speed and torque). Everything else a drive or a simulation needs has a rule here,
//! used by every front end alike (`fado-sim`'s TOML `[motor]`/`[inverter]` tables and Python's
//! `fado.Machine`), and printed with its rule by `fado-sim run --dump-config`:
//!
//! | key | rule |
//! |---|---|
//! | `viscous_friction` | [`FRICTION_TORQUE_RATIO`] of the rated torque at rated speed |
//! | `inertia` | rated torque accelerates it to rated speed in [`MECHANICAL_START_TIME`] |
//! | `dc_voltage` | the rated point uses [`DC_LINK_MODULATION_RATIO`] of the linear range |
//! | `switching_frequency` | ω_rated·Ts ≤ [`MAX_OMEGA_TS`], min(Ld, Lq)/Rs ≥ 2·Ts and the PWM current ripple ([`ripple_current`]) ≤ [`MAX_RIPPLE_CURRENT_RATIO`] of the rated current, at least the DC link's class floor ([`min_switching_frequency`]); none above the class's ceiling of realistic carriers ([`max_switching_frequency`], [`check_carrier`]) |
//! | `dead_time` | [`DEAD_TIME_PERIOD_RATIO`] of the carrier period |
//! | `threshold_voltage` | [`THRESHOLD_VOLTAGE_RATIO`] of the DC link |
//! | `current_band` | [`CURRENT_BAND_RATIO`] of the rated current |
//!
//! # The bound on ω·Ts (why 0.2)
//! The estimator integrates the voltage the inverter held over each sample and the resistive
//! drop of the current averaged over the same interval (trapezoid, `integrator.average_current`); the
//! drive applies its voltage 1.5 samples after the angle it was computed at, advanced by the
//! linearised 1.5·ω̂·Ts. A stator quantity that turns by x = ω·Ts per sample is therefore
//! represented with the gain cos(x/2) by the trapezoid and sinc(x/2) = sin(x/2)/(x/2) by the
//! hold, and the drive's voltage of a held sample spans an arc of x. At x = 0.2 the trapezoid's
//! gain error 1 − cos(x/2) is 0.50 %, the hold's 0.17 %, both below the 1 % tolerance fado's
//! identification reports its parameters to; at the 0.73 of a 14-pole-pair outrunner on a
//! 5 kHz inverter they are 6.6 % and 2.2 %, the size of the errors its commissioning then
//! makes. 0.2 also keeps the observer's gains within their series range (|x| ≤ 0.25 in `f64`,
//! 0.5 in `f32`, see [`crate::observer`]). The test `omega_ts_bound_keeps_the_discretisation_within_one_percent`
//! checks these numbers.
//!
//! # The bound on the current ripple (why Vdc/(6·L·f_sw) and 0.6)
//! The bound on ω_rated·Ts says nothing about the inductance: a slotless motor (maxon EC 22
//! 40 W, 27.3 µH per phase on 24 V) meets it at 5 kHz, where its PWM current ripple is
//! eight times its rated current. With the centred (min-max zero sequence) modulation of
//! [`crate::control::modulation`] the phase voltage deviates from its period average by at
//! most (2/3)·Vdc while an active vector lasts; the peak-to-peak ripple of a phase current
//! grows with the modulation and, over the linear range (|v| ≤ Vdc/√3), is largest at its
//! edge: ΔI_pp = Vdc/(6·L·f_sw) with L = min(Ld, Lq) ([`ripple_current`]; the test
//! `ripple_bound_is_the_largest_ripple_of_the_centred_modulation` integrates the pattern).
//! The half-bridge estimate Vdc/(4·L·f_sw) (one leg at duty ½ against the DC link's
//! mid-point) overstates the three-phase ripple 1.5 times. The derived
//! frequency keeps ΔI_pp ≤ [`MAX_RIPPLE_CURRENT_RATIO`] = 0.6 of the rated current: maxon's
//! rule for its controllers' motor chokes (ESCON and EPOS4 hardware references, "Motor
//! chokes": Vcc/(6·f_PWM·L_terminal) ≤ 0.3·I_N, L_terminal = 2·L, the ripple at half the
//! linear range), stated at the linear range's edge. Measured closed loop
//! (`crates/fado-sim/tests/datasheet_carrier.rs`, sensor seed 1): the maxon EC 22 fails
//! `stops` at 12, 20 and 30 kHz (ΔI_pp 3.3, 2.0 and 1.3 times its rated current; largest
//! |θ − θ̂| 0.96, 0.72, 0.28 rad) and passes at 40 kHz (1.0 times, 0.05 rad); the rule gives
//! it 67 kHz.

use crate::Real;
use crate::machine::{MachineModel, PAPER_RATED_CURRENT};

mod carrier;

pub use carrier::{
    CarrierBound, CarrierFinding, CarrierNeed, FAST_CARRIER_RATIO, MAX_GIVEN_RIPPLE_RATIO,
    MAX_SWITCHING_FREQUENCY, MAX_SWITCHING_FREQUENCY_MEDIUM_VOLTAGE, carrier_need, check_carrier,
    max_switching_frequency,
};

/// Viscous friction at rated speed as a fraction of the rated torque: 1 % \[A\]
/// (B = 0.01·T_rated/ω_rated,mech). Bearings and windage of industrial servo motors take
/// 0.5–2 % of the rated torque at rated speed; the friction is what the speed controller
/// feeds forward, and a guess on the high side would hide a load.
pub const FRICTION_TORQUE_RATIO: f64 = 0.01;

/// Mechanical start time, s: the rated torque accelerates the shaft (motor and load) from
/// standstill to rated speed in this time, J = T_rated·t/ω_rated,mech. 0.15 s \[A\]: the median
/// of the repository's motor presets is 0.16 s (from 0.06 s for the automotive IPMSM to 0.74 s
/// for the hub motor carrying a robot), the paper's motor and dynamometer 0.16 s.
pub const MECHANICAL_START_TIME: f64 = 0.15;

/// Largest rated electrical speed times sampling period the derived switching frequency allows
/// (see the module documentation for the derivation): 0.2 rad.
pub const MAX_OMEGA_TS: f64 = 0.2;

/// Largest rated electrical speed times sampling period at which the drive runs without a
/// warning: 0.6 rad. Measured closed loop (a 14-pole-pair multirotor motor, 0 → rated speed,
/// a 65 % load step, switching-resolved, `motors/multirotor-mn5006-22v.toml` at 20, 13.3, 10
/// and 8 kHz): the steady angle error is 0.011, 0.022, 0.029 and 0.028 rad at ω_rated·Ts =
/// 0.29, 0.44, 0.59 and 0.73 (0.002 at 0.04); at 0.88 it spikes to 0.14 rad and at 1.17 the
/// rotor is lost. Commissioning identifies the motor to 1 % only up to [`MAX_OMEGA_TS`] and
/// refuses beyond it; the derived switching frequency keeps that bound.
pub const MAX_RUNNING_OMEGA_TS: f64 = 0.6;

/// Lowest derived switching frequency of a low-voltage inverter (DC link up to
/// [`LOW_VOLTAGE_DC_LINK`]), Hz: 5 kHz, the paper's and that of most industrial drives (a
/// slower carrier is audible and its current ripple large).
pub const MIN_SWITCHING_FREQUENCY: f64 = 5000.0;

/// Largest DC link, V, of the low-voltage class: 1.2 kV, the 1,200 V and 1,700 V IGBT and SiC
/// bridges of 400–690 V mains drives and battery inverters (a 690 V mains drive's DC link is
/// 975 V). Above it the bridge is a medium-voltage one (3.3–6.5 kV IGBTs, IGCTs, or devices in
/// series), whose switching losses keep the carrier at 0.5–2 kHz \[A\].
pub const LOW_VOLTAGE_DC_LINK: f64 = 1200.0;

/// Lowest derived switching frequency of a medium-voltage inverter (DC link above
/// [`LOW_VOLTAGE_DC_LINK`]), Hz: 2 kHz, the upper end of that class's carriers, and the lowest
/// whole kHz at which a current loop of 250 Hz (the drive's default bandwidth, the paper's
/// drive's) keeps ωc·Ts ≤ 0.5 with Ts = 1/(2·f_sw) (1.6 kHz). With [`DEAD_TIME_PERIOD_RATIO`]
/// its dead time is 6.25 µs, that of 3.3 kV IGBT modules, rather than the 2.5 µs of a
/// 1,200 V one.
pub const MIN_SWITCHING_FREQUENCY_MEDIUM_VOLTAGE: f64 = 2000.0;

/// The lowest derived switching frequency for an inverter on `dc_voltage` (V): the class floor
/// [`MIN_SWITCHING_FREQUENCY`] up to [`LOW_VOLTAGE_DC_LINK`], else
/// [`MIN_SWITCHING_FREQUENCY_MEDIUM_VOLTAGE`].
pub fn min_switching_frequency(dc_voltage: f64) -> f64 {
    of_class(
        dc_voltage,
        MIN_SWITCHING_FREQUENCY,
        MIN_SWITCHING_FREQUENCY_MEDIUM_VOLTAGE,
    )
}

/// `low_voltage` for an inverter on `dc_voltage` (V) up to [`LOW_VOLTAGE_DC_LINK`], else
/// `medium_voltage`.
pub(crate) fn of_class(dc_voltage: f64, low_voltage: f64, medium_voltage: f64) -> f64 {
    if dc_voltage > LOW_VOLTAGE_DC_LINK {
        medium_voltage
    } else {
        low_voltage
    }
}

/// Largest peak-to-peak PWM current ripple ([`ripple_current`]) the derived switching
/// frequency allows, as a fraction of the rated current: 0.6 (maxon's motor-choke rule, see
/// the module documentation).
pub const MAX_RIPPLE_CURRENT_RATIO: f64 = 0.6;

/// The derived switching frequency is a whole multiple of this, Hz.
pub const SWITCHING_FREQUENCY_STEP: f64 = 1000.0;

/// Fraction of the linear modulation range Vdc/√3 that the rated point's phase voltage takes
/// with the derived DC link: 0.8 \[A\] (20 % voltage headroom for the current controller's
/// transients).
pub const DC_LINK_MODULATION_RATIO: f64 = 0.8;

/// Dead time as a fraction of the carrier period: 1.25 % (2.5 µs at the paper's 5 kHz, paper
/// §V \[P\]).
pub const DEAD_TIME_PERIOD_RATIO: f64 = 0.0125;

/// Device threshold (knee) voltage as a fraction of the DC link: the paper inverter's 1 V of
/// 311 V (docs/method/estimator.md §7 \[A\]); a low-voltage MOSFET bridge has almost none.
pub const THRESHOLD_VOLTAGE_RATIO: f64 = 1.0 / 311.0;

/// Current band of the dead-time and threshold errors as a fraction of the rated current: the
/// paper inverter's 0.3 A of 21.8 A (docs/method/estimator.md §7 \[A\]; it scales with the devices' output
/// capacitance, which scales with their current rating).
pub const CURRENT_BAND_RATIO: f64 = 0.3 / PAPER_RATED_CURRENT;

/// The keys a motor description must give: the circuit and the ratings.
pub const REQUIRED_MOTOR_KEYS: [&str; 8] = [
    "rs",
    "ld",
    "lq",
    "flux_linkage",
    "pole_pairs",
    "rated_current",
    "rated_speed_rpm",
    "rated_torque",
];

/// The ratings among [`REQUIRED_MOTOR_KEYS`].
pub const RATING_KEYS: [&str; 3] = ["rated_current", "rated_speed_rpm", "rated_torque"];

/// Each derivable key (`section.key` as in `fado-sim`'s TOML) and its rule, in words.
pub const RULES: [(&str, &str); 7] = [
    (
        "motor.viscous_friction",
        "1 % of rated_torque at rated_speed_rpm: B = 0.01·T_rated/ω_rated,mech",
    ),
    (
        "motor.inertia",
        "rated_torque reaches rated_speed_rpm in 0.15 s: J = T_rated·0.15 s/ω_rated,mech",
    ),
    (
        "inverter.dc_voltage",
        "the rated point's phase voltage (MTPA, rated_current, rated_speed_rpm) at 80 % of Vdc/√3",
    ),
    (
        "inverter.switching_frequency",
        "ω_rated·Ts ≤ 0.2, the electrical time constant min(ld, lq)/rs ≥ 2·Ts (Ts = 1/(2·f_sw)) and the PWM current ripple dc_voltage/(6·min(ld, lq)·f_sw) ≤ 0.6·rated_current (maxon's motor-choke rule), at least 5 kHz (2 kHz on a DC link above 1.2 kV), rounded up to a whole kHz; refused above 100 kHz (10 kHz above 1.2 kV: no inverter of the class has it; the error names the bound's keys and the carrier it needs), a warning above 40 kHz (4 kHz: a GaN inverter)",
    ),
    (
        "inverter.dead_time",
        "1.25 % of the carrier period 1/switching_frequency",
    ),
    ("inverter.threshold_voltage", "1/311 of dc_voltage"),
    (
        "inverter.current_band",
        "1.38 % of rated_current (0.3 A of 21.78 A)",
    ),
];

/// The rule of a derivable key (`motor.inertia`), if it has one.
pub fn rule(key: &str) -> Option<&'static str> {
    RULES.iter().find(|(k, _)| *k == key).map(|(_, r)| *r)
}

/// Rated mechanical speed in rad/s from r/min.
pub(crate) fn rated_speed_mech(rated_speed_rpm: f64) -> f64 {
    rated_speed_rpm * core::f64::consts::PI / 30.0
}

/// B = [`FRICTION_TORQUE_RATIO`]·T_rated/ω_rated,mech, N·m·s/rad.
pub fn viscous_friction(rated_torque: f64, rated_speed_rpm: f64) -> f64 {
    FRICTION_TORQUE_RATIO * rated_torque / rated_speed_mech(rated_speed_rpm)
}

/// J = T_rated·[`MECHANICAL_START_TIME`]/ω_rated,mech, kg·m².
pub fn inertia(rated_torque: f64, rated_speed_rpm: f64) -> f64 {
    rated_torque * MECHANICAL_START_TIME / rated_speed_mech(rated_speed_rpm)
}

/// The smallest whole multiple of `step` at or above `x` (x ≥ 0, finite).
pub(crate) fn ceil_to(x: f64, step: f64) -> f64 {
    let n = x / step;
    let whole = n as u64 as f64;
    step * if whole < n { whole + 1.0 } else { whole }
}

/// The switching frequency, Hz: the smallest whole kHz at or above the floor of the DC link's
/// class ([`min_switching_frequency`] of `dc_voltage`) at which ω_rated·Ts ≤ [`MAX_OMEGA_TS`]
/// with Ts = 1/(2·f_sw).
pub fn switching_frequency(pole_pairs: u32, rated_speed_rpm: f64, dc_voltage: f64) -> f64 {
    let omega = rated_speed_mech(rated_speed_rpm) * pole_pairs as f64;
    let needed = omega / (2.0 * MAX_OMEGA_TS);
    ceil_to(
        needed.max(min_switching_frequency(dc_voltage)),
        SWITCHING_FREQUENCY_STEP,
    )
}

/// The largest peak-to-peak PWM ripple of a phase current over the linear modulation range,
/// A: Vdc/(6·L·f_sw) for a phase inductance `inductance` (module documentation, "The bound
/// on the current ripple").
pub fn ripple_current(dc_voltage: f64, inductance: f64, switching_frequency: f64) -> f64 {
    dc_voltage / (6.0 * inductance * switching_frequency)
}

/// The switching frequency of machine `m`, Hz: [`switching_frequency`], raised where needed to
/// the smallest whole kHz at which the electrical time constant min(Ld, Lq)/Rs spans two
/// sampling periods (a current loop needs at least that) and at which the PWM current ripple
/// [`ripple_current`] on `m.dc_voltage` is at most [`MAX_RIPPLE_CURRENT_RATIO`] of the rated
/// current (a slotless 40 W motor, 27.3 µH on 24 V, asks for 67 kHz). Above the ceiling of
/// realistic carriers ([`max_switching_frequency`]) the front ends refuse the value
/// ([`check_carrier`], module `carrier`'s documentation).
pub fn switching_frequency_of(m: &MachineModel<f64>) -> f64 {
    carrier_need(m).frequency
}

/// The d and q currents of the maximum-torque-per-ampere point of magnitude `i` (A peak):
/// i_d = (λf − √(λf² + 8·ΔL²·i²))/(4·ΔL) with ΔL = Lq − Ld for a salient rotor with Lq > Ld,
/// else (0, i).
pub fn mtpa_current(m: &MachineModel<f64>, i: f64) -> (f64, f64) {
    let dl = m.lq - m.ld;
    if !(m.is_salient() && dl > 0.0) {
        return (0.0, i);
    }
    let lf = m.flux_linkage;
    let id = (lf - (lf * lf + 8.0 * dl * dl * i * i).step_sqrt()) / (4.0 * dl);
    let iq = (i * i - id * id).max(0.0).step_sqrt();
    (id, iq)
}

/// The model's torque at rated current on the MTPA point, N·m: the closed form of
/// [`mtpa_current`] on constant inductances; on a saturating model (`m.magnetics`, a flux map
/// or the algebraic model) its co-energy torque 1.5·p·(ψd·i_q − ψq·i_d), the largest over the
/// current's angle (1° steps over i_d ≤ 0 and i_d ≥ 0: a saturated q axis or a d axis that
/// saturates on the magnet moves the MTPA point), since the zero-current inductances
/// overstate a saturated machine's reluctance torque (by 1.8 × on the traction IPMSM of
/// `scripts/saturated-replay.py`).
pub fn rated_current_torque(m: &MachineModel<f64>) -> f64 {
    if !m.magnetics.is_linear() {
        return saturated_mtpa_torque(m, m.rated_current);
    }
    let (id, iq) = mtpa_current(m, m.rated_current);
    m.torque(crate::Dq::new(id, iq))
}

/// The largest torque of `m`'s magnetic model on the current circle of magnitude `i`.
fn saturated_mtpa_torque(m: &MachineModel<f64>, i: f64) -> f64 {
    use crate::magnetics::MagneticModel;
    let model = m.magnetics.resolve(m.constant_inductance());
    let step = core::f64::consts::PI / 180.0;
    let mut best = f64::NEG_INFINITY;
    for k in 0..=180u32 {
        // From −d through +q to +d: i_d = −i·cos(β), i_q = i·sin(β).
        let (s, c) = (k as f64 * step).step_sin_cos_any();
        let torque = model.torque(m.pole_pairs, crate::Dq::new(-i * c, i * s));
        best = best.max(torque);
    }
    best
}

/// Magnitude of the steady-state phase voltage (peak) at rated speed and rated current on the
/// MTPA point: |R·i + jω·(L·i + λf)| in the rotor frame, V.
pub fn rated_point_voltage(m: &MachineModel<f64>) -> f64 {
    let (id, iq) = mtpa_current(m, m.rated_current);
    let w = m.rated_speed();
    let vd = m.rs * id - w * m.lq * iq;
    let vq = m.rs * iq + w * (m.ld * id + m.flux_linkage);
    (vd * vd + vq * vq).step_sqrt()
}

/// The DC link, V, at which the rated point's phase voltage is [`DC_LINK_MODULATION_RATIO`]
/// of the linear range Vdc/√3, rounded up to a whole volt.
pub fn dc_voltage(m: &MachineModel<f64>) -> f64 {
    let v = rated_point_voltage(m) * 1.732_050_807_568_877_2 / DC_LINK_MODULATION_RATIO;
    ceil_to(v, 1.0)
}

/// Td = [`DEAD_TIME_PERIOD_RATIO`] / f_sw, s.
pub fn dead_time(switching_frequency: f64) -> f64 {
    DEAD_TIME_PERIOD_RATIO / switching_frequency
}

/// V_th = [`THRESHOLD_VOLTAGE_RATIO`]·Vdc, V.
pub fn threshold_voltage(dc_voltage: f64) -> f64 {
    THRESHOLD_VOLTAGE_RATIO * dc_voltage
}

/// Ic = [`CURRENT_BAND_RATIO`]·I_rated, A.
pub fn current_band(rated_current: f64) -> f64 {
    CURRENT_BAND_RATIO * rated_current
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn omega_ts_bound_keeps_the_discretisation_within_one_percent() {
        let x = MAX_OMEGA_TS;
        let (s, c) = (x / 2.0).step_sin_cos();
        let (trapezoid, hold) = (1.0 - c, 1.0 - s / (x / 2.0));
        assert!(trapezoid < 0.0051 && trapezoid > 0.0049, "{trapezoid}");
        assert!(hold < 0.0017, "{hold}");
        // The outrunner of the issue on a 5 kHz inverter: 6.6 % and 2.2 %.
        let x: f64 = 0.73;
        let (s, c) = (x / 2.0).step_sin_cos();
        assert!((1.0 - c - 0.066).abs() < 1e-3);
        assert!((1.0 - s / (x / 2.0) - 0.022).abs() < 1e-3);
    }

    #[test]
    fn derived_values_follow_their_rules() {
        let m = MachineModel::<f64>::paper();
        // 1 % of 11.5 N·m at 157 rad/s.
        let b = viscous_friction(m.rated_torque, m.rated_speed_rpm);
        assert!((b * 1500.0 * core::f64::consts::PI / 30.0 - 0.115).abs() < 1e-12);
        let j = inertia(m.rated_torque, m.rated_speed_rpm);
        assert!((j * m.rated_speed_mech() / m.rated_torque - 0.15).abs() < 1e-12);
        // 628 rad/s needs 1.6 kHz: the 5 kHz floor.
        assert_eq!(switching_frequency(4, 1500.0, 311.0), 5000.0);
        // A medium-voltage drive (10 kV DC link): the 2 kHz floor, 6.25 µs dead time; the
        // drive's 250 Hz current loop within ωc·Ts ≤ 0.5.
        let f = switching_frequency(2, 1500.0, 10e3);
        assert_eq!(f, 2000.0);
        assert_eq!(dead_time(f), 6.25e-6);
        assert!(core::f64::consts::TAU * 250.0 * 0.5 / f <= 0.5);
        // At 1.2 kV the low-voltage floor still holds.
        assert_eq!(switching_frequency(2, 1500.0, LOW_VOLTAGE_DC_LINK), 5000.0);
        // A 14-pole-pair outrunner at 7000 r/min: 10,263 rad/s → 25.7 kHz → 26 kHz.
        let f = switching_frequency(14, 7000.0, 22.2);
        assert_eq!(f, 26_000.0);
        assert!(14.0 * 7000.0 * core::f64::consts::PI / 30.0 * 0.5 / f <= MAX_OMEGA_TS);
        assert_eq!(dead_time(5000.0), 2.5e-6);
        assert_eq!(threshold_voltage(311.0), 1.0);
        assert!((current_band(PAPER_RATED_CURRENT) - 0.3).abs() < 1e-15);
        // The paper's rated point: |v| = 72 V, so 156 V at 80 % of Vdc/√3.
        let v = rated_point_voltage(&m);
        assert!((v - 72.0).abs() < 1.0, "{v}");
        let vdc = dc_voltage(&m);
        assert!(
            v <= DC_LINK_MODULATION_RATIO * vdc / 3f64.step_sqrt() + 1e-9,
            "{vdc}"
        );
        assert!(vdc - 1.0 < v * 3f64.step_sqrt() / DC_LINK_MODULATION_RATIO);
        for (k, _) in RULES {
            assert!(rule(k).is_some());
        }
    }

    /// The centred modulation's phase-current ripple over one carrier period (pure
    /// inductance L, star point free), integrated on a fine grid for reference vectors over the
    /// linear range and a sixth of a turn: its largest peak-to-peak value is the bound of
    /// [`ripple_current`], reached at the linear range's edge.
    #[test]
    fn ripple_bound_is_the_largest_ripple_of_the_centred_modulation() {
        let (vdc, l, f) = (24.0, 27.3e-6, 20e3);
        let n = 4000usize;
        let ripple = |m: f64, th: f64| {
            let v = [0.0, 2.0, -2.0]
                .map(|k: f64| m / 3f64.sqrt() * (th - k * core::f64::consts::FRAC_PI_3).cos());
            let (mx, mn) = (v[0].max(v[1]).max(v[2]), v[0].min(v[1]).min(v[2]));
            let duty = v.map(|x| 0.5 + x - 0.5 * (mx + mn));
            let mean = (duty[0] + duty[1] + duty[2]) / 3.0;
            let mut i = [0.0f64; 3];
            let (mut hi, mut lo) = ([0.0f64; 3], [0.0f64; 3]);
            for k in 0..n {
                let carrier = (2.0 * (k as f64 + 0.5) / n as f64 - 1.0).abs();
                let pole = duty.map(|d| if carrier < d { 1.0 } else { 0.0 });
                let star = (pole[0] + pole[1] + pole[2]) / 3.0;
                for x in 0..3 {
                    // Phase voltage less its period average, per Vdc; current per Vdc/(L·f).
                    i[x] += (pole[x] - star - (duty[x] - mean)) / n as f64;
                    hi[x] = hi[x].max(i[x]);
                    lo[x] = lo[x].min(i[x]);
                }
            }
            (0..3).map(|x| hi[x] - lo[x]).fold(0.0, f64::max) * vdc / (l * f)
        };
        let bound = ripple_current(vdc, l, f);
        let mut largest = 0.0f64;
        for step in 0..=20 {
            let m = step as f64 / 20.0;
            for a in 0..=12 {
                let r = ripple(m, a as f64 * core::f64::consts::FRAC_PI_3 / 12.0);
                assert!(r <= bound * (1.0 + 1e-3), "m {m}: {r} > {bound}");
                largest = largest.max(r);
            }
        }
        assert!(largest > 0.99 * bound, "{largest} vs {bound}");
        // At half the linear range it is half the bound: maxon's Vcc/(6·f·L_terminal).
        let half = (0..=12)
            .map(|a| ripple(0.5, a as f64 * core::f64::consts::FRAC_PI_3 / 12.0))
            .fold(0.0, f64::max);
        assert!((half / bound - 0.5).abs() < 0.01, "{half} vs {bound}");
    }

    #[test]
    fn derived_switching_frequency_bounds_the_ripple() {
        // The slotless maxon EC 22 40 W on 24 V (27.3 µH, 3.68 A): ω_rated·Ts and L/R ask for
        // 12 kHz, the ripple for 67 kHz.
        let maxon = MachineModel {
            rs: 0.3205,
            ld: 27.3e-6,
            lq: 27.3e-6,
            flux_linkage: 3.75e-3,
            pole_pairs: 1,
            rated_current: 3.68,
            rated_speed_rpm: 31_800.0,
            rated_torque: 20.7e-3,
            dc_voltage: 24.0,
            ..MachineModel::<f64>::paper()
        };
        let f = switching_frequency_of(&maxon);
        assert_eq!(f, 67_000.0);
        let r = ripple_current(24.0, 27.3e-6, f);
        assert!(r <= MAX_RIPPLE_CURRENT_RATIO * 3.68, "{r}");
        assert!(ripple_current(24.0, 27.3e-6, f - 1000.0) > MAX_RIPPLE_CURRENT_RATIO * 3.68);
        // The paper's motor: 311/(6·2.63 mH·5 kHz) = 3.9 A, 18 % of its rated current.
        let paper = MachineModel::<f64>::paper();
        assert_eq!(switching_frequency_of(&paper), 5000.0);
        assert!(ripple_current(311.0, paper.ld.min(paper.lq), 5000.0) < 0.6 * 21.8);
    }

    /// The 2.2 kW IPMSM: p 3, Ld 36 mH, Lq 51 mH, λf 0.545 Wb.
    fn ipmsm_2k2() -> MachineModel<f64> {
        MachineModel {
            rs: 3.6,
            ld: 36e-3,
            lq: 51e-3,
            flux_linkage: 0.545,
            pole_pairs: 3,
            ..MachineModel::<f64>::paper()
        }
    }

    #[test]
    fn mtpa_current_maximises_the_torque_on_the_circle() {
        let m = ipmsm_2k2();
        let (id, iq) = mtpa_current(&m, 6.0);
        assert!((id * id + iq * iq - 36.0).abs() < 1e-9);
        assert!((m.mtpa_id(iq) - id).abs() < 1e-9);
    }

    #[test]
    fn a_saturating_model_gives_its_own_torque_at_rated_current() {
        use crate::magnetics::{MachineMagnetics, Saturation};
        // The algebraic model of a linear machine: the closed form's torque, within the 1°
        // scan's error on a flat maximum.
        let m = ipmsm_2k2();
        let linear: &'static Saturation<f64> = std::boxed::Box::leak(std::boxed::Box::new(
            Saturation::linear(36e-3, 51e-3, 0.545),
        ));
        let as_model = m.with_magnetics(MachineMagnetics::Saturation(linear));
        let ratio = rated_current_torque(&as_model) / rated_current_torque(&m);
        assert!((ratio - 1.0).abs() < 1e-4, "{ratio}");
        // The Baldor PM-SyRM's fit: 31.5 N·m at rated current on β = 45° (its preset file),
        // where its zero-current inductances give 41 N·m.
        let pm = crate::magnetics::tests::pmsyrm_machine();
        let saturated = rated_current_torque(&pm);
        let zero_current = rated_current_torque(&MachineModel {
            magnetics: MachineMagnetics::Linear,
            ..pm
        });
        assert!((31.0..32.5).contains(&saturated), "{saturated}");
        assert!(zero_current > 1.2 * saturated, "{zero_current}");
    }
}
