//! Force elements on spatial bodies: the potential's gradient and Hessian and the
//! non-conservative Jacobians against finite differences, the generalised forces' power
//! against `F . v_P` and `tau . omega` on rigid motions, body-frame loads through bodies with
//! turned principal axes, and the builder's errors.

use mbd_model::spatial::{
    director_velocities, Axes, Orientation, SpatialBody, SpatialForce, SpatialInertia,
};
use mbd_model::{ModelError, System, SystemBuilder, TimeFunction};
use nalgebra::{DMatrix, Rotation3, Vector3};

fn cst(v: [f64; 3]) -> [TimeFunction; 3] {
    v.map(TimeFunction::constant)
}

/// Principal axes turned in the body frame, so lowering points and axes matters.
fn turned_inertia(mass: f64) -> SpatialInertia {
    let axes = *Rotation3::from_euler_angles(0.3, -0.5, 0.8).matrix();
    SpatialInertia::principal_with_axes(mass, [0.2, 0.3, 0.4], axes).expect("valid inertia")
}

fn two_bodies(b: &mut SystemBuilder) -> [mbd_model::spatial::SpatialBodyHandle; 2] {
    let o = Orientation::Matrix(*Rotation3::from_euler_angles(0.1, 0.2, -0.4).matrix());
    let p = b.add_spatial_body(
        SpatialBody::new("p", turned_inertia(2.0))
            .position([0.1, -0.2, 0.3])
            .orientation(o)
            .velocity([0.3, -0.1, 0.2])
            .angular_velocity([1.0, -2.0, 0.5]),
    );
    let r = b.add_spatial_body(
        SpatialBody::new(
            "r",
            SpatialInertia::principal(1.5, [0.1, 0.1, 0.15]).expect("inertia"),
        )
        .position([0.9, 0.4, -0.2])
        .velocity([-0.2, 0.4, 0.1])
        .angular_velocity([0.2, 0.7, -1.1]),
    );
    [p, r]
}

/// A model with every kind of spatial force: spring-dampers between the bodies and to
/// ground, constant and time-dependent forces, body-frame forces and torques.
fn loaded() -> System {
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let [p, r] = two_bodies(&mut b);
    let g = mbd_model::spatial::SpatialBodyRef::Ground;
    b.add_spatial_force(SpatialForce::spring_damper(
        "link",
        p,
        [0.1, 0.2, -0.1],
        r,
        [-0.05, 0.1, 0.2],
        120.0,
        3.0,
        0.4,
    ));
    b.add_spatial_force(SpatialForce::spring_damper(
        "anchor",
        g,
        [0.0, 0.0, 1.0],
        p,
        [0.0, 0.1, 0.0],
        50.0,
        0.5,
        0.0,
    ));
    b.add_spatial_force(SpatialForce::force(
        "push",
        r,
        [0.1, 0.0, 0.05],
        cst([1.0, -2.0, 0.5]),
        Axes::Global,
    ));
    let wave = [
        TimeFunction::Harmonic {
            offset: 2.0,
            amplitude: 3.0,
            omega: 0.1,
            phase: 0.0,
        },
        TimeFunction::constant(-1.0),
        TimeFunction::linear(0.5, 2.0),
    ];
    b.add_spatial_force(SpatialForce::force(
        "thrust",
        p,
        [0.2, -0.1, 0.0],
        wave,
        Axes::Body,
    ));
    b.add_spatial_force(SpatialForce::torque(
        "motor",
        r,
        cst([0.3, 0.1, -0.7]),
        Axes::Body,
    ));
    b.add_spatial_force(SpatialForce::torque(
        "twist",
        p,
        cst([-0.4, 0.2, 0.9]),
        Axes::Global,
    ));
    b.build().expect("loaded model builds")
}

fn state(sys: &System) -> (Vec<f64>, Vec<f64>) {
    let (q, v) = sys.initial_guess();
    (q.iter().copied().collect(), v.iter().copied().collect())
}

