//! The mechanism's scales and the build-time check of negligible inertias.

use mbd_model::models::pendulum;
use mbd_model::{
    Body, BodyRef, Joint, ModelError, SystemBuilder, MAX_INERTIA_RATIO, MAX_MASS_RATIO,
};

fn pinned_rod(mass: f64, inertia: f64, half: f64) -> SystemBuilder {
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let rod = b.add_body(
        Body::new("rod")
            .mass(mass)
            .inertia(inertia)
            .position(half, 0.0, 0.0),
    );
    b.add_joint(Joint::revolute(
        "pin",
        BodyRef::Ground,
        [0.0, 0.0],
        rod,
        [-half, 0.0],
    ));
    b
}

#[test]
fn a_near_massless_rotation_is_rejected_at_build_naming_body_and_joint() {
    let e = pinned_rod(1.0, 1e-14, 0.5)
        .build()
        .expect_err("inertia 1e-14 against m r^2 = 0.25 must be rejected");
    match &e {
        ModelError::NegligibleInertia {
            body, joint, ratio, ..
        } => {
            assert_eq!(body, "rod");
            assert_eq!(joint, "pin");
            assert!((ratio - 0.25e14).abs() < 1e-3 * 0.25e14, "{ratio}");
        }
        other => panic!("expected NegligibleInertia, got {other:?}"),
    }
    let msg = e.to_string();
    assert!(msg.contains("'rod'") && msg.contains("'pin'") && msg.contains("inertia"));
}

#[test]
fn badly_scaled_but_well_posed_bodies_pass() {
    // the scale of a watch mechanism: 1 cm lever arms, 1e-7 kg m^2, 40 g
    pinned_rod(0.04, 1e-7, 0.01)
        .build()
        .expect("m r^2 / J = 40");
    // a heavy rod of tiny inertia still inside the limit
    let j = 1e3 * 0.25 / (0.5 * MAX_INERTIA_RATIO);
    pinned_rod(1e3, j, 0.5).build().expect("ratio 0.5 * limit");
    assert!(
        pinned_rod(1e3, j / 4.0, 0.5).build().is_err(),
        "ratio 2x limit"
    );
}

#[test]
fn length_scale_and_equation_scales() {
    let sys = pendulum(1.0, 2.0, 0.1, 9.81).unwrap();
    // lever arm l / 2 = 1 is the largest (radius of gyration l / sqrt 12 = 0.577)
    assert!((sys.length_scale() - 1.0).abs() < 1e-15);
    assert_eq!(sys.equation_scale(0), 1.0);
    let small = pinned_rod(0.04, 1e-7, 0.01).build().unwrap();
    assert!((small.length_scale() - 0.01).abs() < 1e-15);
    assert!((small.equation_scale(1) - 0.01).abs() < 1e-15);

    // a weld's angle equation is measured in radians whatever the size
    let mut b = SystemBuilder::new();
    let a = b.add_body(Body::new("a").position(0.005, 0.0, 0.0));
    b.add_joint(Joint::weld(
        "w",
        BodyRef::Ground,
        [0.0, 0.0],
        a,
        [-0.005, 0.0],
        0.0,
    ));
    let sys = b.build().unwrap();
    assert!((sys.equation_scale(0) - sys.length_scale()).abs() < 1e-15);
    let all = sys.equation_scales();
    assert_eq!(all.len(), sys.n_constraints());
    assert!((0..all.len()).all(|r| all[r] == sys.equation_scale(r)));
    assert_eq!(sys.equation_scale(2), 1.0);
}

/// Two rods pinned end to end, of masses `m1` and `m2` (inertias m l^2 / 12, l = 1).
fn two_rods(m1: f64, m2: f64) -> SystemBuilder {
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let r1 = b.add_body(
        Body::new("link1")
            .mass(m1)
            .inertia(m1 / 12.0)
            .position(0.5, 0.0, 0.0),
    );
    let r2 = b.add_body(
        Body::new("link2")
            .mass(m2)
            .inertia(m2 / 12.0)
            .position(1.5, 0.0, 0.0),
    );
    b.add_joint(Joint::revolute(
        "shoulder",
        BodyRef::Ground,
        [0.0, 0.0],
        r1,
        [-0.5, 0.0],
    ));
    b.add_joint(Joint::revolute("elbow", r1, [0.5, 0.0], r2, [-0.5, 0.0]));
    b
}

/// A body whose mass is negligible against another's is refused at build, naming both (a
/// 1e-300 kg link beside a 2 kg one failed later, at the consistent initial state, with
/// "singular projection matrix ... check the initial positions"); a gram on a tonne and ratios
/// up to the limit build; the message's limit is the constant's.
#[test]
fn a_negligible_mass_is_rejected_at_build_naming_both_bodies() {
    let e = two_rods(1e-300, 2.0).build().expect_err("mass ratio 2e300");
    match &e {
        ModelError::MassRatio {
            light,
            heavy,
            ratio,
            ..
        } => {
            assert_eq!((light.as_str(), heavy.as_str()), ("link1", "link2"));
            assert!((ratio / 2e300 - 1.0).abs() < 1e-12, "{ratio}");
        }
        other => panic!("expected MassRatio, got {other:?}"),
    }
    let msg = e.to_string();
    assert!(
        msg.contains("'link1'") && msg.contains("'link2'") && msg.contains("limit 1e12"),
        "{msg}"
    );
    assert_eq!(MAX_MASS_RATIO, 1e12);
    two_rods(1e-3, 1e3).build().expect("a gram on a tonne");
    two_rods(1.0, 0.5 * MAX_MASS_RATIO)
        .build()
        .expect("half the limit");
    assert!(two_rods(1.0, 2.0 * MAX_MASS_RATIO).build().is_err());
}
