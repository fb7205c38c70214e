//! Every bad input is rejected with its specific error.

mod common;

use common::PENDULUM_TOML;

use mbd_model::joints::RevoluteSpec;
use mbd_model::models::{self, four_bar, pendulum};
use mbd_model::{
    Body, BodyHandle, BodyRef, Force, Joint, ModelError, ModelFile, RedundantConstraints, System,
    SystemBuilder, TimeFunction,
};

fn one_body() -> (SystemBuilder, BodyHandle) {
    let mut b = SystemBuilder::new();
    let h = b.add_body(Body::new("link").position(0.5, 0.0, 0.0));
    (b, h)
}

fn err(b: SystemBuilder) -> ModelError {
    b.build().expect_err("the model must be rejected")
}

fn invalid(e: &ModelError, el: &str, param: &str) {
    match e {
        ModelError::InvalidParameter {
            element, parameter, ..
        } => {
            assert_eq!(element, el, "{e}");
            assert_eq!(*parameter, param, "{e}");
        }
        _ => panic!("expected InvalidParameter({el}, {param}), got {e:?}"),
    }
}

#[test]
fn valid_reference_file_builds() {
    System::from_toml(PENDULUM_TOML).unwrap();
}

/// An infinite initial velocity is reported as infinite (not as the NaN that frame lowering
/// would make of it), a finite one whose kinetic energy overflows is rejected, and a rigid
/// body without inertia is pointed at the point mass.
#[test]
fn initial_state_and_inertia_errors_say_what_is_wrong() {
    for (velocity, value) in [
        ([0.0, 0.0, f64::INFINITY], f64::INFINITY),
        ([0.0, 1e308, 0.0], 1e308),
    ] {
        let mut b = SystemBuilder::new();
        let h = b.add_body(Body::new("link").position(0.5, 0.0, 0.0).velocity(
            velocity[0],
            velocity[1],
            velocity[2],
        ));
        b.set_body_frame(h, [0.1, 0.0]);
        let e = err(b);
        invalid(&e, "link", "velocity");
        match &e {
            ModelError::InvalidParameter { value: v, .. } => assert_eq!(*v, value, "{e}"),
            _ => unreachable!(),
        }
        // the value as a reader wants it: `inf`, `1e308`, not 309 digits
        let shown = if value.is_finite() {
            "= 1e308 "
        } else {
            "= inf "
        };
        assert!(e.to_string().contains(shown), "{e}");
    }
    let mut b = SystemBuilder::new();
    b.add_body(Body::new("bob").mass(1.0).inertia(0.0));
    let e = err(b);
    invalid(&e, "bob", "inertia");
    assert!(
        e.to_string().contains("point_mass") && e.to_string().contains("add_point_mass"),
        "{e}"
    );
}

#[test]
fn unknown_body_handle() {
    // a handle of another model with four bodies
    let mut other = SystemBuilder::new();
    let fourth = (0..4)
        .map(|i| other.add_body(Body::new(format!("b{i}")).mass(1.0).inertia(1.0)))
        .last()
        .unwrap();
    let (mut b, _) = one_body();
    b.add_joint(Joint::revolute(
        "pin",
        BodyRef::Ground,
        [0.0, 0.0],
        fourth,
        [0.0, 0.0],
    ));
    match err(b) {
        ModelError::UnknownBody { element, body } => {
            assert_eq!(element, "pin");
            assert!(body.contains("#3"), "{body}");
        }
        e => panic!("{e:?}"),
    }
    // in a force too
    let (mut b, _) = one_body();
    b.add_force(Force::torque("tq", fourth, TimeFunction::constant(1.0)));
    assert!(matches!(err(b), ModelError::UnknownBody { element, .. } if element == "tq"));
}

