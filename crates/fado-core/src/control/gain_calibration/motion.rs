//! The rotor-motion test of the gain calibration (see the module docs, "Rotor motion"):
//! in voltage mode a turning rotor's back-EMF drives a current across the axis.

use super::{GainCalibration, Stage};
use crate::{Ab, MachineModel, Real};

/// Speed, as a fraction of the rated speed, at which the rotor-motion test of the gain
/// calibration fires: its back-EMF ω·λ̂f is the test's threshold
/// ([`GainCalibrationConfig::motion_voltage`](super::GainCalibrationConfig::motion_voltage)) \[A\].
/// At rest the test reads the rotor's own swing about the calibration's current, the slow
/// settling of the current across the axis after a level step and the sensors' noise: at most
/// 0.59 of this threshold on the presets at four angles (the 2.2 kW IPMSM; `crates/fado-sim/
/// tests/gain_calibration.rs`). A load of half the rated torque reaches it within
/// milliseconds, and the earlier the test fires the less the rotor has turned: on a light
/// 21-pole-pair multirotor motor (`crates/fado-sim/tests/calibration_load_classes.rs`) the
/// rotor runs back 0.41 rad with 0.5 %, 0.68 rad with 1 % of the rated speed.
pub const MOTION_SPEED_RATIO: f64 = 0.005;

/// Low-pass time constant (s) of the current across the axis in the rotor-motion test \[A\]:
/// its derivative times L̂q is the back-EMF's inductive part, whose sample-to-sample noise
/// (the current sensor's noise and resolution over Ts) the filter averages over ten 10 kHz
/// samples.
pub const MOTION_FILTER_TIME: f64 = 1e-3;

/// Share of the motion threshold above which the back-EMF across the axis counts towards the
/// rotor's turn ([`GainCalibration::motion_flux`]) \[A\]: above the 0.59 of the threshold the
/// presets read at rest, so that a level's noise adds nothing; a rotor that accelerates from
/// rest turns by a·t²/2 = 0.245·ω_t²/a before its back-EMF reaches it (ω_t the threshold's
/// speed, a the load's acceleration), 0.003 rad on the 21-pole-pair multirotor of
/// `crates/fado-sim/tests/calibration_load_classes.rs` under half its rated torque.
pub const MOTION_TRAVEL_SHARE: f64 = 0.7;

/// The motion test's threshold under the current loop (the settling at I₁ and the release to
/// zero), in multiples of `motion_voltage` \[A\]: 6, 3 % of the rated speed. There the
/// test reads the change of the loop's voltage, and the loop's step to or from zero moves the
/// phases through the inverter's band, whose voltage the drive's dead-time model gives only
/// roughly: at rest it reads up to 2.8 × `motion_voltage` (the 60 000 r/min spindle of
/// `crates/fado-sim/tests/calibration_load_classes.rs`, whose PWM ripple is as large as its
/// lower level; the paper's motor 1.7 ×, the other presets at most 1 ×; 5 angles each, the
/// `loop_motion_peak` test there). A rotor that a load turns from rest at the acceleration a
/// has turned 0.245·ω_t²/a when its back-EMF reaches the travel's share of it: 0.06 rad
/// electrical on the 1.5 kW servo motor there under half its rated torque.
pub const LOOP_MOTION_FACTOR: f64 = 6.0;

/// The window (s) over which the motion test also averages the back-EMF under the current
/// loop \[A\]: the loop's step through the inverter's band, which [`LOOP_MOTION_FACTOR`]
/// covers in the 1 ms filter's reading, lasts about a millisecond, and averaged over 4 ms it
/// reads less; a rotor that a load accelerates keeps its back-EMF growing.
pub const LOOP_WINDOW_TIME: f64 = 4e-3;

/// The threshold of the back-EMF's mean over [`LOOP_WINDOW_TIME`] under the current loop, in
/// multiples of `motion_voltage` \[A\]: 2, 1 % of the rated speed, which a rotor that half
/// its rated torque accelerates freely reaches after 0.1 rad on the 2-pole spindle of
/// `crates/fado-sim/tests/calibration_load_classes.rs` (against 0.85 rad at 3 %).
pub const LOOP_WINDOW_FACTOR: f64 = 2.0;

/// The voltage-mode threshold's floor, in multiples of the largest inductive reading
/// L̂q·dΔi⊥/dt of the settled current loop (the second half of the settling at I₁, the rotor
/// held by I₁) \[A\]: 2, the peak of the same sensor noise over a voltage mode up to 15 times
/// as long (a Gaussian's peak grows from 2.9σ over 300 samples to 3.7σ over 5000). The
/// reading is the current sensors' noise and resolution through L̂q/[`MOTION_FILTER_TIME`]:
/// on a high-inductance winding it reaches `motion_voltage` (the 16-pole 310 V appliance
/// motor of `crates/fado-sim/tests/data/unseen/`, L·I/λf 2.4: one 3.4 mA step of its 12-bit
/// sensor reads 0.64 of it: without the floor its calibration ends `RotorMoved` with the
/// rotor still, 0.002 rad turned, at seeds 1 and 2). Where the floor stays below
/// `motion_voltage` the threshold is `motion_voltage`: on every linear preset's `reversal`
/// and `stops` the runs are bit-identical with and without it.
pub const MOTION_NOISE_MARGIN: f64 = 2.0;

