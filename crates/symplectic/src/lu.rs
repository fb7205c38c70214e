//! A small dense LU with partial pivoting on a preallocated row-major buffer (no dispatch
//! overhead for the 10-100 unknowns of the stage equations).

/// Dot product with four independent accumulators (breaks the add-latency chain).
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 4];
    let (ac, bc) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ar, br) = (ac.remainder(), bc.remainder());
    for (x, y) in ac.zip(bc) {
        acc[0] += x[0] * y[0];
        acc[1] += x[1] * y[1];
        acc[2] += x[2] * y[2];
        acc[3] += x[3] * y[3];
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (x, y) in ar.iter().zip(br) {
        s += x * y;
    }
    s
}

/// LU of an `n x n` matrix, row-major, factored in place.
#[derive(Clone, Debug)]
pub(crate) struct SmallLu {
    n: usize,
    pub a: Vec<f64>,
    perm: Vec<usize>,
}

impl SmallLu {
    pub fn new(n: usize) -> Self {
        SmallLu {
            n,
            a: vec![0.0; n * n],
            perm: vec![0; n],
        }
    }

    /// Factors `a` in place; `Err(i)` if pivot `i` is negligible.
    pub fn factor(&mut self) -> Result<(), usize> {
        let n = self.n;
        let a = &mut self.a;
        let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let tol = 1e-14 * scale.max(f64::MIN_POSITIVE) * n as f64;
        for k in 0..n {
            let mut p = k;
            let mut best = a[k * n + k].abs();
            for i in k + 1..n {
                let v = a[i * n + k].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            self.perm[k] = p;
            if best.is_nan() || best <= tol {
                return Err(k);
            }
            if p != k {
                let (lo, hi) = a.split_at_mut(p * n);
                lo[k * n..(k + 1) * n].swap_with_slice(&mut hi[..n]);
            }
            let inv = 1.0 / a[k * n + k];
            let (top, bottom) = a.split_at_mut((k + 1) * n);
            let rowk = &top[k * n..(k + 1) * n];
            for i in 0..n - k - 1 {
                let row = &mut bottom[i * n..(i + 1) * n];
                let f = row[k] * inv;
                row[k] = f;
                if f != 0.0 {
                    for (r, &p) in row[k + 1..].iter_mut().zip(&rowk[k + 1..]) {
                        *r -= f * p;
                    }
                }
            }
        }
        Ok(())
    }

    /// Solves `A x = b` in place after [`SmallLu::factor`].
    pub fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        let a = &self.a;
        for k in 0..n {
            let p = self.perm[k];
            if p != k {
                b.swap(k, p);
            }
        }
        for i in 0..n {
            let row = &a[i * n..i * n + i];
            let s = dot(row, &b[..i]);
            b[i] -= s;
        }
        for i in (0..n).rev() {
            let row = &a[i * n + i + 1..(i + 1) * n];
            let s = dot(row, &b[i + 1..]);
            b[i] = (b[i] - s) / a[i * n + i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn solves_with_pivoting() {
        let mut lu = SmallLu::new(3);
        lu.a.copy_from_slice(&[0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0]);
        let a = lu.a.clone();
        lu.factor().unwrap();
        let x = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| a[i * 3 + j] * x[j]).sum())
            .collect();
        lu.solve(&mut b);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
        }
        let mut s = SmallLu::new(2);
        s.a.copy_from_slice(&[1.0, 2.0, 2.0, 4.0]);
        assert!(s.factor().is_err());
    }
}
