//! Commissioning: identification of the motor (R̂s, L̂d, L̂q, λ̂f, Ĵ, B̂, its magnetic
//! saturation) and of the inverter's voltage error, at standstill and in a short spin, as one
//! state machine stepped at the control rate.
//!
//! # What the user gives
//! A rough [`MachineModel`](crate::MachineModel) (the *nameplate*): the **ratings are required and trusted**
//! (`rated_current`, `rated_speed_rpm`, `rated_torque`, `dc_voltage`, `pole_pairs`: they set
//! the current limit, the spin speed and the voltage limit); the **parameters** (`rs`, `ld`,
//! `lq`, `flux_linkage`, `inertia`) are only used to size the tests (regulator gains,
//! injection amplitude, ramp rate, plausibility bounds); tested off by −20 %/+25 % (and
//! finishing, measured, off by 0.6×/1.6× on six machine classes from a 2-pole spindle to a
//! 10 kV-class machine).
//! Also required: the sampling period and the inverter's dead time (a firmware setting; it
//! splits the measured inverter voltage error into its dead-time and threshold parts).
//!
//! # Safety
//! Every current reference is within `current_limit_ratio · rated_current` (checked by a
//! property test); a measured current above `trip_ratio` (2) times that limit aborts with the
//! gates off. The magnetic model's flux-linkage pulses (step 5) have no current reference:
//! they are voltage pulses stopped at `magnetics.current_ratio` × the rated current (a few
//! ms each), with the trip at `trip_ratio` × that current. Every phase has a nominal and a
//! maximum duration ([`CommissioningConfig::phase_timeout`]); every standstill voltage is
//! limited to `voltage_limit_ratio · Vdc/√3` (the pulses' to `magnetics.voltage_ratio`).
//! Aborts are typed ([`AbortReason`]): rotation where none is expected, current not following
//! its reference, implausible result, over-current, over-speed, timeout, non-finite samples,
//! a rotor too light for the inertia test.
//!
//! # Procedure (phases in order) and why
//! 1. **Offset calibration** ([`Phase::Offset`]), gates off: the mean of the current readings
//!    is the sensor offset, subtracted from then on.
//! 2. **Alignment** ([`Phase::Align`]): a current vector at 2π/3, then turned to 0 (α axis),
//!    drags the rotor's d axis onto phase a. Two steps so that a rotor starting at the
//!    unstable equilibrium of one is pulled by the other (the usual two-step alignment, e.g.
//!    ST MCSDK's and TI InstaSPIN's). The standstill regulator acts **along the current
//!    reference only**: a PI on the error's component along i*, its voltage along i*; across
//!    i* the voltage is the feedforward's alone (voltage mode). The rotor's swing about the
//!    d current turns the magnet's flux, whose back-EMF lies across the d axis, i.e. across
//!    i*; in voltage mode that EMF drives a current through the machine's own resistance
//!    whose torque opposes the swing (damping 1.5·p²·λf²/R). An integral across i* would act
//!    at the swing's frequency ω as a series reactance K/ω that blocks this current: on a
//!    48 V hub motor (15 pole pairs, 0.4 mH, 0.15 Ω) the swing at 5 Hz met K/ω = 0.86 Ω
//!    against R = 0.15 Ω, its damping fell by R²/(R² + (K/ω)²) = 1/33 and the DC test never
//!    settled (`CurrentNotFollowing`, `fado-sim/tests/commission_classes.rs`). Along i* the
//!    loop is as fast as the sampling allows (`standstill_gains`: ζ = 0.7 at
//!    ωn = 0.1/Ts, its proportional part making up √2·L̂·ωn − R̂): the current along the
//!    d axis only sets the swing's stiffness, not its damping, and the voltage the loop has
//!    to find besides R̂·i* is the inverter's threshold, which does not scale with R·I (60 V
//!    against R·I = 8 V on a 10 kV-class machine, where an integral-only K = R̂²/(2L̂) took
//!    5 s to build the alignment's current). The voltage is *frozen* (the integral's state
//!    held, no proportional part) in the alignment hold (once the current has settled within
//!    3 % of its reference, as in the DC test: frozen at a fixed time, mid-swing, the 50 kW
//!    IPMSM preset's hold parked a phase current inside the dead-time band, whose dead zone
//!    took the resistive damping away, and the rotor swung ±50 r/min undamped into the DC
//!    test), the DC measurement windows and the injections. A feedforward of the
//!    reference, R̂·i* (nameplate) plus the dead-time part Td·f_sw·Vdc of the inverter error
//!    (the configured dead time, docs/method/estimator.md §7's trapezoid), carries the bulk of
//!    the voltage, so the loop only makes up the nameplate's error and the device threshold;
//!    being a function of i*, not of i, it leaves the swing's damping unchanged. Without it
//!    a motor whose inverter error dwarfs R·I (the 5 kW PM-SyRM preset: 4.9 V against 1 V)
//!    waits for the loop to climb through the dead-time band while a fraction of an ampere
//!    already swings the rotor (measured: `RotationDetected` in the DC test). The rotor's
//!    swing in voltage mode, and the creep of an over-damped one (time constant λf/(R·I):
//!    1.3 s on the 10 kV-class machine), scale with the machine, so the alignment steps and
//!    the settling scale with the nameplate's τ = L̄/R (defaults of
//!    [`CommissioningConfig::align_time`] and [`CommissioningConfig::settle_time`]).
//! 3. **Resistance** ([`Phase::Resistance`]): DC current along α at two levels I₁ = I₂/2, I₂ =
//!    90 % of the limit (capped for reluctance rotors, see `dc_level`; where the cap leaves
//!    the lower level's phases b and c, I₂/4, below ¾ of the current band the procedure
//!    assumes, 5 % of the limit, R̂s is the nameplate's with a 1-σ of ∞, k is not measured and the
//!    inverter error is read at the upper level: the ferrite PM-SyRM of
//!    `fado-sim/tests/data/motulator/`, whose levels gave R̂s +50 %). With all three phase currents beyond the inverter's current band the
//!    pole-voltage error is a constant V̂·sign(i_x) per phase, i.e. 4/3·V̂ on the α axis, so
//!    v_α = Rs·i_α + 4/3·V̂: the slope of the two points is Rs, the intercept the inverter
//!    error (the classic two-point DC test, e.g. Bertoluzzo, Buja & Menis, "Self-commissioning
//!    of RFOC induction motor drives: one-line estimation of the stator resistance", and
//!    the dead-time voltage identification of Guerrero et al., "Inverter nonlinearity effects
//!    in high-frequency signal-injection-based sensorless control methods", IEEE TIA 41(2),
//!    2005). V̂ = Td·f_sw·Vdc + V_th (docs/method/estimator.md §7) with the known dead time gives V_th.
//!    The same two levels give the current sensors' gain ratio k = (1 + g_a)/(1 + g_b) =
//!    (Δi_a/Δv_a)/(Δi_b/Δv_b), the drive's start-up calibration
//!    ([`crate::control::gain_calibration`]: its [`ratio_of`](crate::control::gain_calibration::ratio_of), and R̂s as its
//!    [`resistance_of`](crate::control::gain_calibration::resistance_of) along the level difference with phase a corrected by k). From the
//!    inductance tests on, phase a is divided by k, so R̂s, L̂d, L̂q and λ̂f are all in phase
//!    b's scale: the one the drive works in once its own calibration has run. Uncorrected,
//!    R̂s came out in phase a's scale (the α axis *is* phase a's): −0.50 % with the
//!    simulator's default +0.5 % gain error of that sensor, and with that R̂s fixed the
//!    `outrunner-cheetah-24v` preset (2.4 mWb) lost `reversal` and `stops` (0.45–0.54 rad;
//!    R̂s × 1.005 passed). The calibration's own sequence is not run as a phase of its own:
//!    the DC test already is that sequence (two frozen-voltage levels, one half the other,
//!    along one axis), and on the α axis every phase carries at least half of the current,
//!    the best observability the calibration can have (its `min_observability` is 0.2).
//!    What the calibration needs beyond the DC test for R̂s alone is a rotor at rest: phase b
//!    sees the β axis, across which the back-EMF of the rotor's swing about the d current
//!    lies, so each level is averaged only ten of the swing's time constants after its
//!    voltage is frozen (`DC_HOLD_SWING_TIME_CONSTANTS`; 0.3 s to 2.5 s on the presets; a
//!    swing slower than `DC_MAX_HOLD` leaves k unmeasured).
//!    k is refused (left 1, [`Identification::current_gain_ratio`]) where the drive would
//!    refuse it: beyond [`CommissioningConfig::max_gain_mismatch`], a non-positive
//!    conductance or too little of the current in phase a or b.
//! 4. **Inductances** ([`Phase::InductanceD`], [`Phase::InductanceQ`]): on top of the I₁ bias
//!    along d (which holds the rotor), a square-wave voltage of ±V_h with a half period of 4
//!    samples is injected along d, then along q (standstill voltage injection as in Bolognani,
//!    Ortombina et al. and the VESC's inductance test). Over one sample the current changes by
//!    Ts·v/L (the inverter error is constant because no phase current changes sign and the
//!    resistive drop is uncorrelated with the square wave), so a least-squares line of the
//!    sample-to-sample current change on the voltage applied over that sample gives Ts/L
//!    regardless of any constant voltage. The q injection's torque alternates at 1.25 kHz
//!    (at 10 kHz sampling) and moves the rotor by microradians. Saliency: L̂q/L̂d.
//! 5. **Magnetic model** ([`Phase::Magnetics`]): the flux linkage ψ(i) of a saturating
//!    machine at standstill without locking the rotor, after Hinkkanen, Pescetto, Mölsä,
//!    Saarakkala, Pellegrino and Bojoi, "Sensorless self-commissioning of synchronous
//!    reluctance motors at standstill without rotor locking", IEEE TIA 53(3), 2017
//!    (<https://doi.org/10.1109/TIA.2016.2644624>): bipolar excitation, the flux linkage the
//!    integral of v − R̂s·i, the algebraic saturation model fitted to it. Here the excitation
//!    is three bipolar pairs of voltage pulses whose currents point along 0°, 60° and 120° of
//!    the rotor frame (each phase then carries at least half of the current, away from the
//!    inverter's dead-time band; 60° and 120° cross-saturate), each pulse driven up to
//!    `magnetics.current_ratio` × the rated current (stopped on the next sample's predicted
//!    current) and back to zero, its last sample landing the current on zero at a sample
//!    boundary (so that no sample's current changes sign inside it, where the inverter
//!    error's model is wrong by up to 4/3·V̂·Ts), at up to 0.9·Vdc/√3
//!    ([`MagneticsTestConfig`]) and at least 3·R̂s·I_p (nearer the resistive drop the rise
//!    stalls short of I_p), the identified inverter error compensated, the opposite pulse at
//!    once after it, so that the torque's impulse cancels. A pair with rises of N samples
//!    turns a free rotor by about 2·p·T_p·(N·Ts)²/J; N is 16, and where that would turn the
//!    nameplate's rotor by more than 0.2 rad it is shortened, down to 4, to keep the turn at
//!    0.05 rad, each shortened pair repeated
//!    an even number of times with its order alternating (+−, −+), so that the rotor returns
//!    (Hinkkanen et al.'s bipolar excitation, sized for a light rotor). The rotor's turn over
//!    each pair, read from the flux at its end, is the motion monitor: beyond
//!    [`PULSE_MOTION_LIMIT`] (0.15 rad) the pulses start again with rises half as long, and a
//!    rotor that turns that far at the shortest rises leaves the saturation unidentified
//!    ([`SaturationVerdict::RotorMoved`], never "not detected"). Between pairs the gates are
//!    off: the current is zero and ψ = λf·e^{jθ} exactly, where each pair's integral starts.
//!    ψ̂ = ∫(v − R̂s·i − V̂·sat(i/I_band)), with the DC test's R̂s and inverter error V̂ on the
//!    trapezoid of each sample's currents. Two angles matter: the rotor's at the start, along
//!    the current that held it in the inductance tests (the frozen voltage of the DC test
//!    leaves that current up to 0.1 rad off α; taken as 0, the fit was 10–20 % off), and its
//!    motion within a pair, read from the pair's end (zero current again: the flux change
//!    across the magnet is λf·δ) and spread over the pair by the double integral of the
//!    measured torque's shape ψ × i. At the end, with the final λ̂f, every shape of the
//!    algebraic model (exponents, the magnet as a flux or as a current, and the saturating
//!    rib of a PM-assisted SyRM) is fitted by least squares and the best kept
//!    (`magnetic_fit`). Saturation is reported, and the model
//!    returned in [`Identification::saturation`], when its incremental inductances change by
//!    more than `detection_threshold` (5 %) over the pulses' range and it explains the data
//!    (RMS residual below half the constant-inductance model's) with a physical meaning: its
//!    incremental inductances at the inductance tests' operating point within 20 % of
//!    theirs, and its incremental inductance matrix above a tenth of the zero-current one
//!    over the pulses' range (a fitted law i(ψ) that folds back gives a second flux for some
//!    currents, where the incremental inductance is about zero); a linear machine, or one
//!    whose best fit has no physical meaning, keeps its constants. A fit whose inductances
//!    change by more than [`INCONCLUSIVE_CHANGE`] (a quarter) without explaining the data is
//!    no linear machine's: it keeps the constants too, but its verdict is
//!    [`SaturationVerdict::Inconclusive`], not "not detected"
//!    ([`Identification::saturation_verdict`]). Accuracy against the plant's truth:
//!    docs/results/commissioning-magnetics.md.
//! 6. **Spin and back-EMF** ([`Phase::Spin`], [`Phase::Coast`]): an I-f start (a current vector
//!    turned at a speed ramped to `spin_speed_ratio` of the rated speed), regulated by a
//!    synchronous-frame PI tuned from the identified R̂s, L̂ (bandwidth 0.2/Ts; its integral
//!    follows the spin's back-EMF ramp within 5 % of the limit: `spin_integral_gain`), with the
//!    identified inverter error compensated (V̂·sat(i*ₓ/I_band) per phase of the reference,
//!    I_band = 5 % of the limit). Its current is 90 % of the limit, at most λf/(2(L̂q − L̂d))
//!    (nameplate λf, identified L̂: `if_level`), because the rotor lags the I-f vector by
//!    δ and the torque 1.5·p·I·sin δ·(λf − (Lq − Ld)·I·cos δ) is stable about δ ≈ 0 only for
//!    I < λf/(Lq − Ld); the acceleration uses 10 % of the rated torque on the nameplate
//!    inertia, at most a quarter of the magnet torque of that current (`spin_sizing`: half
//!    of it, with a nameplate λf 1.25× and J 0.8× the truth, pulled the 50 kW IPMSM preset
//!    out of step, `Overspeed`; the quarter also leaves it hunting ±15 r/min instead of
//!    ±115: open-loop I-f has no damping). (At 90 % of the limit the 50 kW
//!    IPMSM preset, (Lq − Ld)·I = 1.36 λf, hunted ±1 rad between the two stable lags ±0.74
//!    rad where its active flux vanishes; the PLL slipped by π, the coast started 2 rad off
//!    and its speed estimate was 6 % high: λ̂f −5.5 … −5.9 %.) Then the q current is regulated
//!    to zero and the rotor coasts with a d current of −½ the limit (less on a light rotor:
//!    `J_PLL_MARGIN` (3); `COAST_ID`: every phase
//!    current outside the inverter's dead-time band most of the time, so that its error is
//!    the compensated V̂·sign(i) rather than the dead zone of i ≈ 0). The back-EMF
//!    E = v − R̂s·i − L̂q·di/dt (the active-flux EMF, Boldea et al. 2008, whose angle is the
//!    rotor's for any saliency) is tracked by a PLL (40 Hz, its phase detector on E low-passed
//!    by 1 ms in the PLL's own frame: the sample-to-sample noise of L̂q·Δi/Ts, 170 Ω on the
//!    PM-SyRM preset, fed straight into atan2 and the current loop locked onto it, biased the
//!    angle by 0.2–0.35 rad with the torque's sign; filtered: 0.075 rad rms). The magnet's
//!    EMF e_f = E_q − ω̂·(L̂d − L̂q)·i_d is averaged, with ω̂ (the PLL's integral state), over
//!    a window of `measure_time` in this coast and over a second one at the top of the
//!    inertia test (step 7), at twice the speed, same currents; λ̂f is the slope of the line
//!    ē_f = λf·ω̄ + e₀ through the two. The intercept e₀ takes what of the EMF error does not
//!    grow with the speed: the residual of the inverter's error after its compensation.
//!    Measured on the 50 kW IPMSM preset (its 14 V per phase against a magnet EMF of 12 V at
//!    the spin speed): e₀ ≈ −0.24 V, −2.3 % of λf when read as a single ratio ∫e_f/∫ω̂
//!    (−1.5 % at 0.3, −1.1 % at 0.4 of the rated speed: the error falls as 1/ω), +0.2 to
//!    +0.3 % through the line (the paper motor's −0.5 % and the PM-SyRM's −0.4 % went to
//!    ±0.1 % with it; the servo preset's −0.5 % stayed: the inverter error's part that grows
//!    with the speed, −0.14 % there without dead time). It comes from the
//!    phase currents' zero crossings, where the compensation's trapezoid (I_band) and the
//!    inverter's sharp error differ and the current loop distorts the crossing (measured:
//!    λ̂f −0.3 % with no dead time, −0.65 % with I_band = 1 % of the limit).
//!    What is left is proportional to the speed: the L̂d − L̂q error times i_d
//!    (0.4 % of (Lq − Ld) at 60 A is 0.3 % of λf on that preset), R̂s·i and the current
//!    sensors' gain error (the PLL frame's d current), and the inverter error's part that
//!    grows with the speed (timing).
//! 7. **Inertia and friction** ([`Phase::Inertia`]): in closed loop on the PLL's angle (the
//!    back-EMF observer is the sensorless angle), a q-current step (sized so that each step
//!    lasts 0.5 s on the nameplate inertia, 10–90 % of the limit (less on a light rotor, see
//!    below), at most the I-f level of
//!    λ̂f and L̂: `step_level`, as the spin's and for its reason) up to 2× the spin speed;
//!    there, the second back-EMF window (no q current, the coast's d current); then the
//!    opposite step down to 0.5×. Since ω_mech(t) = ω(t₀) + (1/J)·∫T̂e − (B/J)·∫ω_mech with
//!    T̂e = 1.5·p·(λ̂f·i_q + (L̂d − L̂q)·i_d·i_q), the means over consecutive windows of 40 ms
//!    of ω̂_mech and of the running integrals give Δω̄ = (1/J)·Δ∫T̂e − (B/J)·Δ∫ω (`JWindows`);
//!    least squares over the coasts and both steps gives 1/Ĵ and B̂/Ĵ (the ST MCSDK
//!    profiler's approach, with both acceleration and deceleration so that friction and
//!    inertia separate), solved at the end with the final λ̂f (`JFit` keeps the magnet and
//!    reluctance parts of ∫T̂e apart). Window means rather than the speed at the windows'
//!    ends: the PLL's speed ripple (±30 r/min at six times the electrical frequency on the
//!    50 kW IPMSM preset below 650 r/min, where its 14 V of inverter error dwarfs a 10 V
//!    EMF at 25 A) otherwise lands on each Δω (measured there: Ĵ −7 … −13 %, σ 10 %;
//!    with the means −1.2 … −1.6 %, σ 1.2 %). The d current moves between 0 and the coast's
//!    level at a bounded rate (`ID_RELEASE_EMF`): the active-flux EMF has a d component
//!    (L̂d − L̂q)·di_d/dt that the PLL reads as an angle error. The noisy speed difference is
//!    the dependent variable: as a regressor its noise would bias Ĵ low (errors in
//!    variables; −20 % measured on the IPMSM). No step ends, and no speed check acts, within
//!    `J_SKIP` (30 ms) of a torque change: the PLL's speed transient there (38 then −10 r/min
//!    at the gimbal motor's 13 r/min coast) is no speed. A light rotor's steps, which at 10 %
//!    of the limit would last less than `J_STEP_MIN_TIME` (0.25 s) on the nameplate inertia
//!    (the Estun EMJ-04 servo's bare 3.1e-5 kg·m² rotor: 46 ms, inside the settling and the
//!    windows), are sized to last that long, down to eight current resolutions (the readings'
//!    rms at gates off); such steps, and those of a motor whose R̂s·I exceeds the back-EMF
//!    at the spin speed, hold the coast's d current, so that the PLL reads the EMF outside
//!    the inverter's dead-time band, and Ĵ adds back what the PLL's lag under the
//!    acceleration turns of that current onto q (`j_hold_d`, `pll_lag_inertia`). A rotor
//!    whose steps still end within two windows aborts with
//!    [`AbortReason::RotorTooLight`], naming the speed it reached and the time, as does a
//!    coast that its friction slows below a quarter of the spin speed before its window
//!    ends (the servo's plant with a 1.5e-5 kg·m² rotor: 471 r/min lost in 229 ms). The
//!    procedure ends with the gates off and the rotor coasting at about 10 % of its rated
//!    speed.
//!
//! # Confidence
//! Each identified parameter comes with a relative 1-σ statistical uncertainty computed from
//! the scatter of its own data (block means of 10 ms for the DC tests and the back-EMF, the
//! residuals of the least-squares fits for L and J). It measures noise, not bias: the
//! accuracy against ground truth is what the simulator's table (docs/commissioning.md) shows.

