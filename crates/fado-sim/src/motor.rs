//! The PMSM in its rotor frame (paper eq. (1)-(2)): surface or interior magnets, with the
//! electrical dynamics integrated in closed form over intervals of constant stator voltage.
//!
//! Rotor-frame model (amplitude-invariant d-q, electrical angle θ, speed ω = p·ω_mech):
//!
//! ```text
//!   Ld·did/dt = vd − R·id + ω·Lq·iq
//!   Lq·diq/dt = vq − R·iq − ω·(Ld·id + λf)
//!   Te = 1.5·p·(λf·iq + (Ld − Lq)·id·iq),   J·dω_mech/dt = Te − T_L − B·ω_mech
//! ```
//!
//! **Integration.** Within one sample the speed is held (mechanics are updated per sample, the
//! mechanical time constant being ~10⁴ samples). With ω fixed and the stator voltage v_ab
//! constant over an interval (one switch state), the rotor-frame voltage rotates,
//! v_dq(t) = e^{−jθ(t)}·v_ab, so `x' = A·x + B·v_dq(t) + c` is linear with a sinusoidal input
//! and has the exact solution
//! `x(h) = e^{Ah}·(x0 − x_p(0) − x_c) + x_p(h) + x_c`,
//! with `x_c = −A⁻¹c` and `x_p(t) = Re{conj(v_ab)·e^{jθ(t)}·K}`, `K = (jωI − A)⁻¹·B·(1, j)ᵀ`.
//! `e^{Ah}` of the 2×2 matrix is written with its eigen-decomposition in closed form
//! (`e^{μh}·(cos νh·I + sin νh/ν·N)`). So each interval is exact to rounding (≈1e-15
//! relative; the unit tests check against a 4th-order Runge-Kutta reference at 1 ns steps):
//! no step-size error, whatever the interval length.
//!
//! A surface machine (Ld = Lq, the paper's) takes a shorter exact path in the stationary
//! frame, `L·di/dt = v − R·i − jω·λf·e^{jθ(t)}` (see [`ElectricalPropagator::advance_ab`]):
//! one real exponential and one complex rotation per interval. Both short exponentials use
//! degree-10 Taylor polynomials for arguments ≤ 0.1 (error < 3e-17), libm beyond.
//!
//! A saturating machine (`[motor.saturation]` or `[motor] flux_map`) has no constant
//! inductances: its state is the stator flux linkage, integrated by [`crate::magnetics`]
//! behind the same [`ElectricalPropagator`] interface.

use std::sync::Arc;

use fado_core::magnetics::{InverseCache, MagneticModel};
use fado_core::{Ab, Dq, MachineModel, wrap_angle};
use num_complex::Complex64;

use crate::error::{SimConfigError, check};
use crate::fastmath::unrotate;
use crate::magnetics::{FluxPoint, FluxPropagator, MagneticBounds, PlantMagnetics};

/// The plant's motor: the same record as the drive's model of it, [`MachineModel`] (the
/// motulator pattern), read from the `[motor]` TOML table. The simulator's default is the
/// paper's motor ([`MachineModel::paper`]); `dc_voltage` of the record is not used by the
/// plant (the inverter has its own, `[inverter] dc_voltage`).
pub type MotorParams = MachineModel<f64>;

/// What the plant's physics needs (the ratings are checked by [`validate_motor`]).
fn check_physics(params: &MotorParams) -> Result<(), SimConfigError> {
    check::positive("rs", params.rs)?;
    check::positive("ld", params.ld)?;
    check::positive("lq", params.lq)?;
    check::non_negative("flux_linkage", params.flux_linkage)?;
    if params.pole_pairs == 0 {
        return Err(SimConfigError::new("pole_pairs", "must be ≥ 1"));
    }
    check::positive("inertia", params.inertia)?;
    check::non_negative("viscous_friction", params.viscous_friction)?;
    Ok(())
}

