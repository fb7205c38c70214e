//! Forward-mode differentiation for joint and force equations: the jets of [`mbd_jet`] and the
//! planar helpers the equations are written with ([`Frame`], [`point`], [`direction`], [`dot`],
//! [`sub2`]).
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

pub use mbd_jet::{Basis, PolyJet, MAX_DIRS};
pub use mbd_jet::{DirJet, Dual, HessJet, Scalar, TanJet, Taylor4, ThirdJet, NV};

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

/// Writes into `f` the frame of a body whose coordinates are the jet variables `slot ..
/// slot + 3` with the values `q`, the components `w[j]` (this body's three) along direction
/// `j`, and `(sin, cos)` of its angle `(sn, cs)`. Only the entries that can be non-zero are
/// written, so every other entry of `f` must be zero already: `f` starts as [`Frame::fixed`]
/// and is only ever set with the same `slot`.
#[inline(always)]
pub fn set_var_frame<const K: usize, B: Basis<K>>(
    f: &mut Frame<PolyJet<K, B>>,
    slot: usize,
    q: [f64; 3],
    w: &[[f64; 3]],
    sn: f64,
    cs: f64,
) {
    let mut wa = [0.0; MAX_DIRS];
    for k in 0..3 {
        let x = &mut f.q[k];
        x.c[0] = q[k];
        x.g[0][slot + k] = 1.0;
        for (d, wd) in w.iter().enumerate().take(B::ND) {
            x.c[B::LIN[d] as usize] = wd[k];
        }
    }
    for (d, wd) in w.iter().enumerate().take(B::ND) {
        wa[d] = wd[2];
    }
    // the angle's gradient is e_(slot + 2): only that column is written
    let [sv, sd, cv, cd] = PolyJet::<K, B>::angle_series(&wa, sn, cs);
    let l = slot + 2;
    for k in 0..K {
        (f.s.c[k], f.s.g[k][l]) = (sv[k], sd[k]);
        (f.c.c[k], f.c.g[k][l]) = (cv[k], cd[k]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::TwoDirections;

    /// A distance between two points of two bodies, times an angle, plus a product.
    fn f<T: Scalar>(x: [T; 6]) -> T {
        let p = point(&Frame::new([x[0], x[1], x[2]]), [0.3, -0.2]);
        let q = point(&Frame::new([x[3], x[4], x[5]]), [-0.1, 0.4]);
        let u = direction(&Frame::new([x[3], x[4], x[5]]), [0.6, 0.8]);
        let d = sub2(q, p);
        dot(d, d).sqrt() * x[2] + x[0] * x[4] + dot(d, u)
    }

    /// The planar helpers on jets: gradient and Hessian against finite differences.
    #[test]
    fn planar_helpers_on_jets_match_finite_differences() {
        let x0 = [0.1, -0.3, 0.7, 1.2, 0.4, -0.5];
        let h = f(std::array::from_fn(|i| HessJet::var(i, x0[i])));
        assert_eq!(h.v, f(x0));
        let e = 1e-5;
        for i in 0..6 {
            let (mut xp, mut xm) = (x0, x0);
            xp[i] += e;
            xm[i] -= e;
            let fd = (f(xp) - f(xm)) / (2.0 * e);
            assert!((fd - h.g[i]).abs() < 1e-8, "grad {i}");
            let gp = f(std::array::from_fn(|k| HessJet::var(k, xp[k]))).g;
            let gm = f(std::array::from_fn(|k| HessJet::var(k, xm[k]))).g;
            for j in 0..6 {
                let fd2 = (gp[j] - gm[j]) / (2.0 * e);
                assert!((fd2 - h.h[i][j]).abs() < 1e-7, "hess {i} {j}");
            }
        }
    }

    /// The frames built in place by [`set_var_frame`] equal the frames of variables.
    #[test]
    fn var_frames_match() {
        let x0 = [0.1, -0.3, 0.7, 1.2, 0.4, -0.5];
        let dirs = [
            [0.3, -0.1, 0.9, 0.2, -0.6, 0.5],
            [-0.4, 0.2, 0.6, -0.3, 0.1, 0.8],
        ];
        for slot in [0, 3] {
            let q = [x0[slot], x0[slot + 1], x0[slot + 2]];
            let w: Vec<[f64; 3]> = dirs
                .iter()
                .map(|d| [d[slot], d[slot + 1], d[slot + 2]])
                .collect();
            let (sn, cs) = q[2].sin_cos();
            let mut g: Frame<PolyJet<8, TwoDirections>> = Frame::fixed();
            set_var_frame(&mut g, slot, q, &w, sn, cs);
            let r = Frame::new(std::array::from_fn(|k| {
                let wk: Vec<f64> = w.iter().map(|d| d[k]).collect();
                PolyJet::<8, TwoDirections>::var(slot + k, q[k], &wk)
            }));
            for (a, b) in [(g.s, r.s), (g.c, r.c), (g.q[0], r.q[0]), (g.q[2], r.q[2])] {
                assert_eq!(a.c, b.c);
                assert_eq!(a.g, b.g);
            }
        }
    }
}
