//! Constraint kinematics of every joint kind against finite differences.
//!
//! Error measure: entry-wise `|fd - exact| / max(1, |exact|)` (see `common::rel`).
//! Steps and tolerances:
//! * `Phi_q`, `Phi_t`, `Phi_q v + Phi_t`, constraint Hessian: central differences with
//!   `h = 1e-5`; truncation ~ h^2 |Phi'''| ~ 1e-10 and round-off ~ eps |Phi| / h ~ 1e-10 for the
//!   O(1..10) coordinates used, tolerance 1e-7.
//! * `gamma`: `d^2/ds^2 Phi(q + s v, t + s)` at `s = 0` equals `-gamma` (the acceleration along the
//!   straight line is zero), by a Richardson-extrapolated central second difference with
//!   `h = 2e-3` (round-off ~ 1e-9, truncation ~ 1e-11), tolerance 1e-6.
//!
//! The worst numbers per joint kind are printed (`cargo test -- --nocapture`).

mod common;

use common::*;
use mbd_model::nalgebra::DMatrix;
use mbd_model::{Body, BodyRef, Coordinate, Joint, System, SystemBuilder, TimeFunction};
use rand_chacha::ChaCha8Rng;

const H1: f64 = 1e-5;
const H2: f64 = 2e-3;
const TOL1: f64 = 1e-7;
const TOL2: f64 = 1e-6;
const CONFIGS: usize = 25;

#[derive(Clone, Copy, Debug)]
enum Kind {
    RevoluteBodyBody,
    RevoluteGroundBody,
    RevoluteBodyGround,
    PrismaticBodyBody,
    PrismaticGroundBody,
    WeldBodyBody,
    WeldBodyGround,
    DistanceBodyBody,
    DistanceGroundBody,
    AbsoluteX,
    AbsoluteY,
    AbsoluteAngle,
    DriverHarmonic,
    DriverPolynomialGround,
}

const KINDS: [Kind; 14] = [
    Kind::RevoluteBodyBody,
    Kind::RevoluteGroundBody,
    Kind::RevoluteBodyGround,
    Kind::PrismaticBodyBody,
    Kind::PrismaticGroundBody,
    Kind::WeldBodyBody,
    Kind::WeldBodyGround,
    Kind::DistanceBodyBody,
    Kind::DistanceGroundBody,
    Kind::AbsoluteX,
    Kind::AbsoluteY,
    Kind::AbsoluteAngle,
    Kind::DriverHarmonic,
    Kind::DriverPolynomialGround,
];

/// Two random bodies and one joint of the given kind with random parameters.
fn make(kind: Kind, r: &mut ChaCha8Rng) -> System {
    let mut b = SystemBuilder::new();
    let b1 = b.add_body(rbody(r, "b1"));
    let b2 = b.add_body(rbody(r, "b2"));
    let (pa, pb) = (rpoint(r, 1.0), rpoint(r, 1.0));
    let g = BodyRef::Ground;
    let gp = rpoint(r, 2.0);
    let angle = uni(r, -3.0, 3.0);
    let axis = [uni(r, -2.0, 2.0), uni(r, 0.2, 2.0)];
    let j = match kind {
        Kind::RevoluteBodyBody => Joint::revolute("j", b1, pa, b2, pb),
        Kind::RevoluteGroundBody => Joint::revolute("j", g, gp, b2, pb),
        Kind::RevoluteBodyGround => Joint::revolute("j", b1, pa, g, gp),
        Kind::PrismaticBodyBody => Joint::prismatic("j", b1, pa, b2, pb, axis, angle),
        Kind::PrismaticGroundBody => Joint::prismatic("j", g, gp, b2, pb, axis, angle),
        Kind::WeldBodyBody => Joint::weld("j", b1, pa, b2, pb, angle),
        Kind::WeldBodyGround => Joint::weld("j", b1, pa, g, gp, angle),
        Kind::DistanceBodyBody => Joint::distance("j", b1, pa, b2, pb, uni(r, 0.3, 3.0)),
        Kind::DistanceGroundBody => Joint::distance("j", g, gp, b2, pb, uni(r, 0.3, 3.0)),
        Kind::AbsoluteX => Joint::absolute("j", b2, pb, Coordinate::X, uni(r, -1.0, 1.0)),
        Kind::AbsoluteY => Joint::absolute("j", b1, pa, Coordinate::Y, uni(r, -1.0, 1.0)),
        Kind::AbsoluteAngle => Joint::absolute("j", b2, pb, Coordinate::Angle, uni(r, -1.0, 1.0)),
        Kind::DriverHarmonic => Joint::angle_driver(
            "j",
            b1,
            b2,
            TimeFunction::Harmonic {
                offset: uni(r, -1.0, 1.0),
                amplitude: uni(r, 0.2, 1.5),
                omega: uni(r, 0.5, 3.0),
                phase: uni(r, -1.0, 1.0),
            },
        ),
        Kind::DriverPolynomialGround => Joint::angle_driver(
            "j",
            g,
            b2,
            TimeFunction::Polynomial {
                coeffs: rvec(r, 4, 1.0),
            },
        ),
    };
    b.add_joint(j);
    b.build().expect("generic random joint builds")
}

