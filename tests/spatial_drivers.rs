//! Spatial drivers (`SpatialJointKind::SlideDriver`, `DistanceDriver`): the driven coordinate
//! follows its motion with every solver that runs spatial bodies, the driver's force is what
//! Newton's law needs, the energy balance books the driver's work, and model files name them.

use mbd::model::spatial::{
    Marker, SpatialBody, SpatialBodyRef, SpatialInertia, SpatialJoint, SpatialJointKind,
};
use mbd::model::{ModelFile, SystemBuilder, TimeFunction};
use mbd::prelude::*;
use mbd::Simulation;
use mbd_analysis::EnergyBalance;

const SOLVERS: [&str; 6] = [
    "rk4",
    "rk4-projected",
    "index1:dopri5",
    "tangent:rk4",
    "symplectic:2",
    "firefly-gauss:polish",
];

/// `s(t) = 0.1 sin(2 t)`.
fn wave() -> TimeFunction {
    TimeFunction::Harmonic {
        offset: 0.0,
        amplitude: 0.1,
        omega: 2.0,
        phase: 0.0,
    }
}

/// A 2 kg block on a vertical cylindrical joint to ground (along global z; it may turn about
/// it), its height driven by a slide driver `s(t)`, under gravity.
fn driven_block() -> System {
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let block = b.add_spatial_body(SpatialBody::new(
        "block",
        SpatialInertia::principal(2.0, [0.1, 0.12, 0.15]).unwrap(),
    ));
    let at = |p: [f64; 3]| Marker::at(p);
    b.add_spatial_joint(
        "guide",
        SpatialBodyRef::Ground,
        block,
        SpatialJoint::new(SpatialJointKind::Cylindrical, at([0.0; 3]), at([0.0; 3])).unwrap(),
    );
    b.add_spatial_driver(
        "lift",
        SpatialBodyRef::Ground,
        block,
        SpatialJoint::new(SpatialJointKind::SlideDriver, at([0.0; 3]), at([0.0; 3])).unwrap(),
        wave(),
    );
    b.build().unwrap()
}

/// The block's height is `s(t)` at t = 1.3 s to 1e-10 with every spatial solver; the driver's
/// multiplier is the force Newton's law needs, `m (s'' + g)` (sign: `M a = Q - Phi_q^T
/// lambda` with `Phi_z = 1`), to 1e-8; the energy balance closes to 1e-8 of the largest energy
/// while `H` changes.
#[test]
fn a_slide_driver_moves_a_block_along_its_guide() {
    let sys = driven_block();
    assert!(sys.is_rheonomic() && sys.dof() == 1);
    // a slide driver subtracts its motion: its Jacobian does not depend on time
    assert!(!sys.jacobian_depends_on_time());
    let t = 1.3;
    let [s, _, ds2] = wave().eval(t);
    for spec in SOLVERS {
        let mut sim = Simulation::new(sys.clone(), spec).unwrap();
        sim.run(RunConfig::new(t, 1e-3)).unwrap();
        let st = sim.state();
        let err = (st.q[2] - s).abs();
        eprintln!("{spec}: height off by {err:.1e}");
        assert!(err < 1e-10, "{spec}: {err:e}");
        let mut os = mbd::solve::OutputSolve::new(&sys).unwrap();
        let (a, lambda) = os.at(&sys, st).unwrap();
        assert!((a[2] - ds2).abs() < 1e-8, "{spec}: a_z {} vs {ds2}", a[2]);
        let row = sys.n_constraints() - 1;
        let expect = -2.0 * (ds2 + 9.81);
        assert!(
            (lambda[row] - expect).abs() < 1e-8,
            "{spec}: lambda {} vs {expect}",
            lambda[row]
        );
    }
    let mut eb = EnergyBalance::new(&sys).unwrap();
    let mut sim = Simulation::new(sys.clone(), "symplectic:2").unwrap();
    sim.run_observed(RunConfig::new(2.0, 1e-3), &mut eb)
        .unwrap();
    let rel = eb.max_residual() / eb.max_energy();
    eprintln!("energy balance residual {rel:.1e} of the largest energy");
    assert!(rel < 1e-8, "{rel:e}");
}

