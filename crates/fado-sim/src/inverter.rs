//! Two-level three-phase PWM inverter: symmetric triangular carrier, double update (sampling at
//! carrier peak and valley, paper §V: 5 kHz switching, 10 kHz sampling), dead time with the
//! current-dependent voltage error, device threshold drops, and a one-sample computational
//! delay (the duty computed at sample n is loaded at n+1 and acts over [n+1, n+2]).
//!
//! Two models of the same inverter:
//!
//! * [`InverterModel::SwitchingResolved`]: within each half carrier period the three legs'
//!   switching instants, shifted by the dead-time delays, are sorted, and the machine is
//!   integrated in closed form over each interval of constant switch state
//!   ([`crate::motor::ElectricalPropagator`], exact to rounding). The dead-time delay of an edge
//!   depends on the *instantaneous* phase current at that edge (ripple included): the outgoing
//!   device turns off, and during Td the pole is moved by the current. If the current opposes
//!   the transition (it keeps the outgoing side's diode conducting) the pole waits the full Td.
//!   If it helps, it slews the pole's parasitic capacitance and the pole moves early; the
//!   ramp is replaced by the step of equal volt-seconds, at a delay set by [`Commutation`]:
//!   by default `Td·(1 − |i|/Ic)⁺`, so that every edge loses exactly `Td·Vdc·sat(i/Ic)`
//!   volt-seconds — the docs/method/estimator.md §7 curve, but applied edge by edge with the instantaneous current;
//!   optionally a linear capacitor (`C = Ic·Td/(2·Vdc)`: delay `t_r/2` if the ramp
//!   `t_r = C·Vdc/|i|` ends within Td, else `Td·(1 − Td/(2·t_r))`), whose error only
//!   approaches its full value as `1 − Ic/(4|i|)`. At zero current both edges wait Td and the
//!   error vanishes. Replacing the µs-long ramp by a step changes the current by < 1e-3 A
//!   (slope Vdc/L times < Td); every other step is exact.
//! * [`InverterModel::Averaged`]: per sample, the average pole voltages
//!   `d·Vdc − (Td·f_sw·Vdc + V_th)·sat(i/Ic)` (docs/method/estimator.md §7), with i the phase current at the sample
//!   start, applied as a constant voltage over the sample (integrated exactly). No ripple.
//!
//! Both models add the device threshold drop `−V_th·sat(i/Ic)` to each pole (IGBT and diode
//! taken alike) and a linear on-resistance r_on in series with each phase (it adds to Rs).
//! With the gates disabled (a trip) the poles follow the freewheeling diodes (2 µs sub-steps);
//! when all currents have decayed to within one sub-step's change and the line back-EMF is
//! below Vdc, the diodes block and the currents stay zero.

use fado_core::{Ab, Abc, Dq};
use serde::{Deserialize, Serialize};

use crate::error::{SimConfigError, check};
use crate::motor::{ElectricalPropagator, Motor};

/// How the inverter is simulated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InverterModel {
    /// Every switching edge resolved, dead time acting on each edge (reference model).
    #[default]
    SwitchingResolved,
    /// Per-sample average pole voltages with the docs/method/estimator.md §7 error model (fast).
    Averaged,
}

/// How the pole voltage commutates during the dead time when the phase current helps the
/// transition (switching-resolved model). With the current opposing, the pole always waits Td.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Commutation {
    /// Equivalent delay `Td·(1 − |i|/Ic)` for |i| < Ic, 0 above: each edge loses exactly
    /// `Td·sat(i/Ic)` volt-seconds per volt, the docs/method/estimator.md §7 error curve resolved edge by edge with
    /// the instantaneous current (ripple included). Default.
    #[default]
    LinearBand,
    /// A linear pole capacitance `C = Ic·Td/(2·Vdc)` slewed by the current: same slope at zero
    /// current, but the error approaches its full value only as `1 − Ic/(4|i|)` (a tail the
    /// docs/method/estimator.md §7 compensation does not model: ≈ 0.06 V residual at 14 A, 0.2 V at 4 A).
    Capacitor,
}

