//! The values of a model's sensors ([`mbd_model::Sensor`]) at a state: what `mbd run` writes
//! beside the state.
//!
//! A point `p` of body `i` (its frame, relative to the centre of mass) is at
//! `r = r_i + R(theta_i) p`, moves at `v = v_i + omega_i k x R p` and accelerates at
//! `a = a_i + alpha_i k x R p - omega_i^2 R p`, with the body's accelerations `(a_i, alpha_i)`
//! from the index-1 solve at the state (the same accelerations every solver's dynamics has).
//! A joint's relative angle is `theta_b - theta_a` (ground: 0) and its rate
//! `omega_b - omega_a`; a prismatic joint's slide is `s = (r_pb - r_pa) . u` with `u` its unit
//! axis turned with body `a`, and `ds = (v_pb - v_pa) . u + (r_pb - r_pa) . (omega_a k x u)`
//! ([`System::joint_coordinates`], shared with assembly from joint coordinates).
//! A reaction sensor reads its joint's [`JointReaction`] from the multipliers of the same
//! index-1 solve; an energy sensor evaluates `T` and `V` at the state (for one body, its
//! kinetic energy and the potential of gravity on it; likewise for a spatial body or point
//! mass).

use crate::error::SolveError;
use crate::output_solve::OutputSolve;
use crate::reactions::{joint_reactions, JointReaction};
use crate::state::State;
use mbd_model::spatial::SpatialJointReaction;
use mbd_model::{SensorKind, System};

/// Evaluates a model's sensors; a workspace allocated once.
///
/// ```
/// use mbd_model::{models, SensorSpec};
/// use mbd_solve::{SensorSolver, State};
/// // a pendulum's tip at rest, hanging: at (0, -1), no velocity, no acceleration
/// let mut file = models::pendulum(1.0, 1.0, 0.0, 9.81)?.to_model_file();
/// file.sensors.push(SensorSpec::Point {
///     name: "tip".into(),
///     body: "link1".into(),
///     point: [0.5, 0.0],
/// });
/// let sys = file.build()?;
/// assert_eq!(SensorSolver::columns(&sys), ["tip.x", "tip.y", "tip.vx", "tip.vy", "tip.ax", "tip.ay"]);
/// let mut rs = SensorSolver::new(&sys)?;
/// let mut out = Vec::new();
/// rs.evaluate(&sys, &State::consistent(&sys, 0.0)?, &mut out)?;
/// assert!(out[0].abs() < 1e-12 && (out[1] + 1.0).abs() < 1e-12);
/// assert!(out[2..].iter().all(|x| x.abs() < 1e-12));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct SensorSolver {
    /// The index-1 solve, built at the first [`SensorSolver::evaluate`] that needs it.
    solve: Option<OutputSolve>,
    /// Accelerations and multipliers when no sensor needs them.
    zeros: Vec<f64>,
    zero_lambda: Vec<f64>,
    /// Whether a sensor needs the accelerations (a point sensor).
    needs_acceleration: bool,
    /// Every joint's reaction and the constraint gradients behind them, when a reaction
    /// sensor needs them.
    reactions: Option<(Vec<[f64; 6]>, Vec<JointReaction>)>,
    /// The spatial joints' reactions, when a spatial reaction sensor needs them.
    spatial_reactions: Option<Vec<SpatialJointReaction>>,
}

impl SensorSolver {
    /// A workspace for `sys`.
    pub fn new(sys: &System) -> Result<Self, SolveError> {
        let kinds = || sys.sensors().iter().map(|s| &s.kind);
        let reactions = kinds()
            .any(|k| matches!(k, SensorKind::Reaction { .. }))
            .then(|| {
                (
                    vec![[0.0; 6]; sys.n_constraints()],
                    vec![JointReaction::default(); sys.joints().len()],
                )
            });
        Ok(SensorSolver {
            solve: None,
            zeros: vec![0.0; sys.n_coords()],
            zero_lambda: vec![0.0; sys.n_constraints()],
            needs_acceleration: kinds().any(|k| {
                matches!(
                    k,
                    SensorKind::Point { .. } | SensorKind::SpatialPoint { .. }
                )
            }),
            reactions,
            spatial_reactions: kinds()
                .any(|k| matches!(k, SensorKind::SpatialReaction { .. }))
                .then(|| vec![SpatialJointReaction::default(); sys.spatial_joints().len()]),
        })
    }

