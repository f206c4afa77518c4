//! The closed loop, one sample at a time: sense → control → switch → move.
//!
//! At sample n (time n·Ts, a carrier peak or valley) the sensors read the true currents and the
//! DC link, the controller computes the duty for n+1, and the plant integrates [n, n+1] with
//! the duty the controller computed at n−1 (one sample of computational delay). Each sample is
//! handed to [`Probe`]s: the metrics, the decimated trace and the scenarios' criteria.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use fado_core::{Abc, Dq, wrap_angle};
use serde::{Deserialize, Serialize};

use crate::controller::{Actuation, ControlEvent, Controller, Measurements};
use crate::dc_link::{DcLink, DcLinkParams};
use crate::error::SimConfigError;
use crate::faults::{FaultParams, Faults};
use crate::inverter::{Inverter, InverterParams, SampleOutcome};
use crate::load::{Load, LoadParams};
use crate::motor::{Motor, MotorParams};
use crate::profile::Profile;
use crate::sensors::{CurrentSensor, CurrentSensorParams, DcLinkSensorParams, Encoder};

const RPM_PER_RAD_S: f64 = 60.0 / std::f64::consts::TAU;

/// Everything physical: machine, inverter, sensors, load.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlantParams {
    /// The PMSM.
    pub motor: MotorParams,
    /// Inverter and DC link.
    pub inverter: InverterParams,
    /// Phase-current sensors.
    pub current_sensor: CurrentSensorParams,
    /// DC-link voltage sensor.
    pub dc_link_sensor: DcLinkSensorParams,
    /// Load machine.
    pub load: LoadParams,
    /// Injected faults (none by default).
    pub faults: FaultParams,
    /// The DC link behind the inverter (stiff by default).
    #[serde(default)]
    pub dc_link: DcLinkParams,
    /// The machine's saturating magnetics (`[motor.saturation]` or `[motor] flux_map`); None:
    /// the constant inductances of `motor`. Not a TOML table of its own (the configuration
    /// keeps it under `[motor]`).
    #[serde(skip)]
    pub magnetics: Option<std::sync::Arc<crate::magnetics::PlantMagnetics>>,
}

impl Default for PlantParams {
    /// The paper's plant: its motor ([`MotorParams::paper`]), docs/method/estimator.md §7–6's inverter and
    /// sensors, no load, no faults.
    fn default() -> Self {
        Self {
            motor: MotorParams::paper(),
            inverter: InverterParams::default(),
            current_sensor: CurrentSensorParams::default(),
            dc_link_sensor: DcLinkSensorParams::default(),
            load: LoadParams::default(),
            faults: FaultParams::default(),
            dc_link: DcLinkParams::default(),
            magnetics: None,
        }
    }
}

impl PlantParams {
    /// Checks every record; the error names the key as `section.field`.
    pub fn validate(&self) -> Result<(), SimConfigError> {
        crate::motor::validate_motor(&self.motor, self.inverter.dc_voltage).map_err(|e| {
            if e.key == "dc_voltage" {
                SimConfigError::new("inverter.dc_voltage", e.message)
            } else {
                e.in_section("motor")
            }
        })?;
        self.inverter
            .validate()
            .map_err(|e| e.in_section("inverter"))?;
        self.current_sensor
            .validate()
            .map_err(|e| e.in_section("current_sensor"))?;
        self.dc_link_sensor
            .validate()
            .map_err(|e| e.in_section("dc_link_sensor"))?;
        self.load.validate().map_err(|e| e.in_section("load"))?;
        self.faults.validate().map_err(|e| e.in_section("faults"))?;
        self.dc_link
            .validate()
            .map_err(|e| e.in_section("dc_link"))?;
        Ok(())
    }
}

/// The plant: machine, inverter, sensors and load machine.
#[derive(Clone, Debug)]
pub struct Plant {
    motor: Motor,
    inverter: Inverter,
    current_sensor: CurrentSensor,
    dc_link_sensor: DcLinkSensorParams,
    load: Load,
    encoder: Encoder,
    load_torque: f64,
    last: SampleOutcome,
    faults: Option<Faults>,
    dc_link: DcLink,
    /// A holding brake on the shaft: while engaged the rotor stays where it is and the load
    /// acts on the brake.
    brake: bool,
}

impl Plant {
    /// A plant at rest at electrical angle `theta0`.
    pub fn new(params: &PlantParams, theta0: f64) -> Result<Self, SimConfigError> {
        params.validate()?;
        let s = |e: SimConfigError, sec: &str| e.in_section(sec);
        let mo = &params.motor;
        let rated_power = mo.rated_torque * mo.rated_speed_rpm / RPM_PER_RAD_S;
        let dc_link = DcLink::new(&params.dc_link, params.inverter.dc_voltage, rated_power)
            .map_err(|e| s(e, "dc_link"))?;
        let mut plant = Self {
            dc_link,
            motor: Motor::with_magnetics(params.motor, params.magnetics.clone(), theta0)
                .map_err(|e| s(e, "motor"))?,
            inverter: Inverter::new(params.inverter.clone()).map_err(|e| s(e, "inverter"))?,
            current_sensor: CurrentSensor::new(
                params.current_sensor.clone(),
                params.motor.rated_current,
            )
            .map_err(|e| s(e, "current_sensor"))?,
            dc_link_sensor: params.dc_link_sensor.clone(),
            load: Load::new(
                params.load.clone(),
                params.motor.inertia,
                params.motor.rated_speed_rpm,
            )
            .map_err(|e| s(e, "load"))?,
            encoder: Encoder::default(),
            load_torque: 0.0,
            brake: false,
            last: SampleOutcome::default(),
            faults: if params.faults.is_empty() {
                None
            } else {
                Some(
                    Faults::new(params.faults.clone(), params.inverter.sample_period())
                        .map_err(|e| s(e, "faults"))?,
                )
            },
        };
        if let Some(f) = &plant.faults {
            plant.inverter.set_voltage_offset(f.voltage_offset());
        }
        Ok(plant)
    }

