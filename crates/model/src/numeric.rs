//! The max-norms of [`mbd_linalg`], kept at their old path for crates that use the model alone.
//!
//! Every crate that measures a residual (`mbd-solve`'s Newton, the solvers' stopping rules,
//! `mbd-analysis`' error measures, this crate's consistent initial conditions) uses
//! [`max_abs`], so a NaN anywhere in a residual is seen everywhere. It lives in `mbd-linalg`,
//! below the model; `mbd-solve` re-exports it as `mbd_solve::linalg::max_abs`.
//!
//! ```
//! use mbd_model::numeric::{max_abs, max_abs_diff};
//! assert!(max_abs(&[f64::NAN, 1e-20]).is_nan());
//! assert_eq!(max_abs_diff(&[1.0, 2.0], &[1.5, 0.0]), 2.0);
//! ```

pub use mbd_linalg::{max_abs, max_abs_diff};
