//! The internal constraints of one spatial body eliminated body by body: the accelerations a
//! body takes under a generalised force, whatever its mass matrix's rank.
//!
//! A body's natural coordinates `q = (x, d_1, d_2, d_3)` carry the mass matrix
//! `M = diag(m I3, E_1 I3, E_2 I3, E_3 I3)` and the internal constraints `g(q) = 0` with Jacobian
//! `G` (6 x 12, [`super::internal_jacobian`]). Given a generalised force `f` and a right-hand
//! side `r` for the internal constraints' acceleration level (`G a = r`, `r = -gamma`), the
//! accelerations solve the body's saddle-point system
//!
//! ```text
//! [ M  G^T ] [ a  ]   [ f ]
//! [ G   0  ] [ mu ] = [ r ]
//! ```
//!
//! which is regular even where `M` is singular (`E_i = 0`: thin discs and plates, the symmetric
//! top), because `M` is definite on the null space of `G`. That null space is spanned by the
//! body's rigid velocities: with `V = [[I3, 0], [0, -[d_1]x], [0, -[d_2]x], [0, -[d_3]x]]` (12 x 6,
//! a translation `v` and an angular velocity `w` give `(v, w x d_1, w x d_2, w x d_3)`), `G V = 0`
//! for any directors (`d_i . (w x d_i) = 0` and `d_i . (w x d_j) + d_j . (w x d_i) = 0`), and
//! `V` has rank 6. Split `a = V alpha + d` with `V^T M d = 0`:
//!
//! * the first block row projected on `V` (`V^T G^T = 0`) gives `V^T M V alpha = V^T f`, and
//!   `V^T M V = diag(m I3, J_eff)` with `J_eff = sum_i E_i (|d_i|^2 I - d_i d_i^T)` (the
//!   inertia tensor in global axes, `R J R^T`, when the directors are orthonormal), so
//!   `alpha = (f_x / m, J_eff^-1 tau)` with the torque `tau = sum_i d_i x f_i`;
//! * `d` solves `G d = r` with `V^T M d = 0`: from any particular solution `d0` (the
//!   minimum-norm one, `G^T (G G^T)^-1 r`), `d = d0 - C M d0`.
//!
//! Hence `a = C f + (I - C M) G^+ r` with the body's constrained inverse mass
//! `C = V (V^T M V)^-1 V^T`: `C f = (f_x / m, beta x d_1, beta x d_2, beta x d_3)`,
//! `beta = J_eff^-1 sum_i d_i x f_i`, the Newton-Euler equations in natural coordinates. `C` is
//! symmetric positive semidefinite of rank 6, and the same for a thin disc as for a solid body:
//! only `J_eff` is inverted (definite whenever every principal moment is positive), never `M`.
//! Joints then meet the body through `C` alone: `S = Phi_q C Phi_q^T` replaces
//! `Phi_q M^-1 Phi_q^T` (docs/spatial.md).

use super::inertia::{SpatialInertia, SpatialInertiaError};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// One spatial body's elimination of its internal constraints at a configuration (see the
/// module documentation): applies its constrained inverse mass `C` and solves its saddle-point
/// system, for any second moments `E_i >= 0` (thin discs and plates included).
///
/// ```
/// use mbd_model::spatial::{director_velocities, internal_gamma, natural_coordinates,
///     RigidSolve, SpatialInertia};
/// use nalgebra::{Matrix3, Vector3};
/// // a thin disc (E_3 = 0: a singular mass matrix) spinning about its axis, no force: its
/// // directors accelerate centripetally, w x (w x d_i), and its spin stays constant
/// let disc = SpatialInertia::principal(2.0, [0.25, 0.25, 0.5])?;
/// assert!(disc.has_singular_mass_matrix());
/// let q = natural_coordinates(Vector3::zeros(), &Matrix3::identity());
/// let w = Vector3::new(0.0, 0.0, 3.0);
/// let qd = director_velocities(Vector3::zeros(), w, &Matrix3::identity());
/// let a = RigidSolve::new(&disc, &q)?.solve(&[0.0; 12], &internal_gamma(&qd).map(|g| -g));
/// // d_1 = e_x turns about z at 3 rad/s: d_1'' = -9 e_x
/// assert!((a[3] + 9.0).abs() < 1e-12 && a[4].abs() < 1e-12 && a[11].abs() < 1e-12);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug)]
pub struct RigidSolve {
    mass: f64,
    e: [f64; 3],
    d: [Vector3<f64>; 3],
    /// `J_eff^-1`.
    j_inv: Matrix3<f64>,
    /// The director columns of `G` (6 x 9; the centre of mass does not enter).
    g: SMatrix<f64, 6, 9>,
    /// The Cholesky factor of `G G^T` (solved against, not inverted).
    gg: nalgebra::Cholesky<f64, nalgebra::Const<6>>,
}