    /// The output columns of `sys`'s sensors, in order (see [`mbd_model::SensorKind`]).
    pub fn columns(sys: &System) -> Vec<String> {
        let mut out = Vec::new();
        for s in sys.sensors() {
            let parts: &[&str] = match &s.kind {
                SensorKind::Point { .. } => &["x", "y", "vx", "vy", "ax", "ay"],
                SensorKind::Joint { joint } => {
                    let prismatic = sys
                        .joints()
                        .get(joint.index())
                        .is_some_and(|j| j.sketch().axis.is_some());
                    if prismatic {
                        &["angle", "rate", "s", "ds"]
                    } else {
                        &["angle", "rate"]
                    }
                }
                SensorKind::Reaction { .. } => &["fx", "fy", "mz", "fx_body", "fy_body"],
                SensorKind::Energy { .. } | SensorKind::SpatialEnergy { .. } => {
                    &["kinetic", "potential", "total"]
                }
                SensorKind::SpatialPoint { .. } => {
                    &["x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"]
                }
                SensorKind::AngularVelocity { .. } => {
                    &["wx", "wy", "wz", "wx_body", "wy_body", "wz_body"]
                }
                SensorKind::SpatialReaction { .. } => &["fx", "fy", "fz", "mx", "my", "mz"],
                _ => &[],
            };
            out.extend(parts.iter().map(|p| format!("{}.{p}", s.name)));
        }
        out
    }

    /// Appends the sensors' values at `state` to `out`, in the order of
    /// [`SensorSolver::columns`]; errors as the index-1 solve (a singular configuration).
    pub fn evaluate(
        &mut self,
        sys: &System,
        state: &State,
        out: &mut Vec<f64>,
    ) -> Result<(), SolveError> {
        let (a, lambda) = if self.needs_solve() {
            OutputSolve::lazy(&mut self.solve, sys)?.at(sys, state)?
        } else {
            state.check(sys)?;
            (self.zeros.as_slice(), self.zero_lambda.as_slice())
        };
        values(
            sys,
            state,
            a,
            lambda,
            &mut self.reactions,
            &mut self.spatial_reactions,
            out,
        )
    }

    /// Whether a sensor needs the index-1 solve at the state (a point sensor its
    /// accelerations, a reaction sensor its multipliers): what
    /// [`SensorSolver::evaluate_with`] is to be given.
    pub fn needs_solve(&self) -> bool {
        self.needs_acceleration || self.reactions.is_some() || self.spatial_reactions.is_some()
    }

    /// [`SensorSolver::evaluate`] with the accelerations `a` and multipliers `lambda` at
    /// `state` solved elsewhere (an [`crate::OutputSolve`] shared with other outputs of the
    /// same row; any values of the right sizes when no sensor [needs
    /// them](SensorSolver::needs_solve)).
    pub fn evaluate_with(
        &mut self,
        sys: &System,
        state: &State,
        a: &[f64],
        lambda: &[f64],
        out: &mut Vec<f64>,
    ) -> Result<(), SolveError> {
        state.check(sys)?;
        for (what, expected, got) in [
            ("a", sys.n_coords(), a.len()),
            ("lambda", sys.n_constraints(), lambda.len()),
        ] {
            if got != expected {
                return Err(SolveError::Dimension {
                    what,
                    expected,
                    got,
                });
            }
        }
        values(
            sys,
            state,
            a,
            lambda,
            &mut self.reactions,
            &mut self.spatial_reactions,
            out,
        )
    }
}

