//! [`Taylor4`]: the truncated Taylor series of `t -> f(q + t w)` to degree 4 (no gradients), so
//! the directional derivatives `D^k f(q)(w, ..., w)`, `k <= 4`, come out of one forward
//! evaluation; mixed contractions follow by polarisation.

use super::Scalar;
use std::ops::{Add, Mul, Sub};

/// Degree of the truncated series.
pub const TAYLOR_DEGREE: usize = 4;

/// `f(q + t w) = v + c[0] t + c[1] t^2 + c[2] t^3 + c[3] t^4 + O(t^5)`: the coefficient of
/// `t^k` is `D^k f(q)(w, ..., w) / k!`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Taylor4 {
    /// Value (`t^0`).
    pub v: f64,
    /// Coefficients of `t^1 .. t^4`.
    pub c: [f64; TAYLOR_DEGREE],
}

impl Taylor4 {
    /// The variable `x + t w`.
    #[inline(always)]
    pub fn var(x: f64, w: f64) -> Self {
        Taylor4 {
            v: x,
            c: [w, 0.0, 0.0, 0.0],
        }
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
    /// The directional derivative `D^k f(w, ..., w) = k! * coefficient k`.
    #[inline(always)]
    pub fn derivative(&self, k: usize) -> f64 {
        let fact = [1.0, 1.0, 2.0, 6.0, 24.0];
        fact[k] * self.coef(k)
    }
    fn from_coefs(a: [f64; TAYLOR_DEGREE + 1]) -> Self {
        Taylor4 {
            v: a[0],
            c: [a[1], a[2], a[3], a[4]],
        }
    }
    fn coefs(&self) -> [f64; TAYLOR_DEGREE + 1] {
        [self.v, self.c[0], self.c[1], self.c[2], self.c[3]]
    }
    /// `(sin x, cos x)` by the recurrences `k s_k = sum_j j x_j c_(k-j)`,
    /// `k c_k = -sum_j j x_j s_(k-j)` (the general case of `sin_cos`).
    #[cfg(test)]
    pub(crate) fn sin_cos_series(self) -> (Self, Self) {
        let (s0, c0) = self.v.sin_cos();
        self.sin_cos_series_with(s0, c0)
    }
    /// [`Taylor4::sin_cos_series`] given `sin` and `cos` of the value.
    #[inline(always)]
    fn sin_cos_series_with(self, s0: f64, c0: f64) -> (Self, Self) {
        let x = self.coefs();
        let (mut s, mut c) = ([0.0; TAYLOR_DEGREE + 1], [0.0; TAYLOR_DEGREE + 1]);
        (s[0], c[0]) = (s0, c0);
        for k in 1..=TAYLOR_DEGREE {
            let (mut ds, mut dc) = (0.0, 0.0);
            for j in 1..=k {
                ds += j as f64 * x[j] * c[k - j];
                dc -= j as f64 * x[j] * s[k - j];
            }
            s[k] = ds / k as f64;
            c[k] = dc / k as f64;
        }
        (Taylor4::from_coefs(s), Taylor4::from_coefs(c))
    }
}

impl Add for Taylor4 {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        for k in 0..TAYLOR_DEGREE {
            self.c[k] += o.c[k];
        }
        self
    }
}
impl Sub for Taylor4 {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, o: Self) -> Self {
        self.v -= o.v;
        for k in 0..TAYLOR_DEGREE {
            self.c[k] -= o.c[k];
        }
        self
    }
}
impl Mul for Taylor4 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let (a, b) = (self.coefs(), o.coefs());
        let mut p = [0.0; TAYLOR_DEGREE + 1];
        for (i, &ai) in a.iter().enumerate() {
            for (j, &bj) in b.iter().enumerate().take(TAYLOR_DEGREE + 1 - i) {
                p[i + j] += ai * bj;
            }
        }
        Taylor4::from_coefs(p)
    }
}
impl Mul<f64> for Taylor4 {
    type Output = Self;
    #[inline(always)]
    fn mul(mut self, k: f64) -> Self {
        self.v *= k;
        for c in self.c.iter_mut() {
            *c *= k;
        }
        self
    }
}
super::scalar_shift_ops!(Taylor4);
impl Scalar for Taylor4 {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        Taylor4 {
            v,
            c: [0.0; TAYLOR_DEGREE],
        }
    }
    /// `s' = c x'`, `c' = -s x'` coefficient by coefficient:
    /// `k s_k = sum_(j=1..k) j x_j c_(k-j)`, `k c_k = -sum_(j=1..k) j x_j s_(k-j)`.
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (sn, cs) = self.v.sin_cos();
        self.sin_cos_with(sn, cs)
    }
    #[inline(always)]
    fn sin_cos_with(self, sn: f64, cs: f64) -> (Self, Self) {
        let x = self.coefs();
        if x[2..].iter().all(|&a| a == 0.0) {
            // a variable theta + t w (an angle variable): coefficients sin^(k)(theta) w^k / k!
            let ds = [sn, cs, -sn, -cs];
            let dc = [cs, -sn, -cs, sn];
            let (mut s, mut c) = ([0.0; TAYLOR_DEGREE + 1], [0.0; TAYLOR_DEGREE + 1]);
            let mut p = 1.0;
            for k in 0..=TAYLOR_DEGREE {
                s[k] = ds[k % 4] * p;
                c[k] = dc[k % 4] * p;
                p *= x[1] / (k + 1) as f64;
            }
            return (Taylor4::from_coefs(s), Taylor4::from_coefs(c));
        }
        self.sin_cos_series_with(sn, cs)
    }
    /// `r^2 = x`: `r_k = (x_k - sum_(j=1..k-1) r_j r_(k-j)) / (2 r_0)`.
    #[inline(always)]
    fn sqrt(self) -> Self {
        let x = self.coefs();
        let mut r = [0.0; TAYLOR_DEGREE + 1];
        r[0] = x[0].sqrt();
        for k in 1..=TAYLOR_DEGREE {
            let mut acc = x[k];
            for j in 1..k {
                acc -= r[j] * r[k - j];
            }
            r[k] = acc / (2.0 * r[0]);
        }
        Taylor4::from_coefs(r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The series of a composite function against its closed-form derivatives:
    /// `f(t) = sin(x) * sqrt(y) + x y^2` with `x = 0.3 + 0.7 t`, `y = 1.2 - 0.4 t`.
    #[test]
    fn series_match_closed_form_derivatives() {
        let (x, y) = (Taylor4::var(0.3, 0.7), Taylor4::var(1.2, -0.4));
        let f = x.sin_cos().0 * y.sqrt() + x * y * y;
        // the same function of t by central differences of high order, at t = 0
        let g = |t: f64| {
            let (x, y) = (0.3 + 0.7 * t, 1.2 - 0.4 * t);
            x.sin() * y.sqrt() + x * y * y
        };
        let h = 1e-2;
        let d = |k: usize| -> f64 {
            // central differences of order h^4 for the derivatives 1..4
            match k {
                1 => (-g(2.0 * h) + 8.0 * g(h) - 8.0 * g(-h) + g(-2.0 * h)) / (12.0 * h),
                2 => {
                    (-g(2.0 * h) + 16.0 * g(h) - 30.0 * g(0.0) + 16.0 * g(-h) - g(-2.0 * h))
                        / (12.0 * h * h)
                }
                3 => {
                    (-g(3.0 * h) + 8.0 * g(2.0 * h) - 13.0 * g(h) + 13.0 * g(-h)
                        - 8.0 * g(-2.0 * h)
                        + g(-3.0 * h))
                        / (8.0 * h * h * h)
                }
                _ => {
                    (-g(3.0 * h) + 12.0 * g(2.0 * h) - 39.0 * g(h) + 56.0 * g(0.0) - 39.0 * g(-h)
                        + 12.0 * g(-2.0 * h)
                        - g(-3.0 * h))
                        / (6.0 * h.powi(4))
                }
            }
        };
        assert!((f.derivative(0) - g(0.0)).abs() < 1e-15);
        for k in 1..=4 {
            let (a, b) = (f.derivative(k), d(k));
            assert!(
                (a - b).abs() < 1e-6 * (1.0 + b.abs()),
                "order {k}: {a} vs {b}"
            );
        }
    }

    /// The closed form for a variable `theta + t w` (an angle variable) against the general
    /// recurrence.
    #[test]
    fn sin_cos_of_a_variable_matches_the_recurrence() {
        for (x, w) in [(0.3, 1.7), (-2.1, -0.4), (5.0, 0.0)] {
            let t = Taylor4::var(x, w);
            let (a, b) = (t.sin_cos(), t.sin_cos_series());
            for k in 0..=TAYLOR_DEGREE {
                assert!((a.0.coef(k) - b.0.coef(k)).abs() < 1e-14, "sin {k}");
                assert!((a.1.coef(k) - b.1.coef(k)).abs() < 1e-14, "cos {k}");
            }
        }
    }
}
