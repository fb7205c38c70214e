//! Cost of one tangent-space RK4 step relative to one plain RK4 step (`Index1Rk`, RK4 tableau)
//! on the manipulator: the two run in interleaved blocks of 20000 steps and the best block of
//! 30 counts, which keeps the ratio steady on a shared machine.
//!
//! `cargo run --release -p mbd-tools --bin tangent_step_ratio [h] [centre|interpolated|broyden]`
use mbd::model::models;
use mbd::solve::{ButcherTableau, Index1Options, Index1Rk, Integrator, State};
use mbd::tangent::{IterationMatrix, TangentOptions, TangentRk};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let h: f64 = match args.next() {
        Some(a) => a.parse()?,
        None => 0.01,
    };
    let iteration_matrix = match args.next().as_deref() {
        Some("interpolated") => IterationMatrix::Interpolated,
        Some("broyden") => IterationMatrix::Broyden,
        Some("centre") => IterationMatrix::Centre,
        _ => IterationMatrix::default(),
    };
    let sys = models::manipulator()?;
    let s0 = State::consistent(&sys, 0.0)?;
    let opts = TangentOptions {
        iteration_matrix,
        ..Default::default()
    };
    let mut tangent = TangentRk::new(&sys, ButcherTableau::rk4(), opts)?;
    let mut plain = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default())?;
    let (mut best_t, mut best_p) = (f64::INFINITY, f64::INFINITY);
    let (mut st, mut sp) = (s0.clone(), s0.clone());
    let n = 20_000;
    for _ in 0..30 {
        let t0 = Instant::now();
        for _ in 0..n {
            if st.t > 10.0 {
                st = s0.clone();
            }
            tangent.step(&sys, &mut st, h)?;
        }
        best_t = best_t.min(t0.elapsed().as_secs_f64() / n as f64);
        let t0 = Instant::now();
        for _ in 0..n {
            if sp.t > 10.0 {
                sp = s0.clone();
            }
            plain.step(&sys, &mut sp, h)?;
        }
        best_p = best_p.min(t0.elapsed().as_secs_f64() / n as f64);
    }
    let s = tangent.stats();
    println!(
        "h = {h}, {iteration_matrix:?}: tangent RK4 {:.0} ns/step, plain RK4 {:.0} ns/step, \
         ratio {:.2}; {:.1} chord iterations per step",
        best_t * 1e9,
        best_p * 1e9,
        best_t / best_p,
        s.newton_iterations as f64 / s.steps as f64
    );
    Ok(())
}
