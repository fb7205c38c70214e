//! [`PolyJet`]: the truncated multivariate Taylor polynomial of
//! `x -> f(q + x_1 w_1 + ... + x_d w_d)` in a few infinitesimals `x_j` (one per direction
//! `w_j`), holding only the monomials of a fixed [`Basis`], every coefficient with its gradient
//! with respect to the 6 local coordinates of the base point `q`.
//!
//! One pass of such a jet gives all the mixed directional derivatives a basis names, e.g. with
//! the basis `{1, t, t^2, e, e t, e t^2}` (directions `v` for `t` and `u` for `e`) the
//! coefficients `D^2 f(u, v)` (of `e t`) and `D^3 f(u, v, v) / 2` (of `e t^2`), where
//! polarisation takes two or three single-direction passes per mixed derivative. The
//! coefficient of the monomial `prod_j x_j^(e_j)` is `D^p f(w_1^(e_1), ..., w_d^(e_d)) / prod_j
//! e_j!` (`p = sum_j e_j`), and
//!
//! * its gradient with respect to `q` is carried along (`g`): `D^(p+1) f(..., .)` over the same
//!   factorials;
//! * its gradient with respect to the direction `w_j` is the `q`-gradient of the coefficient of
//!   the monomial divided by `x_j` (zero if `e_j = 0`), since `d/dw_j f(q + sum x w) = x_j
//!   (grad f)(q + sum x w)` ([`Basis::DIV`]).
//!
//! A basis must contain the constant first, list its monomials by non-decreasing degree, and
//! be closed under division (every divisor of a member is a member), so products truncate
//! consistently; the tables are built, and these rules checked, at compile time.

use super::{Scalar, NV};
use std::marker::PhantomData;
use std::ops::{Add, Mul, Neg, Sub};

/// `1 / e` for the exponents `e` a basis can have (degree at most 4 in practice).
const INV: [f64; 6] = [0.0, 1.0, 0.5, 1.0 / 3.0, 0.25, 0.2];

/// Most directions a [`Basis`] may use.
pub const MAX_DIRS: usize = 6;
/// The entry of a [`Basis`] table for a product or quotient outside the basis (`u8::MAX`).
pub(crate) const NONE: u8 = u8::MAX;

/// The monomials of a [`PolyJet`] (see the module doc for the rules), and the tables the
/// arithmetic needs, derived from the exponents at compile time.
pub trait Basis<const K: usize>: Copy + std::fmt::Debug + 'static {
    /// Number of directions (infinitesimals) used.
    const ND: usize;
    /// The exponents of monomial `k` in each direction (`EXP[0]` all zero).
    const EXP: [[u8; MAX_DIRS]; K];
    /// `PROD[i][j]`: the monomial `i * j`, or `u8::MAX` outside the basis.
    const PROD: [[u8; K]; K] = prod_table(&Self::EXP);
    /// `DIV[k][j]`: the monomial `k / x_j`, or `u8::MAX` if `x_j` does not divide it.
    const DIV: [[u8; MAX_DIRS]; K] = div_table(&Self::EXP);
    /// `LIN[j]`: the monomial `x_j` (`u8::MAX` for unused directions).
    const LIN: [u8; MAX_DIRS] = lin_table(&Self::EXP);
    /// The degree of every monomial.
    const DEG: [u8; K] = degrees(&Self::EXP);
    /// `prod_j e_j!` of every monomial: `D^p f(w_1^(e_1), ...) = FACT[k] * coefficient k`.
    const FACT: [u32; K] = fact_table(&Self::EXP);
    /// The largest degree.
    const MAX_DEG: usize = max_degree(&Self::EXP);
}

const fn index_of<const K: usize>(exp: &[[u8; MAX_DIRS]; K], e: &[u8; MAX_DIRS]) -> u8 {
    let mut k = 0;
    while k < K {
        let mut j = 0;
        let mut same = true;
        while j < MAX_DIRS {
            if exp[k][j] != e[j] {
                same = false;
            }
            j += 1;
        }
        if same {
            return k as u8;
        }
        k += 1;
    }
    NONE
}

