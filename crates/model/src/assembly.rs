//! Assembly from joint coordinates (see [`JointInitial`]).

use crate::builder::SystemBuilder;
use crate::error::ModelError;
use crate::joints::{AngleDriver, Joint, JointKind, SlideDriver};
use crate::system::{JointHandle, System};
use crate::timefn::TimeFunction;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A joint's initial relative coordinate and rate: the angle `theta_b - theta_a` (rad) and its
/// rate (rad/s) of a revolute joint, the slide `s` (m) and its rate (m/s) of a prismatic joint.
/// Either may be left out (`None`): it is then taken from the bodies' stored state.
///
/// Assembly from joint coordinates: a model may give the initial relative angle of revolute
/// joints and the initial slide of prismatic joints (and their rates) instead of placing every
/// body by hand.
///
/// Two steps turn them into a consistent initial state:
///
/// 1. **Tree placement** ([`System::initial_guess`]): starting from the ground, every revolute
///    or prismatic joint with one side placed places the other side so that the joint holds
///    exactly: a revolute joint's bodies keep the given relative angle `theta_b - theta_a`
///    (or, when none is given, the one of the bodies' stored poses) and their joint points
///    coincide; a prismatic joint's bodies keep its fixed relative angle and the given slide
///    `s = (P_b - P_a) . u_a` (or the stored one) with no offset across the axis. Velocities
///    follow in the same order from the rates (`omega_b - omega_a`, `ds/dt`) and the joint
///    points' velocities. Bodies no such joint reaches keep their stored state.
/// 2. **Projection with the joint coordinates held** (`mbd_solve::consistent_state`): the
///    loops the tree left open are closed by the usual projection onto the constraints, with a
///    temporary driver per given coordinate (an angle or slide driver, constant at the given
///    value) and then per given rate (a driver with that rate), so the given values are kept
///    exactly and the other coordinates take up the correction ([`System::with_joint_drivers`]).
///    A joint given a coordinate but no rate keeps the rate of the bodies' stored velocities
///    (zero where none are given) in this projection too, unless the held rates would then
///    outnumber the degrees of freedom.
///    More given coordinates (or rates) than degrees of freedom are refused, naming the
///    joints; a coordinate the constraints already fix makes its driver redundant, and the
///    projection's rank check names it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointInitial {
    /// The relative angle (revolute) or slide (prismatic).
    pub coordinate: Option<f64>,
    /// Its rate.
    pub rate: Option<f64>,
}

impl JointInitial {
    /// A given coordinate, its rate left to the stored velocities.
    pub fn coordinate(value: f64) -> Self {
        JointInitial {
            coordinate: Some(value),
            rate: None,
        }
    }
    /// The same with a given rate.
    pub fn with_rate(mut self, rate: f64) -> Self {
        self.rate = Some(rate);
        self
    }
}

/// A joint's initial coordinate in a model file (see [`JointInitial`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct JointInitialSpec {
    /// The joint (revolute or prismatic).
    pub joint: String,
    /// Its relative angle `theta_b - theta_a` (rad) or slide (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coordinate: Option<f64>,
    /// Its rate (rad/s or m/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate: Option<f64>,
}

/// Checks the builder's joint initial values: known revolute or prismatic joints, each once,
/// finite values, at least one value each.
pub(crate) fn validate(
    joints: &[Joint],
    initials: &[(JointHandle, JointInitial)],
) -> Result<Vec<(usize, JointInitial)>, ModelError> {
    let mut seen = vec![false; joints.len()];
    let mut out = Vec::with_capacity(initials.len());
    for &(h, init) in initials {
        let Some(joint) = joints.get(h.0) else {
            return Err(ModelError::InvalidElement {
                element: format!("joint #{}", h.0),
                message: format!(
                    "an initial joint coordinate refers to a joint that does not exist (the \
                     model has {} joints)",
                    joints.len()
                ),
            });
        };
        let element = format!("joint '{}'", joint.name);
        let invalid = |message: String| ModelError::InvalidElement {
            element: element.clone(),
            message,
        };
        if !matches!(joint.kind, JointKind::Revolute(_) | JointKind::Prismatic(_)) {
            return Err(invalid(format!(
                "an initial joint coordinate needs a revolute or prismatic joint, not a {}",
                joint.kind_name()
            )));
        }
        if std::mem::replace(&mut seen[h.0], true) {
            return Err(invalid("its initial coordinate is given twice".into()));
        }
        if init.coordinate.is_none() && init.rate.is_none() {
            return Err(invalid(
                "an initial joint coordinate entry gives neither 'coordinate' nor 'rate'".into(),
            ));
        }
        for (name, x) in [("coordinate", init.coordinate), ("rate", init.rate)] {
            if let Some(x) = x.filter(|x| !x.is_finite()) {
                return Err(invalid(format!(
                    "initial {name} {} is not finite",
                    crate::error::num(x)
                )));
            }
        }
        out.push((h.0, init));
    }
    Ok(out)
}

