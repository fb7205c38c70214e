//! Drivers: a slide driver moves a slider on its guide along a prescribed smooth step, and its
//! reaction is the force that does it.

use mbd::model::joints::SlideDriver;
use mbd::model::{Body, BodyRef, Joint, SystemBuilder, TimeFunction};
use mbd::prelude::*;
use mbd::solve::{JointReaction, ReactionSolver};

/// A 2 kg slider on a horizontal guide, driven from x = 0.1 m to 0.5 m over [0.2, 1.2] s by a
/// smooth step: with every solver that runs the model (fixed steps of 1e-3 s), the slider is at
/// the step's value at the end and mid-way; the driver's force at the end of a run through
/// the transition's middle is m x'' (no gravity along the guide).
#[test]
fn a_slide_driver_moves_a_slider_along_its_step() {
    let f = TimeFunction::smooth_step(0.2, 1.2, 0.1, 0.5);
    let build = || {
        let mut b = SystemBuilder::new();
        b.set_gravity([0.0, -9.81]);
        let slider = b.add_body(
            Body::new("slider")
                .mass(2.0)
                .inertia(0.01)
                .position(0.1, 0.0, 0.0),
        );
        b.add_joint(Joint::prismatic(
            "guide",
            BodyRef::Ground,
            [0.0, 0.0],
            slider,
            [0.0, 0.0],
            [1.0, 0.0],
            0.0,
        ));
        b.add_joint(Joint::new(
            "actuator",
            SlideDriver {
                a: BodyRef::Ground,
                pa: [0.0, 0.0],
                b: slider.into(),
                pb: [0.0, 0.0],
                axis: [2.0, 0.0],
                f: f.clone(),
            },
        ));
        b.build().unwrap()
    };
    let mut ran = 0;
    for (_, v) in mbd::registry().variants() {
        if v.spec.starts_with("index1") {
            continue;
        }
        for t_end in [0.7, 1.5] {
            let mut sim = match Simulation::new(build(), v.spec) {
                Ok(s) => s,
                // a model without a degree of freedom is refused by the optimisation solver
                Err(e) => {
                    assert!(
                        e.to_string().contains("no degree of freedom"),
                        "{}: {e}",
                        v.spec
                    );
                    continue;
                }
            };
            sim.run(RunConfig::new(t_end, 1e-3)).unwrap();
            let x = sim.state().q[0];
            assert!(
                (x - f.eval(t_end)[0]).abs() < 1e-10,
                "{} t = {t_end}: {x}",
                v.spec
            );
            if t_end == 0.7 {
                let sys = sim.system();
                let mut rs = ReactionSolver::new(sys).unwrap();
                let mut out = vec![JointReaction::default(); 2];
                rs.compute(sys, sim.state(), &mut out).unwrap();
                // the actuator's force on the slider along x: m x''(t)
                let want = 2.0 * f.eval(t_end)[2];
                assert!(
                    (out[1].force[0] - want).abs() < 1e-9 * want.abs().max(1.0),
                    "{} {}",
                    out[1].force[0],
                    want
                );
            }
            ran += 1;
        }
    }
    assert!(ran >= 8, "{ran}");
}

/// A slider on the x axis pulled by a distance driver from the ground point (0, 1): the
/// distance grows along a smooth step from 1.25 to 2 m, so the slider is at
/// `x = sqrt(f^2 - 1)`, to 1e-10 with projected RK4 and symplectic (2,2); a prescribed length
/// that is not positive at the start is refused naming the joint.
#[test]
fn a_distance_driver_pulls_a_slider() {
    use mbd::model::joints::DistanceDriver;
    let f = TimeFunction::smooth_step(0.1, 0.9, 1.25, 2.0);
    let build = |f: TimeFunction| {
        let mut b = SystemBuilder::new();
        let slider = b.add_body(
            Body::new("slider")
                .mass(1.0)
                .inertia(0.01)
                .position(0.75, 0.0, 0.0),
        );
        b.add_joint(Joint::prismatic(
            "guide",
            BodyRef::Ground,
            [0.0, 0.0],
            slider,
            [0.0, 0.0],
            [1.0, 0.0],
            0.0,
        ));
        b.add_joint(Joint::new(
            "winch",
            DistanceDriver {
                a: BodyRef::Ground,
                pa: [0.0, 1.0],
                b: slider.into(),
                pb: [0.0, 0.0],
                f,
            },
        ));
        b.build()
    };
    for spec in ["rk4-projected", "symplectic:2"] {
        for t_end in [0.5, 1.2] {
            let mut sim = Simulation::new(build(f.clone()).unwrap(), spec).unwrap();
            sim.run(RunConfig::new(t_end, 1e-3)).unwrap();
            let l = f.eval(t_end)[0];
            let x = sim.state().q[0];
            assert!(
                (x - (l * l - 1.0).sqrt()).abs() < 1e-10,
                "{spec} t = {t_end}: {x}"
            );
        }
    }
    let e = build(TimeFunction::constant(0.0)).unwrap_err().to_string();
    assert!(e.contains("winch") && e.contains("f(0)"), "{e}");
}
