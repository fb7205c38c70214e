//! # mbd
//!
//! Planar rigid multibody systems as differential-algebraic equations, with the solvers of three
//! papers and the analysis that measures them. This facade re-exports the workspace's crates;
//! depend on a single crate (e.g. `mbd-model` + `mbd-rk4`) if you need only part of it.
//!
//! | crate | what |
//! |---|---|
//! | [`model`] | bodies, joints, forces, `System` (Phi, Phi_q, gamma, Hessians, energy), model files |
//! | [`solve`] | the `Integrator` trait, run loop, observers, Newton, index-1 solve, tableaus |
//! | [`rk4`] | RK4 baseline (optional Baumgarte / projection) |
//! | [`symplectic`] | paper A: (s,s) constrained Galerkin variational integrator, preadjusted gamma |
//! | [`tangent`] | paper B: tangent-space parameterisation with any explicit RK tableau |
//! | [`firefly`] | the firefly metaheuristic, generic over any objective |
//! | [`firefly_gauss`] | paper C: the firefly-Gauss DAE solver |
//! | [`analysis`] | energy/constraint errors, trajectory errors, convergence orders, CSV/JSON |
//!
//! ```
//! use mbd::analysis::MeasureObserver;
//! use mbd::model::models;
//! use mbd::rk4::{Rk4, Rk4Options};
//! use mbd::solve::{run, RunConfig, State};
//!
//! let sys = models::manipulator()?;
//! let mut state = State::consistent(&sys, 0.0)?;
//! let mut rk4 = Rk4::new(&sys, Rk4Options::plain())?;
//! let mut obs = MeasureObserver::new(&sys, false);
//! run(&mut rk4, &sys, &mut state, RunConfig::new(2.0, 0.01), &mut obs)?;
//! let m = obs.measures();
//! assert!(m.e_phi > 1e-12); // plain RK4 drifts off the constraints
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

pub use mbd_analysis as analysis;
pub use mbd_firefly as firefly;
pub use mbd_firefly_gauss as firefly_gauss;
pub use mbd_model as model;
pub use mbd_rk4 as rk4;
pub use mbd_solve as solve;
pub use mbd_symplectic as symplectic;
pub use mbd_tangent as tangent;

/// The README's usage example, compiled and run as a doctest.
#[doc = include_str!("../README.md")]
mod readme {}
