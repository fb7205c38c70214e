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

use crate::error::SolveError;
use crate::output_solve::OutputSolve;
use crate::state::State;
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
    /// Accelerations when no sensor needs them.
    zeros: Vec<f64>,
    /// Whether a sensor needs the accelerations.
    needs_acceleration: bool,
}

impl SensorSolver {
    /// A workspace for `sys`.
    pub fn new(sys: &System) -> Result<Self, SolveError> {
        Ok(SensorSolver {
            solve: None,
            zeros: vec![0.0; sys.n_coords()],
            needs_acceleration: sys
                .sensors()
                .iter()
                .any(|s| matches!(s.kind, SensorKind::Point { .. })),
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
        let a = if self.needs_acceleration {
            OutputSolve::lazy(&mut self.solve, sys)?.at(sys, state)?.0
        } else {
            state.check(sys)?;
            &self.zeros
        };
        values(sys, state, a, out);
        Ok(())
    }

    /// Whether a sensor needs the accelerations (a point sensor): what
    /// [`SensorSolver::evaluate_with`] is to be given.
    pub fn needs_acceleration(&self) -> bool {
        self.needs_acceleration
    }

    /// [`SensorSolver::evaluate`] with the accelerations `a` at `state` solved elsewhere (an
    /// [`crate::OutputSolve`] shared with other outputs of the same row; any values when no
    /// sensor [needs them](SensorSolver::needs_acceleration)).
    pub fn evaluate_with(
        &self,
        sys: &System,
        state: &State,
        a: &[f64],
        out: &mut Vec<f64>,
    ) -> Result<(), SolveError> {
        state.check(sys)?;
        if a.len() != sys.n_coords() {
            return Err(SolveError::Dimension {
                what: "a",
                expected: sys.n_coords(),
                got: a.len(),
            });
        }
        values(sys, state, a, out);
        Ok(())
    }
}

/// The sensors' values from the state and its accelerations (see the module docs).
fn values(sys: &System, state: &State, a: &[f64], out: &mut Vec<f64>) {
    let (q, v) = (state.q.as_slice(), state.v.as_slice());
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
            _ => {}
        }
    }
}