/// A ball pushed out along a line by a distance driver `L(t) = 0.5 + 0.2 t^2` from a ground
/// pin (no gravity, no other joint): it stays on the line and `|x| = L(t)` to 1e-10.
#[test]
fn a_distance_driver_pushes_a_ball_along_a_line() {
    let mut b = SystemBuilder::new();
    let ball = b.add_spatial_body(
        SpatialBody::new(
            "ball",
            SpatialInertia::principal(1.0, [0.1, 0.1, 0.1]).unwrap(),
        )
        .position([0.3, 0.4, 0.0]),
    );
    b.add_spatial_driver(
        "ram",
        SpatialBodyRef::Ground,
        ball,
        SpatialJoint::new(
            SpatialJointKind::DistanceDriver,
            Marker::at([0.0; 3]),
            Marker::at([0.0; 3]),
        )
        .unwrap(),
        TimeFunction::Polynomial {
            coeffs: vec![0.5, 0.0, 0.2],
        },
    );
    let sys = b.build().unwrap();
    let t = 1.0;
    for spec in [
        "rk4-projected",
        "index1:dopri5",
        "symplectic:2",
        "tangent:rk4",
    ] {
        let mut sim = Simulation::new(sys.clone(), spec).unwrap();
        sim.run(RunConfig::new(t, 1e-3)).unwrap();
        let q = &sim.state().q;
        let r = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        let off_line = (q[0] * 0.8 - q[1] * 0.6).abs().max(q[2].abs());
        eprintln!(
            "{spec}: |x| - L {:.1e}, off the line {off_line:.1e}",
            r - 0.7
        );
        assert!((r - 0.7).abs() < 1e-10 && off_line < 1e-10, "{spec}");
    }
}

/// Drivers round-trip through model files; a driver without a motion and a motion on another
/// kind are errors naming the joint.
#[test]
fn spatial_drivers_in_model_files() {
    let sys = driven_block();
    let text = sys.to_model_file().to_toml().unwrap();
    assert!(text.contains("type = \"slide_driver\""), "{text}");
    let back = ModelFile::from_toml(&text).unwrap().build().unwrap();
    assert_eq!(back.spatial_joints(), sys.spatial_joints());
    let mut no_motion = sys.to_model_file();
    no_motion.spatial_joints[1].motion = None;
    let e = no_motion.build().unwrap_err().to_string();
    assert!(
        e.contains("'lift'") && e.contains("needs its motion"),
        "{e}"
    );
    let mut b = SystemBuilder::new();
    let body = b.add_spatial_body(SpatialBody::new(
        "b",
        SpatialInertia::principal(1.0, [0.1, 0.1, 0.1]).unwrap(),
    ));
    let ball = SpatialJoint::new(
        SpatialJointKind::Spherical,
        Marker::at([0.0; 3]),
        Marker::at([0.0; 3]),
    )
    .unwrap();
    b.add_spatial_driver("pin", SpatialBodyRef::Ground, body, ball, wave());
    let e = b.build().unwrap_err().to_string();
    assert!(
        e.contains("'pin'") && e.contains("only the driver kinds"),
        "{e}"
    );
    let mut b = SystemBuilder::new();
    let body = b.add_spatial_body(SpatialBody::new(
        "b",
        SpatialInertia::principal(1.0, [0.1, 0.1, 0.1]).unwrap(),
    ));
    let slide = SpatialJoint::new(
        SpatialJointKind::SlideDriver,
        Marker::at([0.0; 3]),
        Marker::at([0.0; 3]),
    )
    .unwrap();
    b.add_spatial_joint("lift", SpatialBodyRef::Ground, body, slide);
    let e = b.build().unwrap_err().to_string();
    assert!(
        e.contains("'lift'") && e.contains("needs its motion"),
        "{e}"
    );
}
