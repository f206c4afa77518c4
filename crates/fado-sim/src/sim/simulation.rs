//! The run loop: plant + controller + speed reference + timed events, sample after sample.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use fado_core::wrap_angle;
use serde::{Deserialize, Serialize};

use crate::controller::{ControlEvent, Controller, Measurements};
use crate::error::SimConfigError;
use crate::profile::Profile;

use super::{Plant, Probe, RPM_PER_RAD_S, Sample};

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
    /// The brake releases at the first ready sample from this time on (s).
    brake_release_at: f64,
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
            brake_release_at: 0.0,
        })
    }

    /// The plant's brake releases at the first ready sample from `time` (s) on.
    pub fn with_brake_release_at(mut self, time: f64) -> Self {
        self.brake_release_at = time;
        self
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
        let ready = self.controller.ready();
        if self.plant.brake_engaged() && ready && t >= self.brake_release_at {
            self.plant.release_brake();
            self.controller.brake_released();
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
            ready,
            startup: self.controller.startup_status(),
            gain_calibration: self.controller.gain_calibration_status(),
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

/// Wraps a difference of two wrapped angles (within ±3π) into [−π, π] without a division.
#[inline]
pub(super) fn wrap_small(x: f64) -> f64 {
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
