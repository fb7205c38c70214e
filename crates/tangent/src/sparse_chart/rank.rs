//! The rank report of the sparse chart: the sparse Cholesky factorisation of
//! `Phi_q W Phi_q^T` (`W` the model's [`System::rank_weights`], so the test does not depend on
//! the units of lengths) at a configuration names the dependent equation (an error path).

use super::SparseChart;
use mbd_model::System;
use mbd_solve::linalg::FactorError;
use mbd_solve::SolveError;

impl SparseChart {
    /// A singular configuration at the last centre: the sparse Cholesky factorisation of
    /// `Phi_q W Phi_q^T` fails (pivot test) or its condition estimate exceeds `1 / rel_tol^2`,
    /// as [`SolveError::Singular`] naming the dependent equation and its joint (`None` if it
    /// factors well). Allocates only for the report.
    pub fn singular_error(&mut self, sys: &System, t: f64, rel_tol: f64) -> Option<SolveError> {
        if self.m == 0 || self.independent() > self.n {
            return None;
        }
        self.grads_x.copy_from_slice(&self.grads);
        self.pos_report(sys, t, rel_tol)
    }

    /// [`SparseChart::singular_error`] for `Phi_q` at the configuration `q` (length `n`).
    pub fn singular_error_at(
        &mut self,
        sys: &System,
        q: &[f64],
        t: f64,
        rel_tol: f64,
    ) -> Option<SolveError> {
        if self.m == 0 || self.independent() > self.n || q.len() != self.n {
            return None;
        }
        self.rows.gather(sys, q, None, t, &mut self.grads_x, None);
        self.pos_report(sys, t, rel_tol)
    }

    fn pos_report(&mut self, sys: &System, t: f64, rel_tol: f64) -> Option<SolveError> {
        self.pos_chol.clear();
        let vals = self.pos_chol.values_mut();
        for c in &self.pos_contributions {
            let (a1, a2) = (
                &self.grads_x[c.o1..c.o1 + c.w],
                &self.grads_x[c.o2..c.o2 + c.w],
            );
            let w = &self.rank_w[c.col..c.col + c.w];
            vals[c.idx] += a1
                .iter()
                .zip(a2)
                .zip(w)
                .map(|((a, b), w)| a * b * w)
                .sum::<f64>();
        }
        let what = "configuration (rank-deficient constraint Jacobian Phi_q)";
        match self.pos_chol.factor() {
            Ok(()) => {
                let cond = self.pos_chol.condition_estimate();
                if cond * rel_tol * rel_tol > 1.0 {
                    Some(SolveError::Singular {
                        t,
                        what,
                        detail: format!(
                            "condition estimate {cond:.3e} of Phi_q W Phi_q^T (sparse Cholesky, W ~ M^-1)"
                        ),
                    })
                } else {
                    None
                }
            }
            Err(FactorError::Singular(i) | FactorError::NotPositiveDefinite(i)) => {
                let joint = sys
                    .equation_joint(i)
                    .and_then(|h| sys.joints().get(h.index()))
                    .map(|j| j.name.clone())
                    .unwrap_or_default();
                Some(SolveError::Singular {
                    t,
                    what,
                    detail: format!(
                        "dependent equation {} (sparse Cholesky pivot of Phi_q W Phi_q^T); joint {joint}",
                        sys.equation_name(i)
                    ),
                })
            }
        }
    }
}
