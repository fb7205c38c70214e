//! Joint reactions: the force and moment each joint exerts on its second body, from the
//! multipliers of the index-1 equations at a state.
//!
//! With `M a = Q - Phi_q^T lambda`, the constraint force on the coordinates is
//! `-Phi_q^T lambda`, and joint `j`'s share is `-Phi_q,j^T lambda_j` (its own rows). On a body
//! `(x, y, theta)` that share is a force `F` (the `x`, `y` entries) and a moment about the
//! centre of mass `tau` (the `theta` entry); about any point `P` of the plane the moment is
//! `M_P = tau + (r - P) x F`. [`ReactionSolver`] reports, for every joint, `F` and `M_P` on its
//! second body (`b`) with `P` the joint's point on that body (its centre of mass for joints
//! without a point: angle drivers and absolute constraints), in global axes and in `b`'s body
//! axes. A joint whose second side is ground reports the load on the ground: by action and
//! reaction the negative of its load on the first body, about the same point.
//!
//! The multipliers come from the index-1 solve at the state `(q, v, t)`: the reactions that
//! give the state's own accelerations. They are point values at the output time for every
//! solver (a symplectic step's multipliers are stage impulses, not values at the step's end),
//! accurate to the solver's order through the state. Where constraint equations are redundant,
//! the dependent equations carry zero multipliers (the basic solution): the total load on each
//! body is unique, how it splits between redundant joints is not (a rigid model does not
//! determine it), and the reported split puts it on the joints of the independent equations
//! (docs/architecture.md, "Redundant constraints").

use crate::error::SolveError;
use crate::output_solve::OutputSolve;
use crate::state::State;
use mbd_model::{JointElement, System};

/// The load a joint exerts on its second body (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointReaction {
    /// Force on the second body, global axes (N).
    pub force: [f64; 2],
    /// Force on the second body in its body axes (global axes for ground) (N).
    pub local_force: [f64; 2],
    /// Moment on the second body about the joint's point on it (N m).
    pub moment: f64,
    /// The point the moment is taken about, global coordinates (m).
    pub point: [f64; 2],
}

/// Computes [`JointReaction`]s at states of a run; a workspace allocated once (dense or sparse
/// index-1 solve by the constraint count, as the solvers').
///
/// ```
/// use mbd_solve::{JointReaction, ReactionSolver, State};
/// // a pendulum at rest, hanging straight down: the pin carries the weight, m g = 9.81 N
/// let sys = mbd_model::models::pendulum(1.0, 1.0, 0.0, 9.81)?;
/// let s = State::consistent(&sys, 0.0)?;
/// let mut rs = ReactionSolver::new(&sys)?;
/// let mut out = vec![JointReaction::default(); sys.joints().len()];
/// rs.compute(&sys, &s, &mut out)?;
/// // the pin's second side is the rod: the pin holds up its weight, 9.81 N upwards, which
/// // in the rod's axes (its x axis pointing down from the pin) is -9.81 N along x
/// assert!(out[0].force[0].abs() < 1e-12 && (out[0].force[1] - 9.81).abs() < 1e-12);
/// assert!((out[0].local_force[0] + 9.81).abs() < 1e-12);
/// assert!(out[0].moment.abs() < 1e-12);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct ReactionSolver {
    /// The index-1 solve, built at the first use of [`ReactionSolver::compute`] or
    /// [`ReactionSolver::multipliers`] (not needed by [`ReactionSolver::compute_with`]).
    solve: Option<OutputSolve>,
    grads: Vec<[f64; 6]>,
}

impl ReactionSolver {
    /// A workspace for `sys`.
    pub fn new(sys: &System) -> Result<Self, SolveError> {
        Ok(ReactionSolver {
            solve: None,
            grads: vec![[0.0; 6]; sys.n_constraints()],
        })
    }

