//! Spatial bodies in a `System`: the constraint functions over the spatial rows against finite
//! differences, gravity's potential and forces, names, a model mixing planar and spatial
//! bodies, and the builder's errors.

use mbd_model::models::{heavy_top, pendulum, TOP_LENGTH};
use mbd_model::spatial::{
    Marker, Orientation, SpatialBody, SpatialBodyRef, SpatialInertia, SpatialJoint,
    SpatialJointKind,
};
use mbd_model::{System, SystemBuilder};
use nalgebra::{DMatrix, Matrix3};

/// The heavy top off its constraints a little (so every row is exercised away from zero).
fn top_state(sys: &System) -> (Vec<f64>, Vec<f64>) {
    let (q, v) = sys.initial_guess();
    let mut q: Vec<f64> = q.iter().copied().collect();
    for (k, x) in q.iter_mut().enumerate() {
        *x += 1e-2 * ((k as f64) * 0.7).sin();
    }
    (q, v.iter().copied().collect())
}

fn dense(m: usize, n: usize) -> DMatrix<f64> {
    DMatrix::zeros(m, n)
}

fn max_diff(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax()
}

/// `Phi` vanishes at the assembled top; `Phi_q`, `gamma`, `Phi_q v`, `(Phi_q v)_q`, the
/// lambda-weighted Hessian and the triplets agree with central differences (exact for these
/// quadratic equations up to round-off).
#[test]
fn spatial_rows_match_finite_differences() {
    let sys = heavy_top([0.3, 0.3, 0.1], 0.4, 15.0).unwrap();
    let (n, m) = (sys.n_coords(), sys.n_constraints());
    let (q0, _) = sys.initial_guess();
    let mut phi = vec![0.0; m];
    sys.phi(q0.as_slice(), 0.0, &mut phi);
    assert!(phi.iter().all(|e| e.abs() < 1e-15), "{phi:?}");

    let (q, v) = top_state(&sys);
    let h = 1e-4;
    let phi_at = |q: &[f64]| {
        let mut p = vec![0.0; m];
        sys.phi(q, 0.0, &mut p);
        p
    };
    let mut fd = dense(m, n);
    for c in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[c] += h;
        qm[c] -= h;
        let (p, mm) = (phi_at(&qp), phi_at(&qm));
        for r in 0..m {
            fd[(r, c)] = (p[r] - mm[r]) / (2.0 * h);
        }
    }
    let mut jac = dense(m, n);
    let mut gamma = vec![0.0; m];
    sys.phi_q_gamma(&q, &v, 0.0, &mut jac, &mut gamma);
    assert!(max_diff(&jac, &fd) < 1e-9, "{}", max_diff(&jac, &fd));
    let mut jac2 = dense(m, n);
    sys.phi_q(&q, 0.0, &mut jac2);
    assert_eq!(jac, jac2);
    let mut triplets = Vec::new();
    sys.phi_q_triplets(&q, 0.0, &mut triplets);
    let mut from_triplets = dense(m, n);
    for (r, c, x) in triplets {
        from_triplets[(r, c)] += x;
    }
    assert_eq!(from_triplets, jac);

    // Phi_q v and gamma = -(Phi_q v)_q v
    let jv = &jac * nalgebra::DVector::from_column_slice(&v);
    let mut phid = vec![0.0; m];
    sys.phi_dot(&q, &v, 0.0, &mut phid);
    let mut both = (vec![0.0; m], vec![0.0; m]);
    sys.phi_and_phi_dot(&q, &v, 0.0, &mut both.0, &mut both.1);
    for r in 0..m {
        assert!((phid[r] - jv[r]).abs() < 1e-12);
        assert_eq!(both.1[r], phid[r]);
        assert_eq!(both.0[r], phi_at(&q)[r]);
    }
    let jv_at = |q: &[f64]| {
        let mut j = dense(m, n);
        sys.phi_q(q, 0.0, &mut j);
        j * nalgebra::DVector::from_column_slice(&v)
    };
    let mut dqv = dense(m, n);
    for c in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[c] += h;
        qm[c] -= h;
        let d = (jv_at(&qp) - jv_at(&qm)) / (2.0 * h);
        for r in 0..m {
            dqv[(r, c)] = d[r];
        }
    }
    let want_gamma = -(&dqv * nalgebra::DVector::from_column_slice(&v));
    for r in 0..m {
        assert!(
            (gamma[r] - want_gamma[r]).abs() < 1e-8,
            "row {r}: {} vs {}",
            gamma[r],
            want_gamma[r]
        );
    }
    let (mut j3, mut tan) = (dense(m, n), dense(m, n));
    sys.phi_q_dot_jacobian(&q, &v, 0.0, &mut j3, &mut tan);
    assert_eq!(j3, jac);
    assert!(max_diff(&tan, &dqv) < 1e-8, "{}", max_diff(&tan, &dqv));

    // sum_k lambda_k Hess(Phi_k) = d/dq (Phi_q^T lambda)
    let lambda: Vec<f64> = (0..m).map(|k| (k as f64 * 0.9).cos()).collect();
    let mut hess = dense(n, n);
    sys.constraint_hessian(&q, 0.0, &lambda, &mut hess);
    let jtl = |q: &[f64]| {
        let mut j = dense(m, n);
        sys.phi_q(q, 0.0, &mut j);
        j.transpose() * nalgebra::DVector::from_column_slice(&lambda)
    };
    for c in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[c] += h;
        qm[c] -= h;
        let d = (jtl(&qp) - jtl(&qm)) / (2.0 * h);
        for r in 0..n {
            assert!((hess[(r, c)] - d[r]).abs() < 1e-8, "H[{r},{c}]");
        }
    }
}

