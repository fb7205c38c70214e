//! Stopping rules, kept apart from the algorithm.

use crate::{FireflyError, GenerationRecord};

/// Why a run stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum StopReason {
    /// The best value reached the target: `best_f <= target`.
    TargetReached,
    /// The evaluation budget is used up (it is never exceeded).
    EvaluationBudget,
    /// The best value did not improve by more than the tolerance for the
    /// given number of consecutive generations.
    Stagnation,
    /// The generation limit was reached.
    MaxGenerations,
    /// A user [`StopCriterion`] asked to stop.
    Custom,
}

/// Stagnation rule: stop once `generations` consecutive generations brought
/// no improvement of the best value by more than `tolerance` (absolute).
///
/// A generation improves when `best_f < reference - tolerance`, where
/// `reference` is the best value at the last improvement (initially the best
/// of the initial population); the reference then moves to the new best.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Stagnation {
    /// Number `K >= 1` of generations without improvement that stops the run.
    pub generations: u64,
    /// Absolute improvement tolerance, finite and `>= 0`.
    pub tolerance: f64,
}

/// The built-in stopping rules. A run stops after the first generation
/// (possibly generation 0, the initial population) at which any enabled rule
/// holds; if several hold at once the reason reported is the first in this
/// order: target, evaluation budget, stagnation, generation limit, custom
/// criteria.
///
/// At least one of `max_generations` and `max_evaluations` must be set.
/// Default: `max_generations = Some(1000)`, everything else off.
///
/// ```
/// use mbd_firefly::Termination;
/// let t = Termination::default()
///     .max_generations(500)
///     .max_evaluations(20_000)
///     .target(1e-10)
///     .stagnation(50, 1e-12);
/// assert_eq!(t.max_evaluations, Some(20_000));
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Termination {
    /// Stop after this many generations (0: evaluate the initial population only).
    pub max_generations: Option<u64>,
    /// Never call the objective more than this many times (`>= 1`). When the
    /// budget runs out inside a generation, that generation is cut short:
    /// fireflies that could not be evaluated keep their previous position and
    /// brightness, and the run stops with [`StopReason::EvaluationBudget`].
    pub max_evaluations: Option<u64>,
    /// Stop as soon as the best value is `<= target` (must not be NaN).
    pub target: Option<f64>,
    /// Stop on stagnation, see [`Stagnation`].
    pub stagnation: Option<Stagnation>,
}

impl Default for Termination {
    fn default() -> Self {
        Self {
            max_generations: Some(1000),
            max_evaluations: None,
            target: None,
            stagnation: None,
        }
    }
}

impl Termination {
    /// Same as [`Termination::default`] (1000 generations).
    pub fn new() -> Self {
        Self::default()
    }

    /// No rule enabled; add at least a generation limit or a budget before use.
    pub fn none() -> Self {
        Self {
            max_generations: None,
            max_evaluations: None,
            target: None,
            stagnation: None,
        }
    }

    /// Sets the generation limit.
    #[must_use]
    pub fn max_generations(mut self, generations: u64) -> Self {
        self.max_generations = Some(generations);
        self
    }

    /// Sets the evaluation budget.
    #[must_use]
    pub fn max_evaluations(mut self, evaluations: u64) -> Self {
        self.max_evaluations = Some(evaluations);
        self
    }

    /// Sets the target value.
    #[must_use]
    pub fn target(mut self, target: f64) -> Self {
        self.target = Some(target);
        self
    }

    /// Enables the stagnation rule.
    #[must_use]
    pub fn stagnation(mut self, generations: u64, tolerance: f64) -> Self {
        self.stagnation = Some(Stagnation {
            generations,
            tolerance,
        });
        self
    }

    /// Checks the rules for consistency.
    ///
    /// # Errors
    /// [`FireflyError::Unbounded`] if neither a generation limit nor a budget
    /// is set; [`FireflyError::InvalidParameter`] for a zero budget, a NaN
    /// target, a zero stagnation window or a negative / non-finite tolerance.
    pub fn validate(&self) -> Result<(), FireflyError> {
        if self.max_generations.is_none() && self.max_evaluations.is_none() {
            return Err(FireflyError::Unbounded);
        }
        if self.max_evaluations == Some(0) {
            return Err(FireflyError::InvalidParameter {
                name: "max_evaluations",
                value: 0.0,
                requirement: ">= 1",
            });
        }
        if let Some(t) = self.target {
            if t.is_nan() {
                return Err(FireflyError::InvalidParameter {
                    name: "target",
                    value: t,
                    requirement: "not NaN",
                });
            }
        }
        if let Some(s) = self.stagnation {
            if s.generations == 0 {
                return Err(FireflyError::InvalidParameter {
                    name: "stagnation.generations",
                    value: 0.0,
                    requirement: ">= 1",
                });
            }
            if !(s.tolerance.is_finite() && s.tolerance >= 0.0) {
                return Err(FireflyError::InvalidParameter {
                    name: "stagnation.tolerance",
                    value: s.tolerance,
                    requirement: "finite and >= 0",
                });
            }
        }
        Ok(())
    }
}

/// A user-defined stopping rule, consulted after the built-in ones; returning
/// `true` stops the run with [`StopReason::Custom`].
///
/// Implemented for every `FnMut(&GenerationRecord) -> bool`.
pub trait StopCriterion {
    /// Whether to stop after the generation described by `record`.
    fn should_stop(&mut self, record: &GenerationRecord) -> bool;
}

impl<F> StopCriterion for F
where
    F: FnMut(&GenerationRecord) -> bool,
{
    fn should_stop(&mut self, record: &GenerationRecord) -> bool {
        self(record)
    }
}

/// Running state of the built-in rules (only stagnation needs memory).
#[derive(Debug, Clone)]
pub(crate) struct TerminationState {
    rules: Termination,
    reference: f64,
    since_improvement: u64,
}

impl TerminationState {
    pub(crate) fn new(rules: Termination) -> Self {
        Self {
            rules,
            reference: f64::INFINITY,
            since_improvement: 0,
        }
    }

    /// Evaluates the built-in rules after a generation.
    pub(crate) fn check(&mut self, r: &GenerationRecord) -> Option<StopReason> {
        if let Some(s) = self.rules.stagnation {
            // Generation 0 sets the reference; later ones must beat it by
            // more than the tolerance.
            if r.generation == 0 || r.best_f < self.reference - s.tolerance {
                self.reference = r.best_f;
                self.since_improvement = 0;
            } else {
                self.since_improvement += 1;
            }
        }
        if let Some(t) = self.rules.target {
            if r.best_f <= t {
                return Some(StopReason::TargetReached);
            }
        }
        if let Some(b) = self.rules.max_evaluations {
            if r.evaluations >= b {
                return Some(StopReason::EvaluationBudget);
            }
        }
        if let Some(s) = self.rules.stagnation {
            if self.since_improvement >= s.generations {
                return Some(StopReason::Stagnation);
            }
        }
        if let Some(g) = self.rules.max_generations {
            if r.generation >= g {
                return Some(StopReason::MaxGenerations);
            }
        }
        None
    }

    /// Evaluations still allowed, `None` for unlimited.
    pub(crate) fn remaining(&self, evaluations: u64) -> Option<u64> {
        self.rules
            .max_evaluations
            .map(|b| b.saturating_sub(evaluations))
    }
}
