//! Unit tests of the swarm moves and generations.

use super::*;
use proptest::prelude::*;

fn mover(lo: f64, hi: f64, boundary: BoundaryHandling) -> Mover {
    Mover {
        lo: vec![lo],
        hi: vec![hi],
        width: vec![hi - lo],
        dist_scale: vec![1.0],
        beta0: 1.0,
        beta_min: 0.0,
        gamma: 1.0,
        boundary,
    }
}

#[test]
fn clamp_projects_onto_bounds() {
    let m = mover(-1.0, 2.0, BoundaryHandling::Clamp);
    assert_eq!(m.confine(0.5, m.lo[0], m.hi[0]), 0.5);
    assert_eq!(m.confine(-3.0, m.lo[0], m.hi[0]), -1.0);
    assert_eq!(m.confine(7.0, m.lo[0], m.hi[0]), 2.0);
    assert_eq!(m.confine(f64::NAN, m.lo[0], m.hi[0]), -1.0);
    assert_eq!(m.confine(f64::INFINITY, m.lo[0], m.hi[0]), 2.0);
}

#[test]
fn reflect_mirrors_and_folds() {
    let m = mover(0.0, 1.0, BoundaryHandling::Reflect);
    assert_eq!(m.confine(0.25, m.lo[0], m.hi[0]), 0.25);
    assert!((m.confine(1.25, m.lo[0], m.hi[0]) - 0.75).abs() < 1e-15);
    assert!((m.confine(-0.25, m.lo[0], m.hi[0]) - 0.25).abs() < 1e-15);
    // Overshoot by more than a width folds again: 2.25 -> 0.25.
    assert!((m.confine(2.25, m.lo[0], m.hi[0]) - 0.25).abs() < 1e-15);
    assert!((m.confine(-1.75, m.lo[0], m.hi[0]) - 0.25).abs() < 1e-15);
    assert_eq!(m.confine(f64::NEG_INFINITY, m.lo[0], m.hi[0]), 0.0);
    let fixed = mover(3.0, 3.0, BoundaryHandling::Reflect);
    assert_eq!(fixed.confine(5.0, fixed.lo[0], fixed.hi[0]), 3.0);
}

#[test]
fn attraction_with_full_beta_and_no_noise_lands_on_target() {
    let m = Mover {
        gamma: 0.0,
        ..mover(-10.0, 10.0, BoundaryHandling::Clamp)
    };
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut xi = [1.0];
    m.attract(&mut xi, &[4.0], 0.0, &mut rng);
    assert_eq!(xi, [4.0]);
    // beta = beta0 exp(-gamma r^2) with gamma = 1, r = 1.
    let m = mover(-10.0, 10.0, BoundaryHandling::Clamp);
    let mut xi = [0.0];
    m.attract(&mut xi, &[1.0], 0.0, &mut rng);
    assert!((xi[0] - (-1.0f64).exp()).abs() < 1e-15);
}

#[test]
fn two_rows_returns_the_right_rows() {
    let mut buf = [0.0, 1.0, 10.0, 11.0, 20.0, 21.0];
    let (a, b) = two_rows(&mut buf, 2, 0, 2);
    assert_eq!((a.to_vec(), b.to_vec()), (vec![20.0, 21.0], vec![0.0, 1.0]));
    let (a, b) = two_rows(&mut buf, 0, 1, 2);
    assert_eq!((a.to_vec(), b.to_vec()), (vec![0.0, 1.0], vec![10.0, 11.0]));
}

#[test]
fn capped_limits() {
    assert_eq!(capped(10, None), 10);
    assert_eq!(capped(10, Some(3)), 3);
    assert_eq!(capped(10, Some(30)), 10);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn confine_always_lands_in_box(
        lo in -1e6f64..1e6,
        w in 0.0f64..1e3,
        v in -1e7f64..1e7,
        reflect in any::<bool>(),
    ) {
        let hi = lo + w;
        let b = if reflect { BoundaryHandling::Reflect } else { BoundaryHandling::Clamp };
        let m = mover(lo, hi, b);
        let c = m.confine(v, m.lo[0], m.hi[0]);
        prop_assert!(lo <= c && c <= hi, "{} -> {} not in [{}, {}]", v, c, lo, hi);
    }

    #[test]
    fn budget_is_exact_for_any_limit(
        n in 1usize..12,
        budget in 1u64..200,
        variant in 0usize..3,
        walk in any::<bool>(),
        seed in any::<u64>(),
    ) {
        let variant = [Variant::Snapshot, Variant::Classic, Variant::ClassicSweep][variant];
        let bounds = Bounds::cube(3, -1.0, 1.0).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let s = FireflySettings::default()
            .population(n)
            .variant(variant)
            .best_random_walk(walk)
            .seed(seed);
        let mut swarm = Swarm::new(&bounds, &s, &[]).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let mut calls = 0u64;
        let mut f = |x: &[f64]| { calls += 1; x.iter().map(|v| v * v).sum::<f64>() };
        swarm.initialize(&mut f, Some(budget));
        for _ in 0..50 {
            let left = budget - swarm.evaluations();
            swarm.step(&mut f, Some(left));
        }
        prop_assert!(swarm.evaluations() <= budget);
        prop_assert_eq!(swarm.evaluations(), calls);
    }
}
