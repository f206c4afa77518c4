//! Reference frames as small typed values: phase (a-b-c), stationary α-β and rotor d-q.
//!
//! The Clarke transform is amplitude-invariant (a phase current of peak I gives |i_ab| = I),
//! the convention of the paper's eq. (1)-(6). An α-β vector doubles as the complex number
//! `alpha + j·beta` where the observer maths is written in complex form (docs/method/estimator.md §2).

use core::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

use crate::Real;

/// A vector in the stationary α-β frame (paper eq. (1)), or the complex number α + jβ.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Ab<T> {
    /// α component (aligned with phase a).
    pub alpha: T,
    /// β component (90° ahead of α).
    pub beta: T,
}

/// A vector in the rotor d-q frame (paper eq. (2)); d is along the magnet flux.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dq<T> {
    /// d (direct) component, along the rotor flux.
    pub d: T,
    /// q (quadrature) component, 90° ahead of d.
    pub q: T,
}

/// Three phase quantities a, b, c.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Abc<T> {
    /// Phase a.
    pub a: T,
    /// Phase b.
    pub b: T,
    /// Phase c.
    pub c: T,
}

/// A rotation by an angle θ, kept as its unit vector (cos θ, sin θ) so that one `sin_cos`
/// serves every Park transform of a sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rotation<T> {
    /// cos θ.
    pub cos: T,
    /// sin θ.
    pub sin: T,
}

impl<T: Real> Rotation<T> {
    /// The rotation by `angle` (rad). `f64` uses `libm`; `f32` uses
    /// [`crate::approx::sin_cos_any`] (error below 2.5e-7; `libm`'s `f32` kernels run in
    /// `f64`, software on a single-precision FPU).
    #[inline]
    pub fn from_angle(angle: T) -> Self {
        let (sin, cos) = angle.step_sin_cos_any();
        Self { cos, sin }
    }

    /// The unit vector of this rotation as an α-β vector.
    #[inline]
    pub fn unit(self) -> Ab<T> {
        Ab::new(self.cos, self.sin)
    }
}

impl<T: Real> Ab<T> {
    /// A vector from its components.
    #[inline]
    pub const fn new(alpha: T, beta: T) -> Self {
        Self { alpha, beta }
    }

    /// The zero vector.
    #[inline]
    pub fn zero() -> Self {
        Self::new(T::zero(), T::zero())
    }

    /// `magnitude · (cos angle, sin angle)`.
    #[inline]
    pub fn from_polar(magnitude: T, angle: T) -> Self {
        Rotation::from_angle(angle).unit() * magnitude
    }

    /// Squared magnitude.
    #[inline]
    pub fn norm_squared(self) -> T {
        self.alpha * self.alpha + self.beta * self.beta
    }

    /// Magnitude.
    #[inline]
    pub fn norm(self) -> T {
        self.norm_squared().step_sqrt()
    }

    /// Angle `atan2(β, α)` in (−π, π].
    #[inline]
    pub fn angle(self) -> T {
        self.beta.atan2(self.alpha)
    }

    /// True when both components are finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.alpha.is_finite() && self.beta.is_finite()
    }

    /// Complex product (α₁ + jβ₁)(α₂ + jβ₂).
    #[inline]
    pub fn complex_mul(self, other: Self) -> Self {
        Self::new(
            self.alpha * other.alpha - self.beta * other.beta,
            self.alpha * other.beta + self.beta * other.alpha,
        )
    }

    /// Scalar product α₁α₂ + β₁β₂: the component of `other` along `self` when `self` is a unit
    /// vector (e.g. i_d for the unit flux vector).
    #[inline]
    pub fn dot(self, other: Self) -> T {
        self.alpha * other.alpha + self.beta * other.beta
    }

    /// Cross product α₁β₂ − β₁α₂: the component of `other` along j·`self` (e.g. i_q for the
    /// unit flux vector).
    #[inline]
    pub fn cross(self, other: Self) -> T {
        self.alpha * other.beta - self.beta * other.alpha
    }

    /// Multiplication by j (rotation by +90°).
    #[inline]
    pub fn mul_j(self) -> Self {
        Self::new(-self.beta, self.alpha)
    }

    /// Park transform into a frame rotated by `rot` (α-β → d-q).
    #[inline]
    pub fn to_dq(self, rot: Rotation<T>) -> Dq<T> {
        Dq {
            d: self.alpha * rot.cos + self.beta * rot.sin,
            q: -self.alpha * rot.sin + self.beta * rot.cos,
        }
    }

    /// Inverse Clarke transform (amplitude-invariant, zero sequence = 0).
    #[inline]
    pub fn to_abc(self) -> Abc<T> {
        let half = T::lit(0.5);
        let k = T::lit(0.866_025_403_784_438_6); // √3/2
        Abc {
            a: self.alpha,
            b: -half * self.alpha + k * self.beta,
            c: -half * self.alpha - k * self.beta,
        }
    }
}

