//! The standstill phases: offset, alignment, the DC test (R̂s, the inverter error, the
//! sensors' gain ratio) and the inductance injections.

use super::*;
use crate::control::gain_calibration::{self, ratio_of, resistance_of};
use crate::{Ab, Real};

impl<T: Real> Commissioning<T> {
    /// The standstill phases: regulation of the current along `i_ref` (voltage mode across
    /// it), plus the square-wave injection; the measurements; the phase transitions.
    pub(super) fn standstill(&mut self, i: Ab<T>, vdc: T) -> Ab<T> {
        let (inj, window) = self.standstill_reference(i, vdc);
        let frozen = self.standstill_frozen();
        let v = self.standstill_voltage(i, vdc, frozen, inj);
        self.standstill_watch(i);
        if !self.standstill_safe(window) || !self.standstill_transition() {
            return Ab::zero();
        }
        v
    }

    /// The phase's current reference and its measurements: the injected voltage and whether
    /// this sample is inside a measurement window (for the rotation check).
    fn standstill_reference(&mut self, i: Ab<T>, vdc: T) -> (Ab<T>, bool) {
        let i2 = dc_level(&self.cfg.nameplate, self.i_limit);
        let i1 = T::lit(0.5) * i2;
        let at = self.cfg.align_time;
        let t = self.t_phase;
        let mut inj = Ab::zero();
        let mut window = false;
        match self.phase {
            Phase::Align => {
                let ang = if t < at {
                    T::lit(2.0 * core::f64::consts::FRAC_PI_3)
                } else if t < T::lit(2.0) * at {
                    T::lit(2.0 * core::f64::consts::FRAC_PI_3) * (T::lit(2.0) - t / at)
                } else {
                    T::zero()
                };
                // Current ramped up over the whole first step: the rotor is pulled in
                // quasi-statically rather than kicked (a kick's swing drives extra current
                // by its EMF).
                let mag = i2 * (t / at).min(T::one());
                self.i_ref = Ab::from_polar(mag, ang);
                // Rotation is expected here: checked from the DC test on.
            }
            Phase::Resistance => {
                let (level, idx) = if self.sub == 0 { (i2, 1) } else { (i1, 0) };
                self.i_ref = Ab::new(level, T::zero());
                if self.frozen && t > self.dc_window_start() {
                    window = true;
                    if self.have_prev {
                        self.dc.v_lvl[idx].push(self.c2.alpha);
                        self.dc.i_lvl[idx].push(T::lit(0.5) * (i.alpha + self.i_prev.alpha));
                        self.dc.v_lvl_beta[idx].push(self.c2.beta);
                        self.dc.i_lvl_beta[idx].push(T::lit(0.5) * (i.beta + self.i_prev.beta));
                        self.dc.vdc_stats.push(vdc);
                    }
                }
            }
            Phase::InductanceD | Phase::InductanceQ => {
                self.i_ref = Ab::new(i1, T::zero());
                self.inj_count += 1;
                if self.inj_count >= INJ_HALF {
                    self.inj_count = 0;
                    self.inj_sign = -self.inj_sign;
                }
                let d_axis = self.phase == Phase::InductanceD;
                let vh = self.v_inj * self.inj_sign;
                inj = if d_axis {
                    Ab::new(vh, T::zero())
                } else {
                    Ab::new(T::zero(), vh)
                };
                if t > T::lit(0.02) && self.have_prev {
                    window = true;
                    if !d_axis {
                        // The mean current of the q injection: the rotor's d axis lies along
                        // it (flux_pulses::start_magnetics).
                        self.pulses.held_current += i;
                    }
                    let (x, y) = if d_axis {
                        (self.c2.alpha, i.alpha - self.i_prev.alpha)
                    } else {
                        (self.c2.beta, i.beta - self.i_prev.beta)
                    };
                    self.line.push(x, y);
                }
            }
            _ => {}
        }
        (inj, window)
    }

