//! Spatial bodies and joints in model files (docs/model-files.md, "Spatial bodies"), and their
//! way to the builder and back.

use crate::builder::SystemBuilder;
use crate::check::invalid;
use crate::error::ModelError;
use crate::spatial::{
    Axes, EulerSequence, Marker, Orientation, SpatialBody, SpatialBodyRef, SpatialInertia,
    SpatialJoint, SpatialJointEntry, SpatialJointKind, SpatialPointMass,
};
use nalgebra::{Matrix3, Vector3};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How a spatial body moves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum SpatialBodyKind {
    /// A rigid body: 12 natural coordinates (centre of mass and principal axes).
    #[default]
    Rigid,
    /// A particle: 3 coordinates (its position), `mass`, `position` and `velocity` only; joints
    /// and forces attach at its position, and joints that need axes on it are rejected.
    PointMass,
}

impl SpatialBodyKind {
    fn is_rigid(&self) -> bool {
        *self == SpatialBodyKind::Rigid
    }
}

/// A spatial rigid body or point mass in a model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpatialBodySpec {
    /// Unique name (among all bodies).
    pub name: String,
    /// `rigid` (default) or `point_mass`.
    #[serde(default, skip_serializing_if = "SpatialBodyKind::is_rigid")]
    pub kind: SpatialBodyKind,
    /// Mass, kg (> 0).
    pub mass: f64,
    /// Principal moments of inertia about the centre of mass, kg m^2, along `axes` (give these
    /// or `tensor`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moments: Option<[f64; 3]>,
    /// The principal axes as three vectors in the body frame (default: the body frame's
    /// axes), a rotation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axes: Option<[[f64; 3]; 3]>,
    /// The inertia tensor in the body frame, kg m^2 (instead of `moments` and `axes`), about
    /// the centre of mass or about `tensor_about`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tensor: Option<[[f64; 3]; 3]>,
    /// The point `tensor` is taken about, from the centre of mass in the body frame, m
    /// (default: the centre of mass); moved to the centre of mass by the parallel-axis
    /// theorem.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tensor_about: Option<[f64; 3]>,
    /// Initial position of the centre of mass, m.
    #[serde(default)]
    pub position: [f64; 3],
    /// Initial orientation of the body frame (default: along the global axes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation: Option<OrientationSpec>,
    /// Initial velocity of the centre of mass, m/s.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Initial angular velocity in global axes, rad/s.
    #[serde(default)]
    pub angular_velocity: [f64; 3],
    /// Initial angular velocity in the body frame's axes, rad/s (instead of
    /// `angular_velocity`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_velocity_body: Option<[f64; 3]>,
}

/// An orientation in a model file: exactly one of its fields.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum OrientationSpec {
    /// A rotation matrix, row by row (its columns are the body axes in global axes).
    Matrix([[f64; 3]; 3]),
    /// A quaternion `[w, x, y, z]` (normalised when read).
    Quaternion([f64; 4]),
    /// Intrinsic Euler angles, rad.
    Euler {
        /// The axis sequence: `"zyx"` (yaw, pitch, roll), `"zxz"` (precession, nutation,
        /// spin) or `"xyz"`.
        sequence: EulerSpec,
        /// The three angles, rad.
        angles: [f64; 3],
    },
}

/// An Euler axis sequence in a model file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum EulerSpec {
    /// `Z-Y'-X''`.
    Zyx,
    /// `Z-X'-Z''`.
    Zxz,
    /// `X-Y'-Z''`.
    Xyz,
}

/// The kinds of spatial joint in a model file (see `mbd_model::spatial::SpatialJointKind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum SpatialJointType {
    /// Ball joint.
    Spherical,
    /// Hinge about the markers' `z` axis.
    Revolute,
    /// Cardan joint: rotations about `x` of `a` and `y` of `b`.
    Universal,
    /// Rotation about and slide along `z`.
    Cylindrical,
    /// Slide along `z`.
    Prismatic,
    /// Slides in the `x`-`y` plane, rotation about `z`.
    Planar,
    /// Rigid connection.
    Weld,
    /// Massless rod of `length` between the points.
    Distance,
    /// Driver: the slide of `point_b` along `a`'s `z` axis follows `motion`.
    SlideDriver,
    /// Driver: the points' distance follows `motion`.
    DistanceDriver,
    /// Driver: `b`'s `x` axis turns about `a`'s `z` axis (from `a`'s `x` towards its `y`) by
    /// `motion` (rad); beside a revolute or cylindrical joint.
    AngleDriver,
}

