//! What is not a singular configuration. A flyball governor whose shaft is a 1 mm rod has
//! constraint gradients that look nearly parallel in the inverse-mass metric of the index-1
//! solve (its condition estimate is 2.5e5 at the start and passes 1e7 within a step), while
//! `Phi_q` is far from losing rank: the run checks read the estimate in the unit-free measure of
//! the geometry, so the solvers that do not keep the constraints run it, and a real
//! near-singular configuration of a spatial model still stops them. The governor's stiff
//! dampers at a step beyond an explicit solver's stability blow the state up, and a first step
//! from its regular start that misses the smooth relation of displacement and velocities is
//! too long: both are reported as such, not as a branch jump at a singular configuration.

use mbd::model::System;
use mbd::prelude::*;
use mbd::Simulation;

const GOVERNOR: &str = include_str!("../examples/models/flyball_governor.toml");

/// The example governor with its shaft a 1 mm square rod (axial moment 5e-8 kg m^2).
fn thin_governor() -> System {
    let text = GOVERNOR.replace(
        "moments = [0.0250025, 0.0250025, 5e-6]",
        "moments = [0.0250025, 0.0250025, 5e-8]",
    );
    assert_ne!(text, GOVERNOR, "the shaft's moments line moved");
    System::from_toml(&text).unwrap()
}

fn run_to(sys: &System, spec: &str, t_end: f64, h: f64) -> Result<(State, RunStats), mbd::Error> {
    let mut sim = Simulation::new(sys.clone(), spec)?;
    let stats = sim.run(RunConfig::new(t_end, h))?;
    Ok((sim.state().clone(), stats))
}

/// The error of a run of the example governor that must fail, and its message.
fn governor_failure(spec: &str, t_end: f64, h: f64) -> (mbd::Error, String) {
    let sys = System::from_toml(GOVERNOR).unwrap();
    let err = run_to(&sys, spec, t_end, h).unwrap_err();
    let text = err.to_string();
    eprintln!("{spec} at h = {h}: {text}");
    (err, text)
}

/// The unit-free condition of the thin governor's `Phi_q` is small, the index-1 solve's
/// estimate is not: the difference is the shaft's director masses alone.
#[test]
fn a_slender_shaft_only_looks_singular_in_the_mass_metric() {
    let sys = thin_governor();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let g = sys.dependence_condition(s0.q.as_slice(), 0.0).unwrap();
    let mut acc = mbd::solve::AccelerationSolver::new(&sys);
    let mut a = vec![0.0; sys.n_coords()];
    let mut lambda = vec![0.0; sys.n_constraints()];
    acc.solve_accelerations(
        &sys,
        s0.q.as_slice(),
        s0.v.as_slice(),
        0.0,
        None,
        &mut a,
        &mut lambda,
    )
    .unwrap();
    let c = acc.condition_estimate();
    eprintln!("unit-free condition {g:.3e}, index-1 estimate {c:.3e}");
    assert!(g < 1e3, "{g}");
    assert!(c > 1e3 * g, "{c} against {g}");
}

/// Plain RK4 and index-1 DOPRI5 (which stop at a near-singular step) run the thin governor
/// and agree with projected RK4; no step counts as near-singular.
#[test]
fn solvers_that_do_not_keep_the_constraints_run_a_slender_shaft() {
    let sys = thin_governor();
    let (reference, _) = run_to(&sys, "rk4-projected", 0.05, 1e-4).unwrap();
    for spec in ["rk4", "index1:dopri5"] {
        let (s, stats) = run_to(&sys, spec, 0.05, 1e-4).unwrap();
        let d = (&s.q - &reference.q).amax();
        eprintln!(
            "{spec}: max condition {:.3e}, {} near-singular steps, {d:.2e} from projected RK4",
            stats.max_condition, stats.near_singular_steps
        );
        assert_eq!(stats.near_singular_steps, 0, "{spec}");
        assert!(stats.max_condition < 1e3, "{spec}: {}", stats.max_condition);
        assert!(d < 1e-9, "{spec}: {d}");
    }
}

