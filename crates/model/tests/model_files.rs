//! Model-file features: the example models, point masses, body frames, the JSON
//! Schema (up to date, accepting the examples, rejecting malformed models) and the docs.

use mbd_model::{BodyKind, ModelError, ModelFile, System};
use mbd_solve::{consistent_state, AccelerationSolver};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn examples() -> Vec<PathBuf> {
    let dir = repo_root().join("examples/models");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("examples/models exists")
        .map(|e| e.expect("directory entry").path())
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("json" | "toml")
            )
        })
        .collect();
    files.sort();
    files
}

/// A model file as a JSON value (TOML converted), for the schema validator.
fn as_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).expect("readable example");
    match path.extension().and_then(|e| e.to_str()) {
        Some("json") => serde_json::from_str(&text).expect("valid JSON"),
        _ => {
            let t: toml::Value = toml::from_str(&text).expect("valid TOML");
            serde_json::to_value(t).expect("TOML as JSON")
        }
    }
}

fn schema_value() -> Value {
    serde_json::from_str(&ModelFile::json_schema()).expect("the schema is JSON")
}

fn validator() -> jsonschema::Validator {
    jsonschema::validator_for(&schema_value()).expect("the schema compiles")
}

#[test]
fn schema_is_up_to_date() {
    let path = repo_root().join("schema/model.schema.json");
    let fresh = ModelFile::json_schema();
    if std::env::var("MBD_BLESS").is_ok_and(|v| v == "1") {
        std::fs::create_dir_all(path.parent().expect("schema dir")).expect("mkdir schema");
        std::fs::write(&path, &fresh).expect("write schema");
    }
    let stored = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        stored == fresh,
        "schema/model.schema.json is stale or missing; regenerate it with\n  \
         MBD_BLESS=1 cargo test -p mbd-model --test model_files schema_is_up_to_date"
    );
}

#[test]
fn the_schema_accepts_every_example() {
    let v = validator();
    let files = examples();
    assert!(files.len() >= 6, "{files:?}");
    for f in &files {
        let doc = as_json(f);
        let errors: Vec<String> = v.iter_errors(&doc).map(|e| e.to_string()).collect();
        assert!(errors.is_empty(), "{}: {errors:?}", f.display());
    }
}

/// A small valid model to break in one place at a time.
fn valid() -> Value {
    json!({
        "gravity": [0.0, -9.81],
        "bodies": [
            { "name": "bob", "kind": "point_mass", "mass": 1.0, "position": [0.0, -1.0, 0.0] },
            { "name": "rod", "mass": 1.0, "inertia": 0.1, "position": [0.0, -2.0, 0.0] }
        ],
        "joints": [
            { "type": "distance", "name": "string", "body_a": "ground", "body_b": "bob",
              "length": 1.0 },
            { "type": "revolute", "name": "pin", "body_a": "bob", "body_b": "rod",
              "point_b": [0.0, 1.0] },
            { "type": "angle_driver", "name": "drive", "body_a": "ground", "body_b": "rod",
              "f": { "kind": "harmonic", "amplitude": 0.1, "omega": 1.0 } }
        ],
        "forces": [
            { "type": "spring_damper", "name": "s", "body_a": "ground", "point_a": [1.0, 0.0],
              "body_b": "bob", "stiffness": 1.0, "rest_length": 1.0 },
            { "type": "force", "name": "push", "body": "rod",
              "fx": { "kind": "constant", "value": 1.0 },
              "fy": { "kind": "polynomial", "coeffs": [0.0, 1.0] } }
        ]
    })
}

