//! The edge-current method's solve: each switching edge's delay as the root of the band model
//! evaluated at the edge current that the delays themselves imply (parent module,
//! "Edge currents").
//!
//! **The problem.** For delays d = (d_rise, d_fall) per phase, the compensation is
//! c_x = Vdc·f_sw·(d_rise,x − d_fall,x) + V_th·sat(i_x/Ic), the modulator turns v + c into
//! gate times (min-max zero sequence), each pole follows its gate after its delay, and the
//! pattern's piecewise-linear ripple gives every edge's current ie. The delays the inverter
//! then produces are φ_rise(ie) = Td·clamp(1 + ie/Ic, 0, 1) and φ_fall(ie) =
//! Td·clamp(1 − ie/Ic, 0, 1): the solution is the root of G(d) = d − φ(ie(d)). Gate times
//! follow from the compensation itself, so the pattern's mean over the period is v + V_th·sat
//! for any delays, and a phase's delays move its own pole edges by half their sum:
//! pole_rise,x = T_rise,x + (d_rise + d_fall)/2, pole_fall,x = T_fall,x + (d_rise + d_fall)/2.
//!
//! **Per phase, exactly.** Along phase x, with σ the slope of x's current just before its
//! gate edge (the other poles already switched, the mean slope removed) and
//! β = (u_x·L̂⁻¹·u_x)·Vdc/6 (a change of x's delays splits its pulse differently between the
//! two halves, moving the peak and valley samples by β per second), the edge currents are
//! affine in x's own delays on each piece of the pattern:
//!
//! ∂ie_rise/∂(d_rise, d_fall) = (β − σ_rise/2, β + σ_rise/2),
//! ∂ie_fall/∂(d_rise, d_fall) = (σ_fall/2 − β, −σ_fall/2 − β),
//!
//! and G is piecewise linear. A Newton step with these slopes and φ's (Td/Ic inside the band,
//! 0 outside) lands on the root of the piece it starts on; the box [0, Td] bounds each step.
//! On a round rotor with one other pole switched before each of x's edges (the phase near
//! zero current between a positive and a negative one: the loaded standstill) the two edges
//! decouple (β + σ_rise/2 = 0) and each is a scalar increasing piecewise-linear function whose
//! root the step finds in at most three rounds (one per clamp it may start on). The loop
//! gain q = (Td/Ic)·(β − σ/2) is 2·Vdc·Td/(6·L̂·Ic) there, 0.79 on the MAD 5010 KV110
//! (44.4 V, 0.625 µs, 85 µH, 0.138 A); where a piece's Jacobian is singular or reversed
//! (q ≥ 1: the root is not unique, the inverter settles on whichever its past leaves it on),
//! the step is the plain evaluation d ← φ(ie(d)).
//!
//! **Two or three phases in the band** (the current vector within about Ic + ripple of zero):
//! a pole of one phase moves the others' edge currents through the star point, which the
//! per-phase step leaves out of its Jacobian: the same [`ROUNDS`] rounds are then a
//! block-Jacobi Newton iteration, a defined approximation that converges linearly instead of
//! in one step. Measured (unit tests below): a 0.1 A current vector turned in 1e-4 rad steps
//! on the MAD 5010 KV110 (every phase's edges in the band) changes no phase's compensation
//! by more than 1 % of V̂ from one step to the next.
//!
//! The first round is the band model at the edge currents of the sampled currents' delays.
//! Cost: ≈ 150 flops per round and at most three divisions per round (one per phase whose
//! edge is in the band), [`ROUNDS`] rounds (not measured on target).

use super::DeadTimeCompensation;
use crate::control::pi::clamp;
use crate::{Ab, Dq, Real, Rotation};

/// Rounds of the edge solve: one evaluation from the sampled currents' delays, then Newton
/// steps; the loaded standstill's decoupled edges converge in at most three (one per clamp).
pub(super) const ROUNDS: usize = 4;

/// Smallest determinant of a phase's 2×2 Newton matrix, the product (1 − q_rise)·(1 − q_fall)
/// of its edges' loop gains where they decouple: below it a loop gain is near or above 1 and
/// the step is the plain evaluation.
const MIN_DETERMINANT: f64 = 1e-3;

/// The delays (s) of each phase's rising and falling edges.
pub(super) type Delays<T> = ([T; 3], [T; 3]);

/// One carrier period's pattern for given delays: gate and pole times, and along each phase
/// the mean slope and half the peak-valley swing of its current.
struct Pattern<T> {
    gate_rise: [T; 3],
    gate_fall: [T; 3],
    pole_rise: [T; 3],
    pole_fall: [T; 3],
    /// u_x·L̂⁻¹·(mean voltage of the pattern), A/s.
    mean: [T; 3],
    /// Half the swing from the peak to the valley sample along u_x, A.
    half_swing: [T; 3],
}

