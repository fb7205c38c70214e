//! A spatial body's mass and inertia: principal moments and axes, given directly or as a full
//! tensor about any reference point, and the constant mass matrix of natural coordinates.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use thiserror::Error;

/// Why a spatial inertia is invalid.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum SpatialInertiaError {
    /// The mass is not positive and finite.
    #[error("mass {0} must be positive and finite")]
    Mass(f64),
    /// An entry of the inertia, an axis or the centre of mass is NaN or infinite.
    #[error("the {0} must be finite")]
    NotFinite(&'static str),
    /// The inertia tensor is not symmetric.
    #[error("the inertia tensor is not symmetric: entries ({row}, {col}) and ({col}, {row}) differ by {difference:e}")]
    NotSymmetric {
        /// Row of the first entry.
        row: usize,
        /// Column of the first entry.
        col: usize,
        /// `|I_rc - I_cr|`.
        difference: f64,
    },
    /// A principal moment is negative, zero or vanishing against the largest (below `1e-12`
    /// times it): the body's spin about that axis would be undetermined.
    #[error(
        "principal moment J{} = {j:e} must be positive (and above 1e-12 times the largest): a \
         body without inertia about an axis has an undetermined spin about it (an ideal \
         slender rod: give it a small moment about its axis, or model it with point masses)",
        index + 1
    )]
    Moment {
        /// The principal axis (from 0).
        index: usize,
        /// Its moment.
        j: f64,
    },
    /// A principal moment exceeds the sum of the other two (no rigid body has it): the second
    /// moment `E_i = (J_j + J_k - J_i) / 2` would be negative.
    #[error(
        "principal moment J{} = {j:e} exceeds the sum of the other two by {excess:e}: no rigid \
         body has such an inertia (the triangle inequality J_i <= J_j + J_k must hold)",
        index + 1
    )]
    Triangle {
        /// The principal axis (from 0).
        index: usize,
        /// Its moment.
        j: f64,
        /// `J_i - J_j - J_k`.
        excess: f64,
    },
    /// The principal axes are not a rotation (orthonormal, right-handed).
    #[error("the principal axes are not a rotation: |A^T A - I| = {deviation:e}, det A = {det}")]
    Axes {
        /// Max-norm of `A^T A - I`.
        deviation: f64,
        /// The determinant.
        det: f64,
    },
    /// The body's rigid motion is undetermined at a configuration (what is degenerate and
    /// why).
    #[error("degenerate {0}")]
    Degenerate(&'static str),
    /// The directors are (nearly) dependent at a configuration, so the internal constraints
    /// lose rank. On the constraints they are orthonormal: only coordinates far off them
    /// (drift, or a stage point of a step too long for the motion) have this.
    #[error(
        "degenerate directors: they are (nearly) dependent, so the internal constraints lose rank"
    )]
    DependentDirectors,
}

/// A spatial body's mass, principal moments of inertia about its centre of mass and principal
/// axes (the columns of `axes`, in the frame the body is described in).
///
/// ```
/// use mbd_model::spatial::SpatialInertia;
/// // the heavy symmetric top J = (a, 2a, a): E_2 = 0, a singular mass matrix
/// let top = SpatialInertia::principal(1.0, [0.5, 1.0, 0.5])?;
/// assert_eq!(top.second_moments(), [0.5, 0.0, 0.5]);
/// assert!(top.has_singular_mass_matrix());
/// # Ok::<(), mbd_model::spatial::SpatialInertiaError>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialInertia {
    mass: f64,
    moments: [f64; 3],
    axes: Matrix3<f64>,
}

/// Relative tolerance on the triangle inequality and on the orthonormality of axes: round-off
/// of moments computed from a tensor.
const TOL: f64 = 1e-12;

impl SpatialInertia {
    /// Mass and principal moments about the centre of mass, the principal axes along the
    /// body frame's axes.
    pub fn principal(mass: f64, moments: [f64; 3]) -> Result<Self, SpatialInertiaError> {
        Self::principal_with_axes(mass, moments, Matrix3::identity())
    }

