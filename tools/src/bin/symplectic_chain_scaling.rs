//! Time per step of the (1,1) and (2,2) schemes against plain RK4 (`Index1Rk` with the RK4
//! tableau, sparse index-1 solve above the threshold) on `n_link_chain(N)`, all through
//! `mbd::solve::run` in the same process, h = 1e-3. Prints a table with the ratios and the cost
//! exponent between consecutive N. Each figure is the best of three timed runs (the machine
//! may be shared), after one untimed run.
//!
//! `cargo run --release -p mbd-tools --bin symplectic_chain_scaling [N ...] [--never] [--dense]`
//! (`--never`: `reuse_jacobian = JacobianReuse::Never`, a new factorisation at every step; the
//! default `Auto` keeps it on the sparse path; `--dense`: force the dense stage solve.)
use mbd::model::models;
use mbd::solve::{
    run, ButcherTableau, Index1Options, Index1Rk, Integrator, LinearSolver, NoObserver, RunConfig,
    State,
};
use mbd::symplectic::{Galerkin, JacobianReuse, SymplecticOptions};
use std::time::Instant;

/// Best wall time per step (microseconds) of `steps` steps of `h` through `run`.
fn per_step(
    integ: &mut dyn Integrator,
    sys: &mbd::model::System,
    s0: &State,
    steps: usize,
) -> Result<f64, Box<dyn std::error::Error>> {
    let h = 1e-3;
    let mut best = f64::INFINITY;
    for rep in 0..4 {
        let mut st = s0.clone();
        let t0 = Instant::now();
        run(
            integ,
            sys,
            &mut st,
            RunConfig::new(s0.t + steps as f64 * h, h),
            &mut NoObserver,
        )?;
        let us = t0.elapsed().as_secs_f64() * 1e6 / steps as f64;
        if rep > 0 {
            best = best.min(us);
        }
    }
    Ok(best)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let reuse = if args.iter().any(|a| a == "--never") {
        JacobianReuse::Never
    } else {
        JacobianReuse::Auto
    };
    let dense = args.iter().any(|a| a == "--dense");
    let mut ns: Vec<usize> = args.iter().filter_map(|a| a.parse().ok()).collect();
    if ns.is_empty() {
        ns = vec![10, 30, 100, 300, 1000];
    }
    println!("reuse_jacobian = {reuse:?}, forced dense = {dense}");
    println!(
        "{:>5} {:>6} {:>11} {:>11} {:>11} {:>8} {:>8} {:>14}",
        "N", "path", "(1,1) us", "(2,2) us", "RK4 us", "(1,1)/RK", "(2,2)/RK", "nnz J / LU (2,2)"
    );
    let mut prev: Option<(usize, f64, f64, f64)> = None;
    for &n in &ns {
        let sys = models::n_link_chain(n)?;
        let s0 = State::consistent(&sys, 0.0)?;
        let steps = (20_000 / n).clamp(40, 2000);
        let mut t = [0.0; 2];
        let mut path = "";
        let mut nnz = (0, 0);
        for (k, s) in [1usize, 2].into_iter().enumerate() {
            let opts = SymplecticOptions {
                reuse_jacobian: reuse,
                linear_solver: if dense {
                    LinearSolver::Dense
                } else {
                    LinearSolver::Auto
                },
                ..SymplecticOptions::new(s)
            };
            let mut g = Galerkin::new(&sys, opts)?;
            path = if g.is_sparse() { "sparse" } else { "dense" };
            t[k] = per_step(&mut g, &sys, &s0, steps)?;
            nnz = g.sparse_nnz();
        }
        let mut rk = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default())?;
        let tr = per_step(&mut rk, &sys, &s0, steps)?;
        println!(
            "{:>5} {:>6} {:>11.1} {:>11.1} {:>11.1} {:>8.2} {:>8.2} {:>7}/{:<7}",
            n,
            path,
            t[0],
            t[1],
            tr,
            t[0] / tr,
            t[1] / tr,
            nnz.0,
            nnz.1
        );
        if let Some((pn, p1, p2, pr)) = prev {
            let l = (n as f64 / pn as f64).ln();
            println!(
                "      cost exponent {pn} -> {n}: (1,1) {:.2}, (2,2) {:.2}, RK4 {:.2}",
                (t[0] / p1).ln() / l,
                (t[1] / p2).ln() / l,
                (tr / pr).ln() / l
            );
        }
        prev = Some((n, t[0], t[1], tr));
    }
    Ok(())
}
