//! Same seed, same bits: serial vs parallel, any rayon thread count.

use mbd_firefly::{
    testfns, Bounds, Firefly, FireflyResult, FireflySettings, GenerationRecord, History,
    Termination, Variant,
};

type TestResult = Result<(), Box<dyn std::error::Error>>;

/// A multimodal objective that also returns NaN on part of the box, so that
/// the NaN path is covered by the determinism checks too.
fn objective(x: &[f64]) -> f64 {
    if x[0] > 4.0 && x[1] > 4.0 {
        f64::NAN
    } else {
        testfns::rastrigin(x)
    }
}

fn config<'a>(seed: u64, variant: Variant, budget: Option<u64>) -> Firefly<'a> {
    let bounds = Bounds::cube(6, -5.12, 5.12).expect("valid box");
    let mut t = Termination::default().max_generations(40);
    t.max_evaluations = budget;
    Firefly::new(bounds)
        .settings(
            FireflySettings::default()
                .population(24)
                .alpha(0.3)
                .variant(variant)
                .seed(seed),
        )
        .termination(t)
        .initial_position(vec![1.0, -1.0, 0.5, 0.0, 2.0, -3.0])
}

fn serial(seed: u64, variant: Variant, budget: Option<u64>) -> (FireflyResult, History) {
    let mut h = History::new();
    let mut f = objective;
    let r = config(seed, variant, budget)
        .observer(&mut h)
        .minimize(&mut f)
        .expect("valid configuration");
    (r, h)
}

fn parallel(seed: u64, variant: Variant, budget: Option<u64>) -> (FireflyResult, History) {
    let mut h = History::new();
    let r = config(seed, variant, budget)
        .observer(&mut h)
        .minimize_parallel(&objective)
        .expect("valid configuration");
    (r, h)
}

fn record_bits(r: &GenerationRecord) -> [u64; 6] {
    [
        r.generation,
        r.best_f.to_bits(),
        r.mean_f.to_bits(),
        r.alpha.to_bits(),
        r.evaluations,
        r.nan_evaluations,
    ]
}

fn assert_identical(a: &(FireflyResult, History), b: &(FireflyResult, History)) {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a.0.best_x), bits(&b.0.best_x));
    assert_eq!(a.0.best_f.to_bits(), b.0.best_f.to_bits());
    assert_eq!(a.0.final_alpha.to_bits(), b.0.final_alpha.to_bits());
    assert_eq!(a.0.generations, b.0.generations);
    assert_eq!(a.0.evaluations, b.0.evaluations);
    assert_eq!(a.0.nan_evaluations, b.0.nan_evaluations);
    assert_eq!(a.0.stop_reason, b.0.stop_reason);
    assert_eq!(a.1.len(), b.1.len());
    for (x, y) in a.1.records.iter().zip(&b.1.records) {
        assert_eq!(record_bits(x), record_bits(y));
    }
}

#[test]
fn serial_runs_repeat_bit_for_bit() {
    for variant in [Variant::Snapshot, Variant::Classic, Variant::ClassicSweep] {
        let a = serial(11, variant, None);
        let b = serial(11, variant, None);
        assert_identical(&a, &b);
        assert!(a.0.nan_evaluations > 0, "NaN region should be hit");
    }
}

#[test]
fn snapshot_parallel_matches_serial_on_1_2_4_threads() -> TestResult {
    for budget in [None, Some(24 * 17 + 5)] {
        let reference = serial(7, Variant::Snapshot, budget);
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()?;
            let par = pool.install(|| parallel(7, Variant::Snapshot, budget));
            assert_identical(&reference, &par);
        }
    }
    Ok(())
}

#[test]
fn classic_variants_parallel_entry_point_matches_serial() -> TestResult {
    for variant in [Variant::Classic, Variant::ClassicSweep] {
        let reference = serial(3, variant, Some(5000));
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build()?;
        let par = pool.install(|| parallel(3, variant, Some(5000)));
        assert_identical(&reference, &par);
    }
    Ok(())
}

#[test]
fn different_seeds_give_different_results() {
    let results: Vec<Vec<u64>> = (0..6)
        .map(|seed| {
            serial(seed, Variant::Snapshot, None)
                .0
                .best_x
                .iter()
                .map(|v| v.to_bits())
                .collect()
        })
        .collect();
    for i in 0..results.len() {
        for j in i + 1..results.len() {
            assert_ne!(results[i], results[j], "seeds {i} and {j} agree");
        }
    }
}
