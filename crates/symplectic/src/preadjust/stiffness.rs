//! The assembled tangential stiffness `A = Hess V - mu0 . Hess Phi` at the metric's point and
//! the Newton matrices built from it (dense layout only): `A (Pi A)^s`, the Newton Hessian of
//! paper A's `W_s`, and `A Pi A`, which with `A + H_sigma` in place of `A` is the leading
//! position Hessian of the s = 1 modified Lagrangian's term (docs/symplectic.md section 5a).
//!
//! `A` is symmetric, so its zero columns (coordinates that enter `V` and the constraints
//! linearly, e.g. the positions of bodies with revolute joints under gravity) are zero rows
//! too, and both products live on the block `K x K` of the other coordinates, with
//! `Pi_KK = M^-1_KK - Y^T Y`, `Y = L^-1 (G M^-1)_K` (`S = L L^T`): dense products of size `|K|`
//! only.

use super::dot;
use super::metric::{ProjectedMetric, Stamp};
use mbd_model::System;
use nalgebra::DMatrix;

/// `A` at the metric's point (assembled on demand, kept for the point) and the workspace of its
/// `K`-block products.
#[derive(Debug)]
pub(crate) struct TangentStiffness {
    amat: DMatrix<f64>,
    /// The metric's stamp `amat` was assembled at (0: none).
    stamp: Stamp,
    /// Whether `amat` holds `A + H_sigma` (the s = 1 term's stiffness along a velocity,
    /// [`TangentStiffness::total_from_zero`]) rather than `A`, and the tag of the evaluation of
    /// `sigma` it was assembled with.
    with_sigma: bool,
    sigma_tag: u64,
    /// The coordinates `K` where `A` has a nonzero column, and `|K| x |K|` blocks on them
    /// (column-major, `n x n` capacity): `A_KK`, `Pi_KK`, the running product, and `Y`
    /// (`m x |K|`) or a product.
    kset: Vec<usize>,
    ka: Vec<f64>,
    kpi: Vec<f64>,
    kx: Vec<f64>,
    ky: Vec<f64>,
    /// `Z = Y A_KK` (`m x |K|`) of [`TangentStiffness::a_pi_a`].
    kz: Vec<f64>,
}

impl TangentStiffness {
    /// The workspace for `n` coordinates and `m` constraints (empty on the sparse layout).
    pub(super) fn new(n: usize, m: usize, sparse: bool) -> Self {
        let (nd, md) = if sparse { (0, 0) } else { (n, m) };
        TangentStiffness {
            amat: DMatrix::zeros(nd, nd),
            stamp: 0,
            with_sigma: false,
            sigma_tag: 0,
            kset: Vec::with_capacity(n),
            ka: vec![0.0; nd * nd],
            kpi: vec![0.0; nd * nd],
            kx: vec![0.0; nd * nd],
            ky: vec![0.0; nd * nd.max(md)],
            kz: vec![0.0; md * nd],
        }
    }

    /// Assembles `A` at the metric's prepared point `q` (once per point).
    pub(super) fn ensure(&mut self, metric: &ProjectedMetric, sys: &System, q: &[f64]) {
        if self.stamp == metric.stamp() && !self.with_sigma {
            return;
        }
        sys.potential_hessian(q, &mut self.amat);
        if metric.m() > 0 {
            // (planar models: the constraint Hessian does not depend on t)
            sys.add_constraint_hessian(q, metric.t(), metric.mu0(), -1.0, &mut self.amat);
        }
        self.stamp = metric.stamp();
        self.with_sigma = false;
    }

    /// The matrix, zeroed, for a caller that assembles `A + H_sigma` in it at the metric's
    /// prepared point (the s = 1 term's Hessian pass, which gives it with its own matrices);
    /// then kept for the point, and [`TangentStiffness::ensure`] assembles `A` again.
    /// `tag` names the evaluation of `sigma` (point and velocity) it is assembled with.
    pub(super) fn total_from_zero(
        &mut self,
        metric: &ProjectedMetric,
        tag: u64,
    ) -> &mut DMatrix<f64> {
        self.amat.as_mut_slice().fill(0.0);
        self.stamp = metric.stamp();
        self.with_sigma = true;
        self.sigma_tag = tag;
        &mut self.amat
    }

