//! A machine's constants against its own saturating magnetic model.
//!
//! A machine given a flux map (`[motor] flux_map`, Python's `fado.Machine(..., flux_map=...)`)
//! or an algebraic model (`[motor.saturation]`) also states `ld`, `lq` and `flux_linkage`: the
//! zero-current values a datasheet or a no-load test gives, which the drive's default model,
//! the ratings' checks and the commissioning's start take. Both describe one machine, so the
//! model's own zero-current values (incremental L_d, L_q and the magnet's flux ψd(0, 0),
//! `fado_core::magnetics::zero_current_constants`) must agree with them within the spread of a
//! datasheet. A map written in other units (mVs, mA), on other axes (SyR-e's maps put d on
//! the high-permeance axis and the magnet along −q) or of another machine disagrees by far
//! more, and is refused naming both keys instead of being run with nonsense.

use fado_core::Dq;
use fado_core::magnetics::{MagneticModel, zero_current_constants};

use crate::error::SimConfigError;

/// The accepted range of ψd(0, 0) / `flux_linkage`. Both are the magnet's flux at zero
/// current; a datasheet's, from the no-load back-EMF, differs from a map's by the magnet's
/// temperature (NdFeB −0.12 %/K: 12 % over 100 K) and the test's accuracy. A line-to-line
/// value (√3), a per-pole-pair slip (2), mVs (1000) and a magnet off the d axis (0) are
/// outside.
pub const FLUX_RATIO: (f64, f64) = (2.0 / 3.0, 1.5);

/// The accepted range of the model's incremental inductance at zero current over `ld` or
/// `lq`. A datasheet may give the inductance at rated current, where a saturated machine's
/// falls by up to about half (the secant L_q of scripts/saturated-replay.py's traction IPMSM:
/// −57 %); mH read as H or currents in mA (1000) are outside.
pub const INDUCTANCE_RATIO: (f64, f64) = (0.25, 4.0);

/// The band around √2 of the ratio of a map's small-current inductances to the stated `ld` and
/// `lq` that names a map whose currents are rms where peak values are meant (read at 1/√2 of
/// the current it was measured at, the map gives √2 × each inductance and keeps ψd(0, 0)):
/// 1.41 ± 12 %, on both axes at once with the flux within [`RMS_FLUX_RATIO`]. A datasheet's
/// inductances taken at rated current lie below the map's on q (the traction IPMSM's −57 %)
/// but hardly on d, so a correct map of a saturating machine meets only one of the two.
pub const RMS_INDUCTANCE_RATIO: (f64, f64) = (1.25, 1.6);

/// The range of ψd(0, 0) / `flux_linkage` that goes with [`RMS_INDUCTANCE_RATIO`]: the flux
/// agrees (a map in other flux units, or a `flux_linkage` off, is another slip).
pub const RMS_FLUX_RATIO: (f64, f64) = (0.85, 1.15);

/// The machine's stated zero-current constants, with the section that states them
/// (`motor` or `model`, for the keys errors name).
#[derive(Clone, Copy, Debug)]
pub struct Stated<'a> {
    /// The section of `ld`, `lq` and `flux_linkage` (an empty string: bare keyword names).
    pub section: &'a str,
    /// `ld`, H.
    pub ld: f64,
    /// `lq`, H.
    pub lq: f64,
    /// `flux_linkage`, Wb.
    pub flux_linkage: f64,
}

impl Stated<'_> {
    fn key(&self, name: &str) -> String {
        if self.section.is_empty() {
            name.to_owned()
        } else {
            format!("{}.{name}", self.section)
        }
    }
}

