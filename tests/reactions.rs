//! Joint reactions (`mbd::solve::ReactionSolver`): Newton's law on a swinging pendulum, the
//! virtual-work answer on a static slider-crank, and agreement between every registered solver.

use mbd::model::{models, Force, TimeFunction};
use mbd::prelude::*;
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{run, Flow, JointReaction, ReactionSolver};

/// On a pendulum swinging from 0.3 rad, the pin's force on the rod is `m a_com - m g` with
/// `a_com` from central differences of the run's centre-of-mass velocities (RK4, h = 1e-4,
/// sampled every 5e-4 s), to 1e-6 of the weight.
#[test]
fn pin_force_is_mass_times_acceleration_minus_weight() {
    let (m, g) = (1.0, 9.81);
    let sys = models::pendulum(m, 1.0, 0.3, g).unwrap();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Rk4::new(&sys, Rk4Options::plain()).unwrap();
    let mut samples: Vec<State> = Vec::new();
    let mut keep = |_: &System, st: &State, step: usize| -> Result<Flow, SolveError> {
        if step % 5 == 0 {
            samples.push(st.clone());
        }
        Ok(Flow::Continue)
    };
    run(&mut rk, &sys, &mut s, RunConfig::new(1.0, 1e-4), &mut keep).unwrap();
    let mut rs = ReactionSolver::new(&sys).unwrap();
    let mut out = vec![JointReaction::default(); 1];
    let mut worst = 0.0f64;
    for k in (1..samples.len() - 1).step_by(73) {
        let dt = samples[k + 1].t - samples[k - 1].t;
        let a = [
            (samples[k + 1].v[0] - samples[k - 1].v[0]) / dt,
            (samples[k + 1].v[1] - samples[k - 1].v[1]) / dt,
        ];
        rs.compute(&sys, &samples[k], &mut out).unwrap();
        // the pin's second side is the rod: the force on it is m a - m g, g = (0, -9.81)
        let want = [m * a[0], m * a[1] + m * g];
        for (f, w) in out[0].force.iter().zip(want) {
            worst = worst.max((f - w).abs() / (m * g));
        }
        // a revolute joint's moment about its own point vanishes
        assert!(out[0].moment.abs() < 1e-12 * m * g, "{}", out[0].moment);
    }
    eprintln!("largest deviation from m a - m g: {worst:.2e} of m g");
    assert!(worst < 1e-6, "largest deviation {worst:e} of m g");
    assert!(worst > 0.0);
}

/// The static slider-crank of [`static_slider_crank`].
struct Static {
    sys: System,
    /// The rod's force on the slider (N).
    rod_force: [f64; 2],
    /// The push on the slider (N).
    push: f64,
}

/// A slider-crank without gravity at rest (crank 0.3 m at 1 rad, rod 1 m), a push of 50 N on
/// the slider along +x, held by the crank torque that virtual work gives,
/// `tau = -P dx_slider / dtheta`. The rod is then a two-force member: its force on the slider
/// is `T u` (`u` the unit vector from the slider to the crank pin) with `P + T u_x = 0`.
fn static_slider_crank() -> Static {
    let (r, l, th, push) = (0.3, 1.0, 1.0f64, 50.0);
    let a = [r * th.cos(), r * th.sin()];
    let root = (l * l - a[1] * a[1]).sqrt();
    let xs = a[0] + root;
    let dxs = -r * th.sin() - r * r * th.sin() * th.cos() / root;
    let tau = -push * dxs;
    // the project's slider-crank (1 kg rods, 0.5 kg slider) at rest, without gravity
    let params = models::SliderCrankParams {
        crank: r,
        rod: l,
        angle: th,
        speed: 0.0,
        driven: false,
    };
    let mut file = models::slider_crank_with(&params).unwrap().to_model_file();
    file.gravity = [0.0, 0.0];
    let mut b = file.to_builder().unwrap();
    let probe = file.build().unwrap();
    let (crank, slider) = (
        probe.body_handle("crank").unwrap(),
        probe.body_handle("slider").unwrap(),
    );
    b.add_force(Force::torque("drive", crank, TimeFunction::constant(tau)));
    b.add_force(Force::force(
        "push",
        slider,
        [0.0, 0.0],
        TimeFunction::constant(push),
        TimeFunction::constant(0.0),
    ));
    let sys = b.build().unwrap();
    let u = [(a[0] - xs) / l, a[1] / l];
    let t = -push / u[0];
    Static {
        sys,
        rod_force: [t * u[0], t * u[1]],
        push,
    }
}

