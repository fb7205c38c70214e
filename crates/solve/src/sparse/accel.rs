//! The index-1 acceleration solve for large systems: the Schur complement
//! `S = Phi_q M^-1 Phi_q^T` is assembled on its sparse pattern by [`ConstraintSchur`] (it couples
//! two constraint equations only when they act on a common body) and factored by the sparse
//! Cholesky kernel. The symbolic analysis is done once in [`SparseAccelerationSolver::new`];
//! each solve refills the values and refactors into preallocated storage, so a solve allocates
//! nothing. For a chain of `N` bodies `S` is block tridiagonal and a solve costs `O(N)`, against
//! `O(N^3)` for the dense path. A model with spatial bodies takes the body-eliminated kernel
//! ([`SparseBodySchur`]: its rows over body blocks of any width, each spatial body's internal
//! constraints eliminated body by body), `O(N)` for chains as well.

use super::bodies::SparseBodySchur;
use super::schur::ConstraintSchur;
use crate::error::SolveError;
use crate::linalg::FactorError;
use mbd_model::{BodyAngles, System};

/// Sparse index-1 solver (see the module documentation).
#[derive(Debug)]
pub struct SparseAccelerationSolver {
    n: usize,
    m: usize,
    schur: Kernel,
    /// `gamma` at the last solve (callers may modify it before [`SparseAccelerationSolver::finish`]).
    pub gamma: Vec<f64>,
    /// Applied forces `Q` at the last solve.
    pub forces: Vec<f64>,
    w: Vec<f64>,
    /// The bodies' `sin`/`cos` at the last `q` (one evaluation per body and solve).
    angles: BodyAngles,
}

/// The Schur complement of the planar rows, or of the rows over body blocks.
#[derive(Debug)]
enum Kernel {
    Rows(Box<ConstraintSchur>),
    Bodies(Box<SparseBodySchur>),
}

