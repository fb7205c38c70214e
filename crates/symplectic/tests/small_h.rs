//! At small h the solution must not depend on the predictor, and the error must not grow as h
//! falls. The multistep predictor's residual falls below the Newton tolerance at
//! small h; accepted without a correction, its smooth error accumulated from step to step (at
//! t = 2 s on the manipulator the (2,2) error rose from 5.1e-10 at h = 6.25e-4 to 2.0e-8 at
//! h = 1.56e-4), and the end momentum computed as `D_s L_d` divided the displacements' Newton
//! and rounding errors by h (the (3,3) error rose from 2.3e-12 at h = 1.25e-3 to 3.2e-10 at
//! h = 9.8e-6 even when at least two Newton updates per step were forced).
mod common;
use mbd_model::models;
use mbd_model::{Body, System, SystemBuilder};
use mbd_solve::linalg::max_abs_diff;
use mbd_solve::{reference_trajectory, ButcherTableau, Integrator, State};
use mbd_symplectic::{Galerkin, SymplecticOptions};

/// `n` steps of `t_end / n` from `s0`; the final state.
fn integrate(sys: &System, s0: &State, opts: SymplecticOptions, t_end: f64, n: usize) -> State {
    let h = t_end / n as f64;
    let mut g = Galerkin::new(sys, opts).unwrap();
    let mut st = s0.clone();
    for k in 1..=n {
        g.step(sys, &mut st, h).unwrap();
        st.t = k as f64 * h;
    }
    st
}

fn with_predictor(s: usize, p: usize) -> SymplecticOptions {
    SymplecticOptions {
        predictor_order: p,
        ..SymplecticOptions::new(s)
    }
}

/// (1,1) and (2,2) on the manipulator over 2 s at h = 3.1e-4 and 7.8e-5: predictor orders 3
/// and 6 give the solution of order 0 to round-off. Measured: at most 3.3e-13 in q (the (2,2)
/// errors at these h are 1.8e-11 and 3.7e-13). Before the fix the (2,2) runs with orders 3 and
/// 0 differed by 2.5e-9 and 4.2e-8, the (1,1) runs by 2.3e-9 and 4.4e-8.
#[test]
fn predictor_order_does_not_change_the_solution_at_small_h() {
    let sys = models::manipulator().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    for s in [1, 2] {
        for n in [6400, 25600] {
            let base = integrate(&sys, &s0, with_predictor(s, 0), 2.0, n);
            for p in [3, 6] {
                let st = integrate(&sys, &s0, with_predictor(s, p), 2.0, n);
                let d = max_abs_diff(st.q.as_slice(), base.q.as_slice());
                println!(
                    "({s},{s}) h = {:.3e}, p = {p}: |q - q(p = 0)| = {d:.2e}",
                    2.0 / n as f64
                );
                assert!(
                    d <= 2e-12,
                    "({s},{s}) h = {}, p = {p}: {d:e}",
                    2.0 / n as f64
                );
            }
        }
    }
}

/// The (3,3) error at t = 2 s on the manipulator stays at the round-off floor as h falls
/// from 6.25e-4 to 1.56e-4 (measured 1.9e-13 at both against DOPRI5 + projection with 2^15
/// steps, which agrees with the (4,4) scheme to 2e-13). Before: 7.5e-10 and 2.0e-8.
#[test]
fn error_stays_at_the_floor_as_h_falls() {
    let sys = models::manipulator().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let r = reference_trajectory(&sys, &s0, 2.0, 1, 1 << 15, ButcherTableau::dopri5()).unwrap();
    for n in [3200, 12800] {
        let st = integrate(&sys, &s0, SymplecticOptions::new(3), 2.0, n);
        let e = max_abs_diff(st.q.as_slice(), &r.q[1]);
        println!("(3,3) h = {:.3e}: error {e:.2e}", 2.0 / n as f64);
        assert!(e <= 2e-12, "(3,3) h = {}: error {e:e}", 2.0 / n as f64);
    }
}

/// A free body (no constraints, no forces) keeps its velocity exactly: the end momentum is the
/// start momentum plus the impulse (zero), not `D_s L_d` with its rounded coefficients and the
/// Newton error of the displacements divided by h. Before: |v - v0| = 2.2e-7, 5.1e-10, 7.9e-10,
/// 8.6e-10 for s = 1..4 after 20000 steps.
#[test]
fn free_body_momentum_is_conserved() {
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, 0.0]);
    b.add_body(
        Body::new("free")
            .mass(1.3)
            .inertia(0.7)
            .position(0.1, 0.2, 0.3)
            .velocity(0.9, -0.4, 2.3),
    );
    let sys = b.build().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    for s in 1..=4 {
        let st = integrate(&sys, &s0, SymplecticOptions::new(s), 1.0, 20_000);
        let dv = max_abs_diff(st.v.as_slice(), s0.v.as_slice());
        println!("s = {s}: |v - v0| = {dv:.2e}");
        assert!(dv <= 1e-14, "s = {s}: |v - v0| = {dv:e}");
    }
}
