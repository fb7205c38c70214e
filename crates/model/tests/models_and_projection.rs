//! The ready-made models and consistent initial conditions.

mod common;

use common::*;
use mbd_model::models::{self, chain, ChainParams};
use mbd_model::nalgebra::DMatrix;
use mbd_model::{Body, BodyRef, Joint, System, SystemBuilder, TimeFunction};

fn named_models() -> Vec<(&'static str, System)> {
    vec![
        ("pendulum", models::pendulum(1.0, 1.0, 0.5, 9.81).unwrap()),
        ("manipulator", models::manipulator().unwrap()),
        ("slider_crank", models::slider_crank().unwrap()),
        ("four_bar", models::four_bar().unwrap()),
    ]
}

#[test]
fn model_dimensions() {
    let expect = [
        ("pendulum", (3, 2, 1)),
        ("manipulator", (6, 4, 2)),
        ("slider_crank", (9, 8, 1)),
        ("four_bar", (9, 8, 1)),
    ];
    for ((name, sys), (ename, dims)) in named_models().into_iter().zip(expect) {
        assert_eq!(name, ename);
        assert_eq!(
            (sys.n_coords(), sys.n_constraints(), sys.dof()),
            dims,
            "{name}"
        );
        assert!(!sys.is_rheonomic() && sys.is_conservative(), "{name}");
    }
    let sys = models::paper_a_double_pendulum().unwrap();
    assert_eq!((sys.n_coords(), sys.n_constraints(), sys.dof()), (6, 4, 2));
    let sys = models::n_link_chain(7).unwrap();
    assert_eq!(
        (sys.n_coords(), sys.n_constraints(), sys.dof()),
        (21, 14, 7)
    );
}

#[test]
fn manipulator_initial_energy() {
    // theta1 = pi/3, theta2 = 0, at rest: H0 = g (m1 L1/2 sin60 + m2 (L1 sin60 + 0)) = 12.7436 J
    let sys = models::manipulator().unwrap();
    let x0 = mbd_solve::consistent_state(&sys, 0.0).unwrap();
    let h0 = sys.energy(x0.q.as_slice(), x0.v.as_slice());
    assert!((h0 - 12.7436).abs() < 1e-4, "H0 = {h0}");
    let exact = 9.81 * (0.5 + 1.0) * 60f64.to_radians().sin();
    assert!((h0 - exact).abs() < 1e-12, "H0 = {h0} vs {exact}");
    assert_eq!(x0.position_correction, 0.0);
}

#[test]
fn pendulum_is_a_hanging_rod() {
    // 0.3 rad from the downward vertical: V = -m g (l/2) cos(0.3), J = m l^2 / 12
    let sys = models::pendulum(2.0, 1.5, 0.3, 9.81).unwrap();
    let (q, _) = sys.initial_guess();
    assert!((sys.potential(q.as_slice()) + 2.0 * 9.81 * 0.75 * 0.3f64.cos()).abs() < 1e-13);
    assert!((sys.bodies()[0].inertia - 2.0 * 1.5 * 1.5 / 12.0).abs() < 1e-15);
}

#[test]
fn geometric_initial_positions_are_consistent() {
    // The models are built geometrically: Phi(q_guess) = 0 to round-off before any projection.
    for (name, sys) in named_models() {
        let (q, _) = sys.initial_guess();
        let mut phi = vec![0.0; sys.n_constraints()];
        sys.phi(q.as_slice(), 0.0, &mut phi);
        assert!(
            inf_norm(&phi) < 1e-12,
            "{name}: |Phi| = {:e}",
            inf_norm(&phi)
        );
    }
    for n in 1..6 {
        let sys = models::n_link_chain(n).unwrap();
        let (q, _) = sys.initial_guess();
        let mut phi = vec![0.0; sys.n_constraints()];
        sys.phi(q.as_slice(), 0.0, &mut phi);
        assert!(inf_norm(&phi) < 1e-14);
    }
    // the crank velocity guesses of the closed loops are rigid rotations about the ground pivot
    for sys in [models::slider_crank().unwrap(), models::four_bar().unwrap()] {
        let (q, v) = sys.initial_guess();
        let crank = sys.body_handle("crank").unwrap();
        let l = 2.0 * sys.point_position(crank, [0.0, 0.0], q.as_slice()).norm();
        let pv = sys.point_velocity(crank, [-0.5 * l, 0.0], q.as_slice(), v.as_slice());
        assert!(pv.norm() < 1e-14);
    }
}

