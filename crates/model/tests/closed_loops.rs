//! The closed-loop reference models (`n_four_bar`, `double_parallelogram`, `pantograph`) and
//! their exact motions: the elliptic-function solution against an independent integration of
//! the pendulum equation, the reduced inertia and first moment against the models' own kinetic
//! and potential energy, consistent states, ranks, counts and parameter errors.
//!

use mbd_model::models::{
    double_parallelogram, n_four_bar, pantograph, ClosedLoop, CrankMotion, Regime, LOOP_GRAVITY,
    MAX_LOOPS,
};
use mbd_model::nalgebra::DMatrix;
use mbd_model::{ModelError, System};
use std::f64::consts::{FRAC_PI_2, PI};

// ------------------------------------------------------------------ reference integration

/// `x += dx` with the rounding error carried in `c` (Kahan): the reference's round-off stays
/// far below its truncation error over 2e5 steps.
fn kahan(x: &mut f64, c: &mut f64, dx: f64) {
    let y = dx - *c;
    let t = *x + y;
    *c = (t - *x) - y;
    *x = t;
}

/// Classical RK4 on `theta'' = -a cos(theta)` at step `h` to `t = 10`, sampled every 0.5 s.
fn rk4_samples(a: f64, theta0: f64, w0: f64, h: f64) -> Vec<[f64; 2]> {
    let f = |th: f64| -a * th.cos();
    let per_sample = (0.5 / h).round() as usize;
    let (mut th, mut w, mut cth, mut cw) = (theta0, w0, 0.0, 0.0);
    let mut out = vec![[th, w]];
    for _ in 0..20 {
        for _ in 0..per_sample {
            let (k1x, k1v) = (w, f(th));
            let (k2x, k2v) = (w + 0.5 * h * k1v, f(th + 0.5 * h * k1x));
            let (k3x, k3v) = (w + 0.5 * h * k2v, f(th + 0.5 * h * k2x));
            let (k4x, k4v) = (w + h * k3v, f(th + h * k3x));
            kahan(
                &mut th,
                &mut cth,
                h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x),
            );
            kahan(
                &mut w,
                &mut cw,
                h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v),
            );
        }
        out.push([th, w]);
    }
    out
}

/// The worst difference (theta and theta', relative to `max(1, |theta'|)`) between the exact
/// motion and RK4 at h = 1e-4 and 5e-5 with Richardson extrapolation `(16 y_h/2 - y_h) / 15`,
/// and between the two RK4 runs (the size of what the extrapolation removes).
fn against_rk4(motion: &CrankMotion) -> (f64, f64) {
    let a = motion.gs() / motion.inertia();
    let [th0, w0] = motion.at(0.0);
    let coarse = rk4_samples(a, th0, w0, 1e-4);
    let fine = rk4_samples(a, th0, w0, 5e-5);
    let (mut exact_err, mut rk_gap) = (0.0f64, 0.0f64);
    for (j, (c, f)) in coarse.iter().zip(&fine).enumerate() {
        let exact = motion.at(0.5 * j as f64);
        let scale = exact[1].abs().max(1.0);
        for k in 0..2 {
            let rich = (16.0 * f[k] - c[k]) / 15.0;
            exact_err = exact_err.max((rich - exact[k]).abs() / scale);
            rk_gap = rk_gap.max((f[k] - c[k]).abs() / scale);
        }
    }
    (exact_err, rk_gap)
}

/// Free motions in both regimes (and with gravity pointing up), from the models' parameters
/// and directly.
fn motions() -> Vec<(&'static str, CrankMotion)> {
    vec![
        (
            "4-loop four-bar, libration",
            CrankMotion::n_four_bar(4, 1.0, 2.0, 0.5, 0.0).unwrap(),
        ),
        (
            "4-loop four-bar, rotation",
            CrankMotion::n_four_bar(4, 1.0, 2.0, 0.5, 6.0).unwrap(),
        ),
        (
            "double parallelogram, libration",
            CrankMotion::double_parallelogram(0.7, 1.5, -2.0, 3.0).unwrap(),
        ),
        (
            "pantograph, rotation backwards",
            CrankMotion::pantograph(1.2, 2.0, 0.4, 1.0, -9.0).unwrap(),
        ),
        (
            "near the separatrix, libration",
            // k^2 = 1 - 1e-6: from the bottom at just under the speed reaching the top
            CrankMotion::new(2.0, 3.0, -FRAC_PI_2, 2.0 * (1.5f64 * (1.0 - 1e-6)).sqrt()).unwrap(),
        ),
        (
            "gravity up, rotation",
            CrankMotion::new(1.5, -20.0, 0.3, 8.0).unwrap(),
        ),
    ]
}

