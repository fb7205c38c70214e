//! Force elements on spatial bodies through the public run loop: a spring oscillator and a
//! body spun up by a constant body-frame torque against their exact solutions, the energy
//! balance of a damped spatial spring pendulum, and every spatial solver's agreement on it.

use mbd::model::spatial::{
    Axes, Marker, SpatialBody, SpatialBodyRef, SpatialForce, SpatialInertia, SpatialJoint,
    SpatialJointKind,
};
use mbd::model::{SystemBuilder, TimeFunction};
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

fn end_state(sys: &System, spec: &str, t_end: f64, h: f64) -> State {
    let mut sim = Simulation::new(sys.clone(), spec).unwrap();
    sim.run(RunConfig::new(t_end, h)).unwrap();
    sim.state().clone()
}

fn cst(v: [f64; 3]) -> [TimeFunction; 3] {
    v.map(TimeFunction::constant)
}

/// A 2 kg ball on a zero-length spring (k = 50 N/m) from its centre to the origin, spinning,
/// no gravity: its centre moves as `x0 cos(w t) + v0 / w sin(w t)`, `w = 5 rad/s`.
#[test]
fn a_ball_on_a_spring_oscillates_at_sqrt_k_over_m() {
    let (x0, v0, w): ([f64; 3], [f64; 3], f64) = ([0.3, -0.2, 0.1], [0.1, 0.4, -0.2], 5.0);
    let mut b = SystemBuilder::new();
    let ball = b.add_spatial_body(
        SpatialBody::new(
            "ball",
            SpatialInertia::principal(2.0, [0.1, 0.2, 0.25]).unwrap(),
        )
        .position(x0)
        .velocity(v0)
        .angular_velocity([0.5, 0.0, 3.0]),
    );
    b.add_spatial_force(SpatialForce::spring_damper(
        "spring",
        SpatialBodyRef::Ground,
        [0.0; 3],
        ball,
        [0.0; 3],
        50.0,
        0.0,
        0.0,
    ));
    let sys = b.build().unwrap();
    let t = 1.0;
    let exact: Vec<f64> = (0..3)
        .map(|c| x0[c] * (w * t).cos() + v0[c] / w * (w * t).sin())
        .collect();
    for spec in SOLVERS {
        let s = end_state(&sys, spec, t, 1e-3);
        let err = (0..3)
            .map(|c| (s.q[c] - exact[c]).abs())
            .fold(0.0, f64::max);
        eprintln!("{spec}: centre off by {err:.2e}");
        // fourth-order solvers at w h = 5e-3: about 1e-12; symplectic (2,2) likewise
        assert!(err < 1e-9, "{spec}: {err:e}");
    }
}

/// A constant body-frame torque `tau` about the third principal axis of a body at rest turns
/// it by `tau t^2 / (2 J_3)` about that axis, whatever the other moments.
#[test]
fn a_body_torque_spins_a_body_up_about_its_axis() {
    let (tau, j3): (f64, f64) = (0.6, 0.4);
    let mut b = SystemBuilder::new();
    let body = b.add_spatial_body(SpatialBody::new(
        "rotor",
        SpatialInertia::principal(3.0, [0.25, 0.3, j3]).unwrap(),
    ));
    b.add_spatial_force(SpatialForce::torque(
        "motor",
        body,
        cst([0.0, 0.0, tau]),
        Axes::Body,
    ));
    let sys = b.build().unwrap();
    assert!(!sys.is_conservative());
    let t = 1.5;
    let phi = tau * t * t / (2.0 * j3);
    for spec in SOLVERS {
        let s = end_state(&sys, spec, t, 1e-3);
        // d_1 = (cos phi, sin phi, 0)
        let err = (s.q[3] - phi.cos())
            .abs()
            .max((s.q[4] - phi.sin()).abs())
            .max(s.q[5].abs());
        let omega = sys
            .spatial_body_angular_velocity(0, s.q.as_slice(), s.v.as_slice())
            .unwrap();
        let werr = (omega[2] - tau / j3 * t).abs();
        eprintln!("{spec}: director off by {err:.2e}, spin off by {werr:.2e}");
        assert!(err < 1e-9 && werr < 1e-9, "{spec}: {err:e}, {werr:e}");
    }
}