/// Phase x's edge currents (rise, fall) and the slopes σ of its current before them.
struct EdgeCurrents<T> {
    rise: T,
    fall: T,
    slope_rise: T,
    slope_fall: T,
}

impl<T: Real> DeadTimeCompensation<T> {
    /// s[x][k] = (2/3)·Vdc·u_x·L̂⁻¹·u_k, A/s: phase x's current slope per pole k high.
    #[inline(always)]
    fn pole_slopes(&self, rotation: Rotation<T>, vdc: T) -> [[T; 3]; 3] {
        let (zero, one) = (T::zero(), T::one());
        let k3 = T::lit(0.866_025_403_784_438_6);
        let axes = [
            Ab::new(one, zero),
            Ab::new(T::lit(-0.5), k3),
            Ab::new(T::lit(-0.5), -k3),
        ];
        let step = T::lit(2.0 / 3.0) * vdc;
        let (inv_ld, inv_lq) = (self.inv_ripple.d * step, self.inv_ripple.q * step);
        let resp = axes.map(|u| {
            let w = u.to_dq(rotation);
            Dq::new(w.d * inv_ld, w.q * inv_lq).to_ab(rotation)
        });
        [0, 1, 2].map(|x| [0, 1, 2].map(|k| axes[x].dot(resp[k])))
    }

    /// The pattern of `delays` for the reference `v` (V per phase) and currents `i`.
    #[inline(always)]
    fn pattern(
        &self,
        v: [T; 3],
        i: [T; 3],
        (d_rise, d_fall): &Delays<T>,
        s: &[[T; 3]; 3],
        vdc: T,
    ) -> Pattern<T> {
        let (zero, one) = (T::zero(), T::one());
        let half = self.half;
        let c = &self.config;
        let per_second = vdc * c.switching_frequency;
        let vth = c.threshold_voltage;
        let vp = [0, 1, 2].map(|x| {
            v[x] + per_second * (d_rise[x] - d_fall[x])
                + vth * clamp(i[x] * self.inv_band, -one, one)
        });
        let (gate_rise, gate_fall) = self.gate_times(vp, vdc);
        let pole_rise = [0, 1, 2].map(|k| (gate_rise[k] + d_rise[k]).step_min(half));
        let pole_fall = [0, 1, 2].map(|k| (gate_fall[k] + d_fall[k]).step_min(half));
        // High times: half − pole_rise in the falling-carrier half, pole_fall in the rising.
        let (mut mean, mut half_swing) = ([zero; 3], [zero; 3]);
        for x in 0..3 {
            for k in 0..3 {
                let (hr, hf) = (half - pole_rise[k], pole_fall[k]);
                mean[x] += s[x][k] * (hr + hf);
                half_swing[x] += s[x][k] * (hr - hf);
            }
            mean[x] *= self.inv_period;
            half_swing[x] *= T::lit(0.25);
        }
        Pattern {
            gate_rise,
            gate_fall,
            pole_rise,
            pole_fall,
            mean,
            half_swing,
        }
    }

    /// Phase x's current at its two gate edges: the sampled `i_x` less (peak) or plus
    /// (valley) half the swing, plus the ripple of the poles already switched, the mean
    /// slope removed.
    #[inline(always)]
    fn edge_currents(&self, p: &Pattern<T>, s: &[[T; 3]; 3], i_x: T, x: usize) -> EdgeCurrents<T> {
        let zero = T::zero();
        let (tr, tf) = (p.gate_rise[x], p.gate_fall[x]);
        let mut out = EdgeCurrents {
            rise: i_x - p.half_swing[x] - p.mean[x] * tr,
            fall: i_x + p.half_swing[x] - p.mean[x] * tf,
            slope_rise: -p.mean[x],
            slope_fall: -p.mean[x],
        };
        for (k, &sxk) in s[x].iter().enumerate() {
            if k == x {
                continue;
            }
            let (ar, af) = (tr - p.pole_rise[k], tf - p.pole_fall[k]);
            if ar > zero {
                out.rise += sxk * ar;
                out.slope_rise += sxk;
            }
            if af > zero {
                out.fall -= sxk * af;
                out.slope_fall -= sxk;
            }
        }
        out
    }