#[test]
fn the_elliptic_solution_matches_an_extrapolated_rk4_integration() {
    let mut regimes = Vec::new();
    for (name, motion) in motions() {
        let (err, gap) = against_rk4(&motion);
        eprintln!("{name}: exact vs RK4 extrapolated {err:.2e} (RK4 h vs h/2: {gap:.2e})");
        regimes.push(motion.regime());
        // near the separatrix both solutions are sensitive to their rounding
        let tol = if name.contains("separatrix") {
            5e-11
        } else {
            5e-14
        };
        assert!(err < tol, "{name}: {err:e}");
    }
    assert!(regimes.contains(&Regime::Libration) && regimes.contains(&Regime::Rotation));
}

#[test]
fn energy_is_conserved_along_the_exact_solution() {
    for (name, motion) in motions() {
        let [th0, w0] = motion.at(0.0);
        let h0 = motion.energy(th0, w0);
        let scale = 0.5 * motion.inertia() * w0 * w0 + motion.gs().abs();
        let worst = (1..=1000)
            .map(|i| {
                let [th, w] = motion.at(0.01 * i as f64);
                (motion.energy(th, w) - h0).abs() / scale
            })
            .fold(0.0, f64::max);
        eprintln!("{name}: energy drift {worst:.2e}");
        assert!(worst < 1e-14, "{name}: {worst:e}");
    }
}

#[test]
fn the_exact_solution_satisfies_the_equation_of_motion() {
    // fourth-order central differences of step 1e-3: theta' from theta, theta'' from theta'
    let h = 1e-3;
    let diff = |motion: &CrankMotion, t: f64, k: usize| {
        let f = |dt: f64| motion.at(t + dt)[k];
        (8.0 * (f(h) - f(-h)) - (f(2.0 * h) - f(-2.0 * h))) / (12.0 * h)
    };
    for (name, motion) in motions() {
        let a = motion.gs() / motion.inertia();
        let (mut d1, mut d2) = (0.0f64, 0.0f64);
        for i in 0..200 {
            let t = 0.05 * i as f64 - 2.0;
            let [th, w] = motion.at(t);
            d1 = d1.max((diff(&motion, t, 0) - w).abs() / w.abs().max(1.0));
            d2 = d2.max((diff(&motion, t, 1) + a * th.cos()).abs() / a.abs().max(1.0));
        }
        eprintln!("{name}: theta' {d1:.2e}, theta'' {d2:.2e}");
        // the differences' truncation, h^4 theta^(5) / 30
        assert!(d1 < 1e-10 && d2 < 2e-9, "{name}: {d1:e} {d2:e}");
    }
}

#[test]
fn any_time_is_allowed_periods_and_restarts_agree() {
    for (name, motion) in motions() {
        let period = motion.period().unwrap();
        let turn = if motion.regime() == Regime::Rotation {
            2.0 * PI * motion.at(0.0)[1].signum()
        } else {
            0.0
        };
        let mut worst = 0.0f64;
        for t in [-7.3, 0.4, 123.4, 1e4] {
            let [th, w] = motion.at(t);
            let [thp, wp] = motion.at(t + period);
            worst = worst.max((thp - th - turn).abs() / th.abs().max(1.0));
            worst = worst.max((wp - w).abs() / w.abs().max(1.0));
            // a motion restarted from the state at t agrees with the original
            let again = CrankMotion::new(motion.inertia(), motion.gs(), th, w).unwrap();
            for dt in [-3.1, 0.0, 2.2] {
                let (x, y) = (again.at(dt), motion.at(t + dt));
                worst = worst.max((x[0] - y[0]).abs() / y[0].abs().max(1.0));
                worst = worst.max((x[1] - y[1]).abs() / y[1].abs().max(1.0));
            }
        }
        eprintln!("{name}: period {period:.6} s, worst {worst:.2e}");
        // the phase at t = 1e4 s carries the rounding of omega t
        assert!(worst < 1e-10, "{name}: {worst:e}");
    }
}

