//! An ideal PMSM signal generator for open-loop estimator checks: a few lines, not the
//! simulator. The voltage is the exact interval average that moves the flux from one sample
//! to the next, so the only errors left are the estimator's own.

#![allow(dead_code)]

use fado_core::{Ab, Dq, EstimatorConfig, MachineModel, Real, Rotation};

/// Motor of docs/method/estimator.md, "The paper's motor and drive".
pub const RS: f64 = 0.327;
/// Inductance (SMPMSM, Ld = Lq).
pub const L: f64 = 2.63e-3;
/// Magnet flux linkage.
pub const LF: f64 = 0.088;
/// Pole pairs.
pub const PP: f64 = 4.0;
/// Sampling period.
pub const TS: f64 = 100e-6;

/// The estimator's default configuration for this motor ([`MachineModel::paper`], whose
/// parameters are the constants above; `machine_constants_are_the_paper_preset` in
/// `estimator_open_loop.rs` checks it), at 10 kHz.
pub fn default_config<T: Real>() -> EstimatorConfig<T> {
    EstimatorConfig::for_machine(&MachineModel::paper())
}

/// [`default_config`] changed by `f`.
pub fn config_with<T: Real>(f: impl FnOnce(&mut EstimatorConfig<T>)) -> EstimatorConfig<T> {
    let mut c = default_config();
    f(&mut c);
    c
}

/// One sample of the ideal machine at electrical angle `theta` with rotor currents `i_dq`.
pub fn flux_and_current(theta: f64, i_dq: Dq<f64>) -> (Ab<f64>, Ab<f64>) {
    let rot = Rotation::from_angle(theta);
    let lambda = Dq::new(LF + L * i_dq.d, L * i_dq.q).to_ab(rot);
    (lambda, i_dq.to_ab(rot))
}

/// Samples (v applied over the interval ending at n, i[n], θ[n]) for a constant speed
/// `speed_rpm` (mechanical r/min at the user edge) and constant rotor currents, with an optional
/// constant voltage error added to v (an uncompensated integrand error).
pub fn constant_speed(
    speed_rpm: f64,
    theta0: f64,
    i_dq: Dq<f64>,
    samples: usize,
    v_error: Ab<f64>,
) -> impl Iterator<Item = (Ab<f64>, Ab<f64>, f64)> {
    let w = speed_rpm * PP * core::f64::consts::TAU / 60.0;
    let (mut lambda_prev, mut i_prev) = flux_and_current(theta0, i_dq);
    (1..=samples).map(move |n| {
        let theta = theta0 + w * TS * n as f64;
        let (lambda, i) = flux_and_current(theta, i_dq);
        let v = (lambda - lambda_prev) * (1.0 / TS) + (i + i_prev) * (0.5 * RS) + v_error;
        lambda_prev = lambda;
        i_prev = i;
        (v, i, theta)
    })
}

/// One sample of a [`profile`]: what the estimator is given and the truth behind it.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    /// Voltage applied over the interval ending at this sample (plus any voltage error).
    pub v: Ab<f64>,
    /// Current as measured now (true current plus any sensor offset).
    pub i: Ab<f64>,
    /// True electrical rotor angle.
    pub theta: f64,
    /// True electrical speed (rad/s).
    pub omega: f64,
}

/// Samples of the ideal machine following the electrical speed `speed(t)` (rad/s) with rotor
/// currents `i_dq(t)`, starting at `theta0` (t = 0 is sample 0, which is not emitted). The angle
/// integrates the speed by the trapezoidal rule. `v_error` is added to the voltage (an
/// integrand error), `i_offset` to the measured current (a sensor offset); the voltage itself
/// is computed from the true current.
pub fn profile(
    theta0: f64,
    samples: usize,
    speed: impl Fn(f64) -> f64,
    i_dq: impl Fn(f64) -> Dq<f64>,
    v_error: Ab<f64>,
    i_offset: Ab<f64>,
) -> impl Iterator<Item = Sample> {
    let mut theta = theta0;
    let mut omega = speed(0.0);
    let (mut lambda_prev, mut i_prev) = flux_and_current(theta0, i_dq(0.0));
    (1..=samples).map(move |n| {
        let t = TS * n as f64;
        let omega_now = speed(t);
        theta += 0.5 * TS * (omega + omega_now);
        omega = omega_now;
        let (lambda, i) = flux_and_current(theta, i_dq(t));
        let v = (lambda - lambda_prev) * (1.0 / TS) + (i + i_prev) * (0.5 * RS) + v_error;
        lambda_prev = lambda;
        i_prev = i;
        Sample {
            v,
            i: i + i_offset,
            theta,
            omega,
        }
    })
}

/// Electrical rad/s from mechanical r/min (the user-facing unit of the paper's figures).
pub fn rpm_to_electrical(rpm: f64) -> f64 {
    rpm * PP * core::f64::consts::TAU / 60.0
}

/// A machine for the generic generator [`machine_profile`] (salient allowed).
#[derive(Clone, Copy, Debug)]
pub struct Machine {
    /// Stator resistance, Ω.
    pub rs: f64,
    /// d-axis inductance, H.
    pub ld: f64,
    /// q-axis inductance, H.
    pub lq: f64,
    /// Magnet flux linkage, Wb.
    pub lf: f64,
    /// Pole pairs.
    pub pp: f64,
}

