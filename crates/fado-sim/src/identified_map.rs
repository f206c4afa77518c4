//! The identified magnetic model as a flux map: the algebraic model that commissioning fits
//! ([`Identification::saturation`]) tabulated as the CSV that `[model] flux_map` reads
//! (`crate::magnetics_file`: header `i_d,i_q,psi_d,psi_q`, SI peak values, rotor frame), for
//! the drive that looks its model up in a table (a firmware's flash) rather than solving the
//! algebraic model's i(ψ).
//!
//! **Grid.** [`NODES`] × [`NODES`] uniform nodes over ±[`DEFAULT_CURRENT_LIMIT_RATIO`] × the
//! rated current on both axes: the drive's default current limit, so that every current it
//! commands lies inside the map (beyond it the map extends its edge cells linearly). A
//! uniform axis is the one the map's lookup reads without a division
//! ([`fado_core::magnetics::FluxMap`]). The fitted model is measured only up to the pulses'
//! current (the rated one, docs/results/commissioning-magnetics.md); beyond it the table holds
//! the model's extrapolation, monotonic like the model (non-negative saturation
//! coefficients), so the map has an inverse everywhere. Bilinear interpolation between nodes
//! 2·ratio/(NODES − 1) of the rated current apart (9.2 % at the ratio's 1.84): its error
//! against the model is measured by this module's test.

use fado_core::Dq;
use fado_core::commissioning::Identification;
use fado_core::control::speed_controller::DEFAULT_CURRENT_LIMIT_RATIO;
use fado_core::magnetics::{FluxMapError, MagneticModel, Saturation};

use crate::magnetics::FluxMapData;
use crate::magnetics_file::flux_map_csv;

/// The file name `fado-sim commission` writes the map to, beside identified.toml (which names
/// it by this relative path).
pub const IDENTIFIED_MAP_FILE: &str = "identified-flux-map.csv";

/// Nodes per axis (odd: i = 0 is a node).
pub const NODES: usize = 41;

/// The model `saturation` tabulated over ±[`DEFAULT_CURRENT_LIMIT_RATIO`] × `rated_current`
/// (module docs); refused (naming the node) when the model is not monotonic there.
pub fn tabulate(
    saturation: &Saturation<f64>,
    rated_current: f64,
) -> Result<FluxMapData, FluxMapError> {
    let half = (NODES / 2) as f64;
    let axis: Vec<f64> = (0..NODES)
        .map(|k| DEFAULT_CURRENT_LIMIT_RATIO * rated_current * (k as f64 - half) / half)
        .collect();
    let mut psi_d = Vec::with_capacity(NODES * NODES);
    let mut psi_q = Vec::with_capacity(NODES * NODES);
    for &i_d in &axis {
        for &i_q in &axis {
            let psi = saturation.flux(Dq::new(i_d, i_q));
            psi_d.push(psi.d);
            psi_q.push(psi.q);
        }
    }
    FluxMapData::new(axis.clone(), axis, psi_d, psi_q)
}

/// The identified model's map as CSV text (its first lines say what it is), or None when
/// commissioning kept constant inductances.
pub fn identified_map_csv(id: &Identification<f64>) -> Option<Result<String, FluxMapError>> {
    let s = id.saturation.as_ref()?;
    let rated = id.model.rated_current;
    Some(tabulate(s, rated).map(|map| {
        let comment = format!(
            "The algebraic magnetic model identified by `fado-sim commission` \
             ([model.saturation] in identified.toml's header), tabulated on {NODES} x {NODES} \
             nodes over +-{:.4} A (the drive's default current limit, {:.3} x the rated \
             {rated:.4} A); measured up to {:.4} A.\n\
             SI peak values, rotor frame (d on the magnet): i_d, i_q in A, psi_d, psi_q in Wb.",
            DEFAULT_CURRENT_LIMIT_RATIO * rated,
            DEFAULT_CURRENT_LIMIT_RATIO,
            id.saturation_current,
        );
        flux_map_csv(&map, &comment)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use fado_core::magnetics::FluxMap;

    /// The 5.6 kW PM-SyRM's algebraic model (the pmsyrm-baldor-5k6 preset's, rib included),
    /// tabulated: between its nodes the bilinear map stays within 2 % of the magnet's flux of
    /// the model over the rated current range (measured 1.4 %, on a grid offset from the
    /// nodes, where the rib bends ψd most).
    #[test]
    fn the_table_interpolates_the_model_within_two_percent() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../motors/saturated/pmsyrm-baldor-5k6.toml"
        ))
        .unwrap();
        let doc: toml::Table = text.parse().unwrap();
        let s: Saturation<f64> = doc["motor"]["saturation"].clone().try_into().unwrap();
        assert!(s.a_b > 0.0);
        let rated = 12.45;
        let data = tabulate(&s, rated).unwrap();
        let map: FluxMap<'_, f64> = data.map();
        let psi0 = s.flux(Dq::zero()).d;
        let mut worst = 0.0f64;
        for j in -20..=20 {
            for k in -20..=20 {
                let i = Dq::new(j as f64 + 0.37, k as f64 - 0.29) * (rated / 20.0);
                if i.norm() <= rated {
                    worst = worst.max((map.flux(i) - s.flux(i)).norm() / psi0);
                }
            }
        }
        assert!(worst < 0.02, "{worst}");
    }
}