    /// The band model's delays (rise, fall) of edge currents `e`, and their slopes per
    /// ampere (Td/Ic inside the band, 0 outside).
    #[inline(always)]
    fn band_delays(&self, e: &EdgeCurrents<T>) -> ((T, T), (T, T)) {
        let (zero, one) = (T::zero(), T::one());
        let td = self.config.dead_time;
        let q = td * self.inv_band;
        let gr = one + e.rise * self.inv_band;
        let gf = one - e.fall * self.inv_band;
        let inside = |g: T| g > zero && g < one;
        (
            (td * clamp(gr, zero, one), td * clamp(gf, zero, one)),
            (
                if inside(gr) { q } else { zero },
                if inside(gf) { -q } else { zero },
            ),
        )
    }

    /// One Newton step of phase x's two delays `d` towards the root of d − φ(ie(d)).
    #[inline(always)]
    fn newton_step(&self, d: (T, T), e: &EdgeCurrents<T>, beta: T) -> (T, T) {
        let (zero, one, half) = (T::zero(), T::one(), T::lit(0.5));
        let td = self.config.dead_time;
        let ((pr, pf), (qr, qf)) = self.band_delays(e);
        let (rr, rf) = (d.0 - pr, d.1 - pf);
        if qr == zero && qf == zero {
            return (pr, pf); // both edges outside the band: G is d − const
        }
        let j00 = one - qr * (beta - half * e.slope_rise);
        let j01 = -qr * (beta + half * e.slope_rise);
        let j10 = -qf * (half * e.slope_fall - beta);
        let j11 = one + qf * (beta + half * e.slope_fall);
        let det = j00 * j11 - j01 * j10;
        if det.step_max(zero) < T::lit(MIN_DETERMINANT) {
            return (pr, pf);
        }
        let inv = one / det;
        let nr = d.0 - inv * (j11 * rr - j01 * rf);
        let nf = d.1 - inv * (j00 * rf - j10 * rr);
        (clamp(nr, zero, td), clamp(nf, zero, td))
    }

    /// Each edge's delay (rise, fall) for the sampled currents `i`, the reference `v` (V per
    /// phase, before compensation), the frame `rotation` of the ripple inductances and the
    /// DC link `vdc` > 0 (module docs).
    #[inline(always)]
    pub(super) fn edge_delays(
        &self,
        rotation: Rotation<T>,
        i: [T; 3],
        v: [T; 3],
        vdc: T,
    ) -> Delays<T> {
        let s = self.pole_slopes(rotation, vdc);
        let first = (
            i.map(|x| self.edge_delay(true, x)),
            i.map(|x| self.edge_delay(false, x)),
        );
        let mut d = first;
        for round in 0..ROUNDS {
            let p = self.pattern(v, i, &d, &s, vdc);
            let mut next = d;
            for x in 0..3 {
                let e = self.edge_currents(&p, &s, i[x], x);
                (next.0[x], next.1[x]) = if round == 0 {
                    self.band_delays(&e).0
                } else {
                    self.newton_step((d.0[x], d.1[x]), &e, T::lit(0.25) * s[x][x])
                };
            }
            d = next;
        }
        d
    }

    /// The largest |d − φ(ie(d))| over the six edges, s: how far `d` is from the root.
    #[cfg(test)]
    pub(super) fn edge_residual(
        &self,
        rotation: Rotation<T>,
        i: [T; 3],
        v: [T; 3],
        vdc: T,
        d: &Delays<T>,
    ) -> T {
        let s = self.pole_slopes(rotation, vdc);
        let p = self.pattern(v, i, d, &s, vdc);
        let mut worst = T::zero();
        for (x, &ix) in i.iter().enumerate() {
            let e = self.edge_currents(&p, &s, ix, x);
            let ((pr, pf), _) = self.band_delays(&e);
            worst = worst
                .step_max((d.0[x] - pr).abs())
                .step_max((d.1[x] - pf).abs());
        }
        worst
    }
}

#[cfg(test)]
mod tests {
    use super::super::{DeadTimeCompensationConfig, DeadTimeMethod};
    use super::*;
    use crate::{Abc, MachineModel};

    /// The MAD 5010 KV110's inverter (44.4 V, 20 kHz, Td 0.625 µs, Ic 0.138 A) with ripple
    /// inductances `ld`, `lq`.
    fn kv110(ld: f64, lq: f64) -> DeadTimeCompensation<f64> {
        DeadTimeCompensation::new(DeadTimeCompensationConfig {
            method: DeadTimeMethod::EdgeCurrent,
            dead_time: 0.625e-6,
            switching_frequency: 20e3,
            threshold_voltage: 44.4 / 311.0,
            current_band: 0.137_739_130_434_782_6,
            ripple_inductance: Dq::new(ld, lq),
            ..DeadTimeCompensationConfig::for_machine(&MachineModel::paper())
        })
        .unwrap()
    }

    const VDC: f64 = 44.4;
    const RS: f64 = 0.6193;
    const IC: f64 = 0.137_739_130_434_782_6;

