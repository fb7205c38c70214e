//! [`ThirdJet`]: value, gradient and the first two derivatives along one direction `w`, each
//! with its gradient, so `H w` and the third-derivative contraction `D^3 f(w, w, .)` come
//! exactly out of one forward evaluation (a second-order Taylor polynomial along `w` whose
//! coefficients carry gradients).

use super::{Scalar, NV};
use std::ops::{Add, Mul, Sub};

/// Value `f`, gradient, `d1 = f' w`, `g1 = grad d1 = H w`, `d2 = w^T H w` and
/// `g2 = grad d2 = D^3 f(w, w, .)`, with respect to the `N` local variables.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThirdJetN<const N: usize> {
    /// Value.
    pub v: f64,
    /// Gradient.
    pub g: [f64; N],
    /// First derivative along the seeded direction (`g . w`).
    pub d1: f64,
    /// Gradient of `d1` (`H w`).
    pub g1: [f64; N],
    /// Second derivative along the seeded direction (`w^T H w`).
    pub d2: f64,
    /// Gradient of `d2` (`D^3 f(w, w, .)`).
    pub g2: [f64; N],
}

/// The planar jet: gradients over the [`NV`] local coordinates of a planar element.
pub type ThirdJet = ThirdJetN<NV>;

impl<const N: usize> ThirdJetN<N> {
    /// Independent variable number `i` with value `x` and direction component `w`.
    #[inline(always)]
    pub fn var(i: usize, x: f64, w: f64) -> Self {
        let mut j = Self::cst(x);
        j.g[i] = 1.0;
        j.d1 = w;
        j
    }
    /// `f(self)` from `f` and its first three derivatives at the value.
    #[inline(always)]
    fn chain(self, f: [f64; 4]) -> Self {
        let [f0, f1, f2, f3] = f;
        let (d1, d2) = (self.d1, self.d2);
        let mut out = ThirdJetN {
            v: f0,
            g: [0.0; N],
            d1: f1 * d1,
            g1: [0.0; N],
            d2: f2 * d1 * d1 + f1 * d2,
            g2: [0.0; N],
        };
        let c1 = f2 * d1;
        let c2 = f3 * d1 * d1 + f2 * d2;
        let c3 = 2.0 * f2 * d1;
        for i in 0..N {
            out.g[i] = f1 * self.g[i];
            out.g1[i] = c1 * self.g[i] + f1 * self.g1[i];
            out.g2[i] = c2 * self.g[i] + c3 * self.g1[i] + f1 * self.g2[i];
        }
        out
    }
}

impl<const N: usize> Add for ThirdJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        self.d1 += o.d1;
        self.d2 += o.d2;
        for i in 0..N {
            self.g[i] += o.g[i];
            self.g1[i] += o.g1[i];
            self.g2[i] += o.g2[i];
        }
        self
    }
}
impl<const N: usize> Sub for ThirdJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, o: Self) -> Self {
        self.v -= o.v;
        self.d1 -= o.d1;
        self.d2 -= o.d2;
        for i in 0..N {
            self.g[i] -= o.g[i];
            self.g1[i] -= o.g1[i];
            self.g2[i] -= o.g2[i];
        }
        self
    }
}
impl<const N: usize> Mul for ThirdJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let (a, b) = (self, o);
        let mut out = ThirdJetN {
            v: a.v * b.v,
            g: [0.0; N],
            d1: a.d1 * b.v + a.v * b.d1,
            g1: [0.0; N],
            d2: a.d2 * b.v + 2.0 * a.d1 * b.d1 + a.v * b.d2,
            g2: [0.0; N],
        };
        for i in 0..N {
            out.g[i] = a.g[i] * b.v + a.v * b.g[i];
            out.g1[i] = a.g1[i] * b.v + a.d1 * b.g[i] + a.g[i] * b.d1 + a.v * b.g1[i];
            out.g2[i] = a.g2[i] * b.v
                + a.d2 * b.g[i]
                + 2.0 * (a.g1[i] * b.d1 + a.d1 * b.g1[i])
                + a.g[i] * b.d2
                + a.v * b.g2[i];
        }
        out
    }
}
impl<const N: usize> Mul<f64> for ThirdJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(mut self, c: f64) -> Self {
        self.v *= c;
        self.d1 *= c;
        self.d2 *= c;
        for i in 0..N {
            self.g[i] *= c;
            self.g1[i] *= c;
            self.g2[i] *= c;
        }
        self
    }
}
super::scalar_shift_ops!(const ThirdJetN);
impl<const N: usize> Scalar for ThirdJetN<N> {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        ThirdJetN {
            v,
            g: [0.0; N],
            d1: 0.0,
            g1: [0.0; N],
            d2: 0.0,
            g2: [0.0; N],
        }
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        self.sin_cos_with(s, c)
    }
    #[inline(always)]
    fn sin_cos_with(self, s: f64, c: f64) -> (Self, Self) {
        (self.chain([s, c, -s, -c]), self.chain([c, -s, -c, s]))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        let x = self.v;
        self.chain([r, 0.5 / r, -0.25 / (r * x), 0.375 / (r * x * x)])
    }
}