#[derive(Default, Debug)]
struct Worst {
    jac: f64,
    gamma: f64,
    phi_dot: f64,
    phi_t: f64,
    hess: f64,
}

impl std::fmt::Display for Worst {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Phi_q {:.1e}, Phi_t {:.1e}, phi_dot {:.1e}, gamma {:.1e}, Hessian {:.1e}",
            self.jac, self.phi_t, self.phi_dot, self.gamma, self.hess
        )
    }
}

impl Worst {
    fn max(&mut self, o: &Worst) {
        self.jac = self.jac.max(o.jac);
        self.gamma = self.gamma.max(o.gamma);
        self.phi_dot = self.phi_dot.max(o.phi_dot);
        self.phi_t = self.phi_t.max(o.phi_t);
        self.hess = self.hess.max(o.hess);
    }
    fn assert_ok(&self, what: &str) {
        assert!(self.jac < TOL1, "{what}: Phi_q vs FD {:e}", self.jac);
        assert!(self.phi_t < TOL1, "{what}: Phi_t vs FD {:e}", self.phi_t);
        assert!(
            self.phi_dot < TOL1,
            "{what}: phi_dot vs FD {:e}",
            self.phi_dot
        );
        assert!(self.hess < TOL1, "{what}: Hessian vs FD {:e}", self.hess);
        assert!(self.gamma < TOL2, "{what}: gamma vs FD {:e}", self.gamma);
    }
}

/// All kinematic checks of `sys` at one random `(q, v, t, lambda)`.
fn check_at(sys: &System, r: &mut ChaCha8Rng) -> Worst {
    let (n, m) = (sys.n_coords(), sys.n_constraints());
    let q = rconfig(r, n);
    let v = rvec(r, n, 2.0);
    let lambda = rvec(r, m, 2.0);
    let t = uni(r, 0.0, 2.0);
    let mut w = Worst::default();

    // Phi_q vs FD of Phi
    let mut jac = DMatrix::zeros(m, n);
    sys.phi_q(&q, 0.0, &mut jac);
    let fd = fd_jacobian(|x, out| sys.phi(x, t, out), &q, m, H1);
    w.jac = max_rel_mat(&fd, &jac);

    // triplets reproduce the dense Jacobian exactly (duplicates are summed)
    let mut trip = Vec::new();
    sys.phi_q_triplets(&q, 0.0, &mut trip);
    let mut dense = DMatrix::zeros(m, n);
    for &(i, j, x) in &trip {
        assert!(i < m && j < n);
        dense[(i, j)] += x;
    }
    assert_eq!(dense, jac, "triplets differ from phi_q");

    // Phi_t vs FD in t
    let mut pt = vec![0.0; m];
    sys.phi_t(&q, t, &mut pt);
    let fdt = fd_jacobian(|x, out| sys.phi(&q, x[0], out), &[t], m, H1);
    w.phi_t = max_rel(fdt.as_slice(), &pt);
    if !sys.is_rheonomic() {
        assert!(pt.iter().all(|&x| x == 0.0), "scleronomic Phi_t = {pt:?}");
    }

    // phi_dot = Phi_q v + Phi_t, and = d/ds Phi(q + s v, t + s)
    let path = |s: f64, out: &mut [f64]| {
        let qs: Vec<f64> = q.iter().zip(&v).map(|(q, v)| q + s * v).collect();
        sys.phi(&qs, t + s, out);
    };
    let mut pd = vec![0.0; m];
    sys.phi_dot(&q, &v, t, &mut pd);
    let fdd = fd_jacobian(|x, out| path(x[0], out), &[0.0], m, H1);
    w.phi_dot = max_rel(fdd.as_slice(), &pd);
    let jv = &jac * mbd_model::nalgebra::DVector::from_column_slice(&v);
    for i in 0..m {
        assert!(
            rel(jv[i] + pt[i], pd[i]) < 1e-14,
            "phi_dot != Phi_q v + Phi_t"
        );
    }

    // gamma: d^2/ds^2 Phi(q + s v, t + s) = -gamma
    let mut gamma = vec![0.0; m];
    sys.gamma(&q, &v, t, &mut gamma);
    let d2 = second_derivative(path, m, H2);
    let neg: Vec<f64> = gamma.iter().map(|g| -g).collect();
    w.gamma = max_rel(&d2, &neg);
    // the fused evaluation agrees exactly
    let mut jac2 = DMatrix::zeros(m, n);
    let mut gamma2 = vec![0.0; m];
    sys.phi_q_gamma(&q, &v, t, &mut jac2, &mut gamma2);
    assert_eq!(jac2, jac);
    assert_eq!(gamma2, gamma);

    // constraint Hessian vs FD of Phi_q^T lambda
    let mut hess = DMatrix::zeros(n, n);
    sys.constraint_hessian(&q, 0.0, &lambda, &mut hess);
    let lam = mbd_model::nalgebra::DVector::from_column_slice(&lambda);
    let fdh = fd_jacobian(
        |x, out| {
            let mut j = DMatrix::zeros(m, n);
            sys.phi_q(x, 0.0, &mut j);
            out.copy_from_slice(j.tr_mul(&lam).as_slice());
        },
        &q,
        n,
        H1,
    );
    w.hess = max_rel_mat(&fdh, &hess);
    assert_eq!(hess, hess.transpose(), "Hessian not symmetric");
    // add_constraint_hessian accumulates with a scale
    let mut acc = hess.clone();
    sys.add_constraint_hessian(&q, 0.0, &lambda, -2.0, &mut acc);
    assert!((acc + &hess).amax() <= 1e-13 * hess.amax().max(1.0));
    w
}

