//! Drivers: a slide driver moves a slider on its guide along a prescribed smooth step, and its
//! reaction is the force that does it.

use mbd::model::joints::SlideDriver;
use mbd::model::{Body, BodyRef, Joint, SystemBuilder, TimeFunction};
use mbd::prelude::*;
use mbd::solve::{JointReaction, ReactionSolver};

/// The registry's solvers that take fixed steps with the projection or their own constraint
/// handling (the unstabilised index-1 ones drift off a driven guide).
fn fixed_step_specs() -> Vec<&'static str> {
    mbd::registry()
        .variants()
        .map(|(_, v)| v.spec)
        .filter(|spec| !spec.starts_with("index1"))
        .collect()
}

/// A simulation of `sys` with `spec`, or `None` where the solver refuses a model without a
/// degree of freedom (the optimisation solver; any other refusal fails the test).
fn simulation(sys: mbd::model::System, spec: &str) -> Option<Simulation> {
    match Simulation::new(sys, spec) {
        Ok(s) => Some(s),
        Err(e) => {
            assert!(
                e.to_string().contains("no degree of freedom"),
                "{spec}: {e}"
            );
            None
        }
    }
}

/// A slider of mass `m` (inertia 0.01) at `x0` on a prismatic guide along the global x axis,
/// under `gravity`, moved by the driver `driver(slider)` builds.
fn slider_on_guide(
    m: f64,
    x0: f64,
    gravity: [f64; 2],
    driver: impl FnOnce(mbd::model::BodyHandle) -> Joint,
) -> Result<mbd::model::System, mbd::model::ModelError> {
    let mut b = SystemBuilder::new();
    b.set_gravity(gravity);
    let slider = b.add_body(
        Body::new("slider")
            .mass(m)
            .inertia(0.01)
            .position(x0, 0.0, 0.0),
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
    b.add_joint(driver(slider));
    b.build()
}

/// A 2 kg slider on a horizontal guide, driven from x = 0.1 m to 0.5 m over [0.2, 1.2] s by a
/// smooth step: with every solver that runs the model (fixed steps of 1e-3 s), the slider is at
/// the step's value at the end and mid-way; the driver's force at the end of a run through
/// the transition's middle is m x'' (no gravity along the guide).
#[test]
fn a_slide_driver_moves_a_slider_along_its_step() {
    let f = TimeFunction::smooth_step(0.2, 1.2, 0.1, 0.5);
    let build = || {
        slider_on_guide(2.0, 0.1, [0.0, -9.81], |slider| {
            Joint::new(
                "actuator",
                SlideDriver {
                    a: BodyRef::Ground,
                    pa: [0.0, 0.0],
                    b: slider.into(),
                    pb: [0.0, 0.0],
                    axis: [2.0, 0.0],
                    f: f.clone(),
                },
            )
        })
        .unwrap()
    };
    let mut ran = 0;
    for spec in fixed_step_specs() {
        for t_end in [0.7, 1.5] {
            let Some(mut sim) = simulation(build(), spec) else {
                continue;
            };
            sim.run(RunConfig::new(t_end, 1e-3)).unwrap();
            let x = sim.state().q[0];
            assert!(
                (x - f.eval(t_end)[0]).abs() < 1e-10,
                "{spec} t = {t_end}: {x}"
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
        slider_on_guide(1.0, 0.75, [0.0, 0.0], |slider| {
            Joint::new(
                "winch",
                DistanceDriver {
                    a: BodyRef::Ground,
                    pa: [0.0, 1.0],
                    b: slider.into(),
                    pb: [0.0, 0.0],
                    f,
                },
            )
        })
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

/// A slider driven along its guide by a tabulated motion read from a CSV file beside the model
/// (natural cubic spline through samples of x = 0.3 sin(2 t) every 0.05 s): every solver that
/// runs the model keeps the slider on the interpolant to 1e-10, the interpolant is within the
/// spline's error of the sampled function, and the driver's force is m times the spline's
/// second derivative (which enters the acceleration constraint).
#[test]
fn a_slide_driver_follows_a_tabulated_motion_from_a_file() {
    let dir = std::env::temp_dir().join(format!("mbd-table-driver-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut csv = String::from("# lift motion\ntime,x\n");
    for i in 0..=40 {
        let t = 0.05 * i as f64;
        csv.push_str(&format!("{t},{}\n", 0.3 * (2.0 * t).sin()));
    }
    std::fs::write(dir.join("lift.csv"), csv).unwrap();
    let model = r#"
gravity = [0.0, -9.81]
[[bodies]]
name = "slider"
mass = 2.0
inertia = 0.01
position = [0.0, 0.0, 0.0]
[[joints]]
type = "prismatic"
name = "guide"
body_a = "ground"
body_b = "slider"
axis = [1.0, 0.0]
[[joints]]
type = "slide_driver"
name = "actuator"
body_a = "ground"
body_b = "slider"
axis = [1.0, 0.0]
f = { kind = "table", file = "lift.csv", column = "x" }
"#;
    std::fs::write(dir.join("lift.toml"), model).unwrap();
    let sys = mbd::model::System::from_path(dir.join("lift.toml")).unwrap();
    let f = match &sys.joints()[1].kind {
        mbd::model::JointKind::SlideDriver(d) => d.f.clone(),
        other => panic!("{other:?}"),
    };
    // the spline's value error for 0.3 sin(2t) sampled every 0.05 s is of order
    // 0.3 * 2^4 * 0.05^4 / 384 ~ 8e-8 (and larger near the ends, where sin'' != 0)
    for t in [0.52, 1.013, 1.4] {
        let e = (f.eval(t)[0] - 0.3 * (2.0 * t).sin()).abs();
        assert!(e < 1e-6, "t = {t}: {e}");
    }
    let mut ran = 0;
    for spec in fixed_step_specs() {
        let Some(mut sim) = simulation(sys.clone(), spec) else {
            continue;
        };
        let t_end = 1.013;
        sim.run(RunConfig::new(t_end, 1e-3)).unwrap();
        let x = sim.state().q[0];
        let want = f.eval(sim.state().t)[0];
        assert!((x - want).abs() < 1e-10, "{spec}: {x} {want}");
        let s = sim.system();
        let mut rs = ReactionSolver::new(s).unwrap();
        let mut out = vec![JointReaction::default(); 2];
        rs.compute(s, sim.state(), &mut out).unwrap();
        let want = 2.0 * f.eval(sim.state().t)[2];
        assert!(
            (out[1].force[0] - want).abs() < 1e-8 * want.abs().max(1.0),
            "{spec}: {} {want}",
            out[1].force[0]
        );
        ran += 1;
    }
    assert!(ran >= 4, "{ran}");
    std::fs::remove_dir_all(&dir).unwrap();
}
