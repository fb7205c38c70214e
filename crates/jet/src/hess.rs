//! [`HessJet`]: value, gradient and the full local Hessian.

use super::{Scalar, NV};
use std::ops::{Add, Mul, Sub};

/// Value, gradient and full Hessian with respect to the 6 local variables.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HessJet {
    /// Value.
    pub v: f64,
    /// Gradient.
    pub g: [f64; NV],
    /// Hessian (symmetric).
    pub h: [[f64; NV]; NV],
}

impl HessJet {
    /// Independent variable number `i` with value `x`.
    #[inline(always)]
    pub fn var(i: usize, x: f64) -> Self {
        let mut g = [0.0; NV];
        g[i] = 1.0;
        HessJet {
            v: x,
            g,
            h: [[0.0; NV]; NV],
        }
    }
    #[inline(always)]
    fn chain(self, f: f64, df: f64, ddf: f64) -> Self {
        let mut out = HessJet {
            v: f,
            g: [0.0; NV],
            h: [[0.0; NV]; NV],
        };
        for i in 0..NV {
            out.g[i] = df * self.g[i];
            for j in 0..NV {
                // `g_i * g_j` first so the Hessian stays exactly symmetric in floating point
                out.h[i][j] = ddf * (self.g[i] * self.g[j]) + df * self.h[i][j];
            }
        }
        out
    }
}

impl Add for HessJet {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        for i in 0..NV {
            self.g[i] += o.g[i];
            for j in 0..NV {
                self.h[i][j] += o.h[i][j];
            }
        }
        self
    }
}
impl Sub for HessJet {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        self + o * -1.0
    }
}
impl Mul for HessJet {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let mut out = HessJet {
            v: self.v * o.v,
            g: [0.0; NV],
            h: [[0.0; NV]; NV],
        };
        for i in 0..NV {
            out.g[i] = self.g[i] * o.v + o.g[i] * self.v;
            for j in 0..NV {
                out.h[i][j] = self.h[i][j] * o.v
                    + o.h[i][j] * self.v
                    + self.g[i] * o.g[j]
                    + o.g[i] * self.g[j];
            }
        }
        out
    }
}
impl Mul<f64> for HessJet {
    type Output = Self;
    #[inline(always)]
    fn mul(mut self, c: f64) -> Self {
        self.v *= c;
        for i in 0..NV {
            self.g[i] *= c;
            for j in 0..NV {
                self.h[i][j] *= c;
            }
        }
        self
    }
}
super::scalar_shift_ops!(HessJet);
impl Scalar for HessJet {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        HessJet {
            v,
            g: [0.0; NV],
            h: [[0.0; NV]; NV],
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
