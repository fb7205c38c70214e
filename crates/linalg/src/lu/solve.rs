//! The triangular solves of [`DenseLu`] (`A x = b` and `A^T x = b`) over the recorded
//! nonzeros of `L` and `U`.

use super::DenseLu;

impl DenseLu {
    /// Solves `A x = b` in place after a successful factorisation (`b` and `x` in the
    /// caller's numbering; without one, `b` is left unchanged).
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        let (mut y, mut x) = (std::mem::take(&mut self.y), std::mem::take(&mut self.x));
        self.solve_with(b, &mut y, &mut x);
        (self.y, self.x) = (y, x);
    }

    /// [`DenseLu::solve_in_place`] through a shared reference, with the caller's workspace
    /// (`y` and `x` of length at least `n`).
    pub fn solve_with(&self, b: &mut [f64], y: &mut [f64], x: &mut [f64]) {
        let n = self.n;
        if !self.factored || b.len() != n || y.len() < n || x.len() < n {
            return;
        }
        let rp = &self.rp;
        let p = if self.static_used {
            &self.symbolic
        } else {
            &self.dynamic
        };
        for (yi, &r) in y.iter_mut().zip(&self.rows) {
            *yi = b[r];
        }
        // forward: L z = P y, column by column (z_k ends in y[rp[k]])
        for k in 0..n {
            let yk = y[rp[k]];
            if yk != 0.0 {
                let (ls, le) = (p.l_start[k], p.l_start[k + 1]);
                for (&ph, &l) in p.l_idx[ls..le].iter().zip(&self.l_val[ls..le]) {
                    y[ph] -= l * yk;
                }
            }
        }
        // backward: U x = z, row by row
        for k in (0..n).rev() {
            let (us, ue) = (p.u_start[k], p.u_start[k + 1]);
            let mut s = 0.0;
            for (&j, &u) in p.u_idx[us..ue].iter().zip(&self.u_val[us..ue]) {
                s += u * x[j];
            }
            x[k] = (y[rp[k]] - s) * self.dinv[k];
        }
        for (&xj, &c) in x.iter().zip(&self.cols) {
            b[c] = xj;
        }
    }

    /// Solves `A^T x = b` in place after a successful factorisation (`b` and `x` in the
    /// caller's numbering; without one, `b` is left unchanged).
    pub fn solve_transpose_in_place(&mut self, b: &mut [f64]) {
        let n = self.n;
        if !self.factored || b.len() != n {
            return;
        }
        let (y, x, rp) = (&mut self.y, &mut self.x, &self.rp);
        let p = if self.static_used {
            &self.symbolic
        } else {
            &self.dynamic
        };
        // the ordered matrix is B = P^T L U (P: pivot k is physical row rp[k]), so
        // B^T = U^T L^T P: U^T w = d, then L^T v = w, then y = P^T v
        for (xj, &c) in x.iter_mut().zip(&self.cols) {
            *xj = b[c];
        }
        for k in 0..n {
            let wk = x[k] * self.dinv[k];
            x[k] = wk;
            if wk != 0.0 {
                let (us, ue) = (p.u_start[k], p.u_start[k + 1]);
                for (&j, &u) in p.u_idx[us..ue].iter().zip(&self.u_val[us..ue]) {
                    x[j] -= u * wk;
                }
            }
        }
        // L^T v = w backwards, v kept by physical row (L's rows are physical)
        for k in (0..n).rev() {
            let (ls, le) = (p.l_start[k], p.l_start[k + 1]);
            let mut v = x[k];
            for (&ph, &l) in p.l_idx[ls..le].iter().zip(&self.l_val[ls..le]) {
                v -= l * y[ph];
            }
            y[rp[k]] = v;
        }
        for (&yi, &r) in y.iter().zip(&self.rows) {
            b[r] = yi;
        }
    }
}
