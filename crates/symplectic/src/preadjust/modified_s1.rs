//! The modified-Lagrangian term `e(q, v)` of the (1,1) scheme (`docs/symplectic.md` section
//! 5a): its value, its exact gradients, its velocity Hessian and the diagonals of its Newton
//! blocks for the sparse stage solve.
//!
//! The (1,1) scheme evaluates the potential at the chord's midpoint, so its `h^2` term is the
//! midpoint form derived in `docs/modified-lagrangian.md` section 2:
//!
//! `e = -1/24 f_T^T M^-1 f_T + 1/12 v^T A v - 1/8 v^T Hess V v + 1/24 gamma_c^T S^-1 gamma_c`
//!
//! with `gamma_c,k = v^T Hess Phi_k v` and the metric's `f_T`, `S`, `A` ([`ProjectedMetric`]).
//! In code the velocity terms are one quadratic form:
//! `1/12 v^T A v - 1/8 v^T Hess V v = 1/12 v^T (POTENTIAL_WEIGHT Hess V - mu0 . Hess Phi) v`.

use super::dot;
use super::metric::{ProjectedMetric, RowsAlong, Stamp};
use super::stiffness::TangentStiffness;
use crate::passes;
use crate::passes::{
    add_lagrangian_hessian_diagonals, add_lagrangian_hessian_pair, LagrangianWeights,
};
use mbd_model::System;
use mbd_solve::SolveError;
use nalgebra::DMatrix;

/// Weight of `Hess V` in the velocity quadratic form of `e` (times 1/12): `1 - 12/8`.
pub(crate) const POTENTIAL_WEIGHT: f64 = -0.5;

/// The workspace of `e` at one `(q, v)`: its intermediates, kept for the Newton Jacobian at the
/// same point and velocity, and the scratch of its gradients and velocity Hessian.
#[derive(Debug)]
pub(crate) struct ModifiedS1 {
    /// The constraint rows along `v` from the metric's fused pass; `along.vhv` holds
    /// `gamma_c` after [`ModifiedS1::evaluate`].
    along: RowsAlong,
    /// `sigma = S^-1 gamma_c`, `sigma - mu0` (`cm`), `B v` (`hv`) with
    /// `B = A + H_sigma - 3/2 Hess V`, and `D^3 (POTENTIAL_WEIGHT V + (sigma - mu0) . Phi)(v, v, .)`
    /// (`d3`).
    sigma: Vec<f64>,
    /// `S^-1 gamma_c` of the metric's `S` (with spatial bodies the augmented metric's, whose
    /// `M_W^-1 G^T` times it is the minimum-norm `w`; `sigma` is then corrected from it).
    sigma_w: Vec<f64>,
    cm: Vec<f64>,
    hv: Vec<f64>,
    d3: Vec<f64>,
    /// The velocity and the metric's stamp of the last evaluation (0: none), and a count of
    /// the evaluations (the tag of `sigma` for the stiffness `A + H_sigma`).
    mv: Vec<f64>,
    mv_stamp: Stamp,
    evaluations: u64,
    /// Scratch: n zeros (the velocity of `gamma`'s time part), `gamma(q, 0)`, m zero weights,
    /// `scale (sigma - mu0)`, `u - w`.
    zero_n: Vec<f64>,
    gc0: Vec<f64>,
    /// Scratch for a model whose `Phi_q` depends on time: `-v` (n) and `gamma(q, -v, t)` (m).
    neg_v: Vec<f64>,
    gc_neg: Vec<f64>,
    zero_m: Vec<f64>,
    scaled_cm: Vec<f64>,
    uw: Vec<f64>,
    /// Dense layout: `C^T = (Phi_q v)_q` (`m x n`), `Y = L^-1 C^T` on the nonzero columns of
    /// `C^T` (packed, `m x n` capacity) and those columns.
    ct: DMatrix<f64>,
    y: Vec<f64>,
    ycols: Vec<usize>,
}

