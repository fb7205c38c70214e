//! The modified-Lagrangian term `e(q, v)` of the (1,1) scheme, its gradients (exact third
//! derivatives) and its velocity Hessian.

#[cfg(test)]
use super::matvec;
use super::{dot, Preadjustment};
use mbd_model::System;
use mbd_solve::SolveError;
use nalgebra::DMatrix;

impl Preadjustment {
    /// The velocity-dependent modified-Lagrangian term of the (1,1) scheme (without its `h^2`):
    /// `e(q, v) = -1/24 f_T^T M^-1 f_T + 1/12 v^T A v + 1/24 gamma_c^T S^-1 gamma_c` with
    /// `gamma_c,k = v^T Hess Phi_k v` (see `docs/symplectic.md`, "Modified-Lagrangian
    /// preadjustment"). Independent of the `s` of the workspace.
    pub fn modified_term(&mut self, sys: &System, q: &[f64], v: &[f64]) -> Result<f64, SolveError> {
        self.check_v(v)?;
        self.prepare(sys, q)?;
        Ok(self.modified_prepared(sys, q, v))
    }

    fn check_v(&self, v: &[f64]) -> Result<(), SolveError> {
        if v.len() != self.n {
            return Err(SolveError::Dimension {
                what: "v for the modified-Lagrangian term",
                expected: self.n,
                got: v.len(),
            });
        }
        Ok(())
    }

    /// `e(q, v)` after `prepare(q)`; leaves `gamma_c` in `gc`, `S^-1 gamma_c` in `sigma`,
    /// `sigma - mu0` in `cm`, `(A + H_sigma) v` in `hv` and `D^3 (V + (sigma - mu0) . Phi)(v, v, .)`
    /// in `d3` (one third-order pass over the elements, no Hessian assembled).
    fn modified_prepared(&mut self, sys: &System, q: &[f64], v: &[f64]) -> f64 {
        let (n, m) = (self.n, self.m);
        let uu: f64 = (0..n).map(|k| self.mass[k] * self.u[k] * self.u[k]).sum();
        let mut gg = 0.0;
        if m > 0 {
            // gamma(q, v, t) = -(v^T Hess Phi_k v) + time part: the time part cancels
            sys.gamma(q, v, 0.0, &mut self.gc);
            if self.rheonomic {
                sys.gamma(q, &self.zero, 0.0, &mut self.gc0);
                for r in 0..m {
                    self.gc[r] = self.gc0[r] - self.gc[r];
                }
            } else {
                self.gc.iter_mut().for_each(|x| *x = -*x);
            }
            self.sigma.copy_from_slice(&self.gc);
            self.chol.solve_in_place(&mut self.sigma);
            gg = dot(&self.gc, &self.sigma);
        }
        for r in 0..m {
            self.cm[r] = self.sigma[r] - self.mu0[r];
        }
        sys.lagrangian_third(q, v, 1.0, &self.cm, &mut self.hv, &mut self.d3);
        // v^T A v = v^T (A + H_sigma) v - sigma . gamma_c
        let vav = dot(v, &self.hv) - gg;
        -uu / 24.0 + vav / 12.0 + gg / 24.0
    }

