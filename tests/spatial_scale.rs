//! Spatial models on the sparse path: a chain of rods above the sparse threshold runs with the
//! index-1 solvers (energy and constraints kept, the dense path's trajectory reproduced), and
//! the solvers whose sparse path is planar refuse it by name instead of allocating dense
//! matrices of the model's size.

use mbd::model::models::spatial_chain;
use mbd::prelude::*;
use mbd::Simulation;

fn max_phi(sys: &System, s: &State) -> f64 {
    let mut phi = vec![0.0; sys.n_constraints()];
    sys.phi(s.q.as_slice(), s.t, &mut phi);
    phi.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// A 12-rod chain (108 equations: the sparse path) for 0.5 s at h = 1e-3: projected RK4 keeps
/// the energy to 1e-9 of its scale and the constraints to 1e-12; plain RK4 and index-1
/// DOPRI5 agree with it to 1e-8.
#[test]
fn a_spatial_chain_runs_on_the_sparse_path() {
    let sys = spatial_chain(12).unwrap();
    assert!(sys.n_constraints() > mbd::solve::SPARSE_THRESHOLD);
    let end = |spec: &str| {
        let mut sim = Simulation::new(sys.clone(), spec).unwrap();
        sim.run(RunConfig::new(0.5, 1e-3)).unwrap();
        sim.state().clone()
    };
    let (q0, v0) = sys.initial_guess();
    let h0 = sys.energy(q0.as_slice(), v0.as_slice());
    let scale = sys.kinetic(v0.as_slice()) + h0.abs();
    let p = end("rk4-projected");
    let moved = (&p.q - &q0).amax();
    eprintln!("the chain moved by {moved:.2} m");
    assert!(moved > 0.05, "{moved}");
    let dh = (sys.energy(p.q.as_slice(), p.v.as_slice()) - h0).abs() / scale;
    eprintln!(
        "rk4-projected: energy {dh:.1e} of its scale, |Phi| {:.1e}",
        max_phi(&sys, &p)
    );
    assert!(dh < 1e-9, "{dh:e}");
    assert!(max_phi(&sys, &p) < 1e-12);
    for spec in ["rk4", "index1:dopri5"] {
        let s = end(spec);
        let d = (&s.q - &p.q).amax();
        eprintln!("{spec}: {d:.1e} from rk4-projected");
        assert!(d < 1e-8, "{spec}: {d:e}");
    }
}

/// The tangent solvers' sparse chart takes spatial bodies (body blocks of 12 coordinates, the
/// internal constraints among its rows): on the 12-rod chain (108 equations) over 0.1 s the
/// sparse and the forced dense chart agree to 1e-10 (measured 2.8e-13), and both agree with
/// projected RK4 to 1e-8.
#[test]
fn the_sparse_tangent_chart_takes_spatial_bodies() {
    let sys = spatial_chain(12).unwrap();
    let mut sim = Simulation::new(sys.clone(), "rk4-projected").unwrap();
    sim.run(RunConfig::new(0.1, 1e-3)).unwrap();
    let reference = sim.state().clone();
    let mut ends = Vec::new();
    for linear_solver in [
        mbd::solve::LinearSolver::Sparse,
        mbd::solve::LinearSolver::Dense,
    ] {
        let opts = mbd::tangent::TangentOptions {
            linear_solver,
            ..Default::default()
        };
        let mut integ =
            mbd::tangent::TangentRk::new(&sys, mbd::solve::ButcherTableau::rk4(), opts).unwrap();
        let mut s = State::consistent(&sys, 0.0).unwrap();
        for _ in 0..100 {
            integ.step(&sys, &mut s, 1e-3).unwrap();
        }
        let d = (&s.q - &reference.q).amax();
        eprintln!(
            "tangent RK4 ({linear_solver:?}): {d:.1e} from rk4-projected, |Phi| {:.1e}",
            max_phi(&sys, &s)
        );
        assert!(d < 1e-8, "{linear_solver:?}: {d:e}");
        assert!(max_phi(&sys, &s) < 1e-12);
        ends.push(s);
    }
    let d = (&ends[0].q - &ends[1].q)
        .amax()
        .max((&ends[0].v - &ends[1].v).amax());
    eprintln!("sparse against dense chart: {d:.1e}");
    assert!(d < 1e-10, "{d:e}");
}

/// The solvers without a spatial sparse path (symplectic, firefly-Gauss) take the 12-rod chain
/// (108 equations) on their dense path and agree with projected RK4 (symplectic (2,2) within
/// 1e-8 after 0.1 s); a chain past `DENSE_SPATIAL_LIMIT` is refused by name (tangent RK4 runs
/// it), and so is an explicit request for the symplectic scheme's sparse path.
#[test]
fn solvers_without_a_spatial_sparse_path_take_mid_sized_models_densely() {
    let sys = spatial_chain(12).unwrap();
    let end = |spec: &str| {
        let mut sim = Simulation::new(sys.clone(), spec).unwrap();
        sim.run(RunConfig::new(0.1, 1e-3)).unwrap();
        sim.state().clone()
    };
    let reference = end("rk4-projected");
    let d = (&end("symplectic:2").q - &reference.q).amax();
    eprintln!("symplectic:2: {d:.1e} from rk4-projected");
    assert!(d < 1e-8, "{d:e}");
    let large = spatial_chain(mbd::solve::DENSE_SPATIAL_LIMIT / 9 + 1).unwrap();
    for spec in ["symplectic:2", "firefly-gauss"] {
        let e = Simulation::new(large.clone(), spec)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("{} equations", large.n_constraints()))
                && e.contains("rk4-projected")
                && e.contains("tangent"),
            "{spec}: {e}"
        );
    }
    assert!(Simulation::new(large.clone(), "tangent:rk4").is_ok());
    let opts = mbd::symplectic::SymplecticOptions {
        linear_solver: mbd::solve::LinearSolver::Sparse,
        ..mbd::symplectic::SymplecticOptions::new(2)
    };
    let e = mbd::symplectic::Galerkin::new(&sys, opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no sparse path"), "{e}");
}
