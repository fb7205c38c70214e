use super::*;
use nalgebra::{DMatrix, Matrix3, Vector3};

fn top_like() -> SpatialInertia {
    // a tensor about a point off the centre of mass, with products of inertia
    let t = Matrix3::new(2.0, -0.3, 0.1, -0.3, 3.0, 0.2, 0.1, 0.2, 2.5);
    SpatialInertia::from_tensor(1.5, t, Vector3::new(0.2, -0.1, 0.3)).unwrap()
}

fn rotation() -> Matrix3<f64> {
    Orientation::Quaternion([0.8, 0.1, -0.4, 0.3])
        .matrix()
        .unwrap()
}

/// 1/2 q'^T M q' equals 1/2 m |v|^2 + 1/2 omega_p . J omega_p (omega in principal axes): the
/// constant diagonal mass matrix carries the whole kinetic energy.
#[test]
fn the_diagonal_mass_matrix_gives_the_kinetic_energy() {
    let inertia = top_like();
    let r = rotation() * inertia.axes();
    let (v, omega) = (Vector3::new(0.3, -1.2, 0.7), Vector3::new(2.0, -0.5, 1.1));
    let qd = director_velocities(v, omega, &r);
    let m = inertia.mass_diagonal();
    let t_natural: f64 = 0.5 * (0..12).map(|k| m[k] * qd[k] * qd[k]).sum::<f64>();
    let wp = r.transpose() * omega;
    let j = inertia.moments();
    let t_rigid = 0.5 * inertia.mass() * v.norm_squared()
        + 0.5 * (0..3).map(|i| j[i] * wp[i] * wp[i]).sum::<f64>();
    assert!(
        (t_natural - t_rigid).abs() < 1e-13 * t_rigid,
        "{t_natural} {t_rigid}"
    );
}

/// The internal constraints vanish on a rotation, their Jacobian matches central differences
/// and annihilates the velocities of a rigid motion.
#[test]
fn internal_constraints_and_their_jacobian() {
    let r = rotation();
    let q = natural_coordinates(Vector3::new(1.0, 2.0, 3.0), &r);
    assert!(internal_constraints(&q).iter().all(|c| c.abs() < 1e-15));
    let qd = director_velocities(
        Vector3::new(0.1, 0.2, 0.3),
        Vector3::new(1.0, -2.0, 0.5),
        &r,
    );
    let j = internal_jacobian(&q);
    for row in &j {
        let rate: f64 = row.iter().zip(&qd).map(|(a, b)| a * b).sum();
        assert!(rate.abs() < 1e-14, "{rate}");
    }
    // an arbitrary (non-rigid) point for the differences
    let x: [f64; 12] = std::array::from_fn(|k| 0.3 + 0.21 * k as f64 - 0.05 * (k * k) as f64);
    let j = internal_jacobian(&x);
    for c in 0..12 {
        let (mut p, mut m) = (x, x);
        p[c] += 1e-6;
        m[c] -= 1e-6;
        let (fp, fm) = (internal_constraints(&p), internal_constraints(&m));
        for r in 0..6 {
            let fd = (fp[r] - fm[r]) / 2e-6;
            assert!((j[r][c] - fd).abs() < 1e-8, "({r}, {c}): {} {fd}", j[r][c]);
        }
    }
}

/// A body point's position is linear in the coordinates and follows the rotation.
#[test]
fn points_ride_on_the_directors() {
    let r = rotation();
    let x = Vector3::new(1.0, -1.0, 0.5);
    let q = natural_coordinates(x, &r);
    let p = Vector3::new(0.2, -0.7, 1.3);
    assert!((point_position(&q, p) - (x + r * p)).amax() < 1e-15);
}

