//! Spatial bodies through the public run loop: the heavy top and a torque-free body with the
//! index-1 solvers (energy, the conserved angular momentum, constraints, convergence order),
//! and a clear refusal from the solvers that do not run spatial bodies yet.

mod common;
use mbd::model::models::{free_body, heavy_top};
use mbd::prelude::*;
use mbd::Simulation;
use nalgebra::{DVector, Vector3};

/// Angular momentum about the origin (`System::spatial_angular_momentum`).
fn angular_momentum(sys: &System, s: &State) -> Vector3<f64> {
    Vector3::from(sys.spatial_angular_momentum(s.q.as_slice(), s.v.as_slice()))
}

/// The heavy top (a solid body, 20 rad/s) with projected RK4 at h = 1e-3 over 2 s: energy to
/// 1e-8 of its value (RK4's own error; it measured 1.7e-9), the vertical angular momentum (gravity has no moment about the vertical
/// through the tip) to 1e-9, the constraints at round-off.
#[test]
fn the_heavy_top_keeps_its_invariants() {
    // a solid top, a disc on a massless axle (E_3 = 0) and the symmetric top J = (a, 2a, a)
    // (E_2 = 0): singular mass matrices run like the solid body
    for moments in [[0.3, 0.3, 0.1], [0.25, 0.25, 0.5], [0.25, 0.5, 0.25]] {
        top_keeps_its_invariants(moments);
    }
}

fn top_keeps_its_invariants(moments: [f64; 3]) {
    let sys = heavy_top(moments, 0.3, 20.0).unwrap();
    let mut sim = Simulation::new(sys.clone(), "rk4-projected").unwrap();
    let (h0, l0) = {
        let s = sim.state();
        (
            sys.energy(s.q.as_slice(), s.v.as_slice()),
            angular_momentum(&sys, s),
        )
    };
    sim.run(RunConfig::new(2.0, 1e-3)).unwrap();
    let s = sim.state();
    let h1 = sys.energy(s.q.as_slice(), s.v.as_slice());
    let l1 = angular_momentum(&sys, s);
    assert!((h1 - h0).abs() < 1e-8 * h0.abs(), "H {h0} -> {h1}");
    assert!(
        (l1[2] - l0[2]).abs() < 1e-8 * l0.norm(),
        "L_z {} -> {}",
        l0[2],
        l1[2]
    );
    assert!(
        common::max_phi_at(&sys, s) < 1e-12,
        "{}",
        common::max_phi_at(&sys, s)
    );
    // the top precesses: its centre of mass has moved round the vertical
    let o = sys.spatial_offset();
    let x0 = sys.initial_guess().0;
    let moved = (s.q[o] - x0[o]).abs() + (s.q[o + 1] - x0[o + 1]).abs();
    assert!(moved > 1e-2, "{moved}");
}

/// Plain RK4 converges with order 4 on the heavy top (t = 0.5 s, h = 4e-3 .. 1e-3, against
/// h = 1.25e-4), and index-1 DOPRI5 at tol 1e-11 agrees with the reference to 1e-8.
#[test]
fn rk4_converges_with_order_four_on_the_heavy_top() {
    let sys = heavy_top([0.3, 0.3, 0.1], 0.3, 20.0).unwrap();
    let end = |spec: &str, plan: Plan| -> DVector<f64> { common::end_state(&sys, spec, plan).q };
    let reference = end("rk4", RunConfig::new(0.5, 1.25e-4).into());
    let errs: Vec<f64> = [4e-3, 2e-3, 1e-3]
        .iter()
        .map(|&h| (end("rk4", RunConfig::new(0.5, h).into()) - &reference).amax())
        .collect();
    let orders: Vec<f64> = errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    eprintln!("RK4 on the heavy top: errors {errs:?}, orders {orders:?}");
    for p in &orders {
        assert!((p - 4.0).abs() < 0.3, "orders {orders:?}, errors {errs:?}");
    }
    let dopri = end("index1:dopri5", AdaptiveConfig::new(0.5, 1e-11).into());
    let d = (dopri - &reference).amax();
    assert!(d < 1e-8, "{d:e}");
}

