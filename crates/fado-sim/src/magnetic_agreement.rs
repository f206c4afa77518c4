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

#[cfg(test)]
mod tests {
    use fado_core::Dq;
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
}
