//! A parallelogram four-bar driven or swinging through its flat configuration, where `Phi_q`
//! loses rank: every run either passes with its constraints kept or stops with a typed error;
//! none goes on silently wrong. The index-1 condition estimate sees the passage.

use mbd::model::models::parallelogram_four_bar;
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{run, NoObserver, RunConfig, RunStats, SolveError, State};

fn rk4(projected: bool, driven: bool, h: f64, t_end: f64) -> (Result<RunStats, SolveError>, State) {
    // crank 1 m, ground 2 m, from 0.5 rad at 6 rad/s: the flat configuration (crank angle pi)
    // is passed at about t = 0.44 s
    let sys = parallelogram_four_bar(1.0, 2.0, 0.5, 6.0, driven).unwrap();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let opts = if projected {
        Rk4Options::projected()
    } else {
        Rk4Options::plain()
    };
    let mut rk = Rk4::new(&sys, opts).unwrap();
    let r = run(
        &mut rk,
        &sys,
        &mut s,
        RunConfig::new(t_end, h),
        &mut NoObserver,
    );
    (r, s)
}

#[test]
fn the_condition_estimate_sees_the_flat_configuration() {
    for driven in [true, false] {
        let (r, _) = rk4(true, driven, 1e-3, 0.3);
        let before = r.unwrap();
        let (r, _) = rk4(true, driven, 1e-3, 0.8);
        let through = r.unwrap();
        eprintln!(
            "driven {driven}: before the passage max condition {:.3e}; through it {:.3e}, {} near-singular steps",
            before.max_condition, through.max_condition, through.near_singular_steps
        );
        assert!(before.max_condition < 1e3, "{}", before.max_condition);
        assert!(
            through.max_condition > 1e3 * before.max_condition,
            "{} vs {}",
            through.max_condition,
            before.max_condition
        );
    }
}

#[test]
fn plain_rk4_through_the_flat_configuration_stops_loudly_or_stays_on_the_manifold() {
    for (driven, h) in [(false, 1e-4), (false, 1e-3), (true, 1e-4)] {
        let (r, s) = rk4(false, driven, h, 1.5);
        match &r {
            Ok(stats) => {
                // passing is fine only with the constraints kept (the drift guard would have
                // stopped the run otherwise) and on the parallelogram branch: the coupler
                // translates, its angle stays 0 (to plain RK4's drift; the crossed branch would
                // turn it by O(1))
                eprintln!("driven {driven}, h = {h}: passed, {stats:?}");
                assert!(s.q[5].abs() < 1e-2, "coupler angle {}", s.q[5]);
                if h <= 1e-4 {
                    // a step lands next to the singular point: the run says so
                    let w = stats.warning().expect("a near-singular warning");
                    let t0 = stats.first_near_singular.unwrap();
                    // driven: crank angle pi at t = 0.44 s; free: gravity slows it to 0.49 s
                    assert!(t0 > 0.42 && t0 < 0.5, "{w}");
                }
            }
            Err(e) => {
                eprintln!("driven {driven}, h = {h}: {e}");
                assert!(
                    matches!(
                        e,
                        SolveError::ConstraintDrift { .. } | SolveError::Singular { .. }
                    ),
                    "{e:?}"
                );
            }
        }
    }
}

