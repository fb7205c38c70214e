//! Consistent initial states: a guess `(q, v)` projected onto the position and velocity
//! constraints by the one projection of the project, [`Projector`] (dense for small systems,
//! sparse above [`crate::SPARSE_THRESHOLD`] constraints), with a report of how far it moved.

use crate::error::SolveError;
use crate::linalg::{max_abs, max_abs_diff};
use crate::projection::{ProjectionSettings, Projector};
use crate::sparse::LinearSolver;
use mbd_model::System;
use nalgebra::DVector;

/// Settings of [`project_state`]: the position projection's target and iteration limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConsistentOptions {
    /// Target max-norm of `Phi`, floored at the round-off level of the coordinates
    /// (`8 eps max(1, |x, y|, |theta_guess|)`, see [`crate::PROJECTION_ROUNDOFF_FACTOR`]),
    /// which no iteration can beat (so a model placed far from the origin still projects).
    /// Default `1e-13`.
    pub tol: f64,
    /// Newton iteration limit. Default 50.
    pub max_iter: usize,
    /// Dense or sparse factorisation (default: by the constraint count).
    pub linear: LinearSolver,
}

impl Default for ConsistentOptions {
    fn default() -> Self {
        ConsistentOptions {
            tol: 1e-13,
            max_iter: 50,
            linear: LinearSolver::Auto,
        }
    }
}

/// A state on the constraint manifold, with how far the guess was moved.
#[derive(Clone, Debug)]
pub struct ConsistentState {
    /// Positions with `Phi(q, t) = 0`.
    pub q: DVector<f64>,
    /// Velocities with `Phi_q v + Phi_t = 0`.
    pub v: DVector<f64>,
    /// Max-norm of the position correction `q - q_guess`.
    pub position_correction: f64,
    /// Max-norm of the velocity correction `v - v_guess`.
    pub velocity_correction: f64,
    /// Newton iterations of the position projection.
    pub iterations: usize,
    /// Final `||Phi||_inf`.
    pub residual: f64,
    /// Final `||Phi_q v + Phi_t||_inf`.
    pub velocity_residual: f64,
}

/// Projects the bodies' stored initial state ([`System::initial_guess`]) onto the constraints
/// at time `t` (see [`project_state`]). A model with initial joint coordinates
/// ([`System::joint_initials`]) is assembled from them: the guess places the bodies along a
/// spanning tree, and the projection holds the given angles, slides and rates exactly
/// ([`System::with_joint_drivers`]).
///
/// ```
/// let sys = mbd_model::models::slider_crank()?;
/// let x0 = mbd_solve::consistent_state(&sys, 0.0)?;
/// assert!(x0.residual <= 1e-13 && x0.velocity_residual <= 1e-13);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn consistent_state(sys: &System, t: f64) -> Result<ConsistentState, SolveError> {
    let (q, v) = sys.initial_guess();
    let opts = ConsistentOptions::default();
    if sys.joint_initials().next().is_none() {
        return project_state(sys, q.as_slice(), v.as_slice(), t, opts);
    }
    // Assembly from joint coordinates: positions projected with the given angles and slides
    // held by drivers, then velocities with the given rates held (mbd_model's assembly docs).
    let held = sys.with_joint_drivers(q.as_slice(), t, false)?;
    let x = project_state(&held, q.as_slice(), v.as_slice(), t, opts)?;
    let held = sys.with_joint_drivers(x.q.as_slice(), t, true)?;
    let mut c = project_state(&held, x.q.as_slice(), v.as_slice(), t, opts)?;
    c.position_correction = max_abs_diff(c.q.as_slice(), q.as_slice());
    c.iterations += x.iterations;
    // the model's own residuals (the drivers' equations are the model's plus the held ones)
    let (mut phi, mut phid) = (
        vec![0.0; sys.n_constraints()],
        vec![0.0; sys.n_constraints()],
    );
    sys.phi(c.q.as_slice(), t, &mut phi);
    sys.phi_dot(c.q.as_slice(), c.v.as_slice(), t, &mut phid);
    c.residual = max_abs(&phi);
    c.velocity_residual = max_abs(&phid);
    Ok(c)
}

