//! The spatial angle driver (`SpatialJointKind::AngleDriver`), whose Jacobian turns with its
//! angle `theta(t)` (`Phi_qt != 0`): its derivatives against central differences in `q` and
//! `t`, a motor turning a thin rod on a horizontal hinge with every solver that runs spatial
//! bodies (the rod's angle is `theta(t)`, the driver's torque is what Euler's law about the
//! hinge needs, the energy balance books the motor's work), and model files.

use mbd::model::spatial::{
    Marker, Orientation, SpatialBody, SpatialBodyRef, SpatialInertia, SpatialJoint,
    SpatialJointKind,
};
use mbd::model::{ModelFile, SystemBuilder, TimeFunction};
use mbd::prelude::*;
use mbd::Simulation;
use mbd_analysis::EnergyBalance;
use nalgebra::{DMatrix, DVector, Matrix3};

const MASS: f64 = 1.5;
const LENGTH: f64 = 0.8;
const G: f64 = 9.81;

/// `theta(t) = 0.3 + 2 t + 0.5 t^2` (rad): `theta'' = 1`.
fn motion() -> TimeFunction {
    TimeFunction::Polynomial {
        coeffs: vec![0.3, 2.0, 0.5],
    }
}

/// The hinge frame: `x` along global `x`, `z` along global `y` (the hinge axis), so `y` points
/// down (global `-z`) and `theta` turns the rod from the horizontal downwards.
fn hinge_axes() -> Matrix3<f64> {
    Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0)
}

/// A slender uniform rod (a moment about its own axis of 1e-3 of the transverse one: two
/// second moments `E_i` of 5e-4 of the third) along its body `x` axis, hinged at one end to the ground at the origin about global `y`, under gravity, turned
/// by a motor (angle driver) through `theta(t)`; released at `theta(0)` with `theta'(0)`.
fn motor_rod() -> System {
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -G]);
    let jt = MASS * LENGTH * LENGTH / 12.0;
    let [th, dth, _] = motion().eval(0.0);
    let (s, c) = th.sin_cos();
    // a turn by theta about global y: body x goes to (cos, 0, -sin)
    let r = Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c);
    let half = 0.5 * LENGTH;
    let rod = b.add_spatial_body(
        SpatialBody::new(
            "rod",
            SpatialInertia::principal(MASS, [1e-3 * jt, jt, jt]).unwrap(),
        )
        .position([half * c, 0.0, -half * s])
        .orientation(Orientation::Matrix(r))
        .velocity([-half * s * dth, 0.0, -half * c * dth])
        .angular_velocity([0.0, dth, 0.0]),
    );
    let ground = Marker::with_axes([0.0; 3], hinge_axes());
    let end = Marker::with_axes([-half, 0.0, 0.0], hinge_axes());
    b.add_spatial_joint(
        "hinge",
        SpatialBodyRef::Ground,
        rod,
        SpatialJoint::new(SpatialJointKind::Revolute, ground, end).unwrap(),
    );
    b.add_spatial_driver(
        "motor",
        SpatialBodyRef::Ground,
        rod,
        SpatialJoint::new(SpatialJointKind::AngleDriver, ground, end).unwrap(),
        motion(),
    );
    b.build().unwrap()
}

