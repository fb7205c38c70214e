//! Applied forces, potential and kinetic energy, point kinematics.
//!
//! Central differences with `h = 1e-5`, tolerance 1e-7. Error measures:
//! * potential gradient and Hessian: norm-relative, `max|fd - exact| / max(1, max|exact|)`
//!   (`common::norm_rel`): with stiffnesses up to 100 and stretches of several metres, |V| reaches
//!   ~ 1e3 and the FD round-off eps |V| / h ~ 1e-8 is absolute, so an entry-wise measure would
//!   test round-off on the small entries rather than the formulas; relative to the largest entry
//!   (~ |V| / l) it is ~ 1e-10;
//! * everything else (loads, damping, point velocities): entry-wise
//!   `|fd - exact| / max(1, |exact|)` (`common::rel`).

mod common;

use common::*;
use mbd_model::nalgebra::DMatrix;
use mbd_model::{Body, BodyHandle, BodyRef, Force, System, SystemBuilder, TimeFunction};
use rand_chacha::ChaCha8Rng;

const H: f64 = 1e-5;
const TOL: f64 = 1e-7;
const CONFIGS: usize = 25;

/// Two random bodies with the given gravity and force elements (built by `forces(b1, b2)`).
fn two_bodies(
    r: &mut ChaCha8Rng,
    gravity: [f64; 2],
    forces: impl FnOnce(BodyHandle, BodyHandle, &mut ChaCha8Rng) -> Vec<Force>,
) -> System {
    let mut b = SystemBuilder::new();
    b.set_gravity(gravity);
    let b1 = b.add_body(rbody(r, "b1"));
    let b2 = b.add_body(rbody(r, "b2"));
    for f in forces(b1, b2, r) {
        b.add_force(f);
    }
    b.build().unwrap()
}

/// Worst (gradient, Hessian) FD errors of the potential at random configurations; also checks
/// `forces_into = -grad V` when everything is conservative.
fn check_potential(sys: &System, r: &mut ChaCha8Rng) -> (f64, f64) {
    let n = sys.n_coords();
    let (mut wg, mut wh) = (0.0f64, 0.0f64);
    let mut done = 0;
    while done < CONFIGS {
        let q = rconfig(r, n);
        if !springs_stretched(sys, &q) {
            continue;
        }
        done += 1;
        let v = rvec(r, n, 2.0);
        let t = uni(r, 0.0, 3.0);
        let mut g = vec![0.0; n];
        sys.potential_gradient(&q, &mut g);
        let fd = fd_gradient(|x| sys.potential(x), &q, H);
        wg = wg.max(norm_rel(&fd, &g));
        let mut hess = DMatrix::zeros(n, n);
        sys.potential_hessian(&q, &mut hess);
        let fdh = fd_jacobian(|x, out| sys.potential_gradient(x, out), &q, n, H);
        wh = wh.max(norm_rel(fdh.as_slice(), hess.as_slice()));
        assert_eq!(hess, hess.transpose());
        if sys.is_conservative() {
            let mut f = vec![0.0; n];
            sys.forces_into(&q, &v, t, &mut f);
            for i in 0..n {
                assert_eq!(f[i], -g[i]);
            }
            sys.nonconservative_forces(&q, &v, t, &mut f);
            assert!(f.iter().all(|&x| x == 0.0));
        }
    }
    (wg, wh)
}

/// Whether every point-to-point spring is at least 0.3 m long at `q`. A spring with a positive
/// rest length is singular at zero length (its derivatives grow like `k l0 / l^k`), so the FD
/// truncation error `h^2 V''' / 6` would measure the closeness to the singularity, not the
/// formulas; such random configurations are skipped.
fn springs_stretched(sys: &System, q: &[f64]) -> bool {
    sys.forces().iter().all(|f| match f.kind {
        mbd_model::ForceKind::SpringDamper(mbd_model::forces::SpringDamper {
            a,
            pa,
            b,
            pb,
            ..
        }) => length(q, a, pa, b, pb) >= 0.3,
        _ => true,
    })
}

