//! The load on the shaft: the load machine of Fig. 7 (an induction machine on the same shaft)
//! as a prescribed torque profile or a speed-controlled dynamometer that sets the shaft speed
//! while the drive under test produces torque ("the speed control might be carried out by the
//! load machine", paper §V-B), or one of the loads a drive meets in a product: a fan or
//! propeller (torque ∝ ω²), a hoist (gravity: a constant torque whatever the direction) and a
//! constant-power load (a winder, a vehicle above its base speed).
//!
//! Sign convention: the load torque T_L is positive when it opposes positive rotation (docs/guide/first-run.md),
//! so `J·dω/dt = Te − T_L − B·ω`. Speeds are the shaft's mechanical ω in rad/s.
//!
//! | `mode`            | T_L                                                            |
//! |-------------------|----------------------------------------------------------------|
//! | `torque`          | `torque(t)`                                                    |
//! | `speed`           | `torque(t)` − the dynamometer's PI torque on `speed_rpm(t)`     |
//! | `quadratic`       | `torque(t) + coefficient·ω·|ω|`                                 |
//! | `gravity`         | `torque(t)`, the held weight: same sign in both directions      |
//! | `constant_power`  | `torque(t) + power·sgn(ω)/max(|ω|, ω_c)` (ω_c: `corner_speed_ratio`) |

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
    /// A fan or propeller: T_L = `torque` + `coefficient`·ω·|ω| (the drag follows the
    /// direction of rotation; `coefficient` in N·m/(rad/s)², ω the shaft speed in rad/s).
    Quadratic,
    /// A hoist: T_L = `torque`, the weight on the rope referred to the shaft (N·m, positive
    /// pulls towards negative rotation). Gravity does not reverse with the direction of
    /// rotation: lifting (ω > 0) the drive motors, lowering (ω < 0) the weight drives the
    /// motor, which regenerates; at standstill the drive holds it.
    Gravity,
    /// A constant-power load: T_L = `torque` + `power`/|ω| opposing the rotation (`power` in
    /// W). Below the corner speed ω_c = `corner_speed_ratio` × the rated speed the torque is
    /// held at `power`/ω_c (a real constant-power load, a winder or a vehicle above its base
    /// speed, has a torque limit; P/ω is infinite at standstill), and within 1 % of ω_c of
    /// zero it goes linearly through zero (its sign follows the speed without chattering).
    ConstantPower,
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
    /// Quadratic mode: drag coefficient k of T = k·ω·|ω|, N·m/(rad/s)² (ω the shaft speed in
    /// rad/s). Default 0. A propeller absorbing P at ω has k = P/ω³.
    pub coefficient: f64,
    /// Constant-power mode: the power the load absorbs, W (negative: it drives the shaft).
    /// Default 0.
    pub power: f64,
    /// Constant-power mode: corner speed ω_c below which the load torque is held at
    /// `power`/ω_c, as a fraction of the motor's rated speed. Default 1 \[A\]: the motor's
    /// own characteristic (a load of the rated power asks the rated torque up to the rated
    /// speed and the rated power above it; a lower corner asks more than the rated torque
    /// at low speed, `power`/ω_c).
    pub corner_speed_ratio: f64,
}

