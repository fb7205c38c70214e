//! Steps the (2,2) scheme on the manipulator in a loop (for profiling) and prints the time per
//! step and the Newton work.
//!
//! `cargo run --release -p mbd-tools --bin symplectic_profile_step [s] [steps] [predictor_order]`
use mbd::model::models;
use mbd::solve::{Integrator, State};
use mbd::symplectic::{Galerkin, SymplecticOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let s: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(2);
    let sys = models::manipulator()?;
    let s0 = State::consistent(&sys, 0.0)?;
    let mut opts = SymplecticOptions::new(s);
    if let Some(p) = std::env::args().nth(3).and_then(|a| a.parse().ok()) {
        opts.predictor_order = p;
    }
    let mut g = Galerkin::new(&sys, opts)?;
    let mut st = s0.clone();
    let (mut it, mut ev) = (0usize, 0usize);
    let n: usize = std::env::args()
        .nth(2)
        .and_then(|a| a.parse().ok())
        .unwrap_or(200_000);
    let t0 = std::time::Instant::now();
    for _ in 0..n {
        if st.t > 10.0 {
            st = s0.clone();
        }
        let r = g.step(&sys, &mut st, 0.01)?;
        it += r.newton_iterations;
        ev += r.rhs_evals;
    }
    let dt = t0.elapsed().as_secs_f64() / n as f64;
    println!(
        "({s},{s}): {:.3} us/step, {:.2} iterations, {:.2} residuals, {:.3} Jacobians per step",
        dt * 1e6,
        it as f64 / n as f64,
        ev as f64 / n as f64,
        g.jacobian_count() as f64 / n as f64
    );
    Ok(())
}
