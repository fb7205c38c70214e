//! The driver: runs a [`Swarm`] until a stopping rule holds, feeding observers.

use crate::termination::TerminationState;
use crate::{
    Bounds, FireflyError, FireflySettings, Objective, Observer, StopCriterion, StopReason, Swarm,
    SyncObjective, Termination,
};

/// Outcome of a run.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FireflyResult {
    /// Best point found (over the whole run).
    pub best_x: Vec<f64>,
    /// Objective value at `best_x`; `+inf` if every evaluation was non-finite.
    pub best_f: f64,
    /// Generations completed after the initial population (the last one may
    /// have been cut short by the evaluation budget).
    pub generations: u64,
    /// Objective evaluations, initial population included.
    pub evaluations: u64,
    /// Why the run stopped.
    pub stop_reason: StopReason,
    /// Evaluations that returned NaN or an infinity (treated as worst).
    pub nan_evaluations: u64,
    /// Randomisation strength the next generation would have used.
    pub final_alpha: f64,
}

/// Builder and driver of a firefly run: a search box plus
/// [`FireflySettings`] (the algorithm), [`Termination`] (stopping rules),
/// optional initial positions, [`Observer`]s and custom [`StopCriterion`]s.
///
/// ```
/// use mbd_firefly::{Bounds, Firefly, FireflySettings, History, StopReason, Termination};
///
/// # fn main() -> Result<(), mbd_firefly::FireflyError> {
/// let predictor = vec![0.3, -0.2];
/// let bounds = Bounds::centered(&predictor, &[1.0, 1.0])?;
/// let mut history = History::new();
/// let result = Firefly::new(bounds)
///     .settings(FireflySettings::default().population(20).alpha(0.2).alpha_decay(0.95).seed(3))
///     .termination(Termination::default().max_generations(200).target(1e-8))
///     .initial_position(predictor) // one firefly starts at the predictor
///     .observer(&mut history)
///     .minimize(&mut |x: &[f64]| (x[0] - 0.5).powi(2) + (x[1] + 0.1).powi(2))?;
/// assert_eq!(result.stop_reason, StopReason::TargetReached);
/// assert_eq!(history.len() as u64, result.generations + 1);
/// # Ok(())
/// # }
/// ```
pub struct Firefly<'a> {
    bounds: Bounds,
    settings: FireflySettings,
    termination: Termination,
    initial: Vec<Vec<f64>>,
    observers: Vec<&'a mut dyn Observer>,
    criteria: Vec<&'a mut dyn StopCriterion>,
}

impl std::fmt::Debug for Firefly<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Firefly")
            .field("bounds", &self.bounds)
            .field("settings", &self.settings)
            .field("termination", &self.termination)
            .field("initial", &self.initial)
            .field("observers", &self.observers.len())
            .field("criteria", &self.criteria.len())
            .finish()
    }
}

impl<'a> Firefly<'a> {
    /// A run over `bounds` with default settings and termination
    /// (1000 generations).
    pub fn new(bounds: Bounds) -> Self {
        Self {
            bounds,
            settings: FireflySettings::default(),
            termination: Termination::default(),
            initial: Vec::new(),
            observers: Vec::new(),
            criteria: Vec::new(),
        }
    }

    /// Replaces the algorithm settings.
    #[must_use]
    pub fn settings(mut self, settings: FireflySettings) -> Self {
        self.settings = settings;
        self
    }

    /// Replaces the stopping rules.
    #[must_use]
    pub fn termination(mut self, termination: Termination) -> Self {
        self.termination = termination;
        self
    }

    /// Replaces the list of initial positions: firefly `i` starts at
    /// `positions[i]`, the remaining fireflies uniformly at random. At most
    /// `population` positions, each inside the box (checked when the run
    /// starts).
    #[must_use]
    pub fn initial_positions(mut self, positions: Vec<Vec<f64>>) -> Self {
        self.initial = positions;
        self
    }

