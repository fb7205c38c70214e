//! Sensors on spatial bodies: a point's velocity and acceleration against central differences
//! of its position along a run, the ball joint's point standing still, the angular velocity
//! against the bodies' own, the spatial reaction and energy sensors against the model's
//! functions, and model files that name them.

use mbd::model::models::heavy_top;
use mbd::model::{ModelFile, SensorSpec};
use mbd::prelude::*;
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{run, Flow, SensorSolver};

/// The heavy top (solid) with a point sensor at an off-axis point, one at the tip (the ball
/// joint's point), the angular velocity, the tip's reaction and the top's energy.
fn top_with_sensors() -> System {
    let mut file = heavy_top([0.3, 0.3, 0.1], 0.3, 20.0)
        .unwrap()
        .to_model_file();
    file.sensors.push(SensorSpec::SpatialPoint {
        name: "rim".into(),
        body: "top".into(),
        point: [0.2, -0.1, 0.15],
    });
    file.sensors.push(SensorSpec::SpatialPoint {
        name: "tip".into(),
        body: "top".into(),
        point: [0.0, 0.0, -0.5],
    });
    file.sensors.push(SensorSpec::AngularVelocity {
        name: "spin".into(),
        body: "top".into(),
    });
    file.sensors.push(SensorSpec::Reaction {
        name: "ball".into(),
        joint: "tip".into(),
    });
    file.sensors.push(SensorSpec::Energy {
        name: "e".into(),
        body: Some("top".into()),
    });
    file.build().unwrap()
}

/// Along a projected RK4 run (h = 1e-4, 0.2 s): the rim point's velocity and acceleration are
/// the central differences of its position and velocity (to 1e-5 of their largest values),
/// the tip stands still (1e-10), the angular velocity's global components turn the rim point
/// (`v_P = v_x + omega x (P - x)` to 1e-10), the reaction sensor gives
/// `System::spatial_joint_reactions` bit for bit, and the energy sensor the model's `T`, `V`.
#[test]
fn spatial_sensor_values_are_consistent_along_a_run() {
    let sys = top_with_sensors();
    let cols = SensorSolver::columns(&sys);
    assert_eq!(cols.len(), 9 + 9 + 6 + 6 + 3);
    assert_eq!(&cols[..3], ["rim.x", "rim.y", "rim.z"]);
    assert_eq!(
        cols[18..24],
        [
            "spin.wx",
            "spin.wy",
            "spin.wz",
            "spin.wx_body",
            "spin.wy_body",
            "spin.wz_body"
        ]
    );
    assert_eq!(
        cols[24..30],
        ["ball.fx", "ball.fy", "ball.fz", "ball.mx", "ball.my", "ball.mz"]
    );
    let mut ss = SensorSolver::new(&sys).unwrap();
    let mut rows: Vec<(State, Vec<f64>)> = Vec::new();
    let mut keep = |sys: &System, st: &State, _: usize| -> Result<Flow, SolveError> {
        let mut out = Vec::new();
        ss.evaluate(sys, st, &mut out)?;
        rows.push((st.clone(), out));
        Ok(Flow::Continue)
    };
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Rk4::new(&sys, Rk4Options::projected()).unwrap();
    run(&mut rk, &sys, &mut s, RunConfig::new(0.2, 1e-4), &mut keep).unwrap();
    let (mut dv, mut da, mut vmax, mut amax, mut tip, mut turn) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for k in 1..rows.len() - 1 {
        let (prev, cur, next) = (&rows[k - 1], &rows[k], &rows[k + 1]);
        let dt = next.0.t - prev.0.t;
        let o = &cur.1;
        for c in 0..3 {
            dv = dv.max(((next.1[c] - prev.1[c]) / dt - o[3 + c]).abs());
            da = da.max(((next.1[3 + c] - prev.1[3 + c]) / dt - o[6 + c]).abs());
            vmax = vmax.max(o[3 + c].abs());
            amax = amax.max(o[6 + c].abs());
            tip = tip
                .max(o[9 + c].abs())
                .max(o[12 + c].abs())
                .max(o[15 + c].abs());
        }
        // v_P = v_x + omega x (P - x)
        let (q, v) = (cur.0.q.as_slice(), cur.0.v.as_slice());
        let w = nalgebra::Vector3::new(o[18], o[19], o[20]);
        let r = nalgebra::Vector3::new(o[0] - q[0], o[1] - q[1], o[2] - q[2]);
        let vp = nalgebra::Vector3::new(v[0], v[1], v[2]) + w.cross(&r);
        turn = turn.max((vp - nalgebra::Vector3::new(o[3], o[4], o[5])).amax());
        if k % 500 == 0 {
            let lambda = {
                let mut os = mbd::solve::OutputSolve::new(&sys).unwrap();
                os.at(&sys, &cur.0).unwrap().1.to_vec()
            };
            let r = sys.spatial_joint_reactions(q, cur.0.t, &lambda).unwrap()[0];
            assert_eq!(o[24..27], r.force);
            assert_eq!(o[27..30], r.moment);
            let (t, u) = (sys.kinetic(v), sys.potential(q));
            assert!((o[30] - t).abs() < 1e-12 * t && (o[31] - u).abs() < 1e-12 * u.abs());
        }
    }
    eprintln!("rim velocity {dv:.2e} of {vmax:.2e}, acceleration {da:.2e} of {amax:.2e}; tip {tip:.1e}; omega x r {turn:.1e}");
    assert!(dv < 1e-5 * vmax && da < 1e-5 * amax, "{dv:e} {da:e}");
    assert!(tip < 1e-10 && turn < 1e-10, "{tip:e} {turn:e}");
}

/// The sensors round-trip through the file format; an unknown spatial body is an error naming
/// the sensor.
#[test]
fn spatial_sensors_in_model_files() {
    let sys = top_with_sensors();
    let text = sys.to_model_file().to_toml().unwrap();
    assert!(
        text.contains("type = \"spatial_point\"") && text.contains("type = \"angular_velocity\""),
        "{text}"
    );
    let back = ModelFile::from_toml(&text).unwrap().build().unwrap();
    assert_eq!(back.sensors(), sys.sensors());
    let bad = text.replace(
        "body = \"top\"\npoint = [0.2",
        "body = \"tap\"\npoint = [0.2",
    );
    let e = ModelFile::from_toml(&bad)
        .and_then(|f| f.build())
        .unwrap_err()
        .to_string();
    assert!(e.contains("sensor 'rim'") && e.contains("'tap'"), "{e}");
}
