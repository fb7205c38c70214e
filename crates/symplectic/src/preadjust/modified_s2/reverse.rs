//! Exact gradients of the `h^4` modified-Lagrangian term `e4(q, v)`: one forward evaluation
//! that keeps its intermediates ([`E4Forward`]), then a reverse (adjoint) pass through them, so
//! `de4/dq` and `de4/dv` cost a fixed number of passes over the elements, independent of `n`.
//! Both run in a workspace allocated on first use ([`ModifiedS2`]): nothing is allocated per
//! call. Every element pass at `q` takes the bodies' `sin`/`cos` from one table
//! ([`mbd_model::BodyAngles`]).
//!
//! The reverse pass needs, besides the linear algebra's adjoints, the adjoints of three
//! primitives:
//!
//! * a pass of multivariate Taylor jets ([`mbd_model::PolyJet`]; passes A, B, C of
//!   `forward.rs`): the forward evaluation keeps every coefficient's element-local gradient
//!   with respect to `q`, and the reverse pass contracts them with the coefficients' adjoint
//!   weights, which gives the gradient with respect to `q` and, through the basis' division
//!   table, with respect to every direction of the pass
//!   ([`passes::add_constraint_poly_adjoint`](crate::passes::add_constraint_poly_adjoint), [`passes::add_potential_poly_adjoint`](crate::passes::add_potential_poly_adjoint): one
//!   sweep, no element evaluated again);
//! * the four constraint-weighted Hessian-vector products `y = H_w x` (`H_w = sum_r w_r Hess
//!   Phi_r`, `(x, w)` = `(v, sigma)`, `(v, mu0)`, `(u, sigma)`, `(u, mu0)`): with the adjoints
//!   `yb`, `xb += H_w yb`, `wb_r += yb^T Hess Phi_r x` and `qb += D^3 (w . Phi)(x, yb, .)`, all
//!   from one jet pass R along `(v, u, yb_1, .., yb_4)` (the coefficients of `x yb` and `yb`
//!   and their gradients); those of `Hess V` (force elements only) by two third-order passes
//!   each, `D^3 L(x, y, .) = [D^3 L(x + y, x + y, .) - D^3 L(x - y, x - y, .)] / 4`;
//! * `G = Phi_q` itself: every linear-algebra adjoint leaves `Gb` as a sum of outer products
//!   `alpha beta^T`, collected in element-local form, and `qb += sum_r Hess Phi_r Gb_r`
//!   ([`passes::add_constraint_hessian_rows`](crate::passes::add_constraint_hessian_rows)).
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

use super::adjoints::{gbar_add, Adjoints, GbCtx};
use super::forward::E4Forward;
use super::passes::{
    BasisA, BasisB, BasisC, BasisR, Pass, A_ET, A_ETT, A_T4, A_TT, A_TTT, B_ED, B_EE, B_ET, B_ETT,
    C_AT, C_BT, NA, NB, NC, NR, R_DIRS, R_OUTPUTS, R_XY, R_Y,
};
use super::spatial::SpatialRowSet;
use super::{e4_value, Invariant, ModifiedS2, PerInvariant};
use crate::passes;
use crate::preadjust::metric::ProjectedMetric;
use crate::preadjust::LocalRow;
use mbd_model::{Basis, BodyAngles, System};
use mbd_solve::linalg::axpy;

/// `out = ca a + cb b`.
fn comb_into(a: &[f64], ca: f64, b: &[f64], cb: f64, out: &mut [f64]) {
    for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
        *o = ca * x + cb * y;
    }
}