/// Inverter and DC-link parameter record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InverterParams {
    /// Which model to run. Default switching-resolved.
    pub model: InverterModel,
    /// Mean DC-link voltage in V. Default 311 V (rectified 3-phase 220 Vrms, paper §V \[P\];
    /// docs/method/estimator.md §7 says ≈ 300 V \[A\]).
    pub dc_voltage: f64,
    /// Peak amplitude of the DC-link ripple in V (sinusoidal model). Default 0 \[A\].
    pub dc_ripple_amplitude: f64,
    /// Ripple frequency in Hz. Default 360 Hz (6-pulse rectifier on 60 Hz) \[A\].
    pub dc_ripple_frequency: f64,
    /// Switching (carrier) frequency in Hz; sampling is at twice this. Default 5 kHz (paper §V
    /// \[P\]).
    pub switching_frequency: f64,
    /// Dead time Td in s. Default 2.5 µs (paper §V \[P\]).
    pub dead_time: f64,
    /// Current band Ic in A over which the dead-time and threshold errors go through zero
    /// (parasitic capacitance). Default 0.3 A (docs/method/estimator.md §7 \[A\]).
    pub current_band: f64,
    /// Commutation model of the helping edge (switching-resolved model). Default the docs/method/estimator.md §7
    /// linear band.
    pub commutation: Commutation,
    /// Device threshold (knee) voltage V_th in V, IGBT and diode alike. Default 1 V (docs/method/estimator.md §7 \[A\]).
    pub threshold_voltage: f64,
    /// Device on-resistance r_on in Ω. Default 0 \[A\]: a linear drop is indistinguishable from
    /// Rs, so a non-zero value is an R̂s mismatch of the same size.
    pub on_resistance: f64,
}

impl Default for InverterParams {
    fn default() -> Self {
        Self {
            model: InverterModel::SwitchingResolved,
            dc_voltage: 311.0,
            dc_ripple_amplitude: 0.0,
            dc_ripple_frequency: 360.0,
            switching_frequency: 5000.0,
            dead_time: 2.5e-6,
            current_band: 0.3,
            commutation: Commutation::LinearBand,
            threshold_voltage: 1.0,
            on_resistance: 0.0,
        }
    }
}

impl InverterParams {
    /// Checks every field; the error names the key.
    pub fn validate(&self) -> Result<(), SimConfigError> {
        check::positive("dc_voltage", self.dc_voltage)?;
        check::in_range(
            "dc_ripple_amplitude",
            self.dc_ripple_amplitude,
            0.0,
            0.5 * self.dc_voltage,
        )?;
        check::non_negative("dc_ripple_frequency", self.dc_ripple_frequency)?;
        check::in_range("switching_frequency", self.switching_frequency, 100.0, 1e6)?;
        let half_period = 0.5 / self.switching_frequency;
        check::in_range("dead_time", self.dead_time, 0.0, 0.25 * half_period)?;
        check::positive("current_band", self.current_band)?;
        check::non_negative("threshold_voltage", self.threshold_voltage)?;
        check::non_negative("on_resistance", self.on_resistance)?;
        Ok(())
    }

    /// Sampling period Ts = 1/(2·f_sw) (double update).
    pub fn sample_period(&self) -> f64 {
        0.5 / self.switching_frequency
    }

    /// DC-link voltage at time `t`.
    pub fn dc_voltage_at(&self, t: f64) -> f64 {
        if self.dc_ripple_amplitude == 0.0 {
            return self.dc_voltage;
        }
        self.dc_voltage
            + self.dc_ripple_amplitude
                * (std::f64::consts::TAU * self.dc_ripple_frequency * t).cos()
    }

    /// Equivalent pole capacitance C = Ic·Td/(2·Vdc) of [`Commutation::Capacitor`].
    pub fn pole_capacitance(&self) -> f64 {
        self.current_band * self.dead_time / (2.0 * self.dc_voltage)
    }

    /// Delay from the gate command to the equivalent pole-voltage step for one edge
    /// (switching-resolved model, see the module docs). `rising` = low → high, `i` the phase
    /// current (positive out of the inverter) at the edge, `vdc` the DC-link voltage.
    pub fn edge_delay(&self, rising: bool, i: f64, vdc: f64) -> f64 {
        let td = self.dead_time;
        let opposes = if rising { i > 0.0 } else { i < 0.0 };
        if opposes || td == 0.0 {
            return td;
        }
        let ia = i.abs();
        match self.commutation {
            Commutation::LinearBand => td * (1.0 - ia / self.current_band).max(0.0),
            Commutation::Capacitor => {
                // Ramp time t_r = C·Vdc/|i|; compare Td/t_r = Td·|i|/(C·Vdc).
                let ratio = td * ia / (self.pole_capacitance() * vdc);
                if ratio <= 1.0 {
                    td * (1.0 - 0.5 * ratio)
                } else {
                    0.5 * td / ratio
                }
            }
        }
    }