const fn degree(e: &[u8; MAX_DIRS]) -> u8 {
    let mut d = 0;
    let mut j = 0;
    while j < MAX_DIRS {
        d += e[j];
        j += 1;
    }
    d
}

/// The product table; checks the rules of the module doc (a compile error if broken).
const fn prod_table<const K: usize>(exp: &[[u8; MAX_DIRS]; K]) -> [[u8; K]; K] {
    assert!(K >= 1 && K < NONE as usize, "basis size");
    assert!(degree(&exp[0]) == 0, "the constant comes first");
    let mut t = [[NONE; K]; K];
    let mut i = 0;
    while i < K {
        if i > 0 {
            assert!(
                degree(&exp[i - 1]) <= degree(&exp[i]),
                "monomials by degree"
            );
        }
        let mut j = 0;
        while j < K {
            let mut e = [0u8; MAX_DIRS];
            let mut l = 0;
            while l < MAX_DIRS {
                e[l] = exp[i][l] + exp[j][l];
                l += 1;
            }
            t[i][j] = index_of(exp, &e);
            j += 1;
        }
        // closed under division, exponents at most 5
        let mut l = 0;
        while l < MAX_DIRS {
            assert!(exp[i][l] <= 5, "exponents at most 5");
            if exp[i][l] > 0 {
                let mut e = exp[i];
                e[l] -= 1;
                assert!(
                    index_of(exp, &e) != NONE,
                    "the basis is closed under division"
                );
            }
            l += 1;
        }
        i += 1;
    }
    t
}

const fn div_table<const K: usize>(exp: &[[u8; MAX_DIRS]; K]) -> [[u8; MAX_DIRS]; K] {
    let mut t = [[NONE; MAX_DIRS]; K];
    let mut k = 0;
    while k < K {
        let mut j = 0;
        while j < MAX_DIRS {
            if exp[k][j] > 0 {
                let mut e = exp[k];
                e[j] -= 1;
                t[k][j] = index_of(exp, &e);
            }
            j += 1;
        }
        k += 1;
    }
    t
}

const fn lin_table<const K: usize>(exp: &[[u8; MAX_DIRS]; K]) -> [u8; MAX_DIRS] {
    let mut t = [NONE; MAX_DIRS];
    let mut j = 0;
    while j < MAX_DIRS {
        let mut e = [0u8; MAX_DIRS];
        e[j] = 1;
        t[j] = index_of(exp, &e);
        j += 1;
    }
    t
}

const fn degrees<const K: usize>(exp: &[[u8; MAX_DIRS]; K]) -> [u8; K] {
    let mut t = [0u8; K];
    let mut k = 0;
    while k < K {
        t[k] = degree(&exp[k]);
        k += 1;
    }
    t
}

const fn fact_table<const K: usize>(exp: &[[u8; MAX_DIRS]; K]) -> [u32; K] {
    let mut t = [1u32; K];
    let mut k = 0;
    while k < K {
        let mut j = 0;
        while j < MAX_DIRS {
            let mut i = 2;
            while i <= exp[k][j] as u32 {
                t[k] *= i;
                i += 1;
            }
            j += 1;
        }
        k += 1;
    }
    t
}

const fn max_degree<const K: usize>(exp: &[[u8; MAX_DIRS]; K]) -> usize {
    degree(&exp[K - 1]) as usize
}

/// The truncated Taylor polynomial of `f(q + sum_j x_j w_j)` in the monomials of `B`:
/// coefficient `c[k]` of monomial `k` and its gradient `g[k]` with respect to the 6 local
/// coordinates of `q` (module doc).
#[derive(Clone, Copy, Debug)]
pub struct PolyJet<const K: usize, B> {
    /// The coefficients (`c[0]` the value).
    pub c: [f64; K],
    /// Their gradients with respect to the base point.
    pub g: [[f64; NV]; K],
    basis: PhantomData<B>,
}

impl<const K: usize, B: Basis<K>> PolyJet<K, B> {
    /// The polynomial with coefficients `c` and gradients `g`.
    #[inline(always)]
    pub(crate) fn from_parts(c: [f64; K], g: [[f64; NV]; K]) -> Self {
        PolyJet {
            c,
            g,
            basis: PhantomData,
        }
    }

