use super::*;
use crate::{Body, BodyRef};

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// Joints written with the placed side second (ground as `body_b`, a prismatic joint whose
/// axis rides on the unplaced body) are placed backwards: the guess satisfies every constraint
/// and its velocity form, and the joint coordinates read back as given.
#[test]
fn joints_are_placed_from_either_side() {
    let mut b = SystemBuilder::new();
    let arm = b.add_body(Body::new("arm").rod(1.0, 1.0).position(3.0, -2.0, 0.3));
    let slider = b.add_body(Body::new("slider").position(-1.0, 4.0, 2.0));
    let pivot = b.add_joint(Joint::revolute(
        "pivot",
        arm,
        [0.5, 0.1],
        BodyRef::Ground,
        [0.2, -0.3],
    ));
    // the axis is carried by the slider (body a); the arm (body b) is placed first
    let guide = b.add_joint(Joint::prismatic(
        "guide",
        slider,
        [0.1, 0.2],
        arm,
        [-0.5, 0.0],
        [1.0, 1.0],
        0.4,
    ));
    b.set_joint_initial(pivot, JointInitial::coordinate(-0.7).with_rate(1.3));
    b.set_joint_initial(guide, JointInitial::coordinate(0.25).with_rate(-0.6));
    let sys = b.build().unwrap();
    let (q, v) = sys.initial_guess();
    let (q, v) = (q.as_slice(), v.as_slice());
    assert_eq!(sys.assembled_bodies(), vec![true, true]);
    let mut phi = vec![0.0; sys.n_constraints()];
    sys.phi(q, 0.0, &mut phi);
    assert!(max_abs(&phi) < 1e-14, "{phi:?}");
    sys.phi_dot(q, v, 0.0, &mut phi);
    assert!(max_abs(&phi) < 1e-14, "{phi:?}");
    // pivot: theta_ground - theta_arm = -0.7, so the arm is at 0.7, turning at -1.3
    assert!((q[2] - 0.7).abs() < 1e-15 && (v[2] + 1.3).abs() < 1e-15);
    let [s, ds] = sys.joint_coordinates(1, q, v).unwrap().1.unwrap();
    assert!(
        (s - 0.25).abs() < 1e-14 && (ds + 0.6).abs() < 1e-14,
        "{s} {ds}"
    );
}

/// Without initial joint coordinates the guess is the stored state and nothing is assembled.
#[test]
fn without_joint_coordinates_nothing_moves() {
    let sys = crate::models::slider_crank().unwrap();
    let (q, v) = sys.initial_guess();
    let (q0, v0) = sys.stored_state();
    assert_eq!((q.as_slice(), v.as_slice()), (q0.as_slice(), v0.as_slice()));
    assert!(sys.assembled_bodies().iter().all(|&p| !p));
}
