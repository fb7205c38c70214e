//! From a model file to a builder and back: names to handles, body frames to centres of mass,
//! point masses to constrained bodies.

use super::spec::{BodyKind, BodySpec, ForceSpec, JointSpec};
use super::ModelFile;
use crate::body::{Body, BodyHandle, BodyRef};
use crate::builder::SystemBuilder;
use crate::error::ModelError;
use crate::force::{Force, ForceKind};
use crate::joint::{Coordinate, Joint, JointKind};
use crate::system::System;

/// Body names resolved, with each body's frame offset and kind.
struct Resolver<'a> {
    file: &'a ModelFile,
    /// The bodies as the builder gets them (centre-of-mass poses, nominal point-mass inertia).
    bodies: Vec<Body>,
}

/// The nominal length `l` of a file's point masses (inertia `m l^2`): the largest distance-joint
/// length, spring rest length or attachment-point distance from a centre of mass, 1 m if none.
/// So a point mass neither changes [`System::length_scale`] nor trips the inertia-scale check.
fn nominal_length(file: &ModelFile) -> f64 {
    let mut l = 0.0f64;
    let n = |p: &[f64; 2]| p[0].hypot(p[1]);
    for j in &file.joints {
        match j {
            JointSpec::Distance {
                length,
                point_a,
                point_b,
                ..
            } => l = l.max(*length).max(n(point_a)).max(n(point_b)),
            JointSpec::Revolute {
                point_a, point_b, ..
            }
            | JointSpec::Prismatic {
                point_a, point_b, ..
            }
            | JointSpec::Weld {
                point_a, point_b, ..
            } => l = l.max(n(point_a)).max(n(point_b)),
            JointSpec::Absolute { point, .. } => l = l.max(n(point)),
            JointSpec::AngleDriver { .. } => {}
        }
    }
    for f in &file.forces {
        if let ForceSpec::SpringDamper { rest_length, .. } = f {
            l = l.max(*rest_length);
        }
    }
    if l.is_finite() && l > 0.0 {
        l
    } else {
        1.0
    }
}

fn invalid(element: String, message: String) -> ModelError {
    ModelError::InvalidElement { element, message }
}

impl<'a> Resolver<'a> {
    fn new(file: &'a ModelFile) -> Result<Self, ModelError> {
        let l = nominal_length(file);
        let mut bodies = Vec::with_capacity(file.bodies.len());
        for s in &file.bodies {
            let element = format!("body '{}'", s.name);
            let inertia = match (s.kind, s.inertia) {
                (BodyKind::Rigid, Some(j)) => j,
                (BodyKind::Rigid, None) => {
                    return Err(invalid(
                        element,
                        "field 'inertia' (kg m^2, about the centre of mass) is required for a \
                         rigid body"
                            .into(),
                    ))
                }
                (BodyKind::PointMass, Some(j)) => {
                    return Err(invalid(
                        element,
                        format!(
                            "field 'inertia' = {j} is not allowed on a point mass (its rotation \
                             is eliminated)"
                        ),
                    ))
                }
                (BodyKind::PointMass, None) => s.mass * l * l,
            };
            if s.kind == BodyKind::PointMass {
                if s.position[2] != 0.0 {
                    return Err(invalid(
                        element,
                        format!(
                            "position theta = {} must be 0 on a point mass",
                            s.position[2]
                        ),
                    ));
                }
                if s.velocity[2] != 0.0 {
                    return Err(invalid(
                        element,
                        format!(
                            "velocity thetadot = {} must be 0 on a point mass",
                            s.velocity[2]
                        ),
                    ));
                }
            }
            let (mut position, mut velocity) = (s.position, s.velocity);
            if let Some(c) = s.com {
                if !(c[0].is_finite() && c[1].is_finite()) {
                    return Err(invalid(
                        element,
                        format!("field 'com' = {c:?} must be finite"),
                    ));
                }
                // r_com = r_o + R(theta) c;  v_com = v_o + omega x R(theta) c
                let (sn, cs) = s.position[2].sin_cos();
                let rc = [cs * c[0] - sn * c[1], sn * c[0] + cs * c[1]];
                let w = s.velocity[2];
                position[0] += rc[0];
                position[1] += rc[1];
                velocity[0] -= w * rc[1];
                velocity[1] += w * rc[0];
            }
            bodies.push(Body {
                name: s.name.clone(),
                mass: s.mass,
                inertia,
                position,
                velocity,
            });
        }
        Ok(Resolver { file, bodies })
    }

