//! The errors of the factorisations: [`FactorError`] and [`LuError`], what one factorisation
//! reports (small and `Copy`, matched on by the callers that turn a failed pivot into a joint
//! name), and [`LinalgError`], every failure of the crate in one type.

/// Why a factorisation failed.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum FactorError {
    /// A pivot of the LU factorisation is zero or negligible (index of the pivot).
    #[error("singular matrix: pivot {0} is zero or negligible")]
    Singular(usize),
    /// The matrix is not (numerically) positive definite (index of the failing pivot).
    #[error("matrix not positive definite: pivot {0} is negligible against its diagonal entry")]
    NotPositiveDefinite(usize),
}

/// Why an LU factorisation failed, in the caller's numbering of rows (equations) and columns
/// (unknowns).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LuError {
    /// No usable pivot for unknown `col`; `row` is the equation the elimination paired with it
    /// (or could not pair).
    #[error("singular matrix: no pivot for column {col} (row {row})")]
    Singular {
        /// The caller's row.
        row: usize,
        /// The caller's column (unknown).
        col: usize,
    },
    /// Entry `(row, col)` is NaN or infinite.
    #[error("non-finite matrix entry ({row}, {col})")]
    NonFinite {
        /// The caller's row.
        row: usize,
        /// The caller's column.
        col: usize,
    },
}

/// Everything that can fail in this crate: setting up a factorisation (a pattern entry out of
/// range, a failed symbolic analysis, an allocation) and the factorisation itself (converted
/// from [`FactorError`] and [`LuError`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LinalgError {
    /// The matrix is not (numerically) positive definite.
    #[error(
        "matrix not positive definite: pivot {pivot} is negligible against its diagonal entry"
    )]
    NotPositiveDefinite {
        /// Index of the failing pivot.
        pivot: usize,
    },
    /// A pivot is zero or negligible.
    #[error("singular matrix: pivot {pivot} is zero or negligible")]
    Singular {
        /// Index of the pivot.
        pivot: usize,
    },
    /// No usable pivot for an unknown of an LU factorisation.
    #[error("singular matrix: no pivot for column {col} (row {row})")]
    SingularColumn {
        /// The equation the elimination paired with the unknown (or could not pair).
        row: usize,
        /// The unknown.
        col: usize,
    },
    /// A matrix entry is NaN or infinite.
    #[error("non-finite matrix entry ({row}, {col})")]
    NonFinite {
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
    },
    /// An entry of a sparsity pattern lies outside the matrix.
    #[error("{what}: index {index} out of range for dimension {dim}")]
    PatternEntry {
        /// Which pattern (e.g. "sparse Cholesky pattern entry").
        what: &'static str,
        /// The dimension of the matrix.
        dim: usize,
        /// The larger index of the entry.
        index: usize,
    },
    /// The symbolic analysis of a sparse pattern failed (the message names the factorisation
    /// and the reason).
    #[error("{0}")]
    Analysis(String),
    /// The storage of a factorisation could not be allocated.
    #[error("cannot allocate the storage of a {rows} x {cols} matrix")]
    Allocation {
        /// Rows of the matrix.
        rows: usize,
        /// Columns of the matrix.
        cols: usize,
    },
}

impl From<FactorError> for LinalgError {
    fn from(e: FactorError) -> Self {
        match e {
            FactorError::Singular(pivot) => LinalgError::Singular { pivot },
            FactorError::NotPositiveDefinite(pivot) => LinalgError::NotPositiveDefinite { pivot },
        }
    }
}

impl From<LuError> for LinalgError {
    fn from(e: LuError) -> Self {
        match e {
            LuError::Singular { row, col } => LinalgError::SingularColumn { row, col },
            LuError::NonFinite { row, col } => LinalgError::NonFinite { row, col },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions_keep_the_index_and_the_message() {
        for (f, l) in [
            (FactorError::Singular(3), LinalgError::Singular { pivot: 3 }),
            (
                FactorError::NotPositiveDefinite(2),
                LinalgError::NotPositiveDefinite { pivot: 2 },
            ),
        ] {
            assert_eq!(f.to_string(), l.to_string());
            assert_eq!(LinalgError::from(f), l);
        }
        for (f, l) in [
            (
                LuError::Singular { row: 1, col: 4 },
                LinalgError::SingularColumn { row: 1, col: 4 },
            ),
            (
                LuError::NonFinite { row: 0, col: 2 },
                LinalgError::NonFinite { row: 0, col: 2 },
            ),
        ] {
            assert_eq!(f.to_string(), l.to_string());
            assert_eq!(LinalgError::from(f), l);
        }
        let e = LinalgError::Allocation { rows: 7, cols: 7 };
        assert_eq!(
            e.to_string(),
            "cannot allocate the storage of a 7 x 7 matrix"
        );
    }
}