/// A torque-free asymmetric body spinning near its intermediate axis: projected RK4 keeps the
/// energy and all three components of the angular momentum to 1e-8 over 20 s while the
/// intermediate axis flips over (its `y` component changes sign).
#[test]
fn a_torque_free_body_conserves_energy_and_angular_momentum() {
    // a solid body and a flat plate (J = (1, 2, 3): E_3 = 0)
    for moments in [[1.0, 2.0, 2.5], [1.0, 2.0, 3.0]] {
        free_body_conserves(moments);
    }
}

fn free_body_conserves(moments: [f64; 3]) {
    let sys = free_body(moments, [1e-2, 2.0, 1e-2]).unwrap();
    let mut sim = Simulation::new(sys.clone(), "rk4-projected").unwrap();
    let s0 = sim.state().clone();
    let (h0, l0) = (
        sys.energy(s0.q.as_slice(), s0.v.as_slice()),
        angular_momentum(&sys, &s0),
    );
    let o = sys.spatial_offset();
    let mut lowest = f64::INFINITY;
    let mut watch = |_: &System, s: &State, _: usize| -> Result<Flow, SolveError> {
        lowest = lowest.min(s.q[o + 7]);
        Ok(Flow::Continue)
    };
    sim.run_observed(RunConfig::new(20.0, 1e-3), &mut watch)
        .unwrap();
    let s = sim.state();
    let h1 = sys.energy(s.q.as_slice(), s.v.as_slice());
    let l1 = angular_momentum(&sys, s);
    assert!((h1 - h0).abs() < 1e-8 * h0, "{moments:?}: H {h0} -> {h1}");
    assert!(
        (l1 - l0).amax() < 1e-8 * l0.norm(),
        "{moments:?}: L {l0:?} -> {l1:?}"
    );
    assert!(
        lowest < -0.9,
        "{moments:?}: d_2 . e_y never below {lowest}: no flip"
    );
}

/// Every registered solver either runs the top or refuses it naming the body; the index-1
/// family, the plain symplectic schemes, the tangent solvers and the firefly-Gauss solvers run
/// it.
#[test]
fn solvers_that_do_not_run_spatial_bodies_say_so() {
    let sys = heavy_top([0.3, 0.3, 0.1], 0.3, 20.0).unwrap();
    let mut ran = Vec::new();
    for (_, v) in mbd::registry().variants() {
        match Simulation::new(sys.clone(), v.spec) {
            Ok(mut sim) => {
                sim.run(RunConfig::new(0.01, 1e-3)).unwrap();
                ran.push(v.spec);
            }
            Err(e) => {
                let e = e.to_string();
                assert!(
                    e.contains("spatial") && e.contains("'top'"),
                    "{}: {e}",
                    v.spec
                );
            }
        }
    }
    for spec in [
        "rk4",
        "rk4-projected",
        "index1:dopri5",
        "firefly-gauss",
        "firefly-gauss:polish",
    ] {
        assert!(ran.contains(&spec), "{spec} did not run: {ran:?}");
    }
}

/// The body-frame angular velocity of spatial body 0.
fn body_omega(sys: &System, q: &[f64], v: &[f64]) -> Vector3<f64> {
    Vector3::from(
        sys.spatial_body_angular_velocity(0, q, v)
            .unwrap_or_default(),
    )
}

