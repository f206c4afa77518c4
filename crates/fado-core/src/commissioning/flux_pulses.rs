//! The standstill flux-linkage pulses ([`Phase::Magnetics`], module docs step 5): bipolar
//! voltage pulses in six directions of the d-q plane, the flux linkage integrated from zero
//! current, the samples stored for the fit at the end.

use super::magnetic_fit::{
    FluxSamples, RESIDUAL_BANDS, SAMPLE_CAPACITY, best_fit, flux_residual_bands, inductance_change,
};
use super::*;
use crate::magnetics::{MagneticModel, Saturation};
use crate::{Ab, Real};

/// Bipolar pairs of pulses (directions k·π/6 of the voltage, each followed at once by its
/// opposite), in the order that cancels the reluctance torque's impulse of a pair (∝ sin 2φ)
/// with the next one: 0°, 90°, then 30° with 150°, 60° with 120°.
///
/// Every pair starts with its positive pulse, so the magnet torque turns the rotor forward
/// over both the 60° and the 120° pair and their turns add up over the pulses. Starting the
/// 120° pair with its negative pulse instead halves that total (the 6SM107S servo of
/// `crates/fado-sim/tests/data/unseen/servo-6sm107s-3000.toml`: 0.163 → 0.088 rad by the plant;
/// the paper's motor 0.047 → 0.025) but does not unbias the fit, which follows the turn
/// within each pair (`pulse_pair_end`), not the total: its spurious inductance change rises
/// (servo 7.3 → 10.3 %, the paper's motor 0.7 → 1.9 %, the 5 kW PM-SyRM 11.4 → 18.1 % with
/// 0.013 → 0.071 rad within a pair, as the reluctance torque's cancellation between pairs is
/// lost; ipmsm-2k2-qsat's largest L̂q error 0.71 → 1.08 %), so the order stays.
const PAIR_ANGLES_DEG: [f64; 3] = [0.0, 60.0, 120.0];

/// Samples per rise of a pulse on the identified inductance, at most (the pulse voltage is
/// lowered to L̂·I_p/(N·Ts) where the limit would reach I_p sooner); fewer on a light rotor
/// (`pulse_plan`).
const RISE_SAMPLES: f64 = 16.0;

/// The pulse voltage is at least this many times R̂s·I_p: nearer the resistive drop the rise
/// slows and stalls short of I_p (the 750 W servo SPM, τ = L/R = 14 samples, reached 5 of its
/// 6 A on 16-sample rises), and the flux integral becomes a small difference of the command
/// and R̂s·i.
const RESISTIVE_MARGIN: f64 = 3.0;

/// Fewest samples per rise: a light rotor's pulses are shortened to no fewer (the stopping
/// rule predicts the next sample's current, so the overshoot stays about 1/N of the peak).
const MIN_RISE_SAMPLES: f64 = 4.0;

/// The rotor's turn over one pair that `pulse_plan` sizes the rise for, rad (electrical): the
/// presets' heavy rotors turn 0.012–0.10 rad with 16-sample rises and are identified within
/// 1 % (docs/results/commissioning-magnetics.md).
const MOTION_TARGET: f64 = 0.05;

/// The back-EMF at a pair's peak speed over the pulse voltage that [`pulse_plan`] allows
/// full-length rises: 0.2. A pair of rises of N samples peaks at the speed
/// p·T_p·N·Ts/J (electrical), whose back-EMF against the pulse voltage L̂·I_p/(N·Ts) is
/// turn·λf/(2·L̂·I_p) with the pair's turn 2·p·T_p·(N·Ts)²/J: a rotor with a strong magnet for
/// its inductance (λf/(L̂·I_p) 7 on the 7.2 kW 6SM107S servo) reaches it long before the turn
/// reaches [`MOTION_TARGET`] × 4. Above it the next pulses start on a turning rotor whose
/// back-EMF adds to the pulse voltage: full-length rises (0.41) swing the servo with
/// J = 3e-3 kg·m² between ±300 r/min and trip at 41 A (OverCurrent in `Magnetics`). The
/// presets of `motors/` reach at most 0.064 (pmsm-gem-1k1-measured) and keep full-length
/// rises; where it is above, the rise is the length that keeps it at the limit, repeated as
/// a light rotor's.
const EMF_LIMIT: f64 = 0.2;

/// Rises are shortened only where [`pulse_plan`]'s length is below this fraction of
/// [`RISE_SAMPLES`], i.e. where full-length pulses would turn the rotor by more than 4 ×
/// [`MOTION_TARGET`] (0.2 rad) by its estimate, which overstates the presets' measured turn
/// (the 5 kW PM-SyRM: 0.068 estimated, 0.043–0.059 rad measured, with full-length pulses).
const LIGHT_RATIO: f64 = 0.5;