    /// The machine (true state).
    pub fn motor(&self) -> &Motor {
        &self.motor
    }

    /// The machine, mutable (initial conditions).
    pub fn motor_mut(&mut self) -> &mut Motor {
        &mut self.motor
    }

    /// The inverter.
    pub fn inverter(&self) -> &Inverter {
        &self.inverter
    }

    /// Sampling period Ts.
    pub fn sample_period(&self) -> f64 {
        self.inverter.sample_period()
    }

    /// Time of the present sample.
    pub fn time(&self) -> f64 {
        self.inverter.time()
    }

    /// Load torque applied over the last sample (N·m, positive opposing positive rotation).
    pub fn load_torque(&self) -> f64 {
        self.load_torque
    }

    /// What the last sample did (average torque and voltage).
    pub fn last_outcome(&self) -> &SampleOutcome {
        &self.last
    }

    /// True phase currents.
    pub fn phase_currents(&self) -> Abc<f64> {
        self.motor.i_ab().to_abc()
    }

    /// Samples the sensors now: (currents, DC-link voltage, encoder mechanical angle), with
    /// the configured faults applied (a DC-link dip acts on the inverter from this sample on).
    pub fn measure(&mut self) -> (Abc<f64>, f64, f64) {
        if let Some(f) = self.faults.as_mut() {
            let k = f.dc_link_scale(self.inverter.time());
            self.inverter.set_dc_link_scale(k);
        }
        let i = self.current_sensor.measure(self.phase_currents());
        let vdc = self.dc_link_sensor.measure(self.inverter.dc_voltage());
        let enc = self.encoder.angle_mech(self.motor.state().theta_mech);
        match &self.faults {
            Some(f) => {
                let (i, vdc) = f.corrupt(self.inverter.time(), i, vdc);
                (i, vdc, enc)
            }
            None => (i, vdc, enc),
        }
    }

    /// Engages the holding brake (the rotor must be at rest: it is held where it is).
    pub fn engage_brake(&mut self) {
        self.brake = true;
    }

    /// Releases the holding brake.
    pub fn release_brake(&mut self) {
        self.brake = false;
    }

    /// Whether the holding brake holds the rotor.
    pub fn brake_engaged(&self) -> bool {
        self.brake
    }

    /// Integrates one sample [n, n+1] and loads `duty_next` for [n+1, n+2].
    pub fn step(&mut self, duty_next: Abc<f64>, gates_enabled: bool) -> SampleOutcome {
        let ts = self.sample_period();
        let t = self.time();
        self.load_torque = self.load.torque(t, self.motor.state().omega_mech, ts);
        let i_before = self.motor.i_ab();
        let out = self
            .inverter
            .step(&mut self.motor, duty_next, gates_enabled);
        if !self.dc_link.is_stiff() {
            // The inverter's power over the sample: 1.5·v·i with the mean current.
            let i_mean = (i_before + self.motor.i_ab()) * 0.5;
            let power = 1.5 * (out.v_ab_avg.alpha * i_mean.alpha + out.v_ab_avg.beta * i_mean.beta);
            let v = self.dc_link.step(self.inverter.source_voltage(), power, ts);
            self.inverter.set_bus_voltage(v);
        }
        if self.brake {
            // The brake takes both torques: the rotor (at rest) does not move.
            self.motor.advance_mechanical(ts, 0.0, 0.0);
        } else {
            self.motor
                .advance_mechanical(ts, out.torque_avg, self.load_torque);
        }
        self.last = out;
        out
    }
}

/// Wraps a difference of two wrapped angles (within ±3π) into [−π, π] without a division.
#[inline]
fn wrap_small(x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    if x > PI {
        x - TAU
    } else if x < -PI {
        x + TAU
    } else if x.is_finite() {
        x
    } else {
        wrap_angle(x)
    }
}

/// Everything known about one sample: true plant state and the controller's view.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Time in s.
    pub time: f64,
    /// True electrical rotor angle θ, rad.
    pub theta: f64,
    /// Angle error wrap(θ − θ̂), rad.
    pub angle_error: f64,
    /// True speed, r/min (mechanical).
    pub speed_rpm: f64,
    /// Speed reference, r/min.
    pub speed_ref_rpm: f64,
    /// Estimated speed (T2S-2, for control), r/min.
    pub speed_hat_rpm: f64,
    /// True current in the true rotor frame, A.
    pub i_dq_true: Dq<f64>,
    /// True stator flux in α-β (what λ2 estimates), Wb.
    pub flux_ab_true: fado_core::Ab<f64>,
    /// Electromagnetic torque over the previous sample, N·m.
    pub torque: f64,
    /// Load torque over the previous sample, N·m.
    pub load_torque: f64,
    /// Pole pairs (to convert the controller's electrical speeds).
    pub pole_pairs: f64,
    /// True DC-link voltage over the previous sample (what the inverter switched), V.
    pub dc_voltage: f64,
    /// Stator voltage the inverter actually applied over the previous sample [n−1, n]
    /// (time average, α-β), V.
    pub v_ab_applied: fado_core::Ab<f64>,
    /// Measured current in α-β as the controller's estimator was given it (offset-corrected,
    /// a stuck channel reconstructed) when the controller reports it, else the Clarke
    /// transform of the measured phase currents, A.
    pub i_ab_measured: fado_core::Ab<f64>,
    /// The plant's holding brake holds the rotor over this sample.
    pub brake_engaged: bool,
    /// The controller's output at this sample.
    pub act: Actuation,
}

/// Something that watches every sample (metrics, traces, scenario criteria).
pub trait Probe {
    /// Called once per sample.
    fn observe(&mut self, s: &Sample);
    /// Called once at the end of [`Simulation::run`] (e.g. to form RMS values).
    fn finish(&mut self) {}
}

/// The closed loop: plant + controller + speed reference + timed controller events.
pub struct Simulation<C> {
    plant: Plant,
    controller: C,
    speed_ref_rpm: Profile,
    events: Vec<(f64, ControlEvent)>,
    next_event: usize,
    speed_cursor: usize,
    pole_pairs: f64,
    tripped: bool,
}

