//! The error of the adaptive driver (fixed steps return [`SolveError`] through the
//! [`mbd_solve::Integrator`] trait).

use mbd_solve::SolveError;
use thiserror::Error;

/// What can go wrong in [`crate::TangentRk::integrate_adaptive`].
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TangentError {
    /// The error controller asked for a step below `controller.h_min`.
    #[error("adaptive step size h = {h:e} at t = {t} fell below h_min = {h_min:e}")]
    StepSizeTooSmall {
        /// Time of the step.
        t: f64,
        /// The step size asked for.
        h: f64,
        /// The smallest step allowed.
        h_min: f64,
    },
    /// The chart map (or a stage point's index-1 solve) kept failing while the step shrank:
    /// `failures` times in a row at one point, or down to `h_min`.
    #[error("tangent chart failed {failures} times in a row (last step h = {h:e}): {source}")]
    Chart {
        /// The last failure: [`SolveError::Newton`] (time, residual, iterations) for a chart
        /// map, [`SolveError::Singular`] for a stage point's index-1 solve.
        source: SolveError,
        /// The last step size tried.
        h: f64,
        /// Failures in a row at that point.
        failures: usize,
    },
    /// More than `max_steps` step attempts.
    #[error("more than {max_steps} step attempts before reaching the end time (at t = {t})")]
    TooManySteps {
        /// Time reached.
        t: f64,
        /// The limit.
        max_steps: usize,
    },
    /// Any other failure (bad input, singular configuration, model errors).
    #[error(transparent)]
    Solve(#[from] SolveError),
}