/// How far the rod's angle (from its `x` director, `atan2(-d1_z, d1_x)`) is from `theta`,
/// modulo full turns.
fn angle_error(q: &[f64], theta: f64) -> f64 {
    let phi = (-q[5]).atan2(q[3]);
    ((phi - theta + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI)
        .abs()
}

/// A configuration and velocity off the manifold (central differences need no consistency).
fn off_manifold(sys: &System) -> (Vec<f64>, Vec<f64>) {
    let (q0, _) = sys.initial_guess();
    let q: Vec<f64> = q0
        .iter()
        .enumerate()
        .map(|(i, x)| x + 0.05 * (1.3 * i as f64).sin())
        .collect();
    let v: Vec<f64> = (0..q.len()).map(|i| 0.7 * (0.9 * i as f64).cos()).collect();
    (q, v)
}

/// Every derivative the solvers take of a model with an angle driver, at `t = 0.37` and an
/// inconsistent `(q, v)`, against central differences: `Phi_q` (dense, triplets and the
/// element-local rows), `Phi_t`, `gamma = -(v^T Phi_qq v + 2 Phi_qt v + Phi_tt)` (the second
/// derivative of `Phi(q + s v, t + s)`), `(Phi_q v + Phi_t)_q` and the lambda-weighted Hessian.
#[test]
fn the_angle_drivers_derivatives_match_differences() {
    let sys = motor_rod();
    let (m, n) = (sys.n_constraints(), sys.n_coords());
    let (q, v) = off_manifold(&sys);
    let t = 0.37;
    let phi = |q: &[f64], t: f64| {
        let mut out = vec![0.0; m];
        sys.phi(q, t, &mut out);
        DVector::from_vec(out)
    };
    let h = 1e-5;
    let mut fd = DMatrix::zeros(m, n);
    for c in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[c] += h;
        qm[c] -= h;
        fd.set_column(c, &((phi(&qp, t) - phi(&qm, t)) / (2.0 * h)));
    }
    let mut jac = DMatrix::zeros(m, n);
    let mut gamma = vec![0.0; m];
    sys.phi_q_gamma(&q, &v, t, &mut jac, &mut gamma);
    let d = (&jac - &fd).amax();
    eprintln!("Phi_q against differences: {d:.1e}");
    assert!(d < 1e-9, "{d:e}");
    // the Jacobian turns with theta: at another time it differs
    let mut other = DMatrix::zeros(m, n);
    sys.phi_q(&q, t + 0.5, &mut other);
    assert!((&other - &jac).amax() > 0.1);
    let mut dense = DMatrix::zeros(m, n);
    sys.phi_q(&q, t, &mut dense);
    assert_eq!(dense, jac);
    let mut trip = Vec::new();
    sys.phi_q_triplets(&q, t, &mut trip);
    let mut from_trip = DMatrix::zeros(m, n);
    for (r, c, x) in trip {
        from_trip[(r, c)] += x;
    }
    assert_eq!(from_trip, jac);
    let mut gamma_local = vec![0.0; m];
    let mut local = DMatrix::zeros(m, n);
    sys.local_rows_gamma(&q, Some(&v), t, |r, sides, gm| {
        gamma_local[r] = gm;
        for (block, g) in sides.into_iter().flatten() {
            let (c0, _) = sys.body_block(block).unwrap();
            for (l, x) in g.iter().enumerate() {
                local[(r, c0 + l)] += x;
            }
        }
    });
    assert_eq!(local, jac);
    assert_eq!(gamma_local, gamma);
    // Phi_t
    let mut pt = vec![0.0; m];
    sys.phi_t(&q, t, &mut pt);
    let pt_fd = (phi(&q, t + h) - phi(&q, t - h)) / (2.0 * h);
    let d = (DVector::from_vec(pt.clone()) - &pt_fd).amax();
    eprintln!("Phi_t against differences: {d:.1e}");
    assert!(d < 1e-9 && pt[m - 1].abs() > 0.1, "{d:e}");
    // gamma: minus the second derivative along (v, 1)
    let hs = 1e-4;
    let along = |s: f64| {
        let qs: Vec<f64> = q.iter().zip(&v).map(|(a, b)| a + s * b).collect();
        phi(&qs, t + s)
    };
    let second = (along(hs) - 2.0 * along(0.0) + along(-hs)) / (hs * hs);
    let d = (DVector::from_vec(gamma.clone()) + &second).amax();
    eprintln!("gamma against differences: {d:.1e}");
    assert!(d < 1e-6, "{d:e}");
    // (Phi_q v + Phi_t)_q
    let rate = |q: &[f64]| {
        let mut j = DMatrix::zeros(m, n);
        sys.phi_q(q, t, &mut j);
        let mut pt = vec![0.0; m];
        sys.phi_t(q, t, &mut pt);
        j * DVector::from_column_slice(&v) + DVector::from_vec(pt)
    };
    let mut rate_fd = DMatrix::zeros(m, n);
    for c in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[c] += h;
        qm[c] -= h;
        rate_fd.set_column(c, &((rate(&qp) - rate(&qm)) / (2.0 * h)));
    }
    let (mut j2, mut tan) = (DMatrix::zeros(m, n), DMatrix::zeros(m, n));
    sys.phi_q_dot_jacobian(&q, &v, t, &mut j2, &mut tan);
    assert_eq!(j2, jac);
    let d = (&tan - &rate_fd).amax();
    eprintln!("(Phi_q v + Phi_t)_q against differences: {d:.1e}");
    assert!(d < 1e-8, "{d:e}");
    let mut tan_local = DMatrix::zeros(m, n);
    sys.local_rows_tan(&q, &v, t, |r, sides| {
        for (block, _, dg) in sides.into_iter().flatten() {
            let (c0, _) = sys.body_block(block).unwrap();
            for (l, x) in dg.iter().enumerate() {
                tan_local[(r, c0 + l)] += x;
            }
        }
    });
    assert!((&tan_local - &tan).amax() < 1e-15);
    // sum_k lambda_k Hess(Phi_k) = d/dq (Phi_q^T lambda)
    let lambda: Vec<f64> = (0..m).map(|k| (0.8 * k as f64).cos()).collect();
    let mut hess = DMatrix::zeros(n, n);
    sys.constraint_hessian(&q, t, &lambda, &mut hess);
    let jtl = |q: &[f64]| {
        let mut j = DMatrix::zeros(m, n);
        sys.phi_q(q, t, &mut j);
        j.transpose() * DVector::from_column_slice(&lambda)
    };
    let mut hess_fd = DMatrix::zeros(n, n);
    for c in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[c] += h;
        qm[c] -= h;
        hess_fd.set_column(c, &((jtl(&qp) - jtl(&qm)) / (2.0 * h)));
    }
    let d = (&hess - &hess_fd).amax();
    eprintln!("constraint Hessian against differences: {d:.1e}");
    assert!(d < 1e-8, "{d:e}");
}

