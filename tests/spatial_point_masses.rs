//! Spatial point masses (3 coordinates, `m I3`, no internal constraints) through the public
//! run loop: the spherical pendulum against its conserved energy and vertical angular
//! momentum and its small-amplitude period, the conical pendulum on its circle, a point mass
//! against a spatial body whose inertia cannot matter, every spatial solver on the spherical
//! pendulum, the sparse path against the dense one on a chain, and the joint's reaction.

mod common;
use mbd::model::spatial::{
    Marker, SpatialBody, SpatialBodyRef, SpatialInertia, SpatialJoint, SpatialJointKind,
};
use mbd::model::SystemBuilder;
use mbd::prelude::*;
use mbd::solve::{ButcherTableau, Index1Options, Index1Rk, LinearSolver, ProjectionSettings};
use mbd::Simulation;

const G: f64 = 9.81;

fn distance(length: f64, pa: [f64; 3]) -> SpatialJoint {
    SpatialJoint::new(
        SpatialJointKind::Distance { length },
        Marker::at(pa),
        Marker::at([0.0; 3]),
    )
    .unwrap()
}

/// A point mass `m` on a massless rod of length `l` from the origin (a distance joint to
/// ground), started at `x0` with velocity `v0`, gravity `-g z`.
fn spherical_pendulum(m: f64, l: f64, x0: [f64; 3], v0: [f64; 3]) -> System {
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -G]);
    let bob = b.add_spatial_point_mass("bob", m, x0, v0);
    b.add_spatial_joint("rod", SpatialBodyRef::Ground, bob, distance(l, [0.0; 3]));
    b.build().unwrap()
}

/// The pendulum tilted by 0.6 rad in the x-z plane and pushed sideways: it precesses.
fn precessing() -> System {
    let (l, th): (f64, f64) = (1.2, 0.6);
    spherical_pendulum(1.5, l, [l * th.sin(), 0.0, -l * th.cos()], [0.0, 1.9, 0.0])
}

/// The largest `|Phi|` and the largest energy and `L_z` changes (relative to the energy scale
/// and to `|L_z(0)|`) along a run of `spec`, and the end state.
struct Kept {
    phi: f64,
    energy: f64,
    lz: f64,
    end: State,
}

fn run_watched(sys: &System, spec: &str, t_end: f64, h: f64) -> Kept {
    let mut sim = Simulation::new(sys.clone(), spec).unwrap();
    let s0 = sim.state().clone();
    let h0 = sys.energy(s0.q.as_slice(), s0.v.as_slice());
    let scale = sys.kinetic(s0.v.as_slice()) + h0.abs();
    let lz0 = sys.spatial_angular_momentum(s0.q.as_slice(), s0.v.as_slice())[2];
    let (mut phi, mut energy, mut lz) = (0.0f64, 0.0f64, 0.0f64);
    let mut watch = |sys: &System, s: &State, _: usize| -> Result<Flow, SolveError> {
        let (q, v) = (s.q.as_slice(), s.v.as_slice());
        phi = phi.max(common::max_phi(sys, q, s.t));
        energy = energy.max((sys.energy(q, v) - h0).abs() / scale);
        lz = lz.max((sys.spatial_angular_momentum(q, v)[2] - lz0).abs() / lz0.abs());
        Ok(Flow::Continue)
    };
    let plan: Plan = if spec.starts_with("index1") {
        AdaptiveConfig::new(t_end, h).into()
    } else {
        RunConfig::new(t_end, h).into()
    };
    sim.run_observed(plan, &mut watch).unwrap();
    Kept {
        phi,
        energy,
        lz,
        end: sim.state().clone(),
    }
}

#[test]
fn a_point_mass_has_three_coordinates_and_a_width_three_block() {
    let sys = precessing();
    assert_eq!(sys.n_coords(), 3);
    assert_eq!(sys.n_constraints(), 1);
    assert_eq!(sys.coordinate_names(), ["bob.x", "bob.y", "bob.z"]);
    assert_eq!(sys.mass_diag().as_slice(), [1.5; 3]);
    assert_eq!(sys.n_body_blocks(), 1);
    assert_eq!(sys.body_block(0), Some((0, 3)));
    assert!(sys.has_spatial() && sys.spatial_internal_rows().is_empty());
    // gravity: V = -m g . x, its gradient -m g
    let (q, _) = sys.initial_guess();
    let v = sys.potential(q.as_slice());
    assert!((v - 1.5 * G * q[2]).abs() < 1e-14);
    let mut grad = [0.0; 3];
    sys.potential_gradient(q.as_slice(), &mut grad);
    assert_eq!(grad, [0.0, 0.0, 1.5 * G]);
}

