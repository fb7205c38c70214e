//! The types of a model file, one per element; their JSON Schema is derived from them.

use crate::joint::Coordinate;
use crate::timefn::TimeFunction;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How a body moves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum BodyKind {
    /// A rigid body: `x`, `y` of its centre of mass and its angle `theta`.
    #[default]
    Rigid,
    /// A particle: `x`, `y` only. Loaded as a body with a nominal inertia whose angle is held
    /// at 0 by an extra constraint equation; joints and forces attach only at its centre, and
    /// elements that act on its angle are rejected.
    PointMass,
}

fn is_rigid(k: &BodyKind) -> bool {
    *k == BodyKind::Rigid
}

/// A body in a model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Unique name (not `ground`).
    pub name: String,
    /// `rigid` (default) or `point_mass`.
    #[serde(default, skip_serializing_if = "is_rigid")]
    pub kind: BodyKind,
    /// Mass, kg (> 0).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub mass: f64,
    /// Moment of inertia about the centre of mass, kg m^2 (> 0). Required for a rigid body,
    /// not allowed for a point mass.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub inertia: Option<f64>,
    /// Initial `[x, y, theta]` (m, m, rad) of the body frame: of the centre of mass, or of the
    /// frame origin when `com` is given. `theta` must be 0 for a point mass.
    #[serde(default)]
    pub position: [f64; 3],
    /// Initial `[xdot, ydot, thetadot]` (m/s, m/s, rad/s) of the same point; `thetadot` must be
    /// 0 for a point mass.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Centre of mass in the body frame, m. When given, `position` and `velocity` are those of
    /// the frame's origin and every local point on this body is in this frame (like a CAD
    /// part); when absent the frame's origin is the centre of mass.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub com: Option<[f64; 2]>,
}

/// A joint in a model file (bodies by name).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
#[allow(missing_docs)]
pub enum JointSpec {
    /// See [`JointKind::Revolute`](crate::JointKind::Revolute).
    Revolute {
        name: String,
        body_a: String,
        #[serde(default)]
        point_a: [f64; 2],
        body_b: String,
        #[serde(default)]
        point_b: [f64; 2],
    },
    /// See [`JointKind::Prismatic`](crate::JointKind::Prismatic).
    Prismatic {
        name: String,
        body_a: String,
        #[serde(default)]
        point_a: [f64; 2],
        body_b: String,
        #[serde(default)]
        point_b: [f64; 2],
        axis: [f64; 2],
        #[serde(default)]
        angle: f64,
    },
    /// See [`JointKind::Weld`](crate::JointKind::Weld).
    Weld {
        name: String,
        body_a: String,
        #[serde(default)]
        point_a: [f64; 2],
        body_b: String,
        #[serde(default)]
        point_b: [f64; 2],
        #[serde(default)]
        angle: f64,
    },
    /// See [`JointKind::Distance`](crate::JointKind::Distance).
    Distance {
        name: String,
        body_a: String,
        #[serde(default)]
        point_a: [f64; 2],
        body_b: String,
        #[serde(default)]
        point_b: [f64; 2],
        length: f64,
    },
    /// See [`JointKind::Absolute`](crate::JointKind::Absolute).
    Absolute {
        name: String,
        body: String,
        #[serde(default)]
        point: [f64; 2],
        coordinate: Coordinate,
        value: f64,
    },
    /// See [`JointKind::AngleDriver`](crate::JointKind::AngleDriver).
    AngleDriver {
        name: String,
        body_a: String,
        body_b: String,
        f: TimeFunction,
    },
}

/// A force element in a model file (bodies by name).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
#[allow(missing_docs)]
pub enum ForceSpec {
    /// See [`ForceKind::SpringDamper`](crate::ForceKind::SpringDamper).
    SpringDamper {
        name: String,
        body_a: String,
        #[serde(default)]
        point_a: [f64; 2],
        body_b: String,
        #[serde(default)]
        point_b: [f64; 2],
        stiffness: f64,
        #[serde(default)]
        damping: f64,
        rest_length: f64,
    },
    /// See [`ForceKind::RotarySpringDamper`](crate::ForceKind::RotarySpringDamper).
    RotarySpringDamper {
        name: String,
        body_a: String,
        body_b: String,
        stiffness: f64,
        #[serde(default)]
        damping: f64,
        #[serde(default)]
        rest_angle: f64,
    },
    /// See [`ForceKind::Force`](crate::ForceKind::Force).
    Force {
        name: String,
        body: String,
        #[serde(default)]
        point: [f64; 2],
        fx: TimeFunction,
        fy: TimeFunction,
    },
    /// See [`ForceKind::Torque`](crate::ForceKind::Torque).
    Torque {
        name: String,
        body: String,
        torque: TimeFunction,
    },
}
