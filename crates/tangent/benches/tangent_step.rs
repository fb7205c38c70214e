//! One tangent-space RK4 step against one plain RK4 step (`Index1Rk` with the RK4 tableau, what
//! `mbd-rk4` wraps) on the paper-C manipulator, at h = 0.01 (paper C's step) and h = 0.002.
//! The target is a ratio of at most 4; `docs/tangent.md` records the measured ratio.
//! Also: tangent DOPRI5, and tangent RK4 with the interpolated iteration matrix. Criterion times
//! each function on its own; on a loaded machine `tools/src/bin/tangent_step_ratio.rs` (interleaved blocks,
//! best of 30) gives the steadier ratio.
use criterion::{criterion_group, criterion_main, Criterion};
use mbd_model::{models, System};
use mbd_solve::{ButcherTableau, Index1Options, Index1Rk, Integrator, State};
use mbd_tangent::{IterationMatrix, TangentOptions, TangentRk};
use std::hint::black_box;

fn bench_one<I: Integrator>(c: &mut Criterion, name: &str, sys: &System, mut integ: I, h: f64) {
    let s0 = State::consistent(sys, 0.0).expect("state");
    let mut s = s0.clone();
    c.bench_function(name, |b| {
        b.iter(|| {
            // cycle through the first 10 s of the motion (slow and fast phases)
            if s.t > 10.0 {
                s = s0.clone();
            }
            integ.step(sys, black_box(&mut s), h).expect("step");
        })
    });
}

fn bench(c: &mut Criterion) {
    let sys = models::manipulator().expect("model");
    let plain =
        || Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default()).expect("rk4");
    let tangent = || TangentRk::rk4(&sys).expect("tangent");
    for h in [0.01, 0.002] {
        bench_one(
            c,
            &format!("plain_rk4_step_manipulator_h{h}"),
            &sys,
            plain(),
            h,
        );
        bench_one(
            c,
            &format!("tangent_rk4_step_manipulator_h{h}"),
            &sys,
            tangent(),
            h,
        );
    }
    let interp = TangentRk::new(
        &sys,
        ButcherTableau::rk4(),
        TangentOptions {
            iteration_matrix: IterationMatrix::Interpolated,
            ..Default::default()
        },
    )
    .expect("tangent");
    bench_one(
        c,
        "tangent_rk4_interpolated_step_manipulator_h0.01",
        &sys,
        interp,
        0.01,
    );
    let dp = TangentRk::dopri5(&sys).expect("tangent");
    bench_one(c, "tangent_dopri5_step_manipulator_h0.01", &sys, dp, 0.01);
}

criterion_group!(benches, bench);
criterion_main!(benches);
