//! Orientations of spatial bodies: a rotation matrix, a unit quaternion or Euler angles, each
//! turned into the rotation matrix whose columns are the body axes in global axes.

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// The axis sequence of Euler angles, all intrinsic (each rotation about the axis as already
/// turned by the previous ones): angles `(a, b, c)` of sequence `X-Y'-Z''` give
/// `R = R_x(a) R_y(b) R_z(c)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EulerSequence {
    /// `Z-Y'-X''`: yaw, pitch, roll (aerospace, vehicles).
    Zyx,
    /// `Z-X'-Z''`: precession, nutation, spin (the classical angles of the top).
    Zxz,
    /// `X-Y'-Z''` (Cardan angles as in many CAD systems).
    Xyz,
}

/// A spatial body's orientation.
///
/// ```
/// use mbd_model::spatial::{EulerSequence, Orientation};
/// let yaw = Orientation::Euler(EulerSequence::Zyx, [std::f64::consts::FRAC_PI_2, 0.0, 0.0]);
/// let r = yaw.matrix()?;
/// // the body's x axis points along global y
/// assert!((r[(1, 0)] - 1.0).abs() < 1e-15 && r[(0, 0)].abs() < 1e-15);
/// # Ok::<(), String>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Orientation {
    /// A rotation matrix (columns: the body axes in global axes); checked to be orthonormal
    /// and right-handed to 1e-9.
    Matrix(Matrix3<f64>),
    /// A quaternion `[w, x, y, z]` (normalised here; it must not be zero).
    Quaternion([f64; 4]),
    /// Euler angles (rad) of a sequence.
    Euler(EulerSequence, [f64; 3]),
}

impl Orientation {
    /// The rotation matrix, or why the orientation is invalid.
    pub fn matrix(&self) -> Result<Matrix3<f64>, String> {
        match *self {
            Orientation::Matrix(r) => {
                if r.iter().any(|x| !x.is_finite()) {
                    return Err("the rotation matrix must be finite".into());
                }
                let deviation = (r.transpose() * r - Matrix3::identity()).amax();
                let det = r.determinant();
                if deviation > 1e-9 || (det - 1.0).abs() > 1e-9 {
                    return Err(format!(
                        "the rotation matrix is not a rotation: |R^T R - I| = {deviation:e}, det R = {det}"
                    ));
                }
                Ok(r)
            }
            Orientation::Quaternion([w, x, y, z]) => {
                let n = (w * w + x * x + y * y + z * z).sqrt();
                if !(n.is_finite() && n > 0.0) {
                    return Err(format!(
                        "the quaternion [{w}, {x}, {y}, {z}] must be finite and non-zero"
                    ));
                }
                let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z));
                Ok(q.to_rotation_matrix().into_inner())
            }
            Orientation::Euler(seq, [a, b, c]) => {
                if ![a, b, c].iter().all(|x| x.is_finite()) {
                    return Err("Euler angles must be finite".into());
                }
                let axis = |k: usize, angle: f64| {
                    Rotation3::from_axis_angle(&Vector3::ith_axis(k), angle).into_inner()
                };
                let [i, j, k] = match seq {
                    EulerSequence::Zyx => [2, 1, 0],
                    EulerSequence::Zxz => [2, 0, 2],
                    EulerSequence::Xyz => [0, 1, 2],
                };
                Ok(axis(i, a) * axis(j, b) * axis(k, c))
            }
        }
    }
}

/// The global angular velocity of a body at rotation `r` whose angular velocity `omega` is
/// given in its own axes (`r omega`), or `omega` itself when `body_axes` is false.
pub fn global_angular_velocity(
    omega: Vector3<f64>,
    body_axes: bool,
    r: &Matrix3<f64>,
) -> Vector3<f64> {
    if body_axes {
        r * omega
    } else {
        omega
    }
}
