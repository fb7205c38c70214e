//! Settings of the (s,s) scheme.

use mbd_solve::{LinearSolver, NewtonOptions, SolveError};

/// Where the `s + 1` control points of a step lie (and so where the constraints are enforced).
///
/// For `s <= 2` both choices are the same points (`0, 1` and `0, 1/2, 1`) and give bit-identical
/// results. They differ from `s = 3` on: see the crate docs and `docs/symplectic.md`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Nodes {
    /// Gauss-Lobatto points (default): the constraint-curvature forces are then integrated by the
    /// `(s+1)`-point Lobatto rule, of order `2s`, and the scheme has order `2s` for every `s`.
    #[default]
    Lobatto,
    /// Equally spaced points `nu / s` (the literal reading of paper A). The constraint forces are
    /// then lumped by a closed Newton-Cotes rule, which limits the order to 2, 4, 4, 6 for
    /// `s = 1, 2, 3, 4`.
    Equispaced,
}

/// Which preadjustment of the discrete Lagrangian is used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PreadjustMode {
    /// Paper A's `-gamma kappa_s h^(2s) W_s(q)` with [`SymplecticOptions::gamma`] (`gamma = 0`:
    /// the plain scheme). Default.
    #[default]
    Paper,
    /// A parameter-free modified Lagrangian instead of `W_s`. For `s = 1`, `L~ = L + h^2 e(q, v)`
    /// with `e = -1/24 f_T^T M^-1 f_T + 1/12 v^T A v - 1/8 v^T Hess V v +
    /// 1/24 gamma_c^T S^-1 gamma_c`, evaluated at the chord midpoint of each step
    /// (`docs/symplectic.md` section 5a, derivation in `docs/modified-lagrangian.md`); for
    /// `s = 2` the `h^4` term `e4` of section 5b (23 invariant terms, exact gradients by a
    /// reverse pass; a (2,2) step costs 2.4x to 6x the plain one by instructions, more on small
    /// models). Needs `s <= 2`, `gamma = 0` and a conservative model; either path.
    ModifiedLagrangian,
}

/// Settings of [`crate::Galerkin`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SymplecticOptions {
    /// Degree of the interpolation and number of Gauss points (`s >= 1`); order `2s`.
    pub s: usize,
    /// The preadjustment parameter `gamma` (0: the plain scheme; 1: `gamma_T`).
    pub gamma: f64,
    /// Which preadjustment: paper A's `W_s` scaled by `gamma` (default) or the parameter-free
    /// modified Lagrangian (`s = 1` or `2`).
    pub preadjust: PreadjustMode,
    /// Placement of the control points.
    pub nodes: Nodes,
    /// Newton settings for the stage equations. With `tol_k = tol (1 + max |x, y|) + 4 eps
    /// (1 + ||q||_inf)` (lengths: the scaled residual is in displacement units), a step is
    /// converged after at least one update when the max-norm of the residual and that of the
    /// last displacement update are both below `tol_k`, or when the simplified-Newton estimate
    /// of the error left after an update is below `tol_k / 10` (and the constraints below
    /// `tol_k`); an update that stagnates below `step_tol (1 + ||q||_inf)` is accepted if the
    /// residual is below `1e-8`. `max_iter` limits the iterations; `max_halvings` allows
    /// backtracking on the residual norm; the Jacobian is evaluated at the predictor and kept
    /// (simplified Newton) for up to `jacobian_every` iterations while each iteration shrinks
    /// the update at least 4x (`jacobian_every = 1`: full Newton; default 6). See
    /// `docs/symplectic.md` for why the predictor is never accepted without an update.
    pub newton: NewtonOptions,
    /// Relative step of the finite-difference checks of the preadjustment's derivatives. The
    /// integrator itself does not differentiate numerically: the third derivatives of `V` and `Phi` in `grad W_s` and in the
    /// modified-Lagrangian gradient are exact (`passes::potential_third`,
    /// `constraint_third`). Still validated (finite, in `(0, 1)`).
    pub fd_step: f64,
    /// Whether a step starts with the factored Jacobian of the previous step (same `h`) instead
    /// of a new one; a kept factorisation is recomputed as soon as the simplified Newton
    /// iteration contracts by less than 4x per iteration. Default [`JacobianReuse::Auto`]: kept
    /// on the sparse stage path of the plain scheme, where one factorisation costs as much as
    /// many residuals, new at every step otherwise. The converged solution does not depend on it (to the
    /// Newton tolerance).
    pub reuse_jacobian: JacobianReuse,
    /// Order `p` of the multistep predictor: once `p + 1` consecutive steps of the same `h` have
    /// been taken, the unknowns of the next step (control-point displacements and multipliers)
    /// are extrapolated by the degree-`p` polynomial through the last `p + 1` solutions
    /// (error `O(h^(p+1))` in the multipliers); before that, the previous step's interpolant is
    /// extrapolated (or, on the first step, a Taylor predictor from the index-1 accelerations).
    /// 0 turns the multistep predictor off. Default 3; at most 6. Only the number of Newton
    /// iterations depends on it, not the solution (to round-off: at least one Newton update is
    /// made from every prediction).
    pub predictor_order: usize,
    /// Dense or sparse stage solve. [`LinearSolver::Auto`] (default) takes the sparse path
    /// (`O(N)` per step on a chain of `N` bodies; `docs/symplectic.md`, "Sparse stage solve")
    /// above [`mbd_solve::SPARSE_THRESHOLD`] constraint equations, with or without a
    /// preadjustment (the dense Newton blocks of paper A's `W_s` and of the modified
    /// Lagrangian are taken there by diagonal stand-ins or, for the (1,1) scheme where they
    /// are not small, exactly through augmented unknowns).
    pub linear_solver: LinearSolver,
    /// Difference pairs kept by the Anderson mixing of the Newton updates (0 turns it off;
    /// default [`DEFAULT_ANDERSON_DEPTH`], at most [`MAX_ANDERSON_DEPTH`]). The mixing starts
    /// once a plain simplified-Newton update is more than [`ANDERSON_START_CONTRACTION`] times
    /// the one before it (an iteration matrix that leaves out part of the Jacobian, as the modified Lagrangian's diagonal
    /// Newton blocks on a long spatial chain) and carries over to the next step with a kept
    /// Jacobian; an iteration that contracts fast never starts it. Only the number of Newton
    /// iterations depends on it, not the solution (to the Newton tolerance).
    pub anderson_depth: usize,
}

