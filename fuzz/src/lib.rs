//! Fuzz cases for fado-core (issue 6) and the checks every case must pass.
//!
//! A case is decoded from the fuzzer's bytes by `arbitrary`: a configuration (each field the
//! default or an arbitrary number) and a sequence of actions (single samples, runs of a rotating
//! sample, re-alignments, resets, run-time R̂s changes). The core's rules checked after every
//! action: no panic, every output finite, θ̂ in [−π, π], a non-finite input is flagged, and
//! (estimator) a rejected sample leaves the state as it was.
//!
//! A crashing input printed by `cargo fuzz fmt` is a `Debug` of one of these cases; it can be
//! replayed as a plain test in crates/fado-core/tests/fuzz_regressions.rs.

use arbitrary::Arbitrary;
use fado_core::control::{DriveConfig, SensorlessDrive};
use fado_core::estimator::{
    Estimate, EstimatorConfig, EstimatorTuning, RotorAngleEstimator, SensorlessEstimator,
};
use fado_core::tracker::BandwidthDefinition;
use fado_core::{Ab, Abc, MachineModel, Real};

/// A number as the fuzzer picks it: mostly plausible magnitudes, sometimes any bit pattern.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Num {
    /// `x / 100`: the range of physical values, with exact zeros.
    Centi(i16),
    /// `m · 10^e`, |e| < 40: tiny to huge, still finite in f64 (maybe not in f32).
    Scaled(i16, i8),
    /// Any f64, NaN and ±∞ included.
    Raw(f64),
}

impl Num {
    /// The value in f64.
    pub fn value(self) -> f64 {
        match self {
            Num::Centi(x) => f64::from(x) / 100.0,
            Num::Scaled(m, e) => f64::from(m) * 10f64.powi(i32::from(e) % 40),
            Num::Raw(x) => x,
        }
    }

    fn get<T: Real>(self) -> T {
        T::lit(self.value())
    }
}

fn field<T: Real>(x: Option<Num>, default: T) -> T {
    x.map_or(default, Num::get)
}

/// A pole-pair count from a fuzzed number: truncated and saturated (NaN → 0, refused).
fn count(x: Option<Num>, default: u32) -> u32 {
    x.map_or(default, |n| n.value() as u32)
}

/// What the estimator is asked to do next.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum EstimatorAction {
    /// One sample.
    Step {
        /// v_ab.
        v: [Num; 2],
        /// i_ab.
        i: [Num; 2],
    },
    /// `n` samples of a rotating voltage and current at `hz` (drives the estimator through
    /// both modes and the trackers over their whole range).
    Rotate {
        /// Voltage amplitude.
        v: Num,
        /// Current amplitude.
        i: Num,
        /// Electrical frequency in Hz.
        hz: Num,
        /// Number of samples.
        n: u8,
    },
    /// `align(theta0, i_ab)`.
    Align(Num, [Num; 2]),
    /// `reset()`.
    Reset,
    /// `set_rs_hat(rs)`.
    SetRs(Num),
    /// `set_disturbance_feedback_enabled(on)`.
    EnableKdf(bool),
}

/// An estimator configuration and a run.
#[derive(Arbitrary, Clone, Debug)]
pub struct EstimatorCase {
    /// Run in f32 instead of f64.
    pub single: bool,
    /// ts, machine R̂s, L̂q, λ̂f, then the numeric tuning fields in the order of
    /// `EstimatorTuning` up to `tracker.hold_ratio`, then `initial_angle` (None = default; the
    /// layout of the older flat config, so that the stored regressions decode as before).
    pub fields: [Option<Num>; 15],
    /// `integrator.average_current`, `observer.on_rotor_flux`, natural-frequency bandwidths.
    pub flags: [bool; 3],
    /// The R̂s-adaptation fields in the order of `EstimatorTuning` (None = default).
    pub adaptation: [Option<Num>; 5],
    /// `rs_adaptation`, `limiter.recentring` (None = default).
    pub adaptation_flags: [Option<bool>; 2],
    /// What to do.
    pub actions: Vec<EstimatorAction>,
}