/// The largest rotor turn over one pair of pulses that the pulses accept, rad (electrical),
/// compared with the drive's own estimate of that turn (the flux across the magnet at the
/// pair's end, `pulse_pair_end`), never with a total over the pulses. Per pair because the
/// procedure tracks the total: each pair starts in the frame of the angle θ̂0 its
/// predecessors' turns moved, so a turn accumulated over the pairs leaves the samples in
/// the rotor frame; what mixes the turning magnet's back-EMF into the fit is the turn within
/// a pair, which the samples' angle follows only as the shape of the torque's double
/// integral scaled by the pair's end. Measured on the 7.2 kW 6SM107S servo of
/// `crates/fado-sim/tests/data/unseen/servo-6sm107s-3000.toml` (constant inductances): its
/// rotor turns 0.163 rad from the pulses' start by the plant, 0.088 rad over the 60° pair and
/// 0.074 over the 120° one (both forward: their first pulses' magnet torque has one sign),
/// and this estimate reads 0.087 rad for the largest pair. The turn does bias the fit: its
/// inductances change 7.3 %, above the 5 % detection threshold, against 1.6 % on a rotor of
/// 1 kg·m² that turns 0.002 rad; but the saturation terms do not explain the flux (residual
/// 0.80 of the constant inductances', 0.93 held, detection needs below 0.5), so the verdict
/// stays `not_detected`, as on the held rotor. The presets' turns, estimated and the plant's:
/// docs/results/commissioning-magnetics.md. Beyond the limit
/// the pulses start again with rises half as long (down to 4 samples), and a rotor that
/// still turns that far leaves the saturation unidentified ([`MagneticFit::motion`]): the
/// 750 W servo SPM of `crates/fado-sim/tests/data/spm-dq-sat-saturated.toml` with its rotor
/// of 2e-4 kg·m² turned 0.76 rad with 16-sample rises, and the fit read no saturation at
/// all.
pub const PULSE_MOTION_LIMIT: f64 = 0.15;

/// Saturation is reported only where the fitted model's RMS current residual is below this
/// fraction of the constant-inductance model's: the saturation terms must explain the data,
/// not the integration's own errors (the linear presets' fits reach 0.68–0.96 of it, the
/// saturated ones 0.03, docs/results/commissioning-magnetics.md).
const RESIDUAL_RATIO: f64 = 0.5;

/// Largest relative difference between a fitted model's incremental inductances at the
/// inductance tests' operating point and those tests' L̂d, L̂q for the model to be used
/// (`agrees_with_injection`): well above the saturated presets' fits (a few %), well below
/// a meaningless one's.
const INJECTION_AGREEMENT: f64 = 0.2;

/// Smallest fraction of a fitted model's zero-current incremental L_dd, L_qq (and of their
/// product, for the determinant) that its incremental inductance matrix keeps over the
/// pulses' range (`stays_invertible`). Saturated iron leaves the air-gap and leakage
/// inductance, a sizeable part of the unsaturated one, so the incremental inductance of a
/// physical machine never falls near zero. A fitted law i(ψ) that folds back outside the
/// measured fluxes gives several fluxes for one current: the flux solve lands on the far
/// branch at some currents, where the incremental inductance is about zero. Over the rated
/// range the saturated presets' fits keep ≥ 0.18 of L_qq(0) and ≥ 0.11 of the product; the
/// folding rib fits of the measured 1.1 kW PMSM map reach 0.00 (−0.01 on a finer grid).
const INCREMENTAL_FLOOR: f64 = 0.1;

/// Points per side of the square grid over |i| ≤ the pulse current on which
/// `stays_invertible` evaluates a model (the 1 300 points inside the disc: a step of 1/20
/// of the pulse current, where the measured map's folding fits show their far branch; a
/// 17-point grid misses one of them).
const FLOOR_GRID: usize = 41;

/// The rise length in samples and the repeats of each pair, from the nameplate (module docs,
/// step 5). A pair of rises of N samples with the current's peak I_p across the magnet
/// turns the rotor by about 2·p·T_p·(N·Ts)²/J (electrical; T_p = 1.5·p·(λf + |Lq − Ld|·I_p)·I_p
/// the torque's peak, half of it on average over each pulse's 2N samples, the speed's
/// triangle over the pair's 4N): where full-length rises would turn it by more than 4 ×
/// [`MOTION_TARGET`] ([`LIGHT_RATIO`]), N is the largest that keeps this at
/// [`MOTION_TARGET`], at least [`MIN_RISE_SAMPLES`]. A pair shortened so is repeated, its
/// pulses' order alternating (+−, −+, …, an even number of times), for about the samples of
/// one full-length pair: each repeat turns the rotor back by what the one before turned it.
pub(super) fn pulse_plan<T: Real>(cfg: &CommissioningConfig<T>, i_p: T) -> (T, usize) {
    let np = &cfg.nameplate;
    let p = T::lit(np.pole_pairs as f64);
    let torque = T::lit(1.5) * p * (np.flux_linkage + (np.lq - np.ld).abs() * i_p) * i_p;
    let rise_for =
        |turn: T| (turn * np.inertia / (T::lit(2.0) * p * torque)).sqrt() / cfg.sample_period;
    // The back-EMF at the pair's peak speed over the pulse voltage L̂·I_p/(N·Ts) is
    // turn·λf/(2·L̂·I_p): the turn that keeps it at EMF_LIMIT.
    let emf_turn = T::lit(2.0 * EMF_LIMIT) * np.ld.min(np.lq) * i_p / np.flux_linkage;
    rise_repeats(rise_for(T::lit(MOTION_TARGET)), rise_for(emf_turn))
}