mod config;
mod fits;
mod flux_pulses;
mod lifecycle;
mod magnetic_fit;
mod output;
mod phase;
mod saturation_fit;
mod sizing;
mod spin;
mod standstill;

#[cfg(test)]
mod tests;

pub use config::{CommissioningConfig, MagneticsTestConfig};
pub use magnetic_fit::RESIDUAL_BANDS;
pub use output::{CommissioningOutput, Confidence, Identification};
pub use phase::{AbortReason, Parameter, Phase, Status};
pub use saturation_fit::SaturationFit;

use crate::{Ab, Dq};
use fits::{BlockStats, EmfWindow, JFit, JWindows, Line, emf_line};
use flux_pulses::{FluxPulses, magnetics_time};
pub use flux_pulses::{INCONCLUSIVE_CHANGE, MagneticFit, PULSE_MOTION_LIMIT, SaturationVerdict};
use sizing::{
    INVERTER_BAND_RATIO, clamp, dc_level, dead_time_voltage, libm_round, limit, spin_integral_gain,
    spin_sizing, standstill_gains, step_level,
};

/// The commissioning state machine (module docs).
#[derive(Clone, Debug)]
pub struct Commissioning<T: 'static> {
    cfg: CommissioningConfig<T>,
    ts: T,
    i_limit: T,
    // Sizing from the nameplate.
    k_int: T,
    k_p: T,
    v_inj: T,
    spin_speed: T,
    spin_accel: T,
    /// The I-f current amplitude, A (`if_level`).
    i_if: T,
    // Progress and phases.
    phase: Phase,
    sub: u8,
    t_phase: T,
    t_total: T,
    nominal_total: T,
    nominal_done: T,
    status: Status,
    bad_samples: u32,
    // Offsets.
    off_a: T,
    off_b: T,
    off_n: T,
    /// Σ(a² + b²) of the raw readings at gates off, A².
    off_sq: T,
    /// The current readings' rms about their offsets at gates off (noise and quantisation),
    /// A: the current resolution.
    i_resolution: T,
    // Delay line: commands of n−1 and n−2 (estimated applied voltage), current of n−1.
    c1: Ab<T>,
    c2: Ab<T>,
    i_prev: Ab<T>,
    have_prev: bool,
    // Standstill regulator.
    v_int: Ab<T>,
    /// Unit vector along the current reference (the last non-zero one), along which the
    /// loop regulates.
    u_ref: Ab<T>,
    v_ff: Ab<T>,
    i_ref: Ab<T>,
    err_par: T,
    err_perp: T,
    emf_lpf: Ab<T>,
    /// Time in the alignment at which the rotation check's back-EMF was last at half its
    /// limit or above, s (`align_quiet`).
    align_loud_at: T,
    frozen: bool,
    /// Time in the DC level at which its voltage was frozen, s.
    t_frozen: T,
    /// Hold after the freeze before a DC level is averaged, s (`dc_window_start`).
    dc_hold: T,
    /// The swing dies out within [`DC_MAX_HOLD`]: k may be measured.
    gain_swing_settled: bool,
    saturated_time: T,
    /// Resistance (α components; the β ones for the sensors' gain ratio).
    dc: DcStats<T>,
    /// 1/k, applied to the offset-corrected phase-a current from the inductance tests on
    /// (1 before the DC test and when it gave no plausible k).
    gain_correction: T,
    /// The measured k (NaN before the DC test or when not plausible) and its relative 1-σ.
    gain_ratio: T,
    gain_ratio_sigma: T,
    // Inductance.
    line: Line<T>,
    inj_count: u32,
    inj_sign: T,
    // Results so far.
    rs: T,
    rs_sigma: T,
    v_inv: T,
    v_inv_sigma: T,
    ld: T,
    ld_sigma: T,
    lq: T,
    lq_sigma: T,
    flux: T,
    flux_sigma: T,
    /// The standstill flux-linkage pulses and their samples.
    pulses: FluxPulses<T>,
    /// Spin: control frame, synchronous PI, PLL.
    spin_loop: SpinLoop<T>,
    /// The two back-EMF windows: the coast at the spin speed and the one at J_HIGH × it.
    emf_win: [EmfWindow<T>; 2],
    // Inertia windows.
    jfit: JFit<T>,
    jwin: JWindows<T>,
    /// Inertia test stage: 0 the step up, 1 the second back-EMF window at the top, 2 the
    /// step down.
    j_step: u8,
    /// Time since the d current reached its coast level in stage 1, s.
    t_coast2: T,
    i_j: T,
    /// The step up's record (the step down's sizing, `RotorTooLight`).
    step_rec: StepRecord<T>,
    /// The inertia test's torque steps hold the coast's d current (and its windows all go
    /// into the fit) on a light rotor (its steps' floor lowered below 10 % of the limit:
    /// [`J_STEP_MIN_TIME`]) and where the limit's resistive drop R̂s·I exceeds the back-EMF
    /// at the spin speed; elsewhere they run without d current. Without it the steps'
    /// phase currents sit near the inverter's dead-time band and the PLL reads the EMF
    /// through its error: on the Estun EMJ-04 servo's bare rotor (steps of 0.03 A, EMF
    /// 16 V against an inverter error of 4.9 V) its speed read ±150 r/min; on the gimbal
    /// motor (`gbm5208-200t-4s`, 0.45 V of EMF at its 20 r/min spin speed, R̂s·I 2.1 V) its
    /// angle swung 0.2 rad and the step up ended at 18 r/min read as 40. With the d current
    /// held the PLL's lag under the steps' acceleration turns part of it onto q
    /// (`pll_lag_inertia`). Mixing windows with and without it biases the fit: a PLL angle
    /// error ε puts i_d·sin ε on the q axis, a torque the PLL frame does not see (on the
    /// servo −6 … −10 mA in the coasts, a third of the step's; B̂ 1.9× the truth, Ĵ −14.6 %).
    j_hold_d: bool,
    /// The coast's d current (its magnitude), A: `coast_level`.
    coast_id: T,
    /// d-current reference of the inertia test, released from the coast's level to 0 at a
    /// bounded rate ([`ID_RELEASE_EMF`]), A.
    id_j: T,
    /// Its rate, A/s.
    id_j_rate: T,
    result: Option<Identification<T>>,
}