#[test]
fn driven_and_gravity_free_motions_are_uniform() {
    let d = CrankMotion::driven(0.5, 6.0).unwrap();
    assert_eq!(d.regime(), Regime::Uniform);
    assert_eq!(d.at(2.0), [0.5 + 12.0, 6.0]);
    let free = CrankMotion::new(2.0, 0.0, 0.5, -3.0).unwrap();
    assert_eq!(free.at(1.5), [0.5 - 4.5, -3.0]);
}

// ------------------------------------------------------------------ models

/// The mechanisms with the non-redundant four-bars first.
fn four_bars() -> Vec<ClosedLoop> {
    vec![
        ClosedLoop::n_four_bar(1, 1.0, 2.0).unwrap(),
        ClosedLoop::n_four_bar(4, 0.8, 1.3).unwrap(),
        // above the dense rank check's 200 equations
        ClosedLoop::n_four_bar(40, 1.1, 0.9).unwrap(),
    ]
}

fn redundant() -> Vec<ClosedLoop> {
    vec![
        ClosedLoop::double_parallelogram(0.7, 1.5).unwrap(),
        ClosedLoop::pantograph(1.2, 2.0, 0.4).unwrap(),
    ]
}

/// Branch angles, flat ones included.
const ANGLES: [f64; 7] = [0.5, 2.0, -0.3, -FRAC_PI_2, 3.5, 0.0, PI];

fn build(lp: &ClosedLoop, driven: bool) -> System {
    lp.system(0.5, 6.0, driven).unwrap()
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |a, b| a.max(b.abs()))
}

/// Phi = 0, Phi_q v = 0 on the branch (initial state and every angle), the tracked point.
fn check_branch(lp: &ClosedLoop) {
    let sys = build(lp, false);
    let (q0, v0) = sys.initial_guess();
    let (bq, bv) = lp.branch_state(0.5, 6.0);
    assert_eq!((q0.as_slice(), v0.as_slice()), (&bq[..], &bv[..]));
    let m = sys.n_constraints();
    let (mut phi, mut dphi) = (vec![0.0; m], vec![0.0; m]);
    let tip = sys.body_handle(&lp.tracked_body()).unwrap();
    let mut worst = [0.0f64; 3];
    // 4 ulps of the largest coordinate
    let mut tol = 0.0f64;
    for th in ANGLES {
        let (q, v) = lp.branch_state(th, -2.5);
        sys.phi(&q, 0.0, &mut phi);
        sys.phi_dot(&q, &v, 0.0, &mut dphi);
        let p = sys.point_position(tip, [0.5 * lp.crank(), 0.0], &q);
        let e = lp.tracked_point(th);
        tol = tol.max(4.0 * f64::EPSILON * max_abs(&q).max(1.0));
        worst[0] = worst[0].max(max_abs(&phi));
        worst[1] = worst[1].max(max_abs(&dphi));
        worst[2] = worst[2].max((p[0] - e[0]).abs().max((p[1] - e[1]).abs()));
    }
    eprintln!(
        "{lp:?}: |Phi| {:.1e}, |Phi_q v| {:.1e}, tip {:.1e}",
        worst[0], worst[1], worst[2]
    );
    assert!(worst.iter().all(|&w| w <= tol), "{worst:?} vs {tol:e}");
}

/// The model's kinetic and potential energy on the branch are `1/2 I theta'^2` and
/// `g S sin(theta)`.
fn check_energies(lp: &ClosedLoop) {
    let sys = build(lp, false);
    let (i, s) = (lp.reduced_inertia(), lp.first_moment());
    let mut worst = 0.0f64;
    for th in ANGLES {
        for w in [1.0, -3.7] {
            let (q, v) = lp.branch_state(th, w);
            let t = 0.5 * i * w * w;
            let vv = LOOP_GRAVITY * s * th.sin();
            worst = worst.max((sys.kinetic(&v) - t).abs() / t);
            worst = worst.max((sys.potential(&q) - vv).abs() / (LOOP_GRAVITY * s));
        }
    }
    eprintln!("{lp:?}: I = {i}, S = {s}, energies {worst:.1e}");
    // sums over up to 81 bodies
    assert!(worst < 3e-15, "{lp:?}: {worst:e}");
}