/// Projected RK4 at h = 1e-3 for 5 s of the precessing spherical pendulum: the energy and the
/// vertical angular momentum stay constant to 1e-12 (measured 3.5e-14 and 6.6e-14), the
/// rod's length to 1e-12.
#[test]
fn the_spherical_pendulum_keeps_its_energy_and_vertical_angular_momentum() {
    let sys = precessing();
    let k = run_watched(&sys, "rk4-projected", 5.0, 1e-3);
    eprintln!(
        "rk4-projected, 5 s: |Phi| {:.1e}, energy {:.1e}, L_z {:.1e}",
        k.phi, k.energy, k.lz
    );
    assert!(k.phi < 1e-12, "{:e}", k.phi);
    assert!(k.energy < 1e-12, "{:e}", k.energy);
    assert!(k.lz < 1e-12, "{:e}", k.lz);
    // it moved: the bob went round the vertical
    let q = k.end.q.as_slice();
    assert!(q[1].abs() + q[0].abs() > 0.1, "{q:?}");
}

/// Released at 0.02 rad in the x-z plane, the spherical pendulum swings in that plane with the
/// period `2 pi sqrt(L/g) (1 + theta0^2 / 16 + 11 theta0^4 / 3072)` (the next term is 2e-13
/// of it): measured between downward zero crossings of `x` over four periods (without the
/// fourth-order term the difference is 5.7e-10, that term).
#[test]
fn the_small_swing_has_the_pendulum_period() {
    let (l, th): (f64, f64) = (0.8, 0.02);
    let sys = spherical_pendulum(2.0, l, [l * th.sin(), 0.0, -l * th.cos()], [0.0; 3]);
    let mut sim = Simulation::new(sys.clone(), "rk4-projected").unwrap();
    let mut prev: Option<(f64, f64)> = None;
    let mut crossings = Vec::new();
    let mut off_plane = 0.0f64;
    let mut watch = |_: &System, s: &State, _: usize| -> Result<Flow, SolveError> {
        let x = s.q[0];
        off_plane = off_plane.max(s.q[1].abs());
        if let Some((t0, x0)) = prev {
            if x0 > 0.0 && x <= 0.0 {
                crossings.push(t0 + (s.t - t0) * x0 / (x0 - x));
            }
        }
        prev = Some((s.t, x));
        Ok(Flow::Continue)
    };
    sim.run_observed(Plan::from(RunConfig::new(8.0, 1e-3)), &mut watch)
        .unwrap();
    assert!(crossings.len() >= 5, "{crossings:?}");
    let measured = (crossings[4] - crossings[0]) / 4.0;
    let th2 = th * th;
    let exact = 2.0
        * std::f64::consts::PI
        * (l / G).sqrt()
        * (1.0 + th2 / 16.0 + 11.0 * th2 * th2 / 3072.0);
    let rel = (measured - exact).abs() / exact;
    eprintln!("period {measured:.12} s, exact {exact:.12} s: {rel:.1e} relative; y {off_plane:e}");
    assert!(rel < 1e-10, "{rel:e}");
    assert!(off_plane == 0.0, "{off_plane:e}");
}

