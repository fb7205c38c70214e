//! Spatial point masses in the model: the typed errors of bad input (each naming the point
//! mass, joint, force, sensor or field), and the derivatives of joints touching a point mass
//! against central differences.

use crate::error::ModelError;
use crate::spatial::{
    Axes, Marker, SpatialBody, SpatialBodyRef, SpatialForce, SpatialInertia, SpatialJoint,
    SpatialJointKind,
};
use crate::{ModelFile, Sensor, System, SystemBuilder, TimeFunction};
use nalgebra::{DMatrix, Matrix3};

fn joint(kind: SpatialJointKind, pa: [f64; 3], pb: [f64; 3]) -> SpatialJoint {
    SpatialJoint::new(kind, Marker::at(pa), Marker::at(pb)).unwrap()
}

/// A builder with a point mass `bob` at (0.3, -0.2, -1) and a rigid body `box`.
fn builder() -> (
    SystemBuilder,
    crate::spatial::SpatialPointMassHandle,
    crate::spatial::SpatialBodyHandle,
) {
    let mut b = SystemBuilder::new();
    let bob = b.add_spatial_point_mass("bob", 2.0, [0.3, -0.2, -1.0], [0.1, 0.4, 0.0]);
    let body = b.add_spatial_body(
        SpatialBody::new(
            "box",
            SpatialInertia::principal(1.0, [0.1, 0.2, 0.25]).unwrap(),
        )
        .position([1.0, 0.5, 0.0]),
    );
    (b, bob, body)
}

#[test]
fn joints_that_need_axes_on_a_point_mass_are_rejected_by_name() {
    use SpatialJointKind::*;
    for kind in [Revolute, Universal, Cylindrical, Prismatic, Planar, Weld] {
        for bob_first in [true, false] {
            let (mut b, bob, _) = builder();
            let (a, c): (SpatialBodyRef, SpatialBodyRef) = if bob_first {
                (bob.into(), SpatialBodyRef::Ground)
            } else {
                (SpatialBodyRef::Ground, bob.into())
            };
            b.add_spatial_joint("hinge", a, c, joint(kind, [0.0; 3], [0.0; 3]));
            let e = b.build().unwrap_err();
            let want = ModelError::PointMassJoint {
                joint: "hinge".into(),
                kind: joint(kind, [0.0; 3], [0.0; 3]).type_name(),
                point_mass: "bob".into(),
            };
            assert_eq!(e, want, "{kind:?}");
            let text = e.to_string();
            assert!(
                text.contains("'hinge'") && text.contains("'bob'") && text.contains("spherical"),
                "{text}"
            );
        }
    }
    // a slide driver needs axes on its first side only
    let drive = || TimeFunction::constant(-1.0);
    let (mut b, bob, _) = builder();
    let slide = joint(SlideDriver, [0.0; 3], [0.0; 3]);
    b.add_spatial_driver("lift", SpatialBodyRef::Ground, bob, slide, drive());
    assert!(b.build().is_ok());
    let (mut b, bob, _) = builder();
    b.add_spatial_driver("lift", bob, SpatialBodyRef::Ground, slide, drive());
    assert!(matches!(
        b.build().unwrap_err(),
        ModelError::PointMassJoint { joint, .. } if joint == "lift"
    ));
}

#[test]
fn a_marker_off_a_point_mass_is_rejected_by_name() {
    let (mut b, bob, body) = builder();
    let ball = joint(SpatialJointKind::Spherical, [0.0, 0.0, 0.1], [0.0; 3]);
    b.add_spatial_joint("ball", bob, body, ball);
    assert_eq!(
        b.build().unwrap_err(),
        ModelError::PointMassOffset {
            element: "spatial joint 'ball'".into(),
            point_mass: "bob".into(),
            point: [0.0, 0.0, 0.1],
        }
    );
}

