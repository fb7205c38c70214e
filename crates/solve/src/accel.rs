//! The index-1 acceleration solve
//! `[[M, Phi_q^T], [Phi_q, 0]] [a; lambda] = [Q; gamma]`.
//!
//! `M` is diagonal, so the saddle-point system is solved through its Schur complement:
//! `S = Phi_q M^-1 Phi_q^T` (symmetric positive definite when `Phi_q` has full row rank),
//! `S lambda = Phi_q M^-1 Q - gamma`, `a = M^-1 (Q - Phi_q^T lambda)`. This costs
//! `O(m^2 n + m^3)` instead of `O((n+m)^3)` and uses a Cholesky factorisation. `Phi_q` is
//! evaluated in element-local rows (each equation acts on at most two bodies) and `S` is
//! assembled from them directly ([`crate::linalg::DenseSchur`]). A singular `S` means
//! redundant constraints or a singular configuration and is an error naming the equation at
//! the failing pivot.

use crate::error::SolveError;
use crate::linalg::{BodySchur, DenseSchur, FactorError};
use crate::sparse::{LinearSolver, SparseAccelerationSolver};
use mbd_model::{BodyAngles, System};
use nalgebra::DMatrix;

/// Workspace and driver for the index-1 solve; allocation-free after [`AccelerationSolver::new`].
#[derive(Debug)]
pub struct AccelerationSolver {
    n: usize,
    m: usize,
    /// `Phi_q` at the last solve.
    pub phi_q: DMatrix<f64>,
    /// `gamma` at the last solve.
    pub gamma: Vec<f64>,
    /// Applied forces `Q` at the last solve.
    pub forces: Vec<f64>,
    /// `Phi_q` in element-local rows and the factorisation of `S`.
    schur: DenseSchur,
    /// The bodies' `sin`/`cos` at the last solve's `q`.
    angles: BodyAngles,
    /// The model has spatial bodies: the solve from the whole dense `Phi_q`
    /// ([`System::phi_q_gamma`]), their internal constraints eliminated body by body.
    bodies: Option<Box<BodySchur>>,
}

impl AccelerationSolver {
    /// A workspace sized for `sys`.
    pub fn new(sys: &System) -> Self {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        AccelerationSolver {
            n,
            m,
            phi_q: DMatrix::zeros(m, n),
            gamma: vec![0.0; m],
            forces: vec![0.0; n],
            schur: DenseSchur::new(sys),
            // sized now: the first solve allocates nothing
            angles: BodyAngles::new(sys, sys.initial_guess().0.as_slice()),
            bodies: sys.has_spatial().then(|| Box::new(BodySchur::new(sys))),
        }
    }

    /// The condition estimate of the last factored `S = Phi_q M^-1 Phi_q^T` after diagonal
    /// equilibration (see [`crate::linalg::DenseCholesky::condition_estimate`]): about 1 for
    /// well-separated constraints, growing like the inverse square distance to a singular
    /// configuration. 1 for an unconstrained system, 0 before the first solve.
    pub fn condition_estimate(&self) -> f64 {
        if self.m == 0 {
            1.0
        } else if let Some(b) = &self.bodies {
            b.chol.condition_estimate()
        } else {
            self.schur.chol.condition_estimate()
        }
    }

    /// How many dependent rows the last factorisation dropped (at most
    /// [`System::dependency_budget`]).
    pub(crate) fn dropped(&self) -> usize {
        match &self.bodies {
            Some(b) => b.chol.dependent().len(),
            None => self.schur.chol.dependent().len(),
        }
    }

    /// The element-local rows of the last solve (planar models).
    pub(crate) fn schur_rows(&self) -> &DenseSchur {
        &self.schur
    }

    /// Whether the solve eliminates spatial bodies' internal constraints (no plain rows).
    pub(crate) fn has_body_blocks(&self) -> bool {
        self.bodies.is_some()
    }