/// A spatial joint in a model file: markers (point and axes) on two bodies.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpatialJointSpec {
    /// The kind.
    #[serde(rename = "type")]
    pub kind: SpatialJointType,
    /// Unique joint name.
    pub name: String,
    /// First body (`ground` for the ground).
    pub body_a: String,
    /// The marker's point on `body_a` (body frame, from the centre of mass), m.
    #[serde(default)]
    pub point_a: [f64; 3],
    /// The marker's axes on `body_a`: its `x`, `y`, `z` vectors in the body frame (a
    /// rotation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axes_a: Option<[[f64; 3]; 3]>,
    /// Only the marker's `z` axis on `body_a` (its `x`, `y` completed perpendicular), instead
    /// of `axes_a`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis_a: Option<[f64; 3]>,
    /// Second body.
    pub body_b: String,
    /// The marker's point on `body_b`, m.
    #[serde(default)]
    pub point_b: [f64; 3],
    /// The marker's axes on `body_b`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axes_b: Option<[[f64; 3]; 3]>,
    /// Only the marker's `z` axis on `body_b`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis_b: Option<[f64; 3]>,
    /// The rod's length of a distance joint, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
    /// A driver's motion (a function of time): the slide (m) of a `slide_driver`, the distance
    /// (m) of a `distance_driver`, the angle (rad) of an `angle_driver`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<crate::timefn::TimeFunction>,
}

impl SpatialBodySpec {
    /// A point mass's body: only `mass`, `position` and `velocity`; any field of a rigid body
    /// is an error naming the body and the field.
    fn to_point_mass(&self) -> Result<SpatialPointMass, ModelError> {
        let given = [
            ("moments", self.moments.is_some()),
            ("axes", self.axes.is_some()),
            ("tensor", self.tensor.is_some()),
            ("tensor_about", self.tensor_about.is_some()),
            ("orientation", self.orientation.is_some()),
            ("angular_velocity", self.angular_velocity != [0.0; 3]),
            (
                "angular_velocity_body",
                self.angular_velocity_body.is_some(),
            ),
        ];
        if let Some((field, _)) = given.iter().find(|(_, g)| *g) {
            return Err(invalid(
                format!("spatial body '{}'", self.name),
                format!(
                    "`{field}` is not allowed for a point mass (kind = \"point_mass\": mass, \
                     position and velocity only)"
                ),
            ));
        }
        Ok(SpatialPointMass::new(self.name.clone(), self.mass)
            .position(self.position)
            .velocity(self.velocity))
    }

    /// The file form of a model's point mass.
    pub(crate) fn from_point_mass(p: &SpatialPointMass) -> Self {
        SpatialBodySpec {
            name: p.name.clone(),
            kind: SpatialBodyKind::PointMass,
            mass: p.mass,
            moments: None,
            axes: None,
            tensor: None,
            tensor_about: None,
            position: p.position,
            orientation: None,
            velocity: p.velocity,
            angular_velocity: [0.0; 3],
            angular_velocity_body: None,
        }
    }

    fn to_body(&self) -> Result<SpatialBody, ModelError> {
        let element = format!("spatial body '{}'", self.name);
        let bad = |e: String| invalid(element.clone(), e);
        let inertia = match (self.moments, self.axes, self.tensor) {
            (Some(j), axes, None) => {
                let a = axes.map_or_else(Matrix3::identity, columns);
                SpatialInertia::principal_with_axes(self.mass, j, a)
            }
            (None, None, Some(t)) => SpatialInertia::from_tensor(
                self.mass,
                Matrix3::from_fn(|r, c| t[r][c]),
                // the centre of mass seen from the tensor's point
                -Vector3::from(self.tensor_about.unwrap_or([0.0; 3])),
            ),
            _ => {
                return Err(bad(
                    "give the inertia as `moments` (with optional `axes`) or as `tensor`, not \
                     both"
                        .into(),
                ))
            }
        }
        .map_err(|e| bad(format!("inertia: {e}")))?;
        if self.tensor_about.is_some() && self.tensor.is_none() {
            return Err(bad("`tensor_about` belongs to `tensor`".into()));
        }
        let orientation = match &self.orientation {
            None => Orientation::Matrix(Matrix3::identity()),
            Some(OrientationSpec::Matrix(m)) => {
                Orientation::Matrix(Matrix3::from_fn(|r, c| m[r][c]))
            }
            Some(OrientationSpec::Quaternion(q)) => Orientation::Quaternion(*q),
            Some(OrientationSpec::Euler { sequence, angles }) => Orientation::Euler(
                match sequence {
                    EulerSpec::Zyx => EulerSequence::Zyx,
                    EulerSpec::Zxz => EulerSequence::Zxz,
                    EulerSpec::Xyz => EulerSequence::Xyz,
                },
                *angles,
            ),
        };
        let body = SpatialBody::new(self.name.clone(), inertia)
            .position(self.position)
            .orientation(orientation)
            .velocity(self.velocity);
        match self.angular_velocity_body {
            None => Ok(body.angular_velocity(self.angular_velocity)),
            Some(w) if self.angular_velocity == [0.0; 3] => Ok(body.angular_velocity_body(w)),
            Some(_) => Err(bad(
                "give `angular_velocity` (global axes) or `angular_velocity_body`, not both".into(),
            )),
        }
    }

