//! Sensors on spatial bodies: a point's velocity and acceleration against central differences
//! of its position along a run, the ball joint's point standing still, the angular velocity
//! against the bodies' own, the spatial reaction and energy sensors against the model's
//! functions, model files that name them, and the energy sensor of a spatial point mass.

use mbd::model::models::heavy_top;
use mbd::model::spatial::{
    Marker, SpatialBody, SpatialBodyRef, SpatialInertia, SpatialJoint, SpatialJointKind,
};
use mbd::model::{ModelFile, Sensor, SensorSpec, SystemBuilder};
use mbd::prelude::*;
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{run, Flow, SensorSolver};
use mbd::Simulation;

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

const G: f64 = 9.81;

/// A spherical pendulum, a 1.5 kg point mass on a 1.2 m rod from the origin tilted by 0.6 rad
/// and pushed sideways, beside a free spinning rigid box (so that the point mass's coordinates
/// come after a rigid body's 12), gravity `-G z`, with energy sensors on both.
fn bob_and_box() -> (System, [f64; 3], [f64; 3]) {
    let (l, th): (f64, f64) = (1.2, 0.6);
    let (x0, v0) = ([l * th.sin(), 0.0, -l * th.cos()], [0.0, 1.9, 0.0]);
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -G]);
    let boxed = b.add_spatial_body(
        SpatialBody::new(
            "box",
            SpatialInertia::principal(2.0, [0.1, 0.2, 0.25]).unwrap(),
        )
        .position([3.0, 0.0, 0.0])
        .velocity([0.5, 0.0, 2.0])
        .angular_velocity([1.0, 2.0, 3.0]),
    );
    let bob = b.add_spatial_point_mass("bob", 1.5, x0, v0);
    let rod = SpatialJoint::new(
        SpatialJointKind::Distance { length: l },
        Marker::at([0.0; 3]),
        Marker::at([0.0; 3]),
    )
    .unwrap();
    b.add_spatial_joint("rod", SpatialBodyRef::Ground, bob, rod);
    b.add_sensor(Sensor::spatial_energy("e_bob", bob));
    b.add_sensor(Sensor::spatial_energy("e_box", boxed));
    (b.build().unwrap(), x0, v0)
}

/// The point mass's energy sensor: at the initial state `m |v0|^2 / 2` and `m G z0` (to
/// 1e-13); along 5 s of projected RK4 (h = 1e-3) its kinetic energy is `m |x'|^2 / 2` of the
/// state (1e-12), the two sensors' totals add up to the model's `H` (1e-12 relative), and the
/// pendulum's own total stays constant to 1e-11 of its energy scale (measured 3.1e-14; the
/// sum 1.2e-13, the kinetic energy 1.3e-15).
#[test]
fn a_point_mass_energy_sensor_on_the_spherical_pendulum() {
    let (sys, x0, v0) = bob_and_box();
    assert_eq!(
        SensorSolver::columns(&sys),
        [
            "e_bob.kinetic",
            "e_bob.potential",
            "e_bob.total",
            "e_box.kinetic",
            "e_box.potential",
            "e_box.total"
        ]
    );
    let m = 1.5;
    let mut ss = SensorSolver::new(&sys).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let mut out = Vec::new();
    ss.evaluate(&sys, &s0, &mut out).unwrap();
    let t0 = 0.5 * m * v0.iter().map(|x| x * x).sum::<f64>(); // 2.7075 J
    let u0 = m * G * x0[2]; // -m g . x with g = (0, 0, -G)
    assert!((out[0] - t0).abs() < 1e-13, "{} vs {t0}", out[0]);
    assert!((out[1] - u0).abs() < 1e-13, "{} vs {u0}", out[1]);
    assert_eq!(out[2], out[0] + out[1]);
    let (h0, scale) = (out[2], out[0] + out[2].abs());
    let o = sys.spatial_point_mass_offset();
    let (mut drift, mut kinetic, mut sum) = (0.0f64, 0.0f64, 0.0f64);
    let mut watch = |sys: &System, s: &State, _: usize| -> Result<Flow, SolveError> {
        let mut out = Vec::new();
        ss.evaluate(sys, s, &mut out)?;
        let (q, v) = (s.q.as_slice(), s.v.as_slice());
        drift = drift.max((out[2] - h0).abs() / scale);
        let t = 0.5 * m * (o..o + 3).map(|i| v[i] * v[i]).sum::<f64>();
        kinetic = kinetic.max((out[0] - t).abs());
        let h = sys.energy(q, v);
        sum = sum.max((out[2] + out[5] - h).abs() / h.abs());
        Ok(Flow::Continue)
    };
    let mut sim = Simulation::new(sys.clone(), "rk4-projected").unwrap();
    sim.run_observed(Plan::from(RunConfig::new(5.0, 1e-3)), &mut watch)
        .unwrap();
    eprintln!("point mass energy sensor: drift {drift:.1e}, kinetic {kinetic:.1e}, sum {sum:.1e}");
    assert!(drift < 1e-11, "{drift:e}");
    assert!(kinetic < 1e-12 && sum < 1e-12, "{kinetic:e} {sum:e}");
    // it moved: the bob is far from its start
    let q = sim.state().q.as_slice();
    assert!((q[o + 1] - x0[1]).abs() > 0.1, "{q:?}");
}

