//! The factorisations and small kernels of [`mbd_linalg`], re-exported so the solver crates
//! reach them through `mbd-solve` ([`DenseCholesky`], [`DenseLu`], the errors, [`max_abs`],
//! [`axpy`], ...), and the dense Schur complement of the constraint Jacobian that the index-1
//! solve and the projection factor (`local.rs`: it knows the [`mbd_model::System`]; `bodies.rs`
//! the solve of models with spatial bodies, their internal constraints eliminated body by
//! body).

pub use mbd_linalg::{
    axpy, dot, form_q_padded, max_abs, max_abs_diff, pow2_inverse, qr_padded, reflect, solve_rt,
    symmetric_eigen, Anderson, DenseCholesky, DenseLu, FactorError, LinalgError, LuError,
    CHOLESKY_PIVOT_TOL, FIXED_CHOLESKY, PIVOT_THRESHOLD, PIVOT_TOL, SMALL_CHOLESKY,
    SMALL_CHOLESKY_SOLVE,
};

mod bodies;
mod local;

pub(crate) use bodies::{BodyFactorError, BodySchur};
pub(crate) use local::DenseSchur;