impl<C: Controller> Simulation<C> {
    /// A closed loop with the plant at rest at `theta0`; the controller is aligned to
    /// `theta0 + align_error` (a known or aligned start, docs/method/estimator.md, "Start-up").
    pub fn new(
        plant: Plant,
        mut controller: C,
        speed_ref_rpm: Profile,
        align_error: f64,
    ) -> Result<Self, SimConfigError> {
        speed_ref_rpm
            .validate()
            .map_err(|e| e.in_section("speed_reference"))?;
        controller.align(plant.motor().state().theta + align_error);
        let pole_pairs = plant.motor().params().pole_pairs as f64;
        Ok(Self {
            plant,
            controller,
            speed_ref_rpm,
            events: Vec::new(),
            next_event: 0,
            speed_cursor: 0,
            pole_pairs,
            tripped: false,
        })
    }

    /// Adds timed controller events (e.g. k_df off/on), any order.
    pub fn with_events(mut self, mut events: Vec<(f64, ControlEvent)>) -> Self {
        events.sort_by(|a, b| a.0.total_cmp(&b.0));
        self.events = events;
        self
    }

    /// The plant.
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// The controller.
    pub fn controller(&self) -> &C {
        &self.controller
    }

    /// The controller, mutable.
    pub fn controller_mut(&mut self) -> &mut C {
        &mut self.controller
    }

    /// Whether the controller has tripped at any sample so far.
    pub fn tripped(&self) -> bool {
        self.tripped
    }

    /// One sample: sense, control, record, integrate to the next sample.
    #[inline]
    pub fn step(&mut self) -> Sample {
        let t = self.plant.time();
        while let Some(&(te, ev)) = self.events.get(self.next_event) {
            if te > t {
                break;
            }
            self.controller.handle(ev);
            self.next_event += 1;
        }
        let (i_abc, vdc, enc) = self.plant.measure();
        let speed_ref_rpm = self.speed_ref_rpm.value_from(t, &mut self.speed_cursor);
        let m = Measurements {
            time: t,
            i_abc,
            vdc,
            speed_ref_mech: speed_ref_rpm / RPM_PER_RAD_S,
            encoder_angle_mech: enc,
        };
        let act = self.controller.step(&m);
        self.tripped |= act.tripped;
        if self.plant.brake_engaged() && self.controller.ready() {
            self.plant.release_brake();
        }
        let st = *self.plant.motor().state();
        let sample = Sample {
            time: t,
            theta: st.theta,
            angle_error: wrap_small(st.theta - act.estimate.theta),
            speed_rpm: st.omega_mech * RPM_PER_RAD_S,
            speed_ref_rpm,
            speed_hat_rpm: act.estimate.omega_control / self.pole_pairs * RPM_PER_RAD_S,
            i_dq_true: st.i_dq,
            flux_ab_true: self.plant.motor().flux_ab(),
            torque: self.plant.last_outcome().torque_avg,
            load_torque: self.plant.load_torque(),
            v_ab_applied: self.plant.last_outcome().v_ab_avg,
            i_ab_measured: act.i_ab_used.unwrap_or_else(|| i_abc.to_ab()),
            pole_pairs: self.pole_pairs,
            dc_voltage: self.plant.inverter().dc_voltage(),
            brake_engaged: self.plant.brake_engaged(),
            act,
        };
        self.plant.step(act.duty, act.gates_enabled);
        sample
    }

    /// Runs for `duration` seconds, handing every sample to the probes; `progress` (if any) is
    /// called with the completed fraction about a hundred times. Returns the statistics.
    pub fn run(
        &mut self,
        duration: f64,
        probes: &mut [&mut dyn Probe],
        progress: Option<&mut dyn FnMut(f64)>,
    ) -> RunStats {
        self.run_until(duration, probes, progress, None)
    }

    /// [`run`](Self::run) that stops early, within [`CANCEL_CHECK_SAMPLES`] samples, once
    /// `cancel` is set (by another thread: Ctrl-C in the Python bindings); the statistics then
    /// say [`RunStats::cancelled`] and the probes are not finished.
    pub fn run_until(
        &mut self,
        duration: f64,
        probes: &mut [&mut dyn Probe],
        mut progress: Option<&mut dyn FnMut(f64)>,
        cancel: Option<&AtomicBool>,
    ) -> RunStats {
        let ts = self.plant.sample_period();
        let n = (duration / ts).round().max(0.0) as u64;
        let chunk = (n / 100).max(1);
        let start = Instant::now();
        for k in 0..n {
            if let Some(flag) = cancel
                && k % CANCEL_CHECK_SAMPLES == 0
                && flag.load(Ordering::Relaxed)
            {
                return RunStats {
                    simulated_seconds: k as f64 * ts,
                    wall_seconds: start.elapsed().as_secs_f64(),
                    samples: k,
                    cancelled: true,
                };
            }
            let s = self.step();
            for p in probes.iter_mut() {
                p.observe(&s);
            }
            if let Some(cb) = progress.as_mut()
                && (k + 1) % chunk == 0
            {
                cb((k + 1) as f64 / n as f64);
            }
        }
        for p in probes.iter_mut() {
            p.finish();
        }
        RunStats {
            simulated_seconds: n as f64 * ts,
            wall_seconds: start.elapsed().as_secs_f64(),
            samples: n,
            cancelled: false,
        }
    }
}

/// [`Simulation::run_until`] looks at its cancel flag once per this many samples: 1024
/// samples are 0.1 s of simulated time at 10 kHz and about 1 ms of wall time with the
/// switching-resolved inverter, far inside the 0.5 s a Ctrl-C may take.
pub const CANCEL_CHECK_SAMPLES: u64 = 1024;

/// Timing of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunStats {
    /// Simulated time in s.
    pub simulated_seconds: f64,
    /// Wall-clock time in s.
    pub wall_seconds: f64,
    /// Samples run.
    pub samples: u64,
    /// The run was stopped early by its cancel flag ([`Simulation::run_until`]).
    #[serde(default)]
    pub cancelled: bool,
}

