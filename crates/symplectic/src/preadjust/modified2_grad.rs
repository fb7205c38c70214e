//! Exact gradients of the `h^4` modified-Lagrangian term `e4(q, v)` (`modified2.rs`): one
//! forward evaluation that keeps its intermediates ([`E4Forward`]), then a reverse
//! (adjoint) pass through them, so `de4/dq` and `de4/dv` cost a fixed number of passes over the
//! elements, independent of `n` (central differences took `8 n` evaluations of `e4`).
//!
//! The reverse pass needs, besides the linear algebra's adjoints, the adjoints of three
//! primitives:
//!
//! * a directional pass `D^k f(q)(w, .., w)`, `k = 2..4` ([`System::constraint_directional`],
//!   [`System::potential_directional`]): its gradients in `q` and in `w` come from one pass of
//!   Taylor series with gradients ([`System::constraint_directional_grad`],
//!   [`System::potential_directional_grad`]);
//! * a Hessian-vector product `y = H x`, `H = p Hess V + sum_r w_r Hess Phi_r`: with the
//!   adjoint `yb`, `xb += H yb`, `wb_r += yb^T Hess Phi_r x` and `qb += D^3 L(x, yb, .)`, the
//!   last from two third-order passes by polarisation,
//!   `D^3 L(x, y, .) = [D^3 L(x + y, x + y, .) - D^3 L(x - y, x - y, .)] / 4`;
//! * `G = Phi_q` itself: every linear-algebra adjoint leaves `Gb` as a sum of outer products
//!   `alpha beta^T`, collected in element-local form, and `qb += sum_r Hess Phi_r Gb_r`.
//!
//! The linear-algebra adjoints (`D = M^-1`, `S = G D G^T`, `Pi = D - D G^T S^-1 G D`):
//!
//! * `c a^T Pi b`: `ab += c Pi b`, `bb += c Pi a`,
//!   `Gb -= c [p_b (Pi a)^T + p_a (Pi b)^T]` with `p_x = S^-1 G D x`;
//! * `c a^T S^-1 b`: `ab += c S^-1 b`, `bb += c S^-1 a`,
//!   `Gb -= c [al (D G^T be)^T + be (D G^T al)^T]` with `al = S^-1 a`, `be = S^-1 b`;
//! * `y = -D G^T z`: `zb -= G D yb`, `Gb -= z (D yb)^T`; and `z = S^-1 x`: `xb += S^-1 zb`,
//!   `Gb -= a (D G^T z)^T + z (D G^T a)^T` with `a = S^-1 zb`;
//! * `u = -D g + D G^T mu0`, `mu0 = S^-1 G D g` (`g = grad V`), and `gb` to `qb` by `Hess V`.

use super::modified2::{comb, Dirs, E4_TERMS};
use super::Preadjustment;
use mbd_model::System;
use mbd_solve::SolveError;

/// Adjoint weights of one directional pass: of its rows' `[D^2, D^3, D^4]` and of the
/// potential's.
struct PassAdj {
    rows: Vec<[f64; 3]>,
    pot: [f64; 3],
}

impl PassAdj {
    fn new(m: usize) -> Self {
        PassAdj {
            rows: vec![[0.0; 3]; m],
            pot: [0.0; 3],
        }
    }
}

fn axpy(y: &mut [f64], c: f64, x: &[f64]) {
    for (a, b) in y.iter_mut().zip(x) {
        *a += c * b;
    }
}

/// The element-local column indices of each constraint row (`None`: ground).
fn local_columns(sys: &System) -> Vec<[Option<usize>; 6]> {
    (0..sys.n_constraints())
        .map(|r| {
            let (a, b) = sys
                .equation_joint(r)
                .map_or((None, None), |j| sys.joint_bodies(j));
            let mut c = [None; 6];
            for (slot, body) in [(0, a), (3, b)] {
                if let Some(i) = body {
                    for k in 0..3 {
                        c[slot + k] = Some(3 * i + k);
                    }
                }
            }
            c
        })
        .collect()
}

/// The adjoint of `G = Phi_q` in element-local form: `gbar[r][l]` for the local column `l` of
/// row `r`.
struct GBar<'a> {
    cols: &'a [[Option<usize>; 6]],
    gbar: Vec<[f64; 6]>,
}