/// Refuses `model` (named `model_key` in the error) when its zero-current values disagree
/// with the stated constants (module docs; ranges [`FLUX_RATIO`], [`INDUCTANCE_RATIO`]).
pub fn check(
    model: &impl MagneticModel<f64>,
    model_key: &str,
    stated: Stated<'_>,
) -> Result<(), SimConfigError> {
    let (ld, lq, flux) = zero_current_constants(model);
    let ratio = flux / stated.flux_linkage;
    if !(FLUX_RATIO.0..=FLUX_RATIO.1).contains(&ratio) {
        return Err(SimConfigError::new(
            model_key,
            format!(
                "gives ψd = {flux:.6} Wb at zero current, but `{}` = {} Wb ({ratio:.3} ×, \
                 accepted {:.2}–{:.2}): the map's units (Wb and A, peak values) or its axes \
                 (d on the magnet, ψd = λf at i = 0; SyR-e's maps put d on the high-permeance \
                 axis) do not match the machine, or `flux_linkage` is off",
                stated.key("flux_linkage"),
                stated.flux_linkage,
                FLUX_RATIO.0,
                FLUX_RATIO.1,
            ),
        ));
    }
    for (name, of_model, given) in [("ld", ld, stated.ld), ("lq", lq, stated.lq)] {
        let ratio = of_model / given;
        if !(INDUCTANCE_RATIO.0..=INDUCTANCE_RATIO.1).contains(&ratio) {
            return Err(SimConfigError::new(
                model_key,
                format!(
                    "gives an incremental {name} of {of_model:.6e} H at zero current, but `{}` \
                     = {given:e} H ({ratio:.3} ×, accepted {}–{}): the map's current units \
                     (A peak, not mA or rms) or `{name}`'s (H) do not match the machine",
                    stated.key(name),
                    INDUCTANCE_RATIO.0,
                    INDUCTANCE_RATIO.1,
                ),
            ));
        }
    }
    Ok(())
}

/// The current, as a fraction of the rated current, of the secant inductances
/// [`rms_currents`] compares: 5 %, inside the first cell of a measured map's grid (1–2 A
/// steps on 8–12 A machines), where the map is as linear as it gets.
pub const SMALL_CURRENT: f64 = 0.05;

/// The secant inductances of `model` from −h to +h along each axis, H: the zero-current
/// values a datasheet states, taken symmetrically (a PM-SyRM's d axis saturates one way
/// first: the Baldor map's slopes at i = 0 are 0.021 and 0.031 H either side, its stated
/// `ld` their mean).
fn small_current_inductances(model: &impl MagneticModel<f64>, h: f64) -> (f64, f64) {
    let at = |d: f64, q: f64| model.flux(Dq::new(d, q));
    let ld = (at(h, 0.0).d - at(-h, 0.0).d) / (2.0 * h);
    let lq = (at(0.0, h).q - at(0.0, -h).q) / (2.0 * h);
    (ld, lq)
}

/// A warning where `model` (named `model_key`) shows the pattern of currents given rms:
/// both small-current inductances (at ±[`SMALL_CURRENT`] × `rated_current`) √2 × the stated ones ([`RMS_INDUCTANCE_RATIO`]) with the
/// magnet's flux agreeing ([`RMS_FLUX_RATIO`]). The torque at rated current cannot tell: on a
/// surface-magnet rotor 1.5·p·ψd·i_q keeps its value, and on a salient one the reluctance
/// part moves by less than the datasheet's spread. None where the map fits the stated values.
pub fn rms_currents(
    model: &impl MagneticModel<f64>,
    model_key: &str,
    stated: Stated<'_>,
    rated_current: f64,
) -> Option<String> {
    let (ld, lq) = small_current_inductances(model, SMALL_CURRENT * rated_current);
    let flux = model.flux(Dq::zero()).d;
    let (rd, rq, rf) = (ld / stated.ld, lq / stated.lq, flux / stated.flux_linkage);
    let in_band = |r: f64| (RMS_INDUCTANCE_RATIO.0..=RMS_INDUCTANCE_RATIO.1).contains(&r);
    if !(in_band(rd) && in_band(rq) && (RMS_FLUX_RATIO.0..=RMS_FLUX_RATIO.1).contains(&rf)) {
        return None;
    }
    Some(format!(
        "`{model_key}` gives inductances {rd:.3} × `{}` and {rq:.3} × `{}` at small current \
         while its ψd(0, 0) is {rf:.3} × `{}`: its currents i_d, i_q in A rms where A \
         peak is meant (√2 = 1.414 on both axes, the flux unchanged)? Multiply its i_d and i_q \
         columns by √2; or `{}` and `{}` are values at a current the map does not start from",
        stated.key("ld"),
        stated.key("lq"),
        stated.key("flux_linkage"),
        stated.key("ld"),
        stated.key("lq"),
    ))
}