impl EstimatorCase {
    /// The configuration this case asks for.
    pub fn config<T: Real>(&self) -> EstimatorConfig<T> {
        let d = EstimatorConfig::<T>::for_machine(&MachineModel::paper());
        let t = d.tuning;
        let f = &self.fields;
        EstimatorConfig {
            ts: field(f[0], d.ts),
            machine: MachineModel {
                rs: field(f[1], d.machine.rs),
                lq: field(f[2], d.machine.lq),
                flux_linkage: field(f[3], d.machine.flux_linkage),
                ..d.machine
            },
            initial_angle: field(f[14], d.initial_angle),
            tuning: {
                let mut tuned = t;
                tuned.disturbance_feedback.k_df = field(f[4], t.disturbance_feedback.k_df);
                tuned.disturbance_feedback.ramp_time = field(f[5], t.disturbance_feedback.ramp_time);
                tuned.limiter.k_af = field(f[6], t.limiter.k_af);
                tuned.limiter.radius_ratio = field(f[7], t.limiter.radius_ratio);
                tuned.mode.threshold_ratio = field(f[8], t.mode.threshold_ratio);
                tuned.mode.hysteresis_ratio = field(f[9], t.mode.hysteresis_ratio);
                tuned.tracker.t2s1_bandwidth_hz = field(f[10], t.tracker.t2s1_bandwidth_hz);
                tuned.tracker.t2s2_bandwidth_hz = field(f[11], t.tracker.t2s2_bandwidth_hz);
                tuned.tracker.damping = field(f[12], t.tracker.damping);
                tuned.tracker.hold_ratio = field(f[13], t.tracker.hold_ratio);
                tuned.integrator.average_current = self.flags[0];
                tuned.observer.on_rotor_flux = self.flags[1];
                tuned.tracker.bandwidth_definition = if self.flags[2] {
                    BandwidthDefinition::NaturalFrequency
                } else {
                    BandwidthDefinition::Minus3Db
                };
                tuned.rs_adaptation.enabled = self.adaptation_flags[0].unwrap_or(t.rs_adaptation.enabled);
                tuned.rs_adaptation.rate = field(self.adaptation[0], t.rs_adaptation.rate);
                tuned.rs_adaptation.excitation_floor = field(
                    self.adaptation[1],
                    t.rs_adaptation.excitation_floor,
                );
                tuned.rs_adaptation.min_ratio = field(self.adaptation[2], t.rs_adaptation.min_ratio);
                tuned.rs_adaptation.max_ratio = field(self.adaptation[3], t.rs_adaptation.max_ratio);
                tuned.flux_linkage_adaptation.rate = field(
                    self.adaptation[4],
                    t.flux_linkage_adaptation.rate,
                );
                tuned.offset_adaptation.rate = t.offset_adaptation.rate;
                tuned.limiter.recentring = self.adaptation_flags[1].unwrap_or(t.limiter.recentring);
                tuned
            },
        }
    }

    /// Runs the case in the precision it asks for; panics on a broken rule.
    pub fn run(&self) {
        if self.single {
            self.run_in::<f32>();
        } else {
            self.run_in::<f64>();
        }
    }

    fn run_in<T: Real>(&self) {
        let config = self.config::<T>();
        let mut est = match SensorlessEstimator::new(config) {
            Ok(e) => e,
            Err(e) => {
                assert!(!e.field().is_empty());
                return;
            }
        };
        check_estimate(&est.last());
        for action in &self.actions {
            match *action {
                EstimatorAction::Step { v, i } => {
                    step_checked(&mut est, Ab::new(v[0].get(), v[1].get()), ab(i));
                }
                EstimatorAction::Rotate { v, i, hz, n } => {
                    let (v, i, w) = (v.get::<T>(), i.get::<T>(), T::two_pi() * hz.get::<T>());
                    for k in 0..n {
                        let phase = w * config.ts * T::lit(f64::from(k));
                        let (s, c) = phase.sin_cos();
                        let u = Ab::new(c, s);
                        step_checked(&mut est, u.mul_j() * v, u * i);
                    }
                }
                EstimatorAction::Align(theta, i) => {
                    est.align(theta.get(), ab(i));
                    check_estimate(&est.last());
                }
                EstimatorAction::Reset => {
                    est.reset();
                    check_estimate(&est.last());
                }
                EstimatorAction::SetRs(rs) => {
                    let before = *est.state();
                    let rs = rs.get::<T>();
                    match est.set_rs_hat(rs) {
                        Ok(()) => assert!(rs.is_finite() && rs >= T::zero()),
                        Err(_) => assert_eq!(*est.state(), before),
                    }
                }
                EstimatorAction::EnableKdf(on) => est.set_disturbance_feedback_enabled(on),
            }
        }
    }
}

fn ab<T: Real>(x: [Num; 2]) -> Ab<T> {
    Ab::new(x[0].get(), x[1].get())
}