/// `y = -D G^T z` with `z = S^-1 x`: leaves the increment of `xb` in `w.tm[0]` for the
/// adjoint `yb`; `Gb` updated.
fn adj_neg_e(metric: &mut ProjectedMetric, w: &mut Adjoints, cx: GbCtx, z: &[f64], yb: &[f64]) {
    let [dyb, dz, da, ..] = &mut w.tn;
    for ((d, y), mi) in dyb.iter_mut().zip(yb).zip(metric.minv()) {
        *d = mi * y;
    }
    gbar_add(&mut w.gbar, &mut w.sgq, cx, -1.0, z, dyb);
    let a = &mut w.tm[0];
    metric.sgm(yb, a);
    a.iter_mut().for_each(|x| *x = -*x);
    metric.dgt_into(z, dz);
    metric.dgt_into(a, da);
    gbar_add(&mut w.gbar, &mut w.sgq, cx, -1.0, a, dz);
    gbar_add(&mut w.gbar, &mut w.sgq, cx, -1.0, z, da);
}

impl ModifiedS2 {
    /// The value of `e4(q, v)` and its exact gradients `de4/dq` into `gq` and `de4/dv` into
    /// `gv` (both length n, checked by the caller, overwritten), by one forward evaluation
    /// and a reverse pass (module doc).
    pub(in crate::preadjust) fn gradients(
        &mut self,
        metric: &mut ProjectedMetric,
        sys: &System,
        q: &[f64],
        v: &[f64],
        gq: &mut [f64],
        gv: &mut [f64],
    ) -> Result<f64, mbd_solve::SolveError> {
        self.forward(metric, sys, q, v)?;
        Ok(self.reverse(metric, sys, q, v, gq, gv))
    }

