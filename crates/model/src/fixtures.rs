//! Test fixtures: the systems and points the derivative tests of this crate and of the
//! solver crates above it (feature `fixtures`, for their tests only) compare passes on.

use crate::{Body, BodyRef, Coordinate, Force, Joint, System, SystemBuilder, TimeFunction};

/// Every joint kind (revolute, prismatic, weld, distance, absolute x / y / angle, angle
/// driver, slide driver, distance driver) on five bodies: the fixture of the unit tests that check derivatives element by
/// element.
pub fn every_joint_kind() -> System {
    let mut b = SystemBuilder::new();
    let b1 = b.add_body(Body::new("b1").rod(1.0, 1.0).position(0.3, -0.2, 0.4));
    let b2 = b.add_body(Body::new("b2").rod(2.0, 0.7).position(1.1, 0.5, -0.9));
    let b3 = b.add_body(Body::new("b3").rod(0.5, 0.4).position(-0.6, 1.3, 2.1));
    let b4 = b.add_body(Body::new("b4").rod(0.8, 0.9).position(0.2, 2.0, -0.3));
    let b5 = b.add_body(Body::new("b5").rod(0.6, 0.5).position(-1.0, -1.0, 0.8));
    b.add_joint(Joint::revolute(
        "r",
        BodyRef::Ground,
        [0.1, 0.2],
        b1,
        [-0.5, 0.1],
    ));
    b.add_joint(Joint::distance("d", b1, [0.5, 0.0], b2, [-0.3, 0.2], 0.8));
    b.add_joint(Joint::prismatic(
        "p",
        b2,
        [0.1, 0.0],
        b3,
        [0.0, 0.1],
        [1.0, 0.5],
        0.2,
    ));
    b.add_joint(Joint::weld("w", b3, [0.2, 0.0], b4, [-0.4, 0.1], 0.3));
    b.add_joint(Joint::absolute("ay", b4, [0.3, 0.0], Coordinate::Y, 1.0));
    b.add_joint(Joint::absolute("ax", b5, [0.2, -0.1], Coordinate::X, -1.0));
    b.add_joint(Joint::absolute(
        "aa",
        b5,
        [0.0, 0.0],
        Coordinate::Angle,
        0.8,
    ));
    b.add_joint(Joint::angle_driver(
        "drv",
        BodyRef::Ground,
        b2,
        TimeFunction::linear(0.1, 2.0),
    ));
    b.add_joint(Joint::new(
        "slide",
        crate::joints::SlideDriver {
            a: b1.into(),
            pa: [0.2, -0.1],
            b: b5.into(),
            pb: [-0.3, 0.2],
            axis: [0.6, 0.8],
            f: TimeFunction::linear(0.4, -0.7),
        },
    ));
    b.add_joint(Joint::new(
        "winch",
        crate::joints::DistanceDriver {
            a: b3.into(),
            pa: [0.1, 0.1],
            b: b5.into(),
            pb: [0.2, -0.2],
            f: TimeFunction::linear(1.5, 0.3),
        },
    ));
    b.build().unwrap()
}

/// Two free bodies (no joints), a spring between them and one to the ground, under gravity: a
/// potential with non-zero Hessian and higher derivatives, for the unit tests of the potential's
/// derivatives.
pub fn two_springs() -> System {
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let r = b.add_body(Body::new("r").rod(1.0, 1.0).position(0.4, -0.3, 0.7));
    let p = b.add_body(Body::new("p").rod(0.5, 0.6).position(1.2, 0.2, -0.4));
    b.add_force(Force::spring_damper(
        "s1",
        r,
        [0.5, 0.0],
        p,
        [-0.3, 0.0],
        20.0,
        0.0,
        0.4,
    ));
    b.add_force(Force::spring_damper(
        "s2",
        BodyRef::Ground,
        [0.0, 0.5],
        r,
        [-0.5, 0.0],
        7.0,
        0.0,
        0.2,
    ));
    b.build().expect("the two-spring fixture is valid")
}

/// The fixtures of the unit tests that compare derivative passes with each other: every joint
/// kind, the manipulator and [`two_springs`].
pub fn derivative_test_systems() -> [System; 3] {
    [
        every_joint_kind(),
        crate::models::manipulator().expect("the manipulator model is valid"),
        two_springs(),
    ]
}