/// Snapshots of the loop's flux over [`LOOP_WINDOW_TIME`].
pub(super) const WINDOW_SLOTS: usize = 8;

/// The rotor-motion threshold (V) of [`GainCalibrationConfig::motion_voltage`](super::GainCalibrationConfig::motion_voltage) for a
/// machine: [`MOTION_SPEED_RATIO`] × the rated electrical speed × λ̂f.
pub fn motion_voltage<T: Real>(m: &MachineModel<T>) -> T {
    let omega_rated = m.rated_speed_rpm * T::two_pi() / T::lit(60.0) * T::lit(m.pole_pairs as f64);
    T::lit(MOTION_SPEED_RATIO) * omega_rated * m.flux_linkage
}

impl<T: Real> GainCalibration<T> {
    /// The back-EMF across the axis (V) at this sample of finite `i_ab`: R̂s·Δi⊥ +
    /// L̂q·dΔi⊥/dt − Δv⊥, low-passed over [`MOTION_FILTER_TIME`], with Δ the change since the
    /// stage's first sample (a level's hold and average are one stage) and v the voltage that
    /// acted: the realised reference `v_ab` plus the inverter's modelled part `inverter`; in
    /// voltage mode the reference is frozen (the upper level's step lies along the axis) and
    /// only the inverter's part changes.
    pub(super) fn motion_emf(
        &mut self,
        i_ab: Ab<T>,
        v_ab: Ab<T>,
        inverter: Ab<T>,
        voltage_mode: bool,
    ) -> T {
        let cross = self.axis.cross(i_ab);
        let acted = if voltage_mode {
            inverter
        } else {
            v_ab + inverter
        };
        let cross_v = self.axis.cross(acted);
        // The reference is the stage's first sample (the voltage just frozen or stepped,
        // the current loop's new reference).
        let stage_start = match self.stage {
            Stage::HoldLower | Stage::HoldUpper => self.remaining == self.hold_samples,
            Stage::Settle | Stage::Release => self.remaining == self.settle_samples,
            _ => false,
        };
        if stage_start {
            self.cross_ref = cross;
            self.cross_filtered = T::zero();
            // The voltage that acted without the inverter's modelled part: the stage just
            // left is settled at its reference current (at zero current before the first),
            // where the model's compensation and loss cancel, and the loss at this one
            // sample's measured current is the sensors' noise through the band's slope V̂/Ic
            // (module docs, "Rotor motion").
            self.cross_v_ref = if voltage_mode {
                T::zero()
            } else {
                self.axis.cross(v_ab)
            };
            self.cross_v_filtered = T::zero();
            self.motion_flux = T::zero();
        }
        let delta = cross - self.cross_ref;
        let tf = T::lit(MOTION_FILTER_TIME);
        let a = self.config.ts / (tf + self.config.ts);
        self.cross_filtered += a * (delta - self.cross_filtered);
        self.cross_v_filtered += a * (cross_v - self.cross_v_ref - self.cross_v_filtered);
        // d/dt of the filtered current is (Δi⊥ − filtered)/τ_f.
        let inductive = self.config.lq_hat * (delta - self.cross_filtered) / tf;
        if self.stage == Stage::Settle && self.remaining <= self.settle_samples / 2 {
            self.noise_floor = self
                .noise_floor
                .step_max(T::lit(MOTION_NOISE_MARGIN) * inductive.abs());
        }
        let emf = self.config.rs_hat * self.cross_filtered + inductive - self.cross_v_filtered;
        let share = emf.abs() / self.motion_threshold(voltage_mode);
        if share > T::lit(MOTION_TRAVEL_SHARE) {
            self.motion_flux += emf * self.config.ts;
        }
        let peak = if voltage_mode {
            &mut self.motion_peak
        } else {
            &mut self.loop_motion_peak
        };
        if share > *peak {
            *peak = share;
        }
        emf
    }

    /// Under the current loop: the back-EMF `emf` (V) added to the stage's flux, and the mean
    /// back-EMF over the recent [`LOOP_WINDOW_TIME`] (V; zero until two snapshots). At the
    /// stage's first sample the window restarts.
    pub(super) fn window_emf(&mut self, emf: T) -> T {
        let stage_start = match self.stage {
            Stage::Settle | Stage::Release => self.remaining == self.settle_samples,
            _ => false,
        };
        if stage_start {
            self.window_flux = T::zero();
            self.window.reset();
        }
        self.window_flux += emf * self.config.ts;
        let mut mean = T::zero();
        if let Some((oldest, span)) = self.window.oldest().filter(|_| self.window.taken() > 1) {
            let flux = self.window_flux - oldest;
            mean = flux / (T::lit(span as f64) * self.config.ts);
            let share = mean.abs() / (self.config.motion_voltage * T::lit(LOOP_WINDOW_FACTOR));
            if share > self.loop_window_peak {
                self.loop_window_peak = share;
            }
            if share > T::one() && flux.abs() > self.motion_flux.abs() {
                // The turn of a rotor that started within the window.
                self.motion_flux = flux;
            }
        }
        self.window.push(self.window_flux);
        mean
    }