    /// The file form of a model's body (inertia as principal moments and axes, orientation as
    /// a matrix).
    pub(crate) fn from_body(b: &SpatialBody) -> Self {
        let axes = *b.inertia.axes();
        let orientation = b
            .orientation
            .matrix()
            .map_or(None, |m| Some(OrientationSpec::Matrix(rows(&m))));
        SpatialBodySpec {
            name: b.name.clone(),
            kind: SpatialBodyKind::Rigid,
            mass: b.inertia.mass(),
            moments: Some(b.inertia.moments()),
            axes: (axes != Matrix3::identity()).then(|| vectors(&axes)),
            tensor: None,
            tensor_about: None,
            position: b.position,
            orientation,
            velocity: b.velocity,
            angular_velocity: match b.angular_velocity_axes {
                Axes::Global => b.angular_velocity,
                Axes::Body => [0.0; 3],
            },
            angular_velocity_body: match b.angular_velocity_axes {
                Axes::Global => None,
                Axes::Body => Some(b.angular_velocity),
            },
        }
    }
}

impl SpatialJointSpec {
    fn marker(
        &self,
        element: &str,
        side: char,
        point: [f64; 3],
        axes: Option<[[f64; 3]; 3]>,
        axis: Option<[f64; 3]>,
    ) -> Result<Marker, ModelError> {
        let m = match (axes, axis) {
            (None, None) => Matrix3::identity(),
            (Some(a), None) => columns(a),
            (None, Some(z)) => complete_axes(z).ok_or_else(|| {
                invalid(
                    element.to_string(),
                    format!("axis_{side} {z:?} must be a non-zero finite vector"),
                )
            })?,
            (Some(_), Some(_)) => {
                return Err(invalid(
                    element.to_string(),
                    format!("give axes_{side} or axis_{side}, not both"),
                ))
            }
        };
        Ok(Marker::with_axes(point, m))
    }

    fn to_entry(
        &self,
        find: &dyn Fn(&str, &str) -> Result<SpatialBodyRef, ModelError>,
    ) -> Result<SpatialJointEntry, ModelError> {
        let element = format!("spatial joint '{}'", self.name);
        let kind = match self.kind {
            SpatialJointType::Spherical => SpatialJointKind::Spherical,
            SpatialJointType::Revolute => SpatialJointKind::Revolute,
            SpatialJointType::Universal => SpatialJointKind::Universal,
            SpatialJointType::Cylindrical => SpatialJointKind::Cylindrical,
            SpatialJointType::Prismatic => SpatialJointKind::Prismatic,
            SpatialJointType::Planar => SpatialJointKind::Planar,
            SpatialJointType::Weld => SpatialJointKind::Weld,
            SpatialJointType::SlideDriver => SpatialJointKind::SlideDriver,
            SpatialJointType::DistanceDriver => SpatialJointKind::DistanceDriver,
            SpatialJointType::AngleDriver => SpatialJointKind::AngleDriver,
            SpatialJointType::Distance => SpatialJointKind::Distance {
                length: self.length.ok_or_else(|| {
                    invalid(
                        element.clone(),
                        "a distance joint needs `length` (m)".into(),
                    )
                })?,
            },
        };
        if self.length.is_some() && self.kind != SpatialJointType::Distance {
            return Err(invalid(
                element,
                "`length` belongs to distance joints only".into(),
            ));
        }
        let a = self.marker(&element, 'a', self.point_a, self.axes_a, self.axis_a)?;
        let b = self.marker(&element, 'b', self.point_b, self.axes_b, self.axis_b)?;
        let joint =
            SpatialJoint::new(kind, a, b).map_err(|e| invalid(element.clone(), e.to_string()))?;
        Ok(SpatialJointEntry {
            motion: self.motion.clone(),
            name: self.name.clone(),
            a: find(&element, &self.body_a)?,
            b: find(&element, &self.body_b)?,
            joint,
        })
    }