#[test]
fn every_joint_kind_matches_finite_differences() {
    let mut all = Worst::default();
    for (k, kind) in KINDS.iter().enumerate() {
        let mut r = rng(1000 + k as u64);
        let mut worst = Worst::default();
        for _ in 0..CONFIGS {
            let sys = make(*kind, &mut r);
            let w = check_at(&sys, &mut r);
            worst.max(&w);
        }
        eprintln!("{kind:?}: {worst}");
        worst.assert_ok(&format!("{kind:?}"));
        all.max(&worst);
    }
    eprintln!("all joints: {all}");
}

#[test]
fn kitchen_sink_matches_finite_differences() {
    // Several joints in one system: checks row offsets and the scattering into global columns.
    let sys = kitchen_sink().unwrap();
    assert_eq!((sys.n_coords(), sys.n_constraints()), (15, 12));
    assert!(sys.is_rheonomic());
    let mut r = rng(77);
    let mut worst = Worst::default();
    for _ in 0..CONFIGS {
        worst.max(&check_at(&sys, &mut r));
    }
    eprintln!("kitchen sink: {worst}");
    worst.assert_ok("kitchen sink");
}

#[test]
fn driver_time_derivatives_are_exact() {
    // Phi = theta_b - theta_a - f(t): Phi_t = -f'(t) and gamma = -v^T g_qq v + f''(t) = f''(t).
    let f = TimeFunction::Harmonic {
        offset: 0.1,
        amplitude: 0.7,
        omega: 3.0,
        phase: 0.2,
    };
    let mut b = SystemBuilder::new();
    let a = b.add_body(Body::new("a").position(0.0, 0.0, 0.3));
    let c = b.add_body(Body::new("c").position(1.0, 0.0, -0.2));
    b.add_joint(Joint::angle_driver("drv", a, c, f.clone()));
    let sys = b.build().unwrap();
    assert!(sys.is_rheonomic());
    let t = 0.83;
    let [f0, f1, f2] = f.eval(t);
    let q = [0.0, 0.0, 0.3, 1.0, 0.0, -0.2];
    let v = [0.1, 0.2, 0.3, -0.4, 0.5, 0.6];
    let (mut phi, mut pt, mut gamma, mut pd) = ([0.0], [0.0], [0.0], [0.0]);
    sys.phi(&q, t, &mut phi);
    sys.phi_t(&q, t, &mut pt);
    sys.gamma(&q, &v, t, &mut gamma);
    sys.phi_dot(&q, &v, t, &mut pd);
    assert_eq!(phi[0], -0.2 - 0.3 - f0);
    assert_eq!(pt[0], -f1);
    assert_eq!(gamma[0], f2);
    assert!((pd[0] - (0.6 - 0.3 - f1)).abs() < 1e-15);
    // a constant driver is not rheonomic
    let mut b = SystemBuilder::new();
    let a = b.add_body(Body::new("a"));
    b.add_joint(Joint::angle_driver(
        "drv",
        BodyRef::Ground,
        a,
        TimeFunction::constant(0.5),
    ));
    assert!(!b.build().unwrap().is_rheonomic());
}

