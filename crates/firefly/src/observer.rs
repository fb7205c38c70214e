//! Per-generation observation.

/// Summary of the swarm after a generation, handed to every
/// [`Observer`] and [`StopCriterion`](crate::StopCriterion).
///
/// Generation 0 is the evaluated initial population.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct GenerationRecord {
    /// Generations completed (0 for the initial population).
    pub generation: u64,
    /// Best objective value found so far (over the whole run, not only the
    /// current population); `+inf` while every evaluation was non-finite.
    pub best_f: f64,
    /// Mean objective value over the finite values of the current population
    /// (NaN if none is finite).
    pub mean_f: f64,
    /// Randomisation strength that was used in this generation (for
    /// generation 0: the initial `alpha`).
    pub alpha: f64,
    /// Objective evaluations so far.
    pub evaluations: u64,
    /// Non-finite objective values so far.
    pub nan_evaluations: u64,
}

/// Receives a [`GenerationRecord`] after the initial population is evaluated
/// and after every generation.
///
/// Implemented for every `FnMut(&GenerationRecord)`; see [`History`] for a
/// ready-made recorder.
pub trait Observer {
    /// Called once per generation, in order.
    fn observe(&mut self, record: &GenerationRecord);
}

impl<F> Observer for F
where
    F: FnMut(&GenerationRecord),
{
    fn observe(&mut self, record: &GenerationRecord) {
        self(record)
    }
}

/// An [`Observer`] that stores every record.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct History {
    /// Records in generation order, starting with generation 0.
    pub records: Vec<GenerationRecord>,
}

impl History {
    /// An empty history.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of records.
    pub fn len(&self) -> usize {
        self.records.len()
    }

    /// Whether nothing has been recorded.
    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// The best-so-far value of every record, in order.
    pub fn best_values(&self) -> Vec<f64> {
        self.records.iter().map(|r| r.best_f).collect()
    }
}

impl Observer for History {
    fn observe(&mut self, record: &GenerationRecord) {
        self.records.push(*record);
    }
}
