//! Voltage limiting to the inverter hexagon and space-vector PWM (paper, V: "synthesized by
//! the space vector PWM (SVPWM) \[16\]").
//!
//! **Limit: keep the angle, scale the magnitude.** A two-level inverter with dc link Vdc can
//! realise (on average over a period) exactly the α-β vectors whose phase voltages span at
//! most Vdc: max(v_a, v_b, v_c) − min(v_a, v_b, v_c) ≤ Vdc — the hexagon with vertices
//! 2/3·Vdc. A vector outside is scaled by Vdc/span onto the boundary along its own direction.
//! The minimum-distance projection would give a little more voltage in overmodulation, but
//! it turns the vector towards a vertex, i.e. changes the d/q ratio the current controller
//! asked for; scaling keeps the direction the controller wants and is what the anti-windup and
//! the estimator are told was applied. The inscribed circle Vdc/√3 is offered as an option.
//!
//! **Overmodulation up to six-step** (option [`VoltageLimit::Overmodulation`]): a vector
//! outside the hexagon is realised as the hexagon's point nearest to it (the
//! minimum-distance overmodulation of Bolognani & Zigliotto, IEEE TIA 1997). On an edge's
//! normal slab that is the orthogonal projection onto the edge (the tangential component,
//! i.e. the direction the d/q ratio asks for, is kept as far as the edge allows); beyond an
//! edge's end it is the vertex. A reference circle of growing radius is thus realised as a
//! trajectory that spends ever longer on the six vertices and becomes six-step (fundamental
//! 2·Vdc/π, 10 % above the inscribed circle) as the radius grows without bound. The field
//! weakening loop may then hold |v*| above the inscribed circle
//! ([`crate::control::field_weakening`]'s `voltage_margin` up to [`SIX_STEP_MARGIN`]). The
//! realised vector is what the estimator and the anti-windup are told, so the estimator stays
//! exact; the current carries the low-order harmonics the vertices add.
//!
//! **SVPWM as min-max zero-sequence injection** \[16\]: v_x + v_0 with
//! v_0 = −(max + min)/2 centres the three references in the carrier, which is equivalent to
//! the symmetric placement of the two zero vectors in classical SVPWM. Duty d_x = ½ + (v_x +
//! v_0)/Vdc ∈ [0, 1] for every realisable vector.

use crate::control::pi::clamp;
use crate::error::{ConfigError, check};
use crate::{Ab, Abc, Real};

/// Which set of α-β vectors counts as realisable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum VoltageLimit {
    /// The inverter hexagon (linear SVPWM range plus the six sectors' corners), radius Vdc/√3
    /// to 2·Vdc/3 depending on angle. Default.
    #[default]
    Hexagon,
    /// The hexagon's inscribed circle, |v| ≤ Vdc/√3: a direction-independent limit.
    InscribedCircle,
    /// The hexagon, a vector outside realised as its nearest point (minimum-distance
    /// overmodulation, up to six-step; module docs).
    Overmodulation,
}

/// The six-step fundamental 2·Vdc/π in units of the inscribed circle Vdc/√3: 2√3/π ≈ 1.1027,
/// the largest fundamental a two-level inverter gives.
pub const SIX_STEP_MARGIN: f64 = 1.102_657_790_843_585_3;

/// Configuration of a [`SpaceVectorModulator`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModulatorConfig<T> {
    /// Realisable set. Default [`VoltageLimit::Hexagon`] (SVPWM \[16\], paper V).
    pub limit: VoltageLimit,
    /// Fraction (0, 1] of the limit that may be used, a margin e.g. for minimum pulses.
    /// Default 1 \[A\].
    pub max_modulation: T,
}

impl<T: Real> Default for ModulatorConfig<T> {
    fn default() -> Self {
        Self {
            limit: VoltageLimit::Hexagon,
            max_modulation: T::one(),
        }
    }
}

/// Result of one modulation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Modulation<T> {
    /// Duty cycles of the upper switches, each in [0, 1].
    pub duty: Abc<T>,
    /// The α-β voltage these duties realise (the limited reference) in V.
    pub v_ab: Ab<T>,
    /// True when the reference had to be scaled (or Vdc was not usable).
    pub saturated: bool,
}

/// Hexagon limiter and min-max SVPWM (module docs). Stateless.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpaceVectorModulator<T> {
    config: ModulatorConfig<T>,
}

