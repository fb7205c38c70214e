//! From a model file to a builder and back: names to handles. Body frames (`com`) and point
//! masses go to the builder as they are ([`SystemBuilder::set_body_frame`],
//! [`SystemBuilder::add_point_mass`]), which lowers them to centres of mass and constrained
//! bodies: one implementation for files and Rust models.

use super::spec::{BodyKind, BodySpec};
use super::ModelFile;
use crate::body::{Body, BodyHandle, BodyRef};
use crate::builder::SystemBuilder;
use crate::check::invalid;
use crate::error::ModelError;
use crate::init::RedundantConstraints;
use crate::sensors::{Sensor, SensorKind, SensorSpec};
use crate::system::System;

/// Body names resolved, with each body's frame offset and kind.
struct Resolver<'a> {
    /// Body name to index (the first body of a name: duplicates are an error of the build).
    index: std::collections::HashMap<&'a str, usize>,
    /// The bodies as the file gives them (frame-origin poses; a point mass's inertia is set by
    /// the builder).
    bodies: Vec<Body>,
    /// The spatial bodies' names (a planar element naming one gets an error saying so).
    spatial: std::collections::HashSet<&'a str>,
}

impl<'a> Resolver<'a> {
    fn new(file: &'a ModelFile) -> Result<Self, ModelError> {
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
                // set by the builder (nominal inertia)
                (BodyKind::PointMass, None) => f64::NAN,
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
            let mut inputs = crate::Inputs::default();
            for i in &s.inputs {
                let (velocity, k) = i.slot();
                if k == 2 && s.kind == BodyKind::PointMass {
                    return Err(invalid(
                        element,
                        "inputs: a point mass has no angle to keep (theta, d_theta)".into(),
                    ));
                }
                if velocity {
                    inputs.velocity[k] = true;
                } else {
                    inputs.position[k] = true;
                }
            }
            bodies.push(Body {
                name: s.name.clone(),
                mass: s.mass,
                inertia,
                position: s.position,
                velocity: s.velocity,
                inputs,
            });
        }
        let mut index = std::collections::HashMap::with_capacity(file.bodies.len());
        for (i, b) in file.bodies.iter().enumerate() {
            index.entry(b.name.as_str()).or_insert(i);
        }
        let spatial = file
            .spatial_bodies
            .iter()
            .map(|b| b.name.as_str())
            .collect();
        Ok(Resolver {
            index,
            bodies,
            spatial,
        })
    }

    fn find(&self, element: &str, name: &str) -> Result<BodyRef, ModelError> {
        if name.eq_ignore_ascii_case("ground") {
            return Ok(BodyRef::Ground);
        }
        match self.index.get(name) {
            Some(&i) => Ok(BodyRef::Body(BodyHandle(i))),
            None if self.spatial.contains(name) => Err(invalid(
                element.to_string(),
                format!(
                    "'{name}' is a spatial body: planar elements ([[joints]], [[forces]], \
                     point and joint sensors) join planar bodies; join it with \
                     [[spatial_joints]] and [[spatial_forces]]"
                ),
            )),
            None => Err(ModelError::UnknownBody {
                element: element.to_string(),
                body: name.to_string(),
            }),
        }
    }
}