fn report(name: &str, (wg, wh): (f64, f64)) {
    eprintln!("{name}: gradient {wg:.1e}, Hessian {wh:.1e}");
    assert!(wg < TOL, "{name}: gradient vs FD {wg:e}");
    assert!(wh < TOL, "{name}: Hessian vs FD {wh:e}");
}

#[test]
fn spring_potential_matches_finite_differences() {
    let mut r = rng(1);
    let mut worst = (0.0f64, 0.0f64);
    for _ in 0..4 {
        let sys = two_bodies(&mut r, [0.0, 0.0], |b1, b2, r| {
            vec![
                Force::spring_damper(
                    "s",
                    b1,
                    rpoint(r, 1.0),
                    b2,
                    rpoint(r, 1.0),
                    uni(r, 1.0, 100.0),
                    0.0,
                    uni(r, 0.0, 2.0),
                ),
                Force::spring_damper(
                    "anchor",
                    BodyRef::Ground,
                    rpoint(r, 2.0),
                    b1,
                    rpoint(r, 1.0),
                    uni(r, 1.0, 100.0),
                    0.0,
                    uni(r, 0.0, 2.0),
                ),
            ]
        });
        assert!(sys.is_conservative());
        let w = check_potential(&sys, &mut r);
        worst = (worst.0.max(w.0), worst.1.max(w.1));
    }
    report("point-to-point springs", worst);
}

#[test]
fn spring_potential_is_half_k_stretch_squared() {
    // independent closed form at one configuration
    let mut b = SystemBuilder::new();
    let a = b.add_body(Body::new("a").position(0.3, 0.1, 0.4));
    let c = b.add_body(Body::new("c").position(2.0, -1.0, -0.6));
    let (pa, pc) = ([0.2, -0.3], [-0.1, 0.5]);
    b.add_force(Force::spring_damper("s", a, pa, c, pc, 40.0, 0.0, 0.7));
    let sys = b.build().unwrap();
    let (q, _) = sys.initial_guess();
    let (x, y) = (
        body_point(&q.as_slice()[0..3], pa),
        body_point(&q.as_slice()[3..6], pc),
    );
    let l = ((y[0] - x[0]).powi(2) + (y[1] - x[1]).powi(2)).sqrt();
    let expect = 0.5 * 40.0 * (l - 0.7) * (l - 0.7);
    assert!((sys.potential(q.as_slice()) - expect).abs() < 1e-12 * expect);
}

#[test]
fn rotary_spring_potential_matches_finite_differences() {
    let mut r = rng(2);
    let mut worst = (0.0f64, 0.0f64);
    for _ in 0..4 {
        let sys = two_bodies(&mut r, [0.0, 0.0], |b1, b2, r| {
            vec![
                Force::rotary_spring_damper("r", b1, b2, uni(r, 1.0, 50.0), 0.0, uni(r, -1.0, 1.0)),
                Force::rotary_spring_damper(
                    "rg",
                    BodyRef::Ground,
                    b2,
                    uni(r, 1.0, 50.0),
                    0.0,
                    uni(r, -1.0, 1.0),
                ),
            ]
        });
        let w = check_potential(&sys, &mut r);
        worst = (worst.0.max(w.0), worst.1.max(w.1));
        // closed form: V = k/2 (theta_b - theta_a - a0)^2
        let q = rconfig(&mut r, 6);
        let f = sys.forces();
        let mut expect = 0.0;
        for (fi, (a, b)) in [(q[2], q[5]), (0.0, q[5])].into_iter().enumerate() {
            if let mbd_model::ForceKind::RotarySpringDamper(
                mbd_model::forces::RotarySpringDamper {
                    stiffness,
                    rest_angle,
                    ..
                },
            ) = f[fi].kind
            {
                expect += 0.5 * stiffness * (b - a - rest_angle).powi(2);
            } else {
                unreachable!()
            }
        }
        assert!(rel(sys.potential(&q), expect) < 1e-13);
    }
    report("rotary springs", worst);
}

