//! The switching-resolved model: the legs' edges of each half carrier period, delayed by the
//! dead time edge by edge, and the machine integrated in closed form between them.

use fado_core::{Ab, Abc};
use num_complex::Complex64;

use crate::fastmath::{cis, rotate, unrotate};
use crate::motor::{ElectricalPropagator, Motor, MotorParams};

use super::{Inverter, SampleOutcome, phase_currents};

/// One inverter leg of the switching-resolved model.
#[derive(Clone, Copy, Debug)]
pub(super) struct Leg {
    /// Gate command: upper device commanded on.
    pub(super) gate: bool,
    /// Pole voltage state outside transitions: connected to the positive rail.
    pub(super) pole: bool,
    /// Time (from the present sample start) at which the pole follows the gate; ∞ if none.
    pub(super) pending: f64,
}

impl Default for Leg {
    fn default() -> Self {
        Self {
            gate: false,
            pole: false,
            pending: f64::INFINITY,
        }
    }
}

/// A gate edge: (time from the sample start, leg, new gate state).
type Edge = (f64, u8, bool);

/// The gate edges of one half carrier period, sorted by time, and the next one to act.
struct GateEdges {
    list: [Edge; 6],
    len: usize,
    next: usize,
}

impl GateEdges {
    /// The comparator's edges for `duty` over a half period of `ts` (the carrier 1 → 0 on a
    /// `falling` half, 0 → 1 on a rising one), with an edge at t = 0 for each leg whose gate
    /// starts the half in another state than `legs` hold.
    #[inline]
    fn new(legs: &[Leg; 3], duty: Abc<f64>, falling: bool, ts: f64) -> Self {
        let mut list = [(0.0_f64, 0_u8, false); 6];
        let mut len = 0;
        for (k, dk) in [duty.a, duty.b, duty.c].into_iter().enumerate() {
            // Comparator: upper device on while duty > carrier; carrier 1 → 0 on a falling half,
            // 0 → 1 on a rising one.
            let (start, edge) = if falling {
                (
                    dk >= 1.0,
                    (dk > 0.0 && dk < 1.0).then_some(((1.0 - dk) * ts, true)),
                )
            } else {
                (dk > 0.0, (dk > 0.0 && dk < 1.0).then_some((dk * ts, false)))
            };
            if start != legs[k].gate {
                list[len] = (0.0, k as u8, start);
                len += 1;
            }
            if let Some((t, g)) = edge {
                list[len] = (t, k as u8, g);
                len += 1;
            }
        }
        let edges = &mut list[..len];
        // Insertion sort (≤ 6 entries), stable so that a leg's t = 0 edge stays first.
        for a in 1..edges.len() {
            let mut b = a;
            while b > 0 && edges[b - 1].0 > edges[b].0 {
                edges.swap(b - 1, b);
                b -= 1;
            }
        }
        Self { list, len, next: 0 }
    }

    /// The next edge to act, if any.
    #[inline]
    fn peek(&self) -> Option<Edge> {
        self.list[..self.len].get(self.next).copied()
    }

    /// The next edge's time; ∞ when none is left.
    #[inline]
    fn next_time(&self) -> f64 {
        self.peek().map_or(f64::INFINITY, |e| e.0)
    }

    /// Takes the next edge.
    #[inline]
    fn take(&mut self) -> Edge {
        let e = self.list[self.next];
        self.next += 1;
        e
    }
}

/// The machine over one half carrier period: the current carried in α-β (phase currents at
/// every edge, d-q only at the end), its rotation, and the torque and voltage integrals.
struct Span {
    i: Ab<f64>,
    iph: [f64; 3],
    rot: Complex64,
    te_prev: f64,
    t: f64,
    te_int: f64,
    v_int: Ab<f64>,
    intervals: u32,
}

impl Span {
    /// The machine's state at the sample start.
    #[inline]
    fn start(motor: &Motor, prop: &ElectricalPropagator, mp: &MotorParams) -> Self {
        let rot = motor.rotation();
        let i = rotate(motor.state().i_dq, rot);
        Self {
            i,
            iph: phase_currents(i),
            rot,
            te_prev: prop.torque_dq(mp, motor.state().i_dq),
            t: 0.0,
            te_int: 0.0,
            v_int: Ab::zero(),
            intervals: 0,
        }
    }

    /// Integrates the constant pole voltage `v` over `h`, to `t_next`.
    #[inline]
    fn integrate(
        &mut self,
        prop: &ElectricalPropagator,
        mp: &MotorParams,
        v: Ab<f64>,
        h: f64,
        t_next: f64,
    ) {
        let rot_h = cis(prop.omega() * h);
        self.i = prop.advance_ab(self.i, v, h, self.rot, rot_h);
        self.rot *= rot_h;
        self.iph = phase_currents(self.i);
        let te = prop.torque_ab(mp, self.i, self.rot);
        self.te_int += 0.5 * (self.te_prev + te) * h;
        self.te_prev = te;
        self.v_int += v * h;
        self.intervals += 1;
        self.t = t_next;
    }
}

