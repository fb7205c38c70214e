//! The one error type of `mbd-solve` (and the error solver crates return).

use mbd_linalg::LinalgError;
use mbd_model::{format_number as num, ModelError};
use thiserror::Error;

/// Everything that can go wrong while integrating.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum SolveError {
    /// The step size is not positive and finite.
    #[error("step size h = {} is invalid: it must be positive and finite", num(*h))]
    InvalidStep {
        /// The step size given.
        h: f64,
    },
    /// A fixed-step run would take more steps than the library runs
    /// ([`crate::MAX_FIXED_STEPS`]).
    #[error(
        "the run needs {} steps of h = {} over {} s, more than the {} a run may take: take a \
         larger step or a shorter run",
        num(*steps),
        num(*h),
        num(*span),
        num(crate::MAX_FIXED_STEPS)
    )]
    TooManySteps {
        /// Steps the interval needs.
        steps: f64,
        /// The step size.
        h: f64,
        /// The interval's length, s.
        span: f64,
    },
    /// The time interval is empty, reversed or not finite.
    #[error("time interval [{}, {}] is invalid: {reason}", num(*t0), num(*t_end))]
    InvalidInterval {
        /// Start.
        t0: f64,
        /// End.
        t_end: f64,
        /// What is wrong.
        reason: &'static str,
    },
    /// A setting is out of range.
    #[error("parameter '{parameter}' = {} is invalid: {reason}", num(*value))]
    InvalidParameter {
        /// The setting.
        parameter: &'static str,
        /// Its value.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// The adaptive step-size controller asked for a step below its smallest allowed step.
    #[error(
        "adaptive step size h = {h:e} at t = {t} fell below h_min = {h_min:e}: the error test \
         keeps failing there (a singularity, stiffness, or a tolerance below round-off); \
         loosen the tolerance (or, through the library, lower StepController::h_min)"
    )]
    StepSizeTooSmall {
        /// Time of the step.
        t: f64,
        /// The step size asked for.
        h: f64,
        /// The smallest step allowed.
        h_min: f64,
    },
    /// An adaptive run used up its budget of step attempts (accepted plus rejected).
    #[error(
        "adaptive run stopped at t = {t} after {attempts} step attempts (accepted plus \
         rejected) without reaching the end time: raise AdaptiveConfig::max_steps or loosen \
         the tolerance"
    )]
    TooManyAttempts {
        /// Time reached.
        t: f64,
        /// Attempts made (the limit).
        attempts: usize,
    },
    /// Adaptive step attempts kept failing for a reason other than the error test (a chart map
    /// that did not converge, a singular index-1 solve at a stage point) while the step shrank:
    /// `failures` times in a row at one point, or down to the controller's `h_min`.
    #[error(
        "step attempts from t = {t} failed {failures} times in a row (last step h = {h:e}): \
         {source}"
    )]
    RepeatedFailure {
        /// Time of the point the attempts started from.
        t: f64,
        /// The last step size tried.
        h: f64,
        /// Failures in a row at that point.
        failures: usize,
        /// The last failure.
        source: Box<SolveError>,
    },
    /// A solver spec string names no registered solver.
    #[error("unknown solver '{spec}'; use one of: {known}")]
    UnknownSolver {
        /// The spec as given.
        spec: String,
        /// The registered syntaxes.
        known: String,
    },
    /// A solver spec string names a registered solver with options it refuses.
    #[error("solver '{spec}': {reason}")]
    SolverSpec {
        /// The spec as given.
        spec: String,
        /// What is wrong, with an example of what works.
        reason: String,
    },
    /// Newton's method did not converge.
    #[error(
        "Newton failed at t = {t}: residual {residual:e} after {iterations} iterations ({context})"
    )]
    Newton {
        /// Time of the step (its start).
        t: f64,
        /// Max-norm residual when it stopped.
        residual: f64,
        /// Iterations done.
        iterations: usize,
        /// Which solve (e.g. "symplectic stage equations").
        context: String,
    },
    /// A matrix that must be invertible is (numerically) singular.
    #[error("singular {what} at t = {t} (equation/pivot: {detail})")]
    Singular {
        /// Time.
        t: f64,
        /// Which matrix.
        what: &'static str,
        /// The equation or pivot at fault.
        detail: String,
    },
    /// The initial state's inputs (values marked to be kept, [`mbd_model::Inputs`]) leave a
    /// constraint equation no free coordinate (or velocity) to satisfy it.
    #[error(
        "the initial {level} inputs ({inputs}) leave equation {equation} no free {level} to \
         satisfy it: mark fewer inputs, or give values that satisfy it"
    )]
    OverdeterminedInputs {
        /// "position" or "velocity".
        level: &'static str,
        /// The inputs, as coordinate names (`crank.theta`, `d_crank.theta`).
        inputs: String,
        /// The equation (`joint.label`).
        equation: String,
    },
    /// A vector has the wrong length for the system.
    #[error("{what}: expected length {expected}, got {got}")]
    Dimension {
        /// Which vector.
        what: &'static str,
        /// Required length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// The constraints drifted beyond the run's drift guard (`RunConfig::drift_guard`,
    /// `AdaptiveConfig::drift_guard`; `mbd run --drift-tol`, `--no-drift-guard`). A residual
    /// beyond `BLOWUP_RATIO` (100) times the tolerance is reported as a blow-up: the solution
    /// left the constraints by more than the mechanism's size within a few steps, the growth of
    /// a step beyond the solver's stability (stiff springs or dampers, light parts, with an
    /// explicit solver), which only a smaller step (or an implicit solver) cures. (Drift that
    /// grew from a near-singular step is [`SolveError::Singular`] instead.)
    #[error(
        "constraint drift at t = {t}: {level} residual of {equation} is {residual:e}, beyond \
         the drift guard's {tolerance:e}; {}",
        if *residual > crate::guard::BLOWUP_RATIO * *tolerance {
            "the solution blew up within a few steps (more than 100 times the tolerance), a \
             step beyond this solver's stability on the model's fastest motion (stiff springs \
             or dampers, light parts): take a smaller step, an adaptive run or an implicit \
             solver"
        } else {
            "the solver has left the constraint manifold: take a smaller step, use a solver \
             that keeps the constraints (projection, symplectic, tangent), or relax the drift \
             guard"
        }
    )]
    ConstraintDrift {
        /// Time at the end of the step.
        t: f64,
        /// `"position"` (`Phi`) or `"velocity"` (`Phi_q v + Phi_t`).
        level: &'static str,
        /// The equation with the largest residual relative to its tolerance, e.g. `"pin2.x"`.
        equation: String,
        /// The element the equation belongs to ([`mbd_model::System::equation_element`]): its
        /// joint, or the spatial body of an internal (director) constraint.
        joint: String,
        /// Its residual.
        residual: f64,
        /// Its tolerance.
        tolerance: f64,
    },
    /// A spatial body's directors are (nearly) dependent at a state or a stage point: on the
    /// constraints they are orthonormal, so the coordinates there are far off them (a step too
    /// long for the motion, or drift of a solver that does not keep the constraints). Not a
    /// singular configuration of the mechanism.
    #[error(
        "the directors of spatial body '{body}' are (nearly) dependent at t = {t}: a state or a \
         stage point of the step is far off the constraints, on which they are orthonormal (the \
         step is too long for the motion, or the solver lets the constraints drift)"
    )]
    DegenerateDirectors {
        /// Time of the step (its start).
        t: f64,
        /// The body.
        body: String,
    },
    /// The state became NaN or infinite.
    #[error("non-finite {what} at t = {t}")]
    NonFinite {
        /// Time.
        t: f64,
        /// Which quantity.
        what: &'static str,
    },
    /// The model does not support what the solver needs.
    #[error("unsupported model: {0}")]
    Unsupported(String),
    /// An observer asked to abort with an error.
    #[error("observer error at t = {t}: {message}")]
    Observer {
        /// Time.
        t: f64,
        /// Its message.
        message: String,
    },
    /// An error from the model.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A factorisation failed, or its workspace could not be set up, where no time or
    /// equation is known to name (see [`SolveError::from`]).
    #[error("linear algebra: {0}")]
    LinearAlgebra(LinalgError),
}

