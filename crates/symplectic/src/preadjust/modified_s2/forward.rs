//! The forward evaluation of `e4(q, v)`: the intermediates of the module doc at one `(q, v)`
//! ([`E4Forward`], kept for the reverse pass) and the terms of [`super::E4_TERMS`].

use super::passes::{
    BasisA, BasisB, BasisC, Pass, A_E, A_ET, A_ETT, A_T, A_T4, A_TT, A_TTT, B_E, B_ED, B_EE, B_ET,
    B_ETT, C_AT, C_BT, NA, NB, NC,
};
use super::spatial::SpatialRowSet;
use super::{Invariant, ModifiedS2, PerInvariant, E4_TERM_COUNT};
use crate::passes;
use crate::preadjust::metric::ProjectedMetric;
use crate::preadjust::{dot, LocalRow, ZERO_ROW};
use mbd_model::{BodyAngles, System};
use mbd_solve::SolveError;

/// The intermediate quantities of `e4` at one `(q, v)` (names as in the module doc; `nn` is
/// `n`, `hmu_v` is `H_mu v`, `pi_hv` is `Pi H v`, `s_beta` is `S^-1 beta`, `d4v` is
/// `D^4 V(v, v, v, v)`), kept for the reverse pass of the gradient (`reverse.rs`): a
/// workspace allocated once, filled in place by every evaluation.
#[derive(Debug)]
pub(super) struct E4Forward {
    pub(super) u: Vec<f64>,
    pub(super) mu0: Vec<f64>,
    pub(super) gam: Vec<f64>,
    pub(super) sig: Vec<f64>,
    pub(super) nn: Vec<f64>,
    pub(super) beta: Vec<f64>,
    pub(super) k2: Vec<f64>,
    pub(super) kap3: Vec<f64>,
    pub(super) k3: Vec<f64>,
    pub(super) kap3u: Vec<f64>,
    pub(super) kap4: Vec<f64>,
    pub(super) hv: Vec<f64>,
    pub(super) hu: Vec<f64>,
    pub(super) hn: Vec<f64>,
    pub(super) hmu_v: Vec<f64>,
    pub(super) hmu_u: Vec<f64>,
    pub(super) hsig_v: Vec<f64>,
    pub(super) hsig_u: Vec<f64>,
    pub(super) pi_hmu_v: Vec<f64>,
    pub(super) pi_hv: Vec<f64>,
    pub(super) pi_hsig_v: Vec<f64>,
    /// `S^-1 G M^-1 x` for `x = H_mu v, H v, H_sigma v` (the projections' solves, which the
    /// adjoints of the `Pi` terms reuse).
    pub(super) sg_hmu_v: Vec<f64>,
    pub(super) sg_hv: Vec<f64>,
    pub(super) sg_hsig_v: Vec<f64>,
    pub(super) s_beta: Vec<f64>,
    pub(super) s_kap3: Vec<f64>,
    pub(super) d3v_u: f64,
    pub(super) d3v_n: f64,
    pub(super) d4v: f64,
    /// The passes ([`BasisA`], [`BasisB`], [`BasisC`]).
    pub(super) pa: Pass<NA, BasisA>,
    pub(super) pb: Pass<NB, BasisB>,
    pub(super) pc: Pass<NC, BasisC>,
    /// `sin`/`cos` of the body angles at `q`, shared by every pass.
    pub(super) angles: BodyAngles,
    /// The spatial rows at `q`, shared by every pass.
    pub(super) sprows: SpatialRowSet,
    /// Per constraint row, element-local `Hess Phi_r v` and `Hess Phi_r u` (the weighted
    /// Hessian-vector products `H_mu v`, `H_sigma v`, ...; pass A's gradients of `t` and `e`).
    pub(super) rhv_v: Vec<LocalRow>,
    pub(super) rhv_u: Vec<LocalRow>,
    /// Scratch: m zeros.
    pub(super) zero_m: Vec<f64>,
}