    /// Solves for the accelerations `a` (length n) and multipliers `lambda` (length m) at
    /// `(q, v, t)`.
    pub fn solve(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        self.check_sizes(q, v, a, lambda)?;
        sys.forces_into(q, v, t, &mut self.forces);
        self.solve_with_forces(sys, q, v, t, a, lambda)
    }

    fn check_sizes(
        &self,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        lambda: &[f64],
    ) -> Result<(), SolveError> {
        let (n, m) = (self.n, self.m);
        for (what, got, expected) in [
            ("q", q.len(), n),
            ("v", v.len(), n),
            ("a", a.len(), n),
            ("lambda", lambda.len(), m),
        ] {
            if got != expected {
                return Err(SolveError::Dimension {
                    what,
                    expected,
                    got,
                });
            }
        }
        Ok(())
    }

    /// As [`AccelerationSolver::solve`] without filling the dense [`AccelerationSolver::phi_q`]
    /// (it keeps the value of an earlier solve), for callers that read only `a` and `lambda`
    /// (the stages of a Runge-Kutta method). With `angles`, the bodies' `sin`/`cos` come from
    /// the caller's table, brought to `q` by [`BodyAngles::update_near`] (rotated from the
    /// angles it holds, a few units in the last place from the exact values; evaluated after
    /// a larger move): a table the caller keeps near `q` saves the `sin_cos` calls.
    #[allow(clippy::too_many_arguments)]
    pub fn solve_accelerations(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        angles: Option<&mut BodyAngles>,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        self.check_sizes(q, v, a, lambda)?;
        sys.forces_into(q, v, t, &mut self.forces);
        if self.m == 0 || self.bodies.is_some() {
            return self.solve_with_forces(sys, q, v, t, a, lambda);
        }
        match angles {
            Some(table) => {
                table.update_near(sys, q);
                self.rows_with(sys, q, table, v, t);
            }
            None => self.rows(sys, q, v, t),
        }
        self.finish_rows(sys, t, a, lambda)
    }

    /// As [`AccelerationSolver::solve`], with the applied forces already in
    /// [`AccelerationSolver::forces`] (lets a caller add its own terms, e.g. Baumgarte).
    pub fn solve_with_forces(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        self.check_sizes(q, v, a, lambda)?;
        if self.m == 0 {
            let minv = sys.inv_mass_diag();
            for i in 0..self.n {
                a[i] = minv[i] * self.forces[i];
            }
            return Ok(());
        }
        if self.bodies.is_some() {
            self.body_rows(sys, q, v, t)?;
            self.finish_bodies(sys, a, lambda);
            return Ok(());
        }
        self.rows(sys, q, v, t);
        self.schur.scatter(&mut self.phi_q);
        self.finish_rows(sys, t, a, lambda)
    }

    /// The spatial path's rows: `Phi_q` and `gamma` at `(q, v, t)`, each spatial body's
    /// elimination and the factorisation of `S = Phi_e C Phi_e^T`.
    fn body_rows(&mut self, sys: &System, q: &[f64], v: &[f64], t: f64) -> Result<(), SolveError> {
        let Some(b) = self.bodies.as_deref_mut() else {
            return Ok(());
        };
        sys.phi_q_gamma(q, v, t, &mut b.phi_q, &mut self.gamma);
        self.phi_q.copy_from(&b.phi_q);
        b.factor(sys, q, sys.inv_mass_diag().as_slice())
            .map_err(|e| crate::projection::bodies_error(sys, t, e))
    }

    /// The spatial path's solve from [`AccelerationSolver::body_rows`], `gamma` and the forces.
    fn finish_bodies(&mut self, sys: &System, a: &mut [f64], lambda: &mut [f64]) {
        let Some(b) = self.bodies.as_deref_mut() else {
            return;
        };
        // Phi_q a = gamma
        b.solve(
            sys.inv_mass_diag().as_slice(),
            &self.forces,
            &self.gamma,
            a,
            lambda,
        );
    }