#[test]
fn loads_a_point_mass_cannot_take_are_rejected_by_name() {
    let cst = |v: [f64; 3]| v.map(TimeFunction::constant);
    let cases: [(SpatialForce, ModelError); 4] = [
        (
            SpatialForce::torque("motor", SpatialBodyRef::Ground, cst([0.0; 3]), Axes::Global),
            ModelError::PointMassLoad {
                element: "spatial force 'motor'".into(),
                point_mass: "bob".into(),
                what: "torque",
            },
        ),
        (
            SpatialForce::force(
                "push",
                SpatialBodyRef::Ground,
                [0.0; 3],
                cst([1.0; 3]),
                Axes::Body,
            ),
            ModelError::PointMassLoad {
                element: "spatial force 'push'".into(),
                point_mass: "bob".into(),
                what: "body axes",
            },
        ),
        (
            SpatialForce::force(
                "push",
                SpatialBodyRef::Ground,
                [0.1, 0.0, 0.0],
                cst([1.0; 3]),
                Axes::Global,
            ),
            ModelError::PointMassOffset {
                element: "spatial force 'push'".into(),
                point_mass: "bob".into(),
                point: [0.1, 0.0, 0.0],
            },
        ),
        (
            SpatialForce::spring_damper(
                "spring",
                SpatialBodyRef::Ground,
                [0.0; 3],
                SpatialBodyRef::Ground,
                [0.0, 0.2, 0.0],
                10.0,
                0.0,
                0.0,
            ),
            ModelError::PointMassOffset {
                element: "spatial force 'spring'".into(),
                point_mass: "bob".into(),
                point: [0.0, 0.2, 0.0],
            },
        ),
    ];
    for (k, (mut force, want)) in cases.into_iter().enumerate() {
        let (mut b, bob, _) = builder();
        if k == 3 {
            force.b = bob.into();
        } else {
            force.a = bob.into();
        }
        b.add_spatial_force(force);
        let e = b.build().unwrap_err();
        assert!(e.to_string().contains("'bob'"), "{e}");
        assert_eq!(e, want);
    }
    // a force at the point mass and a spring to it are fine
    let (mut b, bob, body) = builder();
    b.add_spatial_force(SpatialForce::force(
        "push",
        bob,
        [0.0; 3],
        cst([1.0, 0.0, 0.0]),
        Axes::Global,
    ));
    b.add_spatial_force(SpatialForce::spring_damper(
        "spring",
        body,
        [0.1, 0.0, 0.0],
        bob,
        [0.0; 3],
        10.0,
        0.5,
        0.2,
    ));
    assert!(b.build().is_ok());
}

#[test]
fn a_bad_mass_or_state_is_rejected_by_name() {
    for m in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let mut b = SystemBuilder::new();
        b.add_spatial_point_mass("bob", m, [0.0; 3], [0.0; 3]);
        match b.build().unwrap_err() {
            ModelError::InvalidParameter {
                element, parameter, ..
            } => {
                assert!(element.contains("'bob'"), "{element}");
                assert_eq!(parameter, "mass");
            }
            e => panic!("{m}: {e}"),
        }
    }
    let mut b = SystemBuilder::new();
    b.add_spatial_point_mass("bob", 1.0, [0.0, f64::NAN, 0.0], [0.0; 3]);
    let e = b.build().unwrap_err().to_string();
    assert!(e.contains("'bob'") && e.contains("position"), "{e}");
    // names are shared with every body
    let (mut b, _, _) = builder();
    b.add_spatial_point_mass("box", 1.0, [0.0; 3], [0.0; 3]);
    assert!(
        matches!(b.build().unwrap_err(), ModelError::DuplicateName { name, .. } if name == "box")
    );
    // a handle from another model
    let mut b = SystemBuilder::new();
    let other = SystemBuilder::new().add_spatial_point_mass("far", 1.0, [0.0; 3], [0.0; 3]);
    let _ = b.add_spatial_point_mass("bob", 1.0, [0.0, 0.0, -1.0], [0.0; 3]);
    let far = crate::spatial::SpatialPointMassHandle(other.0 + 5);
    let d = joint(
        SpatialJointKind::Distance { length: 1.0 },
        [0.0; 3],
        [0.0; 3],
    );
    b.add_spatial_joint("rod", SpatialBodyRef::Ground, far, d);
    assert!(
        matches!(b.build().unwrap_err(), ModelError::UnknownBody { element, .. } if element.contains("'rod'"))
    );
}