impl GBar<'_> {
    /// `Gb += c alpha beta^T`.
    fn add(&mut self, c: f64, alpha: &[f64], beta: &[f64]) {
        for ((g, cols), &a) in self.gbar.iter_mut().zip(self.cols).zip(alpha) {
            if a == 0.0 {
                continue;
            }
            for (gl, col) in g.iter_mut().zip(cols) {
                if let Some(i) = col {
                    *gl += c * a * beta[*i];
                }
            }
        }
    }
}

impl Preadjustment {
    /// `D G^T x` (x of length m).
    fn dgt(&self, x: &[f64]) -> Vec<f64> {
        let m = self.m;
        if m == 0 {
            return vec![0.0; self.n];
        }
        self.gq
            .as_slice()
            .chunks_exact(m)
            .zip(&self.minv)
            .map(|(col, mi)| mi * col.iter().zip(x).map(|(a, b)| a * b).sum::<f64>())
            .collect()
    }

    /// `S^-1 G D x` (x of length n).
    fn sgd(&mut self, x: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.m];
        self.sgm(x, &mut out);
        out
    }

    /// `c a^T Pi b`: returns the increments of `ab` and `bb`, adds to `Gb`.
    fn adj_pi(&mut self, gb: &mut GBar, c: f64, a: &[f64], b: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let (pa, pb) = (self.pi_times(a), self.pi_times(b));
        let (sa, sb) = (self.sgd(a), self.sgd(b));
        gb.add(-c, &sb, &pa);
        gb.add(-c, &sa, &pb);
        (
            pb.iter().map(|x| c * x).collect(),
            pa.iter().map(|x| c * x).collect(),
        )
    }

    /// `c a^T S^-1 b`: returns the increments of `ab` and `bb`, adds to `Gb`.
    fn adj_s(&mut self, gb: &mut GBar, c: f64, a: &[f64], b: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let (al, be) = (self.s_inv(a), self.s_inv(b));
        let (dal, dbe) = (self.dgt(&al), self.dgt(&be));
        gb.add(-c, &al, &dbe);
        gb.add(-c, &be, &dal);
        (
            be.iter().map(|x| c * x).collect(),
            al.iter().map(|x| c * x).collect(),
        )
    }

    /// `y = -D G^T z` with `z = S^-1 x`: the adjoint `xb` from `yb`, adds to `Gb`.
    fn adj_neg_e(&mut self, gb: &mut GBar, z: &[f64], yb: &[f64]) -> Vec<f64> {
        let dyb: Vec<f64> = yb.iter().zip(&self.minv).map(|(y, d)| d * y).collect();
        gb.add(-1.0, z, &dyb);
        let a: Vec<f64> = self.sgd(yb).iter().map(|x| -x).collect();
        let (dz, da) = (self.dgt(z), self.dgt(&a));
        gb.add(-1.0, &a, &dz);
        gb.add(-1.0, z, &da);
        a
    }

    /// The value of `e4(q, v)` ([`Preadjustment::modified_term_s2`]) and its exact gradients
    /// `de4/dq` into `gq` and `de4/dv` into `gv` (both length n, overwritten), by one forward
    /// evaluation and a reverse pass (module doc). Allocates.
    pub fn modified_gradients_s2(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        gq: &mut [f64],
        gv: &mut [f64],
    ) -> Result<f64, SolveError> {
        self.check_v(v)?;
        let (n, m) = (self.n, self.m);
        for (what, got) in [("de4/dq", gq.len()), ("de4/dv", gv.len())] {
            if got != n {
                return Err(SolveError::Dimension {
                    what,
                    expected: n,
                    got,
                });
            }
        }
        let f = self.e4_forward(sys, q, v)?;
        let c: Vec<f64> = E4_TERMS.iter().map(|t| t.1).collect();
        let e4 = f.terms().iter().zip(&c).map(|(t, c)| t * c).sum();
        gq.fill(0.0);
        gv.fill(0.0);
        let cols = local_columns(sys);
        let mut gb = GBar {
            cols: &cols,
            gbar: vec![[0.0; 6]; m],
        };
        let zn = || vec![0.0; n];
        let zm = || vec![0.0; m];
        let (mut ub, mut nnb, mut k2b, mut k3b, mut gradb) = (zn(), zn(), zn(), zn(), zn());
        let (mut hvb, mut hub, mut hnb) = (zn(), zn(), zn());
        let (mut hmu_vb, mut hmu_ub, mut hsig_vb, mut hsig_ub) = (zn(), zn(), zn(), zn());
        let (mut mu0b, mut sigb, mut betab, mut kap3b, mut kap3ub, mut kap4b) =
            (zm(), zm(), zm(), zm(), zm(), zm());
        let pa = || PassAdj::new(m);
        let (mut a_dv, mut a_du, mut a_dn) = (pa(), pa(), pa());
        let (mut a_dupv, mut a_dumv, mut a_dnpv, mut a_dnmv) = (pa(), pa(), pa(), pa());
        let (mut a_dnpu, mut a_dnmu) = (pa(), pa());
        let (mut a_dk2p, mut a_dk2m, mut a_dk3p, mut a_dk3m) = (pa(), pa(), pa(), pa());

        // 1. the terms
        let (x, y) = self.adj_pi(&mut gb, c[0], &f.hsig_v, &f.hmu_v);
        axpy(&mut hsig_vb, 1.0, &x);
        axpy(&mut hmu_vb, 1.0, &y);
        let (x, y) = self.adj_pi(&mut gb, c[1], &f.hmu_v, &f.hmu_v);
        axpy(&mut hmu_vb, 1.0, &x);
        axpy(&mut hmu_vb, 1.0, &y);
        axpy(&mut ub, c[2], &f.hmu_u);
        axpy(&mut hmu_ub, c[2], &f.u);
        let (x, y) = self.adj_pi(&mut gb, c[3], &f.hmu_v, &f.hv);
        axpy(&mut hmu_vb, 1.0, &x);
        axpy(&mut hvb, 1.0, &y);
        let (x, y) = self.adj_s(&mut gb, c[4], &f.beta, &f.beta);
        axpy(&mut betab, 1.0, &x);
        axpy(&mut betab, 1.0, &y);
        axpy(&mut ub, c[5], &f.hsig_u);
        axpy(&mut hsig_ub, c[5], &f.u);
        let (x, y) = self.adj_s(&mut gb, c[6], &f.kap3, &f.beta);
        axpy(&mut kap3b, 1.0, &x);
        axpy(&mut betab, 1.0, &y);
        axpy(&mut hvb, c[7], &f.k2);
        axpy(&mut k2b, c[7], &f.hv);
        axpy(&mut mu0b, c[8], &f.kap3u);
        axpy(&mut kap3ub, c[8], &f.mu0);
        axpy(&mut sigb, c[9], &f.kap3u);
        axpy(&mut kap3ub, c[9], &f.sig);
        axpy(&mut mu0b, c[10], &f.kap4);
        axpy(&mut kap4b, c[10], &f.mu0);
        axpy(&mut hub, c[11], &f.nn);
        axpy(&mut nnb, c[11], &f.hu);
        axpy(&mut ub, c[12], &f.hu);
        axpy(&mut hub, c[12], &f.u);
        // D^3 V(u, v, v) = (D^3 V(u + v) + D^3 V(u - v) - 2 D^3 V(u)) / 6
        a_dupv.pot[1] += c[13] / 6.0;
        a_dumv.pot[1] += c[13] / 6.0;
        a_du.pot[1] -= c[13] / 3.0;
        axpy(&mut nnb, c[14], &f.hn);
        axpy(&mut hnb, c[14], &f.nn);
        let (x, y) = self.adj_pi(&mut gb, c[15], &f.hv, &f.hsig_v);
        axpy(&mut hvb, 1.0, &x);
        axpy(&mut hsig_vb, 1.0, &y);
        axpy(&mut hvb, c[16], &f.k3);
        axpy(&mut k3b, c[16], &f.hv);
        a_dnpv.pot[1] += c[17] / 6.0;
        a_dnmv.pot[1] += c[17] / 6.0;
        a_dn.pot[1] -= c[17] / 3.0;
        let (x, y) = self.adj_pi(&mut gb, c[18], &f.hv, &f.hv);
        axpy(&mut hvb, 1.0, &x);
        axpy(&mut hvb, 1.0, &y);
        a_dv.pot[2] += c[19];
        let (x, y) = self.adj_pi(&mut gb, c[20], &f.hsig_v, &f.hsig_v);
        axpy(&mut hsig_vb, 1.0, &x);
        axpy(&mut hsig_vb, 1.0, &y);
        axpy(&mut sigb, c[21], &f.kap4);
        axpy(&mut kap4b, c[21], &f.sig);
        let (x, y) = self.adj_s(&mut gb, c[22], &f.kap3, &f.kap3);
        axpy(&mut kap3b, 1.0, &x);
        axpy(&mut kap3b, 1.0, &y);

        // 2. the Hessian-vector products
        let u = f.u.clone();
        let nn = f.nn.clone();
        hvp_adj(
            sys,
            q,
            &u,
            0.0,
            Some((&f.sig, &mut sigb)),
            &hsig_ub,
            &mut ub,
            gq,
        );
        hvp_adj(sys, q, v, 0.0, Some((&f.sig, &mut sigb)), &hsig_vb, gv, gq);
        hvp_adj(
            sys,
            q,
            &u,
            0.0,
            Some((&f.mu0, &mut mu0b)),
            &hmu_ub,
            &mut ub,
            gq,
        );
        hvp_adj(sys, q, v, 0.0, Some((&f.mu0, &mut mu0b)), &hmu_vb, gv, gq);
        hvp_adj(sys, q, &nn, 1.0, None, &hnb, &mut nnb, gq);
        hvp_adj(sys, q, &u, 1.0, None, &hub, &mut ub, gq);
        hvp_adj(sys, q, v, 1.0, None, &hvb, gv, gq);

        // 3. kappa4 = D^4 Phi(v^4) + 6 vvn + 3 D^2 Phi(n, n) + 4 h_k3v,
        //    kappa3u = vvu + 2 h_k2v + h_nu, and the polarisations behind them
        for r in 0..m {
            let (k4, k3u) = (kap4b[r], kap3ub[r]);
            a_dv.rows[r][2] += k4;
            a_dn.rows[r][0] += 3.0 * k4;
            // vvn = (D^3(n + v) + D^3(n - v) - 2 D^3(n)) / 6, weight 6 kappa4b
            a_dnpv.rows[r][1] += k4;
            a_dnmv.rows[r][1] += k4;
            a_dn.rows[r][1] -= 2.0 * k4;
            // h_k3v = (D^2(k3 + v) - D^2(k3 - v)) / 4, weight 4 kappa4b
            a_dk3p.rows[r][0] += k4;
            a_dk3m.rows[r][0] -= k4;
            // vvu likewise, weight kappa3ub
            a_dupv.rows[r][1] += k3u / 6.0;
            a_dumv.rows[r][1] += k3u / 6.0;
            a_du.rows[r][1] -= k3u / 3.0;
            // h_k2v, weight 2 kappa3ub; h_nu, weight kappa3ub
            a_dk2p.rows[r][0] += 0.5 * k3u;
            a_dk2m.rows[r][0] -= 0.5 * k3u;
            a_dnpu.rows[r][0] += 0.25 * k3u;
            a_dnmu.rows[r][0] -= 0.25 * k3u;
        }

        // 4. the passes along k3 +- v and k2 +- v
        let mut wb = zn();
        for (dir, adj, sign) in [(&f.k3, &a_dk3p, 1.0), (&f.k3, &a_dk3m, -1.0)] {
            pass_adj(sys, q, &comb(dir, 1.0, v, sign), adj, gq, &mut wb);
            axpy(&mut k3b, 1.0, &wb);
            axpy(gv, sign, &wb);
        }
        for (dir, adj, sign) in [(&f.k2, &a_dk2p, 1.0), (&f.k2, &a_dk2m, -1.0)] {
            pass_adj(sys, q, &comb(dir, 1.0, v, sign), adj, gq, &mut wb);
            axpy(&mut k2b, 1.0, &wb);
            axpy(gv, sign, &wb);
        }

        // 5. k3 = -D G^T S^-1 kappa3, kappa3 = D^3 Phi(v^3) + 3 h_nv
        let x = self.adj_neg_e(&mut gb, &f.s_kap3, &k3b);
        axpy(&mut kap3b, 1.0, &x);
        for r in 0..m {
            a_dv.rows[r][1] += kap3b[r];
            a_dnpv.rows[r][0] += 0.75 * kap3b[r];
            a_dnmv.rows[r][0] -= 0.75 * kap3b[r];
        }
        // 6. k2 = -D G^T S^-1 beta, beta = (D^2(u + v) - D^2(u - v)) / 4
        let x = self.adj_neg_e(&mut gb, &f.s_beta, &k2b);
        axpy(&mut betab, 1.0, &x);
        for r in 0..m {
            a_dupv.rows[r][0] += 0.25 * betab[r];
            a_dumv.rows[r][0] -= 0.25 * betab[r];
        }

        // 7. the passes along n +- u, n +- v, u +- v, u and n
        for (a, b, adj, sign) in [(&nn, &u, &a_dnpu, 1.0), (&nn, &u, &a_dnmu, -1.0)] {
            pass_adj(sys, q, &comb(a, 1.0, b, sign), adj, gq, &mut wb);
            axpy(&mut nnb, 1.0, &wb);
            axpy(&mut ub, sign, &wb);
        }
        for (adj, sign) in [(&a_dnpv, 1.0), (&a_dnmv, -1.0)] {
            pass_adj(sys, q, &comb(&nn, 1.0, v, sign), adj, gq, &mut wb);
            axpy(&mut nnb, 1.0, &wb);
            axpy(gv, sign, &wb);
        }
        for (adj, sign) in [(&a_dupv, 1.0), (&a_dumv, -1.0)] {
            pass_adj(sys, q, &comb(&u, 1.0, v, sign), adj, gq, &mut wb);
            axpy(&mut ub, 1.0, &wb);
            axpy(gv, sign, &wb);
        }
        pass_adj(sys, q, &u, &a_du, gq, &mut wb);
        axpy(&mut ub, 1.0, &wb);
        pass_adj(sys, q, &nn, &a_dn, gq, &mut wb);
        axpy(&mut nnb, 1.0, &wb);

        // 8. n = -D G^T sigma, sigma = S^-1 gamma, gamma = D^2 Phi(v, v)
        let gsig: Vec<f64> = {
            let mut t = vec![0.0; m];
            let dn: Vec<f64> = nnb.iter().zip(&self.minv).map(|(x, d)| d * x).collect();
            super::gm_times(&self.gq, &dn, &mut t);
            gb.add(-1.0, &f.sig, &dn);
            t
        };
        axpy(&mut sigb, -1.0, &gsig);
        let a = self.s_inv(&sigb);
        let (dsig, da) = (self.dgt(&f.sig), self.dgt(&a));
        gb.add(-1.0, &a, &dsig);
        gb.add(-1.0, &f.sig, &da);
        for r in 0..m {
            a_dv.rows[r][0] += a[r];
        }
        pass_adj(sys, q, v, &a_dv, gq, &mut wb);
        axpy(gv, 1.0, &wb);

        // 9. u = -D g + D G^T mu0, mu0 = S^-1 G D g, g = grad V
        let dub: Vec<f64> = ub.iter().zip(&self.minv).map(|(x, d)| d * x).collect();
        {
            let mut t = vec![0.0; m];
            super::gm_times(&self.gq, &dub, &mut t);
            axpy(&mut mu0b, 1.0, &t);
        }
        axpy(&mut gradb, -1.0, &dub);
        gb.add(1.0, &f.mu0, &dub);
        let a = self.s_inv(&mu0b);
        let da = self.dgt(&a);
        axpy(&mut gradb, 1.0, &da);
        let dg: Vec<f64> = self.g.iter().zip(&self.minv).map(|(x, d)| d * x).collect();
        gb.add(1.0, &a, &dg);
        let dmu = self.dgt(&f.mu0);
        gb.add(-1.0, &a, &dmu);
        gb.add(-1.0, &f.mu0, &da);
        let mut t = zn();
        sys.lagrangian_hessian_vector(q, &gradb, 1.0, &zm(), &mut t);
        axpy(gq, 1.0, &t);

        // 10. G's adjoint: qb += sum_r Hess Phi_r Gb_r
        sys.add_constraint_hessian_rows(q, &gb.gbar, gq);
        Ok(e4)
    }
}