/// A solid block whose centre hangs from two ground points 2 m apart on distance joints of
/// length `sqrt(1 + 1e-8)`: the two gradients are 2e-4 rad from parallel (a unit-free
/// condition of about 2.5e7). Plain RK4 stops at its first step naming the joints.
#[test]
fn a_near_singular_spatial_configuration_still_stops_plain_rk4() {
    let sys = System::from_toml(
        r#"
[[spatial_bodies]]
name = "block"
mass = 1.0
moments = [0.1, 0.1, 0.1]
position = [0.0, 1e-4, 0.0]
velocity = [0.0, 0.0, 1e-4]

[[spatial_joints]]
type = "distance"
name = "left"
body_a = "ground"
point_a = [-1.0, 0.0, 0.0]
body_b = "block"
length = 1.000000005

[[spatial_joints]]
type = "distance"
name = "right"
body_a = "ground"
point_a = [1.0, 0.0, 0.0]
body_b = "block"
length = 1.000000005
"#,
    )
    .unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let g = sys.dependence_condition(s0.q.as_slice(), 0.0).unwrap();
    assert!(g > 1e6, "{g}");
    let err = run_to(&sys, "rk4", 0.01, 1e-3).unwrap_err().to_string();
    eprintln!("{err}");
    assert!(err.contains("singular configuration"), "{err}");
    assert!(err.contains("left") && err.contains("right"), "{err}");
    // the solvers that keep the constraints go on
    run_to(&sys, "rk4-projected", 0.01, 1e-3).unwrap();
}

/// On a planar model of equal masses the unit-free condition is the index-1 solve's estimate
/// itself (the same metric `M^-1` up to a factor, the same row scaling): a parallelogram
/// four-bar of three 1 kg rods approaching its flat configuration, where both grow past 1e4.
#[test]
fn on_a_planar_model_of_equal_masses_the_unit_free_condition_is_the_index1_estimate() {
    let sys = mbd::model::models::parallelogram_four_bar(1.0, 2.0, 0.5, 6.0, true).unwrap();
    let mut state = State::consistent(&sys, 0.0).unwrap();
    let mut sim = Simulation::new(sys.clone(), "rk4-projected").unwrap();
    let mut acc = mbd::solve::AccelerationSolver::new(&sys);
    let mut a = vec![0.0; sys.n_coords()];
    let mut lambda = vec![0.0; sys.n_constraints()];
    let mut largest = 0.0f64;
    for t_end in [0.1, 0.3, 0.4, 0.43, 0.44] {
        sim.run(RunConfig::new(t_end, 1e-3)).unwrap();
        state.clone_from(sim.state());
        let (q, v) = (state.q.as_slice(), state.v.as_slice());
        acc.solve_accelerations(&sys, q, v, state.t, None, &mut a, &mut lambda)
            .unwrap();
        let c = acc.condition_estimate();
        let g = sys.dependence_condition(q, state.t).unwrap();
        eprintln!("t = {t_end}: index-1 estimate {c:.6e}, unit-free {g:.6e}");
        assert!((g - c).abs() <= 1e-6 * c, "t = {t_end}: {g} against {c}");
        largest = largest.max(c);
    }
    assert!(largest > 1e4, "{largest}");
}

/// Plain RK4 on the governor at h = 1e-3, beyond its stability on the stiff dampers, blows up
/// within three steps: a drift error that says so, not a "singular configuration" read off
/// the blown-up state's condition estimate (1.4e9 there). At h = 1e-4 it runs.
#[test]
fn a_blow_up_on_stiff_dampers_is_not_a_singular_configuration() {
    let (err, text) = governor_failure("rk4", 0.05, 1e-3);
    match &err {
        mbd::Error::Solve(SolveError::ConstraintDrift {
            residual,
            tolerance,
            joint,
            ..
        }) => {
            assert!(*residual > mbd::solve::BLOWUP_RATIO * tolerance, "{text}");
            assert!(joint.starts_with("arm"), "{joint}");
        }
        other => panic!("expected a drift error, got {other:?}"),
    }
    assert!(
        text.contains("blew up") && text.contains("smaller step"),
        "{text}"
    );
    assert!(!text.contains("singular"), "{text}");
    run_to(&System::from_toml(GOVERNOR).unwrap(), "rk4", 0.05, 1e-4).unwrap();
}

/// Projected RK4 on the governor at h = 0.01, a hundred times its stable step: the first step
/// from the regular initial configuration (unit-free condition 51) misses the smooth relation
/// between displacement and velocities, which the branch check used to report as a jump onto
/// another branch at a singular configuration. The run now fails on what the step did to the
/// state, with the advice of a too-long step.
#[test]
fn a_too_long_first_step_from_a_regular_start_is_not_a_branch_jump() {
    let (err, text) = governor_failure("rk4-projected", 0.2, 1e-2);
    assert!(
        !matches!(err, mbd::Error::Solve(SolveError::Singular { .. })),
        "{text}"
    );
    assert!(
        text.contains("too long") || text.contains("smaller step"),
        "{text}"
    );
}
