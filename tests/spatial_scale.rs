//! Spatial models on the sparse path: a chain of rods above the sparse threshold runs with the
//! index-1 solvers (energy and constraints kept, the dense path's trajectory reproduced), the
//! tangent chart and the symplectic stage solve agree with their dense paths, and FA-DAE,
//! whose solves are dense, refuses a chain past the dense limit by name instead of allocating
//! dense matrices of the model's size.

mod common;
use mbd::model::models::spatial_chain;
use mbd::prelude::*;
use mbd::Simulation;

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
        common::max_phi_at(&sys, &p)
    );
    assert!(dh < 1e-9, "{dh:e}");
    assert!(common::max_phi_at(&sys, &p) < 1e-12);
    for spec in ["rk4", "index1:dopri5"] {
        let s = end(spec);
        let d = (&s.q - &p.q).amax();
        eprintln!("{spec}: {d:.1e} from rk4-projected");
        assert!(d < 1e-8, "{spec}: {d:e}");
    }
}

/// Runs `make(linear)` for the sparse and the forced dense path over 100 steps of 1e-3 on the
/// 12-rod chain: each within 1e-8 of projected RK4 with `|Phi|` below 1e-12; returns the
/// largest difference of the two paths' end states.
fn sparse_against_dense(
    name: &str,
    make: impl Fn(&System, mbd::solve::LinearSolver) -> Box<dyn mbd::solve::Integrator>,
) -> f64 {
    let sys = spatial_chain(12).unwrap();
    let mut sim = Simulation::new(sys.clone(), "rk4-projected").unwrap();
    sim.run(RunConfig::new(0.1, 1e-3)).unwrap();
    let reference = sim.state().clone();
    let mut ends = Vec::new();
    for linear in [
        mbd::solve::LinearSolver::Sparse,
        mbd::solve::LinearSolver::Dense,
    ] {
        let mut integ = make(&sys, linear);
        let mut s = State::consistent(&sys, 0.0).unwrap();
        for _ in 0..100 {
            integ.step(&sys, &mut s, 1e-3).unwrap();
        }
        let d = (&s.q - &reference.q).amax();
        eprintln!(
            "{name} ({linear:?}): {d:.1e} from rk4-projected, |Phi| {:.1e}",
            common::max_phi_at(&sys, &s)
        );
        assert!(d < 1e-8, "{name} {linear:?}: {d:e}");
        assert!(common::max_phi_at(&sys, &s) < 1e-12);
        ends.push(s);
    }
    let d = (&ends[0].q - &ends[1].q)
        .amax()
        .max((&ends[0].v - &ends[1].v).amax());
    eprintln!("{name}, sparse against dense: {d:.1e}");
    d
}

/// The tangent solvers' sparse chart takes spatial bodies (body blocks of 12 coordinates, the
/// internal constraints among its rows): on the 12-rod chain (108 equations) over 0.1 s the
/// sparse and the forced dense chart agree to 1e-10 (measured 2.9e-13), and both agree with
/// projected RK4 to 1e-8.
#[test]
fn the_sparse_tangent_chart_takes_spatial_bodies() {
    let d = sparse_against_dense("tangent RK4", |sys, linear_solver| {
        let opts = mbd::tangent::TangentOptions {
            linear_solver,
            ..Default::default()
        };
        Box::new(
            mbd::tangent::TangentRk::new(sys, mbd::solve::ButcherTableau::rk4(), opts).unwrap(),
        )
    });
    assert!(d < 1e-10, "{d:e}");
}

