//! The spinning phases: the I-f spin, the coast's back-EMF (λ̂f) and the inertia test.

use super::*;
use crate::{Ab, Dq, MachineModel, Real, Rotation, wrap_angle};

impl<T: Real> Commissioning<T> {
    pub(super) fn start_spin(&mut self) {
        // The I-f current and acceleration from the identified L̂d, L̂q (the nameplate's λf).
        (self.i_if, self.spin_accel) = spin_sizing(
            &self.cfg.nameplate,
            self.ld,
            self.lq,
            self.i_limit,
            self.cfg.spin_torque_ratio,
        );
        let wc = T::lit(0.2) / self.ts;
        self.spin_loop.kp = Dq::new(wc * self.ld, wc * self.lq);
        self.spin_loop.ki = spin_integral_gain(
            self.rs,
            wc,
            self.spin_accel,
            self.cfg.nameplate.flux_linkage,
            self.i_limit,
        );
        // Bumpless: the standstill voltage (rotor at θ = 0, frame at 0) becomes the integral,
        // without the inverter error the compensation now supplies.
        let i1 = T::lit(0.5) * dc_level(&self.cfg.nameplate, self.i_limit);
        let comp = self.compensation(Dq::new(i1, T::zero()), T::zero());
        let v0 = self.v_int + self.v_ff;
        self.spin_loop.pi_int = Dq::new(v0.alpha - comp.alpha, v0.beta - comp.beta);
        self.spin_loop.theta_f = T::zero();
        self.spin_loop.omega_f = T::zero();
        self.spin_loop.pll_on = false;
        self.err_perp = T::zero();
        self.coast_id = self.coast_level();
        self.next_phase(Phase::Spin);
    }

    /// The longest the current phase may take: `phase_timeout`, and for the I-f spin its
    /// ramp to the spin speed on top (spin speed / acceleration, finite). Why: the spin's
    /// torque is at most a quarter of the magnet's at the I-f current, which a reluctance
    /// rotor caps at ½·λf/(Lq − Ld) (`spin_sizing`): on a weak-magnet PM-SyRM with a heavy
    /// rotor the ramp alone outlasts the timeout (scripts/motulator-machines.py's
    /// mot-pmsyrm-4k: 0.6 A, 0.09 N·m, 6 rad/s² electrical, a 10.5 s ramp in an 11.6 s
    /// timeout, the spin speed reached 0.9 s before it, too late to settle).
    pub(super) fn phase_limit(&self) -> T {
        let timeout = self.cfg.phase_timeout;
        if self.phase != Phase::Spin {
            return timeout;
        }
        let ramp = self.spin_speed / self.spin_accel;
        if ramp.is_finite() && ramp > T::zero() {
            timeout + ramp
        } else {
            timeout
        }
    }

    /// The coast's d current, A (its magnitude): `COAST_ID` of the limit, less where the
    /// nameplate inertia is below [`J_PLL_MARGIN`] times the inertia the PLL's lag takes
    /// from it (`pll_lag_inertia` at that current), down to [`COAST_ID_MIN`] of the limit.
    fn coast_level(&self) -> T {
        let np = &self.cfg.nameplate;
        let full = T::lit(COAST_ID) * self.i_limit;
        let p = T::lit(np.pole_pairs as f64);
        // The PLL's inertia per ampere of d current (nameplate λf, identified L̂).
        let per_amp = T::lit(1.5) * p * p * np.flux_linkage / self.spin_loop.pll_ki;
        let allowed = np.inertia / (T::lit(J_PLL_MARGIN) * per_amp);
        if allowed >= full {
            full
        } else {
            allowed.max(T::lit(COAST_ID_MIN) * self.i_limit)
        }
    }