    /// Whether the regulator is frozen this sample.
    fn standstill_frozen(&mut self) -> bool {
        let at = self.cfg.align_time;
        let t = self.t_phase;
        let settle = self.cfg.settle_time;
        // The regulator (along the reference, clamping anti-windup) is frozen (voltage mode
        // along the reference too) in the alignment hold, the DC measurement windows and the
        // injections.
        match self.phase {
            // The hold: frozen only once the current has settled at its reference (the
            // criterion of the DC test below), not at a fixed time.
            Phase::Align => {
                if !self.frozen
                    && t >= T::lit(2.0) * at
                    && self.err_par < T::lit(0.03) * self.i_ref.norm()
                {
                    self.frozen = true;
                }
                self.frozen
            }
            // Frozen once settled: after 60 % of the settling time and within 3 % of i*.
            Phase::Resistance => {
                if !self.frozen
                    && t > T::lit(0.6) * settle
                    && self.err_par < T::lit(0.03) * self.i_ref.norm()
                {
                    self.frozen = true;
                    self.t_frozen = t;
                }
                self.frozen
            }
            _ => true,
        }
    }

    /// The regulator's voltage with the injection, limited to the standstill voltage limit.
    pub(super) fn standstill_voltage(
        &mut self,
        i: Ab<T>,
        vdc: T,
        frozen: bool,
        inj: Ab<T>,
    ) -> Ab<T> {
        let cfg = self.cfg;
        let ts = self.ts;
        let e = self.i_ref - i;
        let v_max = cfg.voltage_limit_ratio * vdc * T::lit(SQRT3_INV);
        // The loop regulates the current along the reference only (module docs, step 2):
        // across it the voltage stays the feedforward's, so that the rotor's swing, whose
        // back-EMF lies across the d current, sees the machine's own resistance.
        let n = self.i_ref.norm();
        if n > T::zero() {
            self.u_ref = self.i_ref * (T::one() / n);
        }
        let u = self.u_ref;
        let e_par = u.dot(e);
        let v_int = if frozen {
            self.v_int
        } else {
            u * (u.dot(self.v_int) + e_par * (self.k_int * ts))
        };
        // Feedforward of the reference (module docs): the nameplate R·i* and the dead-time part
        // Td·f_sw·Vdc of the inverter error, so that the loop only makes up the nameplate's
        // error and the device threshold. It follows i*, not i: the rotor's swing still sees
        // the machine's own resistance as damping.
        let ff = self.standstill_feedforward();
        let v_pi = if frozen {
            v_int
        } else {
            v_int + u * (e_par * self.k_p)
        } + ff;
        self.v_ff = ff;
        let v = limit(v_pi + inj, v_max);
        if v != v_pi + inj {
            self.saturated_time += ts;
        } else {
            self.v_int = v_int;
            self.saturated_time = T::zero();
        }
        v
    }

    /// The following check's and the rotation check's low-passes.
    fn standstill_watch(&mut self, i: Ab<T>) {
        let cfg = self.cfg;
        let ts = self.ts;
        let e = self.i_ref - i;
        // Following check: 20 ms low-pass of the error along the reference, the component the
        // loop regulates (across it the current is the rotor's swing's and the sensors' gain
        // mismatch's, which voltage mode leaves), relative to |i*|.
        let k = (ts / T::lit(0.02)).min(T::one());
        self.err_par += k * (self.u_ref.dot(e).abs() - self.err_par);
        // Rotation check: 20 ms low-pass of the back-EMF across the reference (the α axis
        // after the alignment, where a turning rotor's EMF ω·λf lies), from the model with
        // R̂s once known (the nameplate before) and the nameplate L.
        if self.have_prev {
            let np = cfg.nameplate;
            let r = if self.rs > T::zero() { self.rs } else { np.rs };
            let l = T::lit(0.5) * (np.ld + np.lq);
            let emf =
                self.c2 - (i + self.i_prev) * (T::lit(0.5) * r) - (i - self.i_prev) * (l / ts);
            self.emf_lpf += (emf - self.emf_lpf) * k;
        }
    }