    /// Standstill under `load` (phases a, c at ∓load), phase b at `ib`: currents and the
    /// reference R·i.
    fn standstill(load: f64, ib: f64) -> ([f64; 3], [f64; 3]) {
        let i = [-load - 0.5 * ib, ib, load - 0.5 * ib];
        (i, i.map(|x| RS * x))
    }

    #[test]
    fn the_solve_reaches_the_root_where_one_phase_is_in_the_band() {
        // Phase b swept over ±3 Ic, the ripple's amplitude through the inductance (85 and
        // 200 µH, round and salient at two angles) and the load (the active vectors' length).
        let mut worst = 0.0_f64;
        for (ld, lq, theta) in [
            (85e-6, 85e-6, 0.0),
            (200e-6, 200e-6, 0.0),
            (85e-6, 120e-6, 0.3),
            (85e-6, 120e-6, 1.9),
        ] {
            let c = kv110(ld, lq);
            let rot = Rotation::from_angle(theta);
            for load in [2.0, 5.55, 12.0] {
                for k in -60..=60 {
                    let (i, v) = standstill(load, k as f64 * 0.05 * IC);
                    let d = c.edge_delays(rot, i, v, VDC);
                    worst = worst.max(c.edge_residual(rot, i, v, VDC, &d));
                }
            }
        }
        // Residual of the delays against the band model at the edge currents they imply.
        assert!(worst < 1e-4 * 0.625e-6, "worst residual {worst} s");
    }

    /// Phase b's compensation (V) at standstill under `load` with phase b at `ib`.
    fn on_b(c: &DeadTimeCompensation<f64>, rot: Rotation<f64>, load: f64, ib: f64) -> f64 {
        let (i, v) = standstill(load, ib);
        let abc = |x: [f64; 3]| Abc::new(x[0], x[1], x[2]);
        c.edge_current(rot, abc(i), abc(v), VDC).b
    }

    #[test]
    fn the_compensation_rises_with_the_phase_current_and_does_not_jump() {
        // Through the band in steps of 1e-4·Ic: never falling, and no step larger than the
        // solution's own slope allows (K·Td/Ic per edge through a loop gain ≤ 0.8: at most
        // 2/(1 − 0.8) = 10 times the trapezoid's V̂/Ic; a change of piece in a bounded
        // iteration would jump by a sizeable part of V̂).
        // Under 0.05 A every phase is in the band and phases a and c move with b: no
        // monotonicity to expect there, and no step above 1 % of V̂.
        let rot = Rotation::from_angle(0.0);
        for (l, load) in [(85e-6, 5.55), (85e-6, 2.0), (200e-6, 12.0), (85e-6, 0.05)] {
            let c = kv110(l, l);
            let bound = if load > 1.0 {
                12.0 * c.amplitude(VDC) / IC * 1e-4 * IC
            } else {
                0.01 * c.amplitude(VDC) // the block-Jacobi approximation (module docs)
            };
            let mut prev = on_b(&c, rot, load, -3.0 * IC);
            for k in -29_999..=30_000 {
                let v = on_b(&c, rot, load, k as f64 * 1e-4 * IC);
                if load > 1.0 {
                    assert!(v >= prev - 1e-12, "{l} {load} at {k}: {prev} -> {v}");
                }
                assert!(v - prev <= bound, "{l} {load} at {k}: {prev} -> {v}");
                prev = v;
            }
        }
    }

    #[test]
    fn all_three_phases_in_the_band_follow_the_angle_without_chatter() {
        // A 0.1 A current vector turned in 1e-4 rad steps on 85 µH (ripple ±0.33 A: every
        // phase's edges in the band): the compensation follows the angle continuously.
        let c = kv110(85e-6, 85e-6);
        let rot = Rotation::from_angle(0.0);
        let at = |th: f64| {
            let i = Abc::new(
                0.1 * th.cos(),
                0.1 * (th - 2.094_395_102_393_195).cos(),
                0.0,
            );
            let i = Abc::new(i.a, i.b, -i.a - i.b);
            let v = Abc::new(RS * i.a, RS * i.b, RS * i.c);
            c.edge_current(rot, i, v, VDC)
        };
        let vhat = c.amplitude(VDC);
        let mut prev = at(0.0);
        let mut worst = 0.0_f64;
        for k in 1..=62_832 {
            let v = at(k as f64 * 1e-4);
            for (a, b) in [(v.a, prev.a), (v.b, prev.b), (v.c, prev.c)] {
                assert!(a.abs() <= vhat + 1e-12);
                worst = worst.max((a - b).abs());
            }
            prev = v;
        }
        assert!(
            worst < 0.01 * vhat,
            "largest sample-to-sample step {worst} V"
        );
    }
}