#[test]
fn unknown_body_name_in_file() {
    let text = PENDULUM_TOML.replace("body_b = \"link1\"", "body_b = \"lnk1\"");
    match System::from_toml(&text).unwrap_err() {
        ModelError::UnknownBody { element, body } => {
            assert!(element.contains("pin1"), "{element}");
            assert_eq!(body, "lnk1");
        }
        e => panic!("{e:?}"),
    }
    // and in a force, from JSON
    let mut mf = ModelFile::from_toml(PENDULUM_TOML).unwrap();
    mf.forces.push(mbd_model::ForceSpec::Torque(
        mbd_model::forces::TorqueSpec {
            name: "motor".into(),
            body: "link2".into(),
            torque: TimeFunction::constant(1.0),
        },
    ));
    match System::from_json(&mf.to_json().unwrap()).unwrap_err() {
        ModelError::UnknownBody { element, body } => {
            assert!(element.contains("motor"), "{element}");
            assert_eq!(body, "link2");
        }
        e => panic!("{e:?}"),
    }
}

#[test]
fn duplicate_body_name() {
    let (mut b, _) = one_body();
    b.add_body(Body::new("link"));
    assert_eq!(
        err(b),
        ModelError::DuplicateName {
            kind: "body",
            name: "link".into()
        }
    );
}

#[test]
fn duplicate_joint_name() {
    let (mut b, h) = one_body();
    let c = b.add_body(Body::new("other").position(2.0, 0.0, 0.0));
    b.add_joint(Joint::revolute(
        "pin",
        BodyRef::Ground,
        [0.0, 0.0],
        h,
        [-0.5, 0.0],
    ));
    b.add_joint(Joint::revolute("pin", h, [0.5, 0.0], c, [-1.0, 0.0]));
    assert_eq!(
        err(b),
        ModelError::DuplicateName {
            kind: "joint",
            name: "pin".into()
        }
    );
}

#[test]
fn duplicate_force_name() {
    let (mut b, h) = one_body();
    b.add_force(Force::torque("f", h, TimeFunction::constant(1.0)));
    b.add_force(Force::force(
        "f",
        h,
        [0.0, 0.0],
        TimeFunction::constant(1.0),
        TimeFunction::constant(0.0),
    ));
    assert_eq!(
        err(b),
        ModelError::DuplicateName {
            kind: "force",
            name: "f".into()
        }
    );
}

#[test]
fn body_named_ground() {
    for name in ["ground", "Ground"] {
        let mut b = SystemBuilder::new();
        b.add_body(Body::new(name));
        match err(b) {
            ModelError::DuplicateName { kind, name: n } => {
                assert_eq!(n, name);
                assert!(kind.contains("ground"), "{kind}");
            }
            e => panic!("{e:?}"),
        }
    }
}

#[test]
fn zero_mass() {
    let mut b = SystemBuilder::new();
    b.add_body(Body::new("a").mass(0.0));
    invalid(&err(b), "a", "mass");
}

#[test]
fn negative_mass() {
    let mut b = SystemBuilder::new();
    b.add_body(Body::new("a").mass(-1.0));
    invalid(&err(b), "a", "mass");
}

#[test]
fn nan_inertia() {
    let mut b = SystemBuilder::new();
    b.add_body(Body::new("a").inertia(f64::NAN));
    let e = err(b);
    invalid(&e, "a", "inertia");
    assert!(matches!(e, ModelError::InvalidParameter { value, .. } if value.is_nan()));
}

#[test]
fn infinite_position() {
    let mut b = SystemBuilder::new();
    b.add_body(Body::new("a").position(0.0, f64::INFINITY, 0.0));
    invalid(&err(b), "a", "position");
    let mut b = SystemBuilder::new();
    b.add_body(Body::new("a").velocity(0.0, 0.0, f64::NEG_INFINITY));
    invalid(&err(b), "a", "velocity");
}

#[test]
fn non_finite_gravity() {
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, f64::NAN]);
    b.add_body(Body::new("a"));
    invalid(&err(b), "gravity", "gravity");
}

#[test]
fn distance_length_zero_negative_nan() {
    for len in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let (mut b, h) = one_body();
        b.add_joint(Joint::distance(
            "rod",
            BodyRef::Ground,
            [0.0, 0.0],
            h,
            [0.0, 0.0],
            len,
        ));
        invalid(&err(b), "rod", "length");
    }
}