    /// Average pole-voltage error of the averaged model for phase current `i` (docs/method/estimator.md §7):
    /// −(Td·f_sw·Vdc + V_th)·sat(i/Ic).
    pub fn averaged_error(&self, i: f64, vdc: f64) -> f64 {
        -(self.dead_time * self.switching_frequency * vdc + self.threshold_voltage)
            * sat(i / self.current_band)
    }
}

#[inline]
fn sat(x: f64) -> f64 {
    x.clamp(-1.0, 1.0)
}

#[inline]
fn phase_currents(i_ab: Ab<f64>) -> [f64; 3] {
    const K: f64 = 0.866_025_403_784_438_6;
    [
        i_ab.alpha,
        -0.5 * i_ab.alpha + K * i_ab.beta,
        -0.5 * i_ab.alpha - K * i_ab.beta,
    ]
}

/// Clarke transform of three pole voltages (zero sequence dropped: the star point floats).
#[inline]
fn clarke(p: [f64; 3]) -> Ab<f64> {
    const INV_SQRT3: f64 = 0.577_350_269_189_625_8;
    Ab::new(
        (2.0 * p[0] - p[1] - p[2]) * (1.0 / 3.0),
        INV_SQRT3 * (p[1] - p[2]),
    )
}

use crate::fastmath::{cis, rotate, unrotate};

/// One inverter leg of the switching-resolved model.
#[derive(Clone, Copy, Debug)]
struct Leg {
    /// Gate command: upper device commanded on.
    gate: bool,
    /// Pole voltage state outside transitions: connected to the positive rail.
    pole: bool,
    /// Time (from the present sample start) at which the pole follows the gate; ∞ if none.
    pending: f64,
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

/// What one sample of the plant did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SampleOutcome {
    /// Time average of the electromagnetic torque over the sample, N·m.
    pub torque_avg: f64,
    /// Time average of the stator voltage actually applied over the sample (α-β), V.
    pub v_ab_avg: Ab<f64>,
    /// Number of constant-switch-state intervals integrated.
    pub intervals: u32,
}

/// The inverter: parameters, duty shadow register and leg states.
#[derive(Clone, Debug)]
pub struct Inverter {
    params: InverterParams,
    ts: f64,
    inv_current_band: f64,
    /// Duty loaded at the last update, acting over the present sample.
    shadow: Abc<f64>,
    legs: [Leg; 3],
    /// Sample counter: even samples see a falling carrier (peak → valley).
    sample: u64,
    /// DC-link voltage as a fraction of its nominal value (fault injection, a supply dip).
    dc_link_scale: f64,
    /// The bus voltage of a DC link that is not stiff (`crate::dc_link`), V; `None`: the
    /// source's.
    bus_voltage: Option<f64>,
    /// Subtracted from the applied α-β voltage while the gates are enabled (fault injection,
    /// `[faults] voltage_offset`: the drive's voltage is this much above the true one), V.
    voltage_offset: Ab<f64>,
}

impl Inverter {
    /// An inverter with all legs low and a 50 % duty in the shadow register.
    pub fn new(params: InverterParams) -> Result<Self, SimConfigError> {
        params.validate()?;
        let ts = params.sample_period();
        Ok(Self {
            inv_current_band: 1.0 / params.current_band,
            params,
            ts,
            shadow: Abc::new(0.5, 0.5, 0.5),
            legs: [Leg::default(); 3],
            sample: 0,
            dc_link_scale: 1.0,
            bus_voltage: None,
            voltage_offset: Ab::zero(),
        })
    }

    /// Parameters.
    pub fn params(&self) -> &InverterParams {
        &self.params
    }

    /// Sampling period Ts in s.
    pub fn sample_period(&self) -> f64 {
        self.ts
    }

    /// Time of the present sample start in s.
    pub fn time(&self) -> f64 {
        self.sample as f64 * self.ts
    }

    /// DC-link voltage over the present sample (with the dip of
    /// [`set_dc_link_scale`](Self::set_dc_link_scale)).
    pub fn dc_voltage(&self) -> f64 {
        match self.bus_voltage {
            Some(v) => v,
            None => self.source_voltage(),
        }
    }