    fn spec(&self, name: &str) -> Option<(usize, &BodySpec)> {
        if name.eq_ignore_ascii_case("ground") {
            return None;
        }
        self.file
            .bodies
            .iter()
            .enumerate()
            .find(|(_, b)| b.name == name)
    }

    fn find(&self, element: &str, name: &str) -> Result<BodyRef, ModelError> {
        if name.eq_ignore_ascii_case("ground") {
            return Ok(BodyRef::Ground);
        }
        self.spec(name)
            .map(|(i, _)| BodyRef::Body(BodyHandle(i)))
            .ok_or_else(|| ModelError::UnknownBody {
                element: element.to_string(),
                body: name.to_string(),
            })
    }

    /// A local point given in `body`'s frame, relative to its centre of mass; on a point mass it
    /// must be the centre.
    fn point(
        &self,
        element: &str,
        field: &str,
        body: &str,
        p: [f64; 2],
    ) -> Result<[f64; 2], ModelError> {
        let Some((_, s)) = self.spec(body) else {
            return Ok(p);
        };
        let c = s.com.unwrap_or([0.0, 0.0]);
        let local = [p[0] - c[0], p[1] - c[1]];
        if s.kind == BodyKind::PointMass && local != [0.0, 0.0] {
            return Err(invalid(
                element.to_string(),
                format!(
                    "field '{field}' = {p:?} on point mass '{body}': a point mass attaches only \
                     at its centre ({c:?})"
                ),
            ));
        }
        Ok(local)
    }

