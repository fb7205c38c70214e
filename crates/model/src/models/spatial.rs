//! Spatial example models (natural coordinates, docs/spatial.md).

use crate::builder::SystemBuilder;
use crate::error::ModelError;
use crate::spatial::{
    Marker, Orientation, SpatialBody, SpatialBodyRef, SpatialInertia, SpatialJoint,
    SpatialJointKind,
};
use crate::system::System;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Distance from a top's tip to its centre of mass (m).
pub const TOP_LENGTH: f64 = 0.5;

/// A heavy top: a 1 kg body with principal moments `moments` about its centre of mass
/// (symmetry axis along its body `z`), its tip held at the origin by a spherical joint and its
/// centre of mass [`TOP_LENGTH`] up its axis from the tip; tilted by `tilt` (rad) about the
/// global `x` axis, spinning at `spin` (rad/s) about its own axis, gravity 9.81 m/s^2 along
/// `-z`. `moments = [a, a, 2a]` is a flat disc on a massless axle (`E_3 = 0`, a singular mass
/// matrix); `[a, 2a, a]` puts the symmetry elsewhere and is the classic singular case too.
///
/// ```
/// let top = mbd_model::models::heavy_top([0.3, 0.3, 0.1], 0.3, 20.0)?;
/// assert_eq!((top.n_coords(), top.n_constraints(), top.dof()), (12, 9, 3));
/// # Ok::<(), mbd_model::ModelError>(())
/// ```
pub fn heavy_top(moments: [f64; 3], tilt: f64, spin: f64) -> Result<System, ModelError> {
    let inertia = SpatialInertia::principal(1.0, moments)
        .map_err(|e| crate::check::invalid("spatial body 'top'".into(), e.to_string()))?;
    let r = *Rotation3::from_axis_angle(&Vector3::x_axis(), tilt).matrix();
    let axis = r * Vector3::z();
    let x = axis * TOP_LENGTH;
    let w = axis * spin;
    let v = w.cross(&x);
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let top = b.add_spatial_body(
        SpatialBody::new("top", inertia)
            .position(x.into())
            .orientation(Orientation::Matrix(r))
            .velocity(v.into())
            .angular_velocity(w.into()),
    );
    let joint = SpatialJoint::new(
        SpatialJointKind::Spherical,
        Marker::at([0.0; 3]),
        Marker::at([0.0, 0.0, -TOP_LENGTH]),
    )
    .map_err(|e| crate::check::invalid("spatial joint 'tip'".into(), e.to_string()))?;
    b.add_spatial_joint("tip", SpatialBodyRef::Ground, top, joint);
    b.build()
}

/// A torque-free body: principal moments `moments`, 1 kg, at the origin with its axes along
/// the global ones, spinning at `omega` (global axes), no gravity and no joint.
pub fn free_body(moments: [f64; 3], omega: [f64; 3]) -> Result<System, ModelError> {
    let inertia = SpatialInertia::principal(1.0, moments)
        .map_err(|e| crate::check::invalid("spatial body 'body'".into(), e.to_string()))?;
    let mut b = SystemBuilder::new();
    b.add_spatial_body(
        SpatialBody::new("body", inertia)
            .orientation(Orientation::Matrix(Matrix3::identity()))
            .angular_velocity(omega),
    );
    b.build()
}
