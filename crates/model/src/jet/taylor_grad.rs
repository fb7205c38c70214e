//! [`TaylorGrad4`]: the truncated Taylor series of `t -> f(q + t w)` to degree 4 whose
//! coefficients carry their gradients with respect to the 6 local coordinates of the base point
//! `q`, so the gradients of the directional derivatives `D^k f(q)(w, ..., w)`, `k <= 4`, with
//! respect to `q` and to `w` come out of one forward evaluation.
//!
//! Since `d/dq_i [t^k] f(q + t w) = [t^k] (d_i f)(q + t w)`, the gradient of coefficient `k`
//! is `D^(k+1) f(w^k, e_i) / k!`; since `d/dw_i [t^k] f(q + t w) = [t^(k-1)] (d_i f)(q + t w)`,
//! the gradient of coefficient `k` with respect to `w` is the base-point gradient of coefficient
//! `k - 1`. Every coefficient is a small dual number `(value, gradient)` and the recurrences of
//! [`super::Taylor4`] run in that arithmetic.

use super::{Frame, Scalar, NV};
use std::ops::{Add, Mul, Sub};

/// Degree of the truncated series.
const DEG: usize = 4;

/// `f(q + t w) = v + c[0] t + c[1] t^2 + c[2] t^3 + c[3] t^4 + O(t^5)` (the coefficient of
/// `t^k` is `D^k f(q)(w, ..., w) / k!`, as in [`super::Taylor4`]) and `g[k]`, the gradient of coefficient `k` (`k = 0`
/// the value) with respect to the 6 local coordinates of the base point `q`:
/// `g[k][i] = D^(k+1) f(q)(w, ..., w, e_i) / k!`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TaylorGrad4 {
    /// Value (`t^0`).
    pub v: f64,
    /// Coefficients of `t^1 .. t^4`.
    pub c: [f64; DEG],
    /// Gradients of the coefficients of `t^0 .. t^4` with respect to the base point.
    pub g: [[f64; NV]; DEG + 1],
}

