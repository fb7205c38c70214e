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

/// Reference solution at t = 0.03 s: the IVP test set's `andrews` (PSIDE, rtol = atol = 1e-14),
/// confirmed to ~1e-9 by an independent RK4 integration of the benchmark's relative-angle
/// equations.
const REFERENCE: [f64; 7] = [
    15.81077119629904,
    -15.75637105984298,
    0.04082224013073101,
    -0.5347301163226948,
    0.5244099658805304,
    0.5347301163226948,
    1.048080741042263,
];

fn squeezer() -> System {
    models::andrews_squeezer().unwrap()
}

fn angles_at_end(sys: &System, integ: &mut dyn Integrator, h: f64, name: &str) -> [f64; 7] {
    let mut s = State::consistent(sys, 0.0).unwrap();
    let t0 = Instant::now();
    run(
        integ,
        sys,
        &mut s,
        RunConfig::new(T_END, h),
        &mut NoObserver,
    )
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

/// Projected RK4 at h = 1e-5 (3000 steps) lands on the reference to 1e-8 rad: its own error
/// there is ~1e-10 (the change from h = 2e-5 is ~1e-9) and the reference agrees with an
/// independent integration to ~1.5e-9, while a wrong geometry, sign or force would move the
/// angles by orders of magnitude more (beta turns through ~16 rad in 0.03 s).
#[test]
fn projected_rk4_matches_the_reference_at_0_03() {
    let sys = squeezer();
    let h = 1e-5;
    let a = angles_at_end(
        &sys,
        &mut Rk4::new(&sys, Rk4Options::projected()).unwrap(),
        h,
        "RK4+projection",
    );
    let err = max_diff(&a, &REFERENCE);
    eprintln!("RK4+projection, h = {h:e}: max |angle - reference| = {err:e}");
    for (k, (x, r)) in a.iter().zip(&REFERENCE).enumerate() {
        assert!((x - r).abs() < 1e-8, "angle {k}: {x} against {r}");
    }
}

/// Symplectic (2,2) and tangent RK4 agree with projected RK4 at t = 0.03 s: each is run at
/// h = 2e-5 and 1e-5, and its distance from projected RK4 (h = 5e-6) at the finer step is below
/// three times its own change between the two steps (a fourth-order method's error at the finer
/// step is about 1/15 of that change) plus three times projected RK4's own change from
/// h = 1e-5 to 5e-6.
#[test]
fn symplectic_and_tangent_agree_with_projected_rk4() {
    let sys = squeezer();
    let rk4 = |h| {
        angles_at_end(
            &sys,
            &mut Rk4::new(&sys, Rk4Options::projected()).unwrap(),
            h,
            "RK4+projection",
        )
    };
    let base = rk4(5e-6);
    let base_err = max_diff(&rk4(1e-5), &base);
    type Make = fn(&System) -> Box<dyn Integrator>;
    let solvers: [(&str, Make); 2] = [
        ("symplectic (2,2)", |s| {
            Box::new(Galerkin::new(s, SymplecticOptions::new(2)).unwrap())
        }),
        ("tangent RK4", |s| Box::new(TangentRk::rk4(s).unwrap())),
    ];
    for (name, make) in solvers {
        let a1 = angles_at_end(&sys, make(&sys).as_mut(), 2e-5, name);
        let a2 = angles_at_end(&sys, make(&sys).as_mut(), 1e-5, name);
        let change = max_diff(&a1, &a2);
        let diff = max_diff(&a2, &base);
        let err = max_diff(&a2, &REFERENCE);
        eprintln!(
            "{name}: change 2e-5 -> 1e-5 {change:e}, |a(1e-5) - RK4| = {diff:e} \
             (RK4's own change {base_err:e}), |a(1e-5) - reference| = {err:e}"
        );
        assert!(
            diff < 3.0 * change + 3.0 * base_err,
            "{name}: differs from projected RK4 by {diff:e}, change between steps {change:e}"
        );
        assert!(err < 1e-7, "{name}: {err:e} from the reference");
    }
}

/// `examples/models/andrews_squeezer.toml` builds the model in code: the same coordinates and
/// equations, initial guess (to 1e-15), masses, constraint values at a configuration off the
/// constraints (to 1e-13 m) and applied forces (the spring and the drive torque) at a moving
/// state (to 1e-12 relative).
#[test]
fn the_example_file_is_the_model() {
    let code = squeezer();
    let file = System::from_path(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/models/andrews_squeezer.toml"),
    )
    .unwrap();
    assert_eq!(file.n_coords(), code.n_coords());
    assert_eq!(file.n_constraints(), code.n_constraints());
    assert_eq!(file.dof(), code.dof());
    assert_eq!(file.coordinate_names(), code.coordinate_names());
    let (qf, vf) = file.initial_guess();
    let (qc, vc) = code.initial_guess();
    let (dq, dv) = ((&qf - &qc).amax(), (&vf - &vc).amax());
    assert!(dq < 1e-15 && dv < 1e-15, "q {dq:e}, v {dv:e}");
    assert!((file.mass_diag() - code.mass_diag()).amax() < 1e-18);
    let off = qc.map_with_location(|i, _, x| x + 0.01 * ((i as f64) * 0.7).sin());
    let v = qc.map_with_location(|i, _, _| ((i as f64) * 1.3).cos());
    let n = code.n_constraints();
    let (mut pf, mut pc) = (vec![0.0; n], vec![0.0; n]);
    file.phi(off.as_slice(), 0.0, &mut pf);
    code.phi(off.as_slice(), 0.0, &mut pc);
    let d = pf
        .iter()
        .zip(&pc)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(d < 1e-13, "Phi differs by {d:e}");
    let (mut ff, mut fc) = (vec![0.0; code.n_coords()], vec![0.0; code.n_coords()]);
    file.forces_into(off.as_slice(), v.as_slice(), 0.01, &mut ff);
    code.forces_into(off.as_slice(), v.as_slice(), 0.01, &mut fc);
    let scale = fc.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let d = ff
        .iter()
        .zip(&fc)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        scale > 1.0 && d <= 1e-12 * scale,
        "forces differ by {d:e} of {scale:e}"
    );
}

