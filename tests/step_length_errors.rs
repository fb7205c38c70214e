//! A step far too long for a mechanism is a Newton failure whose advice (a smaller step) is
//! right, not a "singular configuration", "redundant constraints" or an "unsupported model":
//! the mechanisms below are regular where these steps fail, and the same solvers run them at a
//! smaller step.

use mbd::model::models::{andrews_squeezer, sprung_rod};
use mbd::model::System;
use mbd::prelude::*;
use mbd::solve::SolveError;

/// Runs `spec` on `sys` to `t_end` with fixed steps `h`.
fn run(sys: &System, spec: &str, t_end: f64, h: f64) -> Result<(), mbd::Error> {
    let mut sim = Simulation::new(sys.clone(), spec)?;
    sim.run(RunConfig::new(t_end, h))?;
    Ok(())
}

/// The example model file `examples/models/<name>`.
fn example(name: &str) -> System {
    System::from_path(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/models")
            .join(name),
    )
    .unwrap()
}

/// Asserts that a run failed with Newton's error (and says so).
fn assert_newton(r: Result<(), mbd::Error>, what: &str) {
    match r {
        Err(mbd::Error::Solve(SolveError::Newton { context, .. })) => {
            assert!(
                context.contains("a smaller h may converge"),
                "{what}: {context}"
            );
        }
        other => panic!("{what}: expected a Newton failure, got {other:?}"),
    }
}

/// Andrews' squeezer at h = 0.05 (the crank turns through about 8 rad in one step): the
/// symplectic stage Jacobian becomes singular at a Newton iterate far from any solution. It was
/// reported as "no pivot ... (redundant constraints or a singular configuration)"; at
/// h = 1e-5 the same scheme reaches the benchmark's reference (`tests/squeezer.rs`).
#[test]
fn the_squeezer_at_a_too_long_step() {
    let sys = andrews_squeezer().unwrap();
    for spec in ["symplectic:2", "symplectic:2:modified"] {
        assert_newton(run(&sys, spec, 0.1, 0.05), spec);
    }
    run(&sys, "symplectic:2", 2e-3, 1e-5).unwrap();
}

/// A rod on an undamped spring (`models::sprung_rod`) at h = 0.3: the (2,2) scheme stalls a
/// few digits above its tolerance at t = 0, at a regular configuration. It was reported as a
/// singular configuration "where a smaller h does not help"; a smaller h does help (h = 0.05
/// runs the same second).
#[test]
fn a_stall_at_a_regular_configuration_advises_a_smaller_step() {
    let sys = sprung_rod([0.05, 0.05, 0.002]).unwrap();
    assert_newton(
        run(&sys, "symplectic:2", 1.0, 0.3),
        "symplectic:2 at h = 0.3",
    );
    run(&sys, "symplectic:2", 1.0, 0.05).unwrap();
}

/// The heavy top file's model at h = 0.3: FA-DAE finds no feasible candidate in its search
/// box (its predictor leaves the reach of the dependent coordinates). That was an
/// "unsupported model" error pointing at `mbd solvers`; the same solver runs it at h = 0.05.
#[test]
fn fa_dae_without_a_feasible_candidate_advises_a_smaller_step() {
    let sys = example("heavy_top.toml");
    assert_newton(
        run(&sys, "firefly-gauss", 0.6, 0.3),
        "firefly-gauss at h = 0.3",
    );
    run(&sys, "firefly-gauss", 0.6, 0.05).unwrap();
}

/// The spatial slider-crank's file at h = 0.3 with projected RK4: a stage point of a step that
/// long has its crank's directors nearly dependent. That was a "singular spatial body" error
/// with the advice for singular configurations; on the constraints the directors are
/// orthonormal, so the error is now the one that says the coordinates are far off them (and
/// the CLI's advice is a smaller step). The same solver runs the model at h = 0.01.
#[test]
fn dependent_directors_are_coordinates_far_off_the_constraints() {
    let sys = example("spatial_slider_crank.toml");
    match run(&sys, "rk4-projected", 1.0, 0.3) {
        Err(mbd::Error::Solve(SolveError::DegenerateDirectors { body, .. })) => {
            assert_eq!(body, "crank");
        }
        other => panic!("expected dependent directors, got {other:?}"),
    }
    run(&sys, "rk4-projected", 1.0, 0.01).unwrap();
}
