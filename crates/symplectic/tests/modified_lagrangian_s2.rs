//! The modified-Lagrangian preadjustment of the (2,2) scheme (`h^5 e4` at the chord midpoint,
//! `docs/symplectic.md` section 5b): the rod pendulum's period error falls with order 6 at
//! 45 degrees, where the plain (2,2) scheme's falls with order 4.
use mbd_analysis::period;
use mbd_model::models;
use mbd_solve::{Integrator, State};
use mbd_symplectic::{Galerkin, PreadjustMode, SymplecticOptions};
use std::f64::consts::PI;

/// Relative period error of the (2,2) scheme on the uniform rod (1 kg, 1 m) released at rest
/// `theta0` from the downward vertical, over about `periods` periods (as in
/// `modified_lagrangian.rs`).
fn period_error(theta0: f64, h: f64, modified: bool, periods: f64) -> f64 {
    let (l, g) = (1.0, 9.81);
    let sys = models::pendulum(1.0, l, theta0, g).unwrap();
    let te = period::pendulum_period((1.5 * g / l).sqrt(), theta0).unwrap();
    let mut st = State::consistent(&sys, 0.0).unwrap();
    let mut o = SymplecticOptions::new(2);
    if modified {
        o = o.with_preadjust(PreadjustMode::ModifiedLagrangian);
    }
    let mut sch = Galerkin::new(&sys, o).unwrap();
    let n = (periods * te / h).ceil() as usize + 4;
    let mut psi = Vec::with_capacity(n + 1);
    psi.push(st.q[2] + PI / 2.0);
    for _ in 0..n {
        sch.step(&sys, &mut st, h).unwrap();
        psi.push(st.q[2] + PI / 2.0);
    }
    period::oscillation_period(&psi, 0.0, h, 6).unwrap() / te - 1.0
}

#[test]
fn pendulum_period_order_six_without_parameter() {
    let th = 45f64.to_radians();
    let (p1, p2) = (
        period_error(th, 0.1, false, 20.0),
        period_error(th, 0.05, false, 20.0),
    );
    let (m1, m2) = (
        period_error(th, 0.1, true, 20.0),
        period_error(th, 0.05, true, 20.0),
    );
    let (op, om) = ((p1 / p2).abs().log2(), (m1 / m2).abs().log2());
    eprintln!(
        "45 deg, (2,2): plain {p1:.3e} / {p2:.3e} (order {op:.2}); modified Lagrangian \
         {m1:.3e} / {m2:.3e} (order {om:.2})"
    );
    assert!((3.7..4.3).contains(&op), "plain order {op}");
    assert!(om >= 5.5, "modified-Lagrangian order {om}");
    assert!(m2.abs() < 0.05 * p2.abs(), "{m2} vs {p2}");
}