    /// Dead-time compensation V̂·sat(i*_x/I_band) per phase of the reference current at the
    /// frame angle `angle` (docs/method/estimator.md §7's trapezoid; I_band = 5 % of the limit).
    pub(super) fn compensation(&self, i_ref_dq: Dq<T>, angle: T) -> Ab<T> {
        let i = i_ref_dq.to_ab(Rotation::from_angle(angle));
        dead_time_voltage(i, self.inverter_band(), self.v_inv)
    }

    /// Back-EMF over the last sample interval: E = v − R̂·i − L̂q·Δi/Ts (module docs).
    pub(super) fn emf(&self, i: Ab<T>) -> Ab<T> {
        let i_mid = (i + self.i_prev) * T::lit(0.5);
        self.c2 - i_mid * self.rs - (i - self.i_prev) * (self.lq / self.ts)
    }

    /// The spinning phases: the I-f spin, the coast and the inertia test, each sample the
    /// back-EMF PLL, the reference and its frame, the measurements, the synchronous current
    /// loop, the checks and the transitions. Returns the commanded voltage and the one the
    /// inverter applies.
    pub(super) fn spinning(&mut self, i: Ab<T>, vdc: T) -> (Ab<T>, Ab<T>) {
        let (rate, e_q) = self.spin_pll(i);
        let (theta_c, omega_c, i_ref_dq) = self.spin_reference(rate);
        let rot = Rotation::from_angle(theta_c);
        let i_dq = i.to_dq(rot);
        self.spin_measure(i_dq, e_q);
        let e = i_ref_dq - i_dq;
        let (v, comp) = self.spin_voltage(vdc, e, i_ref_dq, theta_c, omega_c);
        if !self.spin_advance(e, rate) || !self.spin_transition() {
            return (Ab::zero(), Ab::zero());
        }
        // The voltage the inverter will apply: the command less its error, i.e. less the
        // compensation (which models it).
        let applied = v - comp;
        (v, applied)
    }

    /// The back-EMF PLL (started once the I-f spin has reached its speed): the frame's rate
    /// and the EMF's q component.
    fn spin_pll(&mut self, i: Ab<T>) -> (T, T) {
        let ts = self.ts;
        // Back-EMF PLL.
        let mut rate = self.spin_loop.omega_f;
        let mut e_q = T::zero();
        if self.spin_loop.pll_on {
            let e = self.emf(i);
            let half = T::lit(0.5) * self.spin_loop.pll_omega * ts;
            let rot_mid = Rotation::from_angle(self.spin_loop.pll_theta - half);
            let e_d = e.alpha * rot_mid.cos + e.beta * rot_mid.sin;
            e_q = -e.alpha * rot_mid.sin + e.beta * rot_mid.cos;
            // The phase detector works on E low-passed in the PLL frame (1 ms, 4× the loop's
            // 40 Hz natural frequency).
            let k_f = (ts / T::lit(PLL_EMF_FILTER)).min(T::one());
            if e_d.is_finite() && e_q.is_finite() {
                self.spin_loop.e_filt =
                    self.spin_loop.e_filt + (Dq::new(e_d, e_q) - self.spin_loop.e_filt) * k_f;
            }
            let err = clamp(
                T::atan2(-self.spin_loop.e_filt.d, self.spin_loop.e_filt.q),
                -T::lit(0.5),
                T::lit(0.5),
            );
            if err.is_finite() {
                self.spin_loop.pll_omega += self.spin_loop.pll_ki * ts * err;
                rate = self.spin_loop.pll_omega + self.spin_loop.pll_kp * err;
            } else {
                rate = self.spin_loop.pll_omega;
            }
        } else if self.phase == Phase::Spin
            && self.spin_loop.omega_f >= self.spin_speed
            && self.have_prev
        {
            // Start the PLL on the back-EMF's angle.
            let e = self.emf(i);
            self.spin_loop.pll_theta = wrap_angle(e.angle() - T::frac_pi_2());
            self.spin_loop.e_filt = Dq::new(T::zero(), e.norm());
            self.spin_loop.pll_omega = self.spin_loop.omega_f;
            self.spin_loop.pll_on = true;
            rate = self.spin_loop.omega_f;
        }
        (rate, e_q)
    }