/// A flat plate (J = (1, 2, 3): E_3 = 0, a singular mass matrix) tumbling about its
/// intermediate axis, with index-1 DOPRI5 at tol 1e-12: the flips located by events on the
/// intermediate component of the body angular velocity fall within 1e-8 (relative) of the
/// exact Jacobi-elliptic solution's, and the angular velocity and orientation at the end agree
/// with it to 1e-8.
#[test]
fn flips_of_a_tumbling_plate_match_the_exact_solution() {
    use mbd::model::models::TorqueFreeBody;
    use mbd::solve::{DenseOutput, Event, NoObserver};
    let (j, w0) = ([1.0, 2.0, 3.0], [0.05, 2.0, 0.05]);
    let sys = free_body(j, w0).unwrap();
    let exact = TorqueFreeBody::new(j, Vector3::from(w0), nalgebra::Matrix3::identity()).unwrap();
    let t_end = exact.period().unwrap() * 0.8;
    let flips = exact.flip_times(t_end);
    assert!(flips.len() >= 2, "{flips:?}");
    let o = sys.spatial_offset();
    let probe = sys.clone();
    let mut dense = DenseOutput::new(&sys, NoObserver)
        .with_event(Event::new("omega_2 = 0", move |_, q, v| {
            body_omega(&probe, q, v)[1]
        }));
    let mut sim = Simulation::new(sys.clone(), "index1:dopri5").unwrap();
    sim.run_observed(AdaptiveConfig::new(t_end, 1e-12), &mut dense)
        .unwrap();
    let found: Vec<f64> = dense.events().iter().map(|e| e.t).collect();
    assert_eq!(found.len(), flips.len(), "{found:?} vs {flips:?}");
    for (f, e) in found.iter().zip(&flips) {
        eprintln!("flip at {f}: relative error {:.1e}", (f - e).abs() / e);
        assert!((f - e).abs() < 1e-8 * e, "flip at {f} vs exact {e}");
    }
    let s = sim.state();
    let w = body_omega(&sys, s.q.as_slice(), s.v.as_slice());
    let we = exact.omega(t_end);
    assert!((w - we).amax() < 1e-8 * we.norm(), "{w:?} vs {we:?}");
    let r = nalgebra::Matrix3::from_fn(|row, col| s.q[o + 3 + 3 * col + row]);
    let re = exact.rotation(t_end);
    eprintln!(
        "t = {t_end}: omega off by {:.1e}, R by {:.1e}",
        (w - we).amax() / we.norm(),
        (r - re).amax()
    );
    assert!((r - re).amax() < 1e-8, "{}", (r - re).amax());
}

/// The firefly-Gauss solver (paper C) runs the heavy top and the disc top: with its Gauss-Newton
/// polish at h = 1e-3 over 0.1 s it agrees with an RK4 reference (h = 1e-4) to 1e-7, and
/// keeps the constraints to 1e-10.
#[test]
fn firefly_gauss_runs_spatial_tops() {
    for moments in [[0.3, 0.3, 0.1], [0.25, 0.25, 0.5]] {
        let sys = heavy_top(moments, 0.3, 20.0).unwrap();
        let end = |spec: &str, h: f64| common::end_state(&sys, spec, RunConfig::new(0.1, h));
        let reference = end("rk4", 1e-4);
        let s = end("firefly-gauss:polish", 1e-3);
        let d = (&s.q - &reference.q).amax();
        eprintln!(
            "{moments:?}: firefly-gauss:polish off by {d:.1e}, |Phi| {:.1e}",
            common::max_phi_at(&sys, &s)
        );
        assert!(d < 1e-7, "{moments:?}: {d:e}");
        assert!(common::max_phi_at(&sys, &s) < 1e-10, "{moments:?}");
    }
}

/// The tangent-space solvers (paper B) on the heavy top, solid and disc (`E_3 = 0`): order 4
/// (tangent RK4, h = 1e-3 .. 2.5e-4) and 5 (tangent DOPRI5, fixed steps, h = 2e-3 .. 5e-4) at
/// t = 0.5 against an index-1 DOPRI5 reference (h = 1.25e-4), slopes within 0.3, constraints
/// at 1e-12. (Tangent RK4's leading error term is small in the step-weighted chart: at
/// h = 4e-3 .. 2e-3 the next terms still show, slopes 3.0 and 5.3; docs/tangent.md, "The chart's
/// metric".)
#[test]
fn the_tangent_solvers_reach_their_orders_on_spatial_tops() {
    for moments in [[0.3, 0.3, 0.1], [0.25, 0.25, 0.5]] {
        let sys = heavy_top(moments, 0.3, 20.0).unwrap();
        let end = |spec: &str, h: f64| common::end_state(&sys, spec, RunConfig::new(0.5, h));
        let reference = end("index1:dopri5", 1.25e-4);
        for (spec, order, hs) in [
            ("tangent:rk4", 4.0, [1e-3, 5e-4, 2.5e-4]),
            ("tangent:dopri5", 5.0, [2e-3, 1e-3, 5e-4]),
        ] {
            let mut errs = Vec::new();
            for h in hs {
                let s = end(spec, h);
                errs.push((&s.q - &reference.q).amax());
                assert!(
                    common::max_phi_at(&sys, &s) < 1e-12,
                    "{spec}: {}",
                    common::max_phi_at(&sys, &s)
                );
            }
            let orders: Vec<f64> = errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
            eprintln!("{moments:?} {spec}: errors {errs:?}, orders {orders:?}");
            for p in &orders {
                assert!(
                    (p - order).abs() < 0.3,
                    "{moments:?} {spec}: {orders:?} ({errs:?})"
                );
            }
        }
    }
}

