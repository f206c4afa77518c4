//! The firmware path of the estimator — [`EstimatorState`] stepped with a borrowed
//! [`EstimatorParams`] (docs/guide/firmware.md) — is the owner's step
//! ([`SensorlessEstimator`]) bit for bit: the same outputs and the same state after every
//! sample, accepted and rejected ones, with and without the R̂s adaptation, through the
//! run-time settings (`set_rs_hat`, `enable_rs_adaptation`, `align`, `reset`, the k_df
//! switch), in `f32` and `f64`, on a surface-magnet and an interior-magnet motor.

mod common;

use common::ipmsm_model;
use fado_core::{
    Ab, EstimatorConfig, EstimatorParams, EstimatorState, LeanEstimate, MachineModel, Mode, Real,
    RotorAngleEstimator, SensorlessEstimator,
};

/// A rotor-frame operating point turned into α-β: flux e^{jθ}·(λf + Ld·i_d + j·Lq·i_q) and
/// current e^{jθ}·(i_d + j·i_q); the voltage is Rs·i plus the flux's change over the sample.
struct Signal {
    model: MachineModel<f64>,
    theta: f64,
    flux: Ab<f64>,
    current: Ab<f64>,
}

impl Signal {
    fn new(model: MachineModel<f64>) -> Self {
        Self {
            model,
            theta: 0.0,
            flux: Ab::new(model.flux_linkage, 0.0),
            current: Ab::zero(),
        }
    }

    /// The sample after turning by ω·Ts with the rotor-frame current (i_d, i_q).
    fn sample(&mut self, omega: f64, i_d: f64, i_q: f64, ts: f64) -> (Ab<f64>, Ab<f64>) {
        let m = &self.model;
        self.theta += omega * ts;
        let (s, c) = self.theta.sin_cos();
        let rotate = |d: f64, q: f64| Ab::new(c * d - s * q, s * d + c * q);
        let flux = rotate(m.flux_linkage + m.ld * i_d, m.lq * i_q);
        let current = rotate(i_d, i_q);
        let v = (self.current + current) * (0.5 * m.rs) + (flux - self.flux) * (1.0 / ts);
        self.flux = flux;
        self.current = current;
        (v, current)
    }
}

/// Steps the owner and the split state side by side over standstill with a d-axis current
/// (the standstill laws), a ramp through the Fig. 3 threshold under load and a hold at speed
/// (the turning laws, the λ̂f law), with rejected samples and run-time settings on the way.
/// Returns (mode changes seen, R̂s moved) so that the caller can check the run exercised the
/// laws.
fn split_matches_owner<T: Real>(model: MachineModel<f64>, rs_adaptation: bool) -> (u32, bool) {
    let mut config = EstimatorConfig::for_machine(&model.cast::<T>());
    config.tuning.rs_adaptation.enabled = rs_adaptation;
    let params = EstimatorParams::new(config).unwrap();
    let mut state = EstimatorState::new(&params);
    let mut owner = SensorlessEstimator::new(config).unwrap();
    assert_eq!(owner.params(), &params);
    assert_eq!(owner.state(), &state);
    let ts = 1e-4;
    let rated = model.rated_current;
    let omega_top = 2.0 * core::f64::consts::PI * 0.3 * model.rated_frequency_hz();
    let mut signal = Signal::new(model);
    let (mut mode, mut mode_changes) = (Mode::Limiter, 0);
    let rs0 = owner.rs_hat();
    let mut rs_moved = false;
    let cast = |x: Ab<f64>| Ab::new(T::lit(x.alpha), T::lit(x.beta));
    for n in 0..24_000 {
        let t = n as f64 * ts;
        // 0.4 s at standstill with i_d = 0.3·rated, then 1 s of ramp to ω_top under
        // i_q = 0.4·rated, then the hold.
        let (omega, i_d, i_q) = if t < 0.4 {
            (0.0, 0.3 * rated, 0.0)
        } else {
            (omega_top * ((t - 0.4) / 1.0).min(1.0), 0.0, 0.4 * rated)
        };
        let (v, i) = signal.sample(omega, i_d, i_q, ts);
        let (v, i) = match n {
            // Non-finite, implausibly large, and a current jump the machine cannot make.
            3_001 => (Ab::new(f64::NAN, 0.0), i),
            9_002 => (v, Ab::new(1e7, 0.0)),
            15_003 => (v, i + Ab::new(50.0 * rated, 0.0)),
            _ => (v, i),
        };
        let (v, i) = (cast(v), cast(i));
        // Every other sample the lean step, so that both outputs are compared.
        if n % 2 == 0 {
            let a = owner.step(v, i);
            let b = state.step(&params, v, i);
            assert_eq!(a, b, "sample {n}");
        } else {
            let a: LeanEstimate<T> = owner.step_lean(v, i);
            let b = state.step_lean(&params, v, i);
            assert_eq!(a, b, "sample {n}");
        }
        assert_eq!(owner.state(), &state, "sample {n}");
        assert_eq!(owner.last(), state.last(&params), "sample {n}");
        let now = owner.last().diagnostics.mode;
        if now != mode {
            mode_changes += 1;
            mode = now;
        }
        rs_moved |= owner.rs_hat() != rs0;
        // Run-time settings, applied to both.
        match n {
            6_000 => {
                let rs = T::lit(1.05 * model.rs);
                owner.set_rs_hat(rs).unwrap();
                state.set_rs_hat(&params, rs).unwrap();
                assert!(owner.set_rs_hat(T::lit(-1.0)).is_err());
                assert!(state.set_rs_hat(&params, T::lit(-1.0)).is_err());
            }
            12_000 => {
                owner.enable_rs_adaptation();
                state.enable_rs_adaptation(&params);
            }
            16_000 => {
                owner.set_disturbance_feedback_enabled(false);
                state.set_disturbance_feedback_enabled(false);
            }
            16_500 => {
                owner.set_disturbance_feedback_enabled(true);
                state.set_disturbance_feedback_enabled(true);
                owner.rearm_lock_detector();
                state.rearm_lock_detector();
            }
            _ => {}
        }
        assert_eq!(owner.state(), &state, "after the settings of sample {n}");
    }
    assert_eq!(owner.rejected_samples(), state.rejected_samples());
    assert!(owner.rejected_samples() >= 3);
    // Align and reset take both back to the same start.
    owner.align(T::lit(0.7), cast(Ab::new(1.0, -0.5)));
    state.align(&params, T::lit(0.7), cast(Ab::new(1.0, -0.5)));
    assert_eq!(owner.state(), &state);
    owner.reset();
    state.reset(&params);
    assert_eq!(owner.state(), &state);
    (mode_changes, rs_moved)
}

fn check<T: Real>(model: MachineModel<f64>) {
    for rs_adaptation in [true, false] {
        let (mode_changes, rs_moved) = split_matches_owner::<T>(model, rs_adaptation);
        // The run crossed the Fig. 3 threshold, and R̂s adapted (from the start, or once
        // `enable_rs_adaptation` switched the fixed-R̂s estimator over).
        assert!(mode_changes >= 1, "{mode_changes}");
        assert!(rs_moved);
    }
}

#[test]
fn split_step_is_the_owners_step_paper_motor() {
    check::<f32>(MachineModel::paper());
    check::<f64>(MachineModel::paper());
}

#[test]
fn split_step_is_the_owners_step_salient_motor() {
    check::<f32>(ipmsm_model());
    check::<f64>(ipmsm_model());
}
