//! The edge-current method's two fixed-point passes, the solve where the refinement's loop
//! gain is small (parent module, "Which solve"): the gate times of the reference plus the
//! trapezoid, each edge's delay from the sampled current, then twice the band model at the
//! edge currents the ripple of those gate times and delays implies (once where the first
//! keeps every delay: its fixed point).

use super::DeadTimeCompensation;
use crate::control::pi::clamp;
use crate::{Ab, Abc, Dq, Real, Rotation};

impl<T: Real> DeadTimeCompensation<T> {
    /// Each edge's delay (rise, fall) for the sampled currents `i`, the reference `v_abc` (V,
    /// before compensation), the frame `rotation` of the ripple inductances and the DC link
    /// `vdc` > 0: two passes on the trapezoid's gate times.
    #[inline(always)]
    pub(super) fn passes_delays(
        &self,
        rotation: Rotation<T>,
        i_abc: Abc<T>,
        v_abc: Abc<T>,
        vdc: T,
    ) -> ([T; 3], [T; 3]) {
        let i = [i_abc.a, i_abc.b, i_abc.c];
        let first = self.trapezoid(i_abc, vdc);
        let vp = [v_abc.a + first.a, v_abc.b + first.b, v_abc.c + first.c];
        let gates = self.gate_times(vp, vdc);
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

    /// The gate times (rise, fall) within each half period of the pole voltages `vp` (V per
    /// phase) the modulator will realise (min-max zero sequence as SVPWM, as offsets from the
    /// DC-link mid-point): legs go high at half/2 − v·half/Vdc while the carrier falls
    /// (rising edges), low at half/2 + v·half/Vdc while it rises.
    #[inline(always)]
    pub(super) fn gate_times(&self, mut vp: [T; 3], vdc: T) -> ([T; 3], [T; 3]) {
        let zero = T::zero();
        let half = self.half; // half carrier period = sample period
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
}