impl E4Forward {
    pub(super) fn new(n: usize, m: usize, nf: usize) -> Self {
        let (zn, zm) = (|| vec![0.0; n], || vec![0.0; m]);
        E4Forward {
            u: zn(),
            mu0: zm(),
            gam: zm(),
            sig: zm(),
            nn: zn(),
            beta: zm(),
            k2: zn(),
            kap3: zm(),
            k3: zn(),
            kap3u: zm(),
            kap4: zm(),
            hv: zn(),
            hu: zn(),
            hn: zn(),
            hmu_v: zn(),
            hmu_u: zn(),
            hsig_v: zn(),
            hsig_u: zn(),
            pi_hmu_v: zn(),
            pi_hv: zn(),
            pi_hsig_v: zn(),
            sg_hmu_v: zm(),
            sg_hv: zm(),
            sg_hsig_v: zm(),
            s_beta: zm(),
            s_kap3: zm(),
            d3v_u: 0.0,
            d3v_n: 0.0,
            d4v: 0.0,
            pa: Pass::new(m, nf),
            pb: Pass::new(m, nf),
            pc: Pass::new(m, nf),
            angles: BodyAngles::default(),
            sprows: SpatialRowSet::default(),
            rhv_v: vec![ZERO_ROW; m],
            rhv_u: vec![ZERO_ROW; m],
            zero_m: zm(),
        }
    }

    /// The terms of `e4` from the intermediates.
    pub(super) fn terms(&self) -> PerInvariant {
        use Invariant::*;
        let f = self;
        let mut t = PerInvariant([0.0; E4_TERM_COUNT]);
        t[VHsigPiHmuV] = dot(&f.hsig_v, &f.pi_hmu_v);
        t[VHmuPiHmuV] = dot(&f.hmu_v, &f.pi_hmu_v);
        t[UHmuU] = dot(&f.u, &f.hmu_u);
        t[VHmuPiHV] = dot(&f.hmu_v, &f.pi_hv);
        t[BetaSBeta] = dot(&f.beta, &f.s_beta);
        t[UHsigU] = dot(&f.u, &f.hsig_u);
        t[Kappa3SBeta] = dot(&f.kap3, &f.s_beta);
        t[VHK2] = dot(&f.hv, &f.k2);
        t[Mu0Kappa3u] = dot(&f.mu0, &f.kap3u);
        t[SigmaKappa3u] = dot(&f.sig, &f.kap3u);
        t[Mu0Kappa4] = dot(&f.mu0, &f.kap4);
        t[UHN] = dot(&f.hu, &f.nn);
        t[UHU] = dot(&f.u, &f.hu);
        t[D3VUVV] = f.d3v_u;
        t[NHN] = dot(&f.nn, &f.hn);
        t[VHPiHsigV] = dot(&f.hv, &f.pi_hsig_v);
        t[VHK3] = dot(&f.hv, &f.k3);
        t[D3VNVV] = f.d3v_n;
        t[VHPiHV] = dot(&f.hv, &f.pi_hv);
        t[D4V] = f.d4v;
        t[VHsigPiHsigV] = dot(&f.hsig_v, &f.pi_hsig_v);
        t[SigmaKappa4] = dot(&f.sig, &f.kap4);
        t[Kappa3SKappa3] = dot(&f.kap3, &f.s_kap3);
        t
    }
}

