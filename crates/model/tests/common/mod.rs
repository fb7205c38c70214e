//! Shared helpers of the integration tests: seeded random numbers, finite differences, error
//! measures and a "kitchen sink" model using every joint and force kind.
#![allow(dead_code)]

use mbd_model::nalgebra::DMatrix;
use mbd_model::{Body, BodyHandle, BodyRef, Coordinate, Force, Joint, System, SystemBuilder};
use mbd_model::{ModelError, TimeFunction};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Seeded generator (all tests are deterministic).
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// Uniform in `[lo, hi)`.
pub fn uni(r: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    r.random_range(lo..hi)
}

/// `n` numbers uniform in `[-a, a)`.
pub fn rvec(r: &mut ChaCha8Rng, n: usize, a: f64) -> Vec<f64> {
    (0..n).map(|_| uni(r, -a, a)).collect()
}

/// A random local point in `[-a, a)^2`.
pub fn rpoint(r: &mut ChaCha8Rng, a: f64) -> [f64; 2] {
    [uni(r, -a, a), uni(r, -a, a)]
}

/// Random configuration: positions in `[-2, 2)`, angles in `[-pi, pi)`.
pub fn rconfig(r: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| {
            if i % 3 == 2 {
                uni(r, -std::f64::consts::PI, std::f64::consts::PI)
            } else {
                uni(r, -2.0, 2.0)
            }
        })
        .collect()
}

/// The error measure used throughout: `|a - b| / max(1, |b|)` (absolute for small entries,
/// relative for large ones), with `b` the analytic value.
pub fn rel(fd: f64, exact: f64) -> f64 {
    (fd - exact).abs() / exact.abs().max(1.0)
}

/// Worst [`rel`] over two equally sized slices.
pub fn max_rel(fd: &[f64], exact: &[f64]) -> f64 {
    assert_eq!(fd.len(), exact.len());
    fd.iter()
        .zip(exact)
        .map(|(a, b)| rel(*a, *b))
        .fold(0.0, f64::max)
}

/// Norm-relative error `max|fd - exact| / max(1, max|exact|)`: for quantities (potential
/// gradients and Hessians of stiff springs) whose entries span several orders of magnitude, where
/// the finite-difference round-off `eps |V| / h` scales with the largest entries, not each one.
pub fn norm_rel(fd: &[f64], exact: &[f64]) -> f64 {
    assert_eq!(fd.len(), exact.len());
    let d = fd
        .iter()
        .zip(exact)
        .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
    d / inf_norm(exact).max(1.0)
}

/// Worst entry-wise [`rel`] of two matrices.
pub fn max_rel_mat(fd: &DMatrix<f64>, exact: &DMatrix<f64>) -> f64 {
    assert_eq!(fd.shape(), exact.shape());
    max_rel(fd.as_slice(), exact.as_slice())
}

/// Max-norm.
pub fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |a, b| a.max(b.abs()))
}

/// Central-difference Jacobian of `f: R^n -> R^m` (step `h`).
pub fn fd_jacobian(f: impl Fn(&[f64], &mut [f64]), x: &[f64], m: usize, h: f64) -> DMatrix<f64> {
    let n = x.len();
    let mut jac = DMatrix::zeros(m, n);
    let (mut fp, mut fm) = (vec![0.0; m], vec![0.0; m]);
    let mut xp = x.to_vec();
    for j in 0..n {
        xp[j] = x[j] + h;
        f(&xp, &mut fp);
        xp[j] = x[j] - h;
        f(&xp, &mut fm);
        xp[j] = x[j];
        for i in 0..m {
            jac[(i, j)] = (fp[i] - fm[i]) / (2.0 * h);
        }
    }
    jac
}

/// Central-difference gradient of a scalar function.
pub fn fd_gradient(f: impl Fn(&[f64]) -> f64, x: &[f64], h: f64) -> Vec<f64> {
    fd_jacobian(|x, out| out[0] = f(x), x, 1, h)
        .as_slice()
        .to_vec()
}

/// Second derivative at `s = 0` of `p: R -> R^m` by the central second difference with
/// Richardson extrapolation, `(4 D(h/2) - D(h)) / 3` with `D(h) = (p(h) - 2 p(0) + p(-h)) / h^2`:
/// truncation error O(h^4) instead of O(h^2), so a step of 2e-3 keeps the round-off
/// (~ eps |p| / h^2 ~ 1e-9) and the truncation (~ h^4 ~ 1e-11) both far below the tolerances.
pub fn second_derivative(p: impl Fn(f64, &mut [f64]), m: usize, h: f64) -> Vec<f64> {
    let mut p0 = vec![0.0; m];
    p(0.0, &mut p0);
    let d = |h: f64| -> Vec<f64> {
        let (mut pp, mut pm) = (vec![0.0; m], vec![0.0; m]);
        p(h, &mut pp);
        p(-h, &mut pm);
        (0..m)
            .map(|i| (pp[i] - 2.0 * p0[i] + pm[i]) / (h * h))
            .collect()
    };
    let (d1, d2) = (d(h), d(0.5 * h));
    (0..m).map(|i| (4.0 * d2[i] - d1[i]) / 3.0).collect()
}

