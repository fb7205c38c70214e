//! The constraint rows a dense chart works with. A mechanism with `k` redundant equations
//! (`System::n_redundant`) has `rank Phi_q = m - k`: the chart needs `m - k` independent rows,
//! and which rows are independent can change along the motion (a double parallelogram's third
//! pin drops its `x` row where its crank is vertical and its `y` row elsewhere). So each centre
//! chooses them afresh: `S = Phi_q M^-1 Phi_q^T` at the centre is factored by the semidefinite
//! Cholesky with diagonal pivoting (`DenseCholesky::set_max_dependent(k)` and
//! `set_always_pivot`), which takes the rows in the order of how much of each the rows already
//! taken leave unexplained and drops the `k` left at round-off, and the chart keeps the others
//! until its next centre. The chart's manifold is unchanged: near the centre the kept equations
//! imply the dropped ones (they hold identically on the constraint manifold, and the kept rows
//! span the same row space). Near a singular configuration the choice matters: kept rows that
//! are themselves nearly dependent imply a dropped row only through coefficients of the order
//! of one over their distance from dependence, so a residual at the tolerance in the kept rows
//! leaves a large one in the dropped row (the natural order, which drops the last row of each
//! dependent set, left a velocity residual of 1.8e-4 in a triple parallelogram's redundant row
//! 1.5e-6 rad from its flat position); the pivoting keeps the best-conditioned set it finds.
//!
//! Without redundancy (`k = 0`) every evaluation goes straight into the chart's buffers.

use mbd_model::{BodyAngles, System};
use mbd_solve::linalg::DenseCholesky;
use nalgebra::DMatrix;

/// The row selection and the full-size scratch it evaluates into.
#[derive(Debug)]
pub(crate) struct RowSelection {
    /// Redundant equations of the model (0: the identity selection).
    k: usize,
    /// The model's equations `m` and the kept rows (`m - k`, increasing).
    m_full: usize,
    rows: Vec<usize>,
    /// Full-size `Phi_q`, `(Phi_q v)_q`, `Phi`, `Phi_q v + Phi_t` (allocated only if `k > 0`).
    pq: DMatrix<f64>,
    dp: DMatrix<f64>,
    p: Vec<f64>,
    pd: Vec<f64>,
    /// `M^-1` and the factorisation that finds the dependent rows.
    minv: Vec<f64>,
    chol: DenseCholesky,
}

impl RowSelection {
    /// The selection for `sys` (allocates once; nothing for a model without redundancy).
    pub(crate) fn new(sys: &System) -> Self {
        let (n, m, k) = (sys.n_coords(), sys.n_constraints(), sys.n_redundant());
        let (mf, nf) = if k > 0 { (m, n) } else { (0, 0) };
        let mut chol = DenseCholesky::new(mf);
        chol.set_max_dependent(k);
        chol.set_always_pivot(true);
        RowSelection {
            k,
            m_full: m,
            rows: (0..m - k).collect(),
            pq: DMatrix::zeros(mf, nf),
            dp: DMatrix::zeros(mf, nf),
            p: vec![0.0; mf],
            pd: vec![0.0; mf],
            minv: if k > 0 {
                sys.inv_mass_diag().as_slice().to_vec()
            } else {
                Vec::new()
            },
            chol,
        }
    }

    /// The model's row of kept row `i`.
    #[inline]
    pub(crate) fn full_row(&self, i: usize) -> usize {
        self.rows.get(i).copied().unwrap_or(i)
    }

    /// `Phi_q` and `(Phi_q v + Phi_t)_q` at `(q, v, t)`, kept rows (`m - k` x `n`), into `pq`,
    /// `dp` (the bodies' `sin`/`cos` from `angles` if given, a table at `q`); with `select`,
    /// the rows are chosen afresh at this point first (a centre). `false` if the
    /// selection failed: `Phi_q` has more than `k` dependent rows here (a singular
    /// configuration), or fewer (the redundancy found at build time is gone).
    #[inline]
    #[allow(clippy::too_many_arguments)] // (the point (q, v, t), its angles, two outputs, a flag)
    pub(crate) fn jacobian(
        &mut self,
        sys: &System,
        q: &[f64],
        angles: Option<&BodyAngles>,
        v: &[f64],
        t: f64,
        pq: &mut DMatrix<f64>,
        dp: &mut DMatrix<f64>,
        select: bool,
    ) -> bool {
        let eval = |pq: &mut DMatrix<f64>, dp: &mut DMatrix<f64>| match angles {
            Some(a) => sys.phi_q_dot_jacobian_at(q, a, v, t, pq, dp),
            None => sys.phi_q_dot_jacobian(q, v, t, pq, dp),
        };
        if self.k == 0 {
            eval(pq, dp);
            return true;
        }
        eval(&mut self.pq, &mut self.dp);
        if select && !self.select() {
            return false;
        }
        gather_rows(&self.pq, &self.rows, pq);
        gather_rows(&self.dp, &self.rows, dp);
        true
    }