fn malformed() -> Vec<(&'static str, Value)> {
    let mut cases = Vec::new();
    let mut edit = |what: &'static str, f: &dyn Fn(&mut Value)| {
        let mut v = valid();
        f(&mut v);
        cases.push((what, v));
    };
    edit("a spatial body without mass", &|v| {
        v["spatial_bodies"] = json!([{ "name": "b", "moments": [1.0, 1.0, 1.0] }])
    });
    edit("unknown top-level field", &|v| {
        v["gravitation"] = json!([0.0, 1.0])
    });
    edit("gravity with three components", &|v| {
        v["gravity"] = json!([0.0, -9.81, 0.0])
    });
    edit("body without mass", &|v| {
        v["bodies"][1].as_object_mut().map(|o| o.remove("mass"));
    });
    edit("negative mass", &|v| v["bodies"][1]["mass"] = json!(-1.0));
    edit("zero inertia", &|v| v["bodies"][1]["inertia"] = json!(0.0));
    edit("mass as a string", &|v| {
        v["bodies"][1]["mass"] = json!("1 kg")
    });
    edit("unknown body kind", &|v| {
        v["bodies"][0]["kind"] = json!("particle")
    });
    edit("misspelt body field", &|v| {
        v["bodies"][1]["intertia"] = json!(0.1)
    });
    edit("position with two components", &|v| {
        v["bodies"][1]["position"] = json!([0.0, -2.0])
    });
    edit("com with three components", &|v| {
        v["bodies"][1]["com"] = json!([0.0, 0.0, 0.0])
    });
    edit("unknown joint type", &|v| {
        v["joints"][1]["type"] = json!("hinge")
    });
    edit("joint without type", &|v| {
        v["joints"][1].as_object_mut().map(|o| o.remove("type"));
    });
    edit("distance joint without length", &|v| {
        v["joints"][0].as_object_mut().map(|o| o.remove("length"));
    });
    edit("field of another joint type", &|v| {
        v["joints"][1]["length"] = json!(1.0)
    });
    edit("time function without kind", &|v| {
        v["joints"][2]["f"] = json!({ "amplitude": 0.1, "omega": 1.0 })
    });
    edit("unknown time function kind", &|v| {
        v["joints"][2]["f"]["kind"] = json!("square")
    });
    edit("unknown force type", &|v| {
        v["forces"][0]["type"] = json!("bungee")
    });
    edit("force without fy", &|v| {
        v["forces"][1].as_object_mut().map(|o| o.remove("fy"));
    });
    edit("coordinate not x, y or angle", &|v| {
        v["joints"][0] = json!({ "type": "absolute", "name": "a", "body": "rod",
                                  "coordinate": "z", "value": 0.0 })
    });
    cases
}

#[test]
fn the_schema_and_the_loader_reject_malformed_models() {
    let v = validator();
    let ok = valid();
    assert!(
        v.is_valid(&ok),
        "{:?}",
        v.iter_errors(&ok)
            .map(|e| e.to_string())
            .collect::<Vec<_>>()
    );
    let sys = System::from_json(&ok.to_string()).expect("the valid model loads");
    assert_eq!(sys.n_coords(), 6);
    let cases = malformed();
    assert_eq!(cases.len(), 20);
    for (what, doc) in cases {
        assert!(!v.is_valid(&doc), "the schema accepts: {what}");
        assert!(
            System::from_json(&doc.to_string()).is_err(),
            "the loader accepts: {what}"
        );
    }
}

/// Every property name, tag value and enum value of the schema.
fn schema_names(v: &Value, out: &mut std::collections::BTreeSet<String>) {
    match v {
        Value::Object(o) => {
            if let Some(Value::Object(props)) = o.get("properties") {
                out.extend(props.keys().cloned());
            }
            if let Some(Value::String(c)) = o.get("const") {
                out.insert(c.clone());
            }
            if let Some(Value::Array(e)) = o.get("enum") {
                out.extend(e.iter().filter_map(|x| x.as_str().map(String::from)));
            }
            o.values().for_each(|x| schema_names(x, out));
        }
        Value::Array(a) => a.iter().for_each(|x| schema_names(x, out)),
        _ => {}
    }
}

#[test]
fn the_docs_name_every_schema_field() {
    let doc = std::fs::read_to_string(repo_root().join("docs/model-files.md")).expect("docs");
    let mut names = std::collections::BTreeSet::new();
    schema_names(&schema_value(), &mut names);
    for must in [
        "gravity",
        "point_mass",
        "com",
        "angle_driver",
        "harmonic",
        "rest_angle",
    ] {
        assert!(names.contains(must), "{must} not in the schema: {names:?}");
    }
    let missing: Vec<&String> = names
        .iter()
        .filter(|n| !doc.contains(&format!("`{n}`")))
        .collect();
    assert!(
        missing.is_empty(),
        "docs/model-files.md does not name {missing:?}"
    );
}

