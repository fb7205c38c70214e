//! One step of the (1,1) and (2,2) schemes on the paper-C manipulator, beside one RK4 step
//! (`mbd_solve::Index1Rk` with the RK4 tableau) as a peer.
use criterion::{criterion_group, criterion_main, Criterion};
use mbd_model::models;
use mbd_solve::{ButcherTableau, Index1Options, Index1Rk, Integrator, State};
use mbd_symplectic::{Galerkin, SymplecticOptions};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let sys = models::manipulator().expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let h = 0.01;
    for (s, gamma) in [(1, 0.0), (2, 0.0), (2, 1.0)] {
        let mut g =
            Galerkin::new(&sys, SymplecticOptions::new(s).with_gamma(gamma)).expect("scheme");
        let mut st = s0.clone();
        let name = if gamma == 0.0 {
            format!("symplectic_{s}{s}_step_manipulator")
        } else {
            format!("symplectic_{s}{s}_gamma1_step_manipulator")
        };
        c.bench_function(&name, |b| {
            b.iter(|| {
                if st.t > 10.0 {
                    st = s0.clone();
                }
                g.step(&sys, black_box(&mut st), h).expect("step");
            })
        });
    }
    let mut rk = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default()).expect("rk4");
    let mut st = s0.clone();
    c.bench_function("rk4_peer_step_manipulator", |b| {
        b.iter(|| {
            if st.t > 10.0 {
                st = s0.clone();
            }
            rk.step(&sys, black_box(&mut st), h).expect("step");
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
