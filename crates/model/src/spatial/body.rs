//! Spatial bodies as a model holds them: inertia, initial pose and motion, and their handles.

use super::{director_velocities, natural_coordinates, Orientation, SpatialInertia};
use crate::check::invalid;
use crate::error::ModelError;
use nalgebra::{Matrix3, Vector3};

/// Handle of a spatial body inside a model, given by
/// [`crate::SystemBuilder::add_spatial_body`] (opaque, like [`crate::BodyHandle`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SpatialBodyHandle(pub(crate) usize);

impl SpatialBodyHandle {
    /// The body's position among the model's spatial bodies (insertion order).
    pub fn index(self) -> usize {
        self.0
    }
}

/// What a spatial joint, force or sensor attaches to: the fixed ground frame, a spatial rigid
/// body or a spatial point mass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SpatialBodyRef {
    /// The inertial frame: marker points and axes on ground are global.
    Ground,
    /// A spatial rigid body.
    Body(SpatialBodyHandle),
    /// A spatial point mass (a point, no axes: see [`super::SpatialPointMass`]).
    PointMass(super::SpatialPointMassHandle),
}

impl From<super::SpatialPointMassHandle> for SpatialBodyRef {
    fn from(h: super::SpatialPointMassHandle) -> Self {
        SpatialBodyRef::PointMass(h)
    }
}

impl From<SpatialBodyHandle> for SpatialBodyRef {
    fn from(h: SpatialBodyHandle) -> Self {
        SpatialBodyRef::Body(h)
    }
}

impl SpatialBodyRef {
    /// The rigid body's index among the spatial bodies, or `None` for ground and for a point
    /// mass ([`SpatialBodyRef::point_mass`]).
    pub fn index(self) -> Option<usize> {
        match self {
            SpatialBodyRef::Body(h) => Some(h.0),
            SpatialBodyRef::Ground | SpatialBodyRef::PointMass(_) => None,
        }
    }
    /// The point mass's index among the spatial point masses, or `None` for ground and for a
    /// rigid body.
    pub fn point_mass(self) -> Option<usize> {
        match self {
            SpatialBodyRef::PointMass(h) => Some(h.0),
            SpatialBodyRef::Ground | SpatialBodyRef::Body(_) => None,
        }
    }
    /// Whether this is the ground.
    pub fn is_ground(self) -> bool {
        self == SpatialBodyRef::Ground
    }
    /// The element slot of a model with `nb` spatial rigid bodies: rigid body `k` is slot `k`,
    /// point mass `p` slot `nb + p`, ground `None` (what the model's element attachments hold).
    pub(crate) fn slot(self, nb: usize) -> Option<usize> {
        match self {
            SpatialBodyRef::Ground => None,
            SpatialBodyRef::Body(h) => Some(h.0),
            SpatialBodyRef::PointMass(h) => Some(nb + h.0),
        }
    }
}

/// A spatial rigid body: its inertia (about its centre of mass, principal axes in its body
/// frame) and its initial state, a guess that `mbd_solve::consistent_state` projects onto the
/// constraints. Its coordinates in the model are the natural coordinates of
/// [`crate::spatial`]: the centre of mass and the principal axes in global axes.
///
/// ```
/// use mbd_model::spatial::{Orientation, SpatialBody, SpatialInertia};
/// let disc = SpatialBody::new("disc", SpatialInertia::principal(2.0, [0.25, 0.25, 0.5])?)
///     .position([0.0, 0.0, 1.0])
///     .angular_velocity([0.0, 0.0, 30.0]);
/// assert_eq!(disc.position, [0.0, 0.0, 1.0]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialBody {
    /// Unique name (among planar and spatial bodies).
    pub name: String,
    /// Mass and inertia about the centre of mass.
    pub inertia: SpatialInertia,
    /// Initial position of the centre of mass, global (m).
    pub position: [f64; 3],
    /// Initial orientation of the body frame.
    pub orientation: Orientation,
    /// Initial velocity of the centre of mass, global (m/s).
    pub velocity: [f64; 3],
    /// Initial angular velocity (rad/s), in the axes `angular_velocity_axes` says.
    pub angular_velocity: [f64; 3],
    /// The axes of `angular_velocity`: global (default) or the body frame's.
    pub angular_velocity_axes: super::Axes,
}

impl SpatialBody {
    /// A body at the origin, its frame along the global axes, at rest.
    pub fn new(name: impl Into<String>, inertia: SpatialInertia) -> Self {
        SpatialBody {
            name: name.into(),
            inertia,
            position: [0.0; 3],
            orientation: Orientation::Matrix(Matrix3::identity()),
            velocity: [0.0; 3],
            angular_velocity: [0.0; 3],
            angular_velocity_axes: super::Axes::Global,
        }
    }
    /// Sets the initial position of the centre of mass.
    pub fn position(mut self, x: [f64; 3]) -> Self {
        self.position = x;
        self
    }
    /// Sets the initial orientation of the body frame.
    pub fn orientation(mut self, o: Orientation) -> Self {
        self.orientation = o;
        self
    }
    /// Sets the initial velocity of the centre of mass.
    pub fn velocity(mut self, v: [f64; 3]) -> Self {
        self.velocity = v;
        self
    }
    /// Sets the initial angular velocity (global axes).
    pub fn angular_velocity(mut self, w: [f64; 3]) -> Self {
        self.angular_velocity = w;
        self.angular_velocity_axes = super::Axes::Global;
        self
    }
    /// Sets the initial angular velocity in the body frame's axes (its global value is the
    /// initial orientation times `w`).
    pub fn angular_velocity_body(mut self, w: [f64; 3]) -> Self {
        self.angular_velocity = w;
        self.angular_velocity_axes = super::Axes::Body;
        self
    }

    /// The rotation whose columns are the principal axes in global axes: the body frame's
    /// orientation times the principal axes in the body frame.
    pub(crate) fn principal_rotation(&self) -> Result<Matrix3<f64>, ModelError> {
        let element = format!("spatial body '{}'", self.name);
        let r = self
            .orientation
            .matrix()
            .map_err(|e| invalid(element.clone(), format!("orientation: {e}")))?;
        Ok(r * self.inertia.axes())
    }

    /// The initial natural coordinates and their velocities; errors name the body and field.
    pub(crate) fn natural_state(&self) -> Result<([f64; 12], [f64; 12]), ModelError> {
        let element = format!("spatial body '{}'", self.name);
        for (field, v) in [
            ("position", self.position),
            ("velocity", self.velocity),
            ("angular_velocity", self.angular_velocity),
        ] {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(invalid(element, format!("{field} {v:?} must be finite")));
            }
        }
        let r = self.principal_rotation()?;
        let w = Vector3::from(self.angular_velocity);
        let omega = match self.angular_velocity_axes {
            super::Axes::Global => w,
            // the body frame's rotation is the principal one times A^T
            super::Axes::Body => r * self.inertia.axes().transpose() * w,
        };
        Ok((
            natural_coordinates(Vector3::from(self.position), &r),
            director_velocities(Vector3::from(self.velocity), omega, &r),
        ))
    }
}
