//! The first step from a singular configuration. A chart cannot be centred where `Phi_q` loses
//! rank (its dimension would change), but a mechanism may start there (a parallelogram
//! four-bar with its cranks in line with the ground): such a step is taken by projected RK of
//! the integrator's own tableau on the index-1 form ([`mbd_solve::SingularStarter`]), of the
//! same order, and the chart takes over at its end point, off the singular configuration
//! (docs/singular.md section 6).

use super::*;
use mbd_solve::SingularStarter;

impl TangentRk {
    /// Whether `e`, returned by a step from `t`, is the chart's refusal of a singular
    /// configuration at the step's start (its centre), which the starter can take.
    pub(super) fn singular_at_start(e: &SolveError, t: f64) -> bool {
        SingularStarter::refused_at_start(e, t)
    }

    /// A fixed step of size `h` from the singular configuration `state` by the starter; the
    /// chart's refusal `refused` is returned if the starter fails too (a configuration where
    /// the accelerations are not determined either).
    pub(super) fn starter_step(
        &mut self,
        sys: &System,
        state: &mut State,
        h: f64,
        refused: SolveError,
    ) -> Result<StepStats, SolveError> {
        let stats = self.starter.step(sys, state, h, refused)?;
        self.after_starter();
        Ok(stats)
    }

    /// An adaptive attempt of size `h` from the singular configuration `state` by the
    /// starter (its embedded error estimate judges it); `refused` as in
    /// [`TangentRk::starter_step`].
    pub(super) fn starter_attempt(
        &mut self,
        sys: &System,
        state: &mut State,
        h: f64,
        ctrl: &StepController,
        refused: SolveError,
    ) -> Result<StepAttempt, SolveError> {
        let a = self.starter.attempt(sys, state, h, ctrl, refused)?;
        if a.accepted {
            self.after_starter();
        }
        Ok(a)
    }

    /// The chart takes over at the starter's end point: loaded and checked at the next step
    /// like a state handed in.
    fn after_starter(&mut self) {
        self.cur_ok = false;
        self.hist.clear();
        self.centred_at = f64::NAN;
        self.failures_here = 0;
        self.stats.steps += 1;
        self.stats.starter_steps += 1;
    }
}