    /// `Phi_q` in element-local rows and `gamma` at `(q, v, t)` (one `sin_cos` per body).
    #[inline]
    fn rows(&mut self, sys: &System, q: &[f64], v: &[f64], t: f64) {
        self.angles.update(sys, q);
        sys.phi_q_local_gamma_at(
            q,
            &self.angles,
            v,
            t,
            &mut self.schur.grads,
            &mut self.gamma,
        );
    }

    /// [`AccelerationSolver::rows`] with the angles of `q` from `angles`.
    #[inline]
    fn rows_with(&mut self, sys: &System, q: &[f64], angles: &BodyAngles, v: &[f64], t: f64) {
        sys.phi_q_local_gamma_at(q, angles, v, t, &mut self.schur.grads, &mut self.gamma);
    }

    /// Completes the solve from `phi_q`, `gamma` and `forces` already set (advanced use). With
    /// spatial bodies it reuses the last solve's factorisation (their elimination needs the
    /// configuration), so `phi_q` must be the one that solve left: a changed `phi_q` is
    /// [`SolveError::Unsupported`].
    pub fn finish(
        &mut self,
        sys: &System,
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        if let Some(b) = self.bodies.as_deref() {
            if b.phi_q != self.phi_q {
                return Err(SolveError::Unsupported(
                    "AccelerationSolver::finish with spatial bodies takes the Phi_q of the last \
                     solve; call solve at the new configuration"
                        .into(),
                ));
            }
            self.finish_bodies(sys, a, lambda);
            return Ok(());
        }
        if self.schur.gather(&self.phi_q) {
            self.finish_rows(sys, t, a, lambda)
        } else {
            self.finish_dense(sys, t, a, lambda)
        }
    }

    fn singular(sys: &System, t: f64, e: FactorError) -> SolveError {
        let i = match e {
            FactorError::Singular(i) | FactorError::NotPositiveDefinite(i) => i,
        };
        SolveError::Singular {
            t,
            what: "constraint matrix Phi_q M^-1 Phi_q^T",
            detail: sys.equation_name(i),
        }
    }

    /// [`AccelerationSolver::finish`] from the element-local rows.
    #[inline]
    fn finish_rows(
        &mut self,
        sys: &System,
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        let minv = sys.inv_mass_diag().as_slice();
        // a_free = M^-1 Q (in `a`, updated in place below)
        for ((ak, &mi), &f) in a.iter_mut().zip(minv).zip(&self.forces) {
            *ak = mi * f;
        }
        // S lambda = Phi_q a_free - gamma, a = a_free - M^-1 Phi_q^T lambda
        self.schur
            .factor_rhs(minv, a, &self.gamma, lambda)
            .map_err(|e| Self::singular(sys, t, e))?;
        self.schur.chol.solve_in_place(lambda);
        self.schur.sub_weighted_transpose(lambda, a);
        Ok(())
    }

    /// [`AccelerationSolver::finish`] from a dense `phi_q` that does not have the structure of
    /// the model's `Phi_q`.
    fn finish_dense(
        &mut self,
        sys: &System,
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        let (n, m) = (self.n, self.m);
        let minv = sys.inv_mass_diag().as_slice();
        // a_free = M^-1 Q (in `a`, updated in place below)
        for ((ak, &mi), &f) in a.iter_mut().zip(minv).zip(&self.forces) {
            *ak = mi * f;
        }
        // Phi_q is column-major m x n: column k holds d Phi / d q_k.
        let jac = self.phi_q.as_slice();
        // S = sum_k minv_k col_k col_k^T (lower triangle), rhs = Phi_q a_free - gamma
        let chol = &mut self.schur.chol;
        chol.clear();
        for (lr, g) in lambda.iter_mut().zip(&self.gamma) {
            *lr = -g;
        }
        for k in 0..n {
            let col = &jac[k * m..(k + 1) * m];
            if col.iter().all(|&x| x == 0.0) {
                continue;
            }
            chol.add_rank_one(minv[k], col);
            let wk = a[k];
            for (lr, &c) in lambda.iter_mut().zip(col) {
                *lr += c * wk;
            }
        }
        chol.factor_in_place()
            .map_err(|e| Self::singular(sys, t, e))?;
        chol.solve_in_place(lambda);
        for k in 0..n {
            let col = &jac[k * m..(k + 1) * m];
            let dot: f64 = col.iter().zip(lambda.iter()).map(|(c, l)| c * l).sum();
            a[k] -= minv[k] * dot;
        }
        Ok(())
    }
}

