//! One decimated row of the trace: the columns of `traces.csv`.

use serde::{Deserialize, Serialize};

use super::{RPM_PER_RAD_S, Sample};

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
    /// R̂s the estimator integrated with, Ω (moves with `[estimator.rs_adaptation] enabled`).
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

    /// The columns that are integers (flags, the status word, the lock code): `traces.csv`
    /// prints them without a decimal point.
    const INTEGER_COLUMNS: [bool; 40] = {
        let mut integer = [false; 40];
        let mut k = 24; // flag_limit, limiter_clamping, tracker_hold, tripped
        while k < 28 {
            integer[k] = true;
            k += 1;
        }
        integer[38] = true; // fault_flags
        integer[39] = true; // lock
        integer
    };

    /// Appends the row as one line of `traces.csv` (fields in [`COLUMNS`](Self::COLUMNS)
    /// order, `\n` at the end): the bytes the `csv` crate's serializer writes for it.
    pub fn write_csv_line(&self, out: &mut Vec<u8>) {
        let mut float = zmij::Buffer::new();
        let mut int = itoa::Buffer::new();
        for (k, (value, integer)) in self
            .values()
            .into_iter()
            .zip(Self::INTEGER_COLUMNS)
            .enumerate()
        {
            if k > 0 {
                out.push(b',');
            }
            if integer {
                // Every integer column is a u8 or u16, exact in an f64.
                out.extend_from_slice(int.format(value as u16).as_bytes());
            } else {
                push_float(out, value, &mut float);
            }
        }
        out.push(b'\n');
    }

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

/// Appends `value` as `ryu` prints it (what `csv` writes): `zmij`'s digits and form, which
/// are `ryu`'s but for a positive exponent's `+` (`1e+16`, `ryu` `1e16`), which only
/// |value| ≥ 10¹⁶ has.
#[inline]
fn push_float(out: &mut Vec<u8>, value: f64, buffer: &mut zmij::Buffer) {
    let printed = buffer.format(value).as_bytes();
    let plus = if value.abs() < 1e15 {
        None
    } else {
        printed.iter().position(|&c| c == b'+')
    };
    match plus {
        Some(plus) => {
            out.extend_from_slice(&printed[..plus]);
            out.extend_from_slice(&printed[plus + 1..]);
        }
        None => out.extend_from_slice(printed),
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