impl RigidSolve {
    /// The elimination for a body of inertia `inertia` at coordinates `q` (its directors need
    /// not be exactly orthonormal: the solve is exact for the constraints' linearisation at
    /// `q`). Errors: a zero principal moment (a slender rod, whose spin about its axis has no
    /// inertia) or directors too close to dependent for `G` to have full rank.
    pub fn new(inertia: &SpatialInertia, q: &[f64; 12]) -> Result<Self, SpatialInertiaError> {
        let e = inertia.second_moments();
        let d: [Vector3<f64>; 3] =
            std::array::from_fn(|i| Vector3::new(q[3 + 3 * i], q[4 + 3 * i], q[5 + 3 * i]));
        let mut j_eff = Matrix3::zeros();
        for i in 0..3 {
            j_eff += (Matrix3::identity() * d[i].norm_squared() - d[i] * d[i].transpose()) * e[i];
        }
        let j_inv = j_eff
            .cholesky()
            .filter(|c| {
                // relative pivot test: the smallest moment against the largest
                let l = c.l();
                let (lo, hi) = (0..3).fold((f64::INFINITY, 0.0f64), |(lo, hi), k| {
                    let p = l[(k, k)] * l[(k, k)];
                    (lo.min(p), hi.max(p))
                });
                lo > 1e-12 * hi
            })
            .map(|c| c.inverse())
            .ok_or(SpatialInertiaError::Degenerate(
                "inertia: a principal moment is zero (a slender rod has no inertia about its \
                 axis; give it a small moment or model it with point masses)",
            ))?;
        let jac = super::internal_jacobian(q);
        let g = SMatrix::<f64, 6, 9>::from_fn(|r, c| jac[r][3 + c]);
        let gg = g * g.transpose();
        let scale = gg.diagonal().max();
        let gg = gg
            .cholesky()
            .filter(|c| (0..6).all(|k| c.l()[(k, k)].powi(2) > 1e-12 * scale))
            .ok_or(SpatialInertiaError::DependentDirectors)?;
        Ok(RigidSolve {
            mass: inertia.mass(),
            e,
            d,
            j_inv,
            g,
            gg,
        })
    }

    /// `C f`: the accelerations `(f_x / m, beta x d_1, beta x d_2, beta x d_3)` with
    /// `beta = J_eff^-1 sum_i d_i x f_i` (the constrained inverse mass; no internal-constraint
    /// right-hand side).
    pub fn apply_inverse_mass(&self, f: &[f64; 12]) -> [f64; 12] {
        let mut torque = Vector3::zeros();
        for (i, di) in self.d.iter().enumerate() {
            torque += di.cross(&Vector3::new(f[3 + 3 * i], f[4 + 3 * i], f[5 + 3 * i]));
        }
        let beta = self.j_inv * torque;
        let mut a = [0.0; 12];
        for k in 0..3 {
            a[k] = f[k] / self.mass;
        }
        for (i, di) in self.d.iter().enumerate() {
            a[3 + 3 * i..6 + 3 * i].copy_from_slice(beta.cross(di).as_slice());
        }
        a
    }

    /// The accelerations `a = C f + (I - C M) G^+ r`: the solution of the body's saddle-point
    /// system with force `f` and internal-constraint right-hand side `G a = r` (see the module
    /// documentation).
    pub fn solve(&self, f: &[f64; 12], r: &[f64; 6]) -> [f64; 12] {
        let mut a = self.apply_inverse_mass(f);
        // the minimum-norm particular solution of G d0 = r (directors only)
        let d0: SVector<f64, 9> = self.g.transpose() * self.gg.solve(&SVector::from(*r));
        // minus its rigid part C M d0 (no translation part: d0_x = 0)
        let mut torque = Vector3::zeros();
        for i in 0..3 {
            let v = Vector3::new(d0[3 * i], d0[3 * i + 1], d0[3 * i + 2]) * self.e[i];
            torque += self.d[i].cross(&v);
        }
        let beta = self.j_inv * torque;
        for (i, di) in self.d.iter().enumerate() {
            let c = beta.cross(di);
            for k in 0..3 {
                a[3 + 3 * i + k] += d0[3 * i + k] - c[k];
            }
        }
        a
    }
}

impl RigidSolve {
    /// The internal constraints' multipliers `mu` of the body's saddle-point system for the
    /// force `f` and the accelerations `a` it gave: from `G^T mu = f - M a`,
    /// `mu = (G G^T)^-1 G (f - M a)` (the centre of mass does not enter `G`).
    pub fn multipliers(&self, f: &[f64; 12], a: &[f64; 12]) -> [f64; 6] {
        let res = SVector::<f64, 9>::from_fn(|k, _| f[3 + k] - self.e[k / 3] * a[3 + k]);
        let mu = self.gg.solve(&(self.g * res));
        std::array::from_fn(|k| mu[k])
    }
}

/// The internal constraints' `gamma` at director velocities `qd`: `G(q) a = -gamma` is their
/// acceleration level, with `gamma = qd^T Hess(g) qd = (|d_1'|^2, |d_2'|^2, |d_3'|^2,
/// 2 d_1' . d_2', 2 d_1' . d_3', 2 d_2' . d_3')` (the Hessians are constant, so `gamma` does not
/// depend on `q`).
pub fn internal_gamma(qd: &[f64; 12]) -> [f64; 6] {
    let v: [Vector3<f64>; 3] =
        std::array::from_fn(|i| Vector3::new(qd[3 + 3 * i], qd[4 + 3 * i], qd[5 + 3 * i]));
    [
        v[0].norm_squared(),
        v[1].norm_squared(),
        v[2].norm_squared(),
        2.0 * v[0].dot(&v[1]),
        2.0 * v[0].dot(&v[2]),
        2.0 * v[1].dot(&v[2]),
    ]
}
