//! Sensors (`mbd::model::Sensor`, `mbd::solve::SensorSolver`): a point's velocity and
//! acceleration against finite differences of its position along a run, a prismatic joint's
//! slide against the slider's coordinate, and model files that name them.

use mbd::model::{models, ModelFile, SensorSpec};
use mbd::prelude::*;
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{run, Flow, SensorSolver};

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
    let e = ModelFile::from_toml(&bad)
        .unwrap()
        .build()
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("sensor 'stroke'") && e.contains("'slyde'"),
        "{e}"
    );
    let bad = text.replace("body = \"rod\"", "body = \"rood\"");
    let e = ModelFile::from_toml(&bad)
        .unwrap()
        .build()
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("sensor 'rod_end'") && e.contains("'rood'"),
        "{e}"
    );
    let bad = text.replace("name = \"stroke\"", "name = \"rod_end\"");
    let e = ModelFile::from_toml(&bad)
        .unwrap()
        .build()
        .unwrap_err()
        .to_string();
    assert!(e.contains("sensor") && e.contains("rod_end"), "{e}");
}