/// The rank of `Phi_q` on the branch: `m - redundant` away from the flat configurations,
/// `m - flat_loss` at them; the branch velocity spans the null space off the flat ones.
fn check_rank(lp: &ClosedLoop, flat_loss: usize) {
    let sys = build(lp, false);
    let (n, m) = (sys.n_coords(), sys.n_constraints());
    let mut jac = DMatrix::zeros(m, n);
    for th in ANGLES {
        let (q, _) = lp.branch_state(th, 1.0);
        sys.phi_q(&q, 0.0, &mut jac);
        let sv = jac.clone().singular_values();
        let big = sv.max();
        let rank = sv.iter().filter(|&&x| x > 1e-10 * big).count();
        let smallest_kept = sv
            .iter()
            .filter(|&&x| x > 1e-10 * big)
            .fold(big, |a, &b| a.min(b));
        let flat = th.sin().abs() < 1e-12;
        let lost = if flat { flat_loss } else { lp.redundant() };
        eprintln!("{lp:?} at {th}: rank {rank} of {m}, smallest kept {smallest_kept:.2e}");
        assert_eq!(rank, m - lost, "{lp:?} at theta = {th}");
        assert!(smallest_kept > 1e-3, "{smallest_kept:e}");
        assert_eq!(
            n - rank,
            if flat {
                1 + flat_loss - lp.redundant()
            } else {
                1
            }
        );
    }
}

fn check_counts(lp: &ClosedLoop) {
    for driven in [false, true] {
        let sys = build(lp, driven);
        assert_eq!(sys.n_coords(), 3 * lp.n_bodies());
        assert_eq!(sys.n_constraints(), lp.n_equations() + driven as usize);
        assert_eq!(sys.is_rheonomic(), driven);
        // the driven model follows CrankMotion::driven exactly
        if driven {
            let d = CrankMotion::driven(0.5, 6.0).unwrap();
            let mut phi = vec![0.0; sys.n_constraints()];
            let mut dphi = phi.clone();
            for t in [0.0, 0.3, 1.7] {
                let [th, w] = d.at(t);
                let (q, v) = lp.branch_state(th, w);
                sys.phi(&q, t, &mut phi);
                sys.phi_dot(&q, &v, t, &mut dphi);
                assert!(max_abs(&phi) < 1e-14 && max_abs(&dphi) < 1e-14, "{t}");
            }
        }
    }
}

#[test]
fn n_four_bar_branch_energies_rank_and_counts() {
    for (lp, loops) in four_bars().iter().zip([1, 4, 40]) {
        check_branch(lp);
        check_energies(lp);
        check_counts(lp);
        if loops <= 4 {
            check_rank(lp, loops);
        }
        let sys = build(lp, false);
        assert_eq!(sys.n_coords(), 3 * (2 * loops + 1));
        assert_eq!(sys.n_constraints(), 2 * (3 * loops + 1));
        assert_eq!((sys.n_redundant(), sys.dof()), (0, 1));
    }
    // the formulas of the documentation
    let lp = ClosedLoop::n_four_bar(3, 0.5, 1.0).unwrap();
    assert_eq!(lp.reduced_inertia(), 13.0 * 0.25 / 3.0);
    assert_eq!(lp.first_moment(), 10.0 * 0.5 / 2.0);
}

#[test]
fn a_long_row_of_loops_builds_through_the_sparse_rank_check() {
    let loops = 2000;
    let sys = n_four_bar(loops, 1.0, 0.5, 2.0, -1.0, false).unwrap();
    assert_eq!(sys.n_constraints(), 2 * (3 * loops + 1));
    assert_eq!((sys.n_redundant(), sys.dof()), (0, 1));
    let (q, v) = sys.initial_guess();
    let mut phi = vec![0.0; sys.n_constraints()];
    sys.phi(q.as_slice(), 0.0, &mut phi);
    assert!(max_abs(&phi) <= 4.0 * f64::EPSILON * max_abs(q.as_slice()));
    sys.phi_dot(q.as_slice(), v.as_slice(), 0.0, &mut phi);
    assert!(max_abs(&phi) <= 4.0 * f64::EPSILON);
}