/// Every solver of the registry on a 2-loop N-four-bar driven through five flat configurations
/// (3 s), at two step sizes (tolerances): a run that reaches the end has the last crank's tip
/// on the exact motion; a run that stops, stops with the typed singular error (or the model is
/// refused at construction). This fails if any solver reaches the end on another branch.
#[test]
fn no_solver_reaches_the_end_on_another_branch() {
    use mbd::model::models::{ClosedLoop, CrankMotion};
    use mbd::prelude::*;
    let cl = ClosedLoop::n_four_bar(2, 0.4, 1.0).unwrap();
    let (angle, speed, t_end) = (1.0, 6.0, 3.0);
    let want = cl.tracked_point(CrankMotion::driven(angle, speed).unwrap().at(t_end)[0]);
    let mut reached = 0;
    for (_, v) in mbd::registry().variants() {
        let hs = if v.spec.starts_with("index1") {
            [1e-6, 1e-8]
        } else {
            [1e-2, 1e-3]
        };
        for h in hs {
            let sys = cl.system(angle, speed, true).unwrap();
            let body = sys.body_handle(&cl.tracked_body()).unwrap().index();
            let mut sim = match Simulation::new(sys, v.spec) {
                Ok(s) => s,
                Err(e) => {
                    // only the structural refusal of the optimisation-based solver
                    assert!(
                        e.to_string().contains("no degree of freedom"),
                        "{}: {e}",
                        v.spec
                    );
                    continue;
                }
            };
            let plan: Plan = if v.spec.starts_with("index1") {
                AdaptiveConfig::new(t_end, h).into()
            } else {
                RunConfig::new(t_end, h).into()
            };
            match sim.run(plan) {
                Ok(_) => {
                    let q = &sim.state().q;
                    let (x, y, a) = (q[3 * body], q[3 * body + 1], q[3 * body + 2]);
                    let tip = [x + 0.2 * a.cos(), y + 0.2 * a.sin()];
                    let err = (tip[0] - want[0]).hypot(tip[1] - want[1]);
                    assert!(
                        err < 1e-9,
                        "{} h = {h:e}: reached the end {err:e} off",
                        v.spec
                    );
                    reached += 1;
                }
                Err(mbd::Error::Solve(SolveError::Singular { .. })) => {}
                Err(e) => panic!(
                    "{} h = {h:e}: stopped with a non-singular error: {e}",
                    v.spec
                ),
            }
        }
    }
    // the projecting and symplectic solvers pass
    assert!(reached >= 8, "{reached} runs reached the end");
}

/// Plain RK4 stops at the four-bar's first flat configuration (t = 0.44 s) with the typed
/// error naming the time, the rank deficiency and the loop's joints.
#[test]
fn the_singular_stop_names_time_rank_deficiency_and_joints() {
    let (r, _) = rk4(false, true, 1e-4, 1.0);
    match r {
        Err(SolveError::Singular { t, detail, .. }) => {
            assert!((0.4..0.45).contains(&t), "{t}");
            assert!(detail.contains("rank deficiency 1"), "{detail}");
            for joint in ["A0", "B0"] {
                assert!(detail.contains(joint), "{detail}");
            }
        }
        other => panic!("expected the singular stop, got {other:?}"),
    }
}

/// Plain RK4 at h = 1e-2 without the acceleration bridge passes the free mechanism's flat
/// configurations without landing near enough to stop, but its drift grows from a passage (at
/// t = 1.41) until the guard stops it (t = 1.91): that is reported as the singular
/// configuration it is, naming the passage. With the bridge (the default) the run ends in the
/// typed singular error as well.
#[test]
fn drift_grown_from_a_singular_passage_is_the_singular_error() {
    use mbd::model::models::ClosedLoop;
    let cl = ClosedLoop::n_four_bar(2, 0.4, 1.0).unwrap();
    let sys = cl.system(1.0, 6.0, false).unwrap();
    let unbridged = Rk4Options {
        bridge: false,
        ..Rk4Options::plain()
    };
    for opts in [unbridged, Rk4Options::plain()] {
        let mut s = State::consistent(&sys, 0.0).unwrap();
        let mut rk = Rk4::new(&sys, opts.clone()).unwrap();
        let r = run(
            &mut rk,
            &sys,
            &mut s,
            RunConfig::new(3.0, 1e-2),
            &mut NoObserver,
        );
        match r {
            Err(SolveError::Singular { t, what, detail }) if !opts.bridge => {
                assert!((1.5..2.5).contains(&t), "{t}");
                assert!(what.contains("drift"), "{what}");
                assert!(
                    detail.contains("passed near a singular configuration at t = "),
                    "{detail}"
                );
                assert!(detail.contains("position residual"), "{detail}");
            }
            Err(SolveError::Singular { t, .. }) => assert!((0.3..3.0).contains(&t), "{t}"),
            other => panic!(
                "expected the singular error (bridge {}), got {other:?}",
                opts.bridge
            ),
        }
    }
}

/// Steps `spec` on `sys` with `h` up to `t_end` by the integrator itself, through the run
/// loop's grid times but without its stepping over a failed step: the first error.
fn step_until_error(sys: &mbd::model::System, spec: &str, h: f64, t_end: f64) -> SolveError {
    let mut integ = mbd::registry().parse(spec).unwrap().build(sys).unwrap();
    let mut s = State::consistent(sys, 0.0).unwrap();
    // the times of the run loop's grid
    for k in 1..=(t_end / h).round() as usize {
        if let Err(e) = integ.step(sys, &mut s, h) {
            return e;
        }
        s.t = k as f64 * h;
    }
    panic!("{spec}: no error up to t = {t_end}");
}