/// The plain symplectic (s,s) scheme (paper A without its preadjustment) on the heavy top,
/// solid and disc (`E_3 = 0`: a singular mass matrix, whose massless coordinates' momentum rows
/// are force balances): orders 2 and 4 for s = 1, 2 at t = 0.5, h = 4e-3 .. 1e-3 (slopes within
/// 0.3), s = 3 within 1e-10 of an RK4 reference at h = 4e-3, and the s = 2 modified
/// Lagrangian within 1e-8 at 4e-3 (tests/spatial_preadjusted.rs measures the preadjusted
/// variants' orders).
#[test]
fn the_plain_symplectic_scheme_reaches_its_orders_on_both_tops() {
    for moments in [[0.3, 0.3, 0.1], [0.25, 0.25, 0.5]] {
        let sys = heavy_top(moments, 0.3, 20.0).unwrap();
        let end = |spec: &str, h: f64| common::end_state(&sys, spec, RunConfig::new(0.5, h));
        let reference = end("rk4", 1.25e-4);
        for (spec, order) in [("symplectic:1", 2.0), ("symplectic:2", 4.0)] {
            let errs: Vec<f64> = [4e-3, 2e-3, 1e-3]
                .iter()
                .map(|&h| (&end(spec, h).q - &reference.q).amax())
                .collect();
            let orders: Vec<f64> = errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
            eprintln!("{moments:?} {spec}: errors {errs:?}, orders {orders:?}");
            for p in &orders {
                assert!(
                    (p - order).abs() < 0.3,
                    "{moments:?} {spec}: {orders:?} ({errs:?})"
                );
            }
        }
        let s3 = end("symplectic:3", 4e-3);
        let d = (&s3.q - &reference.q).amax();
        eprintln!(
            "{moments:?} symplectic:3: {d:.1e} from the reference, |Phi| {:.1e}",
            common::max_phi_at(&sys, &s3)
        );
        assert!(d < 1e-10, "{moments:?} symplectic:3: {d:e}");
        assert!(common::max_phi_at(&sys, &s3) < 1e-12);
        // the s = 2 modified Lagrangian (order 6) runs both tops, far closer than plain (2,2)
        // at h = 4e-3 (7.1e-7; measured 1.7e-9 on the solid top)
        let m2 = end("symplectic:2:modified", 4e-3);
        let d = (&m2.q - &reference.q).amax();
        eprintln!("{moments:?} symplectic:2:modified: {d:.1e} from the reference");
        assert!(d < 1e-8, "{moments:?} symplectic:2:modified: {d:e}");
        assert!(common::max_phi_at(&sys, &m2) < 1e-12);
    }
}

/// Symplectic (2,2) on a torque-free body tumbling about its intermediate axis at 1/50 of the
/// spin period, 200 s: the three components of the angular momentum kept to 1e-11 relative
/// (the scheme's discrete Noether theorem), the constraints to 1e-13, the energy error bounded
/// (below 1e-6; it measured 7.8e-8 over 1000 s in a release build).
#[test]
fn symplectic_keeps_the_angular_momentum_of_a_tumbling_body() {
    let sys = free_body([1.0, 2.0, 2.5], [0.05, 2.0, 0.05]).unwrap();
    let mut sim = Simulation::new(sys.clone(), "symplectic:2").unwrap();
    let s0 = sim.state().clone();
    let (h0, l0) = (
        sys.energy(s0.q.as_slice(), s0.v.as_slice()),
        angular_momentum(&sys, &s0),
    );
    let h = std::f64::consts::PI / 50.0;
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    let mut watch = |_: &System, s: &State, _: usize| -> Result<Flow, SolveError> {
        let e = (sys.energy(s.q.as_slice(), s.v.as_slice()) - h0).abs() / h0;
        let l = (angular_momentum(&sys, s) - l0).amax() / l0.norm();
        worst = (
            worst.0.max(e),
            worst.1.max(l),
            worst.2.max(common::max_phi_at(&sys, s)),
        );
        Ok(Flow::Continue)
    };
    sim.run_observed(RunConfig::new(200.0, h), &mut watch)
        .unwrap();
    eprintln!(
        "symplectic:2, 200 s: energy {:.1e}, L {:.1e}, Phi {:.1e}",
        worst.0, worst.1, worst.2
    );
    assert!(worst.1 < 1e-11, "L: {:e}", worst.1);
    assert!(worst.2 < 1e-13, "Phi: {:e}", worst.2);
    assert!(worst.0 < 1e-6, "H: {:e}", worst.0);
}