/// Whether the pulses adapt to the machine (the `adapted` pulses of `FluxPulses`): where a
/// light rotor shortens the rises (`rise` below [`RISE_SAMPLES`]), or where the shortest
/// full-length rise's voltage, L̂·I_p/(16·Ts) with the smaller of L̂d, L̂q, lies below
/// [`RESISTIVE_MARGIN`]·R̂s·I_p (an electrical time constant L/R below 48 samples). Every
/// preset of `motors/` keeps the full-length pulses, whose accuracy
/// docs/results/commissioning-magnetics.md publishes.
pub(super) fn adapted_pulses<T: Real>(rise: T, l_min: T, rs: T, ts: T) -> bool {
    rise < T::lit(RISE_SAMPLES)
        || l_min / (T::lit(RISE_SAMPLES) * ts) < T::lit(RESISTIVE_MARGIN) * rs
}

/// [`pulse_plan`]'s rise length (clamped) and repeats for `n` samples per rise by the turn
/// and `n_emf` by the back-EMF ([`EMF_LIMIT`]).
fn rise_repeats<T: Real>(n: T, n_emf: T) -> (T, usize) {
    let full = T::lit(RISE_SAMPLES);
    let turn_ok = !n.is_finite() || n >= T::lit(LIGHT_RATIO) * full;
    let emf_ok = !n_emf.is_finite() || n_emf >= full;
    if turn_ok && emf_ok {
        return (full, 1);
    }
    let n = match (turn_ok, emf_ok) {
        (true, _) => n_emf,
        (false, true) => n,
        (false, false) => n.min(n_emf),
    };
    let n = n.min(full).max(T::lit(MIN_RISE_SAMPLES));
    let halves = (full / n * T::lit(0.5) - T::lit(1e-9)).index_floor(8) + 1;
    (n, 2 * halves)
}

/// Gates-off rest between pairs, in samples: the diodes take the current to zero (in
/// microseconds), so that the next pair starts from ψ = (λf, 0).
const REST_SAMPLES: u32 = 8;

/// Zero-voltage samples (gates on) after a pair's last command, which the gates-off would
/// otherwise cut short (the gates act at once, a command one sample later).
const DRAIN_SAMPLES: u32 = 2;

/// The algebraic model fitted to the flux-linkage pulses
/// ([`Commissioning::magnetic_model`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MagneticFit<T> {
    /// The best-fitting model.
    pub model: Saturation<T>,
    /// The largest relative change of its incremental inductances over the pulses' range.
    pub change: T,
    /// Its RMS current residual over the samples, A.
    pub residual: T,
    /// The constant-inductance model's RMS residual, A.
    pub linear_residual: T,
    /// The model's RMS flux residual over the samples in each of [`RESIDUAL_BANDS`]
    /// equal bands of the current magnitude up to the pulses' peak current, Wb.
    pub flux_residuals: [T; RESIDUAL_BANDS],
    /// The largest rotor turn over one pair of pulses, estimated from the flux at its end,
    /// rad (electrical): the figure compared with [`PULSE_MOTION_LIMIT`].
    pub motion: T,
    /// Saturation detected: `change` above the threshold, `residual` below half of
    /// `linear_residual` and `motion` within [`PULSE_MOTION_LIMIT`].
    pub detected: bool,
}

impl<T: Real> MagneticFit<T> {
    /// Whether the rotor turned too far during the pulses for them to tell saturation
    /// (`motion` above [`PULSE_MOTION_LIMIT`]): the model then keeps constant inductances
    /// without a statement on the machine's saturation.
    pub fn rotor_moved(&self) -> bool {
        !self.motion.is_finite() || self.motion > T::lit(PULSE_MOTION_LIMIT)
    }

    /// What the pulses say about the machine's saturation.
    pub fn verdict(&self) -> SaturationVerdict {
        verdict(self.detected, self.change, self.motion)
    }
}

/// What the standstill flux-linkage pulses say about a machine's magnetic saturation
/// ([`MagneticFit::verdict`], [`super::Identification::saturation_verdict`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SaturationVerdict {
    /// Saturation detected: the fitted model is used.
    Detected,
    /// The best fit's inductances stay within the detection threshold, or change by less
    /// than [`INCONCLUSIVE_CHANGE`] without explaining the data: a magnetically linear
    /// machine.
    NotDetected,
    /// The best fit's inductances change by more than [`INCONCLUSIVE_CHANGE`] but the fit
    /// does not explain the flux linkage (its residual not below half the constant
    /// inductances'): neither saturation nor its absence is shown; constant inductances
    /// are kept.
    Inconclusive,
    /// The rotor turned beyond [`PULSE_MOTION_LIMIT`] during the pulses: not identified.
    RotorMoved,
    /// The pulses did not run (the test off, or an abort before their end).
    NotMeasured,
}