/// Checks the plant record; the error names the `[motor]` key (the DC-link voltage the
/// consistency check needs is the inverter's).
pub fn validate_motor(motor: &MotorParams, dc_voltage: f64) -> Result<(), SimConfigError> {
    check_physics(motor)?;
    let mut m = *motor;
    m.dc_voltage = dc_voltage;
    m.validate()
        .map_err(|e| SimConfigError::new(e.field(), e.to_string()))
}

/// [`validate_motor`] with the error's key in its configuration section: `motor.<key>`, or
/// `inverter.dc_voltage` for the bus voltage.
pub fn validate_motor_section(motor: &MotorParams, dc_voltage: f64) -> Result<(), SimConfigError> {
    validate_motor(motor, dc_voltage).map_err(|e| {
        if e.key == "dc_voltage" {
            SimConfigError::new("inverter.dc_voltage", e.message)
        } else {
            e.in_section("motor")
        }
    })
}

/// The true machine state (evaluation only: the drive never reads it).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MotorState {
    /// Stator current in the rotor frame, A.
    pub i_dq: Dq<f64>,
    /// Electrical rotor angle θ in rad, wrapped to [−π, π].
    pub theta: f64,
    /// Mechanical speed in rad/s.
    pub omega_mech: f64,
    /// Mechanical angle in rad, not wrapped (for encoders and plots).
    pub theta_mech: f64,
}

/// Exact propagator of the electrical dynamics for one sample at a fixed speed (see the module
/// docs): built once per sample, then applied to each interval of constant stator voltage.
/// For a saturating machine it is the flux-linkage integrator of [`crate::magnetics`].
#[derive(Clone, Debug)]
pub struct ElectricalPropagator {
    /// The saturating machine's integrator (None: the closed forms below).
    flux: Option<FluxPropagator>,
    omega: f64,
    mu: f64,
    /// Traceless part N = A − μI.
    n: [[f64; 2]; 2],
    /// −det N: > 0 real eigenvalues, < 0 oscillatory.
    s: f64,
    /// Ld = Lq: then ν = |ω| and N = ω·[[0, 1], [−1, 0]], so e^{Nh} reuses e^{jωh}.
    surface: bool,
    k: [Complex64; 2],
    x_c: [f64; 2],
    /// Surface machine in the stationary frame: a = R/L, 1/R, and the back-EMF coefficient
    /// b = −jωλf/(L·(a + jω)) (see [`ElectricalPropagator::advance_ab`]).
    a: f64,
    inv_r: f64,
    b: Complex64,
}

impl ElectricalPropagator {
    /// A saturating machine's propagator: `flux` integrates every interval, so the closed
    /// forms' coefficients are not formed (zeros, never read).
    fn saturating(flux: FluxPropagator, omega: f64) -> Self {
        let zero = Complex64::new(0.0, 0.0);
        Self {
            flux: Some(flux),
            omega,
            mu: 0.0,
            n: [[0.0; 2]; 2],
            s: 0.0,
            surface: false,
            k: [zero; 2],
            x_c: [0.0; 2],
            a: 0.0,
            inv_r: 0.0,
            b: zero,
        }
    }