/// Projects a guess `(q, v)` onto the constraint manifold at time `t`: positions by Newton with
/// the minimum `M`-norm correction `dq = -M^-1 Phi_q^T (Phi_q M^-1 Phi_q^T)^-1 Phi`, then
/// velocities by the `M`-orthogonal projection onto `Phi_q v + Phi_t = 0` (twice, so the
/// velocity residual is at round-off). On a singular configuration (more equations dependent
/// than the model's redundant ones, at most [`mbd_model::SPARSE_RANK_THRESHOLD`] equations)
/// that projection leaves `v` free along the extra null directions, and the velocity is then
/// moved onto the nearest branch of the motion, where the accelerations exist
/// (`y^T gamma(q, v, t) = 0` for the left null vectors `y` of `Phi_q`; docs/singular.md
/// section 7). The model's inputs ([`mbd_model::Inputs`],
/// [`System::initial_inputs`]) are kept: their entries of `M^-1` are zero in both corrections,
/// so the other coordinates take up the whole correction (the smallest change of them, in
/// their mass metric).
///
/// Errors: a wrong length ([`SolveError::Dimension`] naming `q_guess` or `v_guess`), a
/// non-finite entry ([`SolveError::NonFinite`]), a Newton iteration that does not converge
/// ([`SolveError::Newton`] naming the equation with the largest residual), or a projected
/// configuration where `Phi_q` loses rank ([`mbd_model::ModelError::Redundant`] from
/// [`System::check_rank`], naming the dependent equation and its joints), or inputs that leave
/// an equation no free coordinate ([`SolveError::OverdeterminedInputs`]).
pub fn project_state(
    sys: &System,
    q_guess: &[f64],
    v_guess: &[f64],
    t: f64,
    opts: ConsistentOptions,
) -> Result<ConsistentState, SolveError> {
    let (n, m) = (sys.n_coords(), sys.n_constraints());
    for (what, x) in [("q_guess", q_guess), ("v_guess", v_guess)] {
        if x.len() != n {
            return Err(SolveError::Dimension {
                what,
                expected: n,
                got: x.len(),
            });
        }
        if x.iter().any(|v| !v.is_finite()) {
            return Err(SolveError::NonFinite {
                t,
                what: if what == "q_guess" {
                    "initial state q_guess"
                } else {
                    "initial state v_guess"
                },
            });
        }
    }
    if !(opts.tol > 0.0 && opts.tol.is_finite()) {
        return Err(SolveError::InvalidParameter {
            parameter: "ConsistentOptions::tol",
            value: opts.tol,
            reason: "must be positive and finite",
        });
    }
    let mut q = q_guess.to_vec();
    let mut v = v_guess.to_vec();
    let mut projector = Projector::with_linear(
        sys,
        ProjectionSettings {
            tol: opts.tol,
            max_iter: opts.max_iter,
        },
        opts.linear,
    )?;
    // a guess on a singular configuration slightly off the constraints is projected by the
    // pseudo-inverse where the factorisation refuses
    projector.set_min_norm_fallback(true);
    // the model's inputs: weight zero, so the projections leave them as given
    let (keep_q, keep_v) = sys.initial_inputs();
    let inputs = Inputs::new(sys, &keep_q, &keep_v);
    projector.set_weights(inputs.weights(sys, &keep_q));
    let stats = projector
        .project_positions(sys, &mut q, t)
        .map_err(|e| inputs.explain(e, "position", &keep_q))?;
    projector.set_weights(inputs.weights(sys, &keep_v));
    // Full rank at the projected configuration: the dense path proves it with the model's
    // rank check (which names the dependent joints); the sparse path's Cholesky pivot test is
    // the check, and the model's check runs only to name the joints when that test fails.
    if !projector.is_sparse() {
        sys.check_rank(&q, t)?;
    }
    for _ in 0..2 {
        if let Err(e) = projector.project_velocities(sys, &q, &mut v, t) {
            sys.check_rank(&q, t)?;
            return Err(inputs.explain(e, "velocity", &keep_v));
        }
    }
    // on a singular configuration: the velocity onto the nearest branch of the motion, then
    // once more onto the velocity constraints (round-off)
    if crate::branch::onto_branch(sys, &q, &mut v, t, &keep_v)? {
        projector
            .project_velocities(sys, &q, &mut v, t)
            .map_err(|e| inputs.explain(e, "velocity", &keep_v))?;
    }
    let mut phi = vec![0.0; m];
    let mut phid = vec![0.0; m];
    sys.phi(&q, t, &mut phi);
    sys.phi_dot(&q, &v, t, &mut phid);
    Ok(ConsistentState {
        position_correction: max_abs_diff(&q, q_guess),
        velocity_correction: max_abs_diff(&v, v_guess),
        q: DVector::from_vec(q),
        v: DVector::from_vec(v),
        iterations: stats.iterations,
        residual: max_abs(&phi),
        velocity_residual: max_abs(&phid),
    })
}