#[test]
fn equation_names_and_rows() {
    let sys = kitchen_sink().unwrap();
    let names = sys.equation_names();
    assert_eq!(names.len(), sys.n_constraints());
    assert_eq!(
        names,
        [
            "rev.x",
            "rev.y",
            "pris.normal",
            "pris.angle",
            "weld.x",
            "weld.y",
            "weld.angle",
            "dist.length",
            "absx.x",
            "drv_h.angle",
            "absy.y",
            "drv_p.angle"
        ]
    );
    for (row, name) in names.iter().enumerate() {
        assert_eq!(&sys.equation_name(row), name);
        let j = sys.equation_joint(row).unwrap();
        assert!(sys.joint_rows(j).contains(&row));
    }
    assert_eq!(sys.equation_joint(12), None);
    let wh = sys.joint_handle("weld").unwrap();
    assert_eq!(sys.joint_rows(wh), 4..7);
    assert_eq!(sys.coordinate_names()[5], "b2.theta");
}

mod rank {
    use super::*;
    use mbd_model::models::{chain, ChainParams};
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 64,
            failure_persistence: None,
            ..ProptestConfig::default()
        })]
        /// An open chain of rods has an independent set of pin equations at every configuration:
        /// `Phi_q` has full row rank (the chain is built at random angles, then checked at the
        /// geometric configuration of other random angles).
        #[test]
        fn open_chain_has_full_row_rank(
            angles in proptest::collection::vec(-3.2f64..3.2, 1..6),
            other in proptest::collection::vec(-3.2f64..3.2, 6),
        ) {
            let k = angles.len();
            let sys = chain(&ChainParams {
                masses: vec![1.0; k],
                lengths: (0..k).map(|i| 0.5 + 0.25 * i as f64).collect(),
                angles: angles.clone(),
                g: 9.81,
            }).unwrap();
            prop_assert_eq!(sys.dof(), k);
            let (q0, _) = sys.initial_guess();
            prop_assert!(sys.check_rank(q0.as_slice(), 0.0).is_ok());
            // a different configuration on the manifold
            let mut q = vec![0.0; 3 * k];
            let mut tip = [0.0, 0.0];
            for i in 0..k {
                let l = 0.5 + 0.25 * i as f64;
                let (s, c) = other[i].sin_cos();
                q[3 * i] = tip[0] + 0.5 * l * c;
                q[3 * i + 1] = tip[1] + 0.5 * l * s;
                q[3 * i + 2] = other[i];
                tip = [tip[0] + l * c, tip[1] + l * s];
            }
            let mut phi = vec![0.0; 2 * k];
            sys.phi(&q, 0.0, &mut phi);
            prop_assert!(inf_norm(&phi) < 1e-14);
            prop_assert!(sys.check_rank(&q, 0.0).is_ok());
        }
    }
}

/// The element-local forms of `Phi_q` and `(Phi_q v)_q` scatter to the dense matrices.
#[test]
fn local_jacobians_scatter_to_the_dense_ones() {
    let sys = mbd_model::models::n_link_chain(5).unwrap();
    let (n, m) = (sys.n_coords(), sys.n_constraints());
    let q: Vec<f64> = (0..n)
        .map(|i| 0.3 * (i as f64).sin() + 0.1 * i as f64)
        .collect();
    let v: Vec<f64> = (0..n).map(|i| (0.7 * i as f64).cos()).collect();
    let mut pq = nalgebra::DMatrix::zeros(m, n);
    let mut pd = nalgebra::DMatrix::zeros(m, n);
    sys.phi_q_dot_jacobian(&q, &v, 0.0, &mut pq, &mut pd);
    let (mut g, mut dg, mut g2) = (vec![[0.0; 6]; m], vec![[0.0; 6]; m], vec![[0.0; 6]; m]);
    sys.phi_q_dot_local(&q, &v, &mut g, &mut dg);
    sys.phi_q_local(&q, &mut g2);
    let (mut sq, mut sd) = (
        nalgebra::DMatrix::zeros(m, n),
        nalgebra::DMatrix::zeros(m, n),
    );
    for jh in sys.joint_handles() {
        let (a, b) = sys.joint_bodies(jh);
        for r in sys.joint_rows(jh) {
            assert_eq!(g[r], g2[r]);
            for (body, off) in [(a, 0), (b, 3)] {
                if let Some(body) = body {
                    for l in 0..3 {
                        sq[(r, 3 * body + l)] += g[r][off + l];
                        sd[(r, 3 * body + l)] += dg[r][off + l];
                    }
                }
            }
        }
    }
    assert!((sq - pq).abs().max() < 1e-15);
    assert!((sd - pd).abs().max() < 1e-15);
}