/// The conical pendulum: at the angle `alpha` from the vertical with the speed
/// `omega r`, `omega^2 = g / (L cos alpha)`, the bob goes round its horizontal circle; after
/// 3 s (about 2.5 turns) it is within 1e-12 of its circle and 1e-10 of the angle `omega t`.
#[test]
fn the_conical_pendulum_stays_on_its_circle() {
    let (l, alpha): (f64, f64) = (1.0, 0.7);
    let (r, z) = (l * alpha.sin(), -l * alpha.cos());
    let omega = (G / (l * alpha.cos())).sqrt();
    let sys = spherical_pendulum(0.5, l, [r, 0.0, z], [0.0, omega * r, 0.0]);
    let k = run_watched(&sys, "rk4-projected", 3.0, 1e-3);
    let q = k.end.q.as_slice();
    let t = k.end.t;
    let radius = (q[0].hypot(q[1]) - r).abs();
    let height = (q[2] - z).abs();
    let angle = (q[1].atan2(q[0])
        - (omega * t + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
        + std::f64::consts::PI)
        .abs();
    eprintln!("conical: radius {radius:.1e}, height {height:.1e}, angle {angle:.1e} off");
    assert!(
        radius < 1e-12 && height < 1e-12 && angle < 1e-10,
        "{radius:e} {height:e} {angle:e}"
    );
}

/// A spinning spatial body of the same mass on the same rod, the rod attached at its centre of
/// mass: its centre moves exactly as the point mass (its inertia cannot matter), to round-off.
#[test]
fn a_point_mass_moves_as_a_body_on_a_rod_at_its_centre() {
    let (l, th): (f64, f64) = (1.2, 0.6);
    let (x0, v0) = ([l * th.sin(), 0.0, -l * th.cos()], [0.0, 1.9, 0.0]);
    let point = spherical_pendulum(1.5, l, x0, v0);
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -G]);
    let body = b.add_spatial_body(
        SpatialBody::new(
            "bob",
            SpatialInertia::principal(1.5, [0.02, 0.03, 0.04]).unwrap(),
        )
        .position(x0)
        .velocity(v0)
        .angular_velocity([3.0, -1.0, 7.0]),
    );
    b.add_spatial_joint("rod", SpatialBodyRef::Ground, body, distance(l, [0.0; 3]));
    let rigid = b.build().unwrap();
    for spec in ["rk4", "rk4-projected"] {
        let a = run_watched(&point, spec, 2.0, 1e-3).end;
        let b = run_watched(&rigid, spec, 2.0, 1e-3).end;
        let dq = (0..3).map(|c| (a.q[c] - b.q[c]).abs()).fold(0.0, f64::max);
        let dv = (0..3).map(|c| (a.v[c] - b.v[c]).abs()).fold(0.0, f64::max);
        eprintln!("{spec}: centre {dq:.1e}, velocity {dv:.1e} apart");
        assert!(dq < 1e-12 && dv < 1e-12, "{spec}: {dq:e} {dv:e}");
    }
}

/// Every spatial solver runs the precessing spherical pendulum for 2 s (index-1 DOPRI5 at
/// tolerance 1e-10, firefly-Gauss for 0.3 s) and keeps `|Phi|` and the energy within its
/// bounds.
#[test]
fn every_spatial_solver_runs_the_spherical_pendulum() {
    let sys = precessing();
    // spec, step (tolerance), end, |Phi| bound, energy bound (of the energy scale)
    let checks: [(&str, f64, f64, f64, f64); 9] = [
        ("rk4", 1e-3, 2.0, 1e-9, 1e-9),
        ("rk4-projected", 1e-3, 2.0, 1e-12, 1e-10),
        ("index1:dopri5", 1e-10, 2.0, 1e-7, 1e-7),
        ("tangent:rk4", 1e-3, 2.0, 1e-12, 1e-9),
        ("tangent:dopri5", 1e-3, 2.0, 1e-12, 1e-10),
        ("symplectic:1", 1e-3, 2.0, 1e-12, 1e-5),
        ("symplectic:2", 1e-3, 2.0, 1e-12, 1e-10),
        ("symplectic:3", 1e-2, 2.0, 1e-12, 1e-8),
        ("firefly-gauss", 1e-3, 0.3, 1e-10, 1e-8),
    ];
    for (spec, h, t_end, phi_max, energy_max) in checks {
        let k = run_watched(&sys, spec, t_end, h);
        eprintln!(
            "{spec}: |Phi| {:.1e}, energy {:.1e}, L_z {:.1e} (h/tol {h:e}, {t_end} s)",
            k.phi, k.energy, k.lz
        );
        assert!(
            (k.end.t - t_end).abs() < 1e-9,
            "{spec}: stopped at {}",
            k.end.t
        );
        assert!(k.phi < phi_max, "{spec}: |Phi| {:e}", k.phi);
        assert!(k.energy < energy_max, "{spec}: energy {:e}", k.energy);
    }
}