/// `R(theta) p`.
fn rot(theta: f64, p: [f64; 2]) -> [f64; 2] {
    let (s, c) = theta.sin_cos();
    [c * p[0] - s * p[1], s * p[0] + c * p[1]]
}

/// `k x r` scaled by `w`: the velocity of a rotating lever `r`.
fn spin(w: f64, r: [f64; 2]) -> [f64; 2] {
    [-w * r[1], w * r[0]]
}

/// A body's pose and velocity (ground: zero).
fn pose(q: &[f64], v: &[f64], i: Option<usize>) -> ([f64; 3], [f64; 3]) {
    match i {
        Some(i) => (
            [q[3 * i], q[3 * i + 1], q[3 * i + 2]],
            [v[3 * i], v[3 * i + 1], v[3 * i + 2]],
        ),
        None => ([0.0; 3], [0.0; 3]),
    }
}

/// A revolute or prismatic joint's geometry: points on `a` and `b`, and the unit axis and
/// fixed relative angle of a prismatic joint.
struct Geometry {
    pa: [f64; 2],
    pb: [f64; 2],
    prismatic: Option<([f64; 2], f64)>,
}

fn geometry(kind: &JointKind) -> Option<Geometry> {
    match kind {
        JointKind::Revolute(r) => Some(Geometry {
            pa: r.pa,
            pb: r.pb,
            prismatic: None,
        }),
        JointKind::Prismatic(p) => Some(Geometry {
            pa: p.pa,
            pb: p.pb,
            prismatic: Some((p.axis, p.angle)),
        }),
        _ => None,
    }
}

impl System {
    /// Joint `joint`'s relative coordinates at `(q, v)`: `[angle, rate]` = `theta_b - theta_a`
    /// and `omega_b - omega_a` (ground: 0), and for a joint with a sliding axis (prismatic,
    /// slide driver) `[s, ds]`: the slide `s = (r_pb - r_pa) . u` of its point on `b` from its
    /// point on `a` along the unit axis `u` turned with `a`, and
    /// `ds = (v_pb - v_pa) . u + (r_pb - r_pa) . (omega_a k x u)`. What joint sensors report and
    /// assembly prescribes. `None` for a joint index out of range or `q`, `v` of the wrong length.
    pub fn joint_coordinates(
        &self,
        joint: usize,
        q: &[f64],
        v: &[f64],
    ) -> Option<([f64; 2], Option<[f64; 2]>)> {
        if q.len() != self.n || v.len() != self.n {
            return None;
        }
        let sketch = self.joints.get(joint)?.sketch();
        let at = self.joint_attach[joint];
        let (a, b) = (pose(q, v, at.a), pose(q, v, at.b));
        let relative = [b.0[2] - a.0[2], b.1[2] - a.1[2]];
        let slide = sketch.axis.map(|axis| {
            let point = |(q, v): ([f64; 3], [f64; 3]), p: [f64; 2]| {
                let r = rot(q[2], p);
                let w = spin(v[2], r);
                ([q[0] + r[0], q[1] + r[1]], [v[0] + w[0], v[1] + w[1]])
            };
            let (ra, va) = point(a, sketch.point_a.unwrap_or_default());
            let (rb, vb) = point(b, sketch.point_b.unwrap_or_default());
            let u = rot(a.0[2], axis);
            let du = spin(a.1[2], u);
            let d = [rb[0] - ra[0], rb[1] - ra[1]];
            let dd = [vb[0] - va[0], vb[1] - va[1]];
            [
                d[0] * u[0] + d[1] * u[1],
                dd[0] * u[0] + dd[1] * u[1] + d[0] * du[0] + d[1] * du[1],
            ]
        });
        Some((relative, slide))
    }

