//! The run loop: the step sizes it passes, its drift guard and its near-singular count.

use mbd_model::{models, Body, BodyRef, Joint, System, SystemBuilder};
use mbd_solve::{
    run, AccelerationSolver, DriftGuard, Integrator, NoObserver, RunConfig, SolveError, State,
    StepStats,
};

/// Records the step sizes it is given and moves nothing but time.
struct Recording(Vec<f64>);
impl Integrator for Recording {
    fn name(&self) -> String {
        "recording".into()
    }
    fn step(&mut self, _: &System, s: &mut State, h: f64) -> Result<StepStats, SolveError> {
        self.0.push(h);
        s.t += h;
        Ok(StepStats::default())
    }
}

#[test]
fn every_step_but_the_last_gets_the_nominal_h_bit_for_bit() {
    let sys = models::pendulum(1.0, 1.0, 0.3, 9.81).unwrap();
    for (t_end, h, steps, last) in [
        (20.0, 0.01, 2000, 0.01),
        (1.0, 1e-3, 1000, 1e-3),
        (1.005, 0.01, 101, 0.005),
    ] {
        let mut s = State::consistent(&sys, 0.0).unwrap();
        let mut rec = Recording(Vec::new());
        let stats = run(
            &mut rec,
            &sys,
            &mut s,
            RunConfig::new(t_end, h),
            &mut NoObserver,
        )
        .unwrap();
        assert_eq!(stats.steps, steps);
        let (init, tail) = rec.0.split_at(steps - 1);
        assert!(init.iter().all(|&x| x == h), "a step differs from h = {h}");
        assert!((tail[0] - last).abs() < 1e-12, "{} vs {last}", tail[0]);
        assert_eq!(s.t, t_end);
    }
}

/// Moves body 0 sideways at constant speed, ignoring the constraints: drift grows linearly.
struct Drifter(f64);
impl Integrator for Drifter {
    fn name(&self) -> String {
        "drifter".into()
    }
    fn step(&mut self, _: &System, s: &mut State, h: f64) -> Result<StepStats, SolveError> {
        s.q[0] += self.0 * h;
        s.t += h;
        Ok(StepStats::default())
    }
}

fn two_link() -> System {
    let mut b = SystemBuilder::new();
    let l1 = b.add_body(Body::new("link1").rod(1.0, 1.0).position(0.5, 0.0, 0.0));
    let l2 = b.add_body(Body::new("link2").rod(1.0, 1.0).position(1.5, 0.0, 0.0));
    b.add_joint(Joint::revolute(
        "pin1",
        BodyRef::Ground,
        [0.0, 0.0],
        l1,
        [-0.5, 0.0],
    ));
    b.add_joint(Joint::revolute("pin2", l1, [0.5, 0.0], l2, [-0.5, 0.0]));
    b.build().unwrap()
}

