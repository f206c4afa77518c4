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

mod averaged;
mod diodes;
mod params;
mod switching;
#[cfg(test)]
mod tests;

use fado_core::{Ab, Abc};
use serde::{Deserialize, Serialize};

use crate::error::SimConfigError;
use crate::motor::Motor;

pub use params::InverterParams;
use switching::Leg;

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
}

/// A duty clamped to [0, 1]; a non-finite one is 0.5.
fn sanitize(d: f64) -> f64 {
    if d.is_finite() {
        d.clamp(0.0, 1.0)
    } else {
        0.5
    }
}
