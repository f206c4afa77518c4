//! What a scenario records during the run beyond the common metrics: λ2's DC per revolution,
//! D̂, the standstill hold, staircase levels and settled windows, the loaded start.

use serde::Serialize;

use crate::config::SimConfig;
use crate::sim::{Probe, Sample};

use super::scaled::*;

/// No probe beyond the common one.
pub(super) fn observe_nothing(_cfg: &SimConfig, _p: &mut ScenarioProbe) {}

/// `fig10`: the standstill hold, from 2 s to the end.
pub(super) fn observe_fig10(cfg: &SimConfig, p: &mut ScenarioProbe) {
    p.hold = Some((2.0, cfg.simulation.duration));
}

/// `loaded-start`: the release and the end window.
pub(super) fn observe_loaded_start(cfg: &SimConfig, p: &mut ScenarioProbe) {
    p.start = Some(StartStats::new(cfg.simulation.duration - 0.5));
}

/// `lowspeed`: the judged window of each staircase level.
pub(super) fn observe_lowspeed(cfg: &SimConfig, p: &mut ScenarioProbe) {
    p.levels = lowspeed_levels_rpm(cfg.motor.rated_speed_rpm)
        .iter()
        .enumerate()
        .map(|(k, &level)| {
            let to = LOWSPEED_START + (k + 1) as f64 * LOWSPEED_LEVEL_SECONDS;
            LevelStats::new(level, to - LOWSPEED_JUDGED_SECONDS, to)
        })
        .collect();
}

pub(super) fn holds_to_levels(holds: Vec<crate::range::Hold>) -> Vec<LevelStats> {
    holds
        .into_iter()
        .map(|(level, from, to)| LevelStats::new(level, from, to))
        .collect()
}

/// `fullrange`: its settled windows.
pub(super) fn observe_fullrange(cfg: &SimConfig, p: &mut ScenarioProbe) {
    p.levels = holds_to_levels(crate::range::fullrange_holds(cfg));
}

/// `regen-stop`: its settled windows.
pub(super) fn observe_regen_stop(cfg: &SimConfig, p: &mut ScenarioProbe) {
    p.levels = holds_to_levels(crate::range::regen_stop_holds(cfg));
}

/// What `loaded-start` measures about the start-up and the release, from t = 0.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StartStats {
    /// When the brake released (the drive's first ready sample), s.
    pub release_time: Option<f64>,
    /// Largest backward travel of the rotor from t = 0 (electrical rad, ≥ 0; backward is
    /// against the lifting direction, negative angles): the start-up's and the release's.
    pub max_backward: f64,
    /// Largest |θ − θ(0)| before the drive was ready (electrical rad): the rotor's motion
    /// during the start-up (calibrations, angle search).
    pub startup_motion: f64,
    /// Largest |θ − θ̂| from the drive's first ready sample on, rad.
    pub max_angle_error: f64,
    /// Largest |n − n*| from `end_from` on, r/min (see [`end_speed_error`](Self::end_speed_error)).
    pub max_end_speed_error_rpm: f64,
    /// Start of the end window, s.
    pub end_from: f64,
    /// The drive's start-up angle phase at the last sample.
    pub startup: fado_core::control::StartupStatus,
    /// |θ − θ̂| at the sample the start-up found its angle (rad; None: it found none).
    pub found_angle_error: Option<f64>,
    travel: f64,
    theta0: Option<f64>,
    last_theta: Option<f64>,
    end_samples: u64,
}

impl StartStats {
    fn new(end_from: f64) -> Self {
        Self {
            end_from,
            ..Self::default()
        }
    }

    fn observe(&mut self, s: &Sample) {
        let found = fado_core::control::StartupStatus::Found;
        if s.startup == found && self.startup != found {
            self.found_angle_error = Some(s.angle_error.abs());
        }
        self.startup = s.startup;
        if let Some(prev) = self.last_theta {
            self.travel += fado_core::wrap_angle(s.theta - prev);
        }
        self.last_theta = Some(s.theta);
        let theta0 = *self.theta0.get_or_insert(s.theta);
        self.max_backward = self.max_backward.max(-self.travel);
        if s.brake_engaged || (self.release_time.is_none() && !s.ready) {
            self.startup_motion = self
                .startup_motion
                .max(fado_core::wrap_angle(s.theta - theta0).abs());
            return;
        }
        if self.release_time.is_none() {
            self.release_time = Some(s.time);
        }
        self.max_angle_error = self.max_angle_error.max(s.angle_error.abs());
        if s.time >= self.end_from {
            self.end_samples += 1;
            self.max_end_speed_error_rpm = self
                .max_end_speed_error_rpm
                .max((s.speed_rpm - s.speed_ref_rpm).abs());
        }
    }

