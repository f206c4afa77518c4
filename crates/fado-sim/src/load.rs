//! The load machine of Fig. 7 (an induction machine on the same shaft): either a prescribed
//! torque profile, or a speed-controlled dynamometer that sets the shaft speed while the drive
//! under test produces torque ("the speed control might be carried out by the load machine",
//! paper §V-B). Sign convention: the load torque T_L is positive when it opposes positive
//! rotation (SPEC §7), so `J·dω/dt = Te − T_L − B·ω`.

use serde::{Deserialize, Serialize};

use crate::error::{SimConfigError, check};
use crate::profile::Profile;

/// How the load machine is operated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoadMode {
    /// T_L follows `torque` (N·m, positive opposing positive rotation).
    #[default]
    Torque,
    /// The load machine runs a PI speed loop on `speed_rpm`; `torque` is its feed-forward.
    Speed,
}

/// Load-machine parameter record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LoadParams {
    /// Torque or speed control of the load machine. Default torque.
    pub mode: LoadMode,
    /// Load torque profile T_L(t) in N·m (torque mode), or the dynamometer's torque
    /// feed-forward (speed mode, as a load torque). Default 0.
    pub torque: Profile,
    /// Dynamometer speed reference in r/min (speed mode). Default 0.
    pub speed_rpm: Profile,
    /// Dynamometer speed-loop bandwidth in Hz. Default 10 Hz \[A\].
    pub speed_bandwidth_hz: f64,
    /// Dynamometer torque limit in N·m. Default 30 N·m \[A\].
    pub torque_limit: f64,
}

impl Default for LoadParams {
    fn default() -> Self {
        Self {
            mode: LoadMode::Torque,
            torque: Profile::constant(0.0),
            speed_rpm: Profile::constant(0.0),
            speed_bandwidth_hz: 10.0,
            torque_limit: 30.0,
        }
    }
}

impl LoadParams {
    /// Checks every field; the error names the key.
    pub fn validate(&self) -> Result<(), SimConfigError> {
        self.torque.validate().map_err(|e| e.in_section("torque"))?;
        self.speed_rpm
            .validate()
            .map_err(|e| e.in_section("speed_rpm"))?;
        check::positive("speed_bandwidth_hz", self.speed_bandwidth_hz)?;
        check::positive("torque_limit", self.torque_limit)?;
        Ok(())
    }
}

/// The load machine with its speed controller state.
#[derive(Clone, Debug)]
pub struct Load {
    params: LoadParams,
    kp: f64,
    ki: f64,
    integral: f64,
    cursors: (usize, usize),
}

impl Load {
    /// A load machine on a shaft of total inertia `inertia` (sets the speed-loop gains:
    /// Kp = J·ω_bw, Ki = Kp·ω_bw/5, the SPEC §6 rule for the drive's own loop).
    pub fn new(params: LoadParams, inertia: f64) -> Result<Self, SimConfigError> {
        params.validate()?;
        let wb = std::f64::consts::TAU * params.speed_bandwidth_hz;
        let kp = inertia * wb;
        Ok(Self {
            params,
            kp,
            ki: kp * wb / 5.0,
            integral: 0.0,
            cursors: (0, 0),
        })
    }

    /// Parameters.
    pub fn params(&self) -> &LoadParams {
        &self.params
    }

    /// The load torque T_L at time `t` for shaft speed `omega_mech` (rad/s), advancing the
    /// dynamometer's controller by `ts`.
    pub fn torque(&mut self, t: f64, omega_mech: f64, ts: f64) -> f64 {
        let ff = self.params.torque.value_from(t, &mut self.cursors.0);
        match self.params.mode {
            LoadMode::Torque => ff,
            LoadMode::Speed => {
                let w_ref = self.params.speed_rpm.value_from(t, &mut self.cursors.1)
                    * std::f64::consts::TAU
                    / 60.0;
                let e = w_ref - omega_mech;
                let lim = self.params.torque_limit;
                // The dynamometer's own torque (positive accelerates) = PI − feed-forward load.
                let unclamped = self.kp * e + self.integral + self.ki * ts * e;
                let t_dyn = unclamped.clamp(-lim, lim);
                if unclamped == t_dyn {
                    self.integral += self.ki * ts * e; // anti-windup: integrate only unclamped
                }
                ff - t_dyn
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dynamometer_holds_speed_against_a_constant_drive_torque() {
        let j = 0.012;
        let params = LoadParams {
            mode: LoadMode::Speed,
            speed_rpm: Profile::constant(60.0),
            ..Default::default()
        };
        let mut load = Load::new(params, j).unwrap();
        let (ts, mut w) = (1e-4, 0.0);
        let te = 5.0; // the drive under test pushes 5 N·m
        for n in 0..20_000 {
            let tl = load.torque(n as f64 * ts, w, ts);
            w += ts * (te - tl) / j;
        }
        assert!(
            (w - 60.0 * std::f64::consts::TAU / 60.0).abs() < 1e-3,
            "{w}"
        );
    }

    #[test]
    fn torque_mode_follows_the_profile() {
        let params = LoadParams {
            torque: Profile::from_points(&[(0.0, 0.0), (1.0, 7.5)]),
            ..Default::default()
        };
        let mut load = Load::new(params, 0.012).unwrap();
        assert!((load.torque(0.5, 3.0, 1e-4) - 3.75).abs() < 1e-12);
        let bad = LoadParams {
            torque: Profile { points: vec![] },
            ..Default::default()
        };
        assert_eq!(bad.validate().unwrap_err().key, "torque.points");
    }
}
