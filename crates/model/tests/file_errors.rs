//! Every malformed model file is rejected with an error naming the line, column or field at
//! fault; I/O errors name the path.

mod common;

use common::PENDULUM_TOML;
use mbd_model::models;
use mbd_model::{ModelError, System};

#[test]
fn malformed_json() {
    let e = System::from_json(r#"{"bodies": [{"name": "a", "mass": 1.0,}]}"#).unwrap_err();
    assert!(
        matches!(e, ModelError::Parse { format: "json", .. }),
        "{e:?}"
    );
    // wrong type
    let e = System::from_json(r#"{"bodies": [{"name": "a", "mass": "heavy", "inertia": 1}]}"#)
        .unwrap_err();
    assert!(
        matches!(e, ModelError::Parse { format: "json", .. }),
        "{e:?}"
    );
}

#[test]
fn malformed_toml() {
    let e = System::from_toml("[[bodies]\nname = \"a\"").unwrap_err();
    assert!(
        matches!(e, ModelError::Parse { format: "toml", .. }),
        "{e:?}"
    );
    // missing required field
    let e = System::from_toml(&PENDULUM_TOML.replace("mass = 1.0\n", "")).unwrap_err();
    match e {
        ModelError::Parse { format, message } => {
            assert_eq!(format, "toml");
            assert!(message.contains("mass"), "{message}");
        }
        e => panic!("{e:?}"),
    }
}

fn unknown_field(text: &str, field: &str) {
    for e in [
        System::from_toml(text).unwrap_err(),
        System::from_json(
            &serde_json::to_string(&toml::from_str::<toml::Value>(text).unwrap()).unwrap(),
        )
        .unwrap_err(),
    ] {
        match e {
            ModelError::Parse { message, .. } => {
                assert!(message.contains("unknown field"), "{message}");
                assert!(message.contains(field), "{message}");
            }
            e => panic!("unknown field '{field}' accepted: {e:?}"),
        }
    }
}

#[test]
fn unknown_fields_are_rejected() {
    // top level
    unknown_field(&format!("gravty = [0.0, 1.0]\n{PENDULUM_TOML}"), "gravty");
    // in a joint
    unknown_field(
        &PENDULUM_TOML.replace(
            "point_b = [-0.5, 0.0]",
            "point_b = [-0.5, 0.0]\nlength = 2.0",
        ),
        "length",
    );
    // in a body: a misspelt optional field must not silently default
    unknown_field(
        &PENDULUM_TOML.replace("position =", "velocty = [0.0, 0.0, 1.0]\nposition ="),
        "velocty",
    );
    // in a time function
    let drv = format!(
        "{PENDULUM_TOML}\n[[forces]]\ntype = \"torque\"\nname = \"m\"\nbody = \"link1\"\n\
         torque = {{ kind = \"harmonic\", amplitude = 1.0, omega = 2.0, phse = 0.5 }}\n"
    );
    unknown_field(&drv, "phse");
    // in a force
    let f = format!(
        "{PENDULUM_TOML}\n[[forces]]\ntype = \"torque\"\nname = \"m\"\nbody = \"link1\"\n\
         torque = {{ kind = \"constant\", value = 1.0 }}\npoint = [1.0, 0.0]\n"
    );
    unknown_field(&f, "point");
}

#[test]
fn wrong_length_vectors() {
    let sys = models::manipulator().unwrap();
    let opts = mbd_solve::ConsistentOptions::default();
    assert_eq!(
        mbd_solve::project_state(&sys, &[0.0; 5], &[0.0; 6], 0.0, opts).unwrap_err(),
        mbd_solve::SolveError::Dimension {
            what: "q_guess",
            expected: 6,
            got: 5
        }
    );
    assert_eq!(
        mbd_solve::project_state(&sys, &[0.0; 6], &[0.0; 7], 0.0, opts).unwrap_err(),
        mbd_solve::SolveError::Dimension {
            what: "v_guess",
            expected: 6,
            got: 7
        }
    );
    assert!(matches!(
        sys.check_rank(&[0.0; 2], 0.0).unwrap_err(),
        ModelError::Dimension {
            what: "q",
            expected: 6,
            got: 2
        }
    ));
}

#[test]
fn non_finite_guess() {
    let sys = models::manipulator().unwrap();
    let (q, v) = sys.initial_guess();
    let mut qb = q.as_slice().to_vec();
    qb[4] = f64::NAN;
    let e = mbd_solve::project_state(
        &sys,
        &qb,
        v.as_slice(),
        0.0,
        mbd_solve::ConsistentOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        e,
        mbd_solve::SolveError::NonFinite {
            t: 0.0,
            what: "initial state q_guess"
        }
    );
    let mut vb = v.as_slice().to_vec();
    vb[0] = f64::INFINITY;
    let e = mbd_solve::project_state(
        &sys,
        q.as_slice(),
        &vb,
        0.0,
        mbd_solve::ConsistentOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        e,
        mbd_solve::SolveError::NonFinite {
            t: 0.0,
            what: "initial state v_guess"
        }
    );
}

#[test]
fn io_errors() {
    let e = System::from_path("/nonexistent/model.toml").unwrap_err();
    assert!(matches!(e, ModelError::Parse { format: "io", .. }), "{e:?}");
    let dir = std::env::temp_dir().join(format!("mbd-model-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("model.yaml");
    std::fs::write(&p, PENDULUM_TOML).unwrap();
    let e = System::from_path(&p).unwrap_err();
    assert!(matches!(e, ModelError::Parse { format: "io", .. }), "{e:?}");
    let p = dir.join("model.toml");
    std::fs::write(&p, PENDULUM_TOML).unwrap();
    assert_eq!(System::from_path(&p).unwrap().n_coords(), 3);
    std::fs::remove_dir_all(&dir).unwrap();
}