#[test]
fn prismatic_zero_axis() {
    let (mut b, h) = one_body();
    b.add_joint(Joint::prismatic(
        "slide",
        BodyRef::Ground,
        [0.0, 0.0],
        h,
        [0.0, 0.0],
        [0.0, 0.0],
        0.0,
    ));
    invalid(&err(b), "slide", "axis length");
}

#[test]
fn non_finite_joint_and_force_parameters() {
    let (mut b, h) = one_body();
    b.add_joint(Joint::revolute(
        "pin",
        BodyRef::Ground,
        [f64::NAN, 0.0],
        h,
        [0.0, 0.0],
    ));
    invalid(&err(b), "pin", "point_a");
    let (mut b, h) = one_body();
    b.add_joint(Joint::angle_driver(
        "drv",
        BodyRef::Ground,
        h,
        TimeFunction::Polynomial {
            coeffs: vec![0.0, f64::INFINITY],
        },
    ));
    invalid(&err(b), "drv", "f");
    let (mut b, h) = one_body();
    b.add_force(Force::force(
        "push",
        h,
        [0.0, 0.0],
        TimeFunction::constant(1.0),
        TimeFunction::constant(f64::NAN),
    ));
    invalid(&err(b), "push", "fy");
}

#[test]
fn joint_to_the_same_body() {
    let (mut b, h) = one_body();
    b.add_joint(Joint::revolute("pin", h, [0.0, 0.0], h, [0.5, 0.0]));
    assert_eq!(
        err(b),
        ModelError::SameBody {
            joint: "pin".into(),
            body: "link".into()
        }
    );
}

#[test]
fn ground_to_ground_joint() {
    let (mut b, _) = one_body();
    b.add_joint(Joint::weld(
        "fix",
        BodyRef::Ground,
        [0.0, 0.0],
        BodyRef::Ground,
        [1.0, 0.0],
        0.0,
    ));
    assert_eq!(
        err(b),
        ModelError::SameBody {
            joint: "fix".into(),
            body: "ground".into()
        }
    );
    // an absolute constraint on ground, a spring from ground to ground, a load on ground
    let (mut b, _) = one_body();
    b.add_joint(Joint::absolute(
        "abs",
        BodyRef::Ground,
        [0.0, 0.0],
        mbd_model::Coordinate::X,
        0.0,
    ));
    assert!(matches!(err(b), ModelError::SameBody { joint, .. } if joint == "abs"));
    let (mut b, _) = one_body();
    b.add_force(Force::spring_damper(
        "s",
        BodyRef::Ground,
        [0.0, 0.0],
        BodyRef::Ground,
        [1.0, 0.0],
        1.0,
        0.0,
        1.0,
    ));
    assert!(matches!(err(b), ModelError::SameBody { joint, .. } if joint == "s"));
    let (mut b, _) = one_body();
    b.add_force(Force::torque(
        "tq",
        BodyRef::Ground,
        TimeFunction::constant(1.0),
    ));
    assert!(matches!(err(b), ModelError::SameBody { joint, .. } if joint == "tq"));
}

#[test]
fn redundant_four_bar() {
    // A fifth pin between the crank tip and the coupler duplicates pin "A".
    let mut mf = four_bar().unwrap().to_model_file();
    mf.joints.push(mbd_model::JointSpec::Revolute(
        mbd_model::joints::RevoluteSpec {
            name: "A_again".into(),
            body_a: "crank".into(),
            point_a: [0.2, 0.0],
            body_b: "coupler".into(),
            point_b: [-0.6, 0.0],
        },
    ));
    // accepted by default, the two dependent rows listed with the joints they combine
    let sys = mf.build().unwrap();
    let red = sys.redundant_equations();
    assert_eq!(red.len(), 2, "{red:?}");
    assert_eq!(sys.dof(), 1);
    for e in red {
        assert!(e.equation.starts_with("A_again."), "{e:?}");
        assert!(e.joints.contains(&"A".to_string()), "{e:?}");
    }
    // refused on request
    mf.redundant_constraints = RedundantConstraints::Reject;
    match mf.build().unwrap_err() {
        ModelError::Redundant { equation, joints } => {
            assert!(equation.starts_with("A_again."), "{equation}");
            assert!(joints.contains(&"A_again".to_string()), "{joints:?}");
            assert!(joints.contains(&"A".to_string()), "{joints:?}");
        }
        e => panic!("{e:?}"),
    }
}

