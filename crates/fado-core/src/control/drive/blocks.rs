//! The control blocks around the estimator, built from a [`DriveConfig`], and the
//! modulation of a voltage reference through them.

use super::{Applied, Blocks, DriveConfig, Resolved};
use crate::control::current_controller::{CurrentController, CurrentControllerConfig};
use crate::control::dc_link_limit::DcLinkLimit;
use crate::control::dead_time_compensation::{DeadTimeCompensation, DeadTimeCompensationConfig};
use crate::control::delay_compensation::{DelayCompensation, DelayCompensationConfig};
use crate::control::field_weakening::FieldWeakening;
use crate::control::lock_reaction::LockSupervisor;
use crate::control::modulation::{ModulatorConfig, SpaceVectorModulator};
use crate::control::phase_band::PhaseBand;
use crate::control::ratings_limit::RatingsLimit;
use crate::control::release_hold::{
    ReleaseHold, SATURATING_SPEED_FILTER_RATIO, holds_through_standstill,
};
use crate::control::saturated_references::SaturatedReferences;
use crate::control::speed_controller::{SpeedController, SpeedControllerConfig};
use crate::control::standstill_probe::{StandstillProbe, StandstillProbeConfig};
use crate::control::start_ramp::StartRamp;
use crate::error::{ConfigError, check};
use crate::injection::{CurrentInjection, CurrentInjectionConfig};
use crate::{Ab, Abc, Dq, Real, Rotation};

impl<T: Real> Blocks<T> {
    /// Dead-time compensation, hexagon limit and SVPWM of the reference `v_ab` (`v_dq` in the
    /// frame of `rot`; `i_dq_ref` and the measured `i_dq` in the frame of θ̂), and the voltage
    /// that then acts, back-calculated without the compensation where the modulator limited
    /// it (zero without a DC link). None when anything is non-finite.
    #[inline(always)]
    pub(super) fn modulate(
        &mut self,
        rot: Rotation<T>,
        v_ab: Ab<T>,
        v_dq: Dq<T>,
        (i_dq_ref, i_dq): (Dq<T>, Dq<T>),
        i_abc: Abc<T>,
        vdc: T,
    ) -> Option<Applied<T>> {
        // While the release hold catches a fall, the compensation stays at the reference:
        // the hold's stiffness is set for the inverter error the compensation at the
        // reference leaves inside the band (`ReleaseHold`'s dead-time softening).
        let holding = self.hold.tracking_fall() || self.hold.active();
        let i_dq = if holding { i_dq_ref } else { i_dq };
        let comp = self
            .dead_time
            .phase_voltages_followed(rot, i_dq_ref, i_dq, i_abc, v_ab, vdc);
        let m = self.modulator.step(v_ab + comp.to_ab(), vdc);
        let (v_ab, v_dq) = if !m.saturated {
            (v_ab, v_dq) // exactly what was asked for: nothing to back-calculate
        } else if vdc > T::zero() {
            // A leg the limit holds at duty 0 or 1 has no edge and loses no dead time.
            let v = m.v_ab - self.dead_time.lost(comp, rot, i_dq_ref, m.duty).to_ab();
            (v, v.to_dq(rot))
        } else {
            (Ab::zero(), Dq::zero())
        };
        (v_ab.is_finite() && v_dq.is_finite() && m.duty.is_finite()).then_some(Applied {
            duty: m.duty,
            v_ab,
            v_dq,
            saturated: m.saturated,
        })
    }

