//! Model files: JSON and TOML round trips, and a hand-written file against the builder.

mod common;

use common::*;
use mbd_model::models;
use mbd_model::nalgebra::DMatrix;
use mbd_model::{ModelFile, System};

/// Every evaluation of `a` and `b` agrees bit for bit at random states.
fn same_equations(a: &System, b: &System, seed: u64) {
    assert_eq!(a.n_coords(), b.n_coords());
    assert_eq!(a.n_constraints(), b.n_constraints());
    assert_eq!(a.equation_names(), b.equation_names());
    assert_eq!(a.coordinate_names(), b.coordinate_names());
    assert_eq!(a.mass_diag(), b.mass_diag());
    assert_eq!(a.gravity(), b.gravity());
    assert_eq!(a.is_rheonomic(), b.is_rheonomic());
    assert_eq!(a.is_conservative(), b.is_conservative());
    assert_eq!(a.initial_guess(), b.initial_guess());
    let (n, m) = (a.n_coords(), a.n_constraints());
    let mut r = rng(seed);
    for _ in 0..10 {
        let q = rconfig(&mut r, n);
        let v = rvec(&mut r, n, 2.0);
        let lam = rvec(&mut r, m, 2.0);
        let t = uni(&mut r, 0.0, 3.0);
        let eval = |s: &System| {
            let mut phi = vec![0.0; m];
            let mut jac = DMatrix::zeros(m, n);
            let mut gamma = vec![0.0; m];
            let mut pt = vec![0.0; m];
            let mut hess = DMatrix::zeros(n, n);
            let mut kq = DMatrix::zeros(n, n);
            let mut f = vec![0.0; n];
            s.phi(&q, t, &mut phi);
            s.phi_q_gamma(&q, &v, t, &mut jac, &mut gamma);
            s.phi_t(&q, t, &mut pt);
            s.constraint_hessian(&q, 0.0, &lam, &mut hess);
            s.potential_hessian(&q, &mut kq);
            s.forces_into(&q, &v, t, &mut f);
            (phi, jac, gamma, pt, hess, kq, f, s.energy(&q, &v))
        };
        assert_eq!(eval(a), eval(b));
    }
}

fn round_trips(sys: &System, seed: u64) {
    let mf = sys.to_model_file();
    let json = mf.to_json().unwrap();
    let toml = mf.to_toml().unwrap();
    let from_json = ModelFile::from_json(&json).unwrap();
    let from_toml = ModelFile::from_toml(&toml).unwrap();
    assert_eq!(from_json, mf, "JSON:\n{json}");
    assert_eq!(from_toml, mf, "TOML:\n{toml}");
    same_equations(sys, &System::from_json(&json).unwrap(), seed);
    same_equations(sys, &System::from_toml(&toml).unwrap(), seed);
    // and once more: the file of the reloaded system is the same file
    assert_eq!(System::from_toml(&toml).unwrap().to_model_file(), mf);
}

#[test]
fn every_joint_and_force_round_trips() {
    let sys = kitchen_sink().unwrap();
    round_trips(&sys, 1);
    // the file names bodies, not handles
    let json = sys.to_model_file().to_json().unwrap();
    assert!(json.contains("\"body_a\": \"ground\""), "{json}");
    assert!(json.contains("\"type\": \"angle_driver\""), "{json}");
    assert!(json.contains("\"kind\": \"harmonic\""), "{json}");
}

#[test]
fn the_models_round_trip() {
    for (k, sys) in [
        models::pendulum(1.3, 0.7, 0.4, 9.81).unwrap(),
        models::manipulator().unwrap(),
        models::slider_crank().unwrap(),
        models::four_bar().unwrap(),
        models::n_link_chain(4).unwrap(),
    ]
    .iter()
    .enumerate()
    {
        round_trips(sys, 10 + k as u64);
    }
}