    /// The current reference and its frame (angle, speed) for the phase.
    fn spin_reference(&mut self, rate: T) -> (T, T, Dq<T>) {
        let cfg = self.cfg;
        let ts = self.ts;
        let t = self.t_phase;
        let i_if = self.i_if;
        // Reference and frame.
        match self.phase {
            Phase::Spin => {
                self.spin_loop.omega_f =
                    (self.spin_loop.omega_f + self.spin_accel * ts).min(self.spin_speed);
                let ramp = (t / T::lit(0.02)).min(T::one());
                let i1 = T::lit(0.5) * dc_level(&cfg.nameplate, self.i_limit);
                let mag = i1 + (i_if - i1) * ramp;
                (
                    self.spin_loop.theta_f,
                    self.spin_loop.omega_f,
                    Dq::new(mag, T::zero()),
                )
            }
            Phase::Coast => (
                self.spin_loop.pll_theta,
                rate,
                Dq::new(-self.coast_id, T::zero()),
            ),
            _ => {
                // Step up, second back-EMF window (no torque, the coast's d current), step
                // down; the d current moved between 0 and the coast's level at the bounded
                // rate.
                let (iq, id_target) = match self.j_step {
                    0 => (self.i_j, self.step_id()),
                    1 => (T::zero(), -self.coast_id),
                    _ => (-self.i_j, self.step_id()),
                };
                let step = self.id_j_rate * ts;
                self.id_j = clamp(id_target, self.id_j - step, self.id_j + step);
                if self.j_step == 1 && self.id_j == id_target {
                    self.t_coast2 += ts;
                }
                (self.spin_loop.pll_theta, rate, Dq::new(self.id_j, iq))
            }
        }
    }

    /// The back-EMF windows (λ̂f) and the inertia windows (Ĵ, B̂).
    fn spin_measure(&mut self, i_dq: Dq<T>, e_q: T) {
        let cfg = self.cfg;
        let ts = self.ts;
        let t = self.t_phase;
        let p = T::lit(cfg.nameplate.pole_pairs as f64);
        // Coast: λf accumulation after 20 ms of decay.
        // The PLL's integral state is its speed (the proportional path's noise, kp·err, would
        // bias any average conditioned on it).
        let w = self.spin_loop.pll_omega;
        // The back-EMF windows: the coast after 20 ms of decay, and the top of the inertia
        // test 20 ms after the d current has reached the coast's level.
        let emf_window = match self.phase {
            Phase::Coast => Some(0),
            Phase::Inertia
                if self.j_step == 1
                    && self.t_coast2 > T::lit(0.02)
                    && self.t_coast2 <= T::lit(0.02) + cfg.measure_time =>
            {
                Some(1)
            }
            _ => None,
        };
        if let Some(k) = emf_window
            && t > T::lit(0.02)
            && w > T::zero()
        {
            // E_q = ω·(λf + (Ld − Lq)·i_d) (active flux).
            let e_f = e_q - w * (self.ld - self.lq) * i_dq.d;
            self.emf_win[k].push(e_f, w, ts);
        }
        // Inertia windows (the back-EMF windows and the steps; 30 ms skipped after a step
        // change).
        let collect = match self.phase {
            Phase::Coast => t > T::lit(0.02),
            Phase::Inertia => {
                emf_window.is_some()
                    || (self.j_step != 1 && t > T::lit(J_SKIP) && self.id_j == self.step_id())
            }
            _ => false,
        };
        if collect {
            // T̂e = λ̂f·(1.5·p·i_q) + 1.5·p·(L̂d − L̂q)·i_d·i_q, its two parts apart (JFit).
            let n = libm_round(J_WINDOW / ts.to_f64());
            self.jwin.push(
                w / p,
                T::lit(1.5) * p * i_dq.q,
                T::lit(1.5) * p * (self.ld - self.lq) * i_dq.d * i_dq.q,
                ts,
                n,
                &mut self.jfit,
            );
        } else {
            self.jwin.reset();
        }
    }

