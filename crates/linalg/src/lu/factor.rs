//! The numeric factorisation of [`DenseLu`]: the static path over the symbolic pattern, the
//! equilibration's scale factors, and the general path (threshold partial pivoting).

use super::{DenseLu, PIVOT_THRESHOLD};
use crate::{pow2_inverse, LuError};

impl DenseLu {
    /// Factors the matrix in place (singularity tests on the equilibrated matrix, see the
    /// module docs). Errors name the entry, row or unknown at fault in the caller's numbering.
    pub fn factor_lu(&mut self) -> Result<(), LuError> {
        let n = self.n;
        self.factored = false;
        if self.raw {
            // written directly: every nonzero joins the pattern
            for (k, &v) in self.f.iter().enumerate() {
                if v != 0.0 && !self.mask[k] {
                    self.mask[k] = true;
                    self.dirty = true;
                }
            }
            self.raw = false;
        }
        if self.dirty {
            self.analyse();
        }
        // the entries outside the pattern are zero: the largest entry and the copy for the
        // fallback need only the pattern's
        let mut gmax = 0.0f64;
        // (a NaN or infinite entry makes the sum non-finite; so can an overflow, which the
        // search below then does not confirm)
        let mut sum = 0.0f64;
        for (b, &k) in self.backup.iter_mut().zip(&self.nz[..self.n_nz]) {
            let v = self.f[k];
            *b = v;
            let a = v.abs();
            sum += a;
            if a > gmax {
                gmax = a;
            }
        }
        if !sum.is_finite() {
            let bad = self.nz[..self.n_nz]
                .iter()
                .find(|&&k| !self.f[k].is_finite());
            if let Some(&k) = bad {
                return Err(LuError::NonFinite {
                    row: self.rows[k / n],
                    col: self.cols[k % n],
                });
            }
        }
        self.scaled = false;
        let tol = self.pivot_tol * n as f64;
        for (k, r) in self.rp.iter_mut().enumerate() {
            *r = k;
        }
        if self.factor_static(tol, gmax)? {
            self.static_used = true;
            self.factored = true;
            return Ok(());
        }
        self.fallbacks += 1;
        self.dropped.clear();
        self.f.fill(0.0);
        for (&b, &k) in self.backup.iter().zip(&self.nz[..self.n_nz]) {
            self.f[k] = b;
        }
        self.static_used = false;
        self.equilibrate()?;
        self.factor_dynamic(tol)
            .map_err(|(i, k)| LuError::Singular {
                row: self.rows[i],
                col: self.cols[k],
            })?;
        self.factored = true;
        Ok(())
    }

    /// The scale factors of the equilibration (from `backup`, the matrix before elimination),
    /// once per factorisation: row by row, the row's largest entry and its scale factor, then
    /// the column maxima of the row-scaled matrix. An all-zero row or column is an error.
    fn equilibrate(&mut self) -> Result<(), LuError> {
        if self.scaled {
            return Ok(());
        }
        let (nz_col, backup) = (&self.nz_col, &self.backup);
        let cmax = &mut self.cmax;
        cmax.fill(0.0);
        for (i, (w, r)) in self
            .nz_start
            .windows(2)
            .zip(self.rscale.iter_mut())
            .enumerate()
        {
            let row = &backup[w[0]..w[1]];
            let mx = row.iter().fold(0.0f64, |m, b| m.max(b.abs()));
            if mx == 0.0 {
                return Err(LuError::Singular {
                    row: self.rows[i],
                    col: self.cols[i],
                });
            }
            let sc = pow2_inverse(mx);
            *r = sc;
            for (&b, &j) in row.iter().zip(&nz_col[w[0]..w[1]]) {
                let c = &mut cmax[j];
                *c = c.max(b.abs() * sc);
            }
        }
        for (j, (sc, &mx)) in self.cscale.iter_mut().zip(cmax.iter()).enumerate() {
            if mx == 0.0 {
                return Err(LuError::Singular {
                    row: self.rows[j],
                    col: self.cols[j],
                });
            }
            *sc = pow2_inverse(mx);
        }
        self.scaled = true;
        self.equilibrations += 1;
        Ok(())
    }