/// Every joint of the static slider-crank carries the statics answer to 1e-10 of the push:
/// the ground pin and the crank-rod pin the rod force, the rod-slider pin the rod force on the
/// slider, the slide the rest of the slider's balance; revolute moments vanish about their
/// points. The accelerations vanish (the virtual-work torque holds the mechanism).
#[test]
fn static_slider_crank_matches_virtual_work() {
    let st = static_slider_crank();
    let sys = &st.sys;
    let s = State::consistent(sys, 0.0).unwrap();
    let mut rs = ReactionSolver::new(sys).unwrap();
    let mut out = vec![JointReaction::default(); 4];
    rs.compute(sys, &s, &mut out).unwrap();
    let f = st.rod_force;
    let want = [
        ("crank_pin", f),
        ("crank_rod", f),
        ("rod_slider", f),
        ("slide", [-f[0] - st.push, -f[1]]),
    ];
    for (k, (name, w)) in want.iter().enumerate() {
        assert_eq!(sys.joints()[k].name, *name);
        for (f, wc) in out[k].force.iter().zip(w) {
            assert!(
                (f - wc).abs() < 1e-10 * st.push,
                "{name}: {:?} against {w:?}",
                out[k].force
            );
        }
        assert!(
            out[k].moment.abs() < 1e-10 * st.push,
            "{name}: {}",
            out[k].moment
        );
    }
    // the slide's force is across its axis only (the push is balanced by the rod)
    assert!(out[3].local_force[0].abs() < 1e-10 * st.push);
    let mut acc: Vec<f64> = vec![0.0; sys.n_coords()];
    let mut lambda = vec![0.0; sys.n_constraints()];
    let mut solver = mbd::solve::AccelerationSolver::new(sys);
    solver
        .solve(
            sys,
            s.q.as_slice(),
            s.v.as_slice(),
            0.0,
            &mut acc,
            &mut lambda,
        )
        .unwrap();
    assert!(acc.iter().all(|a| a.abs() < 1e-9), "{acc:?}");
}

/// Every registered solver's pendulum at t = 0.5 gives the pin force of a reference run
/// (RK4 at h = 1e-5) to within its accuracy at h = 1e-3 (1e-5 of the weight; 1e-3 for the
/// swarm-based solver, whose error is set by its stopping rule).
#[test]
fn every_solver_agrees_on_the_pin_force() {
    let sys = models::pendulum(1.0, 1.0, 0.3, 9.81).unwrap();
    let mut reference = State::consistent(&sys, 0.0).unwrap();
    let mut rk = Rk4::new(&sys, Rk4Options::plain()).unwrap();
    run(
        &mut rk,
        &sys,
        &mut reference,
        RunConfig::new(0.5, 1e-5),
        &mut mbd::solve::NoObserver,
    )
    .unwrap();
    let mut rs = ReactionSolver::new(&sys).unwrap();
    let mut want = vec![JointReaction::default(); 1];
    rs.compute(&sys, &reference, &mut want).unwrap();
    let mut out = vec![JointReaction::default(); 1];
    for (_, v) in mbd::registry().variants() {
        let mut sim = Simulation::new(sys.clone(), v.spec).unwrap();
        let plan: Plan = if v.spec.starts_with("index1") {
            AdaptiveConfig::new(0.5, 1e-10).into()
        } else {
            RunConfig::new(0.5, 1e-3).into()
        };
        sim.run(plan).unwrap();
        rs.compute(&sys, sim.state(), &mut out).unwrap();
        let tol = if v.relative_cost > 20.0 { 1e-3 } else { 1e-5 } * 9.81;
        let dev = (out[0].force[0] - want[0].force[0])
            .abs()
            .max((out[0].force[1] - want[0].force[1]).abs());
        eprintln!("{}: pin force {dev:.2e} N from the reference", v.spec);
        assert!(dev < tol, "{}: {dev:e}", v.spec);
    }
}

/// A reaction buffer of the wrong length is an error naming what it expected.
#[test]
fn a_wrong_buffer_is_an_error() {
    let sys = models::slider_crank().unwrap();
    let s = State::consistent(&sys, 0.0).unwrap();
    let mut rs = ReactionSolver::new(&sys).unwrap();
    let e = rs
        .compute(&sys, &s, &mut [JointReaction::default(); 2])
        .unwrap_err()
        .to_string();
    assert!(e.contains("one per joint") && e.contains('4'), "{e}");
}
