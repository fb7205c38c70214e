//! Any model of mbd-model: closed loops, springs without gravity, dampers (discrete
//! Lagrange-d'Alembert), a rheonomic driver.
mod common;
use mbd_model::{models, Body, BodyRef, Force, Joint, SystemBuilder, TimeFunction};
use mbd_solve::{reference_trajectory, ButcherTableau, Integrator, State};
use mbd_symplectic::{Galerkin, JacobianReuse, SymplecticOptions};

fn constraint_and_energy(
    sys: &mbd_model::System,
    s: usize,
    gamma: f64,
    h: f64,
    n: usize,
) -> (f64, f64, f64) {
    let s0 = State::consistent(sys, 0.0).unwrap();
    let mut g = Galerkin::new(sys, SymplecticOptions::new(s).with_gamma(gamma)).unwrap();
    let mut st = s0.clone();
    let h0 = sys.energy(st.q.as_slice(), st.v.as_slice());
    let mut r = vec![0.0; sys.n_constraints()];
    let (mut cp, mut cv, mut de) = (0.0f64, 0.0f64, 0.0f64);
    for k in 1..=n {
        g.step(sys, &mut st, h).unwrap();
        st.t = k as f64 * h;
        sys.phi(st.q.as_slice(), st.t, &mut r);
        cp = r.iter().fold(cp, |a, &b| a.max(b.abs()));
        sys.phi_dot(st.q.as_slice(), st.v.as_slice(), st.t, &mut r);
        cv = r.iter().fold(cv, |a, &b| a.max(b.abs()));
        de = de.max((sys.energy(st.q.as_slice(), st.v.as_slice()) - h0).abs() / h0.abs().max(1.0));
    }
    (cp, cv, de)
}

#[test]
fn closed_loops_keep_constraints_and_bounded_energy() {
    for (name, sys) in [
        ("slider-crank", models::slider_crank().unwrap()),
        ("four-bar", models::four_bar().unwrap()),
    ] {
        for (s, gamma) in [(1, 0.0), (2, 0.0), (2, 1.0), (3, 0.0)] {
            let (cp, cv, de) = constraint_and_energy(&sys, s, gamma, 0.002, 2000);
            println!(
                "{name} s={s} gamma={gamma}: |Phi| {cp:.2e} |Phi_dot| {cv:.2e} rel |dH| {de:.2e}"
            );
            assert!(cp <= 1e-12 && cv <= 1e-11, "{name} s={s}: {cp} {cv}");
            assert!(
                de < if s == 1 { 1e-3 } else { 1e-5 },
                "{name} s={s}: energy {de}"
            );
        }
    }
}

/// Two bodies and springs, no gravity, no constraints (m = 0), and the same with one pin.
fn spring_model(pinned: bool) -> mbd_model::System {
    let mut b = SystemBuilder::new();
    let a = b.add_body(
        Body::new("a")
            .mass(1.0)
            .inertia(0.1)
            .position(1.2, 0.1, 0.2)
            .velocity(0.0, 0.5, 0.3),
    );
    let c = b.add_body(
        Body::new("c")
            .mass(2.0)
            .inertia(0.2)
            .position(2.5, -0.3, 0.0)
            .velocity(0.1, 0.0, -0.2),
    );
    b.add_force(Force::spring_damper(
        "s1",
        BodyRef::Ground,
        [0.0, 0.0],
        a,
        [-0.2, 0.0],
        50.0,
        0.0,
        1.0,
    ));
    b.add_force(Force::spring_damper(
        "s2",
        a,
        [0.2, 0.0],
        c,
        [-0.3, 0.0],
        80.0,
        0.0,
        0.8,
    ));
    b.add_force(Force::rotary_spring_damper("r", a, c, 5.0, 0.0, 0.0));
    if pinned {
        b.add_joint(Joint::distance(
            "rod",
            BodyRef::Ground,
            [0.0, 0.0],
            c,
            [0.0, 0.0],
            2.5f64.hypot(0.3),
        ));
    }
    b.build().unwrap()
}