/// The sensors' values from the state, its accelerations and multipliers (see the module
/// docs).
fn values(
    sys: &System,
    state: &State,
    a: &[f64],
    lambda: &[f64],
    reactions: &mut Option<(Vec<[f64; 6]>, Vec<JointReaction>)>,
    spatial_reactions: &mut Option<Vec<SpatialJointReaction>>,
    out: &mut Vec<f64>,
) -> Result<(), SolveError> {
    let (q, v) = (state.q.as_slice(), state.v.as_slice());
    if let Some((grads, loads)) = reactions {
        joint_reactions(grads, sys, state, lambda, loads)?;
    }
    if let Some(loads) = spatial_reactions {
        sys.spatial_joint_reactions_into(q, state.t, lambda, loads)?;
    }
    // a body point's position, velocity and acceleration (ground: fixed)
    let kinematics = |i: Option<usize>, p: [f64; 2]| -> [[f64; 2]; 3] {
        let Some(i) = i else {
            return [p, [0.0; 2], [0.0; 2]];
        };
        let (s, c) = q[3 * i + 2].sin_cos();
        let rp = [c * p[0] - s * p[1], s * p[0] + c * p[1]];
        let (w, al) = (v[3 * i + 2], a[3 * i + 2]);
        [
            [q[3 * i] + rp[0], q[3 * i + 1] + rp[1]],
            [v[3 * i] - w * rp[1], v[3 * i + 1] + w * rp[0]],
            [
                a[3 * i] - al * rp[1] - w * w * rp[0],
                a[3 * i + 1] + al * rp[0] - w * w * rp[1],
            ],
        ]
    };
    let (mass, g) = (sys.mass_diag(), sys.gravity());
    for s in sys.sensors() {
        match &s.kind {
            SensorKind::Point { body, point } => {
                let [r, vp, ap] = kinematics(body.index(), *point);
                out.extend([r[0], r[1], vp[0], vp[1], ap[0], ap[1]]);
            }
            SensorKind::Joint { joint } => {
                // a joint index the model checked at build; nothing to add otherwise
                if let Some((relative, slide)) = sys.joint_coordinates(joint.index(), q, v) {
                    out.extend(relative);
                    out.extend(slide.into_iter().flatten());
                }
            }
            SensorKind::Reaction { joint } => {
                let r = reactions
                    .as_ref()
                    .and_then(|(_, loads)| loads.get(joint.index()))
                    .copied()
                    .unwrap_or_default();
                out.extend([
                    r.force[0],
                    r.force[1],
                    r.moment,
                    r.local_force[0],
                    r.local_force[1],
                ]);
            }
            SensorKind::Energy { body: None } => {
                let (t, u) = (sys.kinetic(v), sys.potential(q));
                out.extend([t, u, t + u]);
            }
            SensorKind::Energy { body: Some(body) } => {
                let (t, u) = match body.index() {
                    Some(i) => (
                        (3 * i..3 * i + 3)
                            .map(|k| 0.5 * mass[k] * v[k] * v[k])
                            .sum::<f64>(),
                        -mass[3 * i] * (g[0] * q[3 * i] + g[1] * q[3 * i + 1]),
                    ),
                    None => (0.0, 0.0),
                };
                out.extend([t, u, t + u]);
            }
            SensorKind::SpatialPoint { body, point } => {
                spatial_point(sys, *body, *point, [q, v, a], out);
            }
            SensorKind::AngularVelocity { body } => {
                let k = body.index();
                let w = sys
                    .spatial_body_angular_velocity(k, q, v)
                    .unwrap_or_default();
                let (d, axes) = match sys.spatial_bodies().get(k) {
                    Some(b) => (directors(sys, k, q), *b.inertia.axes()),
                    None => ([[0.0; 3]; 3], nalgebra::Matrix3::identity()),
                };
                // global: sum_i w_i d_i; body frame: A w (A the principal axes in it)
                let global: [f64; 3] =
                    std::array::from_fn(|c| (0..3).map(|i| w[i] * d[i][c]).sum());
                let body_axes = axes * nalgebra::Vector3::from(w);
                out.extend(global);
                out.extend(body_axes.iter());
            }
            SensorKind::SpatialReaction { joint } => {
                let r = spatial_reactions
                    .as_ref()
                    .and_then(|loads| loads.get(*joint))
                    .copied()
                    .unwrap_or_default();
                out.extend(r.force.iter().chain(&r.moment));
            }
            SensorKind::SpatialEnergy { body } => {
                let (t, u) = spatial_energy(sys, *body, q, v);
                out.extend([t, u, t + u]);
            }
            _ => {}
        }
    }
    Ok(())
}

