//! The Cholesky factor of the small `m x m` matrix `S = Phi_q M^-1 Phi_q^T` of the
//! preadjustment workspaces: inline loops for `m <= SMALL`, [`DenseCholesky`] above. The
//! preadjusted steps factor `S` at every new point and solve with it several times per point;
//! for the few dozen constraints of a planar mechanism the inline loops cost a fraction of a
//! general solver's call overhead.

use mbd_solve::linalg::{DenseCholesky, CHOLESKY_PIVOT_TOL};

/// Largest `m` factored by the inline loops.
const SMALL: usize = 64;

#[derive(Debug)]
pub(crate) struct SmallCholesky {
    m: usize,
    /// Column-major; the lower triangle holds `S`, then its factor `L`.
    a: Vec<f64>,
    diag: Vec<f64>,
    big: Option<DenseCholesky>,
}

/// The factorisation failed: `S` is not (numerically) positive definite.
#[derive(Debug)]
pub(crate) struct NotPositiveDefinite;

impl SmallCholesky {
    pub(crate) fn new(m: usize) -> Self {
        SmallCholesky {
            m,
            a: vec![0.0; m * m],
            diag: vec![0.0; m],
            big: (m > SMALL).then(|| DenseCholesky::new(m)),
        }
    }

    /// Zeroes the lower triangle (before the entries are summed in with [`Self::add`]).
    pub(crate) fn clear(&mut self) {
        self.a.fill(0.0);
    }

    /// `S_rc += v` for `r >= c`.
    #[inline]
    pub(crate) fn add(&mut self, r: usize, c: usize, v: f64) {
        self.a[r + c * self.m] += v;
    }

    /// Factors `S = L L^T` in place; fails where [`DenseCholesky`] would (a pivot with
    /// `L_jj^2 < CHOLESKY_PIVOT_TOL * S_jj`, or not positive).
    pub(crate) fn factor(&mut self) -> Result<(), NotPositiveDefinite> {
        let m = self.m;
        if let Some(big) = &mut self.big {
            {
                let mut sm = big.matrix_mut();
                for c in 0..m {
                    for r in c..m {
                        sm[(r, c)] = self.a[r + c * m];
                    }
                }
            }
            return big.factor_in_place().map_err(|_| NotPositiveDefinite);
        }
        let a = &mut self.a;
        for j in 0..m {
            let d0 = a[j + j * m];
            if !(d0 > 0.0 && d0.is_finite()) {
                return Err(NotPositiveDefinite);
            }
            self.diag[j] = d0;
            let (head, tail) = a.split_at_mut(j * m);
            let rowj = |k: usize| head[j + k * m];
            let mut d = d0;
            for k in 0..j {
                let l = rowj(k);
                d -= l * l;
            }
            // (NaN-safe: a NaN fails both comparisons)
            let pivot_ok = d > 0.0 && d0 / d * CHOLESKY_PIVOT_TOL <= 1.0;
            if !pivot_ok {
                return Err(NotPositiveDefinite);
            }
            let ljj = d.sqrt();
            tail[j] = ljj;
            let inv = 1.0 / ljj;
            for i in j + 1..m {
                let mut x = tail[i];
                for k in 0..j {
                    x -= head[i + k * m] * head[j + k * m];
                }
                tail[i] = x * inv;
            }
        }
        Ok(())
    }

    /// `b <- L^-1 b` after [`Self::factor`] (so `x^T S^-1 y = (L^-1 x) . (L^-1 y)`); only
    /// when [`Self::has_factor`].
    pub(crate) fn forward(&self, b: &mut [f64]) {
        debug_assert!(self.big.is_none());
        let (m, a) = (self.m, &self.a);
        for i in 0..m {
            let mut x = b[i];
            for k in 0..i {
                x -= a[i + k * m] * b[k];
            }
            b[i] = x / a[i + i * m];
        }
    }

    /// Whether the triangular factor is at hand for [`Self::forward`] (the inline size).
    pub(crate) fn has_factor(&self) -> bool {
        self.big.is_none()
    }

    /// `b <- S^-1 b` after [`Self::factor`].
    pub(crate) fn solve(&mut self, b: &mut [f64]) {
        let m = self.m;
        if let Some(big) = &mut self.big {
            big.solve_in_place(b);
            return;
        }
        let a = &self.a;
        for i in 0..m {
            let mut x = b[i];
            for k in 0..i {
                x -= a[i + k * m] * b[k];
            }
            b[i] = x / a[i + i * m];
        }
        for i in (0..m).rev() {
            let mut x = b[i];
            for k in i + 1..m {
                x -= a[k + i * m] * b[k];
            }
            b[i] = x / a[i + i * m];
        }
    }
}