/// Point `s` of a body with coordinates `q_i = (x, y, theta)`, written independently of the crate.
pub fn body_point(qi: &[f64], s: [f64; 2]) -> [f64; 2] {
    let (sn, cs) = qi[2].sin_cos();
    [qi[0] + cs * s[0] - sn * s[1], qi[1] + sn * s[0] + cs * s[1]]
}

/// Global point of `r` at local `s` (ground points are global).
pub fn ref_point(q: &[f64], r: BodyRef, s: [f64; 2]) -> [f64; 2] {
    match r {
        BodyRef::Ground => s,
        BodyRef::Body(h) => {
            let i = h.index();
            body_point(&q[3 * i..3 * i + 3], s)
        }
    }
}

/// Random body with a random (generic) initial position.
pub fn rbody(r: &mut ChaCha8Rng, name: &str) -> Body {
    Body::new(name)
        .mass(uni(r, 0.5, 3.0))
        .inertia(uni(r, 0.05, 1.0))
        .position(uni(r, -2.0, 2.0), uni(r, -2.0, 2.0), uni(r, -3.0, 3.0))
        .velocity(uni(r, -1.0, 1.0), uni(r, -1.0, 1.0), uni(r, -1.0, 1.0))
}

/// A model with every joint kind and every force kind (m = 12, n = 15), full rank at its
/// initial guess, non-zero gravity, rheonomic and non-conservative.
pub fn kitchen_sink() -> Result<System, ModelError> {
    let mut r = rng(4242);
    let mut b = SystemBuilder::new();
    b.set_gravity([0.7, -9.81]);
    let h: Vec<BodyHandle> = (1..=5)
        .map(|i| b.add_body(rbody(&mut r, &format!("b{i}"))))
        .collect();
    b.add_joint(Joint::revolute(
        "rev",
        BodyRef::Ground,
        [0.3, -0.2],
        h[0],
        [0.5, 0.1],
    ));
    b.add_joint(Joint::prismatic(
        "pris",
        h[0],
        [0.2, 0.4],
        h[1],
        [-0.3, 0.2],
        [0.6, 0.8],
        0.3,
    ));
    b.add_joint(Joint::weld(
        "weld",
        h[1],
        [0.4, 0.1],
        h[2],
        [-0.2, 0.3],
        -0.7,
    ));
    b.add_joint(Joint::distance(
        "dist",
        h[2],
        [0.3, 0.3],
        h[3],
        [-0.4, 0.2],
        1.3,
    ));
    b.add_joint(Joint::absolute(
        "absx",
        h[3],
        [0.25, -0.5],
        Coordinate::X,
        0.4,
    ));
    b.add_joint(Joint::angle_driver(
        "drv_h",
        BodyRef::Ground,
        h[3],
        TimeFunction::Harmonic {
            offset: 0.2,
            amplitude: 0.5,
            omega: 2.0,
            phase: 0.3,
        },
    ));
    b.add_joint(Joint::absolute(
        "absy",
        h[4],
        [-0.1, 0.6],
        Coordinate::Y,
        -0.8,
    ));
    b.add_joint(Joint::angle_driver(
        "drv_p",
        h[3],
        h[4],
        TimeFunction::Polynomial {
            coeffs: vec![0.1, -0.4, 0.3, 0.05],
        },
    ));
    b.add_force(Force::spring_damper(
        "spring",
        h[0],
        [0.1, -0.3],
        h[4],
        [0.2, 0.2],
        50.0,
        2.0,
        0.8,
    ));
    b.add_force(Force::spring_damper(
        "anchor",
        BodyRef::Ground,
        [1.0, 1.0],
        h[2],
        [0.0, 0.4],
        20.0,
        0.0,
        0.5,
    ));
    b.add_force(Force::rotary_spring_damper(
        "rot", h[0], h[3], 7.0, 0.5, 0.2,
    ));
    b.add_force(Force::force(
        "push",
        h[2],
        [0.3, -0.1],
        TimeFunction::constant(1.5),
        TimeFunction::constant(-2.0),
    ));
    b.add_force(Force::force(
        "shake",
        h[4],
        [-0.2, 0.4],
        TimeFunction::Harmonic {
            offset: 0.0,
            amplitude: 3.0,
            omega: 5.0,
            phase: 0.0,
        },
        TimeFunction::linear(1.0, 0.5),
    ));
    b.add_force(Force::torque("motor", h[1], TimeFunction::constant(0.8)));
    b.add_force(Force::torque("pulse", h[3], TimeFunction::linear(0.0, 2.0)));
    b.build()
}

/// A one-link pendulum model file (TOML), valid as written; tests corrupt copies of it.
pub const PENDULUM_TOML: &str = r#"
gravity = [0.0, -9.81]

[[bodies]]
name = "link1"
mass = 1.0
inertia = 0.08333333333333333
position = [0.0, -0.5, -1.5707963267948966]

[[joints]]
type = "revolute"
name = "pin1"
body_a = "ground"
point_a = [0.0, 0.0]
body_b = "link1"
point_b = [-0.5, 0.0]
"#;

/// The handle of body `i` of `sys` (panics when out of range: a test set-up error).
pub fn body(sys: &System, i: usize) -> BodyHandle {
    sys.body_handles()
        .nth(i)
        .unwrap_or_else(|| panic!("the model has no body #{i}"))
}