    /// The synchronous PI with decoupling, output advanced by 1.5 samples, with the inverter
    /// error's compensation, limited: the voltage and the compensation in it.
    fn spin_voltage(
        &mut self,
        vdc: T,
        e: Dq<T>,
        i_ref_dq: Dq<T>,
        theta_c: T,
        omega_c: T,
    ) -> (Ab<T>, Ab<T>) {
        let ts = self.ts;
        let ff = Dq::new(
            -omega_c * self.lq * i_ref_dq.q,
            omega_c * self.ld * i_ref_dq.d,
        );
        let int_new = self.spin_loop.pi_int + e * (self.spin_loop.ki * ts);
        let v_dq = Dq::new(self.spin_loop.kp.d * e.d, self.spin_loop.kp.q * e.q) + int_new + ff;
        let adv = theta_c + T::lit(1.5) * omega_c * ts;
        let comp = self.compensation(i_ref_dq, adv);
        let v_raw = v_dq.to_ab(Rotation::from_angle(adv)) + comp;
        let v_max = T::lit(0.95) * vdc * T::lit(SQRT3_INV);
        let v = limit(v_raw, v_max);
        if v == v_raw {
            self.spin_loop.pi_int = int_new;
        }
        (v, comp)
    }

    /// The following and over-speed checks, and the frames advanced; false after an abort.
    fn spin_advance(&mut self, e: Dq<T>, rate: T) -> bool {
        let ts = self.ts;
        let t = self.t_phase;
        // Following check (20 ms low-pass of the error against 30 % of the limit).
        let k = (ts / T::lit(0.02)).min(T::one());
        self.err_perp += k * (e.norm() - self.err_perp);
        if self.err_perp > T::lit(0.3) * self.i_limit && t > T::lit(0.05) {
            self.abort(AbortReason::CurrentNotFollowing { phase: self.phase });
            return false;
        }
        // Advance frames.
        self.spin_loop.theta_f = wrap_angle(self.spin_loop.theta_f + self.spin_loop.omega_f * ts);
        if self.spin_loop.pll_on {
            self.spin_loop.pll_theta = wrap_angle(self.spin_loop.pll_theta + rate * ts);
            let w = self.spin_loop.pll_omega;
            // Not within the PLL's transient after a change of the inertia test's torque.
            let settle = if self.phase == Phase::Inertia {
                J_SKIP
            } else {
                0.02
            };
            let slow = w < T::lit(0.25) * self.spin_speed;
            if self.phase == Phase::Coast && t > T::lit(settle) && slow {
                self.abort_coast_too_light(t, w);
                return false;
            }
            if self.phase != Phase::Spin
                && t > T::lit(settle)
                && (w > T::lit(2.0 * J_HIGH) * self.spin_speed || slow)
            {
                self.abort(AbortReason::Overspeed { phase: self.phase });
                return false;
            }
        }
        true
    }

