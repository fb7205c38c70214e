//! Allocation-free projection of a state onto the position and velocity constraints
//! (minimum `M`-norm corrections), for post-step stabilisation and consistent initial states.
//! Dense for small systems, on the sparse kernel ([`ConstraintSchur`]) above
//! [`crate::SPARSE_THRESHOLD`] constraints.

use crate::constrained::ConstrainedSolve;
use crate::error::SolveError;
use crate::linalg::{max_abs, BodyFactorError, DenseSchur, FactorError};
use crate::sparse::{ConstraintSchur, LinearSolver};
use mbd_model::System;

/// The position projection stops at `max(tol, PROJECTION_ROUNDOFF_FACTOR eps max(1, |x, y|,
/// |theta_guess|))`: the round-off floor of evaluating `Phi` at positions of the current iterate
/// (`|x, y|`: the largest centre-of-mass coordinate) and at the angles of the guess (an angle
/// Newton inflates does not raise the floor).
pub const PROJECTION_ROUNDOFF_FACTOR: f64 = 8.0;

/// Settings of [`Projector`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProjectionSettings {
    /// Target `||Phi||_inf` (floored at the round-off level, see [`PROJECTION_ROUNDOFF_FACTOR`]).
    pub tol: f64,
    /// Iteration limit of the position projection.
    pub max_iter: usize,
}

impl Default for ProjectionSettings {
    fn default() -> Self {
        ProjectionSettings {
            tol: 1e-14,
            max_iter: 20,
        }
    }
}

/// The factorisation of `S = Phi_q M^-1 Phi_q^T` a projection uses.
// one per projector, built once: the dense arm stays unboxed (no indirection on small systems)
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
enum Kernel {
    /// `Phi_q` in element-local rows and the dense factorisation of `S`.
    Dense(DenseSchur),
    Sparse(Box<ConstraintSchur>),
    /// Models with spatial bodies: their internal constraints eliminated body by body.
    Bodies(Box<BodiesKernel>),
}

/// The body-eliminated kernel and its buffers: the correction and the multipliers.
#[derive(Debug)]
struct BodiesKernel {
    schur: ConstrainedSolve,
    delta: Vec<f64>,
    lambda: Vec<f64>,
    zeros: Vec<f64>,
    target: Vec<f64>,
}

/// Projects `q` onto `Phi(q, t) = 0` by Newton with the minimum `M`-norm correction
/// `dq = -M^-1 Phi_q^T (Phi_q M^-1 Phi_q^T)^-1 Phi` and `v` onto `Phi_q v + Phi_t = 0` by the
/// `M`-orthogonal projection.
#[derive(Debug)]
pub struct Projector {
    /// Settings.
    pub settings: ProjectionSettings,
    kernel: Kernel,
    r: Vec<f64>,
    /// The weights of the corrections in place of `M^-1` (zero: a coordinate the projections
    /// keep), if set.
    weights: Option<Vec<f64>>,
    /// Whether a correction whose factorisation refuses `S` (a dependent row: the guess lies
    /// on or next to a singular configuration) is taken by the truncated pseudo-inverse
    /// instead ([`Projector::set_min_norm_fallback`]).
    min_norm_fallback: bool,
}

/// The rank cut of the minimum-norm fallback correction, relative to the largest singular
/// value of `Phi_q W^(1/2)` (the square roots of `S`'s eigenvalues): the scale of the pivot
/// ratio `L_jj^2 / S_jj` below which the factorisations refuse
/// ([`mbd_linalg::CHOLESKY_PIVOT_TOL`], a sine of `1e-7` between a row and the span of the
/// others). The directions below it are left out of the correction.
const FALLBACK_RANK_CUT: f64 = 1e-7;

/// The smallest sine of the angle between an equation's gradient and the span of the others
/// (unit-free, [`System::nearly_dependent_at`]) at the end of a projection that took the
/// minimum-norm fallback: the angle below which the factorisations may take a row for a
/// dependent one ([`mbd_linalg::DEPENDENT_PIVOT_TOL`], a pivot ratio of `1e-10`).
const FALLBACK_END_ANGLE: f64 = 1e-5;

/// What a projection did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProjectionStats {
    /// Newton iterations of the position projection.
    pub iterations: usize,
    /// Final `||Phi||_inf`.
    pub residual: f64,
}

