//! The identified magnetic model against the plant's: the relative errors of the secant and
//! incremental d and q inductances and of the flux linkage over the rated current range.
//!
//! The points: a 21 × 21 grid over −I_r ≤ i_d, i_q ≤ I_r (I_r the rated current) inside the
//! circle |i| ≤ I_r. The quantities, each as identified/true − 1:
//! - incremental L_d = ∂ψd/∂i_d and L_q = ∂ψq/∂i_q (what the current controller sees), at
//!   every point;
//! - secant L_q = ψq/i_q (the estimator's active flux, `fado_core::magnetics`) where
//!   |i_q| ≥ 0.1·I_r, and secant L_d = (ψd(i_d, i_q) − ψd(0, i_q))/i_d (the d inductance at
//!   that q current, cross-saturation apart) where |i_d| ≥ 0.1·I_r;
//! - the flux linkage |ψ̂ − ψ|/ψd(0, 0) at every point.

use fado_core::Dq;
use fado_core::magnetics::{ConstantInductance, MagneticModel, Magnetics};
use serde::Serialize;

use crate::sim::PlantParams;

/// Grid nodes per axis.
const GRID: usize = 21;

/// Smallest |i_d| or |i_q| of a secant inductance, relative to the rated current.
const SECANT_MIN: f64 = 0.1;

/// The largest and the RMS relative error of one quantity over the points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ErrorStats {
    /// Largest |error|.
    pub max: f64,
    /// RMS error.
    pub rms: f64,
    /// Points compared.
    pub points: usize,
}

impl ErrorStats {
    fn push(&mut self, e: f64) {
        self.max = self.max.max(e.abs());
        self.rms += e * e;
        self.points += 1;
    }

    fn finish(mut self) -> Self {
        self.rms = (self.rms / self.points.max(1) as f64).sqrt();
        self
    }
}

/// The identified model's errors over the rated current range (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct MagneticAccuracy {
    /// The range: the rated current, A.
    pub rated_current: f64,
    /// Incremental L_d.
    pub incremental_ld: ErrorStats,
    /// Incremental L_q.
    pub incremental_lq: ErrorStats,
    /// Secant L_d.
    pub secant_ld: ErrorStats,
    /// Secant L_q.
    pub secant_lq: ErrorStats,
    /// Flux linkage, relative to the magnet's.
    pub flux: ErrorStats,
}

/// The plant's magnetic model: its saturating one, or its constant inductances.
pub fn plant_model(p: &PlantParams) -> Magnetics<'_, f64> {
    match &p.magnetics {
        Some(m) => m.model(),
        None => Magnetics::Constant(ConstantInductance {
            ld: p.motor.ld,
            lq: p.motor.lq,
            flux_linkage: p.motor.flux_linkage,
        }),
    }
}

/// `identified` against `truth` over the rated current range (module docs).
pub fn compare(
    truth: &impl MagneticModel<f64>,
    identified: &impl MagneticModel<f64>,
    rated_current: f64,
) -> MagneticAccuracy {
    let mut a = MagneticAccuracy {
        rated_current,
        ..Default::default()
    };
    let f0 = truth.magnet_flux();
    let rel = |x: f64, y: f64| x / y - 1.0;
    for k in 0..GRID {
        for m in 0..GRID {
            let node = |n: usize| rated_current * (2.0 * n as f64 / (GRID - 1) as f64 - 1.0);
            let i = Dq::new(node(k), node(m));
            if i.norm() > rated_current * (1.0 + 1e-9) {
                continue;
            }
            let (lt, li) = (
                truth.incremental_inductance(i),
                identified.incremental_inductance(i),
            );
            a.incremental_ld.push(rel(li.dd, lt.dd));
            a.incremental_lq.push(rel(li.qq, lt.qq));
            let (pt, pi) = (truth.flux(i), identified.flux(i));
            a.flux.push((pi - pt).norm() / f0);
            if i.q.abs() >= SECANT_MIN * rated_current {
                a.secant_lq.push(rel(pi.q / i.q, pt.q / i.q));
            }
            if i.d.abs() >= SECANT_MIN * rated_current {
                let q = Dq::new(0.0, i.q);
                let (zt, zi) = (truth.flux(q).d, identified.flux(q).d);
                a.secant_ld.push(rel((pi.d - zi) / i.d, (pt.d - zt) / i.d));
            }
        }
    }
    for s in [
        &mut a.incremental_ld,
        &mut a.incremental_lq,
        &mut a.secant_ld,
        &mut a.secant_lq,
        &mut a.flux,
    ] {
        *s = s.finish();
    }
    a
}
