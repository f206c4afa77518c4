//! Compensation of the inverter non-linearity (paper IV-B, after refs. \[14\]-\[15\]; docs/method/estimator.md §7).
//!
//! Dead time and device drops make each pole voltage fall short by about
//! V̂·sat(i_x/Ic) in the direction of its phase current, V̂ = Td·f_sw·Vdc + V_th (the dead
//! time's average per switching period plus the device threshold), with the band Ic where
//! the parasitic capacitances make the error ramp rather than jump. The compensation adds
//! the opposite per phase:
//!
//! v_comp,x = V̂·sat(I*·cos(θi − φx)/Ic),   θi = θ̂ + 1.5·ω̂·Ts + atan2(i_q*, i_d*),
//! φx = 0, +2π/3, −2π/3 for a, b, c (phase b lags a),
//!
//! a trapezoid in the angle of the *reference* current vector, advanced like the voltage
//! (docs/method/estimator.md §7 \[A\]): no chattering on noisy measured currents near their zero crossings.
//! I*·cos(θi − φx) is just phase x of the reference current rotated to the advanced angle,
//! which is how it is computed (no atan2). The classic sign(i_x) of the measured current is
//! offered as [`DeadTimeMethod::Sign`]. The Clarke transform of v_comp (its zero sequence
//! does not matter) is added to v*_ab before modulation.
//!
//! **Edge currents** ([`DeadTimeMethod::EdgeCurrent`] \[A\]). The error of one edge depends on
//! the phase current *at that edge*, not on the sampled (period-average) current: an edge
//! whose current opposes the transition waits Td, one whose current helps commutates after
//! Td·(1 − |i|/Ic)⁺ (the same band model, edge by edge), and per carrier period the two edges
//! of a leg give the trapezoid above only if both see the average current. Within the band
//! they do not: the PWM ripple moves the current of the leg that switches *between* the two
//! others (at low speed under load, the phase whose current is near zero) by
//! ΔI ≈ (Vdc/3)/L̂ · (time since the first leg's pole edge), always towards a larger |i| at the
//! helping edge (the first active vector pulls it away from zero), so the inverter's error
//! saturates earlier than V̂·sat(i/Ic); the current also swings between the carrier's peak
//! and valley samples (the two halves' edges are delayed differently), which moves it back
//! towards zero. The trapezoid leaves up to 0.64 V on that phase on the paper's motor at
//! standstill under 7.5 N·m (test `edge_current_compensation_matches_…` in fado-sim's
//! inverter), a d-axis error that shrank |λ̂r| by 20 % in a 100 ms stop and put `stops` at
//! 0.25 rad (docs/method/additions.md). This method predicts, from the voltage reference,
//! the DC link and the inductance matrix (L̂d, L̂q at θ̂), the gate times of both half carrier
//! periods (symmetric carrier, min-max zero sequence as [`crate::control::modulation`]), each
//! pole's edge delayed by the band model, the current of each phase at its own gate edge (the
//! piecewise-linear ripple: each other pole already switched adds the current response of its
//! α-β voltage step ±(2/3)·Vdc·u_k, −Vdc/(3L̂) on a round rotor; the mean slope removed; the
//! peak sample i − Δ/2 and the valley sample i + Δ/2, Δ the swing the pattern predicts), the
//! two edges' delays and so the period-average pole error Vdc·f_sw·(t_fall − t_rise) −
//! V_th·sat(i/Ic), in two fixed-point passes; < 0.1 V left in the same test. Outside the band
//! it is the trapezoid exactly. Limit: on a low-inductance salient rotor the swing's dependence
//! on the phase's own edge delay has a loop gain ≈ Vdc·Td/(6·L̂·Ic) above 1, the passes do not
//! converge and the prediction helps little (same test: 1.12 → 0.84 V at 0.37/1.2 mH). Cost:
//! ≈ 200 flops and 6 divisions more than the trapezoid (not measured on target). The current
//! at the switching instants, ripple included, as the quantity that sets the dead-time
//! distortion at low output voltage: Choi & Sul, "A new compensation strategy reducing
//! voltage/current distortion in PWM VSI systems operating
//! with low output voltages", IEEE Trans. Ind. Appl. 31(5), 1995.
//!
//! **Held legs.** Where the modulator limits the reference to the hexagon (and in
//! overmodulation) the largest and the smallest pole are held at duty 1 and 0 over the
//! period: they have no edge, so no dead time acts on them, only the conducting device's
//! drop V_th·sat(i/Ic). The drive tells the estimator the voltage that then acts as the
//! limited vector less what the inverter loses ([`DeadTimeCompensation::lost`]): the whole
//! compensation on the switching leg, the drop alone on a held one. Counting the dead time as
//! lost on the held legs too puts up to (4/3)·Td·f_sw·Vdc into the estimator's integrand on
//! every limited sample: measured on a 24-pole multirotor motor (1.53 mWb, 22.2 V, 48 kHz;
//! `fullrange`, the acceleration at the current limit in field weakening, 3.6–4.4 s), R̂s's
//! turning law read it as −0.7 % of Rs, a creep of θ̂ at the loaded standstill of
//! ΔR̂s·i/λ̂f ≈ 8 rad/s that lost the rotor. With the held legs counted right and the law
//! skipping the limited samples ([`crate::SensorlessEstimator::voltage_limited`]) R̂s stays
//! within 0.06 % (either alone leaves +0.3 %: the flux error of the limited samples lingers
//! into the next periods).

