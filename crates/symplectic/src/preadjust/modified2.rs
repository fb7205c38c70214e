//! The `h^4` modified-Lagrangian term `e4(q, v)` of the constrained (2,2) scheme
//! (`docs/modified-lagrangian.md` section 3: 23 invariant terms, fitted exactly in a graph frame
//! and checked against the pendulum family and under changes of coordinates and of the
//! constraint representation). Value only: the (2,2) preadjustment is not wired into the
//! integrator yet.
//!
//! With `G = Phi_q`, `S = G M^-1 G^T`, `Pi` the tangent projector, `E = M^-1 G^T S^-1`,
//! `mu0 = S^-1 G M^-1 grad V`, `u = -Pi grad V`, `gamma_k = Hess Phi_k(v, v)`,
//! `sigma = S^-1 gamma`, `n = -E gamma`, `beta_k = Hess Phi_k(u, v)`, `K2 = -E beta`,
//! `kappa3_k = D^3 Phi_k(v, v, v) + 3 Hess Phi_k(n, v)`, `K3 = -E kappa3`,
//! `kappa3u_k = D^3 Phi_k(u, v, v) + 2 Hess Phi_k(K2, v) + Hess Phi_k(n, u)`,
//! `kappa4_k = D^4 Phi_k(v, v, v, v) + 6 D^3 Phi_k(n, v, v) + 3 Hess Phi_k(n, n)
//! + 4 Hess Phi_k(K3, v)`, `H = Hess V`, `H_mu = mu0 . Hess Phi`, `H_sigma = sigma . Hess Phi`,
//! the terms and their coefficients are those of [`E4_TERMS`]. The directional derivatives of
//! orders 2 to 4 come from truncated-Taylor passes ([`System::constraint_directional`],
//! [`System::potential_directional`]), mixed ones by polarisation.

use super::{dot, Preadjustment};
use mbd_model::System;
use mbd_solve::SolveError;

/// The terms of `e4` and their coefficients, in the order of [`Preadjustment::modified_term_s2`]'s
/// evaluation (`S` in a name stands for `S^-1`).
pub const E4_TERMS: [(&str, f64); 23] = [
    ("v H_sigma Pi H_mu v", 1.0 / 720.0),
    ("v H_mu Pi H_mu v", -1.0 / 1440.0),
    ("u H_mu u", -1.0 / 960.0),
    ("v H_mu Pi H v", 1.0 / 720.0),
    ("beta S beta", 1.0 / 160.0),
    ("u H_sigma u", 1.0 / 960.0),
    ("kappa3 S beta", 1.0 / 240.0),
    ("v H K2", 1.0 / 240.0),
    ("mu0 . kappa3u", -1.0 / 480.0),
    ("sigma . kappa3u", 1.0 / 480.0),
    ("mu0 . kappa4", -1.0 / 2880.0),
    ("u H n", -1.0 / 720.0),
    ("u H u", -1.0 / 1440.0),
    ("D3V(u, v, v)", -1.0 / 720.0),
    ("n H n", -1.0 / 1440.0),
    ("v H Pi H_sigma v", -1.0 / 720.0),
    ("v H K3", 1.0 / 720.0),
    ("D3V(n, v, v)", -1.0 / 720.0),
    ("v H Pi H v", -1.0 / 1440.0),
    ("D4V(v, v, v, v)", -1.0 / 4320.0),
    ("v H_sigma Pi H_sigma v", -1.0 / 1440.0),
    ("sigma . kappa4", 1.0 / 2880.0),
    ("kappa3 S kappa3", 1.0 / 1440.0),
];

/// Directional derivatives of orders 2..4 of every constraint row and of the potential along
/// one direction.
pub(super) struct Dirs {
    pub(super) rows: Vec<[f64; 3]>,
    pub(super) pot: [f64; 3],
}

impl Dirs {
    pub(super) fn along(sys: &System, q: &[f64], w: &[f64]) -> Self {
        let mut rows = vec![[0.0; 3]; sys.n_constraints()];
        sys.constraint_directional(q, w, &mut rows);
        Dirs {
            rows,
            pot: sys.potential_directional(q, w),
        }
    }
}

pub(super) fn comb(a: &[f64], ca: f64, b: &[f64], cb: f64) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| ca * x + cb * y).collect()
}

/// The passes along `a + b` and `a - b`.
fn along_pm(sys: &System, q: &[f64], a: &[f64], b: &[f64]) -> (Dirs, Dirs) {
    (
        Dirs::along(sys, q, &comb(a, 1.0, b, 1.0)),
        Dirs::along(sys, q, &comb(a, 1.0, b, -1.0)),
    )
}

