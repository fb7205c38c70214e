//! The preadjusted symplectic schemes on spatial bodies (natural coordinates, a constant
//! diagonal mass matrix and quadratic constraints, internal ones included): the s = 1
//! modified Lagrangian and paper A's `W_s` on the solid heavy top and the spatial double
//! pendulum, their orders against an RK4 reference, the modified Lagrangian's gain over the
//! plain (1,1) scheme in the trajectory and in the energy of a torque-free body; the s = 2
//! modified Lagrangian's order 6 and gain over the plain (2,2) scheme.

mod common;
use mbd::model::models::{free_body, heavy_top, spatial_double_pendulum, sprung_rod};
use mbd::prelude::*;
use mbd::Simulation;

/// Errors at t against the reference for h, h/2, h/4, and the two fitted orders.
fn errors(sys: &System, spec: &str, t: f64, h: f64, reference: &State) -> (Vec<f64>, Vec<f64>) {
    let errs: Vec<f64> = [h, h / 2.0, h / 4.0]
        .iter()
        .map(|&h| {
            let s = common::end_state(sys, spec, RunConfig::new(t, h));
            assert!(
                common::max_phi_at(sys, &s) < 1e-12,
                "{spec} h = {h}: |Phi| {:e}",
                common::max_phi_at(sys, &s)
            );
            (&s.q - &reference.q).amax()
        })
        .collect();
    let orders = errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    (errs, orders)
}

/// Plain (s,s) against modified (s,s) on `sys` to `t` at h, h/2, h/4 against `reference`: the
/// plain scheme's fitted slopes within 0.3 of `2 s`, the modified one's within 0.3 of `2 s + 2`,
/// and the modified error at the smallest h more than `gain` times below the plain one.
fn plain_against_modified(
    name: &str,
    sys: &System,
    s: u32,
    (t, h): (f64, f64),
    reference: &State,
    gain: f64,
) {
    let (plain, po) = errors(sys, &format!("symplectic:{s}"), t, h, reference);
    let (modified, mo) = errors(sys, &format!("symplectic:{s}:modified"), t, h, reference);
    eprintln!(
        "{name}: plain ({s},{s}) errors {plain:?}, orders {po:.2?}; modified {modified:?}, \
         orders {mo:.2?}; gain at the smallest h {:.0}x",
        plain[2] / modified[2]
    );
    let order = f64::from(2 * s);
    assert!(po.iter().all(|p| (p - order).abs() < 0.3), "{name}: {po:?}");
    assert!(
        mo.iter().all(|p| (p - order - 2.0).abs() < 0.3),
        "{name}: {mo:?}"
    );
    assert!(
        plain[2] > gain * modified[2],
        "{name}: {plain:?} {modified:?}"
    );
}

/// Largest relative energy error over a run.
fn energy_drift(sys: &System, spec: &str, t: f64, h: f64) -> f64 {
    let mut sim = Simulation::new(sys.clone(), spec).unwrap();
    let s0 = sim.state().clone();
    let h0 = sys.energy(s0.q.as_slice(), s0.v.as_slice());
    let mut worst = 0.0f64;
    let mut watch = |_: &System, s: &State, _: usize| -> Result<Flow, SolveError> {
        worst = worst.max((sys.energy(s.q.as_slice(), s.v.as_slice()) - h0).abs() / h0.abs());
        Ok(Flow::Continue)
    };
    sim.run_observed(RunConfig::new(t, h), &mut watch).unwrap();
    worst
}

/// The s = 1 modified Lagrangian (derived for any constant mass matrix and holonomic
/// constraints, docs/symplectic.md section 5a) carries over to natural coordinates: on the
/// solid heavy top (t = 0.5 s, h = 4e-3 .. 1e-3), the spatial double pendulum and a rod on a
/// spring (a non-linear spatial potential; t = 1 s, h = 1e-2 .. 2.5e-3) the plain (1,1) scheme
/// has order 2 and the modified one order 4 (fitted slopes within 0.3), more than 1000x closer
/// to the RK4 reference at the smallest h.
#[test]
fn the_modified_lagrangian_reaches_order_four_on_spatial_models() {
    for (name, sys, t, h) in [
        (
            "solid top",
            heavy_top([0.3, 0.3, 0.1], 0.3, 20.0).unwrap(),
            0.5,
            4e-3,
        ),
        (
            "spatial double pendulum",
            spatial_double_pendulum().unwrap(),
            1.0,
            1e-2,
        ),
        (
            "rod on a spring",
            sprung_rod([0.05, 0.05, 0.002]).unwrap(),
            1.0,
            1e-2,
        ),
    ] {
        let reference = common::end_state(&sys, "rk4", RunConfig::new(t, h / 32.0));
        plain_against_modified(name, &sys, 1, (t, h), &reference, 1e3);
    }
}

