//! # mbd-firefly — the firefly metaheuristic, deterministic and parallel
//!
//! A generic, box-constrained minimiser implementing X.-S. Yang's firefly
//! algorithm (*Nature-Inspired Metaheuristic Algorithms*, 2008; *Firefly
//! algorithm, stochastic test functions and design optimisation*, 2010). It
//! minimises any `FnMut(&[f64]) -> f64` (or an [`Objective`] implementor) over
//! a box `[lo, hi]^d`, serially or with rayon-parallel moves and evaluations
//! ([`SyncObjective`]), and is bit-for-bit reproducible from a `u64` seed.
//!
//! ```
//! use mbd_firefly::{Bounds, Firefly, FireflySettings, Termination};
//!
//! # fn main() -> Result<(), mbd_firefly::FireflyError> {
//! // Closures need the argument type spelled out.
//! let mut sphere = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>();
//! let bounds = Bounds::cube(3, -5.0, 5.0)?;
//! let result = Firefly::new(bounds)
//!     .settings(FireflySettings::default().population(30).alpha(0.2).alpha_decay(0.95).seed(42))
//!     .termination(Termination::default().max_generations(300).target(1e-10))
//!     .minimize(&mut sphere)?;
//! assert!(result.best_f <= 1e-10);
//! println!("{:?} after {} evaluations", result.best_x, result.evaluations);
//!
//! // Parallel evaluation: identical bits, any number of threads.
//! let bounds = Bounds::cube(3, -5.0, 5.0)?;
//! let par = Firefly::new(bounds)
//!     .settings(FireflySettings::default().population(30).alpha(0.2).alpha_decay(0.95).seed(42))
//!     .termination(Termination::default().max_generations(300).target(1e-10))
//!     .minimize_parallel(&sphere)?;
//! assert_eq!(par.best_f.to_bits(), result.best_f.to_bits());
//! # Ok(())
//! # }
//! ```
//!
//! ## The algorithm as implemented
//!
//! Brightness is the objective value: lower is brighter. Each generation,
//! every firefly `i` moves toward every *strictly* brighter firefly `j`:
//!
//! ```text
//! x_i <- x_i + beta(r_ij) (x_j - x_i) + alpha_t (u - 1/2) (hi - lo)      (per coordinate)
//! beta(r) = (beta0 - beta_min) exp(-gamma r^2) + beta_min
//! ```
//!
//! with a fresh `u ~ U[0, 1)` per coordinate and move; `r` is measured in
//! box-normalised coordinates by default ([`DistanceScaling`]). A firefly
//! that has no brighter firefly (the best one, and any tied with it) takes a
//! pure random step `alpha_t (u - 1/2) (hi - lo)` instead
//! ([`FireflySettings::best_random_walk`]). After every move each coordinate is
//! clamped to the box (or reflected, [`BoundaryHandling`]). `alpha` decays
//! geometrically: generation `t = 1, 2, ...` uses `alpha_0 delta^(t-1)`.
//! The best point ever evaluated is kept apart from the population, so the
//! reported optimum never gets worse.
//!
//! Three loop forms are offered ([`Variant`]):
//! * [`Variant::Snapshot`] (default): sort by brightness, freeze a snapshot,
//!   move every firefly toward the brighter fireflies *of the snapshot*, then
//!   evaluate all new positions — moves and evaluations in parallel with
//!   [`Firefly::minimize_parallel`];
//! * [`Variant::Classic`]: Yang's in-place double loop, evaluating after every
//!   move;
//! * [`Variant::ClassicSweep`]: the in-place loop evaluating each firefly once
//!   after its sweep.
//!
//! ## Determinism
//!
//! Random numbers come from [`rand_chacha::ChaCha8Rng`] keyed with
//! `seed_from_u64(settings.seed)`. Initial positions and the classic variants
//! use the generator's stream 0, drawn serially in a fixed order. In the
//! snapshot variant, the firefly of sorted rank `k` in generation `g` draws
//! from its own ChaCha stream `g n + k`, so its move depends only on the
//! frozen snapshot and that stream; moving and evaluating each firefly is an
//! independent task, run on rayon workers by
//! [`Firefly::minimize_parallel`], each writing only its own slots, and the
//! bookkeeping (counters, best-so-far) is done afterwards serially in index
//! order. The same seed
//! therefore gives bit-identical results serially or in parallel, on any
//! thread count.
//!
//! ## Pieces
//!
//! * [`Bounds`] — the validated search box (`lo == hi` fixes a coordinate);
//! * [`FireflySettings`] — algorithm parameters (defaults: population 60,
//!   `beta0 = 1`, `beta_min = 0`, `gamma = 1`, `alpha = 0.7`, decay 0.97,
//!   snapshot variant, clamping, normalised distance, seed 0);
//! * [`Termination`] — stopping rules (generation limit, evaluation budget,
//!   target value, stagnation; default 1000 generations) plus custom
//!   [`StopCriterion`]s;
//! * [`Observer`] / [`History`] — per-generation [`GenerationRecord`]s;
//! * [`Firefly`] — the driver, returning a [`FireflyResult`] with the
//!   [`StopReason`];
//! * [`Swarm`] — the bare algorithm state for stepping by hand;
//! * [`testfns`] — sphere, Rosenbrock, Rastrigin, Ackley, Griewank.
//!
//! Errors: every configuration problem is a [`FireflyError`], reported before
//! the objective is first called; a started run cannot fail. NaN or infinite
//! objective values count as the worst possible brightness and are tallied
//! in [`FireflyResult::nan_evaluations`].
//!
//! `docs/firefly.md` in the repository discusses the design in more depth.

#![warn(missing_docs)]

mod bounds;
mod driver;
mod error;
mod objective;
mod observer;
mod settings;
mod swarm;
mod termination;
pub mod testfns;

pub use bounds::Bounds;
pub use driver::{Firefly, FireflyResult};
pub use error::FireflyError;
pub use objective::{Objective, SyncObjective};
pub use observer::{GenerationRecord, History, Observer};
pub use settings::{BoundaryHandling, DistanceScaling, FireflySettings, Variant};
pub use swarm::Swarm;
pub use termination::{Stagnation, StopCriterion, StopReason, Termination};