/// The motor turns the rod through `theta(t)` with every solver that runs spatial bodies (the
/// rod's angle within 1e-9 of `theta` at t = 1.2 s, h = 1e-3; the tangent chart also on its
/// sparse path; FA-DAE refuses a model without a degree of freedom), and the driver's multiplier is the torque Euler's law about the hinge needs:
/// `lambda = m g (L/2) cos theta - J_hinge theta''` (`J_hinge = m L^2 / 3`; the driver's
/// equation is `sin(phi - theta)`, slope 1 in the rod's angle `phi`), to 1e-8; the motor's
/// reaction on the rod is the moment `-lambda` about the hinge axis and nothing else.
#[test]
fn a_motor_turns_a_rod_through_its_angle_with_every_solver() {
    let sys = motor_rod();
    assert!(sys.is_rheonomic() && sys.dof() == 0);
    assert!(sys.jacobian_depends_on_time());
    let t = 1.2;
    let [theta, _, ddtheta] = motion().eval(t);
    let torque = MASS * G * 0.5 * LENGTH * theta.cos() - MASS * LENGTH * LENGTH / 3.0 * ddtheta;
    for spec in [
        "rk4",
        "rk4-projected",
        "index1:dopri5",
        "tangent:rk4",
        "tangent:dopri5",
        "symplectic:1",
        "symplectic:2",
    ] {
        let mut sim = Simulation::new(sys.clone(), spec).unwrap();
        sim.run(RunConfig::new(t, 1e-3)).unwrap();
        let st = sim.state();
        let err = angle_error(st.q.as_slice(), theta);
        let mut os = mbd::solve::OutputSolve::new(&sys).unwrap();
        let (_, lambda) = os.at(&sys, st).unwrap();
        let dl = (lambda[sys.n_constraints() - 1] - torque).abs();
        // the motor's reaction on the rod: a moment about the hinge axis (global y, the
        // direction theta turns) of -lambda, and no force
        let r = sys
            .spatial_joint_reactions(st.q.as_slice(), st.t, lambda)
            .unwrap()[1];
        let dm = (r.moment[1] + lambda[sys.n_constraints() - 1]).abs();
        let off = r.force.iter().chain(&r.moment[..1]).chain(&r.moment[2..]);
        let off = off.fold(0.0f64, |m, x| m.max(x.abs()));
        eprintln!(
            "{spec}: angle off by {err:.1e}, motor torque off by {dl:.1e}, its reaction by {dm:.1e}"
        );
        assert!(err < 1e-9, "{spec}: {err:e}");
        assert!(dl < 1e-8, "{spec}: {dl:e}");
        assert!(dm < 1e-9 && off < 1e-9, "{spec}: {dm:e} {off:e}");
    }
    // the motor leaves no degree of freedom, which FA-DAE's optimisation needs
    let e = Simulation::new(sys.clone(), "firefly-gauss")
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("no degree of freedom"), "{e}");
    // ... and the registry's table says so
    let (_, v) = mbd::registry()
        .variants()
        .find(|(_, v)| v.spec == "firefly-gauss")
        .expect("registered");
    assert!(
        v.refuses.contains("without a degree of freedom"),
        "{}",
        v.refuses
    );
    let opts = mbd::tangent::TangentOptions {
        linear_solver: mbd::solve::LinearSolver::Sparse,
        ..Default::default()
    };
    let mut integ =
        mbd::tangent::TangentRk::new(&sys, mbd::solve::ButcherTableau::rk4(), opts).unwrap();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    for _ in 0..1200 {
        integ.step(&sys, &mut s, 1e-3).unwrap();
    }
    let err = angle_error(s.q.as_slice(), theta);
    eprintln!("tangent RK4 (sparse chart): angle off by {err:.1e}");
    assert!(err < 1e-9, "{err:e}");
}

