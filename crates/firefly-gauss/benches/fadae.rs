//! Cost of one objective evaluation and of one FA-DAE step on the manipulator.
//!
//! `cargo bench -p mbd-firefly-gauss --bench fadae`

use criterion::{criterion_group, criterion_main, Criterion};
use mbd_firefly_gauss::{FaDaeOptions, FireflyGauss};
use mbd_model::models;
use mbd_solve::{run, Integrator, NoObserver, RunConfig, State};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let sys = models::manipulator().expect("model");
    for h in [0.01, 0.002] {
        // warm up 0.5 s so the step is a typical one (moving, with correction history)
        let mut s = State::consistent(&sys, 0.0).expect("state");
        let mut fa = FireflyGauss::new(&sys, FaDaeOptions::default()).expect("options");
        run(
            &mut fa,
            &sys,
            &mut s,
            RunConfig::new(0.5, h),
            &mut NoObserver,
        )
        .expect("run");
        let x = fa.last_solution().to_vec();
        let mut g = c.benchmark_group(format!("manipulator_h{h}"));
        g.bench_function("objective", |b| {
            let mut y = x.clone();
            let mut k = 0usize;
            b.iter(|| {
                k = (k + 1) % y.len();
                y[k] += 1e-13;
                black_box(fa.objective_at(&sys, black_box(&y)))
            })
        });
        for polish in [false, true] {
            let name = if polish { "step_polished" } else { "step_pure" };
            let mut fb =
                FireflyGauss::new(&sys, FaDaeOptions::default().polish(polish)).expect("options");
            let mut s0 = State::consistent(&sys, 0.0).expect("state");
            run(
                &mut fb,
                &sys,
                &mut s0,
                RunConfig::new(0.5, h),
                &mut NoObserver,
            )
            .expect("run");
            // the state advances along the trajectory from one iteration to the next, so every
            // measured step is a typical one (a fresh predictor error, a fresh correction)
            g.bench_function(name, |b| b.iter(|| black_box(fb.step(&sys, &mut s0, h))));
        }
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
