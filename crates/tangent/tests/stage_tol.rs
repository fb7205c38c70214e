//! Inexact interior stage maps (`TangentOptions::stage_tol_ratio`): fewer chord iterations,
//! the same end-point constraint accuracy, and a change of the solution far below the method's
//! own error.

mod common;

use common::state_error;
use mbd_model::models;
use mbd_solve::{reference_trajectory, run, ButcherTableau, NoObserver, RunConfig, State};
use mbd_tangent::{TangentOptions, TangentRk};

#[test]
fn inexact_stage_maps_save_iterations_not_accuracy() {
    let sys = models::manipulator().expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let t_end = 2.0;
    let href = 2e-4;
    let r = reference_trajectory(
        &sys,
        &s0,
        href,
        (t_end / href).round() as usize,
        1,
        ButcherTableau::dopri5(),
    )
    .expect("reference");
    let (qr, vr) = (
        r.q.last().expect("reference").clone(),
        r.v.last().expect("reference").clone(),
    );
    for h in [0.02, 0.01, 0.005] {
        let mut out = vec![];
        for ratio in [0.0, TangentOptions::default().stage_tol_ratio] {
            let opts = TangentOptions {
                stage_tol_ratio: ratio,
                ..Default::default()
            };
            let mut rk = TangentRk::new(&sys, ButcherTableau::rk4(), opts).expect("solver");
            let mut s = s0.clone();
            run(
                &mut rk,
                &sys,
                &mut s,
                RunConfig::new(t_end, h),
                &mut NoObserver,
            )
            .expect("run");
            let stats = *rk.stats();
            assert!(stats.max_residual <= 1e-13, "h = {h}: {stats:?}");
            out.push((s, stats.newton_iterations as f64 / stats.steps as f64));
        }
        let err = state_error(&out[0].0, &qr, &vr);
        let change = state_error(&out[0].0, out[1].0.q.as_slice(), out[1].0.v.as_slice());
        println!(
            "h = {h}: error {err:.3e}, change by inexact stage maps {change:.3e}, iterations per step {:.2} -> {:.2}",
            out[0].1, out[1].1
        );
        assert!(
            change <= 0.01 * err,
            "h = {h}: change {change:e} vs error {err:e}"
        );
        // the saving grows with h (the stage tolerance follows the local error)
        let bound = if h >= 0.01 { 0.8 } else { 1.0 };
        assert!(
            out[1].1 < bound * out[0].1,
            "h = {h}: iterations {} -> {}",
            out[0].1,
            out[1].1
        );
    }
}
