//! Building, resetting, aligning and reading the drive: everything but the sample.

use super::{Blocks, DriveConfig, DriveOutput, Resolved, SensorlessDrive};
use crate::control::gain_calibration::{GainCalibration, GainCalibrationStatus};
use crate::control::lock_reaction::LockSupervisor;
use crate::control::monitor::{DriveFlags, FlagCounts, PersistenceMonitor, StuckChannelDetector};
use crate::control::startup::AngleSearch;
use crate::error::{ConfigError, check};
use crate::estimator::{
    Estimate, EstimatorConfig, EstimatorTuning, RotorAngleEstimator, SensorlessEstimator,
};
use crate::lock::Debouncer;
use crate::magnetics::FluxWarmStart;
use crate::{Ab, Abc, Dq, Real};

impl<T: Real> SensorlessDrive<T, SensorlessEstimator<T>> {
    /// The drive with the paper's estimator, built with the drive's own sampling period and
    /// machine model and the given estimator tuning (start-up angle 0; see
    /// [`align`](Self::align)), after the build-time rules of
    /// [`DriveConfig::apply_build_rules`] (tracker feed-forward, speed-loop bandwidth of a
    /// light rotor, the current loop of an enabled release hold).
    pub fn new(
        mut config: DriveConfig<T>,
        mut estimator: EstimatorTuning<T>,
    ) -> Result<Self, ConfigError> {
        config.apply_build_rules(&mut estimator);
        let estimator = EstimatorConfig {
            ts: check::positive("ts", config.ts)?,
            machine: config.machine,
            initial_angle: T::zero(),
            tuning: estimator,
        };
        Self::with_estimator(config, SensorlessEstimator::new(estimator)?)
    }
}

impl<T: Real, E: RotorAngleEstimator<T>> SensorlessDrive<T, E> {
    /// The drive around an estimator built by the caller (which must run at `config.ts`).
    /// The estimator is reset.
    pub fn with_estimator(config: DriveConfig<T>, estimator: E) -> Result<Self, ConfigError> {
        let resolved = Resolved::new(&config)?;
        let blocks = Blocks::new(&config, &resolved)?;
        let mut drive = Self {
            config,
            resolved,
            estimator,
            blocks,
            history: [Ab::zero(); 2],
            calibration_compensation: [Ab::zero(); 2],
            limited: [false; 2],
            last_i_ab: Ab::zero(),
            last: DriveOutput::idle(Estimate::default()),
            tripped: false,
            rejected_samples: 0,
            calibration_remaining: 0,
            calibration_sum: Abc::new(T::zero(), T::zero(), T::zero()),
            calibration_square_sum: T::zero(),
            current_offset: Abc::new(T::zero(), T::zero(), T::zero()),
            aligned_angle: T::zero(),
            gain: GainCalibration::new(config.gain_calibration_config()?)?,
            turn: None,
            gain_correction: T::one(),
            gain_tracking: super::gain_online::gain_tracking_of(&config),
            startup: AngleSearch::new(config.tuning.startup, &config.machine, config.ts)?,
            stuck_sensor: StuckChannelDetector::new(
                config.tuning.stuck_sensor.band_ratio * config.machine.rated_current,
                config.tuning.stuck_sensor.reference_ratio * config.machine.rated_current,
                resolved.stuck_sensor_samples,
            ),
            current_error: PersistenceMonitor::new(resolved.current_error_samples),
            stall: Debouncer::new(resolved.stall.samples, resolved.stall.heal_samples),
            stall_armed: false,
            brake_holds: false,
            coast_reason: DriveFlags::NONE,
            omega_slow: T::zero(),
            sensor_stuck_now: false,
            current_error_now: false,
            consecutive_rejects: 0,
            flag_counts: FlagCounts::default(),
            i_ab_used: Ab::zero(),
            lock: LockSupervisor::new(
                config.tuning.lock.reaction,
                config.ts,
                config.tuning.lock.recovery_time,
                config.tuning.lock.recovery_timeout,
                config.tuning.lock.recovery_attempts,
            )?,
            implausible_now: false,
            saturated_flux: Dq::zero(),
            saturated_warm: FluxWarmStart::empty(),
            saturated_point: Dq::zero(),
        };
        drive.reset();
        Ok(drive)
    }