    pub(super) fn new(c: &DriveConfig<T>, r: &Resolved<T>) -> Result<Self, ConfigError> {
        check_limits(c, r)?;
        let ts = c.ts;
        let t = &c.tuning;
        let m = &c.machine;
        // The speed PI's output is a torque in units of the magnet's q current (see
        // `currents_for_torque`): with MTPA on a salient rotor its limit is the torque of the
        // MTPA point on the current circle |i| = I_max (`SpeedControllerConfig::torque_limit`).
        let speed_config = SpeedControllerConfig {
            bandwidth_hz: t.speed.bandwidth_hz,
            zero_ratio: t.speed.zero_ratio,
            anti_windup_ratio: t.speed.anti_windup_ratio,
            i_max: c.speed_torque_limit(r.saturated.as_ref(), t.mtpa.enabled),
            ..SpeedControllerConfig::new(
                m,
                t.current.limit_ratio * m.rated_current,
                t.mtpa.enabled,
                ts,
            )
        };
        let dc_link = DcLinkLimit::new(&t.dc_link, m, speed_config.i_max, r.i_max, ts)?;
        if t.field_weakening.voltage_margin > T::one()
            && t.modulation.voltage_limit
                != crate::control::modulation::VoltageLimit::Overmodulation
        {
            return Err(ConfigError::OutOfRange {
                field: "field_weakening.voltage_margin",
                expected: "at most 1 unless voltage_limit = \"overmodulation\"",
            });
        }
        let field_weakening = FieldWeakening::new(&t.field_weakening, m, r.i_max, ts)?;
        let speed = SpeedController::new(speed_config).map_err(rename(&[
            ("bandwidth_hz", "speed_bandwidth_hz"),
            ("zero_ratio", "speed_zero_ratio"),
            ("anti_windup_ratio", "speed_anti_windup_ratio"),
        ]))?;
        let injection = CurrentInjection::new(CurrentInjectionConfig { i_min: c.i_min() })?
            .along(c.injection_direction());
        let current_config = c.current_controller_config_with(r.saturated.as_ref());
        let current = CurrentController::new(current_config).map_err(rename(&[
            ("bandwidth_hz", "current_bandwidth_hz"),
            ("anti_windup_ratio", "current_anti_windup_ratio"),
        ]))?;
        let delay = DelayCompensation::new(DelayCompensationConfig {
            ts,
            factor: t.delay_compensation.factor,
        })
        .map_err(rename(&[("factor", "delay_compensation_factor")]))?;
        let mut dead_time =
            DeadTimeCompensation::new(c.dead_time_compensation_config()).map_err(rename(&[
                ("threshold_voltage", "dead_time_threshold_voltage"),
                ("current_band", "dead_time_current_band"),
            ]))?;
        dead_time.set_current_loop(t.current.bandwidth_hz, ts);
        let modulator = SpaceVectorModulator::new(ModulatorConfig {
            limit: t.modulation.voltage_limit,
            max_modulation: t.modulation.max_modulation,
        })?;
        let probe_config = probe_config(c)?;
        let mut probe = StandstillProbe::new(probe_config)?;
        let hold = release_hold(c, &probe_config, speed_config.i_max)?;
        probe.set_release_catch(hold.stiffness());
        let limits = RatingsLimit::new(&t.limits, m)?;
        let start_ramp = StartRamp::new(&t.start_ramp, m, ts)?;
        Ok(Self {
            hold,
            phase_band: PhaseBand::new(m, dead_time.config()),
            speed,
            injection,
            current,
            delay,
            dead_time,
            modulator,
            probe,
            dc_link,
            field_weakening,
            limits,
            start_ramp,
        })
    }

    pub(super) fn reset(&mut self) {
        self.speed.reset();
        self.injection.reset();
        self.current.reset();
        self.delay.reset();
        self.dead_time.reset();
        self.modulator.reset();
        self.probe.reset();
        self.dc_link.reset();
        self.field_weakening.reset();
        self.hold.disarm();
        self.phase_band.reset();
        self.start_ramp.disarm();
    }
}

impl<T: Real> DriveConfig<T> {
    /// The current loop of the machine model with the tuning's `current.bandwidth_hz`,
    /// `decoupling` and `current.anti_windup_ratio`: what the drive builds.
    pub fn current_controller_config(&self) -> CurrentControllerConfig<T> {
        self.current_controller_config_with(self.saturated_references().as_ref())
    }

    /// [`DriveConfig::current_controller_config`] with the saturating model's references
    /// built already.
    fn current_controller_config_with(
        &self,
        saturated: Option<&SaturatedReferences<T>>,
    ) -> CurrentControllerConfig<T> {
        let t = &self.tuning;
        // A saturating model: the incremental inductances at the rated MTPA point
        // (`crate::control::saturated_references`).
        let (ld_hat, lq_hat) = self.current_loop_inductances(saturated);
        CurrentControllerConfig {
            ld_hat,
            lq_hat,
            bandwidth_hz: t.current.bandwidth_hz,
            decoupling: t.current.decoupling,
            anti_windup_ratio: t.current.anti_windup_ratio,
            ..CurrentControllerConfig::for_machine(&self.machine, self.ts)
        }
    }

    /// The dead-time compensation of the machine model with the tuning's inverter data
    /// (`dead_time`, `switching_frequency`, `inverter.threshold_voltage`,
    /// `inverter.current_band`) and method: what the drive builds.
    pub fn dead_time_compensation_config(&self) -> DeadTimeCompensationConfig<T> {
        let t = &self.tuning;
        DeadTimeCompensationConfig {
            enabled: t.dead_time_compensation.enabled,
            method: t.dead_time_compensation.method,
            dead_time: t.inverter.dead_time,
            switching_frequency: t.inverter.switching_frequency,
            threshold_voltage: t.inverter.threshold_voltage,
            current_band: t.inverter.current_band,
            ..DeadTimeCompensationConfig::for_machine(&self.machine)
        }
    }
}