    /// The safety checks (saturation, rotation, current not following); false after an
    /// abort.
    fn standstill_safe(&mut self, window: bool) -> bool {
        let t = self.t_phase;
        let settle = self.cfg.settle_time;
        if self.saturated_time > T::lit(0.05) {
            self.abort(AbortReason::CurrentNotFollowing { phase: self.phase });
            return false;
        }
        let iref = self.i_ref.norm();
        let emf_limit = self.emf_limit();
        // The rotation check starts where the rotor must be still: after the alignment and
        // 60 % of the first settling (whether or not the current has settled).
        let still = match self.phase {
            Phase::Align => false,
            Phase::Resistance => t > T::lit(0.6) * settle,
            _ => true,
        };
        if (window || still) && self.emf_lpf.beta.abs() > emf_limit {
            self.abort(AbortReason::RotationDetected { phase: self.phase });
            return false;
        }
        // (The measurements use the actual mean currents, so only a gross miss matters; the
        // alignment only has to hold the rotor.)
        if window && self.phase != Phase::Align && self.err_par > T::lit(0.5) * iref {
            self.abort(AbortReason::CurrentNotFollowing { phase: self.phase });
            return false;
        }
        true
    }

    /// Whether the alignment's hold may end: the rotor's swing about the aligned current has
    /// died out (the rotation check's back-EMF across the reference below half its limit,
    /// the margin the DC test's settling keeps, over the last half alignment step), or the
    /// hold has lasted half the phase timeout, after which the DC test's rotation check
    /// reports a rotor still turning. The swing's damping in voltage mode is the back-EMF's
    /// current through Rs, 1.5·p²·λf²/R (module docs, step 2): on a high-resistance winding
    /// its time constant 2J/c outlasts the alignment's electrical sizing (the 14-pole gimbal
    /// motor of `crates/fado-sim/tests/data/unseen/`, 8.5 Ω: 2J/c = 0.56 s against a 0.3 s
    /// step; with the hold fixed at one step it entered the DC test swinging at ±8 r/min,
    /// four times the check's 2 % of its rated speed, and aborted with `RotationDetected`).
    fn align_quiet(&mut self) -> bool {
        let t = self.t_phase;
        let at = self.cfg.align_time;
        if t >= T::lit(2.0) * at && self.emf_lpf.beta.abs() >= T::lit(0.5) * self.emf_limit() {
            self.align_loud_at = t;
        }
        t - self.align_loud_at >= T::lit(0.5) * at || t >= T::lit(0.5) * self.cfg.phase_timeout
    }

    /// The phase transitions; false after an abort.
    fn standstill_transition(&mut self) -> bool {
        let at = self.cfg.align_time;
        let t = self.t_phase;
        let settle = self.cfg.settle_time;
        let meas = self.cfg.measure_time;
        let quiet = self.phase == Phase::Align && self.align_quiet();
        // Transitions.
        match self.phase {
            Phase::Align if quiet && t >= T::lit(3.0) * at => {
                self.frozen = false;
                self.next_phase(Phase::Resistance);
            }
            Phase::Resistance if t >= settle + meas && !self.frozen => {
                self.abort(AbortReason::CurrentNotFollowing { phase: self.phase });
                return false;
            }
            Phase::Resistance if t >= self.dc_window_start() + meas => {
                self.frozen = false;
                if self.sub == 0 {
                    self.sub = 1;
                    self.nominal_done += self.t_phase;
                    self.t_phase = T::zero();
                } else {
                    self.finish_resistance();
                    if self.status == Status::Running {
                        self.next_phase(Phase::InductanceD);
                        self.inj_count = 0;
                        self.inj_sign = T::one();
                        self.line = Line::default();
                    }
                }
            }
            Phase::InductanceD if t >= T::lit(0.02) + meas => {
                match self.finish_inductance(self.cfg.nameplate.ld, Parameter::Ld) {
                    Some((l, s)) => {
                        self.ld = l;
                        self.ld_sigma = s;
                        self.next_phase(Phase::InductanceQ);
                        self.inj_count = 0;
                        self.inj_sign = T::one();
                        self.line = Line::default();
                    }
                    None => return false,
                }
            }
            Phase::InductanceQ if t >= T::lit(0.02) + meas => {
                match self.finish_inductance(self.cfg.nameplate.lq, Parameter::Lq) {
                    Some((l, s)) => {
                        self.lq = l;
                        self.lq_sigma = s;
                        self.start_magnetics();
                    }
                    None => return false,
                }
            }
            _ => {}
        }
        true
    }

