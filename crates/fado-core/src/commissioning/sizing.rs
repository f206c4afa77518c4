//! Test levels sized from the nameplate, and small numeric helpers.

use crate::{Ab, Abc, MachineModel, Real};

#[inline]
pub(super) fn clamp<T: Real>(x: T, lo: T, hi: T) -> T {
    x.max(lo).min(hi)
}

/// Limits a vector's magnitude.
#[inline]
pub(super) fn limit<T: Real>(v: Ab<T>, max: T) -> Ab<T> {
    let n = v.norm();
    if n > max && n > T::zero() {
        v * (max / n)
    } else {
        v
    }
}

/// The per-phase inverter voltage error model v·sat(i_x/band) of a current (docs/method/estimator.md §7's
/// trapezoid), in α-β.
pub(super) fn dead_time_voltage<T: Real>(i_ab: Ab<T>, band: T, v: T) -> Ab<T> {
    let i = i_ab.to_abc();
    let s = |x: T| clamp(x / band, -T::one(), T::one()) * v;
    Abc::new(s(i.a), s(i.b), s(i.c)).to_ab()
}

/// The upper DC-test (and alignment) current: 90 % of the limit, and for a rotor with Lq > Ld
/// at most half of λf/(Lq − Ld) (nameplate), so that the d-axis alignment keeps at least half
/// the magnet's stiffness: the torque about it, 1.5·p·(λf + (Ld − Lq)·i_d)·i_q, would vanish
/// at i_d = λf/(Lq − Ld) and a reluctance rotor turn to the q axis (measured: the 5 kW
/// PM-SyRM preset turned during the DC test at 90 % of its limit).
pub(super) fn dc_level<T: Real>(np: &MachineModel<T>, i_limit: T) -> T {
    let i = T::lit(0.9) * i_limit;
    let dl = np.lq - np.ld;
    if dl > T::zero() {
        i.min(T::lit(0.5) * np.flux_linkage / dl)
    } else {
        i
    }
}

/// The standstill loop's gains (k_p in Ω, k_int in V/(A·s)) from the nameplate's `rs` and
/// mean inductance `l` and the sampling period `ts` (module docs, step 2). The loop acts along
/// the current reference only, on L·s² + (R + k_p)·s + k_int: ζ = 0.7 at
/// ωn = [`STANDSTILL_LOOP_BANDWIDTH`]/Ts, i.e. R + k_p = √2·L·ωn and k_int = L·ωn². Where
/// the machine's own resistance already exceeds √2·L·ωn (τ = L/R below 14 samples) k_p is 0
/// and k_int = R²/(2L) (ζ = 0.7 at ωn = R/(√2·L), below the bound).
pub(super) fn standstill_gains<T: Real>(rs: T, l: T, ts: T) -> (T, T) {
    let wn = T::lit(STANDSTILL_LOOP_BANDWIDTH) / ts;
    let r_loop = (T::lit(core::f64::consts::SQRT_2) * l * wn).max(rs);
    (r_loop - rs, T::lit(0.5) * r_loop * r_loop / l)
}

/// Natural frequency of the standstill loop along the reference, × Ts: well below the
/// sampling rate (a nameplate L 1.6× the machine's leaves ωn·Ts = 0.13 and ζ = 0.9, where
/// the loop's 1.5 samples of delay cost 0.19 rad of phase), and the fastest such loop: the
/// voltage it has to find besides R̂·i* is the inverter's unmodelled threshold, which does
/// not scale with R·I: 60 V against R·I = 8 V on a 10 kV-class machine, where K = R²/(2L)
/// (0.2 V/(A·s)) took 5 s to build the alignment's current.
pub(super) const STANDSTILL_LOOP_BANDWIDTH: f64 = 0.1;

/// The spin's synchronous current PI's integral gain, V/(A·s), at crossover `wc` (rad/s) with
/// the proportional gain wc·L: wc·R (its zero cancels the machine's pole R/L), and at least
/// what follows the I-f spin's back-EMF within [`SPIN_EMF_FOLLOWING`] of the current limit
/// `i_limit`. The loop has no feedforward of that EMF, a ramp ω̇·λf (`accel` ω̇ in electrical
/// rad/s², `flux` λf of the nameplate), whose following error is ω̇·λf/k_i: on a 10 kV-class
/// machine (λf 11.7 Wb, R/L = 4 s⁻¹) at a 2 kHz carrier, wc·R left 61 A against the 27 A the
/// spin tolerates (`CurrentNotFollowing` in the spin), and at 5 kHz 24 A, which took λ̂f
/// 1.6 % low.
pub(super) fn spin_integral_gain<T: Real>(rs: T, wc: T, accel: T, flux: T, i_limit: T) -> T {
    (wc * rs).max(accel * flux / (T::lit(SPIN_EMF_FOLLOWING) * i_limit))
}