/// A fit whose inductances change by more than this fraction over the pulses' range is no
/// linear machine's, whether or not it explains the data: the linear presets' fits move by
/// 0.5–12 % (the integration's own errors, docs/results/commissioning-magnetics.md), the
/// saturated ones' by 50–80 %.
pub const INCONCLUSIVE_CHANGE: f64 = 0.25;

/// [`SaturationVerdict`] from the detection, the fit's change and the rotor's motion.
pub(super) fn verdict<T: Real>(detected: bool, change: T, motion: T) -> SaturationVerdict {
    if !change.is_finite() {
        SaturationVerdict::NotMeasured
    } else if !motion.is_finite() || motion > T::lit(PULSE_MOTION_LIMIT) {
        SaturationVerdict::RotorMoved
    } else if detected {
        SaturationVerdict::Detected
    } else if change > T::lit(INCONCLUSIVE_CHANGE) {
        SaturationVerdict::Inconclusive
    } else {
        SaturationVerdict::NotDetected
    }
}

/// Where the pulses stand.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Stage {
    /// Gates off, the current at zero.
    Rest,
    /// The first pulse of a pair rising, then returning to zero (its last sample landing the
    /// current on zero at a sample boundary); the second likewise.
    Rise1,
    Return1,
    Rise2,
    Return2,
    /// Zero voltage before the rest.
    Drain,
    /// The pulses done: the d current brought back to the DC test's I₁ (frozen voltage)
    /// before the spin, which starts from it.
    Hold,
}

/// The pulses' state.
#[derive(Clone, Copy, Debug)]
pub(super) struct FluxPulses<T> {
    pub(super) samples: FluxSamples<T>,
    pub(super) stage: Stage,
    pair: usize,
    /// Samples per rise and the repeats of each pair ([`pulse_plan`]).
    rise: T,
    repeats: usize,
    /// +1 for a pair's +− order, −1 for its −+ repeat.
    order: T,
    /// The largest rotor turn over a pair so far (its estimate), rad.
    pub(super) motion: T,
    count: u32,
    n_max: u32,
    /// The current at the last rise's peak (its direction: the pulse's).
    i_peak: Ab<T>,
    /// The current's change over the last sample, A.
    last_step: Ab<T>,
    /// Pulses adapted to the machine ([`adapted_pulses`]): rises stopped on the predicted
    /// current, returns landed on zero, the inverter error compensated, the voltage at least
    /// [`RESISTIVE_MARGIN`]·R̂s·I_p. Otherwise returns as long as the rises.
    adapted: bool,
    /// Samples of the last rise.
    n_up: u32,
    dir: Ab<T>,
    v_pulse: T,
    /// The flux-linkage change since the pair's start, V·s (α-β = d-q at standstill).
    psi: Ab<T>,
    integrating: bool,
    decimation: u32,
    k: u32,
    /// The rotor's angle at the pair's start, estimated from the pairs before, rad.
    theta0: T,
    /// The first sample of the pair in `samples`.
    pair_start: usize,
    /// ∫τ and ∫∫τ over the pair, τ = ψ × i the torque's shape (its scale 1.5·p/J unknown).
    w: T,
    d: T,
    /// The sum of the current over the q injection before the pulses.
    pub(super) held_current: Ab<T>,
}

impl<T: Real> FluxPulses<T> {
    pub(super) fn new() -> Self {
        Self {
            samples: FluxSamples::new(),
            stage: Stage::Rest,
            pair: 0,
            rise: T::lit(RISE_SAMPLES),
            repeats: 1,
            order: T::one(),
            motion: T::zero(),
            count: 0,
            n_max: 0,
            i_peak: Ab::zero(),
            last_step: Ab::zero(),
            adapted: false,
            n_up: 0,
            dir: Ab::zero(),
            v_pulse: T::zero(),
            psi: Ab::zero(),
            integrating: false,
            decimation: 1,
            k: 0,
            theta0: T::zero(),
            pair_start: 0,
            w: T::zero(),
            d: T::zero(),
            held_current: Ab::zero(),
        }
    }
}

/// The nominal duration of [`Phase::Magnetics`] (for the progress), s: the pairs and their
/// repeats ([`pulse_plan`]) of four edges, each the longer of the planned rise and the
/// nameplate's L̂q·I_p/V at the voltage limit, the rests, and the hold.
pub(super) fn magnetics_time<T: Real>(cfg: &CommissioningConfig<T>) -> T {
    let m = &cfg.magnetics;
    if !m.enabled {
        return T::zero();
    }
    let np = &cfg.nameplate;
    let ts = cfg.sample_period;
    let v_max = m.voltage_ratio * np.dc_voltage * T::lit(SQRT3_INV);
    let i_p = m.current_ratio * np.rated_current;
    let (n, repeats) = pulse_plan(cfg, i_p);
    let rise = (np.ld.max(np.lq) * i_p / v_max).max(n * ts);
    let rest = T::from_index((REST_SAMPLES + DRAIN_SAMPLES) as usize) * ts;
    T::from_index(PAIR_ANGLES_DEG.len() * repeats) * (T::lit(4.0) * rise + rest) + cfg.settle_time
}

