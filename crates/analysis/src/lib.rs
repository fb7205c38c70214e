//! # mbd-analysis
//!
//! What the papers measure, for any solver of `mbd`:
//!
//! * [`RunMeasures`] (paper C): `e(H)`, `MRE(H)`, `e(Phi)`, `e(Phidot)`, `e(Phiddot)`, accumulated
//!   online by [`MeasureObserver`] (no trajectory kept) or from a stored [`Trajectory`];
//! * [`TrajectoryErrors`] (paper A): `E|dx|`, `E|dy|`, `E|dH|`, their signed means and
//!   `dW = E[dx] + E[dy]`, against a reference sampled at other times (interpolated to fourth
//!   order);
//! * [`fit_order`]: the convergence order (least-squares slope and local orders, dropping points
//!   at the round-off floor);
//! * [`period`]: oscillation periods from zero crossings of samples (interpolated, least-squares
//!   slope of the crossing times) and the exact pendulum period ([`period::pendulum_period`]);
//! * [`TimeSeries`] and [`CsvObserver`]: CSV/JSON output;
//! * [`save_state`] / [`load_state`]: a state as JSON, read back as an initial state;
//! * [`EnergyBalance`]: the work of loads and drivers and the energy dampers take, along a run;
//! * [`units`]: the unit of each output column (axis labels); [`ticks`]: axis ticks at round
//!   values; `plot` (feature `plot`): SVG figures.
//!
//! ```
//! use mbd_analysis::{fit_order, MeasureObserver};
//! use mbd_model::models;
//! use mbd_solve::{run, ButcherTableau, Index1Options, Index1Rk, RunConfig, State};
//!
//! let sys = models::pendulum(1.0, 1.0, 0.3, 9.81)?;
//! let mut errs = vec![];
//! let hs = [0.04, 0.02, 0.01];
//! for &h in &hs {
//!     let mut s = State::consistent(&sys, 0.0)?;
//!     let mut rk = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default())?;
//!     let mut obs = MeasureObserver::new(&sys, true);
//!     run(&mut rk, &sys, &mut s, RunConfig::new(2.0, h), &mut obs)?;
//!     errs.push(obs.measures().e_h);
//! }
//! let fit = fit_order(&hs, &errs, 1e-14)?;
//! assert!((fit.order - 4.0).abs() < 0.5, "{fit:?}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]
// Index loops mirror the formulas; negated comparisons deliberately treat NaN as failure.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

mod energy_balance;
mod error;
mod measures;
mod order;
mod output;
pub mod period;
#[cfg(feature = "plot")]
pub mod plot;
mod state_file;
pub mod ticks;
mod trajectory;
pub mod units;

pub use energy_balance::EnergyBalance;
pub use error::AnalysisError;
pub use measures::{measure_trajectory, MeasureObserver, RunMeasures};
pub use order::{fit_order, OrderFit};
pub use output::{CsvObserver, TimeSeries};
pub use state_file::{load_state, save_state, state_from_json, state_to_json, STATE_FORMAT};
pub use trajectory::{position_error_at, trajectory_errors, Trajectory, TrajectoryErrors};