/// A rod hung by a ball joint, pulled sideways by a spring-damper to a wall point and pushed
/// by a body-frame force: the energy balance `H - H0 - W_ext + E_diss` closes to 1e-8 of
/// `max |H|` with symplectic (2,2) and projected RK4 while `H` changes by more than 1%, and
/// the solvers agree on the end state.
#[test]
fn a_damped_spatial_pendulum_closes_its_energy_balance() {
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let rod = b.add_spatial_body(
        SpatialBody::new(
            "rod",
            SpatialInertia::principal(1.0, [0.05, 0.05, 0.002]).unwrap(),
        )
        .position([0.0, 0.0, -0.4])
        .velocity([0.5, 0.2, 0.0])
        .angular_velocity([0.5, -1.25, 2.0]),
    );
    let ball = SpatialJoint::new(
        SpatialJointKind::Spherical,
        Marker::at([0.0; 3]),
        Marker::at([0.0, 0.0, 0.4]),
    )
    .unwrap();
    b.add_spatial_joint("pivot", SpatialBodyRef::Ground, rod, ball);
    b.add_spatial_force(SpatialForce::spring_damper(
        "strut",
        SpatialBodyRef::Ground,
        [0.5, 0.3, -0.3],
        rod,
        [0.0, 0.0, -0.4],
        40.0,
        0.8,
        0.3,
    ));
    b.add_spatial_force(SpatialForce::force(
        "thruster",
        rod,
        [0.0, 0.0, -0.4],
        [
            TimeFunction::constant(0.3),
            TimeFunction::constant(0.0),
            TimeFunction::constant(0.0),
        ],
        Axes::Body,
    ));
    let sys = b.build().unwrap();
    let (t_end, h) = (2.0, 1e-3);
    let mut ends = Vec::new();
    for spec in ["symplectic:2", "rk4-projected"] {
        let mut eb = EnergyBalance::new(&sys).unwrap();
        let mut sim = Simulation::new(sys.clone(), spec).unwrap();
        let (q0, v0) = (sim.state().q.clone(), sim.state().v.clone());
        let h0 = sys.energy(q0.as_slice(), v0.as_slice());
        sim.run_observed(RunConfig::new(t_end, h), &mut eb).unwrap();
        let s = sim.state().clone();
        let change = (sys.energy(s.q.as_slice(), s.v.as_slice()) - h0).abs();
        let rel = eb.max_residual() / eb.max_energy();
        eprintln!(
            "{spec}: balance residual {rel:.2e} of max|H|, H changed by {:.2e}, dissipated {:.3e} J, external {:.3e} J",
            change / eb.max_energy(),
            eb.dissipated(),
            eb.external_work()
        );
        assert!(rel < 1e-8, "{spec}: {rel:e}");
        assert!(change > 1e-2 * eb.max_energy(), "{spec}: {change:e}");
        assert!(eb.dissipated() > 0.0 && eb.external_work().abs() > 1e-3);
        ends.push(s);
    }
    let reference = end_state(&sys, "rk4", t_end, 2.5e-4);
    for (spec, s) in ["symplectic:2", "rk4-projected"].iter().zip(&ends) {
        let d = (&s.q - &reference.q).amax();
        eprintln!("{spec}: off the fine RK4 run by {d:.2e}");
        assert!(d < 1e-8, "{spec}: {d:e}");
    }
    for spec in ["index1:dopri5", "tangent:rk4", "firefly-gauss:polish"] {
        let d = (&end_state(&sys, spec, t_end, h).q - &reference.q).amax();
        eprintln!("{spec}: off the fine RK4 run by {d:.2e}");
        assert!(d < 1e-8, "{spec}: {d:e}");
    }
}