/// Gravity: `V = -m g . x`, its gradient, the forces `-grad V`, and `T` from the mass matrix
/// equals `1/2 w . J w` of the spin at the initial state.
#[test]
fn gravity_and_energy_of_a_spatial_body() {
    let moments = [0.3, 0.3, 0.1];
    let (tilt, spin) = (0.4, 15.0);
    let sys = heavy_top(moments, tilt, spin).unwrap();
    let (q, v) = sys.initial_guess();
    let (q, v) = (q.as_slice(), v.as_slice());
    let z = TOP_LENGTH * tilt.cos();
    assert!((sys.potential(q) - 9.81 * z).abs() < 1e-14);
    let mut grad = vec![0.0; 12];
    sys.potential_gradient(q, &mut grad);
    assert_eq!(grad[..3], [0.0, 0.0, 9.81]);
    assert!(grad[3..].iter().all(|&g| g == 0.0));
    let mut f = vec![0.0; 12];
    sys.forces_into(q, v, 0.0, &mut f);
    assert_eq!(f[..3], [0.0, 0.0, -9.81]);
    // spin about the symmetry axis through the tip: the centre of mass is at rest
    let t = 0.5 * moments[2] * spin * spin;
    assert!(
        (sys.kinetic(v) - t).abs() < 1e-12 * t,
        "{} vs {t}",
        sys.kinetic(v)
    );
}

/// Names: `body.x` ... `body.d3z`; `body.unit1` ... `body.orth23`, `joint.e1` ...; a planar
/// pendulum and a spatial top in one model keep the planar layout and put the spatial one after.
#[test]
fn names_and_a_mixed_model() {
    let top = heavy_top([0.3, 0.3, 0.1], 0.4, 15.0).unwrap();
    let names = top.coordinate_names();
    assert_eq!(names[..4], ["top.x", "top.y", "top.z", "top.d1x"]);
    assert_eq!(names[11], "top.d3z");
    let eq = top.equation_names();
    assert_eq!(
        eq[..6],
        [
            "top.unit1",
            "top.unit2",
            "top.unit3",
            "top.orth12",
            "top.orth13",
            "top.orth23"
        ]
    );
    assert_eq!(eq[6..], ["tip.e1", "tip.e2", "tip.e3"]);

    // the pendulum's model with the top added
    let p = pendulum(1.0, 1.0, 0.3, 9.81).unwrap();
    let mut b = p.to_model_file().to_builder().unwrap();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let inertia = SpatialInertia::principal(1.0, [0.3, 0.3, 0.1]).unwrap();
    let body =
        b.add_spatial_body(SpatialBody::new("top", inertia).position([0.0, 0.0, TOP_LENGTH]));
    b.add_spatial_joint(
        "tip",
        SpatialBodyRef::Ground,
        body,
        SpatialJoint::new(
            SpatialJointKind::Spherical,
            Marker::at([0.0; 3]),
            Marker::at([0.0, 0.0, -TOP_LENGTH]),
        )
        .unwrap(),
    );
    let mixed = b.build().unwrap();
    assert_eq!(
        (mixed.n_coords(), mixed.n_constraints(), mixed.dof()),
        (15, 11, 4)
    );
    assert_eq!(mixed.spatial_offset(), 3);
    let (q, v) = mixed.initial_guess();
    let mut phi = vec![0.0; 11];
    mixed.phi(q.as_slice(), 0.0, &mut phi);
    let mut phi_p = vec![0.0; 2];
    p.phi(&q.as_slice()[..3], 0.0, &mut phi_p);
    assert_eq!(phi[..2], phi_p[..]);
    let e = mixed.energy(q.as_slice(), v.as_slice());
    let (pq, pv) = p.initial_guess();
    let want = p.energy(pq.as_slice(), pv.as_slice()) + 9.81 * TOP_LENGTH;
    assert!((e - want).abs() < 1e-12, "{e} vs {want}");
    assert_eq!(mixed.equation_name(2), "top.unit1");
}