#[test]
fn chain_rejects_mismatched_lengths() {
    let e = chain(&ChainParams {
        masses: vec![1.0, 1.0],
        lengths: vec![1.0],
        angles: vec![0.0, 0.0],
        g: 9.81,
    })
    .unwrap_err();
    assert!(matches!(
        e,
        mbd_model::ModelError::Dimension {
            expected: 2,
            got: 1,
            ..
        }
    ));
}

/// Projects perturbed consistent states; returns the smallest and largest position corrections.
fn perturb_and_project(sys: &System, t: f64, seed: u64) -> (f64, f64) {
    let (n, m) = (sys.n_coords(), sys.n_constraints());
    let base = mbd_solve::consistent_state(sys, t).unwrap();
    let mut r = rng(seed);
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for _ in 0..20 {
        let q: Vec<f64> = base
            .q
            .iter()
            .map(|x| x + uni(&mut r, -1e-3, 1e-3))
            .collect();
        let v: Vec<f64> = base
            .v
            .iter()
            .map(|x| x + uni(&mut r, -1e-3, 1e-3))
            .collect();
        let x = mbd_solve::project_state(sys, &q, &v, t, mbd_solve::ConsistentOptions::default())
            .unwrap();
        let (mut phi, mut pd) = (vec![0.0; m], vec![0.0; m]);
        sys.phi(x.q.as_slice(), t, &mut phi);
        sys.phi_dot(x.q.as_slice(), x.v.as_slice(), t, &mut pd);
        assert!(inf_norm(&phi) <= 1e-12, "|Phi| = {:e}", inf_norm(&phi));
        assert!(
            inf_norm(&pd) <= 1e-12,
            "|Phi_q v + Phi_t| = {:e}",
            inf_norm(&pd)
        );
        assert_eq!(x.residual, inf_norm(&phi));
        assert_eq!(x.velocity_residual, inf_norm(&pd));
        assert!(
            x.iterations >= 1 && x.iterations <= 10,
            "{} iterations",
            x.iterations
        );
        // reported corrections are the max-norms of the moves
        let dq: Vec<f64> = x.q.iter().zip(&q).map(|(a, b)| a - b).collect();
        let dv: Vec<f64> = x.v.iter().zip(&v).map(|(a, b)| a - b).collect();
        assert_eq!(x.position_correction, inf_norm(&dq));
        assert_eq!(x.velocity_correction, inf_norm(&dv));
        assert!(x.position_correction > 1e-6 && x.position_correction < 1e-2);
        assert!(x.velocity_correction > 0.0 && x.velocity_correction < 1e-1);
        // the correction is M-orthogonal to the manifold: dq in range(M^-1 Phi_q^T) to first order
        let _ = n;
        lo = lo.min(x.position_correction);
        hi = hi.max(x.position_correction);
    }
    (lo, hi)
}

#[test]
fn projection_of_perturbed_states() {
    for (k, (name, sys)) in named_models().into_iter().enumerate() {
        let (lo, hi) = perturb_and_project(&sys, 0.0, 100 + k as u64);
        eprintln!("{name}: position corrections in [{lo:.1e}, {hi:.1e}]");
    }
}

#[test]
fn velocity_projection_is_m_orthogonal() {
    // v = v_guess - M^-1 Phi_q^T mu: the correction is the minimum kinetic-energy-norm one,
    // so for every admissible w (Phi_q w = 0): (v - v_guess)^T M w = 0.
    let sys = models::four_bar().unwrap();
    let x = mbd_solve::consistent_state(&sys, 0.0).unwrap();
    let (v_guess_q, v_guess) = sys.initial_guess();
    let _ = v_guess_q;
    let dv = &x.v - &v_guess;
    // the admissible direction: the projected velocity itself (Phi_t = 0)
    let w = &x.v;
    let mdv = dv.component_mul(sys.mass_diag());
    assert!(mdv.dot(w).abs() < 1e-12 * (mdv.norm() * w.norm()));
    let mut jac = DMatrix::zeros(8, 9);
    sys.phi_q(x.q.as_slice(), 0.0, &mut jac);
    assert!((&jac * &x.v).amax() < 1e-12);
    // the crank keeps turning the same way
    assert!(x.v[2] > 0.0, "crank speed {}", x.v[2]);
}

