//! Sensors: quantities a model names for its output, beside the state (`mbd run`'s columns,
//! `mbd_solve::SensorSolver`). Part of the model (as in Exudyn and MuJoCo) so that a model file
//! says what to measure.

use crate::body::BodyRef;
use crate::check::invalid;
use crate::error::ModelError;
use crate::spatial::{SpatialBodyHandle, SpatialBodyRef};
use crate::system::JointHandle;
use serde::{Deserialize, Serialize};

/// A measured quantity (see each kind for its output columns).
#[derive(Clone, Debug, PartialEq)]
pub struct Sensor {
    /// Unique sensor name: the prefix of its columns (`tip.x`, ...).
    pub name: String,
    /// What it measures.
    pub kind: SensorKind,
}

/// What a [`Sensor`] measures.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SensorKind {
    /// A body-fixed point (body frame, relative to the centre of mass; for a body with a frame
    /// offset, in that frame like every local point): its position, velocity and acceleration in
    /// global axes, columns `NAME.x`, `.y`, `.vx`, `.vy`, `.ax`, `.ay`.
    Point {
        /// The body (ground gives a fixed point).
        body: BodyRef,
        /// The point.
        point: [f64; 2],
    },
    /// A joint's relative coordinates: the angle of its second body relative to its first and
    /// its rate, columns `NAME.angle`, `.rate`; for a prismatic joint also the slide along its
    /// axis between its two points and its rate, `NAME.s`, `.ds`.
    Joint {
        /// The joint.
        joint: JointHandle,
    },
    /// The load a joint exerts on its second body (`mbd_solve::JointReaction`, whose
    /// documentation gives the conventions): the force in global axes `NAME.fx`, `.fy` (N),
    /// the moment about the joint's point on that body `NAME.mz` (N m), and the force in the
    /// body's own axes `NAME.fx_body`, `.fy_body` (N).
    Reaction {
        /// The joint.
        joint: JointHandle,
    },
    /// Energies (J), columns `NAME.kinetic`, `.potential`, `.total`. Without a body: the
    /// model's kinetic energy `T`, potential `V` (gravity, springs, constant loads) and
    /// `H = T + V`. With a body: its kinetic energy `m |v|^2 / 2 + J omega^2 / 2` and the
    /// potential of gravity on it, `-m g . r` (springs belong to no single body).
    Energy {
        /// The body, or `None` for the whole model.
        body: Option<BodyRef>,
    },
    /// A point of a spatial body (body frame, from the centre of mass; ground: a global fixed
    /// point; a spatial point mass: its position, the point zero): its position, velocity and
    /// acceleration in global axes, columns `NAME.x`, `.y`, `.z`, `.vx`, `.vy`, `.vz`, `.ax`,
    /// `.ay`, `.az`.
    SpatialPoint {
        /// The body.
        body: SpatialBodyRef,
        /// The point.
        point: [f64; 3],
    },
    /// A spatial body's angular velocity (rad/s): global components `NAME.wx`, `.wy`, `.wz`
    /// and the body frame's `NAME.wx_body`, `.wy_body`, `.wz_body`.
    AngularVelocity {
        /// The body.
        body: SpatialBodyHandle,
    },
    /// The load a spatial joint exerts on its second body
    /// ([`crate::System::spatial_joint_reactions`]): force `NAME.fx`, `.fy`, `.fz` (N) and moment
    /// about the joint's point on that body `NAME.mx`, `.my`, `.mz` (N m), global axes.
    SpatialReaction {
        /// The joint's index among the spatial joints.
        joint: usize,
    },
    /// A spatial body's or spatial point mass's kinetic energy and the potential of gravity on
    /// it (J), columns `NAME.kinetic`, `.potential`, `.total`: for a rigid body
    /// `m |v|^2 / 2 + omega . J omega / 2` and `-m g . x` (`x` its centre of mass), for a point
    /// mass `m |x'|^2 / 2` and `-m g . x` (`x` its position); ground gives zeros, as for the
    /// planar [`SensorKind::Energy`].
    SpatialEnergy {
        /// The rigid body or point mass.
        body: SpatialBodyRef,
    },
}

impl Sensor {
    /// A point sensor (see [`SensorKind::Point`]).
    pub fn point(name: impl Into<String>, body: impl Into<BodyRef>, point: [f64; 2]) -> Self {
        Sensor {
            name: name.into(),
            kind: SensorKind::Point {
                body: body.into(),
                point,
            },
        }
    }

    /// A joint sensor (see [`SensorKind::Joint`]).
    pub fn joint(name: impl Into<String>, joint: JointHandle) -> Self {
        Sensor {
            name: name.into(),
            kind: SensorKind::Joint { joint },
        }
    }

    /// A reaction sensor (see [`SensorKind::Reaction`]).
    pub fn reaction(name: impl Into<String>, joint: JointHandle) -> Self {
        Sensor {
            name: name.into(),
            kind: SensorKind::Reaction { joint },
        }
    }

    /// An energy sensor for the whole model (`body = None`) or one body (see
    /// [`SensorKind::Energy`]).
    pub fn energy(name: impl Into<String>, body: Option<BodyRef>) -> Self {
        Sensor {
            name: name.into(),
            kind: SensorKind::Energy { body },
        }
    }

    /// A point sensor on a spatial body (see [`SensorKind::SpatialPoint`]).
    pub fn spatial_point(
        name: impl Into<String>,
        body: impl Into<SpatialBodyRef>,
        point: [f64; 3],
    ) -> Self {
        Sensor {
            name: name.into(),
            kind: SensorKind::SpatialPoint {
                body: body.into(),
                point,
            },
        }
    }

