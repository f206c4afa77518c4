//! Building, resetting and reading the procedure, and its sample: the safety checks, then
//! the phase in progress.

use super::*;
use crate::error::ConfigError;
use crate::{Ab, Abc, Dq, Real};

impl<T: Real> Commissioning<T> {
    /// A new procedure; the configuration is checked (the error names the field).
    pub fn new(cfg: CommissioningConfig<T>) -> Result<Self, ConfigError> {
        cfg.validate()?;
        let z = Sizing::new(&cfg);
        let block = z.block;
        let mut s = Self {
            ts: z.ts,
            i_limit: z.i_limit,
            k_int: z.k_int,
            k_p: z.k_p,
            v_inj: z.v_inj,
            spin_speed: z.spin_speed,
            spin_accel: z.spin_accel,
            i_if: z.i_if,
            phase: Phase::Offset,
            sub: 0,
            t_phase: T::zero(),
            t_total: T::zero(),
            nominal_total: z.nominal_total,
            nominal_done: T::zero(),
            status: Status::Running,
            bad_samples: 0,
            off_a: T::zero(),
            off_b: T::zero(),
            off_n: T::zero(),
            off_sq: T::zero(),
            i_resolution: T::zero(),
            c1: Ab::zero(),
            c2: Ab::zero(),
            i_prev: Ab::zero(),
            have_prev: false,
            v_int: Ab::zero(),
            u_ref: Ab::new(T::one(), T::zero()),
            v_ff: Ab::zero(),
            i_ref: Ab::zero(),
            err_par: T::zero(),
            err_perp: T::zero(),
            emf_lpf: Ab::zero(),
            align_loud_at: T::zero(),
            frozen: false,
            t_frozen: T::zero(),
            dc_hold: z.dc_hold,
            gain_swing_settled: z.gain_swing_settled,
            saturated_time: T::zero(),
            dc: DcStats::new(block),
            gain_correction: T::one(),
            gain_ratio: T::zero() / T::zero(),
            gain_ratio_sigma: T::lit(f64::INFINITY),
            line: Line::default(),
            inj_count: 0,
            inj_sign: T::one(),
            rs: T::zero(),
            rs_sigma: T::zero(),
            v_inv: T::zero(),
            v_inv_sigma: T::zero(),
            ld: T::zero(),
            ld_sigma: T::zero(),
            lq: T::zero(),
            lq_sigma: T::zero(),
            flux: T::zero(),
            flux_sigma: T::zero(),
            pulses: FluxPulses::new(),
            spin_loop: SpinLoop::new(&cfg),
            emf_win: [EmfWindow::new(block); 2],
            jfit: JFit::default(),
            jwin: JWindows::default(),
            j_step: 0,
            t_coast2: T::zero(),
            i_j: T::zero(),
            step_rec: StepRecord::default(),
            j_hold_d: false,
            coast_id: T::zero(),
            id_j: T::zero(),
            id_j_rate: T::zero(),
            result: None,
            cfg,
        };
        s.reset();
        Ok(s)
    }

    /// Back to the start (offset calibration), results cleared.
    pub fn reset(&mut self) {
        let cfg = self.cfg;
        // Rebuild from a validated config cannot fail.
        self.phase = Phase::Offset;
        self.sub = 0;
        self.t_phase = T::zero();
        self.t_total = T::zero();
        self.nominal_done = T::zero();
        self.status = Status::Running;
        self.bad_samples = 0;
        self.off_a = T::zero();
        self.off_b = T::zero();
        self.off_n = T::zero();
        self.off_sq = T::zero();
        self.i_resolution = T::zero();
        self.c1 = Ab::zero();
        self.c2 = Ab::zero();
        self.have_prev = false;
        self.v_int = Ab::zero();
        self.u_ref = Ab::new(T::one(), T::zero());
        self.v_ff = Ab::zero();
        self.i_ref = Ab::zero();
        self.err_par = T::zero();
        self.err_perp = T::zero();
        self.emf_lpf = Ab::zero();
        self.align_loud_at = T::zero();
        self.frozen = false;
        self.t_frozen = T::zero();
        self.saturated_time = T::zero();
        let block = self.dc.v_lvl[0].block;
        self.dc = DcStats::new(block);
        self.gain_correction = T::one();
        self.gain_ratio = T::zero() / T::zero();
        self.gain_ratio_sigma = T::lit(f64::INFINITY);
        self.emf_win = [EmfWindow::new(block); 2];
        self.line = Line::default();
        self.jfit = JFit::default();
        self.pulses = FluxPulses::new();
        self.spin_loop.pll_on = false;
        self.spin_loop.pi_int = Dq::zero();
        self.spin_loop.theta_f = T::zero();
        self.spin_loop.omega_f = T::zero();
        self.j_step = 0;
        self.t_coast2 = T::zero();
        self.jwin.reset();
        self.result = None;
        self.cfg = cfg;
    }