    /// The end window's largest speed error, r/min; ∞ when the run never got there released.
    pub fn end_speed_error(&self) -> f64 {
        if self.end_samples == 0 {
            f64::INFINITY
        } else {
            self.max_end_speed_error_rpm
        }
    }

    /// The drive ended its start-up saying it has no angle (and stayed off).
    pub fn refused(&self) -> bool {
        matches!(self.startup, fado_core::control::StartupStatus::NoAngle(_))
    }
}

/// One level of the `lowspeed` staircase, judged over its last
/// [`LOWSPEED_JUDGED_SECONDS`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LevelStats {
    /// Commanded speed, r/min.
    pub level_rpm: f64,
    /// Judged window start, s.
    pub from: f64,
    /// Judged window end, s.
    pub to: f64,
    /// Samples in the window.
    pub samples: u64,
    /// max |θ − θ̂| in the window, rad.
    pub max_angle_error: f64,
    /// max |n − n*| in the window, r/min.
    pub max_speed_error_rpm: f64,
    /// Mean true speed in the window, r/min.
    pub mean_speed_rpm: f64,
    /// The drive tripped at or before the end of the window.
    pub tripped: bool,
    #[serde(skip)]
    speed_sum: f64,
}

impl LevelStats {
    /// An empty window `[from, to]` at `level_rpm`.
    pub fn new(level_rpm: f64, from: f64, to: f64) -> Self {
        Self {
            level_rpm,
            from,
            to,
            samples: 0,
            max_angle_error: 0.0,
            max_speed_error_rpm: 0.0,
            mean_speed_rpm: 0.0,
            tripped: false,
            speed_sum: 0.0,
        }
    }

    /// Accumulates one sample (ignored outside the window; a trip before the window's end
    /// counts).
    pub fn observe(&mut self, time: f64, angle_error: f64, speed_rpm: f64, tripped: bool) {
        if time <= self.to {
            self.tripped |= tripped;
        }
        if time < self.from || time > self.to {
            return;
        }
        self.samples += 1;
        self.max_angle_error = self.max_angle_error.max(angle_error.abs());
        self.max_speed_error_rpm = self
            .max_speed_error_rpm
            .max((speed_rpm - self.level_rpm).abs());
        self.speed_sum += speed_rpm;
        self.mean_speed_rpm = self.speed_sum / self.samples as f64;
    }

    /// Held: the whole window was seen, |θ − θ̂| < [`LOWSPEED_ANGLE_BOUND`], |n − n*| <
    /// [`lowspeed_speed_bound`], no trip.
    pub fn held(&self) -> bool {
        self.samples > 0
            && !self.tripped
            && self.max_angle_error < LOWSPEED_ANGLE_BOUND
            && self.max_speed_error_rpm < lowspeed_speed_bound(self.level_rpm)
    }
}

/// Full-rate accumulations the criteria need beyond [`Metrics`](crate::sim::Metrics).
///
/// The DC of λ2 (Fig. 8) is the mean of λ2 − λs (estimate minus the true stator flux) over
/// whole electrical revolutions: every error synchronous with the rotor (dead-time and
/// gain-error harmonics) averages out over a revolution, the offset that D̂ should have removed
/// does not.
#[derive(Clone, Debug)]
pub struct ScenarioProbe {
    eval_start: f64,
    band_rpm: f64,
    rev_angle: f64,
    rev_sum: fado_core::Ab<f64>,
    rev_n: u64,
    rev_valid: bool,
    last_theta: Option<f64>,
    /// Largest |mean(λ2 − λs)| over the revolutions spent entirely above the band in HI mode,
    /// Wb.
    pub max_block_dc: f64,
    /// Number of such revolutions.
    pub blocks: u64,
    /// Every such revolution: (end time in s, |mean(λ2 − λs)| in Wb).
    pub revolutions: Vec<(f64, f64)>,
    /// D̂ every 10 ms: (time, D̂).
    pub disturbance: Vec<(f64, fado_core::Ab<f64>)>,
    /// Window for the standstill statistics (fig10).
    pub hold: Option<(f64, f64)>,
    /// Largest |λ̂r| in the hold window, Wb.
    pub max_lambda_r: f64,
    /// The `lowspeed` staircase levels (empty for the other scenarios).
    pub levels: Vec<LevelStats>,
    /// The `loaded-start` start-up and release (None for the other scenarios).
    pub start: Option<StartStats>,
    hold_n: u64,
    hold_flag: u64,
    next_disturbance_sample: f64,
}