    /// Voltage of the DC source over the present sample (nominal, ripple, the dip of
    /// [`set_dc_link_scale`](Self::set_dc_link_scale)), V: the bus voltage of a stiff link.
    pub fn source_voltage(&self) -> f64 {
        self.params.dc_voltage_at(self.time()) * self.dc_link_scale
    }

    /// Sets the bus voltage the inverter switches from the present sample on (a DC link
    /// with a capacitor, `crate::dc_link`).
    pub fn set_bus_voltage(&mut self, v: f64) {
        self.bus_voltage = Some(v);
    }

    /// Scales the DC-link voltage from the present sample on (1 = nominal; a supply dip of
    /// `crate::faults`).
    pub fn set_dc_link_scale(&mut self, scale: f64) {
        self.dc_link_scale = scale;
    }

    /// A constant α-β voltage error: while the gates are enabled the machine receives the
    /// inverter's voltage minus `offset`, so the drive's (and its estimator's) voltage is the
    /// true one plus `offset` (`crate::faults`). With the gates off nothing changes.
    pub fn set_voltage_offset(&mut self, offset: Ab<f64>) {
        self.voltage_offset = offset;
    }

    /// Runs one sample [n, n+1]: the duty loaded at the previous update acts now, and
    /// `duty_next` (computed by the controller at n) is loaded for [n+1, n+2]. `gates_enabled`
    /// acts at once (a hardware trip does not wait for the update). `omega` is the speed held
    /// over the sample; the motor's current is advanced, its angle is not (see
    /// [`Motor::advance_mechanical`]).
    pub fn step(
        &mut self,
        motor: &mut Motor,
        duty_next: Abc<f64>,
        gates_enabled: bool,
    ) -> SampleOutcome {
        let duty = self.shadow;
        self.shadow = Abc::new(
            sanitize(duty_next.a),
            sanitize(duty_next.b),
            sanitize(duty_next.c),
        );
        let vdc = self.dc_voltage();
        let r = motor.params().rs + self.params.on_resistance;
        let prop = motor.propagator(r);
        let falling = self.sample.is_multiple_of(2);
        let out = if !gates_enabled {
            self.step_diodes(motor, &prop, vdc)
        } else {
            match self.params.model {
                InverterModel::SwitchingResolved => {
                    self.step_switching(motor, &prop, duty, vdc, falling)
                }
                InverterModel::Averaged => self.step_averaged(motor, &prop, duty, vdc),
            }
        };
        self.sample += 1;
        out
    }

    #[inline]
    fn pole_voltages(&self, poles: [bool; 3], i: [f64; 3], vdc: f64) -> Ab<f64> {
        let vth = self.params.threshold_voltage;
        let inv_ic = self.inv_current_band;
        let mut p = [0.0; 3];
        for k in 0..3 {
            p[k] = if poles[k] { vdc } else { 0.0 } - vth * sat(i[k] * inv_ic);
        }
        clarke(p)
    }