#[test]
fn drift_guard_stops_at_the_predicted_step_naming_the_joint() {
    let sys = two_link();
    // length scale 0.5 (lever arms), default tolerance 1e-2 -> 5e-3 m; speed 1e-2 m/s with
    // h = 0.01 adds 1e-4 m per step: the guard fires after step 51 (5.1e-3 m), at t = 0.51.
    assert_eq!(sys.length_scale(), 0.5);
    assert_eq!(DriftGuard::default().position_tol, 1e-2);
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let err = run(
        &mut Drifter(1e-2),
        &sys,
        &mut s,
        RunConfig::new(10.0, 0.01),
        &mut NoObserver,
    )
    .expect_err("the drift guard must stop the run");
    match &err {
        SolveError::ConstraintDrift {
            t,
            level,
            equation,
            joint,
            residual,
            tolerance,
        } => {
            assert!((t - 0.51).abs() < 1e-12, "{t}");
            assert_eq!(*level, "position");
            assert_eq!(equation, "pin1.x"); // body 0's x moves: pin1.x and pin2.x both see it
            assert_eq!(joint, "pin1");
            assert!((tolerance - 5e-3).abs() < 1e-17);
            assert!(*residual > 5e-3 && *residual < 5.2e-3, "{residual}");
        }
        other => panic!("expected ConstraintDrift, got {other:?}"),
    }
    assert!(err.to_string().contains("pin1"));

    // off: the run goes to its end
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let cfg = RunConfig::new(1.0, 0.01).without_drift_guard();
    let stats = run(&mut Drifter(1e-2), &sys, &mut s, cfg, &mut NoObserver).unwrap();
    assert_eq!(stats.steps, 100);

    // a looser guard fires later, a velocity guard at once (the state's Phi_q v = 1e-3)
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let g = DriftGuard {
        position_tol: 1e-1,
        velocity_tol: None,
        ..Default::default()
    };
    let cfg = RunConfig::new(10.0, 0.01).with_drift_guard(g);
    match run(&mut Drifter(1e-2), &sys, &mut s, cfg, &mut NoObserver) {
        Err(SolveError::ConstraintDrift { t, .. }) => assert!((t - 5.01).abs() < 1e-9, "{t}"),
        other => panic!("{other:?}"),
    }
    let mut s = State::consistent(&sys, 0.0).unwrap();
    s.v[0] = 1e-3;
    let g = DriftGuard {
        position_tol: 1.0,
        velocity_tol: Some(1e-4),
        ..Default::default()
    };
    let cfg = RunConfig::new(10.0, 0.01).with_drift_guard(g);
    match run(&mut Drifter(0.0), &sys, &mut s, cfg, &mut NoObserver) {
        Err(SolveError::ConstraintDrift { t, level, .. }) => {
            assert_eq!(level, "velocity");
            assert!((t - 0.01).abs() < 1e-15);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn bad_guard_settings_are_errors() {
    let sys = two_link();
    for (g, name) in [
        (
            DriftGuard {
                position_tol: 0.0,
                velocity_tol: None,
                ..Default::default()
            },
            "drift_guard.position_tol",
        ),
        (
            DriftGuard {
                position_tol: 1e-3,
                velocity_tol: Some(f64::NAN),
                ..Default::default()
            },
            "drift_guard.velocity_tol",
        ),
        (
            DriftGuard {
                branch_tol: Some(-1.0),
                ..Default::default()
            },
            "drift_guard.branch_tol",
        ),
    ] {
        let mut s = State::consistent(&sys, 0.0).unwrap();
        let cfg = RunConfig::new(1.0, 0.01).with_drift_guard(g);
        match run(&mut Drifter(0.0), &sys, &mut s, cfg, &mut NoObserver) {
            Err(SolveError::InvalidParameter { parameter, .. }) => assert_eq!(parameter, name),
            other => panic!("{other:?}"),
        }
    }
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let cfg = RunConfig::new(1.0, 0.01).with_condition_limit(-1.0);
    assert!(matches!(
        run(&mut Drifter(0.0), &sys, &mut s, cfg, &mut NoObserver),
        Err(SolveError::InvalidParameter {
            parameter: "condition_limit",
            ..
        })
    ));
}

/// Reports a scripted condition estimate per step.
struct Scripted(Vec<f64>, usize);
impl Integrator for Scripted {
    fn name(&self) -> String {
        "scripted".into()
    }
    // (counted, not stopped: a solver that keeps the constraints)
    fn keeps_constraints(&self) -> bool {
        true
    }
    fn step(&mut self, _: &System, s: &mut State, h: f64) -> Result<StepStats, SolveError> {
        let c = self.0[self.1 % self.0.len()];
        self.1 += 1;
        s.t += h;
        Ok(StepStats {
            condition: c,
            ..Default::default()
        })
    }
}

#[test]
fn near_singular_steps_are_counted_with_the_first_time() {
    let sys = two_link();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let script = vec![1.0, 1.0, 3e8, 5.0, 2e9, 1.0, 1.0, 1.0, 1.0, 1.0];
    let stats = run(
        &mut Scripted(script, 0),
        &sys,
        &mut s,
        RunConfig::new(0.1, 0.01),
        &mut NoObserver,
    )
    .unwrap();
    assert_eq!(stats.near_singular_steps, 2);
    assert!((stats.first_near_singular.unwrap() - 0.03).abs() < 1e-15);
    assert_eq!(stats.max_condition, 2e9);
    let w = stats.warning().expect("a warning");
    assert!(w.contains("2 step(s)") && w.contains("t = 0.03"), "{w}");
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let stats = run(
        &mut Scripted(vec![1.0], 0),
        &sys,
        &mut s,
        RunConfig::new(0.1, 0.01),
        &mut NoObserver,
    )
    .unwrap();
    assert_eq!(stats.near_singular_steps, 0);
    assert!(stats.warning().is_none());
}

/// Moves body 0 along x at unit speed, reversing its velocity at the step `flip` (a jump to
/// the other branch of a motion, in the velocity only), and reports `condition` every step.
struct Flipper {
    flip: usize,
    k: usize,
    condition: f64,
    keeps: bool,
}
impl Integrator for Flipper {
    fn name(&self) -> String {
        "flipper".into()
    }
    fn keeps_constraints(&self) -> bool {
        self.keeps
    }
    fn step(&mut self, _: &System, s: &mut State, h: f64) -> Result<StepStats, SolveError> {
        self.k += 1;
        s.q[0] += s.v[0] * h;
        if self.k == self.flip {
            s.v[0] = -s.v[0];
        }
        s.t += h;
        Ok(StepStats {
            condition: self.condition,
            ..Default::default()
        })
    }
}

/// A solver that does not keep the constraints stops at its first near-singular step, naming
/// the time; one that does is counted and goes on.
#[test]
fn a_solver_without_projection_stops_at_the_first_near_singular_step() {
    let sys = two_link();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    s.v.fill(0.0);
    s.v[0] = 1.0;
    let cfg = RunConfig::new(0.1, 0.01).without_drift_guard();
    for (keeps, condition) in [(false, 1e7), (true, 1e7), (false, 1e5)] {
        let mut st = s.clone();
        let mut f = Flipper {
            flip: 0,
            k: 0,
            condition,
            keeps,
        };
        let r = run(&mut f, &sys, &mut st, cfg, &mut NoObserver);
        match (keeps || condition < RunConfig::DEFAULT_CONDITION_LIMIT, r) {
            (true, Ok(stats)) => assert_eq!(stats.steps, 10),
            (false, Err(SolveError::Singular { t, what, detail })) => {
                assert!((t - 0.01).abs() < 1e-15, "{t}");
                assert!(what.contains("near rank loss"), "{what}");
                assert!(detail.contains("condition estimate 1.00e7"), "{detail}");
            }
            (_, other) => panic!("keeps {keeps}, condition {condition}: {other:?}"),
        }
    }
}

/// The branch check: a velocity that reverses within a step near a singular configuration
/// (condition above BRANCH_WATCH_CONDITION) stops the run at that step; the same reversal at a
/// well-conditioned step, or with the check off, does not.
#[test]
fn a_velocity_jump_near_a_singular_configuration_is_a_branch_error() {
    let sys = two_link();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    s.v.fill(0.0);
    s.v[0] = 1.0;
    let guard = DriftGuard {
        position_tol: 1e3,
        ..Default::default()
    };
    for (condition, guard, stops) in [
        (1e4, Some(guard), true),
        (10.0, Some(guard), false),
        (
            1e4,
            Some(DriftGuard {
                branch_tol: None,
                ..guard
            }),
            false,
        ),
    ] {
        let mut st = s.clone();
        let mut f = Flipper {
            flip: 4,
            k: 0,
            condition,
            keeps: true,
        };
        let mut cfg = RunConfig::new(0.1, 0.01).without_drift_guard();
        cfg.drift_guard = guard;
        match (stops, run(&mut f, &sys, &mut st, cfg, &mut NoObserver)) {
            (false, Ok(stats)) => assert_eq!(stats.steps, 10),
            (true, Err(SolveError::Singular { t, what, detail })) => {
                assert!((t - 0.04).abs() < 1e-15, "{t}");
                assert!(what.contains("another branch"), "{what}");
                // |q1 - q0 - h (v0 + v1) / 2| = h against h |v|: a fraction 1
                assert!(detail.contains("by 1.00 of the distance"), "{detail}");
            }
            (_, other) => panic!("condition {condition}: {other:?}"),
        }
    }
}

/// A body held by two distance joints from ground points (-1, 0) and (1, 0), at height `y`:
/// as `y -> 0` the rods become collinear and the configuration singular.
fn two_rods(y: f64) -> System {
    let mut b = SystemBuilder::new();
    let p = b.add_body(Body::new("p").mass(1.0).inertia(0.1).position(0.0, y, 0.0));
    let l = (1.0 + y * y).sqrt();
    b.add_joint(Joint::distance(
        "left",
        BodyRef::Ground,
        [-1.0, 0.0],
        p,
        [0.0, 0.0],
        l,
    ));
    b.add_joint(Joint::distance(
        "right",
        BodyRef::Ground,
        [1.0, 0.0],
        p,
        [0.0, 0.0],
        l,
    ));
    b.build().unwrap()
}

#[test]
fn condition_estimate_grows_like_the_inverse_square_distance_to_a_singular_configuration() {
    let mut prev = 0.0;
    for y in [1.0, 1e-2, 1e-4, 1e-6] {
        let sys = two_rods(y);
        let s = State::consistent(&sys, 0.0).unwrap();
        let mut acc = AccelerationSolver::new(&sys);
        let (mut a, mut l) = (vec![0.0; 3], vec![0.0; 2]);
        acc.solve(&sys, s.q.as_slice(), s.v.as_slice(), 0.0, &mut a, &mut l)
            .unwrap();
        let k = acc.condition_estimate();
        // gradients at angle 2 atan(y): sin^2 ~ 4 y^2 for small y
        let expect = 1.0 + 1.0 / (4.0 * y * y);
        assert!(
            k > 0.5 * expect.min(2.0) && k < 2.0 * expect,
            "y = {y}: {k} vs {expect}"
        );
        assert!(k > prev);
        prev = k;
    }
    assert!(prev > RunConfig::DEFAULT_CONDITION_LIMIT);
}

#[test]
fn documented_defaults_match_the_code() {
    let doc = include_str!("../../../docs/architecture.md");
    // (the value in the code, the value documented, the text that documents it)
    let documented = [
        (
            DriftGuard::default().position_tol,
            1e-2,
            "`position_tol = 1e-2`",
        ),
        (RunConfig::DEFAULT_CONDITION_LIMIT, 1e6, "default `1e6`"),
        (
            mbd_linalg::ROUNDOFF_DEPENDENT_TOL,
            1e-12,
            "`ROUNDOFF_DEPENDENT_TOL = 1e-12`",
        ),
        (mbd_linalg::PIVOTING_RATIO, 1e-8, "`PIVOTING_RATIO = 1e-8`"),
        (mbd_model::MAX_MASS_RATIO, 1e12, "`MAX_MASS_RATIO = 1e12`"),
        (
            mbd_solve::linalg::CHOLESKY_PIVOT_TOL,
            1e-14,
            "`L_jj^2 >= 1e-14 S_jj`",
        ),
        (mbd_model::MAX_INERTIA_RATIO, 1e12, "`m r^2 / J > 1e12`"),
    ];
    for (code, value, text) in documented {
        assert_eq!(code, value, "{text}: the code has {code:e}");
        assert!(doc.contains(text), "architecture.md lacks {text}");
    }
    let cfg = RunConfig::new(1.0, 0.1);
    assert_eq!(cfg.drift_guard, Some(DriftGuard::default()));
    assert_eq!(cfg.condition_limit, RunConfig::DEFAULT_CONDITION_LIMIT);
}

/// The sparse projector agrees with the dense one on a 100-link chain moved off its manifold,
/// and both stop at the round-off floor of the chain's coordinates instead of iterating to the
/// limit (a 100 m chain cannot reach |Phi| <= 1e-14).
#[test]
fn sparse_and_dense_projections_agree_and_stop_at_the_roundoff_floor() {
    use mbd_solve::{LinearSolver, ProjectionSettings, Projector};
    let sys = mbd_model::models::n_link_chain(100).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let n = sys.n_coords();
    let mut results = Vec::new();
    for linear in [LinearSolver::Dense, LinearSolver::Sparse] {
        let mut p = Projector::with_linear(&sys, ProjectionSettings::default(), linear).unwrap();
        assert_eq!(p.is_sparse(), linear == LinearSolver::Sparse);
        let mut q: Vec<f64> =
            s0.q.iter()
                .enumerate()
                .map(|(i, x)| x + 1e-6 * (i as f64).sin())
                .collect();
        let mut v: Vec<f64> = (0..n).map(|i| (0.3 * i as f64).cos()).collect();
        let stats = p.project(&sys, &mut q, &mut v, 0.0).unwrap();
        assert!(stats.iterations <= 4, "{} iterations", stats.iterations);
        let mut phid = vec![0.0; sys.n_constraints()];
        sys.phi_dot(&q, &v, 0.0, &mut phid);
        assert!(mbd_solve::linalg::max_abs(&phid) < 1e-12);
        results.push((q, v));
    }
    let dq = mbd_solve::linalg::max_abs_diff(&results[0].0, &results[1].0);
    let dv = mbd_solve::linalg::max_abs_diff(&results[0].1, &results[1].1);
    assert!(dq < 1e-12 && dv < 1e-12, "dense vs sparse: {dq:e} {dv:e}");
}

/// The drift guard skips steps only while the residuals are far below their limits
/// (`GUARD_STRIDE`, `GUARD_QUIET_RATIO`): plain RK4 on the manipulator at h = 0.01 stops at
/// exactly the first step whose residual is over the limit, found by checking every step by
/// hand.
#[test]
fn the_guard_stride_does_not_delay_the_drift_stop() {
    use mbd_solve::{ButcherTableau, Index1Options, Index1Rk, GUARD_QUIET_RATIO, GUARD_STRIDE};
    let sys = models::manipulator().unwrap();
    let h = 0.01;
    let plain = || Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default()).unwrap();
    // by hand: the first step with max_i |Phi_i| / (1e-2 scale_i) > 1
    let scales = sys.equation_scales();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = plain();
    let mut phi = vec![0.0; sys.n_constraints()];
    let mut ratios = Vec::new();
    let first = (1..=5000)
        .find(|&k| {
            rk.step(&sys, &mut s, h).unwrap();
            s.t = k as f64 * h;
            sys.phi(s.q.as_slice(), s.t, &mut phi);
            let r = phi
                .iter()
                .zip(&scales)
                .map(|(p, sc)| p.abs() / (DriftGuard::DEFAULT_POSITION_TOL * sc))
                .fold(0.0, f64::max);
            ratios.push(r);
            r > 1.0
        })
        .expect("plain RK4 at h = 0.01 drifts within 50 s");
    // the run skipped checks on this run (residuals below the quiet ratio early on)
    assert!(ratios
        .iter()
        .take(GUARD_STRIDE)
        .all(|&r| r < GUARD_QUIET_RATIO));
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = plain();
    match run(
        &mut rk,
        &sys,
        &mut s,
        RunConfig::new(50.0, h),
        &mut NoObserver,
    ) {
        Err(SolveError::ConstraintDrift { t, .. }) => {
            assert!(
                (t - first as f64 * h).abs() < 1e-9,
                "{t} vs {}",
                first as f64 * h
            )
        }
        other => panic!("expected the drift stop, got {other:?}"),
    }
}
