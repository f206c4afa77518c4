//! What the procedure reports: the identification with its confidence, and each sample's
//! output.

use super::{Phase, Status};
use crate::magnetics::Saturation;
use crate::{Ab, Abc, MachineModel, Real};

/// Relative 1-σ statistical uncertainties of the result (module docs); `inverter_voltage` in V.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Confidence<T> {
    /// Of R̂s, relative.
    pub rs: T,
    /// Of L̂d, relative.
    pub ld: T,
    /// Of L̂q, relative.
    pub lq: T,
    /// Of λ̂f, relative.
    pub flux_linkage: T,
    /// Of Ĵ, relative.
    pub inertia: T,
    /// Of B̂, absolute in N·m·s/rad.
    pub viscous_friction: T,
    /// Of the per-phase inverter voltage error V̂, absolute in V.
    pub inverter_voltage: T,
    /// Of the current sensors' gain ratio k, relative (∞ when none was measured).
    pub current_gain_ratio: T,
}

/// The identified motor and inverter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Identification<T: 'static> {
    /// The identified model: parameters measured, ratings copied from the nameplate.
    pub model: MachineModel<T>,
    /// Statistical uncertainty of each parameter.
    pub confidence: Confidence<T>,
    /// Per-phase inverter voltage error V̂ = Td·f_sw·Vdc + V_th in V (docs/method/estimator.md §7): what the
    /// dead-time compensation should add.
    pub inverter_voltage: T,
    /// Device threshold voltage V_th = V̂ − Td·f_sw·Vdc in V (for
    /// [`crate::control::dead_time_compensation::DeadTimeCompensationConfig::threshold_voltage`]).
    pub threshold_voltage: T,
    /// The current sensors' gain ratio k = (1 + g_a)/(1 + g_b) measured in the DC test
    /// (module docs, step 3), by which phase a was divided from then on: R̂s, L̂d, L̂q and λ̂f
    /// are in phase b's scale, the drive's after its start-up calibration
    /// ([`crate::control::gain_calibration`]). 1 when the DC test gave no plausible k.
    pub current_gain_ratio: T,
    /// Saliency ratio L̂q/L̂d (> 1: interior magnets).
    pub saliency: T,
    /// Mean DC-link voltage during the DC test, V.
    pub dc_voltage: T,
    /// Duration of the procedure in s.
    pub duration: T,
    /// The magnetic model (module docs, step 5): the algebraic saturation model fitted to the
    /// standstill flux-linkage pulses, when saturation is detected (its incremental
    /// inductances change by more than [`super::MagneticsTestConfig::detection_threshold`]
    /// over the pulses' current range; `model.ld` and `model.lq` are then its zero-current
    /// incremental values). None for a magnetically linear machine, or with the test off.
    pub saturation: Option<Saturation<T>>,
    /// The detection statistic: the largest relative change of the best-fitting model's
    /// incremental inductances over the pulses' current range (NaN with the test off).
    pub saturation_change: T,
    /// RMS current residual of the fit over the pulses' samples, A (NaN with the test off).
    pub saturation_residual: T,
    /// RMS current residual of the constant-inductance model over the same samples, A (NaN
    /// with the test off).
    pub linear_residual: T,
    /// The fit's RMS flux residual |ψ̂(i) − ψ| over the pulses' samples in each of
    /// [`super::RESIDUAL_BANDS`] equal bands of |i| from zero to `saturation_current`, Wb
    /// (NaN with the test off; 0 in a band without samples).
    pub saturation_flux_residuals: [T; super::RESIDUAL_BANDS],
    /// The pulses' peak current, A: the range over which the model is measured.
    pub saturation_current: T,
    /// The rotor's largest turn over one pair of the pulses, estimated from the flux at the
    /// pair's end, rad (electrical; NaN with the test off). Above
    /// [`super::PULSE_MOTION_LIMIT`] the pulses cannot tell saturation from the turning
    /// magnet's back-EMF: `saturation` is then None whatever the machine
    /// ([`super::MagneticFit::rotor_moved`]).
    pub saturation_motion: T,
}

impl<T: Real> Identification<T> {
    /// What the standstill flux-linkage pulses say about the machine's saturation (module
    /// docs, step 5): detected, not detected, inconclusive, the rotor moved, or not measured.
    pub fn saturation_verdict(&self) -> super::SaturationVerdict {
        super::flux_pulses::verdict(
            self.saturation.is_some(),
            self.saturation_change,
            self.saturation_motion,
        )
    }

    /// How far the identified magnetic model's flux may be from the machine's, as a share of
    /// its λ̂f: the fit's RMS current residual over the pulses times the larger of its
    /// zero-current incremental inductances (the flux a current error of that size means),
    /// over its ψd(0, 0). What the online R̂s law takes as
    /// [`crate::rs_adaptation::ResistanceAdaptationConfig::model_flux_uncertainty`]. None
    /// without an identified saturating model, or where the figure is not a finite
    /// non-negative number. Measured (`fado-sim commission`, seed 1): 0.0007 on the
    /// saturated IPMSM preset, 0.016 and 0.026 on the PM-SyRM's algebraic and measured maps
    /// (their identified models' flux 5–10 % of the magnet's off at load,
    /// docs/results/commissioning-magnetics.md).
    pub fn model_flux_uncertainty(&self) -> Option<T> {
        self.saturation.as_ref()?;
        let inductance = crate::real::max(self.model.ld, self.model.lq);
        let u = self.saturation_residual * inductance / self.model.flux_linkage;
        (u.is_finite() && u >= T::zero()).then_some(u)
    }

    /// How much the model's flux uncertainty grows from zero to the rated current, as a share
    /// of λ̂f: the fit's RMS flux residual in the worst of the pulses' bands of |i|
    /// (`saturation_flux_residuals`) at the pulses' peak current, scaled to the rated
    /// current as the square of the current. What the online R̂s law takes as
    /// [`crate::estimator::RsAdaptationTuning::model_flux_uncertainty_rated`]. None where
    /// [`model_flux_uncertainty`](Self::model_flux_uncertainty) is, or where the figure is
    /// not a finite non-negative number.
    pub fn model_flux_uncertainty_rated(&self) -> Option<T> {
        self.model_flux_uncertainty()?;
        let r = &self.saturation_flux_residuals;
        let worst = r.iter().fold(T::zero(), |m, &x| crate::real::max(m, x));
        let scale = self.model.rated_current / self.saturation_current;
        let u = worst * scale * scale / self.model.flux_linkage;
        (u.is_finite() && u >= T::zero()).then_some(u)
    }
}

/// What one step returns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommissioningOutput<T> {
    /// Voltage command for the next sample (α-β), V.
    pub v_ab: Ab<T>,
    /// The same as SVPWM duties (min-max, ½ when the gates are off).
    pub duty: Abc<T>,
    /// Gates on.
    pub gates_enabled: bool,
    /// The current reference (α-β) the command regulates to, A (zero in the flux-linkage
    /// pulses, which are voltage pulses stopped at their peak current).
    pub current_reference: Ab<T>,
    /// Phase of this sample.
    pub phase: Phase,
    /// Completed fraction of the nominal procedure, 0–1.
    pub progress: T,
    /// Where it stands.
    pub status: Status,
    /// The back-EMF observer's speed (spin phases; 0 otherwise), rad/s electrical.
    pub speed: T,
    /// The back-EMF observer's rotor angle (spin phases; 0 otherwise), rad electrical.
    pub angle: T,
}