use crate::control::pi::clamp;
use crate::error::{ConfigError, check};
use crate::{Ab, Abc, Dq, MachineModel, Real, Rotation};

/// How the compensation voltage follows the current.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum DeadTimeMethod {
    /// V̂·sat(i*_x/Ic) of the advanced reference current (docs/method/estimator.md §7). Default.
    #[default]
    Trapezoidal,
    /// V̂·sign(i_x) of the measured phase current: the simple textbook variant.
    Sign,
    /// The band model evaluated at the predicted current of each switching edge, PWM ripple
    /// included (module docs; Choi & Sul 1995). Needs
    /// [`DeadTimeCompensationConfig::ripple_inductance`]; with 0 it is the trapezoid.
    EdgeCurrent,
}

/// Default dead time Td in s: 2.5 µs (paper, V).
pub const DEFAULT_DEAD_TIME: f64 = 2.5e-6;
/// Default shape of the compensation: [`DeadTimeMethod::EdgeCurrent`] \[A\] (the
/// docs/method/estimator.md §7 trapezoid at each switching edge's predicted current; it keeps
/// |λ̂r| from shrinking while a phase current sits in the band at standstill under load,
/// docs/method/additions.md).
pub const DEFAULT_METHOD: DeadTimeMethod = DeadTimeMethod::EdgeCurrent;
/// Default switching frequency in Hz: 5 kHz (paper, V).
pub const DEFAULT_SWITCHING_FREQUENCY: f64 = 5e3;
/// Default device threshold voltage in V: 1 (docs/method/estimator.md §7 \[A\]).
pub const DEFAULT_THRESHOLD_VOLTAGE: f64 = 1.0;
/// Default current band Ic of the trapezoid in A: 0.3 (docs/method/estimator.md §7 \[A\]).
pub const DEFAULT_CURRENT_BAND: f64 = 0.3;