/// The parallel-axis theorem and the diagonalisation: a slender rod's tensor about its end
/// gives m l^2 / 12 about its centre; a rotated tensor gives its principal moments back with
/// axes that diagonalise it.
#[test]
fn tensors_are_moved_to_the_centre_and_diagonalised() {
    let (m, l, axial) = (2.0, 3.0, 1e-3);
    let end = Matrix3::from_diagonal(&Vector3::new(axial, m * l * l / 3.0, m * l * l / 3.0));
    let rod = SpatialInertia::from_tensor(m, end, Vector3::new(l / 2.0, 0.0, 0.0)).unwrap();
    let j = rod.moments();
    assert!(
        (j[0] - axial).abs() < 1e-14 && (j[1] - m * l * l / 12.0).abs() < 1e-13,
        "{j:?}"
    );
    // an ideal rod (no axial moment) has an undetermined spin: refused when built
    let ideal = Matrix3::from_diagonal(&Vector3::new(0.0, m * l * l / 3.0, m * l * l / 3.0));
    let e = SpatialInertia::from_tensor(m, ideal, Vector3::new(l / 2.0, 0.0, 0.0)).unwrap_err();
    assert!(
        matches!(e, SpatialInertiaError::Moment { index: 0, .. }),
        "{e}"
    );
    assert!((j[2] - m * l * l / 12.0).abs() < 1e-13, "{j:?}");
    let r = rotation();
    let moments = [1.0, 2.0, 2.5];
    let t = r * Matrix3::from_diagonal(&Vector3::from(moments)) * r.transpose();
    let b = SpatialInertia::from_tensor(1.0, t, Vector3::zeros()).unwrap();
    for (a, w) in b.moments().iter().zip(moments) {
        assert!((a - w).abs() < 1e-13, "{:?}", b.moments());
    }
    let a = b.axes();
    let d = a.transpose() * t * a;
    assert!((d - Matrix3::from_diagonal(&d.diagonal())).amax() < 1e-13);
    assert!((a.determinant() - 1.0).abs() < 1e-13);
}

/// The symmetric top J = (a, 2a, a): M is singular (E_2 = 0), but the KKT matrix of M with the
/// internal constraints' Jacobian is regular: the smallest singular value stays of the order
/// of the others.
#[test]
fn a_singular_mass_matrix_leaves_the_kkt_matrix_regular() {
    let top = SpatialInertia::principal(1.0, [0.5, 1.0, 0.5]).unwrap();
    assert!(top.has_singular_mass_matrix());
    assert!(!top_like().has_singular_mass_matrix());
    let q = natural_coordinates(Vector3::zeros(), &rotation());
    let sv = kkt(&top, &q).singular_values();
    let (lo, hi) = (sv.min(), sv.max());
    assert!(lo > 1e-2 * hi, "condition {}", hi / lo);
    assert_eq!(top.mass_diagonal()[6..9], [0.0; 3]);
}

/// The body's saddle-point matrix `[[M, G^T], [G, 0]]` at `q`.
fn kkt(inertia: &SpatialInertia, q: &[f64; 12]) -> DMatrix<f64> {
    let j = internal_jacobian(q);
    let m = inertia.mass_diagonal();
    let mut kkt = DMatrix::zeros(18, 18);
    for k in 0..12 {
        kkt[(k, k)] = m[k];
    }
    for r in 0..6 {
        for c in 0..12 {
            kkt[(12 + r, c)] = j[r][c];
            kkt[(c, 12 + r)] = j[r][c];
        }
    }
    kkt
}

/// A solid body, a thin disc (`E_3 = 0`) and the symmetric top (`E_2 = 0`).
fn three_bodies() -> [SpatialInertia; 3] {
    [
        top_like(),
        SpatialInertia::principal(2.0, [0.25, 0.25, 0.5]).unwrap(),
        SpatialInertia::principal(1.0, [0.5, 1.0, 0.5]).unwrap(),
    ]
}