    /// Check of [`Preadjustment::modified_gradients`]: `d e / d q` by Richardson-extrapolated
    /// central differences of `e` in each coordinate, `d e / d v` as there.
    #[cfg(test)]
    pub(crate) fn modified_gradients_fd(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<f64, SolveError> {
        self.check_v(v)?;
        let n = self.n;
        if dq.len() != n || dv.len() != n {
            return Err(SolveError::Dimension {
                what: "gradient buffers of the modified-Lagrangian term",
                expected: n,
                got: dq.len().min(dv.len()),
            });
        }
        let mut qp = q.to_vec();
        for l in 0..n {
            let d = self.fd_step * (1.0 + q[l].abs());
            let mut acc = 0.0;
            for (coef, shift) in [(8.0, 0.5), (-8.0, -0.5), (-1.0, 1.0), (1.0, -1.0)] {
                qp[l] = q[l] + shift * d;
                let r = self.prepare(sys, &qp);
                r?;
                acc += coef * self.modified_prepared(sys, &qp, v);
            }
            qp[l] = q[l];
            dq[l] = acc / (6.0 * d);
        }
        self.prepare(sys, q)?;
        let e = self.modified_prepared(sys, q, v);
        self.ensure_a(sys, q);
        matvec(&self.amat, v, dv);
        if self.m > 0 {
            let mut hs = DMatrix::zeros(n, n);
            sys.constraint_hessian(q, &self.sigma, &mut hs);
            let mut t = std::mem::take(&mut self.tn[0]);
            matvec(&hs, v, &mut t);
            for k in 0..n {
                dv[k] += t[k];
            }
            self.tn[0] = t;
        }
        dv.iter_mut().for_each(|x| *x /= 6.0);
        Ok(e)
    }

    /// `A + H_sigma` at `q` (`H_sigma = sum_k sigma_k Hess Phi_k`, `sigma = S^-1 gamma_c(q, v)`)
    /// into `out` (overwritten): `6 d^2 e / dv^2`, used for the Newton Jacobian.
    pub fn modified_velocity_hessian(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        out: &mut DMatrix<f64>,
    ) -> Result<(), SolveError> {
        self.check_v(v)?;
        self.prepare(sys, q)?;
        self.modified_prepared(sys, q, v);
        // A + H_sigma = Hess V + (sigma - mu0) . Hess Phi, one assembly
        sys.potential_hessian(q, out);
        if self.m > 0 {
            sys.add_constraint_hessian(q, &self.cm, 1.0, out);
        }
        Ok(())
    }

    /// Gradients of [`Preadjustment::modified_term`], into `dq` and `dv`; returns `e(q, v)`.
    /// With `sigma = S^-1 gamma_c`, `H_sigma = sum_k sigma_k Hess Phi_k`, `u = M^-1 f_T` and
    /// `w = M^-1 Phi_q^T sigma` (derivation in `docs/symplectic.md`):
    ///
    /// * `d e / d v = 1/6 (A v + H_sigma v)` (exact),
    /// * `d e / d q = 1/12 [(A + H_sigma)(u - w) + D^3(V + (sigma - mu0) . Phi)(v, v)]`, where
    ///   the third-derivative term is the derivative along `v` of `Hess(V + (sigma - mu0) . Phi) v`
    ///   (`sigma`, `mu0` frozen), exact ([`System::potential_third`],
    ///   [`System::constraint_third`]).
    pub fn modified_gradients(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<f64, SolveError> {
        self.check_v(v)?;
        let (n, m) = (self.n, self.m);
        if dq.len() != n || dv.len() != n {
            return Err(SolveError::Dimension {
                what: "gradient buffers of the modified-Lagrangian term",
                expected: n,
                got: dq.len().min(dv.len()),
            });
        }
        self.prepare(sys, q)?;
        let e = self.modified_prepared(sys, q, v);
        for k in 0..n {
            dv[k] = self.hv[k] / 6.0;
        }
        // (A + H_sigma)(u - w), w = M^-1 Phi_q^T sigma, one Hessian-vector pass
        let uw = &mut self.tn[1];
        for k in 0..n {
            let acc: f64 = (0..m).map(|r| self.gq[(r, k)] * self.sigma[r]).sum();
            uw[k] = self.u[k] - self.minv[k] * acc;
        }
        sys.lagrangian_hessian_vector(q, &self.tn[1], 1.0, &self.cm, dq);
        // third derivatives along v (exact, from modified_prepared)
        for k in 0..n {
            dq[k] += self.d3[k];
        }
        dq.iter_mut().for_each(|x| *x /= 12.0);
        Ok(e)
    }
}

#[cfg(test)]
mod modlag_tests {
    use super::*;
    use mbd_model::models;

    /// The analytic position gradient of the modified-Lagrangian term against central
    /// differences of the term itself, away from equilibrium and with a generic velocity.
    #[test]
    fn modified_gradient_matches_differences() {
        let sys = models::paper_a_double_pendulum().unwrap();
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
        let eb = p
            .modified_gradients_fd(&sys, &q, &v, &mut b, &mut bv)
            .unwrap();
        assert_eq!(ea, eb);
        let scale = b.iter().fold(0.0f64, |x, &y| x.max(y.abs()));
        for i in 0..n {
            assert!(
                (a[i] - b[i]).abs() < 1e-7 * scale,
                "dq[{i}]: {} vs {}",
                a[i],
                b[i]
            );
            assert!((av[i] - bv[i]).abs() < 1e-12 * (1.0 + bv[i].abs()));
        }
    }
}