    /// The multipliers `lambda` (one per constraint equation, in the order of
    /// [`System::equation_names`]) at `state`; errors as the index-1 solve (a singular
    /// configuration names its equation).
    pub fn multipliers(&mut self, sys: &System, state: &State) -> Result<&[f64], SolveError> {
        Ok(OutputSolve::lazy(&mut self.solve, sys)?.at(sys, state)?.1)
    }

    /// The reactions of every joint (in the order of [`System::joints`]) at `state` into
    /// `out`, which must have one entry per joint.
    pub fn compute(
        &mut self,
        sys: &System,
        state: &State,
        out: &mut [JointReaction],
    ) -> Result<(), SolveError> {
        let (_, lambda) = OutputSolve::lazy(&mut self.solve, sys)?.at(sys, state)?;
        joint_reactions(&mut self.grads, sys, state, lambda, out)
    }

    /// [`ReactionSolver::compute`] from the multipliers `lambda` at `state` solved elsewhere
    /// (an [`OutputSolve`] shared with other outputs of the same row).
    pub fn compute_with(
        &mut self,
        sys: &System,
        state: &State,
        lambda: &[f64],
        out: &mut [JointReaction],
    ) -> Result<(), SolveError> {
        state.check(sys)?;
        if lambda.len() != sys.n_constraints() {
            return Err(SolveError::Dimension {
                what: "lambda",
                expected: sys.n_constraints(),
                got: lambda.len(),
            });
        }
        joint_reactions(&mut self.grads, sys, state, lambda, out)
    }
}

/// The joints' reactions from the multipliers (see the module docs).
pub(crate) fn joint_reactions(
    grads: &mut [[f64; 6]],
    sys: &System,
    state: &State,
    lambda: &[f64],
    out: &mut [JointReaction],
) -> Result<(), SolveError> {
    if out.len() != sys.joints().len() {
        return Err(SolveError::Dimension {
            what: "reactions (one per joint)",
            expected: sys.joints().len(),
            got: out.len(),
        });
    }
    let q = state.q.as_slice();
    sys.phi_q_local(q, grads);
    let body = |i: usize| ([q[3 * i], q[3 * i + 1]], q[3 * i + 2]);
    let global = |i: Option<usize>, p: [f64; 2]| match i {
        Some(i) => {
            let (r, th) = body(i);
            let (s, c) = th.sin_cos();
            [r[0] + c * p[0] - s * p[1], r[1] + s * p[0] + c * p[1]]
        }
        None => p,
    };
    for (JointElement { joint, attach, row }, res) in sys.joint_elements().zip(out.iter_mut()) {
        // the joint's generalised force on each side: -Phi_q,j^T lambda_j
        let mut g = [0.0; 6];
        for k in 0..joint.n_equations() {
            let l = lambda[row + k];
            for (gi, &d) in g.iter_mut().zip(&grads[row + k]) {
                *gi -= l * d;
            }
        }
        let sketch = joint.sketch();
        // the load on side b, or by action and reaction the negative of side a's
        let (side, f, tau, sign) = match attach.b {
            Some(_) => (attach.b, [g[3], g[4]], g[5], 1.0),
            None => (attach.a, [g[0], g[1]], g[2], -1.0),
        };
        let point = match sketch.point_b {
            Some(p) => global(attach.b, p),
            None => attach.b.or(attach.a).map_or([0.0; 2], |i| body(i).0),
        };
        // the moment about the point of the side the force acts on
        let centre = side.map_or(point, |i| body(i).0);
        let m = tau + (centre[0] - point[0]) * f[1] - (centre[1] - point[1]) * f[0];
        let force = [sign * f[0], sign * f[1]];
        let local_force = match attach.b {
            Some(i) => {
                let (s, c) = body(i).1.sin_cos();
                [c * force[0] + s * force[1], -s * force[0] + c * force[1]]
            }
            None => force,
        };
        *res = JointReaction {
            force,
            local_force,
            moment: sign * m,
            point,
        };
    }
    Ok(())
}