/// Bad spatial input: a duplicate name (also against planar bodies), a marker on a body of
/// another model, a joint from a body to itself, an orientation that is not a rotation.
#[test]
fn spatial_builder_errors_name_the_element() {
    let inertia = SpatialInertia::principal(1.0, [0.3, 0.3, 0.1]).unwrap();
    let ball = || {
        SpatialJoint::new(
            SpatialJointKind::Spherical,
            Marker::at([0.0; 3]),
            Marker::at([0.0; 3]),
        )
        .unwrap()
    };

    let mut b = SystemBuilder::new();
    b.add_body(mbd_model::Body::new("arm").mass(1.0).inertia(0.1));
    b.add_spatial_body(SpatialBody::new("arm", inertia.clone()));
    let e = b.build().unwrap_err().to_string();
    assert!(e.contains("arm"), "{e}");

    let mut b = SystemBuilder::new();
    let k = b.add_spatial_body(SpatialBody::new("k", inertia.clone()));
    b.add_spatial_joint("self", k, k, ball());
    let e = b.build().unwrap_err().to_string();
    assert!(
        e.contains("self") && e.contains("'k'") || e.contains("self") && e.contains("k"),
        "{e}"
    );

    let mut other = SystemBuilder::new();
    other.add_spatial_body(SpatialBody::new("a", inertia.clone()));
    let far = other.add_spatial_body(SpatialBody::new("b", inertia.clone()));
    let mut b = SystemBuilder::new();
    b.add_spatial_body(SpatialBody::new("only", inertia.clone()));
    b.add_spatial_joint("lost", SpatialBodyRef::Ground, far, ball());
    let e = b.build().unwrap_err().to_string();
    assert!(e.contains("lost") && e.contains("spatial #1"), "{e}");

    let mut b = SystemBuilder::new();
    b.add_spatial_body(
        SpatialBody::new("skew", inertia).orientation(Orientation::Matrix(Matrix3::new(
            1.0, 0.2, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0,
        ))),
    );
    let e = b.build().unwrap_err().to_string();
    assert!(e.contains("skew") && e.contains("orientation"), "{e}");
}

/// On a rigid motion, the angular momentum of the natural coordinates is
/// `m x x v + R J R^T omega`, and the body angular velocity is `R^T omega`.
#[test]
fn angular_momentum_and_body_angular_velocity() {
    let moments = [0.3, 0.4, 0.2];
    let sys = heavy_top(moments, 0.4, 15.0).unwrap();
    let (q, v) = sys.initial_guess();
    let (q, v) = (q.as_slice(), v.as_slice());
    let r = nalgebra::Matrix3::from_fn(|row, col| q[3 + 3 * col + row]);
    let axis = r.column(2).into_owned();
    let omega = axis * 15.0;
    let x = nalgebra::Vector3::new(q[0], q[1], q[2]);
    let xd = nalgebra::Vector3::new(v[0], v[1], v[2]);
    let j = nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::from(moments));
    let want = x.cross(&xd) + r * j * r.transpose() * omega;
    let l = nalgebra::Vector3::from(sys.spatial_angular_momentum(q, v));
    assert!((l - want).amax() < 1e-13 * want.norm(), "{l:?} vs {want:?}");
    let wb = nalgebra::Vector3::from(sys.spatial_body_angular_velocity(0, q, v).unwrap());
    assert!((wb - r.transpose() * omega).amax() < 1e-13 * 15.0, "{wb:?}");
    assert!(sys.spatial_body_angular_velocity(1, q, v).is_none());
}