    /// A spatial body's angular velocity (see [`SensorKind::AngularVelocity`]).
    pub fn angular_velocity(name: impl Into<String>, body: SpatialBodyHandle) -> Self {
        Sensor {
            name: name.into(),
            kind: SensorKind::AngularVelocity { body },
        }
    }

    /// A spatial joint's reaction (see [`SensorKind::SpatialReaction`]); `joint` is its index
    /// among the spatial joints (what [`crate::SystemBuilder::add_spatial_joint`] returns).
    pub fn spatial_reaction(name: impl Into<String>, joint: usize) -> Self {
        Sensor {
            name: name.into(),
            kind: SensorKind::SpatialReaction { joint },
        }
    }

    /// A spatial body's or point mass's energies (see [`SensorKind::SpatialEnergy`]): `body` a
    /// [`SpatialBodyHandle`] or a [`crate::spatial::SpatialPointMassHandle`].
    pub fn spatial_energy(name: impl Into<String>, body: impl Into<SpatialBodyRef>) -> Self {
        Sensor {
            name: name.into(),
            kind: SensorKind::SpatialEnergy { body: body.into() },
        }
    }

    /// The joint a joint or reaction sensor reads, if any.
    pub(crate) fn joint_read(&self) -> Option<JointHandle> {
        match self.kind {
            SensorKind::Joint { joint } | SensorKind::Reaction { joint } => Some(joint),
            _ => None,
        }
    }

    pub(crate) fn validate(&self) -> Result<(), ModelError> {
        let finite = match &self.kind {
            SensorKind::Point { point, .. } => point.iter().all(|x| x.is_finite()),
            SensorKind::SpatialPoint { point, .. } => point.iter().all(|x| x.is_finite()),
            _ => true,
        };
        if !finite {
            return Err(invalid(
                format!("sensor '{}'", self.name),
                "its point must be finite".to_string(),
            ));
        }
        Ok(())
    }

    /// Checks the spatial body, point mass or joint a sensor reads against the model's spatial
    /// `bodies`, `points` and joint count; errors name the sensor (and a point mass whose
    /// sensor point is off its position).
    pub(crate) fn check_spatial(
        &self,
        bodies: &[crate::spatial::SpatialBody],
        points: &[crate::spatial::SpatialPointMass],
        joints: usize,
    ) -> Result<(), ModelError> {
        let bodies = bodies.len();
        let (what, k, n) = match self.kind {
            SensorKind::SpatialPoint {
                body: SpatialBodyRef::PointMass(h),
                point,
            } => match points.get(h.0) {
                Some(p) if point != [0.0; 3] => {
                    return Err(ModelError::PointMassOffset {
                        element: format!("sensor '{}'", self.name),
                        point_mass: p.name.clone(),
                        point,
                    })
                }
                _ => ("spatial point mass", h.0, points.len()),
            },
            SensorKind::SpatialPoint { body, .. } => match body.index() {
                Some(k) => ("spatial body", k, bodies),
                None => return Ok(()),
            },
            SensorKind::SpatialEnergy { body } => match body {
                SpatialBodyRef::Body(h) => ("spatial body", h.0, bodies),
                SpatialBodyRef::PointMass(h) => ("spatial point mass", h.0, points.len()),
                SpatialBodyRef::Ground => return Ok(()),
            },
            SensorKind::AngularVelocity { body } => ("spatial body", body.index(), bodies),
            SensorKind::SpatialReaction { joint } => ("spatial joint", joint, joints),
            _ => return Ok(()),
        };
        if k < n {
            Ok(())
        } else {
            Err(invalid(
                format!("sensor '{}'", self.name),
                format!("{what} #{k} does not exist (the model has {n})"),
            ))
        }
    }
}

/// A sensor in a model file (bodies and joints by name), tagged by `type`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum SensorSpec {
    /// A body-fixed point: position, velocity and acceleration (columns `NAME.x`, `.y`, `.vx`,
    /// `.vy`, `.ax`, `.ay`).
    Point {
        /// Unique sensor name.
        name: String,
        /// The body.
        body: String,
        /// The point on it (body frame), m.
        #[serde(default)]
        point: [f64; 2],
    },
    /// A joint's relative angle and rate (`NAME.angle`, `.rate`; a prismatic joint adds its
    /// slide `NAME.s`, `.ds`).
    Joint {
        /// Unique sensor name.
        name: String,
        /// The joint.
        joint: String,
    },
    /// The load a joint exerts on its second body: `NAME.fx`, `.fy` (global axes), `.mz`
    /// (about the joint's point on that body), `.fx_body`, `.fy_body` (the body's axes).
    Reaction {
        /// Unique sensor name.
        name: String,
        /// The joint.
        joint: String,
    },
    /// Kinetic, potential and total energy (`NAME.kinetic`, `.potential`, `.total`) of the
    /// model, or of one body, planar or spatial, or of a spatial point mass (its kinetic
    /// energy and the potential of gravity on it).
    Energy {
        /// Unique sensor name.
        name: String,
        /// The body (planar or spatial) or spatial point mass; absent for the whole model.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        body: Option<String>,
    },
    /// A point of a spatial body: position, velocity and acceleration in global axes
    /// (`NAME.x`, `.y`, `.z`, `.vx`, `.vy`, `.vz`, `.ax`, `.ay`, `.az`).
    SpatialPoint {
        /// Unique sensor name.
        name: String,
        /// The spatial body (`ground` for a fixed point).
        body: String,
        /// The point on it (body frame, from the centre of mass), m.
        #[serde(default)]
        point: [f64; 3],
    },
    /// A spatial body's angular velocity, global (`NAME.wx`, `.wy`, `.wz`) and in its body
    /// frame (`NAME.wx_body`, `.wy_body`, `.wz_body`), rad/s.
    AngularVelocity {
        /// Unique sensor name.
        name: String,
        /// The spatial body.
        body: String,
    },
}
