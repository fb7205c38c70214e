//! What FA-DAE steps did: per-step information and run statistics.

use mbd_firefly::StopReason;

/// What one step did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepInfo {
    /// Start time of the step.
    pub t: f64,
    /// Step size.
    pub h: f64,
    /// Objective at the predictor (the centre of the first box).
    pub objective_predictor: f64,
    /// Best objective found by the firefly algorithm.
    pub objective_firefly: f64,
    /// Objective of the accepted state (after the polish, if on).
    pub objective_final: f64,
    /// The step's target: `max(tolerance * objective_predictor, floor)`.
    pub target: f64,
    /// Whether the firefly reached the target (`objective_firefly <= target`).
    pub reached_target: bool,
    /// Why the (last) firefly run stopped.
    pub stop_reason: StopReason,
    /// Firefly generations, over all runs of the step.
    pub generations: u64,
    /// Objective evaluations of the firefly runs.
    pub evaluations: u64,
    /// Box widenings (the best point was at a face of the box).
    pub expansions: u32,
    /// Firefly runs (stages) of the step.
    pub stages: u32,
    /// Gauss-Newton iterations of the polish (0 when off).
    pub polish_iterations: usize,
    /// Objective evaluations of the polish.
    pub polish_evaluations: usize,
    /// Whether the partition was re-chosen at this step.
    pub repartitioned: bool,
    /// Auto partitioning: `|det Phi_d| / |det Phi_best|` at the step's start, before any
    /// re-choice, where `Phi_d` is the dependent block of `Phi_q` in use and `Phi_best` the
    /// block that complete pivoting of `Phi_q` picks (capped at 1; 1 when `Phi_q` is rank
    /// deficient). NaN for a user-given partition.
    pub partition_quality: f64,
}

impl Default for StepInfo {
    fn default() -> Self {
        StepInfo {
            t: 0.0,
            h: 0.0,
            objective_predictor: 0.0,
            objective_firefly: 0.0,
            objective_final: 0.0,
            target: 0.0,
            reached_target: true,
            stop_reason: StopReason::TargetReached,
            generations: 0,
            evaluations: 0,
            expansions: 0,
            stages: 0,
            polish_iterations: 0,
            polish_evaluations: 0,
            repartitioned: false,
            partition_quality: f64::NAN,
        }
    }
}

/// Totals over the steps since the last [`Integrator::reset`](mbd_solve::Integrator::reset) (the
/// run loop resets before the first step, so these are per run).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FaDaeStats {
    /// Steps taken.
    pub steps: u64,
    /// Firefly generations.
    pub generations: u64,
    /// Objective evaluations (firefly, polish and the predictor's).
    pub evaluations: u64,
    /// Box re-runs.
    pub expansions: u64,
    /// Steps whose firefly stopped above the target (accepted under
    /// [`MissPolicy::Accept`](crate::MissPolicy::Accept)).
    pub target_misses: u64,
    /// Partition changes.
    pub repartitions: u64,
    /// Gauss-Newton iterations of the polish.
    pub polish_iterations: u64,
    /// Smallest ratio `objective(predictor) / max(objective(firefly result), floor)` of a
    /// counted step.
    pub min_ratio: f64,
    /// Steps whose predictor was already within a factor 100 of the objective's round-off
    /// floor (no 100-fold reduction is measurable there); left out of the ratio statistics.
    pub roundoff_steps: u64,
    /// Sum of `ln(ratio)` over the counted steps.
    pub log_ratio_sum: f64,
    /// Number of counted steps.
    pub ratio_count: u64,
    /// Largest objective of an accepted state.
    pub max_objective: f64,
}

impl FaDaeStats {
    pub(crate) fn new() -> Self {
        FaDaeStats {
            min_ratio: f64::INFINITY,
            ..Default::default()
        }
    }

    /// Geometric mean of `objective(predictor) / objective(firefly result)` over the steps (the
    /// arithmetic mean is dominated by single huge ratios; both are "much larger than 100" when
    /// the optimiser does the work).
    pub fn mean_ratio(&self) -> f64 {
        if self.ratio_count == 0 {
            f64::NAN
        } else {
            (self.log_ratio_sum / self.ratio_count as f64).exp()
        }
    }

    /// Mean generations per step.
    pub fn mean_generations(&self) -> f64 {
        self.generations as f64 / (self.steps.max(1)) as f64
    }
}
