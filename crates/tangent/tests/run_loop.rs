//! Steps driven by `mbd_solve::run`, which passes each step `h = t_next - t` with
//! `t_next = t0 + k h`: that differs from the nominal `h` in the last bits on most steps, and the
//! solver's fast paths for "a step of the same size as the last" (history predictors, inexact
//! stage maps) must not depend on those bits.

mod common;

use common::state_error;
use mbd_model::models;
use mbd_solve::{run, Integrator, NoObserver, RunConfig, State};
use mbd_tangent::TangentRk;

#[test]
fn steps_under_run_take_the_fast_paths_of_direct_steps() {
    let sys = models::manipulator().expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let (h, n) = (0.01, 500usize);
    // the premise: run's step sizes differ from h in the last bits on most steps
    let differing = (1..=n)
        .filter(|&k| k as f64 * h - (k - 1) as f64 * h != h)
        .count();
    assert!(differing > n / 2, "{differing} of {n}");

    let mut direct = TangentRk::rk4(&sys).expect("solver");
    let mut a = s0.clone();
    for _ in 0..n {
        direct.step(&sys, &mut a, h).expect("step");
    }
    let mut via_run = TangentRk::rk4(&sys).expect("solver");
    let mut b = s0.clone();
    run(
        &mut via_run,
        &sys,
        &mut b,
        RunConfig::new(n as f64 * h, h),
        &mut NoObserver,
    )
    .expect("run");
    let (da, db) = (direct.stats(), via_run.stats());
    let per = |s: &mbd_tangent::TangentStats| s.newton_iterations as f64 / s.steps as f64;
    let e = state_error(&a, b.q.as_slice(), b.v.as_slice());
    println!(
        "{differing} of {n} steps differ from h; chord iterations per step: direct {:.2}, \
         under run {:.2}; states differ by {e:.1e}",
        per(da),
        per(db)
    );
    assert_eq!(da.steps, db.steps);
    assert!((per(db) - per(da)).abs() <= 0.01 * per(da), "{da:?} {db:?}");
    assert!(e < 1e-10, "{e}");
}
