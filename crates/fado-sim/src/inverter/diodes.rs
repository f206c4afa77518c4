//! Gates disabled (a trip): the poles follow the freewheeling diodes until the currents have
//! decayed and the diodes block.

use fado_core::{Ab, Dq};

use crate::fastmath::{cis, rotate};
use crate::motor::{ElectricalPropagator, Motor};

use super::{Inverter, SampleOutcome, phase_currents};

impl Inverter {
    pub(super) fn step_diodes(
        &mut self,
        motor: &mut Motor,
        prop: &ElectricalPropagator,
        vdc: f64,
    ) -> SampleOutcome {
        const SUBSTEPS: u32 = 50;
        let h = self.ts / SUBSTEPS as f64;
        let mp = *motor.params();
        // Below what one sub-step can move, a diode current is taken to have reached zero and
        // blocked (resolving the exact zero crossing is not worth it after a trip).
        let blocking_current = 1.5 * vdc * h / prop.min_inductance(&mp);
        let omega = prop.omega();
        let rot_h = cis(omega * h);
        let mut rot = motor.rotation();
        let mut i = motor.state().i_dq;
        let (mut te_int, mut v_int) = (0.0, Ab::zero());
        let emf_line_peak = 3f64.sqrt() * omega.abs() * mp.flux_linkage;
        for _ in 0..SUBSTEPS {
            let iph = phase_currents(rotate(i, rot));
            let te0 = prop.torque_dq(&mp, i);
            let v = if iph.iter().all(|x| x.abs() < blocking_current) && emf_line_peak < vdc {
                // Diodes blocking: the machine is open-circuited.
                i = Dq::zero();
                Ab::zero()
            } else {
                // Positive current (out of the leg) freewheels through the lower diode.
                let poles = [iph[0] <= 0.0, iph[1] <= 0.0, iph[2] <= 0.0];
                let v = self.pole_voltages(poles, iph, vdc);
                i = prop.advance(i, v, h, rot, rot_h);
                v
            };
            rot *= rot_h;
            te_int += 0.5 * (te0 + prop.torque_dq(&mp, i)) * h;
            v_int += v * h;
        }
        for leg in &mut self.legs {
            leg.gate = false;
            leg.pending = f64::INFINITY;
        }
        motor.set_current_from(prop, i);
        SampleOutcome {
            torque_avg: te_int / self.ts,
            v_ab_avg: v_int * (1.0 / self.ts),
            intervals: SUBSTEPS,
        }
    }
}