#[test]
fn springs_without_gravity_converge_and_conserve_energy() {
    for pinned in [false, true] {
        let sys = spring_model(pinned);
        assert!(sys.is_conservative());
        let (cp, cv, de) = constraint_and_energy(&sys, 2, 0.0, 0.005, 2000);
        println!("springs pinned={pinned}: {cp:.2e} {cv:.2e} {de:.2e}");
        assert!(cp <= 1e-12 && cv <= 1e-12 && de < 1e-6);
        // order 4 against an independent reference
        let s0 = State::consistent(&sys, 0.0).unwrap();
        let r = reference_trajectory(&sys, &s0, 1.0, 1, 20000, ButcherTableau::dopri5()).unwrap();
        let mut hs = Vec::new();
        let mut es = Vec::new();
        for n in [20usize, 40, 80] {
            let (st, _) = common::run(&sys, &s0, common::tight(2), 1.0 / n as f64, n);
            hs.push(1.0 / n as f64);
            es.push(common::max_abs_diff(st.q.as_slice(), &r.q[1]));
        }
        let p = common::slope(&hs, &es);
        assert!((p - 4.0).abs() < 0.3, "spring model order {p} ({es:?})");
        // gamma = 1 runs too (W_s from the spring stiffness)
        let (cp, _, de) = constraint_and_energy(&sys, 2, 1.0, 0.005, 400);
        assert!(cp <= 1e-12 && de < 1e-5);
    }
}

#[test]
fn dampers_by_discrete_lagrange_dalembert() {
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let rod = b.add_body(Body::new("rod").rod(1.0, 1.0).position(0.5, 0.0, 0.0));
    b.add_joint(Joint::revolute(
        "pin",
        BodyRef::Ground,
        [0.0, 0.0],
        rod,
        [-0.5, 0.0],
    ));
    b.add_force(Force::rotary_spring_damper(
        "d",
        BodyRef::Ground,
        rod,
        0.0,
        0.3,
        0.0,
    ));
    b.add_force(Force::torque("drive", rod, TimeFunction::linear(0.0, 0.5)));
    let sys = b.build().unwrap();
    assert!(!sys.is_conservative());
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let r = reference_trajectory(&sys, &s0, 1.0, 1, 20000, ButcherTableau::dopri5()).unwrap();
    for s in [1usize, 2] {
        let mut hs = Vec::new();
        let mut es = Vec::new();
        for n in [20usize, 40, 80] {
            let (st, _) = common::run(&sys, &s0, common::tight(s), 1.0 / n as f64, n);
            hs.push(1.0 / n as f64);
            es.push(common::max_abs_diff(st.q.as_slice(), &r.q[1]));
        }
        let p = common::slope(&hs, &es);
        println!("damped s={s}: {es:?} order {p:.3}");
        assert!((p - 2.0 * s as f64).abs() < 0.3, "damped s={s}: order {p}");
    }
}

#[test]
fn rheonomic_driver() {
    // a crank driven at constant speed through an angle driver, with a pendulum hanging from it
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let crank = b.add_body(
        Body::new("crank")
            .rod(1.0, 0.4)
            .position(0.2, 0.0, 0.0)
            .velocity(0.0, 0.4, 2.0),
    );
    let rod = b.add_body(Body::new("rod").rod(1.0, 1.0).position(
        0.4,
        -0.5,
        -std::f64::consts::FRAC_PI_2,
    ));
    b.add_joint(Joint::revolute(
        "o",
        BodyRef::Ground,
        [0.0, 0.0],
        crank,
        [-0.2, 0.0],
    ));
    b.add_joint(Joint::angle_driver(
        "drive",
        BodyRef::Ground,
        crank,
        TimeFunction::linear(0.0, 2.0),
    ));
    b.add_joint(Joint::revolute("p", crank, [0.2, 0.0], rod, [-0.5, 0.0]));
    let sys = b.build().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let r = reference_trajectory(&sys, &s0, 1.0, 1, 20000, ButcherTableau::dopri5()).unwrap();
    let mut hs = Vec::new();
    let mut es = Vec::new();
    for n in [20usize, 40, 80] {
        let (st, _) = common::run(&sys, &s0, common::tight(2), 1.0 / n as f64, n);
        let mut phi = vec![0.0; sys.n_constraints()];
        sys.phi(st.q.as_slice(), st.t, &mut phi);
        assert!(phi.iter().all(|x| x.abs() < 1e-12));
        sys.phi_dot(st.q.as_slice(), st.v.as_slice(), st.t, &mut phi);
        assert!(phi.iter().all(|x| x.abs() < 1e-12));
        hs.push(1.0 / n as f64);
        es.push(common::max_abs_diff(st.q.as_slice(), &r.q[1]));
    }
    let p = common::slope(&hs, &es);
    println!("driven: {es:?} order {p:.3}");
    assert!((p - 4.0).abs() < 0.3, "driven order {p}");
}