impl SparseAccelerationSolver {
    /// Analyses the pattern of `S` for `sys` (allocates; done once).
    pub fn new(sys: &System) -> Result<Self, SolveError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        Ok(SparseAccelerationSolver {
            n,
            m,
            schur: if sys.has_spatial() {
                Kernel::Bodies(Box::new(SparseBodySchur::new(sys)?))
            } else {
                Kernel::Rows(Box::new(ConstraintSchur::new(sys)?))
            },
            gamma: vec![0.0; m],
            forces: vec![0.0; n],
            w: vec![0.0; n],
            angles: BodyAngles::new(sys, sys.initial_guess().0.as_slice()),
        })
    }

    /// Non-zeros stored for the lower triangle of `S`.
    pub fn nnz(&self) -> usize {
        match &self.schur {
            Kernel::Rows(s) => s.nnz(),
            Kernel::Bodies(b) => b.nnz(),
        }
    }

    /// The condition estimate of the last factored `S` (see
    /// [`crate::sparse::SparseCholesky::condition_estimate`]); 1 for an unconstrained system.
    pub fn condition_estimate(&self) -> f64 {
        match &self.schur {
            Kernel::Rows(s) => s.condition_estimate(),
            Kernel::Bodies(b) => b.condition_estimate(),
        }
    }

    /// How many dependent rows the last factorisation dropped.
    pub(crate) fn dropped(&self) -> usize {
        match &self.schur {
            Kernel::Rows(s) => s.dependent().len(),
            Kernel::Bodies(b) => b.dropped(),
        }
    }

    /// The constraint Jacobian and Schur complement of the last solve (`None` for a model
    /// with spatial bodies, whose rows are held per body block).
    pub fn schur(&self) -> Option<&ConstraintSchur> {
        match &self.schur {
            Kernel::Rows(s) => Some(s),
            Kernel::Bodies(_) => None,
        }
    }

    /// Accelerations `a` and multipliers `lambda` at `(q, v, t)`.
    pub fn solve(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &[f64],
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        if q.len() != self.n || v.len() != self.n {
            return Err(SolveError::Dimension {
                what: "sparse acceleration solve q, v",
                expected: self.n,
                got: if q.len() != self.n { q.len() } else { v.len() },
            });
        }
        self.prepare(sys, q, v, t);
        self.finish(sys, t, a, lambda)
    }

    /// Evaluates the forces, `Phi_q` and `gamma` at `(q, v, t)` without solving: a caller may
    /// then modify [`SparseAccelerationSolver::gamma`] or
    /// [`SparseAccelerationSolver::forces`] (e.g. Baumgarte) before
    /// [`SparseAccelerationSolver::finish`].
    pub fn prepare(&mut self, sys: &System, q: &[f64], v: &[f64], t: f64) {
        sys.forces_into(q, v, t, &mut self.forces);
        match &mut self.schur {
            Kernel::Rows(schur) => {
                self.angles.update(sys, q);
                sys.phi_q_local_gamma_at(q, &self.angles, v, t, schur.grads_mut(), &mut self.gamma);
            }
            Kernel::Bodies(b) => b.update(sys, q, Some(v), t, &mut self.gamma),
        }
    }

    /// Completes the solve from `Phi_q`, `gamma` and `forces` already set.
    pub fn finish(
        &mut self,
        sys: &System,
        t: f64,
        a: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        if a.len() != self.n || lambda.len() != self.m {
            return Err(SolveError::Dimension {
                what: "sparse acceleration solve a, lambda",
                expected: if a.len() != self.n { self.n } else { self.m },
                got: if a.len() != self.n {
                    a.len()
                } else {
                    lambda.len()
                },
            });
        }
        let minv = sys.inv_mass_diag().as_slice();
        for ((w, &mi), &f) in self.w.iter_mut().zip(minv).zip(&self.forces) {
            *w = mi * f;
        }
        if self.m == 0 {
            a.copy_from_slice(&self.w);
            return Ok(());
        }
        let schur = match &mut self.schur {
            Kernel::Rows(schur) => schur,
            Kernel::Bodies(b) => {
                b.factor(sys, minv)
                    .map_err(|e| crate::projection::bodies_error(sys, t, e))?;
                b.solve(minv, &self.forces, &self.gamma, a, lambda);
                return Self::check_finite(t, lambda, &self.forces, &self.gamma);
            }
        };
        schur.factor(minv).map_err(|e| {
            let i = match e {
                FactorError::Singular(i) | FactorError::NotPositiveDefinite(i) => i,
            };
            SolveError::Singular {
                t,
                what: "sparse constraint matrix Phi_q M^-1 Phi_q^T",
                detail: sys.equation_name(i),
            }
        })?;
        // rhs = Phi_q M^-1 Q - gamma
        schur.apply(&self.w, lambda);
        for (l, g) in lambda.iter_mut().zip(&self.gamma) {
            *l -= g;
        }
        schur.solve_in_place(lambda);
        // a = M^-1 (Q - Phi_q^T lambda)
        a.copy_from_slice(&self.w);
        schur.add_weighted_transpose(-1.0, minv, lambda, a);
        Self::check_finite(t, lambda, &self.forces, &self.gamma)
    }

    /// Non-finite multipliers: from non-finite forces or velocity terms `gamma` (a state far
    /// off any solution, e.g. after a step too long for the motion) they are
    /// [`SolveError::NonFinite`]; from finite ones the factorisation was numerically singular.
    fn check_finite(
        t: f64,
        lambda: &[f64],
        forces: &[f64],
        gamma: &[f64],
    ) -> Result<(), SolveError> {
        if !lambda.iter().all(|x| x.is_finite()) {
            if !forces.iter().chain(gamma).all(|x| x.is_finite()) {
                return Err(SolveError::NonFinite {
                    t,
                    what: "forces or velocity terms of the index-1 solve",
                });
            }
            return Err(SolveError::Singular {
                t,
                what: "sparse constraint matrix Phi_q M^-1 Phi_q^T",
                detail: "non-finite multipliers".into(),
            });
        }
        Ok(())
    }
}
