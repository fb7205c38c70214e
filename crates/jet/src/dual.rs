//! [`Dual`]: value and one directional derivative.

use super::Scalar;
use std::ops::{Add, Mul, Sub};

/// Value and first derivative along one direction (a dual number): the velocity constraint
/// `Phi_q v` at the cost of about two `f64` evaluations, without the gradient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual {
    /// Value.
    pub v: f64,
    /// Derivative along the seeded direction.
    pub d: f64,
}

impl Dual {
    /// A variable with value `x` and direction component `dir`.
    #[inline(always)]
    pub fn var(x: f64, dir: f64) -> Self {
        Dual { v: x, d: dir }
    }
}

impl Add for Dual {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Dual {
            v: self.v + o.v,
            d: self.d + o.d,
        }
    }
}
impl Sub for Dual {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Dual {
            v: self.v - o.v,
            d: self.d - o.d,
        }
    }
}
impl Mul for Dual {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Dual {
            v: self.v * o.v,
            d: self.d * o.v + self.v * o.d,
        }
    }
}
impl Mul<f64> for Dual {
    type Output = Self;
    #[inline(always)]
    fn mul(self, c: f64) -> Self {
        Dual {
            v: self.v * c,
            d: self.d * c,
        }
    }
}
super::scalar_shift_ops!(Dual);
impl Scalar for Dual {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        Dual { v, d: 0.0 }
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        self.sin_cos_with(s, c)
    }
    #[inline(always)]
    fn sin_cos_with(self, s: f64, c: f64) -> (Self, Self) {
        (
            Dual {
                v: s,
                d: c * self.d,
            },
            Dual {
                v: c,
                d: -s * self.d,
            },
        )
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        Dual {
            v: r,
            d: 0.5 / r * self.d,
        }
    }
}