    /// Propagator at electrical speed `omega` with circuit resistance `r` (Rs plus any
    /// inverter on-resistance).
    pub fn new(p: &MotorParams, r: f64, omega: f64) -> Self {
        let (ld, lq) = (p.ld, p.lq);
        let a = r / ld;
        // b = −jω·λf / (L·(a + jω)), written out: one real division.
        let den = ld * (a * a + omega * omega);
        let b = Complex64::new(
            -omega * omega * p.flux_linkage / den,
            -omega * p.flux_linkage * a / den,
        );
        let mut prop = Self {
            flux: None,
            omega,
            mu: -a,
            n: [[0.0, omega], [-omega, 0.0]],
            s: -omega * omega,
            surface: ld == lq,
            k: [Complex64::new(0.0, 0.0); 2],
            x_c: [0.0; 2],
            a,
            inv_r: 1.0 / r,
            b,
        };
        if prop.surface {
            return prop; // the stationary-frame form needs nothing more
        }
        let (ad, aq) = (r / ld, r / lq);
        // A = [[−ad, ω·Lq/Ld], [−ω·Ld/Lq, −aq]]
        let a12 = omega * lq / ld;
        let a21 = -omega * ld / lq;
        prop.mu = -(ad + aq) * 0.5;
        let half_diff = (aq - ad) * 0.5; // N11 = −ad − μ = (aq − ad)/2
        prop.n = [[half_diff, a12], [a21, -half_diff]];
        prop.s = half_diff * half_diff + a12 * a21;
        // K = (jωI − A)⁻¹·B·(1, j)ᵀ with B = diag(1/Ld, 1/Lq).
        let j = Complex64::i();
        let m11 = j * omega + ad;
        let m12 = Complex64::from(-a12);
        let m21 = Complex64::from(-a21);
        let m22 = j * omega + aq;
        let det = m11 * m22 - m12 * m21;
        let bb = [Complex64::from(1.0 / ld), j / lq];
        prop.k = [
            (m22 * bb[0] - m12 * bb[1]) / det,
            (-m21 * bb[0] + m11 * bb[1]) / det,
        ];
        // x_c = −A⁻¹·c with c = (0, −ω·λf/Lq); A⁻¹ = [[−aq, −a12], [−a21, −ad]]/det_a.
        let c2 = -omega * p.flux_linkage / lq;
        let det_a = ad * aq - a12 * a21;
        prop.x_c = [a12 * c2 / det_a, ad * c2 / det_a];
        prop
    }

    /// As [`advance`](Self::advance), with the current in the stationary frame (what the
    /// inverter needs at every edge). For a surface machine (Ld = Lq = L) the α-β equation
    /// `L·di/dt = v − R·i − jω·λf·e^{jθ(t)}` is solved directly:
    /// `i(h) = e^{−ah}·i0 + (1 − e^{−ah})·v/R + b·e^{jθ0}·(e^{jωh} − e^{−ah})`, a = R/L —
    /// about half the work of the rotor-frame form; an interior machine goes through it.
    #[inline]
    pub fn advance_ab(
        &self,
        i_ab: Ab<f64>,
        v_ab: Ab<f64>,
        h: f64,
        rot0: Complex64,
        rot_h: Complex64,
    ) -> Ab<f64> {
        if let Some(f) = &self.flux {
            return f.advance_ab(i_ab, v_ab, h, rot0, rot_h);
        }
        if self.surface {
            let e = crate::fastmath::exp(-self.a * h);
            let g = (1.0 - e) * self.inv_r;
            let emf = self.b * rot0 * (rot_h - e);
            Ab::new(
                e * i_ab.alpha + g * v_ab.alpha + emf.re,
                e * i_ab.beta + g * v_ab.beta + emf.im,
            )
        } else {
            let i_dq = Dq::new(
                i_ab.alpha * rot0.re + i_ab.beta * rot0.im,
                -i_ab.alpha * rot0.im + i_ab.beta * rot0.re,
            );
            let i1 = self.advance(i_dq, v_ab, h, rot0, rot_h);
            let rot1 = rot0 * rot_h;
            Ab::new(
                i1.d * rot1.re - i1.q * rot1.im,
                i1.d * rot1.im + i1.q * rot1.re,
            )
        }
    }

    /// The electrical speed this propagator was built for.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// Electromagnetic torque at the stationary-frame current `i_ab`, rotor at `rot` = e^{jθ}:
    /// `p.torque` of the rotor-frame current for constant inductances, 1.5·p·(ψ × i) of the
    /// integrated flux for a saturating machine.
    #[inline]
    pub fn torque_ab(&self, p: &MotorParams, i_ab: Ab<f64>, rot: Complex64) -> f64 {
        match &self.flux {
            Some(f) => f.torque_ab(i_ab, rot),
            None => p.torque(unrotate(i_ab, rot)),
        }
    }