    /// The reverse pass after [`ModifiedS2::forward`] at the same `(q, v)`; returns `e4`.
    #[allow(clippy::too_many_arguments)]
    fn reverse(
        &mut self,
        metric: &mut ProjectedMetric,
        sys: &System,
        q: &[f64],
        v: &[f64],
        gq: &mut [f64],
        gv: &mut [f64],
    ) -> f64 {
        use Invariant::*;
        let m = metric.m();
        let ModifiedS2 { f, b: w, cols } = self;
        let (tm, cx) = (metric.t(), GbCtx::new(sys, q, metric.t(), cols));
        let e4 = e4_value(&f.terms().0);
        let c = PerInvariant::coefficients();
        gq.fill(0.0);
        gv.fill(0.0);
        w.clear();

        // 1. the terms (those with Hess V or D^k V only with force elements with a potential:
        //    gravity is linear, so without them H v, H u, H n and the potential's derivatives
        //    are zero and so is every contribution of those terms)
        let pot = super::has_potential(sys);
        let hsig_v = (f.pi_hsig_v.as_slice(), f.sg_hsig_v.as_slice());
        let hmu_v = (f.pi_hmu_v.as_slice(), f.sg_hmu_v.as_slice());
        let hv = (f.pi_hv.as_slice(), f.sg_hv.as_slice());
        adj_pi(&mut w.gbar, &mut w.sgq, cx, c[VHsigPiHmuV], hsig_v, hmu_v);
        axpy(c[VHsigPiHmuV], &f.pi_hmu_v, &mut w.hsig_vb);
        axpy(c[VHsigPiHmuV], &f.pi_hsig_v, &mut w.hmu_vb);
        adj_pi(&mut w.gbar, &mut w.sgq, cx, c[VHmuPiHmuV], hmu_v, hmu_v);
        axpy(2.0 * c[VHmuPiHmuV], &f.pi_hmu_v, &mut w.hmu_vb);
        axpy(c[UHmuU], &f.hmu_u, &mut w.ub);
        axpy(c[UHmuU], &f.u, &mut w.hmu_ub);
        let beta = (f.s_beta.as_slice(), f.k2.as_slice());
        let kap3 = (f.s_kap3.as_slice(), f.k3.as_slice());
        adj_s(&mut w.gbar, &mut w.sgq, cx, c[BetaSBeta], beta, beta);
        axpy(2.0 * c[BetaSBeta], &f.s_beta, &mut w.betab);
        axpy(c[UHsigU], &f.hsig_u, &mut w.ub);
        axpy(c[UHsigU], &f.u, &mut w.hsig_ub);
        adj_s(&mut w.gbar, &mut w.sgq, cx, c[Kappa3SBeta], kap3, beta);
        axpy(c[Kappa3SBeta], &f.s_beta, &mut w.kap3b);
        axpy(c[Kappa3SBeta], &f.s_kap3, &mut w.betab);
        axpy(c[Mu0Kappa3u], &f.kap3u, &mut w.mu0b);
        axpy(c[Mu0Kappa3u], &f.mu0, &mut w.kap3ub);
        axpy(c[SigmaKappa3u], &f.kap3u, &mut w.sigb);
        axpy(c[SigmaKappa3u], &f.sig, &mut w.kap3ub);
        axpy(c[Mu0Kappa4], &f.kap4, &mut w.mu0b);
        axpy(c[Mu0Kappa4], &f.mu0, &mut w.kap4b);
        adj_pi(&mut w.gbar, &mut w.sgq, cx, c[VHsigPiHsigV], hsig_v, hsig_v);
        axpy(2.0 * c[VHsigPiHsigV], &f.pi_hsig_v, &mut w.hsig_vb);
        axpy(c[SigmaKappa4], &f.kap4, &mut w.sigb);
        axpy(c[SigmaKappa4], &f.sig, &mut w.kap4b);
        adj_s(&mut w.gbar, &mut w.sgq, cx, c[Kappa3SKappa3], kap3, kap3);
        axpy(2.0 * c[Kappa3SKappa3], &f.s_kap3, &mut w.kap3b);
        if pot {
            adj_pi(&mut w.gbar, &mut w.sgq, cx, c[VHmuPiHV], hmu_v, hv);
            axpy(c[VHmuPiHV], &f.pi_hv, &mut w.hmu_vb);
            axpy(c[VHmuPiHV], &f.pi_hmu_v, &mut w.hvb);
            axpy(c[VHK2], &f.k2, &mut w.hvb);
            axpy(c[VHK2], &f.hv, &mut w.k2b);
            axpy(c[UHN], &f.nn, &mut w.hub);
            axpy(c[UHN], &f.hu, &mut w.nnb);
            axpy(c[UHU], &f.hu, &mut w.ub);
            axpy(c[UHU], &f.u, &mut w.hub);
            // D^3 V(u, v, v) = 2 (pass A's e t^2)
            w.pa[A_ETT] += 2.0 * c[D3VUVV];
            axpy(c[NHN], &f.hn, &mut w.nnb);
            axpy(c[NHN], &f.nn, &mut w.hnb);
            adj_pi(&mut w.gbar, &mut w.sgq, cx, c[VHPiHsigV], hv, hsig_v);
            axpy(c[VHPiHsigV], &f.pi_hsig_v, &mut w.hvb);
            axpy(c[VHPiHsigV], &f.pi_hv, &mut w.hsig_vb);
            axpy(c[VHK3], &f.k3, &mut w.hvb);
            axpy(c[VHK3], &f.hv, &mut w.k3b);
            w.pb[B_ETT] += 2.0 * c[D3VNVV];
            adj_pi(&mut w.gbar, &mut w.sgq, cx, c[VHPiHV], hv, hv);
            axpy(2.0 * c[VHPiHV], &f.pi_hv, &mut w.hvb);
            w.pa[A_T4] += 24.0 * c[D4V];
        }

        // 2. the Hessian-vector products: the constraint-weighted ones by pass R, those of V
        //    by polarised third-order passes over the force elements
        hvp_weighted_adj(metric.m(), sys, q, v, f, w, gq, gv);
        if pot {
            let zero = f.zero_m.as_slice();
            let ang = &f.angles;
            let sc = &mut w.tn[2..8];
            for (x, yb, xb) in [
                (f.nn.as_slice(), &w.hnb, &mut w.nnb),
                (f.u.as_slice(), &w.hub, &mut w.ub),
            ] {
                hvp_adj(sys, (q, tm), ang, x, (1.0, zero), yb, xb, gq, sc);
            }
            hvp_adj(sys, (q, tm), ang, v, (1.0, zero), &w.hvb, gv, gq, sc);
        }

        // 3. kappa4 = 24 A[t^4] + 12 B[e t^2] + 6 B[e^2] + 4 C[b t],
        //    kappa3u = 2 A[e t^2] + 2 C[a t] + B[e d]
        for r in 0..m {
            let (k4, k3u) = (w.kap4b[r], w.kap3ub[r]);
            w.wa[r][A_T4] += 24.0 * k4;
            w.wb[r][B_ETT] += 12.0 * k4;
            w.wb[r][B_EE] += 6.0 * k4;
            w.wc[r][C_BT] += 4.0 * k4;
            w.wa[r][A_ETT] += 2.0 * k3u;
            w.wc[r][C_AT] += 2.0 * k3u;
            w.wb[r][B_ED] += k3u;
        }

        // 4. pass C along (v, K2, K3)
        contract::<NC, BasisC>(
            sys,
            &f.sprows,
            (&f.pc, &w.wc, None),
            gq,
            &mut [&mut *gv, w.k2b.as_mut_slice(), w.k3b.as_mut_slice()],
        );

        // 5. k3 = -D G^T S^-1 kappa3, kappa3 = 6 A[t^3] + 3 B[e t]
        let k3b = std::mem::take(&mut w.k3b);
        adj_neg_e(metric, w, cx, &f.s_kap3, &k3b);
        w.k3b = k3b;
        axpy(1.0, &w.tm[0], &mut w.kap3b);
        for r in 0..m {
            w.wa[r][A_TTT] += 6.0 * w.kap3b[r];
            w.wb[r][B_ET] += 3.0 * w.kap3b[r];
        }
        // 6. k2 = -D G^T S^-1 beta, beta = A[e t]
        let k2b = std::mem::take(&mut w.k2b);
        adj_neg_e(metric, w, cx, &f.s_beta, &k2b);
        w.k2b = k2b;
        axpy(1.0, &w.tm[0], &mut w.betab);
        for r in 0..m {
            w.wa[r][A_ET] += w.betab[r];
        }

        // 7. pass B along (v, n, u)
        contract::<NB, BasisB>(
            sys,
            &f.sprows,
            (&f.pb, &w.wb, Some(&w.pb)),
            gq,
            &mut [&mut *gv, w.nnb.as_mut_slice(), w.ub.as_mut_slice()],
        );

        // 8. n = -D G^T sigma, sigma = S^-1 gamma, gamma = 2 A[t^2]
        {
            let [dn, dsig, da, ..] = &mut w.tn;
            let [t, a, ..] = &mut w.tm;
            for ((d, x), mi) in dn.iter_mut().zip(&w.nnb).zip(metric.minv()) {
                *d = mi * x;
            }
            metric.g_times(dn, t);
            gbar_add(&mut w.gbar, &mut w.sgq, cx, -1.0, &f.sig, dn);
            axpy(-1.0, t, &mut w.sigb);
            metric.s_inv_into(&w.sigb, a);
            metric.dgt_into(&f.sig, dsig);
            metric.dgt_into(a, da);
            gbar_add(&mut w.gbar, &mut w.sgq, cx, -1.0, a, dsig);
            gbar_add(&mut w.gbar, &mut w.sgq, cx, -1.0, &f.sig, da);
            for r in 0..m {
                w.wa[r][A_TT] += 2.0 * a[r];
            }
        }
        // pass A along (v, u)
        contract::<NA, BasisA>(
            sys,
            &f.sprows,
            (&f.pa, &w.wa, Some(&w.pa)),
            gq,
            &mut [&mut *gv, w.ub.as_mut_slice()],
        );

        // 9. u = -D g + D G^T mu0, mu0 = S^-1 G D g, g = grad V
        {
            let [dub, da, dg, dmu, t, ..] = &mut w.tn;
            let [s, a, ..] = &mut w.tm;
            for ((d, x), mi) in dub.iter_mut().zip(&w.ub).zip(metric.minv()) {
                *d = mi * x;
            }
            metric.g_times(dub, s);
            axpy(1.0, s, &mut w.mu0b);
            axpy(-1.0, dub, &mut w.gradb);
            gbar_add(&mut w.gbar, &mut w.sgq, cx, 1.0, &f.mu0, dub);
            metric.s_inv_into(&w.mu0b, a);
            metric.dgt_into(a, da);
            axpy(1.0, da, &mut w.gradb);
            for ((d, x), mi) in dg.iter_mut().zip(metric.grad_v()).zip(metric.minv()) {
                *d = mi * x;
            }
            gbar_add(&mut w.gbar, &mut w.sgq, cx, 1.0, a, dg);
            metric.dgt_into(&f.mu0, dmu);
            gbar_add(&mut w.gbar, &mut w.sgq, cx, -1.0, a, dmu);
            gbar_add(&mut w.gbar, &mut w.sgq, cx, -1.0, &f.mu0, da);
            passes::lagrangian_hessian_vector_at(
                sys, q, tm, &f.angles, &w.gradb, 1.0, &f.zero_m, t,
            );
            axpy(1.0, t, gq);
        }

        // 10. G's adjoint: qb += sum_r Hess Phi_r Gb_r (the spatial rows' share was added
        //     to `sgq` as Gb grew, `gbar_add`)
        passes::add_constraint_hessian_rows_at(sys, q, &f.angles, &w.gbar, gq);
        axpy(1.0, &w.sgq, gq);
        e4
    }
}