/// Manipulator with the first link driven: theta1 = pi/3 + 0.2 sin(2 t).
fn driven_manipulator() -> System {
    let mut mf = models::manipulator().unwrap().to_model_file();
    mf.joints.push(mbd_model::JointSpec::AngleDriver(
        mbd_model::joints::AngleDriverSpec {
            name: "motor".into(),
            body_a: "ground".into(),
            body_b: "link1".into(),
            f: TimeFunction::Harmonic {
                offset: std::f64::consts::FRAC_PI_3,
                amplitude: 0.2,
                omega: 2.0,
                phase: 0.0,
            },
        },
    ));
    mf.build().unwrap()
}

#[test]
fn rheonomic_projection_includes_phi_t() {
    let sys = driven_manipulator();
    assert!(sys.is_rheonomic());
    assert_eq!(sys.dof(), 1);
    let t = 0.4;
    let x = mbd_solve::consistent_state(&sys, t).unwrap();
    let m = sys.n_constraints();
    let (mut phi, mut pt, mut pd) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    sys.phi(x.q.as_slice(), t, &mut phi);
    sys.phi_t(x.q.as_slice(), t, &mut pt);
    sys.phi_dot(x.q.as_slice(), x.v.as_slice(), t, &mut pd);
    assert!(inf_norm(&phi) <= 1e-12 && inf_norm(&pd) <= 1e-12);
    // the driven angle and its rate follow the driver
    let theta = std::f64::consts::FRAC_PI_3 + 0.2 * (2.0 * t).sin();
    let omega = 0.4 * (2.0 * t).cos();
    assert!((x.q[2] - theta).abs() < 1e-12);
    assert!((x.v[2] - omega).abs() < 1e-12);
    // Phi_q v alone is -Phi_t, far from zero: dropping Phi_t would be caught
    let mut jac = DMatrix::zeros(m, sys.n_coords());
    sys.phi_q(x.q.as_slice(), 0.0, &mut jac);
    let jv = &jac * &x.v;
    assert!((jv[m - 1] + pt[m - 1]).abs() < 1e-12 && pt[m - 1].abs() > 0.2);
    // a pin velocity consistent with the motion: pin2 tip of link 1 moves at omega * L1
    let tip = sys.point_velocity(
        sys.body_handles().next().unwrap(),
        [0.5, 0.0],
        x.q.as_slice(),
        x.v.as_slice(),
    );
    assert!((tip.norm() - omega.abs()).abs() < 1e-12);
    perturb_and_project(&sys, t, 7);
}

#[test]
fn projection_far_from_the_origin() {
    // An absolute tolerance of 1e-13 cannot be met with coordinates of size 1e6 (their ulp is
    // ~1e-10): the projection must floor it at the round-off level instead of failing.
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let p = [1.0e6, -2.5e6];
    let rod = b.add_body(Body::new("rod").rod(1.0, 1.0).position(
        p[0] + 0.5 * 0.3f64.cos(),
        p[1] + 0.5 * 0.3f64.sin(),
        0.3,
    ));
    b.add_joint(Joint::revolute(
        "pivot",
        BodyRef::Ground,
        p,
        rod,
        [-0.5, 0.0],
    ));
    let sys = b.build().unwrap();
    let mut r = rng(11);
    for _ in 0..10 {
        let (q0, v0) = sys.initial_guess();
        let q: Vec<f64> = q0.iter().map(|x| x + uni(&mut r, -1e-3, 1e-3)).collect();
        let x = mbd_solve::project_state(
            &sys,
            &q,
            v0.as_slice(),
            0.0,
            mbd_solve::ConsistentOptions::default(),
        );
        let x = x.unwrap();
        // the best attainable: a few ulps of the coordinates (ulp(2.5e6) = 4.7e-10)
        assert!(x.residual <= 8.0 * f64::EPSILON * 2.6e6, "{:e}", x.residual);
        assert!(x.position_correction > 1e-5 && x.position_correction < 1e-2);
    }
}