    /// As [`ElectricalPropagator::torque_ab`] for a rotor-frame current.
    #[inline]
    pub fn torque_dq(&self, p: &MotorParams, i_dq: Dq<f64>) -> f64 {
        match &self.flux {
            Some(f) => f.torque_dq(i_dq),
            None => p.torque(i_dq),
        }
    }

    /// The smallest (incremental) inductance in H: what bounds the current's slew.
    #[inline]
    pub fn min_inductance(&self, p: &MotorParams) -> f64 {
        match &self.flux {
            Some(f) => f.bounds().l_min,
            None => p.ld.min(p.lq),
        }
    }

    /// A bound on |ψ| for currents up to `i_bound` in Wb (the rotational EMF's bound over ω).
    #[inline]
    pub fn flux_bound(&self, p: &MotorParams, i_bound: f64) -> f64 {
        match &self.flux {
            Some(f) => f.bounds().psi0.abs() + f.bounds().l_max * i_bound,
            None => p.flux_linkage + (p.ld - p.lq).abs() * i_bound,
        }
    }

    /// Advances the rotor-frame current `i` over `h` seconds of constant stator voltage `v_ab`.
    /// `rot0` = e^{jθ} at the interval start, `rot_h` = e^{jωh}; the caller keeps the rotor
    /// angle (e^{jθ} at the end is `rot0·rot_h`).
    #[inline]
    pub fn advance(
        &self,
        i: Dq<f64>,
        v_ab: Ab<f64>,
        h: f64,
        rot0: Complex64,
        rot_h: Complex64,
    ) -> Dq<f64> {
        if let Some(f) = &self.flux {
            return f.advance(i, v_ab, h, rot0, rot_h);
        }
        if self.surface {
            let rot1 = rot0 * rot_h;
            let i_ab = Ab::new(i.d * rot0.re - i.q * rot0.im, i.d * rot0.im + i.q * rot0.re);
            let i1 = self.advance_ab(i_ab, v_ab, h, rot0, rot_h);
            return Dq::new(
                i1.alpha * rot1.re + i1.beta * rot1.im,
                -i1.alpha * rot1.im + i1.beta * rot1.re,
            );
        }
        let vc = Complex64::new(v_ab.alpha, -v_ab.beta); // conj(v_ab)
        let w0 = vc * rot0;
        let w1 = w0 * rot_h;
        let xp0 = [(w0 * self.k[0]).re, (w0 * self.k[1]).re];
        let xp1 = [(w1 * self.k[0]).re, (w1 * self.k[1]).re];
        let y = [i.d - xp0[0] - self.x_c[0], i.q - xp0[1] - self.x_c[1]];
        let e = crate::fastmath::exp(self.mu * h);
        let (c, sn) = expm_traceless(self.s, h);
        let e00 = e * (c + sn * self.n[0][0]);
        let e01 = e * sn * self.n[0][1];
        let e10 = e * sn * self.n[1][0];
        let e11 = e * (c + sn * self.n[1][1]);
        Dq::new(
            e00 * y[0] + e01 * y[1] + xp1[0] + self.x_c[0],
            e10 * y[0] + e11 * y[1] + xp1[1] + self.x_c[1],
        )
    }
}

/// (C, S) with e^{Nh} = C·I + S·N for a traceless 2×2 N with N² = s·I.
#[inline]
fn expm_traceless(s: f64, h: f64) -> (f64, f64) {
    let x = s * h * h;
    if x.abs() < 1e-6 {
        // Series: C = 1 + x/2 + x²/24, S = h·(1 + x/6 + x²/120); error < 1e-20.
        (
            1.0 + x * (0.5 + x / 24.0),
            h * (1.0 + x * (1.0 / 6.0 + x / 120.0)),
        )
    } else if s > 0.0 {
        let r = s.sqrt();
        ((r * h).cosh(), (r * h).sinh() / r)
    } else {
        let nu = (-s).sqrt();
        let (sin, cos) = (nu * h).sin_cos();
        (cos, sin / nu)
    }
}

