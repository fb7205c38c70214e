//! Spatial rigid bodies in natural coordinates (directors): the kinematics and inertia that a
//! spatial body brings to the DAE, independent of any joint or solver.
//!
//! A body is its centre of mass `x` and three unit directors `d_1, d_2, d_3` along its principal
//! axes of inertia: 12 coordinates `q = (x, d_1, d_2, d_3)`, the rotation matrix being
//! `R = [d_1 d_2 d_3]`. A point with principal-frame coordinates `X` (relative to the centre of
//! mass) sits at `x + X_1 d_1 + X_2 d_2 + X_3 d_3`: linear in `q`. With the second moments
//! `E_i = int X_i^2 dm = (J_j + J_k - J_i) / 2` (principal inertias `J`, `(i, j, k)` a
//! permutation), the kinetic energy is
//!
//! ```text
//! T = 1/2 m |x'|^2 + 1/2 sum_i E_i |d_i'|^2,
//! ```
//!
//! since `int |x' + X_i d_i'|^2 dm = m |x'|^2 + sum_i E_i |d_i'|^2` (the first moments vanish
//! about the centre of mass and the cross moments about principal axes). The mass matrix is
//! therefore constant and diagonal, `diag(m I3, E_1 I3, E_2 I3, E_3 I3)`
//! ([`SpatialInertia::mass_diagonal`]), and rigidity is six internal constraints
//! ([`internal_constraints`]) `1/2 (d_i . d_i - 1) = 0`, `d_i . d_j = 0` (`i < j`), quadratic with
//! constant Hessians. With `omega` the angular velocity, `d_i' = omega x d_i`
//! ([`director_velocities`]), and then `sum_i E_i |omega x d_i|^2 = omega . J omega`: the
//! rotational energy.
//!
//! `M` is singular where a principal inertia is the sum of the other two (`E_i = 0`: thin discs
//! and plates, the heavy symmetric top `J = diag(a, 2a, a)`); it is definite on the tangent
//! space of the internal constraints all the same (`d_i'` with `E_i = 0` is fixed by the other
//! two directors' velocities through `d_i . d_j = 0`), which is what the solvers need.
//!
//! A third body kind, the spatial point mass ([`SpatialPointMass`], added by
//! [`crate::SystemBuilder::add_spatial_point_mass`], referred to by
//! [`SpatialBodyRef::PointMass`]), has 3 coordinates (its position, after every spatial body's
//! 12), the mass matrix `m I3` and no internal constraint. It has a point but no axes: the joints
//! whose equations use only a point on its side ([`SpatialJoint::needs_axes`]: spherical,
//! distance, distance driver, and the slide driver's second side) take it, with its marker at
//! its position; spring-dampers and forces act at its position; torques do not. Elements see
//! its directors as the constant global axes, so the joints' equations stay written once.

mod body;
pub(crate) mod build;
mod forces;
mod inertia;
mod joints;
mod orientation;
mod point_mass;
mod reactions;
mod rigid;
pub(crate) mod system;

pub use body::{SpatialBody, SpatialBodyHandle, SpatialBodyRef};
pub use forces::{
    Axes, SpatialForce, SpatialForceElement, SpatialForceKind, SpatialLoad, SpatialSpringDamper,
    SPATIAL_LOCAL_WIDTH,
};
pub use inertia::{SpatialInertia, SpatialInertiaError};
pub use joints::{Marker, SpatialFrame, SpatialJoint, SpatialJointError, SpatialJointKind};
pub use orientation::{global_angular_velocity, EulerSequence, Orientation};
pub use point_mass::{SpatialPointMass, SpatialPointMassHandle};
pub use reactions::SpatialJointReaction;
pub use rigid::{internal_gamma, RigidSolve};
pub use system::SpatialJointEntry;

use nalgebra::{Matrix3, Vector3};

/// The six internal constraints of a body's directors at `q` (12 coordinates `(x, d_1, d_2,
/// d_3)`): `[1/2 (|d_1|^2 - 1), 1/2 (|d_2|^2 - 1), 1/2 (|d_3|^2 - 1), d_1 . d_2, d_1 . d_3,
/// d_2 . d_3]`.
pub fn internal_constraints(q: &[f64; 12]) -> [f64; 6] {
    internal_eval(&SpatialFrame::new(q))
}

/// [`internal_constraints`] of a frame, over any scalar (the jets differentiate it).
pub(crate) fn internal_eval<T: mbd_jet::Scalar>(f: &SpatialFrame<T>) -> [T; 6] {
    let d = f.d;
    let dot = joints::dot3::<T>;
    [
        (dot(d[0], d[0]) - 1.0) * 0.5,
        (dot(d[1], d[1]) - 1.0) * 0.5,
        (dot(d[2], d[2]) - 1.0) * 0.5,
        dot(d[0], d[1]),
        dot(d[0], d[2]),
        dot(d[1], d[2]),
    ]
}

/// The Jacobian of [`internal_constraints`] (6 rows, 12 columns): linear in the directors (the
/// centre of mass does not enter).
pub fn internal_jacobian(q: &[f64; 12]) -> [[f64; 12]; 6] {
    let d = directors(q);
    let mut j = [[0.0; 12]; 6];
    // rows 0..3: d_i . dd_i; rows 3..6: d_j . dd_i + d_i . dd_j
    for (i, di) in d.iter().enumerate() {
        for c in 0..3 {
            j[i][3 + 3 * i + c] = di[c];
        }
    }
    for (row, (a, b)) in [(3, (0, 1)), (4, (0, 2)), (5, (1, 2))] {
        for c in 0..3 {
            j[row][3 + 3 * a + c] = d[b][c];
            j[row][3 + 3 * b + c] = d[a][c];
        }
    }
    j
}

/// The natural coordinates of a body with centre of mass `x` and rotation `r` (its columns the
/// directors, principal axes in global axes).
pub fn natural_coordinates(x: Vector3<f64>, r: &Matrix3<f64>) -> [f64; 12] {
    let mut q = [0.0; 12];
    q[..3].copy_from_slice(x.as_slice());
    for i in 0..3 {
        for c in 0..3 {
            q[3 + 3 * i + c] = r[(c, i)];
        }
    }
    q
}

/// The velocities of the natural coordinates of a body at rotation `r` moving with centre-of-
/// mass velocity `v` and angular velocity `omega` (global axes): `(v, omega x d_1, omega x
/// d_2, omega x d_3)`.
pub fn director_velocities(v: Vector3<f64>, omega: Vector3<f64>, r: &Matrix3<f64>) -> [f64; 12] {
    let mut qd = [0.0; 12];
    qd[..3].copy_from_slice(v.as_slice());
    for i in 0..3 {
        let w = omega.cross(&r.column(i).into_owned());
        qd[3 + 3 * i..6 + 3 * i].copy_from_slice(w.as_slice());
    }
    qd
}

/// The global position of the body point with principal-frame coordinates `p` (relative to
/// the centre of mass): `x + p_1 d_1 + p_2 d_2 + p_3 d_3`.
pub fn point_position(q: &[f64; 12], p: Vector3<f64>) -> Vector3<f64> {
    let d = directors(q);
    Vector3::new(q[0], q[1], q[2]) + d[0] * p[0] + d[1] * p[1] + d[2] * p[2]
}

fn directors(q: &[f64; 12]) -> [Vector3<f64>; 3] {
    std::array::from_fn(|i| Vector3::new(q[3 + 3 * i], q[4 + 3 * i], q[5 + 3 * i]))
}

#[cfg(test)]
mod tests;
