//! Singular configurations: a parallelogram four-bar driven through its flat configurations
//! (all links collinear, `Phi_q` loses rank and the parallelogram branch crosses the crossed
//! one). The tangent solver passes them on the branch it is on (the chord iteration, whose
//! matrix is `Df` at a nearly singular centre, hands over to Newton with the exact matrix), or,
//! when a step lands exactly on one, stops at once with a typed error naming time, rank and
//! joints (which the run loop then steps over).

mod common;

use common::{state_error, ResidualWatch};
use mbd_model::{models, System};
use mbd_solve::{
    reference_trajectory, run, run_adaptive, AdaptiveConfig, ButcherTableau, Flow, Index1Options,
    Index1Rk, Integrator, NoObserver, Observer, ProjectionSettings, RunConfig, SolveError, State,
};
use mbd_tangent::{NewtonSettings, TangentOptions, TangentRk};
use nalgebra::DVector;

/// Crank 0.4 m, ground and coupler 1 m, released at 1 rad with 6 rad/s: the crank turns
/// through the flat configurations at about t = 0.34, 0.63, 1.11, 1.39 and 1.87 s.
fn free_four_bar() -> System {
    models::parallelogram_four_bar(0.4, 1.0, 1.0, 6.0, false).expect("model")
}

/// Watches the parallelogram branch (coupler horizontal, rocker parallel to the crank) and
/// the constraints at every sample; records the crank angles seen.
#[derive(Default)]
struct BranchWatch {
    res: ResidualWatch,
    /// Largest `|coupler angle|` and `|rocker angle - crank angle|`.
    off_branch: f64,
    min_crank: f64,
    max_crank: f64,
}

impl Observer for BranchWatch {
    fn observe(&mut self, sys: &System, s: &State, step: usize) -> Result<Flow, SolveError> {
        self.res.observe(sys, s, step)?;
        let (crank, coupler, rocker) = (s.q[2], s.q[5], s.q[8]);
        self.off_branch = self
            .off_branch
            .max(coupler.abs())
            .max((rocker - crank).abs());
        if step == 0 {
            self.min_crank = crank;
            self.max_crank = crank;
        }
        self.min_crank = self.min_crank.min(crank);
        self.max_crank = self.max_crank.max(crank);
        Ok(Flow::Continue)
    }
}

fn projected_rk4(sys: &System, s0: &State, t_end: f64, h: f64) -> State {
    let opts = Index1Options {
        projection: Some(ProjectionSettings::default()),
        ..Default::default()
    };
    let mut p = Index1Rk::new(sys, ButcherTableau::rk4(), opts).expect("projected RK4");
    let mut s = s0.clone();
    run(
        &mut p,
        sys,
        &mut s,
        RunConfig::new(t_end, h),
        &mut NoObserver,
    )
    .expect("projected RK4");
    s
}

