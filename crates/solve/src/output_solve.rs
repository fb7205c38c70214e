//! The index-1 solve at an output state, shared by everything one output row needs from it:
//! the reactions (multipliers), the sensors (accelerations) and the energy balance (the
//! drivers' power `lambda . Phi_t`). One solve per state instead of one per consumer.

use crate::accel::Accel;
use crate::error::SolveError;
use crate::sparse::LinearSolver;
use crate::state::State;
use mbd_model::System;

/// Accelerations and multipliers of the index-1 equations at a state, cached for the last
/// state asked for (same time, coordinates and velocities: no second solve).
///
/// ```
/// use mbd_solve::{OutputSolve, State};
/// let sys = mbd_model::models::pendulum(1.0, 1.0, 0.3, 9.81)?;
/// let s = State::consistent(&sys, 0.0)?;
/// let mut out = OutputSolve::new(&sys)?;
/// let (a, lambda) = out.at(&sys, &s)?;
/// assert_eq!((a.len(), lambda.len()), (3, 2));
/// assert_eq!(out.solves(), 1);
/// out.at(&sys, &s)?; // the same state: served from the cache
/// assert_eq!(out.solves(), 1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct OutputSolve {
    acc: Accel,
    a: Vec<f64>,
    lambda: Vec<f64>,
    /// The state of the cached solution: `t`, then `q` and `v`.
    key: Option<f64>,
    key_qv: Vec<f64>,
    solves: usize,
    /// The model's redundant equations, and whether the last solve dropped more rows.
    redundant: usize,
    indeterminate: bool,
}

impl OutputSolve {
    /// A workspace for `sys` (dense or sparse by its size).
    pub fn new(sys: &System) -> Result<Self, SolveError> {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        Ok(OutputSolve {
            acc: Accel::new(sys, LinearSolver::Auto)?,
            a: vec![0.0; n],
            lambda: vec![0.0; m],
            key: None,
            key_qv: vec![0.0; 2 * n],
            solves: 0,
            redundant: sys.n_redundant(),
            indeterminate: false,
        })
    }

    /// `(accelerations, multipliers)` at `state`: solved, or the cached ones when `state` is
    /// the state of the last call. Errors: a state of the wrong size, or a singular
    /// configuration ([`SolveError`] from the index-1 solve).
    pub fn at(&mut self, sys: &System, state: &State) -> Result<(&[f64], &[f64]), SolveError> {
        state.check(sys)?;
        let n = sys.n_coords();
        let (q, v) = (state.q.as_slice(), state.v.as_slice());
        let cached = self.key == Some(state.t)
            && self.key_qv.len() == 2 * n
            && self.key_qv[..n] == *q
            && self.key_qv[n..] == *v;
        if !cached {
            self.key = None;
            self.acc
                .solve(sys, q, v, state.t, &mut self.a, &mut self.lambda)?;
            self.indeterminate = self.acc.dropped() > self.redundant;
            self.key_qv[..n].copy_from_slice(q);
            self.key_qv[n..].copy_from_slice(v);
            self.key = Some(state.t);
            self.solves += 1;
        }
        Ok((&self.a, &self.lambda))
    }

    /// The workspace in `slot`, built for `sys` on first use (for owners that need it only
    /// sometimes).
    pub fn lazy<'a>(
        slot: &'a mut Option<OutputSolve>,
        sys: &System,
    ) -> Result<&'a mut OutputSolve, SolveError> {
        match slot {
            Some(s) => Ok(s),
            None => Ok(slot.insert(OutputSolve::new(sys)?)),
        }
    }

    /// Whether the multipliers of the last [`OutputSolve::at`] are not determined by its
    /// state: its factorisation dropped more dependent rows than the model's redundant
    /// equations, so the state is a singular configuration (a start on one:
    /// [`System::singular_start_equations`]). The accelerations are determined there; the
    /// multipliers are one solution of many, not the limit along the motion, and the
    /// reactions and drivers' power from them are not the motion's.
    pub fn indeterminate(&self) -> bool {
        self.indeterminate
    }

    /// How many index-1 solves [`OutputSolve::at`] has made.
    pub fn solves(&self) -> usize {
        self.solves
    }
}