/// The spin's control frame (the I-f angle and speed), its synchronous current PI and the
/// back-EMF PLL.
#[derive(Clone, Debug)]
struct SpinLoop<T> {
    theta_f: T,
    omega_f: T,
    pi_int: Dq<T>,
    kp: Dq<T>,
    ki: T,
    pll_theta: T,
    pll_omega: T,
    pll_on: bool,
    /// Back-EMF in the PLL frame, low-passed (the phase detector's input), V.
    e_filt: Dq<T>,
    pll_kp: T,
    pll_ki: T,
}

/// The inertia test's step up, as measured: it sizes the step down and names a rotor too
/// light for the test.
#[derive(Clone, Copy, Debug, Default)]
struct StepRecord<T> {
    /// Duration of the step up, s (sizes the step down: `rescale_step_down`).
    t_up: T,
    /// The PLL's speed at the step up's start, then the speed it gained, electrical rad/s.
    w_up: T,
    /// Time of the torque steps beyond their [`J_SKIP`], s: the regression's torque data.
    j_step_data: T,
}

/// The DC test's block statistics: the α voltage and current at each level, their β
/// components (the sensors' gain ratio) and the DC-link voltage.
#[derive(Clone, Debug)]
struct DcStats<T> {
    v_lvl: [BlockStats<T>; 2],
    i_lvl: [BlockStats<T>; 2],
    v_lvl_beta: [BlockStats<T>; 2],
    i_lvl_beta: [BlockStats<T>; 2],
    vdc_stats: BlockStats<T>,
}

