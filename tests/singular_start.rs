//! A mechanism that starts on a singular configuration (a parallelogram four-bar with its
//! cranks in line with the ground) is not a redundant one: the build tells the two apart by
//! the rank near the start on the manifold, the solvers that keep the constraints pass the
//! start, and the outputs at the start do not take the undetermined multipliers there.

use mbd::model::{Body, BodyRef, Joint, SystemBuilder, TimeFunction};
use mbd::prelude::*;
use mbd_analysis::EnergyBalance;
use std::f64::consts::PI;

/// `cranks` equal cranks (length 0.5, ground pivots 1 apart) carrying one coupler pinned to
/// each, all horizontal at t = 0 and turning at `speed`; with `driven`, crank 0 is driven at
/// that speed (`theta = speed t`).
fn flat_parallelogram(cranks: usize, speed: f64, driven: bool) -> System {
    parallelogram(cranks, 0.0, 0.0, speed, None, driven)
}

/// [`flat_parallelogram`] with the bodies placed where cranks at `placed` (rad) put them and
/// the cranks' angles given as `given` (a guess off the constraints where they differ); with
/// `rate`, only crank 0 is given a velocity (that angular rate), the other bodies none.
fn parallelogram(
    cranks: usize,
    placed: f64,
    given: f64,
    speed: f64,
    rate: Option<f64>,
    driven: bool,
) -> System {
    let (l, d) = (0.5, 1.0);
    let width = (cranks - 1) as f64 * d;
    let (s, c) = placed.sin_cos();
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let mut handles = Vec::new();
    for k in 0..cranks {
        let x0 = k as f64 * d;
        let w = match rate {
            None => speed,
            Some(r) if k == 0 => r,
            Some(_) => 0.0,
        };
        handles.push(
            b.add_body(
                Body::new(format!("crank{k}"))
                    .rod(1.0, l)
                    .position(x0 + 0.5 * l * c, 0.5 * l * s, given)
                    .velocity(-0.5 * l * s * w, 0.5 * l * c * w, w),
            ),
        );
    }
    let w_coupler = if rate.is_some() { 0.0 } else { speed };
    let coupler = b.add_body(
        Body::new("coupler")
            .rod(2.0, width)
            .position(l * c + 0.5 * width, l * s, 0.0)
            .velocity(-l * s * w_coupler, l * c * w_coupler, 0.0),
    );
    for (k, &cr) in handles.iter().enumerate() {
        let x0 = k as f64 * d;
        b.add_joint(Joint::revolute(
            format!("pivot{k}"),
            BodyRef::Ground,
            [x0, 0.0],
            cr,
            [-0.5 * l, 0.0],
        ));
        b.add_joint(Joint::revolute(
            format!("pin{k}"),
            cr,
            [0.5 * l, 0.0],
            coupler,
            [x0 - 0.5 * width, 0.0],
        ));
    }
    if driven {
        b.add_joint(Joint::angle_driver(
            "motor",
            BodyRef::Ground,
            handles[0],
            TimeFunction::linear(0.0, speed),
        ));
    }
    b.build().unwrap()
}

/// The two-crank four-bar started flat has no redundant equation (one degree of freedom, none
/// when driven); the three-crank one keeps the one it has everywhere; both name the equation
/// dependent at the start only.
#[test]
fn a_singular_start_is_told_from_a_redundant_equation() {
    for (cranks, driven, redundant, dof) in [(2, false, 0, 1), (2, true, 0, 0), (3, false, 1, 1)] {
        let sys = flat_parallelogram(cranks, PI, driven);
        let what = format!("{cranks} cranks, driven {driven}");
        assert_eq!(sys.n_redundant(), redundant, "{what}");
        assert_eq!(sys.dof(), dof, "{what}");
        assert_eq!(sys.singular_start_equations().len(), 1, "{what}");
        assert_eq!(sys.dependency_budget(), redundant + 1, "{what}");
        let note = sys.singular_start_note().unwrap();
        assert!(note.contains("initial configuration is singular"), "{note}");
    }
    // fully driven, where no configuration near the start satisfies the driver at t = 0: the
    // probes move the driven crank too (as the motion does)
    let sys = mbd::model::models::parallelogram_four_bar(0.4, 1.0, 0.0, 6.0, true).unwrap();
    assert_eq!((sys.n_redundant(), sys.dof()), (0, 0));
    assert_eq!(sys.singular_start_equations().len(), 1);
    // 1e-3 rad off the flat position: a regular start
    let mut sys = flat_parallelogram(2, PI, false);
    let mut q = sys.initial_guess().0;
    for k in 0..2 {
        q[3 * k + 2] = 1e-3;
    }
    assert!(sys.redundant_at(q.as_slice(), 0.0).unwrap().is_empty());
    sys = flat_parallelogram(3, 0.0, false);
    assert!(sys.singular_start_note().is_some());
}