impl RunStats {
    /// Simulated seconds per wall-clock second.
    pub fn real_time_factor(&self) -> f64 {
        self.simulated_seconds / self.wall_seconds.max(1e-12)
    }
}

/// Angle and speed accuracy over an evaluation window.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Evaluation starts at this time, s (start-up excluded).
    pub eval_start: f64,
    /// |speed| below this (true, r/min) counts as "near zero speed".
    pub zero_speed_band_rpm: f64,
    /// Samples evaluated.
    pub samples: u64,
    /// Samples near zero speed.
    pub zero_speed_samples: u64,
    /// max |θ − θ̂|, rad (electrical).
    pub max_angle_error: f64,
    /// RMS of θ − θ̂, rad.
    pub rms_angle_error: f64,
    /// max |θ − θ̂| near zero speed, rad.
    pub max_angle_error_zero_speed: f64,
    /// RMS of θ − θ̂ near zero speed, rad.
    pub rms_angle_error_zero_speed: f64,
    /// max |n* − n| (reference minus true speed), r/min.
    pub max_speed_error_rpm: f64,
    /// The controller tripped (at any time, also before the window).
    pub tripped: bool,
    /// Highest true DC-link voltage over the whole run, V.
    pub max_dc_voltage: f64,
    /// Lowest true DC-link voltage over the whole run, V.
    pub min_dc_voltage: f64,
    /// max |θ − θ̂| over the whole run while the gates are on (start-up included), rad:
    /// the label of the loss-of-lock evaluation (docs/method/lock.md).
    pub max_angle_error_run: f64,
    /// First time |θ − θ̂| exceeded 0.5 rad with the gates on, s (None: never).
    pub angle_error_exceeded_time: Option<f64>,
    /// First time the drive reported the estimate lost (`DriveFlags::LOCK_LOST`), s.
    pub lock_lost_time: Option<f64>,
    /// First time the drive reported a stall (`DriveFlags::STALLED`: the speed does not
    /// follow the torque; a real stall or an estimate lost near zero speed), s.
    pub stall_time: Option<f64>,
    /// Onset of the loss, s: the first time |θ − θ̂| exceeded 0.5 rad in the excursion (from
    /// the last time it had settled below 0.25 rad, i.e. stayed there for 0.1 s, on) that
    /// first took it beyond 1 rad (None: it never exceeded 1 rad). Equal to
    /// `angle_error_exceeded_time` unless an earlier excursion beyond 0.5 rad settled again.
    pub loss_onset_time: Option<f64>,
    /// The last time |θ − θ̂| was below 0.25 rad before that onset, s (None: never).
    pub loss_settled_time: Option<f64>,
    /// The loss-of-lock labels below judge the drive's loss evidence, `LOCK_LOST` or
    /// `STALLED` (either up counts as the flag; docs/method/lock.md).
    ///
    /// If the flag (a live status) is up 20 ms after the onset: the time it last rose
    /// minus the onset, s (negative: raised before the error reached 0.5 rad; docs/method/lock.md
    /// counts it as a detection if it rose less than 1 s before). None: down then.
    pub lock_detection_delay: Option<f64>,
    /// First rise of the flag at or after the onset, while the error has not settled
    /// below 0.25 rad again, minus the onset, s (the late detections). None: no rise.
    pub lock_late_delay: Option<f64>,
    /// `lock_detection_delay` for `LOCK_LOST` alone (the estimator's verdict, without the
    /// drive's stall symptom), s.
    pub lock_lost_detection_delay: Option<f64>,
    #[serde(skip)]
    loss: LossTracker,
    #[serde(skip)]
    loss_lock_only: LossTracker,
    #[serde(skip)]
    sum_sq: f64,
    #[serde(skip)]
    sum_sq_zero: f64,
}

impl Metrics {
    /// Metrics from `eval_start` on, with the given zero-speed band.
    pub fn new(eval_start: f64, zero_speed_band_rpm: f64) -> Self {
        Self {
            eval_start,
            zero_speed_band_rpm,
            min_dc_voltage: f64::INFINITY,
            ..Self::default()
        }
    }
}

impl Probe for Metrics {
    fn finish(&mut self) {
        self.rms_angle_error = (self.sum_sq / self.samples.max(1) as f64).sqrt();
        self.rms_angle_error_zero_speed =
            (self.sum_sq_zero / self.zero_speed_samples.max(1) as f64).sqrt();
    }

    fn observe(&mut self, s: &Sample) {
        self.tripped |= s.act.tripped;
        self.max_dc_voltage = self.max_dc_voltage.max(s.dc_voltage);
        self.min_dc_voltage = self.min_dc_voltage.min(s.dc_voltage);
        if s.act.gates_enabled {
            let e = s.angle_error.abs();
            self.max_angle_error_run = self.max_angle_error_run.max(e);
            if e > 0.5 && self.angle_error_exceeded_time.is_none() {
                self.angle_error_exceeded_time = Some(s.time);
            }
        }
        use fado_core::DriveFlags;
        let flags = s.act.flags;
        if self.lock_lost_time.is_none() && flags.contains(DriveFlags::LOCK_LOST) {
            self.lock_lost_time = Some(s.time);
        }
        if self.stall_time.is_none() && flags.contains(DriveFlags::STALLED) {
            self.stall_time = Some(s.time);
        }
        let flag = flags.intersects(DriveFlags::LOCK_LOST | DriveFlags::STALLED);
        let e = s.act.gates_enabled.then(|| s.angle_error.abs());
        self.loss.observe(s.time, e, flag);
        self.loss_lock_only
            .observe(s.time, e, flags.contains(DriveFlags::LOCK_LOST));
        if let Some(x) = self.loss_lock_only.loss {
            self.lock_lost_detection_delay = x.up_at_deadline.flatten().map(|t| t - x.onset);
        }
        if let Some(x) = self.loss.loss {
            self.loss_onset_time = Some(x.onset);
            self.loss_settled_time = x.settled.is_finite().then_some(x.settled);
            self.lock_detection_delay = x.up_at_deadline.flatten().map(|t| t - x.onset);
            self.lock_late_delay = x.first_rise.map(|t| t - x.onset);
        }
        if s.time < self.eval_start {
            return;
        }
        let e = s.angle_error;
        self.samples += 1;
        self.sum_sq += e * e;
        self.max_angle_error = self.max_angle_error.max(e.abs());
        if s.speed_rpm.abs() < self.zero_speed_band_rpm {
            self.zero_speed_samples += 1;
            self.sum_sq_zero += e * e;
            self.max_angle_error_zero_speed = self.max_angle_error_zero_speed.max(e.abs());
        }
        self.max_speed_error_rpm = self
            .max_speed_error_rpm
            .max((s.speed_ref_rpm - s.speed_rpm).abs());
    }
}

