//! # mbd-tools
//!
//! Developer tools of `mbd`, kept out of the published crates' examples: profiling programs
//! (`src/bin/`, e.g. `cargo run --release -p mbd-tools --bin bench_rk4_steps -- 100000 run`,
//! meant for callgrind or perf) and the cross-solver criterion bench `benches/scaling.rs`
//! (`cargo bench -p mbd-tools --bench scaling`: one step of every solver meant to scale on
//! N-link chains, N = 10 to 1000). The same comparison, as ratios to plain RK4 with verdicts,
//! is `cargo xtask reproduce own --only own-scaling`.
//!
//! The library part only shares the solver list of the bench and the binaries.
//!
//! ```
//! let sys = mbd::model::models::n_link_chain(3)?;
//! for (name, make) in mbd_tools::scaling_solvers() {
//!     let integ = make(&sys)?;
//!     assert!(!integ.name().is_empty(), "{name}");
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

use mbd::model::System;
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{Integrator, SolveError};
use mbd::symplectic::{Galerkin, SymplecticOptions};
use mbd::tangent::TangentRk;

/// A solver constructor.
pub type MakeSolver = fn(&System) -> Result<Box<dyn Integrator>, SolveError>;

/// The solvers meant to scale to large mechanisms, with their display names.
pub fn scaling_solvers() -> Vec<(&'static str, MakeSolver)> {
    vec![
        ("RK4 plain", |s| {
            Ok(Box::new(Rk4::new(s, Rk4Options::plain())?))
        }),
        ("RK4 projected", |s| {
            Ok(Box::new(Rk4::new(s, Rk4Options::projected())?))
        }),
        ("symplectic (1,1)", |s| {
            Ok(Box::new(Galerkin::new(s, SymplecticOptions::new(1))?))
        }),
        ("symplectic (2,2)", |s| {
            Ok(Box::new(Galerkin::new(s, SymplecticOptions::new(2))?))
        }),
        ("tangent RK4", |s| Ok(Box::new(TangentRk::rk4(s)?))),
    ]
}