#[test]
fn hand_written_toml_pendulum_matches_the_builder() {
    // Uniform 1 kg, 1 m rod pinned at the origin, released 0.4 rad from the downward vertical.
    let text = r#"
# a rod pendulum
gravity = [0.0, -9.81]

[[bodies]]
name = "link1"
mass = 1.0
inertia = 0.08333333333333333       # m l^2 / 12
position = [0.19470917115432526, -0.46053049700144255, -1.1707963267948966]

[[joints]]
type = "revolute"
name = "pin1"
body_a = "ground"
body_b = "link1"
point_b = [-0.5, 0.0]               # point_a defaults to the origin
"#;
    let file = System::from_toml(text).unwrap();
    let builder = models::pendulum(1.0, 1.0, 0.4, 9.81).unwrap();
    assert_eq!(file.n_coords(), 3);
    assert_eq!(file.n_constraints(), 2);
    assert_eq!(file.mass_diag(), builder.mass_diag());
    let mut r = rng(3);
    for _ in 0..10 {
        let q = rconfig(&mut r, 3);
        let v = rvec(&mut r, 3, 2.0);
        let (mut pa, mut pb) = ([0.0; 2], [0.0; 2]);
        file.phi(&q, 0.0, &mut pa);
        builder.phi(&q, 0.0, &mut pb);
        assert_eq!(pa, pb);
        assert_eq!(file.energy(&q, &v), builder.energy(&q, &v));
    }
    // the stored initial positions agree to the digits written
    let (qa, _) = file.initial_guess();
    let (qb, _) = builder.initial_guess();
    assert!((qa - qb).amax() < 1e-15);
    let xa = mbd_solve::consistent_state(&file, 0.0).unwrap();
    let ea = file.energy(xa.q.as_slice(), xa.v.as_slice());
    assert!((ea + 9.81 * 0.5 * 0.4f64.cos()).abs() < 1e-13, "{ea}");
}

#[test]
fn hand_written_json_slider_with_forces() {
    // JSON with defaults omitted (point_a, damping, rest_angle, phase, offset).
    let text = r#"{
      "gravity": [0.0, -9.81],
      "bodies": [
        {"name": "block", "mass": 2.0, "inertia": 0.1, "position": [0.5, 0.0, 0.0]}
      ],
      "joints": [
        {"type": "prismatic", "name": "rail", "body_a": "ground", "body_b": "block",
         "axis": [2.0, 0.0]}
      ],
      "forces": [
        {"type": "spring_damper", "name": "spring", "body_a": "ground", "body_b": "block",
         "stiffness": 100.0, "rest_length": 0.3},
        {"type": "force", "name": "push", "body": "block",
         "fx": {"kind": "harmonic", "amplitude": 1.0, "omega": 2.0},
         "fy": {"kind": "constant", "value": 0.0}}
      ]
    }"#;
    let sys = System::from_json(text).unwrap();
    assert_eq!((sys.n_coords(), sys.n_constraints(), sys.dof()), (3, 2, 1));
    assert!(!sys.is_conservative());
    // the axis is normalised at build
    match &sys.joints()[0].kind {
        mbd_model::JointKind::Prismatic(mbd_model::joints::Prismatic { axis, pa, .. }) => {
            assert_eq!(*axis, [1.0, 0.0]);
            assert_eq!(*pa, [0.0, 0.0]);
        }
        k => panic!("{k:?}"),
    }
    // spring energy at x = 0.5: 50 * 0.2^2 = 2
    let q = [0.5, 0.0, 0.0];
    assert!((sys.potential(&q) - 2.0).abs() < 1e-13);
    let mut f = [0.0; 3];
    sys.forces_into(&q, &[0.0; 3], 0.25, &mut f);
    assert!(
        (f[0] - (-100.0 * 0.2 + 0.5f64.sin())).abs() < 1e-13,
        "{f:?}"
    );
    assert!((f[1] + 2.0 * 9.81).abs() < 1e-13);
    round_trips(&sys, 5);
}
