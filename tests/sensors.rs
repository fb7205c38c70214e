//! Sensors (`mbd::model::Sensor`, `mbd::solve::SensorSolver`): a point's velocity and
//! acceleration against finite differences of its position along a run, a prismatic joint's
//! slide against the slider's coordinate, and model files that name them.

use mbd::model::{models, ModelFile, SensorSpec};
use mbd::prelude::*;
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{run, Flow, JointReaction, NoObserver, ReactionSolver, SensorSolver};

/// The slider-crank with a point sensor at the crank pin's end of the rod and joint sensors on
/// the crank pin and the slide.
fn slider_crank_with_sensors() -> System {
    let mut file = models::slider_crank().unwrap().to_model_file();
    file.sensors.push(SensorSpec::Point {
        name: "rod_end".into(),
        body: "rod".into(),
        point: [-0.25, 0.0],
    });
    file.sensors.push(SensorSpec::Joint {
        name: "crank_angle".into(),
        joint: "crank_pin".into(),
    });
    file.sensors.push(SensorSpec::Joint {
        name: "stroke".into(),
        joint: "slide".into(),
    });
    file.build().unwrap()
}

/// Along a projected RK4 run (h = 1e-4, every step sampled), the point sensor's velocity and
/// acceleration are the central differences of its position and velocity (to 1e-5 of their
/// largest values; the differences' own error is about 4e-6); the joint sensors give the crank's angle and rate and the slider's x and x-velocity.
#[test]
fn sensor_values_are_consistent_along_a_run() {
    let sys = slider_crank_with_sensors();
    assert_eq!(
        SensorSolver::columns(&sys),
        [
            "rod_end.x",
            "rod_end.y",
            "rod_end.vx",
            "rod_end.vy",
            "rod_end.ax",
            "rod_end.ay",
            "crank_angle.angle",
            "crank_angle.rate",
            "stroke.angle",
            "stroke.rate",
            "stroke.s",
            "stroke.ds",
        ]
    );
    let mut ss = SensorSolver::new(&sys).unwrap();
    let mut rows: Vec<(State, Vec<f64>)> = Vec::new();
    let mut keep = |sys: &System, st: &State, step: usize| -> Result<Flow, SolveError> {
        let _ = step;
        let mut out = Vec::new();
        ss.evaluate(sys, st, &mut out)?;
        rows.push((st.clone(), out));
        Ok(Flow::Continue)
    };
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Rk4::new(&sys, Rk4Options::projected()).unwrap();
    run(&mut rk, &sys, &mut s, RunConfig::new(0.5, 1e-4), &mut keep).unwrap();
    let crank = sys.body_handle("crank").unwrap().index();
    let slider = sys.body_handle("slider").unwrap().index();
    let (mut dv, mut da, mut vmax, mut amax) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for k in 1..rows.len() - 1 {
        let (prev, cur, next) = (&rows[k - 1], &rows[k], &rows[k + 1]);
        let dt = next.0.t - prev.0.t;
        for c in 0..2 {
            let v_fd = (next.1[c] - prev.1[c]) / dt;
            let a_fd = (next.1[2 + c] - prev.1[2 + c]) / dt;
            dv = dv.max((v_fd - cur.1[2 + c]).abs());
            da = da.max((a_fd - cur.1[4 + c]).abs());
            vmax = vmax.max(cur.1[2 + c].abs());
            amax = amax.max(cur.1[4 + c].abs());
        }
        let (q, v) = (&cur.0.q, &cur.0.v);
        assert_eq!(cur.1[6], q[3 * crank + 2]);
        assert_eq!(cur.1[7], v[3 * crank + 2]);
        // the slide runs along x from the origin: its stroke is the slider's x
        assert!((cur.1[10] - q[3 * slider]).abs() < 1e-12, "{}", cur.1[10]);
        assert!((cur.1[11] - v[3 * slider]).abs() < 1e-12, "{}", cur.1[11]);
    }
    eprintln!("velocity {dv:.2e} of {vmax:.2e}, acceleration {da:.2e} of {amax:.2e}");
    assert!(dv < 1e-5 * vmax && da < 1e-5 * amax, "{dv:e} {da:e}");
}

/// Sensors round-trip through the file format; an unknown joint or body and a duplicate name
/// are errors naming the sensor.
#[test]
fn model_files_name_sensors() {
    let sys = slider_crank_with_sensors();
    let text = sys.to_model_file().to_toml().unwrap();
    assert!(
        text.contains("[[sensors]]") && text.contains("type = \"joint\""),
        "{text}"
    );
    let back = ModelFile::from_toml(&text).unwrap().build().unwrap();
    assert_eq!(back.sensors(), sys.sensors());
    let bad = text.replace("joint = \"slide\"", "joint = \"slyde\"");
    let e = build_error(&bad);
    assert!(
        e.contains("sensor 'stroke'") && e.contains("'slyde'"),
        "{e}"
    );
    let bad = text.replace("body = \"rod\"", "body = \"rood\"");
    let e = build_error(&bad);
    assert!(
        e.contains("sensor 'rod_end'") && e.contains("'rood'"),
        "{e}"
    );
    let bad = text.replace("name = \"stroke\"", "name = \"rod_end\"");
    let e = build_error(&bad);
    assert!(e.contains("sensor") && e.contains("rod_end"), "{e}");
}