/// The body-local elimination gives the accelerations of the full saddle-point (KKT) solve, to
/// round-off, for a solid body and for singular mass matrices alike, at directors drifted off
/// orthonormality and with any right-hand side of the internal constraints.
#[test]
fn the_rigid_solve_is_the_kkt_solve() {
    let f = [
        0.3, -1.1, 0.7, 0.2, 0.5, -0.4, 1.3, -0.2, 0.1, -0.6, 0.9, 0.4,
    ];
    let r = [0.2, -0.7, 0.3, 0.5, -0.1, 0.8];
    for inertia in three_bodies() {
        let mut q =
            natural_coordinates(Vector3::new(0.1, 0.2, -0.3), &(rotation() * inertia.axes()));
        // drift the directors by about 1e-3
        for (k, x) in q.iter_mut().enumerate().skip(3) {
            *x += 1e-3 * ((k as f64) * 1.7).sin();
        }
        let a = RigidSolve::new(&inertia, &q).unwrap().solve(&f, &r);
        let mut rhs = DMatrix::zeros(18, 1);
        for k in 0..12 {
            rhs[k] = f[k];
        }
        for k in 0..6 {
            rhs[12 + k] = r[k];
        }
        let x = kkt(&inertia, &q).lu().solve(&rhs).unwrap();
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let err = (0..12).fold(0.0f64, |m, k| m.max((a[k] - x[k]).abs()));
        assert!(
            err < 1e-12 * scale,
            "{:?}: {err:e} of {scale:e}",
            inertia.moments()
        );
        // and C alone: the same with r = 0 (only the joints' forces, no internal right-hand side)
        let c = RigidSolve::new(&inertia, &q)
            .unwrap()
            .apply_inverse_mass(&f);
        let x = kkt(&inertia, &q)
            .lu()
            .solve(&DMatrix::from_fn(
                18,
                1,
                |k, _| if k < 12 { f[k] } else { 0.0 },
            ))
            .unwrap();
        let err = (0..12).fold(0.0f64, |m, k| m.max((c[k] - x[k]).abs()));
        assert!(
            err < 1e-12 * scale,
            "{:?}: C f off by {err:e}",
            inertia.moments()
        );
    }
}

/// Force-free, the directors' accelerations `d_i'' = alpha x d_i + w x (w x d_i)` carry the
/// angular acceleration of Euler's equations `J_g alpha = -w x J_g w` (`J_g = R J R^T`), for a
/// solid body and for singular mass matrices alike.
#[test]
fn force_free_directors_follow_eulers_equations() {
    let w = Vector3::new(0.7, -1.9, 2.6);
    for inertia in three_bodies() {
        let r = rotation() * inertia.axes();
        let q = natural_coordinates(Vector3::zeros(), &r);
        let qd = director_velocities(Vector3::new(1.0, 2.0, 3.0), w, &r);
        let a = RigidSolve::new(&inertia, &q)
            .unwrap()
            .solve(&[0.0; 12], &internal_gamma(&qd).map(|g| -g));
        // alpha from alpha x d_i = d_i'' - w x (w x d_i): alpha = 1/2 sum_i d_i x (alpha x d_i)
        let mut alpha = Vector3::zeros();
        for i in 0..3 {
            let di = r.column(i).into_owned();
            let ddi = Vector3::new(a[3 + 3 * i], a[4 + 3 * i], a[5 + 3 * i]);
            alpha += 0.5 * di.cross(&(ddi - w.cross(&w.cross(&di))));
        }
        let j = inertia.moments();
        let jg = r * Matrix3::from_diagonal(&Vector3::new(j[0], j[1], j[2])) * r.transpose();
        let euler = jg.try_inverse().unwrap() * (-w.cross(&(jg * w)));
        assert!(
            (alpha - euler).amax() < 1e-12 * euler.amax(),
            "{:?}: {alpha:?} vs {euler:?}",
            inertia.moments()
        );
        // the centre of mass does not accelerate
        assert!(a[..3].iter().all(|x| x.abs() < 1e-15));
    }
}

/// A zero principal moment (a slender rod) is refused when the inertia is built, dependent
/// directors by the rigid solve, each by name.
#[test]
fn the_rigid_solve_refuses_degenerate_bodies() {
    let e = SpatialInertia::principal(1.0, [0.0, 1.0, 1.0]).unwrap_err();
    assert!(e.to_string().contains("J1 = 0e0 must be positive"), "{e}");
    let mut q = natural_coordinates(Vector3::zeros(), &Matrix3::identity());
    q[6..9].copy_from_slice(&[1.0, 0.0, 0.0]); // d_2 = d_1
    let e = RigidSolve::new(&top_like(), &q).unwrap_err().to_string();
    assert!(e.contains("directors"), "{e}");
}