impl TaylorGrad4 {
    /// The constant 0 (as [`Scalar::cst`]).
    pub(crate) const ZERO: Self = TaylorGrad4 {
        v: 0.0,
        c: [0.0; DEG],
        g: [[0.0; NV]; DEG + 1],
    };
    /// The constant 1 (as [`Scalar::cst`]).
    pub(crate) const ONE: Self = TaylorGrad4 {
        v: 1.0,
        ..Self::ZERO
    };
    /// Independent variable number `i`: `x + t w`, gradient `e_i` in the value only (the
    /// passes build their frames by [`TaylorGrad4::set_var_frame`]).
    #[cfg(test)]
    pub fn var(i: usize, x: f64, w: f64) -> Self {
        let mut j = Self::cst(x);
        j.c[0] = w;
        j.g[0][i] = 1.0;
        j
    }
    /// Coefficient `k` (`k = 0` the value).
    #[inline(always)]
    pub fn coef(&self, k: usize) -> f64 {
        if k == 0 {
            self.v
        } else {
            self.c[k - 1]
        }
    }
    /// The directional derivative `D^k f(w, ..., w) = k! * coefficient k` (as
    /// [`super::Taylor4::derivative`], bit for bit).
    #[inline(always)]
    pub fn derivative(&self, k: usize) -> f64 {
        FACT[k] * self.coef(k)
    }
    /// The gradient of `D^k f(q)(w, ..., w)` with respect to the base point `q`, from the
    /// coefficient gradients `g` of a series (its field `g`, possibly stored):
    /// `D^(k+1) f(w, ..., w, .) = k! * g[k]`.
    #[inline(always)]
    pub fn derivative_grad_q(g: &[[f64; NV]; DEG + 1], k: usize) -> [f64; NV] {
        g[k].map(|x| FACT[k] * x)
    }
    /// The gradient of `D^k f(q)(w, ..., w)` with respect to the direction `w`, from the
    /// coefficient gradients `g` of a series: `k D^k f(w, ..., w, .) = k! * g[k - 1]` (zero for
    /// `k = 0`).
    #[inline(always)]
    pub fn derivative_grad_w(g: &[[f64; NV]; DEG + 1], k: usize) -> [f64; NV] {
        if k == 0 {
            [0.0; NV]
        } else {
            g[k - 1].map(|x| FACT[k] * x)
        }
    }
    /// Makes `f` the frame of a body whose coordinates are the variables `slot..slot + 3`
    /// (`slot` 0 or 3) at `q` along `w`, with `(sn, cs) = (sin, cos)` of `q[2]`: bit for bit
    /// `Frame::with_sin_cos([var(slot, q[0], w[0]), ..], sn, cs)`, written in place. Only the
    /// values, the coefficients and the gradient entries that can be non-zero (slots `slot`,
    /// `slot + 1` in the value of `x`, `y`; slot `slot + 2` in every coefficient of the angle's
    /// sine and cosine) are written, so every other gradient entry of `f` must be zero already:
    /// `f` starts as [`Frame::fixed`] and is only ever set with the same `slot`.
    #[inline(always)]
    pub(crate) fn set_var_frame(
        f: &mut Frame<Self>,
        slot: usize,
        q: [f64; 3],
        w: [f64; 3],
        sn: f64,
        cs: f64,
    ) {
        for k in 0..3 {
            let x = &mut f.q[k];
            x.v = q[k];
            x.c = [w[k], 0.0, 0.0, 0.0];
            x.g[0][slot + k] = 1.0;
        }
        // the linear case of `sin_cos_with` for a variable (gradient 1 in slot `slot + 2`)
        let ds = [sn, cs, -sn, -cs];
        let dc = [cs, -sn, -cs, sn];
        let l = slot + 2;
        let mut p = 1.0;
        for k in 0..=DEG {
            let (s, c) = (ds[k % 4] * p, dc[k % 4] * p);
            if k == 0 {
                (f.s.v, f.c.v) = (s, c);
            } else {
                (f.s.c[k - 1], f.c.c[k - 1]) = (s, c);
            }
            f.s.g[k][l] = ds[(k + 1) % 4] * p;
            f.c.g[k][l] = dc[(k + 1) % 4] * p;
            p *= w[2] / (k + 1) as f64;
        }
    }
    #[inline(always)]
    fn coefs(&self) -> [f64; DEG + 1] {
        std::array::from_fn(|k| self.coef(k))
    }
    #[inline(always)]
    fn from_parts(a: [f64; DEG + 1], g: [[f64; NV]; DEG + 1]) -> Self {
        TaylorGrad4 {
            v: a[0],
            c: [a[1], a[2], a[3], a[4]],
            g,
        }
    }
    /// `(sin x, cos x)` by the recurrences `k s_k = sum_j j x_j c_(k-j)`,
    /// `k c_k = -sum_j j x_j s_(k-j)` in dual arithmetic (the general case of `sin_cos`).
    #[cfg(test)]
    pub(crate) fn sin_cos_series(self) -> (Self, Self) {
        let (s0, c0) = self.v.sin_cos();
        self.sin_cos_series_with(s0, c0)
    }
    /// [`TaylorGrad4::sin_cos_series`] given `sin` and `cos` of the value.
    #[inline(always)]
    fn sin_cos_series_with(self, s0: f64, c0: f64) -> (Self, Self) {
        let x = self.coefs();
        let gx = &self.g;
        let (mut s, mut c) = ([0.0; DEG + 1], [0.0; DEG + 1]);
        let (mut gs, mut gc) = ([[0.0; NV]; DEG + 1], [[0.0; NV]; DEG + 1]);
        (s[0], c[0]) = (s0, c0);
        for l in 0..NV {
            gs[0][l] = c[0] * gx[0][l];
            gc[0][l] = -s[0] * gx[0][l];
        }
        for k in 1..=DEG {
            let (mut ds, mut dc) = (0.0, 0.0);
            let (mut dgs, mut dgc) = ([0.0; NV], [0.0; NV]);
            for j in 1..=k {
                let jx = j as f64 * x[j];
                ds += jx * c[k - j];
                dc -= jx * s[k - j];
                let jf = j as f64;
                axpby(&mut dgs, jf * c[k - j], &gx[j], jx, &gc[k - j]);
                axpby(&mut dgc, -jf * s[k - j], &gx[j], -jx, &gs[k - j]);
            }
            let inv = 1.0 / k as f64;
            s[k] = ds * inv;
            c[k] = dc * inv;
            gs[k] = dgs.map(|v| v * inv);
            gc[k] = dgc.map(|v| v * inv);
        }
        (
            TaylorGrad4::from_parts(s, gs),
            TaylorGrad4::from_parts(c, gc),
        )
    }
}

