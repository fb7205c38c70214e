//! The dense stage Jacobian: assembled into the project's dense LU with the coordinate-blocked
//! elimination order (`docs/symplectic.md`, "The linear solve").

use super::{with_time, Galerkin};
use mbd_model::System;
use mbd_solve::linalg::DenseLu;
use mbd_solve::SolveError;

/// The LU of the stage Jacobian with the elimination order that keeps it sparse: for each
/// coordinate `i`, the momentum rows `(nu, i)`, `nu = 0..s-1`, paired with the displacement
/// unknowns `Z_(nu+1), i` (their `s x s` block is the stiffness matrix `K` when the Hessians
/// are sparse); then the constraint rows with the multipliers (their Schur complement), of
/// which `redundant` per control point (the model's redundant equations) may be dropped: their
/// multipliers are zero (the basic solution, as in the index-1 solve).
pub(super) fn stage_lu(n: usize, m: usize, s: usize, redundant: usize) -> DenseLu {
    let mut order: Vec<usize> = Vec::with_capacity(s * (n + m));
    for i in 0..n {
        for nu in 0..s {
            order.push(nu * n + i);
        }
    }
    order.extend(s * n..s * (n + m));
    let mut lu = DenseLu::with_ordering(order.clone(), order);
    lu.set_droppable(s * n, s * redundant);
    lu
}

/// Relative size below which the `W_s` term is left out of the Newton Jacobian (see
/// `jacobian_dense`).
const W_JACOBIAN_SKIP: f64 = 1e-4;

/// Jacobians between two checks of the `W_s` term's size.
const W_SKIP_RECHECK: usize = 8;