/// A reaction sensor's columns are its joint's `JointReaction` (global force, moment, force in
/// the body's axes), bit for bit; energy sensors give `T`, `V`, `H` of the model, and per body
/// a kinetic energy summing to the model's and gravity potentials summing to `V` (no springs
/// in the manipulator); both kinds round-trip through model files.
#[test]
fn reaction_and_energy_sensors() {
    let arm = models::manipulator().unwrap();
    let joint = arm.joints()[1].name.clone();
    let mut file = arm.to_model_file();
    file.sensors.push(SensorSpec::Reaction {
        name: "elbow_load".into(),
        joint: joint.clone(),
    });
    file.sensors.push(SensorSpec::Energy {
        name: "all".into(),
        body: None,
    });
    let bodies: Vec<String> = file.bodies.iter().map(|b| b.name.clone()).collect();
    for b in &bodies {
        file.sensors.push(SensorSpec::Energy {
            name: format!("e_{b}"),
            body: Some(b.clone()),
        });
    }
    let sys = file.build().unwrap();
    let back = ModelFile::from_toml(&sys.to_model_file().to_toml().unwrap())
        .unwrap()
        .build()
        .unwrap();
    assert_eq!(back.sensors(), sys.sensors());
    let columns = SensorSolver::columns(&sys);
    assert_eq!(
        columns[..8],
        [
            "elbow_load.fx",
            "elbow_load.fy",
            "elbow_load.mz",
            "elbow_load.fx_body",
            "elbow_load.fy_body",
            "all.kinetic",
            "all.potential",
            "all.total",
        ]
    );
    assert_eq!(columns.len(), 8 + 3 * bodies.len());

    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Rk4::new(&sys, Rk4Options::projected()).unwrap();
    run(
        &mut rk,
        &sys,
        &mut s,
        RunConfig::new(0.3, 1e-3),
        &mut NoObserver,
    )
    .unwrap();
    let mut out = Vec::new();
    SensorSolver::new(&sys)
        .unwrap()
        .evaluate(&sys, &s, &mut out)
        .unwrap();
    let mut loads = vec![JointReaction::default(); sys.joints().len()];
    ReactionSolver::new(&sys)
        .unwrap()
        .compute(&sys, &s, &mut loads)
        .unwrap();
    let j = sys.joints().iter().position(|x| x.name == joint).unwrap();
    let r = loads[j];
    assert_eq!(
        out[..5],
        [
            r.force[0],
            r.force[1],
            r.moment,
            r.local_force[0],
            r.local_force[1]
        ]
    );
    assert!(r.force.iter().any(|f| f.abs() > 1e-3), "{r:?}");
    let (q, v) = (s.q.as_slice(), s.v.as_slice());
    let (t, u) = (sys.kinetic(v), sys.potential(q));
    assert_eq!(out[5..8], [t, u, t + u]);
    assert_eq!(out[7], sys.energy(q, v));
    let per_body = &out[8..];
    let t_sum: f64 = per_body.chunks(3).map(|c| c[0]).sum();
    let u_sum: f64 = per_body.chunks(3).map(|c| c[1]).sum();
    assert!(t > 1e-3, "the arm moves: T = {t:e}");
    assert!((t_sum - t).abs() <= 1e-13 * t.abs(), "{t_sum:e} vs {t:e}");
    assert!(
        (u_sum - u).abs() <= 1e-13 * u.abs().max(1.0),
        "{u_sum:e} vs {u:e}"
    );
    assert!(per_body.chunks(3).all(|c| c[2] == c[0] + c[1]));

    // an unknown body in an energy sensor and an unknown joint in a reaction sensor
    let text = sys.to_model_file().to_toml().unwrap();
    let bad = text.replace(&format!("joint = \"{joint}\""), "joint = \"elbo\"");
    let e = build_error(&bad);
    assert!(
        e.contains("sensor 'elbow_load'") && e.contains("'elbo'"),
        "{e}"
    );
    let bad = text.replace(&format!("body = \"{}\"", bodies[0]), "body = \"nobody\"");
    let e = build_error(&bad);
    assert!(e.contains("sensor") && e.contains("'nobody'"), "{e}");
}

/// The build error of a model file's text.
fn build_error(text: &str) -> String {
    ModelFile::from_toml(text)
        .unwrap()
        .build()
        .unwrap_err()
        .to_string()
}

/// Planar and spatial elements mixed up in a model file are errors that say which is which: a
/// joint sensor on a spatial joint, a planar joint naming a spatial body, and a spatial joint
/// naming an unknown body (its name quoted once).
#[test]
fn mixing_planar_and_spatial_elements_is_an_error_that_says_so() {
    let spatial = include_str!("../examples/models/spherical_pendulum.toml");
    let with = |extra: &str| format!("{spatial}\n{extra}");
    let e = build_error(&with(
        "[[sensors]]\ntype = \"joint\"\nname = \"swing\"\njoint = \"rod\"\n",
    ));
    assert!(
        e.contains("sensor 'swing'")
            && e.contains("'rod' is a spatial joint")
            && e.contains("reaction sensor"),
        "{e}"
    );
    let e = build_error(&with(
        "[[joints]]\ntype = \"revolute\"\nname = \"pin\"\nbody_a = \"ground\"\n\
         point_a = [0.0, 0.0]\nbody_b = \"bob\"\npoint_b = [0.0, 0.0]\n",
    ));
    assert!(
        e.contains("'bob' is a spatial body") && e.contains("[[spatial_joints]]"),
        "{e}"
    );
    let e = build_error(&spatial.replace("body_b = \"bob\"", "body_b = \"bub\""));
    assert!(e.contains("'bub'") && !e.contains("''"), "{e}");
}
