//! The crate's single error type.

use thiserror::Error;

/// Everything that can go wrong when configuring or starting a firefly run.
///
/// All user input is validated before the first objective evaluation; a run
/// that has started never fails (non-finite objective values are absorbed and
/// counted, see [`FireflyResult::nan_evaluations`](crate::FireflyResult::nan_evaluations)).
/// Every message names the parameter or the dimension at fault.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum FireflyError {
    /// The search box has no dimension (`d = 0`).
    #[error("empty search box: the bounds have dimension 0, at least one dimension is required")]
    EmptyBounds,

    /// `lo` and `hi` have different lengths.
    #[error("bounds length mismatch: lo has {lo} entries but hi has {hi}")]
    BoundsLengthMismatch {
        /// Length of the lower-bound vector.
        lo: usize,
        /// Length of the upper-bound vector.
        hi: usize,
    },

    /// A bound is NaN or infinite.
    #[error("non-finite bound in dimension {dim}: lo = {lo}, hi = {hi} (bounds must be finite)")]
    NonFiniteBound {
        /// Zero-based dimension index.
        dim: usize,
        /// Lower bound given for that dimension.
        lo: f64,
        /// Upper bound given for that dimension.
        hi: f64,
    },

    /// `lo > hi` in some dimension (`lo == hi` is allowed and fixes the coordinate).
    #[error("inverted bound in dimension {dim}: lo = {lo} > hi = {hi}")]
    InvertedBound {
        /// Zero-based dimension index.
        dim: usize,
        /// Lower bound given for that dimension.
        lo: f64,
        /// Upper bound given for that dimension.
        hi: f64,
    },

    /// A centre/half-width pair has a negative or non-finite half width.
    #[error("invalid half width in dimension {dim}: {half_width} (must be finite and >= 0)")]
    InvalidHalfWidth {
        /// Zero-based dimension index.
        dim: usize,
        /// The offending half width.
        half_width: f64,
    },

    /// The population size is zero.
    #[error("population must be at least 1, got 0")]
    ZeroPopulation,

    /// A numeric parameter is outside its meaningful range.
    #[error("invalid parameter `{name}` = {value}: must be {requirement}")]
    InvalidParameter {
        /// Name of the parameter (the settings field or termination criterion).
        name: &'static str,
        /// The value given.
        value: f64,
        /// Human readable description of the valid range.
        requirement: &'static str,
    },

    /// More initial positions than fireflies.
    #[error("too many initial positions: {given} given for a population of {population}")]
    TooManyInitialPositions {
        /// Number of initial positions supplied.
        given: usize,
        /// Population size.
        population: usize,
    },

    /// An initial position has the wrong number of coordinates.
    #[error(
        "initial position {index} has dimension {found}, but the search box has dimension {expected}"
    )]
    InitialPositionDimension {
        /// Index of the initial position in the supplied list.
        index: usize,
        /// Dimension of the search box.
        expected: usize,
        /// Dimension of the supplied position.
        found: usize,
    },

    /// An initial position lies outside the box (or is NaN / infinite).
    #[error(
        "initial position {index} is outside the box in dimension {dim}: {value} not in [{lo}, {hi}]"
    )]
    InitialPositionOutOfBounds {
        /// Index of the initial position in the supplied list.
        index: usize,
        /// Zero-based dimension index.
        dim: usize,
        /// The offending coordinate.
        value: f64,
        /// Lower bound of that dimension.
        lo: f64,
        /// Upper bound of that dimension.
        hi: f64,
    },

    /// The objective reports a dimension different from the search box.
    #[error("objective dimension {objective} does not match the search box dimension {bounds}")]
    ObjectiveDimension {
        /// Dimension reported by [`Objective::dim`](crate::Objective::dim).
        objective: usize,
        /// Dimension of the search box.
        bounds: usize,
    },

    /// Neither a generation limit nor an evaluation budget is set, so the run
    /// might never end.
    #[error("unbounded run: set termination max_generations or max_evaluations (or both)")]
    Unbounded,
}
