//! What `fado-sim commission` says of the standstill pulses' verdict on a machine's
//! saturation ([`SaturationVerdict`]): its name in metrics.json, the header line of
//! identified.toml, the online R̂s law fixed where the saturation is unidentified, and the
//! identified model's flux uncertainty where it is.

use fado_core::commissioning::{Identification, PULSE_MOTION_LIMIT, SaturationVerdict};

/// The name of a [`SaturationVerdict`] in metrics.json.
pub fn verdict_name(v: SaturationVerdict) -> &'static str {
    match v {
        SaturationVerdict::Detected => "detected",
        SaturationVerdict::NotDetected => "not_detected",
        SaturationVerdict::Inconclusive => "inconclusive",
        SaturationVerdict::RotorMoved => "rotor_moved",
        SaturationVerdict::NotMeasured => "not_measured",
    }
}

/// `key` = `value` in `doc`'s `[estimator.rs_adaptation]` (the tables made where missing);
/// false, and nothing written, where the user set the key or a table on the way is not one.
fn set_law_key(doc: &mut toml::Table, key: &str, value: toml::Value) -> bool {
    let law = doc
        .entry("estimator")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()))
        .as_table_mut()
        .and_then(|t| {
            t.entry("rs_adaptation")
                .or_insert_with(|| toml::Value::Table(toml::Table::new()))
                .as_table_mut()
        });
    match law {
        Some(law) if !law.contains_key(key) => {
            law.insert(key.into(), value);
            true
        }
        _ => false,
    }
}

/// Where the pulses left the saturation unidentified (`inconclusive`, `rotor_moved`: the
/// model's constant inductances are likely wrong at load), `[estimator.rs_adaptation]
/// enabled = false` in `doc`, and the header line saying why: the online R̂s law reads the
/// model's flux error at load as resistance. On the 750 W servo SPM
/// (`tests/data/spm-dq-sat-saturated.toml`) it drifted by +1.3 % and lost `stops` (0.8–1.1
/// rad on seeds 1–4); with R̂s fixed at the commissioned value `reversal`, `stops` and
/// `rated-reversal` pass (0.04–0.14 rad). A key the user set is kept.
pub(crate) fn freeze_resistance_law(doc: &mut toml::Table, id: &Identification<f64>) -> String {
    if !matches!(
        id.saturation_verdict(),
        SaturationVerdict::Inconclusive | SaturationVerdict::RotorMoved
    ) {
        return String::new();
    }
    if !set_law_key(doc, "enabled", toml::Value::Boolean(false)) {
        return String::new();
    }
    "# [estimator.rs_adaptation] enabled = false: with the saturation unidentified, the online \
     R̂s law would read the constant inductances' flux error at load as resistance; R̂s stays \
     the commissioned value (re-run the commissioning after a large temperature change).\n"
        .into()
}

/// Where the pulses identified a saturating model, its flux uncertainty at zero current
/// ([`Identification::model_flux_uncertainty`]) and its growth to the rated current
/// ([`Identification::model_flux_uncertainty_rated`]) as `[estimator.rs_adaptation]
/// model_flux_uncertainty` and `model_flux_uncertainty_rated` in `doc`, and the header lines
/// saying why: the online R̂s law on a saturating model freezes where the model's flux error
/// at the present current could read as resistance (docs/method/saturation.md, "The R̂s
/// law's regressor"). A key the user set is kept.
pub(crate) fn model_uncertainty(doc: &mut toml::Table, id: &Identification<f64>) -> String {
    let (Some(u), Some(g)) = (
        id.model_flux_uncertainty(),
        id.model_flux_uncertainty_rated(),
    ) else {
        return String::new();
    };
    let mut out = String::new();
    if set_law_key(doc, "model_flux_uncertainty", toml::Value::Float(u)) {
        out += &format!(
            "# [estimator.rs_adaptation] model_flux_uncertainty = {u:.4}: the identified model's \
             flux may be this share of its flux_linkage off the machine's (the fit's RMS \
             current residual {:.4} A times its larger inductance); the online R̂s law freezes \
             where that could read as resistance.\n",
            id.saturation_residual
        );
    }
    if set_law_key(doc, "model_flux_uncertainty_rated", toml::Value::Float(g)) {
        out += &format!(
            "# [estimator.rs_adaptation] model_flux_uncertainty_rated = {g:.4}: and this share \
             more at the rated current, with the current's square (the fit's worst RMS flux \
             residual in a quarter of the pulses' current range, up to {:.3} A).\n",
            id.saturation_current
        );
    }
    out
}

/// The header's statement on the magnetic model: saturation detected (the written
/// `[model.saturation]`) or not (constant inductances), with the detection statistic.
pub(crate) fn saturation_comment(id: &Identification<f64>) -> String {
    let change = 100.0 * id.saturation_change;
    let range = id.saturation_current;
    if !id.saturation_change.is_finite() {
        return "# Magnetic saturation: not measured (the flux-linkage pulses did not run).\n"
            .into();
    }
    match id.saturation_verdict() {
        SaturationVerdict::RotorMoved => {
            return format!(
                "# Magnetic saturation not identified: the rotor turned {:.3} rad (electrical) \
                 over one pair of the standstill flux-linkage pulses by the procedure's flux \
                 estimate, beyond the {PULSE_MOTION_LIMIT} rad per pair within which they tell \
                 saturation from the turning magnet's back-EMF (a rotor \
                 too light for pulses of the rated current, even at the shortest rises); the \
                 model keeps constant inductances.\n",
                id.saturation_motion
            );
        }
        SaturationVerdict::Inconclusive => {
            return format!(
                "# Magnetic saturation not identified: the best fit's incremental inductances \
                 change by {change:.1} % up to {range:.3} A but it does not explain the flux \
                 linkage (RMS current residual {:.3e} A against {:.3e} A with constant \
                 inductances, not below half of it): the pulses' flux is too inaccurate on this \
                 machine to show saturation or its absence; the model keeps constant \
                 inductances.\n",
                id.saturation_residual, id.linear_residual
            );
        }
        _ => {}
    }
    match id.saturation {
        Some(_) => format!(
            "# Magnetic saturation detected: the incremental inductances change by {change:.1} % \
             up to {range:.3} A; [model.saturation] is the algebraic model fitted to the \
             standstill flux-linkage pulses (RMS current residual {:.3e} A).\n",
            id.saturation_residual
        ),
        None => format!(
            "# No magnetic saturation detected: the incremental inductances change by \
             {change:.1} % up to {range:.3} A; the model keeps constant inductances.\n"
        ),
    }
}