impl<T: Real> Commissioning<T> {
    /// The flux-linkage pulses' peak current, A (`magnetics.current_ratio` × the rated
    /// current).
    pub fn pulse_current(&self) -> T {
        self.cfg.magnetics.current_ratio * self.cfg.nameplate.rated_current
    }

    /// Starts [`Phase::Magnetics`] (or the spin, with the test off), from the inductance
    /// tests' I₁ along d.
    pub(super) fn start_magnetics(&mut self) {
        if !self.cfg.magnetics.enabled {
            self.start_spin();
            return;
        }
        // The rotor's angle: along the current it was held by in the inductance tests (the
        // torque 1.5·p·(λf + (Ld − Lq)·i_d)·i_q vanishes at i_q = 0 in its frame). The frozen
        // voltage of the DC test leaves that current up to 0.1 rad off the α axis (its β part:
        // the phases' inverter errors); taken as 0, the pulses' flux and current would be
        // turned by that angle against the rotor's frame.
        let held = self.pulses.held_current;
        let theta = if held.norm() > T::zero() {
            held.beta.atan2(held.alpha)
        } else {
            T::zero()
        };
        self.pulses = FluxPulses::new();
        self.pulses.theta0 = theta;
        let (rise, repeats) = pulse_plan(&self.cfg, self.pulse_current());
        self.pulses.adapted = adapted_pulses(rise, self.ld.min(self.lq), self.rs, self.ts);
        self.plan_pulses(rise, repeats);
        self.i_ref = Ab::zero();
        self.next_phase(Phase::Magnetics);
    }

    /// The pulses from their first pair on with `rise` samples per rise and `repeats` of each
    /// pair, their samples cleared.
    fn plan_pulses(&mut self, rise: T, repeats: usize) {
        let p = &mut self.pulses;
        p.samples = FluxSamples::new();
        p.pair = 0;
        p.pair_start = 0;
        p.motion = T::zero();
        p.rise = rise;
        p.repeats = repeats;
        // Store about 3/4 of the capacity: the pairs' 4 edges of about `rise` samples each
        // (fewer where the voltage limit makes the edges longer: the rest is not stored).
        let edges = (PAIR_ANGLES_DEG.len() * repeats * 4) as f64;
        let expected = edges * rise.to_f64();
        p.decimation = libm_round(expected / (0.75 * SAMPLE_CAPACITY as f64));
    }

    /// One sample of [`Phase::Magnetics`]: (command, applied voltage, gates on).
    pub(super) fn magnetics(&mut self, i: Ab<T>, vdc: T) -> (Ab<T>, Ab<T>, bool) {
        self.pulse_integrate(i);
        self.pulses.count += 1;
        match self.pulses.stage {
            Stage::Rest => return self.pulse_rest(i, vdc),
            Stage::Hold => return self.pulse_hold(i, vdc),
            _ => {}
        }
        let i_p = self.pulse_current();
        let (step, next) = self.pulse_prediction(i);
        let p = &mut self.pulses;
        let reached = if p.adapted { next } else { i }.norm() >= i_p;
        let v = p.v_pulse * p.order;
        // A return lands when the next sample's current along the pulse is within one step of
        // zero.
        let along = (next.alpha * p.i_peak.alpha + next.beta * p.i_peak.beta) / p.i_peak.norm();
        let landing = if p.adapted {
            !along.is_finite() || along <= step.norm() || p.count > p.n_max
        } else {
            p.count > p.n_up
        };
        // `count` is the number of commands of the stage issued so far, plus one.
        let cmd = match p.stage {
            Stage::Rise1 | Stage::Rise2 if reached || p.count > p.n_max => {
                p.i_peak = next;
                p.n_up = p.count - 1;
                p.count = 1;
                if p.stage == Stage::Rise1 {
                    p.stage = Stage::Return1;
                    -v
                } else {
                    p.stage = Stage::Return2;
                    v
                }
            }
            Stage::Rise1 => v,
            Stage::Rise2 => -v,
            Stage::Return1 | Stage::Return2 if landing => {
                let first = p.stage == Stage::Return1;
                p.stage = if first { Stage::Rise2 } else { Stage::Drain };
                if p.adapted {
                    p.count = 0;
                    let out = self.pulse_landing(next);
                    return (out, out, true);
                }
                p.count = 1;
                if first { -v } else { T::zero() }
            }
            Stage::Return1 => -v,
            Stage::Return2 => v,
            Stage::Drain if p.count > DRAIN_SAMPLES => {
                let restarted = self.pulse_pair_end(i);
                let p = &mut self.pulses;
                p.stage = Stage::Rest;
                p.count = 0;
                p.integrating = false;
                if !restarted {
                    p.pair += 1;
                }
                return (Ab::zero(), Ab::zero(), false);
            }
            // Zero volts, uncompensated: the current is (about) zero.
            Stage::Drain | Stage::Rest | Stage::Hold => return (Ab::zero(), Ab::zero(), true),
        };
        // The identified inverter error compensated on the current one and a half samples on
        // (the middle of the sample the command acts over): without it a low-inductance
        // machine's pulse voltage L̂·I_p/(N·Ts) can lie below the error (the 750 W servo SPM:
        // 5.5 V against 4/3·V̂ = 6.7 V, its d pulse stalled at 0.2 A).
        let ahead = i + step * T::lit(1.5);
        let out = if p.adapted {
            p.dir * cmd + dead_time_voltage(ahead, self.inverter_band(), self.v_inv)
        } else {
            p.dir * cmd
        };
        (out, out, true)
    }