#[test]
fn gravity_potential_and_gradient() {
    let mut r = rng(3);
    for gravity in [[0.0, -9.81], [1.3, 2.7], [0.0, 0.0], [-4.0, 0.0]] {
        let sys = two_bodies(&mut r, gravity, |_, _, _| vec![]);
        report(
            &format!("gravity {gravity:?}"),
            check_potential(&sys, &mut r),
        );
        let q = rconfig(&mut r, 6);
        let mut g = vec![0.0; 6];
        sys.potential_gradient(&q, &mut g);
        let mut expect_v = 0.0;
        for (i, body) in sys.bodies().iter().enumerate() {
            expect_v -= body.mass * (gravity[0] * q[3 * i] + gravity[1] * q[3 * i + 1]);
            assert_eq!(g[3 * i], -body.mass * gravity[0]);
            assert_eq!(g[3 * i + 1], -body.mass * gravity[1]);
            assert_eq!(g[3 * i + 2], 0.0);
        }
        assert!(rel(sys.potential(&q), expect_v) < 1e-14);
        let mut h = DMatrix::zeros(6, 6);
        sys.potential_hessian(&q, &mut h);
        assert_eq!(h.amax(), 0.0);
        if gravity == [0.0, 0.0] {
            assert_eq!(sys.potential(&q), 0.0);
        }
    }
}

/// The Jacobian `d r_P / d q` (2 x n) of a body point, by FD of `point_position`.
fn point_jacobian(sys: &System, body: BodyHandle, s: [f64; 2], q: &[f64]) -> DMatrix<f64> {
    fd_jacobian(
        |x, out| {
            let p = sys.point_position(body, s, x);
            out.copy_from_slice(p.as_slice());
        },
        q,
        2,
        H,
    )
}

#[test]
fn constant_loads_are_conservative() {
    // A constant force F at an offset point: V = -F . r_P, so -grad V = J_P^T F.
    // A constant torque tau: V = -tau theta, so -grad V = tau e_theta.
    let mut r = rng(4);
    let mut worst = (0.0f64, 0.0f64);
    for _ in 0..4 {
        let (fx, fy, tau) = (
            uni(&mut r, -5.0, 5.0),
            uni(&mut r, -5.0, 5.0),
            uni(&mut r, -5.0, 5.0),
        );
        let s = rpoint(&mut r, 1.0);
        let sys = two_bodies(&mut r, [0.0, 0.0], |b1, b2, _| {
            vec![
                Force::force(
                    "f",
                    b2,
                    s,
                    TimeFunction::constant(fx),
                    TimeFunction::Polynomial { coeffs: vec![fy] },
                ),
                Force::torque("tq", b1, TimeFunction::constant(tau)),
            ]
        });
        assert!(sys.is_conservative());
        let w = check_potential(&sys, &mut r);
        worst = (worst.0.max(w.0), worst.1.max(w.1));
        for _ in 0..5 {
            let q = rconfig(&mut r, 6);
            let mut g = vec![0.0; 6];
            sys.potential_gradient(&q, &mut g);
            let jp = point_jacobian(&sys, body(&sys, 1), s, &q);
            let qf = jp.tr_mul(&mbd_model::nalgebra::DVector::from_column_slice(&[fx, fy]));
            let mut expect = qf.as_slice().to_vec();
            expect[2] += tau;
            let neg: Vec<f64> = g.iter().map(|x| -x).collect();
            assert!(max_rel(&neg, &expect) < TOL);
        }
    }
    report("constant force and torque", worst);
}

/// Length of the spring between `(a, pa)` and `(b, pb)`, written independently.
fn length(q: &[f64], a: BodyRef, pa: [f64; 2], b: BodyRef, pb: [f64; 2]) -> f64 {
    let (x, y) = (ref_point(q, a, pa), ref_point(q, b, pb));
    ((y[0] - x[0]).powi(2) + (y[1] - x[1]).powi(2)).sqrt()
}