    /// The phase transitions; false after an abort.
    fn spin_transition(&mut self) -> bool {
        let cfg = self.cfg;
        let t = self.t_phase;
        // Transitions.
        let spin_time = self.spin_speed / self.spin_accel + cfg.settle_time;
        match self.phase {
            Phase::Spin if t >= spin_time && self.spin_loop.pll_on => {
                // Re-express the integral in the PLL frame.
                let int_ab = self
                    .spin_loop
                    .pi_int
                    .to_ab(Rotation::from_angle(self.spin_loop.theta_f));
                self.spin_loop.pi_int =
                    int_ab.to_dq(Rotation::from_angle(self.spin_loop.pll_theta));
                self.step_rec.w_up = self.spin_loop.pll_omega;
                self.next_phase(Phase::Coast);
            }
            Phase::Coast if t >= T::lit(0.02) + cfg.measure_time => return self.start_inertia(),
            Phase::Inertia => {
                // No speed ends a step within J_SKIP of its start (the PLL's transient).
                let settled = t > T::lit(J_SKIP);
                if self.j_step == 0
                    && settled
                    && self.spin_loop.pll_omega >= T::lit(J_HIGH) * self.spin_speed
                {
                    self.step_rec.t_up = t;
                    self.step_rec.j_step_data = t - T::lit(J_SKIP);
                    self.step_rec.w_up = self.spin_loop.pll_omega - self.step_rec.w_up;
                    self.j_step = 1;
                    self.jwin.reset();
                    self.nominal_done += self.t_phase;
                    self.t_phase = T::zero();
                } else if self.j_step == 1 && self.t_coast2 > T::lit(0.02) + cfg.measure_time {
                    if !self.finish_flux() {
                        return false;
                    }
                    self.rescale_step_down();
                    self.j_step = 2;
                    self.jwin.reset();
                    self.nominal_done += self.t_phase;
                    self.t_phase = T::zero();
                } else if self.j_step == 2
                    && settled
                    && self.spin_loop.pll_omega <= T::lit(J_LOW) * self.spin_speed
                {
                    self.step_rec.j_step_data += t - T::lit(J_SKIP);
                    if self.step_rec.j_step_data < T::lit(J_MIN_STEP_WINDOWS * J_WINDOW) {
                        self.abort_too_light();
                        return false;
                    }
                    self.finish_inertia();
                }
            }
            _ => {}
        }
        true
    }

    /// The coast's end: the provisional λ̂f, the inertia test's torque steps and the release
    /// of the coast's d current; false (and aborted) when λ̂f is implausible.
    fn start_inertia(&mut self) -> bool {
        let cfg = self.cfg;
        let ts = self.ts;
        // Provisional λ̂f from the first window alone (sizes the torque steps); the
        // final one comes from both windows (`finish_flux`).
        self.flux = self.emf_win[0].e / self.emf_win[0].w;
        let np = cfg.nameplate.flux_linkage;
        if !(self.flux.is_finite() && self.flux > T::lit(0.25) * np && self.flux < T::lit(4.0) * np)
        {
            self.abort(AbortReason::Implausible {
                parameter: Parameter::FluxLinkage,
            });
            return false;
        }
        // q current of the torque steps: each step takes J_STEP_TIME on the nameplate
        // inertia with the identified λ̂f, within 10–90 % of the limit and at most the I-f
        // level of λ̂f and the identified L̂ (`step_level`).
        let p = T::lit(cfg.nameplate.pole_pairs as f64);
        let d_omega_mech = T::lit(J_HIGH - J_LOW) * self.spin_speed / p;
        let kt = T::lit(1.5) * p * self.flux;
        // The q current that takes `time` for the step on the nameplate inertia.
        let lasting = |time: f64| cfg.nameplate.inertia * d_omega_mech / (T::lit(time) * kt);
        // The steps hold the coast's d current on a light rotor (its floor below 10 % of
        // the limit) and where the limit's resistive drop exceeds the back-EMF at the spin
        // speed (`j_hold_d`).
        self.j_hold_d = lasting(J_STEP_MIN_TIME) < T::lit(0.1) * self.i_limit
            || self.rs * self.i_limit > self.spin_speed * self.flux;
        let floor = (T::lit(0.1) * self.i_limit)
            .min(lasting(J_STEP_MIN_TIME))
            .max(self.smallest_step());

        self.i_j = step_level(
            &cfg.nameplate,
            self.flux,
            self.ld,
            self.lq,
            self.i_limit,
            lasting(J_STEP_TIME),
            floor,
        );
        // Release rate of the coast's d current: |(L̂d − L̂q)·di_d/dt| ≤
        // ID_RELEASE_EMF·ω̂·λ̂f.
        self.id_j = -self.coast_id;
        let dl = (self.ld - self.lq).abs();
        let emf = T::lit(ID_RELEASE_EMF) * self.spin_loop.pll_omega.abs() * self.flux;
        self.id_j_rate = if dl * self.i_limit < emf * ts {
            self.i_limit / ts
        } else {
            emf / dl
        };
        self.j_step = 0;
        self.step_rec.w_up = self.spin_loop.pll_omega;
        self.t_coast2 = T::zero();
        self.jwin.reset();
        self.next_phase(Phase::Inertia);
        true
    }