/// The energy balance books the motor's work, `-lambda Phi_t` with `Phi_t` depending on the
/// configuration: it closes to 1e-8 of the largest energy over 2 s (symplectic (2,2) and
/// projected RK4, h = 1e-3) while the rod's energy changes by more than a fifth of the largest.
#[test]
fn the_energy_balance_books_the_motors_work() {
    let sys = motor_rod();
    for spec in ["symplectic:2", "rk4-projected"] {
        let mut eb = EnergyBalance::new(&sys).unwrap();
        let mut sim = Simulation::new(sys.clone(), spec).unwrap();
        sim.run_observed(RunConfig::new(2.0, 1e-3), &mut eb)
            .unwrap();
        let rel = eb.max_residual() / eb.max_energy();
        let (q0, v0) = sys.initial_guess();
        let st = sim.state();
        let dh = (sys.energy(st.q.as_slice(), st.v.as_slice())
            - sys.energy(q0.as_slice(), v0.as_slice()))
        .abs();
        eprintln!(
            "{spec}: energy balance residual {rel:.1e} of the largest energy; H changed by {:.2} of it",
            dh / eb.max_energy()
        );
        assert!(rel < 1e-8, "{spec}: {rel:e}");
        assert!(dh > 0.2 * eb.max_energy(), "{spec}");
    }
}

/// A pendulum on a turning arm: an arm on a vertical hinge turned by a motor at
/// `theta(t) = 3 t`, a slender rod hanging from its tip on a ball joint (three degrees of
/// freedom, the motor's `Phi_qt` in every acceleration). Released 0.4 rad from the vertical,
/// turning with the arm.
fn turning_arm() -> System {
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -G]);
    let (arm_l, rod_l, omega) = (0.5, 0.6, 3.0);
    let arm = b.add_spatial_body(
        SpatialBody::new(
            "arm",
            SpatialInertia::principal(2.0, [1e-3, 0.05, 0.05]).unwrap(),
        )
        .position([0.5 * arm_l, 0.0, 0.0])
        .velocity([0.0, 0.5 * arm_l * omega, 0.0])
        .angular_velocity([0.0, 0.0, omega]),
    );
    let jt = rod_l * rod_l / 12.0;
    let tilt = 0.4f64;
    let (s, c) = tilt.sin_cos();
    // the rod's x axis along its length, pointing down and out: (sin, 0, -cos)
    let r = Matrix3::new(s, 0.0, c, 0.0, 1.0, 0.0, -c, 0.0, s);
    let pend = b.add_spatial_body(
        SpatialBody::new(
            "pendulum",
            SpatialInertia::principal(1.0, [1e-3 * jt, jt, jt]).unwrap(),
        )
        .position([arm_l + 0.5 * rod_l * s, 0.0, -0.5 * rod_l * c])
        .orientation(Orientation::Matrix(r))
        .velocity([0.0, omega * (arm_l + 0.5 * rod_l * s), 0.0])
        .angular_velocity([0.0, 0.0, omega]),
    );
    let vertical = Marker::with_axes([0.0; 3], Matrix3::identity());
    let arm_end = Marker::with_axes([-0.5 * arm_l, 0.0, 0.0], Matrix3::identity());
    b.add_spatial_joint(
        "pivot",
        SpatialBodyRef::Ground,
        arm,
        SpatialJoint::new(SpatialJointKind::Revolute, vertical, arm_end).unwrap(),
    );
    b.add_spatial_driver(
        "motor",
        SpatialBodyRef::Ground,
        arm,
        SpatialJoint::new(SpatialJointKind::AngleDriver, vertical, arm_end).unwrap(),
        TimeFunction::Polynomial {
            coeffs: vec![0.0, omega],
        },
    );
    b.add_spatial_joint(
        "ball",
        arm,
        pend,
        SpatialJoint::new(
            SpatialJointKind::Spherical,
            Marker::at([0.5 * arm_l, 0.0, 0.0]),
            Marker::at([-0.5 * rod_l, 0.0, 0.0]),
        )
        .unwrap(),
    );
    b.build().unwrap()
}