#[test]
fn the_doc_example_loads() {
    let doc = std::fs::read_to_string(repo_root().join("docs/model-files.md")).expect("docs");
    let start = doc.find("```toml\n").expect("a TOML example") + "```toml\n".len();
    let len = doc[start..].find("```").expect("closed");
    let sys = System::from_toml(&doc[start..start + len]).expect("the doc example loads");
    // arm: 3 coordinates, bob: 3; pivot 2, tip 2, the bob's angle 1
    assert_eq!(sys.dof(), 1);
    let x0 = consistent_state(&sys, 0.0).expect("consistent");
    assert!(
        x0.residual <= 1e-12 && x0.position_correction <= 1e-12,
        "{x0:?}"
    );
}

#[test]
fn every_example_loads_with_its_dof_and_a_consistent_state() {
    let expected = [
        ("andrews_squeezer.toml", 1, false),
        ("bricard.toml", 1, false),
        ("driven_arm.toml", 3, true),
        ("driven_three_link_arm.json", 1, true),
        ("flyball_governor.toml", 4, false),
        ("four_bar.toml", 1, false),
        ("heavy_top.toml", 3, false),
        ("manipulator.json", 2, false),
        ("pendulum.toml", 1, false),
        ("point_mass_pendulum.toml", 1, false),
        ("slider_crank_spring.toml", 1, false),
        ("spatial_double_pendulum.toml", 6, false),
        ("spatial_slider_crank.toml", 1, false),
        ("spatial_spring_pendulum.toml", 3, false),
        ("spherical_pendulum.toml", 2, false),
        ("sprung_rod.toml", 3, false),
        ("turning_arm.toml", 3, true),
    ];
    let files = examples();
    assert_eq!(files.len(), expected.len(), "{files:?}");
    for (f, (name, dof, rheonomic)) in files.iter().zip(expected) {
        assert!(f.ends_with(name), "{} vs {name}", f.display());
        let sys = System::from_path(f).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(sys.dof(), dof, "{name}");
        assert_eq!(sys.is_rheonomic(), rheonomic, "{name}");
        let x0 = consistent_state(&sys, 0.0).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(x0.residual <= 1e-12, "{name}: {x0:?}");
        assert!(x0.velocity_residual <= 1e-12, "{name}: {x0:?}");
        // the examples are written consistent: the projection barely moves them (a velocity
        // guess would be moved to the mass-weighted nearest consistent one, not kept)
        assert!(x0.position_correction <= 1e-9, "{name}: {x0:?}");
        assert!(x0.velocity_correction <= 1e-9, "{name}: {x0:?}");
    }
}

fn accelerations(sys: &System, q: &[f64], v: &[f64], t: f64) -> Vec<f64> {
    let mut solver = AccelerationSolver::new(sys);
    let mut a = vec![0.0; sys.n_coords()];
    let mut lam = vec![0.0; sys.n_constraints()];
    solver
        .solve(sys, q, v, t, &mut a, &mut lam)
        .expect("acceleration solve");
    a
}

/// The heavy top's file is `models::heavy_top` (the same coordinates to round-off), and a
/// spatial model round-trips through TOML and JSON.
#[test]
fn the_heavy_top_file_is_the_heavy_top_model() {
    let file = System::from_path(repo_root().join("examples/models/heavy_top.toml")).unwrap();
    let code = mbd_model::models::heavy_top([0.3, 0.3, 0.1], 0.3, 20.0).unwrap();
    let (qf, vf) = file.initial_guess();
    let (qc, vc) = code.initial_guess();
    assert!((&qf - &qc).amax() < 1e-15 && (&vf - &vc).amax() < 1e-14);
    assert_eq!(file.coordinate_names(), code.coordinate_names());
    for text in [
        file.to_model_file().to_toml().unwrap(),
        file.to_model_file().to_json().unwrap(),
    ] {
        let back = if text.starts_with('{') {
            System::from_json(&text)
        } else {
            System::from_toml(&text)
        }
        .unwrap();
        // (the orientation comes back as a matrix: the same coordinates)
        let (qb, vb) = back.initial_guess();
        assert!((&qb - &qf).amax() < 1e-15 && (&vb - &vf).amax() < 1e-15);
        assert_eq!(back.spatial_joints(), file.spatial_joints());
        assert_eq!(back.spatial_gravity(), file.spatial_gravity());
    }
}