    /// The configuration in use.
    pub fn config(&self) -> &CommissioningConfig<T> {
        &self.cfg
    }

    /// The current limit in A (`current_limit_ratio · rated_current`).
    pub fn current_limit(&self) -> T {
        self.i_limit
    }

    /// Where the procedure stands.
    pub fn status(&self) -> Status {
        self.status
    }

    /// The phase running now.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The identification, once [`Status::Done`].
    pub fn result(&self) -> Option<&Identification<T>> {
        self.result.as_ref()
    }

    pub(super) fn output(&self, v: Ab<T>, vdc: T, gates: bool, speed: T) -> CommissioningOutput<T> {
        let gates = gates && self.status == Status::Running;
        let v = if gates { v } else { Ab::zero() };
        let duty = if gates {
            crate::control::modulation::svpwm_duty(v, vdc)
        } else {
            Abc::new(T::lit(0.5), T::lit(0.5), T::lit(0.5))
        };
        CommissioningOutput {
            v_ab: v,
            duty,
            gates_enabled: gates,
            current_reference: if gates { self.i_ref } else { Ab::zero() },
            phase: self.phase,
            progress: self.progress(),
            status: self.status,
            speed,
            angle: if self.spin_loop.pll_on {
                self.spin_loop.pll_theta
            } else {
                T::zero()
            },
        }
    }

    pub(super) fn progress(&self) -> T {
        match self.status {
            Status::Done => T::one(),
            _ => clamp(
                (self.nominal_done + self.t_phase) / self.nominal_total,
                T::zero(),
                T::lit(0.999),
            ),
        }
    }

    /// The measured current that aborts with `OverCurrent`: `trip_ratio` × the current limit,
    /// × the pulses' peak current in [`Phase::Magnetics`].
    fn trip_current(&self) -> T {
        let level = if self.phase == Phase::Magnetics {
            self.i_limit.max(self.pulse_current())
        } else {
            self.i_limit
        };
        self.cfg.trip_ratio * level
    }

    /// Why a measured current `i` beyond the trip stops the procedure. At standstill, an
    /// over-current with a back-EMF beyond the rotation threshold is the rotor being turned
    /// (the EMF drives the current); one mostly across the reference, without that EMF, is a
    /// current that cannot follow its reference's direction (an open phase: the loop, which
    /// regulates along the reference, pushes the current the machine can carry until its
    /// projection matches).
    fn over_current_reason(&self, i: Ab<T>) -> AbortReason {
        let phase = self.phase;
        let standstill = matches!(
            phase,
            Phase::Align | Phase::Resistance | Phase::InductanceD | Phase::InductanceQ
        );
        if standstill && self.emf_lpf.beta.abs() > self.emf_limit() {
            AbortReason::RotationDetected { phase }
        } else if standstill && self.u_ref.cross(i).abs() > self.u_ref.dot(i).abs() {
            AbortReason::CurrentNotFollowing { phase }
        } else {
            AbortReason::OverCurrent { phase }
        }
    }

    pub(super) fn abort(&mut self, reason: AbortReason) {
        self.status = Status::Aborted(reason);
        self.phase = Phase::Aborted;
        self.i_ref = Ab::zero();
    }

    pub(super) fn next_phase(&mut self, p: Phase) {
        self.nominal_done += self.t_phase;
        self.phase = p;
        self.sub = 0;
        self.t_phase = T::zero();
    }