/// The dynamics of the revolute joint: a spatial rod hinged at one end about the horizontal
/// global `y` axis swings in the `x`-`z` plane exactly as the planar compound pendulum with the
/// same mass and moment (both with index-1 DOPRI5 at tol 1e-12: angles agree to 1e-9 at t = 2).
#[test]
fn a_spatial_hinge_swings_like_the_planar_pendulum() {
    use mbd::model::spatial::{
        Marker, Orientation, SpatialBody, SpatialInertia, SpatialJoint, SpatialJointKind,
    };
    use mbd::model::{Body, BodyRef, Joint, SystemBuilder};
    let (m, l, r, th0) = (1.0, 1.0, 0.02, 0.7);
    // a cylinder along its body x axis: J_x = m r^2 / 2, J_y = J_z = m (3 r^2 + l^2) / 12
    let jy = m * (3.0 * r * r + l * l) / 12.0;
    let inertia = SpatialInertia::principal(m, [0.5 * m * r * r, jy, jy]).unwrap();
    // the rod from the hinge at the origin, at th0 from the downward vertical in x-z: body
    // x = (sin th0, 0, -cos th0), the turn about global y by pi/2 - th0 (body y stays global y)
    let rot =
        nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2 - th0);
    let rmat = *rot.matrix();
    let axis_x = rmat.column(0).into_owned();
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let rod = b.add_spatial_body(
        SpatialBody::new("rod", inertia)
            .position((axis_x * 0.5 * l).into())
            .orientation(Orientation::Matrix(rmat)),
    );
    // hinge about the body y axis: the markers' z axes along body y (and global y on ground)
    let hinge_axes = nalgebra::Matrix3::from_columns(&[Vector3::z(), Vector3::x(), Vector3::y()]);
    let ground_axes = rmat * hinge_axes;
    b.add_spatial_joint(
        "hinge",
        mbd::model::spatial::SpatialBodyRef::Ground,
        rod,
        SpatialJoint::new(
            SpatialJointKind::Revolute,
            Marker::with_axes([0.0; 3], ground_axes),
            Marker::with_axes([-0.5 * l, 0.0, 0.0], hinge_axes),
        )
        .unwrap(),
    );
    let spatial = b.build().unwrap();
    assert_eq!(spatial.dof(), 1);
    // the planar pendulum in the x-y plane, gravity -y, the same angle from the downward vertical
    let mut p = SystemBuilder::new();
    p.set_gravity([0.0, -9.81]);
    let angle = th0 - std::f64::consts::FRAC_PI_2;
    let body = p.add_body(Body::new("rod").mass(m).inertia(jy).position(
        0.5 * l * angle.cos(),
        0.5 * l * angle.sin(),
        angle,
    ));
    p.add_joint(Joint::revolute(
        "hinge",
        BodyRef::Ground,
        [0.0, 0.0],
        body,
        [-0.5 * l, 0.0],
    ));
    let planar = p.build().unwrap();
    let end =
        |sys: &System| common::end_state(sys, "index1:dopri5", AdaptiveConfig::new(2.0, 1e-12));
    let (s, pl) = (end(&spatial), end(&planar));
    // the rod's direction: body x = d_1; its angle from the downward vertical in x-z
    let d1 = Vector3::new(s.q[3], s.q[4], s.q[5]);
    let spatial_angle = d1[0].atan2(-d1[2]);
    let planar_angle = pl.q[2] + std::f64::consts::FRAC_PI_2;
    eprintln!(
        "hinge vs planar pendulum: {:.1e}",
        (spatial_angle - planar_angle).abs()
    );
    assert!(d1[1].abs() < 1e-12, "left the plane: {d1:?}");
    assert!(
        (spatial_angle - planar_angle).abs() < 1e-9,
        "{spatial_angle} vs {planar_angle}"
    );
    assert!((spatial_angle - th0).abs() > 0.1, "it swings");
}