impl ModelFile {
    /// See [`ModelFile::to_builder`].
    pub(super) fn to_builder_impl(
        &self,
        laws: &crate::forces::ForceLaws,
    ) -> Result<SystemBuilder, ModelError> {
        let r = Resolver::new(self)?;
        let mut b = SystemBuilder::new();
        b.set_gravity(self.gravity);
        b.redundant_constraints(self.redundant_constraints);
        for (body, spec) in r.bodies.iter().zip(&self.bodies) {
            let h = if spec.kind == BodyKind::PointMass {
                let (p, v) = (body.position, body.velocity);
                let h = b.add_point_mass(body.name.clone(), body.mass, [p[0], p[1]], [v[0], v[1]]);
                b.set_inputs(h, body.inputs);
                h
            } else {
                b.add_body(body.clone())
            };
            if let Some(c) = spec.com {
                b.set_body_frame(h, c);
            }
        }
        let find = |element: &str, body: &str| r.find(element, body);
        let mut joints = std::collections::HashMap::with_capacity(self.joints.len());
        for j in &self.joints {
            let joint = j.to_joint(&find)?;
            let name = joint.name.clone();
            let h = b.add_joint(joint);
            joints.entry(name).or_insert(h);
        }
        for f in &self.forces {
            b.add_force(f.to_force(&find, laws)?);
        }
        for a in &self.assembly {
            let h = joints.get(&a.joint).copied().ok_or_else(|| {
                invalid(
                    format!("assembly entry for joint '{}'", a.joint),
                    "no joint has this name".to_string(),
                )
            })?;
            b.set_joint_initial(
                h,
                crate::JointInitial {
                    coordinate: a.coordinate,
                    rate: a.rate,
                },
            );
        }
        let sensor_joint = |name: &str, joint: &str| {
            joints.get(joint).copied().ok_or_else(|| {
                let spatial = self.spatial_joints.iter().any(|j| j.name == joint);
                invalid(
                    format!("sensor '{name}'"),
                    if spatial {
                        format!(
                            "'{joint}' is a spatial joint: joint sensors read a planar joint's \
                             coordinate and rate; for a spatial joint use a reaction sensor, or \
                             spatial_point and angular_velocity sensors on its bodies"
                        )
                    } else {
                        format!("refers to unknown joint '{joint}'")
                    },
                )
            })
        };
        // spatial bodies, point masses and joints by name: their handles are their places in
        // the file among their kind (`add_spatial` adds them in order)
        let place = |kind, name: &str| {
            self.spatial_bodies
                .iter()
                .filter(|b| b.kind == kind)
                .position(|b| b.name == name)
        };
        let spatial_body = |name: &str| {
            place(super::SpatialBodyKind::Rigid, name).map(crate::spatial::SpatialBodyHandle)
        };
        let spatial_point = |name: &str| {
            place(super::SpatialBodyKind::PointMass, name)
                .map(crate::spatial::SpatialPointMassHandle)
        };
        // a spatial point mass or rigid body (names are unique among all bodies)
        let spatial_ref = |name: &str| -> Option<crate::spatial::SpatialBodyRef> {
            spatial_point(name)
                .map(Into::into)
                .or_else(|| spatial_body(name).map(Into::into))
        };
        let spatial_joint = |name: &str| self.spatial_joints.iter().position(|j| j.name == name);
        let unknown_spatial = |sensor: &str, body: &str| {
            invalid(
                format!("sensor '{sensor}'"),
                format!("refers to unknown spatial body '{body}'"),
            )
        };
        for s in &self.sensors {
            b.add_sensor(match s {
                SensorSpec::Point { name, body, point } => {
                    Sensor::point(name, find(&format!("sensor '{name}'"), body)?, *point)
                }
                SensorSpec::Joint { name, joint } => {
                    Sensor::joint(name, sensor_joint(name, joint)?)
                }
                SensorSpec::Reaction { name, joint } => match spatial_joint(joint) {
                    Some(k) if !joints.contains_key(joint) => Sensor::spatial_reaction(name, k),
                    _ => Sensor::reaction(name, sensor_joint(name, joint)?),
                },
                // a spatial body or point mass, else a planar body (or ground)
                SensorSpec::Energy { name, body } => match body.as_deref() {
                    Some(body) => match spatial_ref(body) {
                        Some(r) => Sensor::spatial_energy(name, r),
                        None => {
                            Sensor::energy(name, Some(find(&format!("sensor '{name}'"), body)?))
                        }
                    },
                    None => Sensor::energy(name, None),
                },
                SensorSpec::SpatialPoint { name, body, point } => {
                    let r = if body.eq_ignore_ascii_case("ground") {
                        crate::spatial::SpatialBodyRef::Ground
                    } else {
                        spatial_ref(body).ok_or_else(|| unknown_spatial(name, body))?
                    };
                    Sensor::spatial_point(name, r, *point)
                }
                SensorSpec::AngularVelocity { name, body } if spatial_point(body).is_some() => {
                    return Err(ModelError::PointMassLoad {
                        element: format!("sensor '{name}'"),
                        point_mass: body.clone(),
                        what: "angular velocity",
                    })
                }
                SensorSpec::AngularVelocity { name, body } => Sensor::angular_velocity(
                    name,
                    spatial_body(body).ok_or_else(|| unknown_spatial(name, body))?,
                ),
            });
        }
        let planar = |n: &str| self.bodies.iter().any(|b| b.name == n);
        super::spatial::add_spatial(
            &mut b,
            self.spatial_gravity,
            &self.spatial_bodies,
            &self.spatial_joints,
            &self.spatial_forces,
            &planar,
        )?;
        Ok(b)
    }
}