/// Default [`SymplecticOptions::anderson_depth`].
pub const DEFAULT_ANDERSON_DEPTH: usize = 4;

/// Largest [`SymplecticOptions::anderson_depth`].
pub const MAX_ANDERSON_DEPTH: usize = 16;

/// The contraction of the plain simplified-Newton updates (the ratio of one update to the one
/// before it) above which the Anderson mixing starts: below it the plain iteration reaches the
/// tolerance within a few more updates anyway.
pub const ANDERSON_START_CONTRACTION: f64 = 0.12;

impl Default for SymplecticOptions {
    fn default() -> Self {
        SymplecticOptions {
            s: 2,
            gamma: 0.0,
            preadjust: PreadjustMode::Paper,
            nodes: Nodes::Lobatto,
            newton: NewtonOptions {
                tol: 1e-14,
                step_tol: 1e-15,
                max_iter: 25,
                max_halvings: 0,
                jacobian_every: 6,
            },
            fd_step: 2e-3,
            reuse_jacobian: JacobianReuse::Auto,
            predictor_order: 3,
            linear_solver: LinearSolver::Auto,
            anderson_depth: DEFAULT_ANDERSON_DEPTH,
        }
    }
}

impl SymplecticOptions {
    /// The plain `(s,s)` scheme with default settings.
    pub fn new(s: usize) -> Self {
        SymplecticOptions {
            s,
            ..Default::default()
        }
    }
    /// Sets `gamma`.
    pub fn with_gamma(mut self, gamma: f64) -> Self {
        self.gamma = gamma;
        self
    }
    /// Sets the preadjustment mode.
    pub fn with_preadjust(mut self, mode: PreadjustMode) -> Self {
        self.preadjust = mode;
        self
    }
    /// Sets the control-point placement.
    pub fn with_nodes(mut self, nodes: Nodes) -> Self {
        self.nodes = nodes;
        self
    }
    /// Sets when the factored stage Jacobian is kept from one step to the next.
    pub fn with_jacobian_reuse(mut self, reuse: JacobianReuse) -> Self {
        self.reuse_jacobian = reuse;
        self
    }
    /// Sets the Newton settings.
    pub fn with_newton(mut self, newton: NewtonOptions) -> Self {
        self.newton = newton;
        self
    }