/// A given initial value that the consistent initial state changed (see [`initial_changes`]).
#[derive(Clone, Debug, PartialEq)]
pub struct InitialChange {
    /// The coordinate (`crank.theta`) or velocity (`d_crank.theta`).
    pub name: String,
    /// The value the model gives.
    pub given: f64,
    /// The value the consistent state uses.
    pub used: f64,
}

/// A change of a given initial value below this, relative to `max(1, |given|)`, is the
/// projection's round-off and not reported by [`initial_changes`].
pub const INITIAL_CHANGE_TOL: f64 = 1e-8;

/// The given initial values that the consistent state `(q, v)` changed by more than
/// [`INITIAL_CHANGE_TOL`] (relative to `max(1, |given|)`): every coordinate, and every
/// velocity the model gives as non-zero (a velocity left at zero is one the model leaves to the
/// constraints). Inputs ([`mbd_model::Inputs`]) never change. Bodies placed from initial joint
/// coordinates ([`System::assembled_bodies`]) are not reported: the joint coordinates are what
/// the model gives, and they are kept. What `mbd run` warns about.
///
/// ```
/// use mbd_model::{models::SliderCrankParams, Coord};
/// // a slider-crank whose crank is given 6 rad/s: the consistent state keeps the kinetic
/// // energy's nearest velocities, not the crank's rate
/// let mut p = SliderCrankParams::default();
/// p.speed = 6.0;
/// let sys = mbd_model::models::slider_crank_with(&p)?;
/// let x = mbd_solve::consistent_state(&sys, 0.0)?;
/// let changes = mbd_solve::initial_changes(&sys, x.q.as_slice(), x.v.as_slice());
/// assert!(changes.iter().any(|c| c.name == "d_crank.theta" && c.given == 6.0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn initial_changes(sys: &System, q: &[f64], v: &[f64]) -> Vec<InitialChange> {
    let (q0, v0) = sys.initial_guess();
    let names = sys.coordinate_names();
    // bodies placed from joint coordinates: their stored values were not what the model gives
    let assembled = sys.assembled_bodies();
    let moved = |i: usize, given: f64, used: f64| {
        // (spatial coordinates, after the planar bodies', are never assembled)
        !assembled.get(i / 3).copied().unwrap_or(false)
            && (used - given).abs() > INITIAL_CHANGE_TOL * given.abs().max(1.0)
    };
    let mut out = Vec::new();
    for (i, name) in names.iter().enumerate() {
        if let (Some(&given), Some(&used)) = (q0.get(i), q.get(i)) {
            if moved(i, given, used) {
                out.push(InitialChange {
                    name: name.clone(),
                    given,
                    used,
                });
            }
        }
    }
    for (i, name) in names.iter().enumerate() {
        if let (Some(&given), Some(&used)) = (v0.get(i), v.get(i)) {
            if given != 0.0 && moved(i, given, used) {
                out.push(InitialChange {
                    name: format!("d_{name}"),
                    given,
                    used,
                });
            }
        }
    }
    out
}

/// The names of the initial state's inputs, for the weights and the errors of
/// [`project_state`].
struct Inputs {
    names: Vec<String>,
}

impl Inputs {
    fn new(sys: &System, keep_q: &[bool], keep_v: &[bool]) -> Self {
        let names = if keep_q.iter().chain(keep_v).any(|&k| k) {
            sys.coordinate_names()
        } else {
            Vec::new()
        };
        Inputs { names }
    }

    /// `M^-1` with the kept coordinates' weights zero, or `None` when none is kept.
    fn weights(&self, sys: &System, keep: &[bool]) -> Option<Vec<f64>> {
        keep.iter().any(|&k| k).then(|| {
            sys.inv_mass_diag()
                .iter()
                .zip(keep)
                .map(|(&w, &k)| if k { 0.0 } else { w })
                .collect()
        })
    }