/// The driven four-bar started flat, to t = 1.5: projected RK4, symplectic (1,1), plain and
/// modified, and (2,2), and the tangent solvers keep the driven kinematics, step over t = 1 (flat again; a step landing
/// there would take a velocity along the other branch), and close the energy balance to 1e-9 of
/// max |H| (5.6e-4 when the driver's power at the start came from the undetermined multipliers
/// there, and 2.9e-4 with the landing at t = 1 accepted). No chart can be centred on the
/// singular start: the tangent solvers take the first step by projected RK of their own
/// tableau and the chart takes over at its end (they stopped at `t = 0` with the typed singular
/// error before), and so does symplectic (1,1), whose own step has no solution there (it
/// stopped at `t = 0` with its Newton residual stalled at `O(h^3)`). A run that ends on the
/// flat position (t = 2) stops there with the singular error, as any mechanism's does (tangent
/// RK4 ended there with the coupler turning at -1.4e-3 rad/s, off the branch, when a window of
/// steps before the last grid time covered it).
#[test]
fn the_solvers_that_keep_the_constraints_pass_a_singular_start_and_close_the_balance() {
    let sys = flat_parallelogram(2, PI, true);
    let crank1 = sys.body_handle("crank1").unwrap().index();
    for spec in [
        "rk4-projected",
        "symplectic:1",
        "symplectic:1:modified",
        "symplectic:2",
        "tangent:rk4",
        "tangent:dopri5",
    ] {
        let mut eb = EnergyBalance::new(&sys).unwrap();
        let mut sim = Simulation::new(sys.clone(), spec).unwrap();
        let stats = sim
            .run_observed(RunConfig::new(1.5, 1e-3), &mut eb)
            .unwrap_or_else(|e| panic!("{spec}: {e}"));
        assert_eq!(stats.stepped_over, 1, "{spec}");
        let first = stats.first_stepped_over.unwrap();
        assert!((first - 1.0).abs() < 1e-9, "{spec}: at {first}");
        let s = sim.state();
        let off = (s.q[3 * crank1 + 2] - 1.5 * PI).abs() + (s.v[3 * crank1 + 2] - PI).abs();
        assert!(off < 1e-9, "{spec}: crank 1 {off:e} off");
        let rel = eb.max_residual() / eb.max_energy();
        assert!(rel < 1e-9, "{spec}: energy balance {rel:e} of max |H|");
        let mut sim = Simulation::new(sys.clone(), spec).unwrap();
        match sim.run(RunConfig::new(2.0, 1e-3)) {
            Err(mbd::Error::Solve(SolveError::Singular { t, .. })) => {
                assert!((t - 2.0).abs() < 1e-9, "{spec}: at {t}")
            }
            other => panic!("{spec}: {other:?}"),
        }
    }
}

