//! [`DirJet`]: value, gradient and two derivatives along one direction.

use super::{Scalar, NV};
use std::ops::{Add, Mul, Sub};

/// Value, gradient (`N` local variables) and first/second derivative along one direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirJetN<const N: usize> {
    /// Value.
    pub v: f64,
    /// Gradient with respect to the `N` local variables.
    pub g: [f64; N],
    /// First derivative along the seeded direction (`g . dir`).
    pub d1: f64,
    /// Second derivative along the seeded direction (`dir^T H dir`).
    pub d2: f64,
}

/// The planar jet: gradients over the [`NV`] local coordinates of a planar element.
pub type DirJet = DirJetN<NV>;

impl<const N: usize> DirJetN<N> {
    /// Independent variable number `i` with value `x` and direction component `dir`.
    #[inline(always)]
    pub fn var(i: usize, x: f64, dir: f64) -> Self {
        let mut g = [0.0; N];
        g[i] = 1.0;
        DirJetN {
            v: x,
            g,
            d1: dir,
            d2: 0.0,
        }
    }
    #[inline(always)]
    fn chain(self, f: f64, df: f64, ddf: f64) -> Self {
        let mut g = [0.0; N];
        for k in 0..N {
            g[k] = df * self.g[k];
        }
        DirJetN {
            v: f,
            g,
            d1: df * self.d1,
            d2: ddf * self.d1 * self.d1 + df * self.d2,
        }
    }
}

impl<const N: usize> Add for DirJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        let mut g = self.g;
        for k in 0..N {
            g[k] += o.g[k];
        }
        DirJetN {
            v: self.v + o.v,
            g,
            d1: self.d1 + o.d1,
            d2: self.d2 + o.d2,
        }
    }
}
impl<const N: usize> Sub for DirJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        let mut g = self.g;
        for k in 0..N {
            g[k] -= o.g[k];
        }
        DirJetN {
            v: self.v - o.v,
            g,
            d1: self.d1 - o.d1,
            d2: self.d2 - o.d2,
        }
    }
}
impl<const N: usize> Mul for DirJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let mut g = [0.0; N];
        for k in 0..N {
            g[k] = self.g[k] * o.v + o.g[k] * self.v;
        }
        DirJetN {
            v: self.v * o.v,
            g,
            d1: self.d1 * o.v + self.v * o.d1,
            d2: self.d2 * o.v + 2.0 * self.d1 * o.d1 + self.v * o.d2,
        }
    }
}
impl<const N: usize> Mul<f64> for DirJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, c: f64) -> Self {
        let mut g = self.g;
        for x in g.iter_mut() {
            *x *= c;
        }
        DirJetN {
            v: self.v * c,
            g,
            d1: self.d1 * c,
            d2: self.d2 * c,
        }
    }
}
super::scalar_shift_ops!(const DirJetN);
impl<const N: usize> Scalar for DirJetN<N> {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        DirJetN {
            v,
            g: [0.0; N],
            d1: 0.0,
            d2: 0.0,
        }
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        self.sin_cos_with(s, c)
    }
    #[inline(always)]
    fn sin_cos_with(self, s: f64, c: f64) -> (Self, Self) {
        (self.chain(s, c, -s), self.chain(c, -s, -c))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        self.chain(r, 0.5 / r, -0.25 / (r * self.v))
    }
}
