//! The error type of the crate's functions beyond the [`mbd_solve::Integrator`] interface.

use mbd_solve::SolveError;
use thiserror::Error;

/// Errors of the calibration and of the error measures (integration errors are wrapped).
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum SymplecticError {
    /// An error of the integrator or the model.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The secant iteration for `gamma_opt` failed.
    #[error("gamma calibration failed after {iterations} secant iterations at gamma = {gamma}: {reason} (dW history: {history:?})")]
    Calibration {
        /// Secant iterations done.
        iterations: usize,
        /// The last gamma tried.
        gamma: f64,
        /// Why it stopped.
        reason: String,
        /// `(gamma, dW)` pairs evaluated so far.
        history: Vec<(f64, f64)>,
    },
}
