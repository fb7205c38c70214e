//! The sparse body-eliminated solve against the dense one on models with spatial bodies (a
//! chain of rods, a disc top with a singular mass matrix, a model mixing planar and spatial
//! bodies): accelerations, every multiplier and the projections agree to round-off, and RK4
//! runs the same on both paths.

use mbd_model::models::{heavy_top, pendulum, spatial_chain};
use mbd_model::spatial::{
    Marker, SpatialBody, SpatialBodyRef, SpatialInertia, SpatialJoint, SpatialJointKind,
};
use mbd_model::{System, SystemBuilder};
use mbd_solve::{
    run, AccelerationSolver, ButcherTableau, Index1Options, Index1Rk, LinearSolver, NoObserver,
    ProjectionSettings, Projector, RunConfig, SparseAccelerationSolver, State,
};

/// A planar pendulum beside a spatial double pendulum of two rods on ball joints.
fn mixed() -> System {
    let mut b = SystemBuilder::new();
    let p = pendulum(1.0, 1.0, 0.4, 9.81).unwrap().to_model_file();
    let mut b2 = p.to_builder().unwrap();
    std::mem::swap(&mut b, &mut b2);
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let rod = SpatialInertia::principal(1.0, [0.02, 0.02, 1e-3]).unwrap();
    let r1 = b.add_spatial_body(
        SpatialBody::new("r1", rod.clone())
            .position([0.0, 0.0, -0.25])
            .angular_velocity([1.0, 0.0, 0.5]),
    );
    let r2 = b.add_spatial_body(SpatialBody::new("r2", rod).position([0.0, 0.0, -0.75]));
    let ball = |a: [f64; 3], b: [f64; 3]| {
        SpatialJoint::new(SpatialJointKind::Spherical, Marker::at(a), Marker::at(b)).unwrap()
    };
    b.add_spatial_joint(
        "s1",
        SpatialBodyRef::Ground,
        r1,
        ball([0.0; 3], [0.0, 0.0, 0.25]),
    );
    b.add_spatial_joint("s2", r1, r2, ball([0.0, 0.0, -0.25], [0.0, 0.0, 0.25]));
    b.build().unwrap()
}

/// A state off the manifold a little, with velocities, so every term is exercised.
fn perturbed(sys: &System) -> (Vec<f64>, Vec<f64>) {
    let (q, v) = sys.initial_guess();
    let q: Vec<f64> = q
        .iter()
        .enumerate()
        .map(|(k, x)| x + 1e-3 * ((k as f64) * 0.37).sin())
        .collect();
    let v: Vec<f64> = v
        .iter()
        .enumerate()
        .map(|(k, x)| x + 0.3 * ((k as f64) * 0.91).cos())
        .collect();
    (q, v)
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

#[test]
fn sparse_and_dense_body_solves_agree() {
    for (name, sys) in [
        ("chain of 6", spatial_chain(6).unwrap()),
        ("disc top", heavy_top([0.25, 0.25, 0.5], 0.3, 20.0).unwrap()),
        ("mixed", mixed()),
    ] {
        let (n, m) = (sys.n_coords(), sys.n_constraints());
        let (q, v) = perturbed(&sys);
        let mut dense = AccelerationSolver::new(&sys);
        let mut sparse = SparseAccelerationSolver::new(&sys).unwrap();
        let (mut a1, mut l1, mut a2, mut l2) =
            (vec![0.0; n], vec![0.0; m], vec![0.0; n], vec![0.0; m]);
        dense.solve(&sys, &q, &v, 0.3, &mut a1, &mut l1).unwrap();
        sparse.solve(&sys, &q, &v, 0.3, &mut a2, &mut l2).unwrap();
        let (da, dl) = (rel_diff(&a1, &a2), rel_diff(&l1, &l2));
        eprintln!("{name}: accelerations {da:.1e}, multipliers {dl:.1e} apart");
        assert!(da < 1e-12 && dl < 1e-12, "{name}: {da:e}, {dl:e}");
        assert!(sparse.schur().is_none() && sparse.nnz() > 0);
        // the projections: the same corrections
        let settings = ProjectionSettings::default();
        let mut pd = Projector::with_linear(&sys, settings, LinearSolver::Dense).unwrap();
        let mut ps = Projector::with_linear(&sys, settings, LinearSolver::Sparse).unwrap();
        assert!(ps.is_sparse() && !pd.is_sparse());
        let (mut qd, mut vd, mut qs, mut vs) = (q.clone(), v.clone(), q.clone(), v.clone());
        pd.project(&sys, &mut qd, &mut vd, 0.0).unwrap();
        ps.project(&sys, &mut qs, &mut vs, 0.0).unwrap();
        let (dq, dv) = (rel_diff(&qd, &qs), rel_diff(&vd, &vs));
        eprintln!("{name}: projected q {dq:.1e}, v {dv:.1e} apart");
        assert!(dq < 1e-13 && dv < 1e-12, "{name}: {dq:e}, {dv:e}");
        let mut phi = vec![0.0; m];
        sys.phi(&qs, 0.0, &mut phi);
        assert!(phi.iter().all(|p| p.abs() < 1e-13), "{name}");
    }
}

/// Projected RK4 on a chain of 8 rods, 0.2 s: the sparse and dense paths end within 1e-12.
#[test]
fn rk4_runs_alike_on_both_paths() {
    let sys = spatial_chain(8).unwrap();
    let end = |linear: LinearSolver| {
        let mut rk = Index1Rk::new(
            &sys,
            ButcherTableau::rk4(),
            Index1Options {
                baumgarte: None,
                projection: Some(ProjectionSettings::default()),
                linear,
                ..Default::default()
            },
        )
        .unwrap();
        let (q, v) = sys.initial_guess();
        let mut s = State::new(&sys, 0.0, q, v).unwrap();
        run(
            &mut rk,
            &sys,
            &mut s,
            RunConfig::new(0.2, 1e-3),
            &mut NoObserver,
        )
        .unwrap();
        s
    };
    let (d, s) = (end(LinearSolver::Dense), end(LinearSolver::Sparse));
    let diff = (&d.q - &s.q).amax().max((&d.v - &s.v).amax());
    eprintln!("dense and sparse end states {diff:.1e} apart");
    assert!(diff < 1e-12, "{diff:e}");
}

/// Velocities so large that the velocity terms `gamma` overflow (a state far off any solution,
/// as after a step too long for the motion) give non-finite multipliers in the sparse solve:
/// that is `SolveError::NonFinite`, not a singular matrix (it was reported as "singular sparse
/// constraint matrix ... non-finite multipliers"), on both sparse kernels (planar rows, spatial
/// bodies).
#[test]
fn overflowing_velocity_terms_are_non_finite_not_singular() {
    for (name, sys) in [
        ("planar chain", mbd_model::models::n_link_chain(30).unwrap()),
        ("spatial chain", spatial_chain(6).unwrap()),
    ] {
        let (q, _) = sys.initial_guess();
        let v = vec![1e200; sys.n_coords()];
        let mut sparse = SparseAccelerationSolver::new(&sys).unwrap();
        let (mut a, mut l) = (vec![0.0; sys.n_coords()], vec![0.0; sys.n_constraints()]);
        match sparse.solve(&sys, q.as_slice(), &v, 0.0, &mut a, &mut l) {
            Err(mbd_solve::SolveError::NonFinite { what, .. }) => {
                assert!(what.contains("velocity terms"), "{name}: {what}");
            }
            other => panic!("{name}: expected a non-finite error, got {other:?}"),
        }
    }
}