/// A chain of `n` point masses on distance joints from ground, its last link a rigid rod on a
/// ball joint, released tilted and pushed sideways.
fn chain(n: usize) -> System {
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -G]);
    let (seg, dir) = (0.1, [0.8, 0.0, -0.6]);
    let mut prev = SpatialBodyRef::Ground;
    for k in 0..n {
        let s = seg * (k + 1) as f64;
        let p = b.add_spatial_point_mass(
            format!("m{k}"),
            0.1 + 0.01 * k as f64,
            dir.map(|d| d * s),
            [0.0, 0.05 * k as f64, 0.0],
        );
        b.add_spatial_joint(format!("link{k}"), prev, p, distance(seg, [0.0; 3]));
        prev = p.into();
    }
    // the rod: its upper end on the last point mass
    let s = seg * n as f64 + 0.25;
    let rod = b.add_spatial_body(
        SpatialBody::new(
            "rod",
            SpatialInertia::principal(0.3, [1e-3, 1e-3, 2e-5]).unwrap(),
        )
        .position(dir.map(|d| d * s)),
    );
    let ball = SpatialJoint::new(
        SpatialJointKind::Spherical,
        Marker::at([0.0; 3]),
        Marker::at([0.0, 0.0, 0.25]),
    )
    .unwrap();
    b.add_spatial_joint("ball", prev, rod, ball);
    b.build().unwrap()
}

fn end_on(sys: &System, linear: LinearSolver, t_end: f64) -> State {
    let mut rk = Index1Rk::new(
        sys,
        ButcherTableau::rk4(),
        Index1Options {
            baumgarte: None,
            projection: Some(ProjectionSettings::default()),
            linear,
            ..Default::default()
        },
    )
    .unwrap();
    let mut s = State::consistent(sys, 0.0).unwrap();
    mbd::solve::run(
        &mut rk,
        sys,
        &mut s,
        RunConfig::new(t_end, 1e-3),
        &mut mbd::solve::NoObserver,
    )
    .unwrap();
    s
}

/// 60 point masses and a rod (63 equations, above the sparse threshold): projected RK4 on the
/// sparse path (what `rk4-projected` picks) and on the dense path end within 1e-12 after
/// 0.3 s, and the sparse run keeps the constraints and the energy.
#[test]
fn a_chain_of_point_masses_runs_alike_on_the_sparse_and_dense_paths() {
    let sys = chain(60);
    assert!(sys.n_constraints() > mbd::solve::SPARSE_THRESHOLD);
    assert_eq!(sys.n_coords(), 12 + 3 * 60);
    assert_eq!(sys.body_block(60), Some((12 + 3 * 59, 3)));
    let (d, s) = (
        end_on(&sys, LinearSolver::Dense, 0.3),
        end_on(&sys, LinearSolver::Sparse, 0.3),
    );
    let diff = (&d.q - &s.q).amax().max((&d.v - &s.v).amax());
    let moved = (&s.q - &sys.initial_guess().0).amax();
    eprintln!("chain: moved {moved:.2} m; dense and sparse end states {diff:.1e} apart");
    assert!(moved > 0.01, "{moved}");
    assert!(diff < 1e-12, "{diff:e}");
    let k = run_watched(&sys, "rk4-projected", 0.3, 1e-3);
    eprintln!(
        "chain, rk4-projected: |Phi| {:.1e}, energy {:.1e}",
        k.phi, k.energy
    );
    assert!(
        k.phi < 1e-12 && k.energy < 1e-10,
        "{:e} {:e}",
        k.phi,
        k.energy
    );
    assert!((&k.end.q - &s.q).amax() < 1e-12);
}

