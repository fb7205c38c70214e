//! Cost of the modified-Lagrangian steps against the plain step of the same `s` on
//! `n_link_chain(N)` (h = 0.01 unless `--h H`), through `Integrator::step` in the same process:
//! the plain and the modified integrator, both from the same consistent state, go on stepping in
//! alternating batches, and the best batch of each after the first is kept (the machine may be
//! shared). Prints the time per step, the ratio and the Newton iterations per step (plain /
//! modified).
//!
//! `cargo run --release -p mbd-tools --bin symplectic_modified_scaling [N ...] [--h H]`
use mbd::model::models;
use mbd::solve::{Integrator, State};
use mbd::symplectic::{Galerkin, PreadjustMode, SymplecticOptions};
use std::time::Instant;

/// Times `steps` steps of `g` from `st` (advanced); returns (microseconds per step, Newton iterations per
/// step).
fn batch(
    g: &mut Galerkin,
    sys: &mbd::model::System,
    st: &mut State,
    h: f64,
    steps: usize,
) -> Result<(f64, f64), Box<dyn std::error::Error>> {
    let mut it = 0usize;
    let t0 = Instant::now();
    for _ in 0..steps {
        it += g.step(sys, st, h)?.newton_iterations;
    }
    let us = t0.elapsed().as_secs_f64() * 1e6 / steps as f64;
    Ok((us, it as f64 / steps as f64))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut h = 0.01;
    let mut ns = Vec::new();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--h" {
            h = it.next().ok_or("--h needs a value")?.parse()?;
        } else {
            ns.push(a.parse::<usize>()?);
        }
    }
    if ns.is_empty() {
        ns = vec![10, 50, 100, 200];
    }
    println!("h = {h}");
    println!(
        "{:>5} {:>3} {:>12} {:>14} {:>7} {:>13}",
        "N", "s", "plain us", "modified us", "ratio", "iterations"
    );
    for &n in &ns {
        let sys = models::n_link_chain(n)?;
        let s0 = State::consistent(&sys, 0.0)?;
        let steps = (20_000 / n).clamp(20, 2000);
        for s in [1usize, 2] {
            let opts = [
                SymplecticOptions::new(s),
                SymplecticOptions::new(s).with_preadjust(PreadjustMode::ModifiedLagrangian),
            ];
            let mut gs = [Galerkin::new(&sys, opts[0])?, Galerkin::new(&sys, opts[1])?];
            let mut best = [f64::INFINITY; 2];
            let mut iters = [0.0; 2];
            let mut states = [s0.clone(), s0.clone()];
            for rep in 0..4 {
                for (k, g) in gs.iter_mut().enumerate() {
                    let (us, its) = batch(g, &sys, &mut states[k], h, steps)?;
                    if rep > 0 {
                        best[k] = best[k].min(us);
                    }
                    iters[k] = its;
                }
            }
            println!(
                "{:>5} {:>3} {:>12.1} {:>14.1} {:>6.2}x {:>6.2} / {:.2}",
                n,
                s,
                best[0],
                best[1],
                best[1] / best[0],
                iters[0],
                iters[1]
            );
        }
    }
    Ok(())
}