    /// Whether the matrix holds `A + H_sigma` at the metric's prepared point for the
    /// evaluation of `sigma` named `tag`.
    pub(super) fn holds_total(&self, metric: &ProjectedMetric, tag: u64) -> bool {
        self.with_sigma && self.stamp == metric.stamp() && self.sigma_tag == tag
    }

    /// A bound on the spectral radius of `M^-1 A` (Gershgorin: `max_i minv_i sum_l |A_il|`; the
    /// eigenvalues are those of the symmetric `M^-1/2 A M^-1/2`), after
    /// [`TangentStiffness::ensure`].
    pub(super) fn bound(&self, metric: &ProjectedMetric) -> f64 {
        let n = metric.n();
        let minv = metric.minv();
        let mut rho = 0.0f64;
        for i in 0..n {
            let row: f64 = (0..n).map(|l| self.amat[(i, l)].abs()).sum();
            rho = rho.max(minv[i] * row);
        }
        rho
    }

    /// The block `K` of the coordinates where `A` is not zero (into `kset`; returns `|K|`),
    /// `Y = L^-1 (G M^-1)_K` (one triangular solve per column, packed into `ky`, `m x |K|`) and
    /// `A_KK` (column-major into `ka`), after [`TangentStiffness::ensure`].
    fn k_block(&mut self, metric: &ProjectedMetric) -> usize {
        let (n, m) = (metric.n(), metric.m());
        let (gq, minv) = (metric.gq(), metric.minv());
        self.kset.clear();
        for (c, col) in self.amat.as_slice().chunks_exact(n).enumerate() {
            if col.iter().any(|&a| a != 0.0) {
                self.kset.push(c);
            }
        }
        let k = self.kset.len();
        for (cj, &c) in self.kset.iter().enumerate() {
            let y = &mut self.ky[cj * m..(cj + 1) * m];
            if metric.is_augmented() {
                // (G M_W^-1)_:c over the coordinates sharing c's block of M_W^-1
                y.fill(0.0);
                for j in metric.minv_partners(c) {
                    let w = metric.minv_entry(j, c);
                    for r in 0..m {
                        y[r] += gq[(r, j)] * w;
                    }
                }
            } else {
                for r in 0..m {
                    y[r] = gq[(r, c)] * minv[c];
                }
            }
            metric.chol().forward_in_place(y);
            for (ri, &r) in self.kset.iter().enumerate() {
                self.ka[cj * k + ri] = self.amat[(r, c)];
            }
        }
        k
    }

    /// `A (Pi A)^s`, symmetrised, into `out` (overwritten), after
    /// [`TangentStiffness::ensure`]: `A_KK (Pi_KK A_KK)^s` by dense products of size `|K|`.
    pub(super) fn a_pi_a_power(
        &mut self,
        metric: &ProjectedMetric,
        s: usize,
        out: &mut DMatrix<f64>,
    ) {
        let (n, m) = (metric.n(), metric.m());
        let minv = metric.minv();
        let k = self.k_block(metric);
        // Pi_KK = M^-1_KK - Y^T Y (ky is free after this, until the products below)
        for cj in 0..k {
            for ri in 0..k {
                let yy = dot(
                    &self.ky[ri * m..(ri + 1) * m],
                    &self.ky[cj * m..(cj + 1) * m],
                );
                let d = if metric.is_augmented() {
                    metric.minv_entry(self.kset[ri], self.kset[cj])
                } else if ri == cj {
                    minv[self.kset[cj]]
                } else {
                    0.0
                };
                self.kpi[cj * k + ri] = d - yy;
            }
        }
        // X = A_KK, then X <- A_KK (Pi_KK X), s times
        self.kx[..k * k].copy_from_slice(&self.ka[..k * k]);
        let mul = |a: &[f64], b: &[f64], o: &mut [f64]| {
            // o = a b, k x k column-major
            for cj in 0..k {
                for ri in 0..k {
                    o[cj * k + ri] = (0..k).map(|l| a[l * k + ri] * b[cj * k + l]).sum();
                }
            }
        };
        for _ in 0..s {
            mul(&self.kpi, &self.kx, &mut self.ky);
            mul(&self.ka, &self.ky, &mut self.kx);
        }
        out.fill(0.0);
        let o = out.as_mut_slice();
        for (cj, &c) in self.kset.iter().enumerate() {
            for (ri, &r) in self.kset.iter().enumerate() {
                o[c * n + r] = 0.5 * (self.kx[cj * k + ri] + self.kx[ri * k + cj]);
            }
        }
    }