    /// Everything back to the start-up state: controllers, history, estimator, the trip, and
    /// the current-offset calibration (restarted if configured; the old offsets are kept
    /// until the new ones are measured).
    pub fn reset(&mut self) {
        self.estimator.reset();
        self.clear_control(T::zero());
        self.last_i_ab = Ab::zero();
        self.tripped = false;
        self.rejected_samples = 0;
        self.consecutive_rejects = 0;
        self.flag_counts.reset();
        self.lock.reset();
        self.gain.arm();
        self.gain_tracking.reset();
        self.turn = None;
        self.startup.arm();
        self.calibrate_offsets();
    }

    /// (Re)arms the current-sensor gain calibration (see
    /// [`gain_calibration`](crate::control::gain_calibration)): it runs at the next sample
    /// after any offset calibration, along the d axis of the last [`align`](Self::align)'s
    /// angle (the rotor must be there and at rest), then the drive re-aligns there and starts.
    /// The ratio in use is kept until a new one is measured. Nothing happens when it is
    /// disabled (`gain_calibration.time` 0).
    pub fn calibrate_gain(&mut self) {
        self.gain.arm();
    }

    /// True while the gain calibration is armed or running (the gates are on, the speed
    /// reference is ignored).
    pub fn is_calibrating_gain(&self) -> bool {
        self.gain.running()
    }

    /// The current-sensor gain ratio k = (1 + g_a)/(1 + g_b) in use: the phase-a reading is
    /// divided by it. 1 until the calibration has measured one.
    pub fn current_gain_ratio(&self) -> T {
        self.gain.ratio()
    }

    /// Where the gain calibration stands (skipped as unobservable or refused as implausible
    /// leaves [`current_gain_ratio`](Self::current_gain_ratio) unchanged).
    pub fn gain_calibration_status(&self) -> GainCalibrationStatus {
        self.gain.status()
    }

    /// The gain calibration block (its last measured ratio, accepted or not, and its
    /// configuration).
    pub fn gain_calibration(&self) -> &GainCalibration<T> {
        &self.gain
    }

    /// (Re)starts the current-sensor offset calibration: for the next
    /// `offset_calibration.time` the samples run with the gates off (the machine must be at
    /// rest, so that the true current is zero) and average the raw phase currents; then the
    /// drive re-aligns at the angle of the last [`align`](Self::align) and starts.
    pub fn calibrate_offsets(&mut self) {
        self.calibration_remaining = self.resolved.offset_calibration_samples;
        self.calibration_sum = Abc::new(T::zero(), T::zero(), T::zero());
        self.calibration_square_sum = T::zero();
        if self.calibration_remaining > 0 {
            self.last.gates_enabled = false;
        }
    }

    /// True while the offset calibration runs (gates off).
    pub fn is_calibrating(&self) -> bool {
        self.calibration_remaining > 0
    }

    /// The phase-current offsets subtracted from every sample (A).
    pub fn current_offset(&self) -> Abc<T> {
        self.current_offset
    }

    /// Start-up at a known (e.g. aligned) rotor angle θ0 (docs/method/estimator.md, "Start-up"): the estimator
    /// starts from it with the last measured current; controllers and voltage history are
    /// cleared (the next duty is the first). A trip stays latched.
    pub fn align(&mut self, theta0: T) {
        if self.gain.running() {
            // A gain calibration under way restarts along the new axis.
            self.gain.arm();
            self.turn = None;
        }
        self.realign(theta0);
    }