/// The dynamics of the prismatic joint: a block on a frictionless incline (a slide along a
/// direction 30 degrees above the horizontal) accelerates at g sin 30 along it; RK4 is exact
/// for the quadratic motion (to 1e-10 at t = 1).
#[test]
fn a_block_slides_down_a_prismatic_incline() {
    use mbd::model::spatial::{
        Marker, SpatialBody, SpatialInertia, SpatialJoint, SpatialJointKind,
    };
    use mbd::model::SystemBuilder;
    let a = std::f64::consts::FRAC_PI_6;
    let dir = Vector3::new(a.cos(), 0.0, a.sin());
    // the marker's z axis along the incline: x, y completed perpendicular
    let z = dir;
    let x = Vector3::new(-a.sin(), 0.0, a.cos());
    let y = z.cross(&x);
    let axes = nalgebra::Matrix3::from_columns(&[x, y, z]);
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let block = b.add_spatial_body(SpatialBody::new(
        "block",
        SpatialInertia::principal(2.0, [0.1, 0.2, 0.25]).unwrap(),
    ));
    b.add_spatial_joint(
        "incline",
        mbd::model::spatial::SpatialBodyRef::Ground,
        block,
        SpatialJoint::new(
            SpatialJointKind::Prismatic,
            Marker::with_axes([0.0; 3], axes),
            Marker::with_axes([0.0; 3], axes),
        )
        .unwrap(),
    );
    let sys = b.build().unwrap();
    assert_eq!(sys.dof(), 1);
    let mut sim = Simulation::new(sys.clone(), "rk4").unwrap();
    sim.run(RunConfig::new(1.0, 1e-2)).unwrap();
    let s = sim.state();
    let pos = Vector3::new(s.q[0], s.q[1], s.q[2]);
    let want = -dir * (0.5 * 9.81 * a.sin());
    assert!((pos - want).amax() < 1e-10, "{pos:?} vs {want:?}");
    // no rotation
    assert!((s.q[3] - 1.0).abs() < 1e-12 && (s.q[7] - 1.0).abs() < 1e-12);
}

/// A spatial double pendulum (two rods on spherical joints, chaotic): projected RK4 keeps the
/// energy to 1e-7 of its scale over 2 s at h = 1e-3 and the constraints at round-off.
#[test]
fn a_spatial_double_pendulum_conserves_energy() {
    use mbd::model::spatial::{
        Marker, SpatialBody, SpatialInertia, SpatialJoint, SpatialJointKind,
    };
    use mbd::model::SystemBuilder;
    let rod = || SpatialInertia::principal(1.0, [0.0002, 0.0834, 0.0834]).unwrap();
    let ball = |a: [f64; 3], b: [f64; 3]| {
        SpatialJoint::new(SpatialJointKind::Spherical, Marker::at(a), Marker::at(b)).unwrap()
    };
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    // both rods along global x at first (horizontal), the second moving sideways
    let r1 = b.add_spatial_body(SpatialBody::new("r1", rod()).position([0.5, 0.0, 0.0]));
    let r2 = b.add_spatial_body(
        SpatialBody::new("r2", rod())
            .position([1.5, 0.0, 0.0])
            .velocity([0.0, 2.0, 0.0])
            .angular_velocity([0.0, 0.0, 4.0]),
    );
    b.add_spatial_joint(
        "shoulder",
        mbd::model::spatial::SpatialBodyRef::Ground,
        r1,
        ball([0.0; 3], [-0.5, 0.0, 0.0]),
    );
    b.add_spatial_joint("elbow", r1, r2, ball([0.5, 0.0, 0.0], [-0.5, 0.0, 0.0]));
    let sys = b.build().unwrap();
    assert_eq!(sys.dof(), 6);
    let mut sim = Simulation::new(sys.clone(), "rk4-projected").unwrap();
    let s0 = sim.state().clone();
    let h0 = sys.energy(s0.q.as_slice(), s0.v.as_slice());
    let scale = sys.kinetic(s0.v.as_slice()) + 2.0 * 9.81 * 2.0;
    sim.run(RunConfig::new(2.0, 1e-3)).unwrap();
    let s = sim.state();
    let h1 = sys.energy(s.q.as_slice(), s.v.as_slice());
    assert!((h1 - h0).abs() < 1e-7 * scale, "H {h0} -> {h1}");
    assert!(common::max_phi_at(&sys, s) < 1e-12);
    // it fell
    assert!(s.q[12 + 2] < -0.5, "{}", s.q[14]);
}