/// `c a^T Pi b` with `(Pi a, S^-1 G M^-1 a)` and `(Pi b, S^-1 G M^-1 b)` from the forward
/// evaluation: `Gb -= c [p_b (Pi a)^T + p_a (Pi b)^T]`; the increments of `ab` and `bb`,
/// `c Pi b` and `c Pi a`, are the caller's.
fn adj_pi(
    gbar: &mut [LocalRow],
    sgq: &mut [f64],
    cx: GbCtx,
    c: f64,
    (pa, sa): (&[f64], &[f64]),
    (pb, sb): (&[f64], &[f64]),
) {
    gbar_add(gbar, sgq, cx, -c, sb, pa);
    gbar_add(gbar, sgq, cx, -c, sa, pb);
}

/// `c a^T S^-1 b` with `(S^-1 a, k_a)` and `(S^-1 b, k_b)`, `k_x = -D G^T S^-1 x`, from the
/// forward evaluation: `Gb -= c [al (D G^T be)^T + be (D G^T al)^T]`, i.e.
/// `Gb += c [al k_b^T + be k_a^T]`; the increments of `ab` and `bb`, `c S^-1 b` and
/// `c S^-1 a`, are the caller's.
fn adj_s(
    gbar: &mut [LocalRow],
    sgq: &mut [f64],
    cx: GbCtx,
    c: f64,
    (al, ka): (&[f64], &[f64]),
    (be, kb): (&[f64], &[f64]),
) {
    gbar_add(gbar, sgq, cx, c, al, kb);
    gbar_add(gbar, sgq, cx, c, be, ka);
}