impl Projector {
    /// A workspace for `sys`, dense or sparse by the constraint count ([`LinearSolver::Auto`]).
    pub fn new(sys: &System, settings: ProjectionSettings) -> Result<Self, SolveError> {
        Self::with_linear(sys, settings, LinearSolver::Auto)
    }

    /// A workspace for `sys` with the factorisation chosen by `linear`.
    pub fn with_linear(
        sys: &System,
        settings: ProjectionSettings,
        linear: LinearSolver,
    ) -> Result<Self, SolveError> {
        let m = sys.n_constraints();
        let kernel = if sys.has_spatial() {
            let n = sys.n_coords();
            Kernel::Bodies(Box::new(BodiesKernel {
                schur: ConstrainedSolve::new(sys, linear)?,
                delta: vec![0.0; n],
                lambda: vec![0.0; m],
                zeros: vec![0.0; n],
                target: vec![0.0; m],
            }))
        } else if linear.use_sparse(m) {
            Kernel::Sparse(Box::new(ConstraintSchur::new(sys)?))
        } else {
            Kernel::Dense(DenseSchur::new(sys))
        };
        Ok(Projector {
            settings,
            kernel,
            r: vec![0.0; m],
            weights: None,
            min_norm_fallback: false,
        })
    }

    /// Weights the corrections by `w` (length n) in place of `M^-1`: the smallest
    /// `W^-1`-weighted change, and a coordinate with `w_i = 0` is not changed at all (an input
    /// of the initial state). `None` restores `M^-1`. A weight vector that leaves an equation
    /// no coordinate to move makes the projection's factorisation singular (the error names
    /// the equation).
    pub(crate) fn set_weights(&mut self, w: Option<Vec<f64>>) {
        self.weights = w;
    }

    /// Lets a correction that the factorisation of `S = Phi_q W Phi_q^T` refuses (a singular
    /// `S`: the constraint gradients are dependent where the correction is computed) be taken
    /// as the minimum-`W`-norm correction of the truncated pseudo-inverse of `Phi_q W^(1/2)`
    /// instead (dense planar models up to [`mbd_model::SPARSE_RANK_THRESHOLD`] equations; it
    /// allocates). For consistent initial states: a guess on a singular configuration that
    /// is slightly off the constraints (a flat four-bar with a coordinate rounded) is projected
    /// onto them instead of being refused. Off by default: during a run a singular `S` is the
    /// run's singular-configuration handling's to see.
    pub(crate) fn set_min_norm_fallback(&mut self, on: bool) {
        self.min_norm_fallback = on;
    }

    /// Whether the sparse kernel is in use.
    pub fn is_sparse(&self) -> bool {
        match &self.kernel {
            Kernel::Sparse(_) => true,
            Kernel::Bodies(k) => k.schur.is_sparse(),
            Kernel::Dense(_) => false,
        }
    }

    fn factor(&mut self, sys: &System, q: &[f64], t: f64) -> Result<(), SolveError> {
        let minv = self
            .weights
            .as_deref()
            .unwrap_or(sys.inv_mass_diag().as_slice());
        let res = match &mut self.kernel {
            Kernel::Dense(schur) => {
                sys.phi_q_local(q, &mut schur.grads);
                schur.factor(minv)
            }
            Kernel::Sparse(schur) => {
                schur.update(sys, q);
                schur.factor(minv)
            }
            Kernel::Bodies(k) => return k.schur.factor_weighted(sys, q, t, minv),
        };
        res.map_err(|e| {
            let i = match e {
                FactorError::Singular(i) | FactorError::NotPositiveDefinite(i) => i,
            };
            SolveError::Singular {
                t,
                what: "projection matrix Phi_q M^-1 Phi_q^T",
                detail: sys.equation_name(i),
            }
        })
    }