/// Configuration of a [`DeadTimeCompensation`].
///
/// No `Default`: the dead time, switching frequency, threshold and band are the inverter's and
/// the ripple inductances the motor's. Build it with [`for_machine`](Self::for_machine) and
/// give your inverter's data in the fields; each field's "Default" is what `for_machine` gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeadTimeCompensationConfig<T> {
    /// Compensate at all. Default true (paper IV-B).
    pub enabled: bool,
    /// Shape. Default [`DEFAULT_METHOD`] (edge current).
    pub method: DeadTimeMethod,
    /// Dead time Td in s (inverter datum). Default [`DEFAULT_DEAD_TIME`] (2.5 µs, paper V).
    pub dead_time: T,
    /// Switching frequency f_sw in Hz (inverter datum). Default
    /// [`DEFAULT_SWITCHING_FREQUENCY`] (5 kHz, paper V).
    pub switching_frequency: T,
    /// Device threshold voltage V_th in V (inverter datum). Default
    /// [`DEFAULT_THRESHOLD_VOLTAGE`] (1 V, docs/method/estimator.md §7 \[A\]).
    pub threshold_voltage: T,
    /// Current band Ic of the trapezoid in A (inverter datum). Default
    /// [`DEFAULT_CURRENT_BAND`] (0.3 A, docs/method/estimator.md §7 \[A\]).
    pub current_band: T,
    /// Inductances (L̂d, L̂q) of the ripple prediction of [`DeadTimeMethod::EdgeCurrent`] in H,
    /// in the rotor frame of the rotation it is given; 0: no ripple (the trapezoid). Default
    /// the machine model's (L̂d, L̂q).
    pub ripple_inductance: Dq<T>,
}

impl<T: Real> DeadTimeCompensationConfig<T> {
    /// The compensation for `machine` (ripple inductances L̂d, L̂q of the edge-current method)
    /// on the paper's inverter data ([`DEFAULT_DEAD_TIME`] 2.5 µs and
    /// [`DEFAULT_SWITCHING_FREQUENCY`] 5 kHz, paper V; [`DEFAULT_THRESHOLD_VOLTAGE`] 1 V and
    /// [`DEFAULT_CURRENT_BAND`] 0.3 A, docs/method/estimator.md §7 \[A\]) with
    /// [`DeadTimeMethod::EdgeCurrent`]. Give your inverter's data in the fields.
    pub fn for_machine(machine: &MachineModel<T>) -> Self {
        Self {
            enabled: true,
            method: DEFAULT_METHOD,
            dead_time: T::lit(DEFAULT_DEAD_TIME),
            switching_frequency: T::lit(DEFAULT_SWITCHING_FREQUENCY),
            threshold_voltage: T::lit(DEFAULT_THRESHOLD_VOLTAGE),
            current_band: T::lit(DEFAULT_CURRENT_BAND),
            ripple_inductance: Dq::new(machine.ld, machine.lq),
        }
    }
}

/// Per-phase dead-time compensation (module docs). Stateless.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeadTimeCompensation<T> {
    config: DeadTimeCompensationConfig<T>,
    inv_band: T,
    /// Half the carrier period (= the sample period), s: 0.5/f_sw.
    half: T,
    /// 1/(2·half), 1/s: the mean over one carrier period.
    inv_period: T,
    /// 1/L̂d, 1/L̂q of `ripple_inductance` (zero where it is zero: edge current off).
    inv_ripple: Dq<T>,
}

impl<T: Real> DeadTimeCompensation<T> {
    /// A new compensation; every field is checked and a bad one named.
    pub fn new(config: DeadTimeCompensationConfig<T>) -> Result<Self, ConfigError> {
        let td = check::non_negative("dead_time", config.dead_time)?;
        let fsw = check::positive("switching_frequency", config.switching_frequency)?;
        check::below(
            "dead_time",
            td * fsw,
            T::lit(0.5),
            "dead_time·switching_frequency below 0.5",
        )?;
        check::non_negative("threshold_voltage", config.threshold_voltage)?;
        let ic = check::positive("current_band", config.current_band)?;
        check::non_negative("ripple_inductance", config.ripple_inductance.d)?;
        check::non_negative("ripple_inductance", config.ripple_inductance.q)?;
        let half = T::lit(0.5) / fsw;
        let inv = |l: T| {
            if l > T::zero() {
                T::one() / l
            } else {
                T::zero()
            }
        };
        Ok(Self {
            config,
            inv_band: T::one() / ic,
            half,
            inv_period: T::one() / (half + half),
            inv_ripple: Dq::new(
                inv(config.ripple_inductance.d),
                inv(config.ripple_inductance.q),
            ),
        })
    }

    /// No state.
    pub fn reset(&mut self) {}