    /// `A Pi A` into `out` (overwritten), after [`TangentStiffness::ensure`] (or, with
    /// `A + H_sigma` in place of `A`, after [`TangentStiffness::total_from_zero`]):
    /// [`TangentStiffness::a_pi_a_power`] with `s = 1` in fewer operations, the same matrix up
    /// to rounding and symmetric by construction. With `Z = Y A_KK` (`m x |K|`, zeros of `A_KK`
    /// skipped), `A_KK Pi_KK A_KK = A_KK M^-1_KK A_KK - Z^T Z`, so each entry of the upper
    /// triangle is one `|K|`-term and one `m`-term dot product (no `|K|^3` products).
    pub(super) fn a_pi_a(&mut self, metric: &ProjectedMetric, out: &mut DMatrix<f64>) {
        let (n, m) = (metric.n(), metric.m());
        let minv = metric.minv();
        let k = self.k_block(metric);
        let z = self.kz.as_mut_slice();
        for cj in 0..k {
            let zc = &mut z[cj * m..(cj + 1) * m];
            zc.fill(0.0);
            for (l, &a) in self.ka[cj * k..(cj + 1) * k].iter().enumerate() {
                if a != 0.0 {
                    for (zr, &yr) in zc.iter_mut().zip(&self.ky[l * m..(l + 1) * m]) {
                        *zr += yr * a;
                    }
                }
            }
        }
        if metric.is_augmented() {
            // W = M_W^-1_KK A_KK into kpi (free here), by the blocks of M_W^-1
            for cj in 0..k {
                for (ri, &r) in self.kset.iter().enumerate() {
                    let p = metric.minv_partners(r);
                    let lo = self.kset.partition_point(|&x| x < p.start);
                    let hi = self.kset.partition_point(|&x| x < p.end);
                    self.kpi[cj * k + ri] = (lo..hi)
                        .map(|l| metric.minv_entry(r, self.kset[l]) * self.ka[cj * k + l])
                        .sum();
                }
            }
        }
        let o = out.as_mut_slice();
        o.fill(0.0);
        for (cj, &c) in self.kset.iter().enumerate() {
            let ac = &self.ka[cj * k..(cj + 1) * k];
            let zc = &z[cj * m..(cj + 1) * m];
            for (ri, &r) in self.kset.iter().enumerate().take(cj + 1) {
                // (A symmetric: row ri of A_KK is its column ri)
                let ar = &self.ka[ri * k..(ri + 1) * k];
                let am: f64 = if metric.is_augmented() {
                    dot(ar, &self.kpi[cj * k..(cj + 1) * k])
                } else {
                    ar.iter()
                        .zip(ac)
                        .zip(&self.kset)
                        .map(|((&x, &y), &l)| x * minv[l] * y)
                        .sum()
                };
                let x = am - dot(&z[ri * m..(ri + 1) * m], zc);
                o[c * n + r] = x;
                o[r * n + c] = x;
            }
        }
    }

    /// `out = A x` with the assembled `A` (tests).
    #[cfg(test)]
    pub(super) fn times(&self, x: &[f64], out: &mut [f64]) {
        matvec(&self.amat, x, out);
    }
}

/// `out = a x` (tests).
#[cfg(test)]
pub(super) fn matvec(a: &DMatrix<f64>, x: &[f64], out: &mut [f64]) {
    let n = a.nrows();
    out.iter_mut().for_each(|o| *o = 0.0);
    for (j, &xj) in x.iter().enumerate() {
        if xj == 0.0 {
            continue;
        }
        let col = &a.as_slice()[j * n..(j + 1) * n];
        for i in 0..n {
            out[i] += col[i] * xj;
        }
    }
}
