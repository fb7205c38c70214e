//! Random model files, with redundant joints (doubled pins and distances) and near-singular
//! geometry (collinear distance joints, points on top of each other), odd numbers included:
//! loading, checking and running them never panics. Every outcome is a model, a typed error,
//! or a run that ends or stops with a typed error.

use mbd::model::ModelFile;
use mbd::prelude::*;
use proptest::prelude::*;

/// A number a file could hold: ordinary, tiny, huge, zero, negative or not finite.
fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => -2.0f64..2.0,
        1 => Just(0.0),
        1 => prop_oneof![Just(1e-300), Just(1e300), Just(-1e300), Just(f64::INFINITY), Just(f64::NAN)],
    ]
}

/// TOML for a number (`nan`, `inf`, `-inf` are TOML too).
fn t(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        }
    } else {
        format!("{x:e}")
    }
}

/// One joint line set: kind, bodies (index, `k` = ground), points, parameter, and whether it
/// repeats the previous joint (a redundant copy).
#[derive(Clone, Debug)]
struct J {
    kind: usize,
    a: usize,
    b: usize,
    pa: [f64; 2],
    pb: [f64; 2],
    p: f64,
    repeat: bool,
}

fn joint() -> impl Strategy<Value = J> {
    (
        0usize..4,
        0usize..4,
        0usize..4,
        [number(), number()],
        [number(), number()],
        number(),
        proptest::bool::weighted(0.3),
    )
        .prop_map(|(kind, a, b, pa, pb, p, repeat)| J {
            kind,
            a,
            b,
            pa,
            pb,
            p,
            repeat,
        })
}

/// A model file of up to three bodies and six joints.
fn model() -> impl Strategy<Value = String> {
    (
        proptest::collection::vec(([number(), number(), number()], number(), number()), 1..4),
        proptest::collection::vec(joint(), 0..7),
        proptest::bool::weighted(0.2),
    )
        .prop_map(|(bodies, joints, reject)| {
            let nb = bodies.len();
            let mut s = String::from("gravity = [0.0, -9.81]\n");
            if reject {
                s += "redundant_constraints = \"reject\"\n";
            }
            for (i, (pos, mass, vel)) in bodies.iter().enumerate() {
                s += &format!(
                    "[[bodies]]\nname = \"b{i}\"\nmass = {}\ninertia = {}\nposition = [{}, {}, {}]\nvelocity = [{}, 0.0, 0.0]\n",
                    t(mass.abs() + 0.5),
                    t(mass.abs() * 0.1 + 0.01),
                    t(pos[0]),
                    t(pos[1]),
                    t(pos[2]),
                    t(*vel),
                );
            }
            let name = |k: usize| {
                if k >= nb {
                    "ground".to_string()
                } else {
                    format!("b{k}")
                }
            };
            let mut prev: Option<J> = None;
            for (ji, j) in joints.iter().enumerate() {
                let j = match (&prev, j.repeat) {
                    (Some(p), true) => p.clone(),
                    _ => j.clone(),
                };
                let (a, b) = (name(j.a), name(j.b));
                let head = format!(
                    "name = \"j{ji}\"\nbody_a = \"{a}\"\npoint_a = [{}, {}]\nbody_b = \"{b}\"\npoint_b = [{}, {}]\n",
                    t(j.pa[0]),
                    t(j.pa[1]),
                    t(j.pb[0]),
                    t(j.pb[1])
                );
                s += "[[joints]]\n";
                s += &match j.kind {
                    0 => format!("type = \"revolute\"\n{head}"),
                    1 => format!("type = \"distance\"\nlength = {}\n{head}", t(j.p.abs() + 0.1)),
                    2 => format!("type = \"weld\"\nangle = {}\n{head}", t(j.p)),
                    _ => format!("type = \"prismatic\"\naxis = [1.0, {}]\n{head}", t(j.p)),
                };
                prev = Some(j);
            }
            s
        })
}

/// Loads, checks and runs one file with a few solvers: returns nothing, panics only on a
/// defect.
fn exercise(text: &str) {
    let Ok(file) = ModelFile::from_toml(text) else {
        return;
    };
    let Ok(sys) = file.build() else {
        return;
    };
    let _ = sys.redundant_equations();
    let Ok(state) = State::consistent(&sys, 0.0) else {
        return;
    };
    for solver in [
        "rk4",
        "rk4-projected",
        "symplectic:2",
        "tangent:rk4",
        "index1:dopri5",
    ] {
        let Ok(mut sim) = Simulation::new(sys.clone(), solver) else {
            continue;
        };
        let _ = sim.set_state(state.clone());
        let plan: Plan = if solver.starts_with("index1") {
            AdaptiveConfig::new(0.05, 1e-6).into()
        } else {
            RunConfig::new(0.05, 1e-2).into()
        };
        let _ = sim.run(plan);
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 96,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]
    #[test]
    fn random_files_with_redundant_and_near_singular_joints_never_panic(text in model()) {
        exercise(&text);
    }
}

/// The hand-made edge cases: a doubled pin, three collinear distance joints (singular), a
/// pendulum whose two rods coincide, with both redundancy policies.
#[test]
fn hand_made_redundant_and_singular_files_give_models_or_typed_errors() {
    let pendulum = "gravity = [0.0, -9.81]\n[[bodies]]\nname = \"rod\"\nmass = 1.0\ninertia = 0.0833\nposition = [0.5, 0.0, 0.0]\n";
    let pin = |n: &str| {
        format!("[[joints]]\ntype = \"revolute\"\nname = \"{n}\"\nbody_a = \"ground\"\npoint_a = [0.0, 0.0]\nbody_b = \"rod\"\npoint_b = [-0.5, 0.0]\n")
    };
    let rod = |n: &str, x: f64| {
        format!("[[joints]]\ntype = \"distance\"\nname = \"{n}\"\nbody_a = \"ground\"\npoint_a = [{x:e}, 0.0]\nbody_b = \"rod\"\npoint_b = [0.5, 0.0]\nlength = {}\n", (1.0 - x).abs().max(1e-3))
    };
    let doubled = format!("{pendulum}{}{}", pin("p1"), pin("p2"));
    let sys = ModelFile::from_toml(&doubled).unwrap().build().unwrap();
    assert_eq!(sys.n_redundant(), 2);
    assert_eq!(sys.dof(), 1);
    exercise(&doubled);
    let rejected = format!("redundant_constraints = \"reject\"\n{doubled}");
    let e = ModelFile::from_toml(&rejected)
        .unwrap()
        .build()
        .unwrap_err();
    assert!(e.to_string().contains("p2.x"), "{e}");
    // a pin and a rod along the same line from the pin: collinear, singular
    let collinear = format!("{pendulum}{}{}", pin("p1"), rod("r", -1.0));
    exercise(&collinear);
    let unknown = format!("redundant_constraints = \"sometimes\"\n{doubled}");
    assert!(ModelFile::from_toml(&unknown).is_err());
}
