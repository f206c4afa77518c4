//! The scenarios' pass criteria on a finished run.

use serde::Serialize;

use crate::config::SimConfig;
use crate::sim::Metrics;

use super::probe::ScenarioProbe;
use super::scaled::*;

/// `fullrange` and `regen-stop`: the angle over the run, the speed in each settled window
/// within 2 % of its target (of the rated speed near zero), the DC link within the drive's
/// limits.
pub(super) fn checks_range(
    cfg: &SimConfig,
    m: &Metrics,
    p: &ScenarioProbe,
    checks: &mut Vec<Check>,
) {
    let rated = cfg.motor.rated_speed_rpm;
    checks.push(Check::at_most("max |θ − θ̂| (rad)", m.max_angle_error, 0.25));
    for l in &p.levels {
        let bound = 0.02 * l.level_rpm.abs().max(rated);
        checks.push(Check::at_most(
            &format!(
                "speed error at {:.0} r/min, {:.1}–{:.1} s (r/min)",
                l.level_rpm, l.from, l.to
            ),
            l.max_speed_error_rpm,
            bound,
        ));
    }
    let v = cfg.inverter.dc_voltage;
    checks.push(Check::at_most(
        "max DC-link voltage (V)",
        m.max_dc_voltage,
        cfg.controller.dc_link.over_voltage_trip_ratio * v,
    ));
    checks.push(Check::at_least(
        "min DC-link voltage (V)",
        m.min_dc_voltage,
        cfg.controller.protection.dc_link_min_ratio * v,
    ));
    if p.levels.len() == 5 {
        let t = crate::range::targets(cfg);
        checks.push(Check::at_least(
            &format!(
                "mean speed at the top (r/min; model: {:.0})",
                t.top_speed_rpm
            ),
            p.levels[2].mean_speed_rpm,
            0.98 * t.top_speed_rpm,
        ));
        checks.push(Check::at_least(
            &format!(
                "power held at the top (W; model limit {:.0}, rated {:.0})",
                t.limit_power_at_top, t.rated_power
            ),
            cfg.load
                .torque
                .value(0.5 * (p.levels[2].from + p.levels[2].to))
                * p.levels[2].mean_speed_rpm
                * std::f64::consts::TAU
                / 60.0,
            0.98 * t.hold_power,
        ));
    }
}

/// No criterion of the scenario's own.
pub(super) fn checks_nothing(
    _cfg: &SimConfig,
    _m: &Metrics,
    _p: &ScenarioProbe,
    _checks: &mut Vec<Check>,
) {
}

/// `fig8`: pass criteria.
pub(super) fn checks_fig8(
    cfg: &SimConfig,
    m: &Metrics,
    p: &ScenarioProbe,
    checks: &mut Vec<Check>,
) {
    checks.push(Check::at_most(
        "max |DC(λ2 − λs)| / λf",
        p.max_block_dc / cfg.motor.flux_linkage,
        0.02,
    ));
    checks.push(Check::at_least(
        "revolutions evaluated",
        p.blocks as f64,
        4.0,
    ));
    // No loss of control: without it an estimator that runs the machine away
    // (as the EMF baseline does) could still show a centred λ2.
    checks.push(Check::at_most(
        "max speed error (r/min)",
        m.max_speed_error_rpm,
        30.0,
    ));
}

/// `fig9`: pass criteria.
pub(super) fn checks_fig9(
    cfg: &SimConfig,
    m: &Metrics,
    p: &ScenarioProbe,
    checks: &mut Vec<Check>,
) {
    if let Some(&[t_off, t_on]) = cfg.simulation.disturbance_feedback_off.first() {
        let d = |t: f64| p.disturbance_at(t);
        let end = d(cfg.simulation.duration);
        let drift = (d(t_on) - d(t_off)).norm();
        let residual = (d(t_on + 2.0) - end).norm() / (d(t_on) - end).norm().max(1e-12);
        checks.push(Check::at_least("λ1 drift while k_df off (Wb)", drift, 2e-3));
        checks.push(Check::within(
            "recovery residual after 2 s",
            residual,
            0.2,
            0.55,
        ));
    } else {
        // Without the k_df-off window there is no Fig. 9 experiment to judge.
        checks.push(Check::at_least("k_df-off windows configured", 0.0, 1.0));
    }
    checks.push(Check::at_most("max |θ − θ̂| (rad)", m.max_angle_error, 0.05));
}

/// `fig10`: pass criteria.
pub(super) fn checks_fig10(
    cfg: &SimConfig,
    m: &Metrics,
    p: &ScenarioProbe,
    checks: &mut Vec<Check>,
) {
    checks.push(Check::at_most("max |θ − θ̂| (rad)", m.max_angle_error, 0.35));
    checks.push(Check::at_most(
        "max |λ̂r| / (1.15·λ̂f)",
        p.max_lambda_r / (cfg.estimator.limiter.radius_ratio * cfg.machine_model().flux_linkage),
        1.01,
    ));
    checks.push(Check::at_least(
        "FLAG_limit fraction of the hold",
        p.flag_fraction(),
        0.95,
    ));
}

/// `steady300`: pass criteria.
pub(super) fn checks_steady300(
    _cfg: &SimConfig,
    m: &Metrics,
    _p: &ScenarioProbe,
    checks: &mut Vec<Check>,
) {
    checks.push(Check::at_most(
        "settled max |θ − θ̂| (rad)",
        m.max_angle_error,
        0.05,
    ));
    checks.push(Check::at_most(
        "max speed error (r/min)",
        m.max_speed_error_rpm,
        10.0,
    ));
}