/// The machine: parameters plus true state. Electrical intervals are applied by the inverter
/// through [`ElectricalPropagator`] and [`Motor::set_current`]; [`Motor::advance_mechanical`]
/// closes each sample.
#[derive(Clone, Debug)]
pub struct Motor {
    params: MotorParams,
    /// A saturating machine's magnetics and their bounds (None: constant inductances).
    magnetics: Option<(Arc<PlantMagnetics>, MagneticBounds)>,
    /// Stator flux linkage in the rotor frame (a saturating machine's state).
    psi_dq: Dq<f64>,
    state: MotorState,
    /// e^{jθ}, computed once per sample.
    rot: Complex64,
    /// (ts, e^{−B·ts/J}) of the last mechanical step: the sample period never changes.
    decay: (f64, f64),
    /// A flux map's inverse cells, carried from one sample's integrator to the next: moved
    /// into it and back (a box: no copy of its cells per sample).
    inverse: Option<Box<InverseCache<f64>>>,
}

impl Motor {
    /// A machine at rest at electrical angle `theta0` with zero current.
    pub fn new(params: MotorParams, theta0: f64) -> Result<Self, SimConfigError> {
        Self::with_magnetics(params, None, theta0)
    }

    /// A machine at rest with the saturating `magnetics` (None: the constant inductances of
    /// `params`). `params`' Ld, Lq and λf are then the datasheet's (the drive's default model);
    /// the physics is the magnetic model's.
    pub fn with_magnetics(
        params: MotorParams,
        magnetics: Option<Arc<PlantMagnetics>>,
        theta0: f64,
    ) -> Result<Self, SimConfigError> {
        check_physics(&params)?;
        check::finite("theta0", theta0)?;
        let magnetics = magnetics.map(|m| {
            let b = m.bounds(2.0 * params.rated_current.max(1e-3));
            (m, b)
        });
        if let Some((_, b)) = &magnetics
            && !(b.l_min.is_finite() && b.l_min > 0.0)
        {
            return Err(SimConfigError::new(
                "saturation",
                "the magnetic model has no positive incremental inductance within twice the \
                 rated current",
            ));
        }
        let mut m = Self {
            magnetics,
            psi_dq: Dq::zero(),
            params,
            state: MotorState::default(),
            rot: Complex64::new(1.0, 0.0),
            decay: (0.0, 1.0),
            inverse: Some(Box::default()),
        };
        m.set_state(Dq::zero(), theta0, 0.0);
        Ok(m)
    }

    /// Overrides the state (initial conditions of a scenario).
    pub fn set_state(&mut self, i_dq: Dq<f64>, theta: f64, omega_mech: f64) {
        self.state = MotorState {
            i_dq,
            theta: wrap_angle(theta),
            omega_mech,
            theta_mech: theta / self.params.pole_pairs as f64,
        };
        self.psi_dq = self.flux_of(i_dq);
        self.update_rotation();
    }

    /// ψ(i) of the machine's magnetics.
    fn flux_of(&self, i_dq: Dq<f64>) -> Dq<f64> {
        match &self.magnetics {
            Some((m, _)) => m.model().flux(i_dq),
            None => self.params.flux_dq(i_dq),
        }
    }

    /// The saturating magnetics, if any (None: constant inductances).
    pub fn magnetics(&self) -> Option<&PlantMagnetics> {
        self.magnetics.as_ref().map(|(m, _)| m.as_ref())
    }

    /// The propagator of one sample at the present speed with circuit resistance `r`: the
    /// closed form for constant inductances, the flux integrator for a saturating machine.
    pub fn propagator(&mut self, r: f64) -> ElectricalPropagator {
        match &self.magnetics {
            Some((m, b)) => ElectricalPropagator::saturating(
                FluxPropagator::new(
                    m.clone(),
                    b,
                    r,
                    self.omega(),
                    self.params.pole_pairs,
                    FluxPoint::at(self.state.i_dq, self.psi_dq, self.rot),
                    self.inverse.take().unwrap_or_default(),
                ),
                self.omega(),
            ),
            None => ElectricalPropagator::new(&self.params, r, self.omega()),
        }
    }