    /// Start of a DC level's measurement window (time in the level, once frozen): the
    /// settling time, and at least [`DC_HOLD_SWING_TIME_CONSTANTS`] of the rotor's swing after
    /// the voltage was frozen (module docs, step 3).
    pub(super) fn dc_window_start(&self) -> T {
        self.cfg.settle_time.max(self.t_frozen + self.dc_hold)
    }

    /// Standstill feedforward R̂·i* + Td·f_sw·Vdc·sat(i*_x/I_band) per phase (the nameplate's
    /// Rs and DC link, the configured dead time; I_band = 5 % of the limit). The full
    /// nameplate Rs: 0.75 × it (no overshoot for a nameplate up to 1.33× too high) left the
    /// loop less settled at the injections (measured: L̂q −3.5 % and Ĵ up to +23 % on the
    /// PM-SyRM preset, L̂q −2 % on the IPMSM, against −0.2 %, +11 %, −1.3 %).
    pub(super) fn standstill_feedforward(&self) -> Ab<T> {
        let np = &self.cfg.nameplate;
        let v_dt = self.cfg.dead_time * self.cfg.switching_frequency * np.dc_voltage;
        self.i_ref * np.rs + dead_time_voltage(self.i_ref, self.inverter_band(), v_dt)
    }

    /// The inverter's current band the procedure assumes, A: [`INVERTER_BAND_RATIO`] of the
    /// limit.
    pub(super) fn inverter_band(&self) -> T {
        T::lit(INVERTER_BAND_RATIO) * self.i_limit
    }

    /// Whether the DC test's lower level keeps phases b and c (on the α axis they carry half
    /// of it, I₁/2 = I₂/4) out of the depth of the inverter's current band: at least ¾ of
    /// the band the procedure assumes (`inverter_band`). Only a reluctance rotor's cap on I₂
    /// (`dc_level`) leaves them deeper: the ferrite PM-SyRM of
    /// `crates/fado-sim/tests/data/motulator/mot-pmsyrm-4k.toml` (I₂ = 0.6 A, 12 % of its 5 A
    /// limit: phases b and c at 0.15 A, 60 % of the band; measured from its levels R̂s is
    /// +50 %). The ¾ is not a bound of the physics but a margin below the band the procedure
    /// assumes, which over-states a large machine's: the 50 kW IPMSM preset told a nameplate
    /// 1.25× off (`commission.rs`' rough nameplate) puts them at 92 % of the assumed band
    /// (I₂ 18 % of the limit) and its levels give R̂s within 0.02 %, the simulator's band being
    /// 0.3 A; the presets' own nameplates give I₂ at 31 % of the limit or more.
    fn dc_levels_beyond_band(&self) -> bool {
        dc_level(&self.cfg.nameplate, self.i_limit) >= T::lit(3.0) * self.inverter_band()
    }