    /// A singular projection with inputs at this level: the inputs leave its equation no
    /// free coordinate.
    fn explain(&self, e: SolveError, level: &'static str, keep: &[bool]) -> SolveError {
        match e {
            SolveError::Singular { detail, .. } if keep.iter().any(|&k| k) => {
                let prefix = if level == "velocity" { "d_" } else { "" };
                let inputs: Vec<String> = keep
                    .iter()
                    .zip(&self.names)
                    .filter(|(&k, _)| k)
                    .map(|(_, n)| format!("{prefix}{n}"))
                    .collect();
                SolveError::OverdeterminedInputs {
                    level,
                    inputs: inputs.join(", "),
                    equation: detail,
                }
            }
            e => e,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dense and sparse paths give the same consistent state for a 30-link chain guessed
    /// off its manifold, at the requested tolerances.
    #[test]
    fn dense_and_sparse_paths_agree() {
        let sys = mbd_model::models::n_link_chain(30).unwrap();
        let (q, v) = sys.initial_guess();
        let q: Vec<f64> = q
            .iter()
            .enumerate()
            .map(|(i, x)| x + 1e-3 * (i as f64).cos())
            .collect();
        let v: Vec<f64> = (0..v.len()).map(|i| (0.2 * i as f64).sin()).collect();
        let mut out = Vec::new();
        for linear in [LinearSolver::Dense, LinearSolver::Sparse] {
            let opts = ConsistentOptions {
                linear,
                ..Default::default()
            };
            let x = project_state(&sys, &q, &v, 0.0, opts).unwrap();
            assert!(x.residual <= 1e-12 && x.velocity_residual <= 1e-12, "{x:?}");
            assert!(x.position_correction > 1e-4 && x.iterations >= 2);
            out.push(x);
        }
        assert!(max_abs_diff(out[0].q.as_slice(), out[1].q.as_slice()) < 1e-12);
        assert!(max_abs_diff(out[0].v.as_slice(), out[1].v.as_slice()) < 1e-12);
    }

    /// A guess far from the origin (x = 1e20) must not lend its round-off floor to the
    /// configuration Newton brings back (a residual of 0.5 used to be reported as converged):
    /// one pinned rod projects onto its pin to the requested tolerance; the double pendulum
    /// does not converge from there and says so.
    #[test]
    fn a_far_guess_converges_or_fails_honestly() {
        use mbd_model::{Body, BodyRef, Joint, SystemBuilder};
        let mut b = SystemBuilder::new();
        let rod = b.add_body(Body::new("rod").rod(1.0, 1.0).position(1e20, 0.0, 0.0));
        b.add_joint(Joint::revolute(
            "pin",
            BodyRef::Ground,
            [0.0, 0.0],
            rod,
            [-0.5, 0.0],
        ));
        let sys = b.build().unwrap();
        let (q, v) = sys.initial_guess();
        let x = project_state(&sys, q.as_slice(), v.as_slice(), 0.0, Default::default())
            .expect("the far guess of one rod projects");
        assert!(x.residual <= 1e-13 && x.position_correction > 1e19, "{x:?}");

        let sys = mbd_model::models::pendulum(1.0, 1.0, 0.2, 9.81).unwrap();
        let (mut q, v) = sys.initial_guess();
        q[0] = 1e20;
        match project_state(&sys, q.as_slice(), v.as_slice(), 0.0, Default::default()) {
            Err(SolveError::Newton { residual, .. }) => assert!(residual > 1e-3, "{residual}"),
            other => panic!("expected a Newton failure, got {other:?}"),
        }
    }

    #[test]
    fn bad_tolerance_is_an_error() {
        let sys = mbd_model::models::pendulum(1.0, 1.0, 0.2, 9.81).unwrap();
        let (q, v) = sys.initial_guess();
        let opts = ConsistentOptions {
            tol: -1.0,
            ..Default::default()
        };
        assert!(matches!(
            project_state(&sys, q.as_slice(), v.as_slice(), 0.0, opts),
            Err(SolveError::InvalidParameter {
                parameter: "ConsistentOptions::tol",
                ..
            })
        ));
    }
}