/// The (2,2) modified-Lagrangian scheme at h = 1e-2 fails on the step that crosses a flat
/// configuration at t = 7.24 (it starts 0.046 rad before it, where the preadjustment's
/// projected metric degenerates): the configurations along the step, not only its start, are
/// checked for rank loss, so the error is the typed singular one naming the loops' equations.
/// The run stops there too: a Newton failure near a singular configuration is not stepped
/// over (docs/singular.md, section 5).
#[test]
fn a_newton_failure_on_a_step_across_rank_loss_is_the_singular_error() {
    use mbd::model::models::ClosedLoop;
    use mbd::prelude::*;
    let cl = ClosedLoop::n_four_bar(2, 0.4, 1.0).unwrap();
    let sys = cl.system(1.0, 6.0, false).unwrap();
    match step_until_error(&sys, "symplectic:2:modified", 1e-2, 7.3) {
        SolveError::Singular { t, detail, .. } => {
            assert!((7.2..7.3).contains(&t), "{t}");
            assert!(detail.contains("rank deficiency 2"), "{detail}");
            assert!(detail.contains("G1.x"), "{detail}");
        }
        other => panic!("expected the singular error, got {other:?}"),
    }
    let mut sim = Simulation::new(sys, "symplectic:2:modified").unwrap();
    match sim.run(RunConfig::new(7.3, 1e-2)) {
        Err(mbd::Error::Solve(e @ SolveError::Singular { .. })) => {
            assert!(e.is_newton_near_rank_loss(), "{e}")
        }
        other => panic!("expected the singular error from the run, got {other:?}"),
    }
}

/// Symplectic (2,2) on the driven 10-four-bar at h = 1e-3 fails 2.2 steps before the flat
/// configuration at t = 0.357 (the crank 0.013 rad from it, no equation yet within 1e-2 of
/// dependence along the step itself): configurations a few steps either side of a failing
/// step are checked too, so the error is the typed singular one, not a Newton failure
/// advising a shorter step; the run stops with it (not stepped over).
#[test]
fn a_newton_failure_steps_before_rank_loss_is_the_singular_error() {
    use mbd::model::models::ClosedLoop;
    use mbd::prelude::*;
    let cl = ClosedLoop::n_four_bar(10, 0.4, 1.0).unwrap();
    let sys = cl.system(1.0, 6.0, true).unwrap();
    match step_until_error(&sys, "symplectic:2", 1e-3, 0.4) {
        SolveError::Singular { t, detail, .. } => {
            assert!((0.35..0.357).contains(&t), "{t}");
            assert!(detail.contains("rank deficiency"), "{detail}");
        }
        other => panic!("expected the singular error, got {other:?}"),
    }
    let mut sim = Simulation::new(sys, "symplectic:2").unwrap();
    match sim.run(RunConfig::new(0.4, 1e-3)) {
        Err(mbd::Error::Solve(SolveError::Singular { t, .. })) => {
            assert!((0.35..0.357).contains(&t), "{t}")
        }
        other => panic!("expected the singular error from the run, got {other:?}"),
    }
}

/// Symplectic (1,1) on the free 10-four-bar (sparse path, whose stage factorisation is kept
/// across steps) at h = 1e-3 reaches t = 9.2: near a flat configuration a kept factorisation
/// can stall Newton at round-off short of the solution (it stopped at t = 9.115 with
/// "Newton failed ... residual 1.8e-6 after 5 iterations"), where a new Jacobian converges.
#[test]
fn a_kept_stage_factorisation_is_refreshed_where_newton_stalls() {
    use mbd::model::models::ClosedLoop;
    use mbd::prelude::*;
    let cl = ClosedLoop::n_four_bar(10, 0.4, 1.0).unwrap();
    let sys = cl.system(1.0, 6.0, false).unwrap();
    assert!(sys.n_constraints() > mbd::solve::SPARSE_THRESHOLD);
    let mut sim = Simulation::new(sys, "symplectic:1").unwrap();
    let stats = sim.run(RunConfig::new(9.2, 1e-3)).unwrap();
    assert!((sim.state().t - 9.2).abs() < 1e-9, "{stats:?}");
}