    /// The current's last step and its value one sample on, at the end of the command already
    /// issued (a command acts a sample late): a rise stopped when the measured current reaches
    /// I_p overshoots by two steps, one when the next does. On a return, from its third
    /// measured step on, to second order: the steps shrink as the resistive drop falls with
    /// the current (on the 750 W servo SPM the linear prediction left 0.18 A where the landing
    /// was to leave none).
    fn pulse_prediction(&mut self, i: Ab<T>) -> (Ab<T>, Ab<T>) {
        let step = i - self.i_prev;
        let p = &mut self.pulses;
        let returning = matches!(p.stage, Stage::Return1 | Stage::Return2) && p.count >= 4;
        let curve = if returning {
            step - p.last_step
        } else {
            Ab::zero()
        };
        p.last_step = step;
        (step, i + step + curve)
    }

    /// The command that takes the current from `next` (the next sample's) to zero over the
    /// sample it acts on: L̂·Δi/Ts on the inductance tests' L̂d, L̂q in the rotor frame, plus
    /// R̂s and the identified inverter error at the sample's mean current. A return that
    /// crossed zero inside a sample would put the inverter error's sign change there, where
    /// its model on the samples' mean current is wrong by up to 4/3·V̂·Ts (7 % of the flux
    /// L·I_p on the 750 W servo SPM); landed on a sample boundary, every sample's current
    /// keeps one sign.
    fn pulse_landing(&self, next: Ab<T>) -> Ab<T> {
        let (c, s) = (self.pulses.theta0.cos(), self.pulses.theta0.sin());
        let d = (c * next.alpha + s * next.beta) * self.ld;
        let q = (c * next.beta - s * next.alpha) * self.lq;
        let flux = Ab::new(c * d - s * q, s * d + c * q);
        let mean = next * T::lit(0.5);
        flux * (-T::one() / self.ts)
            + mean * self.rs
            + dead_time_voltage(mean, self.inverter_band(), self.v_inv)
    }

    /// The flux-linkage integral over the last sample, v − R̂s·i less the identified inverter
    /// error (the DC test's V̂ on the trapezoid of the phase currents), and the stored sample.
    fn pulse_integrate(&mut self, i: Ab<T>) {
        if !(self.pulses.integrating && self.have_prev) {
            return;
        }
        let i_mid = (i + self.i_prev) * T::lit(0.5);
        let err = dead_time_voltage(i_mid, self.inverter_band(), self.v_inv);
        let (c, s) = (self.pulses.theta0.cos(), self.pulses.theta0.sin());
        let flux = self.cfg.nameplate.flux_linkage;
        let p = &mut self.pulses;
        p.psi += (self.c2 - err - i_mid * self.rs) * self.ts;
        let psi = Ab::new(flux * c, flux * s) + p.psi;
        p.w += (psi.alpha * i.beta - psi.beta * i.alpha) * self.ts;
        p.d += p.w * self.ts;
        p.k += 1;
        if p.k >= p.decimation {
            p.k = 0;
            p.samples.push(
                Dq::new(p.psi.alpha, p.psi.beta),
                Dq::new(i.alpha, i.beta),
                p.d,
            );
        }
    }