/// Adaptive tangent DOPRI5 passes the free four-bar's flat start (its starter's attempt judged
/// by its own embedded estimate) with the energy kept.
#[test]
fn adaptive_tangent_dopri5_passes_a_singular_start() {
    let free = flat_parallelogram(2, PI, false);
    let mut sim = Simulation::new(free.clone(), "tangent:dopri5").unwrap();
    let h0 = free.energy(sim.state().q.as_slice(), sim.state().v.as_slice());
    sim.run(AdaptiveConfig::new(0.5, 1e-10))
        .unwrap_or_else(|e| panic!("adaptive: {e}"));
    let s = sim.state();
    let dh = (free.energy(s.q.as_slice(), s.v.as_slice()) - h0).abs() / h0.abs();
    assert!(dh < 1e-9, "adaptive: energy {dh:e}");
}

/// A rough guess that looks singular (the cranks' angles given as 0, their centres of mass
/// where cranks at 0.5 rad put them) is neither: the build judges the start from the guess
/// projected onto the constraints, where the four-bar is regular.
#[test]
fn a_guess_that_only_looks_singular_is_neither() {
    let sys = parallelogram(2, 0.5, 0.0, 0.0, None, false);
    let q = sys.initial_guess().0;
    assert_eq!(sys.redundant_at(q.as_slice(), 0.0).unwrap().len(), 1);
    assert_eq!((sys.n_redundant(), sys.dof()), (0, 1));
    assert!(sys.singular_start_equations().is_empty());
}

/// Without the motion's velocities, the consistent state at the flat start takes its velocity
/// on the nearest branch of the motion (the velocity constraints alone leave one direction
/// free there, and the projection's choice is on no branch: the projecting solvers stopped at
/// the first step). Driven with every body given at rest: the parallelogram branch, the
/// coupler not turning, the second crank at the motor's rate, and the runs keep the driven
/// kinematics and close the balance. Free with only crank 0 given a rate: both cranks at one
/// rate (the parallelogram branch, the nearer one), and the energy is kept.
#[test]
fn a_singular_start_takes_its_velocity_on_the_nearest_branch() {
    let driven = parallelogram(2, 0.0, 0.0, PI, Some(0.0), true);
    let free = parallelogram(2, 0.0, 0.0, PI, Some(30.0), false);
    let rate =
        |sys: &System, s: &State, body: &str| s.v[3 * sys.body_handle(body).unwrap().index() + 2];
    for (sys, driven) in [(&driven, true), (&free, false)] {
        let s0 = State::consistent(sys, 0.0).unwrap();
        let (w0, w1, wc) = (
            rate(sys, &s0, "crank0"),
            rate(sys, &s0, "crank1"),
            rate(sys, &s0, "coupler"),
        );
        assert!(
            (w0 - w1).abs() < 1e-12 && wc.abs() < 1e-12,
            "{w0} {w1} {wc}"
        );
        if driven {
            assert!((w0 - PI).abs() < 1e-12, "{w0}");
        } else {
            assert!(w0 > 0.1, "{w0}");
        }
        for spec in ["rk4-projected", "symplectic:2"] {
            let mut eb = EnergyBalance::new(sys).unwrap();
            let mut sim = Simulation::new(sys.clone(), spec).unwrap();
            sim.run_observed(RunConfig::new(0.5, 1e-3), &mut eb)
                .unwrap_or_else(|e| panic!("{spec}: {e}"));
            let rel = eb.max_residual() / eb.max_energy();
            assert!(
                rel < 1e-9,
                "{spec} (driven {driven}): energy balance {rel:e} of max |H|"
            );
            // on the parallelogram branch: the cranks turn together, the coupler does not
            let s = sim.state();
            let (w0, w1) = (rate(sys, s, "crank0"), rate(sys, s, "crank1"));
            let coupler = s.q[3 * sys.body_handle("coupler").unwrap().index() + 2];
            assert!(
                (w0 - w1).abs() < 1e-9 && coupler.abs() < 1e-9,
                "{spec}: {w0} {w1} {coupler}"
            );
            if driven {
                assert!((w0 - PI).abs() < 1e-9, "{spec}: {w0}");
            }
        }
    }
}