    fn step_averaged(
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
            p[k] = d[k] * vdc + self.params.averaged_error(iph[k], vdc);
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

    fn step_switching(
        &mut self,
        motor: &mut Motor,
        prop: &ElectricalPropagator,
        duty: Abc<f64>,
        vdc: f64,
        falling: bool,
    ) -> SampleOutcome {
        let ts = self.ts;
        // Gate edges of this half carrier period, sorted: (time, leg, new gate state).
        let mut edges = [(0.0_f64, 0_u8, false); 6];
        let mut n_edges = 0;
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
            if start != self.legs[k].gate {
                edges[n_edges] = (0.0, k as u8, start);
                n_edges += 1;
            }
            if let Some((t, g)) = edge {
                edges[n_edges] = (t, k as u8, g);
                n_edges += 1;
            }
        }
        let edges = &mut edges[..n_edges];
        // Insertion sort (≤ 6 entries), stable so that a leg's t = 0 edge stays first.
        for a in 1..edges.len() {
            let mut b = a;
            while b > 0 && edges[b - 1].0 > edges[b].0 {
                edges.swap(b - 1, b);
                b -= 1;
            }
        }

        let mp = *motor.params();
        let omega = prop.omega();
        let mut rot = motor.rotation();
        // The current is carried in α-β (phase currents at every edge), d-q only at the end.
        let mut i = rotate(motor.state().i_dq, rot);
        let mut iph = phase_currents(i);
        let mut te_prev = prop.torque_dq(&mp, motor.state().i_dq);
        let mut t = 0.0;
        let mut next_edge = 0;
        let (mut te_int, mut v_int) = (0.0, Ab::zero());
        let mut intervals = 0;
        // Bound on |di_x/dt|: phase voltage ≤ 2/3·Vdc plus drops, back-EMF ≤ ω·λf. An edge whose
        // current certainly keeps its sign until the edge, and opposes it, waits exactly Td
        // whatever the current's value: no need to stop the integration at the edge itself.
        let l_min = prop.min_inductance(&mp);
        let i_bound = i.norm() + 2.0 * vdc * ts / l_min;
        let slew = (2.0 / 3.0 * vdc
            + 2.0 * self.params.threshold_voltage
            + omega.abs() * prop.flux_bound(&mp, i_bound)
            + (mp.rs + self.params.on_resistance) * i_bound)
            / l_min;
        loop {
            while let Some(&(te, k, g)) = edges.get(next_edge) {
                let k = k as usize;
                let margin = slew * (te - t);
                let opposing = if g {
                    iph[k] - margin > 0.0
                } else {
                    iph[k] + margin < 0.0
                };
                if !opposing || te >= ts {
                    break;
                }
                next_edge += 1;
                let leg = &mut self.legs[k];
                leg.gate = g;
                leg.pending = if leg.pole == g {
                    f64::INFINITY
                } else {
                    te + self.params.dead_time
                };
            }
            let edge_t = edges.get(next_edge).map_or(f64::INFINITY, |e| e.0);
            let (mut pend_t, mut pend_leg) = (f64::INFINITY, 0);
            for (k, leg) in self.legs.iter().enumerate() {
                if leg.pending < pend_t {
                    (pend_t, pend_leg) = (leg.pending, k);
                }
            }
            let t_next = edge_t.min(pend_t).min(ts);
            let h = t_next - t;
            if h > 0.0 {
                let poles = [self.legs[0].pole, self.legs[1].pole, self.legs[2].pole];
                let v = self.pole_voltages(poles, iph, vdc) - self.voltage_offset;
                let rot_h = cis(omega * h);
                i = prop.advance_ab(i, v, h, rot, rot_h);
                rot *= rot_h;
                iph = phase_currents(i);
                let te = prop.torque_ab(&mp, i, rot);
                te_int += 0.5 * (te_prev + te) * h;
                te_prev = te;
                v_int += v * h;
                intervals += 1;
                t = t_next;
            }
            if t_next >= ts && edge_t >= ts && pend_t >= ts {
                break;
            }
            if pend_t <= edge_t {
                let leg = &mut self.legs[pend_leg];
                leg.pole = leg.gate;
                leg.pending = f64::INFINITY;
            } else {
                let (_, k, g) = edges[next_edge];
                next_edge += 1;
                let k = k as usize;
                let delay = self.params.edge_delay(g, iph[k], vdc);
                let leg = &mut self.legs[k];
                leg.gate = g;
                if leg.pole == g {
                    // A pulse shorter than the transition: the pole never left.
                    leg.pending = f64::INFINITY;
                } else if delay <= 0.0 {
                    leg.pole = g;
                    leg.pending = f64::INFINITY;
                } else {
                    leg.pending = t + delay;
                }
            }
        }
        let i = unrotate(i, rot);
        for leg in &mut self.legs {
            leg.pending -= ts; // ∞ stays ∞
        }
        motor.set_current_from(prop, i);
        SampleOutcome {
            torque_avg: te_int / ts,
            v_ab_avg: v_int * (1.0 / ts),
            intervals,
        }
    }

