//! Helpers shared by the integration tests of the facade crate (each test file that needs them
//! declares `mod common;`; not every file uses every helper).
#![allow(dead_code)]

use mbd::prelude::*;
use mbd::Simulation;

/// The largest `|Phi|` at `(q, t)`.
pub fn max_phi(sys: &System, q: &[f64], t: f64) -> f64 {
    let mut phi = vec![0.0; sys.n_constraints()];
    sys.phi(q, t, &mut phi);
    phi.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// The largest `|Phi|` at a state.
pub fn max_phi_at(sys: &System, s: &State) -> f64 {
    max_phi(sys, s.q.as_slice(), s.t)
}

/// The largest `|Phi_q v + Phi_t|` at a state.
pub fn max_phi_dot_at(sys: &System, s: &State) -> f64 {
    let mut phid = vec![0.0; sys.n_constraints()];
    sys.phi_dot(s.q.as_slice(), s.v.as_slice(), s.t, &mut phid);
    phid.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// The end state of a run of `spec` on `sys` from its consistent initial state (a failure
/// names the solver).
pub fn end_state(sys: &System, spec: &str, plan: impl Into<Plan>) -> State {
    let mut sim = Simulation::new(sys.clone(), spec).unwrap_or_else(|e| panic!("{spec}: {e}"));
    sim.run(plan).unwrap_or_else(|e| panic!("{spec}: {e}"));
    sim.state().clone()
}