    /// V̂ = Td·f_sw·Vdc + V_th in V (0 when disabled or for a non-finite or negative Vdc).
    #[inline]
    pub fn amplitude(&self, vdc: T) -> T {
        if !(self.config.enabled && vdc.is_finite() && vdc >= T::zero()) {
            return T::zero();
        }
        let c = &self.config;
        c.dead_time * c.switching_frequency * vdc + c.threshold_voltage
    }

    /// The trapezoid v_comp,x = V̂·sat(i_x/Ic) for phase currents `i_abc` (A).
    #[inline]
    pub fn trapezoid(&self, i_abc: Abc<T>, vdc: T) -> Abc<T> {
        let v = self.amplitude(vdc);
        let one = T::one();
        let f = |i: T| v * clamp(i * self.inv_band, -one, one);
        Abc::new(f(i_abc.a), f(i_abc.b), f(i_abc.c))
    }

    /// The sign variant v_comp,x = V̂·sign(i_x) (0 at exactly zero current).
    #[inline]
    pub fn sign(&self, i_abc: Abc<T>, vdc: T) -> Abc<T> {
        let v = self.amplitude(vdc);
        let f = |i: T| {
            if i > T::zero() {
                v
            } else if i < T::zero() {
                -v
            } else {
                T::zero()
            }
        };
        Abc::new(f(i_abc.a), f(i_abc.b), f(i_abc.c))
    }

    /// The compensation for one sample as per-phase voltages: `rotation` is e^{j(θ̂+1.5ω̂Ts)}
    /// (the delay-compensated angle), `i_dq_ref` the current reference, `i_abc` the measured
    /// phase currents (used by [`DeadTimeMethod::Sign`] only), `v_ab` the voltage reference
    /// (V, before compensation; used by [`DeadTimeMethod::EdgeCurrent`] only, for the ripple).
    /// Zero when disabled; a non-finite input gives zero.
    #[inline]
    pub fn phase_voltages(
        &self,
        rotation: Rotation<T>,
        i_dq_ref: Dq<T>,
        i_abc: Abc<T>,
        v_ab: Ab<T>,
        vdc: T,
    ) -> Abc<T> {
        let out = match self.config.method {
            _ if !self.config.enabled => return Abc::default(),
            DeadTimeMethod::Trapezoidal => self.trapezoid(i_dq_ref.to_ab(rotation).to_abc(), vdc),
            DeadTimeMethod::EdgeCurrent => self.edge_current(
                rotation,
                i_dq_ref.to_ab(rotation).to_abc(),
                v_ab.to_abc(),
                vdc,
            ),
            DeadTimeMethod::Sign => self.sign(i_abc, vdc),
        };
        if out.is_finite() { out } else { Abc::default() }
    }

    /// [`DeadTimeMethod::EdgeCurrent`] for phase currents `i_abc` (A) and the phase voltage
    /// reference `v_abc` (V, before compensation), the rotor frame `rotation` setting the
    /// inductance matrix: −(period-average pole error) per phase (module docs). The trapezoid
    /// without a positive DC link or inductance.
    pub fn edge_current(
        &self,
        rotation: Rotation<T>,
        i_abc: Abc<T>,
        v_abc: Abc<T>,
        vdc: T,
    ) -> Abc<T> {
        let c = &self.config;
        let l = c.ripple_inductance;
        let first = self.trapezoid(i_abc, vdc);
        if !(vdc > T::zero() && l.d > T::zero() && l.q > T::zero()) {
            return first;
        }
        let one = T::one();
        let i = [i_abc.a, i_abc.b, i_abc.c];
        let gates = self.gate_times(v_abc, first, vdc);
        let (d_rise, d_fall) = self.edge_delays(rotation, i, gates, vdc);
        let band = self.inv_band;
        let vth = c.threshold_voltage;
        let per_second = vdc * c.switching_frequency;
        let f =
            |k: usize| per_second * (d_rise[k] - d_fall[k]) + vth * clamp(i[k] * band, -one, one);
        Abc::new(f(0), f(1), f(2))
    }