    pub(super) fn finish_resistance(&mut self) {
        let np = self.cfg.nameplate;
        let (v1, v2) = (self.dc.v_lvl[0].mean(), self.dc.v_lvl[1].mean());
        let (i1, i2) = (self.dc.i_lvl[0].mean(), self.dc.i_lvl[1].mean());
        // The sensors' gain ratio k from the same two levels (module docs, step 3), and R̂s
        // along the current difference with phase a corrected by it: in phase b's scale, the
        // drive's once it has calibrated.
        let di_ab = Ab::new(
            i2 - i1,
            self.dc.i_lvl_beta[1].mean() - self.dc.i_lvl_beta[0].mean(),
        );
        let dv_ab = Ab::new(
            v2 - v1,
            self.dc.v_lvl_beta[1].mean() - self.dc.v_lvl_beta[0].mean(),
        );
        let beyond = self.dc_levels_beyond_band();
        let (k, k_sigma) = if beyond {
            self.gain_ratio_of(di_ab, dv_ab)
        } else {
            (T::zero() / T::zero(), T::lit(f64::INFINITY))
        };
        let k_used = if k.is_finite() { k } else { T::one() };
        self.gain_ratio = k;
        self.gain_ratio_sigma = k_sigma;
        let rs = if beyond {
            resistance_of(di_ab, dv_ab, k_used)
        } else {
            np.rs
        };
        // The α current levels in the corrected scale (i_α is phase a's reading).
        let (i1, i2) = (i1 / k_used, i2 / k_used);
        let di = i2 - i1;
        let sq = |x: T| x * x;
        // Voltage and current scatter of both levels (the voltage is frozen in the window,
        // so the current carries the noise).
        let s_v = (sq(self.dc.v_lvl[0].sem())
            + sq(self.dc.v_lvl[1].sem())
            + sq(rs * self.dc.i_lvl[0].sem() / k_used)
            + sq(rs * self.dc.i_lvl[1].sem() / k_used))
        .sqrt();
        self.rs = rs;
        // From now on phase a is read in phase b's scale.
        self.gain_correction = T::one() / k_used;
        // α-axis intercept = 4/3 of the per-phase error (module docs): at the lower level
        // with the measured R̂s; with the nameplate's, at the upper level, whose phases b
        // and c lie nearest the saturated part of the band.
        if beyond {
            self.rs_sigma = s_v / di.abs() / rs.abs();
            self.v_inv = T::lit(0.75) * (v1 - rs * i1);
            self.v_inv_sigma = T::lit(0.75) * (s_v + rs * self.rs_sigma * i1.abs());
        } else {
            self.rs_sigma = T::lit(f64::INFINITY);
            self.v_inv = T::lit(0.75) * (v2 - rs * i2);
            self.v_inv_sigma = T::lit(0.75) * s_v;
        }
        if !(rs.is_finite() && rs > np.rs * T::lit(0.25) && rs < np.rs * T::lit(4.0)) {
            self.abort(AbortReason::Implausible {
                parameter: Parameter::Rs,
            });
            return;
        }
        let vdc = self.dc.vdc_stats.mean();
        if !(self.v_inv.is_finite()
            && self.v_inv > T::lit(-0.01) * vdc
            && self.v_inv < T::lit(0.1) * vdc)
        {
            self.abort(AbortReason::Implausible {
                parameter: Parameter::InverterVoltage,
            });
        }
    }

    /// The current sensors' gain ratio k = (Δi_a/Δv_a)/(Δi_b/Δv_b) of the DC test's two
    /// levels ([`ratio_of`], the drive's start-up calibration's formula) and its relative
    /// 1-σ from the levels' block scatter; (NaN, ∞) when the levels do not give one (a
    /// current off the α axis, a non-positive conductance) or when |k − 1| is beyond
    /// `max_gain_mismatch` (which the drive would refuse too).
    pub(super) fn gain_ratio_of(&self, di: Ab<T>, dv: Ab<T>) -> (T, T) {
        let none = (T::zero() / T::zero(), T::lit(f64::INFINITY));
        if !self.gain_swing_settled {
            return none;
        }
        let min_share = T::lit(gain_calibration::DEFAULT_MIN_OBSERVABILITY);
        let Some(k) = ratio_of(di, dv, min_share) else {
            return none;
        };
        if (k - T::one()).abs() > self.cfg.max_gain_mismatch {
            return none;
        }
        // Variances of the level differences, α and β, of the current and the voltage; a
        // phase-b value is −½·α + (√3/2)·β.
        let sq = |x: T| x * x;
        let var = |s: &[BlockStats<T>; 2]| sq(s[0].sem()) + sq(s[1].sem());
        let (ia, ib) = (var(&self.dc.i_lvl), var(&self.dc.i_lvl_beta));
        let (va, vb) = (var(&self.dc.v_lvl), var(&self.dc.v_lvl_beta));
        let phase_b = |a: T, b: T| T::lit(0.25) * a + T::lit(0.75) * b;
        let dib = (di.to_abc()).b;
        let dvb = (dv.to_abc()).b;
        let rel = ia / sq(di.alpha)
            + phase_b(ia, ib) / sq(dib)
            + va / sq(dv.alpha)
            + phase_b(va, vb) / sq(dvb);
        (k, rel.sqrt())
    }

    pub(super) fn finish_inductance(
        &mut self,
        nameplate: T,
        parameter: Parameter,
    ) -> Option<(T, T)> {
        let (a, sa) = self.line.slope();
        let l = self.ts / a;
        if !(l.is_finite()
            && a > T::zero()
            && l > nameplate * T::lit(0.25)
            && l < nameplate * T::lit(4.0))
        {
            self.abort(AbortReason::Implausible { parameter });
            return None;
        }
        Some((l, sa / a))
    }
}