/// Above `SPARSE_RANK_THRESHOLD` equations the rank check is sparse: a long chain builds, and
/// a duplicated pin at its far end is found and named, as the dense check does on a short one
/// (listed by default, an error on request).
#[test]
fn sparse_rank_check_accepts_chains_and_names_a_duplicate_pin() {
    let links = mbd_model::SPARSE_RANK_THRESHOLD / 2 + 20;
    for n in [10, links] {
        let sys = models::n_link_chain(n).unwrap();
        assert_eq!(sys.n_constraints(), 2 * n);
        let mut mf = sys.to_model_file();
        let last = mf.joints.last().cloned().unwrap();
        let mbd_model::JointSpec::Revolute(r) = last else {
            panic!("the chain ends with a revolute joint")
        };
        mf.joints.push(mbd_model::JointSpec::Revolute(RevoluteSpec {
            name: "pin_again".into(),
            ..r.clone()
        }));
        let sys = mf.build().unwrap();
        let red = sys.redundant_equations();
        assert_eq!(red.len(), 2, "{n} links: {red:?}");
        assert_eq!(sys.dof(), n, "{n} links");
        for e in red {
            assert!(
                e.joints.contains(&"pin_again".to_string()),
                "{n} links: {e:?}"
            );
            assert!(e.joints.contains(&r.name), "{n} links: {e:?}");
        }
        mf.redundant_constraints = RedundantConstraints::Reject;
        match mf.build().unwrap_err() {
            ModelError::Redundant { equation, joints } => {
                assert!(
                    equation.starts_with("pin_again.") || equation.starts_with(&r.name),
                    "{n} links: {equation}"
                );
                assert!(
                    joints.contains(&"pin_again".to_string()),
                    "{n} links: {joints:?}"
                );
                assert!(joints.contains(&r.name), "{n} links: {joints:?}");
            }
            e => panic!("{n} links: {e:?}"),
        }
    }
}

#[test]
fn redundant_double_pin() {
    let mut mf = pendulum(1.0, 1.0, 0.2, 9.81).unwrap().to_model_file();
    let extra = match &mf.joints[0] {
        mbd_model::JointSpec::Revolute(r) => mbd_model::JointSpec::Revolute(RevoluteSpec {
            name: "pin_again".into(),
            ..r.clone()
        }),
        _ => unreachable!(),
    };
    mf.joints.push(extra);
    let sys = mf.build().unwrap();
    let names: Vec<&str> = sys
        .redundant_equations()
        .iter()
        .map(|e| e.equation.as_str())
        .collect();
    assert_eq!(names, ["pin_again.x", "pin_again.y"]);
    assert_eq!(sys.redundant_equations()[0].joints, ["pin_again", "pin1"]);
    mf.redundant_constraints = RedundantConstraints::Reject;
    assert_eq!(
        mf.build().unwrap_err(),
        ModelError::Redundant {
            equation: "pin_again.x".into(),
            joints: vec!["pin_again".into(), "pin1".into()],
        }
    );
}

#[test]
fn unreachable_initial_state() {
    // One point 1 m from (0, 0) and 1 m from (5, 0): no such point exists.
    let mut b = SystemBuilder::new();
    let h = b.add_body(Body::new("p").position(2.5, 1.0, 0.0));
    b.add_joint(Joint::distance(
        "left",
        BodyRef::Ground,
        [0.0, 0.0],
        h,
        [0.0, 0.0],
        1.0,
    ));
    b.add_joint(Joint::distance(
        "right",
        BodyRef::Ground,
        [5.0, 0.0],
        h,
        [0.0, 0.0],
        1.0,
    ));
    let sys = b.build().unwrap();
    match mbd_solve::consistent_state(&sys, 0.0).unwrap_err() {
        mbd_solve::SolveError::Newton {
            residual, context, ..
        } => {
            assert!(residual > 1.0, "{residual}");
            assert!(
                context.contains("largest residual in left")
                    || context.contains("largest residual in right"),
                "{context}"
            );
        }
        e => panic!("{e:?}"),
    }
}