    /// Chooses the kept rows from the full `Phi_q` in `self.pq`.
    fn select(&mut self) -> bool {
        let (m, n) = (self.m_full, self.pq.ncols());
        let g = self.pq.as_slice();
        {
            let s = self.chol.values_mut();
            // S = Phi_q M^-1 Phi_q^T, lower triangle, column-major
            for c in 0..m {
                for r in c..m {
                    let mut acc = 0.0;
                    for j in 0..n {
                        acc += g[r + j * m] * self.minv[j] * g[c + j * m];
                    }
                    s[r + c * m] = acc;
                }
            }
        }
        if self.chol.factor_in_place().is_err() || self.chol.dependent().len() != self.k {
            return false;
        }
        let dep = self.chol.dependent();
        let mut d = 0;
        let mut i = 0;
        for r in 0..m {
            if d < dep.len() && dep[d] == r {
                d += 1;
                continue;
            }
            self.rows[i] = r;
            i += 1;
        }
        true
    }

    /// `Phi` and `Phi_q v + Phi_t` at `(q, v)` and `t`, kept rows, into the two halves of
    /// `out` (the rotations from `angles` near the previous evaluation when given).
    #[inline]
    pub(crate) fn residual(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        out: &mut [f64],
        angles: Option<&mut BodyAngles>,
    ) {
        let (p, pd) = out.split_at_mut(out.len() / 2);
        if self.k == 0 {
            match angles {
                Some(a) => sys.phi_and_phi_dot_cached(q, v, t, p, pd, a),
                None => sys.phi_and_phi_dot(q, v, t, p, pd),
            }
            return;
        }
        match angles {
            Some(a) => sys.phi_and_phi_dot_cached(q, v, t, &mut self.p, &mut self.pd, a),
            None => sys.phi_and_phi_dot(q, v, t, &mut self.p, &mut self.pd),
        }
        for (i, &r) in self.rows.iter().enumerate() {
            p[i] = self.p[r];
            pd[i] = self.pd[r];
        }
    }

    /// `Phi_q(q, t)`, kept rows, into `pq` (the rank report).
    pub(crate) fn phi_q(&mut self, sys: &System, q: &[f64], t: f64, pq: &mut DMatrix<f64>) {
        if self.k == 0 {
            sys.phi_q(q, t, pq);
            return;
        }
        sys.phi_q(q, t, &mut self.pq);
        gather_rows(&self.pq, &self.rows, pq);
    }
}

impl Clone for RowSelection {
    /// (the factorisation is scratch: a clone gets a fresh one of the same size)
    fn clone(&self) -> Self {
        let mut chol = DenseCholesky::new(self.chol.dim());
        chol.set_max_dependent(self.k);
        RowSelection {
            k: self.k,
            m_full: self.m_full,
            rows: self.rows.clone(),
            pq: self.pq.clone(),
            dp: self.dp.clone(),
            p: self.p.clone(),
            pd: self.pd.clone(),
            minv: self.minv.clone(),
            chol,
        }
    }
}

/// `out` (rows.len() x n) = the rows `rows` of `full` (column-major both).
fn gather_rows(full: &DMatrix<f64>, rows: &[usize], out: &mut DMatrix<f64>) {
    let (mf, n) = full.shape();
    let mo = rows.len();
    let (f, o) = (full.as_slice(), out.as_mut_slice());
    for c in 0..n {
        for (i, &r) in rows.iter().enumerate() {
            o[i + c * mo] = f[r + c * mf];
        }
    }
}