/// A step far too long for the squeezer (h = 0.05 s: the crank turns about 8 rad in it) fails
/// in the tangent chart as a Newton failure, whose advice is a smaller step, and not as a
/// "singular configuration": the mechanism is regular there, its lever arms (1 to 40 mm) are
/// just small numbers in metres, which the chart's rank report weighs by the bodies' radii of
/// gyration (`System::rank_weights`). Before the weights it reported "rank 19 of 20".
#[test]
fn a_too_long_step_is_a_newton_failure_not_a_singular_configuration() {
    use mbd::solve::SolveError;
    let sys = squeezer();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut integ = TangentRk::rk4(&sys).unwrap();
    let err = run(
        &mut integ,
        &sys,
        &mut s,
        RunConfig::new(0.1, 0.05),
        &mut NoObserver,
    )
    .unwrap_err();
    assert!(matches!(err, SolveError::Newton { .. }), "{err}");
}

/// Later in its run the squeezer's crank is wound up to thousands of radians and turns at
/// about 1e4 rad/s (4.1e3 rad and 1.05e4 rad/s at t = 0.82 s), so its `sin`/`cos` carry
/// `eps |theta|` ~ 1e-12 and the velocity constraints cannot be evaluated below about
/// `eps |theta| |omega| L` ~ 2e-11. Tangent RK4's chart maps must accept a stall there as
/// convergence: with a round-off floor of `eps (1 + |x|)` alone they failed ("Newton failed at
/// t = 0.8203: residual 2.07e-11 after 100 iterations"), and adaptive tangent DOPRI5 failed at
/// every tolerance. Starts from projected RK4's state at t = 0.8 (h = 2e-5).
#[test]
fn tangent_rk4_runs_with_the_crank_wound_up() {
    let sys = squeezer();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk4 = Rk4::new(&sys, Rk4Options::projected()).unwrap();
    run(
        &mut rk4,
        &sys,
        &mut s,
        RunConfig::new(0.8, 2e-5),
        &mut NoObserver,
    )
    .unwrap();
    assert!(
        s.q[2] > 3e3 && s.v[2] > 5e3,
        "{} rad, {} rad/s",
        s.q[2],
        s.v[2]
    );
    let mut integ = TangentRk::rk4(&sys).unwrap();
    run(
        &mut integ,
        &sys,
        &mut s,
        RunConfig::new(0.84, 1e-5),
        &mut NoObserver,
    )
    .unwrap();
}