impl Galerkin {
    /// Jacobian of the stage equations at `self.x` (after `residual` at the same point), factored.
    pub(super) fn jacobian_dense(
        &mut self,
        sys: &System,
        t: f64,
        h: f64,
    ) -> Result<(), SolveError> {
        let (n, m, s) = (self.n, self.m, self.tab.s);
        let s1 = s + 1;
        let qs = &self.qn[s * n..(s + 1) * n];
        sys.phi_q(qs, t + self.tab.tau[s] * h, &mut self.phiq[s]);
        let any_hessian = self.has_forces || !self.pre.is_empty() || self.nonconservative;
        // The W_s term of the momentum rows' Jacobian is h^2 gk M^-1 A (Pi A)^s, at most
        // h^2 |gk| rho^(s+1) against the identity blocks (rho: a bound on the spectral radius
        // of M^-1 A at the Gauss points). Below W_JACOBIAN_SKIP it would change Newton's
        // contraction by that factor at most, so it is left out (the solution does not depend
        // on it). The bound needs A assembled: it is checked every W_SKIP_RECHECK Jacobians
        // and whenever h or gk change.
        let scale = h * h * self.gk.abs();
        if !self.pre.is_empty() && (self.w_skip_left == 0 || scale != self.w_skip_scale) {
            let mut worst = 0.0f64;
            for j in 0..s {
                let qj = &self.qj[j * n..(j + 1) * n];
                self.pre[j].set_time(t + self.tab.c[j] * h);
                let rho = self.pre[j]
                    .hessian_bound(sys, qj)
                    .map_err(|e| with_time(e, t))?;
                let size = scale * rho.powi(s as i32 + 1);
                // (NaN-safe: a NaN bound keeps the term)
                worst = if size.is_nan() {
                    f64::INFINITY
                } else {
                    worst.max(size)
                };
            }
            self.w_skip = worst <= W_JACOBIAN_SKIP;
            self.w_skip_left = W_SKIP_RECHECK;
            self.w_skip_scale = scale;
        }
        self.w_skip_left = self.w_skip_left.saturating_sub(1);
        for j in 0..s {
            if !any_hessian {
                self.hess_nz[j] = false;
                continue;
            }
            let qj = &self.qj[j * n..(j + 1) * n];
            if self.has_forces {
                sys.potential_hessian(qj, &mut self.hq[j]);
            } else {
                self.hq[j].fill(0.0);
            }
            if let Some(pre) = self.pre.get_mut(j) {
                if !self.w_skip {
                    pre.set_time(t + self.tab.c[j] * h);
                    pre.approximate_hessian(sys, qj, &mut self.wh)
                        .map_err(|e| with_time(e, t))?;
                    for (a, b) in self.hq[j].iter_mut().zip(self.wh.iter()) {
                        *a += self.gk * b;
                    }
                }
            }
            if self.nonconservative {
                self.nc_jacobian(sys, j, t + self.tab.c[j] * h, h);
            }
            self.hess_nz[j] = self.hq[j].iter().any(|&x| x != 0.0)
                || (self.nonconservative && self.hv[j].iter().any(|&x| x != 0.0));
        }
        let h2 = h * h;
        let tab = &self.tab;
        let jm = &mut self.lu;
        jm.clear();
        for nu in 0..s {
            for mu in 1..=s {
                let (ro, co) = (nu * n, (mu - 1) * n);
                let kk = tab.k[nu * s1 + mu];
                for i in 0..n {
                    jm.add(ro + i, co + i, kk * self.unit[i]);
                }
                for j in 0..s {
                    if !self.hess_nz[j] {
                        continue;
                    }
                    let ca = tab.b[j] * tab.a[j * s1 + nu] * tab.a[j * s1 + mu];
                    let cv = tab.b[j] * tab.a[j * s1 + nu] * tab.d[j * s1 + mu] / h;
                    let (hq, hv) = (self.hq[j].as_slice(), self.hv[j].as_slice());
                    for l in 0..n {
                        let hql = &hq[l * n..(l + 1) * n];
                        if self.nonconservative {
                            let hvl = &hv[l * n..(l + 1) * n];
                            for i in 0..n {
                                let v = ca * hql[i] + cv * hvl[i];
                                jm.add(ro + i, co + l, -(h2 * self.minv[i] * v));
                            }
                        } else {
                            // (zeros skipped: adding them changes nothing; e.g. the position
                            // columns of revolute-jointed bodies under W_s)
                            for (i, &hil) in hql.iter().enumerate() {
                                if hil != 0.0 {
                                    jm.add(ro + i, co + l, -(h2 * self.minv[i] * (ca * hil)));
                                }
                            }
                        }
                    }
                }
            }
            // multiplier columns
            let co = s * n + nu * m;
            for r in 0..m {
                for i in 0..n {
                    let g = self.phiq[nu][(r, i)];
                    if g != 0.0 {
                        jm.set(nu * n + i, co + r, -h2 * self.minv[i] * g);
                    }
                }
            }
        }
        // modified Lagrangian (s = 1): h M^-1 D_1 E_d in Z_1 = h v, with qbar = q_k + Z_1 / 2:
        // * the velocity part -(h^2 / 6) M^-1 E(qbar), E = 6 d^2 e / dv^2 = B + 2 C S^-1 C^T
        //   (B = A + H_sigma - 3/2 Hess V, C = [Hess Phi_k v]_k), where the residual evaluated
        //   e (its factors are reused);
        // * the leading position part (h^4 / 4) M^-1 d^2 e / dq^2 of the h^3 / 2 de/dq term,
        //   d^2 e / dq^2 ~ -1/12 A_s Pi A_s with A_s = A + H_sigma = Hess V + (sigma - mu0) .
        //   Hess Phi, the stiffness of the whole multiplier (static and centripetal): O((h^2
        //   rho)^2) against the identity (rho the spectral radius of M^-1 A_s), the one that
        //   slows Newton on stiff chains, and on long swinging ones through sigma.
        // The other position derivatives (O(h) relative to the velocity part, or linear in the
        // third derivatives) are left out (docs/symplectic.md, section 5a); the converged
        // solution does not depend on them.
        // Both blocks are dense on the coordinates K that enter V and the constraints
        // non-linearly (S^-1 and Pi are dense), which fills the stage LU there. Sparser
        // approximations of either block cost more Newton iterations than they save
        // (docs/symplectic.md section 8, "Cost of the preadjusted steps"): only dropping both
        // off-diagonals removes the fill, and the extra iterations cost as much as it saves
        // here; the sparse path, where the fill would cost O(N^3), takes the diagonals
        // (sparse.rs, docs/symplectic.md section 5a).
        if let Some(ml) = self.ml.first_mut().filter(|_| s == 1) {
            // (s = 2: the h^4 e4 term is left out of the Newton matrix)
            // (the slice's fill is a memset; the matrix's goes entry by entry)
            self.wh.as_mut_slice().fill(0.0);
            ml.set_time(t + 0.5 * h);
            ml.add_modified_velocity_hessian(sys, &self.mlmid, &self.mlvel, 2.0, &mut self.wh)
                .map_err(|e| with_time(e, t))?;
            // (s = 1 has no interior control point: hc is free)
            ml.modified_position_hessian(sys, &self.mlmid, &self.mlvel, &mut self.hc)
                .map_err(|e| with_time(e, t))?;
            let jm = &mut self.lu;
            let (cw, ch) = (-h2 / 12.0, -(h2 * h2) / 48.0);
            // by columns; both blocks are zero outside the coordinates that enter V and the
            // constraints non-linearly (e.g. the angles of a revolute chain under gravity)
            let cols = self.wh.as_slice().chunks_exact(n);
            for (l, (w, a)) in cols.zip(self.hc.as_slice().chunks_exact(n)).enumerate() {
                if w.iter().chain(a).all(|&x| x == 0.0) {
                    continue;
                }
                for (i, ((&wi, &ai), &mi)) in w.iter().zip(a).zip(&self.minv).enumerate() {
                    let b = cw * wi + ch * ai;
                    if b != 0.0 {
                        jm.add(i, l, mi * b);
                    }
                }
            }
        }
        // constraint curvature at the interior control points
        for nu in 1..s {
            let lam = &self.x[s * n + nu * m..s * n + (nu + 1) * m];
            sys.constraint_hessian(
                &self.qn[nu * n..(nu + 1) * n],
                t + self.tab.tau[nu] * h,
                lam,
                &mut self.hc,
            );
            let jm = &mut self.lu;
            let o = (nu - 1) * n;
            for l in 0..n {
                for i in 0..n {
                    let c = self.hc[(i, l)];
                    if c != 0.0 {
                        jm.add(nu * n + i, o + l, -(h2 * self.minv[i] * c));
                    }
                }
            }
        }
        {
            let jm = &mut self.lu;
            for nu in 1..=s {
                let ro = s * n + (nu - 1) * m;
                let co = (nu - 1) * n;
                for r in 0..m {
                    for l in 0..n {
                        let g = self.phiq[nu][(r, l)];
                        if g != 0.0 {
                            jm.set(ro + r, co + l, g);
                        }
                    }
                }
            }
        }
        self.jacobians += 1;
        self.jac_valid = false;
        let res = self.lu.factor_lu();
        self.stage_error(sys, t, h, res)
    }

    /// Jacobians of the non-conservative forces at Gauss point `j`, element by element (a
    /// custom law's own, else central differences of the element):
    /// `hq[j] -= dQnc/dq`, `hv[j] = -dQnc/dv`.
    fn nc_jacobian(&mut self, sys: &System, j: usize, tj: f64, h: f64) {
        let n = self.n;
        let [q, v, ..] = &mut self.tn;
        q.copy_from_slice(&self.qj[j * n..(j + 1) * n]);
        for i in 0..n {
            v[i] = self.hvj[j * n + i] / h;
        }
        let (hq, hv) = (&mut self.hq[j], &mut self.hv[j]);
        hv.fill(0.0);
        sys.nonconservative_jacobian(q, v, tj, |r, c, dq, dv| {
            hq[(r, c)] -= dq;
            hv[(r, c)] -= dv;
        });
    }
}