    /// Elimination with the static diagonal pivots over the symbolic pattern; `Ok(false)`
    /// (with the matrix partly eliminated) if a pivot fails the threshold test (at least
    /// `PIVOT_THRESHOLD` times the largest entry below it) or the singularity test.
    ///
    /// The singularity test is `|u_kk| r_k c_k > tol` in the equilibrated matrix. Since every
    /// entry of the row-scaled matrix is below 1, `c_k >= 1/2`, and `r_k > 1 / (2 max |A|)`,
    /// so `|u_kk| > 4 tol max |A|` passes it without the scale factors, which are computed
    /// only when a pivot is smaller than that (on the papers' models: at h below about 1e-4).
    fn factor_static(&mut self, tol: f64, gmax: f64) -> Result<bool, LuError> {
        let n = self.n;
        let sure = 4.0 * tol * gmax;
        let dep_tol = crate::DEPENDENT_PIVOT_TOL * n as f64;
        self.dropped.clear();
        for k in 0..n {
            let piv = self.f[k * n + k];
            let pa = piv.abs();
            if pa.is_nan() {
                return Ok(false);
            }
            if k >= self.drop_from
                && self.dropped.len() < self.drop_max
                && pa <= 4.0 * dep_tol * gmax
            {
                self.equilibrate()?;
                if pa * self.rscale[k] * self.cscale[k] <= dep_tol {
                    // a dependent row: its unknown is zero and nothing is eliminated with it
                    self.dropped.push(k);
                    self.dinv[k] = 0.0;
                    let p = &self.symbolic;
                    self.l_val[p.l_start[k]..p.l_start[k + 1]].fill(0.0);
                    self.u_val[p.u_start[k]..p.u_start[k + 1]].fill(0.0);
                    continue;
                }
            }
            if pa <= sure {
                self.equilibrate()?;
                if pa * self.rscale[k] * self.cscale[k] <= tol {
                    return Ok(false);
                }
            }
            let (a, p) = (&mut self.f, &self.symbolic);
            let (l_val, u_val, dinv) = (&mut self.l_val, &mut self.u_val, &mut self.dinv);
            let (ls, le) = (p.l_start[k], p.l_start[k + 1]);
            let lrows = &p.l_idx[ls..le];
            // (the entries were checked finite; a NaN from an overflow in the elimination,
            // which `max` would skip here, reaches a later pivot through the multipliers and
            // fails its test)
            let colmax = lrows.iter().fold(0.0f64, |m, &i| m.max(a[i * n + k].abs()));
            if pa < PIVOT_THRESHOLD * colmax {
                return Ok(false);
            }
            let (us, ue) = (p.u_start[k], p.u_start[k + 1]);
            let ucols = &p.u_idx[us..ue];
            for (v, &j) in u_val[us..ue].iter_mut().zip(ucols) {
                *v = a[k * n + j];
            }
            let uv = &u_val[us..ue];
            let inv = 1.0 / piv;
            dinv[k] = inv;
            for (lv, &i) in l_val[ls..le].iter_mut().zip(lrows) {
                let row = &mut a[i * n..(i + 1) * n];
                let f = row[k] * inv;
                *lv = f;
                if f != 0.0 {
                    for (&j, &v) in ucols.iter().zip(uv) {
                        row[j] -= f * v;
                    }
                }
            }
        }
        Ok(true)
    }

    /// Threshold partial pivoting, recording the nonzeros of `L` and `U`; `Err((i, k))` if
    /// column `k` has no usable pivot (`i`: the physical row at position `k`).
    ///
    /// Droppable columns (see [`DenseLu::set_droppable`]) whose best scaled pivot is at most
    /// [`crate::DEPENDENT_PIVOT_TOL`] `n` are dropped as on the static path: the reduced
    /// column is zero, so the column depends on the earlier ones; its unknown is zero and no
    /// row is consumed for it. The rows left over at the end (one per dropped column) are the
    /// dependent equations: after the elimination they are zero, and they are left out.
    fn factor_dynamic(&mut self, tol: f64) -> Result<(), (usize, usize)> {
        let n = self.n;
        let dep_tol = crate::DEPENDENT_PIVOT_TOL * n as f64;
        let a = &mut self.f;
        let p = &mut self.dynamic;
        for (k, r) in self.rp.iter_mut().enumerate() {
            *r = k;
        }
        // pivot row of each column (usize::MAX: dropped), chosen from positions r..n
        let prow = &mut self.prow;
        let mut r = 0;
        let (mut nl, mut nu) = (0, 0);
        let (rs, cs) = (&self.rscale, &self.cscale);
        for k in 0..n {
            // scaled partial pivoting: magnitudes in the equilibrated matrix
            let (mut piv, mut best, mut diag) = (r, f64::NAN, 0.0);
            if r < n {
                diag = a[self.rp[r] * n + k].abs() * rs[self.rp[r]];
                best = diag;
                for i in r + 1..n {
                    let v = a[self.rp[i] * n + k].abs() * rs[self.rp[i]];
                    // (a NaN is taken, and fails the test below)
                    if v > best || v.is_nan() {
                        best = v;
                        piv = i;
                    }
                }
            }
            let droppable = k >= self.drop_from && self.dropped.len() < self.drop_max;
            let negligible = r == n || (!best.is_nan() && best * cs[k] <= dep_tol);
            if droppable && negligible {
                self.dropped.push(k);
                self.dinv[k] = 0.0;
                prow[k] = usize::MAX;
                p.u_start[k] = nu;
                p.l_start[k] = nl;
                continue;
            }
            if r == n || best.is_nan() || best * cs[k] <= tol {
                return Err((self.rp[piv.min(n - 1)], k));
            }
            if diag < PIVOT_THRESHOLD * best {
                self.rp.swap(r, piv);
            }
            let pk = self.rp[r];
            prow[k] = pk;
            // the nonzeros of the pivot row right of the diagonal: the row of U
            p.u_start[k] = nu;
            for (j, &v) in a[pk * n..(pk + 1) * n].iter().enumerate().skip(k + 1) {
                if v != 0.0 {
                    p.u_idx[nu] = j;
                    self.u_val[nu] = v;
                    nu += 1;
                }
            }
            let uc = &p.u_idx[p.u_start[k]..nu];
            let uv = &self.u_val[p.u_start[k]..nu];
            let inv = 1.0 / a[pk * n + k];
            self.dinv[k] = inv;
            p.l_start[k] = nl;
            for &ph in &self.rp[r + 1..] {
                let row = &mut a[ph * n..(ph + 1) * n];
                let f = row[k];
                if f != 0.0 {
                    let f = f * inv;
                    for (&j, &v) in uc.iter().zip(uv) {
                        row[j] -= f * v;
                    }
                    p.l_idx[nl] = ph;
                    self.l_val[nl] = f;
                    nl += 1;
                }
            }
            r += 1;
        }
        p.l_start[n] = nl;
        p.u_start[n] = nu;
        if !self.dropped.is_empty() {
            // pivot k is physical row rp[k]; a dropped column takes a left-over row (its
            // solve reads that row's value and multiplies it by dinv = 0)
            let mut left = r;
            for pr in prow.iter_mut() {
                if *pr == usize::MAX {
                    *pr = self.rp[left];
                    left += 1;
                }
            }
            self.rp.copy_from_slice(prow);
        }
        Ok(())
    }
}