/// Angle-error thresholds and deadline of the loss-of-lock evaluation (docs/method/lock.md):
/// an excursion starts when |θ − θ̂| leaves 0.25 rad (the clean-run level), the loss's onset is
/// its first crossing of 0.5 rad, it is a loss if it then exceeds 1 rad, and the flag must be
/// up 20 ms after the onset. An excursion ends when the error has stayed below 0.25 rad for
/// [`LOSS_SETTLE_TIME`].
const LOSS_START: f64 = 0.5;
const LOSS_LOST: f64 = 1.0;
const LOSS_SETTLED: f64 = 0.25;
const LOSS_DEADLINE: f64 = 0.020;
/// How long |θ − θ̂| must stay below [`LOSS_SETTLED`] for an excursion to end, s: 0.1 s (the
/// detector's default healing time). An estimate that slips poles makes the *wrapped* error
/// pass through zero once per slip cycle; that is no return to lock. Below 0.25 rad for
/// 0.1 s at a time means a slip slower than 0.5 rad / 0.1 s = 5 rad/s electrical (12 r/min
/// mechanical on the paper's 4 pole pairs), i.e. the estimate following the rotor. (Without
/// the dwell, 8 fixed-R̂s losses of the fig11 envelope ended their excursion in a wrap before
/// the deadline and counted as "not raised" with the flag up throughout; docs/method/lock.md.)
const LOSS_SETTLE_TIME: f64 = 0.1;

/// An excursion of |θ − θ̂| above [`LOSS_SETTLED`] that reached [`LOSS_START`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Excursion {
    /// First time above 0.5 rad in the excursion.
    onset: f64,
    /// Last time below 0.25 rad before it (−∞: never, e.g. a start-up error).
    settled: f64,
    /// At onset + 20 ms: Some(Some(rise)) if the flag was up then, having last risen at
    /// `rise`; Some(None) if it was down; None before the deadline.
    up_at_deadline: Option<Option<f64>>,
    /// First rise of the flag at or after the onset, while the excursion lasts.
    first_rise: Option<f64>,
}

/// Streaming labels of [`Metrics`]' loss-of-lock fields: flag edges against the angle error.
#[derive(Clone, Copy, Debug, PartialEq)]
struct LossTracker {
    flag: bool,
    last_rise: Option<f64>,
    /// Last time below 0.25 rad.
    settled: f64,
    /// Since when the error has been below 0.25 rad (NaN: above it now).
    below_since: f64,
    /// The open excursion that reached 0.5 rad, if any.
    current: Option<Excursion>,
    /// The excursion that first exceeded 1 rad; `open` until the error has been below
    /// 0.25 rad for [`LOSS_SETTLE_TIME`] again.
    loss: Option<Excursion>,
    open: bool,
}

impl Default for LossTracker {
    fn default() -> Self {
        Self {
            flag: false,
            last_rise: None,
            settled: f64::NEG_INFINITY,
            below_since: f64::NAN,
            current: None,
            loss: None,
            open: false,
        }
    }
}

impl LossTracker {
    /// One sample: time, |θ − θ̂| (None while the gates are off), the flag.
    fn observe(&mut self, t: f64, error: Option<f64>, flag: bool) {
        let rise = flag && !self.flag;
        if rise {
            self.last_rise = Some(t);
        }
        self.flag = flag;
        if let Some(e) = error {
            if e < LOSS_SETTLED {
                self.settled = t;
                if self.below_since.is_nan() {
                    self.below_since = t;
                }
                if t - self.below_since >= LOSS_SETTLE_TIME {
                    self.current = None;
                    self.open = false;
                }
            } else {
                self.below_since = f64::NAN;
            }
            if e > LOSS_START {
                self.current.get_or_insert(Excursion {
                    onset: t,
                    settled: self.settled,
                    up_at_deadline: None,
                    first_rise: None,
                });
            }
            if e > LOSS_LOST && self.loss.is_none() {
                self.loss = self.current;
                self.open = true;
            }
        }
        let open = self.open;
        let current = self.current.as_mut();
        let loss = self.loss.as_mut().filter(|_| open);
        for x in [current, loss].into_iter().flatten() {
            if rise && x.first_rise.is_none() {
                x.first_rise = Some(t);
            }
            if x.up_at_deadline.is_none() && t >= x.onset + LOSS_DEADLINE {
                x.up_at_deadline = Some(self.last_rise.filter(|_| flag));
            }
        }
    }
}