#[test]
fn spring_damping_force_is_minus_c_ldot_grad_l() {
    let mut r = rng(5);
    let mut worst = 0.0f64;
    for case in 0..CONFIGS {
        let (pa, pb) = (rpoint(&mut r, 1.0), rpoint(&mut r, 1.0));
        let (k, c) = (uni(&mut r, 0.0, 30.0), uni(&mut r, 0.1, 5.0));
        let ground = case % 2 == 1;
        let sys = two_bodies(&mut r, [0.3, -9.81], |b1, b2, _| {
            let a = if ground { BodyRef::Ground } else { b1.into() };
            vec![Force::spring_damper("sd", a, pa, b2, pb, k, c, 0.5)]
        });
        assert!(!sys.is_conservative());
        let a = if ground {
            BodyRef::Ground
        } else {
            BodyRef::Body(body(&sys, 0))
        };
        let b = BodyRef::Body(body(&sys, 1));
        // away from the l = 0 singularity of grad l (see `springs_stretched`)
        let q = loop {
            let q = rconfig(&mut r, 6);
            if length(&q, a, pa, b, pb) >= 0.3 {
                break q;
            }
        };
        let v = rvec(&mut r, 6, 2.0);
        let t = uni(&mut r, 0.0, 1.0);
        let grad_l = fd_gradient(|x| length(x, a, pa, b, pb), &q, H);
        let ldot = fd_jacobian(
            |s, out| {
                let qs: Vec<f64> = q.iter().zip(&v).map(|(q, v)| q + s[0] * v).collect();
                out[0] = length(&qs, a, pa, b, pb);
            },
            &[0.0],
            1,
            H,
        )[(0, 0)];
        let expect: Vec<f64> = grad_l.iter().map(|g| -c * ldot * g).collect();
        let mut qnc = vec![0.0; 6];
        sys.nonconservative_forces(&q, &v, t, &mut qnc);
        worst = worst.max(max_rel(&qnc, &expect));
        // forces_into = -grad V + Q_nc
        let mut g = vec![0.0; 6];
        sys.potential_gradient(&q, &mut g);
        let mut f = vec![0.0; 6];
        sys.forces_into(&q, &v, t, &mut f);
        for i in 0..6 {
            assert!(rel(f[i], -g[i] + qnc[i]) < 1e-14);
        }
        // the damping force does negative work: v . Q_nc = -c ldot^2
        let p: f64 = v.iter().zip(&qnc).map(|(a, b)| a * b).sum();
        assert!(p <= 1e-12 && rel(p, -c * ldot * ldot) < TOL);
    }
    eprintln!("spring damper: {worst:.1e}");
    assert!(worst < TOL, "spring damping vs FD {worst:e}");
}

#[test]
fn rotary_damper_torque() {
    let mut r = rng(6);
    for case in 0..CONFIGS {
        let c = uni(&mut r, 0.1, 5.0);
        let ground = case % 2 == 1;
        let sys = two_bodies(&mut r, [0.0, 0.0], |b1, b2, _| {
            let a = if ground { BodyRef::Ground } else { b1.into() };
            vec![Force::rotary_spring_damper("rd", a, b2, 3.0, c, 0.1)]
        });
        let q = rconfig(&mut r, 6);
        let v = rvec(&mut r, 6, 2.0);
        let mut qnc = vec![0.0; 6];
        sys.nonconservative_forces(&q, &v, 0.0, &mut qnc);
        let wa = if ground { 0.0 } else { v[2] };
        let tau = -c * (v[5] - wa);
        let expect = [0.0, 0.0, if ground { 0.0 } else { -tau }, 0.0, 0.0, tau];
        assert!(max_rel(&qnc, &expect) < 1e-15, "{qnc:?} vs {expect:?}");
    }
}