/// `k!` for `k = 0..=4`.
const FACT: [f64; DEG + 1] = [1.0, 1.0, 2.0, 6.0, 24.0];

/// `acc += a * x + b * y` entry by entry (the gradient of a product of two dual numbers).
#[inline(always)]
fn axpby(acc: &mut [f64; NV], a: f64, x: &[f64; NV], b: f64, y: &[f64; NV]) {
    for l in 0..NV {
        acc[l] += a * x[l] + b * y[l];
    }
}

impl Add for TaylorGrad4 {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        for k in 0..DEG {
            self.c[k] += o.c[k];
        }
        for k in 0..=DEG {
            for l in 0..NV {
                self.g[k][l] += o.g[k][l];
            }
        }
        self
    }
}
impl Sub for TaylorGrad4 {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, o: Self) -> Self {
        self.v -= o.v;
        for k in 0..DEG {
            self.c[k] -= o.c[k];
        }
        for k in 0..=DEG {
            for l in 0..NV {
                self.g[k][l] -= o.g[k][l];
            }
        }
        self
    }
}
impl Mul for TaylorGrad4 {
    type Output = Self;
    /// Cauchy product of the series, with the product rule on every term's gradient.
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let (a, b) = (self.coefs(), o.coefs());
        let mut p = [0.0; DEG + 1];
        let mut gp = [[0.0; NV]; DEG + 1];
        for i in 0..=DEG {
            for j in 0..=DEG - i {
                p[i + j] += a[i] * b[j];
                axpby(&mut gp[i + j], b[j], &self.g[i], a[i], &o.g[j]);
            }
        }
        TaylorGrad4::from_parts(p, gp)
    }
}
impl Mul<f64> for TaylorGrad4 {
    type Output = Self;
    #[inline(always)]
    fn mul(mut self, k: f64) -> Self {
        self.v *= k;
        for c in self.c.iter_mut() {
            *c *= k;
        }
        for g in self.g.iter_mut() {
            for x in g.iter_mut() {
                *x *= k;
            }
        }
        self
    }
}
super::scalar_shift_ops!(TaylorGrad4);
impl Scalar for TaylorGrad4 {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        TaylorGrad4 {
            v,
            c: [0.0; DEG],
            g: [[0.0; NV]; DEG + 1],
        }
    }
    /// The recurrences of [`super::Taylor4`] in dual arithmetic:
    /// `k s_k = sum_(j=1..k) j x_j c_(k-j)`, `k c_k = -sum_(j=1..k) j x_j s_(k-j)`, and
    /// `grad s_0 = c_0 grad x_0`, `grad c_0 = -s_0 grad x_0`.
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (sn, cs) = self.v.sin_cos();
        self.sin_cos_with(sn, cs)
    }
    #[inline(always)]
    fn sin_cos_with(self, sn: f64, cs: f64) -> (Self, Self) {
        let x = self.coefs();
        let gx = &self.g;
        if x[2..].iter().all(|&a| a == 0.0) && gx[1..].iter().flatten().all(|&a| a == 0.0) {
            // a variable theta + t w (a body angle): sin(theta + t w) has the coefficients
            // sin^(k)(theta) w^k / k!, whose theta-derivatives are sin^(k+1)(theta) w^k / k!
            let ds = [sn, cs, -sn, -cs];
            let dc = [cs, -sn, -cs, sn];
            let (mut s, mut c) = ([0.0; DEG + 1], [0.0; DEG + 1]);
            let (mut gs, mut gc) = ([[0.0; NV]; DEG + 1], [[0.0; NV]; DEG + 1]);
            let mut p = 1.0;
            for k in 0..=DEG {
                s[k] = ds[k % 4] * p;
                c[k] = dc[k % 4] * p;
                gs[k] = gx[0].map(|g| g * ds[(k + 1) % 4] * p);
                gc[k] = gx[0].map(|g| g * dc[(k + 1) % 4] * p);
                p *= x[1] / (k + 1) as f64;
            }
            return (
                TaylorGrad4::from_parts(s, gs),
                TaylorGrad4::from_parts(c, gc),
            );
        }
        self.sin_cos_series_with(sn, cs)
    }
    /// `r^2 = x`: `r_k = (x_k - sum_(j=1..k-1) r_j r_(k-j)) / (2 r_0)` in dual arithmetic
    /// (`grad r_0 = grad x_0 / (2 r_0)`).
    #[inline(always)]
    fn sqrt(self) -> Self {
        let x = self.coefs();
        let mut r = [0.0; DEG + 1];
        let mut gr = [[0.0; NV]; DEG + 1];
        r[0] = x[0].sqrt();
        let inv2r0 = 0.5 / r[0];
        gr[0] = self.g[0].map(|v| v * inv2r0);
        for k in 1..=DEG {
            let mut acc = x[k];
            let mut gacc = self.g[k];
            for j in 1..k {
                acc -= r[j] * r[k - j];
                axpby(&mut gacc, -r[k - j], &gr[j], -r[j], &gr[k - j]);
            }
            // the value as `Taylor4` rounds it (so the series' values are bit for bit Taylor4's)
            r[k] = acc / (2.0 * r[0]);
            // (acc / (2 r_0))' = acc' / (2 r_0) - r_k r_0' / r_0 = (acc' - 2 r_k r_0') / (2 r_0)
            for l in 0..NV {
                gr[k][l] = (gacc[l] - 2.0 * r[k] * gr[0][l]) * inv2r0;
            }
        }
        TaylorGrad4::from_parts(r, gr)
    }
}

