//! Small dense LU with partial pivoting on a flat buffer (row-major), allocation-free after
//! construction. Used for the `m x m` dependent block of `Phi_q` and the `dof x dof` metric,
//! where faer's general machinery costs more than the arithmetic.

/// `A = P L U` of an `n x n` matrix stored row-major; `solve` and `solve_transpose` in place.
#[derive(Clone, Debug)]
pub(crate) struct SmallLu {
    n: usize,
    a: Vec<f64>,
    piv: Vec<usize>,
}

impl SmallLu {
    pub(crate) fn new(n: usize) -> Self {
        SmallLu {
            n,
            a: vec![0.0; n * n],
            piv: vec![0; n],
        }
    }

    /// The matrix to factor, row-major (`a[r * n + c]`).
    #[inline]
    pub(crate) fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.a
    }

    /// Factors in place. Returns the smallest and largest pivot magnitudes, `Err(row)` for a
    /// zero (or non-finite) pivot.
    pub(crate) fn factor(&mut self) -> Result<(f64, f64), usize> {
        let n = self.n;
        let a = &mut self.a;
        let (mut pmin, mut pmax) = (f64::INFINITY, 0.0f64);
        for k in 0..n {
            let mut p = k;
            let mut best = a[k * n + k].abs();
            for r in k + 1..n {
                let v = a[r * n + k].abs();
                if v > best {
                    best = v;
                    p = r;
                }
            }
            if best.is_nan() || best <= 0.0 || !best.is_finite() {
                return Err(k);
            }
            self.piv[k] = p;
            if p != k {
                for c in 0..n {
                    a.swap(k * n + c, p * n + c);
                }
            }
            pmin = pmin.min(best);
            pmax = pmax.max(best);
            let inv = 1.0 / a[k * n + k];
            for r in k + 1..n {
                let l = a[r * n + k] * inv;
                a[r * n + k] = l;
                if l != 0.0 {
                    for c in k + 1..n {
                        a[r * n + c] -= l * a[k * n + c];
                    }
                }
            }
        }
        Ok((pmin, pmax))
    }

    /// `ln |det A|` of the last successful [`SmallLu::factor`]: the sum of the logarithms of
    /// the pivot magnitudes (no overflow or underflow for any size).
    pub(crate) fn log_abs_det(&self) -> f64 {
        (0..self.n).map(|k| self.a[k * self.n + k].abs().ln()).sum()
    }

    /// Solves `A x = b` in place.
    pub(crate) fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        let a = &self.a;
        for k in 0..n {
            let p = self.piv[k];
            if p != k {
                b.swap(k, p);
            }
        }
        for r in 0..n {
            let mut s = b[r];
            for c in 0..r {
                s -= a[r * n + c] * b[c];
            }
            b[r] = s;
        }
        for r in (0..n).rev() {
            let mut s = b[r];
            for c in r + 1..n {
                s -= a[r * n + c] * b[c];
            }
            b[r] = s / a[r * n + r];
        }
    }

    /// Solves `A^T x = b` in place.
    pub(crate) fn solve_transpose(&self, b: &mut [f64]) {
        let n = self.n;
        let a = &self.a;
        // A = P^T L U (rows swapped by piv), so A^T = U^T L^T P: solve U^T y = b, L^T w = y,
        // then x = P^T w.
        for c in 0..n {
            let mut s = b[c];
            for r in 0..c {
                s -= a[r * n + c] * b[r];
            }
            b[c] = s / a[c * n + c];
        }
        for c in (0..n).rev() {
            let mut s = b[c];
            for r in c + 1..n {
                s -= a[r * n + c] * b[r];
            }
            b[c] = s;
        }
        for k in (0..n).rev() {
            let p = self.piv[k];
            if p != k {
                b.swap(k, p);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_and_transposed_solves() {
        let m = [
            0.1, 2.0, -1.0, 0.5, //
            3.0, 0.2, 0.0, 1.0, //
            -1.0, 0.5, 4.0, 0.0, //
            0.0, 1.0, 1.0, -2.0,
        ];
        let mut lu = SmallLu::new(4);
        lu.matrix_mut().copy_from_slice(&m);
        lu.factor().unwrap();
        // ln|det| against the determinant by cofactor expansion along the first row
        let det = {
            let d3 = |a: [f64; 9]| {
                a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6])
                    + a[2] * (a[3] * a[7] - a[4] * a[6])
            };
            let minor = |c: usize| {
                let mut out = [0.0; 9];
                let mut k = 0;
                for r in 1..4 {
                    for cc in (0..4).filter(|&cc| cc != c) {
                        out[k] = m[r * 4 + cc];
                        k += 1;
                    }
                }
                d3(out)
            };
            (0..4)
                .map(|c| if c % 2 == 0 { 1.0 } else { -1.0 } * m[c] * minor(c))
                .sum::<f64>()
        };
        assert!((lu.log_abs_det() - det.abs().ln()).abs() < 1e-13, "{det}");
        let x = [1.0, -2.0, 0.5, 3.0];
        let mut b: Vec<f64> = (0..4)
            .map(|r| (0..4).map(|c| m[r * 4 + c] * x[c]).sum())
            .collect();
        lu.solve(&mut b);
        for i in 0..4 {
            assert!((b[i] - x[i]).abs() < 1e-13, "{b:?}");
        }
        let mut bt: Vec<f64> = (0..4)
            .map(|c| (0..4).map(|r| m[r * 4 + c] * x[r]).sum())
            .collect();
        lu.solve_transpose(&mut bt);
        for i in 0..4 {
            assert!((bt[i] - x[i]).abs() < 1e-13, "{bt:?}");
        }
        let mut s = SmallLu::new(2);
        s.matrix_mut().copy_from_slice(&[1.0, 2.0, 2.0, 4.0]);
        assert!(s.factor().is_err());
    }
}
