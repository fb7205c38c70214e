//! The chord iteration's matrix changes the work, not the result: the centre matrix (the
//! paper's chord, default), the interpolated one and the Broyden-updated one land on the same
//! chart points.

mod common;

use common::state_error;
use mbd_model::models;
use mbd_solve::{run, ButcherTableau, NoObserver, RunConfig, State};
use mbd_tangent::{IterationMatrix, TangentOptions, TangentRk};

#[test]
fn centre_interpolated_and_broyden_matrices_agree() {
    for sys in [
        models::manipulator().expect("model"),
        models::four_bar().expect("model"),
    ] {
        let s0 = State::consistent(&sys, 0.0).expect("state");
        let mut ends = vec![];
        let mut iters = vec![];
        for m in [
            IterationMatrix::Centre,
            IterationMatrix::Interpolated,
            IterationMatrix::Broyden,
        ] {
            // exact stage maps: with inexact ones each iteration stops at a different point
            // inside the stage tolerance (tests/stage_tol.rs)
            let opts = TangentOptions {
                iteration_matrix: m,
                stage_tol_ratio: 0.0,
                ..Default::default()
            };
            let mut rk = TangentRk::new(&sys, ButcherTableau::rk4(), opts).expect("solver");
            let mut s = s0.clone();
            run(
                &mut rk,
                &sys,
                &mut s,
                RunConfig::new(1.0, 0.01),
                &mut NoObserver,
            )
            .expect("run");
            iters.push(rk.stats().newton_iterations);
            ends.push(s);
        }
        let d = state_error(&ends[0], ends[1].q.as_slice(), ends[1].v.as_slice());
        let db = state_error(&ends[0], ends[2].q.as_slice(), ends[2].v.as_slice());
        println!(
            "iterations centre {} interpolated {} Broyden {}, difference {d:e} / {db:e}",
            iters[0], iters[1], iters[2]
        );
        assert!(d < 1e-10, "{d}");
        assert!(db < 1e-10, "{db}");
        assert!((iters[1] as f64) < 0.75 * iters[0] as f64, "{iters:?}");
        assert!(iters[2] < iters[0], "{iters:?}");
    }
}