impl ModifiedS2 {
    /// Evaluates the intermediates of `e4` at `q` with the velocity `v` into `self.f` (after
    /// the caller checked `v`; prepares the metric at `q`); the passes keep their coefficient
    /// gradients for the reverse pass. Allocates nothing.
    pub(in crate::preadjust) fn forward(
        &mut self,
        metric: &mut ProjectedMetric,
        sys: &System,
        q: &[f64],
        v: &[f64],
    ) -> Result<(), SolveError> {
        metric.prepare(sys, q)?;
        let m = metric.m();
        let f = &mut self.f;
        f.angles.update(sys, q);
        f.sprows.update(sys, q, metric.t());
        f.u.copy_from_slice(metric.u());
        f.mu0.copy_from_slice(metric.mu0());
        // pass A along (v, u): gamma, beta, D^3 Phi(v^3), D^4 Phi(v^4), D^3 Phi(v, v, u), the
        // rows Hess Phi_r v and Hess Phi_r u, and of V: D^4 V(v^4), D^3 V(u, v, v), H v, H u
        f.pa.eval(sys, q, (&f.angles, &f.sprows), &[v, &f.u]);
        for r in 0..m {
            let (c, g) = (&f.pa.vals[r], &f.pa.grads[r]);
            f.gam[r] = 2.0 * c[A_TT];
            f.beta[r] = c[A_ET];
            f.rhv_v[r] = g[A_T];
            f.rhv_u[r] = g[A_E];
        }
        f.pa.pot_grad_into(sys, A_T, &mut f.hv);
        f.pa.pot_grad_into(sys, A_E, &mut f.hu);
        metric.neg_e_into(&f.gam, &mut f.sig, &mut f.nn);
        metric.neg_e_into(&f.beta, &mut f.s_beta, &mut f.k2);
        // pass B along (v, n, u): D^2 Phi(n, v), D^3 Phi(v, v, n), D^2 Phi(n, n), D^2 Phi(n, u),
        // and of V: D^3 V(n, v, v), H n
        f.pb.eval(sys, q, (&f.angles, &f.sprows), &[v, &f.nn, &f.u]);
        f.pb.pot_grad_into(sys, B_E, &mut f.hn);
        for r in 0..m {
            f.kap3[r] = 6.0 * f.pa.vals[r][A_TTT] + 3.0 * f.pb.vals[r][B_ET];
        }
        metric.neg_e_into(&f.kap3, &mut f.s_kap3, &mut f.k3);
        // pass C along (v, K2, K3): D^2 Phi(K2, v), D^2 Phi(K3, v)
        f.pc.eval(sys, q, (&f.angles, &f.sprows), &[v, &f.k2, &f.k3]);
        for r in 0..m {
            let (a, b, c) = (&f.pa.vals[r], &f.pb.vals[r], &f.pc.vals[r]);
            f.kap3u[r] = 2.0 * a[A_ETT] + 2.0 * c[C_AT] + b[B_ED];
            f.kap4[r] = 24.0 * a[A_T4] + 12.0 * b[B_ETT] + 6.0 * b[B_EE] + 4.0 * c[C_BT];
        }
        // the constraint-weighted Hessian-vector products from the rows (pass A's direction
        // 0 is v, 1 is u: the spatial rows' H_r v and H_r u)
        for (out, rows, w, j) in [
            (&mut f.hmu_v, &f.rhv_v, &f.mu0, 0),
            (&mut f.hsig_v, &f.rhv_v, &f.sig, 0),
            (&mut f.hmu_u, &f.rhv_u, &f.mu0, 1),
            (&mut f.hsig_u, &f.rhv_u, &f.sig, 1),
        ] {
            out.fill(0.0);
            passes::add_local_rows(sys, rows, w, out);
            f.pa.sp.add_hessian_direction(&f.sprows, j, w, out);
        }
        metric.pi_sgm(&f.hmu_v, &mut f.pi_hmu_v, &mut f.sg_hmu_v);
        if !super::has_potential(sys) {
            // (H v = 0: gravity is linear)
            f.pi_hv.fill(0.0);
            f.sg_hv.fill(0.0);
        } else {
            metric.pi_sgm(&f.hv, &mut f.pi_hv, &mut f.sg_hv);
        }
        metric.pi_sgm(&f.hsig_v, &mut f.pi_hsig_v, &mut f.sg_hsig_v);
        f.d3v_u = 2.0 * f.pa.pot[A_ETT];
        f.d3v_n = 2.0 * f.pb.pot[B_ETT];
        f.d4v = 24.0 * f.pa.pot[A_T4];
        Ok(())
    }

    /// The terms of the last forward evaluation ([`super::E4_TERMS`], without their coefficients).
    pub(in crate::preadjust) fn terms(&self) -> [f64; E4_TERM_COUNT] {
        self.f.terms().0
    }
}