/// The pendulum on the turning arm with four independent solvers: at t = 1 s their positions
/// agree with index-1 DOPRI5 at tolerance 1e-12 to 1e-10 (projected RK4 at h = 2.5e-4, tangent
/// DOPRI5 at 1e-3, symplectic (2,2) at 5e-4; measured 5.0e-13, 5.3e-13, 4.1e-11), and the
/// energy balance with the motor's work closes to 1e-10 of the largest energy (measured
/// 5.6e-14, 3.2e-13, 3.2e-13).
#[test]
fn a_pendulum_on_a_turning_arm_agrees_across_solvers() {
    let sys = turning_arm();
    assert_eq!(sys.dof(), 3);
    // examples/models/turning_arm.toml is this model
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let file = System::from_path(root.join("examples/models/turning_arm.toml")).unwrap();
    let (qf, vf) = file.initial_guess();
    let (qs, vs) = sys.initial_guess();
    assert!((&qf - &qs).amax() < 1e-12 && (&vf - &vs).amax() < 1e-12);
    let t = 1.0;
    let mut reference = Simulation::new(sys.clone(), "index1:dopri5").unwrap();
    reference.run(AdaptiveConfig::new(t, 1e-12)).unwrap();
    let q_ref = reference.state().q.clone();
    let moved = (&q_ref - sys.initial_guess().0).amax();
    assert!(moved > 0.1, "{moved}");
    for (spec, h) in [
        ("rk4-projected", 2.5e-4),
        ("tangent:dopri5", 1e-3),
        ("symplectic:2", 5e-4),
    ] {
        let mut sim = Simulation::new(sys.clone(), spec).unwrap();
        let mut eb = EnergyBalance::new(&sys).unwrap();
        sim.run_observed(RunConfig::new(t, h), &mut eb).unwrap();
        let d = (&sim.state().q - &q_ref).amax();
        let rel = eb.max_residual() / eb.max_energy();
        eprintln!("{spec} (h = {h}): {d:.1e} from index-1 DOPRI5; energy balance {rel:.1e}");
        assert!(d < 1e-10, "{spec}: {d:e}");
        assert!(rel < 1e-10, "{spec}: {rel:e}");
    }
}

/// The angle driver round-trips through model files (`type = "angle_driver"` with its
/// `motion`), and without a motion it is an error naming the joint.
#[test]
fn angle_drivers_in_model_files() {
    let sys = motor_rod();
    let text = sys.to_model_file().to_toml().unwrap();
    assert!(text.contains("type = \"angle_driver\""), "{text}");
    let back = ModelFile::from_toml(&text).unwrap().build().unwrap();
    assert_eq!(back.spatial_joints(), sys.spatial_joints());
    let mut no_motion = sys.to_model_file();
    no_motion.spatial_joints[1].motion = None;
    let e = no_motion.build().unwrap_err().to_string();
    assert!(e.contains("motor") && e.contains("motion"), "{e}");
}
