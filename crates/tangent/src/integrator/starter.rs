//! The first step from a singular configuration. A chart cannot be centred where `Phi_q` loses
//! rank (its dimension would change), but a mechanism may start there (a parallelogram
//! four-bar with its cranks in line with the ground): such a step is taken by projected RK of
//! the integrator's own tableau on the index-1 form ([`mbd_solve::SingularStarter`]), of the
//! same order, and the chart takes over at its end point, off the singular configuration
//! (docs/singular.md section 6). A step or an adaptive attempt that the chart refuses at its
//! start (`SingularStarter::refused_at_start`: no chart can be centred there) goes to
//! `self.starter` (its failure returns the chart's refusal), and an accepted one to
//! [`TangentRk::after_starter`].

use super::*;

impl TangentRk {
    /// The chart takes over at the starter's end point: loaded and checked at the next step
    /// like a state handed in.
    pub(super) fn after_starter(&mut self) {
        self.cur_ok = false;
        self.hist.clear();
        self.centred_at = f64::NAN;
        self.failures_here = 0;
        self.stats.steps += 1;
        self.stats.starter_steps += 1;
    }
}
