//! The first step from a singular configuration, for integrators whose own step cannot be
//! taken there.
//!
//! A mechanism may start where `Phi_q` loses rank (a parallelogram four-bar with its cranks in
//! line with the ground, `System::singular_start_equations`). Some methods cannot step from
//! such a point: a tangent chart cannot be centred where the manifold's dimension changes, and
//! the (1,1) symplectic scheme's end-point equations `Phi(q_1) = 0` get their constraint forces
//! along `Phi_q(q_0)^T` only, one direction short per dependent equation, so they have no
//! solution (the residual stalls at `O(h^3)`). Projected RK on the index-1 form can: its
//! acceleration solve drops the rows dependent at the start (`System::dependency_budget`)
//! and the projection puts the end point back on the constraints. [`SingularStarter`] takes
//! that one step with a tableau the integrator chooses (of at least its own order), and the
//! integrator takes over at its end point, off the singular configuration (docs/singular.md
//! section 6).

use crate::adaptive::{AdaptiveIntegrator, StepAttempt};
use crate::error::SolveError;
use crate::index1::{Index1Options, Index1Rk};
use crate::integrator::{Integrator, StepStats};
use crate::projection::ProjectionSettings;
use crate::state::State;
use crate::tableau::{ButcherTableau, StepController};
use mbd_model::System;

/// Projected RK of a given tableau for the first step from a singular configuration (see the
/// module doc); the index-1 integrator is built on first use, so an integrator that never
/// starts on one pays nothing.
#[derive(Debug)]
pub struct SingularStarter {
    tableau: ButcherTableau,
    rk: Option<Box<Index1Rk>>,
}

impl SingularStarter {
    /// A starter that steps with `tableau` (projection after every step, default settings).
    pub fn new(tableau: ButcherTableau) -> Self {
        SingularStarter { tableau, rk: None }
    }

    /// Whether `e`, returned by a step from time `t`, is a refusal of a singular configuration
    /// at the step's start ([`SolveError::Singular`] at `t` itself), which the starter may
    /// take.
    pub fn refused_at_start(e: &SolveError, t: f64) -> bool {
        matches!(e, SolveError::Singular { t: at, .. } if *at == t)
    }

    /// Whether `state` is a singular configuration of a model that starts on one
    /// (`System::singular_start_equations`): `Phi_q` there has more dependent rows than the
    /// model's redundant equations (`System::redundant_at`, a rank test; the caller gates it
    /// to the steps that may start there).
    pub fn at_singular_start(sys: &System, state: &State) -> Result<bool, SolveError> {
        if sys.singular_start_equations().is_empty() || state.q.len() != sys.n_coords() {
            return Ok(false);
        }
        Ok(sys.redundant_at(state.q.as_slice(), state.t)?.len() > sys.n_redundant())
    }

    /// Whether a step from `state` that failed with `e` is the starter's to take: a refusal at
    /// the step's start ([`SingularStarter::refused_at_start`]) on a singular configuration of
    /// a model that starts on one ([`SingularStarter::at_singular_start`], run only then).
    pub fn takes(e: &SolveError, sys: &System, state: &State) -> Result<bool, SolveError> {
        Ok(Self::refused_at_start(e, state.t) && Self::at_singular_start(sys, state)?)
    }

    /// Forgets the state of the index-1 integrator (a run starts afresh).
    pub fn reset(&mut self) {
        if let Some(rk) = self.rk.as_deref_mut() {
            rk.reset();
        }
    }

    fn integrator(&mut self, sys: &System) -> Result<&mut Index1Rk, SolveError> {
        let rk = match self.rk.take() {
            Some(rk) => rk,
            None => {
                let opts = Index1Options {
                    projection: Some(ProjectionSettings::default()),
                    ..Index1Options::default()
                };
                Box::new(Index1Rk::new(sys, self.tableau.clone(), opts)?)
            }
        };
        Ok(self.rk.insert(rk))
    }

    /// A fixed step of size `h` from `state`. On failure `state` is unchanged and `refused`
    /// (the integrator's own refusal, which says more to the user than the starter's) is
    /// returned.
    pub fn step(
        &mut self,
        sys: &System,
        state: &mut State,
        h: f64,
        refused: SolveError,
    ) -> Result<StepStats, SolveError> {
        let mut trial = state.clone();
        let stats = match self.integrator(sys)?.step(sys, &mut trial, h) {
            Ok(s) => s,
            Err(_) => return Err(refused),
        };
        *state = trial;
        Ok(stats)
    }

    /// An adaptive attempt of size `h` from `state`, judged by the tableau's embedded error
    /// estimate (the tableau must have one); `state` moves only if the attempt is accepted.
    /// On failure `refused` is returned, as by [`SingularStarter::step`].
    pub fn attempt(
        &mut self,
        sys: &System,
        state: &mut State,
        h: f64,
        ctrl: &StepController,
        refused: SolveError,
    ) -> Result<StepAttempt, SolveError> {
        let mut trial = state.clone();
        let a = match self.integrator(sys)?.attempt_step(sys, &mut trial, h, ctrl) {
            Ok(a) => a,
            Err(_) => return Err(refused),
        };
        if a.accepted {
            *state = trial;
        }
        Ok(a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mbd_model::models::parallelogram_four_bar;

    #[test]
    fn only_a_singular_refusal_at_the_step_start_goes_to_the_starter() {
        let singular = |t| SolveError::Singular {
            t,
            what: "x",
            detail: String::new(),
        };
        assert!(SingularStarter::refused_at_start(&singular(0.5), 0.5));
        assert!(!SingularStarter::refused_at_start(&singular(0.6), 0.5));
        assert!(!SingularStarter::refused_at_start(
            &SolveError::InvalidStep { h: 0.0 },
            0.5
        ));
    }

    #[test]
    fn the_flat_start_is_singular_and_the_state_a_step_later_is_not() {
        let sys = parallelogram_four_bar(0.4, 1.0, 0.0, 6.0, false).unwrap();
        let s0 = State::consistent(&sys, 0.0).unwrap();
        assert!(SingularStarter::at_singular_start(&sys, &s0).unwrap());
        let refusal = |t| SolveError::Singular {
            t,
            what: "x",
            detail: String::new(),
        };
        assert!(SingularStarter::takes(&refusal(0.0), &sys, &s0).unwrap());
        assert!(!SingularStarter::takes(&refusal(1.0), &sys, &s0).unwrap());
        let mut starter = SingularStarter::new(ButcherTableau::dopri5());
        let mut s1 = s0.clone();
        let refused = SolveError::InvalidStep { h: 1e-3 };
        starter.step(&sys, &mut s1, 1e-3, refused).unwrap();
        assert!((s1.t - 1e-3).abs() < 1e-15);
        assert!(!SingularStarter::at_singular_start(&sys, &s1).unwrap());
        // a model that does not start on a singular configuration: never
        let regular = parallelogram_four_bar(0.4, 1.0, 1.0, 6.0, false).unwrap();
        let r0 = State::consistent(&regular, 0.0).unwrap();
        assert!(!SingularStarter::at_singular_start(&regular, &r0).unwrap());
        assert!(!SingularStarter::takes(&refusal(0.0), &regular, &r0).unwrap());
    }
}
