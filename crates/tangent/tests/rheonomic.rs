//! Rheonomic drivers: time enters `f` (through `Phi` and `Phi_t`) and `F`. A driven crank of a
//! double pendulum (one degree of freedom left) and a fully driven slider-crank (none left).

mod common;

use common::{fitted_order, state_error};
use mbd_model::{Body, BodyRef, Joint, System, SystemBuilder, TimeFunction};
use mbd_solve::{
    reference_trajectory, run, ButcherTableau, Flow, NoObserver, RunConfig, SolveError, State,
};
use mbd_tangent::TangentRk;

const OMEGA: f64 = 2.5;
const TH0: f64 = -1.2;

/// Two 1 m, 1 kg rods; the first pinned at the origin and driven: theta1 = TH0 + OMEGA t.
fn driven_double_pendulum() -> System {
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let (s, c) = TH0.sin_cos();
    let l1 = b.add_body(
        Body::new("l1")
            .rod(1.0, 1.0)
            .position(0.5 * c, 0.5 * s, TH0),
    );
    let l2 = b.add_body(Body::new("l2").rod(1.0, 1.0).position(c + 0.5, s, 0.0));
    b.add_joint(Joint::revolute(
        "p1",
        BodyRef::Ground,
        [0.0, 0.0],
        l1,
        [-0.5, 0.0],
    ));
    b.add_joint(Joint::revolute("p2", l1, [0.5, 0.0], l2, [-0.5, 0.0]));
    b.add_joint(Joint::angle_driver(
        "drive",
        BodyRef::Ground,
        l1,
        TimeFunction::linear(TH0, OMEGA),
    ));
    b.build().expect("model")
}

#[test]
fn driven_angle_and_its_rate_hold_at_every_step() {
    let sys = driven_double_pendulum();
    assert!(sys.is_rheonomic());
    assert_eq!(sys.dof(), 1);
    let mut state = State::consistent(&sys, 0.0).expect("state");
    let mut rk = TangentRk::rk4(&sys).expect("solver");
    let (mut worst_angle, mut worst_rate, mut worst_phid) = (0.0f64, 0.0f64, 0.0f64);
    let mut pd = vec![0.0; sys.n_constraints()];
    let mut obs = |sys: &System, s: &State, _k: usize| -> Result<Flow, SolveError> {
        worst_angle = worst_angle.max((s.q[2] - (TH0 + OMEGA * s.t)).abs());
        worst_rate = worst_rate.max((s.v[2] - OMEGA).abs());
        sys.phi_dot(s.q.as_slice(), s.v.as_slice(), s.t, &mut pd);
        worst_phid = pd.iter().fold(worst_phid, |a, b| a.max(b.abs()));
        Ok(Flow::Continue)
    };
    run(
        &mut rk,
        &sys,
        &mut state,
        RunConfig::new(4.0, 1e-3),
        &mut obs,
    )
    .expect("run");
    println!(
        "driven angle error {worst_angle:e}, rate error {worst_rate:e}, Phidot {worst_phid:e}"
    );
    assert!(worst_angle <= 1e-12, "{worst_angle}");
    // the velocity constraint includes Phi_t = -OMEGA: theta1' = OMEGA
    assert!(worst_rate <= 1e-12, "{worst_rate}");
    assert!(worst_phid <= 1e-12);
    // the crank really turned
    assert!((state.q[2] - (TH0 + 4.0 * OMEGA)).abs() < 1e-12);
}

#[test]
fn driven_system_converges_with_order_4() {
    let sys = driven_double_pendulum();
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let r = reference_trajectory(&sys, &s0, 1.0, 1, 4000, ButcherTableau::dopri5()).expect("ref");
    let mut hs = vec![];
    let mut es = vec![];
    for n in [40usize, 80, 160, 320] {
        let h = 1.0 / n as f64;
        let mut s = s0.clone();
        let mut rk = TangentRk::rk4(&sys).expect("solver");
        run(
            &mut rk,
            &sys,
            &mut s,
            RunConfig::new(1.0, h),
            &mut NoObserver,
        )
        .expect("run");
        hs.push(h);
        es.push(state_error(&s, &r.q[1], &r.v[1]));
    }
    let p = fitted_order(&hs, &es);
    println!("driven double pendulum, tangent RK4: errors {es:?}, order {p:.3}");
    assert!((p - 4.0).abs() < 0.2, "{p}");
}

#[test]
fn fully_driven_slider_crank_follows_exact_kinematics() {
    // crank r = 0.15, rod l = 0.5, slider on the x-axis; crank angle = 0.7 + 6 t: no dof left
    let (r, l) = (0.15, 0.5);
    let th = 0.7f64;
    let sys = common::slider_crank(r, l, th, Some(6.0));
    assert_eq!(sys.dof(), 0);
    let mut state = State::consistent(&sys, 0.0).expect("state");
    let mut rk = TangentRk::rk4(&sys).expect("solver");
    assert_eq!(rk.state_dim(), 0);
    let mut worst = 0.0f64;
    let mut obs = |_: &System, s: &State, _k: usize| -> Result<Flow, SolveError> {
        let t = th + 6.0 * s.t;
        let x = r * t.cos() + (l * l - (r * t.sin()).powi(2)).sqrt();
        let xd = -r * 6.0 * t.sin()
            - (r * r * 6.0 * t.sin() * t.cos()) / (l * l - (r * t.sin()).powi(2)).sqrt();
        worst = worst.max((s.q[6] - x).abs()).max((s.v[6] - xd).abs());
        Ok(Flow::Continue)
    };
    run(
        &mut rk,
        &sys,
        &mut state,
        RunConfig::new(2.0, 0.01),
        &mut obs,
    )
    .expect("run");
    println!("slider position/velocity error against the exact kinematics: {worst:e}");
    assert!(worst < 1e-12, "{worst}");
}
