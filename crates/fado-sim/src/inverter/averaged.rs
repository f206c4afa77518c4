//! The averaged model: per sample, the average pole voltages with the dead-time and threshold
//! errors of the current at the sample start, applied as a constant voltage (a leg held at
//! duty 0 or 1 has no edge: the threshold drop only, as in the switching-resolved model).

use fado_core::Abc;

use crate::fastmath::{cis, rotate};
use crate::motor::{ElectricalPropagator, Motor};

use super::{Inverter, SampleOutcome, clarke, phase_currents};

impl Inverter {
    pub(super) fn step_averaged(
        &mut self,
        motor: &mut Motor,
        prop: &ElectricalPropagator,
        duty: Abc<f64>,
        vdc: f64,
    ) -> SampleOutcome {
        let rot0 = motor.rotation();
        let i0 = motor.state().i_dq;
        let iph = phase_currents(rotate(i0, rot0));
        let d = [duty.a, duty.b, duty.c];
        let mut p = [0.0; 3];
        for k in 0..3 {
            p[k] = d[k] * vdc + self.params.averaged_error(iph[k], vdc, d[k]);
        }
        let v = clarke(p) - self.voltage_offset;
        let rot_h = cis(prop.omega() * self.ts);
        let i1 = prop.advance(i0, v, self.ts, rot0, rot_h);
        let mp = motor.params();
        let te = 0.5 * (prop.torque_dq(mp, i0) + prop.torque_dq(mp, i1));
        motor.set_current_from(prop, i1);
        // Keep the leg states coherent for a later switch to the resolved model.
        for (leg, dk) in self.legs.iter_mut().zip(d) {
            leg.gate = dk > 0.0;
            leg.pole = leg.gate;
            leg.pending = f64::INFINITY;
        }
        SampleOutcome {
            torque_avg: te,
            v_ab_avg: v,
            intervals: 1,
        }
    }
}
