//! Every kind of bad input is an error naming the culprit, never a panic, and
//! the objective is never called.

use mbd_firefly::{Bounds, Firefly, FireflyError, FireflySettings, Objective, Termination};

fn cube2() -> Bounds {
    Bounds::cube(2, -1.0, 1.0).expect("valid box")
}

/// Runs with the given settings/termination/initial positions and checks
/// that the objective was never called.
fn run(
    bounds: Bounds,
    settings: FireflySettings,
    termination: Termination,
    initial: Vec<Vec<f64>>,
) -> FireflyError {
    let mut calls = 0u32;
    let mut f = |x: &[f64]| {
        calls += 1;
        x[0]
    };
    let err = Firefly::new(bounds)
        .settings(settings)
        .termination(termination)
        .initial_positions(initial)
        .minimize(&mut f)
        .expect_err("configuration must be rejected");
    assert_eq!(calls, 0, "objective called despite invalid input");
    err
}

fn bad_settings(s: FireflySettings) -> FireflyError {
    run(cube2(), s, Termination::default(), vec![])
}

fn bad_termination(t: Termination) -> FireflyError {
    run(cube2(), FireflySettings::default(), t, vec![])
}

fn bad_initial(initial: Vec<Vec<f64>>) -> FireflyError {
    run(
        cube2(),
        FireflySettings::default().population(3),
        Termination::default(),
        initial,
    )
}

fn assert_names(err: &FireflyError, word: &str) {
    let msg = err.to_string();
    assert!(msg.contains(word), "message `{msg}` does not name `{word}`");
}

#[test]
fn empty_box() {
    assert_eq!(Bounds::new(vec![], vec![]), Err(FireflyError::EmptyBounds));
    assert_eq!(Bounds::cube(0, -1.0, 1.0), Err(FireflyError::EmptyBounds));
}

#[test]
fn bounds_length_mismatch() {
    let e = Bounds::new(vec![0.0, 0.0], vec![1.0]).expect_err("mismatch");
    assert_eq!(e, FireflyError::BoundsLengthMismatch { lo: 2, hi: 1 });
}

#[test]
fn lo_greater_than_hi() {
    let e = Bounds::new(vec![0.0, 2.0, 0.0], vec![1.0, 1.0, 1.0]).expect_err("inverted");
    assert!(matches!(e, FireflyError::InvertedBound { dim: 1, .. }));
    assert_names(&e, "dimension 1");
}

#[test]
fn non_finite_bounds() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let e = Bounds::new(vec![0.0, bad], vec![1.0, 1.0]).expect_err("non-finite lo");
        assert!(matches!(e, FireflyError::NonFiniteBound { dim: 1, .. }));
        let e = Bounds::new(vec![0.0, 0.0], vec![bad, 1.0]).expect_err("non-finite hi");
        assert!(matches!(e, FireflyError::NonFiniteBound { dim: 0, .. }));
        assert_names(&e, "dimension 0");
    }
}

#[test]
fn bad_half_width() {
    let e = Bounds::centered(&[0.0, 0.0], &[1.0, -1.0]).expect_err("negative");
    assert!(matches!(e, FireflyError::InvalidHalfWidth { dim: 1, .. }));
    let e = Bounds::centered(&[0.0, 0.0], &[f64::NAN, 1.0]).expect_err("NaN");
    assert!(matches!(e, FireflyError::InvalidHalfWidth { dim: 0, .. }));
    let e = Bounds::centered(&[0.0], &[1.0, 1.0]).expect_err("length");
    assert!(matches!(e, FireflyError::BoundsLengthMismatch { .. }));
    let e = Bounds::centered(&[f64::INFINITY], &[1.0]).expect_err("infinite centre");
    assert!(matches!(e, FireflyError::NonFiniteBound { dim: 0, .. }));
}

#[test]
fn zero_width_dimension_is_allowed() {
    assert!(Bounds::new(vec![0.0, 1.0], vec![1.0, 1.0]).is_ok());
}

#[test]
fn population_zero() {
    let e = bad_settings(FireflySettings::default().population(0));
    assert_eq!(e, FireflyError::ZeroPopulation);
    assert_names(&e, "population");
}

fn assert_param(e: FireflyError, name: &str) {
    match &e {
        FireflyError::InvalidParameter { name: n, .. } => assert_eq!(*n, name),
        other => panic!("expected InvalidParameter({name}), got {other:?}"),
    }
    assert_names(&e, name);
}