impl ModifiedS1 {
    /// The workspace for `n` coordinates and `m` constraints (`sparse`: without the dense
    /// matrices of the velocity Hessian).
    pub(super) fn new(n: usize, m: usize, sparse: bool) -> Self {
        let (nd, md) = if sparse { (0, 0) } else { (n, m) };
        ModifiedS1 {
            along: RowsAlong::new(n, m),
            sigma: vec![0.0; m],
            sigma_w: vec![0.0; m],
            cm: vec![0.0; m],
            hv: vec![0.0; n],
            d3: vec![0.0; n],
            mv: vec![0.0; n],
            mv_stamp: 0,
            evaluations: 0,
            zero_n: vec![0.0; n],
            gc0: vec![0.0; m],
            neg_v: vec![0.0; n],
            gc_neg: vec![0.0; m],
            zero_m: vec![0.0; m],
            scaled_cm: vec![0.0; m],
            uw: vec![0.0; n],
            ct: DMatrix::zeros(md, nd),
            y: vec![0.0; md * nd],
            ycols: Vec::with_capacity(n),
        }
    }

    /// Prepares the metric at `q`, with the fused constraint pass along `v` when `q` is new.
    pub(super) fn prepare(
        &mut self,
        metric: &mut ProjectedMetric,
        sys: &System,
        q: &[f64],
        v: &[f64],
    ) -> Result<(), SolveError> {
        metric.prepare_along(sys, q, v, &mut self.along)
    }

    /// `e(q, v)` at the metric's prepared point `q`; leaves `gamma_c` in `along.vhv`,
    /// `S^-1 gamma_c` in `sigma`, `sigma - mu0` in `cm`, `B v` in `hv` with `B = A + H_sigma -
    /// 3/2 Hess V = POTENTIAL_WEIGHT Hess V + (sigma - mu0) . Hess Phi`, and
    /// `D^3 (POTENTIAL_WEIGHT V + (sigma - mu0) . Phi)(v, v, .)` in `d3`, no Hessian assembled:
    /// with the rows of the metric's fused pass along this `v` the constraints' parts come from
    /// them (only the forces take a third-order pass here), otherwise from one third-order pass
    /// over the elements.
    pub(super) fn evaluate(
        &mut self,
        metric: &mut ProjectedMetric,
        sys: &System,
        q: &[f64],
        v: &[f64],
    ) -> f64 {
        let (n, m) = (metric.n(), metric.m());
        let (mass, u) = (metric.mass(), metric.u());
        let uu: f64 = (0..n).map(|k| mass[k] * u[k] * u[k]).sum();
        let mut gg = 0.0;
        // the rows of the fused pass, if they are along this v at this point
        let along = &mut self.along;
        let rows = m > 0 && along.stamp == metric.stamp() && along.v.as_slice() == v;
        let gc = &mut along.vhv;
        if m > 0 {
            // gc = v^T Hess Phi_k v: from the rows, or gamma(q, v, t) = -(v^T Hess Phi_k v) +
            // time part (which cancels)
            if !rows {
                let t = metric.t();
                sys.gamma(q, v, t, gc);
                // (gc no longer matches the rows)
                along.stamp = 0;
                if metric.time_jacobian() {
                    // gamma also holds -2 Phi_tq v (a spatial angle driver): its even part in v
                    // is the quadratic form's
                    for (a, &b) in self.neg_v.iter_mut().zip(v) {
                        *a = -b;
                    }
                    sys.gamma(q, &self.neg_v, t, &mut self.gc_neg);
                    sys.gamma(q, &self.zero_n, t, &mut self.gc0);
                    for r in 0..m {
                        gc[r] = self.gc0[r] - 0.5 * (gc[r] + self.gc_neg[r]);
                    }
                } else if metric.rheonomic() {
                    sys.gamma(q, &self.zero_n, t, &mut self.gc0);
                    for r in 0..m {
                        gc[r] = self.gc0[r] - gc[r];
                    }
                } else {
                    gc.iter_mut().for_each(|x| *x = -*x);
                }
            }
            self.sigma.copy_from_slice(gc);
            metric.s_solve(&mut self.sigma);
            gg = dot(gc, &self.sigma);
            if metric.is_augmented() {
                // the augmented metric's S^-1 gamma_c and gamma_c^T S^-1 gamma_c exceed those
                // of M by W gamma_int and gamma_int^T W gamma_int (module `augmented`)
                self.sigma_w.copy_from_slice(&self.sigma);
                metric.correct_multipliers(gc, &mut self.sigma);
                gg -= metric.penalty(gc);
            }
        }
        let mu0 = metric.mu0();
        for r in 0..m {
            self.cm[r] = self.sigma[r] - mu0[r];
        }
        if rows {
            // the potential's part by a pass over the forces (the zero weights skip the
            // joints), the constraints' from the rows
            passes::lagrangian_third(
                sys,
                q,
                metric.t(),
                v,
                POTENTIAL_WEIGHT,
                &self.zero_m,
                &mut self.hv,
                &mut self.d3,
            );
            passes::add_local_rows(sys, &along.hess_v, &self.cm, &mut self.hv);
            passes::add_local_rows(sys, &along.third_vv, &self.cm, &mut self.d3);
        } else {
            passes::lagrangian_third(
                sys,
                q,
                metric.t(),
                v,
                POTENTIAL_WEIGHT,
                &self.cm,
                &mut self.hv,
                &mut self.d3,
            );
        }
        self.mv.copy_from_slice(v);
        self.mv_stamp = metric.stamp();
        self.evaluations += 1;
        // v^T (A - 3/2 Hess V) v = v^T B v - sigma . gamma_c
        let vav = dot(v, &self.hv) - gg;
        -uu / 24.0 + vav / 12.0 + gg / 24.0
    }