    /// The d current of the torque steps, A: 0, or the coast's where they hold it (`j_hold_d`).
    fn step_id(&self) -> T {
        if self.j_hold_d {
            -self.coast_id
        } else {
            T::zero()
        }
    }

    /// The inertia the PLL's lag adds back to the fit of steps that hold the coast's d
    /// current (`j_hold_d`), kg·m² (0 where they run without it). Under an electrical acceleration
    /// α the PLL (a PI, integral gain k_i = ωn²) lags by ε = α/k_i, which turns ε·|i_d| of
    /// the d current onto the q axis, a torque 1.5·p·ψa·|i_d|·ε (ψa = λf + (Ld − Lq)·i_d,
    /// the active flux) the PLL frame does not see and that grows with the acceleration:
    /// the fit reads J − 1.5·p²·ψa·|i_d|/k_i. On the servo's bare rotor that is 2.0e-5 of
    /// its 3.1e-5 kg·m² (fitted alone: Ĵ −67 %).
    fn pll_lag_inertia(&self) -> T {
        if !self.j_hold_d {
            return T::zero();
        }
        let p = T::lit(self.cfg.nameplate.pole_pairs as f64);
        let id = self.step_id();
        let active_flux = self.flux + (self.ld - self.lq) * id;
        T::lit(1.5) * p * p * active_flux * id.abs() / self.spin_loop.pll_ki
    }

    /// The smallest torque step's q current: [`J_STEP_RESOLUTION`] current resolutions, A.
    fn smallest_step(&self) -> T {
        T::lit(J_STEP_RESOLUTION) * self.i_resolution
    }

    /// The step down's q current from the measured step up: where the step up ended sooner
    /// than [`J_STEP_MIN_TIME`] (a rotor lighter than the nameplate's), its current scaled by
    /// the time it took over that time (the acceleration goes as the current), at least the
    /// smallest step.
    fn rescale_step_down(&mut self) {
        let t_min = T::lit(J_STEP_MIN_TIME);
        if self.step_rec.t_up < t_min {
            self.i_j = (self.i_j * self.step_rec.t_up / t_min).max(self.smallest_step());
        }
    }

    /// The torque steps ended too soon for the inertia regression: aborted with the speed
    /// the rotor gained in the step up and the time it took.
    fn abort_too_light(&mut self) {
        let p = self.cfg.nameplate.pole_pairs as f64;
        let rpm = self.step_rec.w_up.to_f64() / p * 60.0 / core::f64::consts::TAU;
        self.abort(AbortReason::RotorTooLight {
            phase: Phase::Inertia,
            speed_rpm: libm_round(rpm),
            time_ms: libm_round(self.step_rec.t_up.to_f64() * 1e3),
            needed_ms: libm_round((J_SKIP + J_MIN_STEP_WINDOWS * J_WINDOW) * 1e3),
        });
    }

    /// The coast slowed below a quarter of the spin speed `t` s after it started, at `w`:
    /// aborted with the speed it lost and the time.
    fn abort_coast_too_light(&mut self, t: T, w: T) {
        let p = self.cfg.nameplate.pole_pairs as f64;
        let rpm = (self.step_rec.w_up - w).to_f64() / p * 60.0 / core::f64::consts::TAU;
        self.abort(AbortReason::RotorTooLight {
            phase: Phase::Coast,
            speed_rpm: libm_round(rpm),
            time_ms: libm_round(t.to_f64() * 1e3),
            needed_ms: libm_round((T::lit(0.02) + self.cfg.measure_time).to_f64() * 1e3),
        });
    }