/// The index-1 solve on the path [`LinearSolver`] picks: the dense solver is used inline on the
/// hot path of small systems, the sparse one is boxed.
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
pub(crate) enum Accel {
    Dense(AccelerationSolver),
    Sparse(Box<SparseAccelerationSolver>),
}

impl Accel {
    /// The solver [`LinearSolver::use_sparse`] picks for `sys` (the one policy of the crate).
    pub(crate) fn new(sys: &System, linear: LinearSolver) -> Result<Self, SolveError> {
        Ok(if linear.use_sparse(sys.n_constraints()) {
            Accel::Sparse(Box::new(SparseAccelerationSolver::new(sys)?))
        } else {
            Accel::Dense(AccelerationSolver::new(sys))
        })
    }

    /// Accelerations `a` and multipliers `lambda` at `(q, v, t)`.
    pub(crate) fn solve(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        match self {
            Accel::Dense(acc) => acc.solve(sys, q, v, t, a, lambda),
            Accel::Sparse(sp) => sp.solve(sys, q, v, t, a, lambda),
        }
    }

    /// Whether the sparse path was picked.
    pub(crate) fn is_sparse(&self) -> bool {
        matches!(self, Accel::Sparse(_))
    }

    /// The constraint rows of the last solve (for [`crate::SingularBridge`]).
    pub(crate) fn rows(&self) -> &dyn crate::ConstraintRows {
        match self {
            Accel::Dense(acc) => acc,
            Accel::Sparse(sp) => sp.as_ref(),
        }
    }

    /// How many dependent rows the last factorisation dropped.
    pub(crate) fn dropped(&self) -> usize {
        match self {
            Accel::Dense(acc) => acc.dropped(),
            Accel::Sparse(sp) => sp.dropped(),
        }
    }

    /// Condition estimate of the last index-1 matrix.
    pub(crate) fn condition(&self) -> f64 {
        match self {
            Accel::Dense(acc) => acc.condition_estimate(),
            Accel::Sparse(sp) => sp.condition_estimate(),
        }
    }