    /// The largest mean back-EMF across the axis over [`LOOP_WINDOW_TIME`] under the current
    /// loop since the calibration started, over its threshold [`LOOP_WINDOW_FACTOR`] ×
    /// `motion_voltage` (1 or more: the rotor moved).
    pub fn loop_window_peak(&self) -> T {
        self.loop_window_peak
    }

    /// The motion test's threshold (V): in voltage mode `motion_voltage`, or the sensors'
    /// noise floor ([`motion_noise_floor`](Self::motion_noise_floor)) where that is larger;
    /// [`LOOP_MOTION_FACTOR`] times `motion_voltage` under the current loop.
    pub(super) fn motion_threshold(&self, voltage_mode: bool) -> T {
        if voltage_mode {
            self.config.motion_voltage.step_max(self.noise_floor)
        } else {
            self.config.motion_voltage * T::lit(LOOP_MOTION_FACTOR)
        }
    }

    /// The voltage-mode threshold's noise floor (V): [`MOTION_NOISE_MARGIN`] times the largest
    /// |L̂q·dΔi⊥/dt| read over the second half of the settling at I₁ (zero before it).
    pub fn motion_noise_floor(&self) -> T {
        self.noise_floor
    }

    /// The largest back-EMF across the axis the motion test has read in voltage mode since the
    /// calibration started, as a share of its threshold `motion_voltage` (1 or more: the rotor
    /// moved).
    pub fn motion_peak(&self) -> T {
        self.motion_peak
    }

    /// The largest back-EMF across the axis read under the current loop (the settling at I₁
    /// and the release to zero) since the calibration started, as a share of that stage's
    /// threshold, [`LOOP_MOTION_FACTOR`] × `motion_voltage` (1 or more: the rotor moved).
    pub fn loop_motion_peak(&self) -> T {
        self.loop_motion_peak
    }

    /// The rotor's turn since the stage's first sample, read from its back-EMF, times the
    /// flux it turns across the axis (V·s; zero unless the rotor turned): R̂s·Δi⊥ +
    /// L̂q·dΔi⊥/dt − Δv⊥ = −ω·ψa across the axis (module docs), ψa = λ̂f + (L̂d − L̂q)·i_d the
    /// active flux at the stage's current i_d (in the axis' fixed frame the current's own
    /// flux is in L̂q·dΔi⊥/dt; the saliency's part turns with the rotor), summed over the
    /// samples where it exceeded [`MOTION_TRAVEL_SHARE`] of the threshold. The turn is
    /// −motion_flux/ψa electrical rad; after
    /// [`GainCalibrationStatus::RotorMoved`](super::GainCalibrationStatus::RotorMoved) the
    /// drive starts from the aligned angle plus it.
    pub fn motion_flux(&self) -> T {
        self.motion_flux
    }

    /// The rotor's turn (electrical rad) that ended the calibration with
    /// [`GainCalibrationStatus::RotorMoved`](super::GainCalibrationStatus::RotorMoved):
    /// −[`motion_flux`](Self::motion_flux)/ψa with ψa = `flux_linkage` + `saliency`·i_d at
    /// the stage's current (the model's λ̂f and L̂d − L̂q); zero when the rotor did not move
    /// or ψa is not positive.
    pub fn motion_travel(&self, flux_linkage: T, saliency: T) -> T {
        self.per_flux(self.motion_flux, flux_linkage, saliency)
    }

    /// The rotor's electrical speed (rad/s) when the calibration ended with
    /// [`GainCalibrationStatus::RotorMoved`](super::GainCalibrationStatus::RotorMoved): the
    /// back-EMF that ended it over ψa ([`motion_travel`](Self::motion_travel)); zero
    /// otherwise.
    pub fn motion_speed(&self, flux_linkage: T, saliency: T) -> T {
        self.per_flux(self.motion_emf, flux_linkage, saliency)
    }

    /// −`x`/ψa after a motion, ψa = `flux_linkage` + `saliency`·i_d of the stage; zero
    /// otherwise.
    fn per_flux(&self, x: T, flux_linkage: T, saliency: T) -> T {
        let psi_a = flux_linkage + saliency * self.motion_current;
        // NaN compares false: nothing.
        if self.status == super::GainCalibrationStatus::RotorMoved && psi_a > T::zero() {
            -x / psi_a
        } else {
            T::zero()
        }
    }
}