#[test]
fn time_dependent_loads_are_generalized_by_the_point_jacobian() {
    // Q = J_P^T F(t) for a force at an offset point, Q_theta = tau(t) for a torque.
    let mut r = rng(7);
    let fx = TimeFunction::Harmonic {
        offset: 0.5,
        amplitude: 2.0,
        omega: 3.0,
        phase: 0.1,
    };
    let fy = TimeFunction::Polynomial {
        coeffs: vec![1.0, -2.0, 0.5],
    };
    let tau = TimeFunction::linear(0.3, -1.1);
    let mut worst = 0.0f64;
    for _ in 0..CONFIGS {
        let s = rpoint(&mut r, 1.0);
        let sys = two_bodies(&mut r, [0.0, -9.81], |b1, b2, _| {
            vec![
                Force::force("f", b1, s, fx.clone(), fy.clone()),
                Force::force(
                    "half",
                    b2,
                    s,
                    TimeFunction::constant(1.0),
                    TimeFunction::linear(0.0, 1.0),
                ),
                Force::torque("tq", b2, tau.clone()),
            ]
        });
        assert!(!sys.is_conservative());
        let q = rconfig(&mut r, 6);
        let v = rvec(&mut r, 6, 2.0);
        let t = uni(&mut r, 0.0, 3.0);
        let mut qnc = vec![0.0; 6];
        sys.nonconservative_forces(&q, &v, t, &mut qnc);
        let j1 = point_jacobian(&sys, body(&sys, 0), s, &q);
        let j2 = point_jacobian(&sys, body(&sys, 1), s, &q);
        let f1 = mbd_model::nalgebra::DVector::from_column_slice(&[fx.eval(t)[0], fy.eval(t)[0]]);
        // a force with one time-dependent component is non-conservative as a whole
        let f2 = mbd_model::nalgebra::DVector::from_column_slice(&[1.0, t]);
        let mut expect = j1.tr_mul(&f1) + j2.tr_mul(&f2);
        expect[5] += tau.eval(t)[0];
        worst = worst.max(max_rel(&qnc, expect.as_slice()));
        // the potential has only gravity
        let mut g = vec![0.0; 6];
        sys.potential_gradient(&q, &mut g);
        let mb: Vec<f64> = sys.bodies().iter().map(|b| b.mass).collect();
        assert_eq!(g, [0.0, 9.81 * mb[0], 0.0, 0.0, 9.81 * mb[1], 0.0]);
        let mut f = vec![0.0; 6];
        sys.forces_into(&q, &v, t, &mut f);
        for i in 0..6 {
            assert!(rel(f[i], -g[i] + qnc[i]) < 1e-14);
        }
    }
    eprintln!("time-dependent loads: {worst:.1e}");
    assert!(worst < TOL, "time-dependent loads vs FD {worst:e}");
}

#[test]
fn all_forces_together() {
    // forces_into = -grad V + Q_nc on the kitchen-sink model, and V, grad V, d2V vs FD.
    let sys = kitchen_sink().unwrap();
    assert!(!sys.is_conservative());
    let mut r = rng(8);
    report("kitchen sink potential", check_potential(&sys, &mut r));
    let n = sys.n_coords();
    for _ in 0..10 {
        let q = rconfig(&mut r, n);
        let v = rvec(&mut r, n, 2.0);
        let t = uni(&mut r, 0.0, 3.0);
        let (mut g, mut qnc, mut f) = (vec![0.0; n], vec![1.0; n], vec![2.0; n]);
        sys.potential_gradient(&q, &mut g);
        sys.nonconservative_forces(&q, &v, t, &mut qnc);
        sys.forces_into(&q, &v, t, &mut f);
        for i in 0..n {
            assert!(rel(f[i], qnc[i] - g[i]) < 1e-14);
        }
        // potential_hessian overwrites, add_potential_hessian accumulates with a scale
        let mut h = DMatrix::from_element(n, n, 7.0);
        sys.potential_hessian(&q, &mut h);
        let mut acc = h.clone();
        sys.add_potential_hessian(&q, -1.0, &mut acc);
        assert!(acc.amax() <= 1e-13 * h.amax());
    }
}