    /// The back-EMF that counts as rotation at standstill: that of 2 % of the rated speed on
    /// the nameplate flux.
    pub(super) fn emf_limit(&self) -> T {
        T::lit(0.02) * self.cfg.nameplate.rated_speed() * self.cfg.nameplate.flux_linkage
    }

    /// λ̂f from the two back-EMF windows (module docs, step 6): the line ē_f = λf·ω̄ + e₀
    /// through them. False (and aborted) when implausible.
    pub(super) fn finish_flux(&mut self) -> bool {
        let (flux, sigma, ds) = emf_line(&self.emf_win[0], &self.emf_win[1]);
        let np = self.cfg.nameplate.flux_linkage;
        // The windows must be apart in speed (the torque step doubles it).
        if !(flux.is_finite()
            && ds > T::lit(0.25) * self.emf_win[0].speed()
            && flux > T::lit(0.25) * np
            && flux < T::lit(4.0) * np)
        {
            self.abort(AbortReason::Implausible {
                parameter: Parameter::FluxLinkage,
            });
            return false;
        }
        self.flux = flux;
        self.flux_sigma = sigma;
        true
    }

    pub(super) fn finish_inertia(&mut self) {
        let np = self.cfg.nameplate;
        let Some(((inv_j, b_over_j), (s_inv_j, s_b_over_j))) =
            self.jfit.with_flux(self.flux).solve()
        else {
            self.abort(AbortReason::Implausible {
                parameter: Parameter::Inertia,
            });
            return;
        };
        let j = T::one() / inv_j + self.pll_lag_inertia();
        let b = b_over_j / inv_j;
        let sj = s_inv_j / (inv_j * inv_j);
        let sb = s_b_over_j * j;
        if !(j.is_finite() && j > T::lit(0.1) * np.inertia && j < T::lit(10.0) * np.inertia) {
            self.abort(AbortReason::Implausible {
                parameter: Parameter::Inertia,
            });
            return;
        }
        // Friction: B·ω at the rated speed must stay below the rated torque.
        if !(b.is_finite() && b.abs() * np.rated_speed_mech() < np.rated_torque) {
            self.abort(AbortReason::Implausible {
                parameter: Parameter::ViscousFriction,
            });
            return;
        }
        let (
            saturation,
            saturation_change,
            saturation_residual,
            linear_residual,
            motion,
            saturation_flux_residuals,
        ) = self.magnetic_result();
        let (ld, lq) = saturation
            .as_ref()
            .map_or((self.ld, self.lq), Self::zero_current_inductances);
        let model = MachineModel {
            rs: self.rs,
            ld,
            lq,
            flux_linkage: self.flux,
            inertia: j,
            viscous_friction: b.max(T::zero()),
            ..np
        };
        let vdc = self.dc.vdc_stats.mean();
        self.result = Some(Identification {
            model,
            confidence: Confidence {
                rs: self.rs_sigma,
                ld: self.ld_sigma,
                lq: self.lq_sigma,
                flux_linkage: self.flux_sigma,
                inertia: sj / j,
                viscous_friction: sb,
                inverter_voltage: self.v_inv_sigma,
                current_gain_ratio: self.gain_ratio_sigma,
            },
            inverter_voltage: self.v_inv,
            threshold_voltage: self.v_inv - self.cfg.dead_time * self.cfg.switching_frequency * vdc,
            current_gain_ratio: T::one() / self.gain_correction,
            saliency: self.lq / self.ld,
            dc_voltage: vdc,
            duration: self.t_total,
            saturation,
            saturation_change,
            saturation_residual,
            linear_residual,
            saturation_flux_residuals,
            saturation_current: self.pulse_current(),
            saturation_motion: motion,
        });
        self.status = Status::Done;
        self.nominal_done += self.t_phase;
        self.t_phase = T::zero();
        self.phase = Phase::Done;
        self.i_ref = Ab::zero();
    }
}
