//! Runs many RK4 steps on the manipulator (for profilers such as callgrind).
//!
//! `cargo run --release --example bench_rk4_steps -- 100000`
use mbd::model::models;
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{Integrator, State};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000);
    let sys = models::manipulator()?;
    let mut s = State::consistent(&sys, 0.0)?;
    let mut rk = Rk4::new(&sys, Rk4Options::plain())?;
    let t = std::time::Instant::now();
    for _ in 0..n {
        rk.step(&sys, &mut s, 1e-3)?;
    }
    let dt = t.elapsed().as_secs_f64();
    println!(
        "{n} steps: {:.1} ns/step (q0 = {:.6})",
        dt / n as f64 * 1e9,
        s.q[0]
    );
    Ok(())
}