/// Every number an estimate carries is finite and θ̂ is wrapped.
pub fn check_estimate<T: Real>(e: &Estimate<T>) {
    let d = &e.diagnostics;
    let all = [
        e.theta,
        e.omega,
        e.omega_control,
        d.theta_direct,
        d.lambda1.alpha,
        d.lambda1.beta,
        d.disturbance.alpha,
        d.disturbance.beta,
        d.lambda2.alpha,
        d.lambda2.beta,
        d.lambda_r.alpha,
        d.lambda_r.beta,
    ];
    assert!(
        all.iter().all(|x| x.is_finite()),
        "non-finite output: {e:?}"
    );
    assert!(e.theta.abs() <= T::pi(), "θ̂ out of [−π, π]: {e:?}");
}

/// One sample with the checks of the module docs.
pub fn step_checked<T: Real>(est: &mut SensorlessEstimator<T>, v: Ab<T>, i: Ab<T>) {
    let before = *est;
    let out = est.step(v, i);
    check_estimate(&out);
    if !(v.is_finite() && i.is_finite()) {
        assert!(out.diagnostics.input_fault, "non-finite input accepted");
    }
    if out.diagnostics.input_fault {
        assert_eq!(
            est.rejected_samples(),
            before.rejected_samples().saturating_add(1)
        );
        assert_eq!(
            est.last(),
            before.last(),
            "a rejected sample changed the estimate"
        );
        // The state is unchanged iff the next sample gives the same result from both.
        let (mut a, mut b) = (*est, before);
        let probe_v = Ab::new(T::lit(3.0), T::lit(-1.0));
        let probe_i = Ab::new(T::lit(2.0), T::lit(0.5));
        assert_eq!(
            a.step(probe_v, probe_i),
            b.step(probe_v, probe_i),
            "a rejected sample changed the state"
        );
    } else {
        // `last` recomputes the diagnostics from the state; the outputs are the sample's.
        let last = est.last();
        assert_eq!(
            (last.theta, last.omega, last.omega_control, last.diagnostics.mode),
            (out.theta, out.omega, out.omega_control, out.diagnostics.mode)
        );
    }
}

/// What the drive is asked to do next.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum DriveAction {
    /// One sample.
    Step {
        /// Phase currents.
        i: [Num; 3],
        /// DC-link voltage.
        vdc: Num,
        /// Speed reference (rad/s mechanical).
        speed: Num,
    },
    /// `n` samples with rotating phase currents of amplitude `i` at `hz`, nominal DC link.
    Rotate {
        /// Current amplitude.
        i: Num,
        /// Electrical frequency in Hz.
        hz: Num,
        /// Speed reference (rad/s mechanical).
        speed: Num,
        /// Number of samples.
        n: u8,
    },
    /// `align(theta0)`.
    Align(Num),
    /// `reset()`.
    Reset,
}

/// A drive configuration and a run.
#[derive(Arbitrary, Clone, Debug)]
pub struct DriveCase {
    /// Run in f32 instead of f64.
    pub single: bool,
    /// ts; machine pole pairs (truncated to an integer), R̂s, L̂d, L̂q, λ̂f, Ĵ; tuning
    /// bandwidths, speed zero ratio, current limit ratio, injection ratio, dead time,
    /// switching frequency, threshold voltage, current band, delay factor, trip ratio, max
    /// modulation, anti-windup ratios (None = default; the layout of the older flat config, so
    /// that the stored regressions decode as before).
    pub fields: [Option<Num>; 21],
    /// `dead_time_compensation`, `decoupling`.
    pub flags: [bool; 2],
    /// Offset calibration in sampling periods.
    pub calibration: u8,
    /// What to do.
    pub actions: Vec<DriveAction>,
}

impl DriveCase {
    /// The configuration this case asks for.
    pub fn config<T: Real>(&self) -> DriveConfig<T> {
        let d = DriveConfig::<T>::for_machine(&MachineModel::paper());
        let (m, t) = (d.machine, d.tuning);
        let f = &self.fields;
        let ts = field(f[0], d.ts);
        let mut tuning = t;
        tuning.current.bandwidth_hz = field(f[7], t.current.bandwidth_hz);
        tuning.speed.bandwidth_hz = field(f[8], t.speed.bandwidth_hz);
        tuning.speed.zero_ratio = field(f[9], t.speed.zero_ratio);
        tuning.current.limit_ratio = field(f[10], t.current.limit_ratio);
        tuning.injection.current_ratio = field(f[11], t.injection.current_ratio);
        tuning.inverter.dead_time = field(f[12], t.inverter.dead_time);
        tuning.inverter.switching_frequency = field(f[13], t.inverter.switching_frequency);
        tuning.inverter.threshold_voltage = field(f[14], t.inverter.threshold_voltage);
        tuning.inverter.current_band = field(f[15], t.inverter.current_band);
        tuning.delay_compensation.factor = field(f[16], t.delay_compensation.factor);
        tuning.protection.trip_current_ratio = field(f[17], t.protection.trip_current_ratio);
        tuning.modulation.max_modulation = field(f[18], t.modulation.max_modulation);
        tuning.current.anti_windup_ratio = field(f[19], t.current.anti_windup_ratio);
        tuning.speed.anti_windup_ratio = field(f[20], t.speed.anti_windup_ratio);
        tuning.dead_time_compensation.enabled = self.flags[0];
        tuning.current.decoupling = self.flags[1];
        tuning.offset_calibration.time = ts * T::lit(f64::from(self.calibration));
        DriveConfig {
            ts,
            machine: MachineModel {
                pole_pairs: count(f[1], m.pole_pairs),
                rs: field(f[2], m.rs),
                ld: field(f[3], m.ld),
                lq: field(f[4], m.lq),
                flux_linkage: field(f[5], m.flux_linkage),
                inertia: field(f[6], m.inertia),
                ..m
            },
            tuning,
        }
    }

