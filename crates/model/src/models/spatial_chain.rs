//! A spatial chain of rods on ball joints: the scaling model of the spatial solvers.

use crate::builder::SystemBuilder;
use crate::error::ModelError;
use crate::spatial::{
    Marker, Orientation, SpatialBody, SpatialBodyRef, SpatialInertia, SpatialJoint,
    SpatialJointKind,
};
use crate::system::System;
use nalgebra::{Rotation3, Vector3};

/// Length of each rod of [`spatial_chain`] (m).
pub const SPATIAL_CHAIN_LINK: f64 = 0.5;

/// A chain of `n` rods (1 kg, [`SPATIAL_CHAIN_LINK`] long, principal moments `m L^2 / 12`
/// about their cross axes and `1e-3` about their own) joined end to end by spherical joints,
/// the first hung from the origin, under gravity `-9.81 z`. It starts straight, tilted by 0.4
/// rad from the downward vertical, and turning as a whole at 2 rad/s about the vertical: a
/// consistent state whose motion is spatial. `n` rods give `12 n` coordinates, `9 n`
/// equations and `3 n` degrees of freedom.
///
/// ```
/// let chain = mbd_model::models::spatial_chain(10)?;
/// assert_eq!((chain.n_coords(), chain.n_constraints(), chain.dof()), (120, 90, 30));
/// # Ok::<(), mbd_model::ModelError>(())
/// ```
pub fn spatial_chain(n: usize) -> Result<System, ModelError> {
    if n == 0 {
        return Err(crate::check::invalid(
            "spatial chain".into(),
            "needs at least one rod".into(),
        ));
    }
    let l = SPATIAL_CHAIN_LINK;
    let cross = l * l / 12.0;
    let inertia = SpatialInertia::principal(1.0, [cross, cross, 1e-3])
        .map_err(|e| crate::check::invalid("spatial chain rod".into(), e.to_string()))?;
    // each rod's body z axis points up the chain (towards the pivot)
    let tilt = *Rotation3::from_axis_angle(&Vector3::y_axis(), 0.4).matrix();
    let up = tilt * Vector3::z();
    let omega = Vector3::new(0.0, 0.0, 2.0);
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let mut prev = SpatialBodyRef::Ground;
    for k in 0..n {
        let x = -up * (l * (k as f64 + 0.5));
        let body = b.add_spatial_body(
            SpatialBody::new(format!("rod{}", k + 1), inertia.clone())
                .position(x.into())
                .orientation(Orientation::Matrix(tilt))
                .velocity(omega.cross(&x).into())
                .angular_velocity(omega.into()),
        );
        let top = Marker::at([0.0, 0.0, 0.5 * l]);
        let joint = match prev {
            SpatialBodyRef::Ground => {
                SpatialJoint::new(SpatialJointKind::Spherical, Marker::at([0.0; 3]), top)
            }
            SpatialBodyRef::Body(_) | SpatialBodyRef::PointMass(_) => SpatialJoint::new(
                SpatialJointKind::Spherical,
                Marker::at([0.0, 0.0, -0.5 * l]),
                top,
            ),
        }
        .map_err(|e| {
            crate::check::invalid(format!("spatial joint 'ball{}'", k + 1), e.to_string())
        })?;
        b.add_spatial_joint(format!("ball{}", k + 1), prev, body, joint);
        prev = SpatialBodyRef::Body(body);
    }
    b.build()
}