/// One decimated row of the trace (the columns of `traces.csv`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TraceRow {
    /// Time, s.
    pub time: f64,
    /// True electrical angle, rad.
    pub theta: f64,
    /// Estimated electrical angle θ̂ (T2S-1), rad.
    pub theta_hat: f64,
    /// wrap(θ − θ̂), rad.
    pub angle_error: f64,
    /// True speed, r/min.
    pub speed_rpm: f64,
    /// Estimated speed (T2S-2), r/min.
    pub speed_hat_rpm: f64,
    /// Observer speed (T2S-1), r/min.
    pub speed_hat1_rpm: f64,
    /// Speed reference, r/min.
    pub speed_ref_rpm: f64,
    /// d current in the controller's frame, A.
    pub i_d: f64,
    /// q current in the controller's frame, A.
    pub i_q: f64,
    /// d current reference, A.
    pub i_d_ref: f64,
    /// q current reference, A.
    pub i_q_ref: f64,
    /// True d current, A.
    pub i_d_true: f64,
    /// True q current, A.
    pub i_q_true: f64,
    /// λ1 α, Wb.
    pub lambda1_alpha: f64,
    /// λ1 β, Wb.
    pub lambda1_beta: f64,
    /// D̂ α, Wb.
    pub dist_alpha: f64,
    /// D̂ β, Wb.
    pub dist_beta: f64,
    /// λ2 α, Wb.
    pub lambda2_alpha: f64,
    /// λ2 β, Wb.
    pub lambda2_beta: f64,
    /// λ̂r α, Wb.
    pub lambda_r_alpha: f64,
    /// λ̂r β, Wb.
    pub lambda_r_beta: f64,
    /// True stator flux α, Wb.
    pub flux_alpha_true: f64,
    /// True stator flux β, Wb.
    pub flux_beta_true: f64,
    /// FLAG_limit (limiter mode), 0/1.
    pub flag_limit: u8,
    /// Limiter clamping this sample, 0/1.
    pub limiter_clamping: u8,
    /// Trackers holding, 0/1.
    pub tracker_hold: u8,
    /// Tripped, 0/1.
    pub tripped: u8,
    /// Electromagnetic torque, N·m.
    pub torque: f64,
    /// Load torque, N·m.
    pub load_torque: f64,
    /// Realised voltage reference α computed at this sample (before dead-time compensation),
    /// V. The estimator integrates it two samples later (docs/method/estimator.md §1, one-sample delay + [n−1, n]).
    pub v_alpha_ref: f64,
    /// Realised voltage reference β, V.
    pub v_beta_ref: f64,
    /// Voltage the inverter actually applied over [n−1, n] (time average) α, V.
    pub v_alpha_applied: f64,
    /// Applied voltage β, V.
    pub v_beta_applied: f64,
    /// Measured current α as the estimator sees it at this sample (offset-corrected, a stuck
    /// channel reconstructed), A.
    pub i_alpha: f64,
    /// Measured current β, A.
    pub i_beta: f64,
    /// R̂s the estimator integrated with, Ω (moves with `[estimator] rs_adaptation`).
    pub rs_hat: f64,
    /// The estimator's flux-magnitude reference λ̂f, Wb (moves with `rs_adaptation`).
    pub flux_linkage_hat: f64,
    /// The drive's status word (`fado_core::DriveFlags` bits: 1 input rejected, 2 tripped,
    /// 4 voltage saturated, 8 current error, 16 sensor stuck, 32 DC link low, 64 limiter
    /// mode, 128 lock lost, 256 coasting, 512 input implausible, 1024 stalled).
    pub fault_flags: u16,
    /// The estimator's loss-of-lock status (`fado_core::LockStatus`): 0 locked, 1 suspect,
    /// 2 lost.
    pub lock: u8,
}

impl TraceRow {
    /// Column names, in CSV order (for struct-of-arrays consumers such as the Python
    /// bindings).
    pub const COLUMNS: [&'static str; 40] = [
        "time",
        "theta",
        "theta_hat",
        "angle_error",
        "speed_rpm",
        "speed_hat_rpm",
        "speed_hat1_rpm",
        "speed_ref_rpm",
        "i_d",
        "i_q",
        "i_d_ref",
        "i_q_ref",
        "i_d_true",
        "i_q_true",
        "lambda1_alpha",
        "lambda1_beta",
        "dist_alpha",
        "dist_beta",
        "lambda2_alpha",
        "lambda2_beta",
        "lambda_r_alpha",
        "lambda_r_beta",
        "flux_alpha_true",
        "flux_beta_true",
        "flag_limit",
        "limiter_clamping",
        "tracker_hold",
        "tripped",
        "torque",
        "load_torque",
        "v_alpha_ref",
        "v_beta_ref",
        "v_alpha_applied",
        "v_beta_applied",
        "i_alpha",
        "i_beta",
        "rs_hat",
        "flux_linkage_hat",
        "fault_flags",
        "lock",
    ];

    /// The row's values in [`COLUMNS`](Self::COLUMNS) order (flags as 0.0/1.0).
    pub fn values(&self) -> [f64; 40] {
        [
            self.time,
            self.theta,
            self.theta_hat,
            self.angle_error,
            self.speed_rpm,
            self.speed_hat_rpm,
            self.speed_hat1_rpm,
            self.speed_ref_rpm,
            self.i_d,
            self.i_q,
            self.i_d_ref,
            self.i_q_ref,
            self.i_d_true,
            self.i_q_true,
            self.lambda1_alpha,
            self.lambda1_beta,
            self.dist_alpha,
            self.dist_beta,
            self.lambda2_alpha,
            self.lambda2_beta,
            self.lambda_r_alpha,
            self.lambda_r_beta,
            self.flux_alpha_true,
            self.flux_beta_true,
            self.flag_limit as f64,
            self.limiter_clamping as f64,
            self.tracker_hold as f64,
            self.tripped as f64,
            self.torque,
            self.load_torque,
            self.v_alpha_ref,
            self.v_beta_ref,
            self.v_alpha_applied,
            self.v_beta_applied,
            self.i_alpha,
            self.i_beta,
            self.rs_hat,
            self.flux_linkage_hat,
            self.fault_flags as f64,
            self.lock as f64,
        ]
    }
}

