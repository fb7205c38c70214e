//! Forward-mode differentiation for joint and force equations.
//!
//! Every joint and force element is written once, generically over [`Scalar`], as a function of
//! the six absolute coordinates of the (at most two) bodies it connects. Evaluating it with
//!
//! * `f64` gives the value,
//! * [`DirJet`] gives the value, the gradient and the first and second derivatives along a chosen
//!   direction `v` (so `v^T H v` — the quadratic velocity term of the acceleration right-hand side
//!   `gamma` — without forming the Hessian),
//! * [`HessJet`] gives the value, the gradient and the full 6x6 Hessian,
//! * [`TanJet`] gives the value, the gradient, the derivative along a direction `w` and the
//!   gradient of that derivative (`H w`: the Jacobian `(Phi_q w)_q` of the velocity
//!   constraint) without forming the Hessian,
//! * [`Dual`] gives the value and the first derivative along one direction only (the cheapest
//!   way to the velocity constraint `Phi_q v`),
//!
//! so the Jacobian, `gamma` and the Hessians are exact (to round-off) and consistent with the
//! equation by construction. Finite-difference tests check them all.

use std::ops::{Add, Mul, Neg, Sub};

/// Number of local variables of one element: `(x, y, theta)` of body a, then of body b.
pub const NV: usize = 6;

/// The arithmetic an element equation needs.
pub trait Scalar:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
{
    /// A constant (zero derivatives).
    fn cst(v: f64) -> Self;
    /// `(sin x, cos x)`.
    fn sin_cos(self) -> (Self, Self);
    /// Square root (the caller keeps the argument positive).
    fn sqrt(self) -> Self;
}

impl Scalar for f64 {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        f64::sin_cos(self)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
}

/// Value, gradient (6 local variables) and first/second derivative along one direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirJet {
    /// Value.
    pub v: f64,
    /// Gradient with respect to the 6 local variables.
    pub g: [f64; NV],
    /// First derivative along the seeded direction (`g . dir`).
    pub d1: f64,
    /// Second derivative along the seeded direction (`dir^T H dir`).
    pub d2: f64,
}

impl DirJet {
    /// Independent variable number `i` with value `x` and direction component `dir`.
    #[inline(always)]
    pub fn var(i: usize, x: f64, dir: f64) -> Self {
        let mut g = [0.0; NV];
        g[i] = 1.0;
        DirJet {
            v: x,
            g,
            d1: dir,
            d2: 0.0,
        }
    }
    #[inline(always)]
    fn chain(self, f: f64, df: f64, ddf: f64) -> Self {
        let mut g = [0.0; NV];
        for k in 0..NV {
            g[k] = df * self.g[k];
        }
        DirJet {
            v: f,
            g,
            d1: df * self.d1,
            d2: ddf * self.d1 * self.d1 + df * self.d2,
        }
    }
}

impl Add for DirJet {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        let mut g = self.g;
        for k in 0..NV {
            g[k] += o.g[k];
        }
        DirJet {
            v: self.v + o.v,
            g,
            d1: self.d1 + o.d1,
            d2: self.d2 + o.d2,
        }
    }
}
impl Sub for DirJet {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        let mut g = self.g;
        for k in 0..NV {
            g[k] -= o.g[k];
        }
        DirJet {
            v: self.v - o.v,
            g,
            d1: self.d1 - o.d1,
            d2: self.d2 - o.d2,
        }
    }
}
impl Mul for DirJet {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let mut g = [0.0; NV];
        for k in 0..NV {
            g[k] = self.g[k] * o.v + o.g[k] * self.v;
        }
        DirJet {
            v: self.v * o.v,
            g,
            d1: self.d1 * o.v + self.v * o.d1,
            d2: self.d2 * o.v + 2.0 * self.d1 * o.d1 + self.v * o.d2,
        }
    }
}
impl Neg for DirJet {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self * -1.0
    }
}
impl Add<f64> for DirJet {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, c: f64) -> Self {
        self.v += c;
        self
    }
}
impl Sub<f64> for DirJet {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, c: f64) -> Self {
        self.v -= c;
        self
    }
}
impl Mul<f64> for DirJet {
    type Output = Self;
    #[inline(always)]
    fn mul(self, c: f64) -> Self {
        let mut g = self.g;
        for x in g.iter_mut() {
            *x *= c;
        }
        DirJet {
            v: self.v * c,
            g,
            d1: self.d1 * c,
            d2: self.d2 * c,
        }
    }
}
impl Scalar for DirJet {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        DirJet {
            v,
            g: [0.0; NV],
            d1: 0.0,
            d2: 0.0,
        }
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        (self.chain(s, c, -s), self.chain(c, -s, -c))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        self.chain(r, 0.5 / r, -0.25 / (r * self.v))
    }
}