#[test]
fn potential_derivatives_match_finite_differences() {
    let sys = loaded();
    let n = sys.n_coords();
    let (q, _) = state(&sys);
    let mut grad = vec![0.0; n];
    sys.potential_gradient(&q, &mut grad);
    let mut hess = DMatrix::zeros(n, n);
    sys.potential_hessian(&q, &mut hess);
    let h = 1e-5;
    for c in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[c] += h;
        qm[c] -= h;
        let fd = (sys.potential(&qp) - sys.potential(&qm)) / (2.0 * h);
        assert!(
            (fd - grad[c]).abs() < 1e-6 * (1.0 + fd.abs()),
            "dV/dq{c}: {fd} vs {}",
            grad[c]
        );
        let (mut gp, mut gm) = (vec![0.0; n], vec![0.0; n]);
        sys.potential_gradient(&qp, &mut gp);
        sys.potential_gradient(&qm, &mut gm);
        for r in 0..n {
            let fd = (gp[r] - gm[r]) / (2.0 * h);
            assert!(
                (fd - hess[(r, c)]).abs() < 1e-5 * (1.0 + fd.abs()),
                "d2V/dq{r}dq{c}: {fd} vs {}",
                hess[(r, c)]
            );
        }
    }
    // forces_into is gravity minus the gradient plus the non-conservative part
    let (q, v) = state(&sys);
    let (mut all, mut nc) = (vec![0.0; n], vec![0.0; n]);
    sys.forces_into(&q, &v, 0.7, &mut all);
    sys.nonconservative_forces(&q, &v, 0.7, &mut nc);
    for k in 0..n {
        let expect = nc[k] - grad[k];
        assert!(
            (all[k] - expect).abs() < 1e-12 * (1.0 + expect.abs()),
            "Q[{k}]"
        );
    }
}

