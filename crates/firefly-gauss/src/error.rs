//! The crate's error type.

use mbd_firefly::FireflyError;
use mbd_solve::SolveError;
use thiserror::Error;

/// Everything that can go wrong when configuring [`FireflyGauss`](crate::FireflyGauss) or
/// taking a step. Configuration errors are reported by
/// [`FireflyGauss::new`](crate::FireflyGauss::new) before anything is integrated; step errors
/// are returned by [`FireflyGauss::try_step`](crate::FireflyGauss::try_step) and converted to
/// [`SolveError`] by the [`Integrator`](mbd_solve::Integrator) implementation.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum FaDaeError {
    /// A numeric option is outside its valid range.
    #[error("invalid option `{name}` = {}: must be {requirement}", mbd_model::format_number(*value))]
    InvalidOption {
        /// The option (field path in [`FaDaeOptions`](crate::FaDaeOptions)).
        name: &'static str,
        /// The value given.
        value: f64,
        /// The valid range.
        requirement: &'static str,
    },
    /// The firefly settings or termination rules are invalid (checked with the optimiser's own
    /// validation, before the first step).
    #[error("invalid firefly settings: {0}")]
    Firefly(#[from] FireflyError),
    /// User-given independent coordinates are unusable.
    #[error("invalid independent coordinates {given:?}: {reason}")]
    InvalidPartition {
        /// The indices given.
        given: Vec<usize>,
        /// What is wrong.
        reason: String,
    },
    /// The system has no degree of freedom (nothing to optimise) or is not supported.
    #[error("unsupported system: {0}")]
    Unsupported(String),
    /// An error of the solver core (singular constraint block, non-finite state, wrong-size
    /// state, invalid step size, ...).
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The optimiser stopped without reaching the step's target and
    /// [`MissPolicy::Error`](crate::MissPolicy::Error) is set.
    #[error(
        "firefly did not reach the target at t = {t}: best objective {best:e} > target {target:e} \
         after {generations} generations ({reason})"
    )]
    TargetMissed {
        /// Start time of the step.
        t: f64,
        /// Best objective value found.
        best: f64,
        /// The step's target.
        target: f64,
        /// Generations run (over all attempts of the step).
        generations: u64,
        /// Why the optimiser stopped.
        reason: String,
    },
    /// Every candidate the optimiser tried was infeasible (the dependent coordinates could not be
    /// completed), so no state can be accepted.
    #[error("no feasible candidate at t = {t}: the dependent coordinates could not be completed by Newton anywhere in the box")]
    NoFeasibleCandidate {
        /// Start time of the step.
        t: f64,
    },
}

impl From<FaDaeError> for SolveError {
    fn from(e: FaDaeError) -> SolveError {
        match e {
            FaDaeError::Solve(s) => s,
            FaDaeError::InvalidOption { name, value, .. } => SolveError::InvalidParameter {
                parameter: name,
                value,
                reason: "invalid FA-DAE option (see mbd-firefly-gauss docs)",
            },
            FaDaeError::TargetMissed {
                t,
                best,
                generations,
                reason,
                target,
            } => SolveError::Newton {
                t,
                residual: best.sqrt(),
                iterations: generations as usize,
                context: format!("FA-DAE firefly missed the target {target:e} ({reason})"),
            },
            // (the refusal's own words: SolveError's display adds "unsupported model")
            FaDaeError::Unsupported(reason) => SolveError::Unsupported(reason),
            // not a refusal of the model: the search box around the predicted end state holds
            // no point whose dependent coordinates Newton can complete, which is what a step
            // too long for the motion does (the box follows the step's motion; the models
            // that fail so at h = 0.3 run at h = 0.05)
            FaDaeError::NoFeasibleCandidate { t } => SolveError::Newton {
                t,
                residual: f64::INFINITY,
                iterations: 0,
                context: "FA-DAE: no feasible candidate in the search box, the predicted end \
                          state included (the dependent coordinates could not be completed \
                          by Newton anywhere in it); a smaller h may converge (the step may be \
                          too long for the motion)"
                    .into(),
            },
            other => SolveError::Unsupported(other.to_string()),
        }
    }
}
