//! # mbd-jet
//!
//! Forward-mode differentiation by jets: number types that carry, besides a value, a fixed set
//! of derivatives, and propagate them exactly (to round-off) through `+`, `-`, `*`, `sin_cos`
//! and `sqrt`. A function written once over the [`Scalar`] trait is evaluated with
//!
//! * `f64`: the value;
//! * [`Dual`]: the value and the first derivative along one direction;
//! * [`DirJet`]: the value, the gradient and the first and second derivatives along a direction
//!   `v` (so `v^T H v` without forming the Hessian `H`);
//! * [`HessJet`]: the value, the gradient and the full Hessian;
//! * [`TanJet`]: the value, the gradient, the derivative along a direction `w` and the gradient
//!   of that derivative (`H w`) without forming the Hessian;
//! * [`ThirdJet`]: besides the gradient, `H w`, `w^T H w` and the third-derivative contraction
//!   `D^3 f(w, w, .)` along a direction `w`;
//! * [`Taylor4`]: the Taylor series of `t -> f(q + t w)` to degree [`TAYLOR_DEGREE`] (the
//!   directional derivatives `D^k f(w, ..., w)`, `k <= 4`, without gradients);
//! * [`PolyJet`]: the truncated Taylor polynomial of `f(q + sum_j x_j w_j)` in several
//!   directions at once, restricted to the monomials of a [`Basis`], with the gradient of every
//!   coefficient with respect to the base point (mixed directional derivatives
//!   `D^k f(w_1, ..., w_k)` and their gradients in one pass).
//!
//! Gradients are taken with respect to [`NV`] independent variables (the six coordinates
//! `(x, y, theta)` of the two bodies a multibody joint or force connects, in `mbd-model`).
//! [`DirJetN`], [`HessJetN`] and [`TanJetN`] are the same jets over any number `N` of
//! variables (`DirJet` is `DirJetN<NV>`): the 24 natural coordinates of two spatial bodies, for
//! instance. The crate has no dependencies and knows nothing about mechanics.
//!
//! ```
//! use mbd_jet::{Dual, HessJet, Scalar};
//!
//! // f(x, y) = sin(x) y^2 + sqrt(x), written once for any scalar
//! fn f<T: Scalar>(x: T, y: T) -> T {
//!     let (s, _c) = x.sin_cos();
//!     s * y * y + x.sqrt()
//! }
//! let (x, y) = (0.7, 1.3);
//!
//! // the derivative along (1, 0) with a dual number: df/dx = cos(x) y^2 + 1 / (2 sqrt(x))
//! let d = f(Dual::var(x, 1.0), Dual::var(y, 0.0));
//! let dfdx = x.cos() * y * y + 0.5 / x.sqrt();
//! assert!((d.v - f(x, y)).abs() < 1e-15);
//! assert!((d.d - dfdx).abs() < 1e-14);
//!
//! // the gradient and the Hessian with HessJet (variables 0 and 1 of the NV = 6)
//! let h = f(HessJet::var(0, x), HessJet::var(1, y));
//! assert!((h.g[0] - dfdx).abs() < 1e-14);
//! assert!((h.g[1] - 2.0 * x.sin() * y).abs() < 1e-14);
//! // d2f/dx2 = -sin(x) y^2 - x^(-3/2) / 4, d2f/dxdy = 2 cos(x) y
//! assert!((h.h[0][0] - (-x.sin() * y * y - 0.25 / (x * x.sqrt()))).abs() < 1e-13);
//! assert!((h.h[0][1] - 2.0 * x.cos() * y).abs() < 1e-14);
//! assert_eq!(h.h[0][1], h.h[1][0]);
//! ```
#![warn(missing_docs)]
// Index loops over the fixed-size jets (6 variables, 6x6 Hessians) read like the maths.
#![allow(clippy::needless_range_loop)]

use std::ops::{Add, Mul, Neg, Sub};

/// `-x` (as `x * -1.0`, bit-identical to negating every component), `x + c` and `x - c` (the
/// value shifts, the derivatives do not) for a jet type with a `v` field and `Mul<f64>`.
macro_rules! scalar_shift_ops {
    (const $t:ident) => {
        impl<const N: usize> std::ops::Neg for $t<N> {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                self * -1.0
            }
        }
        impl<const N: usize> std::ops::Add<f64> for $t<N> {
            type Output = Self;
            #[inline(always)]
            fn add(mut self, c: f64) -> Self {
                self.v += c;
                self
            }
        }
        impl<const N: usize> std::ops::Sub<f64> for $t<N> {
            type Output = Self;
            #[inline(always)]
            fn sub(mut self, c: f64) -> Self {
                self.v -= c;
                self
            }
        }
    };
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
#[cfg(any(test, feature = "fixtures"))]
pub mod fixtures;
mod hess;
mod poly;
mod tan;
mod taylor;
mod third;

pub use dir::{DirJet, DirJetN};
pub use dual::Dual;
pub use hess::{HessJet, HessJetN};
pub use poly::{Basis, PolyJet, MAX_DIRS};
pub use tan::{TanJet, TanJetN};
pub use taylor::{Taylor4, TAYLOR_DEGREE};
pub use third::{ThirdJet, ThirdJetN};

/// Number of independent variables every gradient of a jet has (in `mbd-model`: the local
/// coordinates `(x, y, theta)` of the first body of a joint or force, then of the second).
pub const NV: usize = 6;

/// The arithmetic a function differentiated by the jets may use: `+`, `-`, `*` among scalars
/// and with `f64` constants, negation, `sin_cos` and `sqrt`.
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

#[cfg(test)]
mod tests;

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctest;
