//! The output of `mbd run`, shared by the command line and the Python package: the column set
//! ([`output_columns`]), why the energy is not conserved ([`not_conserved`]), and the rows of a
//! run kept in memory ([`Collector`]), so every front end writes the same numbers.

use mbd_analysis::{CsvObserver, EnergyBalance};
use mbd_model::System;
use mbd_solve::{Flow, Observer, SolveError, State};
use std::io::Write;

/// Why the model's energy `H` is not conserved, or `None` if it is: the non-conservative force
/// elements (dampers, time-dependent loads) and the drivers (rheonomic joints) by name.
///
/// ```
/// let sys = mbd::model::models::pendulum(1.0, 1.0, 0.3, 9.81)?;
/// assert_eq!(mbd::output::not_conserved(&sys), None);
/// # Ok::<(), mbd::Error>(())
/// ```
pub fn not_conserved(sys: &System) -> Option<String> {
    let forces: Vec<&str> = sys
        .forces()
        .iter()
        .filter(|f| f.is_nonconservative())
        .map(|f| f.name.as_str())
        .chain(
            sys.spatial_forces()
                .iter()
                .filter(|f| f.is_nonconservative())
                .map(|f| f.name.as_str()),
        )
        .collect();
    let drivers: Vec<&str> = sys
        .joints()
        .iter()
        .filter(|j| j.is_rheonomic())
        .map(|j| j.name.as_str())
        .chain(
            sys.spatial_joints()
                .iter()
                .filter(|j| j.motion.is_some())
                .map(|j| j.name.as_str()),
        )
        .collect();
    let mut parts = Vec::new();
    if !forces.is_empty() {
        parts.push(format!("non-conservative forces {}", forces.join(", ")));
    }
    if !drivers.is_empty() {
        parts.push(format!("drivers {}", drivers.join(", ")));
    }
    (!parts.is_empty()).then(|| parts.join("; "))
}

/// The columns of `mbd run`'s output on `c`: the state and `H`, the constraint residuals, if
/// `reactions` the joint reactions, the model's sensors, and where `H` is not conserved
/// ([`not_conserved`]) the energy balance.
pub fn output_columns<W: Write>(
    c: CsvObserver<W>,
    sys: &System,
    reactions: bool,
) -> CsvObserver<W> {
    let mut c = c.with_residuals().with_sensors();
    if reactions {
        c = c.with_reactions();
    }
    if not_conserved(sys).is_some() {
        c = c.with_energy_balance();
    }
    c
}

/// An [`Observer`] that keeps the rows of `mbd run`'s output in memory: the columns of
/// [`output_columns`], the states of steps `0, k, 2k, ...` and, after [`Collector::finish`],
/// the final state. The command line's JSON output and the Python package's results are its
/// rows.
///
/// ```
/// use mbd::output::Collector;
/// use mbd::solve::RunConfig;
///
/// let mut sim = mbd::Simulation::new(mbd::model::models::pendulum(1.0, 1.0, 0.3, 9.81)?, "rk4")?;
/// let mut rows = Collector::new(sim.system(), false, 3);
/// sim.run_observed(RunConfig::new(0.1, 0.01), &mut rows)?;
/// rows.finish(sim.system(), sim.state())?;
/// assert_eq!(rows.rows(), 5); // steps 0, 3, 6, 9 and the final step 10
/// assert_eq!(rows.columns(sim.system())[0], "t");
/// assert_eq!(rows.data().len(), 5 * rows.columns(sim.system()).len());
/// # Ok::<(), mbd::Error>(())
/// ```
pub struct Collector {
    fmt: CsvObserver<std::io::Sink>,
    every: usize,
    data: Vec<f64>,
    rows: usize,
    last_t: Option<f64>,
}

impl Collector {
    /// Collects `mbd run`'s columns for `sys` (with the joint reactions if `reactions`) every
    /// `every` steps (0 is taken as 1).
    pub fn new(sys: &System, reactions: bool, every: usize) -> Self {
        Collector {
            fmt: output_columns(CsvObserver::new(std::io::sink()), sys, reactions),
            every: every.max(1),
            data: Vec::new(),
            rows: 0,
            last_t: None,
        }
    }

    /// The column names (the CSV header of `mbd run`).
    pub fn columns(&self, sys: &System) -> Vec<String> {
        self.fmt.columns(sys)
    }

    /// The running energy balance, where `H` is not conserved and a state was seen.
    pub fn energy_balance(&self) -> Option<&EnergyBalance> {
        self.fmt.energy_balance()
    }

    /// Adds the final state `s` unless it was the last row kept (the run's last step is not a
    /// multiple of `every`).
    pub fn finish(&mut self, sys: &System, s: &State) -> Result<(), SolveError> {
        if self.last_t != Some(s.t) {
            self.push(sys, s)?;
        }
        Ok(())
    }

    /// The number of rows kept.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The rows kept, one after the other (row-major, [`Collector::columns`] values each).
    pub fn data(&self) -> &[f64] {
        &self.data
    }

    /// The rows kept (row-major), by value.
    pub fn into_data(self) -> Vec<f64> {
        self.data
    }

    fn push(&mut self, sys: &System, s: &State) -> Result<(), SolveError> {
        self.data.extend_from_slice(self.fmt.row(sys, s)?);
        self.rows += 1;
        self.last_t = Some(s.t);
        Ok(())
    }
}

impl Observer for Collector {
    fn observe(&mut self, sys: &System, s: &State, step: usize) -> Result<Flow, SolveError> {
        self.fmt.advance(sys, s)?;
        if step % self.every == 0 {
            self.push(sys, s)?;
        }
        Ok(Flow::Continue)
    }
}