/// The s = 2 modified Lagrangian (docs/symplectic.md section 5b) on spatial bodies: every
/// spatial equation is quadratic, so its passes' series end at degree two (docs/spatial.md,
/// "The preadjusted symplectic schemes"). On the solid heavy top and the disc top (`E_3 = 0`,
/// its massless director regularised in the term; t = 0.5 s, h = 2e-2 .. 5e-3) and the spatial
/// double pendulum (t = 1 s, h = 4e-2 .. 1e-2) the plain (2,2) scheme has order 4 and the
/// modified one order 6 (fitted slopes within 0.3), more than 100x closer to a (4,4) reference
/// at h/16 at the smallest h (measured 274x, 275x and 477x).
#[test]
fn the_s2_modified_lagrangian_reaches_order_six_on_spatial_models() {
    for (name, sys, t, h) in [
        (
            "solid top",
            heavy_top([0.3, 0.3, 0.1], 0.3, 20.0).unwrap(),
            0.5,
            2e-2,
        ),
        (
            "disc top",
            heavy_top([0.25, 0.25, 0.5], 0.3, 20.0).unwrap(),
            0.5,
            2e-2,
        ),
        (
            "spatial double pendulum",
            spatial_double_pendulum().unwrap(),
            1.0,
            4e-2,
        ),
        (
            "rod on a spring",
            sprung_rod([0.05, 0.05, 0.002]).unwrap(),
            1.0,
            2e-2,
        ),
    ] {
        let reference = common::end_state(&sys, "symplectic:4", RunConfig::new(t, h / 16.0));
        plain_against_modified(name, &sys, 2, (t, h), &reference, 1e2);
    }
}

/// On the torque-free body (J = (1, 2, 2.5), spun about its intermediate axis) over 20 s, the
/// s = 2 modified Lagrangian keeps the energy to `O(h^6)`: at 1/50 and 1/100 of the spin
/// period, order within 0.3 of 6 and more than 100x below the plain (2,2) scheme at 1/50
/// (measured over 100 s: 5.4e-10 / 8.4e-12 against 7.8e-8 / 4.9e-9).
#[test]
fn the_s2_modified_lagrangian_keeps_a_free_body_energy_to_order_six() {
    let sys = free_body([1.0, 2.0, 2.5], [0.05, 2.0, 0.05]).unwrap();
    let period = std::f64::consts::PI;
    let plain = energy_drift(&sys, "symplectic:2", 20.0, period / 50.0);
    let m: Vec<f64> = [50.0, 100.0]
        .iter()
        .map(|&k| energy_drift(&sys, "symplectic:2:modified", 20.0, period / k))
        .collect();
    let order = (m[0] / m[1]).log2();
    eprintln!("free body energy: plain (2,2) {plain:.1e}; modified {m:?}, order {order:.2}");
    assert!(plain > 1e2 * m[0], "{plain:e} {m:?}");
    assert!((order - 6.0).abs() < 0.3, "{m:?} {order}");
}