    /// Stator flux linkage in the rotor frame, Wb.
    pub fn flux_dq(&self) -> Dq<f64> {
        match self.magnetics {
            Some(_) => self.psi_dq,
            None => self.params.flux_dq(self.state.i_dq),
        }
    }

    fn update_rotation(&mut self) {
        let (s, c) = self.state.theta.sin_cos();
        self.rot = Complex64::new(c, s);
    }

    /// e^{jθ} of the present rotor angle.
    #[inline]
    pub fn rotation(&self) -> Complex64 {
        self.rot
    }

    /// Parameters.
    pub fn params(&self) -> &MotorParams {
        &self.params
    }

    /// True state.
    pub fn state(&self) -> &MotorState {
        &self.state
    }

    /// Electrical speed p·ω_mech in rad/s.
    #[inline]
    pub fn omega(&self) -> f64 {
        self.params.pole_pairs as f64 * self.state.omega_mech
    }

    /// Stator current in the stationary frame.
    #[inline]
    pub fn i_ab(&self) -> Ab<f64> {
        let (c, s) = (self.rot.re, self.rot.im);
        let i = self.state.i_dq;
        Ab::new(i.d * c - i.q * s, i.d * s + i.q * c)
    }

    /// Stator flux linkage in the stationary frame (what the estimator's λ2 should equal).
    pub fn flux_ab(&self) -> Ab<f64> {
        let (c, s) = (self.rot.re, self.rot.im);
        let f = self.flux_dq();
        Ab::new(f.d * c - f.q * s, f.d * s + f.q * c)
    }

    /// Sets the current after an electrical interval (the angle is advanced per sample).
    #[inline]
    pub fn set_current(&mut self, i_dq: Dq<f64>) {
        self.state.i_dq = i_dq;
        if self.magnetics.is_some() {
            self.psi_dq = self.flux_of(i_dq);
        }
    }

    /// Sets the current at the end of a sample advanced by `prop` (built by
    /// [`Motor::propagator`]): a saturating machine takes the flux `prop` integrated (the
    /// state) when `i_dq` is its last interval's end, else ψ(i_dq).
    #[inline]
    pub fn set_current_from(&mut self, prop: &ElectricalPropagator, i_dq: Dq<f64>) {
        self.state.i_dq = i_dq;
        if let Some(f) = &prop.flux {
            if let Some(cache) = f.take_inverse_cache() {
                self.inverse = Some(cache);
            }
            let last = f.last();
            self.psi_dq = if last.i_dq == i_dq {
                unrotate(last.psi_ab, last.rot)
            } else {
                self.flux_of(i_dq)
            };
        }
    }