/// The symplectic scheme's sparse stage system takes spatial bodies too (body blocks, the
/// momentum rows of massless director coordinates, the end velocity by the sparse constrained
/// solve): on the 12-rod chain over 0.1 s the sparse and the forced dense path of symplectic
/// (2,2) agree to 1e-10 (measured 6.5e-14), and both agree with projected RK4 to 1e-8.
#[test]
fn the_sparse_symplectic_stage_takes_spatial_bodies() {
    let d = sparse_against_dense("symplectic (2,2)", |sys, linear_solver| {
        let opts = mbd::symplectic::SymplecticOptions {
            linear_solver,
            ..mbd::symplectic::SymplecticOptions::new(2)
        };
        let integ = mbd::symplectic::Galerkin::new(sys, opts).unwrap();
        assert_eq!(
            integ.is_sparse(),
            linear_solver == mbd::solve::LinearSolver::Sparse
        );
        Box::new(integ)
    });
    assert!(d < 1e-10, "{d:e}");
}

/// FA-DAE, whose acceleration solves are dense, takes the 12-rod chain (108 equations) and
/// refuses a chain past `DENSE_SPATIAL_LIMIT` by name; tangent RK4 and symplectic (2,2) take
/// it (their sparse paths).
#[test]
fn large_spatial_models_are_refused_by_dense_solvers_only() {
    let sys = spatial_chain(12).unwrap();
    assert!(Simulation::new(sys.clone(), "firefly-gauss").is_ok());
    let large = spatial_chain(mbd::solve::DENSE_SPATIAL_LIMIT / 9 + 1).unwrap();
    let e = Simulation::new(large.clone(), "firefly-gauss")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("{} equations", large.n_constraints()))
            && e.contains("rk4-projected")
            && e.contains("tangent"),
        "{e}"
    );
    for spec in ["tangent:rk4", "symplectic:2"] {
        assert!(Simulation::new(large.clone(), spec).is_ok(), "{spec}");
    }
}

/// A hanging chain of `n` rods on ball joints, turning about the horizontal `x` axis, each rod
/// pulled sideways by a spring-damper to the ground and the last one twisted by a torque in
/// its own axes (a non-conservative load).
fn sprung_chain(n: usize) -> System {
    use mbd::model::spatial::{
        Axes, Marker, SpatialBody, SpatialBodyRef, SpatialForce, SpatialInertia, SpatialJoint,
        SpatialJointKind,
    };
    use mbd::model::{SystemBuilder, TimeFunction};
    let l = 0.5;
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let inertia = SpatialInertia::principal(1.0, [l * l / 12.0, l * l / 12.0, 1e-3]).unwrap();
    let mut prev = SpatialBodyRef::Ground;
    let mut last = prev;
    for k in 0..n {
        let z = -l * (k as f64 + 0.5);
        let rod = b.add_spatial_body(
            SpatialBody::new(format!("rod{k}"), inertia.clone())
                .position([0.0, 0.0, z])
                .velocity([0.0, -2.0 * z, 0.0])
                .angular_velocity([2.0, 0.0, 0.0]),
        );
        let above = if k == 0 {
            [0.0; 3]
        } else {
            [0.0, 0.0, -0.5 * l]
        };
        b.add_spatial_joint(
            format!("ball{k}"),
            prev,
            rod,
            SpatialJoint::new(
                SpatialJointKind::Spherical,
                Marker::at(above),
                Marker::at([0.0, 0.0, 0.5 * l]),
            )
            .unwrap(),
        );
        b.add_spatial_force(SpatialForce::spring_damper(
            format!("spring{k}"),
            rod,
            [0.1, 0.0, 0.0],
            SpatialBodyRef::Ground,
            [0.2 * k as f64, 0.5, z],
            50.0,
            0.5,
            0.3,
        ));
        prev = rod.into();
        last = prev;
    }
    b.add_spatial_force(SpatialForce::torque(
        "twist",
        last,
        [
            TimeFunction::constant(0.1),
            TimeFunction::constant(0.0),
            TimeFunction::constant(0.05),
        ],
        Axes::Body,
    ));
    b.build().unwrap()
}

