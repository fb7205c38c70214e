//! The sparse numerics kernel: what every solver uses above the dense threshold.
//!
//! * [`SparseCholesky`] (from [`mbd_linalg`]): a symmetric positive definite matrix on a fixed
//!   pattern, analysed once (fill-reducing ordering, elimination tree) and refactored into
//!   preallocated storage, with the same scale-invariant pivot test and condition estimate as
//!   the dense [`crate::linalg::DenseCholesky`];
//! * [`ConstraintSchur`]: the constraint Jacobian `Phi_q` in element-local form (each equation
//!   acts on at most two bodies) and the matrix `S = Phi_q W Phi_q^T` for a diagonal weight `W`
//!   (the index-1 solve and the projections use `W = M^-1`);
//! * [`BlockSchur`]: the same for bodies of any kind (rows over body blocks,
//!   [`BlockRows`]), every row kept (the spatial internal ones too);
//! * [`SparseLu`] (from [`mbd_linalg`]): a general square matrix on a fixed pattern (the symplectic stage
//!   equations), analysed once and refactored into reused storage, with a scale-invariant
//!   pivot test by power-of-two equilibration;
//! * [`SparseAccelerationSolver`]: the index-1 acceleration solve on top of both.
//!
//! For a chain of `N` bodies every one of them costs `O(N)` per call.

mod accel;
mod block_rows;
mod block_schur;
mod bodies;
mod schur;

pub(crate) use bodies::SparseBodySchur;

pub use accel::SparseAccelerationSolver;
pub use block_rows::{BlockRows, RowSide};
pub use block_schur::BlockSchur;
pub use mbd_linalg::{ColumnOrder, SparseCholesky, SparseLu, SPARSE_PIVOT_TOL};
pub use schur::{ConstraintSchur, RowIncidence};

/// Constraint count above which [`LinearSolver::Auto`] picks the sparse path (index-1 solve,
/// projection, and the solvers built on them). Below it the dense kernels are faster: for the
/// two-link manipulator (4 equations) a dense Cholesky is a few dozen flops.
pub const SPARSE_THRESHOLD: usize = 48;

/// Which factorisation the index-1 solve and the projection use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LinearSolver {
    /// Dense up to [`SPARSE_THRESHOLD`] constraints, sparse above.
    #[default]
    Auto,
    /// Dense Schur complement with Cholesky ([`crate::AccelerationSolver`]).
    Dense,
    /// Sparse Schur complement with sparse Cholesky ([`SparseAccelerationSolver`]).
    Sparse,
}

impl LinearSolver {
    /// Whether a system with `m` constraint equations takes the sparse path.
    pub fn use_sparse(self, m: usize) -> bool {
        match self {
            LinearSolver::Dense => false,
            LinearSolver::Sparse => true,
            LinearSolver::Auto => m > SPARSE_THRESHOLD,
        }
    }
}
