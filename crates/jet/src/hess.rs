//! [`HessJet`]: value, gradient and the full local Hessian.

use super::{Scalar, NV};
use std::ops::{Add, Mul, Sub};

/// Value, gradient and full Hessian with respect to the `N` local variables.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HessJetN<const N: usize> {
    /// Value.
    pub v: f64,
    /// Gradient.
    pub g: [f64; N],
    /// Hessian (symmetric).
    pub h: [[f64; N]; N],
}

/// The planar jet: gradients over the [`NV`] local coordinates of a planar element.
pub type HessJet = HessJetN<NV>;

impl<const N: usize> HessJetN<N> {
    /// Independent variable number `i` with value `x`.
    #[inline(always)]
    pub fn var(i: usize, x: f64) -> Self {
        let mut g = [0.0; N];
        g[i] = 1.0;
        HessJetN {
            v: x,
            g,
            h: [[0.0; N]; N],
        }
    }
    #[inline(always)]
    fn chain(self, f: f64, df: f64, ddf: f64) -> Self {
        let mut out = HessJetN {
            v: f,
            g: [0.0; N],
            h: [[0.0; N]; N],
        };
        for i in 0..N {
            out.g[i] = df * self.g[i];
            for j in 0..N {
                // `g_i * g_j` first so the Hessian stays exactly symmetric in floating point
                out.h[i][j] = ddf * (self.g[i] * self.g[j]) + df * self.h[i][j];
            }
        }
        out
    }
}

impl<const N: usize> Add for HessJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        for i in 0..N {
            self.g[i] += o.g[i];
            for j in 0..N {
                self.h[i][j] += o.h[i][j];
            }
        }
        self
    }
}
impl<const N: usize> Sub for HessJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self + o * -1.0
    }
}
impl<const N: usize> Mul for HessJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let mut out = HessJetN {
            v: self.v * o.v,
            g: [0.0; N],
            h: [[0.0; N]; N],
        };
        for i in 0..N {
            out.g[i] = self.g[i] * o.v + o.g[i] * self.v;
            for j in 0..N {
                out.h[i][j] = self.h[i][j] * o.v
                    + o.h[i][j] * self.v
                    + self.g[i] * o.g[j]
                    + o.g[i] * self.g[j];
            }
        }
        out
    }
}
impl<const N: usize> Mul<f64> for HessJetN<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(mut self, c: f64) -> Self {
        self.v *= c;
        for i in 0..N {
            self.g[i] *= c;
            for j in 0..N {
                self.h[i][j] *= c;
            }
        }
        self
    }
}
super::scalar_shift_ops!(const HessJetN);
impl<const N: usize> Scalar for HessJetN<N> {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        HessJetN {
            v,
            g: [0.0; N],
            h: [[0.0; N]; N],
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
