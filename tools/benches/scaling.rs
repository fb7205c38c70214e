//! Ten steps of every solver meant to scale, on N-link chains (N = 10, 30, 100, 300, 1000),
//! through the public run loop. Compare within one run: the ratios to "RK4 plain" are the
//! portable numbers (the xtask experiment `own-scaling` reports them with verdicts).
//!
//! `cargo bench -p mbd-tools --bench scaling [-- <filter>]`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use mbd::model::models;
use mbd::solve::{run, NoObserver, RunConfig, State};
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("chain_step");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    for n in [10usize, 30, 100, 300, 1000] {
        let Ok(sys) = models::n_link_chain(n) else {
            continue;
        };
        let Ok(s0) = State::consistent(&sys, 0.0) else {
            continue;
        };
        for (name, make) in mbd_tools::scaling_solvers() {
            let Ok(mut integ) = make(&sys) else {
                continue;
            };
            g.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| {
                    let mut s = s0.clone();
                    // ten steps through the run loop (criterion reports the time of ten)
                    run(
                        &mut integ,
                        &sys,
                        &mut s,
                        RunConfig::new(1e-2, 1e-3),
                        &mut NoObserver,
                    )
                    .map(|st| st.steps)
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
