//! Mechanisms with redundant constraint equations (dependent at every configuration) run with
//! every solver of the registry.

use mbd::model::{Body, BodyRef, Joint, RedundantConstraints, SystemBuilder};
use mbd::prelude::*;

/// Three equal cranks (length `l`, ground pivots `d` apart) carrying one coupler of length
/// `2 d` pinned at its ends and its middle; released from `angle` at rest.
fn double_parallelogram(angle: f64, reject: bool) -> Result<System, mbd::model::ModelError> {
    double_parallelogram_moving(angle, 0.0, 2.0, reject)
}

/// [`double_parallelogram`] with the cranks turning at `speed` (rad/s) from `angle` and a
/// coupler of mass `coupler_mass`.
fn double_parallelogram_moving(
    angle: f64,
    speed: f64,
    coupler_mass: f64,
    reject: bool,
) -> Result<System, mbd::model::ModelError> {
    let (l, d) = (0.5, 1.0);
    let (s, c) = angle.sin_cos();
    // the crank tip's velocity (the coupler translates with it)
    let (vx, vy) = (-l * s * speed, l * c * speed);
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    if reject {
        b.redundant_constraints(RedundantConstraints::Reject);
    }
    let mut cranks = Vec::new();
    for k in 0..3 {
        let x0 = k as f64 * d;
        cranks.push(
            b.add_body(
                Body::new(format!("crank{k}"))
                    .rod(1.0, l)
                    .position(x0 + 0.5 * l * c, 0.5 * l * s, angle)
                    .velocity(0.5 * vx, 0.5 * vy, speed),
            ),
        );
    }
    let coupler = b.add_body(
        Body::new("coupler")
            .rod(coupler_mass, 2.0 * d)
            .position(l * c + d, l * s, 0.0)
            .velocity(vx, vy, 0.0),
    );
    for (k, &cr) in cranks.iter().enumerate() {
        let x0 = k as f64 * d;
        b.add_joint(Joint::revolute(
            format!("G{k}"),
            BodyRef::Ground,
            [x0, 0.0],
            cr,
            [-0.5 * l, 0.0],
        ));
    }
    for (k, &cr) in cranks.iter().enumerate() {
        b.add_joint(Joint::revolute(
            format!("C{k}"),
            cr,
            [0.5 * l, 0.0],
            coupler,
            [(k as f64 - 1.0) * d, 0.0],
        ));
    }
    b.build()
}

/// The exact crank angle of the swinging double parallelogram: on its branch the three cranks
/// share the angle `theta` and the coupler translates, so `T = I theta'^2 / 2` with
/// `I = 3 (m l^2 / 3) + m_c l^2 = 3 l^2` and `V = g (3 m l / 2 + m_c l) sin(theta) = 3.5 g l
/// sin(theta)` (`m = 1`, `m_c = 2`, `l = 0.5`): `theta'' = -(3.5 g / (3 l)) cos(theta)`,
/// integrated here by RK4 at 1e-5 s (error below 1e-15 over 2 s) from `angle` at rest.
fn exact_angle(angle: f64, t_end: f64) -> f64 {
    exact_motion(angle, 0.0, 2.0, t_end)
}