    /// `x -= M^-1 Phi_q^T S^-1 r` with `r` in `self.r`.
    fn correct(&mut self, sys: &System, x: &mut [f64]) {
        let minv = self
            .weights
            .as_deref()
            .unwrap_or(sys.inv_mass_diag().as_slice());
        match &mut self.kernel {
            Kernel::Dense(schur) => {
                schur.chol.solve_in_place(&mut self.r);
                schur.sub_weighted_transpose(&self.r, x);
            }
            Kernel::Sparse(schur) => {
                schur.solve_in_place(&mut self.r);
                schur.add_weighted_transpose(-1.0, minv, &self.r, x);
            }
            Kernel::Bodies(k) => {
                // the smallest correction with Phi_q dx = -r
                for (t, r) in k.target.iter_mut().zip(&self.r) {
                    *t = -r;
                }
                // (the sizes are the model's: the solve cannot refuse them)
                let _ = k
                    .schur
                    .solve(&k.zeros, &k.target, &mut k.delta, &mut k.lambda);
                for (xi, d) in x.iter_mut().zip(&k.delta) {
                    *xi += d;
                }
            }
        }
    }

    /// The end of a position projection at `q` that took the minimum-norm fallback for a
    /// refused factorisation (`refused`, the first refusal): the end configuration must be
    /// regular, every equation's gradient at least [`FALLBACK_END_ANGLE`] from the span of
    /// the others (from there the velocity projection and the solvers start as from any
    /// regular configuration); one that is not (the constraints have their solution on or
    /// next to a singular configuration: a driven crank held in line with the ground) is the
    /// first refusal, as without the fallback.
    #[cold]
    #[inline(never)]
    fn regular_end(
        &self,
        sys: &System,
        q: &[f64],
        t: f64,
        refused: SolveError,
        stats: ProjectionStats,
    ) -> Result<ProjectionStats, SolveError> {
        if sys.nearly_dependent_at(q, t, FALLBACK_END_ANGLE).is_empty() {
            Ok(stats)
        } else {
            Err(refused)
        }
    }

