//! The identified magnetic model as a flux map: the algebraic model that commissioning fits
//! ([`Identification::saturation`]) tabulated as the CSV that `[model] flux_map` reads
//! (`crate::magnetics_file`: header `i_d,i_q,psi_d,psi_q`, SI peak values, rotor frame), for
//! the drive that looks its model up in a table (a firmware's flash) rather than solving the
//! algebraic model's i(ψ).
//!
//! **Grid.** Uniform nodes ([`NODES`] per axis, the cells halved up to [`MAX_NODES`] where
//! the interpolation error exceeds [`TABLE_TOLERANCE`]) over ±[`DEFAULT_CURRENT_LIMIT_RATIO`] × the
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

/// Nodes per axis of the coarsest table (odd: i = 0 is a node).
pub const NODES: usize = 41;

/// Nodes per axis of the finest table: [`NODES`] with its cells halved twice.
pub const MAX_NODES: usize = 161;

/// Largest interpolation error of the table against the model over the rated current range,
/// as a share of the model's ψd(0, 0): 2 %, the bound this module's test holds on the 5.6 kW
/// PM-SyRM's model at [`NODES`] (1.4 % there). Beyond it the cells are halved (up to
/// [`MAX_NODES`]): the ferrite PM-SyRM of `tests/data/motulator/mot-pmsyrm-4k.toml`, whose
/// fitted rib bends ψd within ±2 A of zero, is 2.85 % off on [`NODES`]' 0.92 A cells and
/// 0.72 % on 81 nodes' 0.46 A; its commissioned map on 41 nodes loses `reversal` on seeds 1
/// and 3 (2.0, 3.1 rad) where the model it tabulates holds it (0.17, 0.12 rad), on 81 nodes
/// it holds it on seeds 1–4 (0.200 / 0.093 / 0.105 / 0.030 rad,
/// `bash scripts/motulator-closed-loop.sh`). Every other commissioned map of the saturated
/// presets and test machines stays on 41 nodes.
pub const TABLE_TOLERANCE: f64 = 0.02;

/// The model `saturation` tabulated over ±[`DEFAULT_CURRENT_LIMIT_RATIO`] × `rated_current`
/// (module docs), on the coarsest grid from [`NODES`] to [`MAX_NODES`] that interpolates it
/// within [`TABLE_TOLERANCE`]; refused (naming the node) when the model is not monotonic there.
pub fn tabulate(
    saturation: &Saturation<f64>,
    rated_current: f64,
) -> Result<FluxMapData, FluxMapError> {
    let mut nodes = NODES;
    loop {
        let data = tabulate_on(saturation, rated_current, nodes)?;
        if nodes >= MAX_NODES
            || interpolation_error(&data, saturation, rated_current) <= TABLE_TOLERANCE
        {
            return Ok(data);
        }
        nodes = 2 * nodes - 1;
    }
}

/// The model tabulated on `nodes` × `nodes` uniform nodes.
fn tabulate_on(
    saturation: &Saturation<f64>,
    rated_current: f64,
    nodes: usize,
) -> Result<FluxMapData, FluxMapError> {
    let half = (nodes / 2) as f64;
    let axis: Vec<f64> = (0..nodes)
        .map(|k| DEFAULT_CURRENT_LIMIT_RATIO * rated_current * (k as f64 - half) / half)
        .collect();
    let mut psi_d = Vec::with_capacity(nodes * nodes);
    let mut psi_q = Vec::with_capacity(nodes * nodes);
    for &i_d in &axis {
        for &i_q in &axis {
            let psi = saturation.flux(Dq::new(i_d, i_q));
            psi_d.push(psi.d);
            psi_q.push(psi.q);
        }
    }
    FluxMapData::new(axis.clone(), axis, psi_d, psi_q)
}

/// The table's largest flux error against the model at its cells' centres (where bilinear
/// interpolation is farthest from the nodes) within the rated current, as a share of the
/// model's ψd(0, 0).
pub fn interpolation_error(
    data: &FluxMapData,
    saturation: &Saturation<f64>,
    rated_current: f64,
) -> f64 {
    let map = data.map();
    let axis = map.i_d();
    let psi0 = saturation.flux(Dq::zero()).d.abs();
    let centres: Vec<f64> = axis.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
    let mut worst = 0.0f64;
    for &i_d in &centres {
        for &i_q in &centres {
            let i = Dq::new(i_d, i_q);
            if i.norm() <= rated_current {
                worst = worst.max((map.flux(i) - saturation.flux(i)).norm() / psi0);
            }
        }
    }
    worst
}

/// The identified model's map as CSV text (its first lines say what it is), or None when
/// commissioning kept constant inductances.
pub fn identified_map_csv(id: &Identification<f64>) -> Option<Result<String, FluxMapError>> {
    let s = id.saturation.as_ref()?;
    let rated = id.model.rated_current;
    Some(tabulate(s, rated).map(|map| {
        let n = map.map().i_d().len();
        let comment = format!(
            "The algebraic magnetic model identified by `fado-sim commission` \
             ([model.saturation] in identified.toml's header), tabulated on {n} x {n} \
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
        // The tolerance keeps this model on the coarsest grid.
        assert_eq!(map.i_d().len(), NODES);
        assert!(interpolation_error(&data, &s, rated) <= TABLE_TOLERANCE);
    }

    /// The model commissioning fits to the ferrite PM-SyRM of
    /// `tests/data/motulator/mot-pmsyrm-4k.toml` (sensor seed 1; its rib bends ψd within ±2 A
    /// of zero): on the coarsest grid the table is farther from it than the tolerance, and the
    /// table written is the first finer one within it.
    #[test]
    fn a_model_bent_near_zero_current_gets_finer_cells() {
        let text = "a_b = 50.644337516450776\na_bp = 3.338303602008419\n\
                    a_d0 = 10.164749173920013\na_dd = 42.6502523276584\n\
                    a_dq = 26.98469876002723\na_q0 = 3.728019035691923\n\
                    a_qq = 4.889141411498049\ni_f = 1.9662611656553874\n\
                    k_q = 0.19440636743183137\npsi_f = 0.0\n\
                    psi_n = 0.44924502640276465\ns = 8.0\nt = 5.0\nu = 1.0\nv = 0.0\nw = 2.0\n";
        let s: Saturation<f64> = toml::from_str(text).unwrap();
        let rated = 10.0;
        let coarse = tabulate_on(&s, rated, NODES).unwrap();
        let e_coarse = interpolation_error(&coarse, &s, rated);
        let data = tabulate(&s, rated).unwrap();
        let e = interpolation_error(&data, &s, rated);
        println!(
            "{NODES} nodes: {e_coarse:.4}; {} nodes: {e:.4}",
            data.map().i_d().len()
        );
        assert!(e_coarse > TABLE_TOLERANCE, "{e_coarse}");
        assert!(data.map().i_d().len() > NODES);
        assert!(e <= TABLE_TOLERANCE, "{e}");
    }
}
