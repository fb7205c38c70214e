//! Cost of one generation on sphere, d = 10, population 60.
//!
//! `cargo bench -p mbd-firefly --bench firefly`
//!
//! * `cheap/*`: the plain sphere function, so the time is the algorithm's own
//!   overhead (sorting, `n (n - 1) / 2` moves with their random numbers).
//! * `expensive/*`: sphere plus about 20 µs of extra arithmetic per call,
//!   standing in for a costly objective (a DAE residual), where the parallel
//!   snapshot evaluation pays off.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use mbd_firefly::{testfns, Bounds, FireflySettings, Swarm, Variant};

fn swarm(variant: Variant) -> Swarm {
    let bounds = Bounds::cube(10, -5.12, 5.12).expect("valid box");
    let settings = FireflySettings::default()
        .population(60)
        .variant(variant)
        .seed(1);
    let mut s = Swarm::new(&bounds, &settings, &[]).expect("valid settings");
    let mut f = testfns::sphere;
    s.initialize(&mut f, None);
    s
}

fn expensive(x: &[f64]) -> f64 {
    let mut acc = testfns::sphere(x);
    let mut t = black_box(1.0f64);
    for _ in 0..4000 {
        t = (t * 1.000_000_1).sin() + 1.0;
    }
    acc += 1e-300 * t;
    acc
}

fn bench(c: &mut Criterion) {
    let snapshot = swarm(Variant::Snapshot);
    let sweep = swarm(Variant::ClassicSweep);
    let classic = swarm(Variant::Classic);

    let mut g = c.benchmark_group("cheap");
    g.bench_function("snapshot_serial", |b| {
        b.iter_batched_ref(
            || snapshot.clone(),
            |s| s.step(&mut testfns::sphere, None),
            BatchSize::SmallInput,
        )
    });
    g.bench_function("snapshot_parallel", |b| {
        b.iter_batched_ref(
            || snapshot.clone(),
            |s| s.step_parallel(&testfns::sphere, None),
            BatchSize::SmallInput,
        )
    });
    g.bench_function("classic_sweep_serial", |b| {
        b.iter_batched_ref(
            || sweep.clone(),
            |s| s.step(&mut testfns::sphere, None),
            BatchSize::SmallInput,
        )
    });
    g.bench_function("classic_per_move_serial", |b| {
        b.iter_batched_ref(
            || classic.clone(),
            |s| s.step(&mut testfns::sphere, None),
            BatchSize::SmallInput,
        )
    });
    g.finish();

    let mut g = c.benchmark_group("expensive");
    g.bench_function("snapshot_serial", |b| {
        b.iter_batched_ref(
            || snapshot.clone(),
            |s| s.step(&mut expensive, None),
            BatchSize::SmallInput,
        )
    });
    g.bench_function("snapshot_parallel", |b| {
        b.iter_batched_ref(
            || snapshot.clone(),
            |s| s.step_parallel(&expensive, None),
            BatchSize::SmallInput,
        )
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