#[test]
fn nonconservative_jacobians_match_finite_differences() {
    let sys = loaded();
    let n = sys.n_coords();
    let (q, v) = state(&sys);
    let t = 0.4;
    let (mut jq, mut jv) = (DMatrix::<f64>::zeros(n, n), DMatrix::<f64>::zeros(n, n));
    sys.nonconservative_jacobian(&q, &v, t, |i, j, dq, dv| {
        jq[(i, j)] += dq;
        jv[(i, j)] += dv;
    });
    let h = 1e-6;
    let f = |q: &[f64], v: &[f64]| {
        let mut out = vec![0.0; n];
        sys.nonconservative_forces(q, v, t, &mut out);
        out
    };
    for c in 0..n {
        for (velocity, jac) in [(false, &jq), (true, &jv)] {
            let (mut qp, mut qm, mut vp, mut vm) = (q.clone(), q.clone(), v.clone(), v.clone());
            if velocity {
                vp[c] += h;
                vm[c] -= h;
            } else {
                qp[c] += h;
                qm[c] -= h;
            }
            let (fp, fm) = (f(&qp, &vp), f(&qm, &vm));
            for r in 0..n {
                let fd = (fp[r] - fm[r]) / (2.0 * h);
                assert!(
                    (fd - jac[(r, c)]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "({r}, {c}) velocity {velocity}: {fd} vs {}",
                    jac[(r, c)]
                );
            }
        }
    }
    assert!(
        jv.amax() > 0.1,
        "the dampers' velocity Jacobian is not zero"
    );
}

/// On a rigid motion the generalised forces' power is the loads' mechanical power: `F . v_P`
/// for a force at P, `tau . omega` for a torque, with body-frame components turned by the
/// body frame (not the principal frame).
#[test]
fn loads_do_the_work_of_a_force_and_a_torque() {
    let frame = *Rotation3::from_euler_angles(0.1, 0.2, -0.4).matrix();
    let (tau_b, f_b, p_b) = ([0.3, -0.8, 0.5], [1.5, 0.2, -0.7], [0.2, -0.1, 0.3]);
    let mut b = SystemBuilder::new();
    let body = b.add_spatial_body(
        SpatialBody::new("p", turned_inertia(2.0)).orientation(Orientation::Matrix(frame)),
    );
    b.add_spatial_force(SpatialForce::torque("motor", body, cst(tau_b), Axes::Body));
    b.add_spatial_force(SpatialForce::force(
        "thrust",
        body,
        p_b,
        cst(f_b),
        Axes::Body,
    ));
    let sys = b.build().expect("builds");
    let (q, _) = state(&sys);
    let principal = frame * turned_inertia(2.0).axes();
    let (vel, omega) = (Vector3::new(0.4, -0.3, 0.9), Vector3::new(1.2, -0.7, 2.1));
    let v = director_velocities(vel, omega, &principal);
    let mut qf = vec![0.0; 12];
    sys.nonconservative_forces(&q, &v, 0.0, &mut qf);
    let power: f64 = qf.iter().zip(&v).map(|(f, v)| f * v).sum();
    let tau = frame * Vector3::from(tau_b);
    let force = frame * Vector3::from(f_b);
    let v_point = vel + omega.cross(&(frame * Vector3::from(p_b)));
    let expect = tau.dot(&omega) + force.dot(&v_point);
    assert!(
        (power - expect).abs() < 1e-12 * expect.abs().max(1.0),
        "{power} vs {expect}"
    );
    let (diss, ext) = sys.nonconservative_power(&q, &v, 0.0);
    assert_eq!(diss, 0.0);
    assert!((ext - expect).abs() < 1e-12 * expect.abs().max(1.0));
    assert!(!sys.is_conservative() && sys.has_force_elements());
}

/// A spring between body points: the potential is `k/2 (l - L)^2` of the points' distance,
/// body-frame points taken through the turned principal axes.
#[test]
fn spring_energy_follows_the_body_points() {
    let mut b = SystemBuilder::new();
    let [p, r] = two_bodies(&mut b);
    let (pa, pb) = ([0.1, 0.2, -0.1], [-0.05, 0.1, 0.2]);
    b.add_spatial_force(SpatialForce::spring_damper(
        "s", p, pa, r, pb, 80.0, 0.0, 0.3,
    ));
    let sys = b.build().expect("builds");
    assert!(sys.is_conservative());
    let (q, _) = state(&sys);
    let point = |k: usize, x: [f64; 3]| {
        let body = &sys.spatial_bodies()[k];
        let o = body.orientation.matrix().expect("rotation");
        Vector3::from(body.position) + o * Vector3::from(x)
    };
    let l = (point(1, pb) - point(0, pa)).norm();
    let expect = 0.5 * 80.0 * (l - 0.3) * (l - 0.3);
    let got = sys.potential(&q);
    assert!((got - expect).abs() < 1e-12 * expect, "{got} vs {expect}");
}

#[test]
fn spatial_force_errors_name_the_element_and_field() {
    let build = |f: SpatialForce| {
        let mut b = SystemBuilder::new();
        two_bodies(&mut b);
        b.add_spatial_force(f);
        b.build().expect_err("invalid force").to_string()
    };
    let mut b = SystemBuilder::new();
    let [p, r] = two_bodies(&mut b);
    let e = build(SpatialForce::spring_damper(
        "s", p, [0.0; 3], r, [0.0; 3], -1.0, 0.0, 0.0,
    ));
    assert!(e.contains("'s'") && e.contains("stiffness"), "{e}");
    let e = build(SpatialForce::spring_damper(
        "s",
        p,
        [f64::NAN, 0.0, 0.0],
        r,
        [0.0; 3],
        1.0,
        0.0,
        0.0,
    ));
    assert!(e.contains("point_a"), "{e}");
    let e = build(SpatialForce::torque(
        "m",
        r,
        [
            TimeFunction::constant(f64::INFINITY),
            TimeFunction::constant(0.0),
            TimeFunction::constant(0.0),
        ],
        Axes::Body,
    ));
    assert!(e.contains("'m'") && e.contains("tx"), "{e}");
    let g = mbd_model::spatial::SpatialBodyRef::Ground;
    let e = build(SpatialForce::spring_damper(
        "s", g, [0.0; 3], g, [0.0; 3], 1.0, 0.0, 0.0,
    ));
    assert!(e.contains("ground"), "{e}");
    let mut b = SystemBuilder::new();
    let [p, _] = two_bodies(&mut b);
    b.add_spatial_force(SpatialForce::torque("m", p, cst([1.0; 3]), Axes::Global));
    b.add_spatial_force(SpatialForce::torque("m", p, cst([1.0; 3]), Axes::Global));
    match b.build() {
        Err(ModelError::DuplicateName {
            kind: "force",
            name,
        }) => assert_eq!(name, "m"),
        other => panic!("expected a duplicate name, got {other:?}"),
    }
}

/// Every kind in a model file: the file builds the model the code builds (potential, forces and
/// Jacobians equal), and `to_model_file` writes it back (TOML and JSON round trips).
#[test]
fn spatial_forces_in_model_files() {
    let text = r#"
spatial_gravity = [0.0, 0.0, -9.81]

[[spatial_bodies]]
name = "p"
mass = 2.0
moments = [0.2, 0.3, 0.4]
position = [0.1, -0.2, 0.3]
velocity = [0.3, -0.1, 0.2]
angular_velocity = [1.0, -2.0, 0.5]

[[spatial_forces]]
type = "spring_damper"
name = "anchor"
body_a = "ground"
point_a = [0.0, 0.0, 1.0]
body_b = "p"
point_b = [0.0, 0.1, 0.0]
stiffness = 50.0
damping = 0.5

[[spatial_forces]]
type = "force"
name = "thrust"
body = "p"
point = [0.2, -0.1, 0.0]
fx = { kind = "harmonic", amplitude = 3.0, omega = 0.1 }
fz = { kind = "constant", value = -1.0 }
frame = "body"

[[spatial_forces]]
type = "torque"
name = "motor"
body = "p"
tz = { kind = "constant", value = 0.7 }
"#;
    let file = mbd_model::ModelFile::from_toml(text).expect("parses");
    let sys = file.build().expect("builds");
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let p = b.add_spatial_body(
        SpatialBody::new(
            "p",
            SpatialInertia::principal(2.0, [0.2, 0.3, 0.4]).expect("inertia"),
        )
        .position([0.1, -0.2, 0.3])
        .velocity([0.3, -0.1, 0.2])
        .angular_velocity([1.0, -2.0, 0.5]),
    );
    let g = mbd_model::spatial::SpatialBodyRef::Ground;
    b.add_spatial_force(SpatialForce::spring_damper(
        "anchor",
        g,
        [0.0, 0.0, 1.0],
        p,
        [0.0, 0.1, 0.0],
        50.0,
        0.5,
        0.0,
    ));
    let zero = TimeFunction::constant(0.0);
    let wave = TimeFunction::Harmonic {
        offset: 0.0,
        amplitude: 3.0,
        omega: 0.1,
        phase: 0.0,
    };
    b.add_spatial_force(SpatialForce::force(
        "thrust",
        p,
        [0.2, -0.1, 0.0],
        [wave, zero.clone(), TimeFunction::constant(-1.0)],
        Axes::Body,
    ));
    b.add_spatial_force(SpatialForce::torque(
        "motor",
        p,
        [zero.clone(), zero, TimeFunction::constant(0.7)],
        Axes::Global,
    ));
    let code = b.build().expect("builds");
    assert_eq!(sys.spatial_forces(), code.spatial_forces());
    let (q, v) = state(&sys);
    let (mut a, mut c) = (vec![0.0; 12], vec![0.0; 12]);
    sys.forces_into(&q, &v, 2.0, &mut a);
    code.forces_into(&q, &v, 2.0, &mut c);
    assert_eq!(a, c);
    assert_eq!(sys.potential(&q), code.potential(&q));
    let back = sys.to_model_file();
    let toml = back.to_toml().expect("writes TOML");
    let again = mbd_model::ModelFile::from_toml(&toml).expect("reads back");
    assert_eq!(again, back);
    let json = mbd_model::ModelFile::from_json(&back.to_json().expect("JSON")).expect("reads");
    assert_eq!(
        json.build().expect("builds").spatial_forces(),
        sys.spatial_forces()
    );
    // errors name the element and what is wrong
    let bad = text.replace("body = \"p\"\ntz", "body = \"q\"\ntz");
    let e = mbd_model::ModelFile::from_toml(&bad)
        .and_then(|f| f.build())
        .expect_err("unknown body")
        .to_string();
    assert!(e.contains("'motor'") && e.contains("'q'"), "{e}");
    let bad = text.replace("stiffness = 50.0", "stiffness = -50.0");
    let e = mbd_model::ModelFile::from_toml(&bad)
        .and_then(|f| f.build())
        .expect_err("negative stiffness")
        .to_string();
    assert!(e.contains("'anchor'") && e.contains("stiffness"), "{e}");
    let bad = text.replace("frame = \"body\"", "frame = \"local\"");
    let e = mbd_model::ModelFile::from_toml(&bad)
        .expect_err("unknown frame")
        .to_string();
    assert!(e.contains("local"), "{e}");
}
