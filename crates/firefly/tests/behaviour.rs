//! NaN handling, boxes, boundary handling, initial positions, observers and
//! manual stepping.

use std::cell::Cell;

use mbd_firefly::{
    testfns, BoundaryHandling, Bounds, DistanceScaling, Firefly, FireflySettings, History,
    StopReason, Swarm, Termination, Variant,
};

const VARIANTS: [Variant; 3] = [Variant::Snapshot, Variant::Classic, Variant::ClassicSweep];

#[test]
fn nan_on_half_the_box_is_counted_and_survived() {
    for variant in VARIANTS {
        let bounds = Bounds::cube(3, -2.0, 2.0).expect("valid box");
        let nans = Cell::new(0u64);
        let mut f = |x: &[f64]| {
            if x[0] < 0.0 {
                nans.set(nans.get() + 1);
                f64::NAN
            } else {
                testfns::sphere(&[x[0] - 0.5, x[1], x[2]])
            }
        };
        let r = Firefly::new(bounds)
            .settings(
                FireflySettings::default()
                    .population(20)
                    .alpha(0.2)
                    .alpha_decay(0.95)
                    .variant(variant),
            )
            .termination(
                Termination::default()
                    .max_generations(150)
                    .max_evaluations(30_000),
            )
            .minimize(&mut f)
            .expect("valid configuration");
        assert!(nans.get() > 0);
        assert_eq!(r.nan_evaluations, nans.get(), "{variant:?}");
        assert!(
            r.best_f.is_finite() && r.best_f < 1e-3,
            "{variant:?}: {}",
            r.best_f
        );
        assert!(r.best_x[0] >= 0.0);
    }
}

#[test]
fn all_non_finite_objective_never_panics() {
    for variant in VARIANTS {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let bounds = Bounds::cube(2, -1.0, 1.0).expect("valid box");
            let mut h = History::new();
            let r = Firefly::new(bounds)
                .settings(FireflySettings::default().population(6).variant(variant))
                .termination(Termination::default().max_generations(5).stagnation(3, 0.0))
                .observer(&mut h)
                .minimize(&mut |_: &[f64]| bad)
                .expect("valid configuration");
            assert_eq!(r.best_f, f64::INFINITY);
            assert_eq!(r.nan_evaluations, r.evaluations);
            assert_eq!(r.best_x.len(), 2);
            assert_eq!(r.stop_reason, StopReason::Stagnation);
            assert!(h.records.iter().all(|rec| rec.mean_f.is_nan()));
        }
    }
}

#[test]
fn every_evaluated_point_lies_in_the_box() {
    let lo = [-1.0, 0.0, 2.0, 5.0];
    let hi = [1.0, 0.001, 2.0, 50.0];
    for boundary in [BoundaryHandling::Clamp, BoundaryHandling::Reflect] {
        for distance in [DistanceScaling::Normalized, DistanceScaling::Raw] {
            for variant in VARIANTS {
                let bounds = Bounds::new(lo.to_vec(), hi.to_vec()).expect("valid box");
                let outside = Cell::new(0u32);
                let mut f = |x: &[f64]| {
                    if !bounds.contains(x) || x[2] != 2.0 {
                        outside.set(outside.get() + 1);
                    }
                    // Optimum outside the box pushes fireflies against the bounds.
                    (x[0] - 3.0).powi(2) + x[1] + (x[3] + 10.0).abs()
                };
                let r = Firefly::new(bounds.clone())
                    .settings(
                        FireflySettings::default()
                            .population(12)
                            .alpha(1.0)
                            .boundary(boundary)
                            .distance(distance)
                            .variant(variant),
                    )
                    .termination(Termination::default().max_generations(20))
                    .minimize(&mut f)
                    .expect("valid configuration");
                assert_eq!(outside.get(), 0, "{boundary:?} {distance:?} {variant:?}");
                assert!(bounds.contains(&r.best_x));
                // Zero-width dimension fixed exactly.
                assert_eq!(r.best_x[2], 2.0);
            }
        }
    }
}

#[test]
fn initial_positions_are_used_first() {
    let bounds = Bounds::cube(2, -1.0, 1.0).expect("valid box");
    let seen: std::cell::RefCell<Vec<Vec<f64>>> = Default::default();
    let mut f = |x: &[f64]| {
        seen.borrow_mut().push(x.to_vec());
        testfns::sphere(x)
    };
    let starts = vec![vec![0.25, -0.5], vec![1.0, 1.0]];
    let r = Firefly::new(bounds)
        .settings(FireflySettings::default().population(5))
        .initial_positions(starts.clone())
        .termination(Termination::default().max_generations(0))
        .minimize(&mut f)
        .expect("valid configuration");
    let seen = seen.into_inner();
    assert_eq!(seen.len(), 5);
    assert_eq!(&seen[..2], &starts[..]);
    assert!(r.best_f <= testfns::sphere(&starts[0]));
}