#[test]
fn a_sensor_point_off_a_point_mass_is_rejected_by_name() {
    let (mut b, bob, _) = builder();
    b.add_sensor(Sensor::spatial_point("tip", bob, [0.1, 0.0, 0.0]));
    assert!(matches!(
        b.build().unwrap_err(),
        ModelError::PointMassOffset { element, point_mass, .. }
            if element == "sensor 'tip'" && point_mass == "bob"
    ));
}

#[test]
fn rigid_fields_on_a_point_mass_in_a_file_are_rejected_by_name() {
    let base = "[[spatial_bodies]]\nname = \"bob\"\nkind = \"point_mass\"\nmass = 1.0\n";
    for (field, line) in [
        ("moments", "moments = [1.0, 1.0, 1.0]"),
        (
            "axes",
            "axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]",
        ),
        (
            "tensor",
            "tensor = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]",
        ),
        ("tensor_about", "tensor_about = [0.0, 0.0, 0.1]"),
        (
            "orientation",
            "orientation = { quaternion = [1.0, 0.0, 0.0, 0.0] }",
        ),
        ("angular_velocity", "angular_velocity = [0.0, 0.0, 1.0]"),
        (
            "angular_velocity_body",
            "angular_velocity_body = [0.0, 0.0, 1.0]",
        ),
    ] {
        let file = ModelFile::from_toml(&format!("{base}{line}\n")).unwrap();
        let e = file.build().unwrap_err();
        assert!(
            matches!(&e, ModelError::InvalidElement { element, message }
                if element == "spatial body 'bob'" && message.contains(&format!("`{field}`"))),
            "{field}: {e}"
        );
    }
    // and the file form round-trips
    let file = ModelFile::from_toml(&format!("{base}position = [0.0, 0.0, -1.0]\n")).unwrap();
    let sys = file.build().unwrap();
    assert_eq!(sys.spatial_point_masses().len(), 1);
    let back = sys.to_model_file();
    assert_eq!(back.spatial_bodies, file.spatial_bodies);
}

/// A model with every joint kind a point mass takes: point mass to ground (distance), to a
/// rigid body (ball, at a body point off its centre), to another point mass (distance driver),
/// and a slide driver from a body's axis to a point mass; at a generic configuration.
fn mixed() -> (System, Vec<f64>, Vec<f64>) {
    let mut b = SystemBuilder::new();
    let p = b.add_spatial_point_mass("p", 1.0, [0.3, -0.2, -1.0], [0.0; 3]);
    let r = b.add_spatial_point_mass("r", 0.5, [0.9, 0.1, -0.4], [0.0; 3]);
    let body = b.add_spatial_body(SpatialBody::new(
        "box",
        SpatialInertia::principal_with_axes(1.0, [0.1, 0.2, 0.25], Matrix3::identity()).unwrap(),
    ));
    let g = SpatialBodyRef::Ground;
    b.add_spatial_joint(
        "rod",
        g,
        p,
        joint(
            SpatialJointKind::Distance { length: 1.1 },
            [0.1, 0.0, 0.0],
            [0.0; 3],
        ),
    );
    b.add_spatial_joint(
        "ball",
        body,
        r,
        joint(SpatialJointKind::Spherical, [0.2, -0.1, 0.3], [0.0; 3]),
    );
    b.add_spatial_driver(
        "pull",
        p,
        r,
        joint(SpatialJointKind::DistanceDriver, [0.0; 3], [0.0; 3]),
        TimeFunction::constant(0.9),
    );
    b.add_spatial_driver(
        "slide",
        body,
        p,
        joint(SpatialJointKind::SlideDriver, [0.0, 0.1, 0.0], [0.0; 3]),
        TimeFunction::constant(0.2),
    );
    let sys = b.build().unwrap();
    let n = sys.n_coords();
    let q: Vec<f64> = (0..n)
        .map(|i| 0.3 * (1.7 * i as f64 + 0.4).sin() + if i % 4 == 3 { 1.0 } else { 0.0 })
        .collect();
    let v: Vec<f64> = (0..n).map(|i| 0.5 * (0.9 * i as f64 + 1.1).cos()).collect();
    (sys, q, v)
}