    /// Runs the case in the precision it asks for; panics on a broken rule.
    pub fn run(&self) {
        if self.single {
            self.run_in::<f32>();
        } else {
            self.run_in::<f64>();
        }
    }

    fn run_in<T: Real>(&self) {
        let config = self.config::<T>();
        let mut drive = match SensorlessDrive::new(config, EstimatorTuning::default()) {
            Ok(d) => d,
            Err(e) => {
                assert!(!e.field().is_empty());
                return;
            }
        };
        let vdc_nominal = config.machine.dc_voltage;
        for action in &self.actions {
            match *action {
                DriveAction::Step { i, vdc, speed } => {
                    let i = Abc::new(i[0].get(), i[1].get(), i[2].get());
                    drive_step_checked(&mut drive, i, vdc.get(), speed.get());
                }
                DriveAction::Rotate { i, hz, speed, n } => {
                    let (i, w) = (i.get::<T>(), T::two_pi() * hz.get::<T>());
                    for k in 0..n {
                        let phase = w * config.ts * T::lit(f64::from(k));
                        let i_abc = Ab::from_polar(i, phase).to_abc();
                        drive_step_checked(&mut drive, i_abc, vdc_nominal, speed.get());
                    }
                }
                DriveAction::Align(theta) => drive.align(theta.get()),
                DriveAction::Reset => drive.reset(),
            }
        }
    }
}

/// One drive sample: every output finite, duties in [0, 1], a non-finite input flagged.
pub fn drive_step_checked<T: Real>(
    drive: &mut SensorlessDrive<T, SensorlessEstimator<T>>,
    i_abc: Abc<T>,
    vdc: T,
    speed: T,
) {
    let out = drive.step(i_abc, vdc, speed);
    check_estimate(&out.estimate);
    let all = [
        out.duty.a,
        out.duty.b,
        out.duty.c,
        out.v_ref_ab.alpha,
        out.v_ref_ab.beta,
        out.i_dq.d,
        out.i_dq.q,
        out.i_dq_ref.d,
        out.i_dq_ref.q,
        out.v_dq_ref.d,
        out.v_dq_ref.q,
    ];
    assert!(
        all.iter().all(|x| x.is_finite()),
        "non-finite drive output: {out:?}"
    );
    let duty_ok = |d: T| d >= T::zero() && d <= T::one();
    assert!(
        duty_ok(out.duty.a) && duty_ok(out.duty.b) && duty_ok(out.duty.c),
        "duty out of [0, 1]: {out:?}"
    );
    if !(i_abc.is_finite() && vdc.is_finite() && speed.is_finite()) {
        assert!(out.input_fault, "non-finite drive input accepted");
    }
}

/// A reference estimator (compensated LPF, Ortega–Praly, extended EMF) and a run, with the
/// same checks as the estimator's (the drive runs any of them).
#[derive(Arbitrary, Clone, Debug)]
pub struct BaselineCase {
    /// Which: 0 LPF, 1 Ortega, 2 EMF (modulo 3).
    pub which: u8,
    /// Run in f32 instead of f64.
    pub single: bool,
    /// ts, rs_hat, lq_hat, flux_linkage_hat, t2s1/t2s2 bandwidths, damping, hold ratio,
    /// initial angle (None = default).
    pub shared: [Option<Num>; 9],
    /// The estimator's own fields in declaration order (None = default).
    pub own: [Option<Num>; 4],
    /// `integrator.average_current`.
    pub average_current: bool,
    /// What to do (`SetRs` and `EnableKdf` do not apply and are skipped).
    pub actions: Vec<EstimatorAction>,
}

