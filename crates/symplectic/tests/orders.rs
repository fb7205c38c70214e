//! Measured convergence orders 2s for s = 1..4, positions and energy, on the single pendulum
//! (amplitude 1 rad, t = 1 s) and the manipulator (t = 0.5 s; see the note below). Reference:
//! `mbd_solve::reference_trajectory` with DOPRI5 + projection at h = 2.5e-5 (independent of the
//! scheme). Step sizes are chosen so every error is far above the round-off floor (~1e-13).
mod common;
use common::*;
use mbd_model::models;
use mbd_solve::{reference_trajectory, ButcherTableau, State};
use mbd_symplectic::{Nodes, SymplecticOptions};

fn check(sys: &mbd_model::System, table: &[(usize, f64, &[usize])], label: &str) {
    let s0 = State::consistent(sys, 0.0).unwrap();
    for &(s, t_end, ns) in table {
        let r = reference_trajectory(sys, &s0, t_end, 1, 40000, ButcherTableau::dopri5()).unwrap();
        let mut hs = Vec::new();
        let (mut eq, mut eh) = (Vec::new(), Vec::new());
        for &n in ns {
            let h = t_end / n as f64;
            let (st, e_h) = run(sys, &s0, tight(s), h, n);
            hs.push(h);
            eq.push(max_abs_diff(st.q.as_slice(), &r.q[1]));
            eh.push(e_h);
        }
        let (pq, ph) = (slope(&hs, &eq), slope(&hs, &eh));
        println!(
            "{label} s={s}: position errors {eq:?} slope {pq:.3}; energy {eh:?} slope {ph:.3}"
        );
        let target = 2.0 * s as f64;
        assert!(
            (pq - target).abs() <= 0.3,
            "{label} s={s}: position order {pq}"
        );
        assert!(
            (ph - target).abs() <= 0.3,
            "{label} s={s}: energy order {ph}"
        );
        assert!(
            eq.iter().chain(&eh).all(|&e| e > 2e-13),
            "too close to round-off"
        );
    }
}

#[test]
fn order_2s_on_the_single_pendulum() {
    let sys = models::pendulum(1.0, 1.0, 1.0, 9.81).unwrap();
    check(
        &sys,
        &[
            (1, 1.0, &[10, 20, 40]),
            (2, 1.0, &[10, 20, 40]),
            (3, 1.0, &[8, 12, 16, 24]),
            (4, 1.0, &[7, 10, 14]),
        ],
        "pendulum",
    );
}

/// The manipulator is measured over 0.5 s (0.6 s for s = 4): over 1 s its second link whips
/// (fast rotation near t = 0.8-1 s) and the s = 4 errors reach the asymptotic regime only at the
/// round-off floor (slopes 8.7-9 between h = 1/40 and 1/160 s); over 0.5 s the s = 4 errors
/// fall below 1e-12 before the slope settles (7.6-7.7 for n = 9..16).
#[test]
fn order_2s_on_the_manipulator() {
    let sys = models::manipulator().unwrap();
    check(
        &sys,
        &[
            (1, 0.5, &[10, 14, 20]),
            (2, 0.5, &[10, 14, 20]),
            (3, 0.5, &[10, 14, 20]),
            (4, 0.6, &[18, 24, 32]),
        ],
        "manipulator",
    );
}

/// With equally spaced control points the constraint forces are lumped by Newton-Cotes weights:
/// order 4 for s = 3 (not 6). Documents why the default is Lobatto points.
#[test]
fn equispaced_nodes_lose_order_at_s3() {
    let sys = models::pendulum(1.0, 1.0, 1.0, 9.81).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let r = reference_trajectory(&sys, &s0, 1.0, 1, 40000, ButcherTableau::dopri5()).unwrap();
    let mut hs = Vec::new();
    let mut es = Vec::new();
    for n in [10usize, 20, 40] {
        let mut o: SymplecticOptions = tight(3).with_nodes(Nodes::Equispaced);
        o.newton.tol = 1e-17;
        let (st, _) = run(&sys, &s0, o, 1.0 / n as f64, n);
        hs.push(1.0 / n as f64);
        es.push(max_abs_diff(st.q.as_slice(), &r.q[1]));
    }
    let p = slope(&hs, &es);
    assert!((p - 4.0).abs() < 0.3, "equispaced s=3 order {p}");
}