    #[allow(clippy::too_many_arguments)]
    pub(crate) fn stage(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        baum: Option<(f64, f64)>,
        phi: &mut [f64],
        phid: &mut [f64],
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        let stab = |sys: &System, gamma: &mut [f64], phi: &mut [f64], phid: &mut [f64]| {
            if let Some((al, be)) = baum {
                sys.phi_and_phi_dot(q, v, t, phi, phid);
                for k in 0..gamma.len() {
                    gamma[k] -= 2.0 * al * phid[k] + be * be * phi[k];
                }
            }
        };
        match self {
            Accel::Dense(acc) => {
                sys.forces_into(q, v, t, &mut acc.forces);
                if acc.gamma.is_empty() {
                    let minv = sys.inv_mass_diag();
                    for i in 0..a.len() {
                        a[i] = minv[i] * acc.forces[i];
                    }
                    return Ok(());
                }
                // the element-local rows alone (the dense `phi_q` of the public solve is not
                // needed here)
                if acc.bodies.is_some() {
                    acc.body_rows(sys, q, v, t)?;
                    stab(sys, &mut acc.gamma, phi, phid);
                    acc.finish_bodies(sys, a, lambda);
                    return Ok(());
                }
                acc.rows(sys, q, v, t);
                stab(sys, &mut acc.gamma, phi, phid);
                acc.finish_rows(sys, t, a, lambda)
            }
            Accel::Sparse(sp) => {
                sp.prepare(sys, q, v, t);
                stab(sys, &mut sp.gamma, phi, phid);
                sp.finish(sys, t, a, lambda)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn wrong_sizes_are_errors_not_panics() {
        let sys = mbd_model::models::pendulum(1.0, 1.0, 0.2, 9.81).unwrap();
        let mut acc = AccelerationSolver::new(&sys);
        let (mut a, mut l) = (vec![0.0; 3], vec![0.0; 2]);
        let err = acc.solve(&sys, &[0.0; 2], &[0.0; 3], 0.0, &mut a, &mut l);
        assert!(matches!(
            err,
            Err(SolveError::Dimension {
                what: "q",
                expected: 3,
                got: 2
            })
        ));
        let mut l1 = vec![0.0; 1];
        let err = acc.solve(&sys, &[0.0, -0.5, -1.5], &[0.0; 3], 0.0, &mut a, &mut l1);
        assert!(matches!(
            err,
            Err(SolveError::Dimension { what: "lambda", .. })
        ));
        assert!(acc
            .solve(
                &sys,
                &[0.0, -0.5, -std::f64::consts::FRAC_PI_2],
                &[0.0; 3],
                0.0,
                &mut a,
                &mut l
            )
            .is_ok());
    }

    /// `(a, lambda)` of the saddle-point system `[[M, J^T], [J, 0]] [a; lambda] = [Q; g]` by a
    /// dense LU (the reference).
    fn saddle_point(sys: &System, j: &DMatrix<f64>, q: &[f64], g: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let mut k = DMatrix::zeros(n + m, n + m);
        let mut rhs = nalgebra::DVector::zeros(n + m);
        for i in 0..n {
            k[(i, i)] = sys.mass_diag()[i];
            rhs[i] = q[i];
        }
        for r in 0..m {
            for c in 0..n {
                k[(n + r, c)] = j[(r, c)];
                k[(c, n + r)] = j[(r, c)];
            }
            rhs[n + r] = g[r];
        }
        let x = k.lu().solve(&rhs).unwrap();
        (x.as_slice()[..n].to_vec(), x.as_slice()[n..].to_vec())
    }

    fn close(x: &[f64], y: &[f64], what: &str) {
        let scale = 1.0 + y.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for (i, (a, b)) in x.iter().zip(y).enumerate() {
            assert!((a - b).abs() < 1e-11 * scale, "{what} [{i}]: {a} vs {b}");
        }
    }

    /// The solve from element-local rows against the saddle-point system, on models with
    /// 4 to 40 equations (fixed-size, run-time small and blocked factorisations); `phi_q`
    /// holds `Phi_q` afterwards; `finish` on that `phi_q` gives the same; and `finish` on a
    /// `phi_q` without the model's structure (an entry outside a row's bodies) takes the
    /// dense path and solves that system.
    #[test]
    fn solve_matches_the_saddle_point_system() {
        for sys in [
            mbd_model::models::manipulator().unwrap(),
            mbd_model::models::slider_crank().unwrap(),
            mbd_model::models::four_bar().unwrap(),
            mbd_model::models::n_link_chain(7).unwrap(),
            mbd_model::models::n_link_chain(20).unwrap(),
        ] {
            let (n, m) = (sys.n_coords(), sys.n_constraints());
            let q: Vec<f64> = (0..n).map(|i| 0.2 + 0.3 * (i as f64 * 0.7).sin()).collect();
            let v: Vec<f64> = (0..n).map(|i| 0.9 * (i as f64 * 1.3).cos()).collect();
            let mut acc = AccelerationSolver::new(&sys);
            let (mut a, mut l) = (vec![0.0; n], vec![0.0; m]);
            acc.solve(&sys, &q, &v, 0.3, &mut a, &mut l).unwrap();
            let mut j = DMatrix::zeros(m, n);
            let mut gamma = vec![0.0; m];
            sys.phi_q_gamma(&q, &v, 0.3, &mut j, &mut gamma);
            assert_eq!(acc.phi_q, j);
            let mut forces = vec![0.0; n];
            sys.forces_into(&q, &v, 0.3, &mut forces);
            let (ea, el) = saddle_point(&sys, &j, &forces, &gamma);
            close(&a, &ea, "a");
            close(&l, &el, "lambda");
            let (mut a2, mut l2) = (vec![0.0; n], vec![0.0; m]);
            acc.finish(&sys, 0.3, &mut a2, &mut l2).unwrap();
            assert_eq!((a2.clone(), l2.clone()), (a.clone(), l.clone()));
            // an entry outside row 0's bodies: the dense path
            let c = (0..n).find(|&c| j[(0, c)] == 0.0).unwrap();
            acc.phi_q[(0, c)] = 0.25;
            let mut j2 = j.clone();
            j2[(0, c)] = 0.25;
            acc.finish(&sys, 0.3, &mut a2, &mut l2).unwrap();
            let (ea2, el2) = saddle_point(&sys, &j2, &forces, &gamma);
            close(&a2, &ea2, "a (dense path)");
            close(&l2, &el2, "lambda (dense path)");
        }
    }

    /// With spatial bodies, the body-eliminated solve equals the plain Schur complement with
    /// `M^-1` (all rows, internal constraints included) for a solid body, accelerations and
    /// every multiplier, to round-off; and it runs a disc whose `M` is singular.
    #[test]
    fn the_body_eliminated_solve_equals_the_plain_one_for_a_solid_body() {
        let sys = mbd_model::models::heavy_top([0.3, 0.3, 0.1], 0.4, 15.0).unwrap();
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let (q, v) = sys.initial_guess();
        let (q, v) = (q.as_slice(), v.as_slice());
        let mut acc = AccelerationSolver::new(&sys);
        let (mut a, mut l) = (vec![0.0; n], vec![0.0; m]);
        acc.solve(&sys, q, v, 0.2, &mut a, &mut l).unwrap();
        // the plain path: Phi_q, gamma and forces as they are, M^-1 on every row
        let (mut a2, mut l2) = (vec![0.0; n], vec![0.0; m]);
        acc.finish_dense(&sys, 0.2, &mut a2, &mut l2).unwrap();
        // `finish` on the same rows repeats the body-eliminated solve
        let (mut a3, mut l3) = (vec![0.0; n], vec![0.0; m]);
        acc.finish(&sys, 0.2, &mut a3, &mut l3).unwrap();
        assert_eq!((&a3, &l3), (&a, &l));
        let scale = a.iter().fold(0.0f64, |s, x| s.max(x.abs()));
        for k in 0..n {
            assert!(
                (a[k] - a2[k]).abs() < 1e-12 * scale,
                "a[{k}]: {} vs {}",
                a[k],
                a2[k]
            );
        }
        let lscale = l.iter().fold(0.0f64, |s, x| s.max(x.abs()));
        for k in 0..m {
            assert!(
                (l[k] - l2[k]).abs() < 1e-11 * lscale,
                "lambda[{k}]: {} vs {}",
                l[k],
                l2[k]
            );
        }
        // the disc on a massless axle: E_3 = 0, M singular; the solve is finite and keeps the
        // acceleration constraints
        let disc = mbd_model::models::heavy_top([0.25, 0.25, 0.5], 0.4, 15.0).unwrap();
        let (q, v) = disc.initial_guess();
        let mut acc = AccelerationSolver::new(&disc);
        acc.solve(&disc, q.as_slice(), v.as_slice(), 0.0, &mut a, &mut l)
            .unwrap();
        let res = &acc.phi_q * nalgebra::DVector::from_column_slice(&a);
        for r in 0..m {
            assert!(
                (res[r] - acc.gamma[r]).abs() < 1e-10,
                "row {r}: {} vs {}",
                res[r],
                acc.gamma[r]
            );
        }
    }
}