#[test]
fn negative_gamma() {
    assert_param(
        bad_settings(FireflySettings::default().gamma(-1.0)),
        "gamma",
    );
    assert_param(
        bad_settings(FireflySettings::default().gamma(f64::NAN)),
        "gamma",
    );
    assert_param(
        bad_settings(FireflySettings::default().gamma(f64::INFINITY)),
        "gamma",
    );
}

#[test]
fn negative_beta0() {
    assert_param(
        bad_settings(FireflySettings::default().beta0(-0.5)),
        "beta0",
    );
    assert_param(
        bad_settings(FireflySettings::default().beta0(f64::NAN)),
        "beta0",
    );
}

#[test]
fn bad_beta_min() {
    assert_param(
        bad_settings(FireflySettings::default().beta_min(-0.1)),
        "beta_min",
    );
    assert_param(
        bad_settings(FireflySettings::default().beta0(1.0).beta_min(1.5)),
        "beta_min",
    );
}

#[test]
fn negative_alpha() {
    assert_param(
        bad_settings(FireflySettings::default().alpha(-0.1)),
        "alpha",
    );
    assert_param(
        bad_settings(FireflySettings::default().alpha(f64::INFINITY)),
        "alpha",
    );
}

#[test]
fn decay_outside_unit_interval() {
    for d in [0.0, -0.5, 1.0001, f64::NAN, f64::INFINITY] {
        assert_param(
            bad_settings(FireflySettings::default().alpha_decay(d)),
            "alpha_decay",
        );
    }
}

#[test]
fn initial_position_wrong_dimension() {
    let e = bad_initial(vec![vec![0.0, 0.0], vec![0.0, 0.0, 0.0]]);
    assert_eq!(
        e,
        FireflyError::InitialPositionDimension {
            index: 1,
            expected: 2,
            found: 3
        }
    );
}

#[test]
fn initial_position_outside_box() {
    let e = bad_initial(vec![vec![0.0, 1.5]]);
    assert!(matches!(
        e,
        FireflyError::InitialPositionOutOfBounds {
            index: 0,
            dim: 1,
            ..
        }
    ));
    assert_names(&e, "dimension 1");
    let e = bad_initial(vec![vec![f64::NAN, 0.0]]);
    assert!(matches!(
        e,
        FireflyError::InitialPositionOutOfBounds { dim: 0, .. }
    ));
}

#[test]
fn too_many_initial_positions() {
    let e = bad_initial(vec![vec![0.0, 0.0]; 4]);
    assert_eq!(
        e,
        FireflyError::TooManyInitialPositions {
            given: 4,
            population: 3
        }
    );
}

struct ThreeDim;

impl Objective for ThreeDim {
    fn eval(&mut self, x: &[f64]) -> f64 {
        x.iter().sum()
    }
    fn dim(&self) -> Option<usize> {
        Some(3)
    }
}

#[test]
fn objective_dimension_mismatch() {
    let e = Firefly::new(cube2())
        .minimize(&mut ThreeDim)
        .expect_err("dimension mismatch");
    assert_eq!(
        e,
        FireflyError::ObjectiveDimension {
            objective: 3,
            bounds: 2
        }
    );
}

#[test]
fn unbounded_termination() {
    assert_eq!(
        bad_termination(Termination::none().target(0.0)),
        FireflyError::Unbounded
    );
}

#[test]
fn zero_budget() {
    assert_param(
        bad_termination(Termination::default().max_evaluations(0)),
        "max_evaluations",
    );
}

#[test]
fn nan_target() {
    assert_param(
        bad_termination(Termination::default().target(f64::NAN)),
        "target",
    );
}

#[test]
fn bad_stagnation() {
    assert_param(
        bad_termination(Termination::default().stagnation(0, 1e-9)),
        "stagnation.generations",
    );
    assert_param(
        bad_termination(Termination::default().stagnation(5, -1.0)),
        "stagnation.tolerance",
    );
    assert_param(
        bad_termination(Termination::default().stagnation(5, f64::NAN)),
        "stagnation.tolerance",
    );
}

#[test]
fn parallel_entry_point_validates_too() {
    let e = Firefly::new(cube2())
        .settings(FireflySettings::default().gamma(-2.0))
        .minimize_parallel(&|x: &[f64]| x[0])
        .expect_err("invalid gamma");
    assert!(matches!(
        e,
        FireflyError::InvalidParameter { name: "gamma", .. }
    ));
}

#[test]
fn absurd_population_is_rejected_not_allocated() {
    assert_param(
        bad_settings(FireflySettings::default().population(usize::MAX)),
        "population",
    );
}