#[cfg(test)]
mod tests {
    use super::super::Taylor4;
    use super::*;

    /// A function of 6 variables with products, `sin_cos` (through the frames and directly) and
    /// `sqrt`.
    fn f<T: Scalar>(x: [T; 6]) -> T {
        use super::super::{dot, point, sub2, Frame};
        let p = point(&Frame::new([x[0], x[1], x[2]]), [0.3, -0.2]);
        let q = point(&Frame::new([x[3], x[4], x[5]]), [-0.1, 0.4]);
        let d = sub2(q, p);
        let (s, c) = (x[1] * x[5]).sin_cos();
        dot(d, d).sqrt() * x[2] + x[0] * x[4] * s + c * c * c
    }

    const X0: [f64; 6] = [0.1, -0.3, 0.7, 1.2, 0.4, -0.5];
    const W: [f64; 6] = [0.3, -0.1, 0.9, 0.2, -0.6, 0.5];

    fn taylor_at(x: [f64; 6], w: [f64; 6]) -> [f64; 5] {
        let t = f(std::array::from_fn(|i| Taylor4::var(x[i], w[i])));
        std::array::from_fn(|k| t.coef(k))
    }

    /// Fourth-order central difference of the Taylor4 coefficients along coordinate `i` of the
    /// base point (`dir = false`) or of the direction (`dir = true`).
    fn fd_coefs(i: usize, dir: bool) -> [f64; 5] {
        let h = 1e-3;
        let at = |s: f64| {
            let (mut x, mut w) = (X0, W);
            if dir {
                w[i] += s;
            } else {
                x[i] += s;
            }
            taylor_at(x, w)
        };
        let (p2, p1, m1, m2) = (at(2.0 * h), at(h), at(-h), at(-2.0 * h));
        std::array::from_fn(|k| (-p2[k] + 8.0 * p1[k] - 8.0 * m1[k] + m2[k]) / (12.0 * h))
    }

    /// The series equals [`Taylor4`]'s, and the gradients of every coefficient match
    /// fourth-order differences of [`Taylor4`] coefficients in the base point; the base-point
    /// gradient of coefficient `k - 1` matches the `w`-gradient of coefficient `k`.
    #[test]
    fn gradients_match_differences_of_taylor4() {
        let j = f(std::array::from_fn(|i| TaylorGrad4::var(i, X0[i], W[i])));
        let t = taylor_at(X0, W);
        for k in 0..=DEG {
            assert!(
                (j.coef(k) - t[k]).abs() <= 1e-14 * (1.0 + t[k].abs()),
                "coef {k}"
            );
        }
        let mut worst: f64 = 0.0;
        for i in 0..NV {
            let (fq, fw) = (fd_coefs(i, false), fd_coefs(i, true));
            for k in 0..=DEG {
                let e = (j.g[k][i] - fq[k]).abs() / (1.0 + fq[k].abs());
                worst = worst.max(e);
                assert!(
                    e < 1e-8,
                    "grad_q coef {k} var {i}: {} vs {}",
                    j.g[k][i],
                    fq[k]
                );
                if k > 0 {
                    let e = (j.g[k - 1][i] - fw[k]).abs() / (1.0 + fw[k].abs());
                    assert!(
                        e < 1e-8,
                        "grad_w coef {k} var {i}: {} vs {}",
                        j.g[k - 1][i],
                        fw[k]
                    );
                }
            }
            assert!(
                fq[DEG].abs() > 1e-3,
                "the test function is nonlinear in var {i}"
            );
        }
        // derivative_grad_w(k) = k! g[k-1] = d/dw D^k f(w^k)
        let (gw, fw) = (
            TaylorGrad4::derivative_grad_w(&j.g, 3),
            fd_coefs(2, true)[3] * 6.0,
        );
        assert!((gw[2] - fw).abs() < 1e-8 * (1.0 + fw.abs()));
        eprintln!("TaylorGrad4 against differences of Taylor4: worst relative error {worst:e}");
    }