impl Inverter {
    /// One half carrier period with the gates enabled: the duty's edges, each delayed by the
    /// dead time at its own current, and the machine integrated between every two events
    /// (an edge or a pole following its gate).
    pub(super) fn step_switching(
        &mut self,
        motor: &mut Motor,
        prop: &ElectricalPropagator,
        duty: Abc<f64>,
        vdc: f64,
        falling: bool,
    ) -> SampleOutcome {
        let ts = self.ts;
        let mut edges = GateEdges::new(&self.legs, duty, falling, ts);
        let mp = *motor.params();
        let mut span = Span::start(motor, prop, &mp);
        let slew = self.current_slew(prop, &mp, span.i, vdc);
        loop {
            self.take_opposing_edges(&mut edges, &span, slew);
            let edge_t = edges.next_time();
            let (pend_t, pend_leg) = self.first_pending();
            let t_next = edge_t.min(pend_t).min(ts);
            let h = t_next - span.t;
            if h > 0.0 {
                let poles = [self.legs[0].pole, self.legs[1].pole, self.legs[2].pole];
                let v = self.pole_voltages(poles, span.iph, vdc) - self.voltage_offset;
                span.integrate(prop, &mp, v, h, t_next);
            }
            if t_next >= ts && edge_t >= ts && pend_t >= ts {
                break;
            }
            if pend_t <= edge_t {
                let leg = &mut self.legs[pend_leg];
                leg.pole = leg.gate;
                leg.pending = f64::INFINITY;
            } else {
                self.switch(edges.take(), &span, vdc);
            }
        }
        self.end_half_period(motor, prop, &span)
    }

    /// Bound on |di_x/dt| over the half period: phase voltage ≤ 2/3·Vdc plus drops, back-EMF
    /// ≤ ω·λf, from the current `i` at its start.
    #[inline]
    fn current_slew(
        &self,
        prop: &ElectricalPropagator,
        mp: &MotorParams,
        i: Ab<f64>,
        vdc: f64,
    ) -> f64 {
        let l_min = prop.min_inductance(mp);
        let i_bound = i.norm() + 2.0 * vdc * self.ts / l_min;
        (2.0 / 3.0 * vdc
            + 2.0 * self.params.threshold_voltage
            + prop.omega().abs() * prop.flux_bound(mp, i_bound)
            + (mp.rs + self.params.on_resistance) * i_bound)
            / l_min
    }

    /// Takes the next edges whose current certainly keeps its sign until the edge and opposes
    /// it (with the bound `slew`): they wait exactly Td whatever the current's value, so the
    /// integration need not stop at the edge itself.
    #[inline]
    fn take_opposing_edges(&mut self, edges: &mut GateEdges, span: &Span, slew: f64) {
        while let Some((te, k, g)) = edges.peek() {
            let k = k as usize;
            let margin = slew * (te - span.t);
            let opposing = if g {
                span.iph[k] - margin > 0.0
            } else {
                span.iph[k] + margin < 0.0
            };
            if !opposing || te >= self.ts {
                break;
            }
            edges.next += 1;
            let leg = &mut self.legs[k];
            leg.gate = g;
            leg.pending = if leg.pole == g {
                f64::INFINITY
            } else {
                te + self.params.dead_time
            };
        }
    }

    /// The earliest pole transition pending: (time, leg); ∞ when none is.
    #[inline]
    fn first_pending(&self) -> (f64, usize) {
        let (mut pend_t, mut pend_leg) = (f64::INFINITY, 0);
        for (k, leg) in self.legs.iter().enumerate() {
            if leg.pending < pend_t {
                (pend_t, pend_leg) = (leg.pending, k);
            }
        }
        (pend_t, pend_leg)
    }

    /// A gate edge at `span.t`: its pole follows after the dead-time delay of the phase
    /// current at the edge (at once when the delay is nil).
    #[inline]
    fn switch(&mut self, (_, k, g): Edge, span: &Span, vdc: f64) {
        let k = k as usize;
        let delay = self.params.edge_delay(g, span.iph[k], vdc);
        let leg = &mut self.legs[k];
        leg.gate = g;
        if leg.pole == g {
            // A pulse shorter than the transition: the pole never left.
            leg.pending = f64::INFINITY;
        } else if delay <= 0.0 {
            leg.pole = g;
            leg.pending = f64::INFINITY;
        } else {
            leg.pending = span.t + delay;
        }
    }

    /// The machine's current back in d-q, the pending transitions carried into the next
    /// half, the sample's averages.
    #[inline]
    fn end_half_period(
        &mut self,
        motor: &mut Motor,
        prop: &ElectricalPropagator,
        span: &Span,
    ) -> SampleOutcome {
        let ts = self.ts;
        let i = unrotate(span.i, span.rot);
        for leg in &mut self.legs {
            leg.pending -= ts; // ∞ stays ∞
        }
        motor.set_current_from(prop, i);
        SampleOutcome {
            torque_avg: span.te_int / ts,
            v_ab_avg: span.v_int * (1.0 / ts),
            intervals: span.intervals,
        }
    }
}