/// A singular mass matrix (the disc top, `J = (0.25, 0.25, 0.5)`: `E_3 = 0`): the augmented
/// metric (`M + G_int^T W G_int`, exact on the constraint manifold) gives the modified (1,1)
/// scheme its order 4 and the same gain over the plain scheme as on the solid top (t = 0.5 s,
/// h = 4e-3 .. 1e-3; more than 1000x at 1e-3), and `W_2` (gamma = 1) its order 4.
#[test]
fn a_thin_disc_takes_the_preadjusted_schemes_at_their_orders() {
    let sys = heavy_top([0.25, 0.25, 0.5], 0.3, 20.0).unwrap();
    let (t, h) = (0.5, 4e-3);
    let reference = common::end_state(&sys, "rk4", RunConfig::new(t, h / 32.0));
    let (plain, po) = errors(&sys, "symplectic:1", t, h, &reference);
    let (modified, mo) = errors(&sys, "symplectic:1:modified", t, h, &reference);
    let (paper, pa) = errors(&sys, "symplectic:2:gamma=1", t, h, &reference);
    eprintln!(
        "disc top: plain (1,1) {plain:?} (orders {po:.2?}); modified {modified:?} (orders \
         {mo:.2?}); W_2 {paper:?} (orders {pa:.2?}); gain {:.0}x",
        plain[2] / modified[2]
    );
    assert!(mo.iter().all(|p| (p - 4.0).abs() < 0.3), "{mo:?}");
    assert!(pa.iter().all(|p| (p - 4.0).abs() < 0.3), "{pa:?}");
    assert!(plain[2] > 1e3 * modified[2], "{plain:?} {modified:?}");
}

/// Paper A's `W_s` (gamma = 1) on the spatial double pendulum: the term acts (the errors move
/// by more than 1% against the plain scheme's: measured 30% for s = 1, 11% for s = 2) and the
/// orders stay 2s (within 0.3).
#[test]
fn paper_w_s_keeps_the_orders_on_spatial_models() {
    let sys = spatial_double_pendulum().unwrap();
    let (t, h) = (1.0, 1e-2);
    let reference = common::end_state(&sys, "rk4", RunConfig::new(t, h / 32.0));
    for s in [1usize, 2] {
        let (plain, _) = errors(&sys, &format!("symplectic:{s}"), t, h, &reference);
        let (paper, po) = errors(&sys, &format!("symplectic:{s}:gamma=1"), t, h, &reference);
        eprintln!("W_{s}, gamma = 1: errors {paper:?} (plain {plain:?}), orders {po:.2?}");
        let order = 2.0 * s as f64;
        assert!(
            po.iter().all(|p| (p - order).abs() < 0.3),
            "s = {s}: {po:?}"
        );
        assert!(
            (paper[0] - plain[0]).abs() > 0.01 * plain[0],
            "s = {s}: {paper:?} {plain:?}"
        );
    }
}

/// On a torque-free body (J = (1, 2, 2.5), spun about its intermediate axis) over 50 s: the
/// plain (1,1) scheme keeps the energy to round-off (a quadratic kinetic energy, no potential,
/// quadratic constraints; measured 2e-14), while the modified Lagrangian, whose discrete
/// momentum carries `h^2 de/dv`, keeps the energy of its own Lagrangian and `H` to `O(h^4)`
/// (measured 1.6e-7 / 9.7e-9 at 1/50 and 1/100 of the spin period: order 4.0).
#[test]
fn the_modified_lagrangian_keeps_a_free_body_energy_to_order_four() {
    let sys = free_body([1.0, 2.0, 2.5], [0.05, 2.0, 0.05]).unwrap();
    let period = std::f64::consts::PI;
    let plain = energy_drift(&sys, "symplectic:1", 50.0, period / 50.0);
    let m: Vec<f64> = [50.0, 100.0]
        .iter()
        .map(|&k| energy_drift(&sys, "symplectic:1:modified", 50.0, period / k))
        .collect();
    let order = (m[0] / m[1]).log2();
    eprintln!("free body energy: plain (1,1) {plain:.1e}; modified {m:?}, order {order:.2}");
    assert!(plain < 1e-12, "{plain:e}");
    assert!(m[0] < 1e-6 && (order - 4.0).abs() < 0.3, "{m:?} {order}");
}