/// The one conversion of the linear algebra's errors: a pattern entry out of range becomes
/// [`SolveError::Dimension`], a failed symbolic analysis [`SolveError::Unsupported`] (the
/// analysis refuses the model's structure), anything else [`SolveError::LinearAlgebra`]. The
/// solvers turn a failed factorisation at a time `t` into [`SolveError::Singular`] themselves,
/// with the equation at fault.
/// [`SolveError::Singular::what`] of a symplectic step whose Newton iteration failed on a step
/// that passes, or comes within a few steps of, a configuration within `1e-2` of rank loss
/// (not one that is singular to rounding at the step's start or end).
pub const STAGES_NEAR_RANK_LOSS: &str =
    "configuration (Phi_q near rank loss: the stage equations failed there)";

/// [`SolveError::Singular::what`] of a symplectic step whose Newton iteration stalled a few
/// digits above its tolerance where the step passes, or comes within a few steps of, a
/// configuration within `1e-2` of rank loss.
pub const STAGES_STALLED_NEAR_RANK_LOSS: &str = "configuration (the stage Jacobian near-singular)";

/// [`SolveError::Singular::what`] of a tangent chart map that failed at every halving at a
/// centre within `1e-2` of rank loss.
pub const CHART_NEAR_RANK_LOSS: &str =
    "configuration (Phi_q near rank loss: the chart's map failed there)";