    /// Appends one initial position (for instance a predictor point).
    #[must_use]
    pub fn initial_position(mut self, x: Vec<f64>) -> Self {
        self.initial.push(x);
        self
    }

    /// Adds an observer, called after the initial population and after every
    /// generation.
    #[must_use]
    pub fn observer(mut self, observer: &'a mut dyn Observer) -> Self {
        self.observers.push(observer);
        self
    }

    /// Adds a custom stopping rule, consulted after the built-in ones.
    #[must_use]
    pub fn stop_when(mut self, criterion: &'a mut dyn StopCriterion) -> Self {
        self.criteria.push(criterion);
        self
    }

    /// The search box.
    pub fn bounds(&self) -> &Bounds {
        &self.bounds
    }

    /// Minimises `objective`, calling it serially from the current thread.
    ///
    /// # Errors
    /// Any configuration error (see [`FireflyError`]); checked before the
    /// first evaluation. A started run always returns `Ok`.
    pub fn minimize<O: Objective + ?Sized>(
        &mut self,
        objective: &mut O,
    ) -> Result<FireflyResult, FireflyError> {
        let dim = objective.dim();
        let mut swarm = self.prepare(dim)?;
        let mut state = TerminationState::new(self.termination.clone());
        swarm.initialize(objective, state.remaining(0));
        loop {
            if let Some(reason) = self.after_generation(&swarm, &mut state) {
                return Ok(result(&swarm, reason));
            }
            swarm.step(objective, state.remaining(swarm.evaluations()));
        }
    }

    /// Minimises `objective`, moving and evaluating the fireflies of each
    /// generation in parallel on the current rayon thread pool (use
    /// `ThreadPool::install` to choose one). Only
    /// [`Variant::Snapshot`](crate::Variant::Snapshot) runs in parallel; the
    /// classic variants run serially. The result is
    /// bit-identical to [`Firefly::minimize`] with the same settings, whatever
    /// the number of threads.
    ///
    /// # Errors
    /// As [`Firefly::minimize`].
    pub fn minimize_parallel<O: SyncObjective + ?Sized>(
        &mut self,
        objective: &O,
    ) -> Result<FireflyResult, FireflyError> {
        let dim = objective.dim();
        let mut swarm = self.prepare(dim)?;
        let mut state = TerminationState::new(self.termination.clone());
        swarm.initialize_parallel(objective, state.remaining(0));
        loop {
            if let Some(reason) = self.after_generation(&swarm, &mut state) {
                return Ok(result(&swarm, reason));
            }
            swarm.step_parallel(objective, state.remaining(swarm.evaluations()));
        }
    }

    fn prepare(&self, objective_dim: Option<usize>) -> Result<Swarm, FireflyError> {
        self.settings.validate()?;
        self.termination.validate()?;
        if let Some(dim) = objective_dim {
            if dim != self.bounds.dim() {
                return Err(FireflyError::ObjectiveDimension {
                    objective: dim,
                    bounds: self.bounds.dim(),
                });
            }
        }
        Swarm::new(&self.bounds, &self.settings, &self.initial)
    }

    /// Notifies observers, then checks the built-in and custom rules.
    fn after_generation(
        &mut self,
        swarm: &Swarm,
        state: &mut TerminationState,
    ) -> Option<StopReason> {
        let record = swarm.record();
        for o in self.observers.iter_mut() {
            o.observe(&record);
        }
        if let Some(reason) = state.check(&record) {
            return Some(reason);
        }
        for c in self.criteria.iter_mut() {
            if c.should_stop(&record) {
                return Some(StopReason::Custom);
            }
        }
        None
    }
}

fn result(swarm: &Swarm, stop_reason: StopReason) -> FireflyResult {
    FireflyResult {
        best_x: swarm.best_x().to_vec(),
        best_f: swarm.best_f(),
        generations: swarm.generation(),
        evaluations: swarm.evaluations(),
        stop_reason,
        nan_evaluations: swarm.nan_evaluations(),
        final_alpha: swarm.alpha(),
    }
}
