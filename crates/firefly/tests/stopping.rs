//! Each stopping rule triggers with the right reason; evaluations are
//! counted exactly and the budget is never exceeded.

use mbd_firefly::{
    testfns, Bounds, Firefly, FireflySettings, GenerationRecord, History, StopReason, Termination,
    Variant,
};

const VARIANTS: [Variant; 3] = [Variant::Snapshot, Variant::Classic, Variant::ClassicSweep];

fn sphere_run(
    settings: FireflySettings,
    termination: Termination,
) -> (mbd_firefly::FireflyResult, History, u64) {
    let bounds = Bounds::cube(4, -5.0, 5.0).expect("valid box");
    let mut calls = 0u64;
    let mut f = |x: &[f64]| {
        calls += 1;
        testfns::sphere(x)
    };
    let mut h = History::new();
    let r = Firefly::new(bounds)
        .settings(settings)
        .termination(termination)
        .observer(&mut h)
        .minimize(&mut f)
        .expect("valid configuration");
    (r, h, calls)
}

#[test]
fn max_generations() {
    for variant in VARIANTS {
        let s = FireflySettings::default().population(10).variant(variant);
        let (r, h, calls) = sphere_run(s, Termination::default().max_generations(7));
        assert_eq!(r.stop_reason, StopReason::MaxGenerations);
        assert_eq!(r.generations, 7);
        assert_eq!(r.evaluations, calls);
        assert_eq!(h.len(), 8);
        if variant != Variant::Classic {
            // One evaluation per firefly per generation.
            assert_eq!(r.evaluations, 10 * 8);
        }
    }
}

#[test]
fn zero_generations_evaluates_initial_population_only() {
    let s = FireflySettings::default().population(12);
    let (r, h, calls) = sphere_run(s, Termination::default().max_generations(0));
    assert_eq!(r.stop_reason, StopReason::MaxGenerations);
    assert_eq!((r.generations, r.evaluations, calls), (0, 12, 12));
    assert_eq!(h.len(), 1);
}

#[test]
fn evaluation_budget_is_never_exceeded() {
    for variant in VARIANTS {
        for budget in [1, 5, 10, 11, 99, 100, 101, 457] {
            let s = FireflySettings::default()
                .population(10)
                .variant(variant)
                .seed(budget);
            let (r, h, calls) = sphere_run(
                s,
                Termination::default()
                    .max_generations(10_000)
                    .max_evaluations(budget),
            );
            assert_eq!(
                r.stop_reason,
                StopReason::EvaluationBudget,
                "{variant:?} {budget}"
            );
            assert_eq!(r.evaluations, budget, "{variant:?} budget {budget}");
            assert_eq!(calls, budget, "{variant:?} budget {budget}");
            assert!(h.records.iter().all(|rec| rec.evaluations <= budget));
        }
    }
}

#[test]
fn target_value() {
    for variant in VARIANTS {
        let s = FireflySettings::default()
            .population(15)
            .alpha(0.2)
            .alpha_decay(0.95)
            .variant(variant);
        let (r, h, _) = sphere_run(s, Termination::default().max_generations(500).target(1e-4));
        assert_eq!(r.stop_reason, StopReason::TargetReached, "{variant:?}");
        assert!(r.best_f <= 1e-4);
        assert!(r.generations < 500);
        // It stopped at the first generation that reached the target.
        let n = h.len();
        assert!(h.records[n - 1].best_f <= 1e-4);
        assert!(h.records[..n - 1].iter().all(|rec| rec.best_f > 1e-4));
    }
}

#[test]
fn target_reached_by_initial_population() {
    let bounds = Bounds::cube(3, -1.0, 1.0).expect("valid box");
    let r = Firefly::new(bounds)
        .initial_position(vec![0.0; 3])
        .termination(Termination::default().target(0.0))
        .minimize(&mut testfns::sphere)
        .expect("valid configuration");
    assert_eq!(r.stop_reason, StopReason::TargetReached);
    assert_eq!(r.generations, 0);
    assert_eq!(r.best_x, vec![0.0; 3]);
    assert_eq!(r.best_f, 0.0);
}

#[test]
fn stagnation_on_constant_objective() {
    let bounds = Bounds::cube(2, -1.0, 1.0).expect("valid box");
    let r = Firefly::new(bounds)
        .settings(FireflySettings::default().population(5))
        .termination(Termination::default().stagnation(6, 0.0))
        .minimize(&mut |_: &[f64]| 1.0)
        .expect("valid configuration");
    assert_eq!(r.stop_reason, StopReason::Stagnation);
    assert_eq!(r.generations, 6);
}

#[test]
fn stagnation_with_tolerance() {
    // With a generous tolerance, the small late improvements of a converging
    // swarm do not count, so the run stops long before the generation limit.
    let s = FireflySettings::default()
        .population(20)
        .alpha(0.3)
        .alpha_decay(0.9);
    let (r, h, _) = sphere_run(
        s,
        Termination::default()
            .max_generations(1000)
            .stagnation(10, 1e-3),
    );
    assert_eq!(r.stop_reason, StopReason::Stagnation);
    assert!(r.generations < 1000);
    // The last 10 generations improved by no more than the tolerance in total
    // relative to the reference value.
    let last = h.records.len() - 1;
    let reference = h.records[last - 10].best_f;
    assert!(reference - h.records[last].best_f <= 1e-3);
}

#[test]
fn custom_criterion() {
    let bounds = Bounds::cube(2, -1.0, 1.0).expect("valid box");
    let mut stop = |rec: &GenerationRecord| rec.generation == 3;
    let r = Firefly::new(bounds)
        .settings(FireflySettings::default().population(5))
        .stop_when(&mut stop)
        .minimize(&mut testfns::sphere)
        .expect("valid configuration");
    assert_eq!(r.stop_reason, StopReason::Custom);
    assert_eq!(r.generations, 3);
}

#[test]
fn target_takes_precedence_over_generation_limit() {
    let bounds = Bounds::cube(2, -1.0, 1.0).expect("valid box");
    let r = Firefly::new(bounds)
        .termination(
            Termination::default()
                .max_generations(0)
                .target(f64::INFINITY),
        )
        .minimize(&mut testfns::sphere)
        .expect("valid configuration");
    assert_eq!(r.stop_reason, StopReason::TargetReached);
}

#[test]
fn budget_smaller_than_population_leaves_rest_unevaluated() {
    let s = FireflySettings::default().population(10);
    let (r, h, calls) = sphere_run(s, Termination::default().max_evaluations(4));
    assert_eq!((r.evaluations, calls, r.generations), (4, 4, 0));
    assert_eq!(r.stop_reason, StopReason::EvaluationBudget);
    assert!(r.best_f.is_finite());
    assert_eq!(h.len(), 1);
}