impl SolveError {
    /// Whether this is the singular error of a Newton iteration that failed *near* a
    /// singular configuration ([`STAGES_NEAR_RANK_LOSS`], [`STAGES_STALLED_NEAR_RANK_LOSS`],
    /// [`CHART_NEAR_RANK_LOSS`]): the
    /// solver cannot pass the configuration at this step size, so a fixed-step run does not
    /// step over it (it does over a step that starts or ends *on* one, where a factorisation
    /// is singular to rounding; `docs/singular.md`, section 5).
    pub fn is_newton_near_rank_loss(&self) -> bool {
        matches!(self, SolveError::Singular { what, .. }
            if [STAGES_NEAR_RANK_LOSS, STAGES_STALLED_NEAR_RANK_LOSS, CHART_NEAR_RANK_LOSS]
                .contains(what))
    }
}

impl From<LinalgError> for SolveError {
    fn from(e: LinalgError) -> Self {
        match e {
            LinalgError::PatternEntry { what, dim, index } => SolveError::Dimension {
                what,
                expected: dim,
                got: index,
            },
            LinalgError::Analysis(reason) => SolveError::Unsupported(reason),
            e => SolveError::LinearAlgebra(e),
        }
    }
}

/// The refusal of a solver that cannot run a mechanism with redundant constraint equations
/// ([`mbd_model::System::redundant_equations`]): `Ok` for a mechanism without them, else
/// [`SolveError::Unsupported`] naming `solver` and the redundant equations with their joints.
pub fn refuse_redundant(sys: &mbd_model::System, solver: &str) -> Result<(), SolveError> {
    let red = sys.redundant_equations();
    if red.is_empty() {
        return Ok(());
    }
    let list: Vec<String> = red
        .iter()
        .map(|e| format!("{} (joints {})", e.equation, e.joints.join(", ")))
        .collect();
    Err(SolveError::Unsupported(format!(
        "{solver} does not run mechanisms with redundant constraint equations: {}",
        list.join("; ")
    )))
}

/// The refusal of a solver that does not run spatial bodies yet: `Ok` for a planar model,
/// else [`SolveError::Unsupported`] naming `solver` and the first spatial body (or point mass).
/// Every registered solver runs spatial models now; this is for a solver crate of one's own.
///
/// ```
/// use mbd_model::models::{heavy_top, pendulum};
/// let top = heavy_top([0.3, 0.3, 0.1], 0.3, 20.0)?;
/// let e = mbd_solve::refuse_spatial(&top, "my solver").unwrap_err().to_string();
/// assert!(e.contains("my solver") && e.contains("'top'"), "{e}");
/// assert!(mbd_solve::refuse_spatial(&pendulum(1.0, 1.0, 0.5, 9.81)?, "my solver").is_ok());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn refuse_spatial(sys: &mbd_model::System, solver: &str) -> Result<(), SolveError> {
    let first = sys
        .spatial_bodies()
        .first()
        .map(|b| b.name.as_str())
        .or_else(|| sys.spatial_point_masses().first().map(|p| p.name.as_str()));
    match first {
        None => Ok(()),
        Some(name) => Err(SolveError::Unsupported(format!(
            "{solver} does not run spatial bodies yet (body '{name}'); `mbd solvers` lists the \
             solvers that do"
        ))),
    }
}

/// The largest spatial model (constraint equations) the solvers without a spatial sparse path
/// (tangent, symplectic, FA-DAE) take on their dense path: above it their dense matrices
/// (`O(m n)` memory, `O(m^3)` work per step) would make a step take seconds to minutes.
pub const DENSE_SPATIAL_LIMIT: usize = 600;

/// The refusal of a solver whose sparse path does not take spatial bodies yet: `Ok` for a
/// planar model, or a spatial one of at most [`DENSE_SPATIAL_LIMIT`] equations on its dense
/// path; an error for a larger spatial model or an explicit `LinearSolver::Sparse`, naming
/// `solver`, the equation count and the solvers that run such models.
pub fn refuse_large_spatial(
    sys: &mbd_model::System,
    solver: &str,
    linear: crate::LinearSolver,
) -> Result<(), SolveError> {
    let m = sys.n_constraints();
    if !sys.has_spatial() {
        return Ok(());
    }
    if linear == crate::LinearSolver::Sparse {
        return Err(SolveError::Unsupported(format!(
            "{solver} has no sparse path for spatial bodies yet: use LinearSolver::Dense or \
             Auto (it takes spatial models of up to {DENSE_SPATIAL_LIMIT} equations densely), or \
             rk4, rk4-projected, index1:dopri5 or the tangent solvers, whose sparse path takes \
             them"
        )));
    }
    if m <= DENSE_SPATIAL_LIMIT {
        return Ok(());
    }
    Err(SolveError::Unsupported(format!(
        "{solver} takes spatial bodies on its dense path only, and this model has {m} \
         equations (more than {DENSE_SPATIAL_LIMIT}, where its dense matrices make a step \
         take seconds to minutes): run it with rk4, rk4-projected, index1:dopri5 or the tangent \
         solvers, whose sparse path takes spatial bodies in O(N)"
    )))
}