impl Default for LoadParams {
    fn default() -> Self {
        Self {
            mode: LoadMode::Torque,
            torque: Profile::constant(0.0),
            speed_rpm: Profile::constant(0.0),
            speed_bandwidth_hz: 10.0,
            torque_limit: 30.0,
            coefficient: 0.0,
            power: 0.0,
            corner_speed_ratio: 1.0,
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
        check::non_negative("coefficient", self.coefficient)?;
        check::finite("power", self.power)?;
        check::in_range("corner_speed_ratio", self.corner_speed_ratio, 1e-3, 10.0)?;
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
    /// Constant-power corner speed ω_c, rad/s (mechanical).
    corner_speed: f64,
}

impl Load {
    /// A load on a shaft of total inertia `inertia` (sets the dynamometer's speed-loop gains:
    /// Kp = J·ω_bw, Ki = Kp·ω_bw/5, the docs/method/estimator.md, "The paper's motor and drive" rule for the drive's own loop) driven by a
    /// motor of rated speed `rated_speed_rpm` (sets the constant-power corner speed).
    pub fn new(
        params: LoadParams,
        inertia: f64,
        rated_speed_rpm: f64,
    ) -> Result<Self, SimConfigError> {
        params.validate()?;
        let wb = std::f64::consts::TAU * params.speed_bandwidth_hz;
        let kp = inertia * wb;
        let corner_speed =
            params.corner_speed_ratio * rated_speed_rpm * std::f64::consts::TAU / 60.0;
        Ok(Self {
            params,
            kp,
            ki: kp * wb / 5.0,
            integral: 0.0,
            cursors: (0, 0),
            corner_speed,
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
            LoadMode::Gravity => ff,
            LoadMode::Quadratic => ff + self.params.coefficient * omega_mech * omega_mech.abs(),
            LoadMode::ConstantPower => ff + self.constant_power_torque(omega_mech),
        }
    }

    /// The constant-power part of T_L at shaft speed `omega_mech`: `power`/|ω| opposing the
    /// rotation above the corner speed ω_c, `power`/ω_c below it, linear through zero within
    /// 1 % of ω_c.
    fn constant_power_torque(&self, omega_mech: f64) -> f64 {
        let wc = self.corner_speed;
        let held = self.params.power / wc;
        let w = omega_mech.abs();
        if w >= wc {
            self.params.power / omega_mech
        } else {
            held * (omega_mech / (0.01 * wc)).clamp(-1.0, 1.0)
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
        let mut load = Load::new(params, j, 1500.0).unwrap();
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
        let mut load = Load::new(params, 0.012, 1500.0).unwrap();
        assert!((load.torque(0.5, 3.0, 1e-4) - 3.75).abs() < 1e-12);
        let bad = LoadParams {
            torque: Profile { points: vec![] },
            ..Default::default()
        };
        assert_eq!(bad.validate().unwrap_err().key, "torque.points");
    }

    #[test]
    fn quadratic_load_follows_the_direction_of_rotation() {
        let params = LoadParams {
            mode: LoadMode::Quadratic,
            coefficient: 2e-4,
            torque: Profile::constant(0.5),
            ..Default::default()
        };
        let mut load = Load::new(params, 0.012, 1500.0).unwrap();
        // 100 rad/s: 0.5 + 2e-4·100² = 2.5 N·m; −100 rad/s: 0.5 − 2 = −1.5 N·m.
        assert!((load.torque(0.0, 100.0, 1e-4) - 2.5).abs() < 1e-12);
        assert!((load.torque(0.0, -100.0, 1e-4) + 1.5).abs() < 1e-12);
        assert_eq!(load.torque(0.0, 0.0, 1e-4), 0.5);
        let bad = LoadParams {
            coefficient: -1.0,
            ..Default::default()
        };
        assert_eq!(bad.validate().unwrap_err().key, "coefficient");
    }

    #[test]
    fn gravity_load_does_not_reverse_with_the_rotation() {
        let params = LoadParams {
            mode: LoadMode::Gravity,
            torque: Profile::constant(7.0),
            ..Default::default()
        };
        let mut load = Load::new(params, 0.012, 1500.0).unwrap();
        for w in [-150.0, -1.0, 0.0, 1.0, 150.0] {
            assert_eq!(load.torque(1.0, w, 1e-4), 7.0, "ω = {w}");
        }
        // A shaft left alone under it runs backwards (the weight lowers itself).
        let (j, ts, mut w) = (0.012, 1e-4, 0.0);
        for n in 0..1000 {
            w += ts * (0.0 - load.torque(n as f64 * ts, w, ts)) / j;
        }
        assert!((w + 7.0 / j * 0.1).abs() < 1e-9, "{w}");
    }

    #[test]
    fn constant_power_load_absorbs_its_power_above_the_corner_speed() {
        let params = LoadParams {
            mode: LoadMode::ConstantPower,
            power: 1500.0,
            corner_speed_ratio: 0.1,
            ..Default::default()
        };
        let mut load = Load::new(params, 0.012, 1500.0).unwrap();
        let wc = 0.1 * 1500.0 * std::f64::consts::TAU / 60.0; // 15.7 rad/s
        for w in [wc, 2.0 * wc, 10.0 * wc, -3.0 * wc] {
            let t = load.torque(0.0, w, 1e-4);
            assert!((t * w - 1500.0).abs() < 1e-9, "ω = {w}: P = {}", t * w);
        }
        // Below the corner: held at P/ω_c, the sign of the speed, linear through zero.
        let held = 1500.0 / wc;
        assert!((load.torque(0.0, 0.5 * wc, 1e-4) - held).abs() < 1e-9);
        assert!((load.torque(0.0, -0.5 * wc, 1e-4) + held).abs() < 1e-9);
        assert_eq!(load.torque(0.0, 0.0, 1e-4), 0.0);
        assert!((load.torque(0.0, 0.005 * wc, 1e-4) - 0.5 * held).abs() < 1e-9);
        // Continuous at the corner.
        let below = load.torque(0.0, wc * (1.0 - 1e-9), 1e-4);
        assert!((below - load.torque(0.0, wc, 1e-4)).abs() < 1e-6);
    }
}