/// The tangent chart and the symplectic stage solve take point-mass blocks (width 3) beside a
/// rigid body's (width 12) on their sparse paths: on the 60-mass chain over 0.1 s, tangent
/// RK4 and symplectic (2,2) end within 1e-9 of their dense paths (measured 9.3e-11 and
/// 3.3e-13: the sparse chart's chord iteration stops at its tolerance by another route).
#[test]
fn the_sparse_tangent_and_symplectic_paths_take_point_masses() {
    let sys = chain(60);
    let run = |integ: &mut dyn mbd::solve::Integrator| {
        let mut s = State::consistent(&sys, 0.0).unwrap();
        for _ in 0..100 {
            integ.step(&sys, &mut s, 1e-3).unwrap();
        }
        s
    };
    let mut ends = Vec::new();
    for linear_solver in [LinearSolver::Sparse, LinearSolver::Dense] {
        let topts = mbd::tangent::TangentOptions {
            linear_solver,
            ..Default::default()
        };
        let mut tangent = mbd::tangent::TangentRk::new(&sys, ButcherTableau::rk4(), topts).unwrap();
        let sopts = mbd::symplectic::SymplecticOptions {
            linear_solver,
            ..mbd::symplectic::SymplecticOptions::new(2)
        };
        let mut symplectic = mbd::symplectic::Galerkin::new(&sys, sopts).unwrap();
        assert_eq!(
            symplectic.is_sparse(),
            linear_solver == LinearSolver::Sparse
        );
        ends.push((run(&mut tangent), run(&mut symplectic)));
    }
    let gap = |a: &State, b: &State| (&a.q - &b.q).amax().max((&a.v - &b.v).amax());
    let (dt, ds) = (gap(&ends[0].0, &ends[1].0), gap(&ends[0].1, &ends[1].1));
    eprintln!(
        "point-mass chain, sparse against dense: tangent RK4 {dt:.1e}, symplectic (2,2) {ds:.1e}"
    );
    assert!(dt < 1e-9 && ds < 1e-9, "{dt:e} {ds:e}");
}

/// A `spatial_point` sensor on the bob reads its coordinates, velocities and accelerations, and
/// a reaction sensor on the rod the joint's reaction (force only).
#[test]
fn sensors_read_a_point_mass() {
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -G]);
    let (l, th): (f64, f64) = (1.2, 0.6);
    let bob = b.add_spatial_point_mass(
        "bob",
        1.5,
        [l * th.sin(), 0.0, -l * th.cos()],
        [0.0, 1.9, 0.0],
    );
    let rod = b.add_spatial_joint("rod", SpatialBodyRef::Ground, bob, distance(l, [0.0; 3]));
    b.add_sensor(mbd::model::Sensor::spatial_point("tip", bob, [0.0; 3]));
    b.add_sensor(mbd::model::Sensor::spatial_reaction("pull", rod));
    let sys = b.build().unwrap();
    let mut ss = mbd::solve::SensorSolver::new(&sys).unwrap();
    let mut out = Vec::new();
    let s = State::consistent(&sys, 0.0).unwrap();
    ss.evaluate(&sys, &s, &mut out).unwrap();
    let mut os = mbd::solve::OutputSolve::new(&sys).unwrap();
    let (a, lambda) = os.at(&sys, &s).unwrap();
    let (a, lambda) = (a.to_vec(), lambda.to_vec());
    let want: Vec<f64> = s.q.iter().chain(s.v.iter()).chain(&a).copied().collect();
    assert_eq!(out[..9], want[..]);
    let r = sys
        .spatial_joint_reactions(s.q.as_slice(), s.t, &lambda)
        .unwrap()[0];
    assert_eq!(out[9..12], r.force);
    assert_eq!(out[12..15], [0.0; 3]);
}

/// The rod's reaction on the bob is `m a - m g` (a force along the rod, no moment), at the
/// bob's position; its momentum balance holds to round-off.
#[test]
fn the_rod_reaction_on_a_point_mass_is_its_momentum_balance() {
    let sys = precessing();
    let s = State::consistent(&sys, 0.0).unwrap();
    let mut os = mbd::solve::OutputSolve::new(&sys).unwrap();
    let (a, lambda) = os.at(&sys, &s).unwrap();
    let (a, lambda) = (a.to_vec(), lambda.to_vec());
    let r = sys
        .spatial_joint_reactions(s.q.as_slice(), s.t, &lambda)
        .unwrap()[0];
    let m = 1.5;
    let want = [m * a[0], m * a[1], m * (a[2] + G)];
    let err = (0..3)
        .map(|c| (r.force[c] - want[c]).abs())
        .fold(0.0, f64::max);
    eprintln!("reaction {:?}, m a - m g {want:?}: {err:.1e}", r.force);
    assert!(err < 1e-12 * m * G, "{err:e}");
    assert_eq!(r.moment, [0.0; 3]);
    assert_eq!(r.point, [s.q[0], s.q[1], s.q[2]]);
    // along the rod: force x position = 0
    let x = nalgebra::Vector3::new(s.q[0], s.q[1], s.q[2]);
    assert!(x.cross(&nalgebra::Vector3::from(r.force)).amax() < 1e-12 * m * G);
}