    /// Closes a sample of length `ts`: the angle advances at the speed held during the sample,
    /// then the speed integrates `(Te − T_L − B·ω)/J` (semi-implicit, exact for the viscous
    /// term), `te_avg` being the interval-weighted torque of the sample.
    pub fn advance_mechanical(&mut self, ts: f64, te_avg: f64, load_torque: f64) {
        let p = self.params.pole_pairs as f64;
        let w = self.state.omega_mech;
        self.state.theta = wrap_angle(self.state.theta + p * w * ts);
        self.state.theta_mech += w * ts;
        self.update_rotation();
        let (j, b) = (self.params.inertia, self.params.viscous_friction);
        let drive = te_avg - load_torque;
        if self.decay.0 != ts {
            self.decay = (ts, (-b * ts / j).exp());
        }
        self.state.omega_mech = if b > 0.0 {
            let decay = self.decay.1;
            w * decay + drive / b * (1.0 - decay)
        } else {
            w + ts * drive / j
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Magnetic energy of the stator inductances, 1.5·(Ld·id² + Lq·iq²)/2, in J.
    fn magnetic_energy(p: &MotorParams, i_dq: Dq<f64>) -> f64 {
        0.75 * (p.ld * i_dq.d * i_dq.d + p.lq * i_dq.q * i_dq.q)
    }

    fn rotor_voltage(v_ab: Ab<f64>, theta: f64) -> Dq<f64> {
        let (s, c) = theta.sin_cos();
        Dq::new(
            v_ab.alpha * c + v_ab.beta * s,
            -v_ab.alpha * s + v_ab.beta * c,
        )
    }

    /// The ODE right-hand side in the rotor frame.
    fn deriv(p: &MotorParams, r: f64, w: f64, i: Dq<f64>, v: Dq<f64>) -> Dq<f64> {
        Dq::new(
            (v.d - r * i.d + w * p.lq * i.q) / p.ld,
            (v.q - r * i.q - w * (p.ld * i.d + p.flux_linkage)) / p.lq,
        )
    }

    fn rk4(
        p: &MotorParams,
        r: f64,
        w: f64,
        i0: Dq<f64>,
        v_ab: Ab<f64>,
        th0: f64,
        h: f64,
    ) -> Dq<f64> {
        let n = (h / 1e-9).ceil() as usize;
        let dt = h / n as f64;
        let mut i = i0;
        for k in 0..n {
            let t = k as f64 * dt;
            let v = |t: f64| rotor_voltage(v_ab, th0 + w * t);
            let k1 = deriv(p, r, w, i, v(t));
            let k2 = deriv(p, r, w, i + k1 * (dt / 2.0), v(t + dt / 2.0));
            let k3 = deriv(p, r, w, i + k2 * (dt / 2.0), v(t + dt / 2.0));
            let k4 = deriv(p, r, w, i + k3 * dt, v(t + dt));
            i += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0);
        }
        i
    }

    fn cexp(x: f64) -> Complex64 {
        Complex64::new(x.cos(), x.sin())
    }

    #[test]
    fn closed_form_matches_fine_rk4_surface_and_interior() {
        let spm = MotorParams::paper();
        let ipm = MotorParams {
            ld: 2.0e-3,
            lq: 5.0e-3,
            ..MotorParams::paper()
        };
        for p in [spm, ipm] {
            for w in [0.0, 37.0, -400.0, 2500.0] {
                let prop = ElectricalPropagator::new(&p, p.rs, w);
                let (i0, v, th0, h) = (Dq::new(1.5, -7.0), Ab::new(120.0, -40.0), 0.9, 37e-6);
                let exact = prop.advance(i0, v, h, cexp(th0), cexp(w * h));
                let reference = rk4(&p, p.rs, w, i0, v, th0, h);
                let err = (exact - reference).norm();
                assert!(err < 1e-10, "ω = {w}, Ld = {}: err = {err:e}", p.ld);
            }
        }
    }

    #[test]
    fn stationary_frame_form_matches_the_rotor_frame_form() {
        let ipm = MotorParams {
            ld: 2.0e-3,
            lq: 5.0e-3,
            ..MotorParams::paper()
        };
        for p in [MotorParams::paper(), ipm] {
            for w in [0.0, -55.0, 900.0] {
                let prop = ElectricalPropagator::new(&p, p.rs + 0.01, w);
                let (th0, h) = (-2.2, 63e-6);
                let rot0 = cexp(th0);
                let i_dq = Dq::new(-3.0, 12.0);
                let i_ab = Ab::new(
                    i_dq.d * rot0.re - i_dq.q * rot0.im,
                    i_dq.d * rot0.im + i_dq.q * rot0.re,
                );
                let v = Ab::new(-80.0, 150.0);
                let a = prop.advance_ab(i_ab, v, h, rot0, cexp(w * h));
                let d = prop.advance(i_dq, v, h, rot0, cexp(w * h));
                let r1 = cexp(th0 + w * h);
                let b = Ab::new(d.d * r1.re - d.q * r1.im, d.d * r1.im + d.q * r1.re);
                assert!(
                    (a - b).norm() < 1e-12,
                    "ω = {w}, Ld = {}: {a:?} vs {b:?}",
                    p.ld
                );
            }
        }
    }

    #[test]
    fn energy_balance_input_equals_copper_loss_plus_stored_plus_mechanical() {
        // p_in = 1.5·v·i = 1.5·R·|i|² + dW/dt + Te·ω_mech, integrated along the exact solution
        // over one interval of constant voltage (Simpson on 2000 points of the closed form).
        let ipm = MotorParams {
            ld: 2.0e-3,
            lq: 5.0e-3,
            ..MotorParams::paper()
        };
        for p in [MotorParams::paper(), ipm] {
            let w = 300.0;
            let r = p.rs;
            let prop = ElectricalPropagator::new(&p, r, w);
            let (i0, v, th0, h) = (Dq::new(2.0, 5.0), Ab::new(60.0, 25.0), -0.3, 2e-3);
            let n = 2000;
            let (mut e_in, mut e_cu, mut e_mech) = (0.0, 0.0, 0.0);
            for k in 0..=n {
                let t = h * k as f64 / n as f64;
                let i = prop.advance(i0, v, t, cexp(th0), cexp(w * t));
                let vdq = rotor_voltage(v, th0 + w * t);
                let wt = if k == 0 || k == n {
                    1.0
                } else if k % 2 == 1 {
                    4.0
                } else {
                    2.0
                } * h
                    / n as f64
                    / 3.0;
                e_in += wt * 1.5 * (vdq.d * i.d + vdq.q * i.q);
                e_cu += wt * 1.5 * r * (i.d * i.d + i.q * i.q);
                e_mech += wt * p.torque(i) * w / p.pole_pairs as f64;
            }
            let i_end = prop.advance(i0, v, h, cexp(th0), cexp(w * h));
            let d_w = magnetic_energy(&p, i_end) - magnetic_energy(&p, i0);
            let balance = e_in - (e_cu + d_w + e_mech);
            assert!(
                balance.abs() < 1e-9 * e_in.abs().max(1e-3),
                "Ld = {}: in {e_in}, cu {e_cu}, ΔW {d_w}, mech {e_mech}, residual {balance:e}",
                p.ld
            );
        }
    }

    #[test]
    fn steady_state_at_speed_has_back_emf_along_q() {
        // With no voltage applied at constant speed, currents settle to −x_c: the short-circuit
        // current of the magnet back-EMF.
        let p = MotorParams::paper();
        let w = 200.0;
        let prop = ElectricalPropagator::new(&p, p.rs, w);
        let mut i = Dq::zero();
        let mut rot = Complex64::new(1.0, 0.0);
        let h = 1e-4;
        for _ in 0..5000 {
            i = prop.advance(i, Ab::zero(), h, rot, cexp(w * h));
            rot *= cexp(w * h);
        }
        // Steady state: 0 = −R·id + ωL·iq, 0 = −R·iq − ωL·id − ωλf.
        let (r, l, lf) = (p.rs, p.ld, p.flux_linkage);
        let den = r * r + (w * l) * (w * l);
        let iq = -w * lf * r / den;
        let id = -w * w * l * lf / den;
        assert!((i.d - id).abs() < 1e-9 && (i.q - iq).abs() < 1e-9, "{i:?}");
    }

    #[test]
    fn mechanics_accelerate_by_torque_over_inertia() {
        let mut m = Motor::new(
            MotorParams {
                viscous_friction: 0.0,
                ..MotorParams::paper()
            },
            0.0,
        )
        .unwrap();
        for _ in 0..10_000 {
            m.advance_mechanical(1e-4, 1.2, 0.0);
        }
        assert!((m.state().omega_mech - 1.2 / 0.012).abs() < 1e-9);
        let bad = MotorParams {
            lq: -1.0,
            ..MotorParams::paper()
        };
        assert_eq!(Motor::new(bad, 0.0).err().unwrap().key, "lq");
    }

    #[test]
    fn a_non_finite_start_angle_is_refused_naming_it() {
        for bad in [f64::NAN, f64::INFINITY] {
            let e = Motor::new(MotorParams::paper(), bad).err().unwrap();
            assert_eq!(e.key, "theta0");
        }
        assert!(Motor::new(MotorParams::paper(), -2.0).is_ok());
    }
}