/// Spatial joint reactions from the multipliers: on the heavy top (solid and disc) the ball
/// joint's force on the top is `m a - m g` (Newton's law for the body) and its moment about
/// the tip is zero (a ball joint transmits none); along the run the same holds.
#[test]
fn spatial_joint_reactions_obey_newton_and_the_ball_joint_carries_no_moment() {
    use mbd::solve::OutputSolve;
    for moments in [[0.3, 0.3, 0.1], [0.25, 0.25, 0.5]] {
        let sys = heavy_top(moments, 0.3, 20.0).unwrap();
        let mut out = OutputSolve::new(&sys).unwrap();
        let mut sim = Simulation::new(sys.clone(), "rk4-projected").unwrap();
        for _ in 0..3 {
            let s = sim.state().clone();
            let (a, lambda) = out.at(&sys, &s).unwrap();
            let r = sys
                .spatial_joint_reactions(s.q.as_slice(), s.t, lambda)
                .unwrap();
            assert_eq!(r.len(), 1);
            let want = Vector3::new(a[0], a[1], a[2] + 9.81);
            let f = Vector3::from(r[0].force);
            assert!(
                (f - want).amax() < 1e-10 * want.norm(),
                "{moments:?}: {f:?} vs {want:?}"
            );
            assert!(
                Vector3::from(r[0].moment).amax() < 1e-10,
                "{moments:?}: {:?}",
                r[0].moment
            );
            assert!(
                Vector3::from(r[0].point).norm() < 1e-12,
                "the tip is at the origin"
            );
            sim.run(RunConfig::new(sim.state().t + 0.1, 1e-3)).unwrap();
        }
        let e = sys
            .spatial_joint_reactions(&[0.0; 3], 0.0, &[0.0; 9])
            .unwrap_err()
            .to_string();
        assert!(e.contains('q'), "{e}");
    }
    // the joint written the other way round (ground second): the load on the ground, the
    // negative of the load on the top, about the same point
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/heavy_top.toml"),
    )
    .unwrap();
    let swapped = text
        .replace("body_a = \"ground\"", "body_a = \"top\"")
        .replace("body_b = \"top\"", "body_b = \"ground\"")
        .replace("point_a = [0.0, 0.0, 0.0]", "point_a = [0.0, 0.0, -0.5]")
        .replace("point_b = [0.0, 0.0, -0.5]", "point_b = [0.0, 0.0, 0.0]");
    assert_ne!(swapped, text);
    let (fwd, rev) = (
        mbd::model::System::from_toml(&text).unwrap(),
        mbd::model::System::from_toml(&swapped).unwrap(),
    );
    let load = |sys: &System| {
        let s = State::consistent(sys, 0.0).unwrap();
        let mut out = OutputSolve::new(sys).unwrap();
        let (_, lambda) = out.at(sys, &s).unwrap();
        sys.spatial_joint_reactions(s.q.as_slice(), s.t, lambda)
            .unwrap()[0]
    };
    let (a, b) = (load(&fwd), load(&rev));
    for c in 0..3 {
        assert!((a.force[c] + b.force[c]).abs() < 1e-12, "{a:?} vs {b:?}");
        assert!((a.point[c] - b.point[c]).abs() < 1e-12, "{a:?} vs {b:?}");
    }
}
