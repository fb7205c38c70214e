//! # mbd-tangent
//!
//! Paper B's method: the index-3 equations of motion, written as the first-order DAE
//!
//! ```text
//! x = (q, v),   x' = F(x, t) = (v, a(q, v, t)),   f(x, t) = (Phi(q, t), Phi_q v + Phi_t) = 0,
//! ```
//!
//! are turned into state equations by a *local (tangent-space) parameterisation* of the
//! constraint manifold, and any explicit Runge-Kutta method integrates those. At an accepted
//! point `x_c`:
//!
//! * `Df(x_c) = [[Phi_q, 0], [(Phi_q v)_q, Phi_q]]`; the QR factorisation `Df^T = Q1 R` (from
//!   two small Householder QRs of its blocks) gives an orthonormal basis `U` of `ker Df(x_c)` (`2(n-m)` columns) and `Q1` of its
//!   orthogonal complement;
//! * the chart `x(xi) = x_c + U xi + Df(x_c)^T eta(xi)`, with `eta` by chord Newton on
//!   `f(x(xi), t) = 0`;
//! * the state equation `xi' = U^T F(x(xi), t)`, integrated from `xi = 0` over one step with any
//!   [`ButcherTableau`] (RK4 by default; DOPRI5 with adaptive steps), mapped back, and the chart
//!   re-centred at the new point ([`TangentRk`]).
//!
//! Position and velocity constraints then hold to the Newton tolerance (1e-13 by default, raised
//! to the round-off floor of evaluating them for fast or far-out states) at every step; rheonomic drivers work (`f` and `F` are evaluated at the stage times). Near a
//! singular configuration (where `Phi_q` loses rank) the chord iteration hands over to Newton
//! with the exact matrix ([`NewtonSettings::fallback_change`]), so the solver passes it on the
//! branch it is on; a step that starts or ends exactly on one is a
//! [`mbd_solve::SolveError::Singular`] naming time, numerical rank and joints, at once. A chart
//! failure for a too-large step is recovered by documented step halving (counted in
//! [`TangentStats::halvings`]) or is an error with time and residual — never a silent wrong
//! state. See `docs/tangent.md` for the derivation.
//!
//! Large mechanisms (more than [`mbd_solve::SPARSE_THRESHOLD`] constraint equations, or
//! [`TangentOptions::linear_solver`] = [`LinearSolver::Sparse`]) run on a sparse chart:
//! no basis of `ker Df` is formed; the chart is `x(y) = x_c + y + Df(x_c)^T eta(y)` in redundant
//! coordinates `y in ker Df(x_c)`, the state equation `y' = P F` with the projector
//! `P = I - Df^T (Df Df^T)^-1 Df`, and one sparse Cholesky factorisation of `Df Df^T` per
//! step serves the projector and the chord iteration. Since `y = U xi` and explicit RK is
//! linear in the stage derivatives, both charts give the same trajectory up to rounding, at
//! `O(N)` cost per step for an `N`-link chain (`docs/tangent.md` section 9).
//!
//! ```
//! use mbd_model::models;
//! use mbd_solve::{run, run_adaptive, AdaptiveConfig, NoObserver, RunConfig, State};
//! use mbd_tangent::TangentRk;
//!
//! let sys = models::slider_crank()?;
//! let mut state = State::consistent(&sys, 0.0)?;
//! let mut rk4 = TangentRk::rk4(&sys)?;
//! run(&mut rk4, &sys, &mut state, RunConfig::new(1.0, 1e-3), &mut NoObserver)?;
//! // constraints at the Newton tolerance after 1000 steps
//! let mut phi = vec![0.0; sys.n_constraints()];
//! let mut phid = vec![0.0; sys.n_constraints()];
//! sys.phi(state.q.as_slice(), state.t, &mut phi);
//! sys.phi_dot(state.q.as_slice(), state.v.as_slice(), state.t, &mut phid);
//! assert!(phi.iter().chain(&phid).all(|r| r.abs() <= 1e-12));
//!
//! // adaptive DOPRI5 5(4) to t = 2 s at tolerance 1e-9
//! let mut dp = TangentRk::dopri5(&sys)?;
//! let stats = run_adaptive(&mut dp, &sys, &mut state, AdaptiveConfig::new(2.0, 1e-9), &mut NoObserver)?;
//! assert!(stats.steps > 0 && (state.t - 2.0).abs() < 1e-15);
//! assert!(stats.max_residual <= 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

mod chart;
mod integrator;
mod kernels;
mod registry;
mod sparse_chart;

pub use chart::{NewtonSettings, ROUNDOFF_FACTOR};
pub use integrator::{ChartMetric, IterationMatrix, TangentOptions, TangentRk, TangentStats};
pub use mbd_solve::LinearSolver;
pub use registry::SOLVERS;

pub use mbd_solve::{ButcherTableau, StepController};