/// [`exact_angle`] from `angle` at `speed` with a coupler of mass `m_c`:
/// `I = (1 + m_c) l^2`, `V = g l (3/2 + m_c) sin(theta)`.
fn exact_motion(angle: f64, speed: f64, m_c: f64, t_end: f64) -> f64 {
    let k = (1.5 + m_c) * 9.81 / ((1.0 + m_c) * 0.5);
    let f = |x: [f64; 2]| [x[1], -k * x[0].cos()];
    let steps = (t_end / 1e-5).round() as usize;
    let h = t_end / steps as f64;
    let mut x = [angle, speed];
    for _ in 0..steps {
        let k1 = f(x);
        let k2 = f([x[0] + 0.5 * h * k1[0], x[1] + 0.5 * h * k1[1]]);
        let k3 = f([x[0] + 0.5 * h * k2[0], x[1] + 0.5 * h * k2[1]]);
        let k4 = f([x[0] + h * k3[0], x[1] + h * k3[1]]);
        for i in 0..2 {
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    x[0]
}

/// The registry's solvers that build for the double parallelogram.
fn accepting() -> Vec<&'static str> {
    let sys = double_parallelogram(-0.5, false).expect("model");
    mbd::registry()
        .variants()
        .filter(|(_, v)| Simulation::new(sys.clone(), v.spec).is_ok())
        .map(|(_, v)| v.spec)
        .collect()
}

/// Crank angle error at t = 1 s and max |Phi| (all twelve equations, the redundant one too)
/// over the run.
fn run(solver: &str, h: f64) -> (f64, f64) {
    let sys = double_parallelogram(-0.5, false).expect("model");
    let mut sim = Simulation::new(sys.clone(), solver).expect(solver);
    let mut rec = Recorder::new();
    let plan: Plan = if solver.starts_with("index1") {
        AdaptiveConfig::new(1.0, h).into()
    } else {
        RunConfig::new(1.0, h).into()
    };
    sim.run_observed(plan, &mut rec).expect(solver);
    let mut phi = vec![0.0; sys.n_constraints()];
    let mut worst = 0.0f64;
    for (q, &t) in rec.q.iter().zip(&rec.t) {
        sys.phi(q, t, &mut phi);
        worst = phi.iter().fold(worst, |w, p| w.max(p.abs()));
    }
    let q = &sim.state().q;
    // the three cranks keep one angle and the coupler translates
    assert!(
        (q[2] - q[5]).abs() < 1e-8 && (q[2] - q[8]).abs() < 1e-8,
        "{solver}"
    );
    assert!(q[11].abs() < 1e-8, "{solver}: coupler angle {}", q[11]);
    ((q[2] - exact_angle(-0.5, 1.0)).abs(), worst)
}

#[test]
fn the_redundant_equation_is_found_named_and_refusable() {
    let sys = double_parallelogram(-0.5, false).expect("model");
    let red = sys.redundant_equations();
    assert_eq!(red.len(), 1);
    // the last equation of the dependent set in row order: the third pin's y row
    assert_eq!(red[0].equation, "C2.y");
    assert_eq!(red[0].joints[0], "C2");
    assert_eq!((sys.n_constraints(), sys.dof()), (12, 1));
    match double_parallelogram(-0.5, true) {
        Err(mbd::model::ModelError::Redundant { equation, joints }) => {
            assert_eq!(equation, "C2.y");
            assert!(joints.contains(&"C0".to_string()), "{joints:?}");
        }
        other => panic!("expected a Redundant error, got {other:?}"),
    }
}

#[test]
fn every_accepting_solver_follows_the_exact_motion_at_its_order() {
    let solvers = accepting();
    // every solver but the tangent-space ones (whose chart needs independent equations);
    // FA-DAE completes its dependent coordinates from m - k of the equations
    assert!(solvers.len() >= 9, "{solvers:?}");
    for fadae in ["firefly-gauss", "firefly-gauss:polish"] {
        assert!(
            solvers.contains(&fadae),
            "{fadae} runs redundant models: {solvers:?}"
        );
    }
    for solver in solvers {
        let order = mbd::registry()
            .variants()
            .find(|(_, v)| v.spec == solver)
            .map(|(_, v)| v.order)
            .expect("variant");
        let (hs, want) = if solver.starts_with("index1") {
            // tolerances a decade apart: the error falls with them
            ([1e-6, 1e-8], 10.0)
        } else if order > 4 {
            // (at 4e-3 the (2,2) modified scheme's error is at the reference's 1e-14 floor)
            ([2e-2, 1e-2], 0.7 * 2f64.powi(order as i32))
        } else {
            ([4e-3, 2e-3], 0.7 * 2f64.powi(order as i32))
        };
        let (e1, c1) = run(solver, hs[0]);
        let (e2, c2) = run(solver, hs[1]);
        eprintln!(
            "{solver}: errors {e1:.3e} {e2:.3e} (ratio {:.2}), max|Phi| {c1:.1e} {c2:.1e}",
            e1 / e2
        );
        assert!(
            e1 / e2 > want,
            "{solver}: {e1:e} -> {e2:e}, want a ratio above {want}"
        );
        assert!(e2 < 10f64.powi(-(order as i32) - 1), "{solver}: {e2:e}");
        // (plain RK4 and index-1 DOPRI5 do not project: their drift is the integration error)
        let drift = if solver == "rk4" || solver.starts_with("index1") {
            1e-8
        } else {
            1e-10
        };
        assert!(c2 < drift, "{solver}: max|Phi| = {c2:e}");
    }
}

/// Every solver of the registry runs the double parallelogram, and a 26-link chain with its
/// last pin doubled (54 equations: the sparse paths) for 0.1 s with its constraints kept. A
/// solver crate that cannot run such models refuses them with `refuse_redundant`, naming the
/// equations, and the registry's advice lists the solvers that build for the model.
#[test]
fn every_solver_runs_redundant_models_and_a_refusal_says_which_do() {
    assert_eq!(accepting().len(), mbd::registry().variants().count());
    let mut mf = mbd::model::models::n_link_chain(26)
        .expect("chain")
        .to_model_file();
    let Some(mbd::model::JointSpec::Revolute(last)) = mf.joints.last().cloned() else {
        panic!("the chain ends with a pin");
    };
    mf.joints.push(mbd::model::JointSpec::Revolute(
        mbd::model::joints::RevoluteSpec {
            name: "again".into(),
            ..last
        },
    ));
    let sys = mf.build().expect("a doubled pin builds");
    assert_eq!((sys.n_constraints(), sys.n_redundant()), (54, 2));
    let mut phi = vec![0.0; sys.n_constraints()];
    for (_, v) in mbd::registry().variants() {
        let mut sim = Simulation::new(sys.clone(), v.spec).expect(v.spec);
        let plan: Plan = if v.spec.starts_with("index1") {
            AdaptiveConfig::new(0.1, 1e-8).into()
        } else if v.relative_cost > 20.0 {
            // (the swarm optimises 52 variables a step here: two steps)
            RunConfig::new(0.02, 1e-2).into()
        } else {
            RunConfig::new(0.1, 1e-3).into()
        };
        sim.run(plan).expect(v.spec);
        let s = sim.state();
        sys.phi(s.q.as_slice(), s.t, &mut phi);
        let worst = phi.iter().fold(0.0f64, |w, p| w.max(p.abs()));
        assert!(worst < 1e-6, "{}: max|Phi| = {worst:e}", v.spec);
    }
    let e = mbd::solve::refuse_redundant(&sys, "my solver").expect_err("refused");
    let e = mbd::registry().with_advice(&sys, e).to_string();
    assert!(
        e.contains("my solver does not run") && e.contains("again.x"),
        "{e}"
    );
    for (_, v) in mbd::registry().variants() {
        assert!(e.contains(v.spec), "{e} lacks {}", v.spec);
    }
}

/// Runs the double parallelogram for 1 s at h = 1e-3 with the integrator `make` builds for
/// the dense and for the sparse linear algebra: both keep all twelve equations below 1e-12
/// and end within `tol` of each other.
fn dense_and_sparse_agree(
    label: &str,
    tol: f64,
    make: impl Fn(&System, mbd::solve::LinearSolver) -> Box<dyn mbd::solve::Integrator>,
) {
    use mbd::solve::{run, LinearSolver, NoObserver};
    let sys = double_parallelogram(-0.5, false).expect("model");
    let mut ends = Vec::new();
    for linear in [LinearSolver::Dense, LinearSolver::Sparse] {
        let mut integ = make(&sys, linear);
        let mut s = State::consistent(&sys, 0.0).expect("state");
        run(
            &mut integ,
            &sys,
            &mut s,
            RunConfig::new(1.0, 1e-3),
            &mut NoObserver,
        )
        .expect("run");
        let mut phi = vec![0.0; sys.n_constraints()];
        sys.phi(s.q.as_slice(), s.t, &mut phi);
        let worst = phi.iter().fold(0.0f64, |w, p| w.max(p.abs()));
        assert!(worst < 1e-12, "{label}, {linear:?}: max|Phi| = {worst:e}");
        ends.push(s.q.clone());
    }
    let d = (&ends[0] - &ends[1]).amax();
    assert!(d < tol, "{label}: dense vs sparse: {d:e}");
}

/// The sparse and the dense Schur complement drop the same equation and give the same motion.
#[test]
fn dense_and_sparse_index1_solves_agree() {
    use mbd::rk4::{Rk4, Rk4Options};
    dense_and_sparse_agree("projected RK4", 1e-12, |sys, linear| {
        let mut opts = Rk4Options::projected();
        opts.linear = linear;
        Box::new(Rk4::new(sys, opts).expect("rk4"))
    });
}

/// The tangent-space chart forced onto its sparse path (all rows, the dependent ones dropped in
/// each factorisation of `Df Df^T`) and its dense path (the independent rows chosen at each
/// centre) follow the same motion.
#[test]
fn dense_and_sparse_tangent_charts_agree() {
    use mbd::solve::ButcherTableau;
    use mbd::tangent::{TangentOptions, TangentRk};
    dense_and_sparse_agree("tangent RK4", 1e-11, |sys, linear| {
        let opts = TangentOptions {
            linear_solver: linear,
            ..Default::default()
        };
        Box::new(TangentRk::new(sys, ButcherTableau::rk4(), opts).expect("tangent"))
    });
}

/// The symplectic stage equations on the sparse path (the dependent equations' rows made the
/// identity on their multipliers) and on the dense path (their pivots dropped) follow the same
/// motion, for the (1,1) and (2,2) schemes and the (1,1) modified-Lagrangian one.
#[test]
fn dense_and_sparse_symplectic_stage_solves_agree() {
    use mbd::symplectic::{Galerkin, PreadjustMode, SymplecticOptions};
    for (s_stages, modified) in [(1, false), (2, false), (1, true)] {
        let label = format!("symplectic ({s_stages},{s_stages}), modified {modified}");
        dense_and_sparse_agree(&label, 1e-11, |sys, linear| {
            let mut opts = SymplecticOptions::new(s_stages);
            if modified {
                opts = opts.with_preadjust(PreadjustMode::ModifiedLagrangian);
            }
            opts.linear_solver = linear;
            Box::new(Galerkin::new(sys, opts).expect("symplectic"))
        });
    }
}

/// The double parallelogram with a 4 kg coupler swung over its flat position (from 1 rad at
/// 3 rad/s the cranks pass `theta = pi` near t = 0.7977 s at 6.7 rad/s): there `Phi_q` loses two more ranks (the
/// three cranks and the coupler collinear with the ground), so the nearly dependent rows and
/// the redundant one meet in one factorisation. Every solver that keeps the constraints passes
/// it at steps that land within 1.5e-6 rad of it (3e-4 and 1e-4: t = 0.7977 is on both grids)
/// and follows the exact motion to 1 s: the dense semidefinite Cholesky pivots where a kept
/// pivot is small (natural order lost the redundant row among the rounding of the nearly
/// dependent ones and stopped), and the tangent chart keeps the best-conditioned equations
/// (the natural order kept rows that imply the redundant one only through coefficients of
/// `1 / delta`: its velocity residual reached 1.8e-4 with tangent DOPRI5 at 3e-4).
#[test]
fn every_projecting_solver_passes_the_flat_position_with_its_redundant_equation() {
    let (angle, speed, t_end) = (1.0, 3.0, 1.0);
    let sys = double_parallelogram_moving(angle, speed, 4.0, false).expect("model");
    let exact = exact_motion(angle, speed, 4.0, t_end);
    for solver in [
        "rk4-projected",
        "symplectic:2",
        "tangent:rk4",
        "tangent:dopri5",
    ] {
        for h in [1e-4, 3e-4] {
            let mut sim = Simulation::new(sys.clone(), solver).expect(solver);
            let mut rec = Recorder::new();
            sim.run_observed(RunConfig::new(t_end, h), &mut rec)
                .unwrap_or_else(|e| panic!("{solver} at h = {h}: {e}"));
            // every equation, the redundant one too, position and velocity
            let m = sys.n_constraints();
            let (mut phi, mut phid) = (vec![0.0; m], vec![0.0; m]);
            let mut worst = 0.0f64;
            for ((q, v), &t) in rec.q.iter().zip(&rec.v).zip(&rec.t) {
                sys.phi_and_phi_dot(q, v, t, &mut phi, &mut phid);
                worst = phi.iter().chain(&phid).fold(worst, |w, p| w.max(p.abs()));
            }
            let err = (sim.state().q[2] - exact).abs();
            eprintln!("{solver} h = {h}: angle error {err:.2e}, max |(Phi, Phidot)| {worst:.1e}");
            assert!(err < 1e-4, "{solver} at h = {h}: angle error {err:e}");
            assert!(
                worst < 1e-8,
                "{solver} at h = {h}: constraint residual {worst:e}"
            );
        }
    }
}
