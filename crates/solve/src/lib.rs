//! # mbd-solve
//!
//! The solver core of `mbd`: what every integrator shares.
//!
//! * [`Integrator`]: the trait a solver implements (`step(system, state, h)`), with [`State`]
//!   (`t`, `q`, `v`) and [`StepStats`].
//! * [`run`]: the fixed-step run loop from `state.t` to `t_end`, with [`Observer`]s
//!   ([`Recorder`], [`Every`], closures) that can stream samples instead of keeping them.
//! * [`Newton`]: damped Newton on a [`NewtonProblem`] with an error that reports time, residual
//!   and iterations.
//! * [`AccelerationSolver`]: the index-1 solve `[[M, Phi_q^T], [Phi_q, 0]] [a; lambda] = [Q; gamma]`
//!   (faer Cholesky of the Schur complement), and [`Projector`] for post-step projection.
//! * [`SingularBridge`]: the stage accelerations of the index-1 solvers carried through
//!   singular configurations (their ill-determined components from the motion's extrapolation).
//! * [`ButcherTableau`] (methods as data) and [`ExplicitRk`], an allocation-free explicit
//!   Runge-Kutta stepper with embedded error estimates and a [`StepController`].
//! * [`quadrature`]: Gauss-Legendre rules and Lagrange bases for any number of points.
//!
//! A minimal integrator (semi-implicit Euler on the index-1 form) driven by the run loop:
//!
//! ```
//! use mbd_model::models;
//! use mbd_solve::{run, AccelerationSolver, Integrator, Recorder, RunConfig, SolveError, State, StepStats};
//! use mbd_model::System;
//!
//! struct SymplecticEuler { acc: AccelerationSolver, a: Vec<f64>, lambda: Vec<f64> }
//! impl Integrator for SymplecticEuler {
//!     fn name(&self) -> String { "symplectic Euler".into() }
//!     fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats, SolveError> {
//!         self.acc.solve(sys, s.q.as_slice(), s.v.as_slice(), s.t, &mut self.a, &mut self.lambda)?;
//!         for i in 0..s.v.len() { s.v[i] += h * self.a[i]; s.q[i] += h * s.v[i]; }
//!         Ok(StepStats { rhs_evals: 1, ..Default::default() })
//!     }
//! }
//!
//! let sys = models::pendulum(1.0, 1.0, 0.1, 9.81)?;
//! let mut state = State::consistent(&sys, 0.0)?;
//! let mut integ = SymplecticEuler {
//!     acc: AccelerationSolver::new(&sys),
//!     a: vec![0.0; sys.n_coords()],
//!     lambda: vec![0.0; sys.n_constraints()],
//! };
//! let mut rec = Recorder::new();
//! let stats = run(&mut integ, &sys, &mut state, RunConfig::new(1.0, 0.01), &mut rec)?;
//! assert_eq!(stats.steps, 100);
//! assert_eq!(rec.len(), 101);
//! assert!((state.t - 1.0).abs() < 1e-15);
//! # Ok::<(), SolveError>(())
//! ```
#![warn(missing_docs)]
// Index loops mirror the formulas; negated comparisons deliberately treat NaN as failure.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

mod accel;
mod adaptive;
mod branch;
mod bridge;
mod consistent;
mod constrained;
mod dense;
mod error;
mod guard;
mod index1;
mod integrator;
pub mod linalg;
mod newton;
mod output_solve;
mod projection;
pub mod quadrature;
mod reactions;
pub mod registry;
mod sensors;
pub mod sparse;
mod starter;
mod state;
mod step_over;
mod tableau;

pub use accel::AccelerationSolver;
pub use adaptive::{run_adaptive, AdaptiveConfig, AdaptiveIntegrator, StepAttempt};
pub use bridge::{
    ConstraintRows, SingularBridge, BRIDGE_CONDITION, BRIDGE_DISAGREEMENT, BRIDGE_MAX_CONSTRAINTS,
    BRIDGE_MEMORY, BRIDGE_POINTS, BRIDGE_QUIET,
};
pub use consistent::{
    consistent_state, initial_changes, project_state, ConsistentOptions, ConsistentState,
    InitialChange, INITIAL_CHANGE_TOL,
};
pub use constrained::ConstrainedSolve;
pub use dense::{Crossing, DenseOutput, Event, EventFn, EventHit};
pub use error::{
    refuse_large_spatial, refuse_redundant, refuse_spatial, SolveError, CHART_NEAR_RANK_LOSS,
    DENSE_SPATIAL_LIMIT, STAGES_NEAR_RANK_LOSS, STAGES_STALLED_NEAR_RANK_LOSS,
};
pub use index1::{reference_trajectory, Index1Options, Index1Rk, ReferenceTrajectory};
pub use integrator::{
    observe, observer, run, step_count, DriftGuard, Every, Flow, FnObserver, Integrator,
    NoObserver, Observer, Recorder, RunConfig, RunStats, StateFn, StepStats, StopReason,
    BLOWUP_RATIO, BRANCH_ARM_CONDITION, BRANCH_JUMP_TOL, BRANCH_WATCH_CONDITION, GUARD_QUIET_RATIO,
    GUARD_STRIDE, MAX_FIXED_STEPS,
};
pub use newton::{Newton, NewtonOptions, NewtonProblem, NewtonStats};
pub use output_solve::OutputSolve;
pub use projection::{ProjectionSettings, ProjectionStats, Projector, PROJECTION_ROUNDOFF_FACTOR};
pub use reactions::{JointReaction, ReactionSolver};
pub use sensors::SensorSolver;
pub use sparse::{LinearSolver, SparseAccelerationSolver, SPARSE_THRESHOLD};
pub use starter::SingularStarter;
pub use state::State;
pub use tableau::{ButcherTableau, ExplicitRk, StepController};

pub use mbd_model;
pub use nalgebra;
