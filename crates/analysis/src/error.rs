//! The one error type of `mbd-analysis`.
use thiserror::Error;

/// What can go wrong in an analysis.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum AnalysisError {
    /// Inputs have inconsistent lengths.
    #[error("{what}: expected length {expected}, got {got}")]
    Dimension {
        /// Which input.
        what: &'static str,
        /// Required length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// Not enough data.
    #[error("{what}: need at least {need} points, got {got}")]
    TooFewPoints {
        /// Which input.
        what: &'static str,
        /// Minimum.
        need: usize,
        /// Given.
        got: usize,
    },
    /// A value is NaN or infinite, or not positive where it must be.
    #[error("{what} = {value} is invalid: {reason}")]
    InvalidValue {
        /// Which value.
        what: &'static str,
        /// The value.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// A time outside the reference's range.
    #[error("time {t} is outside the reference's range [{t0}, {t1}]")]
    OutOfRange {
        /// Requested time.
        t: f64,
        /// Reference start.
        t0: f64,
        /// Reference end.
        t1: f64,
    },
    /// Reading or writing failed.
    #[error("io error on {path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// The message.
        message: String,
    },
    /// A solver error while evaluating accelerations.
    #[error(transparent)]
    Solve(#[from] mbd_solve::SolveError),
}