/// `angular_velocity_body` turns with the initial orientation (through turned principal axes),
/// and `tensor_about` moves a tensor to the centre of mass by the parallel-axis theorem; both
/// round-trip through `to_model_file`, and giving both angular velocities is an error.
#[test]
fn body_axes_angular_velocity_and_a_tensor_about_a_point() {
    use nalgebra::{Rotation3, Vector3};
    let turned = || {
        let axes = *Rotation3::from_euler_angles(0.3, -0.5, 0.8).matrix();
        SpatialInertia::principal_with_axes(2.0, [0.2, 0.3, 0.4], axes).expect("inertia")
    };
    let frame = *Rotation3::from_euler_angles(0.4, -0.2, 1.1).matrix();
    let w_body = [0.3, -1.2, 2.0];
    let build = |body: SpatialBody| {
        let mut b = SystemBuilder::new();
        b.add_spatial_body(body);
        b.build().expect("builds")
    };
    let base = SpatialBody::new("p", turned()).orientation(Orientation::Matrix(frame));
    let body_axes = build(base.clone().angular_velocity_body(w_body));
    let global = build(base.angular_velocity((frame * Vector3::from(w_body)).into()));
    let (vb, vg) = (body_axes.initial_guess().1, global.initial_guess().1);
    let d = vb
        .iter()
        .zip(&vg)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(d < 1e-14, "{d:e}");
    // the same body's angular velocity read back in its principal axes
    let (q, v) = body_axes.initial_guess();
    let omega = body_axes
        .spatial_body_angular_velocity(0, q.as_slice(), v.as_slice())
        .expect("body 0");
    let expect = turned().axes().transpose() * Vector3::from(w_body);
    assert!((Vector3::from(omega) - expect).amax() < 1e-14);
    let back = body_axes.to_model_file().build().expect("round trip");
    assert_eq!(back.spatial_bodies(), body_axes.spatial_bodies());

    // a 2 kg box with its tensor about a corner 0.1, 0.2, 0.3 m from the centre of mass
    let (m, c) = (2.0, Vector3::new(0.1, 0.2, 0.3));
    let jc = nalgebra::Matrix3::from_diagonal(&Vector3::new(0.05, 0.07, 0.09));
    let jp: nalgebra::Matrix3<f64> =
        jc + (nalgebra::Matrix3::identity() * c.norm_squared() - c * c.transpose()) * m;
    let rows: Vec<String> = (0..3)
        .map(|r| format!("[{:e}, {:e}, {:e}]", jp[(r, 0)], jp[(r, 1)], jp[(r, 2)]))
        .collect();
    let text = format!(
        "[[spatial_bodies]]\nname = \"box\"\nmass = 2.0\ntensor = [{}]\ntensor_about = [0.1, 0.2, 0.3]\n",
        rows.join(", ")
    );
    let sys = mbd_model::ModelFile::from_toml(&text)
        .and_then(|f| f.build())
        .expect("builds");
    let moments = sys.spatial_bodies()[0].inertia.moments();
    for (got, want) in moments.iter().zip([0.05, 0.07, 0.09]) {
        assert!((got - want).abs() < 1e-14, "{moments:?}");
    }
    let both = "[[spatial_bodies]]\nname = \"b\"\nmass = 1.0\nmoments = [1.0, 1.0, 1.0]\nangular_velocity = [1.0, 0.0, 0.0]\nangular_velocity_body = [1.0, 0.0, 0.0]\n";
    let e = mbd_model::ModelFile::from_toml(both)
        .and_then(|f| f.build())
        .expect_err("both angular velocities")
        .to_string();
    assert!(
        e.contains("'b'") && e.contains("angular_velocity_body"),
        "{e}"
    );
    let stray = "[[spatial_bodies]]\nname = \"b\"\nmass = 1.0\nmoments = [1.0, 1.0, 1.0]\ntensor_about = [1.0, 0.0, 0.0]\n";
    let e = mbd_model::ModelFile::from_toml(stray)
        .and_then(|f| f.build())
        .expect_err("tensor_about without tensor")
        .to_string();
    assert!(e.contains("tensor_about"), "{e}");
}
