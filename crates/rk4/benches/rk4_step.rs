//! One RK4 step on the paper-C manipulator (target: at most 1 us).
use criterion::{criterion_group, criterion_main, Criterion};
use mbd_model::models;
use mbd_rk4::{Rk4, Rk4Options};
use mbd_solve::{Integrator, State};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let sys = models::manipulator().expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let mut rk = Rk4::new(&sys, Rk4Options::plain()).expect("rk4");
    let mut s = s0.clone();
    c.bench_function("rk4_step_manipulator", |b| {
        b.iter(|| {
            if s.t > 10.0 {
                s = s0.clone();
            }
            rk.step(&sys, black_box(&mut s), 0.01).expect("step");
        })
    });
    let mut rkp = Rk4::new(&sys, Rk4Options::projected()).expect("rk4");
    let mut s = s0.clone();
    c.bench_function("rk4_projected_step_manipulator", |b| {
        b.iter(|| {
            if s.t > 10.0 {
                s = s0.clone();
            }
            rkp.step(&sys, black_box(&mut s), 0.01).expect("step");
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
