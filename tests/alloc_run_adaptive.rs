//! `run_adaptive` and `DenseOutput` allocate nothing per step: a run twice as long (twice the
//! steps) makes exactly as many heap allocations as a short one (the set-up's).

use mbd::model::models;
use mbd::solve::{
    run, run_adaptive, AdaptiveConfig, ButcherTableau, DenseOutput, Event, Index1Options, Index1Rk,
    NoObserver, RunConfig, State,
};
use mbd::tangent::{TangentOptions, TangentRk};
use mbd_testkit::allocations;

#[global_allocator]
static GLOBAL: mbd_testkit::CountingAlloc = mbd_testkit::CountingAlloc;

fn count(f: impl FnOnce() -> usize) -> (usize, usize) {
    let before = allocations();
    let steps = f();
    (allocations() - before, steps)
}

#[test]
fn adaptive_run_and_dense_output_allocate_nothing_per_step() {
    let sys = models::manipulator().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Index1Rk::new(&sys, ButcherTableau::dopri5(), Index1Options::default()).unwrap();
    let mut tg = TangentRk::new(&sys, ButcherTableau::dopri5(), TangentOptions::default()).unwrap();
    // an event that never fires: its function runs every step, nothing is recorded
    let mut dense =
        DenseOutput::new(&sys, NoObserver).with_event(Event::new("never", |_, _, _| 1.0));
    let mut results = vec![];
    for t_end in [0.5, 1.0] {
        let index1 = count(|| {
            let mut s = s0.clone();
            let cfg = AdaptiveConfig::new(t_end, 1e-8);
            run_adaptive(&mut rk, &sys, &mut s, cfg, &mut NoObserver)
                .unwrap()
                .steps
        });
        let tangent = count(|| {
            let mut s = s0.clone();
            let cfg = AdaptiveConfig::new(t_end, 1e-8);
            run_adaptive(&mut tg, &sys, &mut s, cfg, &mut NoObserver)
                .unwrap()
                .steps
        });
        let fixed_dense = count(|| {
            let mut s = s0.clone();
            run(
                &mut rk,
                &sys,
                &mut s,
                RunConfig::new(t_end, 0.01),
                &mut dense,
            )
            .unwrap()
            .steps
        });
        println!("t_end {t_end}: (allocations, steps) index-1 {index1:?} tangent {tangent:?} dense {fixed_dense:?}");
        results.push((index1, tangent, fixed_dense));
    }
    let (a, b) = (results[0], results[1]);
    assert!(b.0 .1 > a.0 .1 && b.1 .1 > a.1 .1 && b.2 .1 > a.2 .1);
    assert_eq!(a.0 .0, b.0 .0, "index-1 adaptive run allocates per step");
    assert_eq!(a.1 .0, b.1 .0, "tangent adaptive run allocates per step");
    assert_eq!(a.2 .0, b.2 .0, "DenseOutput allocates per step");
}