/// The adjoint of `y = H x`, `H = p Hess V + sum_r w_r Hess Phi_r` (`(p, w)`), for the adjoint
/// `yb`: `xb += H yb` and `qb += D^3 L(x, yb, .)`, by two third-order passes (polarisation).
/// Scratch: six n-vectors.
#[allow(clippy::too_many_arguments)]
fn hvp_adj(
    sys: &System,
    (q, tm): (&[f64], f64),
    ang: &BodyAngles,
    x: &[f64],
    (pot, wts): (f64, &[f64]),
    yb: &[f64],
    xb: &mut [f64],
    qb: &mut [f64],
    scratch: &mut [Vec<f64>],
) {
    if yb.iter().all(|&y| y == 0.0) {
        return;
    }
    let [xp, xm, hp, hm, dp, dm] = scratch else {
        return;
    };
    comb_into(x, 1.0, yb, 1.0, xp);
    comb_into(x, 1.0, yb, -1.0, xm);
    passes::lagrangian_third_at(sys, q, tm, ang, xp, pot, wts, hp, dp);
    passes::lagrangian_third_at(sys, q, tm, ang, xm, pot, wts, hm, dm);
    for i in 0..x.len() {
        xb[i] += 0.5 * (hp[i] - hm[i]);
        qb[i] += 0.25 * (dp[i] - dm[i]);
    }
}

