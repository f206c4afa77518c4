//! The whole drive in the interrupt: `SensorlessDrive<f32>` (Clarke/Park, current and speed
//! control, fado's estimator, dead-time compensation, modulation) stepped through
//! [`crate::drive_step`] around a simulated motor, so that the cost script measures what a
//! complete sensorless FOC interrupt costs on a Cortex-M4F, not the estimator alone
//! (docs/results/firmware-cost.md).
//!
//! The motor is the paper's (surface magnets, Ld = Lq, `MachineModel::paper()`), simulated in
//! `f32` in its stator flux: dλ/dt = v − Rs·i, i = (λ − λf·e^{jθ})/L, with the mechanical
//! equation J·dω/dt = T − T_L − B·ω, T = 1.5·p·λf·i_q, and an inverter whose pole voltages are
//! duty·Vdc less the dead-time error (Td·fsw·Vdc + the device threshold, trapezoidal in the
//! current over the compensation's band: the inverter the drive's compensation assumes).
//! Second-order Runge–Kutta, 10 substeps per sample; the duty computed at sample n acts over
//! [n + 1, n + 2], as on a real PWM timer. The same model, in `f64`, is fado-core's
//! `sensorless_closed_loop_follows_a_speed_ramp_under_load` test.

use core::f32::consts::TAU;

use fado_core::{Ab, Abc, DriveConfig, EstimatorTuning, MachineModel, SensorlessDrive};

use crate::{cos, sin, wrap};

/// The operating point: 0 → 300 r/min in `RAMP_S`, with a load of `LOAD_RATIO` × the rated
/// torque from `LOAD_AT_S` on, to `END_S` (short: the cost script traces every drive step, and
/// CI runs it through the README's docs test).
pub const SPEED_RPM: f32 = 300.0;
const RAMP_S: f32 = 0.2;
const LOAD_AT_S: f32 = 0.1;
pub const LOAD_RATIO: f32 = 0.3;
const END_S: f32 = 0.5;
/// Substeps of the motor's integration per sample.
const SUBSTEPS: u32 = 10;

/// The simulated motor and inverter (not part of a firmware: the stand-in for the power
/// stage, the ADC and the load machine).
#[derive(Clone, Copy)]
struct Motor {
    lambda: Ab<f32>,
    theta: f32,
    omega_mech: f32,
    rs: f32,
    l: f32,
    flux_linkage: f32,
    pole_pairs: f32,
    inertia: f32,
    friction: f32,
    vdc: f32,
    /// Dead-time error amplitude (V) and the current band it ramps over (A).
    dead_time_error: f32,
    band: f32,
}

impl Motor {
    /// The current of flux `lambda` at rotor angle `theta`.
    fn current_at(&self, lambda: Ab<f32>, theta: f32) -> Ab<f32> {
        let magnet = Ab::new(cos(theta), sin(theta)) * self.flux_linkage;
        (lambda - magnet) * (1.0 / self.l)
    }

    fn current(&self) -> Ab<f32> {
        self.current_at(self.lambda, self.theta)
    }

    /// dλ/dt, dθ/dt, dω/dt at the state (λ, θ, ω) (passed apart: copying the whole record
    /// would be a `memcpy` call, a function the drive's step shares, see `on_sample`).
    fn derivative(
        &self,
        (lambda, theta, omega_mech): (Ab<f32>, f32, f32),
        duty: Abc<f32>,
        load: f32,
    ) -> (Ab<f32>, f32, f32) {
        let i = self.current_at(lambda, theta);
        let i_abc = i.to_abc();
        let err = |ix: f32| self.dead_time_error * (ix / self.band).clamp(-1.0, 1.0);
        let pole = Abc::new(
            duty.a * self.vdc - err(i_abc.a),
            duty.b * self.vdc - err(i_abc.b),
            duty.c * self.vdc - err(i_abc.c),
        );
        let v = pole.to_ab();
        let iq = i.beta * cos(theta) - i.alpha * sin(theta);
        let torque = 1.5 * self.pole_pairs * self.flux_linkage * iq;
        (
            v - i * self.rs,
            self.pole_pairs * omega_mech,
            (torque - load - self.friction * omega_mech) / self.inertia,
        )
    }

    fn advance(&mut self, duty: Abc<f32>, load: f32, ts: f32) {
        let h = ts / SUBSTEPS as f32;
        for _ in 0..SUBSTEPS {
            let now = (self.lambda, self.theta, self.omega_mech);
            let (dl, dth, dw) = self.derivative(now, duty, load);
            let mid = (
                self.lambda + dl * (0.5 * h),
                wrap(self.theta + 0.5 * h * dth),
                self.omega_mech + 0.5 * h * dw,
            );
            let (dl, dth, dw) = self.derivative(mid, duty, load);
            self.lambda += dl * h;
            self.theta = wrap(self.theta + h * dth);
            self.omega_mech += h * dw;
        }
    }
}

