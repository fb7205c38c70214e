//! [`TanJet`]: value, gradient, one directional derivative and its gradient.

use super::{Scalar, NV};
use std::ops::{Add, Mul, Sub};

/// Value, gradient, derivative along a direction `w` and the gradient of that derivative, with
/// respect to the `N` local variables: `H w` (for the velocity constraint's Jacobian
/// `(Phi_q w)_q`) at about a fifth of the cost of a [`HessJet`](crate::HessJet).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TanJetN<const N: usize> {
    /// Value.
    pub v: f64,
    /// Gradient.
    pub g: [f64; N],
    /// Derivative along the seeded direction (`g . w`).
    pub d: f64,
    /// Gradient of `d` (`H w`).
    pub dg: [f64; N],
}

/// The planar jet: gradients over the [`NV`] local coordinates of a planar element.
pub type TanJet = TanJetN<NV>;

impl<const N: usize> TanJetN<N> {
    /// Independent variable number `i` with value `x` and direction component `w`.
    #[inline(always)]
    pub fn var(i: usize, x: f64, w: f64) -> Self {
        let mut g = [0.0; N];
        g[i] = 1.0;
        TanJetN {
            v: x,
            g,
            d: w,
            dg: [0.0; N],
        }
    }
    /// `f(self)` from `f`, `f'` and `f''` at the value: `d f = f' d`,
    /// `grad(f' d) = f'' d grad + f' grad d`.
    #[inline(always)]
    fn chain(self, f: f64, df: f64, ddf: f64) -> Self {
        let mut out = TanJetN {
            v: f,
            g: [0.0; N],
            d: df * self.d,
            dg: [0.0; N],
        };
        let c = ddf * self.d;
        for i in 0..N {
            out.g[i] = df * self.g[i];
            out.dg[i] = c * self.g[i] + df * self.dg[i];
        }
        out
    }
}

impl<const N: usize> Add for TanJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        self.d += o.d;
        for i in 0..N {
            self.g[i] += o.g[i];
            self.dg[i] += o.dg[i];
        }
        self
    }
}
impl<const N: usize> Sub for TanJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, o: Self) -> Self {
        self.v -= o.v;
        self.d -= o.d;
        for i in 0..N {
            self.g[i] -= o.g[i];
            self.dg[i] -= o.dg[i];
        }
        self
    }
}
impl<const N: usize> Mul for TanJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let mut out = TanJetN {
            v: self.v * o.v,
            g: [0.0; N],
            d: self.d * o.v + self.v * o.d,
            dg: [0.0; N],
        };
        for i in 0..N {
            out.g[i] = self.g[i] * o.v + self.v * o.g[i];
            out.dg[i] = self.dg[i] * o.v + self.d * o.g[i] + self.g[i] * o.d + self.v * o.dg[i];
        }
        out
    }
}
impl<const N: usize> Mul<f64> for TanJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(mut self, c: f64) -> Self {
        self.v *= c;
        self.d *= c;
        for i in 0..N {
            self.g[i] *= c;
            self.dg[i] *= c;
        }
        self
    }
}
super::scalar_shift_ops!(const TanJetN);
impl<const N: usize> Scalar for TanJetN<N> {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        TanJetN {
            v,
            g: [0.0; N],
            d: 0.0,
            dg: [0.0; N],
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
