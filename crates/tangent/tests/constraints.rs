//! Position and velocity constraints at the Newton tolerance at every one of 10^5 steps, on the
//! manipulator (open chain), the slider-crank and the four-bar (closed loops).

mod common;

use common::ResidualWatch;
use mbd_model::{models, System};
use mbd_solve::{run, RunConfig, State};
use mbd_tangent::TangentRk;

fn long_run(sys: &System, h: f64, steps: usize) -> (ResidualWatch, f64) {
    let mut state = State::consistent(sys, 0.0).expect("consistent state");
    let h0 = sys.energy(state.q.as_slice(), state.v.as_slice());
    let mut rk = TangentRk::rk4(sys).expect("solver");
    let mut watch = ResidualWatch::default();
    let cfg = RunConfig::new(h * steps as f64, h);
    let stats = run(&mut rk, sys, &mut state, cfg, &mut watch).expect("run");
    assert_eq!(stats.steps, steps);
    assert_eq!(watch.samples, steps + 1);
    assert_eq!(rk.stats().halvings, 0, "no step needed halving");
    let h1 = sys.energy(state.q.as_slice(), state.v.as_slice());
    (watch, ((h1 - h0) / h0).abs())
}

#[test]
fn manipulator_1e5_steps_constraints_at_tolerance() {
    let sys = models::manipulator().expect("model");
    let (w, de) = long_run(&sys, 0.002, 100_000);
    println!(
        "manipulator: max |Phi| {:e}, max |Phidot| {:e}, |dH/H0| {de:e}",
        w.max_phi, w.max_phidot
    );
    assert!(w.max_phi <= 1e-12 && w.max_phidot <= 1e-12);
    // RK4 at h = 0.002 over 200 s of chaotic motion: small energy drift
    assert!(de < 1e-4, "energy drift {de}");
}

#[test]
fn slider_crank_1e5_steps_constraints_at_tolerance() {
    let sys = models::slider_crank().expect("model");
    let (w, de) = long_run(&sys, 0.002, 100_000);
    println!(
        "slider-crank: max |Phi| {:e}, max |Phidot| {:e}, |dH/H0| {de:e}",
        w.max_phi, w.max_phidot
    );
    assert!(w.max_phi <= 1e-12 && w.max_phidot <= 1e-12);
    assert!(de < 1e-5, "energy drift {de}");
}

#[test]
fn four_bar_1e5_steps_constraints_at_tolerance() {
    let sys = models::four_bar().expect("model");
    let (w, de) = long_run(&sys, 0.002, 100_000);
    println!(
        "four-bar: max |Phi| {:e}, max |Phidot| {:e}, |dH/H0| {de:e}",
        w.max_phi, w.max_phidot
    );
    assert!(w.max_phi <= 1e-12 && w.max_phidot <= 1e-12);
    assert!(de < 1e-5, "energy drift {de}");
}
