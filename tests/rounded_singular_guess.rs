//! A model file whose initial guess sits on a singular configuration but slightly off the
//! constraints (a parallelogram four-bar drawn flat with the coupler's height rounded to
//! 1e-5): `Phi_q M^-1 Phi_q^T` is singular at the guess, so the projection's factorisation
//! refuses its first correction. The consistent state takes that correction from the truncated
//! pseudo-inverse instead and ends on the regular configuration next to the guess (the cranks
//! tilted by the rounding), from which the solvers run as from any other; a guess whose
//! solution is the singular configuration itself (the same four-bar with its crank driven flat)
//! is still refused.

mod common;
use common::{max_phi_at, max_phi_dot_at};
use mbd::prelude::*;

/// The parallelogram four-bar (cranks 0.4 m, coupler 1 m, ground pivots 1 m apart), drawn flat
/// with the coupler `lift` above the cranks' tips; crank 1 turns at 3 rad/s, or, with
/// `driven`, is driven at pi rad/s from angle 0.
fn four_bar(lift: f64, driven: bool) -> String {
    let mut s = format!(
        r#"gravity = [0.0, -9.81]
[[bodies]]
name = "c1"
mass = 0.4
inertia = 0.005333333333333335
position = [0.2, 0.0, 0.0]
velocity = [0.0, 0.6, 3.0]
[[bodies]]
name = "cp"
mass = 1.0
inertia = 0.08333333333333333
position = [0.9, {lift:e}, 0.0]
[[bodies]]
name = "c2"
mass = 0.4
inertia = 0.005333333333333335
position = [1.2, 0.0, 0.0]
"#
    );
    for (name, a, pa, b, pb) in [
        ("o1", "ground", "[0.0, 0.0]", "c1", "[-0.2, 0.0]"),
        ("p1", "c1", "[0.2, 0.0]", "cp", "[-0.5, 0.0]"),
        ("p2", "cp", "[0.5, 0.0]", "c2", "[0.2, 0.0]"),
        ("o2", "ground", "[1.0, 0.0]", "c2", "[-0.2, 0.0]"),
    ] {
        s += &format!(
            "[[joints]]\ntype = \"revolute\"\nname = \"{name}\"\nbody_a = \"{a}\"\n\
             point_a = {pa}\nbody_b = \"{b}\"\npoint_b = {pb}\n"
        );
    }
    if driven {
        s += "[[joints]]\ntype = \"angle_driver\"\nname = \"motor\"\nbody_a = \"ground\"\n\
              body_b = \"c1\"\nf = { kind = \"polynomial\", coeffs = [0.0, 3.14159265358979] }\n";
    }
    s
}

#[test]
fn a_rounded_guess_on_a_singular_configuration_projects_onto_the_regular_one_beside_it() {
    for lift in [1e-3, 1e-5, 3e-6] {
        let sys = System::from_toml(&four_bar(lift, false)).unwrap();
        let start = State::consistent(&sys, 0.0).unwrap_or_else(|e| panic!("lift {lift}: {e}"));
        let (phi, phid) = (max_phi_at(&sys, &start), max_phi_dot_at(&sys, &start));
        assert!(
            phi < 1e-14 && phid < 1e-13,
            "lift {lift}: {phi:.1e} {phid:.1e}"
        );
        // the cranks tilt and the coupler comes down to their tips (the smallest mass-weighted
        // change shares the lift): the cranks parallel, the coupler level (the parallelogram
        // branch)
        let (c1, cp, c2) = (start.q[2], start.q[5], start.q[8]);
        assert!(
            c1 > 0.5 * lift / 0.4 && c1 < lift / 0.4 && (c2 - c1).abs() < 1e-9,
            "lift {lift}: cranks {c1:.6e} {c2:.6e}"
        );
        assert!(cp.abs() < 1e-9, "lift {lift}: coupler {cp:.1e}");
        // the solvers that keep the constraints run from it, the coupler level throughout
        for spec in [
            "rk4-projected",
            "tangent:rk4",
            "symplectic:1",
            "symplectic:2",
            "firefly-gauss:polish",
        ] {
            let t_end = if spec.starts_with("firefly") {
                0.1
            } else {
                0.9
            };
            let mut sim = Simulation::new(sys.clone(), spec).unwrap();
            let mut rec = Recorder::new();
            let stats = sim
                .run_observed(RunConfig::new(t_end, 1e-3), &mut rec)
                .unwrap_or_else(|e| panic!("lift {lift}, {spec}: {e}"));
            assert_eq!(stats.stop, StopReason::ReachedEnd);
            let coupler = rec.q.iter().fold(0.0f64, |m, q| m.max(q[5].abs()));
            let phi = max_phi_at(&sys, sim.state());
            assert!(
                coupler < 1e-8 && phi < 1e-10,
                "lift {lift}, {spec}: coupler turned {coupler:.1e}, |Phi| {phi:.1e}"
            );
        }
    }
}

#[test]
fn a_guess_whose_solution_is_the_singular_configuration_is_still_refused() {
    // driven flat at t = 0, the constraints hold only on the singular configuration: the
    // projection would end next to it, where no factorisation can start
    for lift in [1e-3, 1e-5] {
        let sys = System::from_toml(&four_bar(lift, true)).unwrap();
        let e = State::consistent(&sys, 0.0).unwrap_err().to_string();
        assert!(e.contains("singular projection matrix"), "lift {lift}: {e}");
    }
    // the same guess exactly on the constraints is the singular start the solvers pass
    let sys = System::from_toml(&four_bar(0.0, true)).unwrap();
    assert_eq!(sys.singular_start_equations().len(), 1);
    assert!(State::consistent(&sys, 0.0).is_ok());
}