impl System {
    /// The model as a file description (bodies by name; spatial bodies with their inertia as
    /// principal moments and axes and their orientation as a matrix).
    pub fn to_model_file(&self) -> ModelFile {
        let name = |r: BodyRef| -> String {
            match r {
                BodyRef::Ground => "ground".to_string(),
                BodyRef::Body(h) => self.bodies[h.0].name.clone(),
            }
        };
        let joints = self.joints.iter().map(|j| j.to_spec(&name)).collect();
        let forces = self.forces.iter().map(|f| f.to_spec(&name)).collect();
        let spatial_name = |r: crate::spatial::SpatialBodyRef| match r {
            crate::spatial::SpatialBodyRef::Body(h) => self.spatial.bodies[h.0].name.clone(),
            crate::spatial::SpatialBodyRef::PointMass(h) => self.spatial.points[h.0].name.clone(),
            crate::spatial::SpatialBodyRef::Ground => "ground".to_string(),
        };
        let sensors = self
            .sensors
            .iter()
            .filter_map(|s| match &s.kind {
                SensorKind::Point { body, point } => Some(SensorSpec::Point {
                    name: s.name.clone(),
                    body: name(*body),
                    point: *point,
                }),
                SensorKind::Joint { joint } => Some(SensorSpec::Joint {
                    name: s.name.clone(),
                    joint: self.joints.get(joint.index())?.name.clone(),
                }),
                SensorKind::Reaction { joint } => Some(SensorSpec::Reaction {
                    name: s.name.clone(),
                    joint: self.joints.get(joint.index())?.name.clone(),
                }),
                SensorKind::SpatialPoint { body, point } => Some(SensorSpec::SpatialPoint {
                    name: s.name.clone(),
                    body: spatial_name(*body),
                    point: *point,
                }),
                SensorKind::AngularVelocity { body } => Some(SensorSpec::AngularVelocity {
                    name: s.name.clone(),
                    body: spatial_name((*body).into()),
                }),
                SensorKind::SpatialReaction { joint } => Some(SensorSpec::Reaction {
                    name: s.name.clone(),
                    joint: self.spatial.joints.get(*joint)?.name.clone(),
                }),
                SensorKind::SpatialEnergy { body } => Some(SensorSpec::Energy {
                    name: s.name.clone(),
                    body: Some(spatial_name(*body)),
                }),
                SensorKind::Energy { body } => Some(SensorSpec::Energy {
                    name: s.name.clone(),
                    body: body.map(name),
                }),
            })
            .collect();
        let assembly = self
            .joint_initials
            .iter()
            .map(|&(j, init)| crate::JointInitialSpec {
                joint: self.joints[j].name.clone(),
                coordinate: init.coordinate,
                rate: init.rate,
            })
            .collect();
        ModelFile {
            sensors,
            assembly,
            gravity: self.gravity,
            redundant_constraints: RedundantConstraints::Allow,
            spatial_gravity: self.spatial.gravity,
            spatial_bodies: self
                .spatial
                .bodies
                .iter()
                .map(super::spatial::SpatialBodySpec::from_body)
                .chain(
                    self.spatial
                        .points
                        .iter()
                        .map(super::spatial::SpatialBodySpec::from_point_mass),
                )
                .collect(),
            spatial_joints: self
                .spatial
                .joints
                .iter()
                .map(|j| super::spatial::SpatialJointSpec::from_entry(j, &spatial_name))
                .collect(),
            spatial_forces: self
                .spatial
                .forces
                .iter()
                .map(|f| super::SpatialForceSpec::from_force(f, &spatial_name))
                .collect(),
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
                    inputs: super::spec::InitialInput::list(&b.inputs),
                })
                .collect(),
            joints,
            forces,
        }
    }
}
