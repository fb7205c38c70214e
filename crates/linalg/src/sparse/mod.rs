//! Factorisations on a fixed sparsity pattern (faer, simplicial), analysed once and refactored
//! into preallocated storage:
//!
//! * [`SparseCholesky`]: a symmetric positive definite matrix, with the same scale-invariant
//!   pivot test and condition estimate as the dense [`crate::DenseCholesky`];
//! * [`SparseLu`]: a general square matrix, with a scale-invariant pivot test by power-of-two
//!   equilibration.

mod cholesky;
mod lu;
mod lu_factors;

pub use cholesky::SparseCholesky;
pub use lu::{ColumnOrder, SparseLu, REFACTOR_PIVOT_RATIO, SPARSE_PIVOT_TOL};