    /// The fallback of a refused factorisation ([`Projector::set_min_norm_fallback`]):
    /// `q -= W^(1/2) (Phi_q(q) W^(1/2))^+ r` with the residual `r` in `self.r`; `refused` is
    /// returned where the fallback does not apply (spatial bodies, the sparse size, an SVD
    /// that fails).
    #[cold]
    #[inline(never)]
    fn min_norm_correct(
        &mut self,
        sys: &System,
        q: &mut [f64],
        t: f64,
        refused: SolveError,
    ) -> Result<(), SolveError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        if sys.has_spatial() || m > mbd_model::SPARSE_RANK_THRESHOLD {
            return Err(refused);
        }
        let root: Vec<f64> = self
            .weights
            .as_deref()
            .unwrap_or(sys.inv_mass_diag().as_slice())
            .iter()
            .map(|w| w.max(0.0).sqrt())
            .collect();
        let mut a = nalgebra::DMatrix::zeros(m, n);
        sys.phi_q(q, t, &mut a);
        for (k, w) in root.iter().enumerate() {
            a.column_mut(k).scale_mut(*w);
        }
        let r = nalgebra::DVector::from_column_slice(&self.r);
        let y = mbd_linalg::min_norm_solve(a, &r, FALLBACK_RANK_CUT).ok_or(refused)?;
        for ((qi, w), yi) in q.iter_mut().zip(&root).zip(y.iter()) {
            *qi -= w * yi;
        }
        Ok(())
    }

    fn check_len(&self, sys: &System, what: &'static str, x: &[f64]) -> Result<(), SolveError> {
        if x.len() != sys.n_coords() || self.r.len() != sys.n_constraints() {
            return Err(SolveError::Dimension {
                what,
                expected: sys.n_coords(),
                got: x.len(),
            });
        }
        Ok(())
    }

    /// Projects positions in place.
    pub fn project_positions(
        &mut self,
        sys: &System,
        q: &mut [f64],
        t: f64,
    ) -> Result<ProjectionStats, SolveError> {
        // (the fallback's bookkeeping in its own instance: the steps' projections stay as lean
        // as without it)
        if self.min_norm_fallback {
            self.positions::<true>(sys, q, t)
        } else {
            self.positions::<false>(sys, q, t)
        }
    }

    /// [`Projector::project_positions`], with the minimum-norm fallback where `FALLBACK`.
    fn positions<const FALLBACK: bool>(
        &mut self,
        sys: &System,
        q: &mut [f64],
        t: f64,
    ) -> Result<ProjectionStats, SolveError> {
        self.check_len(sys, "q", q)?;
        let m = sys.n_constraints();
        if m == 0 {
            return Ok(ProjectionStats::default());
        }
        let mut stats = ProjectionStats::default();
        // the first refusal of the factorisation that the minimum-norm fallback stood in for
        let mut refused: Option<SolveError> = None;
        // The residual of `Phi` cannot fall below the round-off of evaluating it at coordinates
        // of size |q|: a far-out or long mechanism (a 100-link chain reaches 100 m) has a floor
        // above a fixed 1e-14, and Newton would otherwise iterate to `max_iter` there. The floor
        // takes the positions of the current iterate (a guess far out, x = 1e20, must not lend
        // its floor to the configuration Newton brings back) and the angles of the guess (a
        // wound-up angle is legitimate, an angle Newton inflates is not).
        let angles = (0..q.len() / 3).fold(0.0f64, |a, i| a.max(q[3 * i + 2].abs()));
        let floor = |q: &[f64]| {
            let pos =
                (0..q.len() / 3).fold(0.0f64, |a, i| a.max(q[3 * i].abs()).max(q[3 * i + 1].abs()));
            PROJECTION_ROUNDOFF_FACTOR * f64::EPSILON * pos.max(angles).max(1.0)
        };
        for it in 0..=self.settings.max_iter {
            let tol = self.settings.tol.max(floor(q));
            sys.phi(q, t, &mut self.r);
            let res = max_abs(&self.r);
            stats.residual = res;
            if !res.is_finite() {
                return Err(SolveError::NonFinite {
                    t,
                    what: "constraint residual in projection",
                });
            }
            if res <= tol {
                return match refused {
                    None => Ok(stats),
                    Some(e) => self.regular_end(sys, q, t, e, stats),
                };
            }
            if it == self.settings.max_iter {
                break;
            }
            match self.factor(sys, q, t) {
                Ok(()) => self.correct(sys, q),
                Err(e) if FALLBACK => {
                    self.min_norm_correct(sys, q, t, e.clone())?;
                    refused.get_or_insert(e);
                }
                Err(e) => return Err(e),
            }
            stats.iterations += 1;
        }
        // accept a residual at the round-off floor of the configuration
        if stats.residual <= 1e3 * self.settings.tol.max(floor(q)) {
            return match refused {
                None => Ok(stats),
                Some(e) => self.regular_end(sys, q, t, e, stats),
            };
        }
        let worst = (0..self.r.len())
            .max_by(|&a, &b| self.r[a].abs().total_cmp(&self.r[b].abs()))
            .unwrap_or(0);
        Err(SolveError::Newton {
            t,
            residual: stats.residual,
            iterations: stats.iterations,
            context: format!(
                "position projection (largest residual in {})",
                sys.equation_name(worst)
            ),
        })
    }

    /// Projects velocities in place (at positions `q`, assumed on the manifold).
    pub fn project_velocities(
        &mut self,
        sys: &System,
        q: &[f64],
        v: &mut [f64],
        t: f64,
    ) -> Result<(), SolveError> {
        self.check_len(sys, "q", q)?;
        self.check_len(sys, "v", v)?;
        if sys.n_constraints() == 0 {
            return Ok(());
        }
        self.factor(sys, q, t)?;
        sys.phi_dot(q, v, t, &mut self.r);
        self.correct(sys, v);
        Ok(())
    }

    /// Projects both positions and velocities.
    pub fn project(
        &mut self,
        sys: &System,
        q: &mut [f64],
        v: &mut [f64],
        t: f64,
    ) -> Result<ProjectionStats, SolveError> {
        let s = self.project_positions(sys, q, t)?;
        self.project_velocities(sys, q, v, t)?;
        Ok(s)
    }
}

/// A failed body-eliminated factorisation as the solver's error: a degenerate spatial body
/// (named; dependent directors, which only coordinates far off the constraints have, are
/// [`SolveError::DegenerateDirectors`]) or a singular constraint matrix (the equation named).
pub(crate) fn bodies_error(sys: &System, t: f64, e: BodyFactorError) -> SolveError {
    match e {
        BodyFactorError::Body(body, reason) => SolveError::Singular {
            t,
            what: "spatial body",
            detail: format!("'{body}': {reason}"),
        },
        BodyFactorError::Directors(body) => SolveError::DegenerateDirectors { t, body },
        BodyFactorError::Row(i) => SolveError::Singular {
            t,
            what: "constraint matrix Phi_e C Phi_e^T",
            detail: sys.equation_name(i),
        },
    }
}