    /// The gate times within each half period of the pole voltages the modulator will
    /// realise (reference `v_abc` + first-guess compensation `first`, min-max zero sequence
    /// as SVPWM, as offsets from the DC-link mid-point): legs go high at half/2 − v·half/Vdc
    /// while the carrier falls (rising edges), low at half/2 + v·half/Vdc while it rises.
    #[inline(always)]
    fn gate_times(&self, v_abc: Abc<T>, first: Abc<T>, vdc: T) -> ([T; 3], [T; 3]) {
        let zero = T::zero();
        let half = self.half; // half carrier period = sample period
        let mut vp = [v_abc.a + first.a, v_abc.b + first.b, v_abc.c + first.c];
        let (mx, mn) = (
            vp[0].step_max(vp[1]).step_max(vp[2]),
            vp[0].step_min(vp[1]).step_min(vp[2]),
        );
        let v0 = -(mx + mn) * T::lit(0.5);
        for v in &mut vp {
            *v += v0;
        }
        let secs_per_volt = half / vdc;
        let h = T::lit(0.5) * half;
        let tg_rise = vp.map(|v| clamp(h - v * secs_per_volt, zero, half));
        let tg_fall = vp.map(|v| clamp(h + v * secs_per_volt, zero, half));
        (tg_rise, tg_fall)
    }

    /// Delay of one edge (band model): the opposing current waits Td, the helping one
    /// Td·(1 − |i|/Ic)⁺.
    #[inline(always)]
    fn edge_delay(&self, rising: bool, ie: T) -> T {
        let zero = T::zero();
        let td = self.config.dead_time;
        let opposes = if rising { ie > zero } else { ie < zero };
        if opposes {
            td
        } else {
            td * (T::one() - ie.abs() * self.inv_band).step_max(zero)
        }
    }

    /// Each edge's delay, from the current at the edge: the sampled currents `i`, then twice
    /// refined with the ripple the gate times `gates` (rising, falling) and those delays
    /// imply (once where the first refinement keeps them).
    #[inline(always)]
    fn edge_delays(
        &self,
        rotation: Rotation<T>,
        i: [T; 3],
        gates: ([T; 3], [T; 3]),
        vdc: T,
    ) -> ([T; 3], [T; 3]) {
        let first = (
            i.map(|x| self.edge_delay(true, x)),
            i.map(|x| self.edge_delay(false, x)),
        );
        let once = self.refined_delays(rotation, i, gates, first, vdc);
        // A refinement that keeps every delay is at its fixed point: the second one would
        // repeat the same arithmetic on the same numbers (every current outside the band with
        // its ripple, the common case away from the zero crossings).
        if once == first {
            return once;
        }
        self.refined_delays(rotation, i, gates, once, vdc)
    }