    /// Mass, principal moments and principal axes (the columns of `axes`, a rotation). The
    /// moments must be positive (above `1e-12` times the largest) and satisfy the triangle
    /// inequalities `J_i <= J_j + J_k`.
    pub fn principal_with_axes(
        mass: f64,
        moments: [f64; 3],
        axes: Matrix3<f64>,
    ) -> Result<Self, SpatialInertiaError> {
        if !(mass.is_finite() && mass > 0.0) {
            return Err(SpatialInertiaError::Mass(mass));
        }
        if moments.iter().any(|j| !j.is_finite()) {
            return Err(SpatialInertiaError::NotFinite("principal moments"));
        }
        if axes.iter().any(|a| !a.is_finite()) {
            return Err(SpatialInertiaError::NotFinite("principal axes"));
        }
        let deviation = (axes.transpose() * axes - Matrix3::identity()).amax();
        let det = axes.determinant();
        if deviation > 1e-9 || det <= 0.0 {
            return Err(SpatialInertiaError::Axes { deviation, det });
        }
        let scale = moments.iter().fold(0.0f64, |m, j| m.max(j.abs()));
        if let Some(index) = (0..3).find(|&i| moments[i] <= TOL * scale) {
            return Err(SpatialInertiaError::Moment {
                index,
                j: moments[index],
            });
        }
        for i in 0..3 {
            let excess = moments[i] - moments[(i + 1) % 3] - moments[(i + 2) % 3];
            if excess > TOL * scale {
                return Err(SpatialInertiaError::Triangle {
                    index: i,
                    j: moments[i],
                    excess,
                });
            }
        }
        Ok(SpatialInertia {
            mass,
            moments,
            axes,
        })
    }

    /// Mass and the inertia tensor `tensor` about a reference point, with the centre of mass at
    /// `com` from that point (both in the body frame): moved to the centre of mass by the
    /// parallel-axis theorem `J_c = J_ref - m (|c|^2 I - c c^T)`, then diagonalised (moments in
    /// ascending order, axes a right-handed rotation).
    pub fn from_tensor(
        mass: f64,
        tensor: Matrix3<f64>,
        com: Vector3<f64>,
    ) -> Result<Self, SpatialInertiaError> {
        if !(mass.is_finite() && mass > 0.0) {
            return Err(SpatialInertiaError::Mass(mass));
        }
        if tensor.iter().any(|a| !a.is_finite()) {
            return Err(SpatialInertiaError::NotFinite("inertia tensor"));
        }
        if com.iter().any(|a| !a.is_finite()) {
            return Err(SpatialInertiaError::NotFinite("centre of mass"));
        }
        let scale = tensor.amax().max(f64::MIN_POSITIVE);
        for (row, col) in [(0, 1), (0, 2), (1, 2)] {
            let difference = (tensor[(row, col)] - tensor[(col, row)]).abs();
            if difference > TOL * scale {
                return Err(SpatialInertiaError::NotSymmetric {
                    row,
                    col,
                    difference,
                });
            }
        }
        let shift = (Matrix3::identity() * com.norm_squared() - com * com.transpose()) * mass;
        let centred = 0.5 * (tensor + tensor.transpose()) - shift;
        let eig = SymmetricEigen::new(centred);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let moments = order.map(|k| eig.eigenvalues[k]);
        let mut axes =
            Matrix3::from_columns(&order.map(|k| eig.eigenvectors.column(k).into_owned()));
        if axes.determinant() < 0.0 {
            axes.set_column(2, &(-axes.column(2)));
        }
        Self::principal_with_axes(mass, moments, axes)
    }

    /// The mass.
    pub fn mass(&self) -> f64 {
        self.mass
    }
    /// The principal moments about the centre of mass.
    pub fn moments(&self) -> [f64; 3] {
        self.moments
    }
    /// The principal axes (columns), in the body frame.
    pub fn axes(&self) -> &Matrix3<f64> {
        &self.axes
    }

    /// The second moments `E_i = (J_j + J_k - J_i) / 2 >= 0` about the principal axes (a
    /// round-off negative is clamped to zero).
    pub fn second_moments(&self) -> [f64; 3] {
        let j = self.moments;
        std::array::from_fn(|i| (0.5 * (j[(i + 1) % 3] + j[(i + 2) % 3] - j[i])).max(0.0))
    }

    /// The diagonal of the constant mass matrix of the natural coordinates `(x, d_1, d_2,
    /// d_3)`: `(m, m, m, E_1, E_1, E_1, E_2, E_2, E_2, E_3, E_3, E_3)`.
    pub fn mass_diagonal(&self) -> [f64; 12] {
        let e = self.second_moments();
        std::array::from_fn(|k| if k < 3 { self.mass } else { e[(k - 3) / 3] })
    }

    /// Whether a second moment is zero (a thin disc or plate, the symmetric top): the mass
    /// matrix of natural coordinates is then singular, and no solver may divide by its
    /// diagonal.
    pub fn has_singular_mass_matrix(&self) -> bool {
        let scale = self.moments.iter().fold(0.0f64, |m, j| m.max(j.abs()));
        self.second_moments().iter().any(|&e| e <= TOL * scale)
    }
}