const SQRT3_INV: f64 = 0.577_350_269_189_625_8;
/// Half period of the injected square wave, in samples.
const INJ_HALF: u32 = 4;
/// Block length of the mean statistics, s.
const BLOCK_TIME: f64 = 0.01;
/// d current of the back-EMF measurement, as a fraction of the limit (module docs).
const COAST_ID: f64 = 0.5;
/// The PLL's lag under an electrical acceleration α is α/k_i (its integral gain k_i = ωn²),
/// which turns ε·|i_d| of the coast's d current onto the q axis: a torque against the
/// acceleration, as if the rotor's inertia were J − 1.5·p²·ψa·|i_d|/k_i
/// (`pll_lag_inertia`). On the Estun EMJ-04 servo's bare rotor at `COAST_ID` that is
/// 2.0e-5 of its 3.1e-5 kg·m²; with 1.5e-5 the coast collapsed (500 → 72 r/min in 30 ms,
/// `Overspeed { Coast }`). The coast's d current is held where the nameplate inertia is at
/// least this many times the PLL's (every preset: 4.5 … 240 at `COAST_ID`).
const J_PLL_MARGIN: f64 = 3.0;
/// The least coast d current, as a fraction of the limit: twice the compensation's band
/// (5 % of the limit), so that the phase currents stay out of the dead-time band most of
/// the time.
const COAST_ID_MIN: f64 = 0.1;
/// Speeds between which the inertia test's torque steps run, relative to the spin speed.
const J_HIGH: f64 = 2.0;
/// See [`J_HIGH`].
const J_LOW: f64 = 0.5;
/// Nominal duration of each torque step on the nameplate inertia, s.
const J_STEP_TIME: f64 = 0.5;
/// Low-pass time constant of the back-EMF before the PLL's phase detector, s: its pole
/// (1000 rad/s) four times the PLL's natural frequency (2π·40 Hz), so that it adds little
/// phase lag at the loop's crossover while averaging ten samples of the L̂q·Δi/Ts noise
/// (module docs, step 6).
const PLL_EMF_FILTER: f64 = 0.001;
/// Hold of each DC level after its voltage is frozen, before it is averaged, in time
/// constants of the rotor's swing about the d current in voltage mode
/// (the drive's `swing_time_constant`, its gain calibration's sizing, on the nameplate). The
/// sensors' gain ratio k is read through phase b, i.e. through the β axis, across which the
/// swing's back-EMF lies (R̂s along α does not see it). Without the hold (averaged from
/// `settle_time`, 0.25 s) the swing of the hoverboard hub (15 pole pairs, τ = 0.22 s, still
/// ±1 r/min in the window) biased k by −5.0e-3, the 5 kW PM-SyRM's (τ = 0.25 s) by −3.6e-2,
/// the 50 kW IPMSM's (τ = 0.17 s) by +1.1e-2, against a 5e-3 mismatch. Six time constants
/// (e⁻⁶) were enough with the true parameters (every preset within 7e-4) but not with a rough
/// nameplate: an over-damped swing's slow time constant goes as λf/(Rs·I), which the
/// 1.25×-off nameplate of the tests (Rs × 1.25, λf / 1.25) makes 1.56× too short; k came out
/// 2.9e-3 off on the 2.2 kW IPMSM. Ten cover that (measured: within 1.2e-3).
const DC_HOLD_SWING_TIME_CONSTANTS: f64 = 10.0;
/// Longest hold of a DC level, s (less if the phase time-out leaves less room after the
/// settling and two windows). A swing needing longer is held that long and k is not measured
/// (phase a left uncorrected, as the drive's calibration skips such a machine: `TooSlow`).
/// The presets' holds: 0.3 s (outrunner-cheetah-24v) to 2.5 s (pmsyrm-5k).
const DC_MAX_HOLD: f64 = 3.0;
/// Window of the inertia regression, s.
const J_WINDOW: f64 = 0.04;
/// Time after each change of the inertia test's torque before its windows are collected
/// and before the speed may end the step, s: the current's step and the PLL's speed
/// transient. On the gimbal motor (`gbm5208-200t-4s`: 13 r/min at the step, 0.25 A) the
/// PLL's speed reads 41 r/min for 4 ms after the step, twice the spin speed: taken as the
/// step's end, both back-EMF windows sat at one speed (`Implausible { FluxLinkage }`).
const J_SKIP: f64 = 0.03;
/// Shortest duration the inertia test's torque steps are sized for on the nameplate
/// inertia, s: [`J_SKIP`] and five windows. Where 10 % of the limit would end a step sooner
/// (a light rotor) the step's current floor is lowered to what lasts this long, down to
/// [`J_STEP_RESOLUTION`] current resolutions.
const J_STEP_MIN_TIME: f64 = 0.25;
/// The smallest torque step's q current, in current resolutions (the readings' rms about
/// their offsets at gates off).
const J_STEP_RESOLUTION: f64 = 8.0;
/// Windows the torque steps must give beyond [`J_SKIP`] together: two consecutive windows
/// make one point of the regression's torque data; a rotor whose steps end sooner at the
/// smallest step is too light for the test ([`AbortReason::RotorTooLight`]).
const J_MIN_STEP_WINDOWS: f64 = 2.0;
/// Bound on the active-flux EMF's d component (L̂d − L̂q)·di_d/dt while the coast's d
/// current is released at the start of the inertia test, relative to the EMF ω̂·λ̂f: the
/// PLL's phase detector reads that component as an angle error of about this many rad.
/// A step there (0.75 λ̂f of flux change on the 50 kW IPMSM preset, (Lq − Ld)·60 A) threw
/// the PLL 0.5 rad off within 5 ms (measured: `Overspeed` in `Inertia`).
const ID_RELEASE_EMF: f64 = 0.2;