    /// The file form of a model's joint (markers with full axes), bodies named by `name_of`.
    pub(crate) fn from_entry(
        j: &SpatialJointEntry,
        name_of: &dyn Fn(SpatialBodyRef) -> String,
    ) -> Self {
        let (ma, mb) = j.joint.markers();
        let (kind, length) = match j.joint.kind() {
            SpatialJointKind::Spherical => (SpatialJointType::Spherical, None),
            SpatialJointKind::Revolute => (SpatialJointType::Revolute, None),
            SpatialJointKind::Universal => (SpatialJointType::Universal, None),
            SpatialJointKind::Cylindrical => (SpatialJointType::Cylindrical, None),
            SpatialJointKind::Prismatic => (SpatialJointType::Prismatic, None),
            SpatialJointKind::Planar => (SpatialJointType::Planar, None),
            SpatialJointKind::Weld => (SpatialJointType::Weld, None),
            SpatialJointKind::Distance { length } => (SpatialJointType::Distance, Some(length)),
            SpatialJointKind::SlideDriver => (SpatialJointType::SlideDriver, None),
            SpatialJointKind::DistanceDriver => (SpatialJointType::DistanceDriver, None),
            SpatialJointKind::AngleDriver => (SpatialJointType::AngleDriver, None),
        };
        let axes = |m: &Marker| (m.axes != Matrix3::identity()).then(|| vectors(&m.axes));
        SpatialJointSpec {
            kind,
            name: j.name.clone(),
            body_a: name_of(j.a),
            point_a: ma.point,
            axes_a: axes(ma),
            axis_a: None,
            body_b: name_of(j.b),
            point_b: mb.point,
            axes_b: axes(mb),
            axis_b: None,
            length,
            motion: j.motion.clone(),
        }
    }
}

/// Adds a file's spatial part to the builder: gravity, bodies, joints and force elements
/// (bodies by name; `planar` names the planar bodies, which spatial elements cannot use).
pub(crate) fn add_spatial(
    b: &mut SystemBuilder,
    gravity: [f64; 3],
    bodies: &[SpatialBodySpec],
    joints: &[SpatialJointSpec],
    forces: &[super::SpatialForceSpec],
    planar: &dyn Fn(&str) -> bool,
) -> Result<(), ModelError> {
    b.set_spatial_gravity(gravity);
    let mut handles = std::collections::HashMap::new();
    for s in bodies {
        let h: SpatialBodyRef = match s.kind {
            SpatialBodyKind::Rigid => b.add_spatial_body(s.to_body()?).into(),
            SpatialBodyKind::PointMass => b.add_spatial_point(s.to_point_mass()?).into(),
        };
        handles.entry(s.name.as_str()).or_insert(h);
    }
    let find = |element: &str, name: &str| -> Result<SpatialBodyRef, ModelError> {
        if name.eq_ignore_ascii_case("ground") {
            return Ok(SpatialBodyRef::Ground);
        }
        match handles.get(name) {
            Some(&h) => Ok(h),
            None if planar(name) => Err(invalid(
                element.to_string(),
                format!("'{name}' is a planar body: spatial elements join spatial bodies"),
            )),
            None => Err(ModelError::UnknownBody {
                element: element.to_string(),
                body: name.to_string(),
            }),
        }
    };
    for j in joints {
        let e = j.to_entry(&find)?;
        match e.motion {
            Some(motion) => b.add_spatial_driver(e.name, e.a, e.b, e.joint, motion),
            None => b.add_spatial_joint(e.name, e.a, e.b, e.joint),
        };
    }
    for f in forces {
        b.add_spatial_force(f.to_force(&find)?);
    }
    Ok(())
}

/// The matrix whose columns are the three vectors.
fn columns(v: [[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| v[c][r])
}

/// The columns of `m` as three vectors.
fn vectors(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    std::array::from_fn(|c| std::array::from_fn(|r| m[(r, c)]))
}

/// The rows of `m`.
fn rows(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)]))
}

/// A rotation with `z` along the given vector: `x` perpendicular to it in the plane of `z`
/// and the global axis least aligned with it, `y = z x x`. `None` for a zero or non-finite
/// vector.
fn complete_axes(z: [f64; 3]) -> Option<Matrix3<f64>> {
    let z = Vector3::from(z);
    let norm = z.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return None;
    }
    let z = z / norm;
    let k = (0..3)
        .min_by(|&a, &b| z[a].abs().total_cmp(&z[b].abs()))
        .unwrap_or(0);
    let e = Vector3::ith(k, 1.0);
    let x = (e - z * z.dot(&e)).normalize();
    let y = z.cross(&x);
    Some(Matrix3::from_columns(&[x, y, z]))
}
