//! A speed reference or a load the drive cannot follow, named before the run. The model's
//! steady-state limits ([`crate::range::max_torque`]: |i| ≤ `controller.current.limit_ratio`
//! × `motor.rated_current`, |v| ≤ the field-weakening loop's `voltage_margin` × V_dc/√3) give
//! the speed at which no torque is left (the no-load top speed, field weakening included) and
//! the torque at standstill. A reference above the former by more than [`REACH_MARGIN`], or a
//! load torque above the latter by as much, is a warning naming the profile's key: the run
//! goes on (a user may study a drive at its limits), and its failed criteria then have a
//! named cause rather than a silent one. The usual slips behind such a profile: electrical
//! r/min where mechanical r/min are meant (`motor.pole_pairs` × too fast), a load in N·cm or
//! kg·cm where N·m is meant, another motor's profile.

use crate::config::SimConfig;
use crate::load::LoadMode;
use crate::range::{limits, max_torque};

/// Share by which a profile may exceed the model's limits before it is named: 5 % (the
/// limits are the steady-state model's, without the plant's saturation and losses; a scenario
/// at the limits, as `fullrange`'s ramps, asks at most the limits themselves).
pub const REACH_MARGIN: f64 = 0.05;

/// Largest speed reference, × the rated speed, a motor is taken to be built for wherever its
/// limits would allow more: 10 (field-weakening ranges of traction motors and spindles reach
/// 3–5 × their base speed; a reference beyond 10 × is another unit or another motor).
pub const MECHANICAL_CAP: f64 = 10.0;

/// The speed (r/min, mechanical) above which the model's limits leave no torque: the whole
/// current limit on the negative d axis, λ̂f − L̂d·I_max, turns the voltage limit into
/// ω_max = V_max/(λ̂f − L̂d·I_max) (the resistance's drop, small beside ω·ψ at that speed, left
/// out); infinite where L̂d·I_max ≥ λ̂f (the characteristic current within the limit: field
/// weakening reaches any speed the mechanics allow).
pub fn no_load_top_speed(cfg: &SimConfig) -> f64 {
    let m = cfg.machine_model();
    let (i_max, v_max) = limits(cfg);
    let residual = m.flux_linkage - m.ld * i_max;
    if residual <= 0.0 {
        return f64::INFINITY;
    }
    v_max / residual / m.pole_pairs as f64 * 60.0 / std::f64::consts::TAU
}

/// The warnings on `cfg`'s speed reference and load torque, as (key, text).
pub fn findings(cfg: &SimConfig) -> Vec<(String, String)> {
    let m = cfg.machine_model();
    let mut out = Vec::new();
    let speed = cfg.speed_reference.largest_magnitude();
    let top = no_load_top_speed(cfg);
    let cap = MECHANICAL_CAP * m.rated_speed_rpm;
    if speed > (1.0 + REACH_MARGIN) * top.min(cap) {
        let beyond = if top < cap {
            format!(
                "beyond the {top:.0} r/min at which the model's limits (the current limit \
                 `controller.current.limit_ratio` × `motor.rated_current`, the DC link \
                 `inverter.dc_voltage` with field weakening) leave no torque: the rotor cannot \
                 follow it"
            )
        } else {
            format!("more than {MECHANICAL_CAP} × the rated speed a motor is built for")
        };
        out.push((
            "speed_reference.points".to_owned(),
            format!(
                "`speed_reference.points` reach {speed} r/min, {:.2} × \
                 `motor.rated_speed_rpm`, {beyond} (electrical r/min where mechanical r/min \
                 are meant is `motor.pole_pairs` × too fast)",
                speed / m.rated_speed_rpm
            ),
        ));
    }
    if cfg.load.mode != LoadMode::Speed {
        let load = cfg.load.torque.largest_magnitude();
        let (i_max, v_max) = limits(cfg);
        let standstill = max_torque(cfg, 0.0, i_max, v_max);
        if load > (1.0 + REACH_MARGIN) * standstill {
            out.push((
                "load.torque.points".to_owned(),
                format!(
                    "`load.torque.points` reach {load} N·m, {:.2} × `motor.rated_torque`, beyond \
                     the {standstill:.4} N·m the current limit (`controller.current.limit_ratio` × \
                     `motor.rated_current`) gives: the load turns the rotor against the drive \
                     (a load in N·cm or kg·cm where N·m is meant?)",
                    load / m.rated_torque
                ),
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::scenario_config;

    const SERVO: &str = "[motor]\nrs = 0.268\nld = 2.2e-3\nlq = 2.2e-3\nflux_linkage = 0.12258\n\
                         pole_pairs = 4\nrated_current = 19.0\nrated_speed_rpm = 4500.0\n\
                         rated_torque = 14.0\n[inverter]\ndc_voltage = 565.0\n";

    /// The paper's motor (1,000 r/min rated, 400 V class DC link) with its own scenarios.
    fn paper(scenario: &str, extra: &str) -> SimConfig {
        scenario_config(scenario, Some(extra), true).unwrap()
    }

    #[test]
    fn the_scenarios_scaled_by_the_ratings_stay_within_reach() {
        for s in [
            "fig11",
            "reversal",
            "rated-reversal",
            "fullrange",
            "regen-stop",
        ] {
            assert!(findings(&paper(s, "")).is_empty(), "{s}");
            assert!(findings(&paper(s, SERVO)).is_empty(), "{s}");
        }
    }

    #[test]
    fn the_no_load_top_speed_is_where_the_voltage_leaves_no_torque() {
        // A surface-magnet servo whose characteristic current λf/L is beyond its current
        // limit (motors/servo-1ft6084.toml's circuit and ratings).
        let cfg = paper("fullrange", SERVO);
        let top = no_load_top_speed(&cfg);
        let (i_max, v_max) = limits(&cfg);
        let m = cfg.machine_model();
        let electrical = |rpm: f64| rpm * std::f64::consts::TAU / 60.0 * m.pole_pairs as f64;
        // Torque left below it, none just above; above the rated speed (field weakening).
        assert!(max_torque(&cfg, electrical(0.9 * top), i_max, v_max) > 0.0);
        assert_eq!(max_torque(&cfg, electrical(1.01 * top), i_max, v_max), 0.0);
        assert!(top > m.rated_speed_rpm, "{top}");
    }

    #[test]
    fn a_reference_or_a_load_beyond_the_limits_is_named() {
        let cfg = paper(
            "custom",
            "[speed_reference]\npoints = [[0.0, 0.0], [1.0, 90000.0]]\n\
             [load.torque]\npoints = [[0.0, 0.0], [1.0, 500.0]]\n",
        );
        let found = findings(&cfg);
        let keys: Vec<&str> = found.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(
            keys,
            ["speed_reference.points", "load.torque.points"],
            "{found:?}"
        );
        assert!(found[0].1.contains("90000 r/min"), "{}", found[0].1);
        assert!(found[1].1.contains("500 N·m"), "{}", found[1].1);
        // A dynamometer holding the speed takes its torque from its own loop.
        let speed_mode = paper(
            "custom",
            "[load]\nmode = \"speed\"\n[load.torque]\npoints = [[0.0, 500.0]]\n",
        );
        assert!(findings(&speed_mode).is_empty());
        // The servo's limits, not the cap, bound its reference.
        let servo = format!("{SERVO}[speed_reference]\npoints = [[0.0, 0.0], [1.0, 20000.0]]\n");
        let found = findings(&paper("custom", &servo));
        assert!(found[0].1.contains("leave no torque"), "{found:?}");
    }
}