/// Per row `D^2 f(a, b)` from the passes along `a + b` and `a - b`.
fn bilinear(p: &Dirs, m: &Dirs) -> Vec<f64> {
    p.rows
        .iter()
        .zip(&m.rows)
        .map(|(x, y)| 0.25 * (x[0] - y[0]))
        .collect()
}

/// The intermediate quantities of `e4` at one `(q, v)` (names as in the module doc; `nn` is
/// `n`, `hmu_v` is `H_mu v`, `pi_hv` is `Pi H v`, `s_beta` is `S^-1 beta`, `d4v` is
/// `D^4 V(v, v, v, v)`), kept for the reverse pass of the gradient (`modified2_grad.rs`).
pub(super) struct E4Forward {
    pub(super) u: Vec<f64>,
    pub(super) mu0: Vec<f64>,
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
    pub(super) s_beta: Vec<f64>,
    pub(super) s_kap3: Vec<f64>,
    pub(super) d3v_u: f64,
    pub(super) d3v_n: f64,
    pub(super) d4v: f64,
}

impl E4Forward {
    /// The 23 terms, in the order of [`E4_TERMS`].
    pub(super) fn terms(&self) -> [f64; 23] {
        let f = self;
        [
            dot(&f.hsig_v, &f.pi_hmu_v),
            dot(&f.hmu_v, &f.pi_hmu_v),
            dot(&f.u, &f.hmu_u),
            dot(&f.hmu_v, &f.pi_hv),
            dot(&f.beta, &f.s_beta),
            dot(&f.u, &f.hsig_u),
            dot(&f.kap3, &f.s_beta),
            dot(&f.hv, &f.k2),
            dot(&f.mu0, &f.kap3u),
            dot(&f.sig, &f.kap3u),
            dot(&f.mu0, &f.kap4),
            dot(&f.hu, &f.nn),
            dot(&f.u, &f.hu),
            f.d3v_u,
            dot(&f.nn, &f.hn),
            dot(&f.hv, &f.pi_hsig_v),
            dot(&f.hv, &f.k3),
            f.d3v_n,
            dot(&f.hv, &f.pi_hv),
            f.d4v,
            dot(&f.hsig_v, &f.pi_hsig_v),
            dot(&f.sig, &f.kap4),
            dot(&f.kap3, &f.s_kap3),
        ]
    }
}

impl Preadjustment {
    /// `E x` (`E = M^-1 G^T S^-1`, x of length m) at the prepared point, into a new vector.
    pub(super) fn e_times(&mut self, x: &[f64]) -> Vec<f64> {
        let (n, m) = (self.n, self.m);
        let mut y = x.to_vec();
        self.chol.solve_in_place(&mut y);
        (0..n)
            .map(|k| self.minv[k] * dot(&self.gq.as_slice()[k * m..(k + 1) * m], &y))
            .collect()
    }

    pub(super) fn s_inv(&mut self, x: &[f64]) -> Vec<f64> {
        let mut y = x.to_vec();
        self.chol.solve_in_place(&mut y);
        y
    }