#[test]
fn a_point_mass_pendulum_moves_as_a_particle() {
    let path = repo_root().join("examples/models/point_mass_pendulum.toml");
    let sys = System::from_path(&path).expect("loads");
    assert_eq!((sys.n_coords(), sys.n_constraints(), sys.dof()), (3, 2, 1));
    let (l, g, m) = (1.0, 9.81, 1.0);
    for (phi, omega) in [(0.3, 0.0), (1.1, -2.0), (-2.5, 0.7)] {
        // bob at angle phi from the downward vertical, angular velocity omega
        let (s, c) = f64::sin_cos(phi);
        let q = [l * s, -l * c, 0.0];
        let v = [l * c * omega, l * s * omega, 0.0];
        let a = accelerations(&sys, &q, &v, 0.0);
        // analytic: tangential -g sin(phi), centripetal l omega^2 towards the pivot
        let at = -g * s;
        let ac = l * omega * omega;
        let exact = [at * c - ac * s, at * s + ac * c, 0.0];
        for k in 0..3 {
            assert!(
                (a[k] - exact[k]).abs() <= 1e-12,
                "phi {phi}: a {a:?} vs {exact:?}"
            );
        }
        let e = sys.energy(&q, &v);
        let exact_e = 0.5 * m * (l * omega).powi(2) - m * g * l * c;
        assert!((e - exact_e).abs() <= 1e-12, "energy {e} vs {exact_e}");
    }
    // small-amplitude period: semi-implicit Euler on the angle through the model's
    // accelerations; the first downward zero crossing after release is a quarter period
    let (mut phi, mut omega, h) = (0.01f64, 0.0f64, 1e-4);
    let mut t = 0.0;
    while phi > 0.0 {
        let (s, c) = phi.sin_cos();
        let q = [l * s, -l * c, 0.0];
        let v = [l * c * omega, l * s * omega, 0.0];
        let a = accelerations(&sys, &q, &v, t);
        // angular acceleration from the tangential component
        let alpha = (a[0] * c + a[1] * s) / l;
        omega += h * alpha;
        phi += h * omega;
        t += h;
    }
    let period = 4.0 * t;
    let exact = 2.0 * std::f64::consts::PI * (l / g).sqrt();
    assert!((period - exact).abs() <= 1e-3, "period {period} vs {exact}");
}

/// The three-link arm written with body frames at the proximal joints, rewritten relative to
/// the centres of mass by hand.
fn arm_without_frames(mf: &ModelFile) -> ModelFile {
    let mut out = mf.clone();
    for b in &mut out.bodies {
        let c = b.com.take().expect("the example uses frames");
        assert_eq!(c, [0.25, 0.0]);
        let th = b.position[2];
        b.position[0] += 0.25 * th.cos();
        b.position[1] += 0.25 * th.sin();
        // v + thetadot k x R(theta) c
        let w = b.velocity[2];
        b.velocity[0] -= 0.25 * w * th.sin();
        b.velocity[1] += 0.25 * w * th.cos();
    }
    let text = serde_json::to_string(&out)
        .expect("serialises")
        .replace("\"point_a\":[0.5,0.0]", "\"point_a\":[0.25,0.0]")
        .replace("\"point_b\":[0.0,0.0]", "\"point_b\":[-0.25,0.0]")
        .replace("\"point_a\":[0.0,0.0],\"body_b\":\"upper\"", "X")
        .replace("\"point\":[0.5,0.0]", "\"point\":[0.25,0.0]");
    // the shoulder's ground point stays global
    let text = text.replace("X", "\"point_a\":[0.0,0.0],\"body_b\":\"upper\"");
    ModelFile::from_json(&text).expect("rewritten model parses")
}