    /// [`ModifiedS1::evaluate`] unless it was the last evaluation at this point and velocity
    /// (the Newton Jacobian is evaluated where the residual was).
    fn ensure_evaluated(
        &mut self,
        metric: &mut ProjectedMetric,
        sys: &System,
        q: &[f64],
        v: &[f64],
    ) {
        if !(self.mv_stamp == metric.stamp() && self.mv.as_slice() == v) {
            self.evaluate(metric, sys, q, v);
        }
    }

    /// The gradients of `e` into `dq` and `dv` (length n, checked by the caller) at the
    /// metric's point `q`, prepared by [`ModifiedS1::prepare`]; returns `e(q, v)`. With
    /// `sigma = S^-1 gamma_c`, `H_sigma = sum_k sigma_k Hess Phi_k`, `u = M^-1 f_T` and
    /// `w = M^-1 Phi_q^T sigma` (derivation in `docs/symplectic.md` section 5a):
    ///
    /// * `d e / d v = 1/6 (A + H_sigma - 3/2 Hess V) v` (exact),
    /// * `d e / d q = 1/12 [(A + H_sigma)(u - w) + D^3(-1/2 V + (sigma - mu0) . Phi)(v, v)]`,
    ///   where the third-derivative term is the derivative along `v` of
    ///   `Hess(-1/2 V + (sigma - mu0) . Phi) v` (`sigma`, `mu0` frozen), exact
    ///   ([`passes::lagrangian_third`](crate::passes::lagrangian_third)).
    pub(super) fn gradients(
        &mut self,
        metric: &mut ProjectedMetric,
        sys: &System,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> f64 {
        let n = metric.n();
        let e = self.evaluate(metric, sys, q, v);
        for k in 0..n {
            dv[k] = self.hv[k] / 6.0;
        }
        // (A + H_sigma)(u - w), w = M^-1 Phi_q^T sigma, one Hessian-vector pass
        let uw = &mut self.uw;
        if metric.is_sparse() {
            uw.copy_from_slice(metric.u());
            metric.add_dgt_to(&self.sigma, -1.0, uw);
        } else if metric.is_augmented() {
            // w = M_W^-1 G^T S_W^-1 gamma_c, the minimum-norm solution of G w = gamma_c
            uw.copy_from_slice(metric.u());
            if metric.m() > 0 {
                metric.add_dgt_to(&self.sigma_w, -1.0, uw);
            }
        } else {
            let (minv, u) = (metric.minv(), metric.u());
            for k in 0..n {
                let acc = metric.g_col_dot(k, &self.sigma);
                uw[k] = u[k] - minv[k] * acc;
            }
        }
        passes::lagrangian_hessian_vector(sys, q, metric.t(), uw, 1.0, &self.cm, dq);
        // third derivatives along v (exact, from evaluate)
        for k in 0..n {
            dq[k] += self.d3[k];
        }
        dq.iter_mut().for_each(|x| *x /= 12.0);
        e
    }

    /// `out += scale * (B + 2 C S^-1 C^T)` at the metric's prepared point `q` and velocity `v`
    /// (dense layout; `out` is `n x n`), with `B = A + H_sigma - 3/2 Hess V`
    /// (`H_sigma = sum_k sigma_k Hess Phi_k`, `sigma = S^-1 gamma_c(q, v)`) and
    /// `C = [Hess Phi_k v]_k` (the derivative of `sigma` in `v`): `6 d^2 e / dv^2`, for the
    /// Newton Jacobian. One Hessian pass over the elements
    /// ([`add_lagrangian_hessian_pair`]) also assembles `A + H_sigma` into `stiffness`, which
    /// the position Newton block ([`ModifiedS1::position_newton_hessian`]) then reuses.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn add_velocity_hessian(
        &mut self,
        metric: &mut ProjectedMetric,
        stiffness: &mut TangentStiffness,
        sys: &System,
        q: &[f64],
        v: &[f64],
        scale: f64,
        out: &mut DMatrix<f64>,
    ) {
        self.ensure_evaluated(metric, sys, q, v);
        // one Hessian pass: out += scale B, A + H_sigma (kept for the position Newton block)
        // and C^T = (Phi_q v)_q
        let (n, m) = (metric.n(), metric.m());
        for r in 0..m {
            self.scaled_cm[r] = scale * self.cm[r];
        }
        add_lagrangian_hessian_pair(
            sys,
            q,
            metric.t(),
            v,
            (
                LagrangianWeights {
                    potential: 1.0,
                    constraints: &self.cm,
                },
                stiffness.total_from_zero(metric, self.evaluations),
            ),
            (
                LagrangianWeights {
                    potential: scale * POTENTIAL_WEIGHT,
                    constraints: &self.scaled_cm,
                },
                out,
            ),
            &mut self.ct,
        );
        if m > 0 {
            // + 2 C S^-1 C^T, C = [Hess Phi_k v]_k: the derivative of sigma = S^-1 gamma_c(v)
            // (gamma_c,k = v^T Hess Phi_k v, d gamma_c / dv = 2 C^T), so that
            // 6 d^2 e / dv^2 = B + 2 C S^-1 C^T exactly (q fixed);
            // the coordinates where C^T has a nonzero column, and Y = L^-1 C^T on them
            // (C S^-1 C^T = Y^T Y)
            self.ycols.clear();
            let y = self.y.as_mut_slice();
            for (i, ci) in self.ct.as_slice().chunks_exact(m).enumerate() {
                if ci.iter().any(|&c| c != 0.0) {
                    let o = self.ycols.len() * m;
                    y[o..o + m].copy_from_slice(ci);
                    metric.chol().forward_in_place(&mut y[o..o + m]);
                    self.ycols.push(i);
                }
            }
            // (Y^T Y is symmetric: each dot product once, the same bits both ways)
            let o = out.as_mut_slice();
            for (a, &i) in self.ycols.iter().enumerate() {
                for (b, &l) in self.ycols.iter().enumerate().take(a + 1) {
                    let d = 2.0 * scale * dot(&y[b * m..(b + 1) * m], &y[a * m..(a + 1) * m]);
                    o[i * n + l] += d;
                    if l != i {
                        o[l * n + i] += d;
                    }
                }
            }
            // The augmented metric's gamma_c^T S_W^-1 gamma_c exceeds the term's by
            // penalty(gamma_c) = sum_r w_r gamma_c,r^2 over the internal rows (`evaluate`
            // subtracts it, and corrects sigma by -W gamma_int, which H_sigma in B carries):
            // the velocity Hessian of that difference, 2 sum_r w_r C_r C_r^T, comes off too.
            // (C_r = Hess Phi_r v lives on the body's directors: a few nonzeros per row.)
            let ct = self.ct.as_slice();
            let nz = &mut self.ycols;
            metric.for_each_penalty_row(|r, w| {
                nz.clear();
                nz.extend((0..n).filter(|&i| ct[i * m + r] != 0.0));
                for &i in nz.iter() {
                    for &l in nz.iter() {
                        o[l * n + i] -= 2.0 * scale * w * ct[i * m + r] * ct[l * m + r];
                    }
                }
            });
        }
    }