    /// Independent variable `i` with the value `x` and the component `w[j]` along direction
    /// `j`: `x + sum_j w[j] x_j`, gradient `e_i` in the value.
    pub fn var(i: usize, x: f64, w: &[f64]) -> Self {
        let mut j = Self::cst(x);
        j.g[0][i] = 1.0;
        for (d, &wj) in w.iter().enumerate().take(B::ND) {
            j.c[B::LIN[d] as usize] = wj;
        }
        j
    }

    /// The mixed directional derivative of monomial `k`: `FACT[k] * c[k]`.
    #[inline(always)]
    pub fn derivative(&self, k: usize) -> f64 {
        B::FACT[k] as f64 * self.c[k]
    }

    /// `prod_j w_j^(e_j) / e_j!` for every monomial, from the components `w` of a linear
    /// polynomial along the directions (monomials of degree 1).
    #[inline(always)]
    pub fn powers(w: &[f64; MAX_DIRS]) -> [f64; K] {
        let mut p = [0.0; K];
        p[0] = 1.0;
        for k in 1..K {
            let e = &B::EXP[k];
            let mut j = 0;
            while e[j] == 0 {
                j += 1;
            }
            p[k] = p[B::DIV[k][j] as usize] * w[j] * INV[e[j] as usize];
        }
        p
    }

    /// `sin` and `cos` of `theta + sum_j w_j x_j` with `(sin theta, cos theta) = (sn, cs)`:
    /// coefficient `k` is `sin^(p)(theta) prod_j w_j^(e_j) / e_j!` (`p` its degree), and its
    /// derivative with respect to `theta` is `sin^(p+1)(theta)` times the same. Returns the
    /// coefficients and those derivatives, `[sin, d sin, cos, d cos]` (what a caller that seeds
    /// a linear argument itself, e.g. an angle variable, writes into the coefficients and the
    /// angle's gradient column).
    #[inline(always)]
    pub fn angle_series(w: &[f64; MAX_DIRS], sn: f64, cs: f64) -> [[f64; K]; 4] {
        let ds = [sn, cs, -sn, -cs];
        let dc = [cs, -sn, -cs, sn];
        let p = Self::powers(w);
        let mut out = [[0.0; K]; 4];
        for k in 0..K {
            let d = B::DEG[k] as usize;
            out[0][k] = ds[d % 4] * p[k];
            out[1][k] = ds[(d + 1) % 4] * p[k];
            out[2][k] = dc[d % 4] * p[k];
            out[3][k] = dc[(d + 1) % 4] * p[k];
        }
        out
    }

    /// `f(self)` for a function with the scaled derivatives `a[k] = f^(k)(x0) / k!` at the
    /// value `x0`, `k = 0..=MAX_DEG + 1`: `sum_k a_k d^k` with `d = self - x0` (nilpotent),
    /// the gradient of `a_k` being `(k + 1) a_(k+1) grad x0`.
    fn compose(self, a: &[f64; 6]) -> Self {
        let g0 = self.g[0];
        let mut d = self;
        d.c[0] = 0.0;
        d.g[0] = [0.0; NV];
        let mut out = Self::cst(a[0]);
        out.g[0] = g0.map(|x| a[1] * x);
        let mut pw = d;
        for k in 1..=B::MAX_DEG {
            let ga = (k + 1) as f64 * a[k + 1];
            for i in 0..K {
                out.c[i] += a[k] * pw.c[i];
                for l in 0..NV {
                    out.g[i][l] += a[k] * pw.g[i][l] + ga * pw.c[i] * g0[l];
                }
            }
            if k < B::MAX_DEG {
                pw = pw * d;
            }
        }
        out
    }
}

