//! Force elements on spatial bodies in a model file (`[[spatial_forces]]`, tagged by `type`).

use crate::error::ModelError;
use crate::spatial::{Axes, SpatialBodyRef, SpatialForce, SpatialForceKind};
use crate::timefn::TimeFunction;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A spatial force element in a model file (bodies by name, points and load axes in the
/// bodies' frames), tagged by `type`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum SpatialForceSpec {
    /// A spring-damper between a point of each body.
    SpringDamper(SpatialSpringDamperSpec),
    /// A force at a body point.
    Force(SpatialPointForceSpec),
    /// A torque on a body.
    Torque(SpatialTorqueSpec),
}

/// A spatial spring-damper in a model file (see [`crate::spatial::SpatialSpringDamper`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpatialSpringDamperSpec {
    /// Unique element name.
    pub name: String,
    /// First body (`ground` for the ground).
    pub body_a: String,
    /// The point on `body_a` (body frame, from the centre of mass; ground: global), m.
    #[serde(default)]
    pub point_a: [f64; 3],
    /// Second body.
    pub body_b: String,
    /// The point on `body_b`, m.
    #[serde(default)]
    pub point_b: [f64; 3],
    /// Stiffness, N/m.
    pub stiffness: f64,
    /// Damping, N s/m (default 0).
    #[serde(default)]
    pub damping: f64,
    /// Rest length, m (default 0).
    #[serde(default)]
    pub rest_length: f64,
}

/// A force at a point of a spatial body in a model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpatialPointForceSpec {
    /// Unique element name.
    pub name: String,
    /// The loaded body.
    pub body: String,
    /// Point of application (body frame, from the centre of mass), m.
    #[serde(default)]
    pub point: [f64; 3],
    /// Component along the `frame`'s x axis, N, as a function of time (default 0).
    #[serde(default = "zero")]
    pub fx: TimeFunction,
    /// Component along y, N (default 0).
    #[serde(default = "zero")]
    pub fy: TimeFunction,
    /// Component along z, N (default 0).
    #[serde(default = "zero")]
    pub fz: TimeFunction,
    /// The axes of the components: `"global"` (default) or `"body"` (turning with the body).
    #[serde(default)]
    pub frame: Axes,
}

/// A torque on a spatial body in a model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpatialTorqueSpec {
    /// Unique element name.
    pub name: String,
    /// The loaded body.
    pub body: String,
    /// Component along the `frame`'s x axis, N m, as a function of time (default 0).
    #[serde(default = "zero")]
    pub tx: TimeFunction,
    /// Component along y, N m (default 0).
    #[serde(default = "zero")]
    pub ty: TimeFunction,
    /// Component along z, N m (default 0).
    #[serde(default = "zero")]
    pub tz: TimeFunction,
    /// The axes of the components: `"global"` (default) or `"body"`.
    #[serde(default)]
    pub frame: Axes,
}

fn zero() -> TimeFunction {
    TimeFunction::constant(0.0)
}

impl SpatialForceSpec {
    /// The element, bodies found by `find(element, name)`.
    pub(crate) fn to_force(
        &self,
        find: &dyn Fn(&str, &str) -> Result<SpatialBodyRef, ModelError>,
    ) -> Result<SpatialForce, ModelError> {
        Ok(match self {
            SpatialForceSpec::SpringDamper(s) => {
                let element = format!("spatial force '{}'", s.name);
                SpatialForce::spring_damper(
                    s.name.clone(),
                    find(&element, &s.body_a)?,
                    s.point_a,
                    find(&element, &s.body_b)?,
                    s.point_b,
                    s.stiffness,
                    s.damping,
                    s.rest_length,
                )
            }
            SpatialForceSpec::Force(s) => SpatialForce::force(
                s.name.clone(),
                find(&format!("spatial force '{}'", s.name), &s.body)?,
                s.point,
                [s.fx.clone(), s.fy.clone(), s.fz.clone()],
                s.frame,
            ),
            SpatialForceSpec::Torque(s) => SpatialForce::torque(
                s.name.clone(),
                find(&format!("spatial force '{}'", s.name), &s.body)?,
                [s.tx.clone(), s.ty.clone(), s.tz.clone()],
                s.frame,
            ),
        })
    }

    /// The file form of a model's element (as given), bodies named by `name_of`.
    pub(crate) fn from_force(f: &SpatialForce, name_of: &dyn Fn(SpatialBodyRef) -> String) -> Self {
        let name = f.name.clone();
        match &f.kind {
            SpatialForceKind::SpringDamper(s) => {
                SpatialForceSpec::SpringDamper(SpatialSpringDamperSpec {
                    name,
                    body_a: name_of(f.a),
                    point_a: s.point_a,
                    body_b: name_of(f.b),
                    point_b: s.point_b,
                    stiffness: s.stiffness,
                    damping: s.damping,
                    rest_length: s.rest_length,
                })
            }
            SpatialForceKind::Force(l) => {
                let [fx, fy, fz] = l.components.clone();
                SpatialForceSpec::Force(SpatialPointForceSpec {
                    name,
                    body: name_of(f.a),
                    point: l.point,
                    fx,
                    fy,
                    fz,
                    frame: l.frame,
                })
            }
            SpatialForceKind::Torque(l) => {
                let [tx, ty, tz] = l.components.clone();
                SpatialForceSpec::Torque(SpatialTorqueSpec {
                    name,
                    body: name_of(f.a),
                    tx,
                    ty,
                    tz,
                    frame: l.frame,
                })
            }
        }
    }
}
