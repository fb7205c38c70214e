//! Point masses and body frames in the Rust builder: the same systems as the model files'
//! `kind = "point_mass"` and `com` (the file resolver lowers them through the builder), and an
//! error for each misuse.

use mbd_model::{Body, BodyRef, Force, Joint, System, SystemBuilder, TimeFunction};
use std::path::PathBuf;

fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn same_system(a: &System, b: &System) {
    assert_eq!(a.bodies(), b.bodies());
    assert_eq!(a.joints(), b.joints());
    assert_eq!(a.forces(), b.forces());
    assert_eq!(a.gravity(), b.gravity());
    assert_eq!(a.initial_guess(), b.initial_guess());
}

#[test]
fn point_mass_pendulum_from_the_builder_equals_the_file() {
    let file = System::from_path(repo_root().join("examples/models/point_mass_pendulum.toml"))
        .expect("example loads");
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let bob = b.add_point_mass(
        "bob",
        1.0,
        [0.49999999999999994, -0.8660254037844387],
        [0.0, 0.0],
    );
    b.add_joint(Joint::distance(
        "rod",
        BodyRef::Ground,
        [0.0, 0.0],
        bob,
        [0.0, 0.0],
        1.0,
    ));
    let sys = b.build().expect("builds");
    same_system(&sys, &file);
    // the point mass's angle joint is added, its nominal inertia is m l^2 with l = 1 m
    assert_eq!(
        sys.joints().last().map(|j| j.name.as_str()),
        Some("bob:point_mass")
    );
    assert_eq!(sys.bodies()[0].inertia, 1.0);
    assert_eq!(sys.n_constraints(), 2);
}

/// A rod of length 2 pinned to ground at one end, with a spring from its other end, given in
/// a frame whose origin is the pinned end (centre of mass at `[1, 0]`), equals the same rod
/// given about its centre of mass; the file form with `com` agrees with both.
#[test]
fn body_frame_model_equals_its_centre_of_mass_equivalent() {
    let theta = 0.4f64;
    let omega = 0.7;
    let spring =
        |body, p| Force::spring_damper("s", BodyRef::Ground, [3.0, 0.0], body, p, 10.0, 0.5, 1.5);

    // in the body frame: origin at the pinned end, rotating with the rod
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let rod = b.add_body(
        Body::new("rod")
            .rod(2.0, 2.0)
            .position(0.0, 0.0, theta)
            .velocity(0.0, 0.0, omega),
    );
    b.add_joint(Joint::revolute(
        "pin",
        BodyRef::Ground,
        [0.0, 0.0],
        rod,
        [0.0, 0.0],
    ));
    b.add_force(spring(rod, [2.0, 0.0]));
    b.set_body_frame(rod, [1.0, 0.0]);
    let framed = b.build().expect("builds");

    // about the centre of mass
    let (s, c) = theta.sin_cos();
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let rod = b.add_body(
        Body::new("rod")
            .rod(2.0, 2.0)
            .position(c, s, theta)
            .velocity(-omega * s, omega * c, omega),
    );
    b.add_joint(Joint::revolute(
        "pin",
        BodyRef::Ground,
        [0.0, 0.0],
        rod,
        [-1.0, 0.0],
    ));
    b.add_force(spring(rod, [1.0, 0.0]));
    let plain = b.build().expect("builds");

    let (qf, vf) = framed.initial_guess();
    let (qp, vp) = plain.initial_guess();
    assert!((qf.clone() - qp.clone()).amax() < 1e-15, "{qf} vs {qp}");
    assert!((vf - vp).amax() < 1e-15);
    assert_eq!(framed.joints(), plain.joints());
    assert_eq!(framed.forces(), plain.forces());
    let mut phi = vec![0.0; 2];
    framed.phi(qf.as_slice(), 0.0, &mut phi);
    assert!(phi.iter().all(|x| x.abs() < 1e-15), "{phi:?}");

    let toml = format!(
        "gravity = [0.0, -9.81]\n\
         [[bodies]]\nname = \"rod\"\nmass = 2.0\ninertia = {}\nposition = [0.0, 0.0, {theta}]\n\
         velocity = [0.0, 0.0, {omega}]\ncom = [1.0, 0.0]\n\
         [[joints]]\ntype = \"revolute\"\nname = \"pin\"\nbody_a = \"ground\"\nbody_b = \"rod\"\n\
         [[forces]]\ntype = \"spring_damper\"\nname = \"s\"\nbody_a = \"ground\"\n\
         point_a = [3.0, 0.0]\nbody_b = \"rod\"\npoint_b = [2.0, 0.0]\nstiffness = 10.0\n\
         damping = 0.5\nrest_length = 1.5\n",
        2.0 * 4.0 / 12.0
    );
    let file = System::from_toml(&toml).expect("file loads");
    same_system(&file, &framed);
}

