//! The solver registry is what every front end reads: spec strings round-trip, bad ones say
//! what to use, and every variant is what its solver says it is.

use mbd::prelude::*;

#[test]
fn spec_strings_round_trip_and_bad_ones_say_what_to_use() {
    for name in [
        "rk4",
        "rk4-projected",
        "symplectic:2",
        "symplectic:3:gamma=0.5",
        "symplectic:1:modified",
        "index1:dopri5",
        "tangent:rk4",
        "tangent:dopri5",
        "tangent:rk4:euclidean",
        "tangent:dopri5:euclidean",
        "firefly-gauss",
        "firefly-gauss:polish:seed=7",
    ] {
        let spec = mbd::registry().parse(name).expect(name);
        assert_eq!(spec.to_string(), name);
        assert_eq!(mbd::registry().parse(&spec.to_string()).expect(name), spec);
    }
    // every listed variant parses to itself
    for (_, v) in mbd::registry().variants() {
        assert_eq!(mbd::registry().parse(v.spec).expect(v.spec).spec(), v.spec);
    }
    let bad = [
        ("rk5", "unknown solver 'rk5'"),
        ("symplectic:x", "S must be a whole number"),
        ("symplectic:9", "S must be a whole number"),
        ("symplectic:2:gamma=abc", "gamma must be a finite number"),
        ("symplectic:2:gamma=inf", "gamma must be a finite number"),
        ("symplectic:3:modified", "needs S = 1 or 2"),
        ("symplectic:2:modified:gamma=1", "no gamma"),
        ("symplectic:2:foo", "unknown option 'foo'"),
        ("symplectic:2:gamma=1:gamma=2", "'gamma' is given twice"),
        (
            "symplectic:1:modified:modified",
            "'modified' is given twice",
        ),
        ("rk4:fast", "takes no options"),
        ("tangent:rk5", "tangent:rk4 or tangent:dopri5"),
        ("tangent:rk4:metric", "unknown option 'metric'"),
        ("tangent:rk4:euclidean:x", "at most one option"),
        ("index1:rk4", "index1:dopri5"),
        ("firefly-gauss:seed=-1", "seed must be a whole number"),
        ("firefly-gauss:polish:polish", "given twice"),
    ];
    for (spec, want) in bad {
        let e = mbd::registry().parse(spec).unwrap_err().to_string();
        assert!(e.contains(want), "{spec}: {e}");
    }
    // an unknown name lists every family's syntax
    let e = mbd::registry().parse("rk5").unwrap_err().to_string();
    for f in mbd::registry().families() {
        assert!(e.contains(f.syntax), "{e}");
    }
}

#[test]
fn the_registry_lists_what_the_solvers_say() {
    let sys = models::manipulator().expect("model");
    for (_, v) in mbd::registry().variants() {
        let spec = mbd::registry().parse(v.spec).expect(v.spec);
        let mut integ = spec.build(&sys).expect(v.spec);
        assert_eq!(integ.order(), Some(v.order), "{}", v.spec);
        assert_eq!(integ.as_adaptive().is_some(), v.adaptive, "{}", v.spec);
    }
}

#[test]
fn modified_lagrangian_refusal_names_the_cause() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/models/slider_crank_spring.toml"
    );
    let sys = System::from_path(path).expect("model");
    assert!(!sys.is_conservative());
    let e = Simulation::new(sys, "symplectic:2:modified")
        .unwrap_err()
        .to_string();
    assert!(e.contains("conservative"), "{e}");
}

/// A registry entry that names the equation count above which it refuses spatial models names
/// the limit the refusal uses (`mbd_solve::DENSE_SPATIAL_LIMIT`), and the refusal happens
/// there: a spatial chain of more equations is refused, one of 108 (above the sparse threshold,
/// so on the dense path) is taken.
#[test]
fn refusals_of_large_spatial_models_name_the_dense_limit() {
    let limit = mbd::solve::DENSE_SPATIAL_LIMIT;
    let large = mbd::model::models::spatial_chain(limit / 9 + 1).unwrap();
    let small = mbd::model::models::spatial_chain(12).unwrap();
    assert!(small.n_constraints() > mbd::solve::SPARSE_THRESHOLD);
    let mut named = 0;
    for (_, v) in mbd::registry().variants() {
        let Some(rest) = v.refuses.split("spatial models above ").nth(1) else {
            continue;
        };
        named += 1;
        let n: usize = rest
            .split_whitespace()
            .next()
            .and_then(|x| x.parse().ok())
            .unwrap_or_else(|| panic!("{}: '{}'", v.spec, v.refuses));
        assert_eq!(n, limit, "{}", v.spec);
        assert!(
            mbd::Simulation::new(small.clone(), v.spec).is_ok(),
            "{}",
            v.spec
        );
        let e = mbd::Simulation::new(large.clone(), v.spec)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("{} equations", large.n_constraints())),
            "{}: {e}",
            v.spec
        );
    }
    assert!(named >= 2, "{named}");
}

/// The symplectic scheme runs a spatial model past the dense limit with redundant equations on
/// its sparse path (a ball joint given twice: three of them, which the stage Jacobian leaves
/// out where the body-eliminated Schur complement finds them dependent): 20 steps of (2,2) at
/// h = 1e-3 end within 1e-10 of the same chain without the repeated joint, the constraints
/// at round-off.
#[test]
fn symplectic_runs_large_spatial_models_with_redundant_equations() {
    let limit = mbd::solve::DENSE_SPATIAL_LIMIT;
    let chain = mbd::model::models::spatial_chain(limit / 9 + 1).unwrap();
    let mut file = chain.to_model_file();
    let mut twice = file.spatial_joints[0].clone();
    twice.name = "again".into();
    file.spatial_joints.push(twice);
    let redundant = file.build().unwrap();
    assert_eq!(redundant.n_redundant(), 3);
    assert!(redundant.n_constraints() > limit);
    let end = |sys: &System| {
        let mut sim = mbd::Simulation::new(sys.clone(), "symplectic:2").unwrap();
        sim.run(RunConfig::new(0.02, 1e-3)).unwrap();
        sim.state().clone()
    };
    let (a, b) = (end(&chain), end(&redundant));
    let d = (&a.q - &b.q).amax().max((&a.v - &b.v).amax());
    let mut phi = vec![0.0; redundant.n_constraints()];
    redundant.phi(b.q.as_slice(), b.t, &mut phi);
    let worst = phi.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    eprintln!("repeated ball joint: {d:.1e} from the plain chain, |Phi| {worst:.1e}");
    assert!(d < 1e-10, "{d:e}");
    assert!(worst < 1e-12, "{worst:e}");
}