impl From<&Sample> for TraceRow {
    fn from(s: &Sample) -> Self {
        let d = &s.act.estimate.diagnostics;
        Self {
            time: s.time,
            theta: s.theta,
            theta_hat: s.act.estimate.theta,
            angle_error: s.angle_error,
            speed_rpm: s.speed_rpm,
            speed_hat_rpm: s.speed_hat_rpm,
            speed_hat1_rpm: s.act.estimate.omega / s.pole_pairs * RPM_PER_RAD_S,
            speed_ref_rpm: s.speed_ref_rpm,
            i_d: s.act.i_dq.d,
            i_q: s.act.i_dq.q,
            i_d_ref: s.act.i_dq_ref.d,
            i_q_ref: s.act.i_dq_ref.q,
            i_d_true: s.i_dq_true.d,
            i_q_true: s.i_dq_true.q,
            lambda1_alpha: d.lambda1.alpha,
            lambda1_beta: d.lambda1.beta,
            dist_alpha: d.disturbance.alpha,
            dist_beta: d.disturbance.beta,
            lambda2_alpha: d.lambda2.alpha,
            lambda2_beta: d.lambda2.beta,
            lambda_r_alpha: d.lambda_r.alpha,
            lambda_r_beta: d.lambda_r.beta,
            flux_alpha_true: s.flux_ab_true.alpha,
            flux_beta_true: s.flux_ab_true.beta,
            flag_limit: d.flag_limit as u8,
            limiter_clamping: d.limiter_clamping as u8,
            tracker_hold: d.tracker_hold as u8,
            tripped: s.act.tripped as u8,
            torque: s.torque,
            load_torque: s.load_torque,
            v_alpha_ref: s.act.v_ref_ab.alpha,
            v_beta_ref: s.act.v_ref_ab.beta,
            v_alpha_applied: s.v_ab_applied.alpha,
            v_beta_applied: s.v_ab_applied.beta,
            i_alpha: s.i_ab_measured.alpha,
            i_beta: s.i_ab_measured.beta,
            rs_hat: d.rs_hat,
            flux_linkage_hat: d.flux_linkage_hat,
            fault_flags: s.act.flags.bits(),
            lock: d.lock.code(),
        }
    }
}

/// Where the rows of a trace go as they are produced: memory ([`Vec`], [`TraceColumns`]) or
/// a file ([`CsvTraceWriter`]), so that a run's memory need not grow with its duration.
pub trait TraceSink {
    /// Takes one row.
    fn push(&mut self, row: &TraceRow);
}

impl TraceSink for Vec<TraceRow> {
    fn push(&mut self, row: &TraceRow) {
        Vec::push(self, *row);
    }
}

/// The trace as one `Vec<f64>` per column of [`TraceRow::COLUMNS`] (struct of arrays, flags
/// as 0.0/1.0): what the Python bindings hand to numpy without another copy.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceColumns {
    /// One vector per column, in [`TraceRow::COLUMNS`] order.
    pub columns: Vec<Vec<f64>>,
}

impl TraceColumns {
    /// Empty columns with room for `rows` rows.
    pub fn with_capacity(rows: usize) -> Self {
        Self {
            columns: vec![Vec::with_capacity(rows); TraceRow::COLUMNS.len()],
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }

    /// True without rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl TraceSink for TraceColumns {
    fn push(&mut self, row: &TraceRow) {
        for (column, value) in self.columns.iter_mut().zip(row.values()) {
            column.push(value);
        }
    }
}

/// Writes rows as CSV (header first) as they come. A write error is kept, the following rows
/// are dropped, and [`finish`](Self::finish) reports it.
pub struct CsvTraceWriter<W: std::io::Write> {
    writer: csv::Writer<W>,
    error: Option<csv::Error>,
    rows: u64,
}

impl<W: std::io::Write> CsvTraceWriter<W> {
    /// A writer onto `w` (buffer `w` yourself if it is a file; csv adds its own 8 KiB).
    pub fn new(w: W) -> Self {
        Self {
            writer: csv::Writer::from_writer(w),
            error: None,
            rows: 0,
        }
    }

    /// Rows written.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// A write failed (the rest of the rows are dropped; [`finish`](Self::finish) says why).
    pub fn failed(&self) -> bool {
        self.error.is_some()
    }

    /// Flushes and returns the inner writer, or the first error.
    pub fn finish(mut self) -> Result<W, csv::Error> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        if self.rows == 0 {
            // The header alone, as `Trace::write_csv` writes for an empty trace.
            self.writer.write_record(TraceRow::COLUMNS)?;
        }
        self.writer
            .into_inner()
            .map_err(|e| csv::Error::from(e.into_error()))
    }
}

impl<W: std::io::Write> TraceSink for CsvTraceWriter<W> {
    fn push(&mut self, row: &TraceRow) {
        if self.error.is_none() {
            match self.writer.serialize(row) {
                Ok(()) => self.rows += 1,
                Err(e) => self.error = Some(e),
            }
        }
    }
}

/// Hands every `decimation`-th sample to a [`TraceSink`] as a [`TraceRow`].
pub struct Decimated<'a> {
    decimation: u64,
    count: u64,
    sink: &'a mut dyn TraceSink,
}

impl<'a> Decimated<'a> {
    /// Keeps one sample in `decimation` (at least 1), starting with the first.
    pub fn new(decimation: u32, sink: &'a mut dyn TraceSink) -> Self {
        Self {
            decimation: decimation.max(1) as u64,
            count: 0,
            sink,
        }
    }
}

impl Probe for Decimated<'_> {
    fn observe(&mut self, s: &Sample) {
        if self.count.is_multiple_of(self.decimation) {
            self.sink.push(&TraceRow::from(s));
        }
        self.count += 1;
    }
}

/// Keeps every `decimation`-th sample as a [`TraceRow`] in memory.
#[derive(Clone, Debug, Default)]
pub struct Trace {
    /// Keep one sample in this many (≥ 1).
    pub decimation: u32,
    /// The rows kept.
    pub rows: Vec<TraceRow>,
    count: u64,
}

impl Trace {
    /// An empty trace keeping one sample in `decimation`.
    pub fn new(decimation: u32) -> Self {
        Self {
            decimation: decimation.max(1),
            rows: Vec::new(),
            count: 0,
        }
    }

    /// One column of the trace by name (see [`TraceRow::COLUMNS`]).
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = TraceRow::COLUMNS.iter().position(|c| *c == name)?;
        Some(self.rows.iter().map(|r| r.values()[k]).collect())
    }

    /// Writes the rows as CSV with a header.
    pub fn write_csv<W: std::io::Write>(&self, w: W) -> Result<(), csv::Error> {
        let mut wr = CsvTraceWriter::new(w);
        for r in &self.rows {
            wr.push(r);
        }
        wr.finish()?.flush()?;
        Ok(())
    }
}