#[test]
fn predictor_in_population_is_never_lost() {
    // A good predictor seeded into the population bounds the result.
    let bounds = Bounds::cube(5, -3.0, 3.0).expect("valid box");
    let predictor = vec![1e-3; 5];
    let r = Firefly::new(bounds)
        .settings(FireflySettings::default().population(8))
        .initial_position(predictor.clone())
        .termination(Termination::default().max_generations(3))
        .minimize(&mut testfns::rastrigin)
        .expect("valid configuration");
    assert!(r.best_f <= testfns::rastrigin(&predictor));
}

#[test]
fn history_records_are_consistent() {
    let bounds = Bounds::cube(3, -5.0, 5.0).expect("valid box");
    let mut h = History::new();
    let mut count = 0usize;
    let mut counter = |_: &mbd_firefly::GenerationRecord| count += 1;
    let r = Firefly::new(bounds)
        .settings(
            FireflySettings::default()
                .population(10)
                .alpha(0.5)
                .alpha_decay(0.9),
        )
        .termination(Termination::default().max_generations(25))
        .observer(&mut h)
        .observer(&mut counter)
        .minimize(&mut testfns::ackley)
        .expect("valid configuration");
    assert_eq!(count, 26);
    assert_eq!(h.len(), 26);
    assert!(!h.is_empty());
    for (t, rec) in h.records.iter().enumerate() {
        assert_eq!(rec.generation, t as u64);
        assert_eq!(rec.evaluations, 10 * (t as u64 + 1));
        assert!(rec.mean_f >= rec.best_f);
        let expected_alpha = if t == 0 {
            0.5
        } else {
            0.5 * 0.9f64.powi(t as i32 - 1)
        };
        assert!((rec.alpha - expected_alpha).abs() <= 1e-15);
    }
    assert!(h.best_values().windows(2).all(|w| w[1] <= w[0]));
    assert_eq!(h.records[25].best_f, r.best_f);
    assert!((r.final_alpha - 0.5 * 0.9f64.powi(25)).abs() <= 1e-15);
}

#[test]
fn no_random_walk_keeps_leaders_in_place() {
    // Without the random walk a lone firefly never moves and is never
    // re-evaluated; a generation costs nothing.
    let bounds = Bounds::cube(2, -1.0, 1.0).expect("valid box");
    for variant in VARIANTS {
        let r = Firefly::new(bounds.clone())
            .settings(
                FireflySettings::default()
                    .population(1)
                    .best_random_walk(false)
                    .variant(variant),
            )
            .termination(Termination::default().max_generations(10))
            .minimize(&mut testfns::sphere)
            .expect("valid configuration");
        assert_eq!(r.evaluations, 1, "{variant:?}");
    }
}

#[test]
fn population_of_one_random_walks() {
    let bounds = Bounds::cube(2, -1.0, 1.0).expect("valid box");
    let r = Firefly::new(bounds)
        .settings(
            FireflySettings::default()
                .population(1)
                .alpha(0.3)
                .alpha_decay(0.99),
        )
        .termination(Termination::default().max_generations(300))
        .minimize(&mut testfns::sphere)
        .expect("valid configuration");
    // A lone firefly has nobody to follow: it only random-walks (no
    // acceptance step), evaluated once per generation.
    assert_eq!(r.evaluations, 301);
    assert_eq!(r.generations, 300);
    assert!(r.best_f.is_finite());
}

#[test]
fn swarm_can_be_stepped_by_hand() {
    let bounds = Bounds::cube(3, -2.0, 2.0).expect("valid box");
    let settings = FireflySettings::default().population(8).seed(5);
    let mut swarm = Swarm::new(&bounds, &settings, &[vec![0.5; 3]]).expect("valid");
    assert_eq!((swarm.population(), swarm.dim()), (8, 3));
    assert_eq!(swarm.position(0), Some(&[0.5, 0.5, 0.5][..]));
    assert_eq!(swarm.position(8), None);
    let mut f = testfns::sphere;
    swarm.initialize(&mut f, None);
    assert_eq!(swarm.evaluations(), 8);
    for _ in 0..5 {
        swarm.step(&mut f, None);
    }
    assert_eq!(swarm.generation(), 5);
    assert_eq!(swarm.evaluations(), 48);
    assert!(swarm.best_f() <= 0.75);
    assert!(swarm.fitness(0).is_some() && swarm.fitness(8).is_none());
    assert_eq!(swarm.record().generation, 5);
    assert!((swarm.alpha() - 0.7 * 0.97f64.powi(5)).abs() < 1e-15);

    // The same through the driver gives the same best value.
    let r = Firefly::new(bounds)
        .settings(settings)
        .initial_position(vec![0.5; 3])
        .termination(Termination::default().max_generations(5))
        .minimize(&mut f)
        .expect("valid configuration");
    assert_eq!(r.best_f.to_bits(), swarm.best_f().to_bits());
}

#[test]
fn centered_box_around_predictor() {
    let b = Bounds::centered(&[1.0, -2.0], &[0.5, 0.0]).expect("valid");
    assert_eq!(b.lo(), &[0.5, -2.0]);
    assert_eq!(b.hi(), &[1.5, -2.0]);
    assert_eq!(b.width(0), Some(1.0));
    assert_eq!(b.width(2), None);
    assert!(b.contains(&[1.0, -2.0]));
    assert!(!b.contains(&[1.0, -1.9]));
    assert!(!b.contains(&[1.0]));
}