    /// [`TaylorGrad4::set_var_frame`] (also over a frame set before with other coordinates)
    /// equals the frame of [`TaylorGrad4::var`] coordinates entry for entry (the values bit for
    /// bit; zero entries may differ in sign only).
    #[test]
    fn set_var_frame_matches_the_frame_of_variables() {
        use super::super::Frame;
        let bits = |a: &TaylorGrad4, b: &TaylorGrad4| {
            let (fa, fb) = (
                std::iter::once(a.v)
                    .chain(a.c)
                    .chain(a.g.into_iter().flatten()),
                std::iter::once(b.v)
                    .chain(b.c)
                    .chain(b.g.into_iter().flatten()),
            );
            fa.zip(fb)
                .all(|(x, y)| x.to_bits() == y.to_bits() || (x == 0.0 && y == 0.0))
        };
        for slot in [0, 3] {
            let mut f = Frame::fixed();
            for (q, w) in [(X0, W), (W, X0)] {
                let (q3, w3) = ([q[0], q[1], q[2]], [w[0], w[1], w[2]]);
                let (sn, cs) = q3[2].sin_cos();
                TaylorGrad4::set_var_frame(&mut f, slot, q3, w3, sn, cs);
                let r = Frame::with_sin_cos(
                    std::array::from_fn(|k| TaylorGrad4::var(slot + k, q3[k], w3[k])),
                    sn,
                    cs,
                );
                for k in 0..3 {
                    assert!(bits(&f.q[k], &r.q[k]), "slot {slot} q[{k}]");
                }
                assert!(bits(&f.c, &r.c) && bits(&f.s, &r.s), "slot {slot} sin, cos");
            }
        }
    }

    /// Each operation alone: `sin_cos`, `sqrt` and a product of two variables against
    /// differences of [`Taylor4`].
    #[test]
    fn elementary_operations_match_differences() {
        type Op<T> = fn(T, T) -> T;
        fn ops<T: Scalar>() -> [Op<T>; 4] {
            [
                |a, _| a.sin_cos().0,
                |a, _| a.sin_cos().1,
                |a, b| (a * a + b * 0.5 + 2.0).sqrt(),
                |a, b| a * b * a,
            ]
        }
        let (x0, w0) = ([0.4, -0.7], [0.8, 0.3]);
        for (n, (opj, opt)) in ops::<TaylorGrad4>()
            .iter()
            .zip(ops::<Taylor4>())
            .enumerate()
        {
            let j = opj(
                TaylorGrad4::var(0, x0[0], w0[0]),
                TaylorGrad4::var(1, x0[1], w0[1]),
            );
            let h = 1e-3;
            for i in 0..2 {
                let at = |s: f64| {
                    let mut x = x0;
                    x[i] += s;
                    let t = opt(Taylor4::var(x[0], w0[0]), Taylor4::var(x[1], w0[1]));
                    [t.v, t.c[0], t.c[1], t.c[2], t.c[3]]
                };
                let (p2, p1, m1, m2) = (at(2.0 * h), at(h), at(-h), at(-2.0 * h));
                for k in 0..=DEG {
                    let fd = (-p2[k] + 8.0 * p1[k] - 8.0 * m1[k] + m2[k]) / (12.0 * h);
                    assert!(
                        (j.g[k][i] - fd).abs() < 1e-9 * (1.0 + fd.abs()),
                        "op {n} coef {k} var {i}: {} vs {fd}",
                        j.g[k][i]
                    );
                }
            }
        }
    }
}