#[test]
fn negative_stiffness_and_damping() {
    let (mut b, h) = one_body();
    b.add_force(Force::spring_damper(
        "s",
        BodyRef::Ground,
        [0.0, 0.0],
        h,
        [0.0, 0.0],
        -1.0,
        0.0,
        1.0,
    ));
    invalid(&err(b), "s", "stiffness");
    let (mut b, h) = one_body();
    b.add_force(Force::spring_damper(
        "s",
        BodyRef::Ground,
        [0.0, 0.0],
        h,
        [0.0, 0.0],
        1.0,
        -0.1,
        1.0,
    ));
    invalid(&err(b), "s", "damping");
    let (mut b, h) = one_body();
    b.add_force(Force::spring_damper(
        "s",
        BodyRef::Ground,
        [0.0, 0.0],
        h,
        [0.0, 0.0],
        1.0,
        0.0,
        -1.0,
    ));
    invalid(&err(b), "s", "rest_length");
    let (mut b, h) = one_body();
    b.add_force(Force::rotary_spring_damper(
        "r",
        BodyRef::Ground,
        h,
        -2.0,
        0.0,
        0.0,
    ));
    invalid(&err(b), "r", "stiffness");
    let (mut b, h) = one_body();
    b.add_force(Force::rotary_spring_damper(
        "r",
        BodyRef::Ground,
        h,
        2.0,
        f64::NAN,
        0.0,
    ));
    invalid(&err(b), "r", "damping");
}

#[test]
fn empty_model() {
    assert_eq!(SystemBuilder::new().build().unwrap_err(), ModelError::Empty);
    assert_eq!(models::n_link_chain(0).unwrap_err(), ModelError::Empty);
    assert_eq!(
        System::from_json(r#"{"bodies": []}"#).unwrap_err(),
        ModelError::Empty
    );
}

#[test]
fn slider_crank_parameters_are_checked() {
    use mbd_model::models::{slider_crank_with, SliderCrankParams};
    let base = SliderCrankParams::default();
    let cases = [
        (
            SliderCrankParams {
                crank: -0.1,
                ..base
            },
            "crank",
        ),
        (
            SliderCrankParams {
                rod: f64::NAN,
                ..base
            },
            "rod",
        ),
        // the rod cannot reach the slider's line: |r sin(angle)| > l
        (
            SliderCrankParams {
                crank: 1.0,
                rod: 0.5,
                angle: 1.2,
                ..base
            },
            "rod",
        ),
        (
            SliderCrankParams {
                angle: f64::INFINITY,
                ..base
            },
            "angle",
        ),
        (
            SliderCrankParams {
                speed: f64::NAN,
                ..base
            },
            "speed",
        ),
    ];
    for (p, name) in cases {
        match slider_crank_with(&p) {
            Err(ModelError::InvalidParameter { parameter, .. }) => assert_eq!(parameter, name),
            other => panic!("{p:?}: expected InvalidParameter({name}), got {other:?}"),
        }
    }
    let driven = slider_crank_with(&SliderCrankParams {
        driven: true,
        ..base
    })
    .unwrap();
    assert!(driven.is_rheonomic());
    assert_eq!(driven.dof(), 0);
    assert_eq!(slider_crank_with(&base).unwrap().dof(), 1);
}

/// A ramp or smooth step whose end is not after its start is refused, naming the element and
/// the time function.
#[test]
fn a_step_that_ends_before_it_starts() {
    for f in [
        TimeFunction::ramp(1.0, 1.0, 0.0, 2.0),
        TimeFunction::smooth_step(2.0, 1.0, 0.0, 2.0),
    ] {
        let (mut b, h) = one_body();
        b.add_force(Force::torque("motor", h, f));
        let e = err(b).to_string();
        assert!(
            e.contains("motor") && e.contains("'torque'") && e.contains("t1 must be after"),
            "{e}"
        );
    }
}