    /// The leading position Hessian of `e` at the metric's prepared point `q` and velocity `v`,
    /// up to its factor `-1/12`: `(A + H_sigma) Pi (A + H_sigma)` into `out` (overwritten;
    /// dense layout), with `A + H_sigma = Hess V + (sigma - mu0) . Hess Phi` from the velocity
    /// Hessian's pass when that ran at this point. `d e / d q = 1/12 (A + H_sigma)(u - w) + ...`
    /// and `d(u - w) = -Pi (A + H_sigma) dq + ...` (`u - w` is the acceleration;
    /// docs/symplectic.md section 5a); the parts left out are linear in the third derivatives
    /// of `V` and `Phi`, or in the acceleration rather than in the multipliers.
    pub(super) fn position_newton_hessian(
        &mut self,
        metric: &mut ProjectedMetric,
        stiffness: &mut TangentStiffness,
        sys: &System,
        q: &[f64],
        v: &[f64],
        out: &mut DMatrix<f64>,
    ) {
        self.ensure_evaluated(metric, sys, q, v);
        if !stiffness.holds_total(metric, self.evaluations) {
            let a = stiffness.total_from_zero(metric, self.evaluations);
            sys.potential_hessian(q, a);
            if metric.m() > 0 {
                sys.add_constraint_hessian(q, metric.t(), &self.cm, 1.0, a);
            }
        }
        stiffness.a_pi_a(metric, out);
    }

