//! Runs N steps of one solver on a model (for callgrind: the difference of two runs with N and
//! 2N steps is the cost of N steps without the set-up), and prints the time per step.
//!
//! `cargo run --release -p mbd-tools --bin bench_solver_steps -- SOLVER [N] [MODEL]` with SOLVER
//! one of `rk4` (plain RK4), `rk4-projected`, `tangent-rk4`, `symplectic2` (`symplectic:2`; `symplecticS`, `modifiedS` for the (s,s) scheme, plain or with
//! the modified Lagrangian, and a `-never` suffix for a new stage Jacobian at every step), `dopri5` (index-1
//! DOPRI5, fixed steps), `fadae` (firefly-Gauss, default options), and MODEL one of
//! `manipulator` (the default), `slider_crank`, `four_bar`, `chainK` (a K-link chain: above 24
//! links the index-1 solve takes the sparse path), `spatialK` (a chain of K spatial rods on
//! ball joints, `mbd_model::models::spatial_chain`). A fourth argument `state` prints the final
//! state in full (for comparing trajectories between builds). `MBD_LINEAR=dense|sparse` picks the
//! linear-algebra path of RK4, tangent RK4 and the symplectic scheme (default: automatic), `MBD_REUSE=always` keeps its stage Jacobian across steps, `MBD_ANDERSON=K` sets the Anderson depth of its Newton iteration (0: off), `MBD_GAMMA=G` its paper-A preadjustment, `MBD_TANGENT_MATRIX=interpolated|broyden` the tangent chart's chord matrix (default: the centre's). The environment variable `MBD_H`
//! overrides the step; `MBD_RUN=1` runs the steps through the public run loop (`mbd_solve::run`,
//! default drift guard) in runs of at most 500 steps.
use mbd::firefly_gauss::{FaDaeOptions, FireflyGauss};
use mbd::model::{models, System};
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{ButcherTableau, Index1Options, Index1Rk, Integrator, State};
use mbd::symplectic::{Galerkin, SymplecticOptions};
use mbd::tangent::{IterationMatrix, TangentRk};

