//! The constrained (saddle-point) solve `M x + Phi_q^T lambda = f`, `Phi_q x = r` at a
//! configuration, for any model: planar bodies, spatial bodies whose mass matrix is singular
//! (thin discs and plates: `M` need only be definite on the constraints' tangent space), dense
//! below the sparse threshold and over body blocks above it (`linalg::BodySchur`,
//! `sparse::SparseBodySchur`; docs/spatial.md). The index-1 solve is `f = Q`, `r = gamma`; a
//! projection's correction `f = 0`, `r = -Phi`; a velocity from a momentum `f = p`,
//! `r = -Phi_t`.

use crate::error::SolveError;
use crate::linalg::BodySchur;
use crate::sparse::{LinearSolver, SparseBodySchur};
use mbd_model::System;

/// The dense or sparse body-eliminated kernel.
#[derive(Debug)]
enum Kernel {
    Dense(Box<BodySchur>),
    Sparse(Box<SparseBodySchur>),
}

/// Workspace of the constrained solve (see the module documentation); allocation-free after
/// [`ConstrainedSolve::new`].
///
/// ```
/// use mbd_model::models::heavy_top;
/// use mbd_solve::{ConstrainedSolve, LinearSolver};
/// // a disc top (E_3 = 0: a singular mass matrix) at rest: the acceleration under gravity
/// let top = heavy_top([0.25, 0.25, 0.5], 0.3, 0.0)?;
/// let (n, m) = (top.n_coords(), top.n_constraints());
/// let (q, _) = top.initial_guess();
/// let mut solve = ConstrainedSolve::new(&top, LinearSolver::Auto)?;
/// solve.factor(&top, q.as_slice(), 0.0)?;
/// let mut f = vec![0.0; n];
/// f[2] = -9.81; // gravity on the 1 kg top's centre
/// let (mut a, mut lambda) = (vec![0.0; n], vec![0.0; m]);
/// solve.solve(&f, &vec![0.0; m], &mut a, &mut lambda)?;
/// assert!(a[2] < 0.0 && a[2] > -9.81); // it falls, slower than freely
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct ConstrainedSolve {
    n: usize,
    m: usize,
    kernel: Kernel,
    /// `gamma` from the sparse kernel's row update (unused here).
    gamma: Vec<f64>,
    /// The planar weights of the last factorisation (`M^-1` unless given).
    w: Vec<f64>,
}

impl ConstrainedSolve {
    /// A workspace for `sys`, dense or sparse as `linear` picks for its equation count.
    pub fn new(sys: &System, linear: LinearSolver) -> Result<Self, SolveError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        Ok(ConstrainedSolve {
            n,
            m,
            kernel: if linear.use_sparse(m) {
                Kernel::Sparse(Box::new(SparseBodySchur::new(sys)?))
            } else {
                Kernel::Dense(Box::new(BodySchur::new(sys)))
            },
            gamma: vec![0.0; m],
            w: sys.inv_mass_diag().as_slice().to_vec(),
        })
    }

    /// Whether the sparse kernel is in use.
    pub fn is_sparse(&self) -> bool {
        matches!(self.kernel, Kernel::Sparse(_))
    }

    /// Factors the solve at configuration `q` (time `t`, for the error) with `M^-1`.
    pub fn factor(&mut self, sys: &System, q: &[f64], t: f64) -> Result<(), SolveError> {
        self.w.copy_from_slice(sys.inv_mass_diag().as_slice());
        self.factor_with(sys, q, t)
    }

    /// Factors with the planar coordinates weighted by `w` in place of `M^-1` (a projection's
    /// weights); spatial bodies keep their own elimination.
    pub(crate) fn factor_weighted(
        &mut self,
        sys: &System,
        q: &[f64],
        t: f64,
        w: &[f64],
    ) -> Result<(), SolveError> {
        self.w.copy_from_slice(w);
        self.factor_with(sys, q, t)
    }

    fn factor_with(&mut self, sys: &System, q: &[f64], t: f64) -> Result<(), SolveError> {
        if q.len() != self.n {
            return Err(SolveError::Dimension {
                what: "constrained solve q",
                expected: self.n,
                got: q.len(),
            });
        }
        let res = match &mut self.kernel {
            Kernel::Dense(schur) => {
                sys.phi_q(q, t, &mut schur.phi_q);
                schur.factor(sys, q, &self.w)
            }
            Kernel::Sparse(schur) => {
                schur.update(sys, q, None, t, &mut self.gamma);
                schur.factor(sys, &self.w)
            }
        };
        res.map_err(|e| crate::projection::bodies_error(sys, t, e))
    }

    /// The equations the last factorisation dropped as dependent on earlier ones (a model
    /// with redundant equations: their multipliers are zero, the basic solution), into `out`
    /// (cleared first; no allocation once `out` has the capacity).
    pub fn dependent_rows(&self, out: &mut Vec<usize>) {
        out.clear();
        match &self.kernel {
            Kernel::Dense(schur) => schur.dependent_rows(out),
            Kernel::Sparse(schur) => schur.dependent_rows(out),
        }
    }

    /// The solution `x` of `M x + Phi_q^T lambda = f`, `Phi_q x = r` and its multipliers at the
    /// last factorisation.
    pub fn solve(
        &mut self,
        f: &[f64],
        r: &[f64],
        x: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<(), SolveError> {
        for (what, got, expected) in [
            ("constrained solve f", f.len(), self.n),
            ("constrained solve x", x.len(), self.n),
            ("constrained solve r", r.len(), self.m),
            ("constrained solve lambda", lambda.len(), self.m),
        ] {
            if got != expected {
                return Err(SolveError::Dimension {
                    what,
                    expected,
                    got,
                });
            }
        }
        match &mut self.kernel {
            Kernel::Dense(schur) => schur.solve(&self.w, f, r, x, lambda),
            Kernel::Sparse(schur) => schur.solve(&self.w, f, r, x, lambda),
        }
        Ok(())
    }
}