    fn no_rotation(&self, element: String, kind: &str, bodies: &[&str]) -> Result<(), ModelError> {
        for b in bodies {
            if let Some((_, s)) = self.spec(b) {
                if s.kind == BodyKind::PointMass {
                    return Err(invalid(
                        element,
                        format!(
                            "a {kind} acts on the angle of point mass '{b}', which has no \
                             rotation; make '{b}' a rigid body"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Joints that constrain a body's angle cannot attach to a point mass.
    fn check_rotation(&self, j: &JointSpec) -> Result<(), ModelError> {
        match j {
            JointSpec::Prismatic {
                name,
                body_a,
                body_b,
                ..
            } => self.no_rotation(
                format!("joint '{name}'"),
                "prismatic joint",
                &[body_a, body_b],
            ),
            JointSpec::Weld {
                name,
                body_a,
                body_b,
                ..
            } => self.no_rotation(format!("joint '{name}'"), "weld joint", &[body_a, body_b]),
            JointSpec::AngleDriver {
                name,
                body_a,
                body_b,
                ..
            } => self.no_rotation(format!("joint '{name}'"), "angle driver", &[body_a, body_b]),
            JointSpec::Absolute {
                name,
                body,
                coordinate: Coordinate::Angle,
                ..
            } => self.no_rotation(format!("joint '{name}'"), "absolute angle joint", &[body]),
            _ => Ok(()),
        }
    }

    /// Torques and rotary springs cannot act on a point mass.
    fn check_force_rotation(&self, f: &ForceSpec) -> Result<(), ModelError> {
        match f {
            ForceSpec::RotarySpringDamper {
                name,
                body_a,
                body_b,
                ..
            } => self.no_rotation(
                format!("force '{name}'"),
                "rotary spring-damper",
                &[body_a, body_b],
            ),
            ForceSpec::Torque { name, body, .. } => {
                self.no_rotation(format!("force '{name}'"), "torque", &[body])
            }
            _ => Ok(()),
        }
    }
}

impl ModelFile {
    /// See [`ModelFile::to_builder`].
    pub(super) fn to_builder_impl(&self) -> Result<SystemBuilder, ModelError> {
        let r = Resolver::new(self)?;
        let mut b = SystemBuilder::new();
        b.set_gravity(self.gravity);
        for body in &r.bodies {
            b.add_body(body.clone());
        }
        for j in &self.joints {
            r.check_rotation(j)?;
            let joint = match j {
                JointSpec::Revolute {
                    name,
                    body_a,
                    point_a,
                    body_b,
                    point_b,
                } => Joint::revolute(
                    name.clone(),
                    r.find(&format!("joint '{name}'"), body_a)?,
                    r.point(&format!("joint '{name}'"), "point_a", body_a, *point_a)?,
                    r.find(&format!("joint '{name}'"), body_b)?,
                    r.point(&format!("joint '{name}'"), "point_b", body_b, *point_b)?,
                ),
                JointSpec::Prismatic {
                    name,
                    body_a,
                    point_a,
                    body_b,
                    point_b,
                    axis,
                    angle,
                } => Joint::prismatic(
                    name.clone(),
                    r.find(&format!("joint '{name}'"), body_a)?,
                    r.point(&format!("joint '{name}'"), "point_a", body_a, *point_a)?,
                    r.find(&format!("joint '{name}'"), body_b)?,
                    r.point(&format!("joint '{name}'"), "point_b", body_b, *point_b)?,
                    *axis,
                    *angle,
                ),
                JointSpec::Weld {
                    name,
                    body_a,
                    point_a,
                    body_b,
                    point_b,
                    angle,
                } => Joint::weld(
                    name.clone(),
                    r.find(&format!("joint '{name}'"), body_a)?,
                    r.point(&format!("joint '{name}'"), "point_a", body_a, *point_a)?,
                    r.find(&format!("joint '{name}'"), body_b)?,
                    r.point(&format!("joint '{name}'"), "point_b", body_b, *point_b)?,
                    *angle,
                ),
                JointSpec::Distance {
                    name,
                    body_a,
                    point_a,
                    body_b,
                    point_b,
                    length,
                } => Joint::distance(
                    name.clone(),
                    r.find(&format!("joint '{name}'"), body_a)?,
                    r.point(&format!("joint '{name}'"), "point_a", body_a, *point_a)?,
                    r.find(&format!("joint '{name}'"), body_b)?,
                    r.point(&format!("joint '{name}'"), "point_b", body_b, *point_b)?,
                    *length,
                ),
                JointSpec::Absolute {
                    name,
                    body,
                    point,
                    coordinate,
                    value,
                } => Joint::absolute(
                    name.clone(),
                    r.find(&format!("joint '{name}'"), body)?,
                    r.point(&format!("joint '{name}'"), "point", body, *point)?,
                    *coordinate,
                    *value,
                ),
                JointSpec::AngleDriver {
                    name,
                    body_a,
                    body_b,
                    f,
                } => Joint::angle_driver(
                    name.clone(),
                    r.find(&format!("joint '{name}'"), body_a)?,
                    r.find(&format!("joint '{name}'"), body_b)?,
                    f.clone(),
                ),
            };
            b.add_joint(joint);
        }
        for f in &self.forces {
            r.check_force_rotation(f)?;
            let force = match f {
                ForceSpec::SpringDamper {
                    name,
                    body_a,
                    point_a,
                    body_b,
                    point_b,
                    stiffness,
                    damping,
                    rest_length,
                } => Force::spring_damper(
                    name.clone(),
                    r.find(&format!("force '{name}'"), body_a)?,
                    r.point(&format!("force '{name}'"), "point_a", body_a, *point_a)?,
                    r.find(&format!("force '{name}'"), body_b)?,
                    r.point(&format!("force '{name}'"), "point_b", body_b, *point_b)?,
                    *stiffness,
                    *damping,
                    *rest_length,
                ),
                ForceSpec::RotarySpringDamper {
                    name,
                    body_a,
                    body_b,
                    stiffness,
                    damping,
                    rest_angle,
                } => Force::rotary_spring_damper(
                    name.clone(),
                    r.find(&format!("force '{name}'"), body_a)?,
                    r.find(&format!("force '{name}'"), body_b)?,
                    *stiffness,
                    *damping,
                    *rest_angle,
                ),
                ForceSpec::Force {
                    name,
                    body,
                    point,
                    fx,
                    fy,
                } => Force::force(
                    name.clone(),
                    r.find(&format!("force '{name}'"), body)?,
                    r.point(&format!("force '{name}'"), "point", body, *point)?,
                    fx.clone(),
                    fy.clone(),
                ),
                ForceSpec::Torque { name, body, torque } => Force::torque(
                    name.clone(),
                    r.find(&format!("force '{name}'"), body)?,
                    torque.clone(),
                ),
            };
            b.add_force(force);
        }
        for (i, spec) in self.bodies.iter().enumerate() {
            if spec.kind == BodyKind::PointMass {
                b.add_joint(Joint::absolute(
                    format!("{}:point_mass", spec.name),
                    BodyHandle(i),
                    [0.0, 0.0],
                    Coordinate::Angle,
                    0.0,
                ));
            }
        }
        Ok(b)
    }
}

impl System {
    /// The model as a file description (bodies by name).
    pub fn to_model_file(&self) -> ModelFile {
        let name = |r: BodyRef| -> String {
            match r {
                BodyRef::Ground => "ground".to_string(),
                BodyRef::Body(h) => self.bodies[h.0].name.clone(),
            }
        };
        let joints = self
            .joints
            .iter()
            .map(|j| {
                let n = j.name.clone();
                match &j.kind {
                    JointKind::Revolute { a, pa, b, pb } => JointSpec::Revolute {
                        name: n,
                        body_a: name(*a),
                        point_a: *pa,
                        body_b: name(*b),
                        point_b: *pb,
                    },
                    JointKind::Prismatic {
                        a,
                        pa,
                        b,
                        pb,
                        axis,
                        angle,
                    } => JointSpec::Prismatic {
                        name: n,
                        body_a: name(*a),
                        point_a: *pa,
                        body_b: name(*b),
                        point_b: *pb,
                        axis: *axis,
                        angle: *angle,
                    },
                    JointKind::Weld {
                        a,
                        pa,
                        b,
                        pb,
                        angle,
                    } => JointSpec::Weld {
                        name: n,
                        body_a: name(*a),
                        point_a: *pa,
                        body_b: name(*b),
                        point_b: *pb,
                        angle: *angle,
                    },
                    JointKind::Distance {
                        a,
                        pa,
                        b,
                        pb,
                        length,
                    } => JointSpec::Distance {
                        name: n,
                        body_a: name(*a),
                        point_a: *pa,
                        body_b: name(*b),
                        point_b: *pb,
                        length: *length,
                    },
                    JointKind::Absolute {
                        body,
                        point,
                        coordinate,
                        value,
                    } => JointSpec::Absolute {
                        name: n,
                        body: name(*body),
                        point: *point,
                        coordinate: *coordinate,
                        value: *value,
                    },
                    JointKind::AngleDriver { a, b, f } => JointSpec::AngleDriver {
                        name: n,
                        body_a: name(*a),
                        body_b: name(*b),
                        f: f.clone(),
                    },
                }
            })
            .collect();
        let forces = self
            .forces
            .iter()
            .map(|f| {
                let n = f.name.clone();
                match &f.kind {
                    ForceKind::SpringDamper {
                        a,
                        pa,
                        b,
                        pb,
                        stiffness,
                        damping,
                        rest_length,
                    } => ForceSpec::SpringDamper {
                        name: n,
                        body_a: name(*a),
                        point_a: *pa,
                        body_b: name(*b),
                        point_b: *pb,
                        stiffness: *stiffness,
                        damping: *damping,
                        rest_length: *rest_length,
                    },
                    ForceKind::RotarySpringDamper {
                        a,
                        b,
                        stiffness,
                        damping,
                        rest_angle,
                    } => ForceSpec::RotarySpringDamper {
                        name: n,
                        body_a: name(*a),
                        body_b: name(*b),
                        stiffness: *stiffness,
                        damping: *damping,
                        rest_angle: *rest_angle,
                    },
                    ForceKind::Force {
                        body,
                        point,
                        fx,
                        fy,
                    } => ForceSpec::Force {
                        name: n,
                        body: name(*body),
                        point: *point,
                        fx: fx.clone(),
                        fy: fy.clone(),
                    },
                    ForceKind::Torque { body, torque } => ForceSpec::Torque {
                        name: n,
                        body: name(*body),
                        torque: torque.clone(),
                    },
                }
            })
            .collect();
        ModelFile {
            gravity: self.gravity,
            bodies: self
                .bodies
                .iter()
                .map(|b| BodySpec {
                    name: b.name.clone(),
                    kind: BodyKind::Rigid,
                    mass: b.mass,
                    inertia: Some(b.inertia),
                    position: b.position,
                    velocity: b.velocity,
                    com: None,
                })
                .collect(),
            joints,
            forces,
        }
    }
}