    /// One control sample: the measured phase currents (A, positive out of the inverter) and
    /// DC-link voltage (V) at this sample; returns the command for the next one. After
    /// [`Status::Done`] or an abort it returns gates off.
    pub fn step(&mut self, i_abc: Abc<T>, vdc: T) -> CommissioningOutput<T> {
        if self.status != Status::Running {
            return self.output(Ab::zero(), vdc, false, T::zero());
        }
        let ts = self.ts;
        self.t_phase += ts;
        self.t_total += ts;
        if !(i_abc.a.is_finite() && i_abc.b.is_finite() && vdc.is_finite() && vdc > T::zero()) {
            // Hold the previous command; abort after 10 ms of bad samples.
            self.bad_samples += 1;
            if T::lit(self.bad_samples as f64) * ts > T::lit(0.01) {
                self.abort(AbortReason::NonFiniteMeasurements { phase: self.phase });
            }
            let v = self.c1;
            let vdc = if vdc.is_finite() && vdc > T::zero() {
                vdc
            } else {
                self.cfg.nameplate.dc_voltage
            };
            return self.output(v, vdc, self.phase != Phase::Offset, T::zero());
        }
        self.bad_samples = 0;
        if self.phase != Phase::Offset && self.t_phase > self.phase_limit() {
            self.abort(AbortReason::Timeout { phase: self.phase });
            return self.output(Ab::zero(), vdc, false, T::zero());
        }
        if self.phase == Phase::Offset {
            self.off_a += i_abc.a;
            self.off_b += i_abc.b;
            self.off_n += T::one();
            self.off_sq += i_abc.a * i_abc.a + i_abc.b * i_abc.b;
            if self.t_phase >= self.cfg.offset_time {
                self.off_a /= self.off_n;
                self.off_b /= self.off_n;
                // The readings' rms about their means (noise and quantisation): the current
                // resolution that sizes the inertia test's smallest torque step.
                let mean_sq = self.off_a * self.off_a + self.off_b * self.off_b;
                let var = (self.off_sq / self.off_n - mean_sq) * T::lit(0.5);
                self.i_resolution = var.max(T::zero()).sqrt();
                self.next_phase(Phase::Align);
            }
            return self.output(Ab::zero(), vdc, false, T::zero());
        }
        // Offset-corrected current (two sensors, c = −a − b), phase a divided by the sensors'
        // gain ratio k once the DC test has measured it (the drive's correction, in phase b's
        // scale: module docs, step 3).
        let a = (i_abc.a - self.off_a) * self.gain_correction;
        let b = i_abc.b - self.off_b;
        let i = Abc::new(a, b, -a - b).to_ab();
        if i.norm() > self.trip_current() {
            let reason = self.over_current_reason(i);
            self.abort(reason);
            return self.output(Ab::zero(), vdc, false, T::zero());
        }
        let (v, applied, gates) = match self.phase {
            Phase::Align | Phase::Resistance | Phase::InductanceD | Phase::InductanceQ => {
                let v = self.standstill(i, vdc);
                (v, v, true)
            }
            Phase::Magnetics => self.magnetics(i, vdc),
            Phase::Spin | Phase::Coast | Phase::Inertia => {
                let (v, applied) = self.spinning(i, vdc);
                (v, applied, true)
            }
            Phase::Offset | Phase::Done | Phase::Aborted => (Ab::zero(), Ab::zero(), true),
        };
        self.c2 = self.c1;
        self.c1 = applied;
        self.i_prev = i;
        self.have_prev = true;
        let speed = self.spin_loop.pll_omega;
        let running = gates && self.status == Status::Running && self.phase != Phase::Done;
        self.output(v, vdc, running, speed)
    }
}

/// The procedure's sizing from the nameplate (module docs): the regulator gains, the
/// injection, the spin, the DC levels' hold and the nominal duration.
struct Sizing<T> {
    ts: T,
    i_limit: T,
    k_int: T,
    k_p: T,
    v_inj: T,
    spin_speed: T,
    spin_accel: T,
    i_if: T,
    nominal_total: T,
    dc_hold: T,
    gain_swing_settled: bool,
    /// Samples per block of the mean statistics.
    block: u32,
}