    /// Diagonals of the Newton blocks at the metric's point `q` (prepared by
    /// [`ModifiedS1::prepare`]) and velocity `v`, for the sparse stage solve
    /// (`docs/symplectic.md` section 5a), from one pass in `O(N)`; overwrites the three:
    /// `wd = diag(B)` (the velocity Hessian `6 d^2 e / dv^2 = B + 2 C S^-1 C^T` without its
    /// dense part), `sd = diag(A_s)` of the stiffness `A_s = A + H_sigma` of the position
    /// block, and `ad_i = A_ii^2 / m_i` (the diagonal of `A M^-1 A` with the off-diagonal
    /// entries of `A = Hess V - mu0 . Hess Phi` left out), the position block where the exact
    /// one does not pay (`galerkin/sparse/projected.rs`). Returns `max_i m_i^-1 |A_s,ii|`.
    pub(super) fn newton_diagonals(
        &mut self,
        metric: &mut ProjectedMetric,
        sys: &System,
        (q, v): (&[f64], &[f64]),
        [wd, sd, ad]: [&mut [f64]; 3],
    ) -> f64 {
        self.ensure_evaluated(metric, sys, q, v);
        wd.fill(0.0);
        sd.fill(0.0);
        ad.fill(0.0);
        add_lagrangian_hessian_diagonals(
            sys,
            q,
            metric.t(),
            [
                (
                    LagrangianWeights {
                        potential: POTENTIAL_WEIGHT,
                        constraints: &self.cm,
                    },
                    wd,
                ),
                (
                    LagrangianWeights {
                        potential: 1.0,
                        constraints: &self.cm,
                    },
                    &mut *sd,
                ),
                (
                    LagrangianWeights {
                        potential: 1.0,
                        constraints: metric.neg_mu0(),
                    },
                    &mut *ad,
                ),
            ],
        );
        for (a, mi) in ad.iter_mut().zip(metric.minv()) {
            *a = *a * *a * mi;
        }
        sd.iter()
            .zip(metric.minv())
            .fold(0.0f64, |r, (&a, &mi)| r.max(a.abs() * mi))
    }

    /// The constraint weights `sigma - mu0` of the stiffness `A + H_sigma = Hess V +
    /// (sigma - mu0) . Hess Phi` at the last evaluation.
    pub(super) fn stiffness_weights(&self) -> &[f64] {
        &self.cm
    }

    /// `sigma = S^-1 gamma_c` of the last evaluation (tests).
    #[cfg(test)]
    pub(super) fn sigma(&self) -> &[f64] {
        &self.sigma
    }
}

#[cfg(test)]
pub(crate) mod modlag_tests {
    use super::*;
    use crate::Preadjustment;
    use mbd_model::models;