#[test]
fn a_body_frame_gives_the_same_model_as_centre_of_mass_points() {
    let path = repo_root().join("examples/models/driven_three_link_arm.json");
    let framed = System::from_path(&path).expect("loads");
    let mf = ModelFile::from_json(&std::fs::read_to_string(&path).expect("read")).expect("parse");
    let plain_file = arm_without_frames(&mf);
    assert!(plain_file.bodies.iter().all(|b| b.com.is_none()));
    let plain = plain_file.build().expect("builds");
    // same local points: the lowered files agree exactly
    assert_eq!(framed.to_model_file().joints, plain.to_model_file().joints);
    assert_eq!(framed.to_model_file().forces, plain.to_model_file().forces);
    // same initial state up to rounding of r + R c
    let (qa, va) = framed.initial_guess();
    let (qb, vb) = plain.initial_guess();
    assert!((&qa - &qb).amax() <= 1e-15, "{qa} vs {qb}");
    assert!((&va - &vb).amax() <= 1e-15);
    let x0 = consistent_state(&framed, 0.0).expect("consistent");
    let (q, v) = (x0.q.as_slice(), x0.v.as_slice());
    let m = framed.n_constraints();
    let (mut pa, mut pb) = (vec![0.0; m], vec![0.0; m]);
    framed.phi(q, 0.3, &mut pa);
    plain.phi(q, 0.3, &mut pb);
    assert_eq!(pa, pb);
    assert_eq!(framed.energy(q, v), plain.energy(q, v));
    assert_eq!(
        accelerations(&framed, q, v, 0.3),
        accelerations(&plain, q, v, 0.3)
    );
    // and the frame's velocity converts: a spinning frame moves its centre of mass
    let mut spun = mf.clone();
    spun.bodies[0].velocity = [0.0, 0.0, 2.0];
    let (_, v0) = spun.build().expect("builds").initial_guess();
    let th = spun.bodies[0].position[2];
    assert!((v0[0] - (-2.0 * 0.25 * th.sin())).abs() <= 1e-15);
    assert!((v0[1] - 2.0 * 0.25 * th.cos()).abs() <= 1e-15);
}

fn load_err(doc: &Value) -> ModelError {
    match System::from_json(&doc.to_string()) {
        Ok(_) => panic!("loaded: {doc}"),
        Err(e) => e,
    }
}