/// The I-f spin's largest following error of its back-EMF ramp, as a fraction of the current
/// limit: 5 % (the spin aborts at 30 %; the nameplate's λf and J may be 1.25× off).
pub(super) const SPIN_EMF_FOLLOWING: f64 = 0.05;

/// The I-f spin's current amplitude: the DC test's upper level ([`dc_level`]), for the same
/// reason. The rotor lags the I-f vector by δ, with i_d = I·cos δ, and the torque
/// 1.5·p·I·sin δ·(λf − (Lq − Ld)·I·cos δ) is stable about δ ≈ 0 only for
/// I < λf/(Lq − Ld); at half that, the active flux λf + (Ld − Lq)·i_d, whose EMF the spin's
/// PLL locks onto, stays above λf/2 for any lag. Measured at 90 % of the limit on the 50 kW
/// IPMSM preset ((Lq − Ld)·I = 1.36 λf): the rotor hunted ±1 rad (±60 r/min) between the
/// two stable lags δ = ±0.74 rad, where the active flux is zero, the PLL slipped to π, and
/// the coast started 2 rad off (λ̂f −5.8 %). `ld`, `lq`: the identified inductances (the
/// nameplate's λf: off by 1.25× it still leaves the lag stable, (Lq − Ld)·I ≤ 0.63 λf; the
/// nameplate's inductances 0.8×/1.25× off gave 1.05 λf on that preset, `Overspeed`).
pub(super) fn if_level<T: Real>(np: &MachineModel<T>, ld: T, lq: T, i_limit: T) -> T {
    dc_level(&MachineModel { ld, lq, ..*np }, i_limit)
}

/// The inertia test's q-current step: `wanted` within `floor` and 90 % of the limit (the
/// floor: 10 % of the limit, lower on a light rotor, `Commissioning::step_floor`), and at most the
/// I-f level ([`if_level`]) of the identified λ̂f, L̂d, L̂q. The step's current runs in closed
/// loop on the back-EMF PLL's angle, and an angle error ε puts I·sin ε of it on the d axis,
/// where the active flux λf + (Ld − Lq)·i_d that the PLL locks onto falls; at
/// I = λf/(Lq − Ld) it vanishes for ε = −π/2 and the PLL has nothing to hold it. Measured
/// on the 5.6 kW PM-SyRM presets (I = 4.0 A ≈ λf/(Lq − Ld), its secant Lq below the
/// injection's L̂q under load): the PLL drifted to ε ≈ −1.5 rad within 0.1 s of the step,
/// the current turned onto +d, the rotor stopped accelerating and the test timed out.
pub(super) fn step_level<T: Real>(
    np: &MachineModel<T>,
    flux: T,
    ld: T,
    lq: T,
    i_limit: T,
    wanted: T,
    floor: T,
) -> T {
    let cap = if_level(
        &MachineModel {
            flux_linkage: flux,
            ..*np
        },
        ld,
        lq,
        i_limit,
    );
    clamp(wanted, floor, T::lit(0.9) * i_limit).min(cap)
}

/// The I-f current (`if_level`) and the spin's electrical acceleration: spin_torque_ratio ×
/// the rated torque on the nameplate J, at most a quarter of the magnet torque 1.5·p·λf·I_if
/// (the rotor then lags the current vector by about 15°, far from the pull-out even with the
/// nameplate's λf 1.25× and J 0.8× the truth; module docs, step 6).
pub(super) fn spin_sizing<T: Real>(
    np: &MachineModel<T>,
    ld: T,
    lq: T,
    i_limit: T,
    ratio: T,
) -> (T, T) {
    let i_if = if_level(np, ld, lq, i_limit);
    let p = T::lit(np.pole_pairs as f64);
    let magnet_torque = T::lit(1.5) * p * np.flux_linkage * i_if;
    let torque = (ratio * np.rated_torque).min(T::lit(0.25) * magnet_torque);
    (i_if, torque / np.inertia * p)
}

pub(super) fn libm_round(x: f64) -> u32 {
    let r = x + 0.5;
    if r < 1.0 { 1 } else { r as u32 }
}

/// The inverter's current band the standstill phases assume, as a fraction of the current
/// limit: 5 % (docs/method/estimator.md §7's trapezoid, whose band is the pole's parasitic
/// capacitance's; the simulator's default 0.3 A is 5 % of the paper drive's 6 A limit).
pub(super) const INVERTER_BAND_RATIO: f64 = 0.05;