    /// Check of [`Preadjustment::modified_gradients`]: `d e / d q` by Richardson-extrapolated
    /// central differences of `e` in each coordinate (relative step `p.fd_step`), `d e / d v`
    /// from the assembled matrices.
    fn modified_gradients_fd(
        p: &mut Preadjustment,
        sys: &System,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<f64, SolveError> {
        let n = q.len();
        let mut qp = q.to_vec();
        for l in 0..n {
            let d = p.fd_step * (1.0 + q[l].abs());
            let mut acc = 0.0;
            for (coef, shift) in [(8.0, 0.5), (-8.0, -0.5), (-1.0, 1.0), (1.0, -1.0)] {
                qp[l] = q[l] + shift * d;
                acc += coef * p.modified_term(sys, &qp, v)?;
            }
            qp[l] = q[l];
            dq[l] = acc / (6.0 * d);
        }
        let e = p.modified_term(sys, q, v)?;
        p.stiffness.ensure(&p.metric, sys, q);
        p.stiffness.times(v, dv);
        // + H_sigma v - 3/2 Hess V v
        let mut hs = DMatrix::zeros(n, n);
        sys.potential_hessian(q, &mut hs);
        // A already holds Hess V once: the weight left to add is POTENTIAL_WEIGHT - 1 = -3/2
        hs *= POTENTIAL_WEIGHT - 1.0;
        if p.metric.m() > 0 {
            sys.add_constraint_hessian(q, p.metric.t(), p.s1.sigma(), 1.0, &mut hs);
        }
        let mut t = vec![0.0; n];
        crate::preadjust::stiffness::matvec(&hs, v, &mut t);
        for k in 0..n {
            dv[k] += t[k];
        }
        dv.iter_mut().for_each(|x| *x /= 6.0);
        Ok(e)
    }

    /// The rod with a spring of the models (`Hess V != 0`).
    pub(crate) fn rod_with_spring() -> System {
        mbd_model::models::rod_with_spring().unwrap()
    }

    /// The analytic gradients of the modified-Lagrangian term against central differences of
    /// the term itself, away from equilibrium and with a generic velocity: on the double
    /// pendulum (gravity), on a rod with a spring (where the `-1/8 v^T Hess V v` term and its
    /// third derivatives matter), and on spatial models (12 natural coordinates per body, the
    /// internal constraints among the rows: the heavy top, the spatial double pendulum, a rod on
    /// a spring (a spatial force element's third derivatives) and the disc top, whose singular
    /// mass matrix takes the augmented metric).
    #[test]
    fn modified_gradient_matches_differences() {
        for sys in [
            models::paper_a_double_pendulum().unwrap(),
            rod_with_spring(),
            models::heavy_top([0.3, 0.3, 0.1], 0.3, 20.0).unwrap(),
            models::spatial_double_pendulum().unwrap(),
            models::sprung_rod([0.05, 0.05, 0.002]).unwrap(),
            models::heavy_top([0.25, 0.25, 0.5], 0.3, 20.0).unwrap(),
        ] {
            let st = mbd_solve::State::consistent(&sys, 0.0).unwrap();
            let n = sys.n_coords();
            let q: Vec<f64> = st.q.iter().copied().collect();
            let v: Vec<f64> = (0..n)
                .map(|i| 0.7 * ((i as f64) * 1.3 + 0.4).sin())
                .collect();
            let mut p = Preadjustment::new(&sys, 1).unwrap();
            let (mut a, mut av, mut b, mut bv) =
                (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            let ea = p.modified_gradients(&sys, &q, &v, &mut a, &mut av).unwrap();
            let eb = modified_gradients_fd(&mut p, &sys, &q, &v, &mut b, &mut bv).unwrap();
            assert_eq!(ea, eb);
            let scale = b.iter().fold(0.0f64, |x, &y| x.max(y.abs()));
            for i in 0..n {
                assert!(
                    (a[i] - b[i]).abs() < 1e-7 * scale,
                    "dq[{i}]: {} vs {}",
                    a[i],
                    b[i]
                );
                assert!(
                    (av[i] - bv[i]).abs() < 1e-12 * (1.0 + bv[i].abs()),
                    "dv[{i}]: {} vs {}",
                    av[i],
                    bv[i]
                );
            }
        }
    }

    /// The modified Lagrangian's position Newton block
    /// ([`Preadjustment::modified_position_hessian`]) at `v = 0` is the `s = 1` approximate
    /// Hessian `A Pi A` to rounding, and exactly symmetric; at a velocity it carries the
    /// centripetal multipliers `sigma` (it differs from `A Pi A` by more than rounding).
    #[test]
    fn position_hessian_is_a_pi_a_at_rest() {
        for sys in [
            models::paper_a_double_pendulum().unwrap(),
            models::n_link_chain(4).unwrap(),
            rod_with_spring(),
        ] {
            let st = mbd_solve::State::consistent(&sys, 0.0).unwrap();
            let n = sys.n_coords();
            let q: Vec<f64> = st.q.iter().copied().collect();
            let mut p = Preadjustment::new(&sys, 1).unwrap();
            let (mut a, mut b) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
            p.approximate_hessian(&sys, &q, &mut a).unwrap();
            p.modified_position_hessian(&sys, &q, &vec![0.0; n], &mut b)
                .unwrap();
            let scale = a.iter().fold(0.0f64, |x, &y| x.max(y.abs()));
            assert!(scale > 0.0);
            for i in 0..n {
                for l in 0..n {
                    assert!(
                        (a[(i, l)] - b[(i, l)]).abs() <= 1e-12 * scale,
                        "({i}, {l}): {} vs {}",
                        a[(i, l)],
                        b[(i, l)]
                    );
                    assert_eq!(b[(i, l)], b[(l, i)]);
                }
            }
            // at a velocity the centripetal multipliers change the block
            let v: Vec<f64> = (0..n).map(|i| 0.5 + 0.1 * i as f64).collect();
            p.modified_position_hessian(&sys, &q, &v, &mut b).unwrap();
            let diff = (&a - &b).amax();
            assert!(diff > 1e-6 * scale, "{diff} against {scale}");
        }
    }

    /// Largest position error over `[0, 2 s]` (sampled every 0.05 s) of the (1,1) scheme on the
    /// rod with a spring, against a DOPRI5 reference on the grid of `h_ref`.
    fn spring_rod_error(modified: bool, h: f64, h_ref: f64, reference: &[Vec<f64>]) -> f64 {
        use crate::{Galerkin, PreadjustMode, SymplecticOptions};
        use mbd_solve::Integrator;
        let sys = rod_with_spring();
        let mut st = mbd_solve::State::consistent(&sys, 0.0).unwrap();
        let mut o = SymplecticOptions::new(1);
        if modified {
            o = o.with_preadjust(PreadjustMode::ModifiedLagrangian);
        }
        let mut g = Galerkin::new(&sys, o).unwrap();
        let (per_sample, every) = ((0.05 / h).round() as usize, (0.05 / h_ref).round() as usize);
        let mut err = 0.0f64;
        for k in 1..=40 {
            for _ in 0..per_sample {
                g.step(&sys, &mut st, h).unwrap();
            }
            let r = &reference[k * every];
            for i in 0..3 {
                err = err.max((st.q[i] - r[i]).abs());
            }
        }
        err
    }

    /// With a non-linear potential (a spring) the midpoint form of `e` restores order 4 where
    /// the plain scheme has order 2 (`docs/symplectic.md` section 5a compares the trapezoid
    /// form).
    #[test]
    fn spring_rod_converges_with_order_four() {
        let sys = rod_with_spring();
        let s0 = mbd_solve::State::consistent(&sys, 0.0).unwrap();
        let h_ref = 0.0125;
        let reference = mbd_solve::reference_trajectory(
            &sys,
            &s0,
            h_ref,
            160,
            32,
            mbd_solve::ButcherTableau::dopri5(),
        )
        .unwrap();
        let plain: Vec<f64> = [0.05, 0.025]
            .iter()
            .map(|&h| spring_rod_error(false, h, h_ref, &reference.q))
            .collect();
        let modified: Vec<f64> = [0.05, 0.025]
            .iter()
            .map(|&h| spring_rod_error(true, h, h_ref, &reference.q))
            .collect();
        let order = |e: &[f64]| (e[0] / e[1]).log2();
        eprintln!(
            "rod + spring, max |dq| over 2 s at h = 0.05 / 0.025: plain {:.3e} / {:.3e} (order \
             {:.2}), modified {:.3e} / {:.3e} (order {:.2})",
            plain[0],
            plain[1],
            order(&plain),
            modified[0],
            modified[1],
            order(&modified)
        );
        assert!(
            (1.8..2.3).contains(&order(&plain)),
            "plain order {}",
            order(&plain)
        );
        assert!(
            order(&modified) > 3.6,
            "modified order {}",
            order(&modified)
        );
        assert!(modified[1] * 20.0 < plain[1]);
    }
}