impl<const K: usize, B: Basis<K>> Add for PolyJet<K, B> {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, o: Self) -> Self {
        for k in 0..K {
            self.c[k] += o.c[k];
            for l in 0..NV {
                self.g[k][l] += o.g[k][l];
            }
        }
        self
    }
}
impl<const K: usize, B: Basis<K>> Sub for PolyJet<K, B> {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, o: Self) -> Self {
        for k in 0..K {
            self.c[k] -= o.c[k];
            for l in 0..NV {
                self.g[k][l] -= o.g[k][l];
            }
        }
        self
    }
}
impl<const K: usize, B: Basis<K>> Mul for PolyJet<K, B> {
    type Output = Self;
    /// The truncated product ([`Basis::PROD`]), with the product rule on every gradient.
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let mut p = [0.0; K];
        let mut gp = [[0.0; NV]; K];
        for i in 0..K {
            for j in 0..K {
                let k = B::PROD[i][j];
                if k == NONE {
                    continue;
                }
                let k = k as usize;
                p[k] += self.c[i] * o.c[j];
                for l in 0..NV {
                    gp[k][l] += o.c[j] * self.g[i][l] + self.c[i] * o.g[j][l];
                }
            }
        }
        Self::from_parts(p, gp)
    }
}
impl<const K: usize, B: Basis<K>> Mul<f64> for PolyJet<K, B> {
    type Output = Self;
    #[inline(always)]
    fn mul(mut self, s: f64) -> Self {
        for k in 0..K {
            self.c[k] *= s;
            for l in 0..NV {
                self.g[k][l] *= s;
            }
        }
        self
    }
}
impl<const K: usize, B: Basis<K>> Neg for PolyJet<K, B> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self * -1.0
    }
}
impl<const K: usize, B: Basis<K>> Add<f64> for PolyJet<K, B> {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, s: f64) -> Self {
        self.c[0] += s;
        self
    }
}
impl<const K: usize, B: Basis<K>> Sub<f64> for PolyJet<K, B> {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, s: f64) -> Self {
        self.c[0] -= s;
        self
    }
}

impl<const K: usize, B: Basis<K>> Scalar for PolyJet<K, B> {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        let mut c = [0.0; K];
        c[0] = v;
        Self::from_parts(c, [[0.0; NV]; K])
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (sn, cs) = self.c[0].sin_cos();
        self.sin_cos_with(sn, cs)
    }
    fn sin_cos_with(self, sn: f64, cs: f64) -> (Self, Self) {
        // a linear argument theta + sum_j w_j x_j whose coefficients carry no gradient (an
        // angle variable): the closed form of `angle_series` times the value's gradient
        let linear = (1..K).all(|k| (B::DEG[k] == 1 || self.c[k] == 0.0) && self.g[k] == [0.0; NV]);
        if linear {
            let mut w = [0.0; MAX_DIRS];
            for (j, wj) in w.iter_mut().enumerate().take(B::ND) {
                *wj = self.c[B::LIN[j] as usize];
            }
            let [sv, sd, cv, cd] = Self::angle_series(&w, sn, cs);
            let (mut s, mut c) = (Self::cst(0.0), Self::cst(0.0));
            let g0 = self.g[0];
            for k in 0..K {
                (s.c[k], c.c[k]) = (sv[k], cv[k]);
                for l in 0..NV {
                    s.g[k][l] = sd[k] * g0[l];
                    c.g[k][l] = cd[k] * g0[l];
                }
            }
            return (s, c);
        }
        let ds = [sn, cs, -sn, -cs];
        let dc = [cs, -sn, -cs, sn];
        let mut a = [0.0; 6];
        let mut b = [0.0; 6];
        let mut f = 1.0;
        for k in 0..6 {
            a[k] = ds[k % 4] / f;
            b[k] = dc[k % 4] / f;
            f *= (k + 1) as f64;
        }
        (self.compose(&a), self.compose(&b))
    }
    /// `sqrt(x0 + d) = sqrt(x0) sum_k binom(1/2, k) (d / x0)^k`.
    fn sqrt(self) -> Self {
        let x0 = self.c[0];
        let r = x0.sqrt();
        let mut a = [0.0; 6];
        let mut bin = 1.0;
        let mut p = r;
        for (k, ak) in a.iter_mut().enumerate() {
            *ak = bin * p;
            bin *= (0.5 - k as f64) / (k + 1) as f64;
            p /= x0;
        }
        self.compose(&a)
    }
}

#[cfg(test)]
#[path = "poly_tests.rs"]
mod tests;