#[test]
fn derivatives_of_joints_on_point_masses_match_central_differences() {
    let (sys, q, v) = mixed();
    let (n, m) = (sys.n_coords(), sys.n_constraints());
    assert_eq!(n, 12 + 3 + 3);
    let mut jac = DMatrix::zeros(m, n);
    let mut gamma = vec![0.0; m];
    sys.phi_q_gamma(&q, &v, 0.0, &mut jac, &mut gamma);
    let eps = 1e-6;
    let phi_at = |q: &[f64]| {
        let mut out = vec![0.0; m];
        sys.phi(q, 0.0, &mut out);
        out
    };
    let mut err = 0.0f64;
    for c in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[c] += eps;
        qm[c] -= eps;
        let (fp, fm) = (phi_at(&qp), phi_at(&qm));
        for r in 0..m {
            err = err.max(((fp[r] - fm[r]) / (2.0 * eps) - jac[(r, c)]).abs());
        }
    }
    assert!(err < 1e-8, "Phi_q: {err:e}");
    // gamma = -(Phi_q v)_q v: central differences of Phi_q v along v
    let phi_q_v = |q: &[f64]| {
        let mut j = DMatrix::zeros(m, n);
        sys.phi_q(q, 0.0, &mut j);
        j * nalgebra::DVector::from_column_slice(&v)
    };
    let qp: Vec<f64> = q.iter().zip(&v).map(|(q, v)| q + eps * v).collect();
    let qm: Vec<f64> = q.iter().zip(&v).map(|(q, v)| q - eps * v).collect();
    let d = (phi_q_v(&qp) - phi_q_v(&qm)) / (2.0 * eps);
    let gerr = (0..m).map(|r| (d[r] + gamma[r]).abs()).fold(0.0, f64::max);
    assert!(gerr < 1e-8, "gamma: {gerr:e}");
    // the point masses' columns: only their joints' rows, no internal constraint
    let names = sys.equation_names();
    for c in 12..18 {
        for r in 0..m {
            if jac[(r, c)] != 0.0 {
                assert!(!names[r].starts_with("box."), "{} on column {c}", names[r]);
            }
        }
    }
}

#[test]
fn the_lambda_weighted_hessian_matches_central_differences() {
    let (sys, q, _) = mixed();
    let (n, m) = (sys.n_coords(), sys.n_constraints());
    let lambda: Vec<f64> = (0..m).map(|r| 0.7 - 0.3 * r as f64).collect();
    let mut h = DMatrix::zeros(n, n);
    sys.add_constraint_hessian(&q, 0.0, &lambda, 1.0, &mut h);
    let grad = |q: &[f64]| {
        let mut j = DMatrix::zeros(m, n);
        sys.phi_q(q, 0.0, &mut j);
        j.transpose() * nalgebra::DVector::from_column_slice(&lambda)
    };
    let eps = 1e-6;
    let mut err = 0.0f64;
    for c in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[c] += eps;
        qm[c] -= eps;
        let d = (grad(&qp) - grad(&qm)) / (2.0 * eps);
        for r in 0..n {
            err = err.max((d[r] - h[(r, c)]).abs());
        }
    }
    assert!(err < 1e-8, "{err:e}");
}