    /// The rotor's motion over the pair from its flux linkage, and the pair's samples turned
    /// into the rotor frame (module docs, step 5). At the pair's end the current is (nearly)
    /// zero again, so ψ is the magnet's λf·e^{j(θ0 + δ)}: the flux change's component across
    /// the magnet, less L̂·i of the residual current, is λf·δ. Within the pair the angle
    /// follows the double integral of the torque, whose shape ψ × i is measured and whose
    /// scale (1.5·p/J) the end's δ gives: δ(t) = δ·D(t)/D(end). The magnet's flux enters as
    /// the nameplate's, to first order without effect: δ ∝ 1/λf and its correction ∝ λf·δ.
    /// True when the motion monitor started the pulses again ([`PULSE_MOTION_LIMIT`]).
    fn pulse_pair_end(&mut self, i: Ab<T>) -> bool {
        let flux = self.cfg.nameplate.flux_linkage;
        let lq = self.lq;
        let p = &mut self.pulses;
        let theta0 = p.theta0;
        let to_dq = |x: Ab<T>, a: T| {
            let (c, s) = (a.cos(), a.sin());
            Dq::new(c * x.alpha + s * x.beta, c * x.beta - s * x.alpha)
        };
        let (psi_end, i_end) = (to_dq(p.psi, theta0), to_dq(i, theta0));
        let delta = (psi_end.q - lq * i_end.q) / flux;
        let d_end = p.d;
        let magnet = Ab::new(flux * theta0.cos(), flux * theta0.sin());
        let delta = if delta.is_finite() { delta } else { T::zero() };
        p.samples.map_from(p.pair_start, |dpsi, i, d| {
            let share = if d_end != T::zero() {
                d / d_end
            } else {
                T::zero()
            };
            let angle = theta0 + delta * share.max(T::zero()).min(T::lit(2.0));
            let psi = to_dq(magnet + Ab::new(dpsi.d, dpsi.q), angle);
            (
                Dq::new(psi.d - flux, psi.q),
                to_dq(Ab::new(i.d, i.q), angle),
            )
        });
        p.theta0 += delta;
        p.pair_start = p.samples.len();
        p.w = T::zero();
        p.d = T::zero();
        p.motion = p.motion.max(delta.abs());
        // The motion monitor: a rotor that turned beyond the limit over this pair starts the
        // pulses again with rises half as long (a light rotor the nameplate's inertia did not
        // foresee); at the shortest rises the pulses run on and the fit reports the motion.
        let min = T::lit(MIN_RISE_SAMPLES);
        if delta.abs() > T::lit(PULSE_MOTION_LIMIT) && p.rise > min {
            // Both bounds at the halved length: the turn's alone would take a half of a
            // full-length rise (8 samples, [`LIGHT_RATIO`]) for full length again.
            let halved = (p.rise * T::lit(0.5)).max(min);
            let (rise, repeats) = rise_repeats(halved, halved);
            self.plan_pulses(rise, repeats);
            return true;
        }
        false
    }

    /// Gates off until the current is zero, then the next pair (or the hold after the last).
    fn pulse_rest(&mut self, i: Ab<T>, vdc: T) -> (Ab<T>, Ab<T>, bool) {
        let i_p = self.pulse_current();
        if self.pulses.count < REST_SAMPLES || i.norm() > T::lit(0.02) * i_p {
            return (Ab::zero(), Ab::zero(), false);
        }
        let repeats = self.pulses.repeats;
        if self.pulses.pair >= PAIR_ANGLES_DEG.len() * repeats {
            self.pulses.stage = Stage::Hold;
            self.pulses.count = 0;
            let i1 = T::lit(0.5) * dc_level(&self.cfg.nameplate, self.i_limit);
            self.i_ref = Ab::new(i1, T::zero());
            return self.pulse_hold(i, vdc);
        }
        // The voltage's direction that drives the current along the pair's angle γ on the
        // identified inductances: Δψ ∥ (L̂d·cos γ, L̂q·sin γ).
        let gamma = T::lit(PAIR_ANGLES_DEG[self.pulses.pair / repeats].to_radians());
        let flux_dir = Ab::new(self.ld * gamma.cos(), self.lq * gamma.sin());
        let l_eff = flux_dir.norm();
        let (c, s) = (self.pulses.theta0.cos(), self.pulses.theta0.sin());
        let flux_dir = flux_dir * (T::one() / l_eff);
        let dir = Ab::new(
            c * flux_dir.alpha - s * flux_dir.beta,
            s * flux_dir.alpha + c * flux_dir.beta,
        );
        let v_max = self.cfg.magnetics.voltage_ratio * vdc * T::lit(SQRT3_INV);
        let floor = if self.pulses.adapted {
            T::lit(RESISTIVE_MARGIN) * self.rs * i_p
        } else {
            T::zero()
        };
        let v = v_max.min((l_eff * i_p / (self.pulses.rise * self.ts)).max(floor));
        // A rise that has not reached I_p after 4× its nominal length stops there.
        let nominal = l_eff * i_p / (v * self.ts);
        let p = &mut self.pulses;
        p.order = if (p.pair % repeats) % 2 == 1 {
            -T::one()
        } else {
            T::one()
        };
        p.dir = dir;
        p.v_pulse = v;
        p.n_max = (T::lit(4.0) * nominal).index_floor(100_000) as u32 + 8;
        p.psi = Ab::zero();
        p.integrating = true;
        p.stage = Stage::Rise1;
        p.count = 1;
        let out = dir * (v * p.order);
        (out, out, true)
    }

    /// After the pulses: I₁ along d at the inductance tests' frozen voltage, held for the
    /// settling time, then the spin (which starts from that voltage).
    fn pulse_hold(&mut self, i: Ab<T>, vdc: T) -> (Ab<T>, Ab<T>, bool) {
        let v = self.standstill_voltage(i, vdc, true, Ab::zero());
        if T::from_index(self.pulses.count as usize) * self.ts >= self.cfg.settle_time {
            self.start_spin();
        }
        (v, v, true)
    }