/// The 2.2 kW interior-magnet motor of the `ipmsm-2k2` preset as a `MachineModel` (p 3, Rs 3.6 Ω, Ld 36 mH,
/// Lq 51 mH, λf 0.545 Wb, J 0.02 kg·m², B 2e-3 N·m·s/rad, 6 A peak, 1500 r/min, 14.9 N·m:
/// magnet plus reluctance torque at the MTPA point of 6 A, 540 V DC link): the one definition
/// the tests start from, overriding what a test needs.
pub fn ipmsm_model() -> MachineModel<f64> {
    MachineModel {
        rs: Machine::IPMSM.rs,
        ld: Machine::IPMSM.ld,
        lq: Machine::IPMSM.lq,
        flux_linkage: Machine::IPMSM.lf,
        pole_pairs: 3,
        inertia: 0.02,
        viscous_friction: 2e-3,
        rated_current: Machine::IPMSM_RATED_CURRENT,
        rated_speed_rpm: 1500.0,
        rated_torque: 14.9,
        dc_voltage: 540.0,
        magnetics: Default::default(),
    }
}

/// The 50 kW automotive IPMSM of motors/ipmsm-gem-50k.toml (gym-electric-motor's default
/// PMSM: 18 mΩ, Lq/Ld 3.24, 240 A, 3000 r/min, 160.6 N·m, its inertia small for its torque)
/// on a `dc_voltage` link.
pub fn gem_50k_model(dc_voltage: f64) -> MachineModel<f64> {
    MachineModel {
        rs: 0.018,
        ld: 0.37e-3,
        lq: 1.2e-3,
        flux_linkage: 0.066,
        pole_pairs: 3,
        inertia: 0.03883,
        viscous_friction: 5.1e-3,
        rated_current: 240.0,
        rated_speed_rpm: 3000.0,
        rated_torque: 160.6,
        dc_voltage,
        magnetics: Default::default(),
    }
}

impl Machine {
    /// The paper's surface-magnet motor ([`RS`], [`L`], [`LF`], [`PP`]).
    pub const PAPER: Machine = Machine {
        rs: RS,
        ld: L,
        lq: L,
        lf: LF,
        pp: PP,
    };
    /// The 2.2 kW interior-magnet motor of the `ipmsm-2k2` preset (p 3, Rs 3.6 Ω, Ld 36 mH, Lq 51 mH,
    /// λf 0.545 Wb, 6 A peak rated, 1500 r/min).
    pub const IPMSM: Machine = Machine {
        rs: 3.6,
        ld: 36e-3,
        lq: 51e-3,
        lf: 0.545,
        pp: 3.0,
    };
    /// Its rated current, A peak.
    pub const IPMSM_RATED_CURRENT: f64 = 6.0;

    /// Torque 1.5·p·(λf·i_q + (Ld − Lq)·i_d·i_q), N·m.
    pub fn torque(&self, i_dq: Dq<f64>) -> f64 {
        1.5 * self.pp * (self.lf * i_dq.q + (self.ld - self.lq) * i_dq.d * i_dq.q)
    }

    /// The q current giving `torque` with a d current `i_d`.
    pub fn iq_for(&self, torque: f64, i_d: f64) -> f64 {
        torque / (1.5 * self.pp * (self.lf + (self.ld - self.lq) * i_d))
    }

    /// Stator flux and current in α-β at angle `theta`.
    pub fn flux_and_current(&self, theta: f64, i_dq: Dq<f64>) -> (Ab<f64>, Ab<f64>) {
        let rot = Rotation::from_angle(theta);
        let lambda = Dq::new(self.lf + self.ld * i_dq.d, self.lq * i_dq.q).to_ab(rot);
        (lambda, i_dq.to_ab(rot))
    }
}

/// [`profile`] for any [`Machine`]: the exact interval-average voltage of the ideal machine
/// following `speed(t)` (rad/s electrical) with rotor currents `i_dq(t)`, plus `v_error`;
/// `i_offset` is added to the measured current.
pub fn machine_profile(
    m: Machine,
    theta0: f64,
    samples: usize,
    speed: impl Fn(f64) -> f64,
    i_dq: impl Fn(f64) -> Dq<f64>,
    v_error: Ab<f64>,
    i_offset: Ab<f64>,
) -> impl Iterator<Item = Sample> {
    let mut theta = theta0;
    let mut omega = speed(0.0);
    let (mut lambda_prev, mut i_prev) = m.flux_and_current(theta0, i_dq(0.0));
    (1..=samples).map(move |n| {
        let t = TS * n as f64;
        let omega_now = speed(t);
        theta += 0.5 * TS * (omega + omega_now);
        omega = omega_now;
        let (lambda, i) = m.flux_and_current(theta, i_dq(t));
        let v = (lambda - lambda_prev) * (1.0 / TS) + (i + i_prev) * (0.5 * m.rs) + v_error;
        lambda_prev = lambda;
        i_prev = i;
        Sample {
            v,
            i: i + i_offset,
            theta,
            omega,
        }
    })
}