/// A spatial rigid body's or point mass's kinetic energy (`sum_i m_ii v_i^2 / 2` over its
/// coordinates, with the diagonal mass of the natural coordinates: `m |v|^2 / 2 +
/// omega . J omega / 2` for a body, `m |x'|^2 / 2` for a point mass) and the potential of
/// gravity on it, `-m g . x` with `x` its centre of mass or position; ground (and an index the
/// model does not have, which its build refuses): zeros.
fn spatial_energy(
    sys: &System,
    body: mbd_model::spatial::SpatialBodyRef,
    q: &[f64],
    v: &[f64],
) -> (f64, f64) {
    let (offset, width, m) = if let Some(p) = body.point_mass() {
        match sys.spatial_point_masses().get(p) {
            Some(pm) => (sys.spatial_point_mass_offset() + 3 * p, 3, pm.mass),
            None => return (0.0, 0.0),
        }
    } else if let Some(k) = body.index() {
        match sys.spatial_bodies().get(k) {
            Some(b) => (sys.spatial_offset() + 12 * k, 12, b.inertia.mass()),
            None => return (0.0, 0.0),
        }
    } else {
        return (0.0, 0.0);
    };
    let (mass, g) = (sys.mass_diag(), sys.spatial_gravity());
    let t = (offset..offset + width)
        .map(|i| 0.5 * mass[i] * v[i] * v[i])
        .sum::<f64>();
    let u = -m * (0..3).map(|c| g[c] * q[offset + c]).sum::<f64>();
    (t, u)
}

/// Spatial body `k`'s directors at `q`.
fn directors(sys: &System, k: usize, q: &[f64]) -> [[f64; 3]; 3] {
    let o = sys.spatial_offset() + 12 * k;
    std::array::from_fn(|i| std::array::from_fn(|c| q[o + 3 + 3 * i + c]))
}

/// A spatial body point's position, velocity and acceleration (linear in the natural
/// coordinates: `P = x + sum_i p_i d_i` with `p` in the principal frame), a point mass's
/// (its coordinates), or a fixed point.
fn spatial_point(
    sys: &System,
    body: mbd_model::spatial::SpatialBodyRef,
    point: [f64; 3],
    [q, v, a]: [&[f64]; 3],
    out: &mut Vec<f64>,
) {
    if let Some(p) = body.point_mass() {
        let o = sys.spatial_point_mass_offset() + 3 * p;
        for y in [q, v, a] {
            out.extend_from_slice(&y[o..o + 3]);
        }
        return;
    }
    let body = body.index();
    let Some((k, b)) = body.and_then(|k| sys.spatial_bodies().get(k).map(|b| (k, b))) else {
        out.extend(point);
        out.extend([0.0; 6]);
        return;
    };
    let p = b.inertia.axes().transpose() * nalgebra::Vector3::from(point);
    let o = sys.spatial_offset() + 12 * k;
    for y in [q, v, a] {
        for c in 0..3 {
            out.push(y[o + c] + (0..3).map(|i| p[i] * y[o + 3 + 3 * i + c]).sum::<f64>());
        }
    }
}