/// The adjoints of the four constraint-weighted Hessian-vector products `y = H_w x`
/// (`H_w = sum_r w_r Hess Phi_r`) for `(x, w) = (v, sigma), (v, mu0), (u, sigma), (u,
/// mu0)` with the adjoints `yb`, from one pass R ([`BasisR`](super::passes::BasisR)): `qb += D^3 (w . Phi)(x, yb,
/// .)` (the `q`-gradients of `x yb`), `xb += H_w yb` (those of `yb`), `wb_r += yb^T Hess
/// Phi_r x` (the coefficients of `x yb`).
#[allow(clippy::too_many_arguments)]
fn hvp_weighted_adj(
    m: usize,
    sys: &System,
    q: &[f64],
    v: &[f64],
    f: &E4Forward,
    w: &mut Adjoints,
    gq: &mut [f64],
    gv: &mut [f64],
) {
    let dirs: [&[f64]; R_DIRS] = [v, &f.u, &w.hsig_vb, &w.hmu_vb, &w.hsig_ub, &w.hmu_ub];
    w.rpass
        .eval_constraints(sys, q, (&f.angles, &f.sprows), &dirs);
    for r in 0..m {
        let (s, mu) = (f.sig[r], f.mu0[r]);
        let c = &w.rpass.vals[r];
        w.sigb[r] += c[R_XY[0]] + c[R_XY[2]];
        w.mu0b[r] += c[R_XY[1]] + c[R_XY[3]];
        // weights of q (the x yb coefficients), of v (y1, y2) and of u (y3, y4)
        let mut x = [[0.0; NR]; R_OUTPUTS];
        for (i, wt) in [s, mu, s, mu].into_iter().enumerate() {
            x[0][R_XY[i]] = wt;
            x[1 + i / 2][R_Y[i]] = wt;
        }
        w.rw[r] = x;
    }
    let mut outs = [gq, gv, &mut w.ub];
    w.rpass
        .sp
        .add_grads_many::<NR, R_OUTPUTS, BasisR>(&f.sprows, &w.rw, &mut outs);
    passes::add_constraint_poly_grads_many(sys, &w.rpass.grads, &w.rw, outs);
}

/// The adjoint of a pass ([`Pass`]) with the adjoint weights `wts` of its rows' coefficients
/// and `pot` of its potential's: adds the `q`-gradient to `qb` and the gradient with respect to
/// direction `j` to `dirs[j]`.
fn contract<const K: usize, B: Basis<K>>(
    sys: &System,
    set: &SpatialRowSet,
    (p, wts, pot): (&Pass<K, B>, &[[f64; K]], Option<&[f64; K]>),
    qb: &mut [f64],
    dirs: &mut [&mut [f64]],
) {
    passes::add_constraint_poly_adjoint::<K, B>(sys, &p.grads, wts, qb, dirs);
    p.sp.adjoint::<K, B>(set, wts, qb, dirs);
    if let Some(pw) = pot {
        passes::add_potential_poly_adjoint::<K, B>(sys, &p.pgrads, pw, qb, dirs);
        p.spp.adjoint::<B>(pw, qb, dirs);
    }
}

#[cfg(test)]
mod tests {
    use crate::Preadjustment;
    use mbd_model::models;
    use mbd_solve::State;

