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
//! periods of the reference plus the compensation itself (symmetric carrier, min-max zero
//! sequence as [`crate::control::modulation`]), each pole's edge delayed by the band model,
//! the current of each phase at its own gate edge (the piecewise-linear ripple: each other
//! pole already switched adds the current response of its α-β voltage step ±(2/3)·Vdc·u_k,
//! −Vdc/(3L̂) on a round rotor; the mean slope removed; the peak sample i − Δ/2 and the
//! valley sample i + Δ/2, Δ the swing the pattern predicts), and the two edges' delays from
//! the band model at the edge currents the delays imply (next paragraph); the period-average
//! pole error is then Vdc·f_sw·(t_fall − t_rise) − V_th·sat(i/Ic). Outside the band it is
//! the trapezoid exactly.
//!
//! **Which solve.** The delays move the edge currents they are computed from: on a round
//! rotor at the loaded standstill (the phase near zero current between a positive and a
//! negative one) one second of an edge's delay moves its own edge current by Vdc/(3·L̂),
//! and the band model turns one ampere into Td/Ic seconds, a loop gain
//! g = Vdc·Td/(3·min(L̂d, L̂q)·Ic) ([`DeadTimeCompensation::loop_gain`], computed once from
//! the configuration at the rated DC link `dc_voltage`). Two solves:
//! - g ≤ [`EDGE_SOLVE_LOOP_GAIN`] (0.75): two fixed-point passes on the gate times of the
//!   reference plus the trapezoid (`passes` submodule). Against the switching-resolved
//!   inverter at standstill (fado-sim's inverter tests, phase b through the band) they
//!   leave 0.097 V on the paper's motor (g = 0.33; 0.64 V with the trapezoid alone) and
//!   0.042 / 0.080 V under 5.55 / 12 A on the MAD 5010 KV110's inverter with 200 µH
//!   (g = 0.34).
//! - g above it and below 1, in the samples where the middle pole's edges follow the
//!   others' (below; the passes elsewhere): the root of delay − band model(edge current the delays imply) with the
//!   gate times of the reference plus the compensation itself, a piecewise-linear problem
//!   (`edges` submodule: Newton steps with the pattern's own slopes, bounded rounds). The
//!   passes oscillate as g nears 1: on the MAD 5010 KV110 (44.4 V, 85 µH, 20 kHz, g = 0.79)
//!   they leave 0.32 V under 5.55 A, the root solve 0.043 V (0.054 V under 12 A), and its
//!   `stops` from a zero start angle keeps |θ − θ̂| at 0.12–0.20 rad (0.21–0.35 rad on the
//!   passes; crates/fado-sim/tests/multirotor_datasheets.rs). Where g is small the passes
//!   are the better of the two: the root solve leaves 0.119 V on the paper's motor.
//!
//! The threshold lies between the Siemens 1FT6084 preset (g = 0.71, the largest of the
//! machines whose reversal and stops are kept bit-identical on the passes) and the MAD 5010
//! KV110 (g = 0.79): a margin of 5 % either side. g of the presets: ipmsm-2k2 0.04,
//! hub-hoverboard-48v 0.12, outrunner-cheetah-24v 0.18, pmsyrm-5k 0.22, paper 0.33,
//! servo-1ft6084 0.71 (passes); multirotor-mn5006-22v 1.23, ipmsm-gem-50k 3.9 (passes, g ≥ 1).
//! Per sample, the root solve runs only where the middle pole's gate edges
//! follow the other two poles' edges by a margin: the references plus the trapezoid more
//! than 4·Td·f_sw·Vdc (2·Td in time) from the largest and from the smallest; elsewhere the
//! passes. Where the middle phase's two edges come before any other pole's edge they see
//! only the phase's own swing, which both of its delays move (sum-mode loop gain g), and
//! what the model leaves out moves the root by its error/(1 − g): the device drop
//! V_th·sat(i(t)/Ic) following the instantaneous current (21 Ω inside the band against
//! 6 mH on the 400 V servo test class: 560 V, 6 mH, 5 kHz, Td 2.5 µs, Ic 0.085 A, V_th 1.8 V,
//! g = 0.91) and the zero vector's slope. There, at standstill under 1.5 A with phase b at
//! −0.5 Ic (the a and c edges 1.9 µs, < Td, from b's), the model's root is unique and
//! reached (Td on both edges, −0.90 V) while the inverter's own is −1.41 V: it puts the
//! rising edge's current 5 mA (0.06 Ic) above the inverter's. Measured worst error on
//! phase b (fado-sim's inverter tests, phase b through ±6 Ic) under 1.5 / 4.4 / 8.8 A: the
//! passes 0.79 / 1.17 / 2.70 V, the root solve in every sample 1.39 / 1.00 / 0.06 V; with
//! the margin at 2·Td·f_sw·Vdc (Td in time) the 8.8 A case keeps the root solve
//! (0.06 V) but the servo's start-up with its load arriving in the release reads 0.253 rad
//! (crates/fado-sim/tests/calibration_load_classes.rs, bound 0.25; 0.248 at 4·Td·f_sw·Vdc,
//! 0.283 on the root solve in every sample).
//! At g ≥ 1 the two passes run in every sample. There an edge's loop gain exceeds 1 wherever
//! it is in the band, the model's root need not be unique (`edges` submodule) and the passes
//! are measured the better of the two: on the T-Motor U8 II KV100 (44.4 V, 12 µH, 24 kHz,
//! g = 2.1) `stops` from the start angle 1.0 rad keeps |θ − θ̂| at 0.057 rad on the passes
//! and reaches 0.317 rad with the root solve in every sample. Not at the loaded standstill
//! itself, where the ripple (Vdc/(3·L̂) = 1.2 A/µs) keeps the edges out of the band and both
//! leave 0.012 V under the stops' 14.3 A (fado-sim's inverter tests), but (a) at the
//! start-up's release, where the held d current steps to zero and the current vector passes
//! through it with every phase in the band (where the per-phase Newton steps leave the star
//! point's coupling out): i_q reaches −4.5 A against a −2.5 A reference and |θ − θ̂|
//! 0.17 rad (0.007 rad on the passes), and (b) from the release and the loaded acceleration
//! on, R̂s settles at −0.42 % of Rs (−0.17 % on the passes), which the loaded standstill's
//! resistive speed R̂s·I/λ̂f ≈ 400 rad/s turns into the angle (0.27–0.32 rad in each
//! standstill, 0.02–0.06 on the passes). ipmsm-gem-50k, multirotor-mn5006-22v and the
//! Flipsky 6215 (g = 1.5) pass their scenarios on the passes.
//! Limit of the root solve: where an edge's loop gain
//! (Td/Ic)·(β − σ/2) reaches 1 (a low-inductance salient rotor; same test at 0.37/1.2 mH,
//! g = 2.3: trapezoid 1.12 V, the root solve 0.75 V, the passes 0.84 V) the root is not unique and the step is the plain
//! evaluation; with every phase in the band the per-phase steps leave the star point's
//! coupling out (`edges` submodule). Cost over the trapezoid: the passes ≈ 200 flops and 6
//! divisions, the root solve ≈ 600 flops and up to 9 divisions (not measured on target).
//! The current
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