/// The linear-algebra path `MBD_LINEAR=dense|sparse` asks for (default: automatic).
fn linear() -> mbd::solve::LinearSolver {
    match std::env::var("MBD_LINEAR").as_deref() {
        Ok("dense") => mbd::solve::LinearSolver::Dense,
        Ok("sparse") => mbd::solve::LinearSolver::Sparse,
        _ => mbd::solve::LinearSolver::Auto,
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let solver = args.next().unwrap_or_else(|| "rk4".into());
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let model = args.next().unwrap_or_else(|| "manipulator".into());
    let print_state = args.next().is_some_and(|a| a == "state");
    let sys = match model.as_str() {
        "manipulator" => models::manipulator()?,
        "slider_crank" => models::slider_crank()?,
        "four_bar" => models::four_bar()?,
        other if other.ends_with(".toml") || other.ends_with(".json") => System::from_path(other)?,
        other => match (
            other.strip_prefix("chain").and_then(|k| k.parse().ok()),
            other.strip_prefix("spatial").and_then(|k| k.parse().ok()),
        ) {
            (Some(k), _) => models::n_link_chain(k)?,
            (None, Some(k)) => models::spatial_chain(k)?,
            _ => return Err(format!("unknown model '{other}'").into()),
        },
    };
    let s0 = State::consistent(&sys, 0.0)?;
    let (mut integ, h): (Box<dyn Integrator>, f64) = match solver.as_str() {
        "rk4" => (
            Box::new(Rk4::new(
                &sys,
                Rk4Options {
                    linear: linear(),
                    ..Rk4Options::plain()
                },
            )?),
            1e-3,
        ),
        "rk4-projected" => (
            Box::new(Rk4::new(
                &sys,
                Rk4Options {
                    linear: linear(),
                    ..Rk4Options::projected()
                },
            )?),
            1e-3,
        ),
        "tangent-rk4" => {
            // MBD_TANGENT_MATRIX=interpolated|broyden picks the chord iteration's matrix
            let mut opts = mbd::tangent::TangentOptions {
                linear_solver: linear(),
                ..Default::default()
            };
            match std::env::var("MBD_TANGENT_MATRIX").as_deref() {
                Ok("interpolated") => opts.iteration_matrix = IterationMatrix::Interpolated,
                Ok("broyden") => opts.iteration_matrix = IterationMatrix::Broyden,
                _ => {}
            }
            let t = TangentRk::new(&sys, ButcherTableau::rk4(), opts)?;
            (Box::new(t), 1e-3)
        }
        other if other.starts_with("symplectic") || other.starts_with("modified") => {
            // symplecticS / modifiedS, `-never`: a new stage Jacobian at every step
            let (name, never) = match other.strip_suffix("-never") {
                Some(n) => (n, true),
                None => (other, false),
            };
            let (s, modified) = match (
                name.strip_prefix("symplectic").and_then(|k| k.parse().ok()),
                name.strip_prefix("modified").and_then(|k| k.parse().ok()),
            ) {
                (Some(s), _) => (s, false),
                (None, Some(s)) => (s, true),
                _ => return Err(format!("unknown solver '{other}'").into()),
            };
            let mut o = SymplecticOptions::new(s);
            if modified {
                o = o.with_preadjust(mbd::symplectic::PreadjustMode::ModifiedLagrangian);
            }
            if never {
                o = o.with_jacobian_reuse(mbd::symplectic::JacobianReuse::Never);
            }
            // MBD_GAMMA=G: paper A's preadjustment W_s with gamma = G
            if let Some(g) = std::env::var("MBD_GAMMA").ok().and_then(|g| g.parse().ok()) {
                o = o.with_gamma(g);
            }
            // MBD_REUSE=always keeps the stage Jacobian across steps
            if std::env::var("MBD_REUSE").as_deref() == Ok("always") {
                o = o.with_jacobian_reuse(mbd::symplectic::JacobianReuse::Always);
            }
            // MBD_ANDERSON=K sets the Anderson depth of the Newton iteration (0: off)
            if let Some(k) = std::env::var("MBD_ANDERSON")
                .ok()
                .and_then(|k| k.parse().ok())
            {
                o.anderson_depth = k;
            }
            // MBD_LINEAR=dense|sparse picks the path (default: Auto)
            match std::env::var("MBD_LINEAR").as_deref() {
                Ok("dense") => o.linear_solver = mbd::solve::LinearSolver::Dense,
                Ok("sparse") => o.linear_solver = mbd::solve::LinearSolver::Sparse,
                _ => {}
            }
            (Box::new(Galerkin::new(&sys, o)?), 1e-2)
        }
        "dopri5" => (
            Box::new(Index1Rk::new(
                &sys,
                ButcherTableau::dopri5(),
                Index1Options::default(),
            )?),
            1e-3,
        ),
        "fadae" => (
            Box::new(FireflyGauss::new(&sys, FaDaeOptions::default())?),
            1e-3,
        ),
        other => {
            return Err(format!(
            "unknown solver '{other}': rk4, rk4-projected, tangent-rk4, symplectic2, dopri5, fadae"
        )
            .into())
        }
    };
    // MBD_H overrides the step
    let h = std::env::var("MBD_H")
        .ok()
        .and_then(|x| x.parse().ok())
        .unwrap_or(h);
    let mut s = s0.clone();
    let mut its = 0usize;
    let t = std::time::Instant::now();
    if std::env::var("MBD_RUN").as_deref() == Ok("1") {
        // through the public run loop (default drift guard), in runs of at most 500 steps
        let mut left = n;
        while left > 0 {
            let k = left.min(500);
            s = s0.clone();
            let cfg = mbd::solve::RunConfig::new(k as f64 * h, h);
            mbd::solve::run(
                integ.as_mut(),
                &sys,
                &mut s,
                cfg,
                &mut mbd::solve::NoObserver,
            )?;
            left -= k;
        }
    } else {
        for _ in 0..n {
            // restart every 10 s of model time so that long runs stay in the same regime
            if s.t > 10.0 {
                s = s0.clone();
            }
            its += integ.step(&sys, &mut s, h)?.newton_iterations;
        }
    }
    let dt = t.elapsed().as_secs_f64();
    println!(
        "{solver} on {model}: {n} steps, {:.1} ns/step, {:.2} Newton iterations/step (q0 = {:.6})",
        dt / n as f64 * 1e9,
        its as f64 / n as f64,
        s.q[0]
    );
    if print_state {
        for (i, x) in s.q.iter().chain(s.v.iter()).enumerate() {
            println!("x[{i}] = {x:?}");
        }
    }
    Ok(())
}