impl<T: Real> Dq<T> {
    /// A vector from its components.
    #[inline]
    pub const fn new(d: T, q: T) -> Self {
        Self { d, q }
    }

    /// The zero vector.
    #[inline]
    pub fn zero() -> Self {
        Self::new(T::zero(), T::zero())
    }

    /// Magnitude.
    #[inline]
    pub fn norm(self) -> T {
        (self.d * self.d + self.q * self.q).step_sqrt()
    }

    /// True when both components are finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.d.is_finite() && self.q.is_finite()
    }

    /// Inverse Park transform out of a frame rotated by `rot` (d-q → α-β).
    #[inline]
    pub fn to_ab(self, rot: Rotation<T>) -> Ab<T> {
        Ab {
            alpha: self.d * rot.cos - self.q * rot.sin,
            beta: self.d * rot.sin + self.q * rot.cos,
        }
    }
}

impl<T: Real> Abc<T> {
    /// Phase quantities from their values.
    #[inline]
    pub const fn new(a: T, b: T, c: T) -> Self {
        Self { a, b, c }
    }

    /// Amplitude-invariant Clarke transform; the zero-sequence part is discarded.
    #[inline]
    pub fn to_ab(self) -> Ab<T> {
        let third = T::lit(1.0 / 3.0);
        let inv_sqrt3 = T::lit(0.577_350_269_189_625_8);
        Ab {
            alpha: third * (self.a + self.a - self.b - self.c),
            beta: inv_sqrt3 * (self.b - self.c),
        }
    }

    /// True when all three components are finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.a.is_finite() && self.b.is_finite() && self.c.is_finite()
    }
}

macro_rules! vector_ops {
    ($ty:ident { $($f:ident),+ }) => {
        impl<T: Real> Add for $ty<T> {
            type Output = Self;
            #[inline]
            fn add(self, o: Self) -> Self { Self { $($f: self.$f + o.$f),+ } }
        }
        impl<T: Real> Sub for $ty<T> {
            type Output = Self;
            #[inline]
            fn sub(self, o: Self) -> Self { Self { $($f: self.$f - o.$f),+ } }
        }
        impl<T: Real> Neg for $ty<T> {
            type Output = Self;
            #[inline]
            fn neg(self) -> Self { Self { $($f: -self.$f),+ } }
        }
        impl<T: Real> Mul<T> for $ty<T> {
            type Output = Self;
            #[inline]
            fn mul(self, k: T) -> Self { Self { $($f: self.$f * k),+ } }
        }
        impl<T: Real> AddAssign for $ty<T> {
            #[inline]
            fn add_assign(&mut self, o: Self) { $(self.$f += o.$f;)+ }
        }
        impl<T: Real> SubAssign for $ty<T> {
            #[inline]
            fn sub_assign(&mut self, o: Self) { $(self.$f -= o.$f;)+ }
        }
    };
}

vector_ops!(Ab { alpha, beta });
vector_ops!(Dq { d, q });
vector_ops!(Abc { a, b, c });

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clarke_of_balanced_set_has_phase_amplitude() {
        let th = 0.7_f64;
        let two_thirds_pi = 2.0 * core::f64::consts::PI / 3.0;
        let abc = Abc::new(
            2.0 * th.cos(),
            2.0 * (th - two_thirds_pi).cos(),
            2.0 * (th + two_thirds_pi).cos(),
        );
        let ab = abc.to_ab();
        assert!((ab.norm() - 2.0).abs() < 1e-12);
        assert!((ab.angle() - th).abs() < 1e-12);
        let back = ab.to_abc();
        assert!((back.a - abc.a).abs() < 1e-12 && (back.c - abc.c).abs() < 1e-12);
    }

    #[test]
    fn park_round_trip_and_alignment() {
        let rot = Rotation::from_angle(1.1_f64);
        let x = Ab::from_polar(3.0, 1.1);
        let dq = x.to_dq(rot);
        assert!((dq.d - 3.0).abs() < 1e-12 && dq.q.abs() < 1e-12);
        let y = Dq::new(0.3, -2.0).to_ab(rot).to_dq(rot);
        assert!((y.d - 0.3).abs() < 1e-12 && (y.q + 2.0).abs() < 1e-12);
    }
}