    fn step_diodes(
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

fn sanitize(d: f64) -> f64 {
    if d.is_finite() {
        d.clamp(0.0, 1.0)
    } else {
        0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motor::MotorParams;

    fn ideal() -> InverterParams {
        InverterParams {
            dead_time: 0.0,
            threshold_voltage: 0.0,
            ..Default::default()
        }
    }

    fn motor_with(i_dq: Dq<f64>, theta: f64, omega_mech: f64) -> Motor {
        let mut m = Motor::new(MotorParams::paper(), 0.0).unwrap();
        m.set_state(i_dq, theta, omega_mech);
        m
    }

    #[test]
    fn ideal_pwm_volt_seconds_equal_the_reference_every_half_period() {
        let mut m = motor_with(Dq::new(1.0, 3.0), 0.4, 20.0);
        let mut inv = Inverter::new(ideal()).unwrap();
        let duties = [
            Abc::new(0.5, 0.5, 0.5),
            Abc::new(0.9, 0.1, 0.37),
            Abc::new(0.02, 0.98, 0.5),
            Abc::new(1.0, 0.0, 0.6),
            Abc::new(0.3, 0.7, 0.45),
            Abc::new(0.61, 0.22, 0.0),
        ];
        let vdc = inv.params().dc_voltage;
        let mut loaded = Abc::new(0.5, 0.5, 0.5);
        for (k, d) in duties.iter().cycle().take(24).enumerate() {
            let out = inv.step(&mut m, *d, true);
            let expect = clarke([loaded.a * vdc, loaded.b * vdc, loaded.c * vdc]);
            let err = (out.v_ab_avg - expect).norm();
            assert!(err < 1e-9, "sample {k}: {:?} vs {expect:?}", out.v_ab_avg);
            m.advance_mechanical(inv.sample_period(), out.torque_avg, 0.0);
            loaded = *d;
        }
    }

    #[test]
    fn synchronous_sampling_sees_the_average_current() {
        // Ideal inverter: at carrier peaks and valleys the switching-resolved current equals
        // the averaged model's to within a small fraction of the ripple (several A p-p).
        let run = |model| {
            let mut m = motor_with(Dq::new(0.0, 5.0), 0.0, 10.0);
            let mut inv = Inverter::new(InverterParams { model, ..ideal() }).unwrap();
            let mut out = Vec::new();
            for n in 0..400 {
                let th = 0.2 + n as f64 * 0.01;
                let d = Abc::new(
                    0.5 + 0.2 * th.cos(),
                    0.5 + 0.2 * (th - 2.094).cos(),
                    0.5 + 0.2 * (th + 2.094).cos(),
                );
                let o = inv.step(&mut m, d, true);
                m.advance_mechanical(inv.sample_period(), o.torque_avg, 0.0);
                out.push(m.state().i_dq);
            }
            out
        };
        let a = run(InverterModel::SwitchingResolved);
        let b = run(InverterModel::Averaged);
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (*x - *y).norm())
            .fold(0.0, f64::max);
        assert!(worst < 0.05, "max |Δi| = {worst} A");
    }

    fn period_average_voltage(
        model: InverterModel,
        commutation: Commutation,
        i_dq: Dq<f64>,
        vth: f64,
    ) -> Ab<f64> {
        let p = InverterParams {
            model,
            commutation,
            threshold_voltage: vth,
            ..Default::default()
        };
        let mut inv = Inverter::new(p).unwrap();
        let mut m = motor_with(i_dq, 0.0, 0.0);
        let mut acc = Ab::zero();
        for n in 0..6 {
            m.set_state(i_dq, 0.0, 0.0); // hold the current: isolate the voltage error
            let o = inv.step(&mut m, Abc::new(0.5, 0.5, 0.5), true);
            if n >= 2 {
                acc += o.v_ab_avg * 0.25;
            }
        }
        acc
    }

    #[test]
    fn dead_time_error_opposes_the_current_with_td_fsw_vdc() {
        // Phase currents (10, −5, −5) A, well outside Ic and the ripple: each pole loses
        // Td·f_sw·Vdc·g(|i|) in the current's direction; g = 1 for the linear band, and
        // g = 1 − Ic/(4|i|) for the capacitor's slew of the helping edge.
        let p = InverterParams::default();
        let full = p.dead_time * p.switching_frequency * p.dc_voltage; // 3.89 V
        let g_cap = |i: f64| 1.0 - p.current_band / (4.0 * i);
        for sign in [1.0, -1.0] {
            let i = Dq::new(10.0 * sign, 0.0);
            let sw = InverterModel::SwitchingResolved;
            let v = period_average_voltage(sw, Commutation::LinearBand, i, 0.0);
            let expect = -sign * full * 4.0 / 3.0;
            assert!((v.alpha - expect).abs() < 1e-9 * full, "{v:?} vs {expect}");
            assert!(v.beta.abs() < 1e-9);
            let v = period_average_voltage(sw, Commutation::Capacitor, i, 0.0);
            let expect = -sign * full * (2.0 * g_cap(10.0) + 2.0 * g_cap(5.0)) / 3.0;
            assert!((v.alpha - expect).abs() < 1e-3 * full, "{v:?} vs {expect}");
            // The averaged model: −(Td·f_sw·Vdc + V_th)·sat(i/Ic) per pole.
            let va =
                period_average_voltage(InverterModel::Averaged, Commutation::LinearBand, i, 1.0);
            let expect = -sign * (full + 1.0) * 4.0 / 3.0;
            assert!((va.alpha - expect).abs() < 1e-9, "{va:?} vs {expect}");
        }
    }

    #[test]
    fn dead_time_error_goes_through_zero_smoothly_and_monotonically() {
        for commutation in [Commutation::LinearBand, Commutation::Capacitor] {
            let p = InverterParams {
                commutation,
                ..Default::default()
            };
            let vdc = p.dc_voltage;
            let full = p.dead_time * p.switching_frequency * vdc;
            let ic = p.current_band;
            // Error of the high time per carrier period, as a pole-voltage average.
            let err = |i: f64| {
                -(p.edge_delay(true, i, vdc) - p.edge_delay(false, i, vdc))
                    * p.switching_frequency
                    * vdc
            };
            assert_eq!(err(0.0), 0.0);
            let mut prev = f64::INFINITY;
            for k in -400..=400 {
                let i = k as f64 * 0.01;
                let e = err(i);
                assert!(e <= prev + 1e-15, "{commutation:?}: not monotone at {i}");
                assert!(
                    (e + err(-i)).abs() < 1e-12,
                    "{commutation:?}: not odd at {i}"
                );
                assert!(e.abs() <= full);
                prev = e;
            }
            // Slope at zero equals the averaged model's −full/Ic; half the error at Ic/2.
            let slope = (err(1e-4) - err(-1e-4)) / 2e-4;
            assert!(
                (slope + full / ic).abs() < 1e-6 * full / ic,
                "{commutation:?}"
            );
            assert!((err(ic / 2.0) + full / 2.0).abs() < 1e-9, "{commutation:?}");
            assert!((err(40.0) + full).abs() < 0.01 * full, "{commutation:?}");
            if commutation == Commutation::LinearBand {
                // Exactly the docs/method/estimator.md §7 curve −Td·f_sw·Vdc·sat(i/Ic).
                for i in [-2.0, -0.2, 0.1, 0.29, 0.31, 3.0] {
                    assert!((err(i) + full * (i / ic).clamp(-1.0, 1.0)).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn gates_off_decays_the_current_and_then_blocks() {
        let mut m = motor_with(Dq::new(0.0, 10.0), 0.3, 5.0);
        let mut inv = Inverter::new(InverterParams::default()).unwrap();
        for _ in 0..200 {
            let o = inv.step(&mut m, Abc::new(0.5, 0.5, 0.5), false);
            m.advance_mechanical(inv.sample_period(), o.torque_avg, 0.0);
        }
        assert_eq!(m.state().i_dq, Dq::zero());
    }

    /// Period-average α-β voltage error (applied − reference) of the switching-resolved
    /// inverter at standstill with phase currents `i_abc` (sum 0), reference R·i (the
    /// standstill steady state) plus the drive's dead-time compensation `method`, min-max
    /// zero sequence. The current starts each carrier period at the peak sample i − Δ/2 so
    /// that the peak and valley samples average to i (Δ = their measured swing).
    fn standstill_compensation_error(
        method: fado_core::control::DeadTimeMethod,
        mp: MotorParams,
        theta: f64,
        i_abc: [f64; 3],
    ) -> Ab<f64> {
        use fado_core::control::{DeadTimeCompensation, DeadTimeCompensationConfig};
        let p = InverterParams::default();
        let comp = DeadTimeCompensation::new(DeadTimeCompensationConfig {
            enabled: true,
            method,
            dead_time: p.dead_time,
            switching_frequency: p.switching_frequency,
            threshold_voltage: p.threshold_voltage,
            current_band: p.current_band,
            ripple_inductance: Dq::new(mp.ld, mp.lq),
        })
        .unwrap();
        let vdc = p.dc_voltage;
        let i_ab = clarke(i_abc);
        let v_ref = i_ab * mp.rs;
        let rot = fado_core::Rotation::from_angle(theta);
        let i_dq = i_ab.to_dq(rot);
        let c = comp.phase_voltages(rot, i_dq, Abc::default(), v_ref, vdc);
        let v = v_ref.to_abc();
        let pole = [v.a + c.a, v.b + c.b, v.c + c.c];
        let v0 = -0.5 * (pole[0].max(pole[1]).max(pole[2]) + pole[0].min(pole[1]).min(pole[2]));
        let duty = Abc::new(
            0.5 + (pole[0] + v0) / vdc,
            0.5 + (pole[1] + v0) / vdc,
            0.5 + (pole[2] + v0) / vdc,
        );
        let mut inv = Inverter::new(p).unwrap();
        let mut m = Motor::new(mp, 0.0).unwrap();
        m.set_state(i_dq, theta, 0.0);
        inv.step(&mut m, duty, true); // load the duty
        inv.step(&mut m, duty, true); // now at a carrier peak
        let mut start = i_dq;
        let mut err = Ab::zero();
        for _ in 0..3 {
            m.set_state(start, theta, 0.0);
            let a = inv.step(&mut m, duty, true);
            let valley = m.state().i_dq;
            let b = inv.step(&mut m, duty, true);
            err = (a.v_ab_avg + b.v_ab_avg) * 0.5 - v_ref;
            start = i_dq - (valley - start) * 0.5;
        }
        err
    }

    #[test]
    fn edge_current_compensation_matches_the_switching_resolved_error_in_the_band() {
        // Standstill under ≈ 12 A, phase b's current swept through the band Ic = 0.3 A (the
        // restart of `stops`). The paper's round rotor: the trapezoid on the average current
        // leaves up to 0.64 V on phase b (measured: the ripple moves its helping edge's
        // current away from zero, the peak-valley swing towards it); the edge-current
        // prediction < 0.1 V (0.097). A salient rotor (0.37/1.2 mH as ipmsm-gem-50k) at
        // 0.4 rad, ripple ≈ 7× larger: trapezoid 1.12 V, edge current 0.84 V — only a little
        // better: there the peak-valley swing's dependence on the phase's own edge delay has
        // a loop gain Vdc·Td/(6·L̂·Ic) ≈ 1.2 > 1, the two-pass prediction does not converge
        // (docs/method/additions.md). Outside the band both are exact.
        use fado_core::control::DeadTimeMethod;
        let salient = MotorParams {
            rs: 0.018,
            ld: 0.37e-3,
            lq: 1.2e-3,
            ..MotorParams::paper()
        };
        for (mp, theta, trap_min, edge_max) in [
            (MotorParams::paper(), 0.0, 0.5, 0.12),
            (salient, 0.4, 1.0, 0.9),
        ] {
            let (mut worst_trap, mut worst_edge) = (0.0_f64, 0.0_f64);
            for k in -8..=8 {
                let ib = k as f64 * 0.05;
                let i_abc = [-12.2 - 0.5 * ib, ib, 12.2 - 0.5 * ib];
                // Phase b's share of the α-β error: 1.5·(e·u_b).
                let on_b = |e: Ab<f64>| 1.5 * (-0.5 * e.alpha + 0.866_025_403_784_438_6 * e.beta);
                let err = |m| on_b(standstill_compensation_error(m, mp, theta, i_abc));
                let (trap, edge) = (
                    err(DeadTimeMethod::Trapezoidal),
                    err(DeadTimeMethod::EdgeCurrent),
                );
                if ib.abs() > 0.3 {
                    assert!(
                        trap.abs() < 0.02 && edge.abs() < 0.02,
                        "{ib}: {trap} {edge}"
                    );
                }
                worst_trap = worst_trap.max(trap.abs());
                worst_edge = worst_edge.max(edge.abs());
            }
            assert!(
                worst_trap > trap_min,
                "trapezoid's worst in-band error {worst_trap} V"
            );
            assert!(
                worst_edge < edge_max,
                "edge-current's worst in-band error {worst_edge} V"
            );
        }
    }

    #[test]
    fn validation_names_the_key() {
        let p = InverterParams {
            dead_time: 1e-3,
            ..Default::default()
        };
        assert_eq!(p.validate().unwrap_err().key, "dead_time");
        let p = InverterParams {
            dc_voltage: f64::NAN,
            ..Default::default()
        };
        assert_eq!(p.validate().unwrap_err().key, "dc_voltage");
    }
}