/// What the preadjusted schemes do not take on spatial bodies is refused at construction,
/// naming it: a spatial damper and a load for the modified Lagrangian (non-conservative). Paper
/// A's `W_s` and the modified Lagrangian take the forced sparse path and step on it, `W_s` to
/// the dense path's steps within 1e-9 on the spatial double pendulum and on a thin-disc top
/// (`E_3 = 0`, whose massless director the sparse metric regularises and the dense one
/// augments).
#[test]
fn what_the_preadjusted_schemes_do_not_take_is_refused_by_name() {
    let example = |f: &str| {
        System::from_path(format!(
            "{}/examples/models/{f}",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap()
    };
    let cases = [(
        example("spatial_spring_pendulum.toml"),
        "symplectic:1:modified",
        "'strut' (spring_damper), 'thruster'",
    )];
    for (sys, spec, what) in cases {
        let e = Simulation::new(sys, spec).unwrap_err().to_string();
        eprintln!("{spec}: {e}");
        assert!(e.contains(what), "{spec}: {e}");
    }
    let sys = spatial_double_pendulum().unwrap();
    let sparse = |o: mbd::symplectic::SymplecticOptions| mbd::symplectic::SymplecticOptions {
        linear_solver: mbd::solve::LinearSolver::Sparse,
        ..o
    };
    let disc = mbd::model::models::heavy_top([0.25, 0.25, 0.5], 0.3, 20.0).unwrap();
    for (name, model) in [("double pendulum", &sys), ("disc top", &disc)] {
        for s in [1, 2] {
            let gamma = mbd::symplectic::SymplecticOptions::new(s).with_gamma(1.0);
            let mut ends = Vec::new();
            for o in [sparse(gamma), gamma] {
                let mut g = mbd::symplectic::Galerkin::new(model, o).unwrap();
                let mut st = State::consistent(model, 0.0).unwrap();
                for _ in 0..50 {
                    g.step(model, &mut st, 1e-2).unwrap();
                }
                ends.push((g.is_sparse(), st));
            }
            assert!(ends[0].0 && !ends[1].0, "{name}: the paths");
            let dq = (&ends[0].1.q - &ends[1].1.q).amax();
            eprintln!("{name}, ({s},{s}) gamma = 1: sparse - dense {dq:.2e} in q");
            assert!(dq < 1e-9, "{name}, ({s},{s}): {dq:e}");
        }
    }
    let modified = sparse(
        mbd::symplectic::SymplecticOptions::new(1)
            .with_preadjust(mbd::symplectic::PreadjustMode::ModifiedLagrangian),
    );
    let mut g = mbd::symplectic::Galerkin::new(&sys, modified).unwrap();
    assert!(g.is_sparse());
    let mut st = State::consistent(&sys, 0.0).unwrap();
    for _ in 0..10 {
        g.step(&sys, &mut st, 1e-3).unwrap();
    }
}

/// Spatial angle drivers (`examples/models/driven_arm.toml`: `Phi_q` and the constraint
/// Hessians turn with time): every preadjusted spec runs them, and the modified Lagrangian's
/// sparse layout (forced) takes the same steps as its dense one, up to rounding and the Newton
/// tolerance.
#[test]
fn the_preadjusted_schemes_take_spatial_angle_drivers_on_both_layouts() {
    let sys = System::from_path(format!(
        "{}/examples/models/driven_arm.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    assert!(sys.jacobian_depends_on_time());
    for spec in [
        "symplectic:1:modified",
        "symplectic:2:modified",
        "symplectic:1:gamma=1",
        "symplectic:2:gamma=1",
    ] {
        let mut sim = Simulation::new(sys.clone(), spec).unwrap();
        sim.run(RunConfig::new(0.1, 5e-3))
            .unwrap_or_else(|e| panic!("{spec}: {e}"));
    }
    for s in [1, 2] {
        let ends: Vec<Vec<f64>> = [
            mbd::solve::LinearSolver::Dense,
            mbd::solve::LinearSolver::Sparse,
        ]
        .into_iter()
        .map(|linear_solver| {
            let o = mbd::symplectic::SymplecticOptions {
                linear_solver,
                ..mbd::symplectic::SymplecticOptions::new(s)
                    .with_preadjust(mbd::symplectic::PreadjustMode::ModifiedLagrangian)
            };
            let mut g = mbd::symplectic::Galerkin::new(&sys, o).unwrap();
            assert_eq!(
                g.is_sparse(),
                linear_solver == mbd::solve::LinearSolver::Sparse
            );
            let mut st = State::consistent(&sys, 0.0).unwrap();
            for _ in 0..40 {
                g.step(&sys, &mut st, 5e-3).unwrap();
            }
            st.q.as_slice().to_vec()
        })
        .collect();
        let d = ends[0]
            .iter()
            .zip(&ends[1])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(d < 1e-10, "s = {s}: sparse and dense layouts {d:e} apart");
    }
}
