//! The table of scenarios: each one's name, words and the functions that set it up, probe it
//! and judge it.

use super::Scenario;
use super::checks::*;
use super::probe::*;
use super::profiles::*;
use super::scaled::*;

/// The five scenarios of docs/guide/first-run.md in the paper's units, two of ours for the estimator
/// comparison ([`crate::compare`]): a medium-speed sanity check under load and a low-speed
/// staircase; then the paper's experiments scaled by the motor's ratings (its motor: 1500
/// r/min, 11.5 N·m), which run for any motor: `reversal` (Fig. 11), `stops` (Fig. 12) and
/// `rated-reversal` (Fig. 11 under the rated torque); `loaded-start`, a start under the
/// rated torque held by a brake until the drive is ready; `fullrange` and `regen-stop`, the
/// whole operating range and regenerating stops; and `custom`, the user's own profiles.
pub const SCENARIOS: [Scenario; 14] = [
    Scenario {
        name: "fig8",
        title: "Flux and disturbance estimation under 2 N·m (Fig. 8)",
        profile: "0 → +90 r/min, T_L → 2 N·m, then +90 → −90 r/min at 90 r/min/s",
        criterion: "λ2 centred on zero: mean of λ2 − λs over every whole electrical \
                    revolution spent above 30 r/min in HI mode < 2 % of λf; no trip; \
                    speed error < 30 r/min",
        scaled: false,
        neutral: false,
        setup: setup_fig8,
        observe: observe_nothing,
        checks: checks_fig8,
    },
    Scenario {
        name: "fig9",
        title: "k_df switched off for 2 s at −300 r/min under −3 N·m (Fig. 9)",
        profile: "0 → −300 r/min, T_L → −3 N·m, k_df off over [3 s, 5 s], run to 11 s \
                  (no start-up offset calibration)",
        criterion: "λ1 drifts while off (|ΔD̂| > 2 mWb) and recovers with τ ≈ 2 s \
                    (residual after 2 s in [0.2, 0.55]); |θ − θ̂| < 0.05 rad",
        scaled: false,
        neutral: false,
        setup: setup_fig9,
        observe: observe_nothing,
        checks: checks_fig9,
    },
    Scenario {
        name: "fig10",
        title: "No-load standstill held by the limiter (Fig. 10)",
        profile: "0 → 60 → 0 r/min without load, then 0 r/min from 1.7 s to 5.5 s",
        criterion: "|θ − θ̂| < 0.35 rad (does not diverge); |λ̂r| ≤ 1.15·λ̂f (+1 %); \
                    FLAG_limit high ≥ 95 % of the hold",
        scaled: false,
        neutral: false,
        setup: setup_fig10,
        observe: observe_fig10,
        checks: checks_fig10,
    },
    Scenario {
        name: "fig11",
        title: "Speed reversal under 7.5 N·m (Fig. 11)",
        profile: "0 → −90 r/min, T_L → +7.5 N·m, then −90 → +90 r/min at 90 r/min/s",
        criterion: "|θ − θ̂| < 0.25 rad near zero speed (|n| < 30 r/min) [P]; no trip; \
                    speed error < 30 r/min",
        scaled: false,
        neutral: false,
        setup: setup_fig11,
        observe: observe_nothing,
        checks: checks_reversal,
    },
    Scenario {
        name: "fig12",
        title: "Repeated 300 ms stops under 7.5 N·m (Fig. 12)",
        profile: "60 r/min, T_L → +7.5 N·m, then 3 × (60 → 0 at 120 r/min/s, 300 ms at 0, \
                  0 → 60, 500 ms at 60)",
        criterion: "no trip or instability [P]; |θ − θ̂| < 0.25 rad [A]; speed error < 30 r/min",
        scaled: false,
        neutral: false,
        setup: setup_fig12,
        observe: observe_nothing,
        checks: checks_stops,
    },
    Scenario {
        name: "steady300",
        title: "Steady 300 r/min under 7.5 N·m (sanity check of every estimator) [A]",
        profile: "0 → 300 r/min in 1 s, T_L → 7.5 N·m over [1.5 s, 2 s], hold to 4 s",
        criterion: "settled (from 2.5 s) |θ − θ̂| < 0.05 rad; speed error < 10 r/min; no trip",
        scaled: false,
        neutral: false,
        setup: setup_steady300,
        observe: observe_nothing,
        checks: checks_steady300,
    },
    Scenario {
        name: "lowspeed",
        title: "Lowest speed held under 65 % of rated torque: a staircase from 4 % of rated speed, halved six times [A]",
        profile: "0 → 4 % of rated speed, T_L → 65.2 % of rated torque, then 2 s at each of 4, 2, 1, \
                  0.5, 0.25, 0.125, 0.0625 % of rated speed (each reached by a 0.2 s ramp; \
                  the paper's motor: 7.5 N·m and 60, 30, 15, 7.5, 3.75, 1.875, 0.9375 r/min)",
        criterion: "a level is held when, over its last 1.5 s, |θ − θ̂| < 0.25 rad, \
                    |n − n*| < max(0.5·n*, 0.5 r/min) and no trip; the lowest speed held is \
                    the lowest level held together with every level above it; the scenario \
                    passes when every level is held",
        scaled: true,
        neutral: false,
        setup: setup_lowspeed,
        observe: observe_lowspeed,
        checks: checks_lowspeed,
    },
    Scenario {
        name: "reversal",
        title: "Speed reversal under 65 % of rated torque (Fig. 11, scaled by the ratings)",
        profile: "0 → −6 % of rated speed, T_L → 65.2 % of rated torque, then a reversal to \
                  +6 % at 6 % of rated speed per second (the paper's motor: fig11)",
        criterion: "|θ − θ̂| < 0.25 rad near zero speed (|n| < 2 % of rated) [P]; no trip; \
                    speed error < 2 % of rated speed from 2.0 s, or from where the default \
                    drive's speed loop brings the load ramp's lag within half of it on a rotor too \
                    light for 2.0 s (at the latest 2.5 s)",
        scaled: true,
        neutral: false,
        setup: setup_reversal,
        observe: observe_nothing,
        checks: checks_reversal,
    },
    Scenario {
        name: "stops",
        title: "Repeated 300 ms stops under 65 % of rated torque (Fig. 12, scaled)",
        profile: "4 % of rated speed, T_L → 65.2 % of rated torque, then 3 × (ramp to 0 in \
                  0.5 s, 300 ms at 0, back in 0.5 s, 500 ms at 4 %) (the paper's motor: fig12)",
        criterion: "no trip or instability [P]; |θ − θ̂| < 0.25 rad [A]; speed error < 2 % \
                    of rated speed",
        scaled: true,
        neutral: false,
        setup: setup_stops,
        observe: observe_nothing,
        checks: checks_stops,
    },
    Scenario {
        name: "rated-reversal",
        title: "Speed reversal under the rated torque (Fig. 11 at 100 % load, scaled)",
        profile: "as `reversal` with T_L → 100 % of rated torque",
        criterion: "as `reversal`",
        scaled: true,
        neutral: false,
        setup: setup_rated_reversal,
        observe: observe_nothing,
        checks: checks_reversal,
    },
    Scenario {
        name: "loaded-start",
        title: "Start under the rated torque, the rotor held by a brake until the drive is ready",
        profile: "rotor at rest at a seeded random angle, a brake holding it and a constant \
                  100 % of rated torque (gravity-like) on it; the drive is not told the angle \
                  and finds it at standstill (`[controller.startup] find_angle`; a plant with \
                  constant inductances gets the assumed d-axis saturation \
                  `LOADED_START_D_SATURATION`; `rotor_held`: the brake holds it through the \
                  start-up); the brake opens at the drive's first ready \
                  sample from 0.7 s on; 0 r/min until 1 s, then a ramp to +6 % of rated speed \
                  (lifting) by 2 s, held to 3 s",
        criterion: "from t = 0: the angle found and |θ − θ̂| from ready on < 0.25 rad; backward \
                    travel ≤ 0.5 rad electrical; commanded speed reached (|n − n*| < 2 % of \
                    rated speed over the last 0.5 s); no trip. A drive that says it has no \
                    angle (`StartupStatus::NoAngle`) passes if it stays off and the rotor \
                    does not move",
        scaled: true,
        neutral: false,
        setup: setup_loaded_start,
        observe: observe_loaded_start,
        checks: checks_loaded_start,
    },
    Scenario {
        name: "fullrange",
        title: "The whole operating range, scaled by the ratings and the model's limits",
        profile: "standstill under 50 % of rated torque; to rated speed at the current limit; \
                  rated load step; field weakening to the top speed the voltage and current \
                  limits allow (≤ 2× rated; half the rated power still available) holding \
                  min(rated power, 80 % of the limits' power); brake at the current limit \
                  through zero; 1 s at zero under 65 % of rated torque; to −rated speed; each \
                  judged window later where the rotor needs longer to reach its speed",
        criterion: "|θ − θ̂| < 0.25 rad over the whole run; in each settled window speed within \
                    2 % of its target (of the rated speed near zero); no trip; DC voltage within \
                    the drive's limits",
        scaled: true,
        neutral: false,
        setup: setup_fullrange,
        observe: observe_fullrange,
        checks: checks_range,
    },
    Scenario {
        name: "regen-stop",
        title: "Stops regenerating into a rectifier-fed DC link (with a brake chopper)",
        profile: "rated speed, stop at the current limit; rated speed again under an overhauling \
                  rated load, stop and hold it (rectifier, chopper at 1.05 × the bus); each \
                  judged window later where the rotor needs longer to reach its speed",
        criterion: "as `fullrange`",
        scaled: true,
        neutral: false,
        setup: setup_regen_stop,
        observe: observe_regen_stop,
        checks: checks_range,
    },
    Scenario {
        name: "custom",
        title: "The user's own experiment: `[speed_reference]`, `[load]`, `[criteria]`",
        profile: "the configuration's `[speed_reference] points` and `[load]`; it runs to 1 s \
                  after the last breakpoint unless `[simulation] duration` is given",
        criterion: "only the `[criteria]` written (none: it reports and passes)",
        scaled: false,
        neutral: true,
        setup: setup_custom,
        observe: observe_nothing,
        checks: checks_nothing,
    },
];