#[test]
fn point_mass_and_frame_errors_name_the_element_and_field() {
    let mut v = valid();
    v["joints"][1]["point_a"] = json!([0.1, 0.0]);
    let e = load_err(&v).to_string();
    assert!(
        e.contains("joint 'pin'") && e.contains("point_a") && e.contains("'bob'"),
        "{e}"
    );

    let mut v = valid();
    v["forces"][0]["point_b"] = json!([0.0, 0.2]);
    let e = load_err(&v).to_string();
    assert!(
        e.contains("force 's'") && e.contains("point_b") && e.contains("'bob'"),
        "{e}"
    );

    let mut v = valid();
    v["bodies"][0]["inertia"] = json!(0.5);
    let e = load_err(&v).to_string();
    assert!(e.contains("body 'bob'") && e.contains("inertia"), "{e}");

    let mut v = valid();
    v["bodies"][0]["position"] = json!([0.0, -1.0, 0.2]);
    let e = load_err(&v).to_string();
    assert!(e.contains("body 'bob'") && e.contains("theta"), "{e}");

    let mut v = valid();
    v["bodies"][1].as_object_mut().map(|o| o.remove("inertia"));
    let e = load_err(&v).to_string();
    assert!(e.contains("body 'rod'") && e.contains("inertia"), "{e}");

    for (joint, kind) in [
        (
            json!({ "type": "prismatic", "name": "p", "body_a": "ground", "body_b": "bob",
                  "axis": [1.0, 0.0] }),
            "prismatic",
        ),
        (
            json!({ "type": "weld", "name": "p", "body_a": "rod", "body_b": "bob" }),
            "weld",
        ),
        (
            json!({ "type": "angle_driver", "name": "p", "body_a": "ground", "body_b": "bob",
                  "f": { "kind": "constant", "value": 0.0 } }),
            "angle driver",
        ),
        (
            json!({ "type": "absolute", "name": "p", "body": "bob", "coordinate": "angle",
                  "value": 0.0 }),
            "absolute angle",
        ),
    ] {
        let mut v = valid();
        v["joints"].as_array_mut().expect("joints").push(joint);
        let e = load_err(&v);
        assert!(matches!(e, ModelError::InvalidElement { .. }), "{e:?}");
        let e = e.to_string();
        assert!(
            e.contains("joint 'p'") && e.contains(kind) && e.contains("'bob'"),
            "{e}"
        );
    }
    let mut v = valid();
    v["forces"]
        .as_array_mut()
        .expect("forces")
        .push(json!({ "type": "torque", "name": "tq", "body": "bob",
                "torque": { "kind": "constant", "value": 1.0 } }));
    let e = load_err(&v).to_string();
    assert!(e.contains("force 'tq'") && e.contains("'bob'"), "{e}");

    // a point mass with a frame attaches at its centre of mass, given in that frame
    let mut v = valid();
    v["bodies"][0]["com"] = json!([0.5, 0.0]);
    v["bodies"][0]["position"] = json!([-0.5, -1.0, 0.0]);
    v["joints"][0]["point_b"] = json!([0.5, 0.0]);
    v["joints"][1]["point_a"] = json!([0.5, 0.0]);
    v["forces"][0]["point_b"] = json!([0.5, 0.0]);
    let sys = System::from_json(&v.to_string()).expect("loads");
    let (q, _) = sys.initial_guess();
    assert_eq!((q[0], q[1]), (0.0, -1.0));
    assert_eq!(
        sys.bodies()[0].inertia,
        1.0,
        "nominal inertia m l^2 with l = 1 m"
    );
    assert!(mbd_model::ModelFile::from_json(&v.to_string())
        .is_ok_and(|f| f.bodies[0].kind == BodyKind::PointMass));
}

#[test]
fn parse_errors_carry_line_and_column() {
    let json = "{\n  \"bodies\": [\n    { \"name\": \"a\", \"mass\": oops }\n  ]\n}";
    let e = System::from_json(json).expect_err("bad JSON").to_string();
    assert!(e.contains("line 3") && e.contains("column"), "{e}");
    let toml = "[[bodies]]\nname = \"a\"\nmass = 1.0\ninertia = 1.0\nmasss = 2.0\n";
    let e = System::from_toml(toml)
        .expect_err("unknown field")
        .to_string();
    assert!(e.contains("line 5") && e.contains("masss"), "{e}");
}

#[test]
fn point_masses_and_frames_round_trip_through_both_formats() {
    for name in ["point_mass_pendulum.toml", "driven_three_link_arm.json"] {
        let path = repo_root().join("examples/models").join(name);
        let text = std::fs::read_to_string(&path).expect("read");
        let mf = if name.ends_with(".toml") {
            ModelFile::from_toml(&text)
        } else {
            ModelFile::from_json(&text)
        }
        .expect("parses");
        // the file form (kind, com) survives both formats
        let json = mf.to_json().expect("to JSON");
        let toml = mf.to_toml().expect("to TOML");
        assert_eq!(
            ModelFile::from_json(&json).expect("JSON back"),
            mf,
            "{json}"
        );
        assert_eq!(
            ModelFile::from_toml(&toml).expect("TOML back"),
            mf,
            "{toml}"
        );
        // the system writes its lowered form (rigid bodies, the point mass's angle joint),
        // which loads to the same system
        let sys = mf.build().expect("builds");
        let lowered = sys.to_model_file();
        assert!(lowered
            .bodies
            .iter()
            .all(|b| b.com.is_none() && b.inertia.is_some()));
        let again = lowered.build().expect("lowered form builds");
        assert_eq!(again.to_model_file(), lowered);
        assert_eq!(again.dof(), sys.dof());
        assert_eq!(again.initial_guess(), sys.initial_guess());
        assert_eq!(again.equation_names(), sys.equation_names());
    }
}