#[test]
fn tangent_rk4_passes_flat_configurations_on_the_parallelogram_branch() {
    let sys = free_four_bar();
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let (t_end, h) = (2.0, 1e-3);
    let r = reference_trajectory(&sys, &s0, t_end, 1, 16_000, ButcherTableau::dopri5())
        .expect("reference");
    let proj = projected_rk4(&sys, &s0, t_end, h);
    let mut s = s0.clone();
    let mut rk = TangentRk::rk4(&sys).expect("solver");
    let mut watch = BranchWatch::default();
    run(&mut rk, &sys, &mut s, RunConfig::new(t_end, h), &mut watch).expect("tangent RK4 run");
    let st = *rk.stats();
    let e_ref = state_error(&s, &r.q[1], &r.v[1]);
    let e_proj = state_error(&s, proj.q.as_slice(), proj.v.as_slice());
    let e_proj_ref = state_error(&proj, &r.q[1], &r.v[1]);
    println!(
        "crank {:.2} .. {:.2} rad; tangent - ref {e_ref:.2e}, tangent - projected {e_proj:.2e}, \
         projected - ref {e_proj_ref:.2e}; off branch {:.1e}; max |Phi| {:.1e}, |Phidot| {:.1e}; \
         {st:?}",
        watch.min_crank, watch.max_crank, watch.off_branch, watch.res.max_phi, watch.res.max_phidot
    );
    // the crank turned through 0 (mod 2 pi) and pi several times
    assert!(watch.max_crank - watch.min_crank > 3.0 * std::f64::consts::PI);
    // the flat configurations needed the exact Newton fallback, and nothing was halved
    assert!(st.exact_maps > 0, "{st:?}");
    assert_eq!(st.halvings, 0, "{st:?}");
    assert_eq!(st.chart_failures, 0, "{st:?}");
    // on the parallelogram branch all the time, constraints at tolerance
    assert!(watch.off_branch < 1e-10, "{}", watch.off_branch);
    assert!(watch.res.max_phi <= 1e-12 && watch.res.max_phidot <= 1e-12);
    // the same state as projected RK4 and the reference, to RK4's accuracy at this step
    assert!(e_ref < 1e-7, "{e_ref}");
    assert!(e_proj < 1e-7, "{e_proj}");
}

#[test]
fn driven_crank_passes_flat_configurations() {
    // no degree of freedom: the driver fixes the crank, the loop closes on the branch
    let sys = models::parallelogram_four_bar(0.4, 1.0, 1.0, 6.0, true).expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let (t_end, h) = (2.0, 1e-3);
    let proj = projected_rk4(&sys, &s0, t_end, h);
    let mut s = s0.clone();
    let mut rk = TangentRk::rk4(&sys).expect("solver");
    let mut watch = BranchWatch::default();
    run(&mut rk, &sys, &mut s, RunConfig::new(t_end, h), &mut watch).expect("tangent RK4 run");
    let st = *rk.stats();
    let e_proj = state_error(&s, proj.q.as_slice(), proj.v.as_slice());
    println!(
        "tangent - projected {e_proj:.2e}; off branch {:.1e}; {st:?}",
        watch.off_branch
    );
    assert!(st.exact_maps > 0 && st.halvings == 0, "{st:?}");
    assert!(watch.off_branch < 1e-10, "{}", watch.off_branch);
    assert!(watch.res.max_phi <= 1e-12 && watch.res.max_phidot <= 1e-12);
    // the driven crank angle is exact: theta = 1 + 6 t
    assert!((s.q[2] - 13.0).abs() < 1e-12, "{}", s.q[2]);
    assert!(e_proj < 1e-9, "{e_proj}");
}

