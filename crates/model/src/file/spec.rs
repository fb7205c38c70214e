//! The types of a model file, one per element; their JSON Schema is derived from them.

use crate::forces::{PointForceSpec, RotarySpringDamperSpec, SpringDamperSpec, TorqueSpec};
use crate::joints::{
    AbsoluteSpec, AngleDriverSpec, DistanceDriverSpec, DistanceSpec, PrismaticSpec, RevoluteSpec,
    SlideDriverSpec, WeldSpec,
};
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
    /// Initial values the consistent-state solve keeps (the others are solved for): any of
    /// `x`, `y`, `theta` (positions) and `d_x`, `d_y`, `d_theta` (velocities), e.g.
    /// `inputs = ["d_theta"]` for a crank whose `6 rad/s` must stay. `x`, `y` inputs need no
    /// `com`; a point mass has no `theta`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inputs: Vec<InitialInput>,
}

/// An initial value a model file marks as an input ([`BodySpec::inputs`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub enum InitialInput {
    /// The centre of mass's `x`.
    #[serde(rename = "x")]
    X,
    /// The centre of mass's `y`.
    #[serde(rename = "y")]
    Y,
    /// The angle.
    #[serde(rename = "theta")]
    Theta,
    /// The velocity `xdot`.
    #[serde(rename = "d_x")]
    DX,
    /// The velocity `ydot`.
    #[serde(rename = "d_y")]
    DY,
    /// The angular velocity.
    #[serde(rename = "d_theta")]
    DTheta,
}

impl InitialInput {
    /// Whether it is a velocity, and its offset in `(x, y, theta)`.
    pub fn slot(self) -> (bool, usize) {
        match self {
            InitialInput::X => (false, 0),
            InitialInput::Y => (false, 1),
            InitialInput::Theta => (false, 2),
            InitialInput::DX => (true, 0),
            InitialInput::DY => (true, 1),
            InitialInput::DTheta => (true, 2),
        }
    }
    /// The inputs of a body's [`crate::Inputs`], positions first.
    pub fn list(inputs: &crate::Inputs) -> Vec<InitialInput> {
        use InitialInput::*;
        let mut out = Vec::new();
        for (k, v) in [X, Y, Theta].into_iter().enumerate() {
            if inputs.position[k] {
                out.push(v);
            }
        }
        for (k, v) in [DX, DY, DTheta].into_iter().enumerate() {
            if inputs.velocity[k] {
                out.push(v);
            }
        }
        out
    }
}

/// A joint in a model file (bodies by name), tagged by `type`. Each variant's fields are
/// documented on its spec struct, beside the joint it describes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum JointSpec {
    /// A [`Revolute`](crate::joints::Revolute) joint.
    Revolute(RevoluteSpec),
    /// A [`Prismatic`](crate::joints::Prismatic) joint.
    Prismatic(PrismaticSpec),
    /// A [`Weld`](crate::joints::Weld) joint.
    Weld(WeldSpec),
    /// A [`Distance`](crate::joints::Distance) joint.
    Distance(DistanceSpec),
    /// An [`Absolute`](crate::joints::Absolute) joint.
    Absolute(AbsoluteSpec),
    /// An [`AngleDriver`](crate::joints::AngleDriver).
    AngleDriver(AngleDriverSpec),
    /// A [`SlideDriver`](crate::joints::SlideDriver).
    SlideDriver(SlideDriverSpec),
    /// A [`DistanceDriver`](crate::joints::DistanceDriver).
    DistanceDriver(DistanceDriverSpec),
}

/// A force element in a model file (bodies by name), tagged by `type`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum ForceSpec {
    /// A [`SpringDamper`](crate::forces::SpringDamper).
    SpringDamper(SpringDamperSpec),
    /// A [`RotarySpringDamper`](crate::forces::RotarySpringDamper).
    RotarySpringDamper(RotarySpringDamperSpec),
    /// A [`PointForce`](crate::forces::PointForce).
    Force(PointForceSpec),
    /// A [`Torque`](crate::forces::Torque).
    Torque(TorqueSpec),
    /// A [`CustomForce`](crate::forces::CustomForce): a law registered in a
    /// [`ForceLaws`](crate::forces::ForceLaws).
    Custom(crate::forces::CustomForceSpec),
}