/// The limits that involve several fields: the injection within the current limit, the trip
/// above it, the stuck-sensor thresholds, the plausibility ratios and the lock supervisor.
fn check_limits<T: Real>(c: &DriveConfig<T>, r: &Resolved<T>) -> Result<(), ConfigError> {
    let t = &c.tuning;
    // The configured level, before the bound on a salient rotor (`DriveConfig::i_min`).
    let (i_max, i_min) = (r.i_max, t.injection.current_ratio * c.machine.rated_current);
    if i_min > i_max {
        return Err(ConfigError::OutOfRange {
            field: "injection_current_ratio",
            expected: "at most current_limit_ratio",
        });
    }
    if r.trip_current <= i_max {
        return Err(ConfigError::OutOfRange {
            field: "trip_current_ratio",
            expected: "above current_limit_ratio",
        });
    }
    let band = check::non_negative("stuck_sensor_band_ratio", t.stuck_sensor.band_ratio)?;
    let min_ref = check::positive(
        "stuck_sensor_reference_ratio",
        t.stuck_sensor.reference_ratio,
    )?;
    if min_ref <= band {
        return Err(ConfigError::OutOfRange {
            field: "stuck_sensor_reference_ratio",
            expected: "above stuck_sensor_band_ratio",
        });
    }
    check::below(
        "plausible_current_ratio",
        T::one(),
        check::finite(
            "plausible_current_ratio",
            c.tuning.plausibility.current_ratio,
        )?,
        "above 1",
    )?;
    check::positive("dc_link_max_ratio", c.tuning.plausibility.dc_link_ratio)?;
    LockSupervisor::new(
        c.tuning.lock.reaction,
        c.ts,
        c.tuning.lock.recovery_time,
        c.tuning.lock.recovery_timeout,
        0,
    )?;
    Ok(())
}

/// A block's error renamed by `map` (block field → drive field).
fn rename(map: &'static [(&'static str, &'static str)]) -> impl Fn(ConfigError) -> ConfigError {
    move |e: ConfigError| {
        let field = map
            .iter()
            .find(|(from, _)| *from == e.field())
            .map_or(e.field(), |(_, to)| *to);
        match e {
            ConfigError::NotFinite { .. } => ConfigError::NotFinite { field },
            ConfigError::NotPositive { .. } => ConfigError::NotPositive { field },
            ConfigError::Negative { .. } => ConfigError::Negative { field },
            ConfigError::OutOfRange { expected, .. } => ConfigError::OutOfRange { field, expected },
        }
    }
}

/// The release hold for the drive's torque limit `i_max` (A), through the loaded standstill
/// where the probe of `probe` would swing the rotor beyond its design travel
/// ([`holds_through_standstill`]).
fn release_hold<T: Real>(
    c: &DriveConfig<T>,
    probe: &StandstillProbeConfig<T>,
    i_max: T,
) -> Result<ReleaseHold<T>, ConfigError> {
    let (t, m) = (&c.tuning, &c.machine);
    let mut hold = ReleaseHold::new(&t.release_hold, m, c.ts, t.current.bandwidth_hz, i_max)?;
    let through = holds_through_standstill(&t.release_hold, m, probe.amplitude, probe.period);
    hold.set_through_standstill(through);
    hold.set_speed_loop(t.speed.bandwidth_hz, t.speed.zero_ratio);
    if !m.magnetic_model().is_linear() {
        hold.set_speed_filter_ratio(T::lit(SATURATING_SPEED_FILTER_RATIO));
        hold.set_saturating(true);
    } else {
        let d = c.dead_time_compensation_config();
        hold.set_dead_time_voltage(
            d.error_voltage(d.dc_voltage),
            m.flux_linkage,
            m.is_salient(),
        );
    }
    Ok(hold)
}

/// The loaded-standstill probe's configuration in absolute units (amplitude 0: off).
fn probe_config<T: Real>(c: &DriveConfig<T>) -> Result<StandstillProbeConfig<T>, ConfigError> {
    let (t, m) = (&c.tuning, &c.machine);
    let rated = m.rated_current;
    Ok(StandstillProbeConfig {
        ts: c.ts,
        amplitude: if t.standstill_probe.enabled {
            check::non_negative(
                "standstill_probe_current_ratio",
                t.standstill_probe.current_ratio,
            )? * rated
        } else {
            T::zero()
        },
        period: t.standstill_probe.period,
        gain: t.standstill_probe.gain,
        max_speed: check::non_negative(
            "standstill_probe_speed_ratio",
            t.standstill_probe.speed_ratio,
        )? * m.rated_speed(),
        min_load: check::non_negative(
            "standstill_probe_load_ratio",
            t.standstill_probe.load_ratio,
        )? * rated,
        inertia: {
            let p = T::lit(m.pole_pairs as f64);
            m.inertia / (T::lit(1.5) * p * p * m.flux_linkage)
        },
        swing: check::non_negative(
            "standstill_probe_swing_ratio",
            t.standstill_probe.swing_ratio,
        )? * m.rated_speed(),
        arm_time: t.standstill_probe.arm_time,
    })
}
