//! Options and work counters of [`TangentRk`](super::TangentRk).

use crate::chart::NewtonSettings;
use mbd_solve::{LinearSolver, SolveError};

/// The matrix of the chord Newton iteration of the chart maps (the limit, the point of the
/// chart, is the same for both; only the speed differs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum IterationMatrix {
    /// `Df(x_c) Q1 = R^T`, factored once per chart: the paper's chord iteration (the
    /// default). Contraction factor `O(h)` per iteration; each iteration costs one residual
    /// evaluation and one `2n x 2m` product.
    #[default]
    Centre,
    /// `Df Q1` interpolated linearly between the centre and the Euler prediction of the end
    /// point, `x_c + h F(x_c)`: one more evaluation of `Df` per step, and each iteration applies
    /// a `2m x 2m` correction on top. Contraction factor `O(h^2)`: about half the iterations of
    /// [`IterationMatrix::Centre`], and a larger domain of convergence for large steps; per
    /// step it is slower on the small mechanisms of the papers (see `docs/tangent.md`).
    Interpolated,
    /// Starts each chart from the centre's `R^-T` and improves the iteration's inverse matrix
    /// by good Broyden rank-one updates after every correction, carried from one map of the
    /// step to the next (carried from map to map): superlinear convergence for `O(n m)`
    /// more work per iteration, no extra `Df`. On the manipulator it saves a third of the
    /// iterations at `h = 0.01` but costs more per step than the centre chord (the residual is
    /// cheap there; `docs/tangent.md`), so it is not the default.
    Broyden,
}

/// The metric of the state space `x = (q, v)` in which the chart's tangent and normal
/// directions are orthogonal (`docs/tangent.md`, "The chart's metric"). The chart's manifold and
/// the constraints kept are the same for both; the tangent coordinates the Runge-Kutta method
/// integrates differ, and with them the error constant.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[non_exhaustive]
pub enum ChartMetric {
    /// `|dq|^2 + h^2 |dv|^2` for a step of size `h` (the default): a velocity change counts
    /// as the displacement it makes over one step, so the metric does not depend on the
    /// model's unit of time, and the velocity constraints' curvature `(Phi_q v)_q`, which grows
    /// with the speed, is weighted by `h`. The chart is built for the first attempt's `h` at
    /// each centre.
    #[default]
    StepWeighted,
    /// `|dq|^2 + |dv|^2` in the model's units: paper B's chart as published. Its error
    /// constant depends on the unit of time, and on fast motion (a whipping chain of slender
    /// rods) it is hundreds of times larger than [`ChartMetric::StepWeighted`]'s.
    Euclidean,
}

impl ChartMetric {
    /// The velocity weight `tau` of the metric `|dq|^2 + tau^2 |dv|^2` for a step `h`.
    pub fn velocity_weight(self, h: f64) -> f64 {
        match self {
            ChartMetric::StepWeighted => h.abs(),
            ChartMetric::Euclidean => 1.0,
        }
    }
}

/// Settings of [`TangentRk`](crate::TangentRk).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentOptions {
    /// The chord Newton iteration of the chart map (tolerance 1e-13 on `||(Phi, Phidot)||_inf`
    /// by default).
    pub newton: NewtonSettings,
    /// The chord iteration's matrix (default [`IterationMatrix::Centre`]).
    pub iteration_matrix: IterationMatrix,
    /// Automatic step halving on chart failure in fixed-step mode: a step whose chart map fails
    /// is redone as two half steps (each re-centring the chart), recursively up to this depth
    /// (so at most `2^max_halvings` sub-steps). Every halving is counted in
    /// [`TangentStats::halvings`]. 0 turns it off: a chart failure is then an error at once.
    /// Default 4. At most 30.
    pub max_halvings: u32,
    /// Relative threshold on the diagonal of `R` (QR of `Df^T`) below which the configuration
    /// counts as singular (an error). Default 1e-8.
    pub singular_tol: f64,
    /// Largest `||(Phi, Phidot)||_inf` accepted for the state handed to a step (it is projected
    /// onto the manifold by the first chart map). Larger is an error: project the state first
    /// (`mbd_solve::project_state`). Default 1e-8.
    pub consistency_tol: f64,
    /// Inexact stage maps: after an accepted step of the same size, the chart maps of the
    /// interior Runge-Kutta stages stop at `max(newton.tol, stage_tol_ratio * E)`, where `E` is
    /// the constraint residual `||f||_inf` of the previous step's plain RK end point
    /// `x_c + h sum_j b_j F_j` (the end map's starting point: the method's local error in the
    /// normal directions, `O(h^(p+1))`). A stage point off the manifold by `delta` changes the
    /// step by about `h L delta`, so the ratio keeps that a small fraction of the local error
    /// the method makes anyway; the step's end point is always mapped to `newton.tol`. 0 maps
    /// every stage to `newton.tol`. Not used for FSAL tableaus (their last stage is the end
    /// point). Default 1e-2; must lie in [0, 1).
    pub stage_tol_ratio: f64,
    /// Which chart: [`LinearSolver::Dense`] the QR chart with an orthonormal tangent basis
    /// (`O(n^3)` per step), [`LinearSolver::Sparse`] the chart in
    /// redundant tangent coordinates on the sparse Cholesky factorisation of `Df Df^T`
    /// (`O(n)` per step for chains; centre iteration matrix only, no
    /// exact-Newton fallback), [`LinearSolver::Auto`] (default) dense up to
    /// [`mbd_solve::SPARSE_THRESHOLD`] constraint equations, sparse above. Both give the same
    /// trajectory up to rounding (`docs/tangent.md` section 9).
    pub linear_solver: LinearSolver,
    /// Adaptive steps: the factor applied to the step after an attempt whose chart map did not
    /// converge, or whose index-1 solve at a stage point was singular (the error controller's
    /// memory is left alone). Default 0.25; must lie in (0, 1).
    pub chart_shrink: f64,
    /// Adaptive steps: most such failures in a row at one point before
    /// [`SolveError::RepeatedFailure`]. Default 8 (the step shrinks by `chart_shrink^8`,
    /// 1.5e-5 by default); at least 1.
    pub max_chart_failures: usize,
    /// Bridge the stage accelerations through singular configurations
    /// ([`mbd_solve::SingularBridge`]; default on). Off, a stage near a singular
    /// configuration takes the index-1 solve's accelerations as they are.
    pub bridge: bool,
    /// The chart's metric (default [`ChartMetric::StepWeighted`]).
    pub metric: ChartMetric,
}