#[test]
fn bad_inertias_and_orientations_are_refused() {
    let e = SpatialInertia::principal(1.0, [1.0, 1.0, 3.0]).unwrap_err();
    assert!(
        e.to_string()
            .contains("J3 = 3e0 exceeds the sum of the other two"),
        "{e}"
    );
    // a negative moment is named as such, not as a triangle violation of another one
    let e = SpatialInertia::principal(1.0, [2.2e-4, 1.0e-4, -4.0e-5]).unwrap_err();
    assert!(e.to_string().contains("J3 = -4e-5 must be positive"), "{e}");
    // an ideal slender rod (no axial moment) and moments all zero are refused when built
    for (moments, name) in [([1.0, 1.0, 0.0], "J3 = 0e0"), ([0.0; 3], "J1 = 0e0")] {
        let e = SpatialInertia::principal(1.0, moments)
            .unwrap_err()
            .to_string();
        assert!(e.contains(name) && e.contains("slender rod"), "{e}");
    }
    let e = SpatialInertia::principal(1.0, [1.0, 1.0, 1e-13]).unwrap_err();
    assert!(
        matches!(e, SpatialInertiaError::Moment { index: 2, .. }),
        "{e}"
    );
    // a thin disc (E_i = 0) and a thin but solid rod stay valid
    SpatialInertia::principal(1.0, [0.5, 1.0, 0.5]).unwrap();
    SpatialInertia::principal(1.0, [1.0, 1.0, 1e-9]).unwrap();
    let e = SpatialInertia::principal(0.0, [1.0, 1.0, 1.0]).unwrap_err();
    assert_eq!(e.to_string(), "mass 0 must be positive and finite");
    let e = SpatialInertia::principal(1.0, [1.0, f64::NAN, 1.0]).unwrap_err();
    assert_eq!(e.to_string(), "the principal moments must be finite");
    let mut t = Matrix3::identity();
    t[(0, 1)] = 0.5;
    let e = SpatialInertia::from_tensor(1.0, t, Vector3::zeros()).unwrap_err();
    assert!(e.to_string().contains("not symmetric"), "{e}");
    let flip = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
    let e = SpatialInertia::principal_with_axes(1.0, [1.0, 1.0, 1.0], flip).unwrap_err();
    assert!(e.to_string().contains("det A = -1"), "{e}");
    let e = Orientation::Quaternion([0.0; 4]).matrix().unwrap_err();
    assert!(e.contains("non-zero"), "{e}");
    let e = Orientation::Matrix(Matrix3::identity() * 2.0)
        .matrix()
        .unwrap_err();
    assert!(e.contains("not a rotation"), "{e}");
}

/// Euler sequences compose their elementary rotations in order; the three sequences agree with
/// the quaternion of the same rotation.
#[test]
fn euler_sequences() {
    use std::f64::consts::FRAC_PI_2;
    let r = Orientation::Euler(EulerSequence::Zyx, [FRAC_PI_2, FRAC_PI_2, 0.0])
        .matrix()
        .unwrap();
    // yaw 90 deg then pitch 90 deg about the new y: the body x axis points down
    assert!(
        (r.column(0) - Vector3::new(0.0, 0.0, -1.0)).amax() < 1e-15,
        "{r}"
    );
    let q = rotation();
    let (yaw, pitch, roll) = {
        let rot = nalgebra::Rotation3::from_matrix_unchecked(q);
        let (roll, pitch, yaw) = rot.euler_angles();
        (yaw, pitch, roll)
    };
    let e = Orientation::Euler(EulerSequence::Zyx, [yaw, pitch, roll])
        .matrix()
        .unwrap();
    assert!((e - q).amax() < 1e-14, "{e} {q}");
    let omega_body = Vector3::new(0.1, 0.2, 0.3);
    assert_eq!(
        global_angular_velocity(omega_body, true, &q),
        q * omega_body
    );
    assert_eq!(global_angular_velocity(omega_body, false, &q), omega_body);
}