    pub(super) fn pi_times(&mut self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.n];
        self.apply_pi(x, &mut y);
        y
    }

    /// The intermediate quantities of `e4` at `q` with the velocity `v` (after `check_v`;
    /// prepares the workspace at `q`).
    pub(super) fn e4_forward(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
    ) -> Result<E4Forward, SolveError> {
        self.prepare(sys, q)?;
        let (n, m) = (self.n, self.m);
        let u = self.u.clone();
        let zero_m = vec![0.0; m];
        let hess = |x: &[f64], pot: f64, w: &[f64]| -> Vec<f64> {
            let mut out = vec![0.0; n];
            sys.lagrangian_hessian_vector(q, x, pot, w, &mut out);
            out
        };
        let dv = Dirs::along(sys, q, v);
        let gam: Vec<f64> = dv.rows.iter().map(|r| r[0]).collect();
        let sig = self.s_inv(&gam);
        let nn: Vec<f64> = self.e_times(&gam).iter().map(|x| -x).collect();
        let mu0 = self.mu0.clone();
        let (du, dn) = (Dirs::along(sys, q, &u), Dirs::along(sys, q, &nn));
        let (dupv, dumv) = along_pm(sys, q, &u, v);
        let (dnpv, dnmv) = along_pm(sys, q, &nn, v);
        let (dnpu, dnmu) = along_pm(sys, q, &nn, &u);
        let beta = bilinear(&dupv, &dumv);
        let k2: Vec<f64> = self.e_times(&beta).iter().map(|x| -x).collect();
        let h_nv = bilinear(&dnpv, &dnmv);
        let kap3: Vec<f64> = (0..m).map(|r| dv.rows[r][1] + 3.0 * h_nv[r]).collect();
        let k3: Vec<f64> = self.e_times(&kap3).iter().map(|x| -x).collect();
        let (dk2p, dk2m) = along_pm(sys, q, &k2, v);
        let (dk3p, dk3m) = along_pm(sys, q, &k3, v);
        // D^3 Phi(v, v, u) from the passes along v + u, v - u (= -(u - v): odd) and u
        let vvu: Vec<f64> = (0..m)
            .map(|r| (dupv.rows[r][1] + dumv.rows[r][1] - 2.0 * du.rows[r][1]) / 6.0)
            .collect();
        // D^3 Phi(v, v, n) likewise from v + n, v - n (= -(n - v)) and n
        let vvn: Vec<f64> = (0..m)
            .map(|r| (dnpv.rows[r][1] + dnmv.rows[r][1] - 2.0 * dn.rows[r][1]) / 6.0)
            .collect();
        let h_k2v = bilinear(&dk2p, &dk2m);
        let h_k3v = bilinear(&dk3p, &dk3m);
        let h_nu = bilinear(&dnpu, &dnmu);
        let kap3u: Vec<f64> = (0..m).map(|r| vvu[r] + 2.0 * h_k2v[r] + h_nu[r]).collect();
        let kap4: Vec<f64> = (0..m)
            .map(|r| dv.rows[r][2] + 6.0 * vvn[r] + 3.0 * dn.rows[r][0] + 4.0 * h_k3v[r])
            .collect();
        // Hessian-vector products
        let hv = hess(v, 1.0, &zero_m);
        let hu = hess(&u, 1.0, &zero_m);
        let hn = hess(&nn, 1.0, &zero_m);
        let hmu_v = hess(v, 0.0, &mu0);
        let hmu_u = hess(&u, 0.0, &mu0);
        let hsig_v = hess(v, 0.0, &sig);
        let hsig_u = hess(&u, 0.0, &sig);
        let (pi_hmu_v, pi_hv, pi_hsig_v) = (
            self.pi_times(&hmu_v),
            self.pi_times(&hv),
            self.pi_times(&hsig_v),
        );
        let (s_beta, s_kap3) = (self.s_inv(&beta), self.s_inv(&kap3));
        // potential: D^3 V(u, v, v) and D^3 V(n, v, v) by polarisation (odd in the direction)
        let d3v_u = (dupv.pot[1] + dumv.pot[1] - 2.0 * du.pot[1]) / 6.0;
        let d3v_n = (dnpv.pot[1] + dnmv.pot[1] - 2.0 * dn.pot[1]) / 6.0;
        let d4v = dv.pot[2];
        Ok(E4Forward {
            u,
            mu0,
            sig,
            nn,
            beta,
            k2,
            kap3,
            k3,
            kap3u,
            kap4,
            hv,
            hu,
            hn,
            hmu_v,
            hmu_u,
            hsig_v,
            hsig_u,
            pi_hmu_v,
            pi_hv,
            pi_hsig_v,
            s_beta,
            s_kap3,
            d3v_u,
            d3v_n,
            d4v,
        })
    }

    /// The 23 terms of `e4(q, v)` ([`E4_TERMS`], without their coefficients), at `q` with
    /// the velocity `v` (tangent, or a step's chord). Allocates: a reference evaluation (tests,
    /// derivations), not the integrator's hot path.
    pub fn modified_terms_s2(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
    ) -> Result<[f64; 23], SolveError> {
        self.check_v(v)?;
        let f = self.e4_forward(sys, q, v)?;
        Ok(f.terms())
    }

    /// The `h^4` modified-Lagrangian term of the (2,2) scheme, `e4(q, v) = sum_i c_i T_i`
    /// ([`E4_TERMS`], [`Preadjustment::modified_terms_s2`]).
    pub fn modified_term_s2(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
    ) -> Result<f64, SolveError> {
        let t = self.modified_terms_s2(sys, q, v)?;
        Ok(t.iter().zip(E4_TERMS.iter()).map(|(x, (_, c))| c * x).sum())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
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
        let spring = super::super::modified::modlag_tests::rod_with_spring();
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
                    E4_TERMS[i].0
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