/// Two loops flat at once (the driven 2-loop N-four-bar started flat): two singular
/// equations, two solvability conditions, and the velocity from rest in the model on the
/// parallelogram branch of both loops (the Gauss-Newton path of several conditions).
#[test]
fn two_loops_flat_at_once_start_on_the_parallelogram_branch() {
    let sys = mbd::model::models::ClosedLoop::n_four_bar(2, 0.4, 1.0)
        .unwrap()
        .system(0.0, 6.0, true)
        .unwrap();
    assert_eq!(sys.singular_start_equations().len(), 2);
    let q = sys.initial_guess().0;
    let zero = vec![0.0; q.len()];
    let x = mbd::solve::project_state(&sys, q.as_slice(), &zero, 0.0, Default::default()).unwrap();
    let names = sys.coordinate_names();
    let rates: Vec<(&String, f64)> = names
        .iter()
        .zip(x.v.iter().copied())
        .filter(|(n, _)| n.ends_with(".theta"))
        .collect();
    assert_eq!(rates.len(), 5);
    for (name, w) in rates {
        let want = if name.starts_with("crank") { 6.0 } else { 0.0 };
        assert!((w - want).abs() < 1e-12, "{name}: {w}");
    }
    let mut sim = Simulation::new(sys.clone(), "rk4-projected").unwrap();
    sim.set_state(State::new(&sys, 0.0, x.q, x.v).unwrap())
        .unwrap();
    sim.run(RunConfig::new(0.3, 1e-3)).unwrap();
    for k in [1, 2] {
        let c = sys.body_handle(&format!("coupler{k}")).unwrap().index();
        let turn = sim.state().q[3 * c + 2];
        assert!(turn.abs() < 1e-9, "coupler{k} turned by {turn}");
    }
}

/// FA-DAE on the free four-bar started flat: every choice of dependent coordinates has a
/// singular block there, so the solver starts with a provisional partition and its first step
/// is projected DOPRI5 (the singular starter); from its end the firefly steps follow the
/// motion on the parallelogram branch. It refused the model before ("Phi_q is rank
/// deficient"). Reference: projected RK4 at a tenth of the step (the unpolished solver's swarm
/// stops at its own tolerance: 1e-7; polished 1e-9).
#[test]
fn fa_dae_passes_a_singular_start_on_the_branch() {
    let free = flat_parallelogram(2, PI, false);
    let coupler = free.body_handle("coupler").unwrap().index();
    let t_end = 0.3;
    let mut reference = Simulation::new(free.clone(), "rk4-projected").unwrap();
    reference.run(RunConfig::new(t_end, 1e-4)).unwrap();
    let r = reference.state().clone();
    for spec in ["firefly-gauss", "firefly-gauss:polish"] {
        let mut sim = Simulation::new(free.clone(), spec).unwrap_or_else(|e| panic!("{spec}: {e}"));
        sim.run(RunConfig::new(t_end, 1e-3))
            .unwrap_or_else(|e| panic!("{spec}: {e}"));
        let s = sim.state();
        let dq = (&s.q - &r.q).amax();
        let dv = (&s.v - &r.v).amax();
        // (the unpolished swarm stops at its own tolerance)
        let tol = if spec == "firefly-gauss" { 1e-7 } else { 1e-9 };
        assert!(
            dq < tol && dv < tol,
            "{spec}: off the reference by {dq:e} / {dv:e}"
        );
        let turn = s.q[3 * coupler + 2].abs();
        assert!(turn < 1e-9, "{spec}: coupler turned by {turn:e}");
    }
}

/// A bad step size on a singular start is an invalid step, not the starter's refusal (the
/// (1,1) scheme hands such a step to the starter before its own checks would run).
#[test]
fn a_bad_step_from_a_singular_start_is_an_invalid_step() {
    let sys = flat_parallelogram(2, PI, true);
    let mut integ = Galerkin::new(&sys, SymplecticOptions::new(1)).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    for h in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        let mut s = s0.clone();
        match integ.step(&sys, &mut s, h) {
            Err(SolveError::InvalidStep { .. }) => {}
            other => panic!("h = {h}: {other:?}"),
        }
        assert_eq!(s.q, s0.q);
    }
    let mut s = s0.clone();
    integ.step(&sys, &mut s, 1e-3).unwrap();
}