#[test]
fn without_the_exact_newton_fallback_a_passage_fails() {
    // the behaviour before the fallback (and the proof that the test above exercises it): the
    // chord iteration alone cannot cross a flat configuration, and halving helps only by luck
    // (the half steps' centres must straddle the crossing at a distance larger than the step)
    let sys = free_four_bar();
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let opts = TangentOptions {
        newton: NewtonSettings {
            fallback_change: 0.0,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut rk = TangentRk::new(&sys, ButcherTableau::rk4(), opts).expect("solver");
    let mut s = s0.clone();
    let e = run(
        &mut rk,
        &sys,
        &mut s,
        RunConfig::new(2.0, 1e-3),
        &mut NoObserver,
    )
    .unwrap_err();
    println!("{e}; {:?}", rk.stats());
    match e {
        // at the first or second passage (t = 0.34, 0.63), after halvings: a chart failure
        // near rank loss, reported as the singular configuration with the Newton failure
        SolveError::Singular { t, ref detail, .. } => {
            assert!((0.3..0.7).contains(&t), "{t}");
            assert!(detail.contains("Newton failed"), "{detail}");
        }
        other => panic!("expected a chart failure, got {other}"),
    }
    assert!(rk.stats().halvings > 0);
}

#[test]
fn step_ending_exactly_on_a_flat_configuration_is_a_typed_error_at_once() {
    // crank driven from pi/2 at pi/2 rad/s: flat (theta = pi) at t = 1 exactly, a step end of
    // h = 1e-3. The index-1 acceleration is undefined there (projected RK4 stops too); the
    // step that would evaluate it is an error naming the rank and the loop's joints, without
    // halving (a halved step still ends at t = 1)
    let half = std::f64::consts::FRAC_PI_2;
    let sys = models::parallelogram_four_bar(0.4, 1.0, half, half, true).expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let mut rk = TangentRk::rk4(&sys).expect("solver");
    let mut s = s0.clone();
    // the integrator's own steps through the run loop's grid times (the loop would step over
    // the failing step, below)
    let mut failure = None;
    for k in 1..=2000 {
        if let Err(e) = rk.step(&sys, &mut s, 1e-3) {
            failure = Some(e);
            break;
        }
        s.t = k as f64 * 1e-3;
    }
    let e = failure.expect("a singular step");
    println!("{e}; {:?}", rk.stats());
    match &e {
        SolveError::Singular { t, what, detail } => {
            assert_eq!(*t, 1.0);
            assert!(what.contains("configuration"), "{what}");
            assert!(detail.contains("rank 8 of 9"), "{detail}");
            for j in ["A0", "A", "B", "B0"] {
                assert!(detail.contains(j), "{detail}");
            }
            assert!(!detail.contains("crank_drive"), "{detail}");
        }
        other => panic!("expected a singular configuration, got {other}"),
    }
    assert_eq!(rk.stats().halvings, 0);
    assert!(
        (s.t - 0.999).abs() < 1e-12,
        "the state stays at the last good step"
    );
    let projected = Index1Rk::new(
        &sys,
        ButcherTableau::rk4(),
        Index1Options {
            projection: Some(ProjectionSettings::default()),
            ..Default::default()
        },
    )
    .expect("projected RK4")
    .step(&sys, &mut s.clone(), 1e-3);
    assert!(matches!(projected, Err(SolveError::Singular { .. })));
    // the run loop steps over it (docs/singular.md, section 5) and ends on the driven motion
    let mut rk = TangentRk::rk4(&sys).expect("solver");
    let mut s = s0.clone();
    let stats = run(
        &mut rk,
        &sys,
        &mut s,
        RunConfig::new(2.0, 1e-3),
        &mut NoObserver,
    )
    .expect("stepped over");
    assert_eq!(stats.stepped_over, 1);
    // on the parallelogram branch the coupler translates and the rocker turns with the crank
    let idx = |name: &str| 3 * sys.body_handle(name).expect("body").index() + 2;
    let (coupler, rocker) = (s.q[idx("coupler")], s.q[idx("rocker")]);
    assert!(coupler.abs() < 1e-10, "coupler angle {coupler:e}");
    let turn = (rocker - s.q[idx("crank")]).abs();
    assert!(turn < 1e-10, "rocker {turn:e} off the crank");
}

#[test]
fn adaptive_dopri5_passes_flat_configurations_without_a_cascade() {
    let sys = free_four_bar();
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let r = reference_trajectory(&sys, &s0, 2.0, 1, 16_000, ButcherTableau::dopri5())
        .expect("reference");
    let mut dp = TangentRk::dopri5(&sys).expect("solver");
    let mut s = s0.clone();
    let mut watch = BranchWatch::default();
    let st = run_adaptive(
        &mut dp,
        &sys,
        &mut s,
        AdaptiveConfig::new(2.0, 1e-8),
        &mut watch,
    )
    .expect("adaptive run");
    let e = state_error(&s, &r.q[1], &r.v[1]);
    let ts = *dp.stats();
    println!(
        "error {e:.2e}; off branch {:.1e}; {st:?}; {ts:?}",
        watch.off_branch
    );
    assert_eq!(s.t, 2.0);
    assert!(ts.exact_maps > 0, "{ts:?}");
    // no cascade of ever smaller steps: at most one chart rejection per flat passage
    assert!(ts.chart_failures <= 5, "{ts:?}");
    assert!(st.min_step > 1e-4, "{st:?}");
    assert!(watch.off_branch < 1e-10 && watch.res.max_phi <= 1e-12);
    assert!(e < 1e-5, "{e}");
}

#[test]
fn singular_start_is_a_typed_error_at_once_in_both_modes() {
    // slider-crank with crank and rod of equal length folded at the pivot (crank up, rod down
    // onto the slider at the origin): Phi_q has rank 7 of 8
    let l = 0.3;
    let sys = common::slider_crank(l, l, 1.0, None);
    let half = std::f64::consts::FRAC_PI_2;
    let q = DVector::from_vec(vec![0.0, 0.5 * l, half, 0.0, 0.5 * l, -half, 0.0, 0.0, 0.0]);
    let s0 = State::new(&sys, 0.0, q, DVector::zeros(9)).expect("state");
    let mut rk = TangentRk::rk4(&sys).expect("solver");
    let e = rk.step(&sys, &mut s0.clone(), 1e-3).unwrap_err();
    println!("{e}");
    assert!(
        matches!(&e, SolveError::Singular { detail, .. } if detail.contains("rank 7 of 8")),
        "{e}"
    );
    let mut dp = TangentRk::dopri5(&sys).expect("solver");
    let mut s = s0.clone();
    let e = run_adaptive(
        &mut dp,
        &sys,
        &mut s,
        AdaptiveConfig::new(1.0, 1e-6),
        &mut NoObserver,
    )
    .unwrap_err();
    assert!(matches!(&e, SolveError::Singular { .. }), "{e}");
    assert_eq!(dp.stats().chart_failures, 0);
    assert_eq!(s, s0);
}

#[test]
fn parallelogram_four_bar_parameters_are_checked() {
    let bad = [
        (0.0, 1.0, 1.0, 6.0, "crank"),
        (0.4, f64::NAN, 1.0, 6.0, "ground"),
        (0.4, 1.0, f64::INFINITY, 6.0, "angle"),
        (0.4, 1.0, 1.0, f64::NAN, "speed"),
    ];
    for (l, d, th, w, name) in bad {
        match models::parallelogram_four_bar(l, d, th, w, false) {
            Err(mbd_model::ModelError::InvalidParameter { parameter, .. }) => {
                assert_eq!(parameter, name)
            }
            other => panic!("{name}: expected an invalid parameter, got {other:?}"),
        }
    }
    // a flat start builds, as a singular initial configuration
    let flat = models::parallelogram_four_bar(0.4, 1.0, 0.0, 6.0, false).unwrap();
    assert_eq!(flat.singular_start_equations().len(), 1);
    // as built, the state is consistent (on the parallelogram branch)
    let sys = free_four_bar();
    let (q, v) = sys.initial_guess();
    let s = State::new(&sys, 0.0, q, v).expect("state");
    let mut buf = [vec![], vec![]];
    let (p, d) = common::residuals(&sys, &s, &mut buf);
    assert!(p < 1e-15 && d < 1e-15, "{p} {d}");
}

/// Direct `step` calls of size `h` from `s0` to about `t = 2`: the end states of tangent RK4
/// and projected RK4, the largest distance from the parallelogram branch and the largest
/// constraint residuals of tangent RK4, and its counters.
fn direct_steps(sys: &System, s0: &State, h: f64) -> (State, State, BranchWatch, f64) {
    let n = (2.0 / h).round() as usize;
    let mut rk = TangentRk::rk4(sys).expect("solver");
    let mut proj = Index1Rk::new(
        sys,
        ButcherTableau::rk4(),
        Index1Options {
            projection: Some(ProjectionSettings::default()),
            ..Default::default()
        },
    )
    .expect("projected RK4");
    let (mut s, mut p) = (s0.clone(), s0.clone());
    let mut watch = BranchWatch::default();
    watch.observe(sys, &s, 0).expect("observe");
    for k in 1..=n {
        rk.step(sys, &mut s, h)
            .unwrap_or_else(|e| panic!("h = {h:e}, step {k}: {e}"));
        proj.step(sys, &mut p, h).expect("projected RK4");
        watch.observe(sys, &s, k).expect("observe");
    }
    let st = *rk.stats();
    assert_eq!(st.steps, n);
    (s, p, watch, st.exact_maps as f64)
}

#[test]
fn direct_steps_keep_the_branch_at_step_sizes_differing_in_the_last_bits() {
    // Branch selection at the flat configurations must not depend on rounding: before the
    // travel bound on the chart maps, the driven crank under `run` (nominal h = 1e-3) ended on
    // the crossed branch (a chord iteration from a near-singular centre drifted along the
    // nearly singular direction onto it), while `h = t_next - t` (a few ulps off) stayed on
    // the parallelogram. Steps 1e-3, 1e-3 (1 + 1e-15) and 0.9e-3, free and driven.
    for driven in [true, false] {
        let sys = models::parallelogram_four_bar(0.4, 1.0, 1.0, 6.0, driven).expect("model");
        let s0 = State::consistent(&sys, 0.0).expect("state");
        for h in [1e-3, 1e-3 * (1.0 + 1e-15), 0.9e-3] {
            let (s, p, watch, exact) = direct_steps(&sys, &s0, h);
            let e_proj = state_error(&s, p.q.as_slice(), p.v.as_slice());
            println!(
                "driven {driven}, h = {h:.17e}: t = {:.6}, crank {:.6}, off branch {:.1e}, \
                 tangent - projected {e_proj:.1e}, max |Phi| {:.1e}, |Phidot| {:.1e}, \
                 exact maps {exact}",
                s.t, s.q[2], watch.off_branch, watch.res.max_phi, watch.res.max_phidot
            );
            assert!(watch.max_crank - watch.min_crank > 3.0 * std::f64::consts::PI);
            assert!(watch.off_branch < 1e-10, "h = {h:e}: {}", watch.off_branch);
            assert!(watch.res.max_phi <= 1e-12 && watch.res.max_phidot <= 1e-12);
            assert!(
                e_proj < if driven { 1e-9 } else { 1e-7 },
                "h = {h:e}: {e_proj}"
            );
            if driven {
                assert!((s.q[2] - (1.0 + 6.0 * s.t)).abs() < 1e-11, "{}", s.q[2]);
            }
        }
    }
}

#[test]
fn run_keeps_the_branch_at_perturbed_nominal_steps() {
    // the same through `mbd_solve::run` (nominal h to every step, times t0 + k h)
    for driven in [true, false] {
        let sys = models::parallelogram_four_bar(0.4, 1.0, 1.0, 6.0, driven).expect("model");
        let s0 = State::consistent(&sys, 0.0).expect("state");
        for h in [1e-3 * (1.0 + 1e-15), 0.9e-3] {
            let mut s = s0.clone();
            let mut rk = TangentRk::rk4(&sys).expect("solver");
            let mut watch = BranchWatch::default();
            run(&mut rk, &sys, &mut s, RunConfig::new(2.0, h), &mut watch).expect("run");
            let proj = projected_rk4(&sys, &s0, 2.0, h);
            let e_proj = state_error(&s, proj.q.as_slice(), proj.v.as_slice());
            println!(
                "driven {driven}, h = {h:e}: off branch {:.1e}, tangent - projected {e_proj:.1e}",
                watch.off_branch
            );
            assert!(watch.off_branch < 1e-10, "h = {h:e}: {}", watch.off_branch);
            assert!(
                e_proj < if driven { 1e-9 } else { 1e-7 },
                "h = {h:e}: {e_proj}"
            );
        }
    }
}