mod edges;
mod passes;

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
/// Loop gain g = Vdc·Td/(3·min(L̂d, L̂q)·Ic) above which [`DeadTimeMethod::EdgeCurrent`]
/// solves the edges' delays for their root instead of taking two fixed-point passes (up to
/// g = 1, in the samples where the middle pole's edges follow the others'): 0.75
/// (module docs, "Which solve": between the Siemens 1FT6084 preset at g = 0.71, kept on the
/// passes, and the MAD 5010 KV110 at g = 0.79, where the passes leave 0.32 V at standstill
/// and the root solve 0.043 V).
pub const EDGE_SOLVE_LOOP_GAIN: f64 = 0.75;
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
    /// Rated DC-link voltage in V (inverter datum): with the other fields it sets the
    /// refinement's loop gain g that chooses the edge-current solve (module docs, "Which
    /// solve"); 0: the two passes. Default the machine model's `dc_voltage`.
    pub dc_voltage: T,
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
            dc_voltage: machine.dc_voltage,
        }
    }

    /// The inverter's voltage error V̂ = Td·f_sw·Vdc + V_th (V) at the DC link `vdc`, whether
    /// or not the compensation is enabled.
    #[inline]
    pub fn error_voltage(&self, vdc: T) -> T {
        self.dead_time * self.switching_frequency * vdc + self.threshold_voltage
    }
}