#[test]
fn zero_length_spring_at_coincident_points_is_smooth() {
    // rest length 0, attachment points coincident: V = k/2 |d|^2 is smooth, the force is zero.
    let mut b = SystemBuilder::new();
    let a = b.add_body(Body::new("a").position(1.0, 0.0, 0.0));
    b.add_force(Force::spring_damper(
        "bushing",
        BodyRef::Ground,
        [1.5, 0.0],
        a,
        [0.5, 0.0],
        100.0,
        3.0,
        0.0,
    ));
    let sys = b.build().unwrap();
    let q = [1.0, 0.0, 0.0];
    let v = [0.2, -0.1, 0.3];
    let mut g = vec![0.0; 3];
    sys.potential_gradient(&q, &mut g);
    assert_eq!(sys.potential(&q), 0.0);
    assert!(g.iter().all(|x| x.abs() < 1e-14), "{g:?}");
    let mut h = DMatrix::zeros(3, 3);
    sys.potential_hessian(&q, &mut h);
    assert!(h.iter().all(|x| x.is_finite()), "{h}");
    // V = k/2 |d|^2 with d = r + A s - p: Hessian vs FD
    let fdh = fd_jacobian(|x, out| sys.potential_gradient(x, out), &q, 3, H);
    assert!(max_rel_mat(&fdh, &h) < TOL, "{h} vs {fdh}");
    let mut f = vec![0.0; 3];
    sys.forces_into(&q, &v, 0.0, &mut f);
    assert!(f.iter().all(|x| x.is_finite()), "{f:?}");
    // and away from the singular point the gradient is still right
    let q2 = [1.1, 0.2, 0.3];
    sys.potential_gradient(&q2, &mut g);
    let fd = fd_gradient(|x| sys.potential(x), &q2, H);
    assert!(max_rel(&fd, &g) < TOL);
}

#[test]
fn kinetic_energy_and_point_kinematics() {
    let sys = kitchen_sink().unwrap();
    let n = sys.n_coords();
    let mut r = rng(9);
    let mut worst = 0.0f64;
    for _ in 0..CONFIGS {
        let q = rconfig(&mut r, n);
        let v = rvec(&mut r, n, 2.0);
        let mut t = 0.0;
        for (i, b) in sys.bodies().iter().enumerate() {
            t += 0.5 * b.mass * (v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1]);
            t += 0.5 * b.inertia * v[3 * i + 2] * v[3 * i + 2];
        }
        assert!(rel(sys.kinetic(&v), t) < 1e-14);
        assert!(rel(sys.energy(&q, &v), t + sys.potential(&q)) < 1e-14);
        for i in 0..sys.bodies().len() {
            let s = rpoint(&mut r, 1.0);
            let h = body(&sys, i);
            let p = sys.point_position(h, s, &q);
            let e = body_point(&q[3 * i..3 * i + 3], s);
            assert!((p[0] - e[0]).abs() < 1e-14 && (p[1] - e[1]).abs() < 1e-14);
            // velocity = d/ds position(q + s v)
            let fd = fd_jacobian(
                |x, out| {
                    let qs: Vec<f64> = q.iter().zip(&v).map(|(q, v)| q + x[0] * v).collect();
                    out.copy_from_slice(sys.point_position(h, s, &qs).as_slice());
                },
                &[0.0],
                2,
                H,
            );
            let pv = sys.point_velocity(h, s, &q, &v);
            worst = worst.max(max_rel(fd.as_slice(), pv.as_slice()));
        }
    }
    eprintln!("point velocity: {worst:.1e}");
    assert!(worst < TOL);
    // mass matrix
    let m = sys.mass_matrix();
    for (i, b) in sys.bodies().iter().enumerate() {
        assert_eq!(m[(3 * i, 3 * i)], b.mass);
        assert_eq!(m[(3 * i + 1, 3 * i + 1)], b.mass);
        assert_eq!(m[(3 * i + 2, 3 * i + 2)], b.inertia);
        assert_eq!(sys.inv_mass_diag()[3 * i + 2], 1.0 / b.inertia);
    }
    assert_eq!(m.iter().filter(|&&x| x != 0.0).count(), n);
}