impl BaselineCase {
    /// Runs the case; panics on a broken rule.
    pub fn run(&self) {
        if self.single {
            self.run_in::<f32>();
        } else {
            self.run_in::<f64>();
        }
    }

    /// The machine model and the shared record with the case's `shared` fields.
    fn shared<T: Real>(&self) -> (MachineModel<T>, fado_core::baselines::CommonTuning<T>) {
        let s = &self.shared;
        let m = MachineModel::<T>::paper();
        let d = fado_core::baselines::CommonTuning::<T>::default();
        let machine = MachineModel {
            rs: field(s[1], m.rs),
            lq: field(s[2], m.lq),
            flux_linkage: field(s[3], m.flux_linkage),
            ..m
        };
        let common = fado_core::baselines::CommonTuning {
            ts: field(s[0], d.ts),
            t2s1_bandwidth_hz: field(s[4], d.t2s1_bandwidth_hz),
            t2s2_bandwidth_hz: field(s[5], d.t2s2_bandwidth_hz),
            tracker_damping: field(s[6], d.tracker_damping),
            tracker_hold_ratio: field(s[7], d.tracker_hold_ratio),
            initial_angle: field(s[8], d.initial_angle),
            average_current: self.average_current,
            ..d
        };
        (machine, common)
    }

    fn run_in<T: Real>(&self) {
        use fado_core::baselines::*;
        let o = &self.own;
        let (machine, common) = self.shared::<T>();
        let ts = common.ts;
        match self.which % 3 {
            0 => {
                let d = LpfIntegratorSettings::<T>::default();
                let settings = LpfIntegratorSettings {
                    cutoff_hz: field(o[0], d.cutoff_hz),
                    compensation_floor_hz: field(o[1], d.compensation_floor_hz),
                };
                if let Ok(e) = LpfIntegratorEstimator::build(&machine, &common, &settings) {
                    run_baseline(e, ts, &self.actions);
                }
            }
            1 => {
                let d = OrtegaSettings::<T>::default();
                let settings = OrtegaSettings {
                    observer_bandwidth: field(o[0], d.observer_bandwidth),
                    observer_speed_ratio: field(o[1], d.observer_speed_ratio),
                    observer_bandwidth_min: field(o[2], d.observer_bandwidth_min),
                    flux_adaptation_ratio: field(o[3], d.flux_adaptation_ratio),
                };
                if let Ok(e) = OrtegaEstimator::build(&machine, &common, &settings) {
                    run_baseline(e, ts, &self.actions);
                }
            }
            _ => {
                let d = EmfObserverSettings::<T>::default();
                let settings = EmfObserverSettings {
                    emf_bandwidth_hz: field(o[0], d.emf_bandwidth_hz),
                    speed_floor_hz: field(o[1], d.speed_floor_hz),
                };
                if let Ok(e) = EmfObserverEstimator::build(&machine, &common, &settings) {
                    run_baseline(e, ts, &self.actions);
                }
            }
        }
    }
}

fn run_baseline<T: Real, E: RotorAngleEstimator<T> + Copy>(
    mut est: E,
    ts: T,
    actions: &[EstimatorAction],
) {
    let step = |est: &mut E, v: Ab<T>, i: Ab<T>| {
        let before = *est;
        let out = est.step(v, i);
        check_estimate(&out);
        if !(v.is_finite() && i.is_finite()) {
            assert!(out.diagnostics.input_fault, "non-finite input accepted");
        }
        if out.diagnostics.input_fault {
            let (mut a, mut b) = (*est, before);
            let probe_v = Ab::new(T::lit(3.0), T::lit(-1.0));
            let probe_i = Ab::new(T::lit(2.0), T::lit(0.5));
            assert_eq!(
                a.step(probe_v, probe_i),
                b.step(probe_v, probe_i),
                "a rejected sample changed the state"
            );
        }
    };
    for action in actions {
        match *action {
            EstimatorAction::Step { v, i } => step(&mut est, ab(v), ab(i)),
            EstimatorAction::Rotate { v, i, hz, n } => {
                let (v, i, w) = (v.get::<T>(), i.get::<T>(), T::two_pi() * hz.get::<T>());
                for k in 0..n {
                    let u = Ab::from_polar(T::one(), w * ts * T::lit(f64::from(k)));
                    step(&mut est, u.mul_j() * v, u * i);
                }
            }
            EstimatorAction::Align(theta, i) => est.align(theta.get(), ab(i)),
            EstimatorAction::Reset => est.reset(),
            EstimatorAction::SetRs(_) | EstimatorAction::EnableKdf(_) => {}
        }
    }
}
