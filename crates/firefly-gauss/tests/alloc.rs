//! An objective evaluation (completion of the dependent coordinates by Newton on the
//! partition's equations, velocities, Gauss residuals) allocates nothing, with and without
//! redundant equations: every buffer is sized once when the solver is built.

use mbd_firefly_gauss::{FaDaeOptions, FireflyGauss};
use mbd_model::{models, System};
use mbd_solve::{Integrator, State};
use mbd_testkit::allocations_during;

#[global_allocator]
static GLOBAL: mbd_testkit::CountingAlloc = mbd_testkit::CountingAlloc;

fn check(name: &str, sys: &System) {
    let mut fa = FireflyGauss::new(sys, FaDaeOptions::default()).expect(name);
    let mut s = State::consistent(sys, 0.0).expect(name);
    // the double parallelogram re-chooses its partition (equations too) near t = 0.3
    for _ in 0..40 {
        fa.step(sys, &mut s, 1e-2).expect(name);
    }
    let x = fa.last_solution().to_vec();
    let mut f = 0.0;
    let n = allocations_during(|| {
        for _ in 0..10 {
            f += fa.objective_at(sys, &x);
        }
    });
    assert!(f.is_finite(), "{name}: {f}");
    assert_eq!(n, 0, "{name}: {n} allocations in 10 evaluations");
}

#[test]
fn objective_evaluations_do_not_allocate() {
    let probe = allocations_during(|| {
        std::hint::black_box(vec![1u8; 16]);
    });
    assert!(probe >= 1, "the counter works");
    check("manipulator", &models::manipulator().expect("model"));
    check(
        "double parallelogram",
        &models::double_parallelogram(0.4, 1.0, -0.5, 0.0, false).expect("model"),
    );
    check(
        "pantograph",
        &models::pantograph(0.4, 1.0, 0.5, -0.5, 0.0, false).expect("model"),
    );
}
