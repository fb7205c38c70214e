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
//! * [`ThirdJet`] gives, besides the gradient, `H w`, `w^T H w` and the third-derivative
//!   contraction `D^3 f(w, w, .)` along a direction `w` (for the gradients of preadjustment
//!   terms that contain Hessians),
//! * [`Taylor4`] gives the Taylor series of `t -> f(q + t w)` to degree 4 (the directional
//!   derivatives `D^k f(w, ..., w)`, `k <= 4`, without gradients),
//! * [`PolyJet`] gives the truncated Taylor polynomial of `f(q + sum_j x_j w_j)` in several
//!   directions at once, restricted to a fixed set of monomials, with the gradient of every
//!   coefficient with respect to the base point (the mixed directional derivatives
//!   `D^k f(w_1, ..., w_k)` and their gradients with respect to `q` and to every direction, in
//!   one pass),
//!
//! so the Jacobian, `gamma`, the Hessians and the third derivatives are exact (to round-off) and consistent with the
//! equation by construction. Finite-difference tests check them all.

use std::ops::{Add, Mul, Neg, Sub};

/// `-x` (as `x * -1.0`, bit-identical to negating every component), `x + c` and `x - c` (the
/// value shifts, the derivatives do not) for a jet type with a `v` field and `Mul<f64>`.
macro_rules! scalar_shift_ops {
    ($t:ty) => {
        impl std::ops::Neg for $t {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                self * -1.0
            }
        }
        impl std::ops::Add<f64> for $t {
            type Output = Self;
            #[inline(always)]
            fn add(mut self, c: f64) -> Self {
                self.v += c;
                self
            }
        }
        impl std::ops::Sub<f64> for $t {
            type Output = Self;
            #[inline(always)]
            fn sub(mut self, c: f64) -> Self {
                self.v -= c;
                self
            }
        }
    };
}
use scalar_shift_ops;

mod dir;
mod dual;
mod hess;
mod poly;
mod tan;
mod taylor;
mod third;

pub use dir::DirJet;
pub use dual::Dual;
pub use hess::HessJet;
pub use poly::{Basis, PolyJet, MAX_DIRS};
pub use tan::TanJet;
pub use taylor::Taylor4;
pub use third::ThirdJet;

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
    /// `(sin x, cos x)` given `s = sin` and `c = cos` of the value of `x` (evaluated once and
    /// shared by several jets at the same point): bit for bit [`Scalar::sin_cos`] when `(s, c)`
    /// is `value.sin_cos()`.
    fn sin_cos_with(self, s: f64, c: f64) -> (Self, Self);
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
    fn sin_cos_with(self, s: f64, c: f64) -> (Self, Self) {
        (s, c)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
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
    /// A moving frame whose angle `q[2]` has the value `theta` with `(sin theta, cos theta)`
    /// `= (s, c)` given (see [`Scalar::sin_cos_with`]): no trigonometry.
    #[inline(always)]
    pub fn with_sin_cos(q: [T; 3], s: f64, c: f64) -> Self {
        let (s, c) = q[2].sin_cos_with(s, c);
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
        // ThirdJet: H w, w^T H w and grad(w^T H w) against differences of the HessJet
        let t3 = f(std::array::from_fn(|i| ThirdJet::var(i, x0[i], dir[i])));
        assert!((t3.v - h.v).abs() < 1e-15);
        assert!((t3.d1 - d.d1).abs() < 1e-14);
        assert!((t3.d2 - vhv).abs() < 1e-12);
        let quad = |x: [f64; 6]| -> f64 {
            let hh = f(std::array::from_fn(|k| HessJet::var(k, x[k]))).h;
            (0..6)
                .map(|i| (0..6).map(|j| dir[i] * hh[i][j] * dir[j]).sum::<f64>())
                .sum()
        };
        for i in 0..6 {
            assert!((t3.g[i] - h.g[i]).abs() < 1e-14, "ThirdJet grad {i}");
            let hw: f64 = (0..6).map(|j| h.h[i][j] * dir[j]).sum();
            assert!((t3.g1[i] - hw).abs() < 1e-13, "ThirdJet H w {i}");
            let (mut xp, mut xm) = (x0, x0);
            xp[i] += e;
            xm[i] -= e;
            let fd3 = (quad(xp) - quad(xm)) / (2.0 * e);
            assert!(
                (t3.g2[i] - fd3).abs() < 1e-7,
                "ThirdJet D3 {i}: {} vs {fd3}",
                t3.g2[i]
            );
        }
        let du = f(std::array::from_fn(|i| Dual::var(x0[i], dir[i])));
        assert!((du.v - d.v).abs() < 1e-15);
        assert!((du.d - d.d1).abs() < 1e-14);
    }
}