/// `steps` steps of 1e-3 of symplectic (2,2) on the sparse and on the dense stage solve (a new
/// Jacobian at every step on both, so that they differ by their linear algebra alone): the
/// end states and the Newton iterations, sparse first.
fn symplectic_paths(sys: &System, steps: usize) -> ([State; 2], [usize; 2]) {
    let run = |linear_solver| {
        let opts = mbd::symplectic::SymplecticOptions {
            linear_solver,
            ..mbd::symplectic::SymplecticOptions::new(2)
        }
        .with_jacobian_reuse(mbd::symplectic::JacobianReuse::Never);
        let mut integ = mbd::symplectic::Galerkin::new(sys, opts).unwrap();
        let mut s = State::consistent(sys, 0.0).unwrap();
        let mut its = 0;
        for _ in 0..steps {
            its += integ.step(sys, &mut s, 1e-3).unwrap().newton_iterations;
        }
        (s, its)
    };
    let (a, ia) = run(mbd::solve::LinearSolver::Sparse);
    let (b, ib) = run(mbd::solve::LinearSolver::Dense);
    ([a, b], [ia, ib])
}

/// With spring-dampers and a body-frame torque (force Hessians by coloured differences over
/// 12-coordinate blocks, the non-conservative Jacobian included), the sparse and the dense
/// stage solve of symplectic (2,2) agree to 1e-9 over 0.2 s on a 6-rod chain (54 equations).
#[test]
fn the_sparse_symplectic_stage_takes_spatial_forces() {
    let sys = sprung_chain(6);
    assert!(sys.n_constraints() > mbd::solve::SPARSE_THRESHOLD);
    let (ends, _) = symplectic_paths(&sys, 200);
    let moved = (&ends[1].q - sys.initial_guess().0).amax();
    let d = (&ends[0].q - &ends[1].q)
        .amax()
        .max((&ends[0].v - &ends[1].v).amax());
    eprintln!("sprung chain: moved {moved:.2}; sparse against dense stage solve {d:.1e}");
    assert!(moved > 0.05, "{moved}");
    assert!(d < 1e-9, "{d:e}");
}

/// 60 point masses hung as a chain of distance links (60 equations: the sparse path), each
/// pulled sideways by a stiff spring to ground (`h^2 k / m` up to 0.2 at h = 1e-3): the
/// sparse stage Jacobian carries the springs' Hessians on the point-mass blocks, so its
/// Newton iteration takes as few iterations as the dense path's exact Jacobian (a Jacobian
/// without them contracts by about `h^2 k / m` per iteration), and both end at the same state.
#[test]
fn the_sparse_symplectic_stage_carries_point_mass_force_hessians() {
    use mbd::model::spatial::{
        Marker, SpatialBodyRef, SpatialForce, SpatialJoint, SpatialJointKind,
    };
    let mut b = mbd::model::SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let seg = 0.1;
    let mut prev = SpatialBodyRef::Ground;
    for k in 0..60 {
        let z = -seg * (k + 1) as f64;
        let p = b.add_spatial_point_mass(format!("m{k}"), 0.1, [0.0, 0.0, z], [0.0; 3]);
        b.add_spatial_joint(
            format!("link{k}"),
            prev,
            p,
            SpatialJoint::new(
                SpatialJointKind::Distance { length: seg },
                Marker::at([0.0; 3]),
                Marker::at([0.0; 3]),
            )
            .unwrap(),
        );
        b.add_spatial_force(SpatialForce::spring_damper(
            format!("spring{k}"),
            SpatialBodyRef::Ground,
            [0.05, 0.02, z],
            p,
            [0.0; 3],
            2e4,
            0.0,
            0.0,
        ));
        prev = p.into();
    }
    let sys = b.build().unwrap();
    assert!(sys.n_constraints() > mbd::solve::SPARSE_THRESHOLD);
    let (ends, iterations) = symplectic_paths(&sys, 100);
    let d = (&ends[0].q - &ends[1].q).amax();
    eprintln!("sprung point masses: Newton iterations sparse / dense {iterations:?}, end states {d:.1e} apart");
    assert!(iterations[0] <= iterations[1] + 10, "{iterations:?}");
    assert!(d < 1e-10, "{d:e}");
}