    /// The initial joint coordinates given with [`SystemBuilder::set_joint_initial`] (or a
    /// model file's `[[assembly]]`), in the order given.
    pub fn joint_initials(&self) -> impl Iterator<Item = (JointHandle, JointInitial)> + '_ {
        self.joint_initials
            .iter()
            .map(|&(j, init)| (JointHandle(j), init))
    }

    /// Which bodies the initial joint coordinates place (all `false` without them): those a
    /// chain of revolute and prismatic joints reaches from the ground (see the
    /// docs of [`JointInitial`]).
    pub fn assembled_bodies(&self) -> Vec<bool> {
        let (mut q, mut v) = self.stored_state();
        self.assemble(&mut q, &mut v)
    }

    /// Places the bodies from the given joint coordinates along a spanning tree from the
    /// ground (see the docs of [`JointInitial`]); `q`, `v` hold the stored state on entry. Returns
    /// which bodies it placed.
    pub(crate) fn assemble(&self, q: &mut [f64], v: &mut [f64]) -> Vec<bool> {
        let mut placed = vec![false; self.bodies.len()];
        if self.joint_initials.is_empty() {
            return placed;
        }
        let stored = (q.to_vec(), v.to_vec());
        let mut given = vec![JointInitial::default(); self.joints.len()];
        for &(j, init) in &self.joint_initials {
            given[j] = init;
        }
        let is_placed = |placed: &[bool], i: Option<usize>| i.map_or(true, |i| placed[i]);
        loop {
            let mut progress = false;
            for (j, joint) in self.joints.iter().enumerate() {
                let Some(g) = geometry(&joint.kind) else {
                    continue;
                };
                let at = self.joint_attach[j];
                let (pa_done, pb_done) = (is_placed(&placed, at.a), is_placed(&placed, at.b));
                if pa_done == pb_done {
                    continue;
                }
                // the joint's coordinate and rate: given, else the stored bodies'
                let [c0, r0] = match self.joint_coordinates(j, &stored.0, &stored.1) {
                    Some((relative, slide)) => slide.unwrap_or(relative),
                    None => continue,
                };
                let c = given[j].coordinate.unwrap_or(c0);
                let r = given[j].rate.unwrap_or(r0);
                if pa_done {
                    let (qa, va) = pose(q, v, at.a);
                    let (qb, vb) = place(&g, qa, va, c, r, true);
                    write(q, v, at.b, qb, vb);
                    if let Some(i) = at.b {
                        placed[i] = true;
                    }
                } else {
                    let (qb, vb) = pose(q, v, at.b);
                    let (qa, va) = place(&g, qb, vb, c, r, false);
                    write(q, v, at.a, qa, va);
                    if let Some(i) = at.a {
                        placed[i] = true;
                    }
                }
                progress = true;
            }
            if !progress {
                break;
            }
        }
        placed
    }

    /// The rate the velocity projection holds for each entry of `joint_initials`: the given
    /// rate; for an entry that gives a coordinate but no rate, the joint's rate in the bodies'
    /// stored velocities (zero where none are given), as long as the held rates do not
    /// outnumber the degrees of freedom (else only the given ones are held).
    fn held_rates(&self) -> Vec<Option<f64>> {
        let given: Vec<Option<f64>> = self.joint_initials.iter().map(|(_, i)| i.rate).collect();
        let (qs, vs) = self.stored_state();
        let implied: Vec<Option<f64>> = self
            .joint_initials
            .iter()
            .map(|&(j, init)| {
                init.rate.or_else(|| {
                    init.coordinate?;
                    let (relative, slide) = self.joint_coordinates(j, &qs, &vs)?;
                    Some(slide.unwrap_or(relative)[1])
                })
            })
            .collect();
        if implied.iter().flatten().count() <= self.dof() {
            implied
        } else {
            given
        }
    }

    /// This model with a driver per given joint coordinate (`rates = false`: the given
    /// angles and slides, constant) or per given rate (`rates = true`: a driver through the
    /// joint's coordinate at `(q, t)` with the given rate), the bodies placed at `q`: the
    /// system whose projection keeps the given values (see the docs of [`JointInitial`]). The
    /// drivers are named `<joint>:assembly`; forces and sensors are left out. More held values
    /// than the model's degrees of freedom is an error naming the joints.
    pub fn with_joint_drivers(&self, q: &[f64], t: f64, rates: bool) -> Result<System, ModelError> {
        self.check_len("q", q, self.n)?;
        let held_rates = self.held_rates();
        let held: Vec<&str> = self
            .joint_initials
            .iter()
            .zip(&held_rates)
            .filter(|((_, init), rate)| if rates { **rate } else { init.coordinate }.is_some())
            .map(|(&(j, _), _)| self.joints[j].name.as_str())
            .collect();
        if held.len() > self.dof() {
            let what = if rates { "rates" } else { "coordinates" };
            return Err(ModelError::InvalidElement {
                element: format!("assembly (joints '{}')", held.join("', '")),
                message: format!(
                    "{} joint {what} given, but the model has {} degree(s) of freedom: give at \
                     most {} (the constraints fix the others)",
                    held.len(),
                    self.dof(),
                    self.dof()
                ),
            });
        }
        let mut b = SystemBuilder::new();
        b.redundant_constraints(crate::RedundantConstraints::Allow);
        for (i, body) in self.bodies.iter().enumerate() {
            let mut body = body.clone();
            body.position = [q[3 * i], q[3 * i + 1], q[3 * i + 2]];
            b.add_body(body);
        }
        for joint in &self.joints {
            b.add_joint(joint.clone());
        }
        let zero = vec![0.0; self.n];
        for (&(j, init), &held_rate) in self.joint_initials.iter().zip(&held_rates) {
            let joint = &self.joints[j];
            let Some(g) = geometry(&joint.kind) else {
                continue;
            };
            let f = if rates {
                let Some(rate) = held_rate else { continue };
                let Some((relative, slide)) = self.joint_coordinates(j, q, &zero) else {
                    continue;
                };
                let [c, _] = slide.unwrap_or(relative);
                TimeFunction::linear(c - rate * t, rate)
            } else {
                let Some(c) = init.coordinate else { continue };
                TimeFunction::constant(c)
            };
            let (a, bb) = joint.bodies();
            let name = format!("{}:assembly", joint.name);
            let driver = match g.prismatic {
                None => Joint::new(name, AngleDriver { a, b: bb, f }),
                Some((axis, _)) => Joint::new(
                    name,
                    SlideDriver {
                        a,
                        pa: g.pa,
                        b: bb,
                        pb: g.pb,
                        axis,
                        f,
                    },
                ),
            };
            b.add_joint(driver);
        }
        b.build()
    }
}