/// Value, gradient, derivative along a direction `w` and the gradient of that derivative, with
/// respect to the 6 local variables: `H w` (for the velocity constraint's Jacobian
/// `(Phi_q w)_q`) at about a fifth of the cost of a [`HessJet`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TanJet {
    /// Value.
    pub v: f64,
    /// Gradient.
    pub g: [f64; NV],
    /// Derivative along the seeded direction (`g . w`).
    pub d: f64,
    /// Gradient of `d` (`H w`).
    pub dg: [f64; NV],
}

impl TanJet {
    /// Independent variable number `i` with value `x` and direction component `w`.
    #[inline(always)]
    pub fn var(i: usize, x: f64, w: f64) -> Self {
        let mut g = [0.0; NV];
        g[i] = 1.0;
        TanJet {
            v: x,
            g,
            d: w,
            dg: [0.0; NV],
        }
    }
    /// `f(self)` from `f`, `f'` and `f''` at the value: `d f = f' d`,
    /// `grad(f' d) = f'' d grad + f' grad d`.
    #[inline(always)]
    fn chain(self, f: f64, df: f64, ddf: f64) -> Self {
        let mut out = TanJet {
            v: f,
            g: [0.0; NV],
            d: df * self.d,
            dg: [0.0; NV],
        };
        let c = ddf * self.d;
        for i in 0..NV {
            out.g[i] = df * self.g[i];
            out.dg[i] = c * self.g[i] + df * self.dg[i];
        }
        out
    }
}

