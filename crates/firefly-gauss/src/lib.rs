//! # mbd-firefly-gauss — FA-DAE, paper C's firefly-algorithm DAE solver
//!
//! Zhang and Ding (J. Dynamics and Control 19(2), 2021) turn each step of the index-3
//! equations of motion
//!
//! ```text
//! M q'' + Phi_q^T lambda = Q(q, q', t),    Phi(q, t) = 0
//! ```
//!
//! into an optimisation problem solved by the firefly algorithm. This crate implements that
//! method as an [`mbd_solve::Integrator`], [`FireflyGauss`]. Per step `[t_k, t_k + h]`:
//!
//! 1. **Decision variables**: the independent coordinates `z` and velocities `zdot` at
//!    `t_{k+1}` (`2 dof` numbers; for the two-link manipulator the two link angles and their
//!    rates, as in the paper). The split is found by Gaussian elimination with complete
//!    pivoting of `Phi_q` ([`Partition::auto`]) and re-chosen during the run when the
//!    dependent block becomes much worse than the best available one
//!    ([`FaDaeOptions::repartition_threshold`]), or given by the user
//!    ([`PartitionChoice::Given`]). With `k` redundant constraint equations
//!    ([`mbd_model::System::n_redundant`]) `Phi_q` has rank `m - k`: the partition also picks
//!    the `m - k` equations that complete the dependent coordinates ([`Partition::equations`]),
//!    and `dof = n - m + k`.
//! 2. **Completion**: the dependent coordinates follow from `Phi(q, t_{k+1}) = 0` (chord Newton
//!    from the predictor, to `1e-14`), the dependent velocities from
//!    `Phi_q v + Phi_t = 0`, so every accepted state satisfies the position and velocity
//!    constraints to round-off, and its accelerations (index-1 solve) the acceleration
//!    constraint.
//! 3. **Objective**: `q` is interpolated over the step by the cubic Hermite polynomial through
//!    `(q_k, v_k)` and `(q_{k+1}, v_{k+1})`; at the two Gauss points
//!    `t_k + (1/2 -/+ sqrt(3)/6) h` (weights `h/2`) the residual `M q'' - Q` is projected on the
//!    tangent space of the constraints (null-space projection eliminates `lambda`) and
//!    expressed as an independent-coordinate acceleration; the objective is the Gauss-weighted
//!    mean of its square, scaled by `h^4` (a squared position defect). Its zero is a symmetric
//!    collocation method of order 4.
//! 4. **Optimiser**: [`mbd_firefly`] minimises the objective in a box around a predictor (RK4
//!    plus the previous step's correction), in stages that shrink the box around the best
//!    firefly, until the objective is `tolerance` times the predictor's. The project's default
//!    is `tolerance = 1e-2` (every step improves the predictor a hundredfold);
//!    [`FaDaeOptions::paper`] uses the paper's `epsilon = 1e-7` instead (about five times the
//!    generations). Optionally ([`FaDaeOptions::polish`]) Gauss-Newton polishes the result on
//!    the same residual.
//!
//! ```
//! use mbd_firefly_gauss::{FaDaeOptions, FireflyGauss};
//! use mbd_model::models;
//! use mbd_solve::{run, NoObserver, RunConfig, State};
//!
//! let sys = models::manipulator()?;
//! let mut state = State::consistent(&sys, 0.0)?;
//! let h0 = sys.energy(state.q.as_slice(), state.v.as_slice());
//! let mut fa = FireflyGauss::new(&sys, FaDaeOptions::default().seed(7))?;
//! assert_eq!(fa.partition().independent, vec![2, 5]); // the two link angles
//! run(&mut fa, &sys, &mut state, RunConfig::new(0.2, 0.01), &mut NoObserver)?;
//!
//! // all constraint levels hold at round-off at every grid point
//! let mut phi = vec![0.0; sys.n_constraints()];
//! sys.phi(state.q.as_slice(), state.t, &mut phi);
//! assert!(phi.iter().all(|r| r.abs() < 1e-13));
//! sys.phi_dot(state.q.as_slice(), state.v.as_slice(), state.t, &mut phi);
//! assert!(phi.iter().all(|r| r.abs() < 1e-13));
//! // energy is kept well
//! let h1 = sys.energy(state.q.as_slice(), state.v.as_slice());
//! assert!(((h1 - h0) / h0).abs() < 1e-6);
//! // the answer comes from the optimiser: it improved the predictor's objective a hundredfold
//! assert!(fa.stats().mean_ratio() > 100.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Determinism
//!
//! Step `k` runs the firefly algorithm with the seed [`step_seed`]`(seed, k, stage)`; every
//! objective evaluation is a pure function of the candidate (Newton always starts from the
//! same point), so the same seed gives bit-identical trajectories, and
//! [`FaDaeOptions::parallel`] (rayon evaluation of each generation) gives the same bits as
//! serial evaluation.
//!
//! ## Failure behaviour
//!
//! Invalid options, partitions, states or step sizes are errors ([`FaDaeError`]), never panics.
//! When the optimiser stops above the step's target, the best candidate (which is still a
//! consistent state) is accepted and flagged ([`StepInfo::reached_target`],
//! [`FaDaeStats::target_misses`]) under [`MissPolicy::Accept`] (default), or the step fails
//! under [`MissPolicy::Error`].
//!
//! `docs/firefly-gauss.md` in the repository gives the maths as implemented and the reasons
//! for each choice.
#![warn(missing_docs)]

mod accel;
mod error;
mod integrator;
mod objective;
mod options;
mod partition;
mod registry;

pub use accel::RefinedAcceleration;
pub use error::FaDaeError;
pub use integrator::{step_seed, FaDaeStats, FireflyGauss, StepInfo};
pub use options::{BoxSettings, FaDaeOptions, MissPolicy, PartitionChoice, Predictor};
pub use partition::Partition;
pub use registry::SOLVERS;