/// Per-phase dead-time compensation (module docs). Its only state is the reference through
/// the current loop's response that [`DeadTimeCompensation::phase_voltages_followed`] keeps.
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
    /// The edge-current refinement's loop gain g = Vdc·Td/(3·min(L̂d, L̂q)·Ic) at the rated
    /// DC link (module docs, "Which solve").
    loop_gain: T,
    /// g above [`EDGE_SOLVE_LOOP_GAIN`]: the root solve, else the two passes.
    solve_edges: bool,
    /// The current reference through the current loop's response (A, in the frame of θ̂;
    /// see [`DeadTimeCompensation::phase_voltages_followed`]).
    followed: Dq<T>,
    /// That response's gain per sample, 1 − e^{−ωc·Ts} (0: not set, the reference alone).
    follow_gain: T,
    /// The reference ran ahead of the current across a phase's band and the measured
    /// current has not crossed it yet.
    ahead: bool,
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
        let vdc = check::non_negative("dc_voltage", config.dc_voltage)?;
        let half = T::lit(0.5) / fsw;
        let inv = |l: T| {
            if l > T::zero() {
                T::one() / l
            } else {
                T::zero()
            }
        };
        let l_min = config
            .ripple_inductance
            .d
            .step_min(config.ripple_inductance.q);
        let loop_gain = if l_min > T::zero() {
            vdc * td / (T::lit(3.0) * l_min * ic)
        } else {
            T::zero()
        };
        Ok(Self {
            config,
            loop_gain,
            solve_edges: loop_gain > T::lit(EDGE_SOLVE_LOOP_GAIN) && loop_gain < T::one(),
            inv_band: T::one() / ic,
            half,
            inv_period: T::one() / (half + half),
            inv_ripple: Dq::new(
                inv(config.ripple_inductance.d),
                inv(config.ripple_inductance.q),
            ),
            followed: Dq::zero(),
            follow_gain: T::zero(),
            ahead: false,
        })
    }

    /// Forgets the followed reference (it starts again from zero current).
    pub fn reset(&mut self) {
        self.followed = Dq::zero();
        self.ahead = false;
    }

    /// The current loop whose response [`DeadTimeCompensation::phase_voltages_followed`]
    /// follows the reference with: its bandwidth (Hz) and the sample period `ts` (s).
    /// A non-positive or non-finite product leaves the reference alone.
    pub fn set_current_loop(&mut self, bandwidth_hz: T, ts: T) {
        let x = T::lit(2.0 * core::f64::consts::PI) * bandwidth_hz * ts;
        self.follow_gain = if x.is_finite() && x > T::zero() {
            T::one() - (-x).exp()
        } else {
            T::zero()
        };
    }

    /// V̂ = Td·f_sw·Vdc + V_th in V (0 when disabled or for a non-finite or negative Vdc).
    #[inline]
    pub fn amplitude(&self, vdc: T) -> T {
        if !(self.config.enabled && vdc.is_finite() && vdc >= T::zero()) {
            return T::zero();
        }
        self.config.error_voltage(vdc)
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

    /// [`phase_voltages`](Self::phase_voltages) in a drive whose current loop is set
    /// ([`DeadTimeCompensation::set_current_loop`]), given the measured current `i_dq` (A, in
    /// the frame of θ̂, the frame of `i_dq_ref`). The trapezoid and the edge currents take the
    /// reference, except where the reference has run ahead of the current across a phase's
    /// band: in a phase where the reference and the reference through the current loop's
    /// first-order response lie on opposite sides of the band (both beyond ±Ic, of opposite
    /// signs), they take the measured current (turned by `rotation` as the reference is).
    ///
    /// Why: a step of the reference (a speed PI swinging its output between the current
    /// limits reverses i_q within a few carrier periods) crosses a phase's zero about one
    /// time constant of the current loop before the current does, and for that time the
    /// reference's sign is the wrong one for that phase: a pole error of 2·V̂ that the
    /// estimator integrates as if it had been applied. On the drawn 192 kW IPMSM at standstill
    /// (i_q* swinging ±910 A) each swing left 0.02–0.05 Wb in λ1 and the angle was lost. The
    /// filtered reference carries no sensor noise and equals the reference wherever the
    /// reference is steady in the rotor frame, so the test fires in such transients alone.
    #[inline]
    pub fn phase_voltages_followed(
        &mut self,
        rotation: Rotation<T>,
        i_dq_ref: Dq<T>,
        i_dq: Dq<T>,
        i_abc: Abc<T>,
        v_ab: Ab<T>,
        vdc: T,
    ) -> Abc<T> {
        let followed = self.followed + (i_dq_ref - self.followed) * self.follow_gain;
        // A non-finite reference must not stay in the state.
        self.followed = if followed.is_finite() {
            followed
        } else {
            i_dq_ref
        };
        if self.follow_gain == T::zero() {
            return self.phase_voltages(rotation, i_dq_ref, i_abc, v_ab, vdc);
        }
        let reference = i_dq_ref.to_ab(rotation).to_abc();
        let band = T::one() / self.inv_band;
        let followed = self.followed.to_ab(rotation).to_abc();
        let measured = i_dq.to_ab(rotation).to_abc();
        // Set by the filtered reference (noise-free: never in a steady state), held until
        // the measured current has crossed too (the loop's response to a large step is
        // limited by the voltage, slower than its small-signal bandwidth).
        self.ahead = opposed(band, reference, followed)
            || (self.ahead && opposed(band, reference, measured));
        let at = if self.ahead { i_dq } else { i_dq_ref };
        self.phase_voltages(rotation, at, i_abc, v_ab, vdc)
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
        let solve = self.solves_edges() && self.middle_follows(i_abc, v_abc, vdc);
        self.edge_current_by(solve, rotation, i_abc, v_abc, vdc)
    }

    /// [`edge_current`](Self::edge_current) with the root solve in every sample, whatever the
    /// loop gain and the sample: what the choice is measured against (module docs).
    pub fn edge_current_root_solve(
        &self,
        rotation: Rotation<T>,
        i_abc: Abc<T>,
        v_abc: Abc<T>,
        vdc: T,
    ) -> Abc<T> {
        self.edge_current_by(true, rotation, i_abc, v_abc, vdc)
    }

    /// [`edge_current`](Self::edge_current) with the root solve (`solve`) or the two passes.
    #[inline(always)]
    fn edge_current_by(
        &self,
        solve: bool,
        rotation: Rotation<T>,
        i_abc: Abc<T>,
        v_abc: Abc<T>,
        vdc: T,
    ) -> Abc<T> {
        let c = &self.config;
        let l = c.ripple_inductance;
        if !(vdc > T::zero() && l.d > T::zero() && l.q > T::zero()) {
            return self.trapezoid(i_abc, vdc);
        }
        let one = T::one();
        let i = [i_abc.a, i_abc.b, i_abc.c];
        let (d_rise, d_fall) = if solve {
            self.edge_delays(rotation, i, [v_abc.a, v_abc.b, v_abc.c], vdc)
        } else {
            self.passes_delays(rotation, i_abc, v_abc, vdc)
        };
        let band = self.inv_band;
        let vth = c.threshold_voltage;
        let per_second = vdc * c.switching_frequency;
        let f =
            |k: usize| per_second * (d_rise[k] - d_fall[k]) + vth * clamp(i[k] * band, -one, one);
        Abc::new(f(0), f(1), f(2))
    }

    /// The edge-current refinement's loop gain g = Vdc·Td/(3·min(L̂d, L̂q)·Ic) at the rated DC
    /// link, computed once from the configuration (module docs, "Which solve").
    pub fn loop_gain(&self) -> T {
        self.loop_gain
    }

    /// Whether [`DeadTimeMethod::EdgeCurrent`] solves the edges' delays for their root (g
    /// above [`EDGE_SOLVE_LOOP_GAIN`] and below 1; only in the samples where the middle
    /// pole's edges follow the others') rather than taking the two fixed-point passes (module
    /// docs, "Which solve").
    #[inline(always)]
    pub fn solves_edges(&self) -> bool {
        self.solve_edges
    }

    /// Whether the middle pole's gate edges follow the other poles' edges with a margin
    /// (module docs, "Which solve"): the poles of the reference `v_abc` plus the trapezoid of
    /// `i_abc` more than 2·Td·Vdc/(half period) = 4·Td·f_sw·Vdc apart (2·Td in time: a pole
    /// edge waits at most Td after its gate, and as much again), the middle from the largest
    /// and from the smallest.
    #[inline(always)]
    fn middle_follows(&self, i_abc: Abc<T>, v_abc: Abc<T>, vdc: T) -> bool {
        let t = self.trapezoid(i_abc, vdc);
        let vp = [v_abc.a + t.a, v_abc.b + t.b, v_abc.c + t.c];
        let mx = vp[0].step_max(vp[1]).step_max(vp[2]);
        let mn = vp[0].step_min(vp[1]).step_min(vp[2]);
        let mid = vp[0] + vp[1] + vp[2] - mx - mn;
        let apart = T::lit(2.0) * self.config.dead_time * vdc / self.half;
        mx - mid > apart && mid - mn > apart
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
mod tests;

/// Whether a phase of `r` and `m` lies on opposite sides of the band ±`band`.
#[inline(always)]
fn opposed<T: Real>(band: T, r: Abc<T>, m: Abc<T>) -> bool {
    let o = |r: T, m: T| (r > band && m < -band) || (r < -band && m > band);
    o(r.a, m.a) || o(r.b, m.b) || o(r.c, m.c)
}