    /// One refinement of the edges' delays (rising, falling): the current at each edge is
    /// the sampled one plus the ripple of the volt-seconds applied up to it.
    #[inline(always)]
    fn refined_delays(
        &self,
        rotation: Rotation<T>,
        i: [T; 3],
        (tg_rise, tg_fall): ([T; 3], [T; 3]),
        (d_rise, d_fall): ([T; 3], [T; 3]),
        vdc: T,
    ) -> ([T; 3], [T; 3]) {
        let (zero, one) = (T::zero(), T::one());
        let half = self.half;
        // Phase axes u_x and the current response L⁻¹·w of a volt-second vector w (α-β, the
        // rotor frame's 1/L̂d, 1/L̂q).
        let k3 = T::lit(0.866_025_403_784_438_6);
        let axes = [
            Ab::new(one, zero),
            Ab::new(T::lit(-0.5), k3),
            Ab::new(T::lit(-0.5), -k3),
        ];
        let (inv_ld, inv_lq) = (self.inv_ripple.d, self.inv_ripple.q);
        let respond = |w: Ab<T>| {
            let w = w.to_dq(rotation);
            Dq::new(w.d * inv_ld, w.q * inv_lq).to_ab(rotation)
        };
        let pole_step = T::lit(2.0 / 3.0) * vdc; // α-β step of one pole moving by Vdc
        let pr = [0, 1, 2].map(|k| (tg_rise[k] + d_rise[k]).step_min(half));
        let pf = [0, 1, 2].map(|k| (tg_fall[k] + d_fall[k]).step_min(half));
        // Volt-seconds over each half: poles low → high at pr while the carrier falls,
        // high → low at pf while it rises (zero vectors at the samples).
        let (mut int_r, mut int_f) = (Ab::zero(), Ab::zero());
        for k in 0..3 {
            int_r += axes[k] * (pole_step * (half - pr[k]));
            int_f += axes[k] * (-pole_step * (half - pf[k]));
        }
        // Mean voltage over the period (the back-EMF and R·i it balances) and the current's
        // swing between the carrier's peak and valley samples, whose mean is the reference:
        // i(peak) = i − Δ/2, i(valley) = i + Δ/2.
        let vbar = (int_r + int_f) * self.inv_period;
        let half_swing = respond((int_r - int_f) * T::lit(0.25));
        let mut nr = d_rise;
        let mut nf = d_fall;
        for x in 0..3 {
            // Volt-seconds (mean removed) up to x's own gate edge, x not yet switched.
            let (mut wr, mut wf) = (vbar * -tg_rise[x], vbar * -tg_fall[x]);
            for k in 0..3 {
                if k != x {
                    wr += axes[k] * (pole_step * (tg_rise[x] - pr[k]).step_max(zero));
                    wf += axes[k] * (-pole_step * (tg_fall[x] - pf[k]).step_max(zero));
                }
            }
            let ie_r = i[x] + axes[x].dot(respond(wr) - half_swing);
            let ie_f = i[x] + axes[x].dot(respond(wf) + half_swing);
            nr[x] = self.edge_delay(true, ie_r);
            nf[x] = self.edge_delay(false, ie_f);
        }
        (nr, nf)
    }

    /// The part of the compensation `comp` (per phase, from
    /// [`phase_voltages`](Self::phase_voltages) with the same `rotation` and `i_dq_ref`) that
    /// the inverter loses with the duty `duty`: all of it on a leg that switches, only the
    /// device drop V_th·sat(i*_x/Ic) on a leg held at duty 0 or 1 over the period (no edge,
    /// hence no dead time; the device still conducts). Where the modulator limits the
    /// reference (the hexagon, overmodulation) one or two legs are held, and telling the
    /// estimator that the dead time was lost there too would put V_dt·sign(i_x) into its
    /// integrand (module docs, "Held legs").
    #[inline]
    pub fn lost(
        &self,
        comp: Abc<T>,
        rotation: Rotation<T>,
        i_dq_ref: Dq<T>,
        duty: Abc<T>,
    ) -> Abc<T> {
        if !self.config.enabled {
            return comp;
        }
        let i = i_dq_ref.to_ab(rotation).to_abc();
        let one = T::one();
        let vth = self.config.threshold_voltage;
        let f = |c: T, d: T, i: T| {
            if d <= T::zero() || d >= one {
                vth * clamp(i * self.inv_band, -one, one)
            } else {
                c
            }
        };
        let out = Abc::new(
            f(comp.a, duty.a, i.a),
            f(comp.b, duty.b, i.b),
            f(comp.c, duty.c, i.c),
        );
        if out.is_finite() { out } else { comp }
    }

    /// The compensation as an α-β vector (Clarke of [`phase_voltages`](Self::phase_voltages)),
    /// to add to v*_ab before modulation.
    #[inline]
    pub fn step(
        &self,
        rotation: Rotation<T>,
        i_dq_ref: Dq<T>,
        i_abc: Abc<T>,
        v_ab: Ab<T>,
        vdc: T,
    ) -> Ab<T> {
        self.phase_voltages(rotation, i_dq_ref, i_abc, v_ab, vdc)
            .to_ab()
    }