impl<T: Real> SpaceVectorModulator<T> {
    /// A new modulator; `max_modulation` must be in (0, 1].
    pub fn new(config: ModulatorConfig<T>) -> Result<Self, ConfigError> {
        let m = check::positive("max_modulation", config.max_modulation)?;
        if m > T::one() {
            return Err(ConfigError::OutOfRange {
                field: "max_modulation",
                expected: "at most 1",
            });
        }
        Ok(Self { config })
    }

    /// No state.
    pub fn reset(&mut self) {}

    /// The reference limited to the realisable set for dc-link voltage `vdc`, keeping its
    /// angle; and whether it was scaled. Non-finite inputs or vdc ≤ 0 give the zero vector
    /// (flagged as saturated).
    #[inline]
    pub fn limit(&self, v_ab: Ab<T>, vdc: T) -> (Ab<T>, bool) {
        if !(v_ab.is_finite() && vdc.is_finite() && vdc > T::zero()) {
            return (Ab::zero(), true);
        }
        let m = self.config.max_modulation;
        let scale = match self.config.limit {
            VoltageLimit::Overmodulation => {
                let span = phase_span(v_ab.to_abc());
                let avail = m * vdc;
                if span > avail {
                    return (nearest_on_hexagon(v_ab, avail), true);
                }
                T::one()
            }
            VoltageLimit::Hexagon => {
                let span = phase_span(v_ab.to_abc());
                let avail = m * vdc;
                if span > avail { avail / span } else { T::one() }
            }
            VoltageLimit::InscribedCircle => {
                let n = v_ab.norm();
                let avail = m * vdc * T::lit(0.577_350_269_189_625_8);
                if n > avail { avail / n } else { T::one() }
            }
        };
        if scale < T::one() {
            (v_ab * scale, true)
        } else {
            (v_ab, false)
        }
    }

    /// Limits `v_ab` and modulates it: duties in [0, 1] and the realised α-β vector.
    #[inline]
    pub fn step(&self, v_ab: Ab<T>, vdc: T) -> Modulation<T> {
        let (v, saturated) = self.limit(v_ab, vdc);
        let duty = if vdc.is_finite() && vdc > T::zero() {
            svpwm_duty(v, vdc)
        } else {
            Abc::new(T::lit(0.5), T::lit(0.5), T::lit(0.5))
        };
        Modulation {
            duty,
            v_ab: v,
            saturated,
        }
    }

    /// The configuration in use.
    pub fn config(&self) -> &ModulatorConfig<T> {
        &self.config
    }
}

/// The point of the hexagon of line-voltage span `span` (vertices 2·span/3) nearest to `v`, a
/// vector outside it: the edge whose outward normal (at 30° + k·60°) is nearest to `v`'s
/// direction, the orthogonal projection onto its line, clamped to the edge's ends (the
/// vertices).
#[inline]
fn nearest_on_hexagon<T: Real>(v: Ab<T>, span: T) -> Ab<T> {
    let c30 = T::lit(0.866_025_403_784_438_6);
    let half = T::lit(0.5);
    // Projections on the normals at 30°, 90° and 150° (the other three are their negatives).
    let d1 = v.alpha * c30 + v.beta * half;
    let d2 = v.beta;
    let d3 = -v.alpha * c30 + v.beta * half;
    let (mut nx, mut ny, mut dot) = (c30, half, d1);
    if d2.abs() > dot.abs() {
        (nx, ny, dot) = (T::zero(), T::one(), d2);
    }
    if d3.abs() > dot.abs() {
        (nx, ny, dot) = (-c30, half, d3);
    }
    if dot < T::zero() {
        (nx, ny) = (-nx, -ny);
    }
    // Inscribed radius span/√3, half an edge span/3; tangent (−ny, nx).
    let radius = span * T::lit(0.577_350_269_189_625_8);
    let half_edge = span / T::lit(3.0);
    let t = clamp(-v.alpha * ny + v.beta * nx, -half_edge, half_edge);
    Ab::new(radius * nx - t * ny, radius * ny + t * nx)
}

/// max − min of the three phase values (the line-to-line span a vector needs).
#[inline]
fn phase_span<T: Real>(v: Abc<T>) -> T {
    let (hi, lo) = max_min(v);
    hi - lo
}

#[inline]
fn max_min<T: Real>(v: Abc<T>) -> (T, T) {
    let hi = if v.a > v.b { v.a } else { v.b };
    let hi = if hi > v.c { hi } else { v.c };
    let lo = if v.a < v.b { v.a } else { v.b };
    let lo = if lo < v.c { lo } else { v.c };
    (hi, lo)
}

