//! Per-step cost of tangent-space RK4 against plain RK4 (`Index1Rk` with the RK4 tableau, the
//! index-1 method `mbd-rk4` wraps) on `n_link_chain(N)`, both through `mbd::solve::run` at
//! `h = 1e-3`. Tangent RK4 runs on its default path (dense QR chart up to
//! `SPARSE_THRESHOLD` constraint equations, sparse chart above) and, for the smaller chains,
//! forced onto the dense chart for comparison. Each solver runs in interleaved blocks of about
//! 0.2 s from the same initial state; the best block counts (steady on a shared machine).
//!
//! `cargo run --release -p mbd-tools --bin tangent_chain_scaling [N ...] [--dense-max N]`
//! (default N = 10 30 100 300 1000, dense chart for N <= 100).
use mbd::model::models;
use mbd::solve::{
    run, ButcherTableau, Index1Options, Index1Rk, Integrator, NoObserver, RunConfig, State,
};
use mbd::tangent::{LinearSolver, TangentOptions, TangentRk};
use std::time::Instant;

const H: f64 = 1e-3;
const BLOCK_SECONDS: f64 = 0.2;
const BLOCKS: usize = 5;

/// Best per-step time (seconds) of `integ` over [`BLOCKS`] blocks of `steps` steps from `s0`.
fn block_time(
    integ: &mut dyn Integrator,
    sys: &mbd::model::System,
    s0: &State,
    steps: usize,
) -> Result<f64, Box<dyn std::error::Error>> {
    let mut s = s0.clone();
    let t0 = Instant::now();
    run(
        integ,
        sys,
        &mut s,
        RunConfig::new(steps as f64 * H, H),
        &mut NoObserver,
    )?;
    Ok(t0.elapsed().as_secs_f64() / steps as f64)
}

/// Steps per block for a solver that takes `per_step` seconds.
fn block_steps(per_step: f64) -> usize {
    ((BLOCK_SECONDS / per_step) as usize).clamp(2, 20_000)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut sizes = vec![];
    let mut dense_max = 100usize;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--dense-max" {
            dense_max = args.next().ok_or("--dense-max needs a value")?.parse()?;
        } else {
            sizes.push(a.parse::<usize>()?);
        }
    }
    if sizes.is_empty() {
        sizes = vec![10, 30, 100, 300, 1000];
    }
    println!(
        "{:>6} {:>6} {:>6} {:>14} {:>14} {:>14} {:>8} {:>10}",
        "N", "m", "path", "tangent us", "plain us", "other-path us", "ratio", "chord it"
    );
    let mut rows = vec![];
    for &n in &sizes {
        let sys = models::n_link_chain(n)?;
        let s0 = State::consistent(&sys, 0.0)?;
        let mut tangent = TangentRk::rk4(&sys)?;
        let mut plain = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default())?;
        // the other chart: dense for the sparse-by-default sizes up to `dense_max`, sparse for
        // the dense-by-default ones
        let mut dense = if !tangent.is_sparse() || n <= dense_max {
            let linear_solver = if tangent.is_sparse() {
                LinearSolver::Dense
            } else {
                LinearSolver::Sparse
            };
            let opts = TangentOptions {
                linear_solver,
                ..Default::default()
            };
            Some(TangentRk::new(&sys, ButcherTableau::rk4(), opts)?)
        } else {
            None
        };
        // trial blocks size the real ones
        let kt = block_steps(block_time(&mut tangent, &sys, &s0, 3)?);
        let kp = block_steps(block_time(&mut plain, &sys, &s0, 3)?);
        let kd = match dense.as_mut() {
            Some(d) => block_steps(block_time(d, &sys, &s0, 2)?),
            None => 0,
        };
        let (mut bt, mut bp, mut bd) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        for _ in 0..BLOCKS {
            bt = bt.min(block_time(&mut tangent, &sys, &s0, kt)?);
            bp = bp.min(block_time(&mut plain, &sys, &s0, kp)?);
            if let Some(d) = dense.as_mut() {
                bd = bd.min(block_time(d, &sys, &s0, kd)?);
            }
        }
        let st = tangent.stats();
        let path = if tangent.is_sparse() {
            "sparse"
        } else {
            "dense"
        };
        println!(
            "{:>6} {:>6} {:>6} {:>14.1} {:>14.1} {:>14} {:>8.2} {:>10.2}",
            n,
            sys.n_constraints(),
            path,
            bt * 1e6,
            bp * 1e6,
            if bd.is_finite() {
                format!("{:.1}", bd * 1e6)
            } else {
                "-".into()
            },
            bt / bp,
            st.newton_iterations as f64 / st.steps.max(1) as f64
        );
        rows.push((n as f64, bt, bp));
    }
    // cost exponents between consecutive sizes: t ~ N^p
    for w in rows.windows(2) {
        let ((n0, t0, p0), (n1, t1, p1)) = (w[0], w[1]);
        let k = (n1 / n0).ln();
        println!(
            "N {} -> {}: tangent exponent {:.2}, plain exponent {:.2}",
            n0,
            n1,
            (t1 / t0).ln() / k,
            (p1 / p0).ln() / k
        );
    }
    if let (Some(a), Some(b)) = (
        rows.iter().find(|r| r.0 == 100.0),
        rows.iter().find(|r| r.0 == 1000.0),
    ) {
        println!(
            "N 100 -> 1000: tangent exponent {:.2}",
            (b.1 / a.1).ln() / 10f64.ln()
        );
    }
    Ok(())
}