/// `examples/models/spherical_pendulum.toml` with `[[sensors]] type = "energy"` on its point
/// mass gives the code-built sensor's values bit for bit (at the initial state and after a
/// projected RK4 run), and the model round-trips through the file with that sensor.
#[test]
fn a_point_mass_energy_sensor_in_a_model_file() {
    let text = format!(
        "{}\n[[sensors]]\ntype = \"energy\"\nname = \"e\"\nbody = \"bob\"\n",
        include_str!("../examples/models/spherical_pendulum.toml")
    );
    let file = ModelFile::from_toml(&text).unwrap().build().unwrap();
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -G]);
    let bob = b.add_spatial_point_mass(
        "bob",
        1.0,
        [0.479425538604203, 0.0, -0.8775825618903728],
        [0.0, 1.5, 0.0],
    );
    let rod = SpatialJoint::new(
        SpatialJointKind::Distance { length: 1.0 },
        Marker::at([0.0; 3]),
        Marker::at([0.0; 3]),
    )
    .unwrap();
    b.add_spatial_joint("rod", SpatialBodyRef::Ground, bob, rod);
    b.add_sensor(Sensor::spatial_energy("e", bob));
    let code = b.build().unwrap();
    assert_eq!(file.sensors(), code.sensors());
    let values = |sys: &System, t_end: f64| {
        let mut sim = Simulation::new(sys.clone(), "rk4-projected").unwrap();
        if t_end > 0.0 {
            sim.run(RunConfig::new(t_end, 1e-3)).unwrap();
        }
        let mut out = Vec::new();
        SensorSolver::new(sys)
            .unwrap()
            .evaluate(sys, sim.state(), &mut out)
            .unwrap();
        out
    };
    for t_end in [0.0, 0.5] {
        let (a, b) = (values(&file, t_end), values(&code, t_end));
        assert_eq!(a, b, "at {t_end} s");
        assert!(a[0] > 0.0 && a[1] < 0.0, "{a:?}");
    }
    // 1 kg at 1.5 m/s, z0 = -cos 0.5
    let v0 = values(&file, 0.0);
    assert!((v0[0] - 1.125).abs() < 1e-13, "{v0:?}");
    assert!((v0[1] + G * 0.8775825618903728).abs() < 1e-13, "{v0:?}");
    let back_text = code.to_model_file().to_toml().unwrap();
    assert!(
        back_text.contains("type = \"energy\"\nname = \"e\"\nbody = \"bob\""),
        "{back_text}"
    );
    let back = ModelFile::from_toml(&back_text).unwrap().build().unwrap();
    assert_eq!(back.sensors(), code.sensors());
}

/// An energy sensor naming no body is an error naming the sensor and the name (file); a
/// point-mass handle the model does not have is an error naming the sensor and the point mass
/// (code).
#[test]
fn an_energy_sensor_on_an_unknown_body_is_an_error() {
    let text = format!(
        "{}\n[[sensors]]\ntype = \"energy\"\nname = \"e\"\nbody = \"bobby\"\n",
        include_str!("../examples/models/spherical_pendulum.toml")
    );
    let e = ModelFile::from_toml(&text)
        .and_then(|f| f.build())
        .unwrap_err()
        .to_string();
    assert!(e.contains("sensor 'e'") && e.contains("'bobby'"), "{e}");
    // a handle from a model with two point masses, in a model with one
    let mut other = SystemBuilder::new();
    other.add_spatial_point_mass("a", 1.0, [0.0; 3], [0.0; 3]);
    let second = other.add_spatial_point_mass("b", 1.0, [1.0, 0.0, 0.0], [0.0; 3]);
    let mut b = SystemBuilder::new();
    b.add_spatial_point_mass("bob", 1.0, [0.0; 3], [0.0; 3]);
    b.add_sensor(Sensor::spatial_energy("e2", second));
    let e = b.build().unwrap_err().to_string();
    assert!(
        e.contains("sensor 'e2'") && e.contains("spatial point mass #1"),
        "{e}"
    );
}