/// A generic configuration and direction for `n` coordinates (no symmetry, no zero entries).
pub fn generic_point(n: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..n).map(|i| 0.3 + 0.2 * (i as f64 * 0.9).sin()).collect();
    let v = (0..n).map(|i| 0.5 * (i as f64 * 1.7 + 0.3).cos()).collect();
    (q, v)
}

pub use mbd_jet::fixtures::TwoDirections;

/// Every kind of spatial potential on a spatial model: two bars on ball joints (the upper to
/// ground) with gravity, a spring between the bars (rest length 0.2 m), one from the lower bar
/// to ground (rest length 0), a free point mass on a spring from the lower bar, and a constant
/// force in global axes on the lower bar. The fixture of the tests that check the spatial
/// force elements' series and their gradients.
pub fn spatial_springs() -> System {
    use crate::spatial::{
        Axes, Marker, SpatialBody, SpatialForce, SpatialInertia, SpatialJoint, SpatialJointKind,
    };
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let i1 = SpatialInertia::principal(1.0, [0.05, 0.06, 0.012]).expect("valid inertia");
    let i2 = SpatialInertia::principal(0.7, [0.03, 0.025, 0.01]).expect("valid inertia");
    let upper = b.add_spatial_body(
        SpatialBody::new("upper", i1)
            .position([0.1, 0.0, -0.3])
            .angular_velocity([0.4, -0.8, 1.2]),
    );
    let lower = b.add_spatial_body(
        SpatialBody::new("lower", i2)
            .position([0.15, 0.2, -0.8])
            .angular_velocity([-0.3, 0.5, 0.9]),
    );
    let ball = |a: [f64; 3], c: [f64; 3]| {
        SpatialJoint::new(SpatialJointKind::Spherical, Marker::at(a), Marker::at(c))
            .expect("valid joint")
    };
    let g = crate::spatial::SpatialBodyRef::Ground;
    b.add_spatial_joint("shoulder", g, upper, ball([0.0; 3], [-0.1, 0.0, 0.3]));
    b.add_spatial_joint(
        "elbow",
        upper,
        lower,
        ball([0.05, 0.1, -0.2], [0.0, -0.1, 0.3]),
    );
    let bob = b.add_spatial_point_mass("bob", 0.3, [0.4, 0.1, -1.2], [0.2, -0.1, 0.3]);
    b.add_spatial_force(SpatialForce::spring_damper(
        "between",
        upper,
        [0.1, 0.05, 0.0],
        lower,
        [-0.05, 0.1, 0.1],
        30.0,
        0.0,
        0.2,
    ));
    b.add_spatial_force(SpatialForce::spring_damper(
        "anchor",
        lower,
        [0.0, 0.0, -0.3],
        g,
        [0.3, -0.2, -1.0],
        12.0,
        0.0,
        0.0,
    ));
    b.add_spatial_force(SpatialForce::spring_damper(
        "bob_spring",
        lower,
        [0.05, 0.0, -0.2],
        bob,
        [0.0; 3],
        20.0,
        0.0,
        0.35,
    ));
    b.add_spatial_force(SpatialForce::force(
        "push",
        lower,
        [0.02, 0.0, -0.1],
        [1.5, -0.7, 0.4].map(TimeFunction::constant),
        Axes::Global,
    ));
    b.build().expect("the spatial-springs fixture is valid")
}

#[cfg(test)]
mod tests {
    /// The fixture holds every joint kind, the slide driver among them, and goes through the
    /// file format unchanged: the same equations at a generic point (to rounding).
    #[test]
    fn every_joint_kind_round_trips() {
        let sys = super::every_joint_kind();
        let toml = sys.to_model_file().to_toml().unwrap();
        assert!(toml.contains("type = \"slide_driver\""), "{toml}");
        assert!(toml.contains("type = \"distance_driver\""), "{toml}");
        let back = crate::ModelFile::from_toml(&toml).unwrap().build().unwrap();
        let (q, _) = super::generic_point(sys.n_coords());
        let (mut a, mut b) = (
            vec![0.0; sys.n_constraints()],
            vec![0.0; back.n_constraints()],
        );
        sys.phi(&q, 0.3, &mut a);
        back.phi(&q, 0.3, &mut b);
        // (a normalised axis normalised again moves by rounding)
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() <= 1e-15, "{x} {y}");
        }
    }
}
