//! The error of the adaptive driver (fixed steps return [`SolveError`] through the
//! [`mbd_solve::Integrator`] trait).

use mbd_solve::SolveError;
use thiserror::Error;

/// What can go wrong in [`crate::TangentRk::integrate_adaptive`].
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TangentError {
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
    /// Any other failure: bad input, a singular configuration, model errors, and the run
    /// loop's [`SolveError::StepSizeTooSmall`] and [`SolveError::TooManyAttempts`].
    #[error(transparent)]
    Solve(#[from] SolveError),
}