    /// The fitted magnetic model with the final λ̂f (module docs, step 5): (the model if
    /// saturation is detected, the detection statistic, the RMS current residuals of the
    /// model and of constant inductances, the rotor's largest turn over a pair).
    pub(super) fn magnetic_result(
        &self,
    ) -> (Option<Saturation<T>>, T, T, T, T, [T; RESIDUAL_BANDS]) {
        let nan = T::zero() / T::zero();
        match self.magnetic_model(self.flux) {
            Some(f) => (
                f.detected.then_some(f.model),
                f.change,
                f.residual,
                f.linear_residual,
                f.motion,
                f.flux_residuals,
            ),
            None => (None, nan, nan, nan, nan, [nan; RESIDUAL_BANDS]),
        }
    }

    /// The algebraic model fitted to the flux-linkage pulses (module docs, step 5) with the
    /// magnet's flux `flux_linkage`, once the pulses are done (None before, with the test off
    /// or with too few samples). The procedure fits it with its final λ̂f
    /// ([`Identification::saturation`]); this gives it also when a later phase aborts (with
    /// the nameplate's λf, say). One call fits about 22 000 shapes (1620 without the rib,
    /// 18 000 with it on the coarse grid, then the refinement): a few tenths of a second on a
    /// host, far longer than a sample on a microcontroller (call it with the gates off).
    pub fn magnetic_model(&self, flux_linkage: T) -> Option<MagneticFit<T>> {
        // The stage stays `Hold` from the last pair's end on (through an abort too).
        if !self.cfg.magnetics.enabled || self.pulses.stage != Stage::Hold {
            return None;
        }
        let consistent =
            |m: &Saturation<T>| self.agrees_with_injection(m) && self.stays_invertible(m);
        let (model, residual, linear_residual) =
            best_fit(&self.pulses.samples, flux_linkage, consistent)?;
        let change = inductance_change(&model, self.pulse_current());
        Some(MagneticFit {
            model,
            change,
            residual,
            linear_residual,
            flux_residuals: flux_residual_bands(
                &self.pulses.samples,
                &model,
                flux_linkage,
                self.pulse_current(),
            ),
            motion: self.pulses.motion,
            detected: change > self.cfg.magnetics.detection_threshold
                && residual < T::lit(RESIDUAL_RATIO) * linear_residual
                && consistent(&model)
                && self.pulses.motion <= T::lit(PULSE_MOTION_LIMIT),
        })
    }

    /// Whether the incremental L_dd, L_qq of `model` at the inductance tests' operating point
    /// (the I₁ bias along d) are within [`INJECTION_AGREEMENT`] of what those tests measured
    /// there: a fit that explains the pulses with terms of no physical meaning and inductances
    /// far from the tests' is refused (one that agrees here but folds elsewhere in the range
    /// is refused by `stays_invertible`).
    fn agrees_with_injection(&self, model: &Saturation<T>) -> bool {
        let i1 = T::lit(0.5) * dc_level(&self.cfg.nameplate, self.i_limit);
        let l = model.incremental_inductance(Dq::new(i1, T::zero()));
        let tol = T::lit(INJECTION_AGREEMENT);
        (l.dd / self.ld - T::one()).abs() < tol && (l.qq / self.lq - T::one()).abs() < tol
    }

    /// Whether the incremental inductance matrix of `model` stays above
    /// [`INCREMENTAL_FLOOR`] of its zero-current diagonal (L_dd, L_qq, and the determinant
    /// above the floor squared times their product) on every point of a [`FLOOR_GRID`]²
    /// grid inside |i| ≤ the pulse current: the range the pulses measured, where a fit
    /// without physical meaning loses its inverse. About 1 300 flux solves: a host's
    /// milliseconds, next to the fit's 22 000 shapes.
    fn stays_invertible(&self, model: &Saturation<T>) -> bool {
        let (ld0, lq0) = Self::zero_current_inductances(model);
        let floor = T::lit(INCREMENTAL_FLOOR);
        let i_max = self.pulse_current();
        let step = T::lit(2.0) * i_max / T::from_index(FLOOR_GRID - 1);
        let at = |k: usize| T::from_index(k) * step - i_max;
        (0..FLOOR_GRID).all(|a| {
            (0..FLOOR_GRID).all(|b| {
                let i = Dq::new(at(a), at(b));
                if i.d * i.d + i.q * i.q > i_max * i_max {
                    return true;
                }
                let l = model.incremental_inductance(i);
                l.dd > floor * ld0
                    && l.qq > floor * lq0
                    && l.dd * l.qq - l.dq * l.qd > floor * floor * ld0 * lq0
            })
        })
    }

    /// The zero-current constants (incremental L̂d, L̂q) of a fitted model.
    pub(super) fn zero_current_inductances(model: &Saturation<T>) -> (T, T) {
        let l = model.incremental_inductance(Dq::zero());
        (l.dd, l.qq)
    }
}