/// What the run records ([`DriveApp::result`]).
#[derive(Clone, Copy)]
pub struct DriveResult {
    /// Worst |θ̂ − θ| (rad) over the start (to the end of the ramp) and over the last 0.1 s.
    pub worst_start: f32,
    pub worst_end: f32,
    /// Speed at the end (r/min).
    pub speed_rpm: f32,
    pub tripped: bool,
    pub input_faults: u32,
}

/// The drive, its motor and what the run records.
pub struct DriveApp {
    drive: SensorlessDrive<f32>,
    motor: Motor,
    /// The duty computed last sample: it acts over the next interval.
    pending: Abc<f32>,
    rated_torque: f32,
    ts: f32,
    samples: u32,
    total_samples: u32,
    worst_start: f32,
    worst_end: f32,
    speed_rpm: f32,
    tripped: bool,
    input_faults: u32,
    pub done: bool,
}

impl DriveApp {
    /// The drive with its default tuning around the paper's motor, without the start-up
    /// offset and gain calibrations and the stuck-sensor check (this motor's sensors are
    /// ideal), aligned to the rotor at rest; `None` if the configuration is refused.
    pub fn new() -> Option<Self> {
        let model = MachineModel::<f32>::paper();
        let mut config = DriveConfig::for_machine(&model);
        config.tuning.offset_calibration.time = 0.0;
        config.tuning.gain_calibration.time = 0.0;
        config.tuning.stuck_sensor.time = 0.0;
        let t = config.tuning;
        let ts = config.ts;
        let mut drive = SensorlessDrive::new(config, EstimatorTuning::default()).ok()?;
        let theta0 = 0.7;
        drive.align(theta0);
        let motor = Motor {
            lambda: Ab::new(cos(theta0), sin(theta0)) * model.flux_linkage,
            theta: theta0,
            omega_mech: 0.0,
            rs: model.rs,
            l: model.lq,
            flux_linkage: model.flux_linkage,
            pole_pairs: model.pole_pairs as f32,
            inertia: model.inertia,
            friction: model.viscous_friction,
            vdc: model.dc_voltage,
            dead_time_error: t.inverter.dead_time
                * t.inverter.switching_frequency
                * model.dc_voltage
                + t.inverter.threshold_voltage,
            band: t.inverter.current_band,
        };
        Some(Self {
            drive,
            motor,
            pending: Abc::new(0.5, 0.5, 0.5),
            rated_torque: model.rated_torque,
            ts,
            samples: 0,
            total_samples: (END_S / ts) as u32,
            worst_start: 0.0,
            worst_end: 0.0,
            speed_rpm: 0.0,
            tripped: false,
            input_faults: 0,
            done: false,
        })
    }

    /// What the run recorded.
    pub fn result(&self) -> DriveResult {
        DriveResult {
            worst_start: self.worst_start,
            worst_end: self.worst_end,
            speed_rpm: self.speed_rpm,
            tripped: self.tripped,
            input_faults: self.input_faults,
        }
    }

    /// The interrupt's work for one sample: sample the currents, step the drive, record,
    /// and let the motor move on under the duty of the last sample.
    pub fn on_sample(&mut self) {
        if self.done {
            return;
        }
        let t = self.samples as f32 * self.ts;
        // (A compare, not `f32::min`: that is a call of `fminf` on this FPU, a function the
        // drive's step also calls, which the cost script would count as the step's work when
        // called between two steps.)
        let ramp = if t < RAMP_S { t / RAMP_S } else { 1.0 };
        let speed_ref_mech = SPEED_RPM * TAU / 60.0 * ramp;
        crate::note_step_sp();
        let out = crate::drive_step(
            &mut self.drive,
            self.motor.current().to_abc(),
            self.motor.vdc,
            speed_ref_mech,
        );
        let e = wrap(self.motor.theta - out.estimate.theta).abs();
        // (Compares, not `f32::max`: see the speed reference above.)
        if t <= RAMP_S && e > self.worst_start {
            self.worst_start = e;
        }
        if t >= END_S - 0.1 && e > self.worst_end {
            self.worst_end = e;
        }
        self.tripped |= out.tripped;
        self.input_faults += out.input_fault as u32;
        let load = if t >= LOAD_AT_S {
            LOAD_RATIO * self.rated_torque
        } else {
            0.0
        };
        self.motor.advance(self.pending, load, self.ts);
        self.pending = out.duty;
        self.samples += 1;
        if self.samples >= self.total_samples {
            self.speed_rpm = self.motor.omega_mech * 60.0 / TAU;
            self.done = true;
        }
    }
}