/// `lowspeed`: pass criteria.
pub(super) fn checks_lowspeed(
    _cfg: &SimConfig,
    _m: &Metrics,
    p: &ScenarioProbe,
    checks: &mut Vec<Check>,
) {
    checks.push(Check::at_least(
        "levels held from 4 % of rated speed down",
        p.levels_held_in_a_row() as f64,
        p.levels.len() as f64,
    ));
}

/// `reversal`, `rated-reversal` and `fig11`: pass criteria (on the paper's motor: 30 r/min,
/// 1000 samples of 100 µs, as the paper's fig11).
pub(super) fn checks_reversal(
    cfg: &SimConfig,
    m: &Metrics,
    _p: &ScenarioProbe,
    checks: &mut Vec<Check>,
) {
    let band = SCALED_SPEED_ERROR_RATIO * cfg.motor.rated_speed_rpm;
    checks.push(Check::at_most(
        "max |θ − θ̂| near zero speed (rad)",
        m.max_angle_error_zero_speed,
        0.25,
    ));
    // 0.1 s of samples at least in the band (fig11: 0.67 s).
    checks.push(Check::at_least(
        "samples near zero speed",
        m.zero_speed_samples as f64,
        0.1 / cfg.inverter.sample_period(),
    ));
    // Judged from a later instant where the drive's speed loop settles the load ramp later
    // (`load_settling`): the check says from when.
    let start = cfg.simulation.eval_start;
    let name = if cfg.motor.rated_speed_rpm > 0.0 && start > REVERSAL_EVAL_START {
        format!("max speed error from {start:.3} s, the speed loop's load settling (r/min)")
    } else {
        "max speed error (r/min)".to_owned()
    };
    checks.push(Check::at_most(&name, m.max_speed_error_rpm, band));
}

/// `stops` and `fig12`: pass criteria (on the paper's motor: 30 r/min, as fig12).
pub(super) fn checks_stops(
    cfg: &SimConfig,
    m: &Metrics,
    _p: &ScenarioProbe,
    checks: &mut Vec<Check>,
) {
    let band = SCALED_SPEED_ERROR_RATIO * cfg.motor.rated_speed_rpm;
    checks.push(Check::at_most("max |θ − θ̂| (rad)", m.max_angle_error, 0.25));
    checks.push(Check::at_most(
        "max speed error (r/min)",
        m.max_speed_error_rpm,
        band,
    ));
}

/// `loaded-start`: pass criteria, from t = 0. A drive that ends its start-up saying it has no
/// angle (the machine shows none at standstill) is judged on that: it stays off and the
/// brake holds.
pub(super) fn checks_loaded_start(
    cfg: &SimConfig,
    _m: &Metrics,
    p: &ScenarioProbe,
    checks: &mut Vec<Check>,
) {
    let band = SCALED_SPEED_ERROR_RATIO * cfg.motor.rated_speed_rpm;
    let st = p.start.clone().unwrap_or_default();
    let back = (
        "backward travel from t = 0 (rad)",
        st.max_backward,
        LOADED_START_MAX_BACK,
    );
    let motion = (
        "rotor motion before ready (rad)",
        st.startup_motion,
        LOADED_START_MAX_BACK,
    );
    if st.refused() && st.release_time.is_none() {
        checks.push(Check::at_least(
            &format!("start-up says it has no angle ({:?})", st.startup),
            1.0,
            1.0,
        ));
        checks.extend([back, motion].map(|(name, value, max)| Check::at_most(name, value, max)));
        return;
    }
    let bounds = [
        (
            "drive ready (time, s; never: ∞)",
            st.release_time.unwrap_or(f64::INFINITY),
            cfg.simulation.duration,
        ),
        back,
        motion,
        (
            "|θ − θ̂| at the angle found (rad; none: 0)",
            st.found_angle_error.unwrap_or(0.0),
            0.25,
        ),
        ("max |θ − θ̂| from ready on (rad)", st.max_angle_error, 0.25),
        ("speed error at the end (r/min)", st.end_speed_error(), band),
    ];
    checks.extend(bounds.map(|(name, value, max)| Check::at_most(name, value, max)));
}

/// One pass criterion and how the run did against it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Check {
    /// What is measured.
    pub name: String,
    /// Measured value.
    pub value: f64,
    /// Lower limit (inclusive), if any.
    pub min: Option<f64>,
    /// Upper limit (exclusive for errors), if any.
    pub max: Option<f64>,
    /// The value is within its limits.
    pub passed: bool,
}

impl Check {
    pub(crate) fn at_most(name: &str, value: f64, max: f64) -> Self {
        Self {
            name: name.into(),
            value,
            min: None,
            max: Some(max),
            passed: value <= max,
        }
    }
    pub(crate) fn at_least(name: &str, value: f64, min: f64) -> Self {
        Self {
            name: name.into(),
            value,
            min: Some(min),
            max: None,
            passed: value >= min,
        }
    }
    fn within(name: &str, value: f64, min: f64, max: f64) -> Self {
        Self {
            name: name.into(),
            value,
            min: Some(min),
            max: Some(max),
            passed: (min..=max).contains(&value),
        }
    }
}