    /// The configuration in use.
    pub fn config(&self) -> &DeadTimeCompensationConfig<T> {
        &self.config
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    fn comp(method: DeadTimeMethod) -> DeadTimeCompensation<f64> {
        DeadTimeCompensation::new(DeadTimeCompensationConfig {
            method,
            ripple_inductance: Dq::zero(),
            ..DeadTimeCompensationConfig::for_machine(&MachineModel::paper())
        })
        .unwrap()
    }

    #[test]
    fn amplitude_is_dead_time_average_plus_threshold() {
        let c = comp(DeadTimeMethod::Trapezoidal);
        // 2.5 µs · 5 kHz · 300 V + 1 V
        assert!((c.amplitude(300.0) - 4.75).abs() < 1e-12);
        let off = DeadTimeCompensation::new(DeadTimeCompensationConfig {
            enabled: false,
            ..DeadTimeCompensationConfig::<f64>::for_machine(&MachineModel::paper())
        })
        .unwrap();
        assert_eq!(off.amplitude(300.0), 0.0);
        let rot = Rotation::from_angle(0.2);
        assert_eq!(
            off.step(
                rot,
                Dq::new(0.0, 10.0),
                Abc::new(1.0, 2.0, -3.0),
                Ab::zero(),
                300.0
            ),
            Ab::zero()
        );
    }

    #[test]
    fn trapezoid_follows_spec_formula_sign_and_magnitude() {
        let c = comp(DeadTimeMethod::Trapezoidal);
        let vhat = c.amplitude(300.0);
        let (theta_adv, i_ref) = (0.4, Dq::new(1.0, 5.0));
        let rot = Rotation::from_angle(theta_adv);
        let v = c.phase_voltages(rot, i_ref, Abc::default(), Ab::zero(), 300.0);
        let theta_i = theta_adv + 5.0_f64.atan2(1.0);
        let mag = i_ref.norm();
        for (vx, phi) in [(v.a, 0.0), (v.b, 2.0 * PI / 3.0), (v.c, -2.0 * PI / 3.0)] {
            let ix = mag * (theta_i - phi).cos();
            let expected = vhat * (ix / 0.3).clamp(-1.0, 1.0);
            assert!((vx - expected).abs() < 1e-12, "{vx} vs {expected}");
        }
        // Trapezoid over one electrical turn: plateaus at ±V̂, linear through zero with slope
        // V̂/Ic per ampere, and the compensation pushes each pole towards its current.
        let mut plateau = 0;
        for k in 0..3600 {
            let th = k as f64 * 2.0 * PI / 3600.0;
            let va = c
                .phase_voltages(
                    Rotation::from_angle(th),
                    Dq::new(2.0, 0.0),
                    Abc::default(),
                    Ab::zero(),
                    300.0,
                )
                .a;
            let ia = 2.0 * th.cos();
            assert!(va * ia >= 0.0 && va.abs() <= vhat + 1e-12);
            if ia.abs() >= 0.3 {
                assert!((va.abs() - vhat).abs() < 1e-12);
                plateau += 1;
            } else {
                assert!((va - vhat * ia / 0.3).abs() < 1e-12);
            }
        }
        // |cos| ≥ 0.15 over all but 2·2·asin(0.15)/2π ≈ 9.6 % of the turn.
        assert!(
            (plateau as f64 / 3600.0 - (1.0 - 4.0 * 0.15_f64.asin() / (2.0 * PI))).abs() < 2e-3
        );
    }

    #[test]
    fn sign_variant_uses_measured_currents() {
        let c = comp(DeadTimeMethod::Sign);
        let v = c.phase_voltages(
            Rotation::from_angle(0.0),
            Dq::new(10.0, 0.0),
            Abc::new(0.01, -0.02, 0.0),
            Ab::zero(),
            300.0,
        );
        assert_eq!(v, Abc::new(4.75, -4.75, 0.0));
        // Clarke: the α-β vector of the per-phase compensation.
        let ab = c.step(
            Rotation::from_angle(0.0),
            Dq::zero(),
            Abc::new(1.0, -0.5, -0.5),
            Ab::zero(),
            300.0,
        );
        assert!((ab.alpha - 4.75 * (2.0 + 2.0) / 3.0).abs() < 1e-12 && ab.beta.abs() < 1e-12);
    }

    fn edge(l: f64) -> DeadTimeCompensation<f64> {
        let l = Dq::new(l, l);
        DeadTimeCompensation::new(DeadTimeCompensationConfig {
            method: DeadTimeMethod::EdgeCurrent,
            ripple_inductance: l,
            ..DeadTimeCompensationConfig::for_machine(&MachineModel::paper())
        })
        .unwrap()
    }

    #[test]
    fn edge_current_is_the_trapezoid_outside_the_band_and_odd() {
        let c = edge(2.63e-3);
        let t = comp(DeadTimeMethod::Trapezoidal);
        let rot = Rotation::from_angle(0.0);
        // Every phase far outside Ic + ripple: exactly the trapezoid (±V̂ per phase).
        for (i, v) in [
            (Ab::new(12.0, 3.0), Ab::new(4.0, 1.0)),
            (Ab::new(-2.0, 8.0), Ab::new(-60.0, 90.0)),
        ] {
            let i_dq = Dq::new(i.alpha, i.beta);
            let e = c.phase_voltages(rot, i_dq, Abc::default(), v, 300.0);
            let p = t.phase_voltages(rot, i_dq, Abc::default(), v, 300.0);
            assert!((e.a - p.a).abs() < 1e-12 && (e.b - p.b).abs() < 1e-12);
            assert!((e.c - p.c).abs() < 1e-12, "{e:?} vs {p:?}");
        }
        // Odd: (−i, −v) gives −v_comp; within the band it differs from the trapezoid but
        // stays within ±V̂ and pushes each pole towards its current.
        let vhat = c.amplitude(300.0);
        for ib in [-0.25, -0.1, 0.05, 0.2] {
            let i = Abc::new(-12.0 - 0.5 * ib, ib, 12.0 - 0.5 * ib).to_ab();
            let v = i * 0.327;
            let i_dq = Dq::new(i.alpha, i.beta);
            let neg = Dq::new(-i.alpha, -i.beta);
            let e = c.phase_voltages(rot, i_dq, Abc::default(), v, 300.0);
            let f = c.phase_voltages(rot, neg, Abc::default(), v * -1.0, 300.0);
            assert!(
                (e.a + f.a).abs() < 1e-9 && (e.b + f.b).abs() < 1e-9,
                "{e:?} {f:?}"
            );
            assert!(e.b.abs() <= vhat && e.b * ib >= 0.0, "{ib}: {e:?}");
        }
        // No inductance or no DC link: the trapezoid.
        let i = Dq::new(-0.1, 0.2);
        let e = edge(0.0).phase_voltages(rot, i, Abc::default(), Ab::new(1.0, 0.0), 300.0);
        assert_eq!(
            e,
            t.phase_voltages(rot, i, Abc::default(), Ab::zero(), 300.0)
        );
        assert_eq!(
            c.phase_voltages(rot, i, Abc::default(), Ab::new(1.0, 0.0), -1.0),
            Abc::default()
        );
    }

    #[test]
    fn bad_config_names_field() {
        let bad = |f: fn(&mut DeadTimeCompensationConfig<f64>)| {
            let mut cfg = DeadTimeCompensationConfig::for_machine(&MachineModel::paper());
            f(&mut cfg);
            DeadTimeCompensation::new(cfg).unwrap_err().field()
        };
        assert_eq!(bad(|c| c.dead_time = -1e-6), "dead_time");
        assert_eq!(bad(|c| c.dead_time = 1e-3), "dead_time");
        assert_eq!(bad(|c| c.switching_frequency = 0.0), "switching_frequency");
        assert_eq!(bad(|c| c.threshold_voltage = f64::NAN), "threshold_voltage");
        assert_eq!(bad(|c| c.current_band = 0.0), "current_band");
        assert_eq!(
            bad(|c| c.ripple_inductance = Dq::new(1e-3, -1e-3)),
            "ripple_inductance"
        );
    }
}