impl Add for TanJet {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        self.d += o.d;
        for i in 0..NV {
            self.g[i] += o.g[i];
            self.dg[i] += o.dg[i];
        }
        self
    }
}
impl Sub for TanJet {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, o: Self) -> Self {
        self.v -= o.v;
        self.d -= o.d;
        for i in 0..NV {
            self.g[i] -= o.g[i];
            self.dg[i] -= o.dg[i];
        }
        self
    }
}
impl Mul for TanJet {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let mut out = TanJet {
            v: self.v * o.v,
            g: [0.0; NV],
            d: self.d * o.v + self.v * o.d,
            dg: [0.0; NV],
        };
        for i in 0..NV {
            out.g[i] = self.g[i] * o.v + self.v * o.g[i];
            out.dg[i] = self.dg[i] * o.v + self.d * o.g[i] + self.g[i] * o.d + self.v * o.dg[i];
        }
        out
    }
}
impl Neg for TanJet {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self * -1.0
    }
}
impl Add<f64> for TanJet {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, c: f64) -> Self {
        self.v += c;
        self
    }
}
impl Sub<f64> for TanJet {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, c: f64) -> Self {
        self.v -= c;
        self
    }
}
impl Mul<f64> for TanJet {
    type Output = Self;
    #[inline(always)]
    fn mul(mut self, c: f64) -> Self {
        self.v *= c;
        self.d *= c;
        for i in 0..NV {
            self.g[i] *= c;
            self.dg[i] *= c;
        }
        self
    }
}
impl Scalar for TanJet {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        TanJet {
            v,
            g: [0.0; NV],
            d: 0.0,
            dg: [0.0; NV],
        }
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        (self.chain(s, c, -s), self.chain(c, -s, -c))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        self.chain(r, 0.5 / r, -0.25 / (r * self.v))
    }
}

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
impl Neg for HessJet {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self * -1.0
    }
}
impl Add<f64> for HessJet {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, c: f64) -> Self {
        self.v += c;
        self
    }
}
impl Sub<f64> for HessJet {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, c: f64) -> Self {
        self.v -= c;
        self
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
        (self.chain(s, c, -s), self.chain(c, -s, -c))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        self.chain(r, 0.5 / r, -0.25 / (r * self.v))
    }
}

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
impl Neg for Dual {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Dual {
            v: -self.v,
            d: -self.d,
        }
    }
}
impl Add<f64> for Dual {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, c: f64) -> Self {
        self.v += c;
        self
    }
}
impl Sub<f64> for Dual {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, c: f64) -> Self {
        self.v -= c;
        self
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
impl Scalar for Dual {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        Dual { v, d: 0.0 }
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
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

/// A body's coordinates `(x, y, theta)` with `cos theta` and `sin theta` evaluated once, so the
/// points and directions of one element share them (and ground costs no trigonometry).
#[derive(Clone, Copy, Debug)]
pub struct Frame<T> {
    /// `(x, y, theta)`.
    pub q: [T; 3],
    /// `cos theta`.
    pub c: T,
    /// `sin theta`.
    pub s: T,
}

impl<T: Scalar> Frame<T> {
    /// A moving frame.
    #[inline(always)]
    pub fn new(q: [T; 3]) -> Self {
        let (s, c) = q[2].sin_cos();
        Frame { q, c, s }
    }
    /// The ground frame (identity, constant).
    #[inline(always)]
    pub fn fixed() -> Self {
        Frame {
            q: [T::cst(0.0); 3],
            c: T::cst(1.0),
            s: T::cst(0.0),
        }
    }
}

impl<T> std::ops::Index<usize> for Frame<T> {
    type Output = T;
    #[inline(always)]
    fn index(&self, i: usize) -> &T {
        &self.q[i]
    }
}

/// A point fixed in a body frame, in global coordinates: `r + A(theta) s`.
#[inline(always)]
pub fn point<T: Scalar>(f: &Frame<T>, s: [f64; 2]) -> [T; 2] {
    [
        f.q[0] + f.c * s[0] - f.s * s[1],
        f.q[1] + f.s * s[0] + f.c * s[1],
    ]
}

/// A direction fixed in a body frame, in global coordinates: `A(theta) u`.
#[inline(always)]
pub fn direction<T: Scalar>(f: &Frame<T>, u: [f64; 2]) -> [T; 2] {
    [f.c * u[0] - f.s * u[1], f.s * u[0] + f.c * u[1]]
}

/// Dot product of two planar vectors.
#[inline(always)]
pub fn dot<T: Scalar>(a: [T; 2], b: [T; 2]) -> T {
    a[0] * b[0] + a[1] * b[1]
}

/// `b - a` for planar vectors.
#[inline(always)]
pub fn sub2<T: Scalar>(b: [T; 2], a: [T; 2]) -> [T; 2] {
    [b[0] - a[0], b[1] - a[1]]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f<T: Scalar>(x: [T; 6]) -> T {
        let p = point(&Frame::new([x[0], x[1], x[2]]), [0.3, -0.2]);
        let q = point(&Frame::new([x[3], x[4], x[5]]), [-0.1, 0.4]);
        let d = sub2(q, p);
        dot(d, d).sqrt() * x[2] + x[0] * x[4]
    }

    #[test]
    fn jets_match_finite_differences() {
        let x0 = [0.1, -0.3, 0.7, 1.2, 0.4, -0.5];
        let dir = [0.3, -0.1, 0.9, 0.2, -0.6, 0.5];
        let dj: [DirJet; 6] = std::array::from_fn(|i| DirJet::var(i, x0[i], dir[i]));
        let hj: [HessJet; 6] = std::array::from_fn(|i| HessJet::var(i, x0[i]));
        let d = f(dj);
        let h = f(hj);
        let e = 1e-5;
        for i in 0..6 {
            let mut xp = x0;
            let mut xm = x0;
            xp[i] += e;
            xm[i] -= e;
            let fd = (f(xp) - f(xm)) / (2.0 * e);
            assert!((fd - d.g[i]).abs() < 1e-8, "grad {i}");
            assert!((fd - h.g[i]).abs() < 1e-8, "grad {i}");
            let gp = f(std::array::from_fn(|k| HessJet::var(k, xp[k]))).g;
            let gm = f(std::array::from_fn(|k| HessJet::var(k, xm[k]))).g;
            for j in 0..6 {
                let fd2 = (gp[j] - gm[j]) / (2.0 * e);
                assert!((fd2 - h.h[i][j]).abs() < 1e-7, "hess {i} {j}");
            }
        }
        let mut vhv = 0.0;
        for i in 0..6 {
            for j in 0..6 {
                vhv += dir[i] * h.h[i][j] * dir[j];
            }
        }
        assert!((vhv - d.d2).abs() < 1e-12);
        let gd: f64 = (0..6).map(|i| d.g[i] * dir[i]).sum();
        assert!((gd - d.d1).abs() < 1e-14);
        // TanJet: H w and the directional derivative, against the HessJet
        let tj = f(std::array::from_fn(|i| TanJet::var(i, x0[i], dir[i])));
        assert!((tj.v - h.v).abs() < 1e-15);
        assert!((tj.d - d.d1).abs() < 1e-14);
        for i in 0..6 {
            assert!((tj.g[i] - h.g[i]).abs() < 1e-14, "TanJet grad {i}");
            let hw: f64 = (0..6).map(|j| h.h[i][j] * dir[j]).sum();
            assert!((tj.dg[i] - hw).abs() < 1e-13, "TanJet H w {i}");
        }
        let du = f(std::array::from_fn(|i| Dual::var(x0[i], dir[i])));
        assert!((du.v - d.v).abs() < 1e-15);
        assert!((du.d - d.d1).abs() < 1e-14);
    }
}