    /// Checks every setting; the error names the parameter at fault.
    pub fn validate(&self) -> Result<(), SolveError> {
        if self.s == 0 || self.s > 16 {
            return Err(SolveError::InvalidParameter {
                parameter: "s",
                value: self.s as f64,
                reason: "the degree s must be between 1 and 16",
            });
        }
        if !self.gamma.is_finite() {
            return Err(SolveError::InvalidParameter {
                parameter: "gamma",
                value: self.gamma,
                reason: "must be finite",
            });
        }
        if self.preadjust == PreadjustMode::ModifiedLagrangian {
            if self.s > 2 {
                return Err(SolveError::InvalidParameter {
                    parameter: "preadjust",
                    value: self.s as f64,
                    reason: "the modified-Lagrangian preadjustment is derived for s = 1 and \
                             s = 2 only (s >= 3: not derived)",
                });
            }
            if self.gamma != 0.0 {
                return Err(SolveError::InvalidParameter {
                    parameter: "gamma",
                    value: self.gamma,
                    reason: "gamma scales paper A's W_s; it must be 0 with the \
                             modified-Lagrangian preadjustment",
                });
            }
        }
        if !(self.fd_step.is_finite() && self.fd_step > 0.0 && self.fd_step < 1.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "fd_step",
                value: self.fd_step,
                reason: "must be in (0, 1)",
            });
        }
        if self.predictor_order > MAX_PREDICTOR_ORDER {
            return Err(SolveError::InvalidParameter {
                parameter: "predictor_order",
                value: self.predictor_order as f64,
                reason: "must be at most 6",
            });
        }
        if self.anderson_depth > MAX_ANDERSON_DEPTH {
            return Err(SolveError::InvalidParameter {
                parameter: "anderson_depth",
                value: self.anderson_depth as f64,
                reason: "must be at most MAX_ANDERSON_DEPTH = 16 (0 turns the mixing off)",
            });
        }
        self.newton.validate()
    }
}

/// Largest [`SymplecticOptions::predictor_order`].
pub const MAX_PREDICTOR_ORDER: usize = 6;

/// `kappa_s`: the constant of the preadjustment term `-gamma kappa_s h^(2s) W_s` for which
/// `gamma = 1` cancels the leading phase error of the (s,s) scheme with Lobatto control points
/// (for `s <= 2` also the equispaced scheme):
/// `kappa_s = -(s!)^2 / (s ((2s)!)^2 (2s+1))`, i.e. `-1/12, -1/1440, -1/302400, -1/101606400`
/// for `s = 1..4`. Derived in `docs/symplectic.md`; returns NaN for `s = 0`.
pub fn kappa(s: usize) -> f64 {
    if s == 0 {
        return f64::NAN;
    }
    let mut fs = 1.0f64;
    for k in 1..=s {
        fs *= k as f64;
    }
    let mut f2s = 1.0f64;
    for k in 1..=2 * s {
        f2s *= k as f64;
    }
    -(fs * fs) / (s as f64 * f2s * f2s * (2 * s + 1) as f64)
}

/// The scheme's leading relative frequency error on a linear(ised) system whose stiffness comes
/// from constraint curvature (gravity-loaded pendulums): `omega_h / omega - 1 ~ c_s (omega h)^(2s)`
/// with `c_s = -kappa_s / 2` (1/24, 1/2880, 1/604800, 1/203212800): the numerical motion runs
/// fast. For stiffness from the potential Hessian (springs) the constant is instead
/// `-(s!)^2 / (((2s)!)^2 (2s+1))` (the Gauss rule's), and runs slow.
pub fn phase_constant(s: usize) -> f64 {
    -0.5 * kappa(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn kappa_values() {
        assert!((kappa(1) + 1.0 / 12.0).abs() < 1e-17);
        assert!((kappa(2) + 1.0 / 1440.0).abs() < 1e-18);
        assert!((kappa(3) + 1.0 / 302400.0).abs() < 1e-20);
        assert!((kappa(4) + 1.0 / 101606400.0).abs() < 1e-22);
        assert!(kappa(0).is_nan());
    }
}

/// When the symplectic scheme keeps the factored stage Jacobian from one step to the next
/// ([`SymplecticOptions::reuse_jacobian`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum JacobianReuse {
    /// Kept on the sparse stage path of the plain scheme, and of the modified Lagrangian on
    /// models with spatial bodies (large models, where one sparse factorisation costs as much
    /// as many residuals and triangular solves); a new one at every step on the dense path and
    /// for the modified Lagrangian on planar models (whose residuals can cost more than the
    /// factorisation they would save). Measured in docs/symplectic.md, "Large mechanisms".
    #[default]
    Auto,
    /// Always kept while Newton contracts.
    Always,
    /// A new Jacobian at the predictor of every step.
    Never,
}

impl JacobianReuse {
    /// Whether a step on the given stage path (`sparse`) starts from the kept factorisation
    /// (`planar_modified`: the modified Lagrangian on a model without spatial bodies).
    pub(crate) fn keeps(self, sparse: bool, planar_modified: bool) -> bool {
        match self {
            JacobianReuse::Auto => sparse && !planar_modified,
            JacobianReuse::Always => true,
            JacobianReuse::Never => false,
        }
    }
}