#[cfg(test)]
mod tests {
    use fado_core::magnetics::{ConstantInductance, InductanceMatrix};

    use super::*;

    /// A linear model with a flux scale and a current scale (a map in other units).
    struct Scaled {
        linear: ConstantInductance<f64>,
        flux: f64,
        current: f64,
    }

    impl MagneticModel<f64> for Scaled {
        fn flux(&self, i: Dq<f64>) -> Dq<f64> {
            let psi = self
                .linear
                .flux(Dq::new(i.d / self.current, i.q / self.current));
            Dq::new(psi.d * self.flux, psi.q * self.flux)
        }

        fn current(&self, psi: Dq<f64>) -> Dq<f64> {
            let i = self
                .linear
                .current(Dq::new(psi.d / self.flux, psi.q / self.flux));
            Dq::new(i.d * self.current, i.q * self.current)
        }

        fn incremental_inductance(&self, i: Dq<f64>) -> InductanceMatrix<f64> {
            let l = self.linear.incremental_inductance(i);
            let k = self.flux / self.current;
            InductanceMatrix::diagonal(l.dd * k, l.qq * k)
        }
    }

    const STATED: Stated<'static> = Stated {
        section: "motor",
        ld: 0.012,
        lq: 0.030,
        flux_linkage: 0.30,
    };

    fn model(flux: f64, current: f64) -> Scaled {
        let linear = ConstantInductance {
            ld: 0.012,
            lq: 0.030,
            flux_linkage: 0.30,
        };
        Scaled {
            linear,
            flux,
            current,
        }
    }

    #[test]
    fn a_map_of_the_same_machine_passes_and_one_in_other_units_is_refused() {
        assert!(check(&model(1.0, 1.0), "motor.flux_map", STATED).is_ok());
        // 10 % warmer magnet, inductances at rated current (−40 %): the same machine.
        let mut warm = STATED;
        warm.flux_linkage = 0.30 * 0.9;
        warm.lq = 0.030 * 0.6;
        assert!(check(&model(1.0, 1.0), "motor.flux_map", warm).is_ok());
        // ψ in mVs.
        let e = check(&model(1000.0, 1.0), "motor.flux_map", STATED).unwrap_err();
        assert_eq!(e.key, "motor.flux_map");
        assert!(e.to_string().contains("`motor.flux_linkage`"), "{e}");
        // Currents in mA: the flux agrees, the inductances are 1000 × too small.
        let e = check(&model(1.0, 1000.0), "motor.flux_map", STATED).unwrap_err();
        assert!(e.to_string().contains("`motor.ld`"), "{e}");
        // A line-to-line flux linkage.
        let mut line = STATED;
        line.flux_linkage = 0.30 * 3f64.sqrt();
        assert!(check(&model(1.0, 1.0), "motor.flux_map", line).is_err());
    }

    #[test]
    fn a_map_in_rms_currents_is_named_and_the_same_machines_map_is_not() {
        assert!(rms_currents(&model(1.0, 1.0), "motor.flux_map", STATED, 10.0).is_none());
        // Currents rms: the map reads at i/√2 what the machine has at i.
        let rms = model(1.0, 1.0 / 2f64.sqrt());
        assert!(check(&rms, "motor.flux_map", STATED).is_ok());
        let w = rms_currents(&rms, "motor.flux_map", STATED, 10.0).expect("named");
        assert!(w.contains("A rms") && w.contains("`motor.ld`"), "{w}");
        // The same map with `lq` at rated current (−40 %): only one axis at √2, not named.
        let mut rated = STATED;
        rated.lq = 0.030 * 0.6;
        assert!(rms_currents(&model(1.0, 1.0), "motor.flux_map", rated, 10.0).is_none());
        // Fluxes in other units too: another slip, which `check` names.
        assert!(rms_currents(&model(1000.0, 1.0), "motor.flux_map", STATED, 10.0).is_none());
    }
}