impl Probe for Trace {
    fn observe(&mut self, s: &Sample) {
        if self.count.is_multiple_of(self.decimation as u64) {
            self.rows.push(TraceRow::from(s));
        }
        self.count += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feeds (time, |θ − θ̂|, flag) at 1 ms steps to a tracker.
    fn track(samples: &[(f64, f64, bool)]) -> LossTracker {
        let mut l = LossTracker::default();
        for &(t, e, flag) in samples {
            l.observe(t, Some(e), flag);
        }
        l
    }

    /// A piecewise-linear error and a flag window, sampled every ms from 0 to `end`.
    fn run(error: &dyn Fn(f64) -> f64, flag: (f64, f64), end: f64) -> LossTracker {
        let n = (end * 1000.0).round() as usize;
        let s: Vec<_> = (0..=n)
            .map(|k| {
                let t = k as f64 * 1e-3;
                (t, error(t), t >= flag.0 && t < flag.1)
            })
            .collect();
        track(&s)
    }

    #[test]
    fn loss_labels_follow_the_definition() {
        // Error ramps 0 → 2 rad between 1 s and 2 s: onset (0.5 rad) at 1.25 s, last below
        // 0.25 rad at 1.124 s.
        let ramp = |t: f64| ((t - 1.0) * 2.0).clamp(0.0, 2.0);
        // Flag up from 1.2 s on: rose 50 ms before the onset, up at the deadline.
        let l = run(&ramp, (1.2, 9.0), 3.0);
        let x = l.loss.unwrap();
        assert!((x.onset - 1.251).abs() < 1e-9, "{x:?}");
        assert!((x.settled - 1.124).abs() < 1e-9, "{x:?}");
        assert_eq!(x.up_at_deadline, Some(Some(1.2)));
        assert_eq!(x.first_rise, None); // no rise after the onset
        // Flag rising 30 ms after the onset: down at the deadline, a late rise.
        let x = run(&ramp, (1.281, 9.0), 3.0).loss.unwrap();
        assert_eq!(x.up_at_deadline, Some(None));
        assert_eq!(x.first_rise, Some(1.281));
        // A flag that rose at start-up and stayed up: up at the deadline, risen at 0.1 s
        // (the evaluation's window then refuses it).
        let x = run(&ramp, (0.1, 9.0), 3.0).loss.unwrap();
        assert_eq!(x.up_at_deadline, Some(Some(0.1)));
        // A start-up excursion beyond 0.5 rad that came back below 0.25 rad does not move the
        // onset of the later loss.
        let bump = |t: f64| {
            if (0.3..0.4).contains(&t) {
                0.6
            } else {
                ramp(t)
            }
        };
        let x = run(&bump, (0.3, 0.35), 3.0).loss.unwrap();
        assert!((x.onset - 1.251).abs() < 1e-9, "{x:?}");
        assert_eq!(x.up_at_deadline, Some(None));
        // Never beyond 1 rad: no loss.
        assert!(run(&|_| 0.7, (0.0, 9.0), 1.0).loss.is_none());
        // An estimate slipping poles (the error growing at 300 rad/s from 1.2 s on, its
        // wrapped value through zero every 21 ms, first at 1.220 s, before the deadline): one
        // excursion, not ended by the wrapped error passing below 0.25 rad for 2 ms at a
        // time; the flag up since 1.0 s is up at its deadline. Only 0.1 s below 0.25 rad ends
        // it.
        let slip = |t: f64| {
            if t < 1.2 {
                0.0
            } else {
                fado_core::wrap_angle(0.3 + 300.0 * (t - 1.2)).abs()
            }
        };
        let x = run(&slip, (1.0, 9.0), 3.0).loss.unwrap();
        assert!((x.onset - 1.201).abs() < 1e-9, "{x:?}");
        assert_eq!(x.up_at_deadline, Some(Some(1.0)));
        let settles = |t: f64| {
            if (1.5..1.7).contains(&t) {
                0.1
            } else {
                slip(t)
            }
        };
        let l = run(&settles, (1.0, 1.25), 3.0);
        assert!(!l.open, "{l:?}"); // settled at 1.6 s: the loss is over
        assert_eq!(l.loss.unwrap().first_rise, None);
    }

    #[test]
    fn csv_header_is_the_column_list_and_values_follow_it() {
        let mut t = Trace::new(1);
        let mut s = Sample {
            time: 0.25,
            speed_rpm: -12.0,
            pole_pairs: 4.0,
            ..Default::default()
        };
        s.act.estimate.omega = -2.0 * std::f64::consts::TAU; // −30 r/min with 4 pole pairs
        s.act.estimate.diagnostics.flag_limit = true;
        s.act.i_dq_ref = Dq::new(4.0, -1.5);
        s.act.v_ref_ab = fado_core::Ab::new(12.5, -3.0);
        s.i_ab_measured = fado_core::Ab::new(0.75, 2.0);
        t.observe(&s);
        let mut buf = Vec::new();
        t.write_csv(&mut buf).unwrap();
        let text = String::from_utf8(buf).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next().unwrap(), TraceRow::COLUMNS.join(","));
        let values: Vec<f64> = lines
            .next()
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(values, t.rows[0].values().to_vec());
        assert_eq!(t.column("i_q_ref").unwrap(), vec![-1.5]);
        assert_eq!(t.column("flag_limit").unwrap(), vec![1.0]);
        assert_eq!(t.column("speed_rpm").unwrap(), vec![-12.0]);
        assert_eq!(t.column("v_beta_ref").unwrap(), vec![-3.0]);
        assert_eq!(t.column("i_alpha").unwrap(), vec![0.75]);
        assert!((t.column("speed_hat1_rpm").unwrap()[0] + 30.0).abs() < 1e-12);
        assert!(t.column("nope").is_none());
    }
}