/// Min-max SVPWM \[16\] of a realisable α-β vector: d_x = ½ + (v_x − (max + min)/2)/Vdc,
/// clamped to [0, 1] against rounding (a vector outside the hexagon is clipped per phase —
/// limit it first). `vdc` must be positive; non-finite values give ½ on every phase.
#[inline]
pub fn svpwm_duty<T: Real>(v_ab: Ab<T>, vdc: T) -> Abc<T> {
    let half = T::lit(0.5);
    if !(v_ab.is_finite() && vdc.is_finite() && vdc > T::zero()) {
        return Abc::new(half, half, half);
    }
    let v = v_ab.to_abc();
    let (hi, lo) = max_min(v);
    let v0 = -(hi + lo) * half;
    let inv = T::one() / vdc;
    let duty = |x: T| clamp(half + (x + v0) * inv, T::zero(), T::one());
    Abc::new(duty(v.a), duty(v.b), duty(v.c))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn pole_ab(duty: Abc<f64>, vdc: f64) -> Ab<f64> {
        (duty * vdc).to_ab()
    }

    #[test]
    fn hexagon_radius_varies_between_inscribed_circle_and_vertex() {
        let m = SpaceVectorModulator::new(ModulatorConfig::default()).unwrap();
        let vdc = 300.0_f64;
        // Along a vertex (phase a) the limit is 2/3·Vdc, between vertices Vdc/√3.
        let (v, sat) = m.limit(Ab::new(1000.0, 0.0), vdc);
        assert!(sat && (v.norm() - 200.0).abs() < 1e-9);
        let dir = Ab::from_polar(1000.0, core::f64::consts::PI / 6.0);
        let (v, _) = m.limit(dir, vdc);
        assert!((v.norm() - vdc / 3f64.sqrt()).abs() < 1e-9);
        let circle = SpaceVectorModulator::new(ModulatorConfig {
            limit: VoltageLimit::InscribedCircle,
            max_modulation: 1.0,
        })
        .unwrap();
        let (v, _) = circle.limit(Ab::new(1000.0, 0.0), vdc);
        assert!((v.norm() - vdc / 3f64.sqrt()).abs() < 1e-9);
    }

    #[test]
    fn overmodulation_reaches_six_step() {
        let m = SpaceVectorModulator::new(ModulatorConfig {
            limit: VoltageLimit::Overmodulation,
            max_modulation: 1.0,
        })
        .unwrap();
        let vdc = 300.0_f64;
        // The fundamental of a circular reference of radius r, realised: from the inscribed
        // circle (r = Vdc/√3, linear) up to 2·Vdc/π (six-step) as r grows.
        let fundamental = |r: f64| {
            let n = 3600;
            let mut sum = 0.0;
            for k in 0..n {
                let a = core::f64::consts::TAU * k as f64 / n as f64;
                let (v, _) = m.limit(Ab::from_polar(r, a), vdc);
                sum += v.alpha * a.cos() + v.beta * a.sin();
            }
            sum / n as f64
        };
        let inscribed = vdc / 3f64.sqrt();
        assert!((fundamental(inscribed) - inscribed).abs() < 1e-9);
        let six_step = 2.0 * vdc / core::f64::consts::PI;
        assert!((SIX_STEP_MARGIN * inscribed - six_step).abs() < 1e-9);
        let (f1, f2, f3) = (
            fundamental(1.05 * inscribed),
            fundamental(1.2 * inscribed),
            fundamental(1e6 * inscribed),
        );
        assert!(inscribed < f1 && f1 < f2 && f2 < f3, "{f1} {f2} {f3}");
        assert!(
            (f3 - six_step).abs() < 1e-3 * six_step,
            "{f3} vs {six_step}"
        );
        // Far outside, every angle is realised as a vertex (2/3·Vdc): six-step.
        let (v, sat) = m.limit(Ab::from_polar(1e6, 0.4), vdc);
        assert!(sat && (v.norm() - 200.0).abs() < 1e-9, "{v:?}");
    }

    #[test]
    fn bad_vdc_gives_zero_vector_and_half_duty() {
        let m = SpaceVectorModulator::new(ModulatorConfig::default()).unwrap();
        for vdc in [0.0, -5.0, f64::NAN, f64::INFINITY] {
            let out = m.step(Ab::new(10.0, 0.0), vdc);
            assert_eq!(out.v_ab, Ab::zero());
            assert_eq!(out.duty, Abc::new(0.5, 0.5, 0.5));
        }
        assert!(
            SpaceVectorModulator::new(ModulatorConfig {
                limit: VoltageLimit::Hexagon,
                max_modulation: 1.2
            })
            .is_err()
        );
    }

    proptest! {
        #[test]
        fn duties_realise_the_reference_inside_the_hexagon(
            mag in 0.0..1.0_f64, ang in -4.0..4.0_f64, vdc in 1.0..800.0_f64,
        ) {
            let m = SpaceVectorModulator::new(ModulatorConfig::default()).unwrap();
            // Scale so that the vector is inside: a fraction of the radius in that direction.
            let unit = Ab::from_polar(1.0, ang);
            let radius = vdc / phase_span(unit.to_abc());
            let v = unit * (mag * radius);
            let out = m.step(v, vdc);
            prop_assert!(!out.saturated);
            for d in [out.duty.a, out.duty.b, out.duty.c] {
                prop_assert!((0.0..=1.0).contains(&d));
            }
            // Line-to-line averages equal the reference's.
            let r = v.to_abc();
            let tol = 1e-9 * vdc;
            prop_assert!(((out.duty.a - out.duty.b) * vdc - (r.a - r.b)).abs() < tol);
            prop_assert!(((out.duty.b - out.duty.c) * vdc - (r.b - r.c)).abs() < tol);
            prop_assert!((pole_ab(out.duty, vdc) - v).norm() < tol);
            // Min-max injection centres the duties.
            let (hi, lo) = max_min(out.duty);
            prop_assert!((hi + lo - 1.0).abs() < 1e-12);
        }

        #[test]
        fn overmodulation_gives_the_nearest_point_of_the_hexagon(
            mag in 0.0..5000.0_f64, ang in -4.0..4.0_f64, vdc in 1.0..800.0_f64,
        ) {
            let m = SpaceVectorModulator::new(ModulatorConfig {
                limit: VoltageLimit::Overmodulation,
                max_modulation: 1.0,
            }).unwrap();
            let v = Ab::from_polar(mag, ang);
            let out = m.step(v, vdc);
            prop_assert!(phase_span(out.v_ab.to_abc()) <= vdc * (1.0 + 1e-9));
            prop_assert!((pole_ab(out.duty, vdc) - out.v_ab).norm() < 1e-9 * vdc);
            if !out.saturated {
                prop_assert_eq!(out.v_ab, v);
            } else {
                // No point of the hexagon's boundary is nearer (sampled finely).
                let d = (v - out.v_ab).norm();
                for k in 0..720 {
                    let u = Ab::from_polar(1.0, core::f64::consts::TAU * k as f64 / 720.0);
                    let p = u * (vdc / phase_span(u.to_abc()));
                    prop_assert!((v - p).norm() >= d - 1e-9 * vdc);
                }
            }
        }

        #[test]
        fn limiting_keeps_angle_and_lands_on_the_boundary(
            mag in 0.0..5000.0_f64, ang in -4.0..4.0_f64, vdc in 1.0..800.0_f64,
        ) {
            let m = SpaceVectorModulator::new(ModulatorConfig::default()).unwrap();
            let v = Ab::from_polar(mag, ang);
            let out = m.step(v, vdc);
            for d in [out.duty.a, out.duty.b, out.duty.c] {
                prop_assert!((0.0..=1.0).contains(&d));
            }
            prop_assert!(out.v_ab.norm() <= v.norm() * (1.0 + 1e-12) + 1e-12);
            prop_assert!(phase_span(out.v_ab.to_abc()) <= vdc * (1.0 + 1e-12));
            prop_assert!((pole_ab(out.duty, vdc) - out.v_ab).norm() < 1e-9 * vdc);
            if out.saturated {
                // Same direction (cross product 0, dot product positive), on the boundary.
                let cross = v.alpha * out.v_ab.beta - v.beta * out.v_ab.alpha;
                prop_assert!(cross.abs() < 1e-9 * v.norm() * out.v_ab.norm() + 1e-12);
                prop_assert!(v.alpha * out.v_ab.alpha + v.beta * out.v_ab.beta > 0.0);
                prop_assert!((phase_span(out.v_ab.to_abc()) - vdc).abs() < 1e-9 * vdc);
                let (hi, lo) = max_min(out.duty);
                prop_assert!(hi > 1.0 - 1e-9 && lo < 1e-9);
            } else {
                prop_assert_eq!(out.v_ab, v);
            }
        }
    }
}