impl<T: Real> Sizing<T> {
    fn new(cfg: &CommissioningConfig<T>) -> Self {
        let np = &cfg.nameplate;
        let ts = cfg.sample_period;
        let i_limit = cfg.current_limit_ratio * np.rated_current;
        let l_avg_np = T::lit(0.5) * (np.ld + np.lq);
        let (k_p, k_int) = standstill_gains(np.rs, l_avg_np, ts);
        // Injection: a current ripple of 30 % of the I₁ bias (45 % of the limit), peak-peak.
        let i_dc = dc_level(np, i_limit);
        let i1 = T::lit(0.5) * i_dc;
        let v_inj = T::lit(0.3) * i1 * l_avg_np / (T::lit(INJ_HALF as f64) * ts);
        let spin_speed = cfg.spin_speed_ratio * np.rated_speed();
        // The I-f current and acceleration on the nameplate's inductances (set again from the
        // identified ones at the start of the spin; here for the nominal duration).
        let (i_if, spin_accel) = spin_sizing(np, np.ld, np.lq, i_limit, cfg.spin_torque_ratio);
        let (dc_hold, gain_swing_settled) = dc_hold(cfg, i_dc, i1);
        let dc_level_time =
            cfg.settle_time.max(T::lit(0.6) * cfg.settle_time + dc_hold) + cfg.measure_time;
        let nominal_total = cfg.offset_time
            + T::lit(3.0) * cfg.align_time
            + T::lit(2.0) * dc_level_time
            + T::lit(2.0) * (T::lit(0.02) + cfg.measure_time)
            + magnetics_time(cfg)
            + (spin_speed / spin_accel + cfg.settle_time)
            + T::lit(2.0) * (T::lit(0.02) + cfg.measure_time)
            + T::lit(1.0);
        Self {
            ts,
            i_limit,
            k_int,
            k_p,
            v_inj,
            spin_speed,
            spin_accel,
            i_if,
            nominal_total,
            dc_hold,
            gain_swing_settled,
            block: libm_round(BLOCK_TIME / ts.to_f64()),
        }
    }
}

/// The DC levels' hold (`dc_window_start`) and whether it lets the rotor's swing die out.
///
/// The swing is the rotor's about the d current (of the nameplate) in voltage mode, at
/// either level (`i_dc`, `i1`), as the drive's gain calibration sizes it. The longest hold:
/// [`DC_MAX_HOLD`], and what the phase time-out leaves of a level frozen as late as allowed
/// (settle + measure) and then averaged. A swing needing longer is held that long and k not
/// used (`gain_swing_settled` false).
fn dc_hold<T: Real>(cfg: &CommissioningConfig<T>, i_dc: T, i1: T) -> (T, bool) {
    let np = &cfg.nameplate;
    let swing = crate::control::drive::swing_time_constant(np, i_dc)
        .max(crate::control::drive::swing_time_constant(np, i1));
    let dc_hold_wanted = T::lit(DC_HOLD_SWING_TIME_CONSTANTS) * swing;
    let dc_hold_max = T::lit(DC_MAX_HOLD)
        .min(cfg.phase_timeout - cfg.settle_time - T::lit(2.0) * cfg.measure_time)
        .max(T::zero());
    let gain_swing_settled = dc_hold_wanted <= dc_hold_max;
    let dc_hold = if gain_swing_settled {
        dc_hold_wanted
    } else {
        dc_hold_max
    };
    (dc_hold, gain_swing_settled)
}

impl<T: Real> SpinLoop<T> {
    /// At rest, with the synchronous PI's gains for a bandwidth of 0.2/Ts on the nameplate and
    /// the PLL's for 40 Hz.
    fn new(cfg: &CommissioningConfig<T>) -> Self {
        let np = &cfg.nameplate;
        let wc = T::lit(0.2) / cfg.sample_period;
        let wn = T::lit(core::f64::consts::TAU * 40.0);
        Self {
            theta_f: T::zero(),
            omega_f: T::zero(),
            pi_int: Dq::zero(),
            kp: Dq::new(wc * np.ld, wc * np.lq),
            ki: wc * np.rs,
            pll_theta: T::zero(),
            pll_omega: T::zero(),
            pll_on: false,
            e_filt: Dq::zero(),
            pll_kp: T::lit(2.0) * wn,
            pll_ki: wn * wn,
        }
    }
}

impl<T: Real> DcStats<T> {
    /// Empty, with blocks of `block` samples.
    fn new(block: u32) -> Self {
        Self {
            v_lvl: [BlockStats::new(block); 2],
            i_lvl: [BlockStats::new(block); 2],
            v_lvl_beta: [BlockStats::new(block); 2],
            i_lvl_beta: [BlockStats::new(block); 2],
            vdc_stats: BlockStats::new(block),
        }
    }
}