    /// The start-up's end at `theta0` ([`realign`](Self::realign)): the speed reference
    /// starts from the rotor's speed there, zero, and ramps to the user's
    /// ([`start_ramp`](crate::control::start_ramp)).
    pub(super) fn start_at(&mut self, theta0: T) {
        self.realign(theta0);
        self.blocks.start_ramp.arm(T::zero());
    }

    /// [`align`](Self::align) without touching the gain calibration (its own end re-aligns).
    pub(super) fn realign(&mut self, theta0: T) {
        self.aligned_angle = theta0;
        self.estimator.align(theta0, self.last_i_ab);
        let theta0 = if theta0.is_finite() {
            crate::wrap_angle(theta0)
        } else {
            T::zero()
        };
        self.clear_control(theta0);
        // A rotor that a brake holds through the start-up cannot move: θ̂ moving then is the
        // estimate's own start transient, which the release hold would wind its integral up
        // on against the brake. The application arms it as it opens the brake
        // (`arm_release_hold`; docs/method/additions.md, "Release hold after the start-up").
        let rotor_held = self.config.tuning.startup.rotor_held;
        if !rotor_held {
            self.blocks.hold.arm(theta0);
        }
        self.brake_holds =
            rotor_held && self.config.tuning.release_hold.enabled && self.resolved.floor_at_brake;
        self.lock.restart();
        if self.tripped {
            self.trip_output();
        } else if self.calibration_remaining > 0 {
            self.last.gates_enabled = false;
        }
    }

    pub(super) fn clear_control(&mut self, theta: T) {
        self.blocks.reset();
        self.stuck_sensor.reset();
        self.current_error.reset();
        self.stall.reset();
        self.stall_armed = false;
        self.omega_slow = T::zero();
        self.sensor_stuck_now = false;
        self.current_error_now = false;
        self.history = [Ab::zero(); 2];
        (self.saturated_flux, self.saturated_warm) = self.zero_current_warm_start();
        self.saturated_point = Dq::zero();
        self.last = DriveOutput::idle(Estimate {
            theta,
            ..Estimate::default()
        });
    }

    pub(super) fn trip_output(&mut self) {
        let half = T::lit(0.5);
        self.last.duty = Abc::new(half, half, half);
        self.last.gates_enabled = false;
        self.last.tripped = true;
        self.last.v_ref_ab = Ab::zero();
        self.last.v_dq_ref = Dq::zero();
        self.history = [Ab::zero(); 2];
    }

    /// The estimator.
    pub fn estimator(&self) -> &E {
        &self.estimator
    }

    /// The estimator, mutable (e.g. to switch k_df off as in Fig. 9).
    pub fn estimator_mut(&mut self) -> &mut E {
        &mut self.estimator
    }

    /// The configuration in use.
    pub fn config(&self) -> &DriveConfig<T> {
        &self.config
    }

    /// The last output.
    pub fn last(&self) -> &DriveOutput<T> {
        &self.last
    }

    /// True after an over-current trip, until `reset`.
    pub fn is_tripped(&self) -> bool {
        self.tripped
    }

    /// Samples rejected since the last reset.
    pub fn rejected_samples(&self) -> u32 {
        self.rejected_samples
    }

    /// Recoveries from a lost rotor started since the last reset (`lock.reaction` recover).
    pub fn lock_recoveries(&self) -> u32 {
        self.lock.attempts()
    }

    /// Samples each [`DriveFlags`] bit was raised since the last reset.
    pub fn flag_counts(&self) -> &FlagCounts {
        &self.flag_counts
    }

    /// The current PIs' integral states (V, d and q): bounded in any healthy run.
    pub fn current_integral(&self) -> Dq<T> {
        self.blocks.current.integral()
    }

    /// The speed PI's integral state (A of i_q*).
    pub fn speed_integral(&self) -> T {
        self.blocks.speed.integral()
    }

    /// The realised references computed at n−1 and n−2 (the latter is what the estimator
    /// gets at the next sample).
    pub fn voltage_history(&self) -> [Ab<T>; 2] {
        self.history
    }
}