/// The adjoint of `y = H x`, `H = pot Hess V + sum_r w_r Hess Phi_r` (`w` with its adjoint,
/// or none), for the adjoint `yb`: `xb += H yb`, `wb_r += yb^T Hess Phi_r x`,
/// `qb += D^3 L(x, yb, .)`.
#[allow(clippy::too_many_arguments)]
fn hvp_adj(
    sys: &System,
    q: &[f64],
    x: &[f64],
    pot: f64,
    w: Option<(&Vec<f64>, &mut Vec<f64>)>,
    yb: &[f64],
    xb: &mut [f64],
    qb: &mut [f64],
) {
    if yb.iter().all(|&y| y == 0.0) {
        return;
    }
    let n = x.len();
    let m = sys.n_constraints();
    let (xp, xm) = (comb(x, 1.0, yb, 1.0), comb(x, 1.0, yb, -1.0));
    let zero = vec![0.0; m];
    let (wv, wb) = match w {
        Some((wv, wb)) => (wv.as_slice(), Some(wb)),
        None => (zero.as_slice(), None),
    };
    let (mut hp, mut hm, mut dp, mut dm) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    sys.lagrangian_third(q, &xp, pot, wv, &mut hp, &mut dp);
    sys.lagrangian_third(q, &xm, pot, wv, &mut hm, &mut dm);
    for i in 0..n {
        xb[i] += 0.5 * (hp[i] - hm[i]);
        qb[i] += 0.25 * (dp[i] - dm[i]);
    }
    if let Some(wb) = wb {
        let (p, mm) = (Dirs::along(sys, q, &xp), Dirs::along(sys, q, &xm));
        for r in 0..m {
            wb[r] += 0.25 * (p.rows[r][0] - mm.rows[r][0]);
        }
    }
}