#[cfg(test)]
mod tests {
    use super::super::E4_TERMS;
    use crate::Preadjustment;
    use mbd_model::models;

    /// The positions and velocities of a revolute chain of unit rods pinned at the origin, with
    /// body angles `th` and rates `om` (as `models::chain` lays them out).
    fn chain_state(th: &[f64], om: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let (mut q, mut v) = (Vec::new(), Vec::new());
        let (mut tip, mut tip_v) = ([0.0, 0.0], [0.0, 0.0]);
        for (&a, &w) in th.iter().zip(om) {
            let (s, c) = a.sin_cos();
            q.extend([tip[0] + 0.5 * c, tip[1] + 0.5 * s, a]);
            v.extend([tip_v[0] - 0.5 * s * w, tip_v[1] + 0.5 * c * w, w]);
            tip = [tip[0] + c, tip[1] + s];
            tip_v = [tip_v[0] - s * w, tip_v[1] + c * w];
        }
        (q, v)
    }

    /// The 23 terms against the Python derivation's own evaluation (sympy tensors of `V` and
    /// `Phi`, dense linear algebra; `scripts/modified_lagrangian/s2_library_point.py`) on paper
    /// A's double pendulum and on a rod with a spring (where the potential's terms are not
    /// zero): every term to 1e-9 of the largest.
    #[test]
    fn terms_match_the_derivation() {
        let dp = models::paper_a_double_pendulum().unwrap();
        let a = -std::f64::consts::FRAC_PI_3;
        let (qa, va) = chain_state(&[a, a], &[0.7, -1.1]);
        let ref_a = [
            -56.38426220875945,
            500.4964600714286,
            -525.5960922082163,
            0.0,
            35.90441230867351,
            50.8406478290817,
            0.0,
            0.0,
            -2.06956715051024,
            0.0,
            -0.3223514809249801,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            6.371919428571428,
            0.1331349285714281,
            0.05536878571428572,
        ];
        let spring = crate::preadjust::modified_s1::modlag_tests::rod_with_spring();
        let (qb, vb) = chain_state(&[-std::f64::consts::FRAC_PI_4], &[0.9]);
        let ref_b = [
            -3.527664921849408,
            124.8873138087755,
            -10715.58062356805,
            -476.1591433729562,
            302.6806865338635,
            302.6806865338635,
            0.0,
            -126.8805916745229,
            46.58617876873627,
            0.0,
            -9.407106458265083,
            -126.880591674523,
            40855.40424285662,
            -756.1989416113539,
            3.229273968170943,
            13.44996426031392,
            5.69730294288866,
            0.01591431209735329,
            1815.456853886915,
            -75.43965648167905,
            0.09964518750000008,
            0.2657205000000001,
            0.03321506250000001,
        ];
        for (sys, q, v, reference, e4) in [
            (&dp, &qa, &va, ref_a, 0.3990623127489463),
            (&spring, &qb, &vb, ref_b, -16.40787277269333),
        ] {
            let mut p = Preadjustment::new(sys, 2).unwrap();
            let t = p.modified_terms_s2(sys, q, v).unwrap();
            let scale = reference
                .iter()
                .fold(0.0f64, |x: f64, y: &f64| x.max(y.abs()));
            for (i, (x, r)) in t.iter().zip(reference).enumerate() {
                assert!(
                    (x - r).abs() < 1e-9 * scale,
                    "term {i} ({}): {x} vs {r}",
                    E4_TERMS[i].name
                );
            }
            let worst = t
                .iter()
                .zip(reference)
                .map(|(x, r)| (x - r).abs())
                .fold(0.0, f64::max);
            eprintln!("e4 terms: largest difference {worst:.2e} of the largest term {scale:.3e}");
            let got = p.modified_term_s2(sys, q, v).unwrap();
            assert!((got - e4).abs() < 1e-9 * scale, "e4 {got} vs {e4}");
        }
    }
}
