//! # mbd-symplectic
//!
//! Paper A's parameter-preadjusted symplectic algorithm for planar and spatial rigid multibody
//! systems in absolute coordinates: the (s,s) constrained Galerkin variational integrator, the preadjusted
//! Lagrangian `L_gamma = T - V - gamma kappa_s h^(2s) W_s(q)`, and the calibration of
//! `gamma_opt` (`docs/symplectic.md` in the repository gives the stage equations in section 2,
//! `W_s` in section 5 and the calibration in section 6).
//!
//! * [`Galerkin`] implements [`mbd_solve::Integrator`]: Lagrange interpolation of `q` through
//!   `s + 1` control points, `s`-point Gauss-Legendre quadrature of the action, constraints at
//!   every control point, Newton with an analytic Jacobian on the `s (n + m)` stage equations
//!   (at least one update per step), the end momentum from the discrete momentum balance
//!   projected onto `Phi_q M^-1 p = 0`. Order `2s`, symplectic, no energy drift; constraints at
//!   position and velocity level to the Newton tolerance.
//! * [`SymplecticOptions`]: `s`, `gamma`, the control-point placement [`Nodes`] and the Newton
//!   settings. `gamma = 0` is the plain scheme bit for bit; [`kappa`] gives `kappa_s`.
//!   [`PreadjustMode::ModifiedLagrangian`] (s = 1 or 2) replaces `W_s` by a parameter-free
//!   modified Lagrangian with velocity terms: order 4 and 6, symplectic
//!   (`docs/symplectic.md` sections 5a and 5b).
//! * [`Preadjustment`]: `W_s`, its gradient and the tangential force on any model.
//! * [`calibrate_gamma`]: `gamma_opt` by the secant method on the averaged signed trajectory
//!   error `dW(gamma)` against a reference, measured by the caller (paper A's `E|dx|`, `E|dy|`,
//!   `E|dH|` and signed means are `mbd_analysis::trajectory_errors`).
//!
//! The control points default to the Gauss-Lobatto points ([`Nodes::Lobatto`]), which for
//! `s <= 2` are the paper's equally spaced points; equally spaced points for `s >= 3` limit the
//! order to 4 (s = 3) and 6 (s = 4) because the constraint forces are then lumped by a
//! Newton-Cotes rule ([`Nodes::Equispaced`] keeps that reading). See `docs/symplectic.md`.
//!
//! ```
//! use mbd_model::models;
//! use mbd_solve::{run, NoObserver, RunConfig, State};
//! use mbd_symplectic::{Galerkin, SymplecticOptions};
//!
//! let sys = models::paper_a_double_pendulum()?;
//! let mut state = State::consistent(&sys, 0.0)?;
//! let h0 = sys.energy(state.q.as_slice(), state.v.as_slice());
//! let mut scheme = Galerkin::new(&sys, SymplecticOptions::new(2).with_gamma(1.0))?;
//! run(&mut scheme, &sys, &mut state, RunConfig::new(1.0, 0.01), &mut NoObserver)?;
//! let mut phi = vec![0.0; sys.n_constraints()];
//! sys.phi(state.q.as_slice(), state.t, &mut phi);
//! assert!(phi.iter().all(|r| r.abs() < 1e-12));
//! let dh = sys.energy(state.q.as_slice(), state.v.as_slice()) - h0;
//! assert!(dh.abs() < 1e-6);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]
// index loops mirror the formulas (several arrays indexed together)
#![allow(clippy::needless_range_loop)]

mod calibrate;
mod error;
mod galerkin;
mod options;
mod passes;
mod preadjust;
mod registry;
mod tables;

pub use calibrate::{calibrate_gamma, Calibration, CalibrationSettings};
pub use error::SymplecticError;
pub use galerkin::Galerkin;
pub use options::{
    kappa, phase_constant, JacobianReuse, Nodes, PreadjustMode, SymplecticOptions,
    ANDERSON_START_CONTRACTION, DEFAULT_ANDERSON_DEPTH, MAX_ANDERSON_DEPTH,
};
pub use preadjust::Preadjustment;
pub use registry::SOLVERS;
pub use tables::lobatto_nodes;
