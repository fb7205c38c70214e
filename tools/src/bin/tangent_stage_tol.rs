//! Effect of `TangentOptions::stage_tol_ratio` (inexact interior stage maps) on the accuracy
//! and the chord work of tangent-space RK4 on the manipulator: error at `t = 2 s` against a
//! DOPRI5 reference for several step sizes and ratios.
//!
//! `cargo run --release -p mbd-tools --bin tangent_stage_tol`
use mbd::model::models;
use mbd::solve::{reference_trajectory, ButcherTableau, Integrator, State};
use mbd::tangent::{TangentOptions, TangentRk};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let sys = models::manipulator()?;
    let s0 = State::consistent(&sys, 0.0)?;
    let t_end = 2.0;
    let href = 1e-4;
    let r = reference_trajectory(
        &sys,
        &s0,
        href,
        (t_end / href).round() as usize,
        1,
        ButcherTableau::dopri5(),
    )?;
    let qref = r.q.last().ok_or("empty reference")?.clone();
    println!("h        ratio   error(t=2)   iterations/step   max end residual");
    for h in [0.02, 0.01, 0.005, 0.0025] {
        for ratio in [0.0, 1e-3, 1e-2, 1e-1] {
            let opts = TangentOptions {
                stage_tol_ratio: ratio,
                ..Default::default()
            };
            let mut tr = TangentRk::new(&sys, ButcherTableau::rk4(), opts)?;
            let mut st = s0.clone();
            let n = (t_end / h).round() as usize;
            for _ in 0..n {
                tr.step(&sys, &mut st, h)?;
            }
            let err =
                st.q.iter()
                    .zip(&qref)
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            let stats = tr.stats();
            println!(
                "{h:<8} {ratio:<7} {err:.6e}   {:>6.2}            {:.2e}",
                stats.newton_iterations as f64 / stats.steps as f64,
                stats.max_residual
            );
        }
    }
    Ok(())
}