/// The pose and velocity of the unplaced side of a joint from the placed side's and the
/// joint's coordinate `c` and rate `r` (`forward`: `a` is placed).
fn place(
    g: &Geometry,
    q: [f64; 3],
    v: [f64; 3],
    c: f64,
    r: f64,
    forward: bool,
) -> ([f64; 3], [f64; 3]) {
    let sign = if forward { 1.0 } else { -1.0 };
    // the relative angle theta_b - theta_a and its rate
    let (rel, rel_rate) = match g.prismatic {
        None => (c, r),
        Some((_, angle)) => (angle, 0.0),
    };
    let (theta, omega) = (q[2] + sign * rel, v[2] + sign * rel_rate);
    let (q_a, v_a) = if forward {
        (q[2], v[2])
    } else {
        (theta, omega)
    };
    // the placed side's joint point and its velocity
    let (p_known, p_other) = if forward { (g.pa, g.pb) } else { (g.pb, g.pa) };
    let rk = rot(q[2], p_known);
    let mut x = [q[0] + rk[0], q[1] + rk[1]];
    let mut xd = [v[0] + spin(v[2], rk)[0], v[1] + spin(v[2], rk)[1]];
    if let Some((axis, _)) = g.prismatic {
        // P_b = P_a + s u_a, with u_a turning with body a
        let u = rot(q_a, axis);
        let du = spin(v_a, u);
        for k in 0..2 {
            x[k] += sign * c * u[k];
            xd[k] += sign * (r * u[k] + c * du[k]);
        }
    }
    let ro = rot(theta, p_other);
    let so = spin(omega, ro);
    (
        [x[0] - ro[0], x[1] - ro[1], theta],
        [xd[0] - so[0], xd[1] - so[1], omega],
    )
}

fn write(q: &mut [f64], v: &mut [f64], i: Option<usize>, qi: [f64; 3], vi: [f64; 3]) {
    if let Some(i) = i {
        q[3 * i..3 * i + 3].copy_from_slice(&qi);
        v[3 * i..3 * i + 3].copy_from_slice(&vi);
    }
}

#[cfg(test)]
mod tests;