    /// `e4`'s gradients by the reverse pass against fourth-order central differences of the
    /// forward evaluation at `(q, v)`: the largest difference, relative to the largest
    /// gradient entry.
    fn gradient_error(sys: &mbd_model::System, q: &[f64], v: &[f64]) -> f64 {
        let n = sys.n_coords();
        let mut p = Preadjustment::new(sys, 2).unwrap();
        let (mut gq, mut gv) = (vec![0.0; n], vec![0.0; n]);
        let e4 = p
            .modified_gradients_s2(sys, q, v, &mut gq, &mut gv)
            .unwrap();
        let e4b = p.modified_term_s2(sys, q, v).unwrap();
        assert!((e4 - e4b).abs() <= 1e-13 * e4.abs().max(1.0));
        let f = |y: &[f64], w: &[f64]| p.modified_term_s2(sys, y, w).unwrap();
        mbd_testkit::gradient_error(f, q, v, &gq, &gv, 1e-4)
    }

    /// The spatial rows (quadratic, in natural coordinates) and the spatial force elements'
    /// potentials through the passes and the reverse pass: gradients against differences on a
    /// heavy top, a torque-free body, a spatial double pendulum, a rod on a spring and the
    /// fixture with every kind of spatial potential, at the consistent state with a generic velocity added (`e4` is defined
    /// off the tangent space too).
    #[test]
    fn spatial_gradients_match_differences() {
        let systems = [
            models::heavy_top([0.3, 0.3, 0.1], 0.3, 20.0).unwrap(),
            models::free_body([0.2, 0.3, 0.4], [0.4, 5.0, 0.3]).unwrap(),
            models::spatial_double_pendulum().unwrap(),
            models::sprung_rod([0.05, 0.05, 0.002]).unwrap(),
            mbd_model::fixtures::spatial_springs(),
        ];
        for sys in &systems {
            let st = State::consistent(sys, 0.0).unwrap();
            let v: Vec<f64> =
                st.v.iter()
                    .enumerate()
                    .map(|(i, x)| x + 0.3 * (0.7 * i as f64).sin())
                    .collect();
            let err = gradient_error(sys, st.q.as_slice(), &v);
            eprintln!("n = {}: gradient error {err:.2e}", sys.n_coords());
            assert!(err < 1e-7, "n = {}: {err:.2e}", sys.n_coords());
        }
    }

    /// On a spatial model whose `Phi_q` depends on time (an angle driver), the s = 2 term is
    /// that of the constraints frozen at the time set last: it changes with the time, and
    /// setting a time back gives the same bits again (the cached evaluation follows the time).
    #[test]
    fn a_spatial_angle_driver_follows_the_set_time() {
        let sys = mbd_model::System::from_path(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../examples/models/turning_arm.toml"
        ))
        .unwrap();
        let st = State::consistent(&sys, 0.0).unwrap();
        let (q, v) = (st.q.as_slice(), st.v.as_slice());
        let mut p = Preadjustment::new(&sys, 2).unwrap();
        let e0 = p.modified_term_s2(&sys, q, v).unwrap();
        p.set_time(0.3);
        let e1 = p.modified_term_s2(&sys, q, v).unwrap();
        p.set_time(0.0);
        let e2 = p.modified_term_s2(&sys, q, v).unwrap();
        assert!(e0.is_finite() && e1.is_finite());
        assert!((e1 - e0).abs() > 1e-6 * e0.abs(), "{e0} {e1}");
        assert_eq!(e0.to_bits(), e2.to_bits());
    }

    /// The reverse-pass gradients against fourth-order central differences of `e4`, on paper
    /// A's double pendulum, a rod with a spring, a 3-link chain and an elastic pendulum (`m = 0`),
    /// at generic states.
    #[test]
    fn gradients_match_differences() {
        let systems = [
            models::paper_a_double_pendulum().unwrap(),
            crate::preadjust::modified_s1::modlag_tests::rod_with_spring(),
            models::n_link_chain(3).unwrap(),
            models::elastic_pendulum().unwrap(),
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
