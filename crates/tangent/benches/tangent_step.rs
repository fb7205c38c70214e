//! One tangent-space RK4 step against one plain RK4 step (`Index1Rk` with the RK4 tableau, what
//! `mbd-rk4` wraps) on the paper-C manipulator, h = 0.01. Target: ratio at most 4.
use criterion::{criterion_group, criterion_main, Criterion};
use mbd_model::models;
use mbd_solve::{ButcherTableau, Index1Options, Index1Rk, Integrator, State};
use mbd_tangent::TangentRk;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let sys = models::manipulator().expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let h = 0.01;

    let mut plain =
        Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default()).expect("rk4");
    let mut s = s0.clone();
    c.bench_function("plain_rk4_step_manipulator", |b| {
        b.iter(|| {
            if s.t > 10.0 {
                s = s0.clone();
            }
            plain.step(&sys, black_box(&mut s), h).expect("step");
        })
    });

    let mut tangent = TangentRk::rk4(&sys).expect("tangent");
    let mut s = s0.clone();
    c.bench_function("tangent_rk4_step_manipulator", |b| {
        b.iter(|| {
            if s.t > 10.0 {
                s = s0.clone();
            }
            tangent.step(&sys, black_box(&mut s), h).expect("step");
        })
    });

    let mut dp = TangentRk::dopri5(&sys).expect("tangent");
    let mut s = s0.clone();
    c.bench_function("tangent_dopri5_step_manipulator", |b| {
        b.iter(|| {
            if s.t > 10.0 {
                s = s0.clone();
            }
            dp.step(&sys, black_box(&mut s), h).expect("step");
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