#[test]
fn point_mass_and_frame_misuse_are_errors_naming_the_element() {
    let build = |f: &dyn Fn(&mut SystemBuilder, mbd_model::BodyHandle)| {
        let mut b = SystemBuilder::new();
        b.set_gravity([0.0, -9.81]);
        let bob = b.add_point_mass("bob", 1.0, [0.0, -1.0], [0.0, 0.0]);
        b.add_joint(Joint::distance(
            "rod",
            BodyRef::Ground,
            [0.0, 0.0],
            bob,
            [0.0, 0.0],
            1.0,
        ));
        f(&mut b, bob);
        b.build().map(|_| ()).expect_err("must fail").to_string()
    };
    let e = build(&|b, bob| {
        b.add_force(Force::force(
            "push",
            bob,
            [0.1, 0.0],
            TimeFunction::constant(1.0),
            TimeFunction::constant(0.0),
        ));
    });
    assert!(
        e.contains("force 'push'") && e.contains("'bob'") && e.contains("point"),
        "{e}"
    );
    let e = build(&|b, bob| {
        b.add_force(Force::torque("tq", bob, TimeFunction::constant(1.0)));
    });
    assert!(
        e.contains("force 'tq'") && e.contains("torque") && e.contains("'bob'"),
        "{e}"
    );
    let e = build(&|b, bob| {
        b.add_joint(Joint::angle_driver(
            "drive",
            BodyRef::Ground,
            bob,
            TimeFunction::constant(0.0),
        ));
    });
    assert!(
        e.contains("joint 'drive'") && e.contains("angle driver"),
        "{e}"
    );
    let e = build(&|b, _| {
        // a handle of another model with eight bodies
        let mut other = SystemBuilder::new();
        let eighth = (0..8)
            .map(|i| other.add_body(Body::new(format!("b{i}"))))
            .last()
            .expect("eight bodies");
        b.set_body_frame(eighth, [0.0, 0.0]);
    });
    assert!(e.contains("#7") && e.contains("set_body_frame"), "{e}");
    let e = build(&|b, bob| {
        b.set_body_frame(bob, [f64::NAN, 0.0]);
    });
    assert!(
        e.contains("body 'bob'") && e.contains("centre of mass"),
        "{e}"
    );
    // a point mass with a frame attaches at its centre of mass given in that frame
    let mut b = SystemBuilder::new();
    let bob = b.add_point_mass("bob", 2.0, [-0.5, -1.0], [0.0, 0.0]);
    b.set_body_frame(bob, [0.5, 0.0]);
    b.add_joint(Joint::distance(
        "rod",
        BodyRef::Ground,
        [0.0, 0.0],
        bob,
        [0.5, 0.0],
        1.0,
    ));
    let sys = b.build().expect("builds");
    let (q, _) = sys.initial_guess();
    assert_eq!((q[0], q[1], q[2]), (0.0, -1.0, 0.0));
}