impl Default for TangentOptions {
    fn default() -> Self {
        TangentOptions {
            newton: NewtonSettings::default(),
            iteration_matrix: IterationMatrix::default(),
            max_halvings: 4,
            singular_tol: 1e-8,
            consistency_tol: 1e-8,
            stage_tol_ratio: 1e-2,
            linear_solver: LinearSolver::Auto,
            chart_shrink: 0.25,
            max_chart_failures: 8,
            bridge: true,
            metric: ChartMetric::StepWeighted,
        }
    }
}

impl TangentOptions {
    /// Checks every setting.
    pub fn validate(&self) -> Result<(), SolveError> {
        self.newton.validate()?;
        if self.max_halvings > 30 {
            return Err(SolveError::InvalidParameter {
                parameter: "max_halvings",
                value: self.max_halvings as f64,
                reason: "must be at most 30",
            });
        }
        if !(self.singular_tol.is_finite() && self.singular_tol > 0.0 && self.singular_tol < 1.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "singular_tol",
                value: self.singular_tol,
                reason: "must lie in (0, 1)",
            });
        }
        if !(self.consistency_tol.is_finite() && self.consistency_tol >= self.newton.tol) {
            return Err(SolveError::InvalidParameter {
                parameter: "consistency_tol",
                value: self.consistency_tol,
                reason: "must be finite and at least newton.tol",
            });
        }
        if !(self.stage_tol_ratio >= 0.0 && self.stage_tol_ratio < 1.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "stage_tol_ratio",
                value: self.stage_tol_ratio,
                reason: "must lie in [0, 1)",
            });
        }
        if !(self.chart_shrink > 0.0 && self.chart_shrink < 1.0) {
            return Err(SolveError::InvalidParameter {
                parameter: "chart_shrink",
                value: self.chart_shrink,
                reason: "must lie in (0, 1)",
            });
        }
        if self.max_chart_failures == 0 {
            return Err(SolveError::InvalidParameter {
                parameter: "max_chart_failures",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        Ok(())
    }
}

/// Work counters of a [`TangentRk`](crate::TangentRk), cumulative since construction or the last
/// [`mbd_solve::Integrator::reset`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TangentStats {
    /// Accepted steps (sub-steps of halved steps count one each).
    pub steps: usize,
    /// Chart centrings (QR factorisations of `Df^T`).
    pub charts: usize,
    /// Fixed-step mode: steps redone as two halves after a chart failure.
    pub halvings: usize,
    /// Chart failures met (recovered by halving or rejection, or returned as errors).
    pub chart_failures: usize,
    /// Chord Newton iterations of the accepted steps (all their maps).
    pub newton_iterations: usize,
    /// Most chord Newton iterations of one map of an accepted step.
    pub max_map_iterations: usize,
    /// Acceleration solves (right-hand-side evaluations) of the accepted steps.
    pub rhs_evals: usize,
    /// Largest `||(Phi, Phidot)||_inf` of an accepted step's end point.
    pub max_residual: f64,
    /// Chart maps of the accepted steps completed by the exact Newton fallback after the chord
    /// iteration failed ([`NewtonSettings::fallback_change`]: near-singular charts).
    pub exact_maps: usize,
    /// Steps from a singular configuration, where no chart can be centred, taken by projected
    /// RK of the same tableau on the index-1 form (counted in `steps` too).
    pub starter_steps: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The defaults the field docs state, and the metric's weights.
    #[test]
    fn the_documented_defaults() {
        let o = TangentOptions::default();
        assert_eq!(o.iteration_matrix, IterationMatrix::Centre);
        assert_eq!(o.max_halvings, 4);
        assert_eq!((o.singular_tol, o.consistency_tol), (1e-8, 1e-8));
        assert_eq!(o.stage_tol_ratio, 1e-2);
        assert_eq!(o.linear_solver, LinearSolver::Auto);
        assert_eq!((o.chart_shrink, o.max_chart_failures), (0.25, 8));
        assert!(o.bridge);
        assert_eq!(o.metric, ChartMetric::StepWeighted);
        assert_eq!(ChartMetric::StepWeighted.velocity_weight(-2e-3), 2e-3);
        assert_eq!(ChartMetric::Euclidean.velocity_weight(2e-3), 1.0);
        assert!(o.validate().is_ok());
    }
}