#[test]
fn redundant_models_branch_energies_rank_and_counts() {
    for lp in redundant() {
        check_branch(&lp);
        check_energies(&lp);
        check_counts(&lp);
        check_rank(&lp, 2);
        let sys = build(&lp, false);
        assert_eq!((sys.n_coords(), sys.n_constraints()), (12, 12));
        // build() finds the one dependent equation: dof = n - rank
        assert_eq!((sys.n_redundant(), sys.dof()), (1, 1), "{lp:?}");
    }
    let dp = ClosedLoop::double_parallelogram(0.5, 1.0).unwrap();
    assert_eq!((dp.reduced_inertia(), dp.first_moment()), (0.5, 1.25));
    let pg = ClosedLoop::pantograph(2.0, 1.0, 0.5).unwrap();
    assert_eq!(
        (pg.reduced_inertia(), pg.first_moment()),
        ((5.0 / 3.0 + 0.25) * 4.0, 5.0)
    );
}

#[test]
fn the_model_dynamics_follow_the_exact_motion() {
    // a swing between -0.57 and -2.57 rad: no flat configuration on the way; DOPRI5 with
    // projection (the redundant models through the dropped dependent rows)
    use mbd_solve::{reference_trajectory, ButcherTableau, State};
    let th0 = -FRAC_PI_2 + 1.0;
    let mut loops = vec![ClosedLoop::n_four_bar(2, 1.0, 1.5).unwrap()];
    loops.extend(redundant());
    for lp in loops {
        let sys = lp.system(th0, 0.0, false).unwrap();
        let motion = lp.motion(th0, 0.0).unwrap();
        let s0 = State::consistent(&sys, 0.0).unwrap();
        let r = reference_trajectory(&sys, &s0, 0.05, 40, 64, ButcherTableau::dopri5()).unwrap();
        let mut worst = 0.0f64;
        for (k, (q, v)) in r.q.iter().zip(&r.v).enumerate() {
            let [th, w] = motion.at(r.t[k]);
            let (bq, bv) = lp.branch_state(th, w);
            for (a, b) in q.iter().chain(v).zip(bq.iter().chain(&bv)) {
                worst = worst.max((a - b).abs());
            }
        }
        eprintln!("{lp:?}: DOPRI5 h = 0.05/64 against the exact motion over 2 s: {worst:.2e}");
        assert!(worst < 3e-13, "{lp:?}: {worst:e}");
    }
}

// ------------------------------------------------------------------ parameter errors

fn expect_parameter<T: std::fmt::Debug>(r: Result<T, ModelError>, name: &str) {
    match r {
        Err(ModelError::InvalidParameter { parameter, .. }) => assert_eq!(parameter, name),
        other => panic!("expected InvalidParameter({name}), got {other:?}"),
    }
}