/// The adjoint of a directional pass along `w`: adds its `q`-gradient to `qb` and writes its
/// `w`-gradient into `wb` (overwritten).
fn pass_adj(sys: &System, q: &[f64], w: &[f64], a: &PassAdj, qb: &mut [f64], wb: &mut [f64]) {
    wb.fill(0.0);
    sys.constraint_directional_grad(q, w, &a.rows, qb, wb);
    sys.potential_directional_grad(q, w, a.pot, qb, wb);
}

#[cfg(test)]
mod tests {
    use super::*;
    use mbd_model::models;

    /// The reverse-pass gradients against fourth-order central differences of `e4`, on paper
    /// A's double pendulum, a rod with a spring and a four-bar loop, at generic states.
    #[test]
    fn gradients_match_differences() {
        let systems = [
            models::paper_a_double_pendulum().unwrap(),
            super::super::modified::modlag_tests::rod_with_spring(),
            models::n_link_chain(3).unwrap(),
        ];
        for sys in &systems {
            let n = sys.n_coords();
            let q: Vec<f64> = (0..n)
                .map(|i| 0.3 + 0.17 * i as f64 - 0.05 * (i * i) as f64)
                .collect();
            let v: Vec<f64> = (0..n)
                .map(|i| 0.4 - 0.23 * i as f64 + 0.03 * (i * i) as f64)
                .collect();
            let mut p = Preadjustment::new(sys, 2).unwrap();
            let (mut gq, mut gv) = (vec![0.0; n], vec![0.0; n]);
            let e4 = p
                .modified_gradients_s2(sys, &q, &v, &mut gq, &mut gv)
                .unwrap();
            let e4b = p.modified_term_s2(sys, &q, &v).unwrap();
            assert!((e4 - e4b).abs() <= 1e-13 * e4.abs().max(1.0));
            let d = 1e-4;
            let mut fd = |x: &[f64], wrt_q: bool, l: usize| -> f64 {
                let mut acc = 0.0;
                for (cf, k) in [(8.0, 1.0), (-8.0, -1.0), (-1.0, 2.0), (1.0, -2.0)] {
                    let mut y = x.to_vec();
                    y[l] += k * d;
                    let val = if wrt_q {
                        p.modified_term_s2(sys, &y, &v).unwrap()
                    } else {
                        p.modified_term_s2(sys, &q, &y).unwrap()
                    };
                    acc += cf * val;
                }
                acc / (12.0 * d)
            };
            let scale = gq.iter().chain(&gv).fold(1e-30f64, |a, x| a.max(x.abs()));
            let mut worst = 0.0f64;
            for l in 0..n {
                let (a, b) = (fd(&q, true, l), fd(&v, false, l));
                worst = worst.max((a - gq[l]).abs()).max((b - gv[l]).abs());
                assert!(
                    (a - gq[l]).abs() < 1e-7 * scale,
                    "de4/dq[{l}]: {} vs {a}",
                    gq[l]
                );
                assert!(
                    (b - gv[l]).abs() < 1e-7 * scale,
                    "de4/dv[{l}]: {} vs {b}",
                    gv[l]
                );
            }
            eprintln!("n = {n}: worst gradient difference {worst:.2e} of {scale:.3e}");
        }
    }
}