#[test]
fn predictor_history_survives_the_run_loop() {
    use mbd_solve::{run, NoObserver, RunConfig};
    let sys = models::manipulator().unwrap();
    let mut st = State::consistent(&sys, 0.0).unwrap();
    let mut g = Galerkin::new(&sys, SymplecticOptions::new(2)).unwrap();
    let stats = run(
        &mut g,
        &sys,
        &mut st,
        RunConfig::new(1.0, 0.01),
        &mut NoObserver,
    )
    .unwrap();
    println!(
        "newton iterations per step: {}",
        stats.newton_iterations as f64 / stats.steps as f64
    );
    assert!(stats.newton_iterations as f64 / (stats.steps as f64) < 3.5);
    assert_eq!(g.order(), Some(4));
}

/// The multistep predictor changes the Newton work, not the solution; order 3 saves
/// iterations against the one-step predictor (order 0).
#[test]
fn multistep_predictor_saves_iterations_not_accuracy() {
    use mbd_solve::{run, NoObserver, RunConfig};
    let sys = models::manipulator().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    for s in [1, 2] {
        let mut res = Vec::new();
        for p in [0, 3, 6] {
            let mut o = SymplecticOptions::new(s);
            o.predictor_order = p;
            let mut g = Galerkin::new(&sys, o).unwrap();
            let mut st = s0.clone();
            let stats = run(
                &mut g,
                &sys,
                &mut st,
                RunConfig::new(2.0, 0.01),
                &mut NoObserver,
            )
            .unwrap();
            res.push((st, stats.newton_iterations as f64 / stats.steps as f64));
        }
        println!(
            "s = {s}: iterations per step {:?}",
            res.iter().map(|r| r.1).collect::<Vec<_>>()
        );
        for r in &res[1..] {
            let d = common::max_abs_diff(res[0].0.q.as_slice(), r.0.q.as_slice());
            assert!(d < 1e-10, "s = {s}: predictor changes the solution by {d}");
        }
        assert!(
            res[1].1 < res[0].1 - 0.5,
            "s = {s}: order-3 predictor {} vs one-step {} iterations per step",
            res[1].1,
            res[0].1
        );
    }
}

#[test]
fn ten_link_chain_and_jacobian_reuse() {
    let sys = models::n_link_chain(10).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let mut plain = SymplecticOptions::new(2);
    plain.reuse_jacobian = JacobianReuse::Never;
    let mut reuse = plain;
    reuse.reuse_jacobian = JacobianReuse::Always;
    plain.newton.tol = 1e-15;
    reuse.newton.tol = 1e-15;
    let (a, _) = common::run(&sys, &s0, plain, 0.005, 200);
    let (b, _) = common::run(&sys, &s0, reuse, 0.005, 200);
    let d = common::max_abs_diff(a.q.as_slice(), b.q.as_slice());
    assert!(d < 1e-10, "reuse_jacobian changes the solution by {d}");
    let mut r = vec![0.0; sys.n_constraints()];
    sys.phi(b.q.as_slice(), b.t, &mut r);
    assert!(r.iter().all(|x| x.abs() < 1e-12));
    let h0 = sys.energy(s0.q.as_slice(), s0.v.as_slice());
    let h1 = sys.energy(b.q.as_slice(), b.v.as_slice());
    assert!((h1 - h0).abs() < 1e-6 * h0.abs().max(1.0), "{h0} {h1}");
}