#[test]
fn bad_parameters_are_rejected_naming_them() {
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    expect_parameter(n_four_bar(0, 1.0, 2.0, 0.5, 1.0, false), "loops");
    expect_parameter(
        n_four_bar(MAX_LOOPS + 1, 1.0, 2.0, 0.5, 1.0, false),
        "loops",
    );
    for bad in [0.0, -1.0, nan, inf] {
        expect_parameter(n_four_bar(2, bad, 2.0, 0.5, 1.0, false), "crank");
        expect_parameter(n_four_bar(2, 1.0, bad, 0.5, 1.0, true), "ground");
        expect_parameter(double_parallelogram(bad, 2.0, 0.5, 1.0, false), "crank");
        expect_parameter(double_parallelogram(1.0, bad, 0.5, 1.0, false), "ground");
        expect_parameter(pantograph(bad, 2.0, 0.5, 0.5, 1.0, false), "crank");
        expect_parameter(pantograph(1.0, bad, 0.5, 0.5, 1.0, false), "ground");
        expect_parameter(CrankMotion::new(bad, 1.0, 0.5, 1.0), "inertia");
        expect_parameter(CrankMotion::n_four_bar(2, bad, 2.0, 0.5, 1.0), "crank");
        expect_parameter(CrankMotion::pantograph(1.0, bad, 0.5, 0.5, 1.0), "ground");
    }
    for bad in [0.0, 1.0, -0.2, 1.5, nan] {
        expect_parameter(pantograph(1.0, 2.0, bad, 0.5, 1.0, false), "ratio");
        expect_parameter(CrankMotion::pantograph(1.0, 2.0, bad, 0.5, 1.0), "ratio");
    }
    for bad in [nan, inf] {
        expect_parameter(n_four_bar(2, 1.0, 2.0, bad, 1.0, false), "angle");
        expect_parameter(double_parallelogram(1.0, 2.0, bad, 1.0, true), "angle");
        expect_parameter(pantograph(1.0, 2.0, 0.5, bad, 1.0, false), "angle");
    }
    // a flat start builds, as a singular initial configuration (not as redundancy)
    for flat in [0.0, PI] {
        // (redundant equations, degrees of freedom): the driven double parallelogram has none
        for (sys, expected) in [
            (n_four_bar(2, 1.0, 2.0, flat, 1.0, false).unwrap(), (0, 1)),
            (
                double_parallelogram(1.0, 2.0, flat, 1.0, true).unwrap(),
                (1, 0),
            ),
            (pantograph(1.0, 2.0, 0.5, flat, 1.0, false).unwrap(), (1, 1)),
        ] {
            assert!(!sys.singular_start_equations().is_empty(), "{flat}");
            assert_eq!((sys.n_redundant(), sys.dof()), expected, "{flat}");
        }
    }
    for bad in [nan, -inf] {
        expect_parameter(n_four_bar(2, 1.0, 2.0, 0.5, bad, false), "speed");
        expect_parameter(double_parallelogram(1.0, 2.0, 0.5, bad, false), "speed");
        expect_parameter(pantograph(1.0, 2.0, 0.5, 0.5, bad, true), "speed");
        expect_parameter(CrankMotion::n_four_bar(2, 1.0, 2.0, bad, 1.0), "angle");
        expect_parameter(
            CrankMotion::double_parallelogram(1.0, 2.0, 0.5, bad),
            "speed",
        );
        expect_parameter(CrankMotion::new(1.0, bad, 0.5, 1.0), "gs");
        expect_parameter(CrankMotion::new(1.0, 1.0, bad, 1.0), "theta0");
        expect_parameter(CrankMotion::new(1.0, 1.0, 0.5, bad), "theta_dot0");
        expect_parameter(CrankMotion::driven(bad, 1.0), "angle");
        expect_parameter(CrankMotion::driven(0.5, bad), "speed");
    }
    // the separatrix: from the bottom with exactly the speed that reaches the top (I = 2,
    // g S = 8: theta'^2 = 4 g S / I = 16)
    expect_parameter(CrankMotion::new(2.0, 8.0, -FRAC_PI_2, 4.0), "theta_dot0");
    // at rest at the double nearest pi/2 the crank is c = cos(FRAC_PI_2) = 6.1e-17 rad below
    // the top: a libration of period 4 K / omega with K = ln(4 / c) + O(c^2), omega = 2
    let top = CrankMotion::new(2.0, 8.0, FRAC_PI_2, 0.0).unwrap();
    assert_eq!(top.regime(), Regime::Libration);
    let period = top.period().unwrap();
    let expected = 2.0 * (4.0 / FRAC_PI_2.cos()).ln();
    assert!((period - expected).abs() < 1e-13, "{period} vs {expected}");
    assert!((top.at(1.0)[0] - FRAC_PI_2).abs() < 1e-15);
    // a model's motion names the model's parameter: from the bottom at the speed reaching
    // the top, theta'^2 = 4 g S / I with I = 2, S = 2.5
    let speed = (4.0 * LOOP_GRAVITY * 2.5 / 2.0).sqrt();
    let e = CrankMotion::double_parallelogram(1.0, 1.0, -FRAC_PI_2, speed).unwrap_err();
    assert!(e.to_string().contains("double parallelogram") && e.to_string().contains("speed"));
}