impl ScenarioProbe {
    pub(super) fn new(eval_start: f64, band_rpm: f64) -> Self {
        Self {
            eval_start,
            band_rpm,
            rev_angle: 0.0,
            rev_sum: fado_core::Ab::zero(),
            rev_n: 0,
            rev_valid: true,
            last_theta: None,
            max_block_dc: 0.0,
            blocks: 0,
            revolutions: Vec::new(),
            disturbance: Vec::new(),
            hold: None,
            max_lambda_r: 0.0,
            levels: Vec::new(),
            start: None,
            hold_n: 0,
            hold_flag: 0,
            next_disturbance_sample: 0.0,
        }
    }

    /// D̂ at (just before) time `t`, from the 10 ms series.
    pub fn disturbance_at(&self, t: f64) -> fado_core::Ab<f64> {
        let k = self.disturbance.partition_point(|(ti, _)| *ti <= t);
        self.disturbance
            .get(k.saturating_sub(1))
            .map_or(fado_core::Ab::zero(), |x| x.1)
    }

    /// Fraction of the hold window with FLAG_limit high.
    pub fn flag_fraction(&self) -> f64 {
        self.hold_flag as f64 / self.hold_n.max(1) as f64
    }

    /// Number of staircase levels held, counted from the top until the first one that is
    /// not.
    pub fn levels_held_in_a_row(&self) -> usize {
        self.levels.iter().take_while(|l| l.held()).count()
    }

    /// The lowest speed held under load, r/min: the lowest staircase level held together
    /// with every level above it; `None` when not even the first was held (or no staircase).
    pub fn lowest_speed_held_rpm(&self) -> Option<f64> {
        self.levels_held_in_a_row()
            .checked_sub(1)
            .map(|k| self.levels[k].level_rpm)
    }

    fn restart_revolution(&mut self) {
        self.rev_angle = 0.0;
        self.rev_sum = fado_core::Ab::zero();
        self.rev_n = 0;
        self.rev_valid = true;
    }
}

impl Probe for ScenarioProbe {
    fn observe(&mut self, s: &Sample) {
        let d = &s.act.estimate.diagnostics;
        for level in &mut self.levels {
            level.observe(s.time, s.angle_error, s.speed_rpm, s.act.tripped);
        }
        if let Some(st) = &mut self.start {
            st.observe(s);
        }
        if s.time >= self.next_disturbance_sample {
            self.disturbance.push((s.time, d.disturbance));
            self.next_disturbance_sample += 0.01;
        }
        if let Some((a, b)) = self.hold
            && s.time >= a
            && s.time <= b
        {
            self.hold_n += 1;
            self.hold_flag += d.flag_limit as u64;
            self.max_lambda_r = self.max_lambda_r.max(d.lambda_r.norm());
        }
        let dtheta = self.last_theta.map_or(0.0, |prev| {
            let d = s.theta - prev;
            if d.abs() > std::f64::consts::PI {
                fado_core::wrap_angle(d)
            } else {
                d
            }
        });
        self.last_theta = Some(s.theta);
        if s.time < self.eval_start {
            return;
        }
        if s.speed_rpm.abs() < self.band_rpm || d.flag_limit {
            self.rev_valid = false;
        }
        self.rev_sum += d.lambda2 - s.flux_ab_true;
        self.rev_n += 1;
        self.rev_angle += dtheta;
        if self.rev_angle.abs() >= std::f64::consts::TAU {
            if self.rev_valid {
                let mean = self.rev_sum * (1.0 / self.rev_n as f64);
                self.max_block_dc = self.max_block_dc.max(mean.norm());
                self.blocks += 1;
                self.revolutions.push((s.time, mean.norm()));
            }
            self.restart_revolution();
        } else if !self.rev_valid {
            self.restart_revolution();
            self.rev_valid = true;
            // A revolution only counts if it starts valid: wait for the next sample.
            self.rev_n = 0;
        }
    }
}