/// Index-1 DOPRI5 stopped by the run guard near the parallelogram four-bar's flat
/// configuration (condition estimate just above the limit) names the nearest equations and
/// their loop, also where none is within 1e-2 of dependence once the equations are scaled to
/// unit norm (the condition estimate carries their scaling): the report then tries wider
/// angles. (The Python package's error test expects `B0` there.)
#[test]
fn the_run_guard_names_the_loop_it_stops_at() {
    use mbd::prelude::*;
    let sys = mbd::model::models::parallelogram_four_bar(1.0, 2.0, 0.5, 6.0, false).unwrap();
    let mut sim = Simulation::new(sys, "index1:dopri5").unwrap();
    match sim.run(RunConfig::new(1.5, 1e-3)) {
        Err(mbd::Error::Solve(SolveError::Singular { t, detail, .. })) => {
            assert!((1.0..1.5).contains(&t), "{t}");
            assert!(
                detail.contains("B0") && detail.contains("of dependence"),
                "{detail}"
            );
        }
        other => panic!("expected the singular stop, got {other:?}"),
    }
}

/// An isosceles slider-crank (crank and rod 0.5 m) driven at 2 pi rad/s from 0 reaches its dead
/// points, where the rod folds onto the crank and `Phi_q` loses a rank, at t = 0.25 and 0.75 s:
/// on the grid of h = 1e-3, so a step lands exactly on them. Every solver that keeps the
/// constraints steps over both (three steps that straddle each, `RunStats::stepped_over`) and
/// stays on the slider's motion `x = 2 r cos(theta)` to 1e-9, where before every one of them
/// stopped with the singular error there; the grid times at the dead points themselves have no
/// state where the step onto them failed (`skipped_outputs`). Off the grid (h = 1.1e-3) nothing
/// is stepped over. Plain RK4, which does not keep the constraints, still stops there.
#[test]
fn a_step_onto_a_singular_configuration_is_stepped_over() {
    use mbd::model::models::{slider_crank_with, SliderCrankParams};
    use mbd::prelude::*;
    let (r, speed) = (0.5, std::f64::consts::TAU);
    let sys = slider_crank_with(&SliderCrankParams {
        crank: r,
        rod: r,
        angle: 0.0,
        speed,
        driven: true,
    })
    .unwrap();
    let slider = sys.body_handle("slider").unwrap().index();
    for spec in [
        "rk4-projected",
        "symplectic:1",
        "symplectic:2",
        "tangent:rk4",
        "tangent:dopri5",
    ] {
        for (h, over) in [(1e-3, 2), (1.1e-3, 0)] {
            let mut sim = Simulation::new(sys.clone(), spec).unwrap();
            let mut rec = Recorder::new();
            let stats = sim
                .run_observed(RunConfig::new(1.0, h), &mut rec)
                .unwrap_or_else(|e| panic!("{spec} at h = {h}: {e}"));
            assert_eq!(stats.stepped_over, over, "{spec} at h = {h}");
            assert!(stats.skipped_outputs <= over, "{spec} at h = {h}");
            let steps = (1.0 / h).ceil() as usize;
            assert_eq!(rec.t.len(), steps + 1 - stats.skipped_outputs, "{spec}");
            let worst = rec
                .q
                .iter()
                .zip(&rec.t)
                .map(|(q, &t)| (q[3 * slider] - 2.0 * r * (speed * t).cos()).abs())
                .fold(0.0f64, f64::max);
            assert!(worst < 1e-9, "{spec} at h = {h}: slider {worst:e} off");
            if over > 0 {
                let first = stats.first_stepped_over.unwrap();
                assert!((first - 0.25).abs() < 2e-3, "{spec}: first at {first}");
                assert!(stats.warning().unwrap().contains("stepped over"), "{spec}");
            }
        }
    }
    let mut sim = Simulation::new(sys, "rk4").unwrap();
    match sim.run(RunConfig::new(1.0, 1e-3)) {
        Err(mbd::Error::Solve(SolveError::Singular { t, .. })) => assert!((t - 0.25).abs() < 2e-3),
        other => panic!("plain RK4: {other:?}"),
    }
}
